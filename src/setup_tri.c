/* Triangle setup for an eye (paper sect. 3.2, eqs. 1–3).
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

/* n = b × a for the edge a → b of a triangle seen from the origin, computed in the
 * stable form h × (l − h) for the canonical order (l, h). */
static vec3 edge_normal(vec3 a, vec3 b) {
  bool swap = lex_less(b, a);
  vec3 l = swap ? b : a, h = swap ? a : b;
  vec3 m = v3_cross(h, v3_sub(l, h)); /* = h × l */
  return swap ? v3_neg(m) : m;
}

int tri_setup_planar(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces,
                     tri_setup *out) {
  vec3 q[3];
  for (int k = 0; k < 3; k++) q[k] = v3_sub(scene_vertex(s, k, i), c->eye);
  /* Edge i runs from q[i+1] to q[i+2]: n_i = q[i+2] × q[i+1] (paper eq. 1). */
  vec3 n[3];
  for (int e = 0; e < 3; e++) n[e] = edge_normal(q[(e + 1) % 3], q[(e + 2) % 3]);
  float vol = v3_dot(q[0], n[0]);
  if (!(vol != 0) || !isfinite(vol)) return SETUP_CULLED; /* the eye lies in its plane */
  int face = vol > 0 ? SETUP_FRONT : SETUP_BACK;
  if (face == SETUP_BACK && cull_backfaces) return SETUP_CULLED;
  float sign = face == SETUP_FRONT ? 1.0f : -1.0f;
  out->vol = vol * sign;
  out->tie = 0;
  for (int e = 0; e < 3; e++) {
    vec3 ne = v3_scale(n[e], sign);
    out->a[e] = v3_dot(ne, c->d0);
    out->b[e] = v3_dot(ne, c->dx);
    out->c[e] = v3_dot(ne, c->dy);
    /* Top-left rule: a sample on the edge belongs to the triangle whose inside
     * lies to its right (V_i,x > 0), or below for a horizontal edge (V_i,y > 0). */
    if (out->b[e] > 0 || (out->b[e] == 0 && out->c[e] > 0)) out->tie |= 1u << e;
  }
  return face;
}
