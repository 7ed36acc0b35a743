/* The threading contract (rastray.h): devices share nothing, so threads that each
 * have their own device may load, commit, render (with threads of their own) and
 * shade at the same time; and a committed scene may be traced by several threads
 * at once. Every result must equal the one computed alone. The thread-sanitizer
 * build (RR_TSAN, scripts/test.sh) runs this test to find the races the results
 * do not show. */
#include "testutil.h"

#include <pthread.h>
#include <string.h>

enum { WORKERS = 4, TRACERS = 4, NRAYS = 2000, W = 80, H = 60 };

/* Heat maps are drawn for images of at least 64 pixels across (with their legends). */
static const rr_method methods[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_2DR_BIN,
                                    RR_METHOD_3DR_BB, RR_METHOD_3DR_FC,    RR_METHOD_3DR_FULL};
enum { NMETHODS = sizeof methods / sizeof *methods };

static uint64_t mix_bytes(uint64_t h, const void *p, size_t n) {
  for (size_t i = 0; i < n; i++) h = (h ^ ((const uint8_t *)p)[i]) * 0x100000001B3ull;
  return h;
}

/* ---- one device per thread ------------------------------------------------------ */

typedef struct {
  const char *scene;
  int rounds;
  uint64_t print;   /* of the visibility buffers and the shaded images, heat maps aside */
  rr_error error;   /* the first failure, with its message */
  char message[512];
} device_work;

static pthread_barrier_t start;

static rr_error fail(device_work *w, rr_device *dev, rr_error e) {
  if (e && !w->error) w->error = e, snprintf(w->message, sizeof w->message, "%s", rr_device_message(dev));
  return e;
}

/* Loads the scene, renders it with every method on two threads from a planar, a
 * curved and a cube camera (whose faces the frustum methods draw at once, sharing
 * each triangle's eye part across the threads), and shades every frame in every
 * mode. */
static uint64_t render_all(device_work *w, rr_device *dev) {
  uint64_t h = 0xcbf29ce484222325ull;
  rr_scene *s;
  if (fail(w, dev, rr_scene_load(dev, w->scene, &s))) return 0;
  rr_camera cam;
  rr_camera_init(&cam);
  if (fail(w, dev, rr_camera_frame(dev, s, W, H, &cam))) goto done;
  for (int kind = 0; kind < 3; kind++) {
    if (kind) cam.type = kind == 1 ? RR_CAMERA_FISHEYE : RR_CAMERA_CUBE, cam.fov_deg = kind == 1 ? 180 : 90;
    for (int m = 0; m < NMETHODS; m++) {
      if (methods[m] == RR_METHOD_2DR_BIN && (kind || s->inf)) continue; /* planar, finite only */
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = methods[m], opt.width = W, opt.height = H, opt.threads = 2, opt.heat = 1;
      rr_frame *f;
      if (fail(w, dev, rr_render(dev, s, &cam, &opt, &f))) goto done;
      h = mix_bytes(h, f->vb.id, sizeof *f->vb.id * W * H);
      h = mix_bytes(h, f->vb.t, sizeof *f->vb.t * W * H);
      for (int mode = 0; mode < RR_SHADE_COUNT; mode++) {
        rr_image img;
        if (fail(w, dev, rr_shade(dev, s, &cam, f, (rr_shade_mode)mode, &img))) break;
        /* heat maps count work, which need not be the same from run to run */
        if (mode != RR_SHADE_HEAT_EVALS && mode != RR_SHADE_HEAT_NODES)
          h = mix_bytes(h, img.data, sizeof(float) * 3 * W * H);
        rr_image_free(&img);
      }
      rr_frame_release(f);
    }
  }
done:
  rr_scene_release(s);
  return h;
}

static void *device_thread(void *arg) {
  device_work *w = arg;
  rr_device *dev = rr_device_new();
  rr_build_options b;
  rr_build_options_init(&b);
  b.threads = 2;
  rr_device_set_build_options(dev, &b);
  pthread_barrier_wait(&start);
  for (int r = 0; r < w->rounds && !w->error; r++) {
    uint64_t h = render_all(w, dev);
    if (!w->error && h != w->print)
      w->error = RR_ERROR_ARGUMENT, snprintf(w->message, sizeof w->message, "round %d gave other results", r);
  }
  rr_device_release(dev);
  return NULL;
}

/* ---- one scene, many tracing threads -------------------------------------------- */

/* The answers for one ray: a bad ray is refused by both calls. */
typedef struct {
  rr_error error;
  rr_hit hit;
  int occluded;
} answer;

/* Each thread queries with its own device (the threading contract of rastray.h). */
static answer trace(rr_device *dev, const rr_scene *s, const rr_ray *ray) {
  answer a;
  memset(&a, 0, sizeof a);
  a.error = rr_intersect(dev, s, ray, &a.hit);
  rr_error e = rr_occluded(dev, s, ray, &a.occluded);
  if (e != a.error) a.error = RR_ERROR_UNSUPPORTED; /* the two calls disagree: never what it was alone */
  return a;
}

typedef struct {
  const rr_scene *scene;
  const rr_ray *rays;
  const answer *alone;
  int wrong; /* rays whose answers differ from those found alone */
} trace_work;

static void *trace_thread(void *arg) {
  trace_work *w = arg;
  rr_device *dev = rr_device_new();
  pthread_barrier_wait(&start);
  for (int i = 0; i < NRAYS; i++) {
    answer a = trace(dev, w->scene, &w->rays[i]);
    w->wrong += memcmp(&a, &w->alone[i], sizeof a) != 0;
  }
  rr_device_release(dev);
  return NULL;
}

static void shared_scene(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s;
  if (rr_scene_load(dev, "demo", &s) != RR_OK) {
    CHECK(0, "load demo: %s", rr_device_message(dev));
    rr_device_release(dev);
    return;
  }
  static rr_ray rays[NRAYS];
  static answer alone[NRAYS];
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  int refused = 0;
  for (int i = 0; i < NRAYS; i++) {
    /* from around the scene towards points in it; half end early, and a few have
     * no direction, which both calls refuse (with a message in the caller's device) */
    rr_ray *r = &rays[i];
    for (int a = 0; a < 3; a++) {
      float lo = info.bounds_min[a], hi = info.bounds_max[a], pad = hi - lo;
      r->org[a] = test_randf(lo - pad, hi + pad);
      r->dir[a] = i % 50 == 7 ? 0 : test_randf(lo, hi) - r->org[a];
    }
    r->tmin = 0, r->tmax = i % 2 ? 0.5f : INFINITY;
    alone[i] = trace(dev, s, r);
    refused += alone[i].error != RR_OK;
    CHECK(alone[i].error == (i % 50 == 7 ? RR_ERROR_ARGUMENT : RR_OK), "ray %d: error %d (%s)", i, (int)alone[i].error,
          rr_device_message(dev));
  }
  trace_work w[TRACERS];
  pthread_t tid[TRACERS];
  pthread_barrier_init(&start, NULL, TRACERS);
  for (int t = 0; t < TRACERS; t++) {
    w[t] = (trace_work){.scene = s, .rays = rays, .alone = alone};
    pthread_create(&tid[t], NULL, trace_thread, &w[t]);
  }
  for (int t = 0; t < TRACERS; t++) {
    pthread_join(tid[t], NULL);
    CHECK(w[t].wrong == 0, "tracing thread %d: %d of %d rays answered otherwise than alone", t, w[t].wrong, NRAYS);
  }
  pthread_barrier_destroy(&start);
  printf("%d threads traced %d rays each (%d refused) through one scene of %llu triangles\n", TRACERS, NRAYS,
         refused, (unsigned long long)info.triangles);
  rr_scene_release(s);
  rr_device_release(dev);
}

int main(void) {
  const char *spot = test_model("spot.obj");
  const char *scenes[WORKERS] = {"demo", "ground", spot ? spot : "box:8", "sphere:48"};
  device_work w[WORKERS];
  pthread_t tid[WORKERS];
  /* what each thread must find: the same work done alone first */
  for (int i = 0; i < WORKERS; i++) {
    w[i] = (device_work){.scene = scenes[i], .rounds = test_quick() ? 1 : 3};
    rr_device *dev = rr_device_new();
    w[i].print = render_all(&w[i], dev);
    CHECK(w[i].error == RR_OK, "%s alone: %s", scenes[i], w[i].message);
    rr_device_release(dev);
  }
  pthread_barrier_init(&start, NULL, WORKERS);
  for (int i = 0; i < WORKERS; i++) pthread_create(&tid[i], NULL, device_thread, &w[i]);
  for (int i = 0; i < WORKERS; i++) {
    pthread_join(tid[i], NULL);
    CHECK(w[i].error == RR_OK, "%s on a thread of its own: %s", scenes[i], w[i].message);
  }
  pthread_barrier_destroy(&start);
  printf("%d threads with a device each loaded, rendered (%d methods, 2 threads each) and shaded at once\n", WORKERS,
         NMETHODS);
  shared_scene();
  return test_done();
}
