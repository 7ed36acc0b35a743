/* The 3D rasterizer's sample loop: every sample of a rectangle against one set-up
 * triangle (paper sect. 3.2), shared by the traversal's configurations. */
#include "vis/vis.h"
#include "core/simd.h"

#include <string.h>

/* The sample loop, one lane at a time (any camera) and, with AVX2, eight. */
#define RR_TEMPLATE "vis/raster3d_tmp.h"
#include "core/simd_widths.h"

/* Tests every sample of rectangle r against one triangle; returns the evaluations.
 * (Two entries, so the one-position frame takes no more steps than before.) */
uint64_t rr_raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                        uint64_t *covered, bool simd) {
  uint64_t n = 0, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
  if (c->planar && samples <= 2) {
    /* one or two samples (most triangles of a detailed mesh): the one sample test
     * as rc calls it, the same bits without the loop's constants (lanes_of) */
    for (int y = r[1]; y <= r[3]; y++)
      for (int x = r[0]; x <= r[2]; x++) {
        const float sx = (float)x + c->sx0, sy = (float)y + c->sy0;
        n += shade_sample_w(ts, id, v3(1.0f, sx, sy), sx, sy, vb, (size_t)y * vb->width + (size_t)x) != 0;
      }
  } else
#ifdef RR_SIMD_X86
  /* a rectangle of a few samples (most triangles of a detailed mesh) costs less
   * than the vector loop's setup, and a curved one's rows of fewer than four
   * than the gathers of their rays; both paths give the same bits */
  if (simd && samples > 2 && (c->planar || r[2] - r[0] >= 3) && __builtin_cpu_supports("avx2"))
    n = raster_one8(ts, id, r, c, vb, c->planar);
  else
#endif
    n = raster_one1(ts, id, r, c, vb, c->planar);
  (void)simd;
  if (covered) *covered += n;
  return samples;
}

void rr_tri_moves_ready(const tri_setup *ts, tri_moves *mv, const camera *cams, int ns, bool simd) {
  if (mv->ready) return;
  const int lanes = (ns + 7) & ~7; /* what the kernels' lanes read */
  for (int s = 0; s < lanes; s++) mv->r[0][s] = mv->r[1][s] = INT32_MAX, mv->r[2][s] = mv->r[3][s] = INT32_MIN;
  if (mv->pl) {
    rr_tri_moved_all(ts, mv->pl, &cams[0], lanes, mv->ox, mv->oy, simd, mv->pa, mv->num0, mv->cx, mv->cy);
  } else {
    for (int s = 0; s < lanes; s++) mv->pa[s] = ts->pa, mv->num0[s] = ts->num0, mv->cx[s] = ts->cx, mv->cy[s] = ts->cy;
  }
  mv->live = 0;
  for (uint32_t todo = mv->pl ? ~(uint32_t)mv->pos->none & ((1u << ns) - 1) : (1u << ns) - 1; todo; todo &= todo - 1) {
    const int s = __builtin_ctz(todo);
    int q[4];
    if (!mv->pl) memcpy(q, mv->bb, sizeof q);
    else if (!tri_pos_rect(mv->pos, mv->bb, s, q) || q[0] > mv->draw[2] || q[2] < mv->draw[0] ||
             q[1] > mv->draw[3] || q[3] < mv->draw[1])
      continue;
    for (int k = 0; k < 4; k++) mv->r[k][s] = q[k];
    mv->live |= 1u << s;
  }
  mv->ready = true;
}

/* rr_raster_rect_samples for a larger draw: each position over its own part of r
 * by scanlines. */
static uint64_t raster_scanlines(const tri_setup *ts, tri_moves *mv, uint32_t id, const int r[4], const camera *cams,
                                 int ns, visbuf *vb, uint64_t *covered, bool simd) {
  const bool planar = cams[0].planar;
  uint8_t act[RR_MAX_SAMPLES];
  int rs[RR_MAX_SAMPLES][4], n = 0;
  uint64_t got, samples = 0;
  rr_tri_moves_ready(ts, mv, cams, ns, simd);
  for (uint32_t live = mv->live; live; live &= live - 1) {
    const int s = __builtin_ctz(live);
    int x0 = mv->r[0][s] > r[0] ? mv->r[0][s] : r[0], y0 = mv->r[1][s] > r[1] ? mv->r[1][s] : r[1];
    int x1 = mv->r[2][s] < r[2] ? mv->r[2][s] : r[2], y1 = mv->r[3][s] < r[3] ? mv->r[3][s] : r[3];
    if (x0 > x1 || y0 > y1) continue;
    rs[n][0] = x0, rs[n][1] = y0, rs[n][2] = x1, rs[n][3] = y1, act[n++] = (uint8_t)s;
    samples += (uint64_t)(x1 - x0 + 1) * (uint64_t)(y1 - y0 + 1);
  }
  if (!n) return 0;
#ifdef RR_SIMD_X86
  /* as rr_raster_rect, by the positions' mean rectangle */
  if (simd && __builtin_cpu_supports("avx2") && planar && samples > 2 * (uint64_t)n)
    got = raster_many8(ts, mv, act, (const int (*)[4])rs, id, cams, n, vb, true);
  else
#endif
    got = raster_many1(ts, mv, act, (const int (*)[4])rs, id, cams, n, vb, planar);
  if (covered) *covered += got;
  return samples;
}

uint64_t rr_raster_rect_samples(const tri_setup *ts, tri_moves *mv, uint32_t id, const int r[4],
                                const camera *cams, int ns, visbuf *vb, uint64_t *covered, bool simd) {
  /* a triangle of a few pixels (most of a detailed mesh): lanes over the positions
   * and the pixels of their own rectangles rather than a scanline of a sample or
   * two per position. The limits are callgrind's on the bunny and the teapot
   * grid: at 16 positions, drawing up to 2·ns pixels this way and larger draws by
   * scanlines took 766 M and 3708 M instructions, and any draw up to 8 pixels wide
   * 780 M and 3708 M; at 4 positions (two pixels a step) the bunny took 277 M and
   * 260 M, the grid 2285 M either way. With the depth test in lanes (stop 30), up
   * to 4·ns pixels: the bunny at 16 positions 613 M against 646 M at 2·ns. */
  if (!cams[0].planar) return raster_scanlines(ts, mv, id, r, cams, ns, vb, covered, simd);
#ifdef RR_SIMD_X86
  simd = simd && __builtin_cpu_supports("avx2");
#endif
  if (rr_raster_few_pixels(r, ns)) return rr_raster_pixels(ts, mv, id, r, &cams[0], ns, vb, covered, simd);
  /* a larger draw: every position's samples of a pixel side by side in the lanes
   * (a pixel's samples are side by side in vb), where a scanline of one position
   * takes a gather and one write per sample */
  if ((ns & (ns - 1)) || vb->ns != ns) return raster_scanlines(ts, mv, id, r, cams, ns, vb, covered, simd);
  uint64_t samples = 0, got;
#ifdef RR_SIMD_X86
  if (simd) got = raster_together8(ts, mv, id, r, &cams[0], ns, vb, &samples);
  else
#endif
    got = raster_together1(ts, mv, id, r, &cams[0], ns, vb, &samples);
  if (covered) *covered += got;
  return samples;
}

uint64_t rr_raster_pixels(const tri_setup *ts, const tri_moves *mv, uint32_t id, const int r[4], const camera *c,
                          int ns, visbuf *vb, uint64_t *covered, bool avx2) {
  uint64_t samples = 0, got;
#ifdef RR_SIMD_X86
  if (avx2) got = raster_pixels8(ts, mv, id, r, c, ns, vb, &samples);
  else
#endif
    got = raster_pixels1(ts, mv, id, r, c, ns, vb, &samples);
  (void)avx2;
  if (covered) *covered += got;
  return samples;
}

rr_pixels_kernel rr_raster_pixels_kernel(bool avx2) {
#ifdef RR_SIMD_X86
  if (avx2) return raster_pixels8;
#endif
  (void)avx2;
  return raster_pixels1;
}
