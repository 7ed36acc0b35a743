/* rc and 3dr-bb visit (sample, triangle) pairs in opposite orders but call the same
 * sample test: their visibility buffers must be bit-identical, on built-in scenes
 * and on real meshes at random views (some from inside the mesh's bounds), with
 * 3dr-bb on 1, 2 and 8 threads. Also: the sort-middle methods on a scene of more
 * triangles than a batch, whose batches are drawn while the next one is set up. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

static void check_scene(rr_device *dev, const char *name, int views, int w, int h) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    return;
  }
  for (int v = 0; v < views; v++) {
    rr_camera cam = test_random_view(s, v % 3 == 0 ? 0.1f : 1.0f, v % 3 == 0 ? 0.9f : 3.0f, 0.3f, 30, 100);
    int cull = v % 2;
    rr_frame *a = test_render(dev, s, &cam, RR_METHOD_RC, 2, w, h, cull);
    if (!a) continue;
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_3DR_BB, opt.width = w, opt.height = h, opt.cull_backfaces = cull;
    char what[256];
    snprintf(what, sizeof what, "%s view %d", name, v);
    /* 3dr-bb on 1, 2 and 8 threads against rc, with the same S, E and N on each */
    rr_frame *b = test_render_threads(dev, s, &cam, &opt, a, what);
    if (b) {
      printf("%s: %d of %d samples hit\n", what, test_frame_hits(a), w * h);
      /* rc sets every triangle up; 3dr-bb only those whose screen bounds hold a
       * sample, once each whatever the thread count */
      CHECK(a->stats.setups == s->ntris, "rc: S = %llu, not every triangle once", (unsigned long long)a->stats.setups);
      CHECK(b->stats.setups <= s->ntris, "3dr-bb: S = %llu for %u triangles", (unsigned long long)b->stats.setups,
            s->ntris);
      CHECK(a->stats.edge_evals >= b->stats.edge_evals, "rc evaluates at least as often as 3dr-bb");
    }
    rr_frame_release(a), rr_frame_release(b);
  }
  rr_scene_release(s);
}

/* A teapot grid of 5² (158k triangles: two batches of the 3D root pass, ten of the
 * 2D pipeline's) on 1, 2 and 8 threads, near and far views: 3dr-bb and 3dr-bin
 * against rc-bvh, 2dr-bb and 2dr-bin against their frame on 1 thread, with the
 * same S and E on each. */
static void check_batches(rr_device *dev) {
  char name[1024];
  snprintf(name, sizeof name, "grid:%s/teapot.obj:5", RR_DATA_DIR);
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK || rr_scene_commit(s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    rr_scene_release(s);
    return;
  }
  CHECK(s->ntris > 131072, "the grid has %u triangles, fewer than a batch", s->ntris);
  const rr_method methods[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_2DR_BB, RR_METHOD_2DR_BIN};
  for (int v = 0; v < 3; v++) {
    rr_camera cam = test_random_view(s, v == 0 ? 0.3f : 1.5f, v == 0 ? 0.6f : 2.5f, 0.3f, 40, 70);
    /* tall: more 64-row blocks (10) than 2 threads have bands (8), so bands wrap */
    const int w = 64, h = 600, cull = v == 2;
    rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC_BVH, 2, w, h, cull);
    if (!ref) continue;
    for (size_t m = 0; m < sizeof methods / sizeof *methods; m++) {
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = methods[m], opt.width = w, opt.height = h, opt.cull_backfaces = cull;
      char what[256];
      snprintf(what, sizeof what, "teapot grid 5^2 view %d", v);
      const bool three_d = methods[m] == RR_METHOD_3DR_BB || methods[m] == RR_METHOD_3DR_BIN;
      rr_frame_release(test_render_threads(dev, s, &cam, &opt, three_d ? ref : NULL, what));
    }
    rr_frame_release(ref);
  }
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  check_scene(dev, "demo", 4, 96, 72);
  check_scene(dev, "sphere:24", 4, 64, 48);
  check_batches(dev);
  const char *meshes[] = {"suzanne.obj", "spot.obj", "stanford-bunny.obj", "ogre.obj", "nefertiti.obj"};
  for (int m = 0; m < (test_quick() ? 2 : 5); m++) {
    const char *p = test_model(meshes[m]);
    if (p) check_scene(dev, p, 3, 64, 48);
  }
  rr_device_release(dev);
  return test_done();
}
