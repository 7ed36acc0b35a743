/* Image files: exact round trips through PNG, PFM, NPY and EXR, the PFM and NPY
 * layouts on disk, failures that leave no file behind, malformed files read as
 * clean parse errors, and material textures; EXR channel names and layers as
 * tinyexr reads them, colour linear in float files and sRGB in PNG, standard
 * output, /dev/null and FIFOs, and output sets written all or nothing. */
#define _POSIX_C_SOURCE 200809L

#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <dirent.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>


static char dir[64];
static rr_device *dev;

/* dir/name in one of a few rotating buffers. */
static const char *tpath(const char *name) {
  static char buf[8][512];
  static int slot;
  char *p = buf[slot++ & 7];
  snprintf(p, sizeof buf[0], "%s/%s", dir, name);
  return p;
}

static bool exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

static bool put_file(const char *path, const void *data, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return false;
  bool ok = fwrite(data, 1, n, f) == n;
  return fclose(f) == 0 && ok;
}

/* The whole file, malloc'd (NULL when unreadable). */
static uint8_t *get_file(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *data = malloc(len > 0 ? (size_t)len : 1);
  *n = fread(data, 1, (size_t)len, f);
  fclose(f);
  return data;
}

static size_t type_bytes(rr_pixel_type t) { return t == RR_PIXEL_U8 ? 1 : 4; }

static rr_image make_image(int w, int h, int c, rr_pixel_type type) {
  rr_image img = {w, h, c, type, calloc((size_t)w * h * c, type_bytes(type)), RR_IMAGE_VALUES};
  return img;
}

static size_t samples(const rr_image *img) {
  return (size_t)img->width * img->height * img->channels;
}

/* Same size, type and bits. */
static bool same_image(const rr_image *a, const rr_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         a->type == b->type && a->data && b->data &&
         memcmp(a->data, b->data, samples(a) * type_bytes(a->type)) == 0;
}

static bool one_line(const char *msg) { return msg[0] && !strchr(msg, '\n'); }

/* Writes img to name, reads it back into out and checks both calls succeeded. */
static bool round_trip(const rr_image *img, const char *name, rr_image *out) {
  const char *path = tpath(name);
  rr_error e = rr_image_write(dev, img, path);
  CHECK(e == RR_OK, "write %s: %s", name, rr_device_message(dev));
  e = rr_image_read(dev, path, out);
  CHECK(e == RR_OK, "read %s: %s", name, rr_device_message(dev));
  return e == RR_OK;
}

/* A write that must fail with `code` and leave no file at name. */
static void write_fails(const rr_image *img, const char *name, rr_error code) {
  const char *path = tpath(name);
  rr_error e = rr_image_write(dev, img, path);
  CHECK(e == code, "write %s gave %d (%s), %d expected", name, e, rr_device_message(dev), code);
  CHECK(rr_device_error(dev) == code, "device error of %s", name);
  CHECK(one_line(rr_device_message(dev)), "message of %s: '%s'", name, rr_device_message(dev));
  CHECK(!exists(path), "%s exists after a failed write", name);
}

/* A read of bytes stored as name that must fail with RR_ERROR_PARSE. */
static void parse_fails(const char *name, const void *bytes, size_t n, const char *what) {
  const char *path = tpath(name);
  CHECK(put_file(path, bytes, n), "cannot make %s", name);
  rr_image out = {1, 1, 1, RR_PIXEL_U8, NULL, RR_IMAGE_VALUES};
  rr_error e = rr_image_read(dev, path, &out);
  CHECK(e == RR_ERROR_PARSE, "%s (%s, %zu bytes) gave %d: %s", what, name, n, e,
        rr_device_message(dev));
  CHECK(out.data == NULL && out.width == 0, "%s: output not cleared", what);
  CHECK(one_line(rr_device_message(dev)) && strstr(rr_device_message(dev), path),
        "%s: message '%s'", what, rr_device_message(dev));
  rr_image_free(&out);
  unlink(path);
}

/* Truncations of a valid file and garbage behind its magic all fail cleanly. */
static void corrupt_copies(const char *valid, const char *ext, size_t magic_len) {
  size_t n = 0;
  uint8_t *data = get_file(tpath(valid), &n);
  CHECK(data && n > 64, "cannot read back %s", valid);
  if (!data || n <= 64) {
    free(data);
    return;
  }
  char name[32], what[64];
  snprintf(name, sizeof name, "bad%s", ext);
  size_t cuts[] = {0, 1, 4, 8, 11, 16, 33, n / 3, n / 2, n - 24};
  for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
    snprintf(what, sizeof what, "%s cut to %zu bytes", valid, cuts[i]);
    parse_fails(name, data, cuts[i], what);
  }
  uint8_t garbage[512];
  for (size_t i = 0; i < sizeof garbage; i++) garbage[i] = (uint8_t)test_rand();
  snprintf(what, sizeof what, "garbage as %s", ext);
  parse_fails(name, garbage, sizeof garbage, what);
  memcpy(garbage, data, magic_len);
  snprintf(what, sizeof what, "garbage behind the magic of %s", ext);
  parse_fails(name, garbage, sizeof garbage, what);
  free(data);
}

/* ---- PNG ---------------------------------------------------------------------- */

static void test_png(void) {
  int channels[] = {3, 1, 4};
  const char *names[] = {"rgb.png", "gray.png", "rgba.png"};
  for (int k = 0; k < 3; k++) {
    rr_image img = make_image(7, 5, channels[k], RR_PIXEL_U8), out;
    for (size_t i = 0; i < samples(&img); i++) ((uint8_t *)img.data)[i] = (uint8_t)test_rand();
    if (round_trip(&img, names[k], &out))
      CHECK(same_image(&img, &out), "%s differs after a round trip", names[k]);
    rr_image_free(&out);
    rr_image_free(&img);
  }

  /* floats are clamped to [0,1] and rounded; NaN becomes 0 */
  float v[6] = {-0.5f, 0.0f, 0.5f, 1.0f, 2.0f, NAN};
  uint8_t want[6] = {0, 0, 128, 255, 255, 0};
  rr_image f = {6, 1, 1, RR_PIXEL_F32, v, RR_IMAGE_VALUES}, out;
  if (round_trip(&f, "float.PNG", &out)) {
    CHECK(out.type == RR_PIXEL_U8 && out.channels == 1, "float PNG read as type %d, %d channels",
          out.type, out.channels);
    CHECK(out.data && memcmp(out.data, want, 6) == 0, "float to 8-bit conversion");
  }
  rr_image_free(&out);

  rr_image ids = make_image(4, 4, 1, RR_PIXEL_U32);
  write_fails(&ids, "ids.png", RR_ERROR_UNSUPPORTED);
  rr_image_free(&ids);
  rr_image two = make_image(4, 4, 2, RR_PIXEL_U8);
  write_fails(&two, "two.png", RR_ERROR_UNSUPPORTED);
  rr_image_free(&two);

  corrupt_copies("rgb.png", ".png", 8);
  /* a bigger image so that the cuts fall inside the compressed pixels */
  rr_image big = make_image(48, 40, 3, RR_PIXEL_U8);
  for (size_t i = 0; i < samples(&big); i++) ((uint8_t *)big.data)[i] = (uint8_t)test_rand();
  CHECK(rr_image_write(dev, &big, tpath("big.png")) == RR_OK, "%s", rr_device_message(dev));
  corrupt_copies("big.png", ".png", 8);
  rr_image_free(&big);
}

/* ---- PFM ---------------------------------------------------------------------- */

static float le_float(const uint8_t *p) {
  uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  float f;
  memcpy(&f, &u, 4);
  return f;
}

static void test_pfm(void) {
  /* one channel: special and exact values, each pixel distinct to catch a flip */
  rr_image g = make_image(5, 3, 1, RR_PIXEL_F32), out;
  float *gv = g.data;
  for (size_t i = 0; i < samples(&g); i++) gv[i] = (float)i * 0.25f - 1.0f;
  gv[0] = INFINITY;
  gv[1] = -INFINITY;
  gv[2] = 1e-40f; /* subnormal */
  gv[3] = FLT_MAX;
  gv[4] = -0.0f;
  gv[14] = 0.1f;
  if (round_trip(&g, "gray.pfm", &out)) CHECK(same_image(&g, &out), "1-channel PFM round trip");
  rr_image_free(&out);

  /* on disk: "Pf", negative scale, then the bottom row first */
  size_t n = 0;
  uint8_t *raw = get_file(tpath("gray.pfm"), &n);
  const char *head = "Pf\n5 3\n-1.0\n";
  size_t hl = strlen(head);
  CHECK(raw && n == hl + 15 * 4 && memcmp(raw, head, hl) == 0, "PFM header or size (%zu bytes)", n);
  if (raw && n == hl + 15 * 4) {
    CHECK(le_float(raw + hl) == gv[10], "first stored row is not the bottom row");
    CHECK(le_float(raw + hl + 4 * 10) == INFINITY, "last stored row is not the top row");
  }
  free(raw);
  rr_image_free(&g);

  rr_image rgb = make_image(4, 3, 3, RR_PIXEL_F32);
  for (size_t i = 0; i < samples(&rgb); i++) ((float *)rgb.data)[i] = test_randf(-1e6f, 1e6f);
  ((float *)rgb.data)[5] = INFINITY;
  if (round_trip(&rgb, "rgb.pfm", &out)) CHECK(same_image(&rgb, &out), "3-channel PFM round trip");
  rr_image_free(&out);
  raw = get_file(tpath("rgb.pfm"), &n);
  CHECK(raw && n > 3 && memcmp(raw, "PF\n", 3) == 0, "3-channel PFM magic");
  free(raw);
  rr_image_free(&rgb);

  /* ids go in as floats when exact, and fail otherwise */
  rr_image ids = make_image(4, 2, 1, RR_PIXEL_U32);
  uint32_t *iv = ids.data;
  for (int i = 0; i < 8; i++) iv[i] = (uint32_t)i * 1000u;
  iv[7] = 16777216u;
  if (round_trip(&ids, "ids.pfm", &out)) {
    CHECK(out.type == RR_PIXEL_F32 && out.channels == 1, "ids PFM type");
    bool same = out.type == RR_PIXEL_F32;
    for (int i = 0; same && i < 8; i++) same = ((float *)out.data)[i] == (float)iv[i];
    CHECK(same, "ids PFM values");
  }
  rr_image_free(&out);
  iv[3] = RR_MISS;
  write_fails(&ids, "miss.pfm", RR_ERROR_UNSUPPORTED);
  iv[3] = 16777217u;
  write_fails(&ids, "odd.pfm", RR_ERROR_UNSUPPORTED);
  rr_image_free(&ids);
  rr_image two = make_image(2, 2, 2, RR_PIXEL_F32);
  write_fails(&two, "two.pfm", RR_ERROR_UNSUPPORTED);
  rr_image_free(&two);

  /* a big-endian file (positive scale) from another writer */
  const uint8_t be[] = {'P', 'f', '\n', '2', ' ', '1', '\n', '1', '.', '0', '\n',
                        0x3F, 0xC0, 0, 0, 0xC0, 0, 0, 0};
  CHECK(put_file(tpath("be.pfm"), be, sizeof be), "cannot make be.pfm");
  if (rr_image_read(dev, tpath("be.pfm"), &out) == RR_OK) {
    CHECK(out.width == 2 && out.height == 1 && ((float *)out.data)[0] == 1.5f &&
              ((float *)out.data)[1] == -2.0f,
          "big-endian PFM values");
  } else {
    CHECK(0, "big-endian PFM: %s", rr_device_message(dev));
  }
  rr_image_free(&out);

  corrupt_copies("gray.pfm", ".pfm", 3);
  const char *bad[] = {
      "Pf\n0 3\n-1.0\n",    "Pf\n20000 3\n-1.0\n", "Pf\n-3 3\n-1.0\n",
      "Pf\n1 1\n0.0\n....", "Pf\n1 1\nabc\n....",  "Pf\n99999999999999999999 1\n-1\n",
      "PX\n1 1\n-1.0\n....", "Pf\n1 1\n-1.0",       "Pf\n2 2\n-1.0\n........"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
    parse_fails("bad.pfm", bad[i], strlen(bad[i]), bad[i]);
}

/* ---- NPY ---------------------------------------------------------------------- */

/* Checks the NPY header of a file: version 1.0, 64-byte aligned, the dict given. */
static void check_npy_header(const char *name, const char *descr, const char *shape,
                             size_t data_bytes) {
  size_t n = 0;
  uint8_t *raw = get_file(tpath(name), &n);
  CHECK(raw && n >= 10 && memcmp(raw, "\x93" "NUMPY\x01\x00", 8) == 0, "%s: NPY magic", name);
  if (!raw || n < 10) {
    free(raw);
    return;
  }
  size_t hlen = raw[8] | (size_t)raw[9] << 8;
  CHECK((10 + hlen) % 64 == 0, "%s: header of %zu bytes not aligned", name, hlen);
  CHECK(n == 10 + hlen + data_bytes, "%s: %zu bytes, %zu expected", name, n,
        10 + hlen + data_bytes);
  if (10 + hlen <= n) {
    char *text = calloc(hlen + 1, 1);
    memcpy(text, raw + 10, hlen);
    char want[128];
    snprintf(want, sizeof want, "{'descr': '%s', 'fortran_order': False, 'shape': %s, }", descr,
             shape);
    size_t wl = strlen(want);
    CHECK(strncmp(text, want, wl) == 0, "%s: header '%s'", name, text);
    bool spaces = true;
    for (size_t i = wl; i + 1 < hlen; i++) spaces &= text[i] == ' ';
    CHECK(spaces && hlen > wl && text[hlen - 1] == '\n', "%s: padding", name);
    free(text);
  }
  free(raw);
}

static void test_npy(void) {
  rr_image out;
  rr_image f1 = make_image(4, 3, 1, RR_PIXEL_F32);
  for (size_t i = 0; i < samples(&f1); i++) ((float *)f1.data)[i] = test_randf(-10, 10);
  ((float *)f1.data)[1] = INFINITY;
  ((float *)f1.data)[2] = NAN;
  if (round_trip(&f1, "f1.npy", &out)) CHECK(same_image(&f1, &out), "f32 1-channel NPY");
  rr_image_free(&out);
  check_npy_header("f1.npy", "<f4", "(3, 4)", 12 * 4);
  rr_image_free(&f1);

  rr_image f3 = make_image(4, 3, 3, RR_PIXEL_F32);
  for (size_t i = 0; i < samples(&f3); i++) ((float *)f3.data)[i] = test_randf(-10, 10);
  if (round_trip(&f3, "f3.npy", &out)) CHECK(same_image(&f3, &out), "f32 3-channel NPY");
  rr_image_free(&out);
  check_npy_header("f3.npy", "<f4", "(3, 4, 3)", 36 * 4);
  rr_image_free(&f3);

  rr_image u = make_image(5, 2, 1, RR_PIXEL_U32);
  for (size_t i = 0; i < samples(&u); i++) ((uint32_t *)u.data)[i] = test_rand() * 7u;
  ((uint32_t *)u.data)[3] = RR_MISS;
  if (round_trip(&u, "ids.npy", &out)) CHECK(same_image(&u, &out), "u32 NPY with RR_MISS");
  rr_image_free(&out);
  check_npy_header("ids.npy", "<u4", "(2, 5)", 10 * 4);
  rr_image_free(&u);

  rr_image b = make_image(3, 2, 3, RR_PIXEL_U8);
  for (size_t i = 0; i < samples(&b); i++) ((uint8_t *)b.data)[i] = (uint8_t)test_rand();
  if (round_trip(&b, "rgb.npy", &out)) CHECK(same_image(&b, &out), "u8 NPY");
  rr_image_free(&out);
  check_npy_header("rgb.npy", "|u1", "(2, 3, 3)", 18);
  rr_image_free(&b);

  /* a header written differently: double quotes, other key order, no trailing comma */
  const char *dict = "{\"shape\": (1, 2), \"fortran_order\": False, \"descr\": \"<u4\"}";
  uint8_t other[128] = "\x93" "NUMPY\x01\x00";
  size_t dl = strlen(dict);
  other[8] = (uint8_t)(dl + 1);
  memcpy(other + 10, dict, dl);
  other[10 + dl] = '\n';
  uint8_t words[8] = {1, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF};
  memcpy(other + 11 + dl, words, 8);
  CHECK(put_file(tpath("other.npy"), other, 19 + dl), "cannot make other.npy");
  if (rr_image_read(dev, tpath("other.npy"), &out) == RR_OK)
    CHECK(out.type == RR_PIXEL_U32 && out.width == 2 && out.height == 1 &&
              ((uint32_t *)out.data)[0] == 1 && ((uint32_t *)out.data)[1] == RR_MISS,
          "other NPY header");
  else
    CHECK(0, "other.npy: %s", rr_device_message(dev));
  rr_image_free(&out);

  corrupt_copies("f3.npy", ".npy", 8);
  const char *dicts[] = {
      "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1), }",
      "{'descr': '<f4', 'fortran_order': True, 'shape': (1, 1), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 1), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (4,), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1, 9), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 99999), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1, 1, 1, 1), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1)",
      "{'descr': '<f4, 'fortran_order': False, 'shape': (1, 1), }",
      "{'descr': '<f4', 'shape': (1, 1), }",
      "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }", /* data too short */
  };
  for (size_t i = 0; i < sizeof dicts / sizeof dicts[0]; i++) {
    uint8_t file[192] = "\x93" "NUMPY\x01\x00";
    size_t len = strlen(dicts[i]);
    memcpy(file + 10, dicts[i], len);
    file[10 + len] = '\n';
    file[8] = (uint8_t)(len + 1);
    memset(file + 11 + len, 0, 4); /* one float of data */
    parse_fails("bad.npy", file, 15 + len, dicts[i]);
  }
  /* a header length past the end of the file */
  uint8_t longhead[16] = "\x93" "NUMPY\x01\x00\xFF\x7F{}";
  parse_fails("bad.npy", longhead, sizeof longhead, "NPY header length past the end");
}

/* ---- EXR ---------------------------------------------------------------------- */

static void test_exr(void) {
  rr_image out;
  for (int c = 1; c <= 4; c++) {
    rr_image img = make_image(6, 5, c, RR_PIXEL_F32);
    float *v = img.data;
    for (size_t i = 0; i < samples(&img); i++) v[i] = test_randf(-100, 100);
    v[0] = INFINITY;
    v[c] = 1e-40f;
    v[samples(&img) - 1] = FLT_MAX;
    char name[32];
    snprintf(name, sizeof name, "f%d.exr", c);
    if (round_trip(&img, name, &out)) CHECK(same_image(&img, &out), "%d-channel EXR round trip", c);
    rr_image_free(&out);
    rr_image_free(&img);
  }

  /* ids as UINT channels, RR_MISS included */
  rr_image ids = make_image(7, 3, 1, RR_PIXEL_U32);
  for (size_t i = 0; i < samples(&ids); i++) ((uint32_t *)ids.data)[i] = test_rand() * 3u;
  ((uint32_t *)ids.data)[4] = RR_MISS;
  if (round_trip(&ids, "ids.exr", &out)) CHECK(same_image(&ids, &out), "uint32 EXR round trip");
  rr_image_free(&out);
  rr_image_free(&ids);

  /* 8-bit values are stored as v / 255 */
  rr_image b = make_image(3, 2, 3, RR_PIXEL_U8);
  for (size_t i = 0; i < samples(&b); i++) ((uint8_t *)b.data)[i] = (uint8_t)(i * 13);
  if (round_trip(&b, "u8.exr", &out)) {
    bool same = out.type == RR_PIXEL_F32 && out.channels == 3;
    for (size_t i = 0; same && i < samples(&b); i++)
      same = ((float *)out.data)[i] == ((uint8_t *)b.data)[i] / 255.0f;
    CHECK(same, "8-bit EXR values");
  }
  rr_image_free(&out);
  rr_image_free(&b);

  corrupt_copies("f3.exr", ".exr", 8);

  /* a data window far too big */
  size_t n = 0;
  uint8_t *raw = get_file(tpath("f1.exr"), &n);
  const char key[] = "dataWindow\0box2i";
  uint8_t *at = NULL;
  for (size_t i = 0; raw && i + sizeof key + 20 <= n; i++)
    if (memcmp(raw + i, key, sizeof key) == 0) at = raw + i + sizeof key + 4;
  CHECK(at != NULL, "no dataWindow in f1.exr");
  if (at) {
    uint8_t huge[16] = {0, 0, 0, 0x80, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0x7F, 4, 0, 0, 0};
    memcpy(at, huge, 16);
    parse_fails("bad.exr", raw, n, "EXR with a huge data window");
  }
  free(raw);
}

/* ---- failures ------------------------------------------------------------------ */

static void test_failures(void) {
  rr_image img = make_image(3, 3, 3, RR_PIXEL_U8);

  /* a missing directory: RR_ERROR_IO naming the path, nothing made */
  const char *missing = tpath("no/such/dir/x.png");
  CHECK(rr_image_write(dev, &img, missing) == RR_ERROR_IO, "write into a missing directory: %s",
        rr_device_message(dev));
  CHECK(strstr(rr_device_message(dev), missing) && one_line(rr_device_message(dev)), "message '%s'",
        rr_device_message(dev));
  CHECK(!exists(tpath("no")), "a missing directory was made");

  /* unknown or missing extensions */
  write_fails(&img, "out.bmp", RR_ERROR_ARGUMENT);
  CHECK(strstr(rr_device_message(dev), "'.bmp'") != NULL, "message '%s'", rr_device_message(dev));
  write_fails(&img, "out", RR_ERROR_ARGUMENT);
  write_fails(&img, "out.png.bak", RR_ERROR_ARGUMENT);
  rr_image out;
  CHECK(rr_image_read(dev, tpath("in.bmp"), &out) == RR_ERROR_ARGUMENT, "read .bmp");
  CHECK(strstr(rr_device_message(dev), "'.bmp'") != NULL, "message '%s'", rr_device_message(dev));

  /* bad images */
  rr_image bad = img;
  bad.width = 0;
  write_fails(&bad, "bad.npy", RR_ERROR_ARGUMENT);
  bad = img;
  bad.channels = 5;
  write_fails(&bad, "bad.npy", RR_ERROR_ARGUMENT);
  bad = img;
  bad.data = NULL;
  write_fails(&bad, "bad.npy", RR_ERROR_ARGUMENT);
  write_fails(NULL, "bad.npy", RR_ERROR_ARGUMENT);

  /* a missing file is an I/O error */
  CHECK(rr_image_read(dev, tpath("absent.png"), &out) == RR_ERROR_IO, "read a missing file");
  CHECK(out.data == NULL, "output of a failed read");

  /* a write replaces an existing file */
  rr_image second = make_image(2, 2, 1, RR_PIXEL_U8);
  memset(second.data, 77, 4);
  CHECK(rr_image_write(dev, &img, tpath("again.npy")) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_device_error(dev) == RR_OK && rr_device_message(dev)[0] == '\0', "success state");
  if (round_trip(&second, "again.npy", &out)) CHECK(same_image(&second, &out), "overwrite");
  rr_image_free(&out);
  rr_image_free(&second);
  rr_image_free(&img);
}

/* ---- textures ------------------------------------------------------------------- */

static void test_textures(void) {
  rr_image rgb = make_image(4, 2, 3, RR_PIXEL_U8), gray = make_image(2, 3, 1, RR_PIXEL_U8);
  for (size_t i = 0; i < samples(&rgb); i++) ((uint8_t *)rgb.data)[i] = (uint8_t)(i * 9);
  for (size_t i = 0; i < samples(&gray); i++) ((uint8_t *)gray.data)[i] = (uint8_t)(i * 40 + 1);
  CHECK(rr_image_write(dev, &rgb, tpath("tex.png")) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_image_write(dev, &gray, tpath("gray_tex.png")) == RR_OK, "%s", rr_device_message(dev));
  CHECK(mkdir(tpath("sub"), 0777) == 0, "mkdir sub");
  CHECK(rr_image_write(dev, &rgb, tpath("sub/t.png")) == RR_OK, "%s", rr_device_message(dev));

  char rel[] = "tex.png", missing[] = "missing.png", windows[] = "sub\\t.png";
  char absolute[512];
  snprintf(absolute, sizeof absolute, "%s", tpath("gray_tex.png"));
  rr_material mats[5];
  memset(mats, 0, sizeof mats);
  mats[0].texture_path = rel;
  mats[1].texture_path = absolute;
  mats[2].texture_path = missing;
  mats[3].texture_path = NULL;
  mats[4].texture_path = windows;
  rr_scene s;
  memset(&s, 0, sizeof s);
  s.materials = mats;
  s.nmaterials = 5;
  rr_scene_load_textures(&s, dir);

  rr_texture *t = &mats[0].texture;
  CHECK(t->width == 4 && t->height == 2 && t->rgb && memcmp(t->rgb, rgb.data, 24) == 0,
        "relative texture");
  t = &mats[1].texture;
  bool grey_ok = t->width == 2 && t->height == 3 && t->rgb;
  for (int i = 0; grey_ok && i < 6; i++)
    for (int k = 0; k < 3; k++) grey_ok &= t->rgb[3 * i + k] == ((uint8_t *)gray.data)[i];
  CHECK(grey_ok, "absolute gray texture widened to RGB");
  CHECK(mats[2].texture.width == 0 && mats[2].texture.rgb == NULL, "missing texture");
  CHECK(mats[3].texture.width == 0 && mats[3].texture.rgb == NULL, "material without texture");
  t = &mats[4].texture;
  CHECK(t->width == 4 && t->rgb && memcmp(t->rgb, rgb.data, 24) == 0, "backslash path");
  for (int i = 0; i < 5; i++) rr_texture_clear(&mats[i].texture);

  unlink(tpath("sub/t.png"));
  rmdir(tpath("sub"));
  rr_image_free(&rgb);
  rr_image_free(&gray);
}

/* ---- what images hold: EXR names, layers, colour ---------------------------------- */

/* A scene of known colours in front of rr_camera_init's camera: a quad through the
 * centre (geometry 0, colour `rgb`) and a triangle in a corner (geometry 1). */
static rr_scene *colour_scene(const float rgb[3]) {
  static const float quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  static const uint32_t quad_idx[] = {0, 1, 2, 0, 2, 3};
  static const float tri[] = {-1.2f, 0.6f, 0.5f, -0.6f, 0.6f, 0.5f, -0.9f, 1.1f, 0.5f};
  static const uint32_t tri_idx[] = {0, 1, 2};
  static const float green[3] = {0.1f, 0.9f, 0.3f};
  rr_scene *s = NULL;
  rr_error e = rr_scene_new(dev, &s);
  if (!e) e = rr_scene_add_mesh(s, quad, 4, quad_idx, 2, rgb);
  if (!e) e = rr_scene_add_mesh(s, tri, 3, tri_idx, 1, green);
  if (!e) e = rr_scene_commit(s);
  CHECK(e == RR_OK, "colour scene: %s", rr_device_message(dev));
  if (e) rr_scene_release(s);
  return e ? NULL : s;
}

enum { SW = 33, SH = 33 }; /* odd: the centre pixel's ray is the view axis */

/* The colour and every AOV of a frame of colour_scene: images[0] colour, then
 * images[1 + a] AOV a. */
static bool frame_images(const rr_scene *s, rr_image images[1 + RR_AOV_COUNT]) {
  rr_camera cam;
  rr_camera_init(&cam);
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = SW, opt.height = SH, opt.threads = 1, opt.heat = 1;
  rr_frame *f = NULL;
  bool ok = rr_render(dev, s, &cam, &opt, &f) == RR_OK &&
            rr_shade(dev, s, &cam, f, RR_SHADE_LAMBERT, &images[0]) == RR_OK;
  for (int a = 0; ok && a < RR_AOV_COUNT; a++) ok = rr_frame_aov(dev, s, &cam, f, (rr_aov)a, &images[1 + a]) == RR_OK;
  CHECK(ok, "frame images: %s", rr_device_message(dev));
  rr_frame_release(f);
  return ok;
}

/* EXR channel names and types per AOV, read back by tinyexr, one file each and all
 * as the layers of one file with the same names, types and bits. */
static void test_exr_layers(void) {
  static const float rgb[3] = {0.5f, 0.2f, 0.8f};
  static const char *const names[1 + RR_AOV_COUNT][4] = {
      {"B", "G", "R"}, [1 + RR_AOV_DEPTH] = {"Z"}, [1 + RR_AOV_ID] = {"id"},
      [1 + RR_AOV_NORMAL] = {"N.X", "N.Y", "N.Z"}, [1 + RR_AOV_BARY] = {"bary.u", "bary.v"},
      [1 + RR_AOV_EVALS] = {"evals"}, [1 + RR_AOV_NODES] = {"nodes"}, [1 + RR_AOV_MESH] = {"mesh"},
      [1 + RR_AOV_MATERIAL] = {"material"}, [1 + RR_AOV_COVERAGE] = {"coverage"},
      [1 + RR_AOV_SAMPLE_ID] = {"id.s00"}, [1 + RR_AOV_SAMPLE_DEPTH] = {"Z.s00"},
      [1 + RR_AOV_SAMPLE_MESH] = {"mesh.s00"}, [1 + RR_AOV_UV] = {"uv.u", "uv.v"},
      [1 + RR_AOV_UV_DERIV] = {"uvdx.u", "uvdx.v", "uvdy.u", "uvdy.v"},
      [1 + RR_AOV_ALBEDO] = {"albedo.B", "albedo.G", "albedo.R"},
      [1 + RR_AOV_DIRECT] = {"direct.B", "direct.G", "direct.R"},
      [1 + RR_AOV_REFLECTION] = {"reflection.B", "reflection.G", "reflection.R"}, [1 + RR_AOV_SHADOW] = {"shadow"},
      [1 + RR_AOV_EMISSION] = {"emission.B", "emission.G", "emission.R"}, [1 + RR_AOV_ZDEPTH] = {"zdepth"},
      [1 + RR_AOV_SHADOW_LIGHTS] = {"shadow.l00"}, /* the default rig's one light */
      [1 + RR_AOV_INSTANCE] = {"instance"}};
  rr_scene *s = colour_scene(rgb);
  rr_image images[1 + RR_AOV_COUNT];
  memset(images, 0, sizeof images);
  if (!s || !frame_images(s, images)) goto done;
  CHECK(images[0].kind == RR_IMAGE_COLOR, "rr_shade gives colour (kind %d)", images[0].kind);
  int total = 0;
  for (int i = 0; i <= RR_AOV_COUNT; i++) {
    const rr_image *img = &images[i];
    char name[32];
    snprintf(name, sizeof name, "layer%d.exr", i);
    CHECK(i == 0 || img->kind == RR_IMAGE_AOV + i - 1, "AOV %d has kind %d", i - 1, img->kind);
    CHECK(rr_image_write(dev, img, tpath(name)) == RR_OK, "%s: %s", name, rr_device_message(dev));
    test_exr_file x;
    if (!test_exr_load(tpath(name), &x)) {
      test_exr_free(&x);
      continue;
    }
    int want_type = img->type == RR_PIXEL_U32 ? TINYEXR_PIXELTYPE_UINT : TINYEXR_PIXELTYPE_FLOAT;
    CHECK(x.h.num_channels == img->channels, "%s: %d channels", name, x.h.num_channels);
    for (int k = 0; k < x.h.num_channels && k < img->channels; k++) {
      CHECK(!strcmp(x.h.channels[k].name, names[i][k]), "%s: channel %d is '%s', '%s' expected", name, k,
            x.h.channels[k].name, names[i][k]);
      CHECK(x.h.pixel_types[k] == want_type, "%s: channel %s of type %d", name, names[i][k], x.h.pixel_types[k]);
    }
    /* the values are the image's (channels sorted by name: colour B, G, R) */
    bool same = x.img.width == SW && x.img.height == SH;
    for (int k = 0; same && k < img->channels; k++) {
      bool rgb = i == 0 || (i - 1 >= RR_AOV_ALBEDO && img->channels == 3); /* written B, G, R */
      int src = rgb ? 2 - k : k;
      for (size_t p = 0; same && p < (size_t)SW * SH; p++)
        same = memcmp((const uint32_t *)img->data + p * img->channels + src, (const uint32_t *)x.img.images[k] + p, 4) == 0;
    }
    CHECK(same, "%s: values differ from the image's", name);
    test_exr_free(&x);
    total += img->channels;

    /* rastray's reader gives the kind back */
    rr_image back;
    if (rr_image_read(dev, tpath(name), &back) == RR_OK)
      CHECK(back.kind == img->kind, "%s read back as kind %d, %d expected", name, back.kind, img->kind);
    else
      CHECK(0, "%s: %s", name, rr_device_message(dev));
    rr_image_free(&back);
  }

  /* every AOV and the colour as layers of one file: the single files' channels */
  CHECK(rr_image_write_layers(dev, images, 1 + RR_AOV_COUNT, tpath("all.exr")) == RR_OK, "layers: %s",
        rr_device_message(dev));
  test_exr_file all;
  if (test_exr_load(tpath("all.exr"), &all)) {
    CHECK(all.h.num_channels == total, "%d channels in all.exr, %d expected", all.h.num_channels, total);
    for (int i = 0; i <= RR_AOV_COUNT; i++) {
      char name[32];
      snprintf(name, sizeof name, "layer%d.exr", i);
      test_exr_file one;
      if (!test_exr_load(tpath(name), &one)) {
        test_exr_free(&one);
        continue;
      }
      for (int k = 0; k < one.h.num_channels; k++) {
        int j = test_exr_find(&all, one.h.channels[k].name);
        CHECK(j >= 0, "all.exr lacks channel %s", one.h.channels[k].name);
        if (j < 0) continue;
        CHECK(all.h.pixel_types[j] == one.h.pixel_types[k], "all.exr: type of %s", one.h.channels[k].name);
        CHECK(memcmp(all.img.images[j], one.img.images[k], (size_t)SW * SH * 4) == 0, "all.exr: values of %s",
              one.h.channels[k].name);
      }
      test_exr_free(&one);
    }
  }
  test_exr_free(&all);

  /* clashing names, mixed sizes and layers outside EXR are refused, leaving nothing */
  rr_image twice[2] = {images[1 + RR_AOV_DEPTH], images[1 + RR_AOV_DEPTH]};
  CHECK(rr_image_write_layers(dev, twice, 2, tpath("twice.exr")) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "'Z'"),
        "two depth layers: %s", rr_device_message(dev));
  rr_image small = make_image(3, 3, 1, RR_PIXEL_F32);
  rr_image mixed[2] = {images[0], small};
  CHECK(rr_image_write_layers(dev, mixed, 2, tpath("mixed.exr")) == RR_ERROR_ARGUMENT, "layers of two sizes: %s",
        rr_device_message(dev));
  rr_image_free(&small);
  CHECK(rr_image_write_layers(dev, images, 2, tpath("layers.npy")) == RR_ERROR_UNSUPPORTED, "layers as NPY: %s",
        rr_device_message(dev));
  CHECK(!exists(tpath("twice.exr")) && !exists(tpath("mixed.exr")) && !exists(tpath("layers.npy")),
        "a refused layered write left a file");
done:
  for (int i = 0; i <= RR_AOV_COUNT; i++) rr_image_free(&images[i]);
  rr_scene_release(s);
}

/* The sRGB encoding, written out independently of the library's. */
static int srgb8(double linear) {
  double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
  return (int)floor(v * 255 + 0.5);
}

/* Colour in float files is linear light, in PNG sRGB-encoded: a known colour lit
 * head-on (lambert's factor 1 at the centre pixel) through EXR, PFM and PNG. */
static void test_linear_colour(void) {
  static const float rgb[3] = {0.5f, 0.2f, 0.8f};
  rr_scene *s = colour_scene(rgb);
  rr_image images[1 + RR_AOV_COUNT];
  memset(images, 0, sizeof images);
  if (!s || !frame_images(s, images)) goto done;
  const rr_image *colour = &images[0];
  size_t centre = (size_t)(SH / 2) * SW + SW / 2;
  CHECK(rr_image_write(dev, colour, tpath("c.exr")) == RR_OK && rr_image_write(dev, colour, tpath("c.pfm")) == RR_OK &&
            rr_image_write(dev, colour, tpath("c.png")) == RR_OK,
        "colour files: %s", rr_device_message(dev));
  const char *linear[] = {"c.exr", "c.pfm"};
  for (int f = 0; f < 2; f++) {
    rr_image back;
    if (rr_image_read(dev, tpath(linear[f]), &back) != RR_OK) {
      CHECK(0, "%s: %s", linear[f], rr_device_message(dev));
      continue;
    }
    const float *px = (const float *)back.data + 3 * centre;
    for (int c = 0; c < 3; c++)
      CHECK(fabsf(px[c] - rgb[c]) < 1e-5f, "%s: channel %d is %g, linear %g expected", linear[f], c, px[c], rgb[c]);
    rr_image_free(&back);
  }
  rr_image png;
  if (rr_image_read(dev, tpath("c.png"), &png) == RR_OK) {
    const uint8_t *px = (const uint8_t *)png.data + 3 * centre;
    for (int c = 0; c < 3; c++)
      CHECK(px[c] == srgb8(rgb[c]), "PNG channel %d is %d, sRGB %d expected", c, px[c], srgb8(rgb[c]));
    rr_image_free(&png);
  } else {
    CHECK(0, "c.png: %s", rr_device_message(dev));
  }

  /* 8-bit colour goes to float files decoded, alpha untouched; plain values as v / 255 */
  uint8_t enc[4] = {(uint8_t)srgb8(0.5), 0, 255, 128};
  rr_image c8 = {1, 1, 4, RR_PIXEL_U8, enc, RR_IMAGE_COLOR}, back;
  if (round_trip(&c8, "c8.exr", &back)) {
    const float *px = back.data;
    double want = pow((enc[0] / 255.0 + 0.055) / 1.055, 2.4); /* sRGB decoding, near 0.5 */
    CHECK(fabs(px[0] - want) < 1e-5 && px[1] == 0 && px[2] == 1 && px[3] == 128 / 255.0f,
          "8-bit colour in EXR: %g %g %g %g", px[0], px[1], px[2], px[3]);
  }
  rr_image_free(&back);
done:
  for (int i = 0; i <= RR_AOV_COUNT; i++) rr_image_free(&images[i]);
  rr_scene_release(s);
}

/* ---- outputs that are not regular files, and output sets -------------------------- */

/* The bytes that rr_image_write(img, spec) sends to standard output. */
static uint8_t *stdout_bytes(const rr_image *img, const char *spec, size_t *n, rr_error *e) {
  fflush(stdout);
  int saved = dup(STDOUT_FILENO);
  int fd = open(tpath("stdout.bin"), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  dup2(fd, STDOUT_FILENO);
  close(fd);
  *e = rr_image_write(dev, img, spec);
  fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
  uint8_t *data = get_file(tpath("stdout.bin"), n);
  unlink(tpath("stdout.bin"));
  return data;
}

static void test_streams(void) {
  float v[12] = {0.5f, 0.25f, 1, 0, 0, 0, 1, 1, 1, 0.1f, 0.2f, 0.3f};
  rr_image colour = {2, 2, 3, RR_PIXEL_F32, v, RR_IMAGE_COLOR};
  uint32_t idv[4] = {1, 2, RR_MISS, 4};
  rr_image ids = {2, 2, 1, RR_PIXEL_U32, idv, RR_IMAGE_AOV + RR_AOV_ID};

  /* /dev/null takes any format, or none */
  const char *nulls[] = {"/dev/null", "exr:/dev/null", "npy:/dev/null"};
  for (int i = 0; i < 3; i++) {
    CHECK(rr_image_write(dev, &colour, nulls[i]) == RR_OK, "colour to %s: %s", nulls[i], rr_device_message(dev));
    CHECK(rr_image_write(dev, &ids, nulls[i]) == RR_OK || i == 0, "ids to %s: %s", nulls[i], rr_device_message(dev));
  }
  CHECK(rr_image_write(dev, &ids, "/dev/null") == RR_OK, "ids to /dev/null (NPY): %s", rr_device_message(dev));
  CHECK(rr_image_write(dev, &ids, "png:/dev/null") == RR_ERROR_UNSUPPORTED, "ids as PNG to /dev/null");
  struct stat st;
  CHECK(stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode), "/dev/null is no longer a device");

  /* standard output: PNG for colour and NPY for AOVs by default, or as named */
  struct {
    const rr_image *img;
    const char *spec;
    const char *magic;
  } outs[] = {{&colour, "-", "\x89PNG"}, {&ids, "-", "\x93NUMPY"}, {&colour, "exr:-", "\x76\x2f\x31\x01"},
              {&ids, "EXR:-", "\x76\x2f\x31\x01"}, {&colour, "pfm:-", "PF\n"}};
  for (size_t i = 0; i < sizeof outs / sizeof outs[0]; i++) {
    size_t n = 0;
    rr_error e;
    uint8_t *data = stdout_bytes(outs[i].img, outs[i].spec, &n, &e);
    size_t ml = strlen(outs[i].magic);
    CHECK(e == RR_OK && data && n > ml && memcmp(data, outs[i].magic, ml) == 0, "%s to stdout: %d bytes, %s", outs[i].spec,
          (int)n, rr_device_message(dev));
    free(data);
  }
  CHECK(rr_image_write(dev, &colour, "gif:-") == RR_ERROR_ARGUMENT, "gif:- is no format");
  CHECK(rr_image_write(dev, &colour, "png:") == RR_ERROR_ARGUMENT, "png: without a path");

  /* a FIFO is written into, not replaced */
  const char *fifo = tpath("fifo");
  CHECK(mkfifo(fifo, 0600) == 0, "mkfifo");
  int rd = open(fifo, O_RDONLY | O_NONBLOCK);
  CHECK(rd >= 0, "open the FIFO");
  CHECK(rr_image_write(dev, &ids, fifo) == RR_OK, "ids to a FIFO: %s", rr_device_message(dev));
  uint8_t buf[512];
  ssize_t got = rd >= 0 ? read(rd, buf, sizeof buf) : -1;
  CHECK(got > 16 && memcmp(buf, "\x93NUMPY", 6) == 0, "FIFO received %d bytes", (int)got);
  if (rd >= 0) close(rd);
  CHECK(stat(fifo, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO was replaced");
  unlink(fifo);
}

static int count_entries(const char *path) {
  DIR *d = opendir(path);
  int n = 0;
  for (struct dirent *e; d && (e = readdir(d)) != NULL;) n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  if (d) closedir(d);
  return n;
}

/* A set whose last output fails leaves nothing, in a fresh directory. */
static void test_output_sets(void) {
  const char *sub = tpath("set");
  CHECK(mkdir(sub, 0777) == 0, "mkdir set");
  char a[600], b[600], c[600], d[600];
  snprintf(a, sizeof a, "%s/a.png", sub);
  snprintf(b, sizeof b, "%s/b.exr", sub);
  snprintf(c, sizeof c, "%s/c.npy", sub);
  snprintf(d, sizeof d, "%s/d.pfm", sub);
  float v[12] = {0};
  rr_image colour = {2, 2, 3, RR_PIXEL_F32, v, RR_IMAGE_COLOR};
  uint32_t idv[4] = {1, 2, RR_MISS, 4};
  rr_image ids = {2, 2, 1, RR_PIXEL_U32, idv, RR_IMAGE_AOV + RR_AOV_ID};
  rr_image layers[2] = {colour, ids};

  rr_output *set;
  CHECK(rr_output_new(dev, &set) == RR_OK, "rr_output_new");
  CHECK(rr_output_add(set, &colour, 1, a) == RR_OK && rr_output_add(set, layers, 2, b) == RR_OK &&
            rr_output_add(set, &ids, 1, c) == RR_OK,
        "adds: %s", rr_device_message(dev));
  CHECK(!exists(a) && !exists(b) && !exists(c), "an output appeared before the commit");
  CHECK(count_entries(sub) == 3, "%d temporaries for 3 outputs", count_entries(sub));
  CHECK(rr_output_add(set, &ids, 1, d) == RR_ERROR_UNSUPPORTED, "ids with RR_MISS as PFM: %s", rr_device_message(dev));
  CHECK(rr_output_add(set, &colour, 1, "-") == RR_OK && rr_output_add(set, &colour, 1, "png:-") == RR_ERROR_ARGUMENT,
        "a second standard output: %s", rr_device_message(dev));
  CHECK(rr_output_add(set, &colour, 1, a) == RR_ERROR_ARGUMENT, "a file twice: %s", rr_device_message(dev));
  rr_output_release(set);
  CHECK(count_entries(sub) == 0, "a failed set left %d files", count_entries(sub));

  /* a rename that fails at the commit takes back the renames before it */
  CHECK(rr_output_new(dev, &set) == RR_OK, "rr_output_new");
  CHECK(rr_output_add(set, &colour, 1, a) == RR_OK && rr_output_add(set, &ids, 1, c) == RR_OK, "adds: %s",
        rr_device_message(dev));
  char inside[640];
  snprintf(inside, sizeof inside, "%s/keep", c);
  CHECK(mkdir(c, 0777) == 0 && put_file(inside, "x", 1), "a directory in c.npy's way");
  CHECK(rr_output_commit(set) == RR_ERROR_IO && strstr(rr_device_message(dev), c), "commit onto a directory: %s",
        rr_device_message(dev));
  CHECK(rr_output_commit(set) == RR_ERROR_ARGUMENT, "a second commit");
  rr_output_release(set);
  CHECK(!exists(a), "a.png stayed after a failed commit");
  CHECK(count_entries(sub) == 1, "%d files after a failed commit (the directory alone expected)", count_entries(sub));
  unlink(inside);
  rmdir(c);

  /* a good set appears whole */
  CHECK(rr_output_new(dev, &set) == RR_OK, "rr_output_new");
  CHECK(rr_output_add(set, &colour, 1, a) == RR_OK && rr_output_add(set, layers, 2, b) == RR_OK &&
            rr_output_add(set, &ids, 1, "npy:/dev/null") == RR_OK && rr_output_commit(set) == RR_OK,
        "a good set: %s", rr_device_message(dev));
  rr_output_release(set);
  CHECK(exists(a) && exists(b) && count_entries(sub) == 2, "a good set wrote %d files", count_entries(sub));
  unlink(a);
  unlink(b);
  rmdir(sub);
}

/* Removes the files of dir; counts those that look like leftover temporaries. */
static int clean_dir(void) {
  int leftovers = 0;
  DIR *d = opendir(dir);
  if (!d) return 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (strstr(e->d_name, ".tmp.")) {
      leftovers++;
      fprintf(stderr, "leftover temporary %s\n", e->d_name);
    }
    unlink(tpath(e->d_name));
  }
  closedir(d);
  rmdir(dir);
  return leftovers;
}

int main(void) {
  snprintf(dir, sizeof dir, "/tmp/rr_image_io_XXXXXX");
  if (!mkdtemp(dir)) {
    perror("mkdtemp");
    return 1;
  }
  dev = rr_device_new();
  test_png();
  test_pfm();
  test_npy();
  test_exr();
  test_failures();
  test_textures();
  test_exr_layers();
  test_linear_colour();
  test_streams();
  test_output_sets();
  rr_device_release(dev);
  int leftovers = clean_dir();
  CHECK(leftovers == 0, "%d temporaries left behind", leftovers);
  CHECK(!exists(dir), "%s not removed", dir);
  return test_done();
}
