/* The 3D rasterizer's sample loop: every sample of a rectangle against one set-up
 * triangle (paper sect. 3.2), shared by the traversal's configurations. */
#include "vis/vis.h"
#include "core/simd.h"

/* A list of samples of any positions (planar cameras), by component for the
 * lanes: the sample (sx, sy), the setup values moved to its position, and its
 * place in the visibility buffer. Room for LIST_MAX, padded to eight. */
enum { LIST_MAX = 32 };
typedef struct sample_list {
  float sx[LIST_MAX + 8], sy[LIST_MAX + 8], pa[LIST_MAX + 8], num0[LIST_MAX + 8], cx[LIST_MAX + 8], cy[LIST_MAX + 8];
  size_t off[LIST_MAX + 8];
} sample_list;

/* The sample loop, one lane at a time (any camera) and, with AVX2, eight. */
#define RR_TEMPLATE "vis/raster3d_tmp.h"
#include "core/simd_widths.h"

/* Tests every sample of rectangle r against one triangle; returns the evaluations.
 * (Two entries, so the one-position frame takes no more steps than before.) */
uint64_t rr_raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                        uint64_t *covered, bool simd) {
  uint64_t n, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
#ifdef RR_SIMD_X86
  /* a rectangle of a few samples (most triangles of a detailed mesh) costs less
   * than the vector loop's setup; both paths give the same bits */
  if (simd && c->planar && samples > 2 && __builtin_cpu_supports("avx2")) n = raster_one8(ts, id, r, c, vb, true);
  else
#endif
    n = raster_one1(ts, id, r, c, vb, c->planar);
  (void)simd;
  if (covered) *covered += n;
  return samples;
}

uint64_t rr_raster_rect_samples(const tri_setup *ts, const tri_moves *mv, uint32_t id, const int r[4],
                                const camera *cams, visbuf *vb, uint64_t *covered, bool simd) {
  /* each position over its own part of r: a sub-pixel triangle's rectangle holds
   * a sample of only a few of the positions */
  const tri_at *at = mv->at;
  uint8_t act[RR_MAX_SAMPLES];
  int rs[RR_MAX_SAMPLES][4], n = 0;
  uint64_t samples = 0;
  for (uint32_t live = mv->live; live; live &= live - 1) {
    const int s = __builtin_ctz(live), *q = at[s].r;
    int x0 = q[0] > r[0] ? q[0] : r[0], y0 = q[1] > r[1] ? q[1] : r[1];
    int x1 = q[2] < r[2] ? q[2] : r[2], y1 = q[3] < r[3] ? q[3] : r[3];
    if (x0 > x1 || y0 > y1) continue;
    rs[n][0] = x0, rs[n][1] = y0, rs[n][2] = x1, rs[n][3] = y1, act[n++] = (uint8_t)s;
    samples += (uint64_t)(x1 - x0 + 1) * (uint64_t)(y1 - y0 + 1);
  }
  if (!n) return 0;
  uint64_t got;
  const bool planar = cams[0].planar;
  const bool avx2 = simd && __builtin_cpu_supports("avx2");
  if (planar && samples <= LIST_MAX) {
    /* a few samples: lanes over them, whatever their positions, rather than a
     * loop of one or two samples per position */
    sample_list L;
    const size_t width = (size_t)vb->width, layer = width * (size_t)vb->height;
    int m = 0;
    for (int k = 0; k < n; k++) {
      const int s = act[k], *q = rs[k];
      const tri_at *p = &at[s];
      const float ox = cams[s].sx0, oy = cams[s].sy0;
      for (int y = q[1]; y <= q[3]; y++)
        for (int x = q[0]; x <= q[2]; x++, m++) {
          L.sx[m] = (float)x + ox, L.sy[m] = (float)y + oy;
          L.pa[m] = p->pa, L.num0[m] = p->num0, L.cx[m] = p->cx, L.cy[m] = p->cy;
          L.off[m] = (size_t)s * layer + (size_t)y * width + (size_t)x;
        }
    }
    for (int k = m; k < m + 8; k++) /* the padding lanes repeat the last sample (masked off) */
      L.sx[k] = L.sx[m - 1], L.sy[k] = L.sy[m - 1], L.pa[k] = L.pa[m - 1], L.num0[k] = L.num0[m - 1],
      L.cx[k] = L.cx[m - 1], L.cy[k] = L.cy[m - 1], L.off[k] = L.off[m - 1];
#ifdef RR_SIMD_X86
    if (avx2 && m > 1) got = raster_list8(ts, id, &L, m, vb);
    else
#endif
      got = raster_list1(ts, id, &L, m, vb);
    if (covered) *covered += got;
    return samples;
  }
#ifdef RR_SIMD_X86
  /* as rr_raster_rect, by the positions' mean rectangle */
  if (avx2 && planar && samples > 2 * (uint64_t)n)
    got = raster_many8(ts, at, act, (const int (*)[4])rs, id, cams, n, vb, true);
  else
#endif
    got = raster_many1(ts, at, act, (const int (*)[4])rs, id, cams, n, vb, planar);
  if (covered) *covered += got;
  return samples;
}
