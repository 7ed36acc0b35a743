/* The hierarchical z-buffer (vis/hiz.h). */
#include "vis/hiz.h"

#include <string.h>

void rr_hiz_free(hiz *h) {
  for (int l = 0; l < HIZ_LEVELS_MAX; l++) free(h->zmax[l]), free(h->dirty[l]);
  memset(h, 0, sizeof *h);
}

bool rr_hiz_init(hiz *h, const visbuf *vb, int shift, int levels) {
  memset(h, 0, sizeof *h);
  h->vb = vb, h->layers = 1, h->shift = shift, h->levels = levels;
  for (int l = 0; l < levels; l++) {
    int s = 1 << (shift + 2 * l);
    h->w[l] = (vb->width + s - 1) / s, h->h[l] = (vb->height + s - 1) / s;
    size_t n = (size_t)h->w[l] * h->h[l];
    h->zmax[l] = malloc(n * sizeof(float));
    h->dirty[l] = calloc(n, 1);
    if (!h->zmax[l] || !h->dirty[l]) {
      rr_hiz_free(h);
      return false;
    }
    for (size_t k = 0; k < n; k++) h->zmax[l][k] = INFINITY;
  }
  return true;
}

float rr_hiz_refresh(hiz *h, int l, int i, int j) {
  float m = -INFINITY;
  for (int cj = 4 * j; cj < 4 * j + 4 && cj < h->h[l - 1]; cj++)
    for (int ci = 4 * i; ci < 4 * i + 4 && ci < h->w[l - 1]; ci++) m = maxf(m, hiz_get(h, l - 1, ci, cj));
  size_t k = (size_t)j * h->w[l] + i;
  h->zmax[l][k] = m;
  h->dirty[l][k] = 0;
  return m;
}
