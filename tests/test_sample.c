/* The one sample test against a double-precision reference on random triangles
 * and rays: hit/miss away from edges, t and barycentrics to a tight tolerance. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

typedef struct { double x, y, z; } dvec;
static dvec dv(vec3 a) { return (dvec){a.x, a.y, a.z}; }
static dvec dsub(dvec a, dvec b) { return (dvec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dvec dcross(dvec a, dvec b) { return (dvec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static vec3 rand_v(float r) { return v3(test_randf(-r, r), test_randf(-r, r), test_randf(-r, r)); }

int main(void) {
  rr_device *dev = rr_device_new();
  int hits = 0, misses = 0, compared = 0;
  for (int iter = 0; iter < 20000; iter++) {
    rr_scene *s;
    rr_scene_new(dev, &s);
    vec3 p[3] = {rand_v(2), rand_v(2), rand_v(2)};
    if (!rr_scene_push(s, p, NULL, NULL, 0)) {
      rr_scene_release(s);
      continue;
    }
    rr_camera rc;
    rr_camera_init(&rc);
    vec3 eye = v3_add(rand_v(1), v3(0, 0, 5)), target = v3_scale(rand_v(1), 0.5f);
    rc.eye[0] = eye.x, rc.eye[1] = eye.y, rc.eye[2] = eye.z;
    rc.target[0] = target.x, rc.target[1] = target.y, rc.target[2] = target.z;
    rc.fov_deg = test_randf(20, 90);
    camera c;
    if (rr_cam_setup(dev, &rc, 64, 48, &c) != RR_OK) {
      rr_scene_release(s);
      continue;
    }
    tri_setup ts;
    int face = rr_tri_setup(s, 0, &c, false, &ts);
    for (int k = 0; k < 8; k++) {
      float sx = test_randf(0, 64), sy = test_randf(0, 48);
      /* reference: the same ray in double precision (Cramer's rule) */
      dvec d = {(double)c.d0.x + sx * (double)c.dx.x + sy * (double)c.dy.x,
                (double)c.d0.y + sx * (double)c.dx.y + sy * (double)c.dy.y,
                (double)c.d0.z + sx * (double)c.dx.z + sy * (double)c.dy.z};
      dvec o = dv(c.eye), a = dv(p[0]), e1 = dsub(dv(p[1]), a), e2 = dsub(dv(p[2]), a);
      dvec pv = dcross(d, e2);
      double det = ddot(e1, pv);
      if (fabs(det) < 1e-9) continue;
      dvec tv = dsub(o, a);
      double u = ddot(tv, pv) / det;
      dvec qv = dcross(tv, e1);
      double v = ddot(d, qv) / det, t = ddot(e2, qv) / det;
      double margin = fmin(fmin(u, v), 1 - u - v);
      bool ref_hit = margin > 0 && t > 0;
      if (fabs(margin) < 1e-4 || fabs(t) < 1e-4) continue; /* too close to call */
      float ft = 0, l1 = 0, l2 = 0;
      float ev[3];
      bool hit = false;
      if (face != SETUP_CULLED) {
        tri_edges(&ts, sx, sy, ev);
        hit = sample_test(&ts, ev, sx, sy, &ft, &l1, &l2);
      }
      CHECK(hit == ref_hit, "iter %d sample (%g,%g): hit %d, reference %d (margin %g, t %g)", iter, sx, sy, hit,
            ref_hit, margin, t);
      if (hit && ref_hit) {
        hits++;
        compared++;
        double tol = 1e-4;
        CHECK(fabs(ft - t) <= tol * fabs(t), "t %g vs %g", ft, t);
        CHECK(fabs(l1 - u) <= tol && fabs(l2 - v) <= tol, "barycentrics (%g,%g) vs (%g,%g)", l1, l2, u, v);
      } else if (!ref_hit) {
        misses++;
      }
    }
    rr_scene_release(s);
  }
  printf("compared %d hits, %d misses\n", compared, misses);
  CHECK(hits > 1000 && misses > 1000, "too few cases: %d hits, %d misses", hits, misses);

  /* Front faces: counter-clockwise as seen from the eye. */
  rr_scene *s;
  rr_scene_new(dev, &s);
  vec3 p[3] = {v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
  rr_scene_push(s, p, NULL, NULL, 0);
  rr_camera rc;
  rr_camera_init(&rc);
  camera c;
  rr_cam_setup(dev, &rc, 8, 8, &c);
  tri_setup ts;
  CHECK(rr_tri_setup(s, 0, &c, false, &ts) == SETUP_FRONT, "CCW triangle seen from +z is a front face");
  CHECK(rr_tri_setup(s, 0, &c, true, &ts) == SETUP_FRONT, "front faces survive culling");
  rc.eye[2] = -3;
  rr_cam_setup(dev, &rc, 8, 8, &c);
  CHECK(rr_tri_setup(s, 0, &c, false, &ts) == SETUP_BACK, "seen from -z it is a back face");
  CHECK(rr_tri_setup(s, 0, &c, true, &ts) == SETUP_CULLED, "back faces are culled on request");
  rr_scene_release(s);
  rr_device_release(dev);
  return test_done();
}
