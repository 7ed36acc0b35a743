/* Resolve: per-sample colours in linear light to one colour per pixel, the last
 * stage before an image is encoded. Shading (shade.c) fills the samples; the
 * filter, which may read neighbouring pixels' samples, is chosen by the caller. */
#ifndef RR_SHADE_RESOLVE_H
#define RR_SHADE_RESOLVE_H

#include "core/core.h"

#include <math.h>

typedef struct resolve_input {
  int width, height, samples;
  const float (*pos)[2]; /* sample s of pixel (x, y) at (x + pos[s][0], y + pos[s][1]) */
  const float *rgb;      /* 3 floats per sample, linear light, layered like the visibility
                            buffer: sample s of pixel k at (s·width·height + k)·3 */
  const float *weight;   /* per sample, layered, >= 0 (a CSAA stored sample: 1 + its votes;
                            0: the sample counts for nothing); NULL: every sample weighs 1 */
  const float *alpha;    /* per sample, layered, in [0, 1] (1: it hit); NULL: an opaque image
                            of 3 channels. Given, the image has a 4th channel, alpha */
} resolve_input;

/* Resolves the samples into out, a new float image of kind RR_IMAGE_COLOR (3 channels,
 * 4 with alpha), on `threads` threads (0: all cores). A pixel's colour is
 * Σ f·w·a·rgb / Σ f·w·a over the samples the filter reaches (f its weight, w the
 * input's, a the alpha, 1 without), clamped at 0; alpha is Σ f·w·a / Σ f·w in [0, 1].
 * Where the filter leaves no positive sum (negative lobes over sparse weights), the
 * pixel's own samples are averaged instead, as by the box; where they too sum to 0,
 * the pixel is 0. opt: the filter and radius (its mode and alpha are not read). */
rr_error rr_resolve_image(rr_device *dev, const resolve_input *in, const rr_shade_options *opt, int threads,
                          rr_image *out);
/* Checks opt's filter and radius; *own: the filter takes each pixel's own samples at
 * weight 1 and nothing else (the box of radius 0.5), so shading may resolve a pixel
 * as soon as its samples are shaded (resolve_own) and keep no per-sample colours. */
rr_error rr_resolve_check(rr_device *dev, const rr_shade_options *opt, bool *own);

/* x clamped to [0, hi] (NaN to 0); comparisons, not fmax/fmin, which are library calls. */
static inline double resolve_clamp0(double x, double hi) {
  return x > 0 ? (x < hi ? x : hi) : 0;
}

/* A pixel's colour (and alpha, channels 4) from its sums Σ f·w·a·rgb, Σ f·w·a, Σ f·w. */
static inline void resolve_finish(const double sum[5], float *o, int channels) {
  for (int c = 0; c < 3; c++) o[c] = sum[3] > 0 ? (float)resolve_clamp0(sum[c] / sum[3], INFINITY) : 0.0f;
  if (channels == 4) o[3] = sum[4] > 0 ? (float)resolve_clamp0(sum[3] / sum[4], 1) : 0.0f;
}

/* The box of one pixel's own n samples, as rr_resolve_image computes it (the same
 * sums in the same order, so the same bits): sample s's colour at rgb + s·rgb_step,
 * its weight w[s·step] and alpha a[s·step] (NULL: 1). */
static inline void resolve_own(int n, const float *rgb, size_t rgb_step, const float *w, const float *a, size_t step,
                               int channels, float *o) {
  double sum[5] = {0, 0, 0, 0, 0};
  for (int s = 0; s < n; s++) {
    double f = w ? w[s * step] : 1.0, fa = a ? f * a[s * step] : f;
    const float *c = rgb + s * rgb_step;
    sum[0] += fa * c[0], sum[1] += fa * c[1], sum[2] += fa * c[2], sum[3] += fa, sum[4] += f;
  }
  resolve_finish(sum, o, channels);
}

/* The box of a pixel whose samples all have colour rgb and alpha `hit` (1 or 0; 1
 * without an alpha channel), whatever their weights: resolve_own's bits. Its sums
 * are then whole multiples (at most 16) of one colour and one alpha, exact in
 * double, so their quotient is the colour itself, clamped at 0 (NaN to 0). */
static inline void resolve_one(const float rgb[3], bool hit, int channels, float *o) {
  for (int c = 0; c < 3; c++) o[c] = hit && rgb[c] > 0 ? rgb[c] : 0.0f;
  if (channels == 4) o[3] = hit ? 1.0f : 0.0f;
}

#endif
