/* Depth precision: every method's t at every hit pixel against the exact hit of
 * the pixel's ray with the plane of the triangle it hit, in double precision
 * (test_depth_errors), on random views of real meshes and built-in scenes,
 * perspective and orthographic, from outside and inside: p99.9 of the relative
 * error at most P999_BOUND_3D (2D pipeline: _2D) and its maximum at most 1e-4,
 * grazing rays (|cos| < 1e-3) aside. The homogeneous `ground` (a plane to the horizon, most of its samples at
 * small |cos|, where any float t errs by a few ulps over |cos|, Embree's too) is
 * held to the maximum and to the median instead of the 99.9th percentile.
 *
 * The 2D pipeline (2dr-bb, 2dr-bin) computes its depth its own way (projected,
 * clipped, interpolated) and is held to the same bounds; it refuses vertices at
 * infinity, so `ground` checks the 3D methods alone.
 *
 * An orthographic ray starts on the image plane, at a float origin whose rounding
 * (2^-24 of its coordinates) is the whole of a tiny t: from inside a scene the
 * plane cuts surfaces, and hits a hundredth of the scene's radius or closer measure
 * that rounding, not the method (for any float ray caster, Embree's too: on
 * nefertiti, radius 329, their p99.9 reached 1e-6 and a 2D hit at t = 6.6e-7 erred
 * by 1, i.e. by 3e-7 absolute). They are left out of the orthographic statistics. */
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

/* The target is "p99.9 no worse than Embree's on the same view". Embree does
 * not run here; on bench_depth's views (bunny, ogre, nefertiti, teapot grid 19²,
 * perspective and orthographic, 1024², docs/depth.md) its rtcIntersect1 reached
 * p99.9 2.5e-7 (nefertiti, perspective) to 5.9e-7 (the grid), the 3D methods
 * 1.6e-7 to 1.9e-7 and the 2D pipeline 6.9e-8 to 1.6e-7. The 3D methods are held
 * to Embree's best figure, the 2D pipeline to below its worst (here its own worst is
 * 4.8e-7, rooms:4 view 1, from inside; the 3D methods' 1.8e-7). */
#define P999_BOUND_3D 2.5e-7
#define P999_BOUND_2D 5e-7
#define MEDIAN_BOUND 1e-6 /* ground */
#define MAX_BOUND 1e-4

static const rr_method methods[] = {RR_METHOD_RC,      RR_METHOD_RC_BVH,  RR_METHOD_RC_PACKET, RR_METHOD_2DR_BB,
                                    RR_METHOD_2DR_BIN, RR_METHOD_3DR_BB,  RR_METHOD_3DR_BIN,   RR_METHOD_3DR_FC,
                                    RR_METHOD_3DR_FS,  RR_METHOD_3DR_FULL};

/* Views 0..3 of a scene: perspective from outside, perspective from inside,
 * orthographic from outside (back faces culled), orthographic from inside. Every
 * view is drawn whether checked or not, so view v is the same in every run. */
enum { VIEW_ALL = 0xF, VIEW_QUICK = 1 << 0 | 1 << 3 };

/* rr_depth_errors of frame f for camera cam, leaving out (orthographic) hits nearer
 * than near to the image plane. */
static bool depth_errors(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f, float near,
                         test_depth_stats *st) {
  size_t n = (size_t)f->vb.width * f->vb.height;
  uint32_t *ids = malloc(n * sizeof *ids);
  camera c;
  bool ok = ids && rr_cam_setup(dev, cam, f->vb.width, f->vb.height, &c) == RR_OK;
  if (ok) {
    for (size_t k = 0; k < n; k++) ids[k] = f->vb.t[k] < near ? RR_MISS : f->vb.id[k];
    ok = rr_depth_errors(s, &c, ids, f->vb.t, st);
    rr_cam_release(&c);
  }
  free(ids);
  return ok;
}

static void check_scene(rr_device *dev, const char *name, unsigned views, int size, bool grazing) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "%s: %s", name, rr_device_message(dev));
    return;
  }
  for (int v = 0; v < 4; v++) {
    bool inside = v % 2 == 1, ortho = v >= 2;
    rr_camera cam = test_random_view(s, inside ? 0.2f : 1.2f, inside ? 0.6f : 2.5f, 0.3f, 30, 90);
    if (!(views >> v & 1u)) continue;
    if (ortho) cam.type = RR_CAMERA_ORTHOGRAPHIC;
    float near = ortho ? 0.01f * 0.5f * v3_len(v3_sub(s->bmax, s->bmin)) : 0;
    double worst3d = 0, worst2d = 0;
    for (size_t m = 0; m < sizeof methods / sizeof *methods; m++) {
      bool is2d = methods[m] == RR_METHOD_2DR_BB || methods[m] == RR_METHOD_2DR_BIN;
      if (methods[m] == RR_METHOD_RC && s->ntris > 5000) continue; /* O(pixels × triangles) */
      if (is2d && grazing) continue;                                 /* vertices at infinity */
      rr_frame *f = test_render(dev, s, &cam, methods[m], 2, size, size, v == 2);
      if (!f) continue;
      test_depth_stats st;
      if (!depth_errors(dev, s, &cam, f, near, &st)) {
        CHECK(0, "%s view %d: no camera", name, v);
      } else {
        const char *mname = rr_method_name(methods[m]);
        double *worst = is2d ? &worst2d : &worst3d;
        if (st.p999 > *worst) *worst = st.p999;
        if (methods[m] == RR_METHOD_RC_BVH || methods[m] == RR_METHOD_2DR_BB)
          printf("%s view %d (%s, %s) %s: %d hits, rel. error p50 %.2g p99.9 %.2g max %.2g\n", name, v,
                 ortho ? "ortho" : "persp", inside ? "inside" : "outside", mname, st.n, st.p50, st.p999, st.max);
        if (grazing)
          CHECK(st.p50 <= MEDIAN_BOUND, "%s view %d %s: median relative depth error %.3g", name, v, mname, st.p50);
        else
          CHECK(st.p999 <= (is2d ? P999_BOUND_2D : P999_BOUND_3D), "%s view %d %s: p99.9 relative depth error %.3g",
                name, v, mname, st.p999);
        CHECK(st.max <= MAX_BOUND, "%s view %d %s: max relative depth error %.3g at pixel %d", name, v, mname,
              st.max, st.worst);
      }
      rr_frame_release(f);
    }
    printf("%s view %d: worst p99.9 of the 3D methods %.2g, of the 2D pipeline %.2g\n", name, v, worst3d, worst2d);
  }
  rr_scene_release(s);
}

int main(void) {
  const char *bunny = test_model("stanford-bunny.obj"), *nef = test_model("nefertiti.obj"),
             *ogre = test_model("ogre.obj");
  if (!bunny || !nef || !ogre) {
    test_skip("shared models absent");
    return test_done();
  }
  rr_device *dev = rr_device_new();
  bool quick = test_quick();
  unsigned views = quick ? VIEW_QUICK : VIEW_ALL;
  check_scene(dev, "rooms:4", views, 256, false);
  check_scene(dev, "ground:inf", views, 128, true);
  char grid[1024];
  snprintf(grid, sizeof grid, "grid:%s/teapot.obj:3", RR_DATA_DIR);
  check_scene(dev, grid, views, 256, false);
  check_scene(dev, bunny, views, 256, false);
  if (!quick) {
    check_scene(dev, nef, VIEW_ALL, 256, false);
    check_scene(dev, ogre, VIEW_ALL, 256, false); /* 4 degenerate faces: a shifted id would look up another plane */
  }
  rr_device_release(dev);
  return test_done();
}
