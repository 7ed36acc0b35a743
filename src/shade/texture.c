/* Texture lookups. For now: bilinear at level 0, whatever the filter. */
#include "shade/texture.h"
#include "core/color.h"

#include <math.h>

bool rr_texture_prepare(rr_texture *t) {
  (void)t;
  return true;
}

void rr_texture_sample(const rr_texture *t, const tex_coord *tc, const tex_filter *f, float rgba[4]) {
  (void)f;
  /* Wrap, bilinear; v points up in the file's convention, rows run down. */
  float u = tc->u - floorf(tc->u), v = tc->v - floorf(tc->v);
  float fx = u * t->width - 0.5f, fy = (1.0f - v) * t->height - 0.5f;
  int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
  float ax = fx - x0, ay = fy - y0;
  for (int c = 0; c < 3; c++) rgba[c] = 0;
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 2; i++) {
      int xx = ((x0 + i) % t->width + t->width) % t->width, yy = ((y0 + j) % t->height + t->height) % t->height;
      float w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
      const uint8_t *p = t->rgb + 3 * ((size_t)yy * t->width + xx);
      for (int c = 0; c < 3; c++) rgba[c] += w * p[c] / 255.0f;
    }
  /* textures are sRGB-encoded; shading works in linear light */
  for (int c = 0; c < 3; c++) rgba[c] = srgb_decode(rgba[c]);
  rgba[3] = 1.0f;
}
