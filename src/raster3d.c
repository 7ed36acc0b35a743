/* 3D rasterization kernels shared by the traversal's configurations: a triangle's
 * screen bounds and the test of every sample of a rectangle (paper sect. 3.2, 5).
 * A triangle that crosses the eye plane has no bounded projection and is tested
 * over the whole screen; 3D edge functions need no clipping for that. */
#include "rr.h"

/* Samples a set-up triangle may cover, as an inclusive pixel rectangle. Returns
 * false when it covers none. */
/* Curved views: the cells whose cone no edge plane leaves wholly outside. */
/* Curved views: does a cone of directions (unit axis, half-angle) miss the
 * triangle's directions? Two conservative tests: the triangle's bounding cap
 * (tight for small triangles), and the four planes through the eye a hit must lie
 * inside of: V_i >= 0 for the three edges and Σw_iV_i > 0 (t > 0). */
bool cone_excludes(const tri_cone *tc, const tri_setup *ts, vec3 axis, float angle) {
  if (tc->cap_angle >= 0 && acosf(fminf(1.0f, v3_dot(axis, tc->cap_axis))) > angle + tc->cap_angle + 1e-5f)
    return true;
  float lim = sinf(angle) + 1e-5f, sum = 0;
  for (int e = 0; e < 3; e++) {
    float v = ts->a[e] * axis.x + ts->b[e] * axis.y + ts->c[e] * axis.z;
    if (v < -tc->len[e] * lim) return true;
    sum += v * ts->w[e];
  }
  return sum < -tc->len[3] * lim;
}

void tri_cone_setup(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, tri_cone *tc) {
  for (int e = 0; e < 3; e++) tc->len[e] = sqrtf(ts->a[e] * ts->a[e] + ts->b[e] * ts->b[e] + ts->c[e] * ts->c[e]);
  const float *w = ts->w; /* the sum that must be positive is Σ w_i V_i */
  float sx = ts->a[0] * w[0] + ts->a[1] * w[1] + ts->a[2] * w[2];
  float sy = ts->b[0] * w[0] + ts->b[1] * w[1] + ts->b[2] * w[2];
  float sz = ts->c[0] * w[0] + ts->c[1] * w[1] + ts->c[2] * w[2];
  /* the sum is evaluated edge by edge: allow for the rounding of each term too */
  tc->len[3] = sqrtf(sx * sx + sy * sy + sz * sz) + 1e-6f * (tc->len[0] + tc->len[1] + tc->len[2]);
  /* A cap around the mean vertex direction holds the spherical triangle when its
   * radius is under 90° (caps that small are spherically convex). */
  vec3 u[3], m = v3(0, 0, 0);
  for (int k = 0; k < 3; k++) u[k] = v3_norm(scene_q(s, k, i, c->eye)), m = v3_add(m, u[k]);
  tc->cap_angle = -1;
  if (v3_len(m) > 1e-3f) {
    tc->cap_axis = v3_norm(m);
    float r = 0;
    for (int k = 0; k < 3; k++) r = fmaxf(r, acosf(fminf(1.0f, v3_dot(u[k], tc->cap_axis))));
    if (r < 1.5f) tc->cap_angle = r * 1.0001f + 1e-5f;
  }
}

static bool curved_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int r[4]) {
  tri_cone tc;
  tri_cone_setup(s, i, c, ts, &tc);
  int x0 = c->cells_x, y0 = c->cells_y, x1 = -1, y1 = -1;
  for (int cy = 0; cy < c->cells_y; cy++)
    for (int cx = 0; cx < c->cells_x; cx++) {
      const float *cell = c->cells + 4 * ((size_t)cy * c->cells_x + cx);
      if (cell[3] < 0) continue; /* no rays */
      if (cell[3] < 1.5f && cone_excludes(&tc, ts, v3(cell[0], cell[1], cell[2]), cell[3])) continue;
      x0 = cx < x0 ? cx : x0, x1 = cx > x1 ? cx : x1, y0 = cy < y0 ? cy : y0, y1 = cy > y1 ? cy : y1;
    }
  if (x1 < 0) return false;
  r[0] = x0 * CAMERA_CELL, r[1] = y0 * CAMERA_CELL;
  r[2] = (x1 + 1) * CAMERA_CELL - 1 < c->width - 1 ? (x1 + 1) * CAMERA_CELL - 1 : c->width - 1;
  r[3] = (y1 + 1) * CAMERA_CELL - 1 < c->height - 1 ? (y1 + 1) * CAMERA_CELL - 1 : c->height - 1;
  return true;
}

bool tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int r[4]) {
  float x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  int behind = 0, projected = 0;
  /* A point at infinity projects to its vanishing point when its direction points
   * ahead; the projection of the segment from a point to it is then the segment
   * to the vanishing point, so the hull of the three still bounds the triangle.
   * An orthographic view sees such a triangle unbounded: whole screen. */
  bool ortho_inf = c->type == RR_CAMERA_ORTHOGRAPHIC && scene_inf(s, i);
  for (int k = 0; k < 3; k++) {
    vec3 q = scene_q(s, k, i, c->eye);
    float sx, sy;
    if (!(v3_dot(q, c->fwd) > 0)) behind++;
    else if (camera_project(c, q, &sx, &sy) && isfinite(sx) && isfinite(sy)) {
      projected++;
      x0 = minf(x0, sx), x1 = maxf(x1, sx), y0 = minf(y0, sy), y1 = maxf(y1, sy); /* finite: no libm calls */
    }
  }
  if (!c->planar) {
    /* Curved views have no straight-edged projection; hemispheres see nothing
     * wholly behind the eye plane. */
    if (behind == 3 && c->type == RR_CAMERA_PARABOLIC) return false;
    return curved_bounds(s, i, c, ts, r);
  }
  if (behind == 3) return false; /* every camera ray has d·fwd > 0: unreachable */
  if (projected == 3 && !ortho_inf) {
    /* Sample (x + 0.5) lies in [x0, x1] for x in [ceil(x0 - 0.5), floor(x1 - 0.5)]. */
    /* The margin covers the rounding of the projection and of the edge functions,
     * a few ulps of the larger coordinate; a whole pixel would double the area of
     * the small triangles of real meshes. */
    float m = 1.0f / 64 + 1e-5f * maxf(maxf(fabsf(x0), fabsf(x1)), maxf(fabsf(y0), fabsf(y1)));
    float lx = maxf(ceilf(x0 - 0.5f - m), 0.0f), hx = minf(floorf(x1 - 0.5f + m), (float)(c->width - 1));
    float ly = maxf(ceilf(y0 - 0.5f - m), 0.0f), hy = minf(floorf(y1 - 0.5f + m), (float)(c->height - 1));
    if (lx > hx || ly > hy) return false;
    r[0] = (int)lx, r[1] = (int)ly, r[2] = (int)hx, r[3] = (int)hy;
    return true;
  }
  r[0] = 0, r[1] = 0, r[2] = c->width - 1, r[3] = c->height - 1;
  return true;
}

/* The planar bounds of one triangle from its corners, as tri_screen_bounds gives them. */
static inline uint32_t keep_bounded(const rr_scene *s, uint32_t i, const camera *c, tri_bound *out) {
  out->id = i;
  return tri_screen_bounds(s, i, c, NULL, out->bb);
}

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

/* tri_screen_bounds for eight triangles at once, for planar cameras and finite
 * corners: the same operations in the same order (no FMA, true divisions), so the
 * same rectangles. Lanes with a corner not strictly in front of the image plane
 * (or projecting to no finite point) take the scalar path. */
/* Triangles ids[0..n-1] (n <= 8), or first..first+n-1 when ids is NULL. */
__attribute__((target("avx2"))) static uint32_t bounds8_avx2(const rr_scene *s, uint32_t first, const uint32_t *ids,
                                                              int n, const camera *c, tri_bound *out) {
  uint32_t lane_id[8];
  for (int l = 0; l < 8; l++) lane_id[l] = ids ? ids[l < n ? l : n - 1] : first + (uint32_t)(l < n ? l : n - 1);
  const __m256i idx = _mm256_loadu_si256((const __m256i *)lane_id);
  const bool persp = c->type == RR_CAMERA_PERSPECTIVE;
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), half = _mm256_set1_ps(0.5f);
  const __m256 W = _mm256_set1_ps((float)c->width), H = _mm256_set1_ps((float)c->height);
  const __m256 inf = _mm256_set1_ps(INFINITY), absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const float e[3] = {c->eye.x, c->eye.y, c->eye.z};
  const float f[3] = {c->fwd.x, c->fwd.y, c->fwd.z}, rt[3] = {c->right.x, c->right.y, c->right.z},
              up[3] = {c->up.x, c->up.y, c->up.z};
  __m256 x0 = inf, y0 = inf, x1 = _mm256_set1_ps(-INFINITY), y1 = x1;
  __m256 ok = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int k = 0; k < 3; k++) {
    __m256 q[3];
    for (int a = 0; a < 3; a++) {
      __m256 p = ids || n < 8 ? _mm256_i32gather_ps(s->p[k][a], idx, 4) : _mm256_loadu_ps(s->p[k][a] + first);
      q[a] = _mm256_sub_ps(p, _mm256_set1_ps(e[a]));
    }
#define DOT3(v) \
  _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(q[0], _mm256_set1_ps(v[0])), _mm256_mul_ps(q[1], _mm256_set1_ps(v[1]))), \
                _mm256_mul_ps(q[2], _mm256_set1_ps(v[2])))
    __m256 z = DOT3(f), qr = DOT3(rt), qu = DOT3(up);
#undef DOT3
    __m256 sx, sy;
    if (persp) {
      __m256 u = _mm256_div_ps(qr, _mm256_mul_ps(z, _mm256_set1_ps(c->tan_half_w)));
      __m256 v = _mm256_div_ps(qu, _mm256_mul_ps(z, _mm256_set1_ps(c->tan_half_h)));
      sx = _mm256_mul_ps(_mm256_mul_ps(_mm256_add_ps(u, one), half), W);
      sy = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(one, v), half), H);
    } else {
      sx = _mm256_mul_ps(_mm256_mul_ps(_mm256_add_ps(_mm256_div_ps(qr, _mm256_set1_ps(c->tan_half_w)), one), half), W);
      sy = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(one, _mm256_div_ps(qu, _mm256_set1_ps(c->tan_half_h))), half), H);
    }
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(z, zero, _CMP_GT_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_and_ps(sx, absmask), inf, _CMP_LT_OQ));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_and_ps(sy, absmask), inf, _CMP_LT_OQ));
    x0 = _mm256_min_ps(x0, sx), x1 = _mm256_max_ps(x1, sx), y0 = _mm256_min_ps(y0, sy), y1 = _mm256_max_ps(y1, sy);
  }
  __m256 big = _mm256_max_ps(_mm256_max_ps(_mm256_and_ps(x0, absmask), _mm256_and_ps(x1, absmask)),
                             _mm256_max_ps(_mm256_and_ps(y0, absmask), _mm256_and_ps(y1, absmask)));
  __m256 m = _mm256_add_ps(_mm256_set1_ps(1.0f / 64), _mm256_mul_ps(_mm256_set1_ps(1e-5f), big));
  const int down = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC, upr = _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC;
  __m256 lx = _mm256_max_ps(_mm256_round_ps(_mm256_sub_ps(_mm256_sub_ps(x0, half), m), upr), zero);
  __m256 ly = _mm256_max_ps(_mm256_round_ps(_mm256_sub_ps(_mm256_sub_ps(y0, half), m), upr), zero);
  __m256 hx = _mm256_min_ps(_mm256_round_ps(_mm256_add_ps(_mm256_sub_ps(x1, half), m), down),
                            _mm256_set1_ps((float)(c->width - 1)));
  __m256 hy = _mm256_min_ps(_mm256_round_ps(_mm256_add_ps(_mm256_sub_ps(y1, half), m), down),
                            _mm256_set1_ps((float)(c->height - 1)));
  __m256 empty = _mm256_or_ps(_mm256_cmp_ps(lx, hx, _CMP_GT_OQ), _mm256_cmp_ps(ly, hy, _CMP_GT_OQ));
  int lanes = (1 << n) - 1, okm = _mm256_movemask_ps(ok) & lanes, keep = okm & ~_mm256_movemask_ps(empty);
  if (!keep && okm == lanes) return 0;
  int b[4][8];
  _mm256_storeu_si256((__m256i *)b[0], _mm256_cvttps_epi32(lx));
  _mm256_storeu_si256((__m256i *)b[1], _mm256_cvttps_epi32(ly));
  _mm256_storeu_si256((__m256i *)b[2], _mm256_cvttps_epi32(hx));
  _mm256_storeu_si256((__m256i *)b[3], _mm256_cvttps_epi32(hy));
  uint32_t kept = 0;
  for (int l = 0; l < n; l++) {
    if (!(okm >> l & 1)) {
      kept += keep_bounded(s, lane_id[l], c, out + kept);
    } else if (keep >> l & 1) {
      out[kept] = (tri_bound){lane_id[l], {b[0][l], b[1][l], b[2][l], b[3][l]}};
      kept++;
    }
  }
  return kept;
}
#endif

uint32_t tri_corner_bounds(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                           bool simd, tri_bound *out) {
  uint32_t kept = 0, k = 0;
#if defined(__x86_64__) || defined(__i386__)
  if (simd && !s->inf && __builtin_cpu_supports("avx2"))
    for (; k < n; k += 8)
      kept += bounds8_avx2(s, first + k, ids ? ids + k : NULL, n - k < 8 ? (int)(n - k) : 8, c, out + kept);
#else
  (void)simd;
#endif
  for (; k < n; k++) kept += keep_bounded(s, ids ? ids[k] : first + k, c, out + kept);
  return kept;
}

/* The sample loop, written once and specialised for planar and curved cameras. */
static inline uint64_t raster_loop(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                                   const bool planar) {
  uint64_t covered = 0;
  for (int y = r[1]; y <= r[3]; y++) {
    float sy = (float)y + 0.5f;
    size_t row = (size_t)y * vb->width;
    for (int x = r[0]; x <= r[2]; x++) {
      float sx = (float)x + 0.5f;
      vec3 w = planar ? v3(1.0f, sx, sy) : c->dirs[row + x];
      covered += shade_sample_w(ts, id, w, sx, sy, vb, row + x) != 0;
    }
  }
  return covered;
}

#if defined(__x86_64__) || defined(__i386__)

/* The planar sample loop, 8 samples of a row at a time with AVX2. Every operation
 * is the scalar one, in the same order, on IEEE single floats (no FMA, a true
 * division), so the bits are those of raster_loop: the same sample test. */
__attribute__((target("avx2"))) static uint64_t raster_loop_avx2(const tri_setup *ts, uint32_t id, const int r[4],
                                                                  visbuf *vb) {
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
    const __m256 sx = _mm256_add_ps(_mm256_cvtepi32_ps(xi), _mm256_set1_ps(0.5f));
    __m256 ax[3];
    for (int e = 0; e < 3; e++) ax[e] = _mm256_add_ps(_mm256_mul_ps(a[e], one), _mm256_mul_ps(b[e], sx));
    const __m256 vx = _mm256_add_ps(vol, _mm256_mul_ps(sx, vol_x));
    for (int y = r[1]; y <= r[3]; y++) {
      const __m256 sy = _mm256_set1_ps((float)y + 0.5f);
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
uint64_t raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                     uint64_t *covered, bool simd) {
  uint64_t n, samples = (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
#if defined(__x86_64__) || defined(__i386__)
  /* a rectangle of a few samples (most triangles of a detailed mesh) costs less
   * than the vector loop's setup; both paths give the same bits */
  if (simd && c->planar && samples > 2 && __builtin_cpu_supports("avx2")) n = raster_loop_avx2(ts, id, r, vb);
  else
#endif
    n = c->planar ? raster_loop(ts, id, r, c, vb, true) : raster_loop(ts, id, r, c, vb, false);
  (void)simd;
  if (covered) *covered += n;
  return samples;
}
