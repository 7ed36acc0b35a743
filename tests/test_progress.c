/* Progress reports (rr_device_set_progress): every stage reported at 0 and 1 with
 * fractions that do not decrease in between, inner fractions at most every
 * RR_PROGRESS_MS, always on the thread that made the call (never a worker's),
 * nothing when unset, and the same frames with and without a callback. Two
 * devices report at once from two threads; the thread-sanitizer build runs this
 * test to find the races the results do not show. */
#include "testutil.h"

#include <pthread.h>
#include <string.h>

enum { MAX_REPORTS = 4096 };

typedef struct {
  pthread_t caller;
  int n;
  bool wrong_thread;
  rr_progress_stage stage[MAX_REPORTS];
  double fraction[MAX_REPORTS], ms[MAX_REPORTS];
} reports;

static void record(void *user, rr_progress_stage stage, double fraction) {
  reports *r = user;
  if (!pthread_equal(pthread_self(), r->caller)) r->wrong_thread = true;
  if (r->n == MAX_REPORTS) return;
  r->stage[r->n] = stage, r->fraction[r->n] = fraction, r->ms[r->n] = rr_now_ms();
  r->n++;
}

/* Checks the reports of one call: runs of stages, each from 0 up to 1; returns the
 * number of inner fractions (0 < f < 1). */
static int check_reports(const reports *r, const char *what) {
  CHECK(!r->wrong_thread, "%s: a report came from a thread other than the caller's", what);
  CHECK(r->n > 0 && r->fraction[0] == 0, "%s: the first report is not a stage's start", what);
  CHECK(r->n > 0 && r->fraction[r->n - 1] == 1, "%s: the last report is not a stage's end", what);
  int inner = 0;
  double last_inner = -1e9;
  for (int i = 1; i < r->n; i++) {
    bool restart = r->fraction[i] == 0 && r->fraction[i - 1] == 1;
    CHECK(restart || (r->stage[i] == r->stage[i - 1] && r->fraction[i] >= r->fraction[i - 1]),
          "%s: report %d (stage %d, %g) after (stage %d, %g)", what, i, r->stage[i], r->fraction[i], r->stage[i - 1],
          r->fraction[i - 1]);
    if (r->fraction[i] > 0 && r->fraction[i] < 1) {
      /* the library reads its clock just before the call, this test just after */
      CHECK(r->ms[i] - last_inner >= RR_PROGRESS_MS - 5, "%s: inner reports %.1f ms apart", what,
            r->ms[i] - last_inner);
      last_inner = r->ms[i], inner++;
    }
  }
  return inner;
}

/* Renders with a callback (and the same without), checking the reports and the bits. */
static void render_checked(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int threads, int w,
                           int h, reports *r, int *inner) {
  char what[64];
  snprintf(what, sizeof what, "%s on %d threads", rr_method_name(m), threads);
  rr_device_set_progress(dev, NULL, NULL);
  rr_frame *plain = test_render(dev, s, cam, m, threads, w, h, 0);
  r->n = 0, r->caller = pthread_self();
  rr_device_set_progress(dev, record, r);
  rr_frame *watched = test_render(dev, s, cam, m, threads, w, h, 0);
  rr_device_set_progress(dev, NULL, NULL);
  CHECK(plain && watched && test_frames_differ(plain, watched) == 0, "%s: a callback changes the frame", what);
  for (int i = 0; i < r->n; i++) CHECK(r->stage[i] == RR_PROGRESS_RENDER, "%s: report of stage %d", what, r->stage[i]);
  *inner += check_reports(r, what);
  rr_frame_release(plain), rr_frame_release(watched);
}

/* One device of its own: load (and build), then render with rc, larger until the
 * pass lasts long enough for inner fractions (at once under the sanitizers). The
 * main thread checks the reports (CHECK counts unguarded). */
typedef struct {
  reports load, render;
  bool ok;
} worker;

static bool has_inner(const reports *r) {
  for (int i = 0; i < r->n; i++)
    if (r->fraction[i] > 0 && r->fraction[i] < 1) return true;
  return false;
}

static void *work(void *arg) {
  worker *w = arg;
  rr_device *dev = rr_device_new();
  w->load.caller = w->render.caller = pthread_self();
  rr_device_set_progress(dev, record, &w->load);
  rr_scene *s;
  w->ok = rr_scene_load(dev, "sphere:32", &s) == RR_OK;
  rr_device_set_progress(dev, record, &w->render);
  for (int size = 32; w->ok && size <= 1024 && !has_inner(&w->render); size *= 2) {
    rr_camera cam;
    rr_camera_init(&cam);
    rr_camera_frame(dev, s, size, size, &cam);
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_RC, opt.width = opt.height = size, opt.threads = 2;
    rr_frame *f = NULL;
    w->render.n = 0;
    w->ok = rr_render(dev, s, &cam, &opt, &f) == RR_OK;
    rr_frame_release(f);
  }
  if (w->ok) rr_scene_release(s);
  rr_device_release(dev);
  return NULL;
}

int main(void) {
  /* Every kind of pass but rc, on one thread and on more than the cores. */
  rr_device *dev = rr_device_new();
  rr_scene *s;
  if (rr_scene_load(dev, "sphere:64", &s) != RR_OK) {
    CHECK(0, "sphere: %s", rr_device_message(dev));
    return test_done();
  }
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, 96, 72, &cam);
  static reports r;
  int inner = 0;
  for (rr_method m = RR_METHOD_RC_BVH; m < RR_METHOD_COUNT; m++) /* rc: the workers below */
    for (int threads = 1; threads <= 3; threads += 2) render_checked(dev, s, &cam, m, threads, 96, 72, &r, &inner);

  /* Unset, nothing is called (the callback would mark the wrong thread). */
  r.n = 0, r.caller = pthread_self();
  rr_device_set_progress(dev, record, &r);
  rr_device_set_progress(dev, NULL, NULL);
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, 64, 48, 0);
  CHECK(r.n == 0, "%d reports after the callback was removed", r.n);
  rr_frame_release(f);
  CHECK(rr_device_set_progress(NULL, record, NULL) == RR_ERROR_ARGUMENT, "a NULL device is refused");
  rr_scene_release(s);
  rr_device_release(dev);

  /* Two devices at once. */
  static worker w[2];
  pthread_t tid[2];
  for (int i = 0; i < 2; i++) CHECK(pthread_create(&tid[i], NULL, work, &w[i]) == 0, "thread %d", i);
  for (int i = 0; i < 2; i++) pthread_join(tid[i], NULL);
  for (int i = 0; i < 2; i++) {
    CHECK(w[i].ok, "worker %d could not load or render", i);
    bool load = false, build = false;
    for (int k = 0; k < w[i].load.n; k++) {
      load |= w[i].load.stage[k] == RR_PROGRESS_LOAD && w[i].load.fraction[k] == 1;
      build |= w[i].load.stage[k] == RR_PROGRESS_BUILD && w[i].load.fraction[k] == 1;
    }
    CHECK(load && build, "rr_scene_load reports loading (%d) and building (%d)", load, build);
    check_reports(&w[i].load, "load");
    CHECK(check_reports(&w[i].render, "rc") > 0, "worker %d: no inner fraction in a long render", i);
  }
  return test_done();
}
