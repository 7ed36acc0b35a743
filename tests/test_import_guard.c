/* Hostile scene files (issue 20): each measured case as a file the test writes,
 * refused by the command line with exit 1, one line on stderr, no output and
 * little time and memory; the child process's crash, time limit and memory limit,
 * each met through the library (a test hook crashes the child, or skips the
 * structural checks so that assimp meets the limits); and the scenes that come
 * back from the child equal, byte for byte, those imported in process. */
#define _GNU_SOURCE
#include "io/import_guard.h"
#include "scene/scene.h"
#include "testutil.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_import_guard_XXXXXX";
static rr_device *dev;

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Writes n bytes to dir/name; returns the path (static, one at a time). */
static const char *write_bytes(const char *name, const void *data, size_t n) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  CHECK(f && fwrite(data, 1, n, f) == n, "cannot write %s", path);
  if (f) fclose(f);
  return path;
}

static void put32(unsigned char *p, uint32_t v) {
  p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24);
}

/* The cases. */
static void make_files(void) {
  /* a 337-byte ASCII PLY declaring 10^8 vertices */
  char ply[337];
  int n = snprintf(ply, sizeof ply,
                   "ply\nformat ascii 1.0\ncomment hostile\nelement vertex 100000000\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                   "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  memset(ply + n, '\n', sizeof ply - (size_t)n);
  write_bytes("vertex1e8.ply", ply, sizeof ply);
  /* a binary PLY whose face declares 2147483647 indices */
  unsigned char bin[512];
  n = snprintf((char *)bin, sizeof bin,
               "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n");
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  memcpy(bin + n, v, sizeof v), n += (int)sizeof v;
  put32(bin + n, 2147483647u), n += 4;
  for (uint32_t i = 0; i < 3; i++) put32(bin + n, i), n += 4;
  write_bytes("facelist.ply", bin, (size_t)n);
  /* a 309-byte OFF declaring 3535352353 vertices */
  char off[309];
  n = snprintf(off, sizeof off, "OFF\n3535352353 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  memset(off + n, '\n', sizeof off - (size_t)n);
  write_bytes("huge.off", off, sizeof off);
  /* a GLB whose JSON chunk declares 0xff800000 bytes */
  static const char json[] = "{\"asset\":{\"version\":\"2.0\"}}    ";
  unsigned char glb[12 + 8 + sizeof json];
  memcpy(glb, "glTF", 4), put32(glb + 4, 2), put32(glb + 8, sizeof glb);
  put32(glb + 12, 0xff800000u), memcpy(glb + 16, "JSON", 4), memcpy(glb + 20, json, sizeof json);
  write_bytes("chunk.glb", glb, sizeof glb);
  /* a PLY header cut short (assimp loops on it) */
  static const char trunc[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nprop";
  write_bytes("trunc.ply", trunc, sizeof trunc - 1);
  /* a binary STL declaring a million triangles in 134 bytes */
  unsigned char stl[134] = {0};
  put32(stl + 80, 1000000);
  write_bytes("short.stl", stl, sizeof stl);
  /* glTF buffers longer than their data: a data URI, a file beside it */
  static const char gltf_uri[] =
      "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":4000000000,"
      "\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA\"}]}";
  write_bytes("uri.gltf", gltf_uri, sizeof gltf_uri - 1);
  static const char gltf_file[] =
      "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":12},{\"uri\":\"small%20data.bin\","
      "\"byteLength\":3000000000}]}";
  write_bytes("file.gltf", gltf_file, sizeof gltf_file - 1);
  write_bytes("small data.bin", "0123456789ab", 12);
  /* a GLB whose buffer is longer than its BIN chunk */
  {
    static const char js[] = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":1000000}]}  ";
    unsigned char g2[12 + 8 + sizeof js - 1 + 8 + 36] = {0};
    size_t jn = sizeof js - 1; /* a multiple of 4 */
    memcpy(g2, "glTF", 4), put32(g2 + 4, 2), put32(g2 + 8, sizeof g2);
    put32(g2 + 12, (uint32_t)jn), memcpy(g2 + 16, "JSON", 4), memcpy(g2 + 20, js, jn);
    put32(g2 + 20 + jn, 36), memcpy(g2 + 24 + jn, "BIN", 4);
    write_bytes("bin.glb", g2, sizeof g2);
  }
  /* a valid triangle, for the child's crash */
  static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  write_bytes("tri.obj", obj, sizeof obj - 1);
}

/* The command line on a hostile file: exit 1, one line naming the file and the
 * cause (`why`), no output file, quickly and in little memory. */
static void check_cli(const char *file, const char *why) {
  char args[600], out[4096], png[600];
  snprintf(png, sizeof png, "%s/out.png", dir);
  snprintf(args, sizeof args, "render %s -o out.png --size 64x48", file);
  double t0 = now_s();
  int rc = test_run_cli(dir, args, true, out, sizeof out);
  double dt = now_s() - t0;
  int lines = 0;
  for (const char *c = out; *c; c++) lines += *c == '\n';
  struct stat st;
  CHECK(rc == 1, "%s: exit %d (%s)", file, rc, out);
  CHECK(lines == 1 && strstr(out, file) && strstr(out, why), "%s: expected one line naming it and '%s', got: %s", file,
        why, out);
  CHECK(stat(png, &st) != 0, "%s: an output was written", file);
  CHECK(dt < 10, "%s: took %.1f s", file, dt); /* unguarded: a minute or more; here microseconds */
  unlink(png);
}

/* Loads path through the library with the given limits and hook; returns the error. */
static rr_error load_with(const char *path, const rr_import_limits *lim, import_test_hook hook, double *secs) {
  rr_device_set_import_limits(dev, lim);
  rr_device_set_import_test_hook(dev, hook);
  rr_scene *s = NULL;
  double t0 = now_s();
  rr_error e = rr_scene_load(dev, path, &s);
  *secs = now_s() - t0;
  rr_scene_release(s);
  rr_device_set_import_test_hook(dev, IMPORT_HOOK_NONE);
  return e;
}

#if defined(__SANITIZE_ADDRESS__)
#define RR_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RR_ASAN 1
#endif
#endif

static void check_limits(void) {
  char path[512];
  double secs;
  rr_import_limits lim;
  rr_import_limits_init(&lim);
  CHECK(lim.timeout_s == 60 && lim.max_memory > 0 && !lim.in_process && !lim.importer_log,
        "defaults: %g s, %llu bytes, in_process %d", lim.timeout_s, (unsigned long long)lim.max_memory, lim.in_process);

  /* a crash in the child: an error naming the file, the caller alive */
  snprintf(path, sizeof path, "%s/tri.obj", dir);
  rr_error e = load_with(path, &lim, IMPORT_HOOK_CRASH, &secs);
  const char *msg = rr_device_message(dev);
  CHECK(e == RR_ERROR_PARSE && strstr(msg, path) && strstr(msg, "crashed") && !strchr(msg, '\n'),
        "crash in the child: %d '%s'", e, msg);
  /* the same file without the hook loads */
  e = load_with(path, &lim, IMPORT_HOOK_NONE, &secs);
  CHECK(e == RR_OK, "tri.obj: %s", rr_device_message(dev));

  /* the time limit: the truncated header, unchecked, makes assimp loop */
  snprintf(path, sizeof path, "%s/trunc.ply", dir);
  rr_import_limits quick = lim;
  quick.timeout_s = 0.5;
  e = load_with(path, &quick, IMPORT_HOOK_NO_CHECK, &secs);
  msg = rr_device_message(dev);
  CHECK(e == RR_ERROR_PARSE && strstr(msg, path) && strstr(msg, "longer than 0.5 s"), "time limit: %d '%s'", e, msg);
  CHECK(secs < 10, "time limit of 0.5 s: the load took %.1f s", secs);

  /* the memory limit: 10^8 vertices, unchecked, want 1.2 GB; 64 MiB are allowed */
  snprintf(path, sizeof path, "%s/vertex1e8.ply", dir);
  rr_import_limits small = lim;
  small.max_memory = 64u << 20;
  e = load_with(path, &small, IMPORT_HOOK_NO_CHECK, &secs);
  msg = rr_device_message(dev);
#ifdef RR_ASAN
  /* AddressSanitizer's allocator reports and exits rather than failing the allocation */
  CHECK(e != RR_OK && strstr(msg, path), "memory limit: %d '%s'", e, msg);
#else
  CHECK(e == RR_ERROR_MEMORY && strstr(msg, path) && strstr(msg, "out of memory") && strstr(msg, "64 MiB"),
        "memory limit: %d '%s'", e, msg);
#endif
  CHECK(secs < 10, "memory limit: the load took %.1f s", secs);

  /* the checks run in process too */
  rr_import_limits inproc = lim;
  inproc.in_process = 1;
  e = load_with(path, &inproc, IMPORT_HOOK_NONE, &secs);
  CHECK(e == RR_ERROR_PARSE && strstr(rr_device_message(dev), "declares 100000000"), "in process: %s",
        rr_device_message(dev));

  rr_import_limits bad = lim;
  bad.timeout_s = -1;
  CHECK(rr_device_set_import_limits(dev, &bad) == RR_ERROR_ARGUMENT, "a negative timeout was accepted");
  CHECK(rr_device_set_import_limits(dev, NULL) == RR_ERROR_ARGUMENT, "NULL limits were accepted");
  rr_device_set_import_limits(dev, &lim);
}

static bool same_floats(float *const a[3][3], float *const b[3][3], int comps, uint32_t n) {
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < comps; c++) {
      if (!a[k][c] != !b[k][c]) return false;
      if (a[k][c] && memcmp(a[k][c], b[k][c], 4 * (size_t)n) != 0) return false;
    }
  return true;
}

/* Loads in two threads at once, one of them hanging until its time limit: the
 * other, forked first, loads as if alone. */
typedef struct hang_arg {
  rr_error e;
  double done; /* when the load returned */
} hang_arg;

static void *hanging_load(void *arg) {
  hang_arg *h = arg;
  struct timespec pause = {0, 50000000};
  nanosleep(&pause, NULL); /* the other thread's child is running */
  rr_device *d = rr_device_new();
  rr_import_limits lim;
  rr_import_limits_init(&lim);
  lim.timeout_s = 2.5;
  rr_device_set_import_limits(d, &lim);
  rr_device_set_import_test_hook(d, IMPORT_HOOK_NO_CHECK);
  rr_scene *s = NULL;
  h->e = rr_scene_load(d, test_write_file(dir, "trunc2.ply", "ply\nformat ascii 1.0\nelement vertex 3\nprop"), &s);
  h->done = now_s();
  rr_scene_release(s);
  rr_device_release(d);
  return NULL;
}

static void check_threads(void) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return; /* sanitizer builds import in process beside other threads (import_guard.c): nothing would end the hang */
#endif
  /* a mesh whose import takes a moment: n × n quads */
  int n = test_quick() ? 100 : 200;
  char path[512];
  snprintf(path, sizeof path, "%s/big.obj", dir);
  FILE *f = fopen(path, "w");
  if (!f) return;
  for (int y = 0; y <= n; y++)
    for (int x = 0; x <= n; x++) fprintf(f, "v %d %d 0\n", x, y);
  for (int y = 0; y < n; y++)
    for (int x = 0; x < n; x++) {
      int a = y * (n + 1) + x + 1;
      fprintf(f, "f %d %d %d %d\n", a, a + 1, a + n + 2, a + n + 1);
    }
  fclose(f);
  pthread_t t;
  hang_arg h = {RR_OK, 0};
  if (pthread_create(&t, NULL, hanging_load, &h) != 0) return;
  rr_scene *s = NULL;
  rr_error e = rr_scene_load(dev, path, &s);
  double done = now_s();
  rr_scene_info info = {0};
  if (s) rr_scene_get_info(s, &info);
  rr_scene_release(s);
  pthread_join(t, NULL);
  CHECK(e == RR_OK && info.triangles == 2ull * n * n, "the load beside a hanging one: %s (%llu triangles)",
        rr_device_message(dev), (unsigned long long)info.triangles);
  CHECK(done < h.done, "the load waited for the hanging import beside it to be killed");
  CHECK(h.e == RR_ERROR_PARSE, "the hanging load: %d", h.e);
}

static bool v3_eq(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

static bool same_str(const char *a, const char *b) { return (!a && !b) || (a && b && !strcmp(a, b)); }

/* Scene `name` loaded in process and through the child: every array and table equal;
 * `expect` lists what the scene must have for the comparison to mean something: c
 * cameras, l lights, t texels, s skipped faces, g several geometries. */
static void check_same(const char *name, const char *expect) {
  rr_import_limits lim;
  rr_import_limits_init(&lim);
  rr_scene *s[2] = {NULL, NULL};
  for (int k = 0; k < 2; k++) {
    lim.in_process = k;
    rr_device_set_import_limits(dev, &lim);
    CHECK(rr_scene_load(dev, name, &s[k]) == RR_OK, "%s (in_process %d): %s", name, k, rr_device_message(dev));
  }
  rr_import_limits_init(&lim);
  rr_device_set_import_limits(dev, &lim);
  if (!s[0] || !s[1]) {
    rr_scene_release(s[0]), rr_scene_release(s[1]);
    return;
  }
  const rr_scene *a = s[0], *b = s[1];
  CHECK(a->ntris == b->ntris && a->skipped == b->skipped && a->ngeoms == b->ngeoms && a->nmaterials == b->nmaterials &&
            a->ncameras == b->ncameras && a->nlights == b->nlights,
        "%s: %u/%u triangles, %llu/%llu skipped, %u/%u geometries, %u/%u materials, %u/%u cameras, %u/%u lights",
        name, a->ntris, b->ntris, (unsigned long long)a->skipped, (unsigned long long)b->skipped, a->ngeoms, b->ngeoms,
        a->nmaterials, b->nmaterials, a->ncameras, b->ncameras, a->nlights, b->nlights);
  if (a->ntris == b->ntris && a->ngeoms == b->ngeoms && a->nmaterials == b->nmaterials && a->ncameras == b->ncameras &&
      a->nlights == b->nlights) {
    uint32_t n = scene_stored(a); /* the arrays as stored (an instanced mesh once) */
    CHECK(scene_stored(b) == n && (a->inst != NULL) == (b->inst != NULL) &&
              (!a->inst || (a->inst->n == b->inst->n && !memcmp(a->inst->xf, b->inst->xf, a->inst->n * sizeof *a->inst->xf))),
          "%s: instances differ", name);
    CHECK(same_floats(a->p, b->p, 3, n) && same_floats(a->n, b->n, 3, n) && same_floats(a->col, b->col, 3, n), "%s: positions, normals or colours differ", name);
    bool uv = true;
    for (int k = 0; k < 3; k++)
      for (int c = 0; c < 2; c++)
        uv &= !a->uv[k][c] == !b->uv[k][c] && (!a->uv[k][c] || !memcmp(a->uv[k][c], b->uv[k][c], 4 * (size_t)n));
    CHECK(uv, "%s: texture coordinates differ", name);
    CHECK(!memcmp(a->material, b->material, 4 * (size_t)n), "%s: triangle materials differ", name);
    CHECK(!a->file_id == !b->file_id && (!a->file_id || !memcmp(a->file_id, b->file_id, 4 * (size_t)n)),
          "%s: ids differ", name);
    for (uint32_t g = 0; g < a->ngeoms; g++) {
      const scene_geometry *x = &a->geoms[g], *y = &b->geoms[g];
      CHECK(x->first == y->first && x->face == y->face && x->material == y->material && x->kind == y->kind &&
                same_str(x->name == NO_NAME ? NULL : a->names + x->name, y->name == NO_NAME ? NULL : b->names + y->name),
            "%s: geometry %u differs", name, g);
    }
    for (uint32_t m = 0; m < a->nmaterials; m++) {
      const rr_material *x = &a->materials[m], *y = &b->materials[m];
      bool maps = true;
      for (int k = 0; k < RR_MAP_COUNT; k++) maps &= same_str(x->maps[k], y->maps[k]);
      size_t texels = (size_t)x->texture.width * (size_t)x->texture.height * 3;
      CHECK(same_str(x->name, y->name) && !memcmp(x->color, y->color, sizeof x->color) &&
                same_str(x->texture_path, y->texture_path) && x->texture_status == y->texture_status &&
                !memcmp(&x->params, &y->params, sizeof x->params) && maps && x->texture.width == y->texture.width &&
                x->texture.height == y->texture.height && !memcmp(x->texture.wrap, y->texture.wrap, sizeof x->texture.wrap) &&
                (!texels || !memcmp(x->texture.rgb, y->texture.rgb, texels)),
            "%s: material %u differs", name, m);
    }
    for (uint32_t c = 0; c < a->ncameras; c++) {
      const file_camera *x = &a->cameras[c], *y = &b->cameras[c];
      CHECK(same_str(x->name, y->name) && v3_eq(x->eye, y->eye) && v3_eq(x->fwd, y->fwd) && v3_eq(x->up, y->up) &&
                x->fov == y->fov && x->fov_vertical == y->fov_vertical && x->ortho_width == y->ortho_width,
            "%s: camera %u differs", name, c);
    }
    for (uint32_t l = 0; l < a->nlights; l++) {
      rr_light_info x = a->lights[l], y = b->lights[l];
      CHECK(same_str(x.name, y.name), "%s: light %u's name differs", name, l);
      x.name = y.name = NULL;
      CHECK(!memcmp(&x, &y, sizeof x), "%s: light %u differs", name, l);
    }
    CHECK(v3_eq(a->up, b->up) && v3_eq(a->front, b->front), "%s: axes differ", name);
  }
  bool texels = false;
  for (uint32_t m = 0; m < b->nmaterials; m++) texels |= b->materials[m].texture.width > 0;
  CHECK((!strchr(expect, 'c') || b->ncameras) && (!strchr(expect, 'l') || b->nlights) && (!strchr(expect, 't') || texels) &&
            (!strchr(expect, 's') || b->skipped) && (!strchr(expect, 'g') || b->ngeoms > 1),
        "%s: expected '%s': %u cameras, %u lights, texels %d, %llu skipped, %u geometries", name, expect, b->ncameras,
        b->nlights, texels, (unsigned long long)b->skipped, b->ngeoms);
  rr_scene_release(s[0]), rr_scene_release(s[1]);
}

int main(void) {
  if (!mkdtemp(dir)) return test_skip("no temporary directory"), test_done();
  dev = rr_device_new();
  make_files();
  check_cli("vertex1e8.ply", "declares 100000000");
  check_cli("facelist.ply", "2147483647");
  check_cli("huge.off", "3535352353");
  check_cli("chunk.glb", "4286578688");
  check_cli("trunc.ply", "truncated PLY header");
  check_cli("short.stl", "1000000 triangles");
  check_cli("bin.glb", "declares 1000000 bytes but its BIN chunk holds 36");
  check_cli("uri.gltf", "declares 4000000000 bytes but its data URI holds 12");
  check_cli("file.gltf", "buffer 1 declares 3000000000 bytes but its file holds 12");
  /* the largest size the options accept, on a cube camera: refused before any work */
  {
    char out[4096], png[600];
    struct stat st;
    snprintf(png, sizeof png, "%s/out.png", dir);
    double t0 = now_s();
    int rc = test_run_cli(dir, "render plane --camera cube --size 16384x12288 -o out.png", true, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "budget") && strchr(out, '\n') == out + strlen(out) - 1 && stat(png, &st) != 0,
          "16384x12288 cube: exit %d: %s", rc, out);
    CHECK(now_s() - t0 < 10, "16384x12288 cube: refused after %.1f s", now_s() - t0);
  }
  /* outputs replace regular files only: a symbolic link (to a file elsewhere, or to
   * nothing) is refused and stays as it was */
  {
    char out[4096], link[600], target[600];
    snprintf(link, sizeof link, "%s/link.png", dir);
    snprintf(target, sizeof target, "%s/elsewhere.png", dir);
    write_bytes("elsewhere.png", "keep", 4);
    for (int dangling = 0; dangling < 2; dangling++) {
      unlink(link);
      CHECK(symlink(dangling ? "/nonexistent/x.png" : target, link) == 0, "cannot make a symbolic link");
      int rc = test_run_cli(dir, "render plane --size 8x8 -o link.png", true, out, sizeof out);
      struct stat st;
      CHECK(rc == 1 && strstr(out, "symbolic link") && lstat(link, &st) == 0 && S_ISLNK(st.st_mode),
            "output through a %s link: exit %d: %s", dangling ? "dangling" : "", rc, out);
    }
    struct stat st;
    CHECK(stat(target, &st) == 0 && st.st_size == 4, "the link's target changed");
    uint8_t px[3] = {1, 2, 3};
    rr_image img = {.width = 1, .height = 1, .channels = 3, .type = RR_PIXEL_U8, .data = px, .kind = RR_IMAGE_COLOR};
    CHECK(rr_image_write(dev, &img, link) == RR_ERROR_IO && strstr(rr_device_message(dev), "symbolic link"),
          "the library wrote over a symbolic link: %s", rr_device_message(dev));
    unlink(link);
  }
  /* the command line's peak memory over all of them: the checks allocate nothing */
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  CHECK(ru.ru_maxrss < 1024 * 1024, "a refusal's peak memory: %ld KiB", ru.ru_maxrss);
  check_limits();
  check_threads();

  /* the child's scenes equal the in-process ones: every format of the fuzz seeds,
   * a textured model, a glTF with a camera and lights, files appended to a scene
   * (demo, grid) */
  static const char *seeds[] = {"tetra.obj", "tri.dae", "tri.gltf", "tri.off", "tri.ply", "tri.stl", "tri_ascii.stl", "tri_bin.ply"};
  for (size_t i = 0; i < sizeof seeds / sizeof *seeds; i++) {
    /* a seed's first byte picks fuzz_load's extension; the file is the rest */
    char path[512], bytes[4096];
    snprintf(path, sizeof path, "%s/../tests/fuzz/load/%s", RR_DATA_DIR, seeds[i]);
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(bytes, 1, sizeof bytes, f) : 0;
    if (f) fclose(f);
    CHECK(n > 1, "cannot read the seed %s", path);
    if (n > 1) check_same(write_bytes(seeds[i], bytes + 1, n - 1), "");
  }
  check_same(RR_DATA_DIR "/spot.obj", "t");
  check_same("demo", "g");
  check_same("grid:" RR_DATA_DIR "/teapot.obj:2", "g");
  /* dropped faces inside and between geometries: the ids keep their places */
  static const char holes[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\no a\nf 1 2 3\nf 1 1 2\nf 2 4 3\n"
                              "o b\nf 1 1 1\nf 1 2 3\no c\nf 2 2 2\n";
  check_same(write_bytes("holes.obj", holes, sizeof holes - 1), "sg");
  static const char gltf[] =
      "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":8,\"name\":\"bulb\"}]}},"
      "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],\"cameras\":[{\"type\":\"perspective\",\"perspective\":"
      "{\"yfov\":0.7,\"znear\":0.1,\"aspectRatio\":1.5}}],"
      "\"nodes\":[{\"mesh\":0,\"name\":\"tri\"},{\"name\":\"bulb\",\"translation\":[1,2,3],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},{\"camera\":0,\"translation\":[0,0,5]}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
      "\"materials\":[{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,0.125,1]}}],"
      "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
      "\"min\":[0,0,0],\"max\":[1,1,0]}]}";
  const char *g = write_bytes("lit.gltf", gltf, sizeof gltf - 1);
  check_same(g, "cl");
  rr_device_release(dev);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
  return test_done();
}
