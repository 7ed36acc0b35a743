/* Texture coordinates and their derivatives: (u, v) is an affine function on the
 * triangle's plane, so its derivative along the image is its gradient in the plane
 * times the hit point's derivative, which the ray differentials give. */
#include "shade/texcoord.h"
#include "core/simd.h"

#include <math.h>

/* The derivatives of a coordinate pair with world gradients gu, gv (in the surface's
 * tangent plane, normal n) at the hit t along (o, d), per pixel step: the hit
 * p = o + t d stays on the tangent plane n·p = const as the sample moves, so
 * ∂p = w − d (n·w)/(n·d) with w = ∂o + t ∂d (Igehy's ray differentials). For a
 * perspective view on a triangle this is the derivative of λ_i = V_i / ΣV (paper
 * Sect. 3) along dx, dy, written with the plane so that every camera (the
 * orthographic's moving origin too) and every kind shares it; its one subtraction
 * takes the part along the ray away from w instead of cancelling products of large
 * edge values, V_i,x ΣV − V_i ΣV_x. */
static void footprint(tex_coord *tc, vec3 gu, vec3 gv, vec3 n, float t, vec3 d, const vec3 do_dxy[2],
                      const vec3 dd_dxy[2]) {
  float nd = v3_dot(n, d);
  if (!(nd != 0)) return; /* a ray in the plane sees no hit */
  vec3 dp[2];
  for (int k = 0; k < 2; k++) {
    vec3 w = v3_add(do_dxy[k], v3_scale(dd_dxy[k], t));
    dp[k] = v3_sub(w, v3_scale(d, v3_dot(n, w) / nd));
  }
  rr_vf4 g = {v3_dot(gu, dp[0]), v3_dot(gv, dp[0]), v3_dot(gu, dp[1]), v3_dot(gv, dp[1])};
  /* at a grazing angle the footprint may overflow: a million texture spans per
   * pixel cover any texture, and keep the filter's squares finite (NaN: 0) */
  g = (rr_vf4)((rr_vi4)g & (g == g));
  g = rr_vf4_min(rr_vf4_max(g, rr_vf4_splat(-1e6f)), rr_vf4_splat(1e6f));
  tc->dudx = g[0], tc->dvdx = g[1], tc->dudy = g[2], tc->dvdy = g[3];
}

/* An analytic primitive's texture coordinates from its hit coordinates (u, v) of
 * rr_ana_hit, with their world gradients on the surface:
 * - sphere: the equirectangular map, u the longitude over 2π (atan2(x, z) + π),
 *   v = 1 − colatitude / π (the +y pole at the top of the image); with m the unit
 *   normal, ρ² = m_x² + m_z² and r the radius, ∇u = (m_z, 0, −m_x) / (2π r ρ²) and
 *   ∇v = (e_y − m_y m) / (π r ρ) (singular at the poles: footprint's clamp takes it);
 * - plane: the hit's offsets along the plane's two axes, in world units (a texture
 *   repeats once per unit), ∇ = the axes;
 * - box: each face shows the whole texture, u along axis (a + 1) mod 3 and v along
 *   (a + 2) mod 3 of its frame over [0, 1]², ∇ = that axis / the face's size. */
static tex_coord ana_texcoord(const rr_scene *s, uint32_t i, float u, float v, float t, vec3 d,
                              const vec3 do_dxy[2], const vec3 dd_dxy[2]) {
  const float *a = rr_ana_params(s, i);
  vec3 n = rr_ana_normal(s, i, u, v), gu, gv;
  tex_coord tc = {0};
  prim_kind kind = scene_kind(s, i);
  if (kind == RR_GEOMETRY_SPHERE) {
    float r2 = n.x * n.x + n.z * n.z, rho = sqrtf(r2), r = a[3];
    tc.u = u, tc.v = 1.0f - v;
    gu = v3_scale(v3(n.z, 0, -n.x), 1.0f / (2.0f * (float)RR_PI * r * r2));
    gv = v3_scale(v3_sub(v3(0, 1, 0), v3_scale(n, n.y)), 1.0f / ((float)RR_PI * r * rho));
  } else if (kind == RR_GEOMETRY_PLANE) {
    double ua[3], va[3];
    rr_ana_plane_axes(a + 3, ua, va);
    tc.u = u, tc.v = v;
    gu = v3((float)ua[0], (float)ua[1], (float)ua[2]), gv = v3((float)va[0], (float)va[1], (float)va[2]);
  } else {
    double R[3][3];
    rr_ana_box_frame(a, R);
    int f = (int)u, ax = f / 2, b1 = (ax + 1) % 3, b2 = (ax + 2) % 3;
    tc.u = (float)(((double)u - f) / (1 - 0x1p-16)), tc.v = v;
    gu = v3_scale(v3((float)R[b1][0], (float)R[b1][1], (float)R[b1][2]), 0.5f / a[3 + b1]);
    gv = v3_scale(v3((float)R[b2][0], (float)R[b2][1], (float)R[b2][2]), 0.5f / a[3 + b2]);
  }
  if (do_dxy) footprint(&tc, gu, gv, n, t, d, do_dxy, dd_dxy);
  return tc;
}

/* Corner k's UVs. */
static void corner_uv(const rr_scene *s, int k, uint32_t i, float uv[2]) {
  uint32_t j = scene_st(s, i);
  uv[0] = s->uv[k][0][j], uv[1] = s->uv[k][1][j];
}

tex_coord rr_texcoord(const rr_scene *s, uint32_t i, float l1, float l2, float t, vec3 o, vec3 d,
                      const vec3 do_dxy[2], const vec3 dd_dxy[2]) {
  if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) return ana_texcoord(s, i, l1, l2, t, d, do_dxy, dd_dxy);
  tex_coord tc = {0};
  /* Two edges from a finite base corner f: to a finite corner, the differences of
   * positions and of UVs; to a corner at infinity, its direction and its UV rate.
   * Their dual basis in the plane (g_a·e_a = 1, g_a·e_b = 0 and so on) gives the
   * gradients of u and v: G = Δuv_a g_a + Δuv_b g_b. */
  unsigned inf = scene_inf(s, i);
  int f = !(inf & 1u) ? 0 : !(inf & 2u) ? 1 : 2, a = (f + 1) % 3, b = (f + 2) % 3;
  vec3 pf = scene_vertex(s, f, i), ea = scene_vertex(s, a, i), eb = scene_vertex(s, b, i);
  float uvf[2], dua[2], dub[2];
  corner_uv(s, f, i, uvf), corner_uv(s, a, i, dua), corner_uv(s, b, i, dub);
  if (!(inf >> a & 1u)) ea = v3_sub(ea, pf), dua[0] -= uvf[0], dua[1] -= uvf[1];
  if (!(inf >> b & 1u)) eb = v3_sub(eb, pf), dub[0] -= uvf[0], dub[1] -= uvf[1];
  vec3 n = v3_cross(ea, eb);
  float nn = v3_dot(n, n);
  if (!(nn > 0)) return tc; /* kept triangles are not degenerate; a guard all the same */
  vec3 ga = v3_scale(v3_cross(eb, n), 1.0f / nn), gb = v3_scale(v3_cross(n, ea), 1.0f / nn);
  vec3 gu = v3_add(v3_scale(ga, dua[0]), v3_scale(gb, dub[0]));
  vec3 gv = v3_add(v3_scale(ga, dua[1]), v3_scale(gb, dub[1]));
  if (!inf) { /* the perspective-correct barycentrics of the visibility buffer */
    float l0 = 1.0f - l1 - l2;
    uint32_t j = scene_st(s, i);
    tc.u = l0 * s->uv[0][0][j] + l1 * s->uv[1][0][j] + l2 * s->uv[2][0][j];
    tc.v = l0 * s->uv[0][1][j] + l1 * s->uv[1][1][j] + l2 * s->uv[2][1][j];
  } else { /* from the hit point: no corner to weigh by 1 - l1 - l2 */
    vec3 q = v3_sub(v3_add(o, v3_scale(d, t)), pf);
    tc.u = uvf[0] + v3_dot(gu, q), tc.v = uvf[1] + v3_dot(gv, q);
  }
  if (do_dxy) footprint(&tc, gu, gv, n, t, d, do_dxy, dd_dxy);
  return tc;
}
