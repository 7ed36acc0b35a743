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

/* Cameras cams[0..ncams-1] that share the eye (a cube camera's faces; one camera
 * otherwise): the part of the setup that depends on the eye alone (the corners
 * relative to it, the edge normals, the volume, the plane's normal) is computed
 * once, the rest (a few dot products) per camera, for the lanes l whose bit k of
 * views[l] asks for camera k (every lane when views is NULL). Camera k's setup of
 * lane l goes to out[k·stride + l], face[k·stride + l] (SETUP_CULLED when not
 * asked for), pl likewise. The same operations in the same order as for each
 * camera alone, so the same bits. flat: a constant, true when the scene has no
 * instances (lane_corners). */
TARGET __attribute__((always_inline)) static inline void RR_CAT(setup_lanes, W)(
    const rr_scene *s, const uint32_t *ids, int count, const camera *cams, int ncams, const uint8_t *views, bool cull,
    tri_setup *out, int *face, tri_plane *pl, size_t stride, bool flat) {
  int32_t lane_id[W], lane_inf[W] = {0};
  for (int l = 0; l < W; l++) lane_id[l] = (int32_t)ids[l < count ? l : count - 1];
  if (s->inf)
    for (int l = 0; l < W; l++) lane_inf[l] = (int32_t)scene_inf(s, (uint32_t)lane_id[l]);
  const bool consecutive =
      count == W && VI_(bits)(VI_(load)(lane_id) == VI_(splat)(lane_id[0]) + VI_(lanes)()) == (1 << W) - 1;
  VF corner[3][3];
  RR_CAT(lane_corners, W)(s, lane_id, consecutive, corner, flat);
  const VI inf = VI_(load)(lane_inf);
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f);
  const V3 zero3 = {zero, zero, zero};
  const vec3 eye = cams[0].eye;
  /* q: the corner relative to the eye, or its direction when it is at infinity */
  V3 q[3], p[3];
  VI at_inf[3] = {VI_(splat)(0), VI_(splat)(0), VI_(splat)(0)};
#pragma GCC unroll 3
  for (int k = 0; k < 3; k++) {
    p[k] = (V3){corner[k][0], corner[k][1], corner[k][2]};
    q[k] = SUB3(p[k], SPLAT3(eye));
    if (s->inf) {
      at_inf[k] = -((inf >> k) & 1);
      q[k] = SELECT3(at_inf[k], p[k], q[k]);
    }
  }
  /* edge e runs from q[e+1] to q[e+2]: n_e = h × (l − h) in the canonical order (l, h) */
  V3 n[3];
  VI swap[3];
#pragma GCC unroll 3
  for (int e = 0; e < 3; e++) {
    V3 a = q[(e + 1) % 3], b = q[(e + 2) % 3];
    swap[e] = LEX_LESS3(b, a);
    V3 l = SELECT3(swap[e], b, a), h = SELECT3(swap[e], a, b);
    V3 m = CROSS3(h, SUB3(l, h));
    n[e] = SELECT3(swap[e], NEG3(m), m);
  }
  const VF vol_eye = DOT3(q[0], n[0]);
  /* The plane (prim/triangle_setup.c) in double, rounded once to float:
   * N = r_{f+2} × r_{f+1}, r_k = p_k − w_k·p_f for a finite corner f (0 unless it
   * lies at infinity). Float corners subtract and multiply exactly in double. */
  V3 pf = p[0], p1 = p[1], p2 = p[2];
  VI inf1 = at_inf[1], inf2 = at_inf[2];
  if (s->inf) {
    const VI f1 = at_inf[0] & ~at_inf[1], f2 = at_inf[0] & at_inf[1]; /* f = 1, f = 2 */
    pf = SELECT3(f1, p[1], SELECT3(f2, p[2], p[0]));
    p1 = SELECT3(f1, p[2], SELECT3(f2, p[0], p[1]));
    p2 = SELECT3(f1, p[0], SELECT3(f2, p[1], p[2]));
    inf1 = VI_(select)(f1, at_inf[2], VI_(select)(f2, at_inf[0], at_inf[1]));
    inf2 = VI_(select)(f1, at_inf[0], VI_(select)(f2, at_inf[1], at_inf[2]));
  }
  /* computed at the first camera that keeps a lane, after its edges: live across
   * them, its doubles would take registers the edges need */
  D3 nrm_eye, qf;
  bool have_plane = false;
  VF w[3];
  for (int k = 0; k < 3; k++) w[k] = VF_(select)(at_inf[k], zero, one);
  const int lanes = (1 << count) - 1;
  for (int view = 0; view < ncams; view++) {
    const camera *c = &cams[view];
    int asked = lanes;
    if (views) {
      asked = 0;
      for (int l = 0; l < count; l++) asked |= (views[l] >> view & 1) << l;
    }
    tri_setup *vout = out + view * stride;
    int *vface = face + view * stride;
    tri_plane *vpl = pl ? pl + view * stride : NULL;
    VF vol = vol_eye, vol_x = zero, vol_y = zero, orient = vol;
    const bool ortho = c->type == RR_CAMERA_ORTHOGRAPHIC;
    const V3 fwd = SPLAT3(c->fwd);
    if (ortho) {
      /* Σ w_i n_i */
      V3 sum = ADD3(ADD3(SELECT3(at_inf[0], zero3, n[0]), SELECT3(at_inf[1], zero3, n[1])),
                    SELECT3(at_inf[2], zero3, n[2]));
      const V3 o0 = SPLAT3(c->o0), ox = SPLAT3(c->ox), oy = SPLAT3(c->oy);
      vol = vol - DOT3(o0, sum);
      vol_x = -DOT3(ox, sum);
      vol_y = -DOT3(oy, sum);
      orient = DOT3(fwd, sum);
    }
    /* seen unless edge-on (or not finite); front faces have orient > 0 */
    const VI seen = (orient != zero) & (VF_(abs)(vol) < VF_(splat)(INFINITY)), front = orient > zero;
    const int front_m = VI_(bits)(front) & lanes,
              kept = VI_(bits)(seen & (cull ? front : VI_(splat)(-1))) & asked;
    if (!kept) {
      for (int l = 0; l < count; l++) vface[l] = SETUP_CULLED;
      continue;
    }
    const VF sign = VF_(select)(front, one, VF_(splat)(-1.0f));
    const V3 d0 = SPLAT3(c->d0), dx = SPLAT3(c->dx), dy = SPLAT3(c->dy);
    VF ea[3], eb[3], ec[3];
    VI tie = VI_(splat)(0);
#pragma GCC unroll 3
    for (int e = 0; e < 3; e++) {
      V3 ne = SCALE3(n[e], sign);
      VF g1, g2;
      if (c->type == RR_CAMERA_PERSPECTIVE) {
        ea[e] = DOT3(ne, d0), eb[e] = DOT3(ne, dx), ec[e] = DOT3(ne, dy);
        g1 = eb[e], g2 = ec[e];
      } else if (ortho) {
        /* the eye at infinity: m_e = d × (w_h·l − w_l·h) in the edge's canonical order */
        int ia = (e + 1) % 3, ib = (e + 2) % 3;
        V3 l = SELECT3(swap[e], q[ib], q[ia]), h = SELECT3(swap[e], q[ia], q[ib]);
        VI l_inf = VI_(select)(swap[e], at_inf[ib], at_inf[ia]), h_inf = VI_(select)(swap[e], at_inf[ia], at_inf[ib]);
        V3 diff = SELECT3(l_inf, SELECT3(h_inf, zero3, l), SELECT3(h_inf, NEG3(h), SUB3(l, h)));
        V3 m = CROSS3(fwd, diff);
        V3 me = SCALE3(SELECT3(swap[e], NEG3(m), m), sign);
        ea[e] = DOT3(ne, fwd) + DOT3(me, SPLAT3(c->o0));
        eb[e] = DOT3(me, SPLAT3(c->ox)), ec[e] = DOT3(me, SPLAT3(c->oy));
        g1 = eb[e], g2 = ec[e];
      } else {
        ea[e] = ne.x, eb[e] = ne.y, ec[e] = ne.z;
        g1 = DOT3(ne, SPLAT3(c->right)), g2 = -DOT3(ne, SPLAT3(c->up));
      }
      /* the top-left rule's tie bit */
      tie |= LEX_POSITIVE(g1, g2, DOT3(ne, fwd)) & (1 << e);
    }
    vol = vol * sign, vol_x = vol_x * sign, vol_y = vol_y * sign;
    if (!have_plane) {
      const V3 base1 = SELECT3(inf1, zero3, pf), base2 = SELECT3(inf2, zero3, pf); /* w_k·p_f */
      const D3 r1 = SUB3_T(D3, TO_D3(p1), TO_D3(base1)), r2 = SUB3_T(D3, TO_D3(p2), TO_D3(base2));
      nrm_eye = CROSS3_T(D3, r2, r1), qf = SUB3_T(D3, TO_D3(pf), DSPLAT3(eye));
      have_plane = true;
    }
    const D3 nrm = SCALE3_T(D3, nrm_eye, TO_D(sign));
    /* (cx, cy): the sample nearest to where p_f projects, within the image; the
     * coordinates of q_f in the basis of the camera's (d0, dx, dy) or, orthographic,
     * of q_f − o0 in (ox, oy, fwd), by the dual basis (the rows of its inverse). */
    VF cx = zero, cy = zero;
    if (c->planar) {
      vec3 u = ortho ? c->ox : c->dx, v = ortho ? c->oy : c->dy, w0 = ortho ? c->fwd : c->d0;
      V3 qp = SUB3(pf, SPLAT3(c->eye));
      if (ortho) qp = SUB3(qp, SPLAT3(c->o0));
      /* perspective: q = λ·(d0 + sx·dx + sy·dy), sx = q·(dy × d0) / q·(dx × dy);
       * orthographic: q = sx·ox + sy·oy + t·fwd, sx = q·(oy × fwd) / fwd·(ox × oy) */
      const vec3 uv = v3_cross(u, v);
      const VF depth = ortho ? VF_(splat)(v3_dot(w0, uv)) : DOT3(qp, SPLAT3(uv));
      const VF lo_x = VF_(splat)(c->sx0), hi_x = VF_(splat)((float)(c->width - 1) + c->sx0);
      const VF lo_y = VF_(splat)(c->sy0), hi_y = VF_(splat)((float)(c->height - 1) + c->sy0);
      cx = DOT3(qp, SPLAT3(v3_cross(v, w0))) / depth, cy = DOT3(qp, SPLAT3(v3_cross(w0, u))) / depth;
      if (vpl)
        for (int l = 0; l < count; l++) vpl[l].px = cx[l], vpl[l].py = cy[l];
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
      if (vpl)
        for (int l = 0; l < count; l++) vpl[l].base = base[l], vpl[l].u = pb[l], vpl[l].v = pc[l];
    } else if (ortho) {
      /* rays from eye + o0 + sx·ox + sy·oy along fwd */
      pa = DOT3(nrm, DSPLAT3(c->fwd)), pb = num_x, pc = num_x;
      num_x = -DOT3(nrm, DSPLAT3(c->ox)), num_y = -DOT3(nrm, DSPLAT3(c->oy));
      base = DOT3(nrm, SUB3_T(D3, qf, DSPLAT3(c->o0)));
      num0 = base + dcx * num_x + dcy * num_y;
      if (vpl)
        for (int l = 0; l < count; l++) vpl[l].base = base[l], vpl[l].u = num_x[l], vpl[l].v = num_y[l];
    } else {
      pa = nrm.x, pb = nrm.y, pc = nrm.z;
      num0 = DOT3(nrm, qf);
    }
    const VF fpa = TO_F(pa), fpb = TO_F(pb), fpc = TO_F(pc), fn0 = TO_F(num0), fnx = TO_F(num_x), fny = TO_F(num_y);
    for (int l = 0; l < count; l++) {
      vface[l] = !(kept >> l & 1) ? SETUP_CULLED : front_m >> l & 1 ? SETUP_FRONT : SETUP_BACK;
      if (vface[l] == SETUP_CULLED) continue;
      tri_setup *o = &vout[l];
      for (int e = 0; e < 3; e++) o->a[e] = ea[e][l], o->b[e] = eb[e][l], o->c[e] = ec[e][l];
      o->vol = vol[l], o->vol_x = vol_x[l], o->vol_y = vol_y[l];
      o->tie = (uint32_t)tie[l];
      for (int k = 0; k < 3; k++) o->w[k] = w[k][l];
      o->pa = fpa[l], o->pb = fpb[l], o->pc = fpc[l];
      o->num0 = fn0[l], o->num_x = fnx[l], o->num_y = fny[l];
      o->cx = cx[l], o->cy = cy[l];
    }
  }
}

/* setup_lanes for several cameras (it is always inlined: a call of its own here),
 * compiled apart for scenes with and without instances. */
TARGET static void RR_CAT(setup_views, W)(const rr_scene *s, const uint32_t *ids, int count, const camera *cams,
                                          int ncams, const uint8_t *views, bool cull, tri_setup *out, int *face,
                                          tri_plane *pl, size_t stride) {
  if (s->inst)
    RR_CAT(setup_lanes, W)(s, ids, count, cams, ncams, views, cull, out, face, pl, stride, false);
  else
    RR_CAT(setup_lanes, W)(s, ids, count, cams, ncams, views, cull, out, face, pl, stride, true);
}

/* setup_lanes for one camera and every lane, compiled without the loop over
 * cameras, and apart for scenes with and without instances. */
TARGET static void RR_CAT(setup_one, W)(const rr_scene *s, const uint32_t *ids, int count, const camera *c, bool cull,
                                        tri_setup *out, int *face, tri_plane *pl) {
  if (s->inst)
    RR_CAT(setup_lanes, W)(s, ids, count, c, 1, NULL, cull, out, face, pl, 0, false);
  else
    RR_CAT(setup_lanes, W)(s, ids, count, c, 1, NULL, cull, out, face, pl, 0, true);
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
