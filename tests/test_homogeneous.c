/* Homogeneous input (paper appendix): vertices at infinity (w = 0). The built-in
 * `ground` (an infinite plane of four triangles fanning from the origin to the
 * points at infinity ±x, ±z, plus a sphere and a box) is rendered by every 3D
 * method with every camera from several views: bit-identical to rc on 1, 2 and 8
 * threads, and close to an independent reference, rays of the camera cast in
 * double precision against the analytic plane y = 0 and the objects' triangles.
 * Also: rr_scene_add_mesh4 (dehomogenisation, three corners at infinity skipped),
 * rr_intersect, and the 2D methods' refusal. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

static const rr_method METHODS[] = {RR_METHOD_RC,     RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET,
                                    RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC,
                                    RR_METHOD_3DR_FS, RR_METHOD_3DR_FULL};
enum { NMETHODS = sizeof METHODS / sizeof METHODS[0] };

/* Möller–Trumbore in double, both faces; t > 0. */
static bool tri_hit_d(const double o[3], const double d[3], const double p[3][3], double *t) {
  double e1[3], e2[3], pv[3], tv[3], qv[3];
  for (int a = 0; a < 3; a++) e1[a] = p[1][a] - p[0][a], e2[a] = p[2][a] - p[0][a], tv[a] = o[a] - p[0][a];
  pv[0] = d[1] * e2[2] - d[2] * e2[1], pv[1] = d[2] * e2[0] - d[0] * e2[2], pv[2] = d[0] * e2[1] - d[1] * e2[0];
  double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
  if (det == 0) return false;
  double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
  if (u < 0 || u > 1) return false;
  qv[0] = tv[1] * e1[2] - tv[2] * e1[1], qv[1] = tv[2] * e1[0] - tv[0] * e1[2], qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
  double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
  if (v < 0 || u + v > 1) return false;
  *t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
  return *t > 0;
}

/* The reference: nearest hit of the ray on the plane y = 0 (triangles 0..3 by
 * quadrant) or on the finite triangles [nplane, ntris). */
static uint32_t reference(const rr_scene *s, uint32_t nplane, vec3 of, vec3 df, double *tbest) {
  double o[3] = {of.x, of.y, of.z}, d[3] = {df.x, df.y, df.z};
  uint32_t best = RR_MISS;
  *tbest = INFINITY;
  if (d[1] != 0) {
    double t = -o[1] / d[1];
    if (t > 0) {
      double x = o[0] + t * d[0], z = o[2] + t * d[2];
      *tbest = t;
      best = x > 0 ? (z < 0 ? 0 : 3) : (z < 0 ? 1 : 2);
    }
  }
  for (uint32_t i = nplane; i < s->ntris; i++) {
    double p[3][3], t;
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) p[k][a] = s->p[k][a][i];
    if (tri_hit_d(o, d, p, &t) && t < *tbest) *tbest = t, best = i;
  }
  return best;
}

/* Compares a frame with the reference; returns the disagreeing samples and
 * counts the samples with a ray and the plane hits. */
static int against_reference(rr_device *dev, const rr_scene *s, uint32_t nplane, const rr_camera *rc,
                             const rr_frame *f, int *rays, int *plane_hits, double *worst_near) {
  camera c;
  if (rr_cam_setup(dev, rc, f->vb.width, f->vb.height, &c) != RR_OK) {
    CHECK(0, "rr_cam_setup: %s", rr_device_message(dev));
    return -1;
  }
  int bad = 0;
  for (int y = 0; y < f->vb.height; y++)
    for (int x = 0; x < f->vb.width; x++) {
      size_t k = (size_t)y * f->vb.width + x;
      vec3 o, d;
      if (!rr_cam_ray(&c, x, y, &o, &d)) {
        bad += f->vb.id[k] != RR_MISS;
        continue;
      }
      (*rays)++;
      double t;
      uint32_t id = reference(s, nplane, o, d, &t);
      uint32_t got = f->vb.id[k];
      if (id != got) {
        bad++;
        continue;
      }
      if (id < nplane) {
        (*plane_hits)++;
        double rel = fabs(f->vb.t[k] - t) / t;
        if (rel > 1e-4) bad++;
        /* away from the horizon the depth is as good as float allows */
        if (t * v3_len(d) < 50 && rel > *worst_near) *worst_near = rel;
      }
    }
  rr_cam_release(&c);
  return bad;
}

typedef struct view {
  const char *what;
  float eye[3], target[3], up[3];
} view;

static void check_views(rr_device *dev, const rr_scene *s, uint32_t nplane, const char *name) {
  const view views[] = {
      {"above", {3.1f, 1.7f, 5.3f}, {0.2f, 0.4f, -0.3f}, {0, 1, 0}},
      {"horizon", {0.7f, 0.6f, 6.2f}, {-0.3f, 0.55f, -4.0f}, {0, 1, 0}},
      {"below", {1.3f, -1.2f, 4.1f}, {0.1f, 0.3f, 0.05f}, {0, 1, 0}},
      {"overhead", {0.37f, 9.0f, 0.53f}, {0.01f, 0.0f, 0.02f}, {0, 0, -1}},
  };
  const int W = 64, H = 48;
  for (size_t v = 0; v < sizeof views / sizeof views[0]; v++)
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      rr_camera cam;
      rr_camera_init(&cam);
      cam.type = (rr_camera_type)type;
      memcpy(cam.eye, views[v].eye, 12), memcpy(cam.target, views[v].target, 12), memcpy(cam.up, views[v].up, 12);
      cam.fov_deg = type == RR_CAMERA_FISHEYE ? 200.0f : 60.0f;
      if (type == RR_CAMERA_ORTHOGRAPHIC) cam.ortho_height = 6.0f;
      const char *cname = rr_camera_name(type);
      rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC, 1, W, H, 0);
      if (!ref) continue;
      char what[256];
      snprintf(what, sizeof what, "%s %s %s", name, views[v].what, cname);
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.width = W, opt.height = H;
      for (int m = 1; m < NMETHODS; m++) {
        opt.method = METHODS[m];
        rr_frame_release(test_render_threads(dev, s, &cam, &opt, ref, what));
      }
      int rays = 0, plane = 0;
      double worst = 0;
      int bad = against_reference(dev, s, nplane, &cam, ref, &rays, &plane, &worst);
      printf("%s %s %s: %d rays, %d on the plane, %d disagree with the double reference, near depth error %.2g\n",
             name, views[v].what, cname, rays, plane, bad, worst);
      CHECK(bad >= 0 && bad * 1000 <= rays, "%s %s %s: %d of %d samples disagree with the reference", name,
            views[v].what, cname, bad, rays);
      CHECK(worst < 1e-5, "%s %s %s: depth error %g away from the horizon", name, views[v].what, cname, worst);
      if (strcmp(views[v].what, "below") != 0 || type != RR_CAMERA_PERSPECTIVE)
        CHECK(plane > 0, "%s %s %s: the plane is seen", name, views[v].what, cname);
      rr_frame_release(ref);
    }
}

/* The reference for check_api's scene: the plane y = 0 (ids 0..3 by quadrant) and
 * triangle 5 (id 5: the skipped triangle 4 keeps its id), the corner (1, 2, 3) with
 * directions +x and -z: the quarter of the plane y = 2 where x >= 1 and z <= 3. */
static uint32_t reference_api(vec3 of, vec3 df, double *tbest) {
  double o[3] = {of.x, of.y, of.z}, d[3] = {df.x, df.y, df.z};
  uint32_t best = RR_MISS;
  *tbest = INFINITY;
  if (d[1] == 0) return best;
  double t = -o[1] / d[1], t2 = (2 - o[1]) / d[1];
  if (t > 0) {
    double x = o[0] + t * d[0], z = o[2] + t * d[2];
    *tbest = t, best = x > 0 ? (z < 0 ? 0 : 3) : (z < 0 ? 1 : 2);
  }
  if (t2 > 0 && t2 < *tbest && o[0] + t2 * d[0] > 1 && o[2] + t2 * d[2] < 3) *tbest = t2, best = 5;
  return best;
}

/* The public API: the same plane through rr_scene_add_mesh4 with a scaled w. */
static void check_api(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new scene");
  const float v[] = {0, 0, 0, 2.5f, 1, 0, 0, 0, 0, 0, -1, 0, -1, 0, 0, 0, 0, 0, 1, 0,
                     /* a box corner and a triangle with three corners at infinity */
                     2, 4, 6, 2};
  const uint32_t idx[] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 1, 2, 3, 5, 1, 2};
  CHECK(rr_scene_add_mesh4(s, v, 6, idx, 6, NULL) == RR_OK, "add_mesh4: %s", rr_device_message(dev));
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  CHECK(info.triangles == 5 && info.skipped == 1, "5 kept, 1 skipped (all at infinity): %llu, %llu",
        (unsigned long long)info.triangles, (unsigned long long)info.skipped);
  CHECK(s->p[0][0][4] == 1 && s->p[0][1][4] == 2 && s->p[0][2][4] == 3, "w != 0 is divided out");
  CHECK(s->p[1][0][4] == 1 && s->p[1][1][4] == 0 && scene_inf(s, 4) == 6u, "w = 0 is a direction");
  uint32_t bad_idx[] = {0, 1, 9};
  CHECK(rr_scene_add_mesh4(s, v, 6, bad_idx, 1, NULL) == RR_ERROR_ARGUMENT, "index out of range");
  CHECK(rr_scene_commit(s) == RR_OK, "commit: %s", rr_device_message(dev));

  /* rr_intersect against the analytic plane, both sides */
  int agree = 0, n = 0;
  for (int r = 0; r < 400; r++) {
    rr_ray ray = {{test_randf(-3, 3), test_randf(-2, 2), test_randf(-3, 3)},
                  {test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)},
                  0,
                  INFINITY};
    rr_hit hit;
    CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK, "rr_intersect");
    double t;
    uint32_t id = reference_api(v3_load(ray.org), v3_load(ray.dir), &t);
    n++;
    agree += id == hit.prim && (id == RR_MISS || fabs(hit.t - t) <= 1e-4 * t);
  }
  CHECK(agree >= n - 2, "rr_intersect agrees with the reference on %d of %d rays", agree, n);

  rr_camera cam;
  rr_camera_init(&cam);
  float eye[3] = {1.1f, 2.0f, 3.3f}, target[3] = {0, 0, 0};
  memcpy(cam.eye, eye, 12), memcpy(cam.target, target, 12);
  rr_frame *a = test_render(dev, s, &cam, RR_METHOD_RC, 1, 48, 32, 0);
  rr_frame *b = test_render(dev, s, &cam, RR_METHOD_3DR_BIN, 2, 48, 32, 0);
  if (a && b) CHECK(test_frames_differ(a, b) == 0, "add_mesh4 scene: 3dr-bin equals rc");
  rr_frame_release(a), rr_frame_release(b);

  /* 2D rasterization cannot take points at infinity, and says so */
  for (int m = RR_METHOD_2DR_BB; m <= RR_METHOD_2DR_BIN; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = (rr_method)m, opt.width = 16, opt.height = 16;
    rr_frame *f = NULL;
    rr_error e = rr_render(dev, s, &cam, &opt, &f);
    CHECK(e == RR_ERROR_UNSUPPORTED && strstr(rr_device_message(dev), "3dr-bb"), "%s refuses: %s",
          rr_method_name((rr_method)m), rr_device_message(dev));
    rr_frame_release(f);
  }
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s = NULL;
  if (rr_scene_load(dev, "ground:inf", &s) != RR_OK) {
    CHECK(0, "load ground: %s", rr_device_message(dev));
  } else {
    CHECK(s->inf && scene_inf(s, 0) == 6u && s->ntris > 4, "ground: four triangles with corners at infinity first");
    CHECK(s->bmax.x < 10 && s->bmin.z > -10, "bounds hold the finite corners only");
    check_views(dev, s, 4, "ground:inf");
    rr_scene_release(s);
  }
  check_api(dev);
  rr_device_release(dev);
  return test_done();
}
