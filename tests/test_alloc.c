/* Out of memory: each allocation the library makes along a sequence of calls is
 * failed in turn, and each time the call that needed it must return
 * RR_ERROR_MEMORY with a message, or succeed with the same results where it can do
 * without (a texture, a tighter copy), never crash, and free what it had (the ASan
 * build's leak checker runs at exit). The test is linked with -Wl,--wrap=malloc,... (CMakeLists.txt), so
 * the library's calls come to the wrappers below; everything runs on one thread. */
#include "testutil.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
void *__real_aligned_alloc(size_t align, size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t n);
void *__wrap_aligned_alloc(size_t align, size_t n);

/* While armed, allocation number fail_at (counting from 0) fails. */
static bool armed;
static long fail_at, made;

static bool fails(void) { return armed && made++ == fail_at; }
void *__wrap_malloc(size_t n) { return fails() ? NULL : __real_malloc(n); }
void *__wrap_calloc(size_t n, size_t size) { return fails() ? NULL : __real_calloc(n, size); }
void *__wrap_realloc(void *p, size_t n) { return fails() ? NULL : __real_realloc(p, n); }
void *__wrap_aligned_alloc(size_t align, size_t n) { return fails() ? NULL : __real_aligned_alloc(align, n); }

/* Results folded into one number, to compare a run that succeeded with the normal one. */
static uint64_t mix(uint64_t h, uint64_t v) { return (h ^ v) * 0x100000001B3ull; }
static uint64_t mix_bytes(uint64_t h, const void *p, size_t n) {
  for (size_t i = 0; i < n; i++) h = mix(h, ((const uint8_t *)p)[i]);
  return h;
}

/* A sequence of calls on dev that stops at the first failure, releases all it
 * made and returns that failure's code; *print sums up its results. */
typedef rr_error (*sequence)(rr_device *dev, const char *arg, uint64_t *print);

/* Runs seq normally, then with each of its allocations failed in turn. */
static void fail_each(const char *what, sequence seq, const char *arg) {
  rr_device *dev = rr_device_new();
  rr_build_options b;
  rr_build_options_init(&b);
  b.threads = 1; /* every allocation on this thread, in the same order every run */
  rr_device_set_build_options(dev, &b);
  uint64_t want = 0, print = 0;
  double t0 = rr_now_ms();
  armed = true, made = 0, fail_at = -1;
  rr_error e = seq(dev, arg, &want);
  armed = false;
  long total = made;
  CHECK(e == RR_OK, "%s: %s", what, rr_device_message(dev));
  for (fail_at = 0; fail_at < total && !e && test_failed < 20; fail_at++) {
    armed = true, made = 0, print = 0;
    rr_error ef = seq(dev, arg, &print);
    armed = false;
    CHECK(ef == RR_OK || ef == RR_ERROR_MEMORY, "%s, allocation %ld of %ld failed: error %d (%s)", what, fail_at, total,
          (int)ef, rr_device_message(dev));
    CHECK(ef != RR_ERROR_MEMORY || rr_device_message(dev)[0], "%s, allocation %ld failed: no message", what, fail_at);
    CHECK(ef || print == want, "%s, allocation %ld failed: it succeeded with other results", what, fail_at);
  }
  printf("%s: each of %ld allocations failed in turn (%.0f ms)\n", what, total, rr_now_ms() - t0);
  rr_device_release(dev);
}

/* What a scene holds (textures aside: one that cannot be loaded is left out). */
static uint64_t scene_print(const rr_scene *s) {
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  uint64_t h = mix(mix(mix(mix(mix(0, info.triangles), info.skipped), info.materials), info.geometries), info.bvh_nodes);
  for (uint32_t i = 0; i < s->ntris; i++)
    for (int k = 0; k < 3; k++) {
      h = mix_bytes(h, &s->p[k][0][i], 4), h = mix_bytes(h, &s->p[k][1][i], 4), h = mix_bytes(h, &s->p[k][2][i], 4);
      if (s->n[0][0]) h = mix_bytes(h, &s->n[k][2][i], 4);
      if (s->uv[0][0]) h = mix_bytes(h, &s->uv[k][1][i], 4);
    }
  return mix_bytes(h, s->material, (size_t)s->ntris * sizeof *s->material);
}

static rr_error load(rr_device *dev, const char *name, uint64_t *print) {
  rr_scene *s;
  rr_error e = rr_scene_load(dev, name, &s);
  if (!e) *print = scene_print(s);
  rr_scene_release(s);
  return e;
}

/* A frame of every method from the camera, shaded in every mode, its AOVs
 * extracted, and an image written and read back in every format. */
static const char *tmp_dir;
static const char *const ext[] = {"png", "pfm", "npy", "exr"};

static rr_error frame_and_images(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m,
                                 uint64_t *print) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = 24, opt.height = 18, opt.threads = 1, opt.heat = 1;
  rr_frame *f;
  rr_error e = rr_render(dev, s, cam, &opt, &f);
  if (!e) *print = mix_bytes(mix_bytes(*print, f->vb.id, 4 * 24 * 18), f->vb.t, 4 * 24 * 18);
  for (int mode = 0; !e && mode < RR_SHADE_COUNT; mode++) {
    rr_image img;
    e = rr_shade(dev, s, cam, f, (rr_shade_mode)mode, &img);
    if (!e) rr_image_free(&img);
  }
  for (int aov = 0; !e && aov < RR_AOV_COUNT; aov++) {
    rr_image img;
    e = rr_frame_aov(dev, s, cam, f, (rr_aov)aov, &img);
    if (!e) rr_image_free(&img);
  }
  for (int k = 0; !e && m == RR_METHOD_RC && k < 4; k++) {
    rr_image img, back;
    e = rr_shade(dev, s, cam, f, RR_SHADE_HEAT_EVALS, &img);
    if (e) break;
    char path[1024];
    snprintf(path, sizeof path, "%s/image.%s", tmp_dir, ext[k]);
    e = rr_image_write(dev, &img, path);
    if (!e) e = rr_image_read(dev, path, &back);
    if (!e) rr_image_free(&back);
    rr_image_free(&img);
  }
  rr_frame_release(f);
  return e;
}

static const float quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
static const uint32_t quad_idx[] = {0, 1, 2, 0, 2, 3};

/* A scene made through the API: a mesh, a homogeneous mesh (with a corner at
 * infinity when arg says "inf"), rays, more triangles, then frames and images. */
static rr_error api(rr_device *dev, const char *arg, uint64_t *print) {
  bool inf = strcmp(arg, "inf") == 0;
  rr_scene *s;
  rr_error e = rr_scene_new(dev, &s);
  if (e) return e;
  e = rr_scene_add_mesh(s, quad, 4, quad_idx, 2, NULL);
  /* a triangle behind the quad, with its third corner at infinity (w = 0) or not */
  const float xyzw[] = {-0.5f, -0.5f, -1, 1, 0.5f, -0.5f, -1, 1, 0, 1, inf ? 0 : -1, inf ? 0 : 1};
  const uint32_t tri[] = {0, 1, 2};
  if (!e) e = rr_scene_add_mesh4(s, xyzw, 3, tri, 1, NULL);
  if (!e) e = rr_scene_commit(s);
  rr_ray ray = {{0.25f, 0.25f, 2}, {0, 0, -1}, 0, INFINITY};
  rr_hit hit;
  int occluded;
  if (!e) e = rr_intersect(s, &ray, &hit);
  if (!e) e = rr_occluded(s, &ray, &occluded);
  /* more after the commit, which gave back the spare room: the arrays grow again */
  if (!e) e = rr_scene_add_mesh(s, quad, 4, quad_idx + 3, 1, NULL);
  if (!e) e = rr_scene_commit(s);
  if (!e) *print = mix(mix(scene_print(s), hit.prim), (uint64_t)occluded);
  rr_camera cam;
  rr_camera_init(&cam);
  /* every method once; the scene with a corner at infinity is about the scene */
  for (int m = 0; !e && m < (inf ? 1 : RR_METHOD_COUNT); m++) e = frame_and_images(dev, s, &cam, (rr_method)m, print);
  cam.type = RR_CAMERA_FISHEYE, cam.fov_deg = 180; /* a curved camera: rays per sample, cones per cell */
  if (!e) e = frame_and_images(dev, s, &cam, RR_METHOD_RC, print);
  rr_scene_release(s);
  return e;
}

int main(void) {
  char dir[] = "/tmp/rr_test_alloc.XXXXXX";
  tmp_dir = mkdtemp(dir);
  CHECK(tmp_dir != NULL, "cannot make a temporary directory");
  if (!tmp_dir) return test_done();
  fail_each("API scene", api, "");
  fail_each("API scene with a corner at infinity", api, "inf");
  /* More than 32768 triangles (BVH_PAR_MIN): the BVH splits its top by chunks. */
  fail_each("sphere:184", load, "sphere:184");
  const char *builtins[] = {"plane:3", "box:2", "ground", "rooms:1"};
  for (int i = 0; i < 4; i++) fail_each(builtins[i], load, builtins[i]);
  /* assimp, materials and a texture */
  fail_each("spot.obj", load, RR_DATA_DIR "/spot.obj");
  fail_each("grid of teapots", load, "grid:" RR_DATA_DIR "/teapot.obj:2");
  for (int k = 0; k < 4; k++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/image.%s", tmp_dir, ext[k]);
    unlink(path);
  }
  rmdir(tmp_dir);
  return test_done();
}
