/* Triangle setup for a camera (paper sect. 3.2, eqs. 1–3, and the appendix).
 *
 * Consistency (sect. 4.2) needs the two triangles of a shared edge to compute
 * exactly opposite edge functions. The edge normal is therefore computed from the
 * edge's endpoints in a canonical order (lexicographic on coordinates) and negated
 * when the triangle runs the edge the other way; negation is exact in IEEE
 * arithmetic, so every later dot product is exactly opposite too. */
#include "prim/triangle.h"

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
int rr_tri_setup(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces, tri_setup *out) {
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

/* ---- eight triangles at once --------------------------------------------- */

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

typedef struct v8 { __m256 x, y, z; } v8;

#define AVX2 __attribute__((target("avx2"))) static inline
AVX2 __m256 d8(v8 a, v8 b) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y)), _mm256_mul_ps(a.z, b.z));
}
AVX2 v8 splat8(vec3 v) { return (v8){_mm256_set1_ps(v.x), _mm256_set1_ps(v.y), _mm256_set1_ps(v.z)}; }
AVX2 v8 sub8(v8 a, v8 b) { return (v8){_mm256_sub_ps(a.x, b.x), _mm256_sub_ps(a.y, b.y), _mm256_sub_ps(a.z, b.z)}; }
AVX2 v8 cross8(v8 a, v8 b) {
  return (v8){_mm256_sub_ps(_mm256_mul_ps(a.y, b.z), _mm256_mul_ps(a.z, b.y)),
              _mm256_sub_ps(_mm256_mul_ps(a.z, b.x), _mm256_mul_ps(a.x, b.z)),
              _mm256_sub_ps(_mm256_mul_ps(a.x, b.y), _mm256_mul_ps(a.y, b.x))};
}
AVX2 v8 blend8(v8 a, v8 b, __m256 m) {
  return (v8){_mm256_blendv_ps(a.x, b.x, m), _mm256_blendv_ps(a.y, b.y, m), _mm256_blendv_ps(a.z, b.z, m)};
}
AVX2 v8 scale8(v8 a, __m256 s) { return (v8){_mm256_mul_ps(a.x, s), _mm256_mul_ps(a.y, s), _mm256_mul_ps(a.z, s)}; }
/* lex_less and lex_positive, lane by lane, with the scalar comparisons' NaN behaviour */
AVX2 __m256 lex_less8(v8 a, v8 b) {
  __m256 nx = _mm256_cmp_ps(a.x, b.x, _CMP_NEQ_UQ), ny = _mm256_cmp_ps(a.y, b.y, _CMP_NEQ_UQ);
  __m256 tail = _mm256_blendv_ps(_mm256_cmp_ps(a.z, b.z, _CMP_LT_OQ), _mm256_cmp_ps(a.y, b.y, _CMP_LT_OQ), ny);
  return _mm256_blendv_ps(tail, _mm256_cmp_ps(a.x, b.x, _CMP_LT_OQ), nx);
}
AVX2 __m256 lex_positive8(__m256 g1, __m256 g2, __m256 g3) {
  const __m256 z = _mm256_setzero_ps();
  __m256 t2 = _mm256_or_ps(_mm256_cmp_ps(g2, z, _CMP_GT_OQ),
                           _mm256_and_ps(_mm256_cmp_ps(g2, z, _CMP_EQ_OQ), _mm256_cmp_ps(g3, z, _CMP_GT_OQ)));
  return _mm256_or_ps(_mm256_cmp_ps(g1, z, _CMP_GT_OQ), _mm256_and_ps(_mm256_cmp_ps(g1, z, _CMP_EQ_OQ), t2));
}

/* rr_tri_setup for count <= 8 finite triangles and a perspective camera: the same
 * operations in the same order, so the same bits. */
__attribute__((target("avx2"))) static void setup8_avx2(const rr_scene *s, const uint32_t *ids, int count,
                                                         const camera *c, bool cull, tri_setup *out, int *face) {
  uint32_t lane_id[8];
  for (int l = 0; l < 8; l++) lane_id[l] = ids[l < count ? l : count - 1];
  __m256i idx = _mm256_loadu_si256((const __m256i *)lane_id);
  v8 eye = splat8(c->eye), q[3];
  for (int k = 0; k < 3; k++) {
    v8 p = {_mm256_i32gather_ps(s->p[k][0], idx, 4), _mm256_i32gather_ps(s->p[k][1], idx, 4),
            _mm256_i32gather_ps(s->p[k][2], idx, 4)};
    q[k] = sub8(p, eye);
  }
  v8 n[3];
  for (int e = 0; e < 3; e++) {
    v8 a = q[(e + 1) % 3], b = q[(e + 2) % 3];
    __m256 swap = lex_less8(b, a);
    v8 l = blend8(a, b, swap), h = blend8(b, a, swap);
    v8 m = cross8(h, sub8(l, h));
    const __m256 sgn = _mm256_set1_ps(-0.0f); /* v3_neg flips the sign bit, zeros too */
    v8 neg = {_mm256_xor_ps(m.x, sgn), _mm256_xor_ps(m.y, sgn), _mm256_xor_ps(m.z, sgn)};
    n[e] = blend8(m, neg, swap);
  }
  __m256 vol = d8(q[0], n[0]);
  const __m256 zero = _mm256_setzero_ps(), inf = _mm256_set1_ps(INFINITY);
  __m256 absvol = _mm256_and_ps(vol, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)));
  __m256 seen = _mm256_and_ps(_mm256_cmp_ps(vol, zero, _CMP_NEQ_UQ), _mm256_cmp_ps(absvol, inf, _CMP_LT_OQ));
  __m256 front = _mm256_cmp_ps(vol, zero, _CMP_GT_OQ);
  __m256 sign = _mm256_blendv_ps(_mm256_set1_ps(-1.0f), _mm256_set1_ps(1.0f), front);
  float a[3][8], b[3][8], cc[3][8], vs[8], vx[8];
  int tie[8] = {0};
  v8 d0 = splat8(c->d0), dx = splat8(c->dx), dy = splat8(c->dy), fwd = splat8(c->fwd);
  for (int e = 0; e < 3; e++) {
    v8 ne = scale8(n[e], sign);
    __m256 ae = d8(ne, d0), be = d8(ne, dx), ce = d8(ne, dy);
    _mm256_storeu_ps(a[e], ae), _mm256_storeu_ps(b[e], be), _mm256_storeu_ps(cc[e], ce);
    int bits = _mm256_movemask_ps(lex_positive8(be, ce, d8(ne, fwd)));
    for (int l = 0; l < 8; l++) tie[l] |= (bits >> l & 1) << e;
  }
  _mm256_storeu_ps(vs, _mm256_mul_ps(vol, sign));
  _mm256_storeu_ps(vx, _mm256_mul_ps(zero, sign));
  int seen_m = _mm256_movemask_ps(seen), front_m = _mm256_movemask_ps(front);
  for (int l = 0; l < count; l++) {
    int f = !(seen_m >> l & 1) ? SETUP_CULLED : front_m >> l & 1 ? SETUP_FRONT : cull ? SETUP_CULLED : SETUP_BACK;
    face[l] = f;
    if (f == SETUP_CULLED) continue;
    tri_setup *o = &out[l];
    for (int e = 0; e < 3; e++) o->a[e] = a[e][l], o->b[e] = b[e][l], o->c[e] = cc[e][l];
    o->vol = vs[l], o->vol_x = vx[l], o->vol_y = vx[l];
    o->tie = (uint32_t)tie[l];
    o->w[0] = o->w[1] = o->w[2] = 1.0f;
  }
}
#endif

void rr_tri_setup_run(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces, bool simd,
                   tri_setup *out, int *face) {
  int k = 0;
#if defined(__x86_64__) || defined(__i386__)
  if (simd && c->type == RR_CAMERA_PERSPECTIVE && !s->inf && __builtin_cpu_supports("avx2"))
    for (; k < n; k += 8) setup8_avx2(s, ids + k, n - k < 8 ? n - k : 8, c, cull_backfaces, out + k, face + k);
#else
  (void)simd;
#endif
  for (; k < n; k++) face[k] = rr_tri_setup(s, ids[k], c, cull_backfaces, &out[k]);
}

bool rr_tri_ray_hit(const rr_scene *s, uint32_t i, const camera *ray, bool cull, float tmin, float tmax, float *t,
                 float *l1, float *l2) {
  tri_setup ts;
  if (rr_tri_setup(s, i, ray, cull, &ts) == SETUP_CULLED) return false;
  float e[3];
  tri_edges(&ts, 0.0f, 0.0f, e); /* = a[i]: the edge functions along the ray itself */
  if (!sample_test_w(e, ts.w, ts.tie, ts.vol, t, l1, l2)) return false;
  return *t >= tmin && *t <= tmax;
}
