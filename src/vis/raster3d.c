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
  uint64_t n, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
  const bool planar = cams[0].planar;
#ifdef RR_SIMD_X86
  if (simd && planar && samples > 2 && __builtin_cpu_supports("avx2"))
    n = raster_many8(ts, at, id, r, cams, ns, vb, true);
  else
#endif
    n = raster_many1(ts, at, id, r, cams, ns, vb, planar);
  if (covered) *covered += n;
  return samples * (uint64_t)ns;
}
