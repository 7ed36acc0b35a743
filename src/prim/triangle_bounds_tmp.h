/* Corner bounds for W triangles at once: a kernel template (core/simd.h) that
 * triangle_bounds.c instantiates per width through core/simd_widths.h.
 *
 * The pixel rectangles of triangles ids[0..n-1] (first..first+n-1 when ids is
 * NULL; n <= W, the padding lanes repeat the last one) for a planar camera, from
 * their projected corners, as rr_tri_screen_bounds defines them (the comments
 * there) for the npos sample positions pos (the union of their rectangles): the
 * same operations in the same order (no FMA, true divisions), lane by
 * lane, so every width gives the same rectangles. Writes the triangles whose
 * rectangle holds a sample to out, in order; returns how many. flat and npos are
 * constants where it is inlined (corner_bounds_any): a scene without instances
 * (lane_corners), and one position, whose rectangles stay in registers. */

#include "prim/triangle_corners_tmp.h"

TARGET __attribute__((always_inline)) static inline uint32_t RR_CAT(corner_bounds, W)(
    const rr_scene *s, uint32_t first, const uint32_t *ids, int n, const camera *c, int npos, const float (*pos)[2],
    tri_bound *out, bool flat) {
  int32_t lane_id[W], lane_inf[W] = {0};
  if (ids) {
    for (int l = 0; l < W; l++) lane_id[l] = (int32_t)ids[l < n ? l : n - 1];
  } else { /* first, first + 1, ...: the root pass's every call, in lanes */
    const VI l = VI_(lanes)(), last = VI_(splat)(n - 1);
    const VI v = VI_(splat)((int32_t)first) + VI_(select)(l < last, l, last);
    memcpy(lane_id, &v, sizeof lane_id);
  }
  if (s->inf)
    for (int l = 0; l < W; l++) lane_inf[l] = (int32_t)scene_inf(s, (uint32_t)lane_id[l]);
  const VI inf = VI_(load)(lane_inf);
  const bool persp = c->type == RR_CAMERA_PERSPECTIVE;
  VF corner[3][3];
  RR_CAT(lane_corners, W)(s, lane_id, !ids && n == W, corner, flat);
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f), half = VF_(splat)(0.5f);
  const VF inf_f = VF_(splat)(INFINITY), width = VF_(splat)((float)c->width), height = VF_(splat)((float)c->height);
  const VF last_x = VF_(splat)((float)(c->width - 1)), last_y = VF_(splat)((float)(c->height - 1));
  const VF eye[3] = {VF_(splat)(c->eye.x), VF_(splat)(c->eye.y), VF_(splat)(c->eye.z)};
  const VF fwd[3] = {VF_(splat)(c->fwd.x), VF_(splat)(c->fwd.y), VF_(splat)(c->fwd.z)};
  const VF right[3] = {VF_(splat)(c->right.x), VF_(splat)(c->right.y), VF_(splat)(c->right.z)};
  const VF up[3] = {VF_(splat)(c->up.x), VF_(splat)(c->up.y), VF_(splat)(c->up.z)};
  VF x0 = inf_f, y0 = inf_f, x1 = -inf_f, y1 = -inf_f, cx[3], cy[3];
  /* some corner ahead of the eye; every corner projects to a finite point */
  VI ahead_any = VI_(splat)(0), projected = VI_(splat)(-1);
#pragma GCC unroll 3
  for (int k = 0; k < 3; k++) {
    VF q[3]; /* the corner relative to the eye, or its direction when at infinity */
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
      VF p = corner[k][a];
      q[a] = p - eye[a];
      if (s->inf) q[a] = VF_(select)(-((inf >> k) & 1), p, q[a]);
    }
#define DOT3(v) (q[0] * v[0] + q[1] * v[1] + q[2] * v[2])
    const VF z = DOT3(fwd), qr = DOT3(right), qu = DOT3(up);
#undef DOT3
    VF sx, sy; /* rr_cam_project */
    if (persp) {
      VF u = qr / (z * VF_(splat)(c->tan_half_w)), v = qu / (z * VF_(splat)(c->tan_half_h));
      sx = (u + one) * half * width;
      sy = (one - v) * half * height;
    } else {
      sx = (qr / VF_(splat)(c->tan_half_w) + one) * half * width;
      sy = (one - qu / VF_(splat)(c->tan_half_h)) * half * height;
    }
    const VI ahead = z > zero;
    ahead_any |= ahead;
    projected &= ahead & (VF_(abs)(sx) < inf_f) & (VF_(abs)(sy) < inf_f);
    x0 = VF_(min)(x0, sx), x1 = VF_(max)(x1, sx), y0 = VF_(min)(y0, sy), y1 = VF_(max)(y1, sy);
    cx[k] = sx, cy[k] = sy;
  }
  /* an orthographic view sees a triangle with a corner at infinity unbounded */
  const VI bounded = c->type == RR_CAMERA_ORTHOGRAPHIC ? projected & (inf == 0) : projected;
  const VF big = VF_(max)(VF_(max)(VF_(abs)(x0), VF_(abs)(x1)), VF_(max)(VF_(abs)(y0), VF_(abs)(y1)));
  const VF m = VF_(splat)(1.0f / 64) + VF_(splat)(1e-5f) * big;
  /* A position whose rectangle is one pixel (most of a sub-pixel triangle's) holds
   * no sample of the triangle when the sample lies outside an edge of the projected
   * corners by more than 2m: each true corner lies within m of its projection (the
   * margin above), so the triangle lies within m of the projected one. The edges'
   * 2D functions e_k = ex·(Y − cy_k) − ey·(X − cx_k), outside where e_k·area < 0
   * and e_k² > (2m)²·|edge|², on coordinates below 2^20 (no overflow) and a
   * triangle whose projection turns (area not 0). */
  VF ex[3], ey[3], len2[3], area = zero; /* made when first needed */
  const VI testable = bounded & (big < VF_(splat)(0x1p20f));
  bool edges = false;
  /* the rectangle of pixels whose sample at position p may lie in the hull, each
   * position's once; with several positions, the union of those that hold one */
  VF plx[RR_MAX_SAMPLES], phx[RR_MAX_SAMPLES], ply[RR_MAX_SAMPLES], phy[RR_MAX_SAMPLES];
  npos = npos > 1 ? npos : 1; /* what callers pass; it tells the compiler plx[0] is set */
  for (int p = 0; p < npos; p++) {
    const VF ox = VF_(splat)(pos[p][0]), oy = VF_(splat)(pos[p][1]);
    plx[p] = VF_(max)(VF_(ceil)(x0 - ox - m), zero), phx[p] = VF_(min)(VF_(floor)(x1 - ox + m), last_x);
    ply[p] = VF_(max)(VF_(ceil)(y0 - oy - m), zero), phy[p] = VF_(min)(VF_(floor)(y1 - oy + m), last_y);
    const VI one_px = testable & (plx[p] == phx[p]) & (ply[p] == phy[p]);
    if (!VI_(bits)(one_px)) continue;
    if (!edges) {
#pragma GCC unroll 3
      for (int k = 0; k < 3; k++) {
        const int j = k == 2 ? 0 : k + 1;
        ex[k] = cx[j] - cx[k], ey[k] = cy[j] - cy[k];
        len2[k] = (ex[k] * ex[k] + ey[k] * ey[k]) * (VF_(splat)(4.0f) * m * m);
      }
      area = ey[0] * ex[2] - ex[0] * ey[2]; /* (c1 − c0) × (c2 − c0): the sign of the turn (0: none) */
      edges = true;
    }
    const VF X = plx[p] + ox, Y = ply[p] + oy;
    VI outside = VI_(splat)(0);
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
      const VF e = ex[k] * (Y - cy[k]) - ey[k] * (X - cx[k]);
      outside |= (e * area < zero) & (e * e > len2[k]);
    }
    plx[p] = VF_(select)(one_px & outside, phx[p] + one, plx[p]); /* no sample: an empty rectangle */
  }
  VF lx = plx[0], hx = phx[0], ly = ply[0], hy = phy[0];
  VI empty = (lx > hx) | (ly > hy);
  for (int p = 1; p < npos; p++) {
    const VI was = empty, none = (plx[p] > phx[p]) | (ply[p] > phy[p]);
    /* empty so far: this position's rectangle; else the union with it unless it is empty */
    lx = VF_(select)(was, plx[p], VF_(select)(none, lx, VF_(min)(lx, plx[p])));
    ly = VF_(select)(was, ply[p], VF_(select)(none, ly, VF_(min)(ly, ply[p])));
    hx = VF_(select)(was, phx[p], VF_(select)(none, hx, VF_(max)(hx, phx[p])));
    hy = VF_(select)(was, phy[p], VF_(select)(none, hy, VF_(max)(hy, phy[p])));
    empty = was & none;
  }
  const int keep = VI_(bits)(ahead_any & ~(bounded & empty)) & ((1 << n) - 1);
  if (!keep) return 0;
  /* not bounded: the whole screen */
  lx = VF_(select)(bounded, lx, zero), ly = VF_(select)(bounded, ly, zero);
  hx = VF_(select)(bounded, hx, last_x), hy = VF_(select)(bounded, hy, last_y);
  const VI bx0 = VI_(trunc)(lx), by0 = VI_(trunc)(ly), bx1 = VI_(trunc)(hx), by1 = VI_(trunc)(hy);
  /* each position's own rectangle within the union, a bit per position (tri_pos_bits) */
  VI none = VI_(splat)(0), in_x0 = none, in_y0 = none, in_x1 = none, in_y1 = none;
  for (int p = 0; p < npos && npos > 1; p++) {
    const VI bit = VI_(splat)(1 << p) & bounded;
    none |= ((plx[p] > phx[p]) | (ply[p] > phy[p])) & bit;
    in_x0 |= (plx[p] > lx) & bit, in_y0 |= (ply[p] > ly) & bit, in_x1 |= (phx[p] < hx) & bit,
        in_y1 |= (phy[p] < hy) & bit;
  }
  uint32_t kept = 0;
  for (int l = 0; l < n; l++)
    if (keep >> l & 1)
      out[kept++] = (tri_bound){(uint32_t)lane_id[l],
                                {bx0[l], by0[l], bx1[l], by1[l]},
                                {(uint16_t)none[l], (uint16_t)in_x0[l], (uint16_t)in_y0[l], (uint16_t)in_x1[l],
                                 (uint16_t)in_y1[l]}};
  return kept;
}

/* corner_bounds over triangles ids[0..n-1] (first..first+n-1), W a step, into out;
 * returns how many it kept. The camera's constants are made once for the run. */
TARGET __attribute__((always_inline)) static inline uint32_t RR_CAT(corner_bounds_run, W)(
    const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c, int npos,
    const float (*pos)[2], tri_bound *out, bool flat) {
  uint32_t kept = 0;
  for (uint32_t k = 0; k < n; k += W)
    kept += RR_CAT(corner_bounds, W)(s, first + k, ids ? ids + k : NULL, n - k < W ? (int)(n - k) : W, c, npos, pos,
                                     out + kept, flat);
  return kept;
}

/* corner_bounds compiled apart for one position and for scenes without instances */
TARGET static uint32_t RR_CAT(corner_bounds_any, W)(const rr_scene *s, uint32_t first, const uint32_t *ids,
                                                    uint32_t n, const camera *c, int npos, const float (*pos)[2],
                                                    tri_bound *out) {
  if (npos == 1)
    return s->inst ? RR_CAT(corner_bounds_run, W)(s, first, ids, n, c, 1, pos, out, false)
                   : RR_CAT(corner_bounds_run, W)(s, first, ids, n, c, 1, pos, out, true);
  return s->inst ? RR_CAT(corner_bounds_run, W)(s, first, ids, n, c, npos, pos, out, false)
                 : RR_CAT(corner_bounds_run, W)(s, first, ids, n, c, npos, pos, out, true);
}
