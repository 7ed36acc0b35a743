/* The analytic kinds' dispatch, bounds for cameras and t floors (prim/analytic.h). */
#include "prim/analytic.h"
#include "prim/triangle.h"


bool rr_ana_hit(const rr_scene *s, uint32_t i, const ana_ray *r, float *t, float *u, float *v) {
  switch (scene_kind(s, i)) {
  case RR_GEOMETRY_SPHERE: return rr_ana_sphere_hit(rr_ana_params(s, i), r, t, u, v);
  case RR_GEOMETRY_PLANE: return rr_ana_plane_hit(rr_ana_params(s, i), r, t, u, v);
  case RR_GEOMETRY_BOX: return rr_ana_box_hit(rr_ana_params(s, i), r, t, u, v);
  default: return false;
  }
}

/* A box's face from the integer part of u (rr_ana_box_hit), clamped to 0..5. */
static int box_face(float u) {
  int f = (int)floorf(u);
  return f < 0 ? 0 : f > 5 ? 5 : f;
}

vec3 rr_ana_normal(const rr_scene *s, uint32_t i, float u, float v) {
  const float *a = rr_ana_params(s, i);
  if (scene_kind(s, i) == RR_GEOMETRY_PLANE) return v3(a[3], a[4], a[5]);
  if (scene_kind(s, i) == RR_GEOMETRY_BOX) {
    double R[3][3];
    rr_ana_box_frame(a, R);
    int f = box_face(u);
    double sg = f & 1 ? 1 : -1;
    (void)v;
    return v3((float)(sg * R[f / 2][0]), (float)(sg * R[f / 2][1]), (float)(sg * R[f / 2][2]));
  }
  double phi = ((double)u - 0.5) * 2 * RR_PI, th = (double)v * RR_PI;
  return v3((float)(sin(th) * sin(phi)), (float)cos(th), (float)(sin(th) * cos(phi)));
}

vec3 rr_ana_point(const rr_scene *s, uint32_t i, float u, float v) {
  const float *a = rr_ana_params(s, i);
  if (scene_kind(s, i) == RR_GEOMETRY_PLANE) {
    double ua[3], va[3], p[3];
    rr_ana_plane_axes(a + 3, ua, va);
    for (int k = 0; k < 3; k++) p[k] = a[k] + (double)u * ua[k] + (double)v * va[k];
    return v3((float)p[0], (float)p[1], (float)p[2]);
  }
  if (scene_kind(s, i) == RR_GEOMETRY_BOX) {
    double R[3][3], q[3];
    rr_ana_box_frame(a, R);
    int f = box_face(u), ax = f / 2, b1 = (ax + 1) % 3, b2 = (ax + 2) % 3;
    q[ax] = (f & 1 ? 1.0 : -1.0) * a[3 + ax];
    q[b1] = (((double)u - f) / (1 - 0x1p-16) * 2 - 1) * a[3 + b1], q[b2] = ((double)v * 2 - 1) * a[3 + b2];
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = a[k] + R[0][k] * q[0] + R[1][k] * q[1] + R[2][k] * q[2];
    return v3((float)p[0], (float)p[1], (float)p[2]);
  }
  vec3 n = rr_ana_normal(s, i, u, v);
  return v3((float)(a[0] + (double)a[3] * n.x), (float)(a[1] + (double)a[3] * n.y), (float)(a[2] + (double)a[3] * n.z));
}

/* The half extents of a sphere's or a box's world box about its centre: the
 * radius, or Σ_a h_a·|axis_a| (a box's corners reach no further), widened by 1e-6:
 * the stored axes are unit and orthogonal to float rounding only, so the box the
 * slab test sees is R⁻¹ of the cube, R⁻¹ = Rᵀ to within ~1e-7. */
static void box_extent(const rr_scene *s, uint32_t i, double ext[3]) {
  const float *a = rr_ana_params(s, i);
  if (scene_kind(s, i) == RR_GEOMETRY_SPHERE) {
    ext[0] = ext[1] = ext[2] = a[3];
    return;
  }
  double R[3][3];
  rr_ana_box_frame(a, R);
  for (int x = 0; x < 3; x++)
    ext[x] = a[3] * fabs(R[0][x]) + a[4] * fabs(R[1][x]) + a[5] * fabs(R[2][x]) + 1e-6 * ((double)a[3] + a[4] + a[5]);
}

/* The sphere around a box (centre, half diagonal widened by 1e-6) or a sphere itself:
 * what cones and floors bound a box by. */
static void bounding_sphere(const rr_scene *s, uint32_t i, float out[4]) {
  const float *a = rr_ana_params(s, i);
  out[0] = a[0], out[1] = a[1], out[2] = a[2];
  out[3] = scene_kind(s, i) == RR_GEOMETRY_BOX
               ? nextafterf((float)((sqrt((double)a[3] * a[3] + (double)a[4] * a[4] + (double)a[5] * a[5]) + 1e-6 * ((double)a[3] + a[4] + a[5]))),
                            INFINITY)
               : a[3];
}

void rr_ana_box(const rr_scene *s, uint32_t i, float lo[3], float hi[3]) {
  const float *a = rr_ana_params(s, i);
  if (scene_kind(s, i) == RR_GEOMETRY_SPHERE || scene_kind(s, i) == RR_GEOMETRY_BOX) {
    double ext[3];
    box_extent(s, i, ext);
    for (int x = 0; x < 3; x++) {
      lo[x] = nextafterf((float)((double)a[x] - ext[x]), -INFINITY);
      hi[x] = nextafterf((float)((double)a[x] + ext[x]), INFINITY);
    }
    return;
  }
  /* A plane perpendicular to an axis is flat along it; along the others, and
   * along every axis for an oblique plane, it reaches ±PRIM_FAR. */
  for (int x = 0; x < 3; x++) {
    bool flat = a[3 + (x + 1) % 3] == 0 && a[3 + (x + 2) % 3] == 0;
    lo[x] = flat ? a[x] : -PRIM_FAR, hi[x] = flat ? a[x] : PRIM_FAR;
  }
}

void rr_ana_corner_rays(const camera *c, ana_ray r[4]) {
  for (int k = 0; k < 4; k++) {
    float sx = k & 1 ? (float)c->width : 0, sy = k & 2 ? (float)c->height : 0;
    ana_sample_ray(c, v3(1, sx, sy), sx, sy, &r[k]);
  }
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const double *a, const double *b, double *o) {
  o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static void d3(vec3 v, double *o) { o[0] = v.x, o[1] = v.y, o[2] = v.z; }

/* Planar cameras, a sphere: every hit p lies in the sphere's box B. Write p − base
 * = λ·e0 + μ·e1 + ν·e2 in the camera's basis (perspective: base = eye, e = d0, dx,
 * dy, and p's sample is (μ / λ, ν / λ); orthographic: base = eye + o0, e = fwd, ox,
 * oy, and the sample is (μ, ν)). A hit has λ = t > 0. When every corner of B has
 * λ > 0, B lies in that half-space, where the projection maps segments to segments,
 * so the hull of B (B itself) projects into the rectangle of its corners' samples;
 * B wholly at λ <= 0 holds no hit. Computed in double (errors ~1e-13 pixel, far
 * inside the 1e-3 pixel pad); the samples of pixel x lie in [x, x + 1). */
/* Perspective cameras, a sphere wholly ahead of the eye's plane: the tight bounds of
 * its image, the conic of its silhouette. The rays d = M·w (w = (1, sx, sy), M the
 * columns d0, dx, dy) that meet the sphere are those where (q·d)² − c·|d|² >= 0
 * (c = |q|² − r² > 0, the eye outside; the hit test's discriminant a·h² in other
 * words), the quadratic form wᵀAw with A = u·uᵀ − c·MᵀM, u = Mᵀq: an ellipse in the
 * image. A line l·w = 0 touches it where lᵀ·adj(A)·l = 0 (the dual conic), so the
 * columns sx = X bounding it solve B00·X² − 2·B01·X + B11 = 0 and the rows
 * B00·Y² − 2·B02·Y + B22 = 0 (B = adj(A)). In double; the rectangle of the box's
 * corners is narrowed to it (both hold every sample that can pass), the caller pads. */
static void conic_rect(const float *a, const double base[3], double M[3][3], double *X0, double *X1, double *Y0,
                       double *Y1) {
  double q[3] = {a[0] - base[0], a[1] - base[1], a[2] - base[2]}, r = a[3];
  double c = dot3(q, q) - r * r, u[3], A[3][3], B[3][3];
  if (!(c > 0)) return;
  for (int i = 0; i < 3; i++) u[i] = dot3(M[i], q);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) A[i][j] = u[i] * u[j] - c * dot3(M[i], M[j]);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      B[i][j] = A[i1][j1] * A[i2][j2] - A[i1][j2] * A[i2][j1]; /* adj(A) = cofactors transposed */
    }
  double dx = B[0][1] * B[0][1] - B[0][0] * B[1][1], dy = B[0][2] * B[0][2] - B[0][0] * B[2][2];
  if (!(B[0][0] != 0 && dx >= 0 && dy >= 0 && isfinite(dx) && isfinite(dy))) return;
  double xa = (B[0][1] - sqrt(dx)) / B[0][0], xb = (B[0][1] + sqrt(dx)) / B[0][0];
  double ya = (B[0][2] - sqrt(dy)) / B[0][0], yb = (B[0][2] + sqrt(dy)) / B[0][0];
  *X0 = fmax(*X0, fmin(xa, xb)), *X1 = fmin(*X1, fmax(xa, xb));
  *Y0 = fmax(*Y0, fmin(ya, yb)), *Y1 = fmin(*Y1, fmax(ya, yb));
}

static bool sphere_rect(const rr_scene *s, uint32_t i, const camera *c, int rect[4]) {
  const float *a = rr_ana_params(s, i);
  bool box = scene_kind(s, i) == RR_GEOMETRY_BOX;
  double ext[3];
  box_extent(s, i, ext);
  double base[3], e[3][3], ex[3], ey[3], ez[3];
  bool persp = c->type == RR_CAMERA_PERSPECTIVE;
  d3(c->eye, base);
  if (persp) d3(c->d0, e[0]), d3(c->dx, e[1]), d3(c->dy, e[2]);
  else {
    double o0[3];
    d3(c->o0, o0);
    for (int k = 0; k < 3; k++) base[k] += o0[k];
    d3(c->fwd, e[0]), d3(c->ox, e[1]), d3(c->oy, e[2]);
  }
  cross3(e[1], e[2], ex), cross3(e[2], e[0], ey), cross3(e[0], e[1], ez);
  double det = dot3(e[0], ex);
  if (!(fabs(det) > 0)) return false;
  double X0 = INFINITY, X1 = -INFINITY, Y0 = INFINITY, Y1 = -INFINITY;
  int ahead = 0;
  double r = (double)a[3] * (1 + 1e-9);
  for (int k = 0; k < 8; k++) {
    double q[3];
    for (int x = 0; x < 3; x++) q[x] = (double)a[x] + (k >> x & 1 ? r : -r) - base[x];
    if (box) /* the corners of its world box (box_extent) */
      for (int x = 0; x < 3; x++) q[x] = (double)a[x] + (k >> x & 1 ? ext[x] : -ext[x]) - base[x];
    double lam = dot3(q, ex) / det, mu = dot3(q, ey) / det, nu = dot3(q, ez) / det;
    if (!(lam > 1e-12 * sqrt(dot3(q, q)))) continue; /* at or behind the eye's plane */
    ahead++;
    double sx = persp ? mu / lam : mu, sy = persp ? nu / lam : nu;
    X0 = fmin(X0, sx), X1 = fmax(X1, sx), Y0 = fmin(Y0, sy), Y1 = fmax(Y1, sy);
  }
  int W = c->width, H = c->height;
  if (ahead == 0) return false;
  if (ahead < 8) {
    rect[0] = 0, rect[1] = 0, rect[2] = W - 1, rect[3] = H - 1;
    return true;
  }
  if (persp && !box) conic_rect(a, base, e, &X0, &X1, &Y0, &Y1);
  double pad = 1e-3 + 1e-9 * fmax(fmax(fabs(X0), fabs(X1)), fmax(fabs(Y0), fabs(Y1)));
  X0 = floor(X0 - pad - 1), X1 = floor(X1 + pad), Y0 = floor(Y0 - pad - 1), Y1 = floor(Y1 + pad);
  rect[0] = X0 < 0 ? 0 : (int)X0, rect[1] = Y0 < 0 ? 0 : (int)Y0;
  rect[2] = X1 > W - 1 ? W - 1 : (int)X1, rect[3] = Y1 > H - 1 ? H - 1 : (int)Y1;
  return rect[0] <= rect[2] && rect[1] <= rect[3];
}

bool rr_ana_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, int rect[4]) {
  if (rr_ana_t_floor(s, i, c) == INFINITY) return false;
  if (c->planar && scene_kind(s, i) != RR_GEOMETRY_PLANE) return sphere_rect(s, i, c, rect);
  rect[0] = 0, rect[1] = 0, rect[2] = c->width - 1, rect[3] = c->height - 1;
  return c->width > 0 && c->height > 0;
}

bool rr_ana_cone_excludes(const rr_scene *s, uint32_t i, const camera *c, vec3 axis, float angle) {
  float bs[4];
  bounding_sphere(s, i, bs);
  const float *a = scene_kind(s, i) == RR_GEOMETRY_PLANE ? rr_ana_params(s, i) : bs;
  double e[3], ax[3];
  d3(c->eye, e), d3(axis, ax);
  double la = sqrt(dot3(ax, ax));
  if (!(la > 0) || !(angle < CAMERA_NO_CONE)) return false;
  if (scene_kind(s, i) != RR_GEOMETRY_PLANE) {
    double q[3] = {a[0] - e[0], a[1] - e[1], a[2] - e[2]}, dist = sqrt(dot3(q, q)), r = a[3];
    if (!(dist > r * (1 + 1e-9))) return false; /* the eye inside: every direction */
    double beta = asin(r / dist), cs = dot3(q, ax) / (dist * la);
    double phi = acos(cs < -1 ? -1 : cs > 1 ? 1 : cs);
    return phi > (double)angle + beta + 1e-6;
  }
  /* A plane is hit along d only where n·d has the sign of n·(P − eye): the cone
   * misses that half-space when its axis is more than 90° + angle from it. */
  double n[3] = {a[3], a[4], a[5]}, side = n[0] * (a[0] - e[0]) + n[1] * (a[1] - e[1]) + n[2] * (a[2] - e[2]);
  if (side == 0) return true; /* the eye on the plane: t = 0 everywhere, no hit */
  double cs = (side > 0 ? 1 : -1) * dot3(n, ax) / la, phi = acos(cs < -1 ? -1 : cs > 1 ? 1 : cs);
  return phi > RR_PI / 2 + (double)angle + 1e-6;
}

/* Floors. A hit at distance L from the origin along d has t = L / |d|.
 * Sphere: L >= |q| − r (q = C − eye), so t >= (|q| − r) / max|d| for curved
 * cameras (dir_len_max: their longest ray). Perspective: t = (p − eye)·fwd /
 * (d·fwd) with (p − eye)·fwd >= q·fwd − r·|fwd| and d·fwd, linear in the sample,
 * at most its largest value at the image's corners. Orthographic: t = (p − o)·fwd
 * / |fwd|² with o = eye + o0 + sx·ox + sy·oy, (o − eye)·fwd again largest at a corner.
 * Plane (c = n·(P − eye)): perspective t = c / (n·d) with n·d linear in the sample,
 * so over the image it is least where c·(n·d) is greatest, at a corner, and no
 * corner with c·(n·d) > 0 means no sample hits; orthographic t = n·(P − o) / n·fwd
 * is linear, least at a corner (no positive corner: no hit); curved t >= |c| / |n|
 * / dir_len_max. Each in double, then rounded down (ana_floor_f). */
float rr_ana_t_floor(const rr_scene *s, uint32_t i, const camera *c) {
  float bs[4]; /* a box's hits lie in its bounding sphere: that sphere's floor holds */
  bounding_sphere(s, i, bs);
  bool sphere = scene_kind(s, i) != RR_GEOMETRY_PLANE;
  const float *a = sphere ? bs : rr_ana_params(s, i);
  double e[3], f[3];
  d3(c->eye, e), d3(c->fwd, f);
  if (!c->planar) {
    double L;
    if (sphere) {
      double q[3] = {a[0] - e[0], a[1] - e[1], a[2] - e[2]};
      L = sqrt(dot3(q, q)) - a[3];
    } else {
      L = fabs(a[3] * (a[0] - e[0]) + a[4] * (a[1] - e[1]) + a[5] * (a[2] - e[2]));
      if (L == 0) return INFINITY;
      L /= sqrt((double)a[3] * a[3] + (double)a[4] * a[4] + (double)a[5] * a[5]);
    }
    return L > 0 ? ana_floor_f(L / ((double)c->dir_len_max * (1 + 1e-6))) : 0;
  }
  ana_ray r[4];
  rr_ana_corner_rays(c, r);
  if (sphere) {
    double q[3] = {a[0] - e[0], a[1] - e[1], a[2] - e[2]};
    double z = dot3(q, f) - a[3] * sqrt(dot3(f, f)), top = -INFINITY;
    if (c->type == RR_CAMERA_PERSPECTIVE) {
      for (int k = 0; k < 4; k++) top = fmax(top, dot3(r[k].d, f));
      return top > 0 ? ana_floor_f(z / top) : 0;
    }
    for (int k = 0; k < 4; k++) {
      double oe[3] = {r[k].o[0] - e[0], r[k].o[1] - e[1], r[k].o[2] - e[2]};
      top = fmax(top, dot3(oe, f));
    }
    return ana_floor_f((z - top) / dot3(f, f));
  }
  double least = INFINITY;
  for (int k = 0; k < 4; k++) {
    double n[3] = {a[3], a[4], a[5]}, p[3] = {a[0] - r[k].o[0], a[1] - r[k].o[1], a[2] - r[k].o[2]};
    double num = dot3(n, p), den = dot3(n, r[k].d);
    if (c->type == RR_CAMERA_PERSPECTIVE) {
      if (num != 0 && num * den > 0) least = fmin(least, num / den);
    } else {
      least = fmin(least, num / den);
    }
  }
  if (c->type == RR_CAMERA_PERSPECTIVE) return least == INFINITY ? INFINITY : ana_floor_f(least);
  /* orthographic: no positive corner, no positive t anywhere */
  double most = -INFINITY;
  for (int k = 0; k < 4; k++) {
    double n[3] = {a[3], a[4], a[5]}, p[3] = {a[0] - r[k].o[0], a[1] - r[k].o[1], a[2] - r[k].o[2]};
    most = fmax(most, dot3(n, p) / dot3(n, r[k].d));
  }
  return !(most > 0) ? INFINITY : ana_floor_f(least);
}
