/* Triangle setup for a camera (paper sect. 3.2, eqs. 1–3, and the appendix).
 *
 * Consistency (sect. 4.2) needs the two triangles of a shared edge to compute
 * exactly opposite edge functions. The edge normal is therefore computed from the
 * edge's endpoints in a canonical order (lexicographic on coordinates) and negated
 * when the triangle runs the edge the other way; negation is exact in IEEE
 * arithmetic, so every later dot product is exactly opposite too. */
#include "rr.h"

static bool lex_less(vec3 a, vec3 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

/* m = d × (w_b·a − w_a·b) for the edge a → b (homogeneous w: 1, or 0 for a point
 * at infinity, given as its direction), with the same canonical order. */
static vec3 edge_normal_dir(vec3 d, vec3 a, vec3 b, bool a_inf, bool b_inf) {
  bool swap = lex_less(b, a);
  vec3 l = swap ? b : a, h = swap ? a : b;
  bool l_inf = swap ? b_inf : a_inf, h_inf = swap ? a_inf : b_inf;
  vec3 diff = !l_inf && !h_inf ? v3_sub(l, h) : l_inf && h_inf ? v3(0, 0, 0) : l_inf ? l : v3_neg(h);
  vec3 m = v3_cross(d, diff);
  return swap ? v3_neg(m) : m;
}

/* n = b × a for the edge a → b of a triangle seen from the origin, computed in the
 * stable form h × (l − h) for the canonical order (l, h). */
static vec3 edge_normal(vec3 a, vec3 b) {
  bool swap = lex_less(b, a);
  vec3 l = swap ? b : a, h = swap ? a : b;
  vec3 m = v3_cross(h, v3_sub(l, h)); /* = h × l */
  return swap ? v3_neg(m) : m;
}

/* Exactly one of n and -n is positive in the lexicographic order of
 * (g1, g2, g3); the tie rule asks it of the edge's derivatives, so the two
 * triangles of a shared edge never both own, nor both refuse, its samples. */
static bool lex_positive(float g1, float g2, float g3) {
  return g1 > 0 || (g1 == 0 && (g2 > 0 || (g2 == 0 && g3 > 0)));
}

/* Homogeneous vertices (paper appendix, eqs. 5–11). A corner at infinity
 * (w = 0) is stored as its direction D and enters as q = D instead of p − eye:
 * the edge normals n_i = q[i+2] × q[i+1] are still the planes through the eye
 * holding the edge (a point and a direction, or two directions), and the canonical
 * order works on q whatever they are. The volume V = q[0]·n[0] is −det(q0, q1, q2)
 * for any mix of points and directions (q_j·n_j is the same for every j). Only the
 * finite vertices enter the sum (eq. 10): t = V / Σ w_i V_i, λ_i = V_i / Σ w_i V_i;
 * tri_setup.w carries the w_i (1 for ordinary triangles, whose bits do not change). */
int tri_setup_camera(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces, tri_setup *out) {
  unsigned inf = scene_inf(s, i);
  vec3 q[3];
  for (int k = 0; k < 3; k++) q[k] = scene_q(s, k, i, c->eye);
  /* Edge i runs from q[i+1] to q[i+2]: n_i = q[i+2] × q[i+1] (paper eq. 1). */
  vec3 n[3];
  for (int e = 0; e < 3; e++) n[e] = edge_normal(q[(e + 1) % 3], q[(e + 2) % 3]);
  float vol = v3_dot(q[0], n[0]), vol_x = 0, vol_y = 0, orient = vol;
  vec3 m[3];
  if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
    /* The eye at infinity (paper appendix): the ray origin o = o0 + sx·ox + sy·oy moves
     * and d = fwd is fixed, so V_i = d·n_i + o·m_i with m_i = d × (q[i+1] - q[i+2]),
     * and the volume V(o) = V - o·Σn_i; the face is the sign of d·Σn_i. With points
     * at infinity, m_i = d × (w[i+2]·q[i+1] − w[i+1]·q[i+2]) and the sums are Σ w_i n_i. */
    vec3 sum = v3_add(v3_add(inf & 1u ? v3(0, 0, 0) : n[0], inf & 2u ? v3(0, 0, 0) : n[1]),
                      inf & 4u ? v3(0, 0, 0) : n[2]);
    for (int e = 0; e < 3; e++) {
      int a = (e + 1) % 3, b = (e + 2) % 3;
      m[e] = edge_normal_dir(c->fwd, q[a], q[b], inf >> a & 1u, inf >> b & 1u);
    }
    vol = vol - v3_dot(c->o0, sum);
    vol_x = -v3_dot(c->ox, sum);
    vol_y = -v3_dot(c->oy, sum);
    orient = v3_dot(c->fwd, sum);
  }
  if (!(orient != 0) || !isfinite(vol)) return SETUP_CULLED; /* seen edge-on */
  int face = orient > 0 ? SETUP_FRONT : SETUP_BACK;
  if (face == SETUP_BACK && cull_backfaces) return SETUP_CULLED;
  float sign = face == SETUP_FRONT ? 1.0f : -1.0f;
  out->vol = vol * sign, out->vol_x = vol_x * sign, out->vol_y = vol_y * sign;
  out->tie = 0;
  for (int k = 0; k < 3; k++) out->w[k] = inf >> k & 1u ? 0.0f : 1.0f;
  for (int e = 0; e < 3; e++) {
    vec3 ne = v3_scale(n[e], sign);
    float g1, g2;
    if (c->type == RR_CAMERA_PERSPECTIVE) {
      out->a[e] = v3_dot(ne, c->d0), out->b[e] = v3_dot(ne, c->dx), out->c[e] = v3_dot(ne, c->dy);
      g1 = out->b[e], g2 = out->c[e];
    } else if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
      vec3 me = v3_scale(m[e], sign);
      out->a[e] = v3_dot(ne, c->fwd) + v3_dot(me, c->o0);
      out->b[e] = v3_dot(me, c->ox), out->c[e] = v3_dot(me, c->oy);
      g1 = out->b[e], g2 = out->c[e];
    } else {
      out->a[e] = ne.x, out->b[e] = ne.y, out->c[e] = ne.z;
      g1 = v3_dot(ne, c->right), g2 = -v3_dot(ne, c->up);
    }
    /* Top-left rule: a sample on the edge belongs to the triangle whose inside lies
     * to its right (V_i,x > 0), or below for a horizontal edge (V_i,y > 0). */
    if (lex_positive(g1, g2, v3_dot(ne, c->fwd))) out->tie |= 1u << e;
  }
  return face;
}
