/* The spherical triangles and caps of four set-up triangles at once
 * (rr_tri_spheres), and the images of four caps (cap_lanes); prim/triangle_curved.c
 * includes this once per target (SPH_NAME, SPH_CAT, SPH_TARGET, SPH_SQRT). Lanes of
 * doubles (GCC vectors) with the operations, order and comparisons of the one-lane
 * argument in triangle_curved.c's comments (no FMA in the build, sqrt correctly
 * rounded at any width), so every lane holds the bits a one-lane call gives (the
 * width does not change them): the proofs there hold lane by lane. */
/* atan2 (fast_atan2's operations, lane by lane; a macro: see vd_splat) */
#ifndef SPH_ATAN2
#define SPH_ATAN2(y_, x_)                                                                                         \
  ({                                                                                                              \
    const vd4 y = (y_), x = (x_), ax = vabs(x), ay = vabs(y);                                                     \
    const vl4 xa = ax > ay;                                                                                       \
    const vd4 hi = vsel(xa, ax, ay), lo = vsel(xa, ay, ax), a = lo / hi, q = a * a;                               \
    vd4 r = ATAN01(a, q);                                                                                         \
    r = vsel(ay > ax, RR_PI / 2 - r, r);                                                                          \
    r = vsel(x < 0, RR_PI - r, r);                                                                                \
    r = vsel(y < 0, -r, r);                                                                                       \
    vsel(hi > 0, r, vd_splat(0));                                                                                 \
  })
#endif

/* The image extents e of caps about unit axes m of radii rho for a polar camera c,
 * in sample coordinates (x0, x1, y0, y1), what rr_tri_curved_cap's comment
 * proves; k: each lane's 1, 0 (no sample can look into it) or -1 (no bound). */
SPH_TARGET static void SPH_CAT(cap_lanes)(const camera *c, const vd4 m[3], const vd4 *rho_, vd4 e[4], vl4 *k_) {
  const vd4 rho = *rho_;
  const double W = c->width, H = c->height;
  const vd4 mr = m[0] * (double)c->right.x + m[1] * (double)c->right.y + m[2] * (double)c->right.z;
  const vd4 mu = m[0] * (double)c->up.x + m[1] * (double)c->up.y + m[2] * (double)c->up.z;
  const vd4 mf = m[0] * (double)c->fwd.x + m[1] * (double)c->fwd.y + m[2] * (double)c->fwd.z;
  const vd4 h = 1 - rho * rho / 2; /* <= cos ρ */
  vl4 k = vl_splat(1);
  if (c->type == RR_CAMERA_LATLONG) {
    const vd4 ct = mu, st = SPH_SQRT(vmax(vd_splat(0), 1 - ct * ct)), theta = SPH_ATAN2(st, ct);
    e[2] = (theta - rho - ATAN_ERR) * H / RR_PI, e[3] = (theta + rho + ATAN_ERR) * H / RR_PI;
    const vd4 slo = st * h - vabs(ct) * rho; /* least sin θ over the cap */
    const vd4 phi = SPH_ATAN2(mr, mf), dphi = rho / slo + ATAN_ERR;
    /* with a pole in the cap, or across the seam: the whole width */
    const vl4 part = (slo > 1e-6) & (rho / slo < RR_PI) & (phi - dphi >= -RR_PI) & (phi + dphi <= RR_PI);
    e[0] = vsel(part, (phi - dphi + RR_PI) * W / (2 * RR_PI), vd_splat(0));
    e[1] = vsel(part, (phi + dphi + RR_PI) * W / (2 * RR_PI), vd_splat(W));
  } else {
    const vd4 ca = mf, sa = SPH_SQRT(vmax(vd_splat(0), 1 - ca * ca));
    const vl4 front = ca >= 0;
    vd4 u, vv, rad;
    if (c->type == RR_CAMERA_PARABOLIC) {
      /* beyond the disk's rim by 1e-3 rad: no rays (cmax >= cos α over the cap) */
      const vd4 cmax = ca * vsel(front, vd_splat(1), h) + sa * rho, cmin = ca * vsel(front, h, vd_splat(1)) - sa * rho;
      u = mr / (1 + ca), vv = mu / (1 + ca), rad = rho / (1 + cmin);
      k = vsel_l(1 + cmin > 1e-3, k, vl_splat(-1));
      k = vsel_l(cmax < -1e-3, vl_splat(0), k);
    } else {
      const double kf = c->fov_deg * RR_PI / 360;
      const vd4 am = SPH_ATAN2(sa, ca);
      const vd4 s = sa * h + vmin(ca, vd_splat(0)) * rho; /* <= sin(α_m + ρ) */
      /* → 1 on the axis, where (mr, mu) → 0; am within ATAN_ERR of α_m: the centre's
       * image within ATAN_ERR / k of (u, v) */
      const vd4 f = vsel(sa > 1e-12, am / sa, vd_splat(1));
      u = f * mr / kf, vv = f * mu / kf, rad = (am + ATAN_ERR + rho) / (kf * s) * rho + ATAN_ERR / kf;
      k = vsel_l(s > 1e-3, k, vl_splat(-1));
      k = vsel_l(am - ATAN_ERR - rho > kf + 1e-3, vl_splat(0), k);
    }
    /* u = 2 sx / W − 1, v = 1 − 2 sy / H */
    e[0] = (u - rad + 1) * W / 2, e[1] = (u + rad + 1) * W / 2;
    e[2] = (1 - vv - rad) * H / 2, e[3] = (1 - vv + rad) * H / 2;
  }
  *k_ = vsel_l(rho < 1.5, k, vl_splat(-1));
}

/* A cap image e (x0, x1, y0, y1) as the sample rectangle sample_rect rounds it to,
 * at the position (sx, sy) and clipped to [lo.x, hi.x] × [lo.y, hi.y] (o: x0, y0,
 * x1, y1 in lanes; empty where x0 > x1 or y0 > y1; a NaN end taken as unbounded,
 * as ceil_in and floor_in take it). */
SPH_TARGET static inline void SPH_CAT(rect_lanes)(const vd4 e[4], double sx, double sy, const int lo[2],
                                                  const int hi[2], vd4 o[4]) {
  o[0] = vmax(SPH_CEIL(e[0] - sx - 1e-2), vd_splat(lo[0])), o[1] = vmax(SPH_CEIL(e[2] - sy - 1e-2), vd_splat(lo[1]));
  o[2] = vmin(SPH_FLOOR(e[1] - sx + 1e-2), vd_splat(hi[0])), o[3] = vmin(SPH_FLOOR(e[3] - sy + 1e-2), vd_splat(hi[1]));
}

/* The lanes of `used` whose cap (axis m, radius rho) may show a sample of r (x0,
 * y0, x1, y1, ends exclusive) at one of the ns positions cams[0..ns-1] (cameras
 * that differ only in sx0, sy0): cap_lanes knows no bound, or the rectangle
 * sample_rect rounds its image to meets r (the same rounding in lanes: that
 * rectangle meets r iff max(ceil(x0'), r.x0) <= min(floor(x1'), r.x1 - 1) per
 * axis, a NaN end taken as unbounded, as ceil_in and floor_in take it). A bit a lane. */
SPH_TARGET static unsigned SPH_CAT(caps_show)(const camera *cams, int ns, const vd4 m[3], const vd4 *rho,
                                              unsigned used, const int r[4]) {
  vd4 e[4];
  vl4 k;
  SPH_CAT(cap_lanes)(cams, m, rho, e, &k);
  vl4 show = k < 0;
  const int lo[2] = {r[0], r[1]}, hi[2] = {r[2] - 1, r[3] - 1};
  for (int p = 0; p < ns; p++) {
    vd4 q[4];
    SPH_CAT(rect_lanes)(e, cams[p].sx0, cams[p].sy0, lo, hi, q);
    show |= (k > 0) & (q[0] <= q[2]) & (q[1] <= q[3]);
  }
  unsigned bits = 0;
  for (int l = 0; l < 4; l++) bits |= (unsigned)(show[l] != 0) << l;
  return bits & used;
}

/* The lanes of `used` whose box (lo, hi: lanes per axis) may show a sample of r
 * at one of the ns positions: rr_cam_boxes_show4's argument (triangle_curved.c),
 * the box's ball's cap about b − eye of radius s / √(1 − s²) + 1e-4, s the ball's
 * radius over its distance; a box too near the eye (s² >= 0.98), or one that sc
 * takes as showing a sample, may. */
/* boxes_show's caps: each box's ball seen from the eye as a cap (axis m, radius
 * *rho); *near: the lanes whose box is too near the eye for one (s² >= 0.98). */
SPH_TARGET static inline void SPH_CAT(box_caps)(const camera *c, const float lo[3][4], const float hi[3][4], vd4 m[3],
                                                vd4 *rho, vl4 *near) {
  const double eye[3] = {c->eye.x, c->eye.y, c->eye.z};
  vd4 b[3], d2 = vd_splat(0), r2 = vd_splat(0);
  for (int a = 0; a < 3; a++) {
    vf4 lf, hf;
    memcpy(&lf, lo[a], sizeof lf), memcpy(&hf, hi[a], sizeof hf);
    const vd4 l = __builtin_convertvector(lf, vd4), h = __builtin_convertvector(hf, vd4);
    b[a] = 0.5 * (l + h) - eye[a], d2 += b[a] * b[a];
    r2 += 0.25 * (h - l) * (h - l);
  }
  const vd4 s2 = r2 * (1 + 1e-9) / d2;
  const vd4 inv = 1 / SPH_SQRT(d2);
  *rho = SPH_SQRT(s2 / (1 - s2)) + 1e-4;
  for (int a = 0; a < 3; a++) m[a] = b[a] * inv;
  *near = ~(s2 < 0.98);
}

SPH_TARGET static unsigned SPH_CAT(boxes_show)(const camera *cams, int ns, const float lo[3][4],
                                               const float hi[3][4], unsigned used, const cam_cap_shortcut *sc,
                                               const int r[4]) {
  vd4 m[3], rho;
  vl4 take;
  SPH_CAT(box_caps)(cams, lo, hi, m, &rho, &take);
  if (sc) {
    const vd4 mf = m[0] * (double)cams->fwd.x + m[1] * (double)cams->fwd.y + m[2] * (double)cams->fwd.z;
    take |= (rho >= sc->rho_min) & (mf >= sc->cos_min + rho * sc->sin_min);
  }
  unsigned bits = 0;
  for (int l = 0; l < 4; l++) bits |= (unsigned)(take[l] != 0) << l;
  bits &= used;
  if (bits == used) return used;
  return bits | SPH_CAT(caps_show)(cams, ns, m, &rho, used & ~bits, r);
}

/* A lane that fails a test only clears its ok or cap; its NaNs go nowhere. Four
 * lanes, not eight: a leaf's setups keep about three. nv (may be NULL): the normals
 * and vertices, for the arcs, and the chart's triangle (gx, gt; else gt infinite).
 * pc (may be NULL): a polar camera whose cap images (cap_lanes) to compute too. */
SPH_TARGET static void SPH_NAME(const tri_setup *ts, int n, const camera *pc, tri_sphere *out, double (*nv)[2][3][3]) {
  vd4 nrm[3][3], v[3][3]; /* [edge or vertex][axis] */
  vl4 ok = vl_splat(-1);
  const tri_setup *t[4]; /* padding lanes repeat the last */
  for (int l = 0; l < 4; l++) t[l] = &ts[l < n ? l : n - 1];
  for (int i = 0; i < 3; i++) {
    nrm[i][0] = (vd4){t[0]->a[i], t[1]->a[i], t[2]->a[i], t[3]->a[i]};
    nrm[i][1] = (vd4){t[0]->b[i], t[1]->b[i], t[2]->b[i], t[3]->b[i]};
    nrm[i][2] = (vd4){t[0]->c[i], t[1]->c[i], t[2]->c[i], t[3]->c[i]};
    vd4 l2 = vdot(nrm[i], nrm[i]);
    ok &= l2 > 0;
    vd4 inv = 1 / SPH_SQRT(l2);
    for (int k = 0; k < 3; k++) nrm[i][k] *= inv;
  }
  /* vertex i lies on edges i+1 and i+2, inside edge i; 1 + n̂_j·n̂_k = 2 sin²(θ_i / 2) */
  vd4 cmin_half = vd_splat(1);
  for (int i = 0; i < 3; i++) {
    const vd4 *nj = nrm[(i + 1) % 3], *nk = nrm[(i + 2) % 3];
    vd4 x[3];
    vcross(nj, nk, x);
    vd4 lx = SPH_SQRT(vdot(x, x)), s = vdot(x, nrm[i]);
    ok &= (lx > 0) & (vabs(s) > 1e-9 * lx);
    vd4 f = vsel(s > 0, vd_splat(1), vd_splat(-1)) / lx;
    for (int k = 0; k < 3; k++) v[i][k] = x[k] * f;
    cmin_half = vmin(cmin_half, 1 + vdot(nj, nk));
  }
  const vd4 smin = SPH_SQRT(vmax(vd_splat(0), 0.5 * cmin_half));
  ok &= smin > 1e-6;
  const double eps = 1e-5;
  const vd4 E = 2 * eps / smin + eps;
  /* the cap about the vertices' mean direction (curved_cap) */
  vd4 m[3];
  for (int k = 0; k < 3; k++) m[k] = v[0][k] + v[1][k] + v[2][k];
  const vd4 lm = SPH_SQRT(vdot(m, m));
  vl4 cap = lm > 1e-3;
  const vd4 il = 1 / lm;
  for (int k = 0; k < 3; k++) m[k] *= il;
  const vd4 cr = vmin(vdot(m, v[0]), vmin(vdot(m, v[1]), vdot(m, v[2])));
  cap &= cr > 0.1;
  const vd4 h2 = vmax(vd_splat(0), 2 - 2 * cr), rho = SPH_SQRT(h2 / (1 - h2 / 4)) + E + 1e-9;
  /* chart_extent's triangle: the vertices in the gnomonic chart about m
   * (v·m >= cr > 0.1 with the cap), each moved to where the edges through it,
   * shifted out by ε / cos ρ, meet (chart_extent's comment) */
  vd4 gx[3][3], gt2 = vd_splat(0); /* (with nv only) */
  const vd4 ec = eps / (1 - rho * rho / 2);
  for (int i = 0; i < 3 && nv; i++) { /* (rarely needed: with the arcs' normals and vertices only) */
    const vd4 *nj = nrm[(i + 1) % 3], *nk = nrm[(i + 2) % 3];
    vd4 jk[3], mx[3], dn[3];
    vcross(nj, nk, jk);
    for (int k = 0; k < 3; k++) dn[k] = nj[k] - nk[k];
    vcross(m, dn, mx);
    const vd4 iv = 1 / vdot(v[i], m), sh = -ec / vdot(m, jk);
    for (int k = 0; k < 3; k++) gx[i][k] = (v[i][k] * iv - m[k]) + mx[k] * sh;
    gt2 = vmax(gt2, vdot(gx[i], gx[i]));
  }
  const vd4 gt = vsel(rho < 1.3, SPH_SQRT(gt2), vd_splat(INFINITY));
  /* the cap's image for pc */
  vd4 ext[4] = {0};
  vl4 img = vl_splat(TRI_CAP_UNSET);
  if (pc) SPH_CAT(cap_lanes)(pc, m, &rho, ext, &img);
  /* rr_tri_curved_rect_sph's answer at pc's own position where the cap alone gives
   * it (no sample; or a round triangle's small rectangle, kept as it is), with
   * sample_rect's rounding (caps_show's comment) */
  vl4 dec = vl_splat(TRI_CAP_UNSET);
  vd4 rl[4] = {0};
  if (pc) {
    const int lo[2] = {0, 0}, hi[2] = {pc->width - 1, pc->height - 1};
    SPH_CAT(rect_lanes)(ext, pc->sx0, pc->sy0, lo, hi, rl);
    const vl4 some = (img == 1) & (rl[0] <= rl[2]) & (rl[1] <= rl[3]);
    const vd4 area = (rl[2] - rl[0] + 1) * (rl[3] - rl[1] + 1);
    const double most = pc->type == RR_CAMERA_PARABOLIC ? CAP_ENOUGH : CHART_FROM;
    const vl4 known = ok & cap & ((img == 0) | ((img == 1) & ~some) | (some & (smin > 1e-3) & (area <= most)));
    dec = vsel_l(known, some & 1, dec);
  }
  /* out of the lanes through memory, a row per quantity */
  int32_t ri[4][4]; /* the rectangles' bounds, where decided 1 (else 0: no conversion out of range) */
  int64_t kk[4][4];
  double ex[4][4], dd[7][4];
  const vd4 drow[7] = {m[0], m[1], m[2], smin, E, rho, nv ? gt : vd_splat(INFINITY)};
  const vl4 krow[4] = {img, dec, ok, ok & cap};
  for (int k = 0; k < 4; k++) {
    const vi4 q = __builtin_convertvector(vsel(dec == 1, rl[k], vd_splat(0)), vi4);
    memcpy(ri[k], &q, sizeof q), memcpy(ex[k], &ext[k], sizeof ex[k]), memcpy(kk[k], &krow[k], sizeof kk[k]);
  }
  memcpy(dd, drow, sizeof dd);
  for (int l = 0; l < n; l++) {
    tri_sphere *o = &out[l];
    o->img_k = (int8_t)kk[0][l], o->rect_k = (int8_t)kk[1][l], o->ok = kk[2][l] != 0, o->cap = kk[3][l] != 0;
    o->rect_sx = pc ? pc->sx0 : 0, o->rect_sy = pc ? pc->sy0 : 0;
    for (int k = 0; k < 4; k++) o->rect[k] = ri[k][l], o->img[k] = ex[k][l];
    for (int k = 0; k < 3; k++) o->axis[k] = dd[k][l];
    o->smin = dd[3][l], o->E = dd[4][l], o->rho = dd[5][l], o->gt = dd[6][l];
    for (int i = 0; i < 3 && nv; i++)
      for (int k = 0; k < 3; k++)
        nv[l][0][i][k] = nrm[i][k][l], nv[l][1][i][k] = v[i][k][l], o->gx[i][k] = gx[i][k][l];
  }
}
