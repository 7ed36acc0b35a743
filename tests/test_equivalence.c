/* rc and 3dr-bb visit (sample, triangle) pairs in opposite orders but call the same
 * sample test: their visibility buffers must be bit-identical, on built-in scenes
 * and on real meshes at random views (some from inside the mesh's bounds), with
 * 3dr-bb on 1, 2 and 8 threads. */
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

int main(void) {
  rr_device *dev = rr_device_new();
  check_scene(dev, "demo", 4, 96, 72);
  check_scene(dev, "sphere:24", 4, 64, 48);
  const char *meshes[] = {"suzanne.obj", "spot.obj", "stanford-bunny.obj", "ogre.obj", "nefertiti.obj"};
  for (int m = 0; m < (test_quick() ? 2 : 5); m++) {
    const char *p = test_model(meshes[m]);
    if (p) check_scene(dev, p, 3, 64, 48);
  }
  rr_device_release(dev);
  return test_done();
}
