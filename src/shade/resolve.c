/* Resolve: a filter over every sample near a pixel's centre, in linear light. The
 * weight of a sample depends only on its position in its pixel and that pixel's
 * offset from the one resolved, the same for every pixel: it is tabulated once per
 * frame as taps (pixel offset, sample, weight), and a pixel is a sum over the taps
 * that land inside the image, normalised by the weights it met (so the border needs
 * no special case and a constant image stays constant). */
#include "shade/resolve.h"
#include "core/vec.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static const char *const filter_names[RR_FILTER_COUNT] = {"box", "mitchell", "blackman-harris"};
static const float default_radius[RR_FILTER_COUNT] = {0.5f, 2.0f, 1.5f};

int rr_filter_from_name(const char *name) {
  for (int i = 0; name && i < RR_FILTER_COUNT; i++)
    if (!strcmp(name, filter_names[i])) return i;
  return -1;
}

const char *rr_filter_name(int filter) {
  return filter >= 0 && filter < RR_FILTER_COUNT ? filter_names[filter] : NULL;
}

/* Mitchell–Netravali's cubic at |x| in [0, 2), B = C = 1/3 (their recommendation). */
static double mitchell(double x) {
  const double B = 1.0 / 3, C = 1.0 / 3;
  x = fabs(x);
  if (x < 1) return ((12 - 9 * B - 6 * C) * x * x * x + (-18 + 12 * B + 6 * C) * x * x + (6 - 2 * B)) / 6;
  if (x < 2) return ((-B - 6 * C) * x * x * x + (6 * B + 30 * C) * x * x + (-12 * B - 48 * C) * x + (8 * B + 24 * C)) / 6;
  return 0;
}

/* The filter's 1D weight at offset x from the centre, radius r. Half-open support
 * [-r, r): with the box's r = 0.5 a pixel takes exactly its own samples. */
static double filter_1d(rr_filter f, double x, double r) {
  if (!(x >= -r && x < r)) return 0;
  switch (f) {
  case RR_FILTER_MITCHELL: return mitchell(2 * x / r);
  case RR_FILTER_BLACKMAN_HARRIS: { /* the window over [-r, r], centred */
    const double a0 = 0.35875, a1 = 0.48829, a2 = 0.14128, a3 = 0.01168, p = RR_PI * x / r;
    return a0 + a1 * cos(p) + a2 * cos(2 * p) + a3 * cos(3 * p);
  }
  default: return 1;
  }
}

typedef struct tap {
  int dx, dy;
  ptrdiff_t off; /* of the sample from the pixel's, in samples: s·width·height + dy·width + dx */
  double f;
} tap;

typedef struct resolve_job {
  const resolve_input *in;
  const tap *taps, *own; /* the filter's; the box of the pixel's own samples */
  int ntaps, reach; /* reach: the farthest tap, in pixels */
  float *out;
  int channels;
  bool failed; /* a box job found no memory */
} resolve_job;

enum { ROWS_PER_JOB = 16 };

/* The sums of pixel (x, y) over the taps inside the image: Σ f·w·a·rgb in sum[0..2],
 * Σ f·w·a in sum[3], Σ f·w in sum[4]; in double, so a constant stays one. */
static inline void sums_of(const resolve_input *in, const tap *taps, int ntaps, int x, int y, bool clip,
                           bool weighed, double sum[5]) {
  int w = in->width, h = in->height;
  ptrdiff_t k0 = (ptrdiff_t)y * w + x;
  double r = 0, g = 0, b = 0, wa = 0, wt = 0;
  for (const tap *tp = taps; tp < taps + ntaps; tp++) {
    if (clip && ((unsigned)(x + tp->dx) >= (unsigned)w || (unsigned)(y + tp->dy) >= (unsigned)h)) continue;
    ptrdiff_t k = k0 + tp->off;
    double f = tp->f, fa = f;
    if (weighed) {
      if (in->weight) f *= in->weight[k];
      fa = in->alpha ? f * in->alpha[k] : f;
    }
    const float *c = in->rgb + 3 * k;
    r += fa * c[0], g += fa * c[1], b += fa * c[2], wa += fa, wt += f;
  }
  sum[0] = r, sum[1] = g, sum[2] = b, sum[3] = wa, sum[4] = wt;
}

/* The same, specialised: taps may fall outside the image only near its border
 * (reach: how far they go), and most inputs have neither weights nor alpha. */
static void pixel_sums(const resolve_input *in, const tap *taps, int ntaps, int reach, int x, int y, double sum[5]) {
  bool clip = x < reach || y < reach || x >= in->width - reach || y >= in->height - reach;
  bool weighed = in->weight || in->alpha;
  if (clip) sums_of(in, taps, ntaps, x, y, true, weighed, sum);
  else if (weighed) sums_of(in, taps, ntaps, x, y, false, true, sum);
  else sums_of(in, taps, ntaps, x, y, false, false, sum);
}

static void resolve_rows(int job, int thread, void *arg) {
  (void)thread;
  const resolve_job *j = arg;
  const resolve_input *in = j->in;
  int y1 = (job + 1) * ROWS_PER_JOB < in->height ? (job + 1) * ROWS_PER_JOB : in->height;
  for (int y = job * ROWS_PER_JOB; y < y1; y++)
    for (int x = 0; x < in->width; x++) {
      double sum[5];
      pixel_sums(in, j->taps, j->ntaps, j->reach, x, y, sum);
      /* negative lobes over sparse weights may leave nothing positive to divide by:
       * the pixel's own samples then decide, as the box would */
      if (!(sum[3] > 0 && sum[4] > 0)) pixel_sums(in, j->own, in->samples, 0, x, y, sum);
      resolve_finish(sum, j->out + (size_t)j->channels * ((size_t)y * in->width + x), j->channels);
    }
}

/* The box of the pixel's own samples: the same sums as resolve_rows, in the same
 * order (sample 0 first), but layer by layer along a row, so that every loop
 * streams contiguous floats (a pixel's samples lie a power of two apart). */
static void resolve_box_rows(int job, int thread, void *arg) {
  (void)thread;
  resolve_job *j = arg;
  const resolve_input *in = j->in;
  size_t w = (size_t)in->width, layer = w * in->height;
  bool weighed = in->weight || in->alpha;
  double *acc = malloc((weighed ? 5 : 3) * w * sizeof *acc); /* Σ f·a·rgb (3 per pixel); Σ f·a; Σ f */
  if (!acc) {
    j->failed = true;
    return;
  }
  double *wa = acc + 3 * w, *wt = acc + 4 * w;
  int y1 = (job + 1) * ROWS_PER_JOB < in->height ? (job + 1) * ROWS_PER_JOB : in->height;
  for (int y = job * ROWS_PER_JOB; y < y1; y++) {
    for (int s = 0; s < in->samples; s++) {
      size_t k0 = s * layer + (size_t)y * w;
      const float *rgb = in->rgb + 3 * k0;
      if (!weighed) { /* the common case: plain sums, the first sample their start; a pixel
                         per step (a loop over 3·w floats costs 3 times the loop's overhead) */
        double *a = acc;
        if (s == 0)
          for (const float *c = rgb; c < rgb + 3 * w; c += 3, a += 3) a[0] = c[0], a[1] = c[1], a[2] = c[2];
        else
          for (const float *c = rgb; c < rgb + 3 * w; c += 3, a += 3) a[0] += c[0], a[1] += c[1], a[2] += c[2];
        continue;
      }
      for (size_t x = 0; x < w; x++) {
        double f = in->weight ? in->weight[k0 + x] : 1.0, fa = in->alpha ? f * in->alpha[k0 + x] : f;
        double *a = acc + 3 * x;
        if (s == 0) a[0] = fa * rgb[3 * x], a[1] = fa * rgb[3 * x + 1], a[2] = fa * rgb[3 * x + 2], wa[x] = fa, wt[x] = f;
        else a[0] += fa * rgb[3 * x], a[1] += fa * rgb[3 * x + 1], a[2] += fa * rgb[3 * x + 2], wa[x] += fa, wt[x] += f;
      }
    }
    float *o = j->out + (size_t)j->channels * y * w;
    double n = in->samples;
    for (size_t x = 0; x < w; x++) {
      double sum[5] = {acc[3 * x], acc[3 * x + 1], acc[3 * x + 2], weighed ? wa[x] : n, weighed ? wt[x] : n};
      resolve_finish(sum, o + j->channels * x, j->channels);
    }
  }
  free(acc);
}

/* The radius opt asks for, or a message when it or the filter is bad. */
static rr_error filter_radius(rr_device *dev, const rr_shade_options *opt, double *r) {
  if ((int)opt->filter < 0 || opt->filter >= RR_FILTER_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown resolve filter %d", (int)opt->filter);
  *r = opt->radius == 0 ? default_radius[opt->filter] : opt->radius;
  if (!(*r >= 0.5 && *r <= RR_FILTER_MAX_RADIUS))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad filter radius %g (0.5 .. %g pixels, 0 for the filter's own)",
                   (double)opt->radius, (double)RR_FILTER_MAX_RADIUS);
  return RR_OK;
}

/* Half-open support: the box of radius 0.5 weighs a sample at p in [0, 1) of its own
 * pixel 1 and one in a neighbour (|dx + p - 0.5| >= 0.5) 0. */
rr_error rr_resolve_check(rr_device *dev, const rr_shade_options *opt, bool *own) {
  double r = 0;
  rr_error e = filter_radius(dev, opt, &r);
  *own = !e && opt->filter == RR_FILTER_BOX && r == 0.5;
  return e;
}

rr_error rr_resolve_image(rr_device *dev, const resolve_input *in, const rr_shade_options *opt, int threads,
                          rr_image *out) {
  double r = 0;
  rr_error e = filter_radius(dev, opt, &r);
  if (e) return e;
  /* a sample at p in a pixel dx away sits dx + p - 0.5 from the centre: |dx| <= R */
  int R = (int)ceil(r + 0.5), side = 2 * R + 1;
  tap *taps = malloc(sizeof *taps * (side * side + 1) * in->samples), *own = taps + side * side * in->samples;
  int channels = in->alpha ? 4 : 3;
  out->width = in->width, out->height = in->height, out->channels = channels;
  out->type = RR_PIXEL_F32, out->kind = RR_IMAGE_COLOR;
  out->data = taps ? rr_alloc_large(sizeof(float) * channels * in->width * in->height) : NULL; /* (shade.c: faults) */
  if (!out->data) {
    free(taps);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory resolving a %dx%d image", in->width, in->height);
  }
  int ntaps = 0;
  ptrdiff_t w = in->width, layer = w * in->height;
  for (int s = 0; s < in->samples; s++) /* in memory order, layer by layer, row by row */
    for (int dy = -R; dy <= R; dy++)
      for (int dx = -R; dx <= R; dx++) {
        double f = filter_1d(opt->filter, dx + (double)in->pos[s][0] - 0.5, r) *
                   filter_1d(opt->filter, dy + (double)in->pos[s][1] - 0.5, r);
        if (f != 0) taps[ntaps++] = (tap){dx, dy, s * layer + dy * w + dx, f};
      }
  for (int s = 0; s < in->samples; s++) own[s] = (tap){0, 0, s * layer, 1};
  /* a filter that keeps each pixel's own samples at weight 1 (the box of radius 0.5)
   * is the box's tight loop */
  bool box = ntaps == in->samples;
  for (int t = 0; box && t < ntaps; t++) box = taps[t].off == own[t].off && taps[t].f == 1;
  resolve_job job = {in, taps, own, ntaps, R, out->data, channels, false};
  rr_parallel_for((in->height + ROWS_PER_JOB - 1) / ROWS_PER_JOB, threads ? threads : rr_cpu_count(), box ? resolve_box_rows : resolve_rows,
                  &job);
  free(taps);
  if (job.failed) {
    free(out->data);
    out->data = NULL;
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory resolving a %dx%d image", in->width, in->height);
  }
  return RR_OK;
}
