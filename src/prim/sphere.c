/* The sphere kind (slides 003, ray–sphere): the sample test in double, bounds. */
#include "prim/analytic.h"

/* |o + t·d − C|² = r² with q = C − o: a·t² − 2b·t + cc = 0, a = d·d, b = d·q,
 * cc = q·q − r². The discriminant b² − a·cc cancels catastrophically near the
 * silhouette; it equals a·(r² − |f|²) with f = q − (b / a)·d the part of q
 * across the ray (the centre's offset from the ray's line), which does not
 * (the "geometric" form of the slides). The roots (b ± √D) / a are formed as
 * k / a and cc / k with k = b + sign(b)·√D, so neither subtracts nearly equal
 * numbers (their product is cc / a). The hit is the least positive root: the
 * near one from outside (cc > 0, both roots of b's sign), the far one from
 * inside (cc < 0, roots of opposite signs). A tangent ray (D = 0) hits. */
bool rr_ana_sphere_hit(const float *sp, const ana_ray *r, float *t, float *u, float *v) {
  const double *o = r->o, *d = r->d, rad = sp[3];
  double q[3] = {sp[0] - o[0], sp[1] - o[1], sp[2] - o[2]};
  double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  double b = d[0] * q[0] + d[1] * q[1] + d[2] * q[2];
  double s = b / a, f[3] = {q[0] - s * d[0], q[1] - s * d[1], q[2] - s * d[2]};
  double h2 = rad * rad - (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (!(h2 >= 0) || !(a > 0)) return false;
  double cc = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) - rad * rad;
  double k = b + copysign(sqrt(a * h2), b);
  if (k == 0) return false; /* both roots 0: the origin on the surface, the ray tangent there */
  double t1 = k / a, t2 = cc / k, th;
  if (t1 > 0 && t2 > 0) th = t1 < t2 ? t1 : t2;
  else if (t1 > 0) th = t1;
  else if (t2 > 0) th = t2;
  else return false;
  float tf = (float)th;
  if (!(tf > 0) || !(tf < INFINITY)) return false;
  double n[3];
  for (int x = 0; x < 3; x++) n[x] = (o[x] + th * d[x] - sp[x]) / rad;
  double ny = n[1] < -1 ? -1 : n[1] > 1 ? 1 : n[1];
  *t = tf;
  *u = (float)(atan2(n[0], n[2]) / (2 * RR_PI) + 0.5);
  *v = (float)(acos(ny) / RR_PI);
  return true;
}
