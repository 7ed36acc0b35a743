/* Image files: PNG (8-bit), PFM (float), NPY (any pixel type) and OpenEXR (floats,
 * uint ids, several AOVs as layers of one file).
 *
 * Writing goes through an output set (rr_output): each file is encoded in memory,
 * then written under a temporary name next to its target; only when every file of
 * the set succeeded are the temporaries renamed over their targets, so a failure
 * leaves no file behind. Standard output and other non-regular targets (devices,
 * FIFOs) cannot be renamed onto: their bytes wait in memory and go out last.
 * Readers load the whole file into memory and check every size against its length
 * before touching pixels: a malformed file is an RR_ERROR_PARSE, never a crash. */
#define _POSIX_C_SOURCE 200809L

#include "io/io.h"
#include "core/color.h"

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

static const char *const format_names[] = {"", "png", "pfm", "exr", "npy"};

/* The extension of the last path component, with its dot ("" when none). */
static const char *path_ext(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  return dot ? dot : "";
}

static image_format format_of(const char *path) {
  const char *ext = path_ext(path);
  for (int f = FMT_PNG; f <= FMT_NPY; f++)
    if (ext[0] == '.' && !strcasecmp(ext + 1, format_names[f])) return (image_format)f;
  return FMT_UNKNOWN;
}

/* The format named by a "fmt:" prefix of spec (and *file past it), FMT_UNKNOWN when
 * there is none (*file = spec). */
static image_format format_prefix(const char *spec, const char **file) {
  *file = spec;
  for (int f = FMT_PNG; f <= FMT_NPY; f++)
    if (!strncasecmp(spec, format_names[f], 3) && spec[3] == ':') {
      *file = spec + 4;
      return (image_format)f;
    }
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

/* Whether sample i of an image is a colour channel (of a colour image, alpha aside). */
static bool is_color(const rr_image *img, size_t i) {
  return img->kind == RR_IMAGE_COLOR && !(img->channels == 4 && i % 4 == 3);
}

/* Sample i (pixel-major, channels interleaved) as a float file holds it: 8-bit
 * values as v / 255, decoded to linear light when colour; ids as their float. */
static float sample_float(const rr_image *img, size_t i) {
  switch (img->type) {
  case RR_PIXEL_U8: {
    float v = ((const uint8_t *)img->data)[i] / 255.0f;
    return is_color(img, i) ? srgb_decode(v) : v;
  }
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

/* Sample i as an 8-bit file holds it: floats clamped and rounded, sRGB-encoded first
 * when colour. */
static uint8_t sample_u8(const rr_image *img, size_t i) {
  if (img->type == RR_PIXEL_U8) return ((const uint8_t *)img->data)[i];
  float v = ((const float *)img->data)[i]; /* check_fits keeps ids out of PNG */
  return to_u8(is_color(img, i) ? srgb_encode(v) : v);
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
/* ---- encoding into memory ------------------------------------------------------ */

typedef struct bytes {
  uint8_t *p;
  size_t n, cap;
  bool nomem; /* an append failed: the buffer is incomplete */
} bytes;

static void bytes_put(bytes *b, const void *p, size_t n) {
  if (b->nomem || n == 0) return;
  if (n > b->cap - b->n) {
    size_t cap = b->cap ? b->cap : 4096;
    while (cap - b->n < n) cap *= 2;
    uint8_t *q = realloc(b->p, cap);
    if (!q) {
      b->nomem = true;
      return;
    }
    b->p = q;
    b->cap = cap;
  }
  memcpy(b->p + b->n, p, n);
  b->n += n;
}

static void bytes_free(bytes *b) {
  free(b->p);
  memset(b, 0, sizeof *b);
}

/* PNG through stb, from a copy converted to 8 bits. */
static void png_write_cb(void *ctx, void *data, int size) {
  if (size > 0) bytes_put(ctx, data, (size_t)size);
}

static bool encode_png(const rr_image *img, bytes *out) {
  size_t n = (size_t)img->width * img->height * img->channels;
  uint8_t *px = malloc(n);
  if (!px) return false;
  for (size_t i = 0; i < n; i++) px[i] = sample_u8(img, i);
  int ok = stbi_write_png_to_func(png_write_cb, out, img->width, img->height, img->channels, px,
                                  img->width * img->channels);
  free(px);
  return ok && !out->nomem;
}

/* PFM rows go bottom to top; a negative scale marks little-endian floats. 8-bit
 * values are written as sample_float gives them, ids as their float (check_fits made
 * sure it is exact). */
static bool encode_pfm(const rr_image *img, bytes *out) {
  char head[64];
  int len = snprintf(head, sizeof head, "%s\n%d %d\n-1.0\n", img->channels == 1 ? "Pf" : "PF",
                     img->width, img->height);
  bytes_put(out, head, (size_t)len);
  size_t row_samples = (size_t)img->width * img->channels;
  for (int y = img->height - 1; y >= 0; y--)
    for (size_t i = 0; i < row_samples; i++) {
      uint8_t w[4];
      store_le32(w, float_bits(sample_float(img, (size_t)y * row_samples + i)));
      bytes_put(out, w, 4);
    }
  return !out->nomem;
}

static bool per_sample_kind(int kind);

/* NPY holds the samples as they are, in the image's own type: (H, W) or (H, W, C); a
 * per-sample AOV is always (H, W, N), shadow-lights (H, W, L). */
static bool encode_npy(const rr_image *img, bytes *out) {
  const char *descr = img->type == RR_PIXEL_U8 ? "|u1" : img->type == RR_PIXEL_F32 ? "<f4" : "<u4";
  char dict[128];
  int n;
  if (img->channels == 1 && !per_sample_kind(img->kind))
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
  bytes_put(out, head, total);
  size_t count = (size_t)img->width * img->height * img->channels;
  if (img->type == RR_PIXEL_U8) {
    bytes_put(out, img->data, count);
  } else {
    const uint32_t *words = img->data; /* F32 and U32 are both 32-bit words */
    for (size_t i = 0; i < count; i++) {
      uint8_t w[4];
      store_le32(w, words[i]);
      bytes_put(out, w, 4);
    }
  }
  return !out->nomem;
}

/* ---- EXR channel names ------------------------------------------------------------ */

/* Values and colour by channel count, as OpenEXR names colour: R, G, B, A (Y alone). */
static const char *const plain_channels[5][4] = {
    {0}, {"Y"}, {"R", "G"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};

/* AOVs: depth in Z as OpenEXR's convention has it; vectors as named layers, which
 * OpenImageIO, Nuke and Blender show as one layer (channels sorted by name read back
 * in this order); ids by what they number. */
#define PER_SAMPLE(p)                                                                                        \
  {0, {p "00", p "01", p "02", p "03", p "04", p "05", p "06", p "07", p "08", p "09", p "10", p "11", p "12", \
       p "13", p "14", p "15"}}
static const struct {
  int channels; /* 0: one per sample, 1 .. RR_MAX_SAMPLES */
  const char *names[RR_MAX_SAMPLES];
} aov_channels[RR_AOV_COUNT] = {
    [RR_AOV_DEPTH] = {1, {"Z"}},
    [RR_AOV_ID] = {1, {"id"}},
    [RR_AOV_NORMAL] = {3, {"N.X", "N.Y", "N.Z"}},
    [RR_AOV_BARY] = {2, {"bary.u", "bary.v"}},
    [RR_AOV_EVALS] = {1, {"evals"}},
    [RR_AOV_NODES] = {1, {"nodes"}},
    [RR_AOV_MESH] = {1, {"mesh"}},
    [RR_AOV_MATERIAL] = {1, {"material"}},
    [RR_AOV_COVERAGE] = {1, {"coverage"}},
    /* a sample per channel, numbered so that sorting by name keeps their order */
    [RR_AOV_SAMPLE_ID] = PER_SAMPLE("id.s"),
    [RR_AOV_SAMPLE_DEPTH] = PER_SAMPLE("Z.s"),
    [RR_AOV_SAMPLE_MESH] = PER_SAMPLE("mesh.s"),
    [RR_AOV_UV] = {2, {"uv.u", "uv.v"}},
    /* two layers, the derivatives along x and along y: sorted as du/dx, dv/dx, du/dy, dv/dy */
    [RR_AOV_UV_DERIV] = {4, {"uvdx.u", "uvdx.v", "uvdy.u", "uvdy.v"}},
    [RR_AOV_ALBEDO] = {3, {"albedo.R", "albedo.G", "albedo.B"}},
    [RR_AOV_DIRECT] = {3, {"direct.R", "direct.G", "direct.B"}},
    [RR_AOV_REFLECTION] = {3, {"reflection.R", "reflection.G", "reflection.B"}},
    [RR_AOV_SHADOW] = {1, {"shadow"}},
    [RR_AOV_EMISSION] = {3, {"emission.R", "emission.G", "emission.B"}},
    [RR_AOV_ZDEPTH] = {1, {"zdepth"}},
    /* a light per channel, as the samples are */
    [RR_AOV_SHADOW_LIGHTS] = PER_SAMPLE("shadow.l"),
    [RR_AOV_INSTANCE] = {1, {"instance"}},
};
_Static_assert(RR_MAX_SHADOW_LIGHTS == RR_MAX_SAMPLES, "PER_SAMPLE names the lights too");
_Static_assert(RR_MAX_SAMPLES == 16, "PER_SAMPLE names 16 samples");

static bool is_aov_kind(int kind) {
  return kind >= RR_IMAGE_AOV && kind < RR_IMAGE_AOV + RR_AOV_COUNT;
}

/* Whether images of kind `kind` have a channel per sample (the sample-* AOVs) or per
 * light (shadow-lights). */
static bool per_sample_kind(int kind) {
  return is_aov_kind(kind) && !aov_channels[kind - RR_IMAGE_AOV].channels;
}

/* Whether an image of kind `kind` may have c channels. */
static bool channels_fit(int kind, int c) {
  if (kind < RR_IMAGE_AOV) return c >= 1 && c <= 4;
  int want = aov_channels[kind - RR_IMAGE_AOV].channels;
  return want ? c == want : c >= 1 && c <= RR_MAX_SAMPLES;
}

/* The EXR name of channel ch of a checked image. */
static const char *exr_channel(const rr_image *img, int ch) {
  if (is_aov_kind(img->kind)) return aov_channels[img->kind - RR_IMAGE_AOV].names[ch];
  return plain_channels[img->channels][ch];
}

typedef struct exr_channel_ref {
  const char *name;
  const rr_image *img;
  int ch;
} exr_channel_ref;

static int cmp_channel(const void *a, const void *b) {
  return strcmp(((const exr_channel_ref *)a)->name, ((const exr_channel_ref *)b)->name);
}

/* Encodes images of one size as the channels of one ZIP-compressed scanline EXR:
 * floats as FLOAT channels (8-bit values as sample_float gives them), ids as UINT.
 * Several images are the layers of one part, as multi-layer EXR files are. */
static rr_error encode_exr(rr_device *dev, const rr_image *images, int n, const char *path,
                           bytes *out) {
  int c = 0;
  for (int i = 0; i < n; i++) c += images[i].channels;
  size_t npix = (size_t)images[0].width * images[0].height;
  exr_channel_ref *refs = calloc((size_t)c, sizeof *refs);
  EXRChannelInfo *info = calloc((size_t)c, sizeof *info);
  int *types = calloc((size_t)c * 2, sizeof *types);
  unsigned char **planes = calloc((size_t)c, sizeof *planes);
  rr_error e = RR_OK;
  if (!refs || !info || !types || !planes) {
    e = rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
    goto done;
  }
  for (int i = 0, k = 0; i < n; i++)
    for (int ch = 0; ch < images[i].channels; ch++, k++)
      refs[k] = (exr_channel_ref){exr_channel(&images[i], ch), &images[i], ch};
  /* OpenEXR lists channels sorted by name, and the pixel data follows that order */
  qsort(refs, (size_t)c, sizeof *refs, cmp_channel);
  for (int k = 0; k < c; k++) {
    if (k > 0 && !strcmp(refs[k].name, refs[k - 1].name)) {
      e = rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': two layers have a channel '%s'", path,
                  refs[k].name);
      goto done;
    }
    const rr_image *img = refs[k].img;
    int ic = img->channels;
    snprintf(info[k].name, sizeof info[k].name, "%s", refs[k].name);
    info[k].x_sampling = info[k].y_sampling = 1;
    types[k] = types[c + k] = img->type == RR_PIXEL_U32 ? TINYEXR_PIXELTYPE_UINT : TINYEXR_PIXELTYPE_FLOAT;
    planes[k] = malloc(npix * 4);
    if (!planes[k]) {
      e = rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
      goto done;
    }
    if (img->type == RR_PIXEL_U32) {
      uint32_t *dst = (uint32_t *)planes[k];
      for (size_t i = 0; i < npix; i++) dst[i] = ((const uint32_t *)img->data)[i * ic + refs[k].ch];
    } else {
      float *dst = (float *)planes[k];
      for (size_t i = 0; i < npix; i++) dst[i] = sample_float(img, i * ic + refs[k].ch);
    }
  }
  {
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = c;
    header.channels = info;
    header.pixel_types = types;
    header.requested_pixel_types = types + c;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    EXRImage image;
    InitEXRImage(&image);
    image.images = planes;
    image.width = images[0].width;
    image.height = images[0].height;
    image.num_channels = c;
    const char *err = NULL;
    unsigned char *mem = NULL;
    size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err);
    /* header and image point at our arrays: not for FreeEXRHeader/FreeEXRImage */
    if (size == 0) {
      char buf[256];
      e = rr_fail(dev, RR_ERROR_IO, "cannot write '%s': EXR encoding failed: %s", path,
                  one_line(buf, sizeof buf, err));
      if (err) FreeEXRErrorMessage(err);
      free(mem);
    } else {
      *out = (bytes){mem, size, size, false};
    }
  }
done:
  for (int k = 0; planes && k < c; k++) free(planes[k]);
  free(planes);
  free(types);
  free(info);
  free(refs);
  return e;
}

/* ---- checks before anything is made ----------------------------------------------- */

static rr_error check_image(rr_device *dev, const rr_image *img, const char *path) {
  if (!img || !img->data)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': no image data", path);
  if (img->width < 1 || img->height < 1 || img->width > RR_MAX_SIZE || img->height > RR_MAX_SIZE)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad image size %dx%d", path,
                   img->width, img->height);
  if (img->channels < 1 || img->channels > RR_MAX_SAMPLES)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad channel count %d", path,
                   img->channels);
  if (img->type != RR_PIXEL_U8 && img->type != RR_PIXEL_F32 && img->type != RR_PIXEL_U32)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad pixel type %d", path,
                   (int)img->type);
  if (img->kind < 0 || img->kind >= RR_IMAGE_AOV + RR_AOV_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad image kind %d", path,
                   img->kind);
  if (!channels_fit(img->kind, img->channels)) {
    if (!is_aov_kind(img->kind) || per_sample_kind(img->kind))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': bad channel count %d", path,
                     img->channels);
    return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': an AOV image of %d channels, %d expected",
                   path, img->channels, aov_channels[img->kind - RR_IMAGE_AOV].channels);
  }
  return RR_OK;
}

/* Checks that the format can hold the image. */
static rr_error check_fits(rr_device *dev, image_format fmt, const rr_image *img,
                           const char *path) {
  int c = img->channels;
  switch (fmt) {
  case FMT_PNG:
    if (img->type == RR_PIXEL_U32)
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PNG holds 8-bit values, not uint32 ids (use .npy or .exr)",
                     path);
    if (c == 2 || c > 4)
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PNG holds 1, 3 or 4 channels, not %d (use .npy or .exr)",
                     path, c);
    if (is_aov_kind(img->kind) && img->type == RR_PIXEL_F32) /* 8 bits would clamp and round them */
      return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                     "cannot write '%s': PNG holds 8-bit colour, not an AOV's floats (use .exr, .npy or .pfm)", path);
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

/* Encodes n checked images (n > 1 only for EXR) in format fmt. */
static rr_error encode(rr_device *dev, image_format fmt, const rr_image *images, int n,
                       const char *path, bytes *out) {
  bool ok = false;
  switch (fmt) {
  case FMT_EXR: return encode_exr(dev, images, n, path, out);
  case FMT_PNG: ok = encode_png(images, out); break;
  case FMT_PFM: ok = encode_pfm(images, out); break;
  case FMT_NPY: ok = encode_npy(images, out); break;
  case FMT_UNKNOWN: break;
  }
  if (ok) return RR_OK;
  bytes_free(out);
  return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
}

/* ---- output sets ------------------------------------------------------------------ */

typedef struct output {
  char *spec;      /* the path as given, with any format prefix (for messages) */
  const char *file;/* the file itself, inside spec */
  char *tmp;       /* a regular file's temporary; NULL for a stream and once renamed */
  bytes data;      /* a stream's bytes, written at commit */
  bool stream;     /* standard output or a non-regular file: written, not renamed onto */
  bool is_stdout;
} output;

struct rr_output {
  rr_device *dev;
  output *v;
  int n, cap;
  bool committed;
};

/* Creates a temporary for file in its directory, exclusively: file.tmp.XXXXXX. Not
 * mkstemp, which makes the file 0600 for good: opening with 0666 lets the umask
 * decide, as for any other output; O_EXCL gives mkstemp's guarantee that two runs
 * never share a temporary. */
static int tmp_create(char *name, size_t cap, const char *file) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t seed = (uint64_t)ts.tv_nsec ^ (uint64_t)ts.tv_sec * 2654435761u ^
                  (uint64_t)getpid() << 12 ^ (uint64_t)(uintptr_t)name;
  int fd = -1;
  for (int attempt = 0; attempt < 100; attempt++) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    snprintf(name, cap, "%s.tmp.%06lx", file, (unsigned long)(seed >> 40) & 0xFFFFFFul);
    fd = open(name, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) break;
  }
  return fd;
}

/* Writes all of b to fd; 0 or an errno. */
static int write_all(int fd, const bytes *b) {
  for (size_t done = 0; done < b->n;) {
    ssize_t w = write(fd, b->p + done, b->n - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return w < 0 ? errno : EIO;
    done += (size_t)w;
  }
  return 0;
}

/* Writes the encoded file to a new temporary for o->file (o->tmp). */
static rr_error write_tmp(rr_device *dev, output *o, const bytes *b) {
  size_t cap = strlen(o->file) + 32;
  o->tmp = malloc(cap);
  if (!o->tmp) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", o->spec);
  int fd = tmp_create(o->tmp, cap, o->file);
  int err = fd < 0 ? errno : write_all(fd, b);
  if (fd >= 0 && close(fd) != 0 && !err) err = errno;
  if (err) {
    if (fd >= 0) unlink(o->tmp);
    free(o->tmp);
    o->tmp = NULL;
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", o->spec, strerror(err));
  }
  return RR_OK;
}

rr_error rr_output_new(rr_device *dev, rr_output **out) {
  if (!out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_output_new: NULL argument");
  *out = calloc(1, sizeof **out);
  if (!*out) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for an output set");
  (*out)->dev = dev;
  return rr_ok(dev);
}

/* The format of an output that names none: what suits the images. */
static image_format default_format(const rr_image *images, int n) {
  if (n > 1) return FMT_EXR;
  return images->kind == RR_IMAGE_COLOR || images->type == RR_PIXEL_U8 ? FMT_PNG : FMT_NPY;
}

/* Checks where an output goes (file inside path, after any format prefix) and
 * starts its entry: a stream or a regular file, not written twice by one set. */
static rr_error output_target(rr_output *set, const char *path, const char *file, output *o) {
  rr_device *dev = set->dev;
  struct stat st;
  bool is_stdout = !strcmp(file, "-");
  bool exists = !is_stdout && stat(file, &st) == 0;
  bool stream = is_stdout || (exists && !S_ISREG(st.st_mode));
  if (exists && S_ISDIR(st.st_mode))
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", path, strerror(EISDIR));
  /* a link to a regular file (or to nothing) would be replaced by the temporary, not
   * written through: refused; a link to a device or FIFO is written through as a stream */
  struct stat lst;
  if (!is_stdout && (!exists || S_ISREG(st.st_mode)) && lstat(file, &lst) == 0 && S_ISLNK(lst.st_mode))
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': a symbolic link%s (name the file it points to, or remove it)",
                   path, exists ? "" : " to nothing");
  for (int i = 0; i < set->n; i++)
    if ((is_stdout && set->v[i].is_stdout) || (!stream && !set->v[i].stream && !strcmp(set->v[i].file, file)))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': %s written twice", path,
                     is_stdout ? "standard output" : "the file");
  if (stream && !is_stdout && access(file, W_OK) != 0)
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", path, strerror(errno));
  *o = (output){.stream = stream, .is_stdout = is_stdout};
  return RR_OK;
}

/* Adds the output o of path with its bytes b, which it takes: a stream keeps them
 * for the commit, a regular file is written to its temporary now. */
static rr_error output_push(rr_output *set, output o, const char *path, const char *file, bytes *b) {
  rr_device *dev = set->dev;
  rr_error e = RR_OK;
  if (set->n == set->cap) {
    int cap = set->cap ? 2 * set->cap : 8;
    output *v = realloc(set->v, (size_t)cap * sizeof *v);
    if (!v) e = rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
    else set->v = v, set->cap = cap;
  }
  if (!e && !(o.spec = strdup(path))) e = rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
  if (!e) o.file = o.spec + (file - path);
  if (!e && o.stream) o.data = *b, *b = (bytes){0}; /* kept for the commit */
  else if (!e) e = write_tmp(dev, &o, b);
  bytes_free(b);
  if (e) {
    free(o.spec);
    return e;
  }
  set->v[set->n++] = o;
  return rr_ok(dev);
}

/* What every add checks first: a set, a path, and the set still open (what: the
 * thing written, for the message). */
static rr_error output_check(const rr_output *set, const char *path, const char *what) {
  if (!set) return RR_ERROR_ARGUMENT;
  if (!path || !*path) return rr_fail(set->dev, RR_ERROR_ARGUMENT, "cannot write %s: no path", what);
  if (set->committed)
    return rr_fail(set->dev, RR_ERROR_ARGUMENT, "cannot write '%s': the output set was committed", path);
  return RR_OK;
}

rr_error rr_output_add(rr_output *set, const rr_image *images, int n, const char *path) {
  rr_error e = output_check(set, path, "an image");
  if (e) return e;
  rr_device *dev = set->dev;
  if (n < 1 || !images) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': no image data", path);
  const char *file;
  image_format fmt = format_prefix(path, &file);
  if (!*file) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': no path after the format", path);
  output o;
  if ((e = output_target(set, path, file, &o)) != RR_OK) return e;
  if (fmt == FMT_UNKNOWN) fmt = format_of(file);
  if (fmt == FMT_UNKNOWN && o.stream) fmt = default_format(images, n);
  if (fmt == FMT_UNKNOWN) return unknown_format(dev, "write", path);
  for (int i = 0; i < n && !e; i++) {
    e = check_image(dev, &images[i], path);
    if (!e && (images[i].width != images[0].width || images[i].height != images[0].height))
      e = rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': layers of %dx%d and %dx%d pixels", path,
                  images[0].width, images[0].height, images[i].width, images[i].height);
  }
  if (e) return e;
  if (n > 1 && fmt != FMT_EXR)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED, "cannot write '%s': only EXR holds several layers", path);
  if ((e = check_fits(dev, fmt, images, path)) != RR_OK) return e;
  bytes b = {0};
  if ((e = encode(dev, fmt, images, n, path, &b)) != RR_OK) return e;
  return output_push(set, o, path, file, &b);
}

rr_error rr_output_add_bytes(rr_output *set, const void *data, size_t size, const char *path) {
  rr_error e = output_check(set, path, "a file");
  if (e) return e;
  rr_device *dev = set->dev;
  if (!data && size) return rr_fail(dev, RR_ERROR_ARGUMENT, "cannot write '%s': no data", path);
  output o;
  if ((e = output_target(set, path, path, &o)) != RR_OK) return e;
  bytes b = {0};
  bytes_put(&b, data, size);
  if (b.nomem) return rr_fail(dev, RR_ERROR_MEMORY, "cannot write '%s': out of memory", path);
  return output_push(set, o, path, path, &b);
}

/* Writes a stream's bytes: the target opened as it is (never created or renamed onto). */
static int write_stream(const output *o) {
  if (o->is_stdout) {
    errno = 0;
    if (fwrite(o->data.p, 1, o->data.n, stdout) != o->data.n || fflush(stdout) != 0)
      return errno ? errno : EIO;
    return 0;
  }
  int fd = open(o->file, O_WRONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  int err = write_all(fd, &o->data);
  if (close(fd) != 0 && !err) err = errno;
  return err;
}

rr_error rr_output_commit(rr_output *set) {
  if (!set) return RR_ERROR_ARGUMENT;
  rr_device *dev = set->dev;
  if (set->committed) return rr_fail(dev, RR_ERROR_ARGUMENT, "an output set is committed once");
  set->committed = true;
  for (int i = 0; i < set->n; i++) {
    output *o = &set->v[i];
    if (!o->tmp) continue;
    if (rename(o->tmp, o->file) == 0) {
      free(o->tmp);
      o->tmp = NULL;
      continue;
    }
    int err = errno;
    /* all or nothing: the files already in place go again; release removes the temporaries */
    for (int j = 0; j < i; j++)
      if (!set->v[j].stream) unlink(set->v[j].file);
    return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", o->spec, strerror(err));
  }
  /* streams after the files, standard output last: a reader gets data only once
   * everything else is in place */
  for (int pass = 0; pass < 2; pass++)
    for (int i = 0; i < set->n; i++) {
      output *o = &set->v[i];
      if (!o->stream || o->is_stdout != (pass == 1)) continue;
      int err = write_stream(o);
      if (err) return rr_fail(dev, RR_ERROR_IO, "cannot write '%s': %s", o->spec, strerror(err));
    }
  return rr_ok(dev);
}

void rr_output_release(rr_output *set) {
  if (!set) return;
  for (int i = 0; i < set->n; i++) {
    if (set->v[i].tmp) unlink(set->v[i].tmp);
    free(set->v[i].tmp);
    bytes_free(&set->v[i].data);
    free(set->v[i].spec);
  }
  free(set->v);
  free(set);
}

/* One call, one set. */
static rr_error write_set(rr_device *dev, const rr_image *images, int n, const char *path) {
  rr_output *set;
  rr_error e = rr_output_new(dev, &set);
  if (e) return e;
  e = rr_output_add(set, images, n, path);
  if (!e) e = rr_output_commit(set);
  rr_output_release(set);
  return e;
}

rr_error rr_image_write(rr_device *dev, const rr_image *img, const char *path) {
  return write_set(dev, img, 1, path);
}

rr_error rr_image_write_layers(rr_device *dev, const rr_image *images, int n, const char *path) {
  return write_set(dev, images, n, path);
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
    /* dtype strings are printable: a control character would end up in a message */
    if (n + 1 >= cap || (unsigned char)**s < 0x20 || (unsigned char)**s >= 0x7f) return false;
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
  /* the kind the channel names say, the channels in aov_channels' order (the file
   * has them sorted by name: albedo.B, albedo.G, albedo.R) */
  out->kind = nrgba == c ? RR_IMAGE_COLOR : RR_IMAGE_VALUES;
  for (int a = 0; a < RR_AOV_COUNT && nrgba == 0 && out->kind == RR_IMAGE_VALUES; a++) {
    int at[4];
    bool same = channels_fit(RR_IMAGE_AOV + a, c);
    for (int k = 0; same && k < c; k++) {
      at[k] = -1;
      for (int j = 0; j < c; j++)
        if (!strcmp(header.channels[j].name, aov_channels[a].names[k])) at[k] = j;
      same = at[k] >= 0;
    }
    if (!same) continue;
    out->kind = RR_IMAGE_AOV + a;
    memcpy(order, at, sizeof(int) * c);
  }
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

rr_error rr_image_read(rr_device *dev, const char *path, rr_image *out) {
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

/* ---- images ------------------------------------------------------------------ */

void rr_image_free(rr_image *img) {
  if (!img) return;
  free(img->data);
  memset(img, 0, sizeof *img);
}
