/* The infinite-plane kind (slides 003, ray–plane): the sample test in double. */
#include "prim/analytic.h"

void rr_ana_plane_axes(const float nf[3], double u[3], double v[3]) {
  double n[3] = {nf[0], nf[1], nf[2]};
  /* u: across n in the plane of its two largest components (never near zero), v = n × u */
  double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
  double w[3] = {0, 0, 0};
  if (ax <= ay && ax <= az) w[1] = n[2], w[2] = -n[1];
  else if (ay <= az) w[0] = -n[2], w[2] = n[0];
  else w[0] = n[1], w[1] = -n[0];
  double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  for (int k = 0; k < 3; k++) u[k] = w[k] / l;
  v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
}

/* t = n·(P − o) / n·d: both sides, hit where t > 0 (a ray in the plane, n·d = 0,
 * gives no finite t and misses, as does an origin on the plane, t = 0). */
bool rr_ana_plane_hit(const float *pl, const ana_ray *r, float *t, float *u, float *v) {
  const double *o = r->o, *d = r->d;
  double den = pl[3] * d[0] + pl[4] * d[1] + pl[5] * d[2];
  double num = pl[3] * (pl[0] - o[0]) + pl[4] * (pl[1] - o[1]) + pl[5] * (pl[2] - o[2]);
  double th = num / den;
  float tf = (float)th;
  if (!(tf > 0) || !(tf < INFINITY)) return false;
  double ua[3], va[3], p[3];
  rr_ana_plane_axes(pl + 3, ua, va);
  for (int k = 0; k < 3; k++) p[k] = o[k] + th * d[k] - pl[k];
  *t = tf;
  *u = (float)(p[0] * ua[0] + p[1] * ua[1] + p[2] * ua[2]);
  *v = (float)(p[0] * va[0] + p[1] * va[1] + p[2] * va[2]);
  return true;
}
