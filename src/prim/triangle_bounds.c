/* Triangle bounds for a camera: which samples a set-up triangle may cover (screen
 * rectangles, cones of curved views) and the least t it can give (paper sect. 3.2, 5).
 * A triangle that crosses the eye plane has no bounded projection and is bounded by
 * the whole screen; 3D edge functions need no clipping for that. */
#include "prim/triangle.h"
#include "core/simd.h"

#include <string.h>

/* Curved views: does a cone of directions (unit axis, half-angle) miss the
 * triangle's directions? Two conservative tests: the triangle's bounding cap
 * (tight for small triangles), and the four planes through the eye a hit must lie
 * inside of: V_i >= 0 for the three edges and Σw_iV_i > 0 (t > 0). */
bool rr_cone_excludes(const tri_cone *tc, const tri_setup *ts, vec3 axis, float angle) {
  if (tc->cap_angle >= 0 && acosf(fminf(1.0f, v3_dot(axis, tc->cap_axis))) > angle + tc->cap_angle + 1e-5f)
    return true;
  float lim = sinf(angle) + 1e-5f, sum = 0;
  for (int e = 0; e < 3; e++) {
    float v = ts->a[e] * axis.x + ts->b[e] * axis.y + ts->c[e] * axis.z;
    if (v < -tc->len[e] * lim) return true;
    sum += v * ts->w[e];
  }
  return sum < -tc->len[3] * lim;
}

void rr_tri_cone_setup(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, tri_cone *tc) {
  for (int e = 0; e < 3; e++) tc->len[e] = sqrtf(ts->a[e] * ts->a[e] + ts->b[e] * ts->b[e] + ts->c[e] * ts->c[e]);
  const float *w = ts->w; /* the sum that must be positive is Σ w_i V_i */
  float sx = ts->a[0] * w[0] + ts->a[1] * w[1] + ts->a[2] * w[2];
  float sy = ts->b[0] * w[0] + ts->b[1] * w[1] + ts->b[2] * w[2];
  float sz = ts->c[0] * w[0] + ts->c[1] * w[1] + ts->c[2] * w[2];
  /* the sum is evaluated edge by edge: allow for the rounding of each term too */
  tc->len[3] = sqrtf(sx * sx + sy * sy + sz * sz) + 1e-6f * (tc->len[0] + tc->len[1] + tc->len[2]);
  /* A cap around the mean vertex direction holds the spherical triangle when its
   * radius is under 90° (caps that small are spherically convex). */
  vec3 u[3], m = v3(0, 0, 0);
  for (int k = 0; k < 3; k++) u[k] = v3_norm(scene_q(s, k, i, c->eye)), m = v3_add(m, u[k]);
  tc->cap_angle = -1;
  if (v3_len(m) > 1e-3f) {
    tc->cap_axis = v3_norm(m);
    /* the angle from the chord h: 2 asin(h/2) <= h / √(1 − h²/4) (asin x <= tan asin x),
     * without acos and its loss of accuracy near 1 */
    float h2 = 0;
    for (int k = 0; k < 3; k++) {
      vec3 d = v3_sub(u[k], tc->cap_axis);
      h2 = fmaxf(h2, v3_dot(d, d));
    }
    float r = h2 < 3.5f ? sqrtf(h2 / (1 - h2 / 4)) : CAMERA_NO_CONE;
    if (r < CAMERA_NO_CONE) tc->cap_angle = r * 1.0001f + 1e-5f;
  }
}

static bool curved_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int r[4]) {
  tri_cone tc;
  rr_tri_cone_setup(s, i, c, ts, &tc);
  int x0 = c->cells_x, y0 = c->cells_y, x1 = -1, y1 = -1;
  for (int cy = 0; cy < c->cells_y; cy++)
    for (int cx = 0; cx < c->cells_x; cx++) {
      const float *cell = c->cells + 4 * ((size_t)cy * c->cells_x + cx);
      if (cell[3] < 0) continue; /* no rays */
      if (cell[3] < CAMERA_NO_CONE && rr_cone_excludes(&tc, ts, v3(cell[0], cell[1], cell[2]), cell[3])) continue;
      x0 = cx < x0 ? cx : x0, x1 = cx > x1 ? cx : x1, y0 = cy < y0 ? cy : y0, y1 = cy > y1 ? cy : y1;
    }
  if (x1 < 0) return false;
  r[0] = x0 * CAMERA_CELL, r[1] = y0 * CAMERA_CELL;
  r[2] = (x1 + 1) * CAMERA_CELL - 1 < c->width - 1 ? (x1 + 1) * CAMERA_CELL - 1 : c->width - 1;
  r[3] = (y1 + 1) * CAMERA_CELL - 1 < c->height - 1 ? (y1 + 1) * CAMERA_CELL - 1 : c->height - 1;
  return true;
}

/* Planar cameras: the hull of the corners' projections. A point at infinity
 * projects to its vanishing point when its direction points ahead; the projection
 * of the segment from a point to it is then the segment to the vanishing point, so
 * the hull of the three still bounds the triangle. A triangle with a corner not
 * strictly ahead of the eye (or projecting to no finite point), or one with a
 * corner at infinity in an orthographic view, is bounded by the whole screen; one
 * with no corner ahead is unseen (every camera ray has d·fwd > 0). Sample
 * (x + sx0) lies in [x0, x1] for x in [ceil(x0 - sx0), floor(x1 - sx0)], widened
 * by a margin that covers the rounding of the projection and of the edge
 * functions, a few ulps of the larger coordinate (a whole pixel would double the
 * area of the small triangles of real meshes). */
#define RR_TEMPLATE "prim/triangle_bounds_tmp.h"
#include "core/simd_widths.h"

bool rr_tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int r[4]) {
  return rr_tri_screen_bounds_sph(s, i, c, ts, NULL, r);
}

bool rr_tri_screen_bounds_sph(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts,
                              const tri_sphere *sp, int r[4]) {
  if (c->planar) {
    tri_bound b;
    const float pos[1][2] = {{c->sx0, c->sy0}};
    if (!corner_bounds_any1(s, i, NULL, 1, c, 1, pos, &b)) return false;
    memcpy(r, b.bb, sizeof b.bb);
    return true;
  }
  /* Curved views have no straight-edged projection: the tight rectangle where it
   * is known, else the cells' cones; hemispheres see nothing wholly behind the eye plane. */
  int tight = sp ? rr_tri_curved_rect_sph(c, ts, sp, r) : rr_tri_curved_rect(c, ts, r);
  if (tight == 0 || tight == 1) return tight > 0;
  int behind = 0;
  for (int k = 0; k < 3; k++) behind += !(v3_dot(scene_q(s, k, i, c->eye), c->fwd) > 0);
  if (behind == 3 && c->type == RR_CAMERA_PARABOLIC) return false;
  int q[4];
  if (tight < 0) return curved_bounds(s, i, c, ts, r);
  /* a sliver's wide rectangle, and the cells': both hold its samples */
  if (!curved_bounds(s, i, c, ts, q)) return false;
  r[0] = q[0] > r[0] ? q[0] : r[0], r[1] = q[1] > r[1] ? q[1] : r[1];
  r[2] = q[2] < r[2] ? q[2] : r[2], r[3] = q[3] < r[3] ? q[3] : r[3];
  return r[0] <= r[2] && r[1] <= r[3];
}

uint32_t rr_tri_corner_bounds_at(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                                 int npos, const float (*pos)[2], bool simd, tri_bound *out) {
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2")) return corner_bounds_any8(s, first, ids, n, c, npos, pos, out);
#endif
  (void)simd;
  return corner_bounds_any1(s, first, ids, n, c, npos, pos, out);
}

uint32_t rr_tri_corner_bounds(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                              bool simd, tri_bound *out) {
  const float pos[1][2] = {{c->sx0, c->sy0}};
  return rr_tri_corner_bounds_at(s, first, ids, n, c, 1, pos, simd, out);
}

/* The least t that sample_test() can return for ts at any sample of camera c.
 *
 * Planar cameras evaluate e_i = a + sx·b + sy·c in float, with an error below
 * u_i = 4u·(|a| + |sx·b| + |sy·c|) (u = 2^-24, bounded over the image); a passing
 * sample has every computed e_i >= 0, so it lies in P = {E_i >= -u_i} for the
 * exact edge functions E_i of the setup values, and the computed sum is at most
 * (1+u)^2 Σ(E_i + u_i). That sum is affine, so its maximum over P is at a vertex
 * of P; at the vertex where E_i + u_i and E_j + u_j vanish it equals
 * det[a' b c] / (b_i·c_j - b_j·c_i) (Cramer; a' = a + u), and P is that bounded
 * triangle when the three values are positive; otherwise P clipped to the image
 * rectangle is a convex polygon and its vertices bound both. Curved cameras evaluate e_i = n_i·d with |d| at most
 * the camera's longest ray, so the sum is at most |Σn_i|·|d| plus the error. The
 * volume (constant but for orthographic views) is bounded below over the image
 * the same way, and t = vol·(1/sum) is at least vol·(1-u)^2 / max sum. P's
 * vertices also bound the samples where the triangle can pass: rect (x0, y0, x1,
 * y1; the whole plane when P is unbounded or the camera curved). Double
 * arithmetic carries a relative slack far above its own rounding. Points at
 * infinity: sample_test sums w_i·e_i with w_i in {0, 1} and every e_i >= 0 on P,
 * so the plain sum bounds it too (curved cameras use |Σ w_i n_i|).
 *
 * That floors V / Σ w_i V_i, the t of TRI_DEPTH's fallback; its usual t = num / den
 * gets a floor of its own (plane_floor) and the bound is the lesser. */
/* A floor under num / den wherever both are positive, over the samples of the
 * rectangle [x0, x1] × [y0, y1] (planar cameras; curved ones: directions up to
 * dmax long). num = num0 + X·num_x + Y·num_y and den = pa + X·pb + Y·pc with
 * X = sx − cx, Y = sy − cy are evaluated in float with three roundings per term,
 * within 4u of the sum of the terms' magnitudes; the least num and the largest
 * den over the rectangle are at its corners (affine forms), and the quotient
 * rounds once more. A floor of num at or below 0 floors t by 0; a largest den at
 * or below 0 means TRI_DEPTH's fallback always applies (+inf: no floor needed). */
static inline double lesser(double a, double b) { return a < b ? a : b; }
static inline double greater(double a, double b) { return a > b ? a : b; }
static double plane_floor(const tri_setup *ts, const camera *cam, double x0, double y0, double x1, double y1,
                          double dmax) {
  const double u = 0x1p-24;
  x0 -= ts->cx, x1 -= ts->cx, y0 -= ts->cy, y1 -= ts->cy;
  double mx = greater(fabs(x0), fabs(x1)), my = greater(fabs(y0), fabs(y1));
  double n0 = ts->num0, nx = ts->num_x, ny = ts->num_y, a = ts->pa, b = ts->pb, c = ts->pc, dhi;
  double nlo = n0 + lesser(x0 * nx, x1 * nx) + lesser(y0 * ny, y1 * ny) -
               4 * u * (fabs(n0) + mx * fabs(nx) + my * fabs(ny));
  if (cam->planar)
    dhi = a + greater(x0 * b, x1 * b) + greater(y0 * c, y1 * c) + 4 * u * (fabs(a) + mx * fabs(b) + my * fabs(c));
  else
    dhi = (sqrt(a * a + b * b + c * c) * (1 + 1e-12) + 4 * u * (fabs(a) + fabs(b) + fabs(c))) * dmax;
  if (!(dhi > 0)) return INFINITY;
  if (!(nlo > 0)) return 0;
  return nlo / dhi * (1 - 4 * u);
}

float rr_tri_bounds(const tri_setup *ts, const camera *cam, float rect[4]) {
  const double u = 0x1p-24, slack = 1e-12;
  int w = cam->width, h = cam->height;
  double smax = -INFINITY;
  double rx0 = -INFINITY, ry0 = -INFINITY, rx1 = INFINITY, ry1 = INFINITY;
  if (cam->planar) {
    double a[3], b[3], c[3];
    for (int i = 0; i < 3; i++) {
      b[i] = ts->b[i], c[i] = ts->c[i];
      a[i] = ts->a[i] + 4 * u * (fabs(ts->a[i]) + w * fabs(b[i]) + h * fabs(c[i]));
    }
    double m[3], mag_m[3];
    for (int k = 0; k < 3; k++) {
      int i = (k + 1) % 3, j = (k + 2) % 3;
      m[k] = b[i] * c[j] - b[j] * c[i], mag_m[k] = fabs(b[i] * c[j]) + fabs(b[j] * c[i]);
    }
    double det = a[0] * m[0] + a[1] * m[1] + a[2] * m[2];
    double mag_d = fabs(a[0]) * mag_m[0] + fabs(a[1]) * mag_m[1] + fabs(a[2]) * mag_m[2];
    /* Bounded when det and the three minors share a sign (either: it depends on
     * how the triangle's projection turns on screen), each clear of the slack. */
    double sg = det < 0 ? -1 : 1;
    bool bounded = sg * det > slack * mag_d;
    double vx[3], vy[3], ex[3], ey[3], den = INFINITY;
    for (int k = 0; k < 3 && bounded; k++) {
      bounded = sg * m[k] > slack * mag_m[k];
      if (!bounded) break;
      double d = sg * m[k] - slack * mag_m[k];
      den = d < den ? d : den;
      /* The vertex itself, where E_i + u_i = E_j + u_j = 0, with a generous error. */
      int i = (k + 1) % 3, j = (k + 2) % 3;
      double inv = 1.0 / m[k], ainv = fabs(inv);
      vx[k] = (-a[i] * c[j] + a[j] * c[i]) * inv, vy[k] = (b[j] * a[i] - b[i] * a[j]) * inv;
      ex[k] = 1e-9 * ((fabs(a[i] * c[j]) + fabs(a[j] * c[i])) * ainv + fabs(vx[k])) + 1e-6;
      ey[k] = 1e-9 * ((fabs(b[j] * a[i]) + fabs(b[i] * a[j])) * ainv + fabs(vy[k])) + 1e-6;
    }
    /* Σ(E + u) at the vertices is det/m_k: the largest has the smallest minor. */
    if (bounded) smax = (sg * det + slack * mag_d) / den;
    if (bounded) {
      rx0 = fmin(vx[0] - ex[0], fmin(vx[1] - ex[1], vx[2] - ex[2]));
      rx1 = fmax(vx[0] + ex[0], fmax(vx[1] + ex[1], vx[2] + ex[2]));
      ry0 = fmin(vy[0] - ey[0], fmin(vy[1] - ey[1], vy[2] - ey[2]));
      ry1 = fmax(vy[0] + ey[0], fmax(vy[1] + ey[1], vy[2] + ey[2]));
    }
    if (!bounded) {
      /* P unbounded (the triangle crosses the eye's plane) or nearly degenerate:
       * clip the image rectangle by its three half-planes, loosened by the slack,
       * and take the polygon's extent and its largest Σ(E + u). */
      double px[8] = {0, w, w, 0}, py[8] = {0, 0, h, h}, qx[8], qy[8];
      int np = 4;
      for (int i = 0; i < 3 && np; i++) {
        double A = a[i] + slack * (fabs(a[i]) + w * fabs(b[i]) + h * fabs(c[i]));
        int nq = 0;
        for (int k = 0; k < np; k++) {
          int l = (k + 1) % np;
          double fk = A + b[i] * px[k] + c[i] * py[k], fl = A + b[i] * px[l] + c[i] * py[l];
          if (fk >= 0) qx[nq] = px[k], qy[nq] = py[k], nq++;
          if ((fk >= 0) != (fl >= 0)) {
            double r = fk / (fk - fl);
            qx[nq] = px[k] + (px[l] - px[k]) * r, qy[nq] = py[k] + (py[l] - py[k]) * r, nq++;
          }
        }
        np = nq;
        memcpy(px, qx, sizeof px), memcpy(py, qy, sizeof py);
      }
      if (!np) smax = -INFINITY; /* no sample of the image can pass */
      double A = a[0] + a[1] + a[2], B = b[0] + b[1] + b[2], C = c[0] + c[1] + c[2];
      for (int k = 0; k < np; k++) {
        double v = A + B * px[k] + C * py[k];
        smax = v > smax ? v : smax;
        rx0 = k ? fmin(rx0, px[k]) : px[k], rx1 = k ? fmax(rx1, px[k]) : px[k];
        ry0 = k ? fmin(ry0, py[k]) : py[k], ry1 = k ? fmax(ry1, py[k]) : py[k];
      }
      smax += slack * (fabs(A) + w * fabs(B) + h * fabs(C));
      rx0 -= 1e-6 * (w + 1), rx1 += 1e-6 * (w + 1), ry0 -= 1e-6 * (h + 1), ry1 += 1e-6 * (h + 1);
    }
  } else {
    double dmax = (double)cam->dir_len_max * (1 + 1e-6), nx = 0, ny = 0, nz = 0, err = 0;
    for (int i = 0; i < 3; i++) {
      nx += ts->a[i] * ts->w[i], ny += ts->b[i] * ts->w[i], nz += ts->c[i] * ts->w[i]; /* Σ w_i n_i */
      err += 4 * u * (fabs(ts->a[i]) + fabs(ts->b[i]) + fabs(ts->c[i]));
    }
    smax = (sqrt(nx * nx + ny * ny + nz * nz) + err) * dmax * (1 + slack);
  }
  /* Rounded outwards to float; samples are small integers + sx0, so this is loose. */
  rect[0] = (float)rx0 - 1e-3f, rect[1] = (float)ry0 - 1e-3f, rect[2] = (float)rx1 + 1e-3f, rect[3] = (float)ry1 + 1e-3f;
  if (!(smax > 0)) { /* no sample can pass */
    rect[0] = rect[1] = INFINITY, rect[2] = rect[3] = -INFINITY;
    return INFINITY;
  }
  double vmin = ts->vol; /* exact when vol_x = vol_y = 0: vol + 0 + 0 */
  if (ts->vol_x != 0 || ts->vol_y != 0) {
    double v0 = ts->vol, vx = ts->vol_x, vy = ts->vol_y;
    double x0 = cam->sx0, x1 = w - 1 + x0, y0 = cam->sy0, y1 = h - 1 + y0; /* the extreme samples */
    vmin = v0 + fmin(x0 * vx, x1 * vx) + fmin(y0 * vy, y1 * vy);
    vmin -= 4 * u * (fabs(v0) + w * fabs(vx) + h * fabs(vy)) + slack * fabs(v0);
  }
  if (!(vmin > 0)) return 0;
  double t = vmin * (1 - u) * (1 - u) / (smax * (1 + u) * (1 + u)) * (1 - 1e-9);
  /* the plane's floor over the samples of rect within the image */
  double x0 = cam->sx0, x1 = w - 1 + x0, y0 = cam->sy0, y1 = h - 1 + y0;
  double tp = plane_floor(ts, cam, greater(x0, rx0), greater(y0, ry0), lesser(x1, rx1), lesser(y1, ry1),
                          (double)cam->dir_len_max * (1 + 1e-6));
  t = lesser(t, tp);
  float f = (float)t;
  return (double)f > t ? nextafterf(f, 0) : f;
}

/* The least t that sample_test() can return for ts at the samples of rect (x0, y0,
 * x1, y1 in sample coordinates; planar cameras), as rr_tri_bounds argues it but
 * over a rectangle the caller tests only inside of (rc-bvh: the corner bounds), so
 * no polygon is needed. At a passing sample every computed e_i = a_i + sx·b_i +
 * sy·c_i is >= 0 and at most E_i + u_i, u_i = 4u·(|a_i| + mx·|b_i| + my·|c_i|)
 * (mx, my: the rect's largest |sx|, |sy|), so the computed Σ w_i e_i is at most
 * (1+u)^2 Σ w_i (E_i + u_i), an affine form whose maximum over the rect is at a
 * corner; the volume's minimum likewise (its error 4u of its terms). That floors
 * TRI_DEPTH's fallback vol·(1/sum); plane_floor floors num / den over the same
 * rect. Double arithmetic keeps a relative slack far above its own rounding; a NaN
 * or infinite sum gives no floor (0). */
float rr_tri_rect_floor(const tri_setup *ts, const camera *cam, const float rect[4]) {
  const double u = 0x1p-24, slack = 1e-12;
  double x0 = rect[0], y0 = rect[1], x1 = rect[2], y1 = rect[3];
  double mx = greater(fabs(x0), fabs(x1)), my = greater(fabs(y0), fabs(y1));
  double A = 0, B = 0, C = 0, err = 0, mag = 0;
  for (int i = 0; i < 3; i++) {
    double w = ts->w[i], m = fabs(ts->a[i]) + mx * fabs(ts->b[i]) + my * fabs(ts->c[i]);
    A += w * ts->a[i], B += w * ts->b[i], C += w * ts->c[i];
    err += w * 4 * u * m, mag += w * m;
  }
  double smax = A + greater(B * x0, B * x1) + greater(C * y0, C * y1) + err + slack * mag;
  if (smax <= 0) return INFINITY; /* no sample of the rect can pass */
  if (!(smax < INFINITY)) return 0;
  double v0 = ts->vol, vx = ts->vol_x, vy = ts->vol_y, vmin = v0; /* exact when vol_x = vol_y = 0 */
  if (vx != 0 || vy != 0)
    vmin = v0 + lesser(x0 * vx, x1 * vx) + lesser(y0 * vy, y1 * vy) -
           (4 * u + slack) * (fabs(v0) + mx * fabs(vx) + my * fabs(vy));
  if (!(vmin > 0)) return 0;
  double t = vmin * (1 - u) * (1 - u) / (smax * (1 + u) * (1 + u)) * (1 - 1e-9);
  t = lesser(t, plane_floor(ts, cam, x0, y0, x1, y1, 0));
  if (!(t >= 0)) return 0; /* NaN from infinite setup values: no floor */
  float f = (float)t;
  return (double)f > t ? nextafterf(f, 0) : f;
}
