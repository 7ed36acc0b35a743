/* rc and 3dr-bb visit (sample, triangle) pairs in opposite orders but call the same
 * sample test: their visibility buffers must be bit-identical, on built-in scenes
 * and on real meshes at random views (some from inside the mesh's bounds). */
#include "rr.h"
#include "testutil.h"

#include <string.h>

static int compare(const rr_frame *a, const rr_frame *b, int *ndiff) {
  size_t n = (size_t)a->vb.width * a->vb.height;
  int d = 0, hits = 0;
  for (size_t k = 0; k < n; k++) {
    d += a->vb.id[k] != b->vb.id[k] || memcmp(&a->vb.t[k], &b->vb.t[k], 4) || memcmp(&a->vb.l1[k], &b->vb.l1[k], 4) ||
         memcmp(&a->vb.l2[k], &b->vb.l2[k], 4);
    hits += a->vb.id[k] != RR_MISS;
  }
  *ndiff = d;
  return hits;
}

static rr_frame *render(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int threads,
                        int w, int h, int cull) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = w, opt.height = h, opt.threads = threads, opt.cull_backfaces = cull;
  rr_frame *f = NULL;
  rr_error e = rr_render(dev, s, cam, &opt, &f);
  CHECK(e == RR_OK, "render: %s", rr_device_message(dev));
  return f;
}

static void random_view(const rr_scene *s, rr_camera *cam, float dist_lo, float dist_hi) {
  rr_camera_init(cam);
  vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
  float r = 0.5f * v3_len(v3_sub(s->bmax, s->bmin));
  vec3 dir = v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)));
  vec3 eye = v3_add(c, v3_scale(dir, r * test_randf(dist_lo, dist_hi)));
  vec3 target = v3_add(c, v3_scale(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)), 0.3f * r));
  memcpy(cam->eye, &eye, 12), memcpy(cam->target, &target, 12);
  cam->fov_deg = test_randf(30, 100);
}

static void check_scene(rr_device *dev, const char *name, int views, int w, int h) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    return;
  }
  for (int v = 0; v < views; v++) {
    rr_camera cam;
    random_view(s, &cam, v % 3 == 0 ? 0.1f : 1.0f, v % 3 == 0 ? 0.9f : 3.0f);
    int cull = v % 2;
    rr_frame *a = render(dev, s, &cam, RR_METHOD_RC, 2, w, h, cull);
    rr_frame *b = render(dev, s, &cam, RR_METHOD_3DR_BB, 1, w, h, cull);
    rr_frame *c = render(dev, s, &cam, RR_METHOD_3DR_BB, 2, w, h, cull);
    if (a && b && c) {
      int d1, d2;
      int hits = compare(a, b, &d1);
      compare(b, c, &d2);
      printf("%s view %d: %d of %d samples hit\n", name, v, hits, w * h);
      CHECK(d1 == 0, "%s view %d: rc and 3dr-bb differ at %d samples", name, v, d1);
      CHECK(d2 == 0, "%s view %d: 3dr-bb on 1 and 2 threads differs at %d samples", name, v, d2);
      /* rc sets every triangle up; 3dr-bb only those whose screen bounds hold a
       * sample, once each whatever the thread count */
      CHECK(a->stats.setups == s->ntris, "rc: S = %llu, not every triangle once", (unsigned long long)a->stats.setups);
      CHECK(b->stats.setups <= s->ntris && b->stats.setups == c->stats.setups,
            "3dr-bb: S = %llu on 1 thread, %llu on 2, for %u triangles", (unsigned long long)b->stats.setups,
            (unsigned long long)c->stats.setups, s->ntris);
      CHECK(a->stats.edge_evals >= b->stats.edge_evals, "rc evaluates at least as often as 3dr-bb");
    }
    rr_frame_release(a), rr_frame_release(b), rr_frame_release(c);
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
