/* bench_depth: the depth's accuracy, not its speed. For each scene (default: the
 * bunny and the teapot grid 19²), auto-framed at --size (default 512x512), in
 * perspective and with --ortho also orthographic: the relative error of every
 * method's t against the exact double-precision hit of each sample's ray with the
 * plane of the triangle it hit (rr_depth_errors; rays within |cos| < 1e-3 of the
 * plane aside), p50 / p99.9 / max, and Embree's rtcIntersect1 on the same rays
 * when the build has Embree.
 *
 *   bench_depth [SCENE...] [--size WxH] [--ortho] */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void row(const char *scene, const char *view, const char *who, const rr_depth_stats *st) {
  printf("| %s | %s | %s | %.2g / %.2g / %.2g |\n", scene, view, who, st->p50, st->p999, st->max);
}

static void measure(rr_device *dev, const char *name, int w, int h, bool ortho) {
  rr_scene *s = bench_load(dev, name, NULL);
  rr_camera cam;
  bench_view(dev, name, s, w, h, &cam);
  if (ortho) cam.type = RR_CAMERA_ORTHOGRAPHIC;
  camera c;
  if (rr_cam_setup(dev, &cam, w, h, &c) != RR_OK) {
    fprintf(stderr, "bench_depth: %s\n", rr_device_message(dev));
    exit(1);
  }
  const char *view = ortho ? "ortho" : "persp";
  static const rr_method methods[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB,
                                      RR_METHOD_3DR_FULL, RR_METHOD_2DR_BB};
  for (size_t m = 0; m < sizeof methods / sizeof *methods; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = methods[m], opt.width = w, opt.height = h;
    rr_frame *f = NULL;
    bench_render(dev, s, &cam, &opt, 1, &f);
    rr_depth_stats st;
    if (rr_depth_errors(s, &c, f->vb.id, f->vb.t, &st)) row(name, view, rr_method_name(methods[m]), &st);
    rr_frame_release(f);
  }
#ifdef RR_HAVE_EMBREE
  double build_ms;
  peer_embree *e = peer_embree_new(s, 1, 1, &build_ms);
  if (e && !ortho) { /* the peer casts from the eye: perspective only */
    size_t n = (size_t)w * h;
    uint32_t *ids = malloc(n * sizeof *ids);
    float *t = malloc(n * sizeof *t);
    rr_depth_stats st;
    if (ids && t) {
      peer_embree_cast(e, &c, 1, 1, ids, t);
      if (rr_depth_errors(s, &c, ids, t, &st)) row(name, view, "Embree rtcIntersect1", &st);
    }
    free(ids), free(t);
  }
  if (e) peer_embree_release(e);
#endif
  rr_cam_release(&c);
  rr_scene_release(s);
}

int main(int argc, char **argv) {
  int w = 512, h = 512, nscenes = 0;
  bool ortho = false;
  const char *scenes[16];
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (sscanf(argv[++i], "%dx%d", &w, &h) != 2 || w < 1 || h < 1) {
        fprintf(stderr, "bench_depth: bad --size '%s' (expected WxH)\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--ortho") == 0) {
      ortho = true;
    } else if (argv[i][0] == '-' || nscenes == 16) {
      fprintf(stderr, "usage: bench_depth [SCENE...] [--size WxH] [--ortho]\n");
      return 2;
    } else {
      scenes[nscenes++] = argv[i];
    }
  }
  if (!nscenes) scenes[nscenes++] = "stanford-bunny.obj", scenes[nscenes++] = "grid:teapot.obj:19";
  rr_device *dev = rr_device_new();
  printf("| scene | view | method | relative depth error p50 / p99.9 / max |\n|---|---|---|---|\n");
  for (int i = 0; i < nscenes; i++) {
    measure(dev, scenes[i], w, h, false);
    if (ortho) measure(dev, scenes[i], w, h, true);
  }
  rr_device_release(dev);
  return 0;
}
