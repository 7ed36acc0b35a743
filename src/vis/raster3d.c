/* The 3D rasterizer's sample loop: every sample of a rectangle against one set-up
 * triangle (paper sect. 3.2), shared by the traversal's configurations. */
#include "vis/vis.h"
#include "core/simd.h"

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

uint64_t rr_raster_rect_samples(const tri_setup *ts, const tri_at *at, uint32_t id, const int r[4],
                                const camera *cams, int ns, visbuf *vb, uint64_t *covered, bool simd) {
  if (ns == 1) return rr_raster_rect(ts, id, r, cams, vb, covered, simd);
  /* each position over its own part of r: a sub-pixel triangle's rectangle holds
   * a sample of only a few of the positions, and the others cost a compare */
  uint8_t act[RR_MAX_SAMPLES];
  int rs[RR_MAX_SAMPLES][4], n = 0;
  uint64_t samples = 0;
  for (int s = 0; s < ns; s++) {
    const int *q = at[s].r;
    int x0 = q[0] > r[0] ? q[0] : r[0], y0 = q[1] > r[1] ? q[1] : r[1];
    int x1 = q[2] < r[2] ? q[2] : r[2], y1 = q[3] < r[3] ? q[3] : r[3];
    if (x0 > x1 || y0 > y1) continue;
    rs[n][0] = x0, rs[n][1] = y0, rs[n][2] = x1, rs[n][3] = y1, act[n++] = (uint8_t)s;
    samples += (uint64_t)(x1 - x0 + 1) * (uint64_t)(y1 - y0 + 1);
  }
  if (!n) return 0;
  uint64_t got;
  const bool planar = cams[0].planar;
#ifdef RR_SIMD_X86
  /* as rr_raster_rect, by the positions' mean rectangle */
  if (simd && planar && samples > 2 * (uint64_t)n && __builtin_cpu_supports("avx2"))
    got = raster_many8(ts, at, act, (const int (*)[4])rs, id, cams, n, vb, true);
  else
#endif
    got = raster_many1(ts, at, act, (const int (*)[4])rs, id, cams, n, vb, planar);
  (void)simd;
  if (covered) *covered += got;
  return samples;
}
