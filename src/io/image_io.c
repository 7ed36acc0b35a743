/* Image files by extension: PNG (8-bit), PFM (float), NPY (any pixel type) and
 * OpenEXR (float or uint ids).
 *
 * Writers encode into a temporary file next to the target and rename it over the
 * target only when everything succeeded, so a failure never leaves a partial file.
 * Readers load the whole file into memory and check every size against its length
 * before touching pixels: a malformed file is an RR_ERROR_PARSE, never a crash. */
#define _POSIX_C_SOURCE 200809L

#include "io/io.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

static const uint8_t npy_magic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};

typedef enum image_format { FMT_UNKNOWN = 0, FMT_PNG, FMT_PFM, FMT_EXR, FMT_NPY } image_format;

/* The extension of the last path component, with its dot ("" when none). */
static const char *path_ext(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  return dot ? dot : "";
}

static image_format format_of(const char *path) {
  const char *ext = path_ext(path);
  if (!strcasecmp(ext, ".png")) return FMT_PNG;
  if (!strcasecmp(ext, ".pfm")) return FMT_PFM;
  if (!strcasecmp(ext, ".exr")) return FMT_EXR;
  if (!strcasecmp(ext, ".npy")) return FMT_NPY;
  return FMT_UNKNOWN;
}

static rr_error unknown_format(rr_device *dev, const char *verb, const char *path) {
  const char *ext = path_ext(path);
  if (!*ext)
    return rr_fail(dev, RR_ERROR_ARGUMENT,
                   "cannot %s '%s': no image format extension (use .png, .pfm, .exr or .npy)",
                   verb, path);
  return rr_fail(dev, RR_ERROR_ARGUMENT,
                 "cannot %s '%s': unknown image format '%s' (use .png, .pfm, .exr or .npy)",
                 verb, path, ext);
}

static size_t type_size(rr_pixel_type t) { return t == RR_PIXEL_U8 ? 1 : 4; }

/* ---- little-endian packing (files are little-endian whatever the host) ---- */

static void store_le16(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
}

static void store_le32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
  p[2] = (uint8_t)(v >> 16);
  p[3] = (uint8_t)(v >> 24);
}

static uint32_t load_le16(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8; }

static uint32_t load_le32(const uint8_t *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint32_t load_be32(const uint8_t *p) {
  return (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
}

static uint32_t float_bits(float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

static float bits_float(uint32_t u) {
  float f;
  memcpy(&f, &u, 4);
  return f;
}

/* Sample i (pixel-major, channels interleaved) of an image as a float. */
static float sample_float(const rr_image *img, size_t i) {
  switch (img->type) {
  case RR_PIXEL_U8: return ((const uint8_t *)img->data)[i] / 255.0f;
  case RR_PIXEL_F32: return ((const float *)img->data)[i];
  default: return (float)((const uint32_t *)img->data)[i];
  }
}

/* Clamps to [0,1] and rounds to 8 bits; NaN becomes 0. */
static uint8_t to_u8(float v) {
  if (!(v > 0.0f)) return 0;
  if (v >= 1.0f) return 255;
  return (uint8_t)(v * 255.0f + 0.5f);
}

/* A library's message made one printable line (tinyexr's often end in '\n', stb's
 * may quote bytes of the file). */
static const char *one_line(char *buf, size_t cap, const char *msg) {
  if (!msg || !*msg) return "unknown error";
  snprintf(buf, cap, "%s", msg);
  for (char *p = buf; *p; p++)
    if ((unsigned char)*p < 0x20 || *p == 0x7F) *p = ' ';
  for (size_t n = strlen(buf); n > 0 && buf[n - 1] == ' '; n--) buf[n - 1] = '\0';
  return buf;
}

/* ---- writing through a temporary file ---------------------------------------- */

typedef struct tmp_file {
  const char *path; /* the target, for messages */
  char *name;       /* the temporary */
  FILE *f;
} tmp_file;

/* Creates path.tmp.XXXXXX exclusively. Not mkstemp: it makes the file 0600 and the
 * image would keep that mode; opening with 0666 lets the umask decide as for any
 * other output file. */
static rr_error tmp_create(rr_device *dev, const char *path, tmp_file *t) {
  size_t cap = strlen(path) + 32;
  t->path = path;
  t->f = NULL;
  t->name = malloc(cap);
  if (!t->name) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t seed = (uint64_t)ts.tv_nsec ^ (uint64_t)ts.tv_sec * 2654435761u ^
                  (uint64_t)getpid() << 12 ^ (uint64_t)(uintptr_t)t;
  int fd = -1;
  for (int attempt = 0; attempt < 100; attempt++) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    snprintf(t->name, cap, "%s.tmp.%06lx", path, (unsigned long)(seed >> 40) & 0xFFFFFFul);
    fd = open(t->name, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) break;
  }
  if (fd < 0) {
    int err = errno;
    free(t->name);
    t->name = NULL;
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", path, strerror(err));
  }
  t->f = fdopen(fd, "wb");
  if (!t->f) {
    int err = errno;
    close(fd);
    unlink(t->name);
    free(t->name);
    t->name = NULL;
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", path, strerror(err));
  }
  return RR_OK;
}

/* Closes the temporary and, when status is RR_OK, renames it over the target;
 * otherwise (or when closing or renaming fails) removes it. */
static rr_error tmp_finish(rr_device *dev, tmp_file *t, rr_error status) {
  int err = 0;
  if (status == RR_OK && fflush(t->f) != 0) err = errno;
  if (fclose(t->f) != 0 && status == RR_OK && !err) err = errno;
  if (status == RR_OK && !err && rename(t->name, t->path) != 0) err = errno;
  if (status != RR_OK || err) unlink(t->name);
  free(t->name);
  t->name = NULL;
  if (status == RR_OK && err)
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", t->path, strerror(err));
  return status;
}

static rr_error put(rr_device *dev, tmp_file *t, const void *p, size_t n) {
  errno = 0;
  if (n && fwrite(p, 1, n, t->f) != n)
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", t->path,
                   strerror(errno ? errno : EIO));
  return RR_OK;
}

/* ---- PNG ---------------------------------------------------------------------- */

typedef struct png_sink {
  FILE *f;
  int err; /* errno of the first failed write */
} png_sink;

static void png_write_cb(void *ctx, void *data, int size) {
  png_sink *s = ctx;
  errno = 0;
  if (!s->err && size > 0 && fwrite(data, 1, (size_t)size, s->f) != (size_t)size)
    s->err = errno ? errno : EIO;
}

static rr_error write_png(rr_device *dev, tmp_file *t, const rr_image *img) {
  size_t n = (size_t)img->width * img->height * img->channels;
  const uint8_t *px = img->data;
  uint8_t *conv = NULL;
  if (img->type == RR_PIXEL_F32) {
    conv = malloc(n);
    if (!conv) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", t->path);
    for (size_t i = 0; i < n; i++) conv[i] = to_u8(((const float *)img->data)[i]);
    px = conv;
  }
  png_sink sink = {t->f, 0};
  int ok = stbi_write_png_to_func(png_write_cb, &sink, img->width, img->height, img->channels, px,
                                  img->width * img->channels);
  free(conv);
  if (!ok) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': PNG encoding failed", t->path);
  if (sink.err)
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", t->path, strerror(sink.err));
  return RR_OK;
}

/* ---- PFM ---------------------------------------------------------------------- */

/* PFM rows go bottom to top; a negative scale marks little-endian floats. 8-bit
 * values are written as v / 255, ids as their float (check_fits made sure it is exact). */
static rr_error write_pfm(rr_device *dev, tmp_file *t, const rr_image *img) {
  char head[64];
  int len = snprintf(head, sizeof head, "%s\n%d %d\n-1.0\n", img->channels == 1 ? "Pf" : "PF",
                     img->width, img->height);
  rr_error e = put(dev, t, head, (size_t)len);
  size_t row_samples = (size_t)img->width * img->channels;
  uint8_t *row = malloc(row_samples * 4);
  if (!row) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", t->path);
  for (int y = img->height - 1; y >= 0 && e == RR_OK; y--) {
    size_t base = (size_t)y * row_samples;
    for (size_t i = 0; i < row_samples; i++)
      store_le32(row + 4 * i, float_bits(sample_float(img, base + i)));
    e = put(dev, t, row, row_samples * 4);
  }
  free(row);
  return e;
}

/* ---- NPY ---------------------------------------------------------------------- */

static rr_error write_npy(rr_device *dev, tmp_file *t, const rr_image *img) {
  const char *descr = img->type == RR_PIXEL_U8 ? "|u1" : img->type == RR_PIXEL_F32 ? "<f4" : "<u4";
  char dict[128];
  int n;
  if (img->channels == 1)
    n = snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d), }",
                 descr, img->height, img->width);
  else
    n = snprintf(dict, sizeof dict,
                 "{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d, %d), }", descr,
                 img->height, img->width, img->channels);
  /* magic (6) + version (2) + header length (2) + dict + spaces + '\n': a multiple of 64 */
  uint8_t head[192];
  size_t total = (10 + (size_t)n + 1 + 63) / 64 * 64;
  memcpy(head, npy_magic, 6);
  head[6] = 1;
  head[7] = 0;
  store_le16(head + 8, (uint32_t)(total - 10));
  memcpy(head + 10, dict, (size_t)n);
  memset(head + 10 + n, ' ', total - 10 - (size_t)n - 1);
  head[total - 1] = '\n';
  rr_error e = put(dev, t, head, total);
  if (e) return e;
  size_t row_samples = (size_t)img->width * img->channels;
  if (img->type == RR_PIXEL_U8) return put(dev, t, img->data, row_samples * img->height);
  uint8_t *row = malloc(row_samples * 4);
  if (!row) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", t->path);
  const uint32_t *words = img->data; /* F32 and U32 are both 32-bit words */
  for (int y = 0; y < img->height && e == RR_OK; y++) {
    for (size_t i = 0; i < row_samples; i++)
      store_le32(row + 4 * i, words[(size_t)y * row_samples + i]);
    e = put(dev, t, row, row_samples * 4);
  }
  free(row);
  return e;
}

/* ---- EXR ---------------------------------------------------------------------- */

/* Channel names by channel count; 2 channels (e.g. barycentrics) are stored as R, G. */
static const char *const exr_names[5][4] = {
    {0}, {"Y"}, {"R", "G"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};

/* Encodes an image as a ZIP-compressed scanline EXR in memory: floats as FLOAT
 * channels (8-bit values divided by 255), ids as UINT channels. */
static rr_error encode_exr(rr_device *dev, const rr_image *img, const char *path,
                           unsigned char **mem, size_t *size) {
  int c = img->channels;
  size_t npix = (size_t)img->width * img->height;
  /* OpenEXR lists channels sorted by name, and the pixel data follows that order */
  int order[4];
  for (int i = 0; i < c; i++) {
    int j = i;
    for (; j > 0 && strcmp(exr_names[c][order[j - 1]], exr_names[c][i]) > 0; j--)
      order[j] = order[j - 1];
    order[j] = i;
  }
  EXRChannelInfo info[4];
  int pixel_types[4], requested[4];
  unsigned char *planes[4] = {0};
  int type = img->type == RR_PIXEL_U32 ? TINYEXR_PIXELTYPE_UINT : TINYEXR_PIXELTYPE_FLOAT;
  memset(info, 0, sizeof info);
  for (int k = 0; k < c; k++) {
    int src = order[k];
    snprintf(info[k].name, sizeof info[k].name, "%s", exr_names[c][src]);
    info[k].x_sampling = info[k].y_sampling = 1;
    pixel_types[k] = requested[k] = type;
    planes[k] = malloc(npix * 4);
    if (!planes[k]) {
      for (int i = 0; i < k; i++) free(planes[i]);
      return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
    }
    if (img->type == RR_PIXEL_U32) {
      uint32_t *dst = (uint32_t *)planes[k];
      for (size_t i = 0; i < npix; i++) dst[i] = ((const uint32_t *)img->data)[i * c + src];
    } else {
      float *dst = (float *)planes[k];
      for (size_t i = 0; i < npix; i++) dst[i] = sample_float(img, i * c + src);
    }
  }
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = c;
  header.channels = info;
  header.pixel_types = pixel_types;
  header.requested_pixel_types = requested;
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  EXRImage image;
  InitEXRImage(&image);
  image.images = planes;
  image.width = img->width;
  image.height = img->height;
  image.num_channels = c;
  const char *err = NULL;
  *mem = NULL;
  *size = SaveEXRImageToMemory(&image, &header, mem, &err);
  for (int k = 0; k < c; k++) free(planes[k]);
  /* header and image point at our arrays: not for FreeEXRHeader/FreeEXRImage */
  if (*size == 0) {
    char buf[256];
    rr_error e = rr_fail(dev, RR_ERROR_IO, "cannot write '%s': EXR encoding failed: %s", path,
                         one_line(buf, sizeof buf, err));
    if (err) FreeEXRErrorMessage(err);
    free(*mem);
    *mem = NULL;
    return e;
  }
  return RR_OK;
}

/* ---- writer entry points ------------------------------------------------------ */

/* Checks that the format can hold the image, before any file is made. */
static rr_error check_fits(rr_device *dev, image_format fmt, const rr_image *img,
                           const char *path) {
  int c = img->channels;
  switch (fmt) {
  case FMT_PNG:
    if (img->type == RR_PIXEL_U32)
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PNG holds 8-bit values, not uint32 ids (use .npy or .exr)",
                     path);
    if (c == 2)
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PNG holds 1, 3 or 4 channels, not 2 (use .npy or .exr)",
                     path);
    return RR_OK;
  case FMT_PFM:
    if (c != 1 && c != 3)
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PFM holds 1 or 3 channels, not %d (use .npy or .exr)",
                     path, c);
    if (img->type == RR_PIXEL_U32) {
      /* ids go in as floats only when the float is the id itself */
      const uint32_t *ids = img->data;
      size_t n = (size_t)img->width * img->height * c;
      for (size_t i = 0; i < n; i++) {
        if ((double)(float)ids[i] != (double)ids[i]) {
          size_t pix = i / (size_t)c;
          return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                         "cannot write '%s': id %u at pixel (%zu, %zu) is not exactly a float "
                         "(use .npy or .exr)",
                         path, ids[i], pix % (size_t)img->width, pix / (size_t)img->width);
        }
      }
    }
    return RR_OK;
  case FMT_EXR:
  case FMT_NPY:
  case FMT_UNKNOWN:
    break;
  }
  return RR_OK;
}

rr_error rr_image_write_file(rr_device *dev, const rr_image *img, const char *path) {
  if (!path || !*path) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write an image: no path");
  image_format fmt = format_of(path);
  if (fmt == FMT_UNKNOWN) return unknown_format(dev, "write", path);
  if (!img || !img->data)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': no image data", path);
  if (img->width < 1 || img->height < 1 || img->width > RR_MAX_SIZE || img->height > RR_MAX_SIZE)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad image size %dx%d", path,
                   img->width, img->height);
  if (img->channels < 1 || img->channels > 4)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad channel count %d", path,
                   img->channels);
  if (img->type != RR_PIXEL_U8 && img->type != RR_PIXEL_F32 && img->type != RR_PIXEL_U32)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad pixel type %d", path,
                   (int)img->type);
  rr_error e = check_fits(dev, fmt, img, path);
  if (e) return e;

  /* EXR is encoded in memory first so that an encoding failure makes no file */
  unsigned char *exr = NULL;
  size_t exr_size = 0;
  if (fmt == FMT_EXR && (e = encode_exr(dev, img, path, &exr, &exr_size)) != RR_OK) return e;

  tmp_file t;
  e = tmp_create(dev, path, &t);
  if (e) {
    free(exr);
    return e;
  }
  switch (fmt) {
  case FMT_PNG: e = write_png(dev, &t, img); break;
  case FMT_PFM: e = write_pfm(dev, &t, img); break;
  case FMT_NPY: e = write_npy(dev, &t, img); break;
  case FMT_EXR: e = put(dev, &t, exr, exr_size); break;
  case FMT_UNKNOWN: break;
  }
  free(exr);
  e = tmp_finish(dev, &t, e);
  return e ? e : rr_ok(dev);
}

/* ---- reading ------------------------------------------------------------------ */

/* No valid file is larger: the largest image as 4 × 32-bit channels plus headers. */
#define MAX_FILE_BYTES ((uint64_t)RR_MAX_SIZE * RR_MAX_SIZE * 16 + (1u << 20))

typedef struct blob {
  uint8_t *data;
  size_t size;
} blob;

static rr_error read_all(rr_device *dev, const char *path, blob *b) {
  b->data = NULL;
  b->size = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return rr_fail(dev, RR_ERROR_IO, "cannot read '%s': %s", path, strerror(errno));
  struct stat st;
  if (fstat(fileno(f), &st) != 0) {
    int err = errno;
    fclose(f);
    return rr_fail(dev, RR_ERROR_IO, "cannot read '%s': %s", path, strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    fclose(f);
    return rr_fail(dev, RR_ERROR_IO, "cannot read '%s': not a regular file", path);
  }
  if ((uint64_t)st.st_size > MAX_FILE_BYTES || (uint64_t)st.st_size > SIZE_MAX) {
    fclose(f);
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': too large to be an image", path);
  }
  b->size = (size_t)st.st_size;
  b->data = malloc(b->size ? b->size : 1);
  if (!b->data) {
    fclose(f);
    return rr_fail(dev, RR_ERROR_MEMORY, "cannot read '%s': out of memory", path);
  }
  size_t got = fread(b->data, 1, b->size, f);
  int err = ferror(f) ? errno : 0;
  fclose(f);
  if (got != b->size) {
    free(b->data);
    b->data = NULL;
    if (err) return rr_fail(dev, RR_ERROR_IO, "cannot read '%s': %s", path, strerror(err));
    return rr_fail(dev, RR_ERROR_IO, "cannot read '%s': the file shrank while read", path);
  }
  return RR_OK;
}

static rr_error alloc_image(rr_device *dev, const char *path, int w, int h, int c,
                            rr_pixel_type type, rr_image *out) {
  out->data = malloc((size_t)w * h * c * type_size(type));
  if (!out->data) return rr_fail(dev, RR_ERROR_MEMORY, "cannot read '%s': out of memory", path);
  out->width = w;
  out->height = h;
  out->channels = c;
  out->type = type;
  return RR_OK;
}

static bool size_ok(long long w, long long h) {
  return w >= 1 && h >= 1 && w <= RR_MAX_SIZE && h <= RR_MAX_SIZE;
}

static const char *stbi_why(char *buf, size_t cap) {
  return one_line(buf, cap, stbi_failure_reason());
}

static rr_error read_png(rr_device *dev, const char *path, const blob *b, rr_image *out) {
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (b->size < 8 || memcmp(b->data, sig, 8) != 0)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': not a PNG file", path);
  if (b->size > INT_MAX)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': too large a PNG", path);
  char why[128];
  int w, h, c;
  if (!stbi_info_from_memory(b->data, (int)b->size, &w, &h, &c))
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad PNG header (%s)", path,
                   stbi_why(why, sizeof why));
  if (!size_ok(w, h) || c < 1 || c > 4)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': PNG of %dx%d pixels, %d channels",
                   path, w, h, c);
  int w2, h2, c2;
  uint8_t *px = stbi_load_from_memory(b->data, (int)b->size, &w2, &h2, &c2, 0);
  if (!px)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': corrupt PNG (%s)", path,
                   stbi_why(why, sizeof why));
  rr_error e = RR_OK;
  if (w2 != w || h2 != h || c2 != c)
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': inconsistent PNG header", path);
  else if ((e = alloc_image(dev, path, w, h, c, RR_PIXEL_U8, out)) == RR_OK)
    memcpy(out->data, px, (size_t)w * h * c); /* copied: our images are freed with free() */
  stbi_image_free(px);
  return e;
}

/* A header token of a PFM: the next run of non-space bytes. */
typedef struct cursor {
  const uint8_t *p, *end;
} cursor;

static bool is_space(uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

static bool next_token(cursor *cur, char *tok, size_t cap) {
  while (cur->p < cur->end && is_space(*cur->p)) cur->p++;
  size_t n = 0;
  while (cur->p < cur->end && !is_space(*cur->p)) {
    if (n + 1 >= cap) return false;
    tok[n++] = (char)*cur->p++;
  }
  tok[n] = '\0';
  return n > 0;
}

/* A decimal image side in 1..RR_MAX_SIZE, or -1. */
static int parse_side(const char *tok) {
  long v = 0;
  if (!*tok) return -1;
  for (const char *s = tok; *s; s++) {
    if (*s < '0' || *s > '9') return -1;
    v = v * 10 + (*s - '0');
    if (v > RR_MAX_SIZE) return -1;
  }
  return v >= 1 ? (int)v : -1;
}

/* The sign of a PFM scale (negative: little-endian), 0 when it is not a nonzero
 * decimal number. By hand because strtod follows the locale's decimal point. */
static int scale_sign(const char *tok) {
  const char *s = tok;
  int sign = 1;
  if (*s == '+' || *s == '-') sign = *s++ == '-' ? -1 : 1;
  bool digits = false, nonzero = false, dot = false;
  for (; *s && *s != 'e' && *s != 'E'; s++) {
    if (*s >= '0' && *s <= '9') {
      digits = true;
      nonzero |= *s != '0';
    } else if (*s == '.' && !dot) {
      dot = true;
    } else {
      return 0;
    }
  }
  if (!digits) return 0;
  if (*s) {
    s++;
    if (*s == '+' || *s == '-') s++;
    if (!*s) return 0;
    for (; *s; s++)
      if (*s < '0' || *s > '9') return 0;
  }
  return nonzero ? sign : 0;
}

static rr_error read_pfm(rr_device *dev, const char *path, const blob *b, rr_image *out) {
  cursor cur = {b->data, b->data + b->size};
  char magic[8], ws[16], hs[16], scale[64];
  if (!next_token(&cur, magic, sizeof magic) || (strcmp(magic, "PF") && strcmp(magic, "Pf")))
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': not a PFM file", path);
  int c = magic[1] == 'F' ? 3 : 1;
  int w = next_token(&cur, ws, sizeof ws) ? parse_side(ws) : -1;
  int h = w > 0 && next_token(&cur, hs, sizeof hs) ? parse_side(hs) : -1;
  if (w < 0 || h < 0)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad PFM size (1 to %d expected)", path,
                   RR_MAX_SIZE);
  int sign = next_token(&cur, scale, sizeof scale) ? scale_sign(scale) : 0;
  /* exactly one whitespace byte separates the scale from the pixels */
  if (sign == 0 || cur.p >= cur.end || !is_space(*cur.p))
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad PFM scale", path);
  cur.p++;
  size_t row_samples = (size_t)w * c;
  size_t need = row_samples * h * 4;
  size_t have = (size_t)(cur.end - cur.p);
  if (have < need)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': truncated PFM (%zu of %zu pixel bytes)",
                   path, have, need);
  rr_error e = alloc_image(dev, path, w, h, c, RR_PIXEL_F32, out);
  if (e) return e;
  float *dst = out->data;
  for (int fy = 0; fy < h; fy++) {
    const uint8_t *src = cur.p + (size_t)fy * row_samples * 4;
    float *row = dst + (size_t)(h - 1 - fy) * row_samples; /* file rows go bottom to top */
    for (size_t i = 0; i < row_samples; i++)
      row[i] = bits_float(sign < 0 ? load_le32(src + 4 * i) : load_be32(src + 4 * i));
  }
  return RR_OK;
}

/* NPY header: a Python dict literal with 'descr', 'fortran_order' and 'shape'. */
typedef struct npy_header {
  char descr[16];
  int fortran; /* -1 when absent */
  int ndim;    /* -1 when absent */
  long long shape[4];
} npy_header;

static void skip_ws(const char **s) {
  while (**s == ' ' || **s == '\t' || **s == '\n' || **s == '\r') (*s)++;
}

static bool parse_pystr(const char **s, char *out, size_t cap) {
  char q = **s;
  if (q != '\'' && q != '"') return false;
  (*s)++;
  size_t n = 0;
  while (**s && **s != q) {
    if (n + 1 >= cap) return false;
    out[n++] = *(*s)++;
  }
  if (**s != q) return false;
  (*s)++;
  out[n] = '\0';
  return true;
}

static bool parse_shape(const char **s, long long *dims, int *ndim) {
  if (**s != '(') return false;
  (*s)++;
  *ndim = 0;
  for (;;) {
    skip_ws(s);
    if (**s == ')') break;
    if (**s < '0' || **s > '9' || *ndim == 4) return false;
    long long v = 0;
    while (**s >= '0' && **s <= '9') {
      v = v * 10 + (*(*s)++ - '0');
      if (v > 1000000000) return false;
    }
    dims[(*ndim)++] = v;
    skip_ws(s);
    if (**s == ',') (*s)++;
    else if (**s != ')') return false;
  }
  (*s)++;
  return true;
}

static bool parse_npy_dict(const char *s, npy_header *h) {
  h->descr[0] = '\0';
  h->fortran = -1;
  h->ndim = -1;
  skip_ws(&s);
  if (*s++ != '{') return false;
  for (;;) {
    skip_ws(&s);
    if (*s == '}') break;
    char key[32];
    if (!parse_pystr(&s, key, sizeof key)) return false;
    skip_ws(&s);
    if (*s++ != ':') return false;
    skip_ws(&s);
    if (!strcmp(key, "descr")) {
      if (!parse_pystr(&s, h->descr, sizeof h->descr)) return false;
    } else if (!strcmp(key, "fortran_order")) {
      if (!strncmp(s, "False", 5)) h->fortran = 0, s += 5;
      else if (!strncmp(s, "True", 4)) h->fortran = 1, s += 4;
      else return false;
    } else if (!strcmp(key, "shape")) {
      if (!parse_shape(&s, h->shape, &h->ndim)) return false;
    } else {
      return false;
    }
    skip_ws(&s);
    if (*s == ',') s++;
    else if (*s != '}') return false;
  }
  return h->descr[0] && h->fortran >= 0 && h->ndim >= 0;
}

static rr_error read_npy(rr_device *dev, const char *path, const blob *b, rr_image *out) {
  if (b->size < 10 || memcmp(b->data, npy_magic, 6) != 0)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': not a NPY file", path);
  size_t off, hlen;
  if (b->data[6] == 1) {
    hlen = load_le16(b->data + 8);
    off = 10;
  } else if ((b->data[6] == 2 || b->data[6] == 3) && b->size >= 12) {
    hlen = load_le32(b->data + 8);
    off = 12;
  } else {
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': unsupported NPY version %u", path,
                   (unsigned)b->data[6]);
  }
  if (hlen > b->size - off || hlen > 65536)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': truncated NPY header", path);
  char *text = malloc(hlen + 1);
  if (!text) return rr_fail(dev, RR_ERROR_MEMORY, "cannot read '%s': out of memory", path);
  memcpy(text, b->data + off, hlen);
  text[hlen] = '\0';
  npy_header h;
  bool ok = parse_npy_dict(text, &h);
  free(text);
  if (!ok) return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad NPY header", path);
  rr_pixel_type type;
  if (!strcmp(h.descr, "<f4")) type = RR_PIXEL_F32;
  else if (!strcmp(h.descr, "<u4")) type = RR_PIXEL_U32;
  else if (!strcmp(h.descr, "|u1") || !strcmp(h.descr, "<u1")) type = RR_PIXEL_U8;
  else
    return rr_fail(dev, RR_ERROR_PARSE,
                   "cannot read '%s': unsupported NPY dtype '%s' (<f4, <u4 or |u1 expected)", path,
                   h.descr);
  if (h.fortran)
    return rr_fail(dev, RR_ERROR_PARSE,
                   "cannot read '%s': Fortran-ordered NPY arrays are not supported", path);
  long long c = h.ndim == 3 ? h.shape[2] : 1;
  if ((h.ndim != 2 && h.ndim != 3) || !size_ok(h.shape[1], h.shape[0]) || c < 1 || c > 4)
    return rr_fail(dev, RR_ERROR_PARSE,
                   "cannot read '%s': NPY shape is not an image (H, W) or (H, W, 1..4) of sides "
                   "1 to %d",
                   path, RR_MAX_SIZE);
  int w = (int)h.shape[1], hh = (int)h.shape[0];
  size_t n = (size_t)w * hh * (size_t)c;
  size_t need = n * type_size(type);
  size_t have = b->size - off - hlen;
  if (have < need)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': truncated NPY (%zu of %zu data bytes)",
                   path, have, need);
  rr_error e = alloc_image(dev, path, w, hh, (int)c, type, out);
  if (e) return e;
  const uint8_t *src = b->data + off + hlen;
  if (type == RR_PIXEL_U8) {
    memcpy(out->data, src, n);
  } else {
    uint32_t *dst = out->data;
    for (size_t i = 0; i < n; i++) dst[i] = load_le32(src + 4 * i);
  }
  return RR_OK;
}

/* Where an EXR channel name goes in an RGBA image, -1 when it is not R, G, B or A. */
static int rgba_rank(const char *name) {
  static const char *const names[4] = {"R", "G", "B", "A"};
  for (int i = 0; i < 4; i++)
    if (!strcmp(name, names[i])) return i;
  return -1;
}

/* Reads a single-part scanline EXR with its stored channel count: R, G, B, A come
 * back in that order, other names in file order; half is widened to float and
 * UINT channels give a uint32 image. */
static rr_error read_exr(rr_device *dev, const char *path, const blob *b, rr_image *out) {
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, b->data, b->size) != TINYEXR_SUCCESS)
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': not an OpenEXR file", path);
  if (version.multipart || version.non_image || version.tiled)
    return rr_fail(dev, RR_ERROR_PARSE,
                   "cannot read '%s': multi-part, deep and tiled EXR files are not supported",
                   path);
  EXRHeader header;
  InitEXRHeader(&header);
  EXRImage image;
  InitEXRImage(&image);
  const char *err = NULL;
  char buf[256];
  rr_error e = RR_OK;
  int order[4] = {0, 1, 2, 3};
  long long w = 0, h = 0;
  int c = 0, nuint = 0, nrgba = 0;
  bool ids = false;

  if (ParseEXRHeaderFromMemory(&header, &version, b->data, b->size, &err) != TINYEXR_SUCCESS) {
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad EXR header: %s", path,
                one_line(buf, sizeof buf, err));
    goto done;
  }
  w = (long long)header.data_window.max_x - header.data_window.min_x + 1;
  h = (long long)header.data_window.max_y - header.data_window.min_y + 1;
  c = header.num_channels;
  if (!size_ok(w, h) || c < 1 || c > 4 || header.tiled) {
    e = rr_fail(dev, RR_ERROR_PARSE,
                "cannot read '%s': EXR of %lldx%lld pixels and %d channels (1 to %d pixels a side, "
                "1 to 4 channels, scanlines expected)",
                path, w, h, c, RR_MAX_SIZE);
    goto done;
  }
  for (int k = 0; k < c; k++) {
    if (header.channels[k].x_sampling != 1 || header.channels[k].y_sampling != 1) {
      e = rr_fail(dev, RR_ERROR_PARSE,
                  "cannot read '%s': subsampled EXR channels are not supported", path);
      goto done;
    }
    if (header.pixel_types[k] == TINYEXR_PIXELTYPE_UINT) nuint++;
    else header.requested_pixel_types[k] = TINYEXR_PIXELTYPE_FLOAT;
    nrgba += rgba_rank(header.channels[k].name) >= 0;
  }
  if (nuint != 0 && nuint != c) {
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': EXR mixes uint and float channels", path);
    goto done;
  }
  ids = nuint == c;
  /* tinyexr sets num_channels only on success, yet frees the channel planes of a
   * failed load by that count: set it first so that a failure leaks nothing */
  image.num_channels = c;
  if (LoadEXRImageFromMemory(&image, &header, b->data, b->size, &err) != TINYEXR_SUCCESS) {
    /* tinyexr has released what it allocated but left the pointers dangling */
    InitEXRImage(&image);
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': bad EXR data: %s", path,
                one_line(buf, sizeof buf, err));
    goto done;
  }
  if (!image.images || image.width != w || image.height != h || image.num_channels != c) {
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read '%s': inconsistent EXR image", path);
    goto done;
  }
  if (nrgba == c && c > 1) {
    /* sort the file's channels (alphabetical: A, B, G, R) into R, G, B, A */
    for (int i = 0; i < c; i++) {
      int j = i;
      int rank = rgba_rank(header.channels[i].name);
      for (; j > 0 && rgba_rank(header.channels[order[j - 1]].name) > rank; j--)
        order[j] = order[j - 1];
      order[j] = i;
    }
  }
  e = alloc_image(dev, path, (int)w, (int)h, c, ids ? RR_PIXEL_U32 : RR_PIXEL_F32, out);
  if (e) goto done;
  {
    size_t npix = (size_t)w * h;
    uint32_t *dst = out->data; /* 32-bit words, float or uint alike */
    for (int k = 0; k < c; k++) {
      const uint32_t *src = (const uint32_t *)image.images[order[k]];
      for (size_t i = 0; i < npix; i++) dst[i * c + k] = src[i];
    }
  }

done:
  if (err) FreeEXRErrorMessage(err);
  if (image.images) FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return e;
}

rr_error rr_image_read_file(rr_device *dev, const char *path, rr_image *out) {
  if (!out) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot read an image: no output image");
  memset(out, 0, sizeof *out);
  if (!path || !*path) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot read an image: no path");
  image_format fmt = format_of(path);
  if (fmt == FMT_UNKNOWN) return unknown_format(dev, "read", path);
  blob b;
  rr_error e = read_all(dev, path, &b);
  if (e) return e;
  switch (fmt) {
  case FMT_PNG: e = read_png(dev, path, &b, out); break;
  case FMT_PFM: e = read_pfm(dev, path, &b, out); break;
  case FMT_NPY: e = read_npy(dev, path, &b, out); break;
  case FMT_EXR: e = read_exr(dev, path, &b, out); break;
  case FMT_UNKNOWN: break;
  }
  free(b.data);
  if (e) {
    rr_image_free(out);
    return e;
  }
  return rr_ok(dev);
}

/* ---- public API --------------------------------------------------------------- */

rr_error rr_image_write(rr_device *dev, const rr_image *img, const char *path) {
  return rr_image_write_file(dev, img, path);
}

rr_error rr_image_read(rr_device *dev, const char *path, rr_image *out) {
  return rr_image_read_file(dev, path, out);
}

void rr_image_free(rr_image *img) {
  if (!img) return;
  free(img->data);
  memset(img, 0, sizeof *img);
}
