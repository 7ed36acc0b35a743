/* The sRGB transfer curve (IEC 61966-2-1): the one place where colour moves between
 * linear light (shading, float files) and display encoding (8-bit files, textures). */
#ifndef RR_COLOR_H
#define RR_COLOR_H

#include <math.h>

/* Linear light in [0, 1] to its sRGB encoding (clamped; NaN gives 0). */
static inline float srgb_encode(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

/* An sRGB-encoded value in [0, 1] to linear light (clamped; NaN gives 0). */
static inline float srgb_decode(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

#endif
