/* The thin vector layer every kernel is written against: GCC vector types, so one
 * body compiles to SSE/AVX2 on x86, NEON on aarch64 and plain code elsewhere.
 * Lane operations are IEEE single floats in program order (the build has no FMA
 * contraction), so a kernel gives the same bits at every width.
 *
 * RR_SIMD_X86 is defined where x86 intrinsics may be used (x86 and not built with
 * RR_NO_SIMD); everything else here is portable C. */
#ifndef RR_SIMD_H
#define RR_SIMD_H

#include <stdint.h>
#include <string.h>

#if (defined(__x86_64__) || defined(__i386__)) && !defined(RR_NO_SIMD)
#define RR_SIMD_X86 1
#include <immintrin.h>
#endif

/* Four lanes: BVH boxes side by side, frustum planes. */
typedef float rr_vf4 __attribute__((vector_size(16)));
typedef int32_t rr_vi4 __attribute__((vector_size(16)));

static inline rr_vf4 rr_vf4_splat(float x) { return (rr_vf4){x, x, x, x}; }
/* Loads four floats from any address. */
static inline rr_vf4 rr_vf4_load(const float *p) {
  rr_vf4 v;
  memcpy(&v, p, sizeof v);
  return v;
}
static inline void rr_vf4_store(float *p, rr_vf4 v) { memcpy(p, &v, sizeof v); }
/* Lane-wise selection: m ? a : b (m holds all-ones or all-zero lanes). */
static inline rr_vf4 rr_vf4_select(rr_vi4 m, rr_vf4 a, rr_vf4 b) {
  return (rr_vf4)((m & (rr_vi4)a) | (~m & (rr_vi4)b));
}
/* a < b ? a : b per lane, so a NaN in either gives b (SSE's minps). */
static inline rr_vf4 rr_vf4_min(rr_vf4 a, rr_vf4 b) { return rr_vf4_select(a < b, a, b); }
/* a > b ? a : b per lane, so a NaN in either gives b (SSE's maxps). */
static inline rr_vf4 rr_vf4_max(rr_vf4 a, rr_vf4 b) { return rr_vf4_select(a > b, a, b); }
static inline rr_vf4 rr_vf4_abs(rr_vf4 a) { return (rr_vf4)((rr_vi4)a & 0x7FFFFFFF); }
/* Bit k set when lane k of the mask is set. */
static inline int rr_vi4_bits(rr_vi4 m) {
#ifdef RR_SIMD_X86
  return _mm_movemask_ps((__m128)m);
#else
  return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
}
/* The largest of the four lanes (NaN lanes ignored unless all are NaN). */
static inline float rr_vf4_hmax(rr_vf4 a) {
  float m = a[0];
  for (int k = 1; k < 4; k++) m = a[k] > m ? a[k] : m;
  return m;
}

/* ---- for the ray casters (vis/bvh_trace.h, vis/rc_bvh.c) ---------------------- */

/* Loads four floats from a 16-byte aligned address: an aligned load, which the
 * compiler may fold into the operation that uses it. */
static inline rr_vf4 rr_vf4_load_aligned(const float *p) { return rr_vf4_load(__builtin_assume_aligned(p, 16)); }

#endif
