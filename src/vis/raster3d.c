/* The 3D rasterizer's sample loop: every sample of a rectangle against one set-up
 * triangle (paper sect. 3.2), shared by the traversal's configurations. */
#include "vis/vis.h"
#include "core/simd.h"

/* The sample loop, one lane at a time (any camera) and, with AVX2, eight. */
#define RR_TEMPLATE "vis/raster3d_tmp.h"
#include "core/simd_widths.h"

/* Tests every sample of rectangle r against one triangle; returns the evaluations. */
uint64_t rr_raster_rect_samples(const tri_setup *ts, const tri_at *at, uint32_t id, const int r[4],
                                const camera *cams, int ns, visbuf *vb, uint64_t *covered, bool simd) {
  uint64_t n, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
  const bool planar = cams[0].planar;
#ifdef RR_SIMD_X86
  /* a rectangle of a few samples (most triangles of a detailed mesh) costs less
   * than the vector loop's setup; both paths give the same bits */
  if (simd && planar && samples > 2 && __builtin_cpu_supports("avx2"))
    n = raster_loop8(ts, at, id, r, cams, ns, vb, true);
  else
#endif
    n = planar ? raster_loop1(ts, at, id, r, cams, ns, vb, true) : raster_loop1(ts, at, id, r, cams, ns, vb, false);
  (void)simd;
  if (covered) *covered += n;
  return samples * (uint64_t)ns;
}

uint64_t rr_raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                        uint64_t *covered, bool simd) {
  return rr_raster_rect_samples(ts, NULL, id, r, c, 1, vb, covered, simd);
}
