/* The 2D pipeline (2dr-bb, 2dr-bin): its projection maps the camera's pixel
 * centres; its fill rule claims every sample of a closed or tessellated surface
 * exactly once, through clipping and for both traversals; 2dr-bin equals 2dr-bb bit
 * for bit on 1, 2 and 8 threads; and it agrees with 3D rasterization (3dr-bb) where
 * snapping allows: near and across the eye plane, behind it, on huge triangles,
 * inside closed meshes, and on real meshes. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

static rr_device *dev;

static rr_camera pub_camera(vec3 eye, vec3 target, vec3 up, float fov) {
  rr_camera rc;
  rr_camera_init(&rc);
  memcpy(rc.eye, &eye, 12), memcpy(rc.target, &target, 12), memcpy(rc.up, &up, 12);
  rc.fov_deg = fov;
  return rc;
}

static camera make_cam(vec3 eye, vec3 target, vec3 up, float fov, int w, int h) {
  rr_camera rc = pub_camera(eye, target, up, fov);
  camera c;
  rr_error e = rr_cam_setup(dev, &rc, w, h, &c);
  CHECK(e == RR_OK, "camera: %s", rr_device_message(dev));
  return c;
}

/* A pattern of 16 positions: a 4x4 grid rotated by atan(1/4), in [0, 1). */
enum { NPAT = 16 };
static void pattern_pos(int k, float *sx, float *sy) {
  int i = k % 4, j = k / 4;
  *sx = (float)(4 * i + j) / 16 + 1.0f / 32, *sy = (float)(4 * j + 3 - i) / 16 + 1.0f / 32;
}

/* c at each position of the pattern (a planar camera's rays differ only there). */
static void pattern_cams(const camera *c, camera out[NPAT]) {
  for (int k = 0; k < NPAT; k++) out[k] = *c, pattern_pos(k, &out[k].sx0, &out[k].sy0);
}

static rr_scene *load(const char *name) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    return NULL;
  }
  return s;
}

/* ---- projection ------------------------------------------------------------------ */

/* A point anywhere on the ray of sample (sx, sy) must project back to (sx, sy), up
 * to the rounding of the test point itself: a few float ulps across the ray, which
 * the image plane magnifies to |d|²/(d·fwd)/|dx| · 2^-23 pixels. The eye sits at the origin so that adding it
 * rounds nothing. */
static void check_projection(const rr_scene *s) {
  double worst = 0, worst_px = 0;
  for (int v = 0; v < 50; v++) {
    vec3 eye = v3(0, 0, 0), target = v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1));
    int w = 64 + (int)(test_rand() % 1000), h = 64 + (int)(test_rand() % 1000);
    camera c = make_cam(eye, target, v3(test_randf(-1, 1), 1, test_randf(-1, 1)), test_randf(10, 150), w, h);
    for (int k = 0; k < 20; k++) {
      int x = (int)(test_rand() % (unsigned)w), y = (int)(test_rand() % (unsigned)h);
      vec3 d = camera_dir(&c, x + 0.5f, y + 0.5f);
      vec3 p = v3_add(c.eye, v3_scale(d, test_randf(0.1f, 20)));
      double sx, sy;
      bool ok = rr_raster2d_project(s, &c, p, &sx, &sy);
      CHECK(ok, "a point in front of the eye is behind the near plane");
      if (!ok) continue;
      double err = fmax(fabs(sx - (x + 0.5)), fabs(sy - (y + 0.5)));
      double ulp_px = v3_dot(d, d) / v3_dot(d, c.fwd) / fmin(v3_len(c.dx), v3_len(c.dy)) * 0x1p-23;
      worst = fmax(worst, err / ulp_px), worst_px = fmax(worst_px, err);
    }
  }
  printf("projection: worst distance from the pixel centre %.2e pixels, %.2f float ulps of the ray\n", worst_px,
         worst);
  CHECK(worst < 4, "points on a pixel's ray land %.2f ulps of the ray from its centre", worst);
  /* Orthographic: points along the ray of a sample, from its origin on the image plane. */
  worst_px = 0;
  for (int v = 0; v < 20; v++) {
    rr_camera rc = pub_camera(v3(test_randf(-2, 2), test_randf(-2, 2), test_randf(-2, 2)), v3(0, 0, 0), v3(0, 1, 0), 45);
    rc.type = RR_CAMERA_ORTHOGRAPHIC, rc.ortho_height = test_randf(0.5f, 4);
    int w = 64 + (int)(test_rand() % 500), h = 64 + (int)(test_rand() % 500);
    camera c;
    if (rr_cam_setup(dev, &rc, w, h, &c) != RR_OK) continue;
    for (int k = 0; k < 20; k++) {
      int x = (int)(test_rand() % (unsigned)w), y = (int)(test_rand() % (unsigned)h);
      vec3 o, d;
      rr_cam_ray(&c, x, y, &o, &d);
      double sx, sy;
      if (!rr_raster2d_project(s, &c, v3_add(o, v3_scale(d, test_randf(0.1f, 4))), &sx, &sy)) {
        CHECK(0, "orthographic: a point in front of the image plane is behind the near plane");
        continue;
      }
      worst_px = fmax(worst_px, fmax(fabs(sx - (x + 0.5)), fabs(sy - (y + 0.5))));
    }
  }
  printf("orthographic projection: worst distance from the pixel centre %.2e pixels\n", worst_px);
  CHECK(worst_px < 1e-3, "orthographic: points on a pixel's ray land %.2e pixels from its centre", worst_px);
}

/* ---- fill rule: every claim counted ---------------------------------------------- */

/* mode 0: every sample claimed exactly once; mode 1 (the plane y = 0): samples whose
 * hit lies inside the plane by more than 1/64 pixel claimed exactly once, none
 * twice; mode 2 (closed mesh from outside): as many front as back claims, none twice.
 * At the pixel centres, then at every position of the 16-position pattern drawn in
 * one pass (the fill rule holds per sample). */
static void check_claims(const rr_scene *s, const camera *c0, int mode, const char *what) {
  size_t npix = (size_t)c0->width * c0->height, n = npix * NPAT;
  uint8_t *front = malloc(n), *back = malloc(n);
  camera pat[NPAT];
  pattern_cams(c0, pat);
  for (int run = 0; run < 6; run++) {
    bool bin = run % 3 > 0, all = run >= 3;
    int threads = run % 3 == 2 ? 3 : 1, samples = all ? NPAT : 1;
    rr_error e = rr_raster2d_claims(s, all ? pat : c0, samples, bin, threads, front, back);
    CHECK(e == RR_OK, "claims: %s", rr_device_message(dev));
    int holes = 0, doubles = 0, unequal = 0;
    /* off the centres, the plane that fits the image at the centres leaves the
     * border's samples uncovered: there mode 1 asks the right question */
    int md = all && mode == 0 && s->bmin.y == 0 && s->bmax.y == 0 ? 1 : mode;
    for (size_t k = 0; k < npix * samples; k++) {
      int total = front[k] + back[k];
      const camera *c = all ? &pat[k / npix] : c0;
      if (md == 0) {
        holes += total == 0, doubles += total > 1;
      } else if (md == 1) {
        doubles += total > 1;
        /* where the ray meets the plane, and the size of a pixel there */
        int x = (int)(k % npix % c->width), y = (int)(k % npix / c->width);
        double hit[3][3], t = 0;
        for (int j = 0; j < 3; j++) {
          vec3 o, d;
          rr_cam_ray(c, x + (j == 1), y + (j == 2), &o, &d);
          double tj = -(double)o.y / d.y;
          hit[j][0] = o.x + tj * d.x, hit[j][2] = o.z + tj * d.z;
          if (j == 0) t = tj;
        }
        double pixel = fmax(hypot(hit[1][0] - hit[0][0], hit[1][2] - hit[0][2]),
                            hypot(hit[2][0] - hit[0][0], hit[2][2] - hit[0][2]));
        double half = 0.5 * sqrt((double)s->ntris / 2), margin = pixel / 64;
        if (t > 0 && fabs(hit[0][0]) < half - margin && fabs(hit[0][2]) < half - margin) holes += total == 0;
      } else {
        doubles += front[k] > 1 || back[k] > 1;
        unequal += front[k] != back[k];
      }
    }
    CHECK(holes == 0 && doubles == 0 && unequal == 0,
          "%s (%s, %d threads, %d positions): %d holes, %d double claims, %d rays entering and leaving unequally", what,
          bin ? "2dr-bin" : "2dr-bb", threads, samples, holes, doubles, unequal);
  }
  free(front), free(back);
}

static void check_fill_rule(void) {
  rr_scene *plane = load("plane:64"), *sphere = load("sphere:48"), *box = load("box:8");
  if (!plane || !sphere || !box) return;
  /* Straight down on the plane with pixel centres exactly on the vertices, then on
   * the edges, then random oblique views. */
  camera c = make_cam(v3(-0.5f, 32, -0.5f), v3(-0.5f, 0, -0.5f), v3(0, 0, -1), 90, 64, 64);
  check_claims(plane, &c, 0, "plane, pixel centres on vertices");
  c = make_cam(v3(0, 32, -0.5f), v3(0, 0, -0.5f), v3(0, 0, -1), 90, 64, 64);
  check_claims(plane, &c, 1, "plane, pixel centres on edges");
  {
    /* Orthographic, one pixel per cell: centres on vertices, then random views. */
    rr_camera rc = pub_camera(v3(-0.5f, 10, -0.5f), v3(-0.5f, 0, -0.5f), v3(0, 0, -1), 45);
    rc.type = RR_CAMERA_ORTHOGRAPHIC, rc.ortho_height = 64;
    CHECK(rr_cam_setup(dev, &rc, 64, 64, &c) == RR_OK, "orthographic camera");
    check_claims(plane, &c, 0, "plane, orthographic, pixel centres on vertices");
    for (int v = 0; v < 3; v++) {
      rc = pub_camera(v3(test_randf(-20, 20), test_randf(2, 30), test_randf(-20, 20)),
                      v3(test_randf(-10, 10), 0, test_randf(-10, 10)), v3(0, 1, 0), 45);
      rc.type = RR_CAMERA_ORTHOGRAPHIC, rc.ortho_height = test_randf(5, 60);
      CHECK(rr_cam_setup(dev, &rc, 96, 72, &c) == RR_OK, "orthographic camera");
      check_claims(plane, &c, 1, "plane, orthographic, random view");
    }
  }
  for (int v = 0; v < 6; v++) {
    vec3 eye = v3(test_randf(-20, 20), test_randf(2, 30), test_randf(-20, 20));
    vec3 target = v3(test_randf(-10, 10), 0, test_randf(-10, 10));
    c = make_cam(eye, target, v3(0, 1, 0), test_randf(30, 100), 96, 72);
    check_claims(plane, &c, 1, "plane, random view");
  }
  /* Low over the plane: triangles cross the eye plane and the guard band. */
  for (int v = 0; v < 4; v++) {
    vec3 eye = v3(test_randf(-5, 5), test_randf(0.05f, 0.5f), test_randf(-5, 5));
    vec3 target = v3(test_randf(-10, 10), test_randf(-1, 0.2f), test_randf(-10, 10));
    c = make_cam(eye, target, v3(0, 1, 0), test_randf(60, 120), 96, 72);
    check_claims(plane, &c, 1, "plane, low view across the eye plane");
  }
  /* Inside the closed box and sphere: every sample claimed exactly once, although
   * the walls beside the eye are clipped at the near plane and the guard band. */
  c = make_cam(v3(-0.015625f, 0.015625f, 0), v3(-0.015625f, 0.015625f, -1), v3(0, 1, 0), 90, 64, 64);
  check_claims(box, &c, 0, "inside box, centres on vertices");
  for (int v = 0; v < 6; v++) {
    const rr_scene *s = v & 1 ? sphere : box;
    vec3 eye = v3(test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f));
    vec3 target = v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1));
    /* odd sizes too: blocks and tiles cut by the image border */
    int w = v < 3 ? 80 : 67 + 2 * v, h = v < 3 ? 60 : 41 + v;
    c = make_cam(eye, target, v3(test_randf(-1, 1), 1, test_randf(-1, 1)), test_randf(40, 150), w, h);
    check_claims(s, &c, 0, v & 1 ? "inside sphere" : "inside box");
  }
  for (int v = 0; v < 6; v++) {
    const rr_scene *s = v & 1 ? sphere : box;
    vec3 eye = v3_scale(v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1))), test_randf(2, 5));
    c = make_cam(eye, v3(0, 0, 0), v3(0, 1, 0), test_randf(30, 70), 80, 60);
    check_claims(s, &c, 2, v & 1 ? "sphere from outside" : "box from outside");
  }
  rr_scene_release(plane), rr_scene_release(sphere), rr_scene_release(box);
}

/* ---- agreement with 2dr-bb (bitwise) and 3dr-bb (within snapping) ----------------- */

/* The ray of pixel (x, y) of a planar camera, from its parameterization in double
 * (rr_cam_ray rounds origin and direction to float). */
static void exact_ray(const camera *c, int x, int y, double o[3], double d[3]) {
  double sx = x + (double)c->sx0, sy = y + (double)c->sy0;
  bool ortho = c->type == RR_CAMERA_ORTHOGRAPHIC;
  vec3 a = ortho ? c->ox : c->dx, b = ortho ? c->oy : c->dy, z = ortho ? c->o0 : c->d0;
  double u[3] = {z.x + sx * a.x + sy * b.x, z.y + sx * a.y + sy * b.y, z.z + sx * a.z + sy * b.z};
  double e[3] = {c->eye.x, c->eye.y, c->eye.z}, f[3] = {c->fwd.x, c->fwd.y, c->fwd.z};
  for (int k = 0; k < 3; k++) {
    o[k] = ortho ? e[k] + u[k] : e[k];
    d[k] = ortho ? f[k] : u[k];
  }
}

/* The ray parameter of the hit of ray o + t·d with triangle i's plane, in double. */
static double exact_t(const rr_scene *s, uint32_t i, const double o[3], const double d[3]) {
  double p[3][3], e1[3], e2[3];
  for (int k = 0; k < 3; k++) {
    vec3 v = scene_vertex(s, k, i);
    p[k][0] = v.x - o[0], p[k][1] = v.y - o[1], p[k][2] = v.z - o[2];
  }
  for (int c = 0; c < 3; c++) e1[c] = p[1][c] - p[0][c], e2[c] = p[2][c] - p[0][c];
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return (n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2]) / (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
}

typedef struct {
  double same_id, same_hit, depth_ok, bary_ok; /* shares; depth and λ where both hit the same id */
  int hits;
  int depth_bad;      /* 2dr depths off the exact hit by more than 1e-4, or off the triangle's range */
  int depth_diff;     /* common hits whose depths differ by more than 1e-4 */
  int depth_3dr_off;  /* ... of which 3dr-bb's depth is the one off the exact hit */
  double worst_2dr, worst_3dr; /* largest relative depth errors against the exact hit */
} agreement;

/* a: 2dr, b: 3dr-bb. Depths are also compared with the exact hit of each id. */
static agreement compare(const rr_scene *s, const camera *c, const rr_frame *a, const rr_frame *b) {
  size_t n = (size_t)a->vb.width * a->vb.height, same_id = 0, same_hit = 0, both = 0, depth_ok = 0, bary_ok = 0;
  agreement g = {0};
  for (size_t k = 0; k < n; k++) {
    uint32_t ia = a->vb.id[k], ib = b->vb.id[k];
    same_id += ia == ib;
    same_hit += (ia == RR_MISS) == (ib == RR_MISS);
    if (ia == RR_MISS) continue;
    g.hits++;
    int x = (int)(k % a->vb.width), y = (int)(k / a->vb.width);
    double o[3], d[3];
    exact_ray(c, x, y, o, d);
    /* Relative errors, but not below a floor: an orthographic image plane through the
     * scene has depths near zero, where only absolute precision means anything. */
    double floor_t = 1e-3 * v3_len(v3_sub(s->bmax, s->bmin));
    double ta = a->vb.t[k], ea = exact_t(s, ia, o, d), err_a = fabs(ta - ea) / fmax(ea, floor_t);
    /* Where snapping alone puts the sample on the triangle (the ids differ), the
     * plane's depth is clamped to the triangle's: check the range only. */
    double lo = INFINITY, hi = -INFINITY, fd = c->fwd.x * d[0] + c->fwd.y * d[1] + c->fwd.z * d[2];
    for (int q = 0; q < 3; q++) {
      vec3 v = scene_vertex(s, q, ia);
      double z = ((v.x - o[0]) * c->fwd.x + (v.y - o[1]) * c->fwd.y + (v.z - o[2]) * c->fwd.z) / fd;
      lo = fmin(lo, z), hi = fmax(hi, z);
    }
    g.depth_bad += !(ta >= lo - 1e-5 * fabs(lo) && ta <= hi + 1e-5 * fabs(hi));
    if (ia != ib) continue;
    g.depth_bad += !(err_a <= 1e-4);
    g.worst_2dr = fmax(g.worst_2dr, err_a);
    both++;
    double tb = b->vb.t[k], err_b = fabs(tb - ea) / fmax(ea, floor_t);
    g.worst_3dr = fmax(g.worst_3dr, err_b);
    if (fabs(ta - tb) <= 1e-4 * fmax(fmax(ta, tb), floor_t)) depth_ok++;
    else g.depth_diff++, g.depth_3dr_off += err_a <= 1e-4 && err_b > err_a;
    bary_ok += fabsf(a->vb.l1[k] - b->vb.l1[k]) <= 1e-2f && fabsf(a->vb.l2[k] - b->vb.l2[k]) <= 1e-2f;
  }
  g.same_id = (double)same_id / n, g.same_hit = (double)same_hit / n;
  g.depth_ok = both ? (double)depth_ok / both : 1, g.bary_ok = both ? (double)bary_ok / both : 1;
  return g;
}

static void check_agreement(const char *what, const agreement *g, double min_id, double min_hit) {
  CHECK(g->same_id >= min_id, "%s: ids agree with 3dr-bb on %.4f%% of samples", what, 100 * g->same_id);
  CHECK(g->same_hit >= min_hit, "%s: hit/miss agrees with 3dr-bb on %.4f%% of samples", what, 100 * g->same_hit);
  CHECK(g->depth_diff == g->depth_3dr_off, "%s: %d depths differ from 3dr-bb's by more than 1e-4 where 3dr-bb is right",
        what, g->depth_diff - g->depth_3dr_off);
  CHECK(g->depth_bad == 0, "%s: %d 2dr depths are off the exact hit by more than 1e-4 (worst %.2e)", what,
        g->depth_bad, g->worst_2dr);
}

/* The view at the 16-position pattern (all positions in one pass): 2dr-bin equals
 * 2dr-bb bit for bit, and each layer agrees with 3dr-bb's at that position as
 * well as the pixel centres must. */
static void check_view_pattern(const rr_scene *s, const rr_camera *cam, const camera *c, int w, int h, int cull,
                               const char *what, double min_id, double min_hit) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = w, opt.height = h, opt.cull_backfaces = cull, opt.threads = 2, opt.samples = NPAT;
  camera pat[NPAT];
  pattern_cams(c, pat);
  for (int k = 0; k < NPAT; k++) opt.sample_pos[k][0] = pat[k].sx0, opt.sample_pos[k][1] = pat[k].sy0;
  const rr_method ms[3] = {RR_METHOD_2DR_BB, RR_METHOD_2DR_BIN, RR_METHOD_3DR_BB};
  rr_frame *f[3];
  for (int m = 0; m < 3; m++) opt.method = ms[m], f[m] = test_render_opt(dev, s, cam, &opt);
  if (f[0] && f[1] && f[2]) {
    size_t npix = (size_t)w * h, n = npix * NPAT;
    const visbuf *a = &f[0]->vb, *b = &f[1]->vb;
    CHECK(memcmp(a->id, b->id, n * 4) == 0 && memcmp(a->t, b->t, n * 4) == 0 && memcmp(a->l1, b->l1, n * 4) == 0 &&
              memcmp(a->l2, b->l2, n * 4) == 0,
          "%s: 2dr-bin differs from 2dr-bb at %d positions", what, NPAT);
    /* position k's layers, copied apart (the buffer keeps a pixel's samples side by side) */
    uint32_t *ids = malloc(2 * npix * sizeof *ids);
    float *fs = malloc(6 * npix * sizeof *fs);
    CHECK(ids && fs, "out of memory");
    double worst_id = 1, worst_hit = 1;
    for (int k = 0; ids && fs && k < NPAT; k++) {
      const visbuf *r = &f[2]->vb;
      for (size_t p = 0; p < npix; p++) {
        size_t q = p * NPAT + k;
        ids[p] = a->id[q], fs[p] = a->t[q], fs[npix + p] = a->l1[q], fs[2 * npix + p] = a->l2[q];
        ids[npix + p] = r->id[q], fs[3 * npix + p] = r->t[q], fs[4 * npix + p] = r->l1[q], fs[5 * npix + p] = r->l2[q];
      }
      rr_frame la = {.vb = {w, h, ids, fs, fs + npix, fs + 2 * npix, 1}};
      rr_frame lr = {.vb = {w, h, ids + npix, fs + 3 * npix, fs + 4 * npix, fs + 5 * npix, 1}};
      agreement g = compare(s, &pat[k], &la, &lr);
      char label[300];
      snprintf(label, sizeof label, "%s, position %d (%g, %g)", what, k, pat[k].sx0, pat[k].sy0);
      check_agreement(label, &g, min_id, min_hit);
      worst_id = fmin(worst_id, g.same_id), worst_hit = fmin(worst_hit, g.same_hit);
    }
    printf("%s, %d positions: ids agree with 3dr-bb on at least %.4f%% (asked %.4f%%), hit/miss %.4f%%\n", what, NPAT,
           100 * worst_id, 100 * min_id, 100 * worst_hit);
    free(ids), free(fs);
  }
  for (int m = 0; m < 3; m++) rr_frame_release(f[m]);
}

/* Renders one view with 2dr-bb and 2dr-bin on 1, 2 and 8 threads, and with 3dr-bb;
 * every 2dr frame must equal 2dr-bb's on one thread bit for bit, and 2dr-bb must
 * agree with 3dr-bb on ids and hits at least as often as asked. Where the ids
 * agree the depths must agree within 1e-4 (relative, or of 1e-3 of the scene's
 * size near the image plane), except where 3dr-bb's float depth is itself that far
 * off the exact hit; and every 2dr depth must be within 1e-4 of the exact hit
 * there, and within the triangle's depth range everywhere. */
static agreement check_view(const rr_scene *s, const rr_camera *cam, int w, int h, int cull, const char *what,
                            double min_id, double min_hit) {
  agreement g = {0};
  camera c;
  if (rr_cam_setup(dev, cam, w, h, &c) != RR_OK) {
    CHECK(0, "%s: camera: %s", what, rr_device_message(dev));
    return g;
  }
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = w, opt.height = h, opt.cull_backfaces = cull;
  opt.method = RR_METHOD_2DR_BB;
  rr_frame *bb = test_render_threads(dev, s, cam, &opt, NULL, what);
  opt.method = RR_METHOD_2DR_BIN;
  rr_frame *bin = bb ? test_render_threads(dev, s, cam, &opt, bb, what) : NULL;
  rr_frame *ref = test_render(dev, s, cam, RR_METHOD_3DR_BB, 1, w, h, cull);
  if (bb && bin && ref) {
    CHECK(bin->stats.setups == bb->stats.setups, "%s: both traversals set up the same triangles", what);
    g = compare(s, &c, bb, ref);
    printf("%s: %d hits; vs 3dr-bb: id %.4f%%, hit/miss %.4f%%, depth %.4f%% (%d off by 3dr-bb's rounding), "
           "bary %.4f%%; worst depth error 2dr %.1e, 3dr %.1e; E bb %llu bin %llu\n",
           what, g.hits, 100 * g.same_id, 100 * g.same_hit, 100 * g.depth_ok, g.depth_3dr_off, 100 * g.bary_ok,
           g.worst_2dr, g.worst_3dr, (unsigned long long)bb->stats.edge_evals,
           (unsigned long long)bin->stats.edge_evals);
    check_agreement(what, &g, min_id, min_hit);
  }
  rr_frame_release(bb), rr_frame_release(bin), rr_frame_release(ref);
  if (w * h <= 128 * 128) check_view_pattern(s, cam, &c, w, h, cull, what, min_id, min_hit);
  return g;
}

static rr_scene *mesh_scene(const float *pos, size_t nv, const uint32_t *idx, size_t nt) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new scene");
  CHECK(rr_scene_add_mesh(s, pos, nv, idx, nt, NULL) == RR_OK, "add mesh: %s", rr_device_message(dev));
  CHECK(rr_scene_commit(s) == RR_OK, "commit: %s", rr_device_message(dev));
  return s;
}

/* Random triangles around the eye: crossing the eye plane, near it, behind it. */
static rr_scene *soup_scene(int n, float radius, float size) {
  float *pos = malloc((size_t)n * 9 * sizeof *pos);
  uint32_t *idx = malloc((size_t)n * 3 * sizeof *idx);
  for (int i = 0; i < n; i++) {
    vec3 c = v3(test_randf(-radius, radius), test_randf(-radius, radius), test_randf(-radius, radius));
    for (int k = 0; k < 3; k++) {
      pos[9 * i + 3 * k + 0] = c.x + test_randf(-size, size);
      pos[9 * i + 3 * k + 1] = c.y + test_randf(-size, size);
      pos[9 * i + 3 * k + 2] = c.z + test_randf(-size, size);
      idx[3 * i + k] = (uint32_t)(3 * i + k);
    }
  }
  rr_scene *s = mesh_scene(pos, (size_t)n * 3, idx, (size_t)n);
  free(pos), free(idx);
  return s;
}

static void check_clipping(void) {
  /* A ground quad 100 units wide under an eye 1 unit above it: it runs behind the
   * eye and to the horizon; with a box standing on it. */
  {
    const float pos[] = {-50, 0, -50, 50, 0, -50, 50, 0, 50, -50, 0, 50,
                         -1, 0, -3, 1, 0, -3, 1, 2, -3, -1, 2, -3};
    const uint32_t idx[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7};
    rr_scene *s = mesh_scene(pos, 8, idx, 4);
    for (int v = 0; v < 6; v++) {
      rr_camera cam = pub_camera(v3(test_randf(-2, 2), test_randf(0.2f, 1.5f), test_randf(-1, 3)),
                                 v3(test_randf(-5, 5), test_randf(-1, 1), test_randf(-10, -3)), v3(0, 1, 0),
                                 test_randf(40, 120));
      check_view(s, &cam, v < 3 ? 128 : 131, v < 3 ? 96 : 77, v & 1, "ground across the eye plane", 0.998, 0.998);
    }
    rr_scene_release(s);
  }
  /* Random triangles all around the eye, many crossing the near and eye planes. */
  {
    rr_scene *s = soup_scene(300, 3, 1.5f);
    for (int v = 0; v < 6; v++) {
      rr_camera cam = pub_camera(v3(test_randf(-0.5f, 0.5f), test_randf(-0.5f, 0.5f), test_randf(-0.5f, 0.5f)),
                                 v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)), v3(0, 1, 0),
                                 test_randf(40, 120));
      check_view(s, &cam, 128, 96, v & 1, "triangles around the eye", 0.995, 0.998);
    }
    rr_scene_release(s);
  }
  /* Triangles wholly behind the eye: nothing is drawn. */
  {
    const float pos[] = {-1, -1, 1, 1, -1, 1, 0, 1, 1, -100, -100, 0.5f, 100, -100, 0.5f, 0, 100, 200};
    const uint32_t idx[] = {0, 1, 2, 3, 4, 5};
    rr_scene *s = mesh_scene(pos, 6, idx, 2);
    rr_camera cam = pub_camera(v3(0, 0, 0), v3(0, 0, -1), v3(0, 1, 0), 90);
    agreement g = check_view(s, &cam, 64, 64, 0, "triangles behind the eye", 1, 1);
    CHECK(g.hits == 0, "%d samples hit a triangle behind the eye", g.hits);
    g = check_view(s, &cam, 1, 1, 0, "one sample", 1, 1);
    CHECK(g.hits == 0, "%d samples hit a triangle behind the eye", g.hits);
    rr_scene_release(s);
  }
  /* Huge triangles, vertices a million units away, around a small one. */
  {
    const float pos[] = {-1e6f, -1e6f, -1e6f, 1e6f, -1e6f, -2e6f, 0, 1e6f, 1e6f,
                         -3e6f, -1, 1e6f, 3e6f, -1, 1e6f, 0, -1, -3e6f,
                         -0.5f, -0.5f, -2, 0.5f, -0.5f, -2, 0, 0.5f, -2};
    const uint32_t idx[] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
    rr_scene *s = mesh_scene(pos, 9, idx, 3);
    for (int v = 0; v < 6; v++) {
      rr_camera cam = pub_camera(v3(test_randf(-0.5f, 0.5f), test_randf(-0.5f, 0.5f), test_randf(-0.5f, 0.5f)),
                                 v3(test_randf(-1, 1), test_randf(-1, 1), -2), v3(0, 1, 0), test_randf(30, 150));
      check_view(s, &cam, 128, 96, 0, "huge triangles", 0.998, 0.998);
    }
    rr_scene_release(s);
  }
  /* Inside closed meshes. */
  const char *closed[] = {"sphere:48", "box:8"};
  for (int m = 0; m < 2; m++) {
    rr_scene *s = load(closed[m]);
    if (!s) continue;
    for (int v = 0; v < 3; v++) {
      rr_camera cam = pub_camera(v3(test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f)),
                                 v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)), v3(0, 1, 0),
                                 test_randf(40, 150));
      check_view(s, &cam, 128, 96, 0, closed[m], 0.995, 1);
    }
    rr_scene_release(s);
  }
}

/* A view where even the pixel centres miss the thresholds on ids: each position of
 * the 16-position pattern must agree with 3dr-bb at the level the centres do (at most
 * twice their share of differing ids: a few samples each at 128²), and on hits, depths
 * and λ as check_view asks. */
static void check_dense_pattern(const rr_scene *s, const rr_camera *cam, int w, int h, const char *what) {
  camera c;
  if (rr_cam_setup(dev, cam, w, h, &c) != RR_OK) {
    CHECK(0, "%s: camera: %s", what, rr_device_message(dev));
    return;
  }
  rr_frame *a = test_render(dev, s, cam, RR_METHOD_2DR_BB, 2, w, h, 0);
  rr_frame *b = test_render(dev, s, cam, RR_METHOD_3DR_BB, 2, w, h, 0);
  if (a && b) {
    agreement g = compare(s, &c, a, b);
    printf("%s: %d hits; pixel centres vs 3dr-bb: id %.4f%%, hit/miss %.4f%%\n", what, g.hits, 100 * g.same_id,
           100 * g.same_hit);
    check_agreement(what, &g, 0.99, 0.9999);
    check_view_pattern(s, cam, &c, w, h, 0, what, 1 - 2 * (1 - g.same_id), 0.9999);
  }
  rr_frame_release(a), rr_frame_release(b);
}

/* Real meshes at several views, one of them from inside the bounds. */
static void check_models(void) {
  const char *meshes[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "suzanne.obj", "spot.obj"};
  for (int m = 0; m < 5; m++) {
    const char *path = test_model(meshes[m]);
    if (!path) continue;
    rr_scene *s = load(path);
    if (!s) continue;
    vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
    float r = 0.5f * v3_len(v3_sub(s->bmax, s->bmin));
    for (int v = 0; v < 3; v++) {
      rr_camera cam;
      if (v == 0) {
        rr_camera_init(&cam);
        cam.fov_deg = 50;
        rr_camera_frame(dev, s, 512, 512, &cam);
      } else {
        cam = test_random_view(s, v == 2 ? 0.3f : 1.5f, v == 2 ? 0.3f : 3, 0.2f, 40, 90);
      }
      char what[256];
      snprintf(what, sizeof what, "%s view %d", meshes[m], v);
      check_view(s, &cam, 512, 512, v == 1, what, 0.999, 0.9999);
      if (m > 0) continue;
      /* The bunny at 128² too, with the 16-position pattern. The sparse view 1 is held
       * to the thresholds of the 512² pixel centres at every position; on views 0 and 2
       * the pixel centres themselves miss 0.999 on ids at 128² (99.88%, 99.87% measured:
       * triangles 1/16 the size, so snapping to 1/256 px moves more ids), and each
       * position is held to the centres' own level instead. */
      snprintf(what, sizeof what, "%s view %d at 128²", meshes[m], v);
      if (v == 1) check_view(s, &cam, 128, 128, 1, what, 0.999, 0.9999);
      else check_dense_pattern(s, &cam, 128, 128, what);
    }
    /* Orthographic, from outside and with the image plane through the mesh. */
    for (int v = 0; v < 2; v++) {
      vec3 dir = v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)));
      rr_camera cam = pub_camera(v3_add(c, v3_scale(dir, r * (v ? 0.2f : 2))), c, v3(0, 1, 0), 45);
      cam.type = RR_CAMERA_ORTHOGRAPHIC, cam.ortho_height = 2.2f * r;
      char what[256];
      snprintf(what, sizeof what, "%s orthographic view %d", meshes[m], v);
      check_view(s, &cam, 512, 512, 0, what, 0.999, 0.9999);
    }
    rr_scene_release(s);
  }
}

/* The per-pixel evaluation charges (heat maps) add up to E, and S and E do not
 * depend on the thread count. */
static void check_stats(void) {
  rr_scene *s = load("demo");
  if (!s) return;
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, 160, 120, &cam);
  for (int m = 0; m < 2; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = m ? RR_METHOD_2DR_BIN : RR_METHOD_2DR_BB, opt.width = 160, opt.height = 120, opt.heat = 1;
    rr_frame *f[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
      opt.threads = k + 1;
      CHECK(rr_render(dev, s, &cam, &opt, &f[k]) == RR_OK, "render: %s", rr_device_message(dev));
    }
    if (f[0] && f[1]) {
      double sum = 0;
      for (int k = 0; k < 160 * 120; k++) sum += f[0]->heat_e[k];
      CHECK(f[0]->stats.setups > 0 && f[0]->stats.edge_evals > 0, "S and E are positive");
      CHECK(sum == (double)f[0]->stats.edge_evals, "%s: per-pixel E adds to %.0f, total %llu",
            rr_method_name(opt.method), sum, (unsigned long long)f[0]->stats.edge_evals);
      CHECK(f[0]->stats.setups == f[1]->stats.setups && f[0]->stats.edge_evals == f[1]->stats.edge_evals,
            "%s: stats differ between 1 and 2 threads", rr_method_name(opt.method));
    }
    rr_frame_release(f[0]), rr_frame_release(f[1]);
  }
  rr_scene_release(s);
}

int main(void) {
  dev = rr_device_new();
  rr_scene *sphere = load("sphere:24");
  if (sphere) check_projection(sphere);
  rr_scene_release(sphere);
  check_fill_rule();
  check_stats();
  check_clipping();
  check_models();
  rr_device_release(dev);
  return test_done();
}
