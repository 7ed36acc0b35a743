/* Resolve: per-sample colours in linear light to one colour per pixel, the last
 * stage before an image is encoded. Shading (shade.c) fills the samples; the
 * filter, which may read neighbouring pixels' samples, is chosen by the caller. */
#ifndef RR_SHADE_RESOLVE_H
#define RR_SHADE_RESOLVE_H

#include "core/core.h"

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

#endif
