/* The values a command line hands the library: a scene name (built-in or path),
 * the method, the camera, the AA mode, the oracle settings and the size, each from
 * the input, then a render of the result. Bad values must be refused with a
 * one-line message; good ones must render. Built-in sizes above 256 are left out:
 * they are legitimate work (millions of triangles), not bugs. */
#include "fuzz_util.h"

#include <math.h>

/* The next NUL- or newline-terminated string of the input (at most cap - 1 bytes). */
static const uint8_t *take_string(const uint8_t *p, const uint8_t *end, char *out, size_t cap) {
  size_t n = 0;
  while (p < end && *p && *p != '\n') {
    if (n + 1 < cap) out[n++] = (char)*p;
    p++;
  }
  out[n] = 0;
  return p < end ? p + 1 : p;
}

static const uint8_t *take_float(const uint8_t *p, const uint8_t *end, float *out) {
  uint32_t bits = 0;
  for (int k = 0; k < 4; k++) bits = bits << 8 | (p < end ? *p++ : 0);
  memcpy(out, &bits, sizeof *out);
  return p;
}

static int has_big_number(const char *s) {
  for (; *s; s++)
    if (*s >= '0' && *s <= '9' && strtol(s, NULL, 10) > 256) return 1;
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const uint8_t *p = data, *end = data + size;
  char name[128], oracles[128];
  p = take_string(p, end, name, sizeof name);
  p = take_string(p, end, oracles, sizeof oracles);
  if (has_big_number(name) || strchr(name, '/')) return 0; /* built-ins only: no file of the machine */
  rr_device *dev = fuzz_device();
  rr_scene *scene = NULL;
  if (rr_scene_load(dev, name[0] ? name : "sphere:8", &scene) != RR_OK) {
    fuzz_check_message(dev);
    return 0;
  }
  rr_render_options opt;
  rr_render_options_init(&opt);
  rr_camera cam;
  rr_camera_init(&cam);
  uint8_t b[6] = {0};
  for (int k = 0; k < 6 && p < end; k++) b[k] = *p++;
  opt.method = (rr_method)(b[0] % (RR_METHOD_COUNT + 1)) == RR_METHOD_COUNT ? RR_METHOD_AUTO : (rr_method)(b[0] % RR_METHOD_COUNT);
  cam.type = (rr_camera_type)(b[1] % RR_CAMERA_COUNT);
  opt.width = 1 + b[2] % 24, opt.height = 1 + b[3] % 24, opt.threads = 1 + b[4] % 2;
  opt.oracles = oracles[0] ? oracles : NULL;
  static const int counts[] = {1, 2, 4, 8, 16};
  rr_error e = rr_render_options_set_aa(dev, &opt, (rr_aa_mode)(b[5] % 4), counts[(b[5] >> 2) % 5],
                                        counts[(b[5] >> 5) % 5], RR_AA_STANDARD, 1);
  if (e == RR_OK) {
    for (int k = 0; k < 3; k++) p = take_float(p, end, &cam.eye[k]);
    for (int k = 0; k < 3; k++) p = take_float(p, end, &cam.target[k]);
    p = take_float(p, end, &cam.fov_deg);
    if (!(p < end) || rr_camera_check(dev, &cam) != RR_OK) rr_camera_frame(dev, scene, opt.width, opt.height, &cam);
    rr_frame *frame = NULL;
    if (rr_render(dev, scene, &cam, &opt, &frame) == RR_OK) {
      rr_image img = {0};
      if (rr_shade(dev, scene, &cam, frame, RR_SHADE_LAMBERT, &img) == RR_OK) rr_image_free(&img);
      rr_frame_release(frame);
    } else {
      fuzz_check_message(dev);
    }
  } else {
    fuzz_check_message(dev);
  }
  rr_scene_release(scene);
  return 0;
}
