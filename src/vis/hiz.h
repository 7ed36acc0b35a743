/* The hierarchical z-buffer: the farthest depth stored in each block of samples, at
 * levels of blocks 4× as wide as the level below. It is kept lazily: a writer marks
 * the blocks over the samples it may have changed, and a query recomputes a marked
 * block, from the samples at level 0 and from its 4×4 blocks above. A block with a
 * miss holds +inf.
 *
 * Two questions are asked of it: 3dr (isOccluded, early-z) asks whether every
 * level-0 block over a rectangle is nearer than a depth, with 8² tiles and one
 * level; 2dr-bin asks for one block's farthest depth at levels of 4², 16² and 64². */
#ifndef RR_VIS_HIZ_H
#define RR_VIS_HIZ_H

#include "vis/vis.h"

#define HIZ_LEVELS_MAX 3

typedef struct hiz {
  const visbuf *vb;          /* the depths it summarises: */
  int layers;                /* vb.ns: every sample of vb's pixels; 1: vb is one layer of a buffer (set
                                after rr_hiz_init, which sets 1) */
  int shift, levels;         /* level l's blocks are 1 << (shift + 2l) samples wide */
  int w[HIZ_LEVELS_MAX], h[HIZ_LEVELS_MAX]; /* blocks a row, rows of blocks */
  float *zmax[HIZ_LEVELS_MAX];
  uint8_t *dirty[HIZ_LEVELS_MAX]; /* zmax is stale: recompute before reading */
} hiz;

/* Sets up h over vb's samples, every block clean at +inf; false when out of memory. */
bool rr_hiz_init(hiz *h, const visbuf *vb, int shift, int levels);
void rr_hiz_free(hiz *h);
/* Recomputes block (i, j) of level l > 0 from the level below; returns its farthest depth. */
float rr_hiz_refresh(hiz *h, int l, int i, int j);

/* Recomputes block (i, j) of level 0 from the samples (of every layer). Inlined into the queries (a
 * call cost 3dr-bin 0.5% of its instructions), four samples a step (blocks are at
 * least 4 wide). */
static inline float hiz_refresh_samples(hiz *h, int i, int j) {
  const visbuf *vb = h->vb;
  int s = 1 << h->shift;
  int x1 = (i + 1) * s < vb->width ? (i + 1) * s : vb->width, y1 = (j + 1) * s < vb->height ? (j + 1) * s : vb->height;
  float m = -INFINITY;
  const int ns = vb->ns;
  for (int y = j * s; y < y1; y++) {
    const float *t = vb->t + (size_t)y * vb->width * ns;
    if (h->layers == ns) { /* a block holds every sample of its pixels: a row's lie side by side */
      int x = i * s * ns, xe = x1 * ns;
      for (; x + 4 <= xe; x += 4) m = maxf(m, maxf(maxf(t[x], t[x + 1]), maxf(t[x + 2], t[x + 3])));
      for (; x < xe; x++) m = maxf(m, t[x]);
    } else /* one layer of several */
      for (int x = i * s; x < x1; x++) m = maxf(m, t[(size_t)x * ns]);
  }
  size_t k = (size_t)j * h->w[0] + i;
  h->zmax[0][k] = m;
  h->dirty[0][k] = 0;
  return m;
}

/* The farthest depth stored in block (i, j) of level l. */
static inline float hiz_get(hiz *h, int l, int i, int j) {
  size_t k = (size_t)j * h->w[l] + i;
  if (!h->dirty[l][k]) return h->zmax[l][k];
  return l ? rr_hiz_refresh(h, l, i, j) : hiz_refresh_samples(h, i, j);
}

/* Marks the blocks of level l over samples [x0, x1) × [y0, y1) stale; with `fresh`,
 * returns whether one of them was not stale yet. */
KERNEL bool hiz_mark_level(hiz *h, int l, int x0, int y0, int x1, int y1, const bool fresh) {
  int s = h->shift + 2 * l;
  uint8_t was_clean = 0;
  for (int j = y0 >> s; j <= (y1 - 1) >> s; j++)
    for (int i = x0 >> s; i <= (x1 - 1) >> s; i++) {
      uint8_t *d = &h->dirty[l][(size_t)j * h->w[l] + i];
      if (fresh) was_clean |= *d ^ 1;
      *d = 1;
    }
  return was_clean;
}

/* Samples [x0, x1) × [y0, y1) may have changed: every block over them is stale.
 * A stale block's parent is stale too (refreshing a block refreshes its children),
 * so the marking stops at the first level where every block was stale already. */
static inline void hiz_mark(hiz *h, int x0, int y0, int x1, int y1) {
  for (int l = 0; l + 1 < h->levels; l++)
    if (!hiz_mark_level(h, l, x0, y0, x1, y1, true)) return;
  hiz_mark_level(h, h->levels - 1, x0, y0, x1, y1, false);
}

/* Is every depth stored in the level-0 blocks over samples [x0, x1) × [y0, y1)
 * nearer than z? Most queries are answered no by the first block, so it stops there. */
static inline bool hiz_nearer(hiz *h, int x0, int y0, int x1, int y1, float z) {
  int s = h->shift;
  for (int j = y0 >> s; j <= (y1 - 1) >> s; j++)
    for (int i = x0 >> s; i <= (x1 - 1) >> s; i++)
      if (!(hiz_get(h, 0, i, j) < z)) return false;
  return true;
}

#endif
