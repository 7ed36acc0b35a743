/* The 3D rasterizer's sample loop: every sample of a rectangle against one set-up
 * triangle (paper sect. 3.2), shared by the traversal's configurations. */
#include "vis/vis.h"

/* The sample loop, written once and specialised for planar and curved cameras. */
static inline uint64_t raster_loop(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                                   const bool planar) {
  uint64_t covered = 0;
  for (int y = r[1]; y <= r[3]; y++) {
    float sy = (float)y + c->sy0;
    size_t row = (size_t)y * vb->width;
    for (int x = r[0]; x <= r[2]; x++) {
      float sx = (float)x + c->sx0;
      vec3 w = planar ? v3(1.0f, sx, sy) : c->dirs[row + x];
      covered += shade_sample_w(ts, id, w, sx, sy, vb, row + x) != 0;
    }
  }
  return covered;
}

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

/* The planar sample loop, 8 samples of a row at a time with AVX2. Every operation
 * is the scalar one, in the same order, on IEEE single floats (no FMA, a true
 * division), so the bits are those of raster_loop: the same sample test. */
__attribute__((target("avx2"))) static uint64_t raster_loop_avx2(const tri_setup *ts, uint32_t id, const int r[4],
                                                                  float sx0, float sy0, visbuf *vb) {
  __m256 a[3], b[3], c[3], tie[3];
  for (int e = 0; e < 3; e++) {
    a[e] = _mm256_set1_ps(ts->a[e]), b[e] = _mm256_set1_ps(ts->b[e]), c[e] = _mm256_set1_ps(ts->c[e]);
    tie[e] = _mm256_castsi256_ps(_mm256_set1_epi32(ts->tie & (1u << e) ? -1 : 0));
  }
  const __m256 w0 = _mm256_set1_ps(ts->w[0]), w1 = _mm256_set1_ps(ts->w[1]), w2 = _mm256_set1_ps(ts->w[2]);
  const __m256 vol = _mm256_set1_ps(ts->vol), vol_x = _mm256_set1_ps(ts->vol_x), vol_y = _mm256_set1_ps(ts->vol_y);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), bias = _mm256_set1_epi32((int)0x80000000);
  const __m256i idv = _mm256_set1_epi32((int)id), id_biased = _mm256_xor_si256(idv, bias);
  uint64_t covered = 0;
  /* Columns of 8 samples, then rows: the terms in sx are the same on every row. */
  for (int x = r[0]; x <= r[2]; x += 8) {
    __m256i xi = _mm256_add_epi32(_mm256_set1_epi32(x), lane);
    const __m256 valid = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(r[2] + 1), xi));
    const __m256 sx = _mm256_add_ps(_mm256_cvtepi32_ps(xi), _mm256_set1_ps(sx0));
    __m256 ax[3];
    for (int e = 0; e < 3; e++) ax[e] = _mm256_add_ps(_mm256_mul_ps(a[e], one), _mm256_mul_ps(b[e], sx));
    const __m256 vx = _mm256_add_ps(vol, _mm256_mul_ps(sx, vol_x));
    for (int y = r[1]; y <= r[3]; y++) {
      const __m256 sy = _mm256_set1_ps((float)y + sy0);
      size_t row = (size_t)y * vb->width;
      __m256 ev[3], in = valid;
      for (int e = 0; e < 3; e++) {
        ev[e] = _mm256_add_ps(ax[e], _mm256_mul_ps(c[e], sy));
        __m256 pos = _mm256_cmp_ps(ev[e], zero, _CMP_GT_OQ);
        __m256 on = _mm256_and_ps(_mm256_cmp_ps(ev[e], zero, _CMP_EQ_OQ), tie[e]);
        in = _mm256_and_ps(in, _mm256_or_ps(pos, on));
      }
      if (!_mm256_movemask_ps(in)) continue;
      __m256 sum = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ev[0], w0), _mm256_mul_ps(ev[1], w1)),
                                 _mm256_mul_ps(ev[2], w2));
      __m256 v = _mm256_add_ps(vx, _mm256_mul_ps(sy, vol_y));
      in = _mm256_and_ps(in, _mm256_and_ps(_mm256_cmp_ps(sum, zero, _CMP_GT_OQ), _mm256_cmp_ps(v, zero, _CMP_GT_OQ)));
      int hit = _mm256_movemask_ps(in);
      if (!hit) continue;
      covered += (uint64_t)__builtin_popcount((unsigned)hit);
      __m256 inv = _mm256_div_ps(one, sum);
      __m256 t = _mm256_mul_ps(v, inv);
      /* depth_wins: nearer, or as near with a lower id */
      __m256i mi = _mm256_castps_si256(in);
      __m256 bt = _mm256_maskload_ps(vb->t + row + x, mi);
      __m256i bid = _mm256_maskload_epi32((const int *)vb->id + row + x, mi);
      __m256 lower_id = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_xor_si256(bid, bias), id_biased));
      __m256 wins = _mm256_or_ps(_mm256_cmp_ps(t, bt, _CMP_LT_OQ),
                                 _mm256_and_ps(_mm256_cmp_ps(t, bt, _CMP_EQ_OQ), lower_id));
      __m256i w = _mm256_castps_si256(_mm256_and_ps(in, wins));
      if (_mm256_testz_si256(w, w)) continue;
      _mm256_maskstore_ps(vb->t + row + x, w, t);
      _mm256_maskstore_epi32((int *)vb->id + row + x, w, idv);
      _mm256_maskstore_ps(vb->l1 + row + x, w, _mm256_mul_ps(ev[1], inv));
      _mm256_maskstore_ps(vb->l2 + row + x, w, _mm256_mul_ps(ev[2], inv));
    }
  }
  return covered;
}
#endif

/* Tests every sample of rectangle r against one triangle; returns the evaluations. */
uint64_t rr_raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                     uint64_t *covered, bool simd) {
  uint64_t n, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
#if defined(__x86_64__) || defined(__i386__)
  /* a rectangle of a few samples (most triangles of a detailed mesh) costs less
   * than the vector loop's setup; both paths give the same bits */
  if (simd && c->planar && samples > 2 && __builtin_cpu_supports("avx2")) n = raster_loop_avx2(ts, id, r, c->sx0, c->sy0, vb);
  else
#endif
    n = c->planar ? raster_loop(ts, id, r, c, vb, true) : raster_loop(ts, id, r, c, vb, false);
  (void)simd;
  if (covered) *covered += n;
  return samples;
}
