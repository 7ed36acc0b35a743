/* auto: the cost model's choice is a method that can draw the camera, gives the bits
 * of that method's own render, and says "model: ..." on a single frame; a trial
 * ("trial: ...") runs only when many frames are expected and the predictions are
 * close, and the device keeps its verdict for the same view. */
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

/* The two smallest predictions in a "model: name ms, name ms, ... ms predicted" reason. */
static bool two_best(const char *why, double *best, double *second) {
  const char *p = strstr(why, "model:");
  if (!p) return false;
  p += strlen("model:");
  *best = *second = INFINITY;
  int n = 0;
  char name[32];
  double ms;
  int used;
  while (sscanf(p, " %31[^ ,] %lf%n", name, &ms, &used) == 2) {
    if (ms < *best) *second = *best, *best = ms;
    else if (ms < *second) *second = ms;
    n++, p += used;
    if (*p == ',') p++;
  }
  return n >= 2;
}

static rr_frame *render(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int frames, int w,
                        int h) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = w, opt.height = h, opt.threads = 1, opt.frames_hint = frames;
  return test_render_opt(dev, s, cam, &opt);
}

/* Every camera on one view: a single frame is the model's choice, a method that can
 * draw the camera, with the bits of that method's own render. */
static void check_cameras(rr_device *dev, const rr_scene *s, rr_camera cam, const char *what) {
  for (int type = 0; type < RR_CAMERA_COUNT; type++) {
    cam.type = (rr_camera_type)type;
    cam.fov_deg = type == RR_CAMERA_FISHEYE ? 180 : 60;
    int w = 96, h = type == RR_CAMERA_LATLONG ? 48 : type == RR_CAMERA_CUBE ? 72 : 96;
    rr_frame *a = render(dev, s, &cam, RR_METHOD_AUTO, 1, w, h);
    if (!a) continue;
    bool planar = type == RR_CAMERA_PERSPECTIVE || type == RR_CAMERA_ORTHOGRAPHIC;
    int m = a->stats.method;
    CHECK(m >= 0 && m < RR_METHOD_COUNT && m != RR_METHOD_RC && m != RR_METHOD_2DR_BB && m != RR_METHOD_2DR_BIN,
          "%s, %s: auto chose %d, not an exact method", what, rr_camera_name(type), m);
    CHECK(planar || m != RR_METHOD_3DR_BB, "%s: auto chose 3dr-bb for a %s camera", what, rr_camera_name(type));
    CHECK(strncmp(a->stats.why, "model: ", 7) == 0, "%s, %s: a single frame ran a trial: %s", what,
          rr_camera_name(type), a->stats.why);
    rr_frame *b = render(dev, s, &cam, (rr_method)m, 1, w, h);
    if (b) CHECK(test_frames_differ(a, b) == 0, "%s, %s: auto's frame is not %s's", what, rr_camera_name(type),
                 rr_method_name(m));
    rr_frame_release(a), rr_frame_release(b);
  }
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *rooms = NULL, *sphere = NULL;
  CHECK(rr_scene_load(dev, "rooms:4", &rooms) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_scene_load(dev, "sphere", &sphere) == RR_OK, "%s", rr_device_message(dev));
  if (!rooms || !sphere) return test_done();
  rr_camera inside;
  rr_camera_init(&inside);
  memcpy(inside.eye, (float[3]){1.2f, 1.6f, 1.4f}, sizeof inside.eye);
  memcpy(inside.target, (float[3]){6, 1.2f, 3}, sizeof inside.target);
  check_cameras(dev, rooms, inside, "rooms:4 from inside");
  rr_camera outside;
  rr_camera_init(&outside);
  CHECK(rr_camera_frame(dev, sphere, 96, 96, &outside) == RR_OK, "%s", rr_device_message(dev));
  check_cameras(dev, sphere, outside, "sphere");

  /* Many frames: a trial where the two best predictions are close (rooms from
   * inside, big triangles: 3dr-bb and 3dr-bin alike), none where they are far apart
   * (the sphere from outside, small triangles: 3dr-bb predicted twice as fast). */
  struct {
    const rr_scene *s;
    rr_camera cam;
    int size;
    bool close;
  } views[] = {{rooms, inside, 128, true}, {sphere, outside, 128, false}};
  for (int v = 0; v < 2; v++) {
    rr_frame *one = render(dev, views[v].s, &views[v].cam, RR_METHOD_AUTO, 1, views[v].size, views[v].size);
    double best, second;
    if (!one || !two_best(one->stats.why, &best, &second)) {
      CHECK(false, "view %d: no predictions in '%s'", v, one ? one->stats.why : "");
      rr_frame_release(one);
      continue;
    }
    /* away from the margin (1.5), so that rounding in the message cannot matter */
    CHECK(views[v].close ? second < 1.4 * best : second > 1.6 * best, "view %d: predictions %g and %g", v, best,
          second);
    rr_frame *many = render(dev, views[v].s, &views[v].cam, RR_METHOD_AUTO, 100, views[v].size, views[v].size);
    if (many) {
      const char *want = views[v].close ? "trial: " : "model: ";
      CHECK(strncmp(many->stats.why, want, 7) == 0, "view %d, 100 frames: expected %s: %s", v, want,
            many->stats.why);
      rr_frame *own = render(dev, views[v].s, &views[v].cam, (rr_method)many->stats.method, 1, views[v].size, views[v].size);
      if (own) CHECK(test_frames_differ(many, own) == 0, "view %d: auto's frame is not its method's", v);
      /* the trial's verdict is kept for the same view, also for a single frame */
      rr_frame *again = render(dev, views[v].s, &views[v].cam, RR_METHOD_AUTO, 1, views[v].size, views[v].size);
      if (again && views[v].close)
        CHECK(again->stats.method == many->stats.method && strcmp(again->stats.why, many->stats.why) == 0,
              "view %d: the verdict was not kept: %s", v, again->stats.why);
      rr_frame_release(own), rr_frame_release(again);
    }
    rr_frame_release(one), rr_frame_release(many);
  }

  /* auto takes no oracles */
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_AUTO, opt.width = opt.height = 32, opt.oracles = "leaves=0";
  rr_frame *f = NULL;
  CHECK(rr_render(dev, rooms, &inside, &opt, &f) == RR_ERROR_ARGUMENT && !f, "auto accepted oracles");
  rr_scene_release(rooms), rr_scene_release(sphere);
  rr_device_release(dev);
  return test_done();
}
