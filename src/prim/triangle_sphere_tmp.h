/* The spherical triangles and caps of four set-up triangles at once
 * (rr_tri_spheres, prim/triangle_curved.c includes this once per target: SPH_NAME,
 * SPH_TARGET, SPH_SQRT). Lanes of doubles (GCC vectors) with the operations, order
 * and comparisons of the one-lane argument in triangle_curved.c's comments (no FMA
 * in the build, sqrt correctly rounded at any width), so every lane holds the bits
 * a scalar evaluation would: the proofs there carry over unchanged. A lane that
 * fails a test only clears its ok or cap; its NaNs go nowhere. Four lanes, not
 * eight: a leaf's setups keep about three. nv (may be NULL): the normals and
 * vertices, for the arcs. */
SPH_TARGET static void SPH_NAME(const tri_setup *ts, int n, tri_sphere *out, double (*nv)[2][3][3]) {
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
  for (int l = 0; l < n; l++) {
    tri_sphere *o = &out[l];
    for (int i = 0; i < 3 && nv; i++)
      for (int k = 0; k < 3; k++) nv[l][0][i][k] = nrm[i][k][l], nv[l][1][i][k] = v[i][k][l];
    for (int k = 0; k < 3; k++) o->axis[k] = m[k][l];
    o->smin = smin[l], o->E = E[l], o->rho = rho[l];
    o->ok = ok[l] != 0, o->cap = ok[l] && cap[l];
  }
}
