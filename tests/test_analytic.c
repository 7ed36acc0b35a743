/* Analytic spheres, planes and boxes (prim/analytic.h) beside triangles:
 * - every 3D method gives rc's bits on scenes mixing the four kinds, at random views
 *   and views from inside, for every camera, on 1 and 2 threads, with and without
 *   back-face culling, and at several sample positions per pixel;
 * - the 2D pipeline draws them as impostors with the same bits;
 * - rr_intersect / rr_occluded give brute force's bits (test_brute_ray) on camera rays;
 * - depth against a closed-form reference in long double (perspective,
 *   orthographic, lat-long): p99.9 relative error <= 1e-6;
 * - a sphere resting on a plane: every sample looking at the plane is claimed,
 *   by the nearer of the two (depth_wins), in every method;
 * - bad input (radius <= 0, NaN, zero normal, degenerate box) refused, naming the
 *   primitive, in the API and in scene files. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Random triangles, spheres (some overlapping, some crossing the plane) and a ground
 * plane y = 0 plus an oblique one far off. */
static rr_scene *mixed_scene(rr_device *dev, int ntri, int nsph) {
  rr_scene *s = NULL;
  if (rr_scene_new(dev, &s) != RR_OK) return NULL;
  float *pos = malloc(sizeof(float) * 9 * (size_t)ntri);
  uint32_t *idx = malloc(sizeof(uint32_t) * 3 * (size_t)ntri);
  for (int t = 0; t < ntri; t++) {
    float cx = test_randf(-4, 4), cy = test_randf(0, 3), cz = test_randf(-4, 4), sz = test_randf(0.5f, 2);
    for (int k = 0; k < 3; k++) {
      pos[9 * t + 3 * k] = cx + sz * test_randf(-1, 1), pos[9 * t + 3 * k + 1] = cy + sz * test_randf(-1, 1);
      pos[9 * t + 3 * k + 2] = cz + sz * test_randf(-1, 1);
      idx[3 * t + k] = (uint32_t)(3 * t + k);
    }
  }
  CHECK(rr_scene_add_mesh(s, pos, (size_t)3 * ntri, idx, (size_t)ntri, NULL) == RR_OK, "add mesh");
  float *sp = malloc(sizeof(float) * 4 * (size_t)nsph);
  for (int k = 0; k < nsph; k++)
    sp[4 * k] = test_randf(-4, 4), sp[4 * k + 1] = test_randf(-0.5f, 3), sp[4 * k + 2] = test_randf(-4, 4),
            sp[4 * k + 3] = test_randf(0.1f, 1.2f);
  const float red[3] = {0.8f, 0.2f, 0.2f};
  CHECK(rr_scene_add_spheres(s, sp, (size_t)nsph, red) == RR_OK, "add spheres: %s", rr_device_message(dev));
  /* boxes: half of them axis-aligned, the others turned at random */
  float bx[12 * 8];
  for (int k = 0; k < 8; k++) {
    float *b = bx + 12 * k;
    b[0] = test_randf(-4, 4), b[1] = test_randf(0, 2.5f), b[2] = test_randf(-4, 4);
    b[3] = test_randf(0.3f, 1.5f), b[4] = test_randf(0.3f, 1.5f), b[5] = test_randf(0.3f, 1.5f);
    for (int c = 0; c < 6; c++) b[6 + c] = k % 2 ? test_randf(-1, 1) : (c == 0 || c == 4);
  }
  CHECK(rr_scene_add_boxes(s, bx, 8, NULL) == RR_OK, "add boxes: %s", rr_device_message(dev));
  const float planes[12] = {0, 0, 0, 0, 1, 0, 0, 0, -9, 0.3f, 0.2f, 1};
  CHECK(rr_scene_add_planes(s, planes, 2, NULL) == RR_OK, "add planes: %s", rr_device_message(dev));
  /* more triangles after the analytic geometries: ids interleave kinds */
  for (int k = 0; k < 9 * ntri; k++) pos[k] *= 0.5f;
  CHECK(rr_scene_add_mesh(s, pos, (size_t)3 * ntri, idx, (size_t)ntri, NULL) == RR_OK, "add mesh 2");
  free(pos), free(idx), free(sp);
  CHECK(rr_scene_commit(s) == RR_OK, "commit");
  return s;
}

static const rr_method methods3d[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                      RR_METHOD_3DR_FC, RR_METHOD_3DR_FS, RR_METHOD_3DR_FULL};

/* Counts the samples of f that hit each kind. */
static void kind_hits(const rr_scene *s, const rr_frame *f, int n[4]) {
  n[0] = n[1] = n[2] = n[3] = 0;
  size_t m = (size_t)f->vb.width * f->vb.height * (size_t)f->samples;
  for (size_t k = 0; k < m; k++)
    if (f->vb.id[k] != RR_MISS) n[scene_kind(s, f->vb.id[k])]++;
}

static int agree_total, agree_frames;

static void check_methods(rr_device *dev, const rr_scene *s, int views) {
  int hits[4] = {0, 0, 0, 0};
  for (int v = 0; v < views; v++) {
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      rr_camera cam = test_random_camera(s, (rr_camera_type)type, v % 2);
      int w = type == RR_CAMERA_CUBE ? 64 : 56, h = 48;
      int cull = type % 2; /* back faces culled (triangles only: analytic primitives show what the ray meets) */
      rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC, 2, w, h, cull);
      if (!ref) continue;
      int kh[4];
      kind_hits(s, ref, kh);
      for (int k = 0; k < 4; k++) hits[k] += kh[k];
      char what[256];
      snprintf(what, sizeof what, "view %d (%s), %s camera", v, v % 2 ? "inside" : "outside", rr_camera_name(type));
      for (size_t m = 0; m < sizeof methods3d / sizeof methods3d[0]; m++) {
        int threads = 1 + (int)((v + type + m) % 2);
        rr_frame *f = test_render(dev, s, &cam, methods3d[m], threads, w, h, cull);
        if (!f) continue;
        int d = test_frames_differ(ref, f);
        CHECK(d == 0, "%s: %s on %d threads differs from rc at %d samples", what, rr_method_name(methods3d[m]),
              threads, d);
        agree_frames++, agree_total += d == 0;
        rr_frame_release(f);
      }
      rr_frame_release(ref);
    }
  }
  printf("rc hits over the views: %d triangle, %d sphere, %d plane, %d box samples\n", hits[0], hits[1], hits[2],
         hits[3]);
  CHECK(hits[0] > 0 && hits[1] > 0 && hits[2] > 0 && hits[3] > 0, "every kind is seen");
}

/* Several sample positions at once (the 3D methods take them in one pass): each
 * layer is rc's frame at that position. */
static void check_patterns(rr_device *dev, const rr_scene *s) {
  const float pos[4][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};
  for (int v = 0; v < 2; v++) {
    rr_camera cam = test_random_view(s, v ? 0.2f : 1.5f, v ? 0.4f : 2.0f, 0.3f, 60, 60);
    cam.type = v ? RR_CAMERA_LATLONG : RR_CAMERA_PERSPECTIVE;
    for (size_t m = 2; m < sizeof methods3d / sizeof methods3d[0]; m++) {
      rr_render_options o = test_pattern(methods3d[m], 40, 32, 1 + (int)(m % 2), 4, pos);
      rr_frame *f = test_render_opt(dev, s, &cam, &o);
      if (!f) continue;
      char what[128];
      snprintf(what, sizeof what, "4 positions, view %d, %s", v, rr_method_name(methods3d[m]));
      test_check_layers(dev, s, &cam, &o, RR_METHOD_RC, f, what);
      rr_frame_release(f);
    }
  }
}

/* The 2D pipeline draws analytic primitives as impostors (a screen rectangle, the
 * one exact test, the z-buffer): on a scene of spheres and planes alone it gives
 * rc's bits; on the mixed scene 2dr-bin equals 2dr-bb, and every sample that both
 * 2dr and rc give to an analytic primitive holds the same bits (triangles' depths
 * in 2dr are interpolated, so they agree with the 3D methods within snapping). */
static void check_2d(rr_device *dev, const rr_scene *mixed, const rr_scene *ana) {
  const float pos[4][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};
  int same = 0, both = 0;
  for (int v = 0; v < 6; v++) {
    const rr_scene *s = v < 3 ? ana : mixed;
    rr_camera cam = test_random_view(s, v % 2 ? 0.1f : 1.2f, v % 2 ? 0.5f : 2.5f, 0.3f, 40, 90);
    cam.type = v % 3 == 2 ? RR_CAMERA_ORTHOGRAPHIC : RR_CAMERA_PERSPECTIVE, cam.ortho_height = 8;
    int ns = v == 4 ? 4 : 1;
    rr_render_options o = test_pattern(RR_METHOD_3DR_BIN, 56, 40, 1, ns, pos);
    rr_frame *ref = test_render_opt(dev, s, &cam, &o);
    o.method = RR_METHOD_2DR_BB, o.threads = 2;
    rr_frame *a = test_render_opt(dev, s, &cam, &o);
    o.method = RR_METHOD_2DR_BIN, o.threads = 1 + v % 2;
    rr_frame *b = test_render_opt(dev, s, &cam, &o);
    if (ref && a && b) {
      CHECK(test_frames_differ(a, b) == 0, "view %d: 2dr-bin differs from 2dr-bb", v);
      if (s == ana) CHECK(test_frames_differ(ref, a) == 0, "view %d: 2dr-bb differs from 3dr-bin on spheres and planes", v);
      size_t m = (size_t)56 * 40 * ns;
      for (size_t k = 0; k < m; k++) {
        uint32_t i = a->vb.id[k];
        if (i == RR_MISS || i != ref->vb.id[k] || scene_kind(s, i) == RR_GEOMETRY_TRIANGLE) continue;
        both++;
        same += memcmp(&a->vb.t[k], &ref->vb.t[k], 4) == 0 && memcmp(&a->vb.l1[k], &ref->vb.l1[k], 4) == 0 &&
                memcmp(&a->vb.l2[k], &ref->vb.l2[k], 4) == 0;
      }
    }
    rr_frame_release(ref), rr_frame_release(a), rr_frame_release(b);
  }
  printf("2dr: %d of %d analytic samples bit-identical to 3dr-bin\n", same, both);
  CHECK(both > 1000 && same == both, "2dr analytic samples: %d of %d identical", same, both);
}

/* rr_intersect against brute force over every primitive, on camera rays. */
static void check_rays(rr_device *dev, const rr_scene *s) {
  int hits, n = test_check_rays(dev, s, NULL, NULL, &hits);
  printf("rays: %d of %d hit\n", hits, n);
}

/* ---- depth against a closed-form reference ------------------------------- */

typedef long double ld;

/* The exact hit of the ray o + t·d (long double) with primitive i, by the
 * textbook formulas on a unit direction: t along d. */
static ld ref_hit(const rr_scene *s, uint32_t i, const ld o[3], const ld d[3]) {
  const float *a = s->ana + (size_t)ANA_FLOATS * i;
  ld len = sqrtl(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), u[3] = {d[0] / len, d[1] / len, d[2] / len};
  if (scene_kind(s, i) == RR_GEOMETRY_BOX) {
    /* the six planes of the box's frame (rows x, y and z = x × y of the stored axes):
     * the entry is the largest of the near planes' t, the exit the least far one */
    ld R[3][3] = {{a[6], a[7], a[8]}, {a[9], a[10], a[11]}, {0, 0, 0}};
    R[2][0] = R[0][1] * R[1][2] - R[0][2] * R[1][1], R[2][1] = R[0][2] * R[1][0] - R[0][0] * R[1][2];
    R[2][2] = R[0][0] * R[1][1] - R[0][1] * R[1][0];
    ld tn = -INFINITY, tf = INFINITY;
    for (int ax = 0; ax < 3; ax++) {
      ld oo = 0, dd = 0;
      for (int k = 0; k < 3; k++) oo += R[ax][k] * (o[k] - (ld)a[k]), dd += R[ax][k] * d[k];
      ld t0 = (-(ld)a[3 + ax] - oo) / dd, t1 = ((ld)a[3 + ax] - oo) / dd;
      tn = fmaxl(tn, fminl(t0, t1)), tf = fminl(tf, fmaxl(t0, t1));
    }
    return tn > 0 ? tn : tf;
  }
  if (scene_kind(s, i) == RR_GEOMETRY_PLANE) {
    ld num = 0, den = 0;
    for (int k = 0; k < 3; k++) num += (ld)a[3 + k] * ((ld)a[k] - o[k]), den += (ld)a[3 + k] * d[k];
    return num / den;
  }
  ld q[3] = {(ld)a[0] - o[0], (ld)a[1] - o[1], (ld)a[2] - o[2]};
  ld b = q[0] * u[0] + q[1] * u[1] + q[2] * u[2], perp2 = 0;
  for (int k = 0; k < 3; k++) {
    ld f = q[k] - b * u[k];
    perp2 += f * f;
  }
  ld h = sqrtl(fmaxl((ld)a[3] * a[3] - perp2, 0));
  ld t = b - h > 0 ? b - h : b + h; /* near root, or the far one from inside */
  return t / len;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

static void check_depth(rr_device *dev, const rr_scene *s) {
  const rr_camera_type types[3] = {RR_CAMERA_PERSPECTIVE, RR_CAMERA_ORTHOGRAPHIC, RR_CAMERA_LATLONG};
  const int W = 160, H = 120;
  for (int ty = 0; ty < 3; ty++) {
    size_t cap = (size_t)W * H * 8, n = 0;
    double *err = malloc(cap * sizeof *err);
    for (int v = 0; v < 8; v++) {
      rr_camera cam = test_random_view(s, v % 2 ? 0.2f : 1.2f, v % 2 ? 0.6f : 2.5f, 0.3f, 30, 90);
      cam.type = types[ty], cam.ortho_height = test_randf(2, 12);
      rr_frame *f = test_render(dev, s, &cam, v % 2 ? RR_METHOD_3DR_FULL : RR_METHOD_RC_BVH, 1, W, H, 0);
      camera c;
      if (!f || rr_cam_setup(dev, &cam, W, H, &c) != RR_OK) {
        rr_frame_release(f);
        continue;
      }
      for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
          size_t k = (size_t)y * W + x;
          uint32_t id = f->vb.id[k];
          if (id == RR_MISS || scene_kind(s, id) == RR_GEOMETRY_TRIANGLE) continue;
          /* the sample's ray from the camera's own basis (as rr_depth_errors takes it) */
          ld o[3], d[3], sx = (ld)x + c.sx0, sy = (ld)y + c.sy0;
          const float e[3] = {c.eye.x, c.eye.y, c.eye.z};
          const float d0[3] = {c.d0.x, c.d0.y, c.d0.z}, dx[3] = {c.dx.x, c.dx.y, c.dx.z}, dy[3] = {c.dy.x, c.dy.y, c.dy.z};
          const float o0[3] = {c.o0.x, c.o0.y, c.o0.z}, ox[3] = {c.ox.x, c.ox.y, c.ox.z}, oy[3] = {c.oy.x, c.oy.y, c.oy.z};
          const float fw[3] = {c.fwd.x, c.fwd.y, c.fwd.z};
          for (int a = 0; a < 3; a++) {
            if (types[ty] == RR_CAMERA_PERSPECTIVE) o[a] = e[a], d[a] = (ld)d0[a] + sx * dx[a] + sy * dy[a];
            else if (types[ty] == RR_CAMERA_ORTHOGRAPHIC) o[a] = (ld)e[a] + o0[a] + sx * ox[a] + sy * oy[a], d[a] = fw[a];
          }
          if (types[ty] == RR_CAMERA_LATLONG) {
            const vec3 w = c.dirs[k];
            o[0] = e[0], o[1] = e[1], o[2] = e[2], d[0] = w.x, d[1] = w.y, d[2] = w.z;
          }
          ld t = ref_hit(s, id, o, d);
          if (n < cap) err[n++] = (double)fabsl(((ld)f->vb.t[k] - t) / t);
        }
      rr_cam_release(&c);
      rr_frame_release(f);
    }
    qsort(err, n, sizeof *err, cmp_double);
    double p50 = n ? err[n / 2] : 0, p999 = n ? err[(size_t)((double)(n - 1) * 0.999)] : 0, mx = n ? err[n - 1] : 0;
    printf("depth, %s: %zu analytic samples, relative error p50 %.3g p99.9 %.3g max %.3g\n", rr_camera_name(types[ty]),
           n, p50, p999, mx);
    CHECK(n > 1000, "%s: %zu samples hit analytic primitives", rr_camera_name(types[ty]), n);
    CHECK(p999 <= 1e-6, "%s: p99.9 relative depth error %.3g over 1e-6", rr_camera_name(types[ty]), p999);
    free(err);
  }
}

/* ---- a sphere resting on a plane ------------------------------------------ */

static void check_tangent(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  const float plane[6] = {0, 0, 0, 0, 1, 0}, sphere[4] = {0, 1, 0, 1};
  CHECK(rr_scene_add_spheres(s, sphere, 1, NULL) == RR_OK, "sphere");
  CHECK(rr_scene_add_planes(s, plane, 1, NULL) == RR_OK, "plane");
  CHECK(rr_scene_commit(s) == RR_OK, "commit");
  int claimed = 0, near_contact = 0, samples = 0;
  for (int v = 0; v < 4; v++) {
    /* grazing views at the contact point from all sides, slightly above the plane */
    float ang = (float)v * 1.5708f + 0.3f;
    vec3 eye = v3(3 * cosf(ang), 0.2f + 0.1f * (float)v, 3 * sinf(ang));
    rr_camera cam = test_camera(RR_CAMERA_PERSPECTIVE, eye, v3(0, 0, 0), 1.5f);
    rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC, 1, 64, 64, 0);
    camera c;
    if (!ref || rr_cam_setup(dev, &cam, 64, 64, &c) != RR_OK) {
      rr_frame_release(ref);
      continue;
    }
    for (int y = 0; y < 64; y++)
      for (int x = 0; x < 64; x++) {
        size_t k = (size_t)y * 64 + x;
        ana_ray r;
        float sx = (float)x + c.sx0, sy = (float)y + c.sy0, t[2], u, w;
        ana_sample_ray(&c, camera_w(&c, x, y), sx, sy, &r);
        bool h0 = rr_ana_hit(s, 0, &r, &t[0], &u, &w), h1 = rr_ana_hit(s, 1, &r, &t[1], &u, &w);
        samples++;
        /* a ray going down meets the plane: it must be claimed */
        if (r.d[1] < 0) CHECK(ref->vb.id[k] != RR_MISS, "view %d: a gap at (%d, %d)", v, x, y);
        uint32_t want = !h0 && !h1 ? RR_MISS : !h1 ? 0 : !h0 ? 1 : depth_wins(t[0], 0, t[1], 1) ? 0 : 1;
        CHECK(ref->vb.id[k] == want, "view %d (%d, %d): claimed by %u, the nearer is %u", v, x, y, ref->vb.id[k], want);
        claimed += ref->vb.id[k] != RR_MISS;
        if (want != RR_MISS) { /* the claimed hit within 0.05 of the contact point (the origin) */
          double th = t[want], p2 = 0;
          for (int a = 0; a < 3; a++) p2 += (r.o[a] + th * r.d[a]) * (r.o[a] + th * r.d[a]);
          near_contact += p2 < 0.05 * 0.05;
        }
      }
    for (size_t m = 0; m < sizeof methods3d / sizeof methods3d[0]; m++) {
      rr_frame *f = test_render(dev, s, &cam, methods3d[m], 2, 64, 64, 0);
      if (f) CHECK(test_frames_differ(ref, f) == 0, "tangent view %d: %s differs", v, rr_method_name(methods3d[m]));
      rr_frame_release(f);
    }
    rr_cam_release(&c);
    rr_frame_release(ref);
  }
  printf("tangent: %d of %d samples claimed, %d hit within 0.05 of the contact\n", claimed, samples, near_contact);
  CHECK(near_contact > 0, "the views reach the contact");
  rr_scene_release(s);
}

/* ---- bad input ------------------------------------------------------------ */

static void expect_refused(rr_device *dev, rr_scene *s, rr_error e, const char *needle) {
  const char *msg = rr_device_message(dev);
  CHECK(e == RR_ERROR_ARGUMENT, "refused (%d)", (int)e);
  CHECK(msg && strstr(msg, needle), "message \"%s\" names \"%s\"", msg ? msg : "", needle);
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  CHECK(info.spheres == 1 && info.planes == 1 && info.geometries == 2, "nothing added (%llu spheres, %u geometries)",
        (unsigned long long)info.spheres, info.geometries);
}

static void check_bad_input(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  const float good[4] = {0, 0, 0, 1}, plane[6] = {0, 0, 0, 0, 1, 0};
  CHECK(rr_scene_add_spheres(s, good, 1, NULL) == RR_OK && rr_scene_add_planes(s, plane, 1, NULL) == RR_OK, "good");
  float sp[12] = {0, 0, 0, 1, 1, 1, 1, 1, 2, 2, 2, -1};
  expect_refused(dev, s, rr_scene_add_spheres(s, sp, 3, NULL), "sphere 2 has radius -1");
  sp[11] = 0;
  expect_refused(dev, s, rr_scene_add_spheres(s, sp, 3, NULL), "sphere 2 has radius 0");
  sp[11] = 1, sp[5] = NAN;
  expect_refused(dev, s, rr_scene_add_spheres(s, sp, 3, NULL), "sphere 1 has a value that is not finite");
  float bx[24] = {0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 1, 1, 0, 2, 2, 0};
  expect_refused(dev, s, rr_scene_add_boxes(s, bx, 2, NULL), "box 1 has a half size that is not positive");
  bx[16] = 1;
  expect_refused(dev, s, rr_scene_add_boxes(s, bx, 2, NULL), "box 1 has axes that are zero or parallel");
  float pl[12] = {0, 0, 0, 0, 1, 0, 1, 1, 1, 0, 0, 0};
  expect_refused(dev, s, rr_scene_add_planes(s, pl, 2, NULL), "plane 1 has a zero normal");
  pl[9] = INFINITY;
  expect_refused(dev, s, rr_scene_add_planes(s, pl, 2, NULL), "plane 1 has a value that is not finite");
  expect_refused(dev, s, rr_scene_add_planes(s, NULL, 2, NULL), "NULL");
  rr_scene_release(s);
}

/* ---- scene files ------------------------------------------------------------ */

static char dir[] = "/tmp/rr_analytic_XXXXXX";

/* Loads the scene file `text`; NULL on failure, the message in msg. */
static rr_scene *load_json(rr_device *dev, const char *text, char *msg, size_t cap) {
  rr_scene *s = NULL;
  rr_error e = rr_scene_load(dev, test_write_file(dir, "a.json", text), &s);
  snprintf(msg, cap, "%s", e ? rr_device_message(dev) : "");
  return e ? NULL : s;
}

static void check_scene_file(rr_device *dev) {
  if (!mkdtemp(dir)) {
    CHECK(0, "mkdtemp");
    return;
  }
  char msg[512];
  rr_scene *s = load_json(dev,
                          "{\"spheres\": [{\"center\": [0, 1, 0], \"radius\": 1, \"name\": \"ball\", "
                          "\"material\": {\"color\": [1, 0, 0]}}, {\"center\": [3, 0.5, 0], \"radius\": 0.5}],"
                          " \"planes\": [{\"point\": [0, 0, 0], \"normal\": [0, 2, 0]}],"
                          " \"boxes\": [{\"center\": [-3, 0.5, 0], \"size\": [1, 2, 4], \"rotate\": [0, 90, 0]}],"
                          " \"meshes\": [{\"builtin\": \"sphere\", \"scale\": 2, \"translate\": [0, 0, -5]},"
                          " {\"builtin\": \"ground\", \"rotate\": [0, 0, 90], \"translate\": [9, 0, 0]}]}",
                          msg, sizeof msg);
  CHECK(s != NULL, "scene file: %s", msg);
  if (s) {
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    rr_geometry_info g0, g4;
    rr_scene_get_geometry_info(s, 0, &g0), rr_scene_get_geometry_info(s, 4, &g4);
    CHECK(in.spheres == 4 && in.planes == 2 && in.boxes == 1 && in.geometries == 8,
          "%llu spheres, %llu planes, %u geometries", (unsigned long long)in.spheres, (unsigned long long)in.planes,
          in.geometries);
    /* the box: half sizes 0.5, 1, 2, its x axis turned by 90° about y to -z */
    const float *bx = s->ana + (size_t)ANA_FLOATS * (s->ntris - 1);
    CHECK(scene_kind(s, s->ntris - 1) == RR_GEOMETRY_BOX && bx[3] == 0.5f && bx[4] == 1 && bx[5] == 2 &&
              fabsf(bx[8] + 1) < 1e-6f && fabsf(bx[6]) < 1e-6f && bx[10] == 1,
          "the box: half sizes %g %g %g, x axis (%g %g %g)", bx[3], bx[4], bx[5], bx[6], bx[7], bx[8]);
    /* meshes first (the built-in sphere scaled by 2 at z = -5, ground turned about z), then spheres, planes */
    CHECK(g0.kind == RR_GEOMETRY_SPHERE && g4.kind == RR_GEOMETRY_SPHERE && g4.name && strcmp(g4.name, "ball") == 0,
          "order and names");
    const float *a = s->ana;
    CHECK(a[0] == 0 && a[1] == 0 && a[2] == -5 && a[3] == 2, "the built-in sphere moved: (%g %g %g) r %g", a[0], a[1],
          a[2], a[3]);
    const float *pl = s->ana + (size_t)ANA_FLOATS * 1; /* ground's plane, turned: normal -x, through (9, 0, 0) */
    CHECK(scene_kind(s, 1) == RR_GEOMETRY_PLANE && fabsf(pl[3] + 1) < 1e-6f && fabsf(pl[4]) < 1e-6f && pl[0] == 9,
          "the built-in plane turned: (%g %g %g) n (%g %g %g)", pl[0], pl[1], pl[2], pl[3], pl[4], pl[5]);
    rr_camera cam = test_camera(RR_CAMERA_PERSPECTIVE, v3(0, 3, 8), v3(0, 1, 0), 50);
    rr_frame *f = test_render(dev, s, &cam, RR_METHOD_RC_BVH, 1, 16, 16, 0);
    /* the centre sample sees the red ball (geometry 4's one primitive) */
    CHECK(f && f->vb.id[8 * 16 + 8] == g4.first, "the centre sees the ball: %u, not %u", f ? f->vb.id[8 * 16 + 8] : 0,
          g4.first);
    rr_frame_release(f);
    rr_scene_release(s);
  }
  /* copies of a mesh written straight into the arrays after analytic primitives, growing them, are triangles */
  char text[512];
  snprintf(text, sizeof text, "{\"meshes\": [{\"builtin\": \"ground\"}, {\"builtin\": \"grid:%s:40\"}]}",
           test_write_file(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  s = load_json(dev, text, msg, sizeof msg);
  CHECK(s != NULL, "ground and grid: %s", msg);
  if (s) {
    uint32_t tris = 0;
    for (uint32_t i = 0; i < s->ntris; i++) tris += scene_kind(s, i) == RR_GEOMETRY_TRIANGLE;
    CHECK(tris == 12 + 1600, "%u triangles (the box's 12 and 1600 copies, past the first room)", tris);
    rr_camera cam = test_camera(RR_CAMERA_PERSPECTIVE, v3(2, 4, 9), v3(0, 0.5, 0), 50);
    rr_frame *a = test_render(dev, s, &cam, RR_METHOD_RC, 1, 40, 30, 0);
    rr_frame *b = test_render(dev, s, &cam, RR_METHOD_3DR_FULL, 2, 40, 30, 0);
    if (a && b) CHECK(test_frames_differ(a, b) == 0, "ground and grid: 3dr-full differs from rc");
    rr_frame_release(a), rr_frame_release(b);
    rr_scene_release(s);
  }
  const struct {
    const char *text, *needle;
  } bad[] = {
      {"{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": -1}]}", "'spheres[0].radius': must be positive"},
      {"{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}, {\"center\": [0, 0, 0], \"radius\": 0}]}",
       "'spheres[1].radius': must be positive"},
      {"{\"spheres\": [{\"center\": [0, 0], \"radius\": 1}]}", "'spheres[0].center'"},
      {"{\"spheres\": [{\"radius\": 1}]}", "'spheres[0]': missing 'center'"},
      {"{\"planes\": [{\"point\": [0, 0, 0], \"normal\": [0, 0, 0]}]}", "'planes[0].normal': a zero normal"},
      {"{\"planes\": [{\"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"size\": 3}]}", "'planes[0]'"},
      {"{\"meshes\": [{\"builtin\": \"sphere\", \"scale\": [1, 2, 1]}]}", "'meshes[0]': a sphere takes only a uniform scale"},
      {"{\"spheres\": [{\"center\": [0, 0, 1e31], \"radius\": 1}]}", "'spheres[0].center'"},
      {"{\"boxes\": [{\"center\": [0, 0, 0], \"size\": [1, 0, 1]}]}", "'boxes[0].size': every size must be positive"},
      {"{\"boxes\": [{\"center\": [0, 0, 0], \"size\": [1, -1, 1]}]}", "'boxes[0].size'"},
      {"{\"boxes\": [{\"center\": [0, 0, 0], \"size\": [1, 1, 1], \"scale\": 2}]}", "'boxes[0]'"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    rr_scene *b = load_json(dev, bad[k].text, msg, sizeof msg);
    CHECK(!b && strstr(msg, bad[k].needle) && !strchr(msg, '\n'), "bad file %zu: \"%s\" should name \"%s\"", k, msg,
          bad[k].needle);
    rr_scene_release(b);
  }
  unlink(test_write_file(dir, "a.json", ""));
  unlink(test_write_file(dir, "tri.obj", ""));
  rmdir(dir);
}

/* msaa shades a primitive once per pixel, so a box's faces must not share that shade:
 * a face's point and normal come from its own samples (l1 keeps the face). Under the
 * headlight, flat faces are all but constant, so msaa:16 must match ssaa:16 closely
 * on every pixel, the edges between faces included. */
static float *shade_box(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, rr_aa_mode m) {
  rr_render_options o;
  rr_render_options_init(&o);
  o.width = w, o.height = w, o.threads = 2, o.method = RR_METHOD_3DR_BB;
  CHECK(rr_render_options_set_aa(dev, &o, m, 16, 0, RR_AA_STANDARD, 0) == RR_OK, "%s", rr_device_message(dev));
  rr_frame *f = test_render_opt(dev, s, cam, &o);
  if (!f) return NULL;
  rr_image img = {0};
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LAMBERT;
  rr_shade_stats st;
  CHECK(rr_shade_frame(dev, s, cam, f, &so, &img, &st) == RR_OK, "shade: %s", rr_device_message(dev));
  rr_frame_release(f);
  return img.data;
}

static void check_msaa_faces(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "scene");
  float bx[12] = {0, 0, 0, 1, 0.7f, 0.5f, 0.8f, 0.6f, 0, -0.6f, 0.8f, 0}; /* turned about z */
  CHECK(rr_scene_add_boxes(s, bx, 1, NULL) == RR_OK && rr_scene_commit(s) == RR_OK, "box: %s", rr_device_message(dev));
  enum { W = 96 };
  int edges = 0;
  for (int v = 0; v < 4; v++) {
    rr_camera cam;
    rr_camera_init(&cam);
    float eye[3] = {test_randf(1.5f, 3), test_randf(1.5f, 3), test_randf(1.5f, 3)};
    for (int k = 0; k < 3; k++) eye[k] *= v & 1 ? -1 : 1, cam.eye[k] = eye[k], cam.target[k] = 0;
    float *ms = shade_box(dev, s, &cam, W, RR_AA_MSAA), *ss = shade_box(dev, s, &cam, W, RR_AA_SSAA);
    if (ms && ss) {
      float worst = 0;
      for (size_t i = 0; i < (size_t)W * W * 3; i++) worst = fmaxf(worst, fabsf(ms[i] - ss[i]));
      CHECK(worst < 0.03f, "view %d: msaa:16 and ssaa:16 of a box differ by %g", v, worst);
      edges++;
    }
    free(ms), free(ss);
  }
  CHECK(edges == 4, "box views shaded");
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s = mixed_scene(dev, test_quick() ? 40 : 120, test_quick() ? 12 : 30);
  if (s) {
    rr_scene_info info;
    rr_scene_get_info(s, &info);
    CHECK(info.spheres == (test_quick() ? 12u : 30u) && info.planes == 2 && info.boxes == 8 && info.geometries == 5,
          "info counts kinds");
    check_methods(dev, s, test_quick() ? 2 : 4);
    printf("agreement: %d of %d frames bit-identical to rc\n", agree_total, agree_frames);
    check_patterns(dev, s);
    check_rays(dev, s);
    check_depth(dev, s);
    rr_scene *ana = mixed_scene(dev, 0, test_quick() ? 12 : 30);
    if (ana) check_2d(dev, s, ana);
    rr_scene_release(ana);
    rr_scene_release(s);
  }
  check_tangent(dev);
  check_msaa_faces(dev);
  check_bad_input(dev);
  check_scene_file(dev);
  rr_device_release(dev);
  return test_done();
}
