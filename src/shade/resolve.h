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
} resolve_input;

#endif
