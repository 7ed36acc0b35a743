/* Tight image rectangles of set-up triangles in the curved views whose maps are
 * polar about an axis (issue 19): lat-long (axis up: latitude θ, longitude φ),
 * parabolic and fisheye (axis fwd: the image radius grows with the angle α from
 * it, the polar angle ψ is the direction's). The bound comes from the spherical
 * triangle the edge test passes in, through its vertices and the extremes of its
 * edges, each a great-circle arc, in closed form.
 *
 * Why it is conservative. A sample passes only where every computed edge value
 * e_i = a_i·w.x + b_i·w.y + c_i·w.z is >= 0; three roundings put it within
 * 3u·Σ|n_i,k w_k| <= 3u·|n_i||w| of n_i·w (n_i = (a_i, b_i, c_i), Cauchy–Schwarz),
 * so the unit direction ŵ has n̂_i·ŵ >= -2e-7. The stored ray lies within ~1e-6
 * rad of the exact direction of its sample (a few float roundings of unit vectors).
 * Offsetting the three great circles of the spherical triangle T = {n_i·d >= 0}
 * outwards by ε moves each vertex along its bisector by ε / sin(θ_i / 2) (θ_i the
 * interior angle), and the offset triangle lies within that distance of T; so the
 * exact direction of a passing sample lies within E = 2ε / sin(θ_min / 2) + ε of
 * T with ε = 1e-5 (the factor 2 covers the sphere's second-order terms). The
 * angle α from the axis changes by at most E over that distance, the polar angle
 * ψ by at most 2E / sin α away from the axis; so the samples lie in
 * α ∈ [α_min − E, α_max + E], ψ within the swept range ± 2E / sin α_lo, and their
 * image in the bounding box of that annular sector (or of the whole disk, or the
 * whole width for the lat-long, near the axis or across the seam). */
#include "prim/triangle.h"

#include <math.h>

typedef struct dv3 { double x, y, z; } dv3;
static dv3 dv(double x, double y, double z) { return (dv3){x, y, z}; }
static dv3 dvf(vec3 v) { return dv(v.x, v.y, v.z); }
static double ddot(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv3 dcross(dv3 a, dv3 b) { return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static dv3 dscale(dv3 a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static dv3 dsub(dv3 a, dv3 b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static double dlen(dv3 a) { return sqrt(ddot(a, a)); }

static double maxd(double a, double b) { return a > b ? a : b; } /* fmax is a call without -ffast-math */
static double mind(double a, double b) { return a < b ? a : b; }
static double wrap_pi(double a) { return a > RR_PI ? a - 2 * RR_PI : a < -RR_PI ? a + 2 * RR_PI : a; }

/* The spherical triangle's angles about unit axis P, with polar angle
 * atan2(d·e2, d·e1): α in [*alo, *ahi], ψ in [*plo, *phi] (plo > phi: any ψ),
 * all widened as the comment at the top argues. nu: the edges' unit normals. */
static void polar_range(const dv3 nu[3], const dv3 v[3], double E, dv3 P, dv3 e1, dv3 e2, double *alo, double *ahi,
                        double *plo, double *phi) {
  double cmax = -1, cmin = 1; /* P·d over T */
  bool has_p = true, has_m = true; /* P (−P) inside T, with a margin */
  double pv[3];
  for (int i = 0; i < 3; i++) {
    double s = ddot(nu[i], P);
    has_p &= s >= -1e-6, has_m &= s <= 1e-6;
    pv[i] = ddot(v[i], P);
    cmax = maxd(cmax, pv[i]), cmin = mind(cmin, pv[i]);
  }
  /* Each edge is the minor arc from a = v[i+1] to b = v[i+2] in the plane of nu[i].
   * P·d along the great circle peaks at ±P's projection on the plane, |P_p|; that
   * counts when it lies on the arc (taking it when in doubt only loosens). */
  for (int i = 0; i < 3 && !(has_p && has_m); i++) {
    dv3 a = v[(i + 1) % 3], b = v[(i + 2) % 3], ab = dcross(a, b);
    dv3 lp = dsub(P, dscale(nu[i], ddot(P, nu[i])));
    double len = dlen(lp), tol = -1e-9 * len * dlen(ab);
    double s1 = ddot(dcross(a, lp), ab), s2 = ddot(dcross(lp, b), ab);
    if (s1 >= tol && s2 >= tol) cmax = maxd(cmax, len);
    if (-s1 >= tol && -s2 >= tol) cmin = mind(cmin, -len);
  }
  if (has_p) cmax = 1;
  if (has_m) cmin = -1;
  *alo = maxd(0.0, acos(mind(1.0, cmax)) - E), *ahi = mind(RR_PI, acos(maxd(-1.0, cmin)) + E);
  *plo = 1, *phi = 0; /* any ψ */
  const double near_axis = 2e-3;
  double lo = mind(*alo, RR_PI - *ahi);
  if (lo < near_axis) return;
  /* ψ sweeps monotonically along an arc that keeps away from the axis, by less
   * than π; three sweeps summing to ±2π would circle the axis (caught above). */
  double ps[3];
  for (int k = 0; k < 3; k++) ps[k] = atan2(ddot(v[k], e2), ddot(v[k], e1));
  double p = ps[0], mn = p, mx = p;
  for (int k = 1; k <= 3; k++) {
    double d = wrap_pi(ps[k % 3] - ps[k - 1]);
    if (fabs(d) > RR_PI - 1e-3) return;
    p += d, mn = mind(mn, p), mx = maxd(mx, p);
  }
  if (fabs(p - ps[0]) > 1.0) return; /* circles the axis */
  double m = 2 * E / sin(lo);
  if (mx - mn + 2 * m >= 2 * RR_PI) return;
  *plo = mn - m, *phi = mx + m;
}

int rr_tri_curved_rect(const camera *c, const tri_setup *ts, int r[4]) {
  if (c->type != RR_CAMERA_LATLONG && c->type != RR_CAMERA_PARABOLIC && c->type != RR_CAMERA_FISHEYE) return -1;
  dv3 n[3], v[3];
  for (int i = 0; i < 3; i++) n[i] = dv(ts->a[i], ts->b[i], ts->c[i]);
  /* T's vertices: vertex i lies on edges i+1 and i+2, inside edge i. Its interior
   * angle θ_i is the angle between the inward normals' planes: cos θ_i = −n̂_j·n̂_k. */
  double cmin_half = 1; /* the least 1 − cos θ_i: 2 sin²(θ_i / 2) */
  for (int i = 0; i < 3; i++) {
    double l = dlen(n[i]);
    if (!(l > 0)) return -1;
    n[i] = dscale(n[i], 1 / l);
  }
  for (int i = 0; i < 3; i++) {
    dv3 nj = n[(i + 1) % 3], nk = n[(i + 2) % 3], x = dcross(nj, nk);
    double lx = dlen(x), s = ddot(x, n[i]);
    if (!(lx > 0) || !(fabs(s) > 1e-9 * lx)) return -1;
    v[i] = dscale(x, (s > 0 ? 1 : -1) / lx);
    cmin_half = mind(cmin_half, 1 + ddot(nj, nk));
  }
  double smin = sqrt(maxd(0.0, 0.5 * cmin_half)); /* sin(θ_min / 2) */
  if (!(smin > 1e-6)) return -1; /* E below 0.02 rad until 1e-3, then growing: a sliver */
  const double eps = 1e-5, E = 2 * eps / smin + eps;
  dv3 R = dvf(c->right), U = dvf(c->up), F = dvf(c->fwd);
  double alo, ahi, plo, phi, W = c->width, H = c->height;
  double x0, x1, y0, y1; /* sample coordinates */
  if (c->type == RR_CAMERA_LATLONG) {
    polar_range(n, v, E, U, F, R, &alo, &ahi, &plo, &phi);
    /* φ = 2π sx / W − π, θ = π sy / H; across the seam: the whole width */
    bool all = plo > phi || plo < -RR_PI || phi > RR_PI;
    x0 = all ? 0 : (plo + RR_PI) * W / (2 * RR_PI), x1 = all ? W : (phi + RR_PI) * W / (2 * RR_PI);
    y0 = alo * H / RR_PI, y1 = ahi * H / RR_PI;
  } else {
    polar_range(n, v, E, F, R, U, &alo, &ahi, &plo, &phi);
    /* image radius ρ(α) in u, v ∈ [-1, 1]: tan(α/2), or α over the fisheye's half angle */
    double k = c->fov_deg * RR_PI / 360, amax = c->type == RR_CAMERA_PARABOLIC ? RR_PI / 2 : k;
    if (alo > amax + 1e-3) return 0; /* beyond the disk: no rays */
    ahi = mind(ahi, amax + 1e-3);
    double r0 = c->type == RR_CAMERA_PARABOLIC ? tan(alo / 2) : alo / k;
    double r1 = c->type == RR_CAMERA_PARABOLIC ? tan(ahi / 2) : ahi / k;
    double u0 = -r1, u1 = r1, v0 = -r1, v1 = r1;
    if (plo <= phi) { /* the annular sector's box: its corners and the axes it crosses */
      u0 = v0 = INFINITY, u1 = v1 = -INFINITY;
      double cs[2] = {cos(plo), cos(phi)}, sn[2] = {sin(plo), sin(phi)};
      for (int k2 = 0; k2 < 4; k2++) {
        double cp = cs[k2 & 1], sp = sn[k2 & 1], rr = k2 & 2 ? r1 : r0;
        u0 = mind(u0, rr * cp), u1 = maxd(u1, rr * cp), v0 = mind(v0, rr * sp), v1 = maxd(v1, rr * sp);
      }
      for (int q = (int)floor(plo / (RR_PI / 2)) + 1; q * (RR_PI / 2) <= phi; q++) {
        int m = ((q % 4) + 4) % 4; /* ψ = qπ/2: +u, +v, −u, −v */
        if (m == 0) u1 = maxd(u1, r1);
        else if (m == 1) v1 = maxd(v1, r1);
        else if (m == 2) u0 = mind(u0, -r1);
        else v0 = mind(v0, -r1);
      }
    }
    /* u = 2 sx / W − 1, v = 1 − 2 sy / H */
    x0 = (u0 + 1) * W / 2, x1 = (u1 + 1) * W / 2, y0 = (1 - v1) * H / 2, y1 = (1 - v0) * H / 2;
  }
  /* sample x + sx0 in [x0, x1], with a hundredth of a pixel against the double rounding */
  double lx = ceil(x0 - c->sx0 - 1e-2), hx = floor(x1 - c->sx0 + 1e-2);
  double ly = ceil(y0 - c->sy0 - 1e-2), hy = floor(y1 - c->sy0 + 1e-2);
  lx = maxd(lx, 0), ly = maxd(ly, 0), hx = mind(hx, W - 1), hy = mind(hy, H - 1);
  if (!(lx <= hx && ly <= hy)) return 0;
  r[0] = (int)lx, r[1] = (int)ly, r[2] = (int)hx, r[3] = (int)hy;
  return smin > 1e-3 ? 1 : 2;
}
