/* The triangle kind: setup for an eye, the one sample test, bounds for a camera. */
#ifndef RR_TRIANGLE_H
#define RR_TRIANGLE_H

#include "camera/camera.h"
#include "core/simd.h"

#include <stdatomic.h>

/* A triangle set up for a camera (paper eqs. 1–3 and appendix). Its edge functions
 * at a sample are V_i = a[i]·w.x + b[i]·w.y + c[i]·w.z for the camera's w
 * (camera_w): for planar cameras that is a + sx·b + sy·c (eq. 3), for curved ones
 * (a, b, c) is the edge normal n_i and V_i = n_i·d. The volume at the sample is
 * vol + sx·vol_x + sy·vol_y (constant but for orthographic views, whose ray origin
 * moves). Everything is sign-normalised so that the inside is positive whichever
 * face is seen. */
typedef struct tri_setup {
  float a[3], b[3], c[3];
  float vol, vol_x, vol_y;
  uint32_t tie; /* bit i: a sample exactly on edge i belongs to this triangle */
  float w[3];   /* homogeneous w of vertex i (1, or 0 at infinity): the sum is Σ w_i V_i */
  /* The depth from the plane: t = num / den with den = pa·w.x + pb·(w.y − cx) +
   * pc·(w.z − cy) (= N·d, the plane normal N = Σ w_i n_i, sign-normalised like the
   * edges) and num = num0 + (sx − cx)·num_x + (sy − cy)·num_y (= N·(p_f − o), p_f
   * a finite corner, o the ray origin), see prim/triangle_setup.c. (cx, cy) is a
   * sample near the triangle (planar cameras; 0 for curved ones), so that the terms
   * the sample adds are small and den and num keep their accuracy at any angle. */
  float pa, pb, pc;
  float num0, num_x, num_y;
  float cx, cy;
} tri_setup;

enum { SETUP_CULLED = 0, SETUP_FRONT = 1, SETUP_BACK = 2 };

/* Sets up triangle `i` of `s` for camera `c`. Returns SETUP_FRONT, SETUP_BACK, or
 * SETUP_CULLED when the triangle cannot be seen (edge-on, or a back face and
 * cull_backfaces is set). */
int rr_tri_setup(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces, tri_setup *out);
/* rr_tri_setup for triangles ids[0..n-1] into out[k], face[k]; with simd, eight
 * at a time where the processor has AVX2, with the same bits. */
void rr_tri_setup_run(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces, bool simd,
                   tri_setup *out, int *face);

/* What a setup for one sample position needs to become the setup for another
 * (planar cameras): only the sample (cx, cy) near the triangle moves with the
 * position, and with it the one coefficient of the depth that depends on it, pa
 * (perspective) or num0 (orthographic) = base + cx·u + cy·v rounded once from
 * double. The edges, the volume and the tie bits do not depend on the position. */
typedef struct tri_plane {
  float px, py;       /* where the finite corner projects, before the clamp to the image */
  double base, u, v;
} tri_plane;
/* rr_tri_setup_run that also writes each kept triangle's tri_plane to pl[k]. */
void rr_tri_setup_planes(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces,
                         bool simd, tri_setup *out, int *face, tri_plane *pl);
/* rr_tri_setup_planes for cameras cams[0..ncams-1] that share one eye (a cube's
 * faces), each for some of the triangles ids[0..n-1] (n <= TRI_SHARED_MAX): what
 * depends on the eye alone is computed once per triangle, the rest per camera for
 * the triangles it asks for, W to a step, with the bits each camera alone gives.
 * Camera k asks for ids[sel[a_k + j]], j < nsel[k] (a_k = nsel[0] + .. + nsel[k-1]);
 * its setup of it goes to entry a_k + j of out, face and pl (when not NULL), the
 * entries of out ostride bytes apart, of pl pstride (a caller's records). */
#define TRI_SHARED_MAX 256
void rr_tri_setup_shared(const rr_scene *s, const uint32_t *ids, int n, const camera *cams, int ncams,
                         const int32_t *sel, const int *nsel, bool cull_backfaces, bool simd, tri_setup *out,
                         size_t ostride, int *face, tri_plane *pl, size_t pstride);
/* Eye parts kept for a frame (rr_tri_setup_kept): each triangle's, what its setup
 * depends on the eye alone, made by the first setup that needs it and read by
 * every later one, on any thread, so that cameras sharing the eye (a cube's faces
 * drawn frustum by frustum) set each triangle up once. The records are packed in
 * the order they are made: a frame touches only those it needs. The caller zeroes
 * slot and used for a frame. */
enum { TRI_EYE_REC = 24, TRI_EYE_NONE = 0, TRI_EYE_BUSY = 1, TRI_EYE_AT = 2 };
typedef struct tri_eyes {
  float (*rec)[TRI_EYE_REC]; /* room for every triangle */
  _Atomic uint32_t *slot;    /* by triangle id: TRI_EYE_NONE, _BUSY (being recorded) or _AT + its record */
  atomic_uint used;          /* records made */
} tri_eyes;
/* rr_tri_setup_planes of triangles ids[0..n-1] (n <= TRI_SHARED_MAX, fewer than
 * INT32_MAX / TRI_EYE_REC in the scene) for a perspective or curved camera c at
 * keep's eye: a triangle whose eye part keep holds costs only the rest. Entry k
 * of out, face and pl (when not NULL) is the setup of ids[order[k]]: first those
 * whose eye part this call made, then the others. Returns how many it made (the
 * setups S counts). */
int rr_tri_setup_kept(const rr_scene *s, tri_eyes *keep, const uint32_t *ids, int n, const camera *c,
                      bool cull_backfaces, bool simd, tri_setup *out, int *face, tri_plane *pl, int *order);
/* The setup ts (from rr_tri_setup_planes with a camera that differs from c only in
 * its sample position) for camera c: the bits rr_tri_setup gives for c. */
void rr_tri_setup_at(const tri_setup *ts, const tri_plane *pl, const camera *c, tri_setup *out);
/* tri_moved at n positions of a planar camera c, whose sample offsets are ox[k],
 * oy[k]: ts's pa, num0, cx, cy there into pa[k], num0[k], cx[k], cy[k], with the
 * same bits; with simd, eight at a time where the processor has AVX2. */
void rr_tri_moved_all(const tri_setup *ts, const tri_plane *pl, const camera *c, int n, const float *ox,
                      const float *oy, bool simd, float *pa, float *num0, float *cx, float *cy);
/* What rr_tri_setup_at changes, without the copy: ts's pa, num0, cx, cy for c
 * into m[0..3] (the setup template's clamp, as minps and maxps, and floor). */
static inline void tri_moved(const tri_setup *ts, const tri_plane *pl, const camera *c, float m[4]) {
  m[0] = ts->pa, m[1] = ts->num0, m[2] = ts->cx, m[3] = ts->cy;
  if (!c->planar) return; /* (cx, cy) = (0, 0) at every position */
  const float lo_x = c->sx0, hi_x = (float)(c->width - 1) + c->sx0;
  const float lo_y = c->sy0, hi_y = (float)(c->height - 1) + c->sy0;
  float cx = pl->px < hi_x ? pl->px : hi_x, cy = pl->py < hi_y ? pl->py : hi_y;
  cx = cx > lo_x ? cx : lo_x, cy = cy > lo_y ? cy : lo_y;
  cx = floorf(cx - lo_x) + lo_x, cy = floorf(cy - lo_y) + lo_y;
  const double dcx = cx, dcy = cy;
  const float p = (float)(pl->base + dcx * pl->u + dcy * pl->v);
  m[2] = cx, m[3] = cy;
  m[c->type == RR_CAMERA_PERSPECTIVE ? 0 : 1] = p;
}
/* The three edge functions of a set-up triangle for evaluation vector w. The
 * order of operations is fixed (the build uses -ffp-contract=off: a fused
 * multiply-add would change the bits) so every method computes the same values
 * for the same (triangle, sample). */
static inline void tri_edges_w(const tri_setup *t, vec3 w, float e[3]) {
  for (int i = 0; i < 3; i++) e[i] = t->a[i] * w.x + t->b[i] * w.y + t->c[i] * w.z;
}
/* The same for a planar camera's sample (sx, sy): w = (1, sx, sy), same bits. */
static inline void tri_edges(const tri_setup *t, float sx, float sy, float e[3]) {
  tri_edges_w(t, v3(1.0f, sx, sy), e);
}
/* The volume term at sample (sx, sy). */
static inline float tri_vol(const tri_setup *t, float sx, float sy) {
  return t->vol + sx * t->vol_x + sy * t->vol_y;
}
/* The depth's denominator N·d for evaluation vector w, and its numerator N·(p_f − o)
 * at sample (sx, sy): the same order of operations as the edges and the volume. */
static inline float tri_den_w(const tri_setup *t, vec3 w) {
  return t->pa * w.x + t->pb * (w.y - t->cx) + t->pc * (w.z - t->cy);
}
static inline float tri_num(const tri_setup *t, float sx, float sy) {
  return t->num0 + (sx - t->cx) * t->num_x + (sy - t->cy) * t->num_y;
}

/* The one sample test's two conditions, written once for a sample (floats, tie 0/1)
 * and for W samples (core/simd.h vectors, tie and results as lane masks), so every
 * method and every width evaluates the same expressions in the same order:
 * edge value e is inside when positive, or zero on an edge the tie rule gives it;
 * the hit counts when the sum Σw_iV_i and the volume are both positive. */
#define TRI_EDGE_INSIDE(e, tie, zero) (((e) > (zero)) | (((e) == (zero)) & (tie)))
#define TRI_HIT_AHEAD(sum, vol, zero) (((sum) > (zero)) & ((vol) > (zero)))
/* The hit's t: from the plane, num / den, unless rounding left either not positive
 * (a ray within a few ulps of the plane's direction), where V / Σ w_i V_i (= vol·inv)
 * stays positive as the sign test requires. The plane form's relative error is a few
 * ulps over the cosine between ray and plane: num is one rounding of a double, den
 * an affine form of three rounded coefficients. V / Σ w_i V_i cancels instead: its
 * edge values are of the size of distance × edge length, their sum of edge length². */
#define TRI_DEPTH(num, den, vol, inv, zero, select) \
  select(((num) > (zero)) & ((den) > (zero)), (num) / (den), (vol) * (inv))

/* The one sample test (paper eq. 2 with the top-left rule of sect. 4.2).
 * e: sign-normalised edge values at the sample; tie: bit i set when the sample
 * belongs to this triangle if it lies exactly on edge i; vol: the sign-normalised
 * volume at the sample (positive when the hit lies ahead of the ray origin).
 * w: the vertices' homogeneous w (appendix eqs. 5–11: a vertex at infinity has
 * w = 0 and leaves the sum). num, den: the plane's numerator and denominator at
 * the sample (tri_num, tri_den_w). On a hit returns true with t = num / den
 * (TRI_DEPTH) and λ_i = V_i / Σw_iV_i. */
static inline float tri_select_f(bool m, float a, float b) { return m ? a : b; }
static inline bool sample_test_w(const float e[3], const float w[3], uint32_t tie, float vol, float num, float den,
                                 float *t, float *l1, float *l2) {
  if (!(TRI_EDGE_INSIDE(e[0], (tie & 1u) != 0, 0.0f) && TRI_EDGE_INSIDE(e[1], (tie & 2u) != 0, 0.0f) &&
        TRI_EDGE_INSIDE(e[2], (tie & 4u) != 0, 0.0f)))
    return false;
  /* Appendix eq. 10: only finite vertices count, Σ w_i V_i; e·1 == e exactly, so
   * ordinary triangles keep the bits of e0 + e1 + e2. */
  float sum = e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
  /* sum == 0: all three on their edges (a degenerate sliver) or a pixel with no ray */
  if (!TRI_HIT_AHEAD(sum, vol, 0.0f)) return false;
  float inv = 1.0f / sum;
  *t = TRI_DEPTH(num, den, vol, inv, 0.0f, tri_select_f);
  *l1 = e[1] * inv;
  *l2 = e[2] * inv;
  return true;
}

/* The one sample test of set-up triangle ts at a planar camera's sample (sx, sy),
 * whose edge values e come from tri_edges. */
static inline bool sample_test(const tri_setup *ts, const float e[3], float sx, float sy, float *t, float *l1,
                               float *l2) {
  return sample_test_w(e, ts->w, ts->tie, tri_vol(ts, sx, sy), tri_num(ts, sx, sy), tri_den_w(ts, v3(1.0f, sx, sy)),
                       t, l1, l2);
}

/* The one sample test for an arbitrary ray set up by rr_cam_for_ray(): true on a hit
 * with t in [tmin, tmax] (t along the unnormalised direction). */
bool rr_tri_ray_hit(const rr_scene *s, uint32_t i, const camera *ray, bool cull_backfaces, float tmin, float tmax,
                 float *t, float *l1, float *l2);
/* The same for a triangle without corners at infinity and no culling, with the same
 * bits and a fraction of the work: only what the ray's one sample reads. */
bool rr_tri_ray_hit1(const rr_scene *s, uint32_t i, const camera *ray, float tmin, float tmax, float *t, float *l1,
                     float *l2);
/* The rest of rr_tri_ray_hit1 (the plane, the sample test, the range) for edge
 * values e that are inside, their tie bits, and the volume q0·n0 before the sign
 * turns it positive (not 0, finite). */
bool rr_tri_ray_finish(const rr_scene *s, uint32_t i, const camera *ray, const float e[3], uint32_t tie, float vol,
                       float tmin, float tmax, float *t, float *l1, float *l2);

/* lex_less and lex_positive of triangle_setup_tmp.h for one lane, same NaN behaviour. */
static inline bool tri_lex_less(vec3 a, vec3 b) {
  return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
}
/* An edge normal as the setup computes it: h × (l − h) for the canonical order
 * (l, h) of the edge's endpoints a → b, negated when the edge runs from h to l. */
static inline vec3 tri_edge_normal(vec3 a, vec3 b) {
  bool swap = tri_lex_less(b, a);
  vec3 l = swap ? b : a, h = swap ? a : b, m = v3_cross(h, v3_sub(l, h));
  return swap ? v3_neg(m) : m;
}

/* Which of four triangles may hit a ray: the rest fail rr_tri_ray_hit, whose
 * work this skips. The setup of a finite triangle for a perspective camera
 * (triangle_setup.c) gives edge value a_i = (σ n_i)·d0 (σ = ±1 turns the inside
 * positive, σ n exactly ±n), and the sample (0, 0) evaluates a_i·1 + b_i·0 +
 * c_i·0, which is negative or NaN whenever σ (n_i·d0) is, and rejects an edge-on
 * triangle (volume 0 or not finite). Computed here in the setup's own operations
 * (q_k = p_k − eye, tri_edge_normal, the dot products), lane by lane, so a lane
 * is rejected only where the full test would reject it. What passes (a few
 * triangles a ray) goes through rr_tri_ray_hit, the full setup and sample test.
 * Not for triangles with corners at infinity (their corners are directions).
 * Corner k's axis x of lane j is v[(3k + x)·stride + j]; eye and d are the ray's
 * origin and direction broadcast. Bit j of the result: lane j may hit. Into
 * out[0..2] the edge values a_i at (0, 0) and into out[3] the volume q0·n0: where
 * they are not 0, the setup's values exactly (negation is exact, rounding
 * symmetric), and where every a_i is positive and finite and so are the setup's
 * b_i, c_i, the edge values of the sample test. */
typedef struct {
  rr_vf4 x, y, z;
} tri_v4;
static inline tri_v4 tri_v4_sub(tri_v4 a, tri_v4 b) { return (tri_v4){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline rr_vf4 tri_v4_dot(tri_v4 a, tri_v4 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
/* tri_edge_normal lane by lane, in fewer operations: h × (a − b), h the edge's
 * higher endpoint in the canonical order. Where a comes first, h = b and this is
 * tri_edge_normal's h × (l − h) itself; where b does, h = a and tri_edge_normal
 * returns −(h × (b − a)), which is h × (a − b) exactly: a − b = −(b − a), and
 * negation is exact and rounding symmetric, so each product and difference of
 * the cross product only changes sign — up to the sign of a zero, which no test
 * below tells apart. */
KERNEL tri_v4 tri_v4_edge_normal(tri_v4 a, tri_v4 b) {
  /* b before a, lexicographically; as ands and ors of comparisons (not selects
   * of them) the compiler knows it for a mask, and blends h in one instruction
   * where it can (AVX) */
  rr_vi4 swap = (b.x < a.x) | ((b.x == a.x) & ((b.y < a.y) | ((b.y == a.y) & (b.z < a.z))));
  tri_v4 h = {rr_vf4_select(swap, a.x, b.x), rr_vf4_select(swap, a.y, b.y), rr_vf4_select(swap, a.z, b.z)};
  tri_v4 e = tri_v4_sub(a, b);
  return (tri_v4){h.y * e.z - h.z * e.y, h.z * e.x - h.x * e.z, h.x * e.y - h.y * e.x};
}
/* σ (the sign that turns the inside positive) is applied to the dot products as
 * a sign bit, exactly as a negation (again up to the sign of a zero). The part
 * that depends on the eye alone (the edge normals, σ, the volume) is set up once
 * for rays sharing an origin (tri4_edges_setup: a leaf's triangles seen from a
 * light); tri4_edges_test is the part each direction pays. */
typedef struct {
  tri_v4 m[3];    /* the edge normals */
  rr_vi4 sgn;     /* σ's sign bits, which turn m·d into the edge value */
  rr_vf4 vol;     /* q0·n0 */
  rr_vi4 ok;      /* the volume is not 0 and finite: the triangle is not edge-on */
} tri4_edges;
/* The part from the eye: corner k's axis x of lane j at v[(3k + x)·stride + j],
 * moved by sh (x, y, z in sh[0..2]; NULL: not moved), each corner then rounded
 * as p + sh first, as a moved copy of the corners would hold it. */
KERNEL void tri4_edges_setup(const float *v, size_t stride, const rr_vf4 *sh, const rr_vf4 eye[3],
                             tri4_edges *te) {
  tri_v4 q[3];
#pragma GCC unroll 3
  for (int k = 0; k < 3; k++) {
    rr_vf4 p[3] = {rr_vf4_load(v + (3 * k) * stride), rr_vf4_load(v + (3 * k + 1) * stride),
                   rr_vf4_load(v + (3 * k + 2) * stride)};
    if (sh) p[0] = p[0] + sh[0], p[1] = p[1] + sh[1], p[2] = p[2] + sh[2];
    q[k] = (tri_v4){p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]};
  }
  te->m[0] = tri_v4_edge_normal(q[1], q[2]), te->m[1] = tri_v4_edge_normal(q[2], q[0]),
  te->m[2] = tri_v4_edge_normal(q[0], q[1]);
  rr_vf4 vol = tri_v4_dot(q[0], te->m[0]);
  rr_vi4 sigma = (rr_vi4)vol & (rr_vi4)rr_vf4_splat(-0.0f); /* σ = −1 where the volume is negative */
  te->sgn = sigma;
  te->vol = vol;
  te->ok = (vol != 0) & (rr_vf4_abs(vol) < INFINITY);
}
/* The part each direction d pays: the result and out as tri_ray_may_hit4's. */
KERNEL int tri4_edges_test(const tri4_edges *te, const rr_vf4 d[3], rr_vf4 out[4]) {
  tri_v4 dv = {d[0], d[1], d[2]};
  rr_vf4 a0 = (rr_vf4)((rr_vi4)tri_v4_dot(te->m[0], dv) ^ te->sgn),
         a1 = (rr_vf4)((rr_vi4)tri_v4_dot(te->m[1], dv) ^ te->sgn),
         a2 = (rr_vf4)((rr_vi4)tri_v4_dot(te->m[2], dv) ^ te->sgn);
  out[0] = a0, out[1] = a1, out[2] = a2, out[3] = te->vol;
  return rr_vi4_bits(te->ok & (a0 >= 0) & (a1 >= 0) & (a2 >= 0));
}
/* The pre-test above for the ray (eye, d), the corners moved by sh as in
 * tri4_edges_setup (NULL: not moved). */
KERNEL int tri_ray_may_hit4(const float *v, size_t stride, const rr_vf4 *sh, const rr_vf4 eye[3], const rr_vf4 d[3],
                            rr_vf4 out[4]) {
  tri4_edges te;
  tri4_edges_setup(v, stride, sh, eye, &te);
  return tri4_edges_test(&te, d, out);
}

/* The inclusive pixel rectangle a set-up triangle's samples may lie in; false when
 * none. For curved cameras it is rr_tri_curved_rect's where it knows one, else the
 * bounding box of the cells whose cone of directions no edge plane excludes. */
bool rr_tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int rect[4]);
/* The same with the setup's rr_tri_spheres for curved cameras (sp may be NULL). */
typedef struct tri_sphere tri_sphere;
bool rr_tri_screen_bounds_sph(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts,
                              const tri_sphere *sp, int rect[4]);
/* The tight rectangle of the curved views polar about an axis (lat-long, parabolic,
 * fisheye), from the spherical triangle of the setup's edge planes
 * (prim/triangle_curved.c), and of the OpenCV lenses, from the cap that holds it
 * (wholly ahead: camera/lens.c, rr_lens_cap_extent): 1 with rect, 2 with a rect
 * whose margin is wide (a sliver: the cells may bound it better), 0 when no sample
 * can pass, -1 when it knows no bound (another camera, a degenerate setup). */
int rr_tri_curved_rect(const camera *c, const tri_setup *ts, int rect[4]);
/* What the curved bounds take from a setup, whatever the camera's position: its
 * spherical triangle (sin of half the least interior angle smin, the widening E;
 * ok false when degenerate or a sliver) and the cap that holds it (unit axis,
 * radius rho; cap false when it bounds nothing). rr_tri_spheres fills
 * out[0..n-1], four lanes at a time (AVX2 when simd). */
struct tri_sphere {
  double smin, E, axis[3], rho;
  bool ok, cap;
  int8_t img_k;  /* the cap's image for rr_tri_spheres_cam's camera (parabolic): TRI_CAP_UNSET, */
  double img[4]; /* or rr_cam_cap_rect's 1 with its extents x0, x1, y0, y1 (sample coordinates), 0, -1 */
  /* rr_tri_curved_rect_sph's answer for that camera at its own position
   * (rect_sx, rect_sy), where the cap's image gives it: TRI_CAP_UNSET, 0, or 1 with rect */
  int8_t rect_k;
  float rect_sx, rect_sy;
  int rect[4];
  /* with the cap, computed only where prim/triangle_curved.c needs them: the
   * triangle in the gnomonic chart about the axis m that holds every passing
   * sample (chart_extent) and the largest length of its vertices (infinite when
   * not computed) */
  double gx[3][3], gt;
};
#define TRI_CAP_UNSET 2
/* sp's rectangle as its lanes decided it for c's position (rect_k): 1 with rect, 0
 * when no sample can pass, -1 when not decided there (rr_tri_curved_rect_sph then). */
static inline int rr_tri_sphere_decided(const camera *c, const tri_sphere *sp, int rect[4]) {
  if (sp->rect_k == TRI_CAP_UNSET || c->sx0 != sp->rect_sx || c->sy0 != sp->rect_sy) return -1;
  memcpy(rect, sp->rect, sizeof sp->rect);
  return sp->rect_k;
}
void rr_tri_spheres(const tri_setup *ts, int n, bool simd, tri_sphere *out);
/* The same with the cap's image for camera c (NULL: none; so far the parabolic's,
 * computed in the lanes), whatever the sample position: rr_tri_sphere_cap_rect then serves every camera that differs from c
 * only in sx0, sy0 (the positions of one frame). */
void rr_tri_spheres_cam(const tri_setup *ts, int n, const camera *c, bool simd, tri_sphere *out);
/* rr_cam_cap_rect of sp's cap for c (from sp's image when it has one): -1 when
 * sp has no cap. */
int rr_tri_sphere_cap_rect(const camera *c, const tri_sphere *sp, int rect[4]);
/* rr_tri_curved_rect from the setup ts and its rr_tri_spheres. */
int rr_tri_curved_rect_sph(const camera *c, const tri_setup *ts, const tri_sphere *sp, int rect[4]);
/* The cheaper cap bound rr_tri_curved_rect starts from (prim/triangle_curved.c):
 * the image of a cap holding the spherical triangle, widened by the map's largest
 * stretch over it; scale multiplies the cap's radius (1; the tests halve it to see
 * samples missed). 1 with rect, 0 when no sample can pass, -1 when it knows no bound. */
int rr_tri_curved_cap(const camera *c, const tri_setup *ts, double scale, int rect[4]);
/* The chart bound rr_tri_curved_rect cuts the cap's with (lat-long and fisheye,
 * prim/triangle_curved.c): the image of the spherical triangle's linearisation in
 * the gnomonic chart about the cap's axis, widened by the map's second-order
 * remainder times rem_scale (1; the tests see that 0 misses samples) and the
 * setup's widening. 1 with rect, 0 when no sample can pass, -1 when it knows no bound. */
int rr_tri_curved_chart(const camera *c, const tri_setup *ts, double rem_scale, int rect[4]);
/* The image rectangle of the directions within angle rho of the unit axis for the
 * curved cameras polar about an axis (lat-long, parabolic, fisheye): 1 with rect,
 * 0 when no sample looks there, -1 when it knows no bound (another camera, rho of
 * 1.5 rad or more, a cap over a pole of the map). */
int rr_cam_cap_rect(const camera *c, const double axis[3], double rho, int rect[4]);
/* rr_cam_cap_rect in two steps: for four caps in lanes (axis[i][l]: coordinate i
 * of lane l's), the sample-coordinate extents of their images, e[0..3][l] = x0,
 * x1, y0, y1, and k[l] 1 with them or rr_cam_cap_rect's 0, -1 (-1 for cameras not polar; AVX2 when simd; the
 * same for every camera that differs from c only in sx0, sy0); then a cap's
 * rectangle for such a camera from its e = x0, x1, y0, y1 and k. */
void rr_cam_cap_extents4(const camera *c, const double axis[3][4], const double rho[4], bool simd, double e[4][4],
                         int64_t k[4]);
int rr_cam_extent_rect(const camera *c, const double e[4], int k, int rect[4]);
/* rr_cam_cap_rect for four caps in lanes at once, and for the ns positions
 * cams[0..ns-1] (cameras that differ only in sx0, sy0): the lanes of the bit mask
 * used whose rectangle at some position meets r (x0, y0, x1, y1, ends exclusive),
 * or that know no bound (every lane for cameras neither polar nor an OpenCV lens,
 * whose caps go through the lens, rr_lens_cap_extent, a lane at a time); AVX2 when simd. */
unsigned rr_cam_caps_show4(const camera *cams, int ns, const double axis[3][4], const double rho[4], unsigned used,
                           const int r[4], bool simd);
/* Boxes a polar camera's samples see most of (rr_cam_cap_shortcut, for a walk
 * over a whole image) are taken as showing one without their image. */
typedef struct cam_cap_shortcut {
  double rho_min, cos_min, sin_min; /* rho_min infinite: none */
} cam_cap_shortcut;
cam_cap_shortcut rr_cam_cap_shortcut(const camera *c);
/* The same for four boxes (lo, hi: lanes per axis) seen from cams' eye, by their
 * bounding balls' caps (prim/triangle_curved.c argues the slack); sc may be NULL. */
unsigned rr_cam_boxes_show4(const camera *cams, int ns, const float lo[3][4], const float hi[3][4], unsigned used,
                            const cam_cap_shortcut *sc, const int r[4], bool simd);
/* Before any setup: the image rectangle of the cap about triangle i's corner
 * directions from c's eye, widened by slack radians (what the caller allows for
 * the rounding of the setup); as rr_cam_cap_rect, -1 also for corners at infinity. */
int rr_tri_corner_cap(const rr_scene *s, uint32_t i, const camera *c, double slack, int rect[4]);
/* That cap's axis and radius, in lane l of rr_cam_cap_extents4's axis and rho:
 * 1, or -1 when it bounds nothing. */
int rr_tri_corner_cap_lane(const rr_scene *s, uint32_t i, const camera *c, double slack, double axis[3][4],
                           double rho[4], int l);
/* Planar cameras bound a triangle from its corners alone, before its setup: most
 * triangles of a detailed mesh fall between samples. rr_tri_corner_bounds bounds triangles
 * ids[0..n-1] (first..first+n-1 when ids is NULL), 8 at a time with AVX2 when
 * simd, and writes those whose rectangle holds a sample to out; returns how many. */
/* Which part of a triangle's rectangle each sample position's own rectangle (the
 * one a one-position frame tests) takes, bit p for position p: none, when it holds
 * no sample; x0, y0: it starts a column right of, a row below bb's start; x1, y1:
 * it ends a column left of, a row above bb's end. Positions lie in one pixel, so
 * their rectangles differ by at most that (and were it more, the rectangle these
 * bits give still holds the position's own). */
typedef struct tri_pos_bits {
  uint16_t none, x0, y0, x1, y1;
} tri_pos_bits;
_Static_assert(RR_MAX_SAMPLES <= 16, "tri_pos_bits holds a bit per position");
typedef struct tri_bound {
  uint32_t id;
  int bb[4]; /* inclusive pixel rectangle, as rr_tri_screen_bounds */
  tri_pos_bits pos; /* several positions: each one's rectangle within bb */
} tri_bound;
/* Position p's rectangle within the inclusive rectangle bb (false: none). */
static inline bool tri_pos_rect(const tri_pos_bits *b, const int bb[4], int p, int r[4]) {
  if (b->none >> p & 1) return false;
  r[0] = bb[0] + (b->x0 >> p & 1), r[1] = bb[1] + (b->y0 >> p & 1);
  r[2] = bb[2] - (b->x1 >> p & 1), r[3] = bb[3] - (b->y1 >> p & 1);
  return true;
}
uint32_t rr_tri_corner_bounds(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                           bool simd, tri_bound *out);
/* The same for the npos sample positions pos[k] (sx0, sy0 of each; c's own is
 * not read): the union of the rectangles of the positions whose samples may
 * meet the triangle, which is kept when one does. */
uint32_t rr_tri_corner_bounds_at(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                                 int npos, const float (*pos)[2], bool simd, tri_bound *out);
/* Curved cameras: what bounds a triangle's directions from the eye. */
typedef struct tri_cone {
  float len[4];      /* lengths of the three edge normals and of their sum */
  vec3 cap_axis;     /* a cap holding the triangle's directions, */
  float cap_angle;   /* or a negative angle when none under 90° does */
} tri_cone;
void rr_tri_cone_setup(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, tri_cone *tc);
/* May a triangle be excluded from a cone of directions (unit axis, half-angle)? */
bool rr_cone_excludes(const tri_cone *tc, const tri_setup *ts, vec3 axis, float angle);

/* The least t that sample_test() can return for a set-up triangle at any sample of
 * camera c, and (planar cameras) a rectangle x0, y0, x1, y1 of sample coordinates
 * holding every sample where it can pass: the exact culling of rc-bvh, rc-packet. */
float rr_tri_bounds(const tri_setup *ts, const camera *c, float rect[4]);
/* The same least t over the samples of a given rectangle x0, y0, x1, y1 only
 * (planar cameras): for a caller that tests the triangle nowhere else. */
float rr_tri_rect_floor(const tri_setup *ts, const camera *c, const float rect[4]);

/* A triangle with corners at infinity (homogeneous input) is unbounded: along an
 * axis it reaches from its finite corners towards each direction's sign. Its box
 * stops at ±PRIM_FAR instead, so every traversal keeps working on finite boxes (no
 * inf − inf, no 0·inf from the box itself; areas overflow float but half_area
 * falls back to double). What this gives up is the part of such a triangle more
 * than 1e30 from the origin: the sample test reaches it only where Σ w_i V_i falls
 * below about 1e-30 of V (a ray grazing the plane to within 1e-30 rad), and there
 * the box-culling traversals could miss a hit that rc keeps. The one alternative,
 * a list of unbounded triangles that every traversal tests at its root, would touch
 * every traversal for that case. */
#define PRIM_FAR 1e30f
static inline void tri_inf_box(unsigned inf, float v0, float v1, float v2, float *lo, float *hi) {
  float v[3] = {v0, v1, v2}, l = INFINITY, h = -INFINITY;
  for (int k = 0; k < 3; k++) {
    if (inf >> k & 1u) {
      if (v[k] > 0) h = PRIM_FAR;
      if (v[k] < 0) l = -PRIM_FAR;
    } else {
      l = fminf(l, fmaxf(v[k], -PRIM_FAR)), h = fmaxf(h, fminf(v[k], PRIM_FAR));
    }
  }
  *lo = l, *hi = h;
}

/* The kind's bounds: triangle i's world box, lo[3] and hi[3] (the BVH's references). */
static inline void rr_tri_box(const rr_scene *s, uint32_t i, float lo[3], float hi[3]) {
  unsigned inf = scene_inf(s, i);
  float c[3][3];
  vec3 v[3];
  scene_corners(s, i, v);
  for (int k = 0; k < 3; k++) v3_store(c[k], v[k]);
  for (int x = 0; x < 3; x++) {
    float v0 = c[0][x], v1 = c[1][x], v2 = c[2][x];
    if (inf) {
      tri_inf_box(inf, v0, v1, v2, &lo[x], &hi[x]);
      continue;
    }
    lo[x] = fminf(v0, fminf(v1, v2));
    hi[x] = fmaxf(v0, fmaxf(v1, v2));
  }
}

#endif
