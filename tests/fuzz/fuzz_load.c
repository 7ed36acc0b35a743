/* Scene files through rr_scene_load, every format rastray reads: the first byte
 * picks the extension (so the importer and rastray's checks for that format see
 * the rest), the rest is the file. A load either gives a scene that renders or
 * fails with a one-line message; nothing may crash, hang or run away in memory. */
#include "fuzz_util.h"

static const char *const exts[] = {"obj", "ply", "off", "stl", "gltf", "glb", "dae", "fbx", "3ds", "json"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  char path[64];
  if (!fuzz_write_file(data + 1, size - 1, exts[data[0] % (sizeof exts / sizeof *exts)], path, sizeof path)) return 0;
  rr_device *dev = fuzz_device();
  rr_scene *scene = NULL;
  /* scene files (json) with a budget: a large built-in is legitimate work, not a bug (fuzz_scene_file goes further) */
  rr_load_options opt;
  rr_load_options_init(&opt);
  opt.sandbox = 1, opt.max_tris = 1u << 16;
  rr_error e = strcmp(exts[data[0] % (sizeof exts / sizeof *exts)], "json") == 0
                   ? rr_scene_load_file(dev, path, &opt, &scene, NULL)
                   : rr_scene_load(dev, path, &scene);
  if (e == RR_OK) {
    /* a loaded scene is a valid one: frame it and render a few pixels */
    rr_camera cam;
    rr_camera_init(&cam);
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.width = opt.height = 8, opt.threads = 1;
    rr_frame *frame = NULL;
    if (rr_camera_frame(dev, scene, 8, 8, &cam) == RR_OK && rr_render(dev, scene, &cam, &opt, &frame) == RR_OK) {
      rr_image img = {0};
      if (rr_shade(dev, scene, &cam, frame, RR_SHADE_LAMBERT, &img) == RR_OK) rr_image_free(&img);
    }
    rr_frame_release(frame);
    rr_scene_release(scene);
  } else {
    fuzz_check_message(dev);
  }
  unlink(path);
  return 0;
}
