/* Curved views' image rectangles (rr_tri_screen_bounds, rr_tri_curved_rect) are
 * conservative: for random triangles in every curved camera, every sample whose
 * ray passes the 3D edge test lies inside the triangle's rectangle. The triangles
 * gather where the maps are singular or wrap: the lat-long's seam and poles, the
 * hemisphere's rim, the fisheye's axis and (at 360°) its antipode, the cube's
 * 12 edges and 8 corners (the cube: each face's perspective rectangle, from the
 * corners, against the face's own samples); the OpenCV cameras with distortion. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <math.h>
#include <string.h>

static uint32_t rng = 12345;
static double rnd(void) { /* xorshift, uniform in [0, 1) */
  rng ^= rng << 13, rng ^= rng >> 17, rng ^= rng << 5;
  return (rng >> 8) * (1.0 / 16777216.0);
}
static vec3 rnd_unit(void) {
  for (;;) {
    vec3 v = v3((float)(2 * rnd() - 1), (float)(2 * rnd() - 1), (float)(2 * rnd() - 1));
    float l = v3_len(v);
    if (l > 0.1f && l <= 1) return v3_scale(v, 1 / l);
  }
}

/* A direction in the camera's frame: angle a from fwd (around the axis at angle
 * psi), or from up for the lat-long's poles. */
static vec3 polar(vec3 axis, vec3 e1, vec3 e2, double a, double psi) {
  return v3_add(v3_scale(axis, (float)cos(a)),
                v3_add(v3_scale(e1, (float)(sin(a) * cos(psi))), v3_scale(e2, (float)(sin(a) * sin(psi)))));
}

/* A centre direction where the camera's map is hard, or anywhere. */
static vec3 hard_dir(const rr_camera *rc, vec3 f, vec3 r, vec3 u) {
  double psi = 2 * RR_PI * rnd(), jit = rnd() < 0.5 ? 0 : 0.05 * (2 * rnd() - 1);
  switch ((int)(rnd() * 5)) {
  case 0: return rnd_unit();
  case 1: return polar(u, f, r, jit, psi);                  /* north pole */
  case 2: return polar(v3_neg(u), f, r, jit, psi);          /* south pole */
  case 3: return polar(v3_neg(f), u, r, jit, psi);          /* behind: the seam, the 360° fisheye's rim */
  default: {                                               /* the rim of the disk, the axis */
    if (rc->type == RR_CAMERA_CUBE) { /* any of the 8 corners, or a point on any of the 12 edges */
      const int free_axis = (int)(rnd() * 3);
      double q[3];
      for (int a = 0; a < 3; a++) q[a] = rnd() < 0.5 ? -1 : 1;
      if (rnd() < 0.6) q[free_axis] = rnd() < 0.5 ? 0 : 2 * rnd() - 1; /* an edge: its middle, or anywhere on it */
      vec3 d = v3_add(v3_scale(f, (float)q[0]), v3_add(v3_scale(r, (float)q[1]), v3_scale(u, (float)q[2])));
      return v3_add(v3_norm(d), v3_scale(rnd_unit(), (float)fabs(jit)));
    }
    double rim = rc->type == RR_CAMERA_FISHEYE ? rc->fov_deg * RR_PI / 360 : RR_PI / 2;
    return polar(f, r, u, rnd() < 0.3 ? jit : rim + jit, psi);
  }
  }
}

static long flat_missed_all; /* passing samples outside chart bounds without their remainder */

/* front: small triangles (1e-2 to 0.25 rad) within 30° of the axis, where every
 * camera's bound must be tight, instead of the hard directions' triangles. */
static void check_camera(rr_device *dev, const rr_camera *rc, int w, int h, int ntri, bool front, const char *what) {
  float pos[2] = {(float)rnd(), (float)rnd()};
  camera c;
  CHECK(rr_cam_setup_at(dev, rc, w, h, pos, &c) == RR_OK, "%s: camera", what);
  /* the triangles, around hard directions, of angular sizes from 1e-3 to 1.5 rad */
  float *p = malloc((size_t)ntri * 9 * sizeof *p);
  uint32_t *idx = malloc((size_t)ntri * 3 * sizeof *idx);
  for (int k = 0; k < 3 * ntri; k++) idx[k] = (uint32_t)k;
  for (int t = 0; t < ntri; t++) {
    vec3 centre = front ? polar(c.fwd, c.right, c.up, 0.52 * rnd(), 2 * RR_PI * rnd()) : hard_dir(rc, c.fwd, c.right, c.up);
    double size = exp((front ? log(1e-2) : log(1e-3)) + rnd() * (front ? log(0.25) - log(1e-2) : log(1.5) - log(1e-3)));
    /* a quarter are slivers: the third corner near the line through the first two
     * (chart_extent moves a sharp corner along the sliver only) */
    const bool sliver = rnd() < 0.25;
    for (int k = 0; k < 3; k++) {
      vec3 d = v3_norm(v3_add(centre, v3_scale(rnd_unit(), (float)size)));
      float dist = (float)(0.5 + 10 * rnd());
      vec3 q = v3_add(c.eye, v3_scale(d, dist));
      if (sliver && k == 2) {
        vec3 a, b;
        memcpy(&a, p + 9 * t, 12), memcpy(&b, p + 9 * t + 3, 12);
        float u = (float)(1.5 * rnd() - 0.25), off = (float)exp(log(1e-5) + rnd() * (log(1e-2) - log(1e-5)));
        q = v3_add(v3_add(a, v3_scale(v3_sub(b, a), u)), v3_scale(rnd_unit(), off * v3_len(v3_sub(b, a))));
      }
      memcpy(p + 9 * t + 3 * k, &q, 12);
    }
  }
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "scene");
  CHECK(rr_scene_add_mesh(s, p, (size_t)ntri * 3, idx, (size_t)ntri, NULL) == RR_OK, "mesh: %s",
        rr_device_message(dev));
  CHECK(rr_scene_commit(s) == RR_OK, "commit");
  long missed = 0, passing = 0, area = 0, tight = 0, seen = 0, caps = 0, cap_missed = 0, half_missed = 0, corner_missed = 0;
  long charts = 0, chart_missed = 0, flat_missed = 0;
  /* a cube's samples are those of its six perspective faces (camera/camera.h) */
  const bool cube = rc->type == RR_CAMERA_CUBE;
  for (int f = 0; f < (cube ? 6 : 1); f++) {
    camera fc;
    if (cube) rr_cam_cube_face(&c, f, &fc);
    const camera *cc = cube ? &fc : &c;
    for (uint32_t i = 0; i < s->ntris; i++) {
      tri_setup ts;
      if (rr_tri_setup(s, i, cc, false, &ts) == SETUP_CULLED) continue;
      int r[4], rt[4], rc[4], rh[4], rg[4], rf[4];
      bool has = rr_tri_screen_bounds(s, i, cc, &ts, r);
      /* the cap bound alone, at its radius and at half of it */
      int cap = cube ? -1 : rr_tri_curved_cap(cc, &ts, 1, rc), half = cube ? -1 : rr_tri_curved_cap(cc, &ts, 0.5, rh);
      caps += cap > 0;
      /* the chart bound alone, with its remainder and without (the linearisation alone) */
      int chart = cube ? -1 : rr_tri_curved_chart(cc, &ts, 1, rg), flat = cube ? -1 : rr_tri_curved_chart(cc, &ts, 0, rf);
      charts += chart >= 0;
      /* before the setup: the corner cap with the root pass's slack (vis/traverse.c, mark_seen) */
      int rk[4], corner = cube ? -1 : rr_tri_corner_cap(s, i, cc, 1e-4, rk);
      tight += cube || rr_tri_curved_rect(cc, &ts, rt) >= 0;
      seen++;
      long in = 0;
      for (int y = 0; y < cc->height; y++)
        for (int x = 0; x < cc->width; x++) {
          vec3 d = camera_w(cc, x, y);
          if (d.x == 0 && d.y == 0 && d.z == 0) continue;
          float e[3], t, l1, l2;
          tri_edges_w(&ts, d, e);
          if (!sample_test_w(e, ts.w, ts.tie, tri_vol(&ts, d.y, d.z), 0, tri_den_w(&ts, d), &t, &l1, &l2)) continue;
          in++;
          if (cap == 0 || (cap > 0 && (x < rc[0] || x > rc[2] || y < rc[1] || y > rc[3]))) {
            if (cap_missed++ < 5)
              fprintf(stderr, "%s: triangle %u passes at (%d, %d) outside its cap rectangle\n", what, i, x, y);
          }
          if (corner == 0 || (corner > 0 && (x < rk[0] || x > rk[2] || y < rk[1] || y > rk[3]))) {
            if (corner_missed++ < 5)
              fprintf(stderr, "%s: triangle %u passes at (%d, %d) outside its corner cap\n", what, i, x, y);
          }
          if (chart == 0 || (chart > 0 && (x < rg[0] || x > rg[2] || y < rg[1] || y > rg[3]))) {
            if (chart_missed++ < 5)
              fprintf(stderr, "%s: triangle %u passes at (%d, %d) outside its chart rectangle\n", what, i, x, y);
          }
          flat_missed += flat == 0 || (flat > 0 && (x < rf[0] || x > rf[2] || y < rf[1] || y > rf[3]));
          half_missed += half == 0 || (half > 0 && (x < rh[0] || x > rh[2] || y < rh[1] || y > rh[3]));
          if (!has || x < r[0] || x > r[2] || y < r[1] || y > r[3]) {
            if (missed++ < 5)
              fprintf(stderr, "%s: triangle %u passes at (%d, %d) of face %d outside [%d,%d]x[%d,%d]%s\n", what, i, x,
                      y, f, has ? r[0] : 0, has ? r[2] : -1, has ? r[1] : 0, has ? r[3] : -1, has ? "" : " (none)");
          }
        }
      passing += in;
      if (has) area += (long)(r[2] - r[0] + 1) * (r[3] - r[1] + 1);
    }
  }
  /* rr_tri_spheres: every lane the bits of a one-lane call, AVX2 or not, in groups
   * of eight and a partial last one (the bounds above took the one-lane calls) */
  tri_setup *all = malloc(s->ntris * sizeof *all);
  uint32_t nset = 0;
  for (uint32_t i = 0; i < s->ntris; i++)
    if (rr_tri_setup(s, i, &c, false, &all[nset]) != SETUP_CULLED) nset++;
  const bool polar_map = rc->type == RR_CAMERA_LATLONG || rc->type == RR_CAMERA_PARABOLIC || rc->type == RR_CAMERA_FISHEYE;
  long lane_diff = 0, lane_ok = 0, lane_img = 0, lane_rect = 0;
  for (uint32_t q = 0; q < nset; q += 8) {
    int m = nset - q < 8 ? (int)(nset - q) : 8;
    tri_sphere wide[8], plain[8], one; /* two passes of four lanes */
    rr_tri_spheres_cam(all + q, m, &c, true, wide);
    rr_tri_spheres_cam(all + q, m, &c, false, plain);
    for (int l = 0; l < m; l++) {
      rr_tri_spheres(all + q + l, 1, true, &one);
      const tri_sphere *x[2] = {&wide[l], &plain[l]};
      for (int k = 0; k < 2; k++) {
        /* the lanes' cap image against rr_cam_cap_rect, here and at another position */
        camera moved = c;
        moved.sx0 = (float)rnd(), moved.sy0 = (float)rnd();
        for (int p2 = 0; p2 < 2 && one.cap; p2++) {
          const camera *cp = p2 ? &moved : &c;
          int ra[4] = {0}, rb[4] = {0}, ka = rr_tri_sphere_cap_rect(cp, x[k], ra), kb = rr_cam_cap_rect(cp, one.axis, one.rho, rb);
          lane_diff += ka != kb || (kb > 0 && memcmp(ra, rb, sizeof ra));
          lane_img += rc->type == RR_CAMERA_PARABOLIC && x[k]->img_k != TRI_CAP_UNSET;
        }
        /* the rectangle the lanes decided at c's position is rr_tri_curved_rect_sph's without it */
        if (x[k]->rect_k != TRI_CAP_UNSET) {
          tri_sphere u = *x[k];
          u.rect_k = TRI_CAP_UNSET;
          int ra[4] = {0}, rb[4] = {0}, ka = rr_tri_curved_rect_sph(&c, &all[q + l], x[k], ra),
              kb = rr_tri_curved_rect_sph(&c, &all[q + l], &u, rb);
          lane_diff += ka != kb || (kb > 0 && memcmp(ra, rb, sizeof ra));
          lane_rect++;
        }
        lane_diff += x[k]->ok != one.ok || x[k]->cap != one.cap ||
                     (one.ok && (memcmp(&x[k]->smin, &one.smin, sizeof one.smin) ||
                                 memcmp(&x[k]->E, &one.E, sizeof one.E))) ||
                     (one.cap && (memcmp(x[k]->axis, one.axis, sizeof one.axis) ||
                                  memcmp(&x[k]->rho, &one.rho, sizeof one.rho)));
      }
      lane_ok += one.ok;
    }
  }
  free(all);
  CHECK(lane_diff == 0, "%s: %ld lanes of rr_tri_spheres differ from one-lane calls", what, lane_diff);
  CHECK(cube || lane_ok > 0, "%s: no spherical triangle to compare lanes on", what);
  CHECK(rc->type != RR_CAMERA_PARABOLIC || lane_img > 0, "%s: no cap image computed in the lanes", what);
  CHECK(!polar_map || lane_rect > 0, "%s: no rectangle decided in the lanes", what);
  CHECK(missed == 0, "%s: %ld passing samples outside their triangle's rectangle", what, missed);
  CHECK(passing > 0, "%s: no triangle passes anywhere (the test would prove nothing)", what);
  CHECK(cap_missed == 0, "%s: %ld passing samples outside their triangle's cap rectangle", what, cap_missed);
  CHECK(chart_missed == 0, "%s: %ld passing samples outside their triangle's chart rectangle", what, chart_missed);
  const bool chart_map = rc->type == RR_CAMERA_LATLONG || rc->type == RR_CAMERA_FISHEYE;
  CHECK(!chart_map || charts * 4 >= seen, "%s: chart bounds for only %ld of %ld triangles", what, charts, seen);
  flat_missed_all += flat_missed; /* checked over every view (main) */
  CHECK(corner_missed == 0, "%s: %ld passing samples outside their triangle's corner cap", what, corner_missed);
  CHECK(!polar_map || tight * 10 >= seen * 9, "%s: tight bounds for only %ld of %ld triangles", what, tight, seen);
  /* the lenses' small triangles ahead: tight rectangles, on average under 10% of the image (one
   * cell of the cones, the bound without, is 13% of it) */
  const bool lens = rc->type == RR_CAMERA_OPENCV || rc->type == RR_CAMERA_OPENCV_FISHEYE;
  CHECK(!lens || !front || tight * 10 >= seen * 9, "%s: tight bounds for only %ld of %ld triangles", what, tight, seen);
  CHECK(!lens || !front || area * 10 < seen * (long)w * h, "%s: rectangles of %.1f%% of the image on average", what,
        seen ? 100.0 * area / ((double)seen * w * h) : 0.0);
  /* the cap's radius is not loose by half: halved, it misses samples */
  CHECK(!polar_map || half_missed > 0, "%s: a cap of half the radius misses no sample", what);
  printf("%s: %ld triangles (%ld tight, %ld capped), %ld passing samples in rectangles of %ld samples (%.1f%%); "
         "half caps miss %ld; %ld charts, without the remainder missing %ld\n",
         what, seen, tight, caps, passing, area, area ? 100.0 * passing / area : 0.0, half_missed, charts, flat_missed);
  rr_scene_release(s);
  free(p), free(idx);
  rr_cam_release(&c);
}

/* Camera `type` of fov degrees at w×h, set up at a random sample position. */
static void setup_at_random(rr_device *dev, rr_camera_type type, float fov, int w, int h, rr_camera *rc, camera *c) {
  rr_camera_init(rc);
  rc->type = type, rc->fov_deg = fov;
  const float pos[2] = {(float)rnd(), (float)rnd()};
  CHECK(rr_cam_setup_at(dev, rc, w, h, pos, c) == RR_OK, "camera");
}

/* The bend bound of curved binning (vis/traverse.c): over a rectangle of samples
 * spanning hx × hy, n·d stays within |n| (bend_x·hx² + bend_y·hy²) / 8 of the
 * bilinear interpolation of its corner values, so below the greatest of them plus
 * that (and the rays' rounding); rr_cam_dir_at gives the stored rays. Random
 * rectangles and normals, every sample with a ray. */
static void check_bend(rr_device *dev, rr_camera_type type, float fov, int w, int h) {
  rr_camera rc;
  camera c;
  setup_at_random(dev, type, fov, w, h, &rc, &c);
  CHECK(c.bend_x > 0 && c.bend_y > 0, "%s: no bend bound", rr_camera_name(type));
  long bad = 0, tested = 0;
  double worst = 0; /* the largest excess over the interpolation, as a share of the bound */
  for (int k = 0; k < 3000; k++) {
    int bw = 2 + (int)(rnd() * 30), bh = 2 + (int)(rnd() * 30);
    int x0 = (int)(rnd() * (w - bw)), y0 = (int)(rnd() * (h - bh));
    vec3 n = rnd_unit();
    double xs[2] = {x0 + (double)c.sx0, x0 + bw - 1 + (double)c.sx0}, ys[2] = {y0 + (double)c.sy0, y0 + bh - 1 + (double)c.sy0};
    double cv[4], dd[3];
    for (int q = 0; q < 4; q++) {
      rr_cam_dir_at(&c, xs[q & 1], ys[q >> 1], dd);
      cv[q] = n.x * dd[0] + n.y * dd[1] + n.z * dd[2];
    }
    double hx = bw - 1, hy = bh - 1, bend = (c.bend_x * hx * hx + c.bend_y * hy * hy) / 8;
    for (int y = y0; y < y0 + bh; y++)
      for (int x = x0; x < x0 + bw; x++) {
        vec3 d = c.dirs[(size_t)y * w + x];
        if (d.x == 0 && d.y == 0 && d.z == 0) continue;
        double fx = (x - x0) / hx, fy = (y - y0) / hy;
        double lin = (1 - fy) * ((1 - fx) * cv[0] + fx * cv[1]) + fy * ((1 - fx) * cv[2] + fx * cv[3]);
        double v = (double)n.x * d.x + (double)n.y * d.y + (double)n.z * d.z;
        tested++;
        bad += fabs(v - lin) > bend + 1e-5 * c.dir_len_max;
        if (bend > 0) worst = fmax(worst, fabs(v - lin) / bend);
      }
  }
  CHECK(bad == 0 && tested > 0, "%s: %ld of %ld samples beyond the bend bound", rr_camera_name(type), bad, tested);
  printf("%s %g: bend bound holds at %ld samples (at most %.2f of it used)\n", rr_camera_name(type), (double)fov,
         tested, worst);
  rr_cam_release(&c);
}

static void check_boxes(const rr_camera *rc, const camera *c);

/* rr_cam_cap_rect: every sample whose ray lies within the cap (short of the rays'
 * rounding) lies in the cap's rectangle; random caps of 1e-3 to 1.4 rad about
 * the maps' hard directions. */
static void check_caps(rr_device *dev, rr_camera_type type, float fov, int w, int h) {
  rr_camera rc;
  camera c;
  setup_at_random(dev, type, fov, w, h, &rc, &c);
  long bad = 0, inside = 0, bounded = 0;
  for (int k = 0; k < 600; k++) {
    vec3 a = v3_norm(hard_dir(&rc, c.fwd, c.right, c.up));
    double rho = exp(log(1e-3) + rnd() * (log(1.4) - log(1e-3))), axis[3] = {a.x, a.y, a.z};
    int r[4], got = rr_cam_cap_rect(&c, axis, rho, r);
    bounded += got >= 0;
    if (got < 0) continue;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        vec3 d = c.dirs[(size_t)y * w + x];
        double l = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
        if (!(l > 0)) continue;
        double cosang = (axis[0] * d.x + axis[1] * d.y + axis[2] * d.z) / l;
        if (cosang < cos(rho - 2e-6)) continue;
        inside++;
        bad += got == 0 || x < r[0] || x > r[2] || y < r[1] || y > r[3];
      }
  }
  CHECK(bad == 0 && inside > 0, "%s: %ld of %ld samples in a cap outside its rectangle", rr_camera_name(type), bad,
        inside);
  /* rr_cam_caps_show4: four caps at once, over two positions and a part of the
   * image, as rr_cam_cap_rect's rectangles say */
  camera two[2] = {c, c};
  two[1].sx0 = (float)rnd(), two[1].sy0 = (float)rnd();
  long lanes_diff = 0, shown = 0;
  for (int k = 0; k < 400; k++) {
    double axis[3][4], rho[4];
    for (int l = 0; l < 4; l++) {
      vec3 a = v3_norm(hard_dir(&rc, c.fwd, c.right, c.up));
      axis[0][l] = a.x, axis[1][l] = a.y, axis[2][l] = a.z, rho[l] = exp(log(1e-3) + rnd() * (log(1.4) - log(1e-3)));
    }
    const int x0 = (int)(rnd() * w), y0 = (int)(rnd() * h), part[4] = {x0, y0, x0 + 1 + (int)(rnd() * (w - x0)),
                                                                    y0 + 1 + (int)(rnd() * (h - y0))};
    const unsigned used = 1 + (unsigned)(rnd() * 15);
    const int ns = 1 + (k & 1);
    unsigned want = 0;
    for (int l = 0; l < 4; l++)
      for (int p = 0; p < ns && (used >> l & 1); p++) {
        int r[4], got = rr_cam_cap_rect(&two[p], (double[3]){axis[0][l], axis[1][l], axis[2][l]}, rho[l], r);
        if (got < 0 || (got > 0 && r[0] < part[2] && r[2] >= part[0] && r[1] < part[3] && r[3] >= part[1]))
          want |= 1u << l;
      }
    for (int simd = 0; simd < 2; simd++)
      lanes_diff += rr_cam_caps_show4(two, ns, (const double(*)[4])axis, rho, used, part, simd) != want;
    shown += __builtin_popcount(want);
  }
  CHECK(lanes_diff == 0 && shown > 0, "%s: rr_cam_caps_show4 differs from rr_cam_cap_rect %ld times",
        rr_camera_name(type), lanes_diff);
  check_boxes(&rc, &c);
  CHECK(bounded > 300, "%s: only %ld of 600 caps bounded", rr_camera_name(type), bounded);
  printf("%s %g: cap rectangles hold the %ld samples of %ld caps\n", rr_camera_name(type), (double)fov, inside,
         bounded);
  rr_cam_release(&c);
}

/* rr_cam_boxes_show4: every sample whose ray meets a random box (from the eye) is
 * shown, with the walk's shortcut and without; some boxes are dropped. */
static void check_boxes(const rr_camera *rc, const camera *cp) {
  const camera c = *cp;
  const int w = c.width, h = c.height;
  const rr_camera_type type = rc->type;
  const cam_cap_shortcut sc = rr_cam_cap_shortcut(&c);
  const int all[4] = {0, 0, w, h};
  long box_missed = 0, box_hit = 0, dropped = 0;
  for (int k = 0; k < 150; k++) {
    float lo[3][4], hi[3][4];
    for (int l = 0; l < 4; l++) {
      vec3 d = v3_norm(hard_dir(rc, c.fwd, c.right, c.up));
      const double dist = 0.5 + 5 * rnd(), size = dist * exp(log(1e-3) + rnd() * (log(0.5) - log(1e-3)));
      const float *e = &c.eye.x;
      for (int a = 0; a < 3; a++) {
        const double mid = e[a] + dist * (&d.x)[a], half = size * (0.2 + rnd());
        lo[a][l] = (float)(mid - half), hi[a][l] = (float)(mid + half);
      }
    }
    const unsigned show[2] = {rr_cam_boxes_show4(&c, 1, (const float(*)[4])lo, (const float(*)[4])hi, 15, NULL, all, true),
                              rr_cam_boxes_show4(&c, 1, (const float(*)[4])lo, (const float(*)[4])hi, 15, &sc, all, false)};
    dropped += 4 - __builtin_popcount(show[0]);
    for (int l = 0; l < 4; l++)
      for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
          vec3 d = c.dirs[(size_t)y * w + x];
          if (!(v3_len(d) > 0)) continue;
          double t0 = 0, t1 = INFINITY; /* the ray's slabs, in double */
          for (int a = 0; a < 3 && t0 <= t1; a++) {
            const double o = (&c.eye.x)[a], v = (&d.x)[a];
            if (v == 0) {
              if (o < lo[a][l] || o > hi[a][l]) t1 = -1;
              continue;
            }
            double ta = (lo[a][l] - o) / v, tb = (hi[a][l] - o) / v;
            t0 = fmax(t0, fmin(ta, tb)), t1 = fmin(t1, fmax(ta, tb));
          }
          if (!(t0 <= t1)) continue;
          box_hit++;
          box_missed += !(show[0] >> l & 1) + !(show[1] >> l & 1);
        }
  }
  CHECK(box_missed == 0 && box_hit > 0, "%s: %ld of %ld samples in boxes not shown", rr_camera_name(type), box_missed,
        box_hit);
  CHECK(dropped > 0, "%s: rr_cam_boxes_show4 dropped no box", rr_camera_name(type));
  printf("%s: boxes hold the %ld samples whose rays meet them, %ld of 600 dropped\n", rr_camera_name(type), box_hit,
         dropped);
}

int main(void) {
  rr_device *dev = rr_device_new();
  int ntri = test_quick() ? 150 : 1500;
  check_caps(dev, RR_CAMERA_PARABOLIC, 90, 96, 80);
  check_caps(dev, RR_CAMERA_LATLONG, 90, 128, 64);
  check_caps(dev, RR_CAMERA_FISHEYE, 180, 96, 96);
  check_caps(dev, RR_CAMERA_FISHEYE, 100, 80, 96);
  check_caps(dev, RR_CAMERA_FISHEYE, 360, 80, 64);
  for (int k = 0; k < 2; k++) { /* the OpenCV lenses' boxes, distorted as below */
    rr_camera rc;
    camera c;
    rr_camera_init(&rc);
    rc.type = k ? RR_CAMERA_OPENCV_FISHEYE : RR_CAMERA_OPENCV, rc.fov_deg = k ? 150 : 100;
    static const float brown[8] = {-0.3f, 0.08f, 0.002f, -0.001f, -0.01f}, kb[8] = {0.05f, -0.01f};
    memcpy(rc.dist, k ? kb : brown, sizeof brown);
    const float pos[2] = {(float)rnd(), (float)rnd()};
    CHECK(rr_cam_setup_at(dev, &rc, 96, 80, pos, &c) == RR_OK, "camera");
    check_boxes(&rc, &c);
    rr_cam_release(&c);
  }
  check_bend(dev, RR_CAMERA_PARABOLIC, 90, 96, 80);
  check_bend(dev, RR_CAMERA_LATLONG, 90, 128, 64);
  check_bend(dev, RR_CAMERA_FISHEYE, 180, 96, 96);
  check_bend(dev, RR_CAMERA_FISHEYE, 360, 80, 64);
  struct {
    rr_camera_type type;
    float fov;
    int w, h;
    const char *what;
  } cams[] = {
      {RR_CAMERA_LATLONG, 90, 128, 64, "latlong"},
      {RR_CAMERA_PARABOLIC, 90, 96, 80, "parabolic"},
      {RR_CAMERA_FISHEYE, 180, 96, 96, "fisheye 180"},
      {RR_CAMERA_FISHEYE, 100, 80, 96, "fisheye 100"},
      {RR_CAMERA_FISHEYE, 360, 96, 96, "fisheye 360"},
      {RR_CAMERA_CUBE, 90, 96, 72, "cube"},
      {RR_CAMERA_OPENCV_FISHEYE, 150, 96, 80, "opencv-fisheye"},
      {RR_CAMERA_OPENCV, 100, 96, 80, "opencv"},
      /* narrower: the field ends at the image's corners, not at the fold (rr_lens_field) */
      {RR_CAMERA_OPENCV_FISHEYE, 90, 96, 80, "opencv-fisheye 90"},
      {RR_CAMERA_OPENCV, 80, 96, 80, "opencv radial"},
  };
  for (size_t k = 0; k < sizeof cams / sizeof cams[0]; k++)
    for (int view = 0; view < 2; view++) {
      rr_camera rc;
      rr_camera_init(&rc);
      rc.type = cams[k].type, rc.fov_deg = cams[k].fov;
      vec3 eye = view ? v3(0.3f, -1.2f, 2.5f) : v3(0, 0, 0), target = view ? v3(1, 0.5f, -0.7f) : v3(0, 0, -1);
      vec3 up = view ? v3(0.2f, 1, 0.1f) : v3(0, 1, 0);
      memcpy(rc.eye, &eye, 12), memcpy(rc.target, &target, 12), memcpy(rc.up, &up, 12);
      if (rc.type == RR_CAMERA_OPENCV_FISHEYE) rc.dist[0] = 0.05f, rc.dist[1] = -0.01f;
      /* Brown–Conrady: strong barrel (folding back near the corners) with tangential terms */
      static const float brown[8] = {-0.3f, 0.08f, 0.002f, -0.001f, -0.01f};
      if (rc.type == RR_CAMERA_OPENCV) memcpy(rc.dist, brown, sizeof brown);
      if (strstr(cams[k].what, "radial")) rc.dist[2] = rc.dist[3] = 0; /* no tangential terms */
      char what[64];
      snprintf(what, sizeof what, "%s, view %d", cams[k].what, view);
      check_camera(dev, &rc, cams[k].w, cams[k].h, ntri, false, what);
      if (rc.type == RR_CAMERA_OPENCV || rc.type == RR_CAMERA_OPENCV_FISHEYE) { /* and small triangles ahead */
        snprintf(what, sizeof what, "%s ahead, view %d", cams[k].what, view);
        check_camera(dev, &rc, cams[k].w, cams[k].h, ntri, true, what);
      }
    }
  /* the chart's remainder is needed: without it, the linearisation misses samples */
  CHECK(flat_missed_all > 0, "the chart bounds without their remainder miss no sample");
  rr_device_release(dev);
  return test_done();
}
