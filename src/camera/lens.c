/* OpenCV's lens models: Brown–Conrady (cv::projectPoints) and Kannala–Brandt
 * (cv::fisheye::projectPoints), forwards and inverted, in double. */
#include "camera/lens.h"

#include <math.h>

#include "core/vec.h"

/* Brown–Conrady's radial factor q(r²) and its derivative by r². */
static double radial(const float *k, double r2, double *dq) {
  double num = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4])), den = 1 + r2 * (k[5] + r2 * (k[6] + r2 * k[7]));
  double dnum = k[0] + r2 * (2 * k[1] + 3 * r2 * k[4]), dden = k[5] + r2 * (2 * k[6] + 3 * r2 * k[7]);
  if (dq) *dq = (dnum * den - num * dden) / (den * den);
  return num / den;
}

/* Kannala–Brandt: θd(θ) and its derivative. */
static double theta_d(const float *k, double th, double *dth) {
  double t2 = th * th;
  if (dth) *dth = 1 + t2 * (3 * k[0] + t2 * (5 * k[1] + t2 * (7 * k[2] + t2 * 9 * k[3])));
  return th * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

/* Brown–Conrady's radial map r·q(r²) and its derivative by r. */
static double radial_r(const float *k, double r, double *dr) {
  double dq, q = radial(k, r * r, &dq);
  *dr = q + 2 * r * r * dq;
  return r * q;
}

/* The x in [0, hi] where f, increasing there with f(0) = 0, reaches y < f(hi):
 * Newton's steps inside a shrinking bracket, bisection when a step would leave it
 * (quadratic convergence near the root, never lost). */
static double solve_increasing(double (*f)(const float *, double, double *), const float *k, double y, double hi) {
  double lo = 0, x = y < hi ? y : 0.5 * hi;
  for (int it = 0; it < 200 && y > 0; it++) {
    double d, e = f(k, x, &d) - y;
    if (e == 0) break;
    if (e < 0) lo = x;
    else hi = x;
    double next = d > 0 ? x - e / d : lo;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == x || hi - lo <= 1e-16 * hi) break;
    x = next;
  }
  return y > 0 ? x : 0;
}

/* Brown–Conrady forwards: the distorted point m of the undistorted (a, b), and its Jacobian. */
static void distort(const float *k, double a, double b, double m[2], double J[2][2]) {
  double r2 = a * a + b * b, dq, q = radial(k, r2, &dq), p1 = k[2], p2 = k[3];
  m[0] = a * q + 2 * p1 * a * b + p2 * (r2 + 2 * a * a);
  m[1] = b * q + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b;
  if (J) {
    J[0][0] = q + 2 * a * a * dq + 2 * p1 * b + 6 * p2 * a;
    J[0][1] = 2 * a * b * dq + 2 * p1 * a + 2 * p2 * b;
    J[1][0] = 2 * a * b * dq + 2 * p1 * a + 2 * p2 * b;
    J[1][1] = q + 2 * b * b * dq + 6 * p1 * b + 2 * p2 * a;
  }
}

/* The radius (or angle) where the radial map stops growing, scanned outwards in
 * steps of 1/1000 of it (relative), up to `limit`: beyond it the map folds back and
 * a distorted point has two preimages, so the rendered field stops there. */
double rr_lens_fold(const rr_camera *cam) {
  const float *k = cam->dist;
  bool fish = cam->type == RR_CAMERA_OPENCV_FISHEYE;
  double limit = fish ? RR_PI : 1e4, x = 0, prev = 0;
  for (double step = 1e-4; x < limit; x += step, step = fmax(1e-4, x * 1e-3)) {
    double next = x + step, f;
    if (fish) f = theta_d(k, next, NULL);
    else f = next * radial(k, next * next, NULL);
    if (!(f > prev) || !isfinite(f)) return x;
    prev = f;
  }
  return limit;
}

/* The undistorted (a, b) of distorted m: the radius first, on the monotone radial
 * map (solve_increasing: robust from any start), then Newton's method on the whole
 * map with the tangential terms, which converges quadratically from there for the
 * small tangential coefficients of real lenses. Stops when the residual is below
 * 1e-13 (relative); false when it does not get there in 40 steps, leaves [0, fold),
 * or lands where the map is not locally one-to-one. */
static bool undistort(const float *k, double fold, const double m[2], double p[2], double Jinv[2][2]) {
  double rd = sqrt(m[0] * m[0] + m[1] * m[1]), d;
  if (!(radial_r(k, fold, &d) > rd)) return false; /* beyond the fold's image */
  double r = solve_increasing(radial_r, k, rd, fold), s = rd > 0 ? r / rd : 1 / radial(k, 0, NULL);
  p[0] = m[0] * s, p[1] = m[1] * s;
  double tol = 1e-13 * (1 + rd);
  for (int it = 0; it < 40; it++) {
    double f[2], J[2][2];
    distort(k, p[0], p[1], f, J);
    double e0 = f[0] - m[0], e1 = f[1] - m[1], det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    if (!(det > 0)) return false;
    Jinv[0][0] = J[1][1] / det, Jinv[0][1] = -J[0][1] / det;
    Jinv[1][0] = -J[1][0] / det, Jinv[1][1] = J[0][0] / det;
    if (fabs(e0) + fabs(e1) <= tol) return p[0] * p[0] + p[1] * p[1] < fold * fold;
    p[0] -= Jinv[0][0] * e0 + Jinv[0][1] * e1;
    p[1] -= Jinv[1][0] * e0 + Jinv[1][1] * e1;
    if (!isfinite(p[0]) || !isfinite(p[1])) return false;
  }
  return false;
}

bool rr_lens_unproject(const rr_camera *cam, double fold, double u, double v, double dir[3], double ddir[2][3]) {
  const float *k = cam->dist;
  double m[2] = {(u - cam->cx) / cam->fx, (v - cam->cy) / cam->fy};
  double dm[2] = {1.0 / cam->fx, 1.0 / cam->fy}; /* dm0/du, dm1/dv */
  if (cam->type == RR_CAMERA_OPENCV_FISHEYE) {
    /* θ from θd on the monotone [0, fold) (solve_increasing); the ray is
     * (sin θ·e, cos θ) with e = m/|m| (polar form, as the equidistant fisheye). */
    double rd = sqrt(m[0] * m[0] + m[1] * m[1]), dth;
    if (!(theta_d(k, fold, NULL) > rd)) return false;
    double th = solve_increasing(theta_d, k, rd, fold);
    theta_d(k, th, &dth);
    if (!(th >= 0 && th < fold && dth > 0)) return false;
    double e[2] = {rd > 0 ? m[0] / rd : 1, rd > 0 ? m[1] / rd : 0}, st = sin(th), ct = cos(th);
    dir[0] = st * e[0], dir[1] = st * e[1], dir[2] = ct;
    if (ddir) {
      /* ∂dir/∂m = (1/θd')(cos θ e, −sin θ) ⊗ e + (sin θ / rd)(t, 0) ⊗ t, t ⊥ e; sin θ / rd → 1 at 0 */
      double g = 1 / dth, s = rd > 0 ? st / rd : 1, t[2] = {-e[1], e[0]};
      for (int j = 0; j < 2; j++) {
        double ej = e[j] * g, tj = t[j] * s;
        ddir[j][0] = (ct * e[0] * ej + t[0] * tj) * dm[j];
        ddir[j][1] = (ct * e[1] * ej + t[1] * tj) * dm[j];
        ddir[j][2] = -st * ej * dm[j];
      }
    }
    return true;
  }
  double p[2], Ji[2][2];
  if (!undistort(k, fold, m, p, Ji)) return false;
  double w[3] = {p[0], p[1], 1}, len = sqrt(p[0] * p[0] + p[1] * p[1] + 1);
  for (int i = 0; i < 3; i++) dir[i] = w[i] / len;
  if (ddir)
    for (int j = 0; j < 2; j++) { /* w's derivative by m_j is (Jinv[0][j], Jinv[1][j], 0); normalised */
      double dw[3] = {Ji[0][j] * dm[j], Ji[1][j] * dm[j], 0};
      double along = dir[0] * dw[0] + dir[1] * dw[1];
      for (int i = 0; i < 3; i++) ddir[j][i] = (dw[i] - dir[i] * along) / len;
    }
  return true;
}

bool rr_lens_project(const rr_camera *cam, const double p[3], double *u, double *v) {
  if (!(p[2] > 0)) return false;
  double a = p[0] / p[2], b = p[1] / p[2], m[2];
  if (cam->type == RR_CAMERA_OPENCV_FISHEYE) {
    double r = sqrt(a * a + b * b), td = theta_d(cam->dist, atan(r), NULL), s = r > 0 ? td / r : 1;
    m[0] = a * s, m[1] = b * s;
  } else {
    distort(cam->dist, a, b, m, NULL);
  }
  *u = cam->fx * m[0] + cam->cx, *v = cam->fy * m[1] + cam->cy;
  return true;
}

/* Intervals, for the distortion over a box of undistorted points (outward
 * rounding is left to the caller's margin: a few ulps of the largest term). */
typedef struct ival {
  double lo, hi;
} ival;
static ival iv(double lo, double hi) { return (ival){lo, hi}; }
static ival iadd(ival a, ival b) { return iv(a.lo + b.lo, a.hi + b.hi); }
static ival iscale(ival a, double s) { return s >= 0 ? iv(a.lo * s, a.hi * s) : iv(a.hi * s, a.lo * s); }
/* (comparisons, not fmin/fmax, which are library calls here: a NaN product, 0·∞,
 * in p[0] stays and makes the bound unusable, as it should; later ones are skipped
 * as fmin would) */
static ival imul(ival a, ival b) {
  double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi}, lo = p[0], hi = p[0];
  for (int i = 1; i < 4; i++) lo = p[i] < lo ? p[i] : lo, hi = p[i] > hi ? p[i] : hi;
  return iv(lo, hi);
}
static ival isq(ival a) {
  double l = a.lo * a.lo, h = a.hi * a.hi;
  return iv(a.lo > 0 ? l : a.hi < 0 ? h : 0, fmax(l, h));
}
/* 1 + x (c[0] + x (c[1] + ... + x c[n-1])), Horner's scheme in intervals */
static ival ipoly1(ival x, const double *c, int n) {
  ival p = iv(c[n - 1], c[n - 1]);
  for (int i = n - 2; i >= 0; i--) p = iadd(imul(p, x), iv(c[i], c[i]));
  return iadd(imul(p, x), iv(1, 1));
}

/* The range of x/z over the directions within angle ρ of the unit axis (a, ·, g),
 * all in front (g > sin ρ): the planes x = t·z through the y axis that touch the
 * cone have normals (1, 0, −t)/√(1 + t²) at ρ from a right angle to the axis,
 * (a − t g)² = sin²ρ (1 + t²), t = (a g ± s √(a² + g² − s²)) / (g² − s²), s = sin ρ. */
static ival cone_range(double a, double g, double s) {
  double den = g * g - s * s, root = s * sqrt(fmax(0.0, a * a + den));
  return iv((a * g - root) / den, (a * g + root) / den);
}

double rr_lens_field(const rr_camera *cam, double fold, int width, int height) {
  const float *k = cam->dist;
  double rd = 0, d; /* the image's farthest point from the centre: samples in [-0.5, W - 0.5] × [-0.5, H - 0.5] */
  for (int i = 0; i < 4; i++) {
    double u = (i & 1 ? width - 0.5 : -0.5) - cam->cx, v = (i & 2 ? height - 0.5 : -0.5) - cam->cy;
    rd = fmax(rd, sqrt(u * u / ((double)cam->fx * cam->fx) + v * v / ((double)cam->fy * cam->fy)));
  }
  rd *= 1 + 1e-9;
  if (cam->type == RR_CAMERA_OPENCV_FISHEYE) /* θ solves θd(θ) = |m| on the monotone [0, fold) */
    return theta_d(k, fold, NULL) > rd ? fmin(fold, solve_increasing(theta_d, k, rd, fold) * (1 + 1e-9) + 1e-9) : fold;
  /* without tangential terms undistort's |p| solves r q(r²) = |m| (its Newton steps start at the answer) */
  if (k[2] == 0 && k[3] == 0 && radial_r(k, fold, &d) > rd)
    return atan(fmin(fold, solve_increasing(radial_r, k, rd, fold) * (1 + 1e-9) + 1e-9));
  return atan(fold);
}

int rr_lens_cap_extent(const rr_camera *cam, double fold, double field, const double axis[3], double rho,
                       double e[4]) {
  const float *k = cam->dist;
  rho += 1e-6; /* the float basis the rays are made in is orthonormal to a few 1e-8 */
  if (field < RR_PI && acos(fmax(-1.0, fmin(1.0, axis[2]))) - rho > field + 1e-6) return 0;
  const double s = sin(rho);
  if (!(rho < 1.5) || !(axis[2] > s + 1e-3)) return -1; /* not wholly in front */
  ival a = cone_range(axis[0], axis[2], s), b = cone_range(axis[1], axis[2], s), m[2];
  a = iv(a.lo - 1e-12 * (1 + fabs(a.lo)), a.hi + 1e-12 * (1 + fabs(a.hi)));
  b = iv(b.lo - 1e-12 * (1 + fabs(b.lo)), b.hi + 1e-12 * (1 + fabs(b.hi)));
  ival r2 = iadd(isq(a), isq(b));
  double big = 1, ksum = 1; /* the sums' largest terms, for the rounding: (1 + Σ|k|)(1 + x)³ / den */
  for (int i = 0; i < 8; i++) ksum += fabs(k[i]);
  if (cam->type == RR_CAMERA_OPENCV_FISHEYE) {
    /* a pixel's m = θd(θ)/tan θ·(a, b), θ = atan |(a, b)| < fold: θd(θ)/θ a polynomial in
     * θ², θ/tan θ decreasing from 1 at 0 */
    ival th = iv(atan(sqrt(r2.lo)) * (1 - 1e-15), fmin(atan(sqrt(r2.hi)) * (1 + 1e-15), fold));
    if (!(th.lo < fold)) return 0;
    const double c[4] = {k[0], k[1], k[2], k[3]};
    ival q = imul(ipoly1(isq(th), c, 4), iv(th.hi > 0 ? th.hi / tan(th.hi) : 1, th.lo > 0 ? th.lo / tan(th.lo) : 1));
    m[0] = imul(a, q), m[1] = imul(b, q);
    big = pow(1 + th.hi * th.hi, 3);
  } else {
    /* distort() in intervals, r² < fold² (undistort's condition for a ray) */
    if (!(r2.lo < fold * fold)) return 0;
    r2.hi = fmin(r2.hi, fold * fold);
    const double cn[3] = {k[0], k[1], k[4]}, cd[3] = {k[5], k[6], k[7]};
    ival num = ipoly1(r2, cn, 3), den = ipoly1(r2, cd, 3);
    if (!(den.lo > 0)) return -1;
    ival q = imul(num, iv(1 / den.hi, 1 / den.lo)), ab = iscale(imul(a, b), 2);
    m[0] = iadd(iadd(imul(a, q), iscale(ab, k[2])), iscale(iadd(r2, iscale(isq(a), 2)), k[3]));
    m[1] = iadd(iadd(imul(b, q), iscale(iadd(r2, iscale(isq(b), 2)), k[2])), iscale(ab, k[3]));
    big = pow(1 + r2.hi, 3) / den.lo;
  }
  big *= 1e-14 * ksum * (1 + fmax(fabs(a.lo), fabs(a.hi)) + fmax(fabs(b.lo), fabs(b.hi)));
  /* sample coordinates: the image point plus 0.5 (rr_lens_unproject's pixel centres
   * at integers); the margin covers the rounding (relative to the products, and
   * `big` for the sums' cancellation) and undistort's residual (1e-13 of m) */
  const double f[2] = {cam->fx, cam->fy}, cc[2] = {cam->cx + 0.5, cam->cy + 0.5};
  for (int j = 0; j < 2; j++) {
    ival p = iscale(m[j], f[j]);
    double mg = 1e-9 * (fabs(p.lo) + fabs(p.hi) + f[j]) + big * f[j];
    e[2 * j] = p.lo + cc[j] - mg, e[2 * j + 1] = p.hi + cc[j] + mg;
    if (!isfinite(e[2 * j]) || !isfinite(e[2 * j + 1])) return -1;
  }
  return 1;
}
