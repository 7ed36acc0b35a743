/* Scene files (rr_scene_load_file) and camera files (rr_camera_load): the input is
 * the JSON file, written into a directory that also holds a small mesh (tri.obj) for
 * "file" keys to find. The load runs sandboxed (nothing outside that directory) with a
 * budget of triangles: a large built-in is legitimate work, not a bug. A loaded scene
 * renders a few pixels with its own settings; a refusal must be one line. */
#include "fuzz_util.h"

#include <sys/stat.h>

static char dir[] = "/tmp/rr_fuzz_scene_XXXXXX";

/* The directory of the run, with its mesh (made once). */
static const char *fuzz_dir(void) {
  static int made;
  if (!made) {
    if (!mkdtemp(dir)) abort();
    char path[128];
    snprintf(path, sizeof path, "%s/tri.obj", dir);
    FILE *f = fopen(path, "w");
    if (!f) abort();
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n", f);
    fclose(f);
    made = 1;
  }
  return dir;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char path[160];
  snprintf(path, sizeof path, "%s/scene.json", fuzz_dir());
  FILE *f = fopen(path, "wb");
  if (!f) return 0;
  size_t written = fwrite(data, 1, size, f);
  fclose(f);
  if (written != size) return 0;
  rr_device *dev = fuzz_device();

  rr_camera cam;
  rr_camera_init(&cam);
  unsigned fields;
  if (rr_camera_load(dev, path, &cam, &fields) != RR_OK) fuzz_check_message(dev);

  rr_load_options opt;
  rr_load_options_init(&opt);
  opt.sandbox = 1;
  opt.max_tris = 1u << 16;
  rr_scene *scene = NULL;
  rr_scene_settings st;
  if (rr_scene_load_file(dev, path, &opt, &scene, &st) != RR_OK) {
    if (scene) abort(); /* nothing is made on failure */
    fuzz_check_message(dev);
    return 0;
  }
  rr_render_options ro = st.render;
  ro.width = ro.width < 12 ? ro.width : 12, ro.height = ro.height < 9 ? ro.height : 9, ro.threads = 1;
  cam = st.camera;
  rr_frame *frame = NULL;
  rr_error e = (st.camera_given & RR_CAMERA_FIELD_EYE) ? RR_OK : rr_camera_frame(dev, scene, ro.width, ro.height, &cam);
  if (!e) e = rr_render(dev, scene, &cam, &ro, &frame);
  rr_image img = {0};
  if (!e) e = rr_shade_frame(dev, scene, &cam, frame, &st.shade, &img, NULL);
  if (e) fuzz_check_message(dev);
  rr_image_free(&img);
  rr_frame_release(frame);
  rr_scene_release(scene);
  return 0;
}
