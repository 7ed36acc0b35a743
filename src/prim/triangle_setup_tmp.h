/* Triangle setup for W triangles at once: a kernel template (core/simd.h) that
 * triangle_setup.c instantiates per width through core/simd_widths.h.
 *
 * Triangles ids[0..count-1] (count <= W; the padding lanes repeat the last one)
 * into out[l] and face[l], for any camera and any corners at infinity, as
 * triangle_setup.c describes it. Lanes hold one triangle each and never mix, and
 * the operations are IEEE single floats in a fixed order (no FMA), so every width
 * gives the same bits. A culled triangle's out[l] is not written. */
#define V3 RR_CAT(setup_v3_, W)

/* W three-vectors, one per lane, and the vec3.h operations on them. */
typedef struct {
  VF x, y, z;
} V3;
#define SPLAT3(v) ((V3){VF_(splat)((v).x), VF_(splat)((v).y), VF_(splat)((v).z)})
#define SUB3(a, b) ((V3){(a).x - (b).x, (a).y - (b).y, (a).z - (b).z})
#define ADD3(a, b) ((V3){(a).x + (b).x, (a).y + (b).y, (a).z + (b).z})
#define NEG3(a) ((V3){-(a).x, -(a).y, -(a).z})
#define SCALE3(a, s) ((V3){(a).x * (s), (a).y * (s), (a).z * (s)})
#define DOT3(a, b) ((a).x * (b).x + (a).y * (b).y + (a).z * (b).z)
#define CROSS3(a, b) \
  ((V3){(a).y * (b).z - (a).z * (b).y, (a).z * (b).x - (a).x * (b).z, (a).x * (b).y - (a).y * (b).x})
#define SELECT3(m, a, b) \
  ((V3){VF_(select)(m, (a).x, (b).x), VF_(select)(m, (a).y, (b).y), VF_(select)(m, (a).z, (b).z)})
/* lex_less(a, b) and lex_positive(g1, g2, g3) as masks, with the scalar comparisons' NaN behaviour */
#define LEX_LESS3(a, b) \
  VI_(select)((a).x != (b).x, (a).x < (b).x, VI_(select)((a).y != (b).y, (a).y < (b).y, (a).z < (b).z))
#define LEX_POSITIVE(g1, g2, g3) \
  (((g1) > zero) | (((g1) == zero) & (((g2) > zero) | (((g2) == zero) & ((g3) > zero)))))

TARGET static inline void RR_CAT(setup_lanes, W)(const rr_scene *s, const uint32_t *ids, int count, const camera *c,
                                                 bool cull, tri_setup *out, int *face) {
  int32_t lane_id[W], lane_inf[W] = {0};
  for (int l = 0; l < W; l++) lane_id[l] = (int32_t)ids[l < count ? l : count - 1];
  if (s->inf)
    for (int l = 0; l < W; l++) lane_inf[l] = s->inf[lane_id[l]];
  const VI idx = VI_(load)(lane_id), inf = VI_(load)(lane_inf);
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f);
  const V3 zero3 = {zero, zero, zero};
  /* q: the corner relative to the eye, or its direction when it is at infinity */
  V3 q[3];
  VI at_inf[3] = {VI_(splat)(0), VI_(splat)(0), VI_(splat)(0)};
#pragma GCC unroll 3
  for (int k = 0; k < 3; k++) {
    V3 p = {VF_(gather)(s->p[k][0], idx), VF_(gather)(s->p[k][1], idx), VF_(gather)(s->p[k][2], idx)};
    q[k] = SUB3(p, SPLAT3(c->eye));
    if (s->inf) {
      at_inf[k] = -((inf >> k) & 1);
      q[k] = SELECT3(at_inf[k], p, q[k]);
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
  VF vol = DOT3(q[0], n[0]), vol_x = zero, vol_y = zero, orient = vol;
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
  const int lanes = (1 << count) - 1;
  const int front_m = VI_(bits)(front) & lanes, kept = VI_(bits)(seen & (cull ? front : VI_(splat)(-1))) & lanes;
  if (!kept) {
    for (int l = 0; l < count; l++) face[l] = SETUP_CULLED;
    return;
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
  VF w[3];
  for (int k = 0; k < 3; k++) w[k] = VF_(select)(at_inf[k], zero, one);
  for (int l = 0; l < count; l++) {
    face[l] = !(kept >> l & 1) ? SETUP_CULLED : front_m >> l & 1 ? SETUP_FRONT : SETUP_BACK;
    if (face[l] == SETUP_CULLED) continue;
    tri_setup *o = &out[l];
    for (int e = 0; e < 3; e++) o->a[e] = ea[e][l], o->b[e] = eb[e][l], o->c[e] = ec[e][l];
    o->vol = vol[l], o->vol_x = vol_x[l], o->vol_y = vol_y[l];
    o->tie = (uint32_t)tie[l];
    for (int k = 0; k < 3; k++) o->w[k] = w[k][l];
  }
}

#undef SPLAT3
#undef SUB3
#undef ADD3
#undef NEG3
#undef SCALE3
#undef DOT3
#undef CROSS3
#undef SELECT3
#undef LEX_LESS3
#undef LEX_POSITIVE
#undef V3
