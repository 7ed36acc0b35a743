/* One ray against one triangle, after the edge pre-test (prim/triangle.h:
 * tri4_edges_test) let it through: the test of rr_intersect and rr_occluded
 * (vis/ray_query.c), written once so that shadows by rasterization from a light
 * (vis/shadow_raster.c) test each (sample, triangle) pair with the same bits. */
#ifndef RR_RAY_TEST_H
#define RR_RAY_TEST_H

#include "prim/triangle.h"

/* Whether the setup's b_i, c_i (n_i·dx, n_i·dy) are finite for every finite
 * triangle of s seen by the ray camera c from org: |n_i| ≤ 4Q² (per axis, up to
 * rounding) for corners within Q of the origin, so |b_i|, |c_i| ≤ 12·Q²·D for dx,
 * dy within D, far below FLT_MAX for Q, D < 1e12. NaN (no finite corner) is not small. */
static inline bool ray_small(const rr_scene *s, const float org[3], const camera *c) {
  const float lo[3] = {s->bmin.x, s->bmin.y, s->bmin.z}, hi[3] = {s->bmax.x, s->bmax.y, s->bmax.z};
  const float dx[3] = {c->dx.x, c->dx.y, c->dx.z}, dy[3] = {c->dy.x, c->dy.y, c->dy.z};
  bool small = true;
  for (int a = 0; a < 3; a++)
    small &= fabsf(lo[a] - org[a]) < 1e12f && fabsf(hi[a] - org[a]) < 1e12f && fabsf(dx[a]) < 1e12f &&
             fabsf(dy[a]) < 1e12f;
  return small;
}

/* Why a ray cannot be traced, or NULL. */
static inline const char *ray_problem(const float org[3], const float dir[3], float tmin, float tmax) {
  /* x − x is 0 for a finite x and NaN otherwise; NaN survives the sums */
  float z = (org[0] - org[0]) + (org[1] - org[1]) + (org[2] - org[2]) + (dir[0] - dir[0]) + (dir[1] - dir[1]) +
            (dir[2] - dir[2]);
  if (__builtin_expect(z == 0 && (dir[0] != 0 || dir[1] != 0 || dir[2] != 0) && tmin == tmin && tmax == tmax, 1))
    return NULL;
  if (z != 0) return "a non-finite origin or direction";
  if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0) return "a zero direction";
  return "a NaN range";
}

/* Whether ray_problem finds nothing wrong with the ray, in four lanes: org and
 * dir finite (x − x is 0), tmin and tmax not NaN, dir not zero. */
static inline bool ray_valid(const rr_ray *ray) {
  _Static_assert(sizeof(rr_ray) == 8 * sizeof(float), "rr_ray: eight floats in a row");
  rr_vf4 a, b; /* o0 o1 o2 d0, d1 d2 tmin tmax: the struct's bytes, read as such */
  memcpy(&a, ray, sizeof a), memcpy(&b, (const char *)ray + sizeof a, sizeof b);
  const rr_vi4 range = {0, 0, -1, -1}; /* tmin, tmax: infinite is fine, NaN is not */
  int ok = rr_vi4_bits((a - a == 0) & ((b - b == 0) | (range & (b == b))));
  return ok == 0xF && (ray->dir[0] != 0 || ray->dir[1] != 0 || ray->dir[2] != 0);
}

/* Whether the full test (ray_tri_test) of a triangle whose pre-test values pre
 * (tri_ray_may_hit4) are all inside, e_i > 0, surely finds its t outside [tmin,
 * tmax], from those values alone: the start triangle of a ray from a surface, or a
 * triangle beyond the best hit so far, then costs no plane in double; S is the
 * triangle's lane of ray_corner_extent4, dmax = D below. The bound: with q_k = p_k − o as the pre-test
 * rounds them, S = max |q_k|, D = max |d| (per axis), u = 2⁻²⁴, the pre-test's
 * edge values are within 80·u·S²·D of the exact (q_{i+2} × q_{i+1})·d, its volume
 * within 80·u·S³ of the exact q0·(q2 × q1) (cross products: |l − h| ≤ 2S, one
 * rounding each, components within 12.1·u·S² and at most 4.01·S²; the dot
 * products γ₃·3·max|c|·D; the rounding of q_k itself moves them by at most
 * 12·u·S²·D and 18·u·S³), and the exact t of the plane is the exact volume over
 * the exact sum of the edge values. The full test's t is num / den (each within a
 * float rounding and double roundings far below u·S³ or u·S²·D of the exact, over
 * the plane normal's components of at most 8S²) or vol / Σe: either within the
 * bounds below, which take 128·u·S³ and 512·u·S²·D, leave a factor 1 ∓ 32u for
 * their own roundings and hold only where nothing under- or overflows (S, D in
 * [2⁻³⁰, 2³⁰]) and the denominator keeps at least half of Σe. tests/test_rays
 * checks it against the full test. */
typedef struct {
  float vol, err_v, den_lo, den_hi; /* t lies in [(vol − err_v) / den_hi·(1 − 32u), (vol + err_v) / den_lo·(1 + 32u)] */
} ray_t_terms;

/* The terms of the bound above, false where it does not hold (dlim: the largest
 * D its caller's proof allows). */
static inline bool ray_t_terms_of(float S, float dmax, float dlim, const float pre[4], ray_t_terms *r) {
  if (!(S >= 0x1p-30f && S <= 0x1p30f && dmax >= 0x1p-30f && dmax <= dlim)) return false;
  const float u = 0x1p-24f, sum = pre[0] + pre[1] + pre[2], err_s = S * S * dmax * (512 * u);
  r->vol = fabsf(pre[3]), r->err_v = S * S * S * (128 * u);
  r->den_lo = sum * (1 - 8 * u) - err_s, r->den_hi = sum * (1 + 8 * u) + err_s;
  return r->den_lo >= 0.5f * sum;
}

static inline bool ray_t_outside(float S, float dmax, const float pre[4], float tmin, float tmax) {
  const float u = 0x1p-24f;
  ray_t_terms r;
  if (!ray_t_terms_of(S, dmax, 0x1p30f, pre, &r)) return false;
  if ((r.vol + r.err_v) / r.den_lo * (1 + 32 * u) < tmin) return true;
  return r.vol - r.err_v > 0 && (r.vol - r.err_v) / r.den_hi * (1 - 32 * u) > tmax;
}

/* The other side of ray_t_outside's bound, for any-hit queries: whether the full
 * test (ray_tri_test) of a triangle whose pre-test values pre are all inside,
 * e_i > 0, surely hits with t in [tmin, tmax], from those values alone, so that
 * rr_occluded stops there without the ray's pseudo-camera or the plane in double.
 * Where every e_i > 0 the full test's sample test reads only e, the volume and
 * the plane's num, den (both of its paths: rr_tri_ray_finish with e, or
 * rr_tri_ray_hit1, whose e_i = a_i + b_i·0 + c_i·0 are the same positive values
 * when b_i, c_i are finite, the tie bits then unread): e inside, Σe > 0 and the
 * volume |pre[3]| > 0 pass, and t is num / den or vol / Σe, both within
 * ray_t_outside's bounds [(vol − err_v) / den_hi·(1 − 32u), (vol + err_v) /
 * den_lo·(1 + 32u)]. b_i, c_i are finite: n_i·dx, n_i·dy with |n_i| ≤ 4.01·S² <
 * 2⁶³ per axis (S ≤ 2³⁰), |dx| ≤ D and |dy| ≤ 2·D² ≤ 2³⁹ (rr_cam_for_ray: dx
 * takes d's components, dy = d × dx) for D ≤ 2¹⁹, so each is below 3·2¹⁰²,
 * also in double and once rounded to float. Hence the extra D ≤ 2¹⁹. tests/test_rays
 * checks it against the full test. */
static inline bool ray_t_inside(float S, float dmax, const float pre[4], float tmin, float tmax) {
  const float u = 0x1p-24f;
  ray_t_terms r;
  if (!ray_t_terms_of(S, dmax, 0x1p19f, pre, &r)) return false;
  return r.vol - r.err_v > 0 && (r.vol - r.err_v) / r.den_hi * (1 - 32 * u) >= tmin &&
         (r.vol + r.err_v) / r.den_lo * (1 + 32 * u) <= tmax;
}

/* S of ray_t_outside for a triangle laid out as tri_ray_may_hit4 reads its lanes
 * (corner k's axis x at v[(3k + x)·stride]): max |q_k| over the corners and axes,
 * q_k = p_k − o rounded as the pre-test rounds it. No NaN (finite corners), so a
 * plain comparison (fmaxf is a call). sh: the corners moved by a translation
 * (x, y, z at sh[0], [4], [8]: a transform's last column), each rounded as p + sh
 * first, or NULL. */
static inline float ray_corner_extent(const float *v, size_t stride, const float *sh, const float org[3]) {
  float S = 0;
#pragma GCC unroll 9
  for (int m = 0; m < 9; m++, v += stride) {
    float q = fabsf((sh ? *v + sh[4 * (m % 3)] : *v) - org[m % 3]);
    S = q > S ? q : S;
  }
  return S;
}

/* A ray's pseudo-camera, made when its first triangle passes the pre-test (many
 * rays need none). */
typedef struct {
  bool ready, small;
  camera cam;
} ray_cam;

/* The full test of triangle id for the ray (org, dir) whose pre-test values are
 * pre (edge values e_0..e_2 and the volume q0·n0): with the pre-test's edge values
 * where all are positive (rr_tri_ray_finish), else with the part of the setup the
 * ray's one sample reads (rr_tri_ray_hit1), or, for corners at infinity, the full
 * setup (rr_tri_ray_hit) — the same bits each way. True on a hit in [tmin, tmax]. */
KERNEL bool ray_tri_test(const rr_scene *s, uint32_t id, ray_cam *rc, const float org[3], const float dir[3],
                                const float pre[4], float tmin, float tmax, float *t, float *l1, float *l2) {
  if (!rc->ready) {
    rr_cam_for_ray(org, dir, &rc->cam);
    rc->ready = true;
    rc->small = ray_small(s, org, &rc->cam);
  }
  /* Edge values all positive are the sample test's: no tie, no sign of a zero to
   * settle, only the plane left to compute. */
  const float e[3] = {pre[0], pre[1], pre[2]};
  if (s->inf && scene_inf(s, id)) return rr_tri_ray_hit(s, id, &rc->cam, false, tmin, tmax, t, l1, l2);
  if (rc->small && e[0] > 0 && e[1] > 0 && e[2] > 0)
    return rr_tri_ray_finish(s, id, &rc->cam, e, 0, pre[3], tmin, tmax, t, l1, l2);
  return rr_tri_ray_hit1(s, id, &rc->cam, tmin, tmax, t, l1, l2);
}

#endif
