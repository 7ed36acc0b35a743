/* Triangle setup for a camera (paper sect. 3.2, eqs. 1–3, and the appendix).
 *
 * Consistency (sect. 4.2) needs the two triangles of a shared edge to compute
 * exactly opposite edge functions. The edge normal is therefore computed from the
 * edge's endpoints in a canonical order (lexicographic on coordinates) and negated
 * when the triangle runs the edge the other way; negation is exact in IEEE
 * arithmetic, so every later dot product is exactly opposite too. */
#include "prim/triangle.h"
#include "core/simd.h"

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
  setup_lanes1(s, &i, 1, c, cull_backfaces, out, &face);
  return face;
}

void rr_tri_setup_run(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces, bool simd,
                      tri_setup *out, int *face) {
  int k = 0;
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2"))
    for (; k < n; k += 8) setup_lanes8(s, ids + k, n - k < 8 ? n - k : 8, c, cull_backfaces, out + k, face + k);
#endif
  (void)simd;
  for (; k < n; k++) setup_lanes1(s, ids + k, 1, c, cull_backfaces, out + k, face + k);
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
