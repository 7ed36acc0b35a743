/* The spherical triangles and caps of four set-up triangles at once
 * (rr_tri_spheres, prim/triangle_curved.c includes this once per target: SPH_NAME,
 * SPH_TARGET, SPH_SQRT). Lanes of doubles (GCC vectors) with the operations, order
 * and comparisons of the one-lane argument in triangle_curved.c's comments (no FMA
 * in the build, sqrt correctly rounded at any width), so every lane holds the bits
 * a scalar evaluation would: the proofs there carry over unchanged. A lane that
 * fails a test only clears its ok or cap; its NaNs go nowhere. Four lanes, not
 * eight: a leaf's setups keep about three. nv (may be NULL): the normals and
 * vertices, for the arcs, and the chart's triangle (gx, gt; else gt infinite). pc (may be NULL): a parabolic camera, whose cap images
 * (cap_extent) the lanes compute too, in its order. */
SPH_TARGET static void SPH_NAME(const tri_setup *ts, int n, const camera *pc, tri_sphere *out, double (*nv)[2][3][3]) {
  vd4 nrm[3][3], v[3][3]; /* [edge or vertex][axis] */
  vl4 ok = vl_splat(-1);
  for (int i = 0; i < 3; i++) {
    for (int l = 0; l < 4; l++) {
      const tri_setup *t = &ts[l < n ? l : n - 1]; /* padding lanes repeat the last */
      nrm[i][0][l] = t->a[i], nrm[i][1][l] = t->b[i], nrm[i][2][l] = t->c[i];
    }
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
  vd4 gx[3][3], gt2 = vd_splat(0);
  memset(gx, 0, sizeof gx);
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
  /* cap_extent's parabolic image of the cap: the centre's stereographic image,
   * the radius ρ / (1 + cmin), and 0 for a cap behind the disk's rim */
  vd4 ext[4] = {0};
  vl4 img = vl_splat(TRI_CAP_UNSET);
  if (pc) {
    const double W = pc->width, H = pc->height;
    vd4 mr = m[0] * (double)pc->right.x + m[1] * (double)pc->right.y + m[2] * (double)pc->right.z;
    vd4 mu = m[0] * (double)pc->up.x + m[1] * (double)pc->up.y + m[2] * (double)pc->up.z;
    vd4 ca = m[0] * (double)pc->fwd.x + m[1] * (double)pc->fwd.y + m[2] * (double)pc->fwd.z;
    vd4 sa = SPH_SQRT(vmax(vd_splat(0), 1 - ca * ca)), q = 1 - rho * rho / 2;
    vl4 front = ca >= 0;
    vd4 cmax = ca * vsel(front, vd_splat(1), q) + sa * rho, cmin = ca * vsel(front, q, vd_splat(1)) - sa * rho;
    vd4 u = mr / (1 + ca), vv = mu / (1 + ca), rad = rho / (1 + cmin);
    ext[0] = (u - rad + 1) * W / 2, ext[1] = (u + rad + 1) * W / 2;
    ext[2] = (1 - vv - rad) * H / 2, ext[3] = (1 - vv + rad) * H / 2;
    img = vsel_l(1 + cmin > 1e-3, vl_splat(1), vl_splat(-1));
    img = vsel_l(cmax < -1e-3, vl_splat(0), img);
    img = vsel_l(rho < 1.5, img, vl_splat(-1));
  }
  for (int l = 0; l < n; l++) {
    tri_sphere *o = &out[l];
    o->img_k = (int8_t)img[l];
    for (int k = 0; k < 4 && pc; k++) o->img[k] = ext[k][l];
    for (int i = 0; i < 3 && nv; i++)
      for (int k = 0; k < 3; k++) nv[l][0][i][k] = nrm[i][k][l], nv[l][1][i][k] = v[i][k][l];
    for (int k = 0; k < 3; k++) o->axis[k] = m[k][l];
    for (int i = 0; i < 3 && nv; i++)
      for (int k = 0; k < 3; k++) o->gx[i][k] = gx[i][k][l];
    o->gt = nv ? gt[l] : INFINITY;
    o->smin = smin[l], o->E = E[l], o->rho = rho[l];
    o->ok = ok[l] != 0, o->cap = ok[l] && cap[l];
  }
}
