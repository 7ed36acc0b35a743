/* Triangle setup for W triangles at once: a kernel template (core/simd.h) that
 * triangle_setup.c instantiates per width through core/simd_widths.h.
 *
 * Triangles ids[0..count-1] (count <= W; the padding lanes repeat the last one)
 * into out[l] and face[l], for any camera and any corners at infinity, as
 * triangle_setup.c describes it. Lanes hold one triangle each and never mix, and
 * the operations are IEEE single floats in a fixed order (no FMA), so every width
 * gives the same bits. A culled triangle's out[l] is not written. */
#define V3 RR_CAT(setup_v3_, W)
#define D3 RR_CAT(setup_d3_, W)
#define VD RR_CAT(rr_vd, W)

/* W three-vectors, one per lane, and the vec3.h operations on them. */
typedef struct {
  VF x, y, z;
} V3;
/* the same in double, for the plane */
typedef struct {
  VD x, y, z;
} D3;
#define TO_D(v) RR_CAT(RR_CAT(rr_vf, W), _to_double)(v)
#define TO_F(v) RR_CAT(RR_CAT(rr_vd, W), _to_float)(v)
#define TO_D3(v) ((D3){TO_D((v).x), TO_D((v).y), TO_D((v).z)})
#define DSPLAT3(v) ((D3){(VD){0} + (double)(v).x, (VD){0} + (double)(v).y, (VD){0} + (double)(v).z})
#define SPLAT3(v) ((V3){VF_(splat)((v).x), VF_(splat)((v).y), VF_(splat)((v).z)})
/* SUB3, SCALE3, CROSS3 build a T: V3, or D3 for the plane's doubles */
#define SUB3_T(T, a, b) ((T){(a).x - (b).x, (a).y - (b).y, (a).z - (b).z})
#define SUB3(a, b) SUB3_T(V3, a, b)
#define ADD3(a, b) ((V3){(a).x + (b).x, (a).y + (b).y, (a).z + (b).z})
#define NEG3(a) ((V3){-(a).x, -(a).y, -(a).z})
#define SCALE3_T(T, a, s) ((T){(a).x * (s), (a).y * (s), (a).z * (s)})
#define SCALE3(a, s) SCALE3_T(V3, a, s)
#define DOT3(a, b) ((a).x * (b).x + (a).y * (b).y + (a).z * (b).z)
#define CROSS3_T(T, a, b) \
  ((T){(a).y * (b).z - (a).z * (b).y, (a).z * (b).x - (a).x * (b).z, (a).x * (b).y - (a).y * (b).x})
#define CROSS3(a, b) CROSS3_T(V3, a, b)
#define SELECT3(m, a, b) \
  ((V3){VF_(select)(m, (a).x, (b).x), VF_(select)(m, (a).y, (b).y), VF_(select)(m, (a).z, (b).z)})
/* lex_less(a, b) and lex_positive(g1, g2, g3) as masks, with the scalar comparisons' NaN behaviour */
#include "prim/triangle_corners_tmp.h"

#define LEX_LESS3(a, b) \
  VI_(select)((a).x != (b).x, (a).x < (b).x, VI_(select)((a).y != (b).y, (a).y < (b).y, (a).z < (b).z))
#define LEX_POSITIVE(g1, g2, g3) \
  (((g1) > zero) | (((g1) == zero) & (((g2) > zero) | (((g2) == zero) & ((g3) > zero)))))

#define EYE RR_CAT(setup_eye_, W)
/* The part of W triangles' setup that depends on the eye alone (and is the same
 * for every camera there): the corners relative to it (q; p as given), the edge
 * normals n and their canonical order (swap), the volume, the plane's corners
 * (pf, p1, p2, the two others' infinity inf1, inf2) and the corners at infinity. */
typedef struct {
  V3 q[3], p[3], n[3], pf, p1, p2;
  VI at_inf[3], swap[3], inf1, inf2;
  VF vol;
} EYE;

/* EYE of triangles ids[0..count-1] (count <= W) seen from eye. flat: a constant,
 * true when the scene has no instances (lane_corners). */
TARGET __attribute__((always_inline)) static inline void RR_CAT(eye_lanes, W)(const rr_scene *s, const uint32_t *ids,
                                                                            int count, vec3 eye, bool flat, EYE *e) {
  int32_t lane_id[W], lane_inf[W] = {0};
  for (int l = 0; l < W; l++) lane_id[l] = (int32_t)ids[l < count ? l : count - 1];
  if (s->inf)
    for (int l = 0; l < W; l++) lane_inf[l] = (int32_t)scene_inf(s, (uint32_t)lane_id[l]);
  const bool consecutive =
      count == W && VI_(bits)(VI_(load)(lane_id) == VI_(splat)(lane_id[0]) + VI_(lanes)()) == (1 << W) - 1;
  VF corner[3][3];
  RR_CAT(lane_corners, W)(s, lane_id, consecutive, corner, flat);
  const VI inf = VI_(load)(lane_inf);
  /* q: the corner relative to the eye, or its direction when it is at infinity */
#pragma GCC unroll 3
  for (int k = 0; k < 3; k++) {
    e->p[k] = (V3){corner[k][0], corner[k][1], corner[k][2]};
    e->q[k] = SUB3(e->p[k], SPLAT3(eye));
    e->at_inf[k] = VI_(splat)(0);
    if (s->inf) {
      e->at_inf[k] = -((inf >> k) & 1);
      e->q[k] = SELECT3(e->at_inf[k], e->p[k], e->q[k]);
    }
  }
  /* edge i runs from q[i+1] to q[i+2]: n_i = h × (l − h) in the canonical order (l, h) */
#pragma GCC unroll 3
  for (int i = 0; i < 3; i++) {
    V3 a = e->q[(i + 1) % 3], b = e->q[(i + 2) % 3];
    e->swap[i] = LEX_LESS3(b, a);
    V3 l = SELECT3(e->swap[i], b, a), h = SELECT3(e->swap[i], a, b);
    V3 m = CROSS3(h, SUB3(l, h));
    e->n[i] = SELECT3(e->swap[i], NEG3(m), m);
  }
  e->vol = DOT3(e->q[0], e->n[0]);
  /* The plane (prim/triangle_setup.c) in double, rounded once to float:
   * N = r_{f+2} × r_{f+1}, r_k = p_k − w_k·p_f for a finite corner f (0 unless it
   * lies at infinity). Float corners subtract and multiply exactly in double. */
  e->pf = e->p[0], e->p1 = e->p[1], e->p2 = e->p[2];
  e->inf1 = e->at_inf[1], e->inf2 = e->at_inf[2];
  if (s->inf) {
    const VI f1 = e->at_inf[0] & ~e->at_inf[1], f2 = e->at_inf[0] & e->at_inf[1]; /* f = 1, f = 2 */
    e->pf = SELECT3(f1, e->p[1], SELECT3(f2, e->p[2], e->p[0]));
    e->p1 = SELECT3(f1, e->p[2], SELECT3(f2, e->p[0], e->p[1]));
    e->p2 = SELECT3(f1, e->p[0], SELECT3(f2, e->p[1], e->p[2]));
    e->inf1 = VI_(select)(f1, e->at_inf[2], VI_(select)(f2, e->at_inf[0], e->at_inf[1]));
    e->inf2 = VI_(select)(f1, e->at_inf[0], VI_(select)(f2, e->at_inf[1], e->at_inf[2]));
  }
}

/* The rest of the setup of the lanes of e for camera c (whose eye is e's): the
 * lanes l < count whose bit is set in asked go to out[l], face[l] and pl[l] (when
 * not NULL), each entry ostride (pstride) bytes after the one before; face is
 * SETUP_CULLED for the others, whose out and pl are not written. may_ortho (a
 * constant): c may be orthographic, which reads e's q and swap. */
TARGET __attribute__((always_inline)) static inline void RR_CAT(view_lanes, W)(const EYE *e, int count, int asked,
                                                                             const camera *c, bool cull, tri_setup *out,
                                                                             size_t ostride, int *face, tri_plane *pl,
                                                                             size_t pstride, bool may_ortho) {
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f);
  const V3 zero3 = {zero, zero, zero};
  const int lanes = (1 << count) - 1;
  VF vol = e->vol, vol_x = zero, vol_y = zero, orient = vol;
  const bool ortho = may_ortho && c->type == RR_CAMERA_ORTHOGRAPHIC;
  const V3 fwd = SPLAT3(c->fwd);
  if (ortho) {
    /* Σ w_i n_i */
    V3 sum = ADD3(ADD3(SELECT3(e->at_inf[0], zero3, e->n[0]), SELECT3(e->at_inf[1], zero3, e->n[1])),
                  SELECT3(e->at_inf[2], zero3, e->n[2]));
    const V3 o0 = SPLAT3(c->o0), ox = SPLAT3(c->ox), oy = SPLAT3(c->oy);
    vol = vol - DOT3(o0, sum);
    vol_x = -DOT3(ox, sum);
    vol_y = -DOT3(oy, sum);
    orient = DOT3(fwd, sum);
  }
  /* seen unless edge-on (or not finite); front faces have orient > 0 */
  const VI seen = (orient != zero) & (VF_(abs)(vol) < VF_(splat)(INFINITY)), front = orient > zero;
  const int front_m = VI_(bits)(front) & lanes,
            kept = VI_(bits)(seen & (cull ? front : VI_(splat)(-1))) & asked & lanes;
  if (!kept) {
    for (int l = 0; l < count; l++) face[l] = SETUP_CULLED;
    return;
  }
  const VF sign = VF_(select)(front, one, VF_(splat)(-1.0f));
  const V3 d0 = SPLAT3(c->d0), dx = SPLAT3(c->dx), dy = SPLAT3(c->dy);
  VF ea[3], eb[3], ec[3];
  VI tie = VI_(splat)(0);
#pragma GCC unroll 3
  for (int i = 0; i < 3; i++) {
    V3 ne = SCALE3(e->n[i], sign);
    VF g1, g2;
    if (c->type == RR_CAMERA_PERSPECTIVE) {
      ea[i] = DOT3(ne, d0), eb[i] = DOT3(ne, dx), ec[i] = DOT3(ne, dy);
      g1 = eb[i], g2 = ec[i];
    } else if (ortho) {
      /* the eye at infinity: m_i = d × (w_h·l − w_l·h) in the edge's canonical order */
      int ia = (i + 1) % 3, ib = (i + 2) % 3;
      V3 l = SELECT3(e->swap[i], e->q[ib], e->q[ia]), h = SELECT3(e->swap[i], e->q[ia], e->q[ib]);
      VI l_inf = VI_(select)(e->swap[i], e->at_inf[ib], e->at_inf[ia]),
         h_inf = VI_(select)(e->swap[i], e->at_inf[ia], e->at_inf[ib]);
      V3 diff = SELECT3(l_inf, SELECT3(h_inf, zero3, l), SELECT3(h_inf, NEG3(h), SUB3(l, h)));
      V3 m = CROSS3(fwd, diff);
      V3 me = SCALE3(SELECT3(e->swap[i], NEG3(m), m), sign);
      ea[i] = DOT3(ne, fwd) + DOT3(me, SPLAT3(c->o0));
      eb[i] = DOT3(me, SPLAT3(c->ox)), ec[i] = DOT3(me, SPLAT3(c->oy));
      g1 = eb[i], g2 = ec[i];
    } else {
      ea[i] = ne.x, eb[i] = ne.y, ec[i] = ne.z;
      g1 = DOT3(ne, SPLAT3(c->right)), g2 = -DOT3(ne, SPLAT3(c->up));
    }
    /* the top-left rule's tie bit */
    tie |= LEX_POSITIVE(g1, g2, DOT3(ne, fwd)) & (1 << i);
  }
  vol = vol * sign, vol_x = vol_x * sign, vol_y = vol_y * sign;
  /* after the edges: live across them, its doubles would take registers the edges need */
  const V3 base1 = SELECT3(e->inf1, zero3, e->pf), base2 = SELECT3(e->inf2, zero3, e->pf); /* w_k·p_f */
  const D3 r1 = SUB3_T(D3, TO_D3(e->p1), TO_D3(base1)), r2 = SUB3_T(D3, TO_D3(e->p2), TO_D3(base2));
  const D3 nrm_eye = CROSS3_T(D3, r2, r1), qf = SUB3_T(D3, TO_D3(e->pf), DSPLAT3(c->eye));
  const D3 nrm = SCALE3_T(D3, nrm_eye, TO_D(sign));
#define PL(l) ((tri_plane *)((char *)pl + (size_t)(l) * pstride))
  /* (cx, cy): the sample nearest to where p_f projects, within the image; the
   * coordinates of q_f in the basis of the camera's (d0, dx, dy) or, orthographic,
   * of q_f − o0 in (ox, oy, fwd), by the dual basis (the rows of its inverse). */
  VF cx = zero, cy = zero;
  if (c->planar) {
    vec3 u = ortho ? c->ox : c->dx, v = ortho ? c->oy : c->dy, w0 = ortho ? c->fwd : c->d0;
    V3 qp = SUB3(e->pf, SPLAT3(c->eye));
    if (ortho) qp = SUB3(qp, SPLAT3(c->o0));
    /* perspective: q = λ·(d0 + sx·dx + sy·dy), sx = q·(dy × d0) / q·(dx × dy);
     * orthographic: q = sx·ox + sy·oy + t·fwd, sx = q·(oy × fwd) / fwd·(ox × oy) */
    const vec3 uv = v3_cross(u, v);
    const VF depth = ortho ? VF_(splat)(v3_dot(w0, uv)) : DOT3(qp, SPLAT3(uv));
    const VF lo_x = VF_(splat)(c->sx0), hi_x = VF_(splat)((float)(c->width - 1) + c->sx0);
    const VF lo_y = VF_(splat)(c->sy0), hi_y = VF_(splat)((float)(c->height - 1) + c->sy0);
    cx = DOT3(qp, SPLAT3(v3_cross(v, w0))) / depth, cy = DOT3(qp, SPLAT3(v3_cross(w0, u))) / depth;
    if (pl)
      for (int l = 0; l < count; l++) PL(l)->px = cx[l], PL(l)->py = cy[l];
    /* NaN (a corner in the eye's plane) clamps to the far side: any sample is exact
     * (tri_setup_at repeats these operations for another position) */
    cx = VF_(max)(VF_(min)(cx, hi_x), lo_x), cy = VF_(max)(VF_(min)(cy, hi_y), lo_y);
    cx = VF_(floor)(cx - lo_x) + lo_x, cy = VF_(floor)(cy - lo_y) + lo_y;
  }
  const VD dcx = TO_D(cx), dcy = TO_D(cy);
  VD pa, pb, pc, num0, num_x = TO_D(zero), num_y = num_x, base;
  if (c->type == RR_CAMERA_PERSPECTIVE) {
    pb = DOT3(nrm, DSPLAT3(c->dx)), pc = DOT3(nrm, DSPLAT3(c->dy));
    base = DOT3(nrm, DSPLAT3(c->d0));
    pa = base + dcx * pb + dcy * pc;
    num0 = DOT3(nrm, qf);
    if (pl)
      for (int l = 0; l < count; l++) PL(l)->base = base[l], PL(l)->u = pb[l], PL(l)->v = pc[l];
  } else if (ortho) {
    /* rays from eye + o0 + sx·ox + sy·oy along fwd */
    pa = DOT3(nrm, DSPLAT3(c->fwd)), pb = num_x, pc = num_x;
    num_x = -DOT3(nrm, DSPLAT3(c->ox)), num_y = -DOT3(nrm, DSPLAT3(c->oy));
    base = DOT3(nrm, SUB3_T(D3, qf, DSPLAT3(c->o0)));
    num0 = base + dcx * num_x + dcy * num_y;
    if (pl)
      for (int l = 0; l < count; l++) PL(l)->base = base[l], PL(l)->u = num_x[l], PL(l)->v = num_y[l];
  } else {
    pa = nrm.x, pb = nrm.y, pc = nrm.z;
    num0 = DOT3(nrm, qf);
  }
#undef PL
  VF w[3];
  for (int k = 0; k < 3; k++) w[k] = VF_(select)(e->at_inf[k], zero, one);
  const VF fpa = TO_F(pa), fpb = TO_F(pb), fpc = TO_F(pc), fn0 = TO_F(num0), fnx = TO_F(num_x), fny = TO_F(num_y);
  for (int l = 0; l < count; l++) {
    face[l] = !(kept >> l & 1) ? SETUP_CULLED : front_m >> l & 1 ? SETUP_FRONT : SETUP_BACK;
    if (face[l] == SETUP_CULLED) continue;
    tri_setup *o = (tri_setup *)((char *)out + (size_t)l * ostride);
    for (int i = 0; i < 3; i++) o->a[i] = ea[i][l], o->b[i] = eb[i][l], o->c[i] = ec[i][l];
    o->vol = vol[l], o->vol_x = vol_x[l], o->vol_y = vol_y[l];
    o->tie = (uint32_t)tie[l];
    for (int k = 0; k < 3; k++) o->w[k] = w[k][l];
    o->pa = fpa[l], o->pb = fpb[l], o->pc = fpc[l];
    o->num0 = fn0[l], o->num_x = fnx[l], o->num_y = fny[l];
    o->cx = cx[l], o->cy = cy[l];
  }
}

/* Triangles ids[0..count-1] for camera c: out[l], face[l], pl[l] (when not NULL). */
TARGET __attribute__((always_inline)) static inline void RR_CAT(setup_lanes, W)(const rr_scene *s, const uint32_t *ids,
                                                                              int count, const camera *c, bool cull,
                                                                              tri_setup *out, int *face, tri_plane *pl,
                                                                              bool flat) {
  EYE e;
  RR_CAT(eye_lanes, W)(s, ids, count, c->eye, flat, &e);
  RR_CAT(view_lanes, W)(&e, count, (1 << count) - 1, c, cull, out, sizeof *out, face, pl, sizeof *pl, true);
}

/* setup_lanes compiled apart for scenes with and without instances. */
TARGET static void RR_CAT(setup_one, W)(const rr_scene *s, const uint32_t *ids, int count, const camera *c, bool cull,
                                        tri_setup *out, int *face, tri_plane *pl) {
  if (s->inst)
    RR_CAT(setup_lanes, W)(s, ids, count, c, cull, out, face, pl, false);
  else
    RR_CAT(setup_lanes, W)(s, ids, count, c, cull, out, face, pl, true);
}

/* EYE's fields (TRI_EYE_REC: p1, p2, pf, n, vol, the 19 every scene needs; at_inf,
 * inf1, inf2 only when inf) into field f, lane l at at[f·fstride + l]. Stored and
 * loaded floats keep their bits, and view_lanes computes what it computes for the
 * triangles in any lanes. */
TARGET __attribute__((always_inline)) static inline void RR_CAT(eye_store, W)(const EYE *e, bool inf, float *at,
                                                                            size_t fstride) {
#define STORE_F(f, v) memcpy(at + (f) * fstride, &(v), W * sizeof(float))
#define STORE3(f, v) (STORE_F(f, (v).x), STORE_F((f) + 1, (v).y), STORE_F((f) + 2, (v).z))
  STORE3(0, e->p1), STORE3(3, e->p2), STORE3(6, e->pf);
  for (int i = 0; i < 3; i++) STORE3(9 + 3 * i, e->n[i]);
  STORE_F(18, e->vol);
  if (inf) {
    for (int i = 0; i < 3; i++) STORE_F(19 + i, e->at_inf[i]);
    STORE_F(22, e->inf1), STORE_F(23, e->inf2);
  }
#undef STORE3
#undef STORE_F
}

/* EYE (what view_lanes reads for a camera that is not orthographic) of W lanes
 * from stored fields: field f of lane l at from[f·fstride + lane[l]], loaded
 * when run (the lanes in a row, fstride apart), else gathered. */
TARGET __attribute__((always_inline)) static inline void RR_CAT(eye_load, W)(const float *from, int fstride,
                                                                           const int32_t *lane, bool run, bool inf,
                                                                           EYE *e) {
  const VI idx = VI_(load)(lane), all = VI_(splat)(-1);
#define GATHER_F(f) (run ? VF_(load)(from + (f) * fstride + lane[0]) : VF_(gather)(from + (f) * fstride, idx))
#define GATHER3(f) ((V3){GATHER_F(f), GATHER_F((f) + 1), GATHER_F((f) + 2)})
#define GATHER_I(f) \
  (run ? VI_(load)((const int32_t *)from + (f) * fstride + lane[0]) \
       : VI_(gather_masked)((const int32_t *)from + (f) * fstride, idx, all))
  e->p1 = GATHER3(0), e->p2 = GATHER3(3), e->pf = GATHER3(6);
  for (int i = 0; i < 3; i++) e->n[i] = GATHER3(9 + 3 * i);
  e->vol = GATHER_F(18);
  e->at_inf[0] = e->at_inf[1] = e->at_inf[2] = e->inf1 = e->inf2 = VI_(splat)(0);
  if (inf) {
    for (int i = 0; i < 3; i++) e->at_inf[i] = GATHER_I(19 + i);
    e->inf1 = GATHER_I(22), e->inf2 = GATHER_I(23);
  }
#undef GATHER_I
#undef GATHER3
#undef GATHER_F
}

/* The shared setup (triangle.h, rr_tri_setup_shared): EYE of every triangle once,
 * stored by field (rec), then, for each camera, the triangles it asks for gathered
 * W to a step (loaded when they are W in a row) and set up for it. */
TARGET __attribute__((always_inline)) static inline void RR_CAT(setup_shared_lanes, W)(
    const rr_scene *s, const uint32_t *ids, int n, const camera *cams, int ncams, const int32_t *sel, const int *nsel,
    bool cull, tri_setup *out, size_t ostride, int *face, tri_plane *pl, size_t pstride, bool flat) {
  /* field f of triangle k at rec[f·stride + k], W lanes past the last triangle
   * for its stores; few triangles keep to few cache lines */
  float rec[TRI_EYE_REC * (TRI_SHARED_MAX + W)];
  const int stride = (n + W - 1) / W * W + W;
  for (int k = 0; k < n; k += W) {
    EYE e;
    RR_CAT(eye_lanes, W)(s, ids + k, n - k < W ? n - k : W, cams[0].eye, flat, &e);
    RR_CAT(eye_store, W)(&e, s->inf, rec + k, stride);
  }
  for (int view = 0, at = 0; view < ncams; at += nsel[view++])
    for (int j = 0; j < nsel[view]; j += W) {
      const int m = nsel[view] - j < W ? nsel[view] - j : W;
      int32_t lane[W];
      for (int l = 0; l < W; l++) lane[l] = sel[at + j + (l < m ? l : m - 1)];
      /* W of a face's triangles in a row (the common case): loads, cheaper than gathers */
      bool run = m == W;
      for (int l = 1; l < W && run; l++) run = lane[l] == lane[0] + l;
      EYE e;
      RR_CAT(eye_load, W)(rec, stride, lane, run, s->inf, &e);
      RR_CAT(view_lanes, W)(&e, m, (1 << m) - 1, &cams[view], cull, (tri_setup *)((char *)out + (at + j) * ostride),
                            ostride, face + at + j, pl ? (tri_plane *)((char *)pl + (at + j) * pstride) : NULL,
                            pstride, false);
    }
}

TARGET static void RR_CAT(setup_shared, W)(const rr_scene *s, const uint32_t *ids, int n, const camera *cams,
                                           int ncams, const int32_t *sel, const int *nsel, bool cull, tri_setup *out,
                                           size_t ostride, int *face, tri_plane *pl, size_t pstride) {
  if (s->inst)
    RR_CAT(setup_shared_lanes, W)(s, ids, n, cams, ncams, sel, nsel, cull, out, ostride, face, pl, pstride, false);
  else
    RR_CAT(setup_shared_lanes, W)(s, ids, n, cams, ncams, sel, nsel, cull, out, ostride, face, pl, pstride, true);
}

/* The setup through a table of eye parts (triangle.h, rr_tri_setup_kept): the
 * triangles whose eye part no setup has made are claimed, set up straight from
 * their EYE and recorded; then those of others, from their records (a claim of
 * another thread waited for: it records without waiting on anything, so each eye
 * part is made once whatever the threads). */
TARGET __attribute__((always_inline)) static inline int RR_CAT(setup_kept_lanes, W)(
    const rr_scene *s, tri_eyes *keep, const uint32_t *ids, int n, const camera *c, bool cull, tri_setup *out,
    int *face, tri_plane *pl, int *order, bool flat) {
  const int fields = s->inf ? TRI_EYE_REC : 19;
  uint32_t mine[TRI_SHARED_MAX];
  int32_t where[TRI_SHARED_MAX + W]; /* the others' records (float offsets), from entry `fresh` on */
  int fresh = 0, rest = n;
  for (int k = 0; k < n; k++) { /* mine from the front of order, the others from its back */
    uint32_t v = atomic_load_explicit(&keep->slot[ids[k]], memory_order_acquire);
    if (v == TRI_EYE_NONE && atomic_compare_exchange_strong_explicit(&keep->slot[ids[k]], &v, TRI_EYE_BUSY,
                                                                     memory_order_acquire, memory_order_acquire))
      mine[fresh] = ids[k], order[fresh++] = k;
    else
      order[--rest] = k;
  }
  const uint32_t base = fresh ? atomic_fetch_add_explicit(&keep->used, (unsigned)fresh, memory_order_relaxed) : 0;
  for (int k = 0; k < fresh; k += W) {
    const int m = fresh - k < W ? fresh - k : W;
    EYE e;
    float lanes[TRI_EYE_REC][W];
    RR_CAT(eye_lanes, W)(s, mine + k, m, c->eye, flat, &e);
    RR_CAT(view_lanes, W)(&e, m, (1 << m) - 1, c, cull, out + k, sizeof *out, face + k, pl ? pl + k : NULL,
                          sizeof *pl, false);
    RR_CAT(eye_store, W)(&e, s->inf, &lanes[0][0], W);
    for (int l = 0; l < m; l++) {
      const uint32_t r = base + (uint32_t)(k + l);
      for (int f = 0; f < fields; f++) keep->rec[r][f] = lanes[f][l];
      atomic_store_explicit(&keep->slot[mine[k + l]], TRI_EYE_AT + r, memory_order_release);
    }
  }
  for (int k = fresh; k < n; k++) {
    uint32_t v;
    while ((v = atomic_load_explicit(&keep->slot[ids[order[k]]], memory_order_acquire)) < TRI_EYE_AT) sched_yield();
    where[k] = (int32_t)(v - TRI_EYE_AT) * TRI_EYE_REC;
  }
  for (int k = fresh; k < n; k += W) {
    const int m = n - k < W ? n - k : W;
    for (int l = m; l < W; l++) where[k + l] = where[k];
    EYE e;
    RR_CAT(eye_load, W)(keep->rec[0], 1, where + k, false, s->inf, &e);
    RR_CAT(view_lanes, W)(&e, m, (1 << m) - 1, c, cull, out + k, sizeof *out, face + k, pl ? pl + k : NULL,
                          sizeof *pl, false);
  }
  return fresh;
}

TARGET static int RR_CAT(setup_kept, W)(const rr_scene *s, tri_eyes *keep, const uint32_t *ids, int n,
                                        const camera *c, bool cull, tri_setup *out, int *face, tri_plane *pl,
                                        int *order) {
  if (s->inst) return RR_CAT(setup_kept_lanes, W)(s, keep, ids, n, c, cull, out, face, pl, order, false);
  return RR_CAT(setup_kept_lanes, W)(s, keep, ids, n, c, cull, out, face, pl, order, true);
}

#include "prim/triangle_moved_tmp.h"

/* tri_moved_lanes stored: positions ox[0..W-1], oy[0..W-1] */
TARGET static void RR_CAT(moved_lanes, W)(const tri_setup *ts, const tri_plane *pl, const camera *c, const float *ox,
                                          const float *oy, float *pa, float *num0, float *cx, float *cy) {
  VF m[4];
  RR_CAT(tri_moved_lanes, W)(ts, pl, c, VF_(load)(ox), VF_(load)(oy), m);
  memcpy(pa, &m[0], W * sizeof(float)), memcpy(num0, &m[1], W * sizeof(float));
  memcpy(cx, &m[2], W * sizeof(float)), memcpy(cy, &m[3], W * sizeof(float));
}

#undef SPLAT3
#undef SUB3
#undef SUB3_T
#undef SCALE3_T
#undef CROSS3_T
#undef ADD3
#undef NEG3
#undef SCALE3
#undef DOT3
#undef CROSS3
#undef SELECT3
#undef LEX_LESS3
#undef LEX_POSITIVE
#undef V3
#undef D3
#undef VD
#undef TO_D
#undef TO_F
#undef TO_D3
#undef DSPLAT3
#undef EYE
