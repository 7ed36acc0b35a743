/* Texture coordinates and their exact derivatives (issue 15):
 * - every camera's ray differentials (rr_cam_ray_diff) against central differences
 *   of rr_cam_ray over cameras set up at nearby sample positions;
 * - the uv AOV against the plane's UV map at the hit (an independent evaluation,
 *   from the depth AOV and the camera's ray), for a finite quad and for an infinite
 *   plane whose corners at infinity carry UV rates;
 * - the uv-deriv AOV against central differences of the uv AOV over frames rendered
 *   at sample positions ±h around a base position away from the pixel's centre, on
 *   random views with every camera: perspective, orthographic, parabolic, lat-long,
 *   fisheye and cube;
 * - the same for the analytic kinds' maps (a sphere, an oriented box, a tilted plane);
 * - the texture filters' names and rr_shade_frame's refusal of bad texture options. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

/* The step of the central differences, in pixels: small enough that the
 * truncation error, (h·ρ)² relative for a projective map whose depth changes by a
 * fraction ρ per pixel, stays far below the tolerance where ρ <= RHO_MAX. */
#define H (1.0f / 8.0f)
#define RHO_MAX 0.25f
/* Relative tolerance of a derivative: (H·RHO_MAX)² ≈ 0.1% truncation, doubled,
 * plus margin for the curved cameras' own curvature over ±H (at most a few 1e-4). */
#define REL_TOL 3e-3
/* The UV map of the test planes: u = A x + B z + C, v = D x + E z + F on y = 0. */
typedef struct uv_map {
  float a, b, c, d, e, f;
} uv_map;

static void map_uv(const uv_map *m, float x, float z, float uv[2]) {
  uv[0] = m->a * x + m->b * z + m->c, uv[1] = m->d * x + m->e * z + m->f;
}

/* The plane y = 0 with UVs by map: a quad of side 2L (two triangles), or four
 * triangles fanning from the origin to the points at infinity ±x, ±z, whose UVs are
 * the map's rates along those directions. */
static rr_scene *plane_scene(rr_device *dev, const uv_map *m, bool infinite, float L) {
  rr_scene *s;
  if (rr_scene_new(dev, &s) != RR_OK) return NULL;
  float grey[3] = {0.8f, 0.8f, 0.8f};
  uint32_t mat = rr_scene_add_material(s, grey, NULL);
  bool ok = mat != UINT32_MAX && rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, "plane") == RR_OK &&
            rr_scene_reserve(s, 4, false, true) == RR_OK && (!infinite || rr_scene_reserve_inf(s) == RR_OK);
  if (ok && infinite) {
    const vec3 dir[4] = {v3(1, 0, 0), v3(0, 0, -1), v3(-1, 0, 0), v3(0, 0, 1)};
    for (int q = 0; q < 4; q++) {
      vec3 p[3] = {v3(0, 0, 0), dir[q], dir[(q + 1) % 4]};
      float uv[3][2];
      map_uv(m, 0, 0, uv[0]);
      for (int k = 1; k < 3; k++) /* the rate: the map's linear part along the direction */
        uv[k][0] = m->a * p[k].x + m->b * p[k].z, uv[k][1] = m->d * p[k].x + m->e * p[k].z;
      ok = ok && rr_scene_push_inf(s, p, 6u, NULL, (const float(*)[2])uv, NULL, mat);
    }
  } else if (ok) {
    const float cx[4] = {-L, L, L, -L}, cz[4] = {L, L, -L, -L};
    const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int t = 0; t < 2; t++) {
      vec3 p[3];
      float uv[3][2];
      for (int k = 0; k < 3; k++) {
        int c = tri[t][k];
        p[k] = v3(cx[c], 0, cz[c]);
        map_uv(m, cx[c], cz[c], uv[k]);
      }
      ok = ok && rr_scene_push(s, p, NULL, (const float(*)[2])uv, mat);
    }
  }
  if (ok) rr_scene_update_bounds(s);
  if (!ok || rr_scene_commit(s) != RR_OK) {
    CHECK(0, "plane scene: %s", rr_device_message(dev));
    rr_scene_release(s);
    return NULL;
  }
  return s;
}


/* ---- ray differentials ---------------------------------------------------------- */

/* rr_cam_ray_diff at sample position pos against (ray(pos + h e) − ray(pos − h e)) / 2h
 * for e = x, y, at pixels over the image (those with a ray at all three positions). */
static void check_ray_diff(rr_device *dev, const rr_camera *rc, int W, int Hh, const float pos[2]) {
  camera c, cx[2], cy[2];
  const float h = 1.0f / 16.0f;
  float px[2][2] = {{pos[0] - h, pos[1]}, {pos[0] + h, pos[1]}}, py[2][2] = {{pos[0], pos[1] - h}, {pos[0], pos[1] + h}};
  if (rr_cam_setup_at(dev, rc, W, Hh, pos, &c) != RR_OK) {
    CHECK(0, "%s: %s", rr_camera_name(rc->type), rr_device_message(dev));
    return;
  }
  bool ok = true;
  for (int k = 0; k < 2; k++) {
    ok = ok && rr_cam_setup_at(dev, rc, W, Hh, px[k], &cx[k]) == RR_OK;
    ok = ok && rr_cam_setup_at(dev, rc, W, Hh, py[k], &cy[k]) == RR_OK;
  }
  CHECK(ok, "%s: %s", rr_camera_name(rc->type), rr_device_message(dev));
  int checked = 0, bad = 0;
  double worst = 0;
  for (int y = 0; ok && y < Hh; y += 3)
    for (int x = 0; x < W; x += 3) {
      vec3 o, d, dO[2], dD[2], o2[2][2], d2[2][2];
      bool has = rr_cam_ray_diff(&c, x, y, &o, &d, dO, dD);
      vec3 oo, dd;
      CHECK(rr_cam_ray(&c, x, y, &oo, &dd) == has && (!has || (!memcmp(&oo, &o, 12) && !memcmp(&dd, &d, 12))),
            "%s (%d,%d): rr_cam_ray_diff's ray is not rr_cam_ray's", rr_camera_name(rc->type), x, y);
      for (int k = 0; k < 2; k++) {
        has = has && rr_cam_ray(&cx[k], x, y, &o2[0][k], &d2[0][k]);
        has = has && rr_cam_ray(&cy[k], x, y, &o2[1][k], &d2[1][k]);
      }
      if (!has) continue;
      for (int a = 0; a < 2; a++) {
        vec3 fo = v3_scale(v3_sub(o2[a][1], o2[a][0]), 0.5f / h), fd = v3_scale(v3_sub(d2[a][1], d2[a][0]), 0.5f / h);
        /* rounding of the float rays over 2h (|d|, |o| ε / h) and the truncation
         * h²/6 |d'''|, far below 1e-4 of the derivative for these fields of view */
        double tol_d = 1e-4 * v3_len(dD[a]) + 1e-5 * v3_len(d), tol_o = 1e-4 * v3_len(dO[a]) + 1e-5 * (v3_len(o) + 1);
        double ed = v3_len(v3_sub(fd, dD[a])), eo = v3_len(v3_sub(fo, dO[a]));
        worst = fmax(worst, ed / (v3_len(dD[a]) + 1e-30));
        if (ed > tol_d || eo > tol_o) {
          if (bad++ < 3)
            CHECK(0, "%s at (%d,%d)+(%g,%g), d/d%c: direction off by %g (|dd| %g), origin off by %g (|do| %g)",
                  rr_camera_name(rc->type), x, y, pos[0], pos[1], "xy"[a], ed, v3_len(dD[a]), eo, v3_len(dO[a]));
        }
        checked++;
      }
    }
  CHECK(bad == 0, "%s: %d of %d derivatives off (worst relative %g)", rr_camera_name(rc->type), bad, checked, worst);
  CHECK(checked > W * Hh / 30, "%s: only %d derivatives checked", rr_camera_name(rc->type), checked);
  rr_cam_release(&c);
  for (int k = 0; k < 2; k++) rr_cam_release(&cx[k]), rr_cam_release(&cy[k]);
}

static void test_ray_differentials(rr_device *dev) {
  const float positions[3][2] = {{0.5f, 0.5f}, {0.25f, 0.75f}, {0.8125f, 0.1875f}};
  vec3 eye = v3(0.3f, 1.2f, -0.7f), target = v3(-1.0f, 0.4f, 2.0f);
  for (int p = 0; p < 3; p++) {
    rr_camera persp = test_camera(RR_CAMERA_PERSPECTIVE, eye, target, 50);
    check_ray_diff(dev, &persp, 64, 48, positions[p]);
    rr_camera ortho = test_camera(RR_CAMERA_ORTHOGRAPHIC, eye, target, 50);
    ortho.ortho_height = 3;
    check_ray_diff(dev, &ortho, 64, 48, positions[p]);
    rr_camera para = test_camera(RR_CAMERA_PARABOLIC, eye, target, 50);
    check_ray_diff(dev, &para, 64, 48, positions[p]);
    rr_camera ll = test_camera(RR_CAMERA_LATLONG, eye, target, 50);
    check_ray_diff(dev, &ll, 96, 48, positions[p]);
    for (int k = 0; k < 3; k++) { /* the centre (ψ undefined there) falls on a sample at (0.5, 0.5) */
      const float fovs[3] = {100, 230, 360};
      rr_camera fish = test_camera(RR_CAMERA_FISHEYE, eye, target, fovs[k]);
      check_ray_diff(dev, &fish, 64, 64, positions[p]);
    }
    rr_camera cube = test_camera(RR_CAMERA_CUBE, eye, target, 50);
    check_ray_diff(dev, &cube, 96, 72, positions[p]);
  }
}

/* ---- texture coordinates -------------------------------------------------------- */

typedef struct view_frames {
  rr_image uv[5], deriv, depth, mesh; /* uv: base, x − h, x + h, y − h, y + h */
  rr_image base_mesh;                  /* the base frame's geometries (mesh: RR_MISS where the frames differ) */
} view_frames;

static bool render_view(rr_device *dev, const rr_scene *s, const rr_camera *cam, int W, int Hh, const float pos[2],
                        view_frames *v) {
  const float off[5][2] = {{0, 0}, {-H, 0}, {H, 0}, {0, -H}, {0, H}};
  bool ok = true;
  for (int k = 0; k < 5 && ok; k++) {
    float p[1][2] = {{pos[0] + off[k][0], pos[1] + off[k][1]}};
    rr_render_options o = test_pattern(RR_METHOD_3DR_BB, W, Hh, 1, 1, (const float(*)[2])p);
    rr_frame *f = test_render_opt(dev, s, cam, &o);
    ok = f && rr_frame_aov(dev, s, cam, f, RR_AOV_UV, &v->uv[k]) == RR_OK;
    if (ok && k == 0)
      ok = rr_frame_aov(dev, s, cam, f, RR_AOV_UV_DERIV, &v->deriv) == RR_OK &&
           rr_frame_aov(dev, s, cam, f, RR_AOV_DEPTH, &v->depth) == RR_OK &&
           rr_frame_aov(dev, s, cam, f, RR_AOV_MESH, &v->base_mesh) == RR_OK;
    if (ok) { /* the mesh of every frame must agree: keep the base's, mark disagreement */
      rr_image m;
      ok = rr_frame_aov(dev, s, cam, f, RR_AOV_MESH, &m) == RR_OK;
      if (ok && k == 0) v->mesh = m;
      else if (ok) {
        uint32_t *a = v->mesh.data, *b = m.data;
        for (size_t i = 0; i < (size_t)W * Hh; i++)
          if (a[i] != b[i]) a[i] = RR_MISS;
        rr_image_free(&m);
      }
    }
    rr_frame_release(f);
  }
  CHECK(ok, "render: %s", rr_device_message(dev));
  return ok;
}

static void free_view(view_frames *v) {
  for (int k = 0; k < 5; k++) rr_image_free(&v->uv[k]);
  rr_image_free(&v->deriv), rr_image_free(&v->depth), rr_image_free(&v->mesh), rr_image_free(&v->base_mesh);
}

/* What a view's uv values are checked against: the coordinates at world point p on
 * geometry `mesh` and their rounding tolerance (dir, distance: the unit ray and the hit's
 * distance along it);
 * false where the point is left out (a seam, an edge). */
typedef struct uv_ref {
  bool (*at)(const struct uv_ref *ref, uint32_t mesh, vec3 p, vec3 dir, float distance, float uv[2], double *tol);
  const uv_map *m; /* plane scenes: the map, and the quad's half side (0: infinite) */
  float L;
  const float *prims; /* analytic scenes: geometry g's one primitive (sphere, box, plane), */
  long *seen;         /* ANA_FLOATS each, and the pixels checked on each */
  double rel_tol;     /* of the derivatives: REL_TOL for planes; curved surfaces' paths bend
                         more within ±H than a projective map's (a sphere: the third
                         derivative), so their central differences are looser */
} uv_ref;

static bool plane_ref(const uv_ref *ref, uint32_t mesh, vec3 p, vec3 dir, float distance, float uv[2], double *tol) {
  const uv_map *m = ref->m;
  (void)mesh, (void)dir;
  map_uv(m, p.x, p.z, uv);
  /* rounding: the uv values are good to some 1e-6 of the map's span over the
   * plane seen (corners, hit, distance): the barycentrics and the hit are floats */
  *tol = 2e-6 * ((fabs(m->a) + fabs(m->b) + fabs(m->d) + fabs(m->e)) * (v3_len(p) + distance + ref->L) +
                 fabs(m->c) + fabs(m->f));
  return true;
}

/* One view of a scene: uv against the reference at the hit, uv-deriv against
 * central differences; returns the pixel directions whose derivatives were compared. */
static int check_view(rr_device *dev, const rr_scene *s, const uv_ref *ref, const rr_camera *cam, int W, int Hh,
                      const float pos[2], const char *what) {
  view_frames v;
  memset(&v, 0, sizeof v);
  camera c;
  if (!render_view(dev, s, cam, W, Hh, pos, &v) || rr_cam_setup_at(dev, cam, W, Hh, pos, &c) != RR_OK) {
    free_view(&v);
    return 0;
  }
  int compared = 0, bad_uv = 0, bad_d = 0, hits = 0;
  double worst = 0;
  const float *uv = v.uv[0].data, *der = v.deriv.data, *depth = v.depth.data;
  const uint32_t *mesh = v.mesh.data;
  for (int y = 0; y < Hh; y++)
    for (int x = 0; x < W; x++) {
      size_t i = (size_t)y * W + x;
      if (!(depth[i] < INFINITY)) {
        CHECK(uv[2 * i] == 0 && uv[2 * i + 1] == 0 && der[4 * i] == 0 && der[4 * i + 3] == 0,
              "%s (%d,%d): a miss with uv (%g, %g)", what, x, y, uv[2 * i], uv[2 * i + 1]);
        continue;
      }
      hits++;
      /* the map at the hit: eye + depth along the unit ray */
      vec3 o, d;
      rr_cam_ray(&c, x, y, &o, &d);
      vec3 dir = v3_scale(d, 1.0f / v3_len(d)), p = v3_add(o, v3_scale(dir, depth[i]));
      float want[2];
      double tol;
      if (!ref->at(ref, ((const uint32_t *)v.base_mesh.data)[i], p, dir, depth[i], want, &tol)) continue;
      for (int a = 0; a < 2; a++)
        if (fabs(uv[2 * i + a] - want[a]) > tol && bad_uv++ < 3)
          CHECK(0, "%s (%d,%d): %c = %.7g, the map gives %.7g", what, x, y, "uv"[a], uv[2 * i + a], want[a]);
      /* derivatives: where the five frames saw the plane, along each direction a whose
       * depth changes by at most RHO_MAX per pixel: for a projective map u''/u' = −2ρ,
       * so the second difference (u(+h) − 2u(0) + u(−h)) / h² bounds ρ; there the
       * central difference is exact to (h ρ)² of D_a = |du/da| + |dv/da| */
      if (mesh[i] == RR_MISS) continue;
      const float *lo[2] = {v.uv[1].data, v.uv[3].data}, *hi[2] = {v.uv[2].data, v.uv[4].data};
      /* their rounding, divided by 2h */
      double round = tol / (2 * H);
      for (int a = 0; a < 2; a++) {
        float D = fabsf(der[4 * i + 2 * a]) + fabsf(der[4 * i + 2 * a + 1]);
        bool smooth = true;
        for (int comp = 0; comp < 2; comp++) {
          double second = fabs(hi[a][2 * i + comp] - 2.0 * uv[2 * i + comp] + lo[a][2 * i + comp]) / (H * H);
          smooth = smooth && second <= 2 * RHO_MAX * D + round / H;
        }
        if (!smooth) continue;
        compared++;
        for (int comp = 0; comp < 2; comp++) {
          int k = 2 * a + comp;
          double fd = (hi[a][2 * i + comp] - (double)lo[a][2 * i + comp]) / (2 * H);
          double err = fabs(fd - der[4 * i + k]);
          worst = fmax(worst, err / (ref->rel_tol * D + round));
          if (err > ref->rel_tol * D + round && bad_d++ < 3)
            CHECK(0, "%s (%d,%d) at (%g,%g): %s = %.6g, central difference %.6g (tolerance %.3g)", what, x, y,
                  pos[0], pos[1], (const char *[]){"du/dx", "dv/dx", "du/dy", "dv/dy"}[k], der[4 * i + k], fd,
                  ref->rel_tol * D + round);
        }
      }
    }
  CHECK(bad_uv == 0, "%s: %d uv values off the map", what, bad_uv);
  CHECK(bad_d == 0, "%s: %d of %d derivatives off (worst: %.3g of the tolerance)", what, bad_d, compared, worst);
  if (getenv("RR_TEST_VERBOSE")) fprintf(stderr, "%s: %d compared, worst %.3g of the tolerance\n", what, compared, worst);
  CHECK(hits > W * Hh / 10, "%s: the plane covers only %d pixels", what, hits);
  rr_cam_release(&c);
  free_view(&v);
  return compared;
}

static void test_plane_views(rr_device *dev, bool infinite) {
  int views = test_quick() ? 2 : 6;
  const rr_camera_type types[] = {RR_CAMERA_PERSPECTIVE, RR_CAMERA_ORTHOGRAPHIC, RR_CAMERA_PARABOLIC,
                                  RR_CAMERA_LATLONG,     RR_CAMERA_FISHEYE,      RR_CAMERA_CUBE};
  for (int view = 0; view < views; view++) {
    uv_map m = {test_randf(0.2f, 2), test_randf(-1, 1), test_randf(-3, 3),
                test_randf(-1, 1),   test_randf(0.2f, 2), test_randf(-3, 3)};
    const float L = 40;
    rr_scene *s = plane_scene(dev, &m, infinite, L);
    if (!s) return;
    for (size_t t = 0; t < sizeof types / sizeof types[0]; t++) {
      /* above the plane, looking down at a random slant (grazing to steep) */
      vec3 eye = v3(test_randf(-3, 3), test_randf(0.3f, 3), test_randf(-3, 3));
      float ang = test_randf(0, 6.2832f), reach = test_randf(0.5f, 8) * eye.y;
      vec3 target = v3(eye.x + reach * cosf(ang), 0, eye.z + reach * sinf(ang));
      rr_camera cam = test_camera(types[t], eye, target, types[t] == RR_CAMERA_FISHEYE ? 200 : test_randf(30, 80));
      if (types[t] == RR_CAMERA_ORTHOGRAPHIC) cam.ortho_height = test_randf(1, 6);
      int W = types[t] == RR_CAMERA_CUBE ? 96 : types[t] == RR_CAMERA_LATLONG ? 128 : 80, Hh = types[t] == RR_CAMERA_CUBE ? 72 : 64;
      float pos[2] = {test_randf(H, 1 - H), test_randf(H, 1 - H)};
      if (view == 0) pos[0] = pos[1] = 0.5f; /* the centre too */
      char what[96];
      snprintf(what, sizeof what, "%s plane, %s view %d", infinite ? "infinite" : "finite", rr_camera_name(types[t]), view);
      uv_ref ref = {plane_ref, &m, infinite ? 0 : L, NULL, NULL, REL_TOL};
      int n = check_view(dev, s, &ref, &cam, W, Hh, pos, what);
      CHECK(n > W * Hh / 20, "%s: only %d pixels' derivatives compared", what, n);
    }
    rr_scene_release(s);
  }
}

/* The analytic kinds' maps, from the hit point and the primitive as given (texcoord.c
 * defines them): sphere (geometry 0) equirectangular with the +y pole at the top,
 * box (1) the whole texture on each face, plane (2) offsets in world units along the
 * plane's axes. Seams, poles and box edges are left out: the maps jump there. */
static bool ana_ref(const uv_ref *ref, uint32_t mesh, vec3 p, vec3 dir, float distance, float uv[2], double *tol) {
  if (mesh > 2) return false;
  const float *a = ref->prims + ANA_FLOATS * mesh;
  vec3 c = v3(a[0], a[1], a[2]), q = v3_sub(p, c);
  if (mesh == 0) {
    vec3 m = v3_scale(q, 1.0f / a[3]);
    double rho2 = (double)m.x * m.x + (double)m.z * m.z;
    uv[0] = (float)(atan2(m.x, m.z) / (2 * RR_PI) + 0.5), uv[1] = (float)(1 - acos(fmax(-1, fmin(1, m.y))) / RR_PI);
    /* and where the ray grazes the sphere: the central differences' truncation,
     * which grows with the curvature of the hit's path, passes the tolerance */
    if (rho2 < 0.4 || uv[0] < 0.01f || uv[0] > 0.99f || fabsf(v3_dot(m, dir)) < 0.3f) return false;
    *tol = 3e-6 * (1 + distance / a[3]) / rho2;
  } else if (mesh == 1) {
    double R[3][3], f[3];
    rr_ana_box_frame(a, R);
    int ax = 0;
    for (int k = 0; k < 3; k++) {
      f[k] = (R[k][0] * q.x + R[k][1] * q.y + R[k][2] * q.z) / a[3 + k];
      if (fabs(f[k]) > fabs(f[ax])) ax = k;
    }
    int b1 = (ax + 1) % 3, b2 = (ax + 2) % 3;
    if (fabs(f[b1]) > 0.97 || fabs(f[b2]) > 0.97) return false;
    uv[0] = (float)((f[b1] + 1) / 2), uv[1] = (float)((f[b2] + 1) / 2);
    *tol = 3e-6 * (1 + distance / fmin(a[3], fmin(a[4], a[5])));
  } else {
    double ua[3], va[3];
    rr_ana_plane_axes(a + 3, ua, va);
    uv[0] = (float)(ua[0] * q.x + ua[1] * q.y + ua[2] * q.z), uv[1] = (float)(va[0] * q.x + va[1] * q.y + va[2] * q.z);
    *tol = 3e-6 * (v3_len(q) + distance + 1);
  }
  ref->seen[mesh]++;
  return true;
}

/* A sphere, an oriented box and a tilted plane, random views with every camera: their
 * uv AOV against the maps at the hit, the uv-deriv AOV against central differences. */
static void test_analytic_views(rr_device *dev) {
  int views = test_quick() ? 2 : 4;
  const rr_camera_type types[] = {RR_CAMERA_PERSPECTIVE, RR_CAMERA_ORTHOGRAPHIC, RR_CAMERA_PARABOLIC,
                                  RR_CAMERA_LATLONG,     RR_CAMERA_FISHEYE,      RR_CAMERA_CUBE};
  long seen[3] = {0, 0, 0};
  for (int view = 0; view < views; view++) {
    float prims[3][ANA_FLOATS] = {{0, 1, 0, test_randf(0.7f, 1.3f)}};
    float yaw = test_randf(0, 6.2832f), tilt = test_randf(-0.4f, 0.4f);
    float box[ANA_FLOATS] = {2.6f, 0.9f, 0.4f, test_randf(0.5f, 1), test_randf(0.4f, 0.8f), test_randf(0.5f, 1),
                             cosf(yaw) * cosf(tilt), sinf(tilt), sinf(yaw) * cosf(tilt), -sinf(tilt) * cosf(yaw),
                             cosf(tilt), -sinf(tilt) * sinf(yaw)};
    float plane[ANA_FLOATS] = {test_randf(-1, 1), 0, test_randf(-1, 1), test_randf(-0.2f, 0.2f), 1, test_randf(-0.2f, 0.2f)};
    memcpy(prims[1], box, sizeof box), memcpy(prims[2], plane, sizeof plane);
    rr_scene *s;
    if (rr_scene_new(dev, &s) != RR_OK) return;
    if (rr_scene_add_spheres(s, prims[0], 1, NULL) != RR_OK || rr_scene_add_boxes(s, prims[1], 1, NULL) != RR_OK ||
        rr_scene_add_planes(s, prims[2], 1, NULL) != RR_OK || rr_scene_commit(s) != RR_OK) {
      CHECK(0, "analytic scene: %s", rr_device_message(dev));
      rr_scene_release(s);
      return;
    }
    /* the stored parameters: the box's axes made unit and orthogonal, the plane's normal unit */
    for (int g = 0; g < 3; g++) memcpy(prims[g], s->ana + ANA_FLOATS * g, sizeof prims[g]);
    uv_ref ref = {ana_ref, NULL, 0, prims[0], seen, 1e-2};
    for (size_t t = 0; t < sizeof types / sizeof types[0]; t++) {
      float ang = test_randf(0, 6.2832f), dist = test_randf(3.5f, 7);
      vec3 target = v3(1.3f, 0.6f, 0.2f);
      vec3 eye = v3(target.x + dist * cosf(ang), test_randf(1, 4), target.z + dist * sinf(ang));
      rr_camera cam = test_camera(types[t], eye, target, types[t] == RR_CAMERA_FISHEYE ? 200 : test_randf(40, 70));
      if (types[t] == RR_CAMERA_ORTHOGRAPHIC) cam.ortho_height = test_randf(4, 7);
      int W = types[t] == RR_CAMERA_CUBE ? 96 : types[t] == RR_CAMERA_LATLONG ? 128 : 80, Hh = types[t] == RR_CAMERA_CUBE ? 72 : 64;
      float pos[2] = {test_randf(H, 1 - H), test_randf(H, 1 - H)};
      char what[96];
      snprintf(what, sizeof what, "analytic, %s view %d", rr_camera_name(types[t]), view);
      int n = check_view(dev, s, &ref, &cam, W, Hh, pos, what);
      CHECK(n > W * Hh / 20, "%s: only %d pixels' derivatives compared", what, n);
    }
    rr_scene_release(s);
  }
  for (int g = 0; g < 3; g++) CHECK(seen[g] > 300, "analytic views: only %ld pixels checked on geometry %d", seen[g], g);
}

static void test_options(rr_device *dev) {
  for (int f = 0; f < RR_TEXTURE_FILTER_COUNT; f++)
    CHECK(rr_texture_filter_from_name(rr_texture_filter_name(f)) == f, "filter %d's name", f);
  CHECK(rr_texture_filter_from_name("aniso:4") < 0 && rr_texture_filter_from_name(NULL) < 0 &&
            rr_texture_filter_name(RR_TEXTURE_FILTER_COUNT) == NULL && !strcmp(rr_texture_filter_name(RR_TEXTURE_EWA), "ewa"),
        "texture filter names");
  uv_map m = {1, 0, 0, 0, 1, 0};
  rr_scene *s = plane_scene(dev, &m, false, 4);
  if (!s) return;
  rr_camera cam = test_camera(RR_CAMERA_PERSPECTIVE, v3(0, 2, 2), v3(0, 0, 0), 45);
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, 16, 12, 0);
  rr_shade_options o;
  rr_shade_options_init(&o);
  CHECK(o.texture_filter == RR_TEXTURE_ANISO && o.aniso == 16 && o.lod_bias == 0, "defaults: aniso:16, no bias");
  const struct {
    int filter, aniso;
    float bias;
    const char *needle;
  } bad[] = {{-1, 16, 0, "texture filter"}, {RR_TEXTURE_FILTER_COUNT, 16, 0, "texture filter"},
             {RR_TEXTURE_ANISO, 0, 0, "anisotropy"},  {RR_TEXTURE_ANISO, 17, 0, "anisotropy"},
             {RR_TEXTURE_TRILINEAR, 16, NAN, "bias"}, {RR_TEXTURE_TRILINEAR, 16, INFINITY, "bias"}};
  for (size_t k = 0; f && k < sizeof bad / sizeof bad[0]; k++) {
    o.texture_filter = (rr_texture_filter)bad[k].filter, o.aniso = bad[k].aniso, o.lod_bias = bad[k].bias;
    rr_image img = {0};
    CHECK(rr_shade_frame(dev, s, &cam, f, &o, &img, NULL) == RR_ERROR_ARGUMENT && !img.data &&
              strstr(rr_device_message(dev), bad[k].needle),
          "bad texture options %zu refused: %s", k, rr_device_message(dev));
  }
  rr_frame_release(f);
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  test_options(dev);
  test_ray_differentials(dev);
  test_plane_views(dev, false);
  test_plane_views(dev, true);
  test_analytic_views(dev);
  rr_device_release(dev);
  return test_done();
}
