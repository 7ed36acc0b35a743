/* The thin vector layer every kernel is written against: GCC vector types, so one
 * body compiles to SSE/AVX2 on x86, NEON on aarch64 and plain code elsewhere.
 * Lane operations are IEEE single floats in program order (the build has no FMA
 * contraction), so a kernel gives the same bits at every width.
 *
 * RR_SIMD_X86 is defined where x86 intrinsics may be used (x86 and not built with
 * RR_NO_SIMD); everything else here is portable C. */
#ifndef RR_SIMD_H
#define RR_SIMD_H

#include <math.h>
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
static inline rr_vf4 rr_vf4_min(rr_vf4 a, rr_vf4 b) {
#ifdef RR_SIMD_X86
  return (rr_vf4)_mm_min_ps((__m128)a, (__m128)b); /* one instruction, the same lanes */
#else
  return rr_vf4_select(a < b, a, b);
#endif
}
/* a > b ? a : b per lane, so a NaN in either gives b (SSE's maxps). */
static inline rr_vf4 rr_vf4_max(rr_vf4 a, rr_vf4 b) {
#ifdef RR_SIMD_X86
  return (rr_vf4)_mm_max_ps((__m128)a, (__m128)b);
#else
  return rr_vf4_select(a > b, a, b);
#endif
}
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
/* Lanes 1, 2, 0, 3 of a (the cyclic next axis of an xyz vector). */
#ifdef __clang__ /* the fuzzing build: clang names GCC's vector shuffle differently */
static inline rr_vf4 rr_vf4_yzx(rr_vf4 a) { return __builtin_shufflevector(a, a, 1, 2, 0, 3); }
#else
static inline rr_vf4 rr_vf4_yzx(rr_vf4 a) { return __builtin_shuffle(a, (rr_vi4){1, 2, 0, 3}); }
#endif
/* Float to int, rounding towards zero (for lanes in int range). */
static inline rr_vi4 rr_vi4_trunc(rr_vf4 a) { return __builtin_convertvector(a, rr_vi4); }

/* ---- kernel templates -------------------------------------------------------
 * A hot kernel is written once, in a header included once per width (like
 * llvmpipe's lp_rast_tri_tmp.h): with W 1, a plain function that is the scalar
 * code every machine runs, and with W 8 under RR_SIMD_X86, an AVX2 function
 * (RR_TARGET_AVX2) chosen at run time. The template writes VF, VI for RR_VF(W),
 * RR_VI(W), the float and int vectors of W lanes, and VF_(op), VI_(op) for their
 * helpers below (rr_vf<W>_op, rr_vi<W>_op): every width has the same helpers with
 * the same lane semantics, so both instances give the same bits. Comparisons
 * (a < b) give VI masks of all-ones or all-zero lanes. */
#define RR_CAT_(a, b) a##b
#define RR_CAT(a, b) RR_CAT_(a, b)
#define RR_VF(w) RR_CAT(rr_vf, w)
#define RR_VI(w) RR_CAT(rr_vi, w)
#define RR_VF_OP(w, op) RR_CAT(RR_CAT(rr_vf, w), RR_CAT(_, op))
#define RR_VI_OP(w, op) RR_CAT(RR_CAT(rr_vi, w), RR_CAT(_, op))

/* One lane: the scalar instance. It is lane 0 of a four-lane vector, the other
 * lanes zero or unused: GCC keeps four-lane vectors in SSE or NEON registers, an
 * operation costing what the scalar one does, whereas it moves one-element
 * vectors through integer registers and the stack. */
typedef rr_vf4 rr_vf1;
typedef rr_vi4 rr_vi1;
/* Doubles for a VF's lanes (setup's exact parts): conversions both ways. */
typedef double rr_vd1 __attribute__((vector_size(16)));
#define rr_vf1_to_double(a) ((rr_vd1){(a)[0]})
#define rr_vd1_to_float(a) ((rr_vf1){(float)(a)[0]})

static inline rr_vf1 rr_vf1_splat(float x) { return (rr_vf1){x}; }
static inline rr_vi1 rr_vi1_splat(int32_t x) { return (rr_vi1){x}; }
/* The lane indices 0..W-1. */
static inline rr_vi1 rr_vi1_lanes(void) { return (rr_vi1){0}; }
/* Loads W values. */
static inline rr_vf1 rr_vf1_load(const float *p) { return (rr_vf1){p[0]}; }
static inline rr_vi1 rr_vi1_load(const int32_t *p) { return (rr_vi1){p[0]}; }
/* Lane k is p[i[k]]. */
static inline rr_vf1 rr_vf1_gather(const float *p, rr_vi1 i) { return (rr_vf1){p[i[0]]}; }
/* Lane k is p[i[k]] where m is set, else 0 (reading no memory). */
static inline rr_vf1 rr_vf1_gather_masked(const float *p, rr_vi1 i, rr_vi1 m) { return (rr_vf1){m[0] ? p[i[0]] : 0.0f}; }
static inline rr_vi1 rr_vi1_gather_masked(const int32_t *p, rr_vi1 i, rr_vi1 m) { return (rr_vi1){m[0] ? p[i[0]] : 0}; }
/* Loads and stores only the lanes set in m (the others load as 0 and touch no memory). */
static inline rr_vf1 rr_vf1_load_masked(const float *p, rr_vi1 m) { return (rr_vf1){m[0] ? p[0] : 0.0f}; }
static inline rr_vi1 rr_vi1_load_masked(const int32_t *p, rr_vi1 m) { return (rr_vi1){m[0] ? p[0] : 0}; }
static inline void rr_vf1_store_masked(float *p, rr_vi1 m, rr_vf1 v) {
  if (m[0]) p[0] = v[0];
}
static inline void rr_vi1_store_masked(int32_t *p, rr_vi1 m, rr_vi1 v) {
  if (m[0]) p[0] = v[0];
}
/* m ? a : b per lane (m holds all-ones or all-zero lanes); min and max with SSE
 * semantics, a < b ? a : b and a > b ? a : b, so a NaN in either gives b. One
 * lane takes a branch, cheaper than the bitwise blend SSE2 has. */
static inline rr_vf1 rr_vf1_select(rr_vi1 m, rr_vf1 a, rr_vf1 b) { return m[0] ? a : b; }
static inline rr_vi1 rr_vi1_select(rr_vi1 m, rr_vi1 a, rr_vi1 b) { return m[0] ? a : b; }
static inline rr_vf1 rr_vf1_min(rr_vf1 a, rr_vf1 b) { return a[0] < b[0] ? a : b; }
static inline rr_vf1 rr_vf1_max(rr_vf1 a, rr_vf1 b) { return a[0] > b[0] ? a : b; }
static inline rr_vf1 rr_vf1_abs(rr_vf1 a) { return rr_vf4_abs(a); }
static inline rr_vf1 rr_vf1_floor(rr_vf1 a) { return (rr_vf1){floorf(a[0])}; }
static inline rr_vf1 rr_vf1_ceil(rr_vf1 a) { return (rr_vf1){ceilf(a[0])}; }
static inline rr_vf1 rr_vf1_from_int(rr_vi1 a) { return (rr_vf1){(float)a[0]}; }
/* Float to int, rounding towards zero (for lanes in int range). */
static inline rr_vi1 rr_vi1_trunc(rr_vf1 a) { return (rr_vi1){(int32_t)a[0]}; }
/* Bit k set when lane k of the mask is set. */
static inline int rr_vi1_bits(rr_vi1 m) { return m[0] & 1; }

#ifdef RR_SIMD_X86
/* Eight lanes: AVX2, so only inside functions with RR_TARGET_AVX2, which run where
 * __builtin_cpu_supports("avx2"). Operators compile to the AVX2 instructions;
 * the helpers that have none in GCC's vector extension use the intrinsics. */
#define RR_TARGET_AVX2 __attribute__((target("avx2")))
typedef double rr_vd8 __attribute__((vector_size(64)));
#define rr_vf8_to_double(a) __builtin_convertvector((a), rr_vd8)
#define rr_vd8_to_float(a) __builtin_convertvector((a), rr_vf8)
typedef float rr_vf8 __attribute__((vector_size(32)));
typedef int32_t rr_vi8 __attribute__((vector_size(32)));

RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_splat(float x) { return _mm256_set1_ps(x); }
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_splat(int32_t x) { return (rr_vi8)_mm256_set1_epi32(x); }
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_lanes(void) { return (rr_vi8){0, 1, 2, 3, 4, 5, 6, 7}; }
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_load(const float *p) { return _mm256_loadu_ps(p); }
/* Loads eight floats from a 32-byte aligned address. */
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_load_aligned(const float *p) { return _mm256_load_ps(p); }
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_load(const int32_t *p) {
  return (rr_vi8)_mm256_loadu_si256((const __m256i *)p);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_gather(const float *p, rr_vi8 i) {
  return _mm256_i32gather_ps(p, (__m256i)i, 4);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_gather_masked(const float *p, rr_vi8 i, rr_vi8 m) {
  return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), p, (__m256i)i, (__m256)m, 4);
}
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_gather_masked(const int32_t *p, rr_vi8 i, rr_vi8 m) {
  return (rr_vi8)_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), (const int *)p, (__m256i)i, (__m256i)m, 4);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_load_masked(const float *p, rr_vi8 m) {
  return _mm256_maskload_ps(p, (__m256i)m);
}
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_load_masked(const int32_t *p, rr_vi8 m) {
  return (rr_vi8)_mm256_maskload_epi32((const int *)p, (__m256i)m);
}
RR_TARGET_AVX2 static inline void rr_vf8_store_masked(float *p, rr_vi8 m, rr_vf8 v) {
  _mm256_maskstore_ps(p, (__m256i)m, v);
}
RR_TARGET_AVX2 static inline void rr_vi8_store_masked(int32_t *p, rr_vi8 m, rr_vi8 v) {
  _mm256_maskstore_epi32((int *)p, (__m256i)m, (__m256i)v);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_select(rr_vi8 m, rr_vf8 a, rr_vf8 b) {
  return _mm256_blendv_ps(b, a, (__m256)m);
}
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_select(rr_vi8 m, rr_vi8 a, rr_vi8 b) {
  return (rr_vi8)_mm256_blendv_ps((__m256)b, (__m256)a, (__m256)m);
}
/* a < b ? a : b, a > b ? a : b per lane, as the one-lane helpers (minps, maxps) */
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_min(rr_vf8 a, rr_vf8 b) { return _mm256_min_ps(a, b); }
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_max(rr_vf8 a, rr_vf8 b) { return _mm256_max_ps(a, b); }
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_abs(rr_vf8 a) { return (rr_vf8)((rr_vi8)a & 0x7FFFFFFF); }
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_floor(rr_vf8 a) {
  return _mm256_round_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_ceil(rr_vf8 a) {
  return _mm256_round_ps(a, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
}
RR_TARGET_AVX2 static inline rr_vf8 rr_vf8_from_int(rr_vi8 a) { return __builtin_convertvector(a, rr_vf8); }
RR_TARGET_AVX2 static inline rr_vi8 rr_vi8_trunc(rr_vf8 a) { return (rr_vi8)_mm256_cvttps_epi32(a); }
RR_TARGET_AVX2 static inline int rr_vi8_bits(rr_vi8 m) { return _mm256_movemask_ps((__m256)m); }
#endif

/* ---- for the ray casters (vis/bvh_trace.h, vis/rc_bvh.c) ---------------------- */

/* Loads four floats from a 16-byte aligned address: an aligned load, which the
 * compiler may fold into the operation that uses it. */
static inline rr_vf4 rr_vf4_load_aligned(const float *p) { return rr_vf4_load(__builtin_assume_aligned(p, 16)); }

#endif
