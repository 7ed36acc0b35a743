/* Out of memory: each allocation the library makes along a sequence of calls is
 * failed in turn, and each time the call that needed it must return
 * RR_ERROR_MEMORY with a message, or succeed with the same results where it can do
 * without (a texture, a tighter copy), never crash, and free what it had (the ASan
 * build's leak checker runs at exit). The test is linked with -Wl,--wrap=malloc,...
 * (CMakeLists.txt), so the library's calls come to the wrappers below; everything
 * runs on one thread. Sequences are short (what they work on is made beforehand),
 * since each runs once per allocation it makes. */
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

/* What the sequences work on, made beforehand. */
typedef struct fixture {
  rr_device *dev; /* every call's, the fixtures' too */
  rr_scene *scene;
  rr_camera cam;
  const char *name; /* a scene to load */
  rr_method method;
  const char *dir; /* for files */
} fixture;

/* A sequence of calls that stops at the first failure, releases all it made and
 * returns that failure's code; *print sums up its results. */
typedef rr_error (*sequence)(const fixture *fx, uint64_t *print);

/* Runs seq normally, then with each of its allocations failed in turn. */
static void fail_each(const char *what, sequence seq, const fixture *fx) {
  uint64_t want = 0, print = 0;
  double t0 = rr_now_ms();
  armed = true, made = 0, fail_at = -1;
  rr_error e = seq(fx, &want);
  armed = false;
  long total = made;
  CHECK(e == RR_OK, "%s: %s", what, rr_device_message(fx->dev));
  for (fail_at = 0; fail_at < total && !e && test_failed < 20; fail_at++) {
    armed = true, made = 0, print = 0;
    rr_error ef = seq(fx, &print);
    armed = false;
    CHECK(ef == RR_OK || ef == RR_ERROR_MEMORY, "%s, allocation %ld of %ld failed: error %d (%s)", what, fail_at, total,
          (int)ef, rr_device_message(fx->dev));
    CHECK(ef != RR_ERROR_MEMORY || rr_device_message(fx->dev)[0], "%s, allocation %ld failed: no message", what,
          fail_at);
    CHECK(ef || print == want, "%s, allocation %ld failed: it succeeded with other results", what, fail_at);
  }
  printf("%s: each of %ld allocations failed in turn (%.0f ms)\n", what, total, rr_now_ms() - t0);
}

/* ---- scenes --------------------------------------------------------------------- */

/* What a scene holds (textures aside: one that cannot be loaded is left out). */
static uint64_t scene_print(const rr_scene *s) {
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  uint64_t h = mix(mix(mix(mix(mix(0, info.triangles), info.skipped), info.materials), info.geometries), info.bvh_nodes);
  for (uint32_t i = 0; i < scene_stored(s); i++) /* (the arrays as stored: an instanced mesh once) */
    for (int k = 0; k < 3; k++) {
      h = mix_bytes(h, &s->p[k][0][i], 4), h = mix_bytes(h, &s->p[k][1][i], 4), h = mix_bytes(h, &s->p[k][2][i], 4);
      if (s->n[0][0]) h = mix_bytes(h, &s->n[k][2][i], 4);
      if (s->uv[0][0]) h = mix_bytes(h, &s->uv[k][1][i], 4);
      if (s->col[0][0]) h = mix_bytes(h, &s->col[k][1][i], 4);
    }
  return mix_bytes(h, s->material, (size_t)scene_stored(s) * sizeof *s->material);
}

static rr_error load(const fixture *fx, uint64_t *print) {
  rr_scene *s;
  rr_error e = rr_scene_load(fx->dev, fx->name, &s);
  if (!e) *print = scene_print(s);
  rr_scene_release(s);
  return e;
}

/* The fixture's scene built again (its arrays are already trimmed). */
static rr_error commit(const fixture *fx, uint64_t *print) {
  rr_error e = rr_scene_commit(fx->scene);
  if (!e) *print = scene_print(fx->scene);
  return e;
}

static const float quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
static const uint32_t quad_idx[] = {0, 1, 2, 0, 2, 3};

/* A scene made through the API: a mesh, a homogeneous mesh (with a corner at
 * infinity when fx->name says "inf"), rays, more triangles after the commit gave
 * back the spare room, and another commit. */
static rr_error api(const fixture *fx, uint64_t *print) {
  bool inf = strcmp(fx->name, "inf") == 0;
  rr_scene *s;
  rr_error e = rr_scene_new(fx->dev, &s);
  if (e) return e;
  e = rr_scene_add_mesh(s, quad, 4, quad_idx, 2, NULL);
  /* a triangle behind the quad, its third corner at infinity (w = 0) or not */
  const float xyzw[] = {-0.5f, -0.5f, -1, 1, 0.5f, -0.5f, -1, 1, 0, 1, inf ? 0 : -1, inf ? 0 : 1};
  const uint32_t tri[] = {0, 1, 2};
  if (!e) e = rr_scene_add_mesh4(s, xyzw, 3, tri, 1, NULL);
  if (!e) e = rr_scene_commit(s);
  rr_ray ray = {{0.25f, 0.25f, 2}, {0, 0, -1}, 0, INFINITY};
  rr_hit hit;
  int occluded;
  if (!e) e = rr_intersect(fx->dev, s, &ray, &hit);
  if (!e) e = rr_occluded(fx->dev, s, &ray, &occluded);
  if (!e) e = rr_scene_add_mesh(s, quad, 4, quad_idx + 3, 1, NULL);
  static const float colours[] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  if (!e) e = rr_scene_add_mesh_colors(s, quad, 4, quad_idx, 2, NULL, colours);
  if (!e) e = rr_scene_commit(s);
  if (!e) *print = mix(mix(scene_print(s), hit.prim), (uint64_t)occluded);
  rr_scene_release(s);
  return e;
}

/* ---- frames and images ---------------------------------------------------------- */

enum { W = 24, H = 18 };

/* A frame of the fixture's method (with heat maps), shaded in every mode, and its AOVs. */
static rr_error frame(const fixture *fx, uint64_t *print) {
  rr_scratch_free(fx->dev); /* the device's kept work buffers: allocated (and failed) afresh */
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = fx->method, opt.width = W, opt.height = H, opt.threads = 1, opt.heat = 1;
  rr_frame *f;
  rr_error e = rr_render(fx->dev, fx->scene, &fx->cam, &opt, &f);
  if (!e) *print = mix_bytes(mix_bytes(*print, rr_frame_ids(f), 4 * W * H), rr_frame_t(f), 4 * W * H);
  for (int mode = 0; !e && mode < RR_SHADE_COUNT; mode++) {
    rr_image img;
    e = rr_shade(fx->dev, fx->scene, &fx->cam, f, (rr_shade_mode)mode, &img);
    if (!e) rr_image_free(&img);
  }
  for (int aov = 0; !e && aov < RR_AOV_COUNT; aov++) {
    rr_image img;
    e = rr_frame_aov(fx->dev, fx->scene, &fx->cam, f, (rr_aov)aov, &img);
    if (!e) rr_image_free(&img);
  }
  rr_frame_release(f);
  return e;
}

static const char *const ext[] = {"png", "pfm", "npy", "exr"};

static void image_path(char *path, size_t cap, const char *dir, int k) {
  snprintf(path, cap, "%s/image.%s", dir, ext[k]);
}

/* A heat map with its legend written and read back in every format. */
static rr_error images(const fixture *fx, uint64_t *print) {
  (void)print;
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_RC, opt.width = 80, opt.height = 60, opt.threads = 1, opt.heat = 1;
  rr_frame *f;
  rr_error e = rr_render(fx->dev, fx->scene, &fx->cam, &opt, &f);
  for (int k = 0; !e && k < 4; k++) {
    rr_image img, back;
    e = rr_shade(fx->dev, fx->scene, &fx->cam, f, RR_SHADE_HEAT_EVALS, &img);
    if (e) break;
    char path[1024];
    image_path(path, sizeof path, fx->dir, k);
    e = rr_image_write(fx->dev, &img, path);
    if (!e) e = rr_image_read(fx->dev, path, &back);
    if (!e) rr_image_free(&back);
    rr_image_free(&img);
  }
  rr_frame_release(f);
  return e;
}

/* A small OBJ file with a material and a texture, for the loaders. */
static bool write_obj(rr_device *dev, const char *dir, char *obj, size_t cap) {
  char path[1024];
  float texels[2 * 2 * 3] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  rr_image tex = {2, 2, 3, RR_PIXEL_F32, texels, RR_IMAGE_VALUES};
  snprintf(path, sizeof path, "%s/tiny.png", dir);
  if (rr_image_write(dev, &tex, path) != RR_OK) return false;
  snprintf(path, sizeof path, "%s/tiny.mtl", dir);
  FILE *f = fopen(path, "w");
  if (!f) return false;
  fprintf(f, "newmtl m\nKd 1 1 1\nmap_Kd tiny.png\n");
  fclose(f);
  snprintf(obj, cap, "%s/tiny.obj", dir);
  f = fopen(obj, "w");
  if (!f) return false;
  fprintf(f, "mtllib tiny.mtl\no tiny\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "vn 0 0 1\nusemtl m\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  fclose(f);
  return true;
}

int main(void) {
  char dir[] = "/tmp/rr_test_alloc.XXXXXX";
  fixture fx = {.dev = rr_device_new(), .dir = mkdtemp(dir)};
  CHECK(fx.dir != NULL, "cannot make a temporary directory");
  if (!fx.dir) return test_done();
  rr_build_options b;
  rr_build_options_init(&b);
  b.threads = 1; /* every allocation on this thread, in the same order every run */
  rr_device_set_build_options(fx.dev, &b);

  fx.name = "";
  fail_each("API scene", api, &fx);
  fx.name = "inf";
  fail_each("API scene with a corner at infinity", api, &fx);
  const char *builtins[] = {"plane:3", "box:2", "ground", "rooms:1"};
  for (int i = 0; i < 4; i++) fx.name = builtins[i], fail_each(builtins[i], load, &fx);
  char obj[1024], grid[1100];
  CHECK(write_obj(fx.dev, fx.dir, obj, sizeof obj), "cannot write an OBJ file: %s", rr_device_message(fx.dev));
  snprintf(grid, sizeof grid, "grid:%s:3", obj);
  /* the file through assimp, then its copies (one sequence: loading a file is slow) */
  fx.name = grid, fail_each("a grid of copies of an OBJ file with a material and a texture", load, &fx);
  /* a glTF file with vertex colours, an embedded PNG (a data URI), a camera and a light */
  char gltf[1100];
  snprintf(gltf, sizeof gltf, "%s/all.gltf", fx.dir);
  FILE *gf = fopen(gltf, "w");
  CHECK(gf != NULL, "cannot write %s", gltf);
  if (gf)
    fputs(
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],\"nodes\":[{\"mesh\":0,\"name\":\"tri\"},{"
      "\"camera\":0,\"name\":\"cam\",\"translation\":[0,0,3]},{\"name\":\"lamp\",\"extensions\":{\"KHR_lights_punctual\":{\""
      "light\":0}}}],\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],\"extensionsUs"
      "ed\":[\"KHR_lights_punctual\"],\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\"}]}},\"mesh"
      "es\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"COLOR_0\":1,\"TEXCOORD_0\":2},\"material\":0}]}],\"materi"
      "als\":[{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],\"textures\":[{\"source\":0}"
      "],\"images\":[{\"uri\":\"data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAIAAAD91JpzAAAAE0lEQVR4Xm"
      "P4z8AAxgz///9nAAAe7wT8A8yZgQAAAABJRU5ErkJggg==\"}],\"buffers\":[{\"byteLength\":96,\"uri\":\"data:applicatio"
      "n/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAA"
      "AAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/\"}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byt"
      "eLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":2"
      "4}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1"
      ",1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},{\"bufferView\":2,\"componentType\""
      ":5126,\"count\":3,\"type\":\"VEC2\"}]}",
        gf),
        fclose(gf);
  fx.name = gltf, fail_each("a glTF file with vertex colours, an embedded texture, a camera and a light", load, &fx);

  /* More than 32768 triangles (BVH_PAR_MIN): the BVH splits its top by chunks. */
  CHECK(rr_scene_load(fx.dev, "sphere:184", &fx.scene) == RR_OK, "sphere:184: %s", rr_device_message(fx.dev));
  fail_each("BVH of sphere:184", commit, &fx);
  rr_scene_release(fx.scene);

  CHECK(rr_scene_load(fx.dev, "ground", &fx.scene) == RR_OK, "ground: %s", rr_device_message(fx.dev));
  rr_camera_init(&fx.cam);
  CHECK(rr_camera_frame(fx.dev, fx.scene, W, H, &fx.cam) == RR_OK, "%s", rr_device_message(fx.dev));
  for (int m = 0; m < RR_METHOD_COUNT; m++) {
    if (m == RR_METHOD_2DR_BB || m == RR_METHOD_2DR_BIN) continue; /* no corners at infinity */
    fx.method = (rr_method)m, fail_each(rr_method_name(m), frame, &fx);
  }
  rr_scene_release(fx.scene);
  CHECK(rr_scene_load(fx.dev, "box:2", &fx.scene) == RR_OK, "box:2: %s", rr_device_message(fx.dev));
  rr_camera_frame(fx.dev, fx.scene, W, H, &fx.cam);
  fx.method = RR_METHOD_2DR_BB, fail_each("2dr-bb", frame, &fx);
  fx.method = RR_METHOD_2DR_BIN, fail_each("2dr-bin", frame, &fx);
  fx.cam.type = RR_CAMERA_FISHEYE, fx.cam.fov_deg = 180; /* a curved camera: rays per sample, cones per cell */
  fx.method = RR_METHOD_RC, fail_each("rc, fisheye camera", frame, &fx);
  fx.method = RR_METHOD_3DR_FULL, fail_each("3dr-full, fisheye camera", frame, &fx);
  fail_each("images", images, &fx);
  rr_scene_release(fx.scene);

  const char *files[] = {"tiny.png", "tiny.mtl", "tiny.obj", "all.gltf"};
  for (int k = 0; k < 4; k++) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", fx.dir, files[k]);
    unlink(path);
  }
  for (int k = 0; k < 4; k++) {
    char path[1024];
    image_path(path, sizeof path, fx.dir, k);
    unlink(path);
  }
  rmdir(fx.dir);
  rr_device_release(fx.dev);
  return test_done();
}
