/* Triangle setup for a camera (paper sect. 3.2, eqs. 1–3, and the appendix).
 *
 * Consistency (sect. 4.2) needs the two triangles of a shared edge to compute
 * exactly opposite edge functions. The edge normal is therefore computed from the
 * edge's endpoints in a canonical order (lexicographic on coordinates) and negated
 * when the triangle runs the edge the other way; negation is exact in IEEE
 * arithmetic, so every later dot product is exactly opposite too. */
#include "prim/triangle.h"
#include "core/simd.h"

#include <sched.h>

/* Homogeneous vertices (paper appendix, eqs. 5–11). A corner at infinity
 * (w = 0) is stored as its direction D and enters as q = D instead of p − eye:
 * the edge normals n_i = q[i+2] × q[i+1] are still the planes through the eye
 * holding the edge (a point and a direction, or two directions), and the canonical
 * order works on q whatever they are. The volume V = q[0]·n[0] is −det(q0, q1, q2)
 * for any mix of points and directions (q_j·n_j is the same for every j). Only the
 * finite vertices enter the sum (eq. 10): t = V / Σ w_i V_i, λ_i = V_i / Σ w_i V_i;
 * tri_setup.w carries the w_i (1 for ordinary triangles, whose bits do not change).
 *
 * Each edge normal is computed in the stable form h × (l − h) = h × l for the
 * canonical order (l, h) of its endpoints (lexicographic on coordinates), negated
 * when the triangle runs the edge from h to l.
 *
 * The eye at infinity (orthographic views, paper appendix): the ray origin
 * o = o0 + sx·ox + sy·oy moves and d = fwd is fixed, so V_i = d·n_i + o·m_i with
 * m_i = d × (q[i+1] − q[i+2]) (with points at infinity, m_i = d × (w[i+2]·q[i+1] −
 * w[i+1]·q[i+2]), in the same canonical order), and the volume V(o) = V − o·Σ w_i n_i;
 * the face is the sign of d·Σ w_i n_i.
 *
 * The edge functions for the camera's w (triangle.h), after the normals are
 * turned to face the inside: perspective a, b, c = n·d0, n·dx, n·dy (eq. 3);
 * orthographic a = n·d + m·o0, b = m·ox, c = m·oy; curved (a, b, c) = n.
 *
 * The top-left rule: a sample on an edge belongs to the triangle whose inside lies
 * to its right (V_i,x > 0), or below for a horizontal edge (V_i,y > 0). Exactly one
 * of n and −n is positive in the lexicographic order of (g1, g2, g3), the edge's
 * screen derivatives (b and c; n·right and −n·up for curved views) and its value
 * along the view direction, so the two triangles of a shared edge never both own,
 * nor both refuse, its samples. */
/* The depth from the plane (triangle.h: num, den). The plane normal Σ w_i n_i is
 * the same for every point c the corners are taken relative to (q_k = p_k − w_k·c:
 * the terms in c cancel), and with c = p_f, a finite corner, only the term of n_f
 * remains: N = r_{f+2} × r_{f+1}, r_k = p_k − w_k·p_f, which is (p2 − p0) × (p1 − p0)
 * for an ordinary triangle. It is computed from the world corners: its size is edge
 * length², not the distance × edge length of the n_i whose sum cancels, and its
 * rounding tilts the plane about p_f by about u·|p|/L radians, which moves a hit at
 * most L from p_f by u·|p| (L: edge length). Then V = N·q_f (n_i·q_f = 0 for i ≠ f)
 * and Σ w_i V_i = N·d, so num / den is, exactly, V / Σ w_i V_i; rounded, each is a
 * dot product whose error is a few ulps over the cosine between N and q_f or d. */
#define RR_TEMPLATE "prim/triangle_setup_tmp.h"
#include "core/simd_widths.h"

int rr_tri_setup(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces, tri_setup *out) {
  int face;
  setup_one1(s, &i, 1, c, cull_backfaces, out, &face, NULL);
  return face;
}

void rr_tri_setup_shared(const rr_scene *s, const uint32_t *ids, int n, const camera *cams, int ncams,
                         const int32_t *sel, const int *nsel, bool cull_backfaces, bool simd, tri_setup *out,
                         size_t ostride, int *face, tri_plane *pl, size_t pstride) {
  bool ortho = false;
  for (int k = 0; k < ncams; k++) ortho |= cams[k].type == RR_CAMERA_ORTHOGRAPHIC;
  if (ortho) { /* (no caller: the shared EYE leaves out what the eye at infinity reads) */
    for (int k = 0, at = 0; k < ncams; at += nsel[k++])
      for (int j = at; j < at + nsel[k]; j++)
        setup_one1(s, &ids[sel[j]], 1, &cams[k], cull_backfaces, (tri_setup *)((char *)out + j * ostride), &face[j],
                   pl ? (tri_plane *)((char *)pl + j * pstride) : NULL);
    return;
  }
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2")) {
    setup_shared8(s, ids, n, cams, ncams, sel, nsel, cull_backfaces, out, ostride, face, pl, pstride);
    return;
  }
#endif
  (void)simd;
  setup_shared1(s, ids, n, cams, ncams, sel, nsel, cull_backfaces, out, ostride, face, pl, pstride);
}

int rr_tri_setup_kept(const rr_scene *s, tri_eyes *keep, const uint32_t *ids, int n, const camera *c,
                      bool cull_backfaces, bool simd, tri_setup *out, int *face, tri_plane *pl, int *order) {
  if (c->type == RR_CAMERA_ORTHOGRAPHIC) { /* (no caller: the eye at infinity keeps no EYE) */
    for (int k = 0; k < n; k++) order[k] = k;
    rr_tri_setup_planes(s, ids, n, c, cull_backfaces, simd, out, face, pl);
    return n;
  }
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2"))
    return setup_kept8(s, keep, ids, n, c, cull_backfaces, out, face, pl, order);
#endif
  (void)simd;
  return setup_kept1(s, keep, ids, n, c, cull_backfaces, out, face, pl, order);
}

void rr_tri_setup_planes(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces,
                         bool simd, tri_setup *out, int *face, tri_plane *pl) {
  int k = 0;
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2"))
    for (; k < n; k += 8)
      setup_one8(s, ids + k, n - k < 8 ? n - k : 8, c, cull_backfaces, out + k, face + k, pl ? pl + k : NULL);
#endif
  (void)simd;
  for (; k < n; k++) setup_one1(s, ids + k, 1, c, cull_backfaces, out + k, face + k, pl ? pl + k : NULL);
}

void rr_tri_setup_run(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces, bool simd,
                      tri_setup *out, int *face) {
  rr_tri_setup_planes(s, ids, n, c, cull_backfaces, simd, out, face, NULL);
}

void rr_tri_setup_at(const tri_setup *ts, const tri_plane *pl, const camera *c, tri_setup *out) {
  float m[4];
  tri_moved(ts, pl, c, m);
  *out = *ts;
  out->pa = m[0], out->num0 = m[1], out->cx = m[2], out->cy = m[3];
}

void rr_tri_moved_all(const tri_setup *ts, const tri_plane *pl, const camera *c, int n, const float *ox,
                      const float *oy, bool simd, float *pa, float *num0, float *cx, float *cy) {
  int k = 0;
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2"))
    for (; k + 8 <= n; k += 8) moved_lanes8(ts, pl, c, ox + k, oy + k, pa + k, num0 + k, cx + k, cy + k);
#endif
  (void)simd;
  for (; k < n; k++) moved_lanes1(ts, pl, c, ox + k, oy + k, pa + k, num0 + k, cx + k, cy + k);
}

bool rr_tri_ray_hit(const rr_scene *s, uint32_t i, const camera *ray, bool cull, float tmin, float tmax, float *t,
                 float *l1, float *l2) {
  tri_setup ts;
  if (rr_tri_setup(s, i, ray, cull, &ts) == SETUP_CULLED) return false;
  /* sample (0, 0): the edge functions and the plane along the ray itself */
  float e[3];
  tri_edges(&ts, 0.0f, 0.0f, e);
  if (!sample_test(&ts, e, 0.0f, 0.0f, t, l1, l2)) return false;
  return *t >= tmin && *t <= tmax;
}

/* Double three-vectors for the plane of rr_tri_ray_hit1: the template's D3 operations. */
typedef struct {
  double x, y, z;
} dvec3;
static inline dvec3 dv3(vec3 a) { return (dvec3){a.x, a.y, a.z}; }
/* DSPLAT3: 0 + x, whose zeros are +0 */
static inline dvec3 dv3_splat(vec3 a) { return (dvec3){0.0 + a.x, 0.0 + a.y, 0.0 + a.z}; }
static inline dvec3 dv3_sub(dvec3 a, dvec3 b) { return (dvec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline double dv3_dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* The plane and the sample test of rr_tri_ray_hit1 once the edge values e, their
 * tie bits and the unturned volume vol (= q0·n0, not 0, finite) are known. */
bool rr_tri_ray_finish(const rr_scene *s, uint32_t i, const camera *ray, const float e[3], uint32_t tie, float vol,
                       float tmin, float tmax, float *t, float *l1, float *l2) {
  const float sign = vol > 0.0f ? 1.0f : -1.0f;
  tri_setup ts = {.vol = vol * sign, .vol_x = 0.0f * sign, .vol_y = 0.0f * sign, .tie = tie, .w = {1.0f, 1.0f, 1.0f}};
  /* the plane: N = (p2 − p0) × (p1 − p0), exact in double, turned like the edges */
  const dvec3 p0 = dv3(scene_vertex(s, 0, i)), r1 = dv3_sub(dv3(scene_vertex(s, 1, i)), p0),
              r2 = dv3_sub(dv3(scene_vertex(s, 2, i)), p0);
  const double dsign = sign;
  const dvec3 nrm = {(r2.y * r1.z - r2.z * r1.y) * dsign, (r2.z * r1.x - r2.x * r1.z) * dsign,
                     (r2.x * r1.y - r2.y * r1.x) * dsign};
  const double pb = dv3_dot(nrm, dv3_splat(ray->dx)), pc = dv3_dot(nrm, dv3_splat(ray->dy));
  ts.pa = (float)(dv3_dot(nrm, dv3_splat(ray->d0)) + 0.0 * pb + 0.0 * pc), ts.pb = (float)pb, ts.pc = (float)pc;
  ts.num0 = (float)dv3_dot(nrm, dv3_sub(p0, dv3_splat(ray->eye)));
  ts.num_x = ts.num_y = (float)0.0;
  if (!sample_test(&ts, e, 0.0f, 0.0f, t, l1, l2)) return false;
  return *t >= tmin && *t <= tmax;
}

/* rr_tri_ray_hit's setup_lanes1 for one finite triangle and a camera of
 * rr_cam_for_ray (perspective, not planar: cx = cy = 0), cut to what the sample
 * (0, 0) reads, in the template's operations and order (vec.h's dot and cross are
 * its DOT3 and CROSS3, tri_edge_normal its canonical normal), so the bits are its
 * bits; tests/test_rays compares the two on every triangle of many rays. The plane
 * (in double) is computed only once the edges pass. */
bool rr_tri_ray_hit1(const rr_scene *s, uint32_t i, const camera *ray, float tmin, float tmax, float *t, float *l1,
                     float *l2) {
  vec3 q[3], n[3];
  for (int k = 0; k < 3; k++) q[k] = v3_sub(scene_vertex(s, k, i), ray->eye);
  for (int e = 0; e < 3; e++) n[e] = tri_edge_normal(q[(e + 1) % 3], q[(e + 2) % 3]);
  float vol = v3_dot(q[0], n[0]);
  if (!(vol != 0.0f && fabsf(vol) < INFINITY)) return false; /* edge-on or not finite: SETUP_CULLED */
  const float sign = vol > 0.0f ? 1.0f : -1.0f;
  float e[3];
  uint32_t tie = 0;
  for (int k = 0; k < 3; k++) {
    vec3 ne = v3_scale(n[k], sign);
    float a = v3_dot(ne, ray->d0), b = v3_dot(ne, ray->dx), c = v3_dot(ne, ray->dy), f = v3_dot(ne, ray->fwd);
    tie |= (b > 0.0f || (b == 0.0f && (c > 0.0f || (c == 0.0f && f > 0.0f)))) ? 1u << k : 0u; /* LEX_POSITIVE */
    e[k] = a * 1.0f + b * 0.0f + c * 0.0f; /* tri_edges at (0, 0) */
    if (!TRI_EDGE_INSIDE(e[k], (tie >> k & 1u) != 0, 0.0f)) return false;
  }
  return rr_tri_ray_finish(s, i, ray, e, tie, vol, tmin, tmax, t, l1, l2);
}
