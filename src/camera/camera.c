/* Cameras: the ray direction of every sample, and bounds for rasterization. */
#include "camera/camera.h"
#include "camera/lens.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void rr_camera_init(rr_camera *cam) {
  if (!cam) return;
  *cam = (rr_camera){.type = RR_CAMERA_PERSPECTIVE,
                     .eye = {0, 0, 3},
                     .target = {0, 0, 0},
                     .up = {0, 1, 0},
                     .fov_deg = 45};
}

static const char *const camera_names[RR_CAMERA_COUNT] = {"perspective", "orthographic", "parabolic",
                                                          "latlong",     "fisheye",      "cube",
                                                          "opencv",      "opencv-fisheye"};

int rr_camera_from_name(const char *name) {
  for (int i = 0; name && i < RR_CAMERA_COUNT; i++)
    if (strcmp(camera_names[i], name) == 0) return i;
  return -1;
}

const char *rr_camera_name(int type) { return type >= 0 && type < RR_CAMERA_COUNT ? camera_names[type] : NULL; }

static bool finite_v(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

rr_error rr_camera_check(rr_device *dev, const rr_camera *c) {
  if (!c) return rr_fail(dev, RR_ERROR_ARGUMENT, "camera is NULL");
  if ((int)c->type < 0 || c->type >= RR_CAMERA_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown camera type %d", (int)c->type);
  if (!finite_v(c->eye) || !finite_v(c->target) || !finite_v(c->up))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "camera vectors must be finite");
  float fov_max = c->type == RR_CAMERA_FISHEYE ? 360 : 180;
  bool fov_used = c->type == RR_CAMERA_PERSPECTIVE || c->type == RR_CAMERA_FISHEYE ||
                  ((c->type == RR_CAMERA_OPENCV || c->type == RR_CAMERA_OPENCV_FISHEYE) && c->fx == 0 && c->fy == 0) ||
                  (c->type == RR_CAMERA_ORTHOGRAPHIC && c->ortho_height == 0);
  if (fov_used && !(c->fov_deg >= RR_FOV_MIN && (c->fov_deg < fov_max || (fov_max == 360 && c->fov_deg == 360))))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad field of view %g (expected %g <= fov < %g degrees)", c->fov_deg,
                   (double)RR_FOV_MIN, fov_max);
  if (c->type == RR_CAMERA_OPENCV || c->type == RR_CAMERA_OPENCV_FISHEYE) {
    bool from_fov = c->fx == 0 && c->fy == 0;
    if (!from_fov && (!(c->fx > 0 && c->fy > 0 && c->fx < FLT_MAX && c->fy < FLT_MAX) || !isfinite(c->cx) ||
                      !isfinite(c->cy)))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "bad intrinsics fx=%g fy=%g cx=%g cy=%g (focal lengths > 0, all finite)",
                     c->fx, c->fy, c->cx, c->cy);
    for (int i = 0; i < 8; i++)
      if (!isfinite(c->dist[i]) || (c->type == RR_CAMERA_OPENCV_FISHEYE && i >= 4 && c->dist[i] != 0))
        return rr_fail(dev, RR_ERROR_ARGUMENT, "bad distortion coefficient %d: %g (%s)", i + 1, c->dist[i],
                       i >= 4 && c->type == RR_CAMERA_OPENCV_FISHEYE ? "the fisheye model has 4" : "not finite");
  }
  if (!(c->ortho_height >= 0) || !isfinite(c->ortho_height))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad orthographic height %g (expected > 0)", c->ortho_height);
  /* in double: the lengths of float vectors neither overflow nor underflow there */
  double f[3], u[3], x[3], lf = 0, lu = 0, lx = 0;
  for (int i = 0; i < 3; i++) f[i] = (double)c->target[i] - c->eye[i], u[i] = c->up[i];
  for (int i = 0; i < 3; i++) {
    x[i] = f[(i + 1) % 3] * u[(i + 2) % 3] - f[(i + 2) % 3] * u[(i + 1) % 3];
    lf += f[i] * f[i], lu += u[i] * u[i], lx += x[i] * x[i];
  }
  if (lf == 0)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "eye equals target (%g,%g,%g)", c->eye[0], c->eye[1], c->eye[2]);
  if (!((float)sqrt(lf) < FLT_MAX))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "eye and target too far apart (their distance %g overflows a float)",
                   sqrt(lf));
  if (!(lu > 0) || !(sqrt(lx) > 1e-6 * sqrt(lf) * sqrt(lu)))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "up (%g,%g,%g) is parallel to the view direction", c->up[0], c->up[1],
                   c->up[2]);
  return rr_ok(dev);
}

/* A perspective camera's rays from its basis and image size:
 * d(sx, sy) = fwd + (2 sx / W - 1) tw right + (1 - 2 sy / H) th up. */
static void perspective_rays(vec3 fwd, vec3 right, vec3 up, float tw, float th, int width, int height, vec3 *d0,
                             vec3 *dx, vec3 *dy) {
  *d0 = v3_add(fwd, v3_sub(v3_scale(up, th), v3_scale(right, tw)));
  *dx = v3_scale(right, 2.0f * tw / (float)width);
  *dy = v3_scale(up, -2.0f * th / (float)height);
}

/* A perspective camera's rays and side planes from its basis and image size. */
static void perspective_basis(camera *c) {
  perspective_rays(c->fwd, c->right, c->up, c->tan_half_w, c->tan_half_h, c->width, c->height, &c->d0, &c->dx, &c->dy);
  /* the planes through the eye and a column x (a row y) of the image have normals
   * linear in x (y); the sign makes them face increasing x (y) */
  float s = v3_dot(v3_cross(c->dx, c->dy), c->d0) > 0 ? 1.0f : -1.0f;
  c->col_n0 = v3_scale(v3_cross(c->d0, c->dy), -s), c->col_n1 = v3_scale(v3_cross(c->dx, c->dy), -s);
  c->row_n0 = v3_scale(v3_cross(c->d0, c->dx), s), c->row_n1 = v3_scale(v3_cross(c->dy, c->dx), s);
}

/* The cube's faces in the horizontal cross: row 1 holds left, front, right, back,
 * row 0 the top face above the front, row 2 the bottom one below it. */
static const int cube_cols[6] = {1, 2, 3, 0, 1, 1}, cube_rows[6] = {1, 1, 1, 1, 0, 2};

int rr_cam_cube_face_at(const camera *c, int x, int y) {
  int col = x / c->face, row = y / c->face;
  for (int f = 0; f < 6; f++)
    if (cube_cols[f] == col && cube_rows[f] == row) return f;
  return -1;
}

void rr_cam_cube_face_origin(const camera *c, int f, int *x0, int *y0) {
  *x0 = cube_cols[f] * c->face, *y0 = cube_rows[f] * c->face;
}

/* Face f's forward, right and up in the cube's basis (up = right × forward). */
static void cube_face_basis(const camera *c, int f, vec3 *fwd, vec3 *right, vec3 *up) {
  const vec3 r = c->right, u = c->up, w = c->fwd;
  const vec3 fw[6] = {w, r, v3_neg(w), v3_neg(r), u, v3_neg(u)};
  const vec3 ri[6] = {r, v3_neg(w), v3_neg(r), w, r, r};
  const vec3 uu[6] = {u, u, u, u, v3_neg(w), w};
  *fwd = fw[f], *right = ri[f], *up = uu[f];
}

void rr_cam_cube_face(const camera *c, int f, camera *out) {
  vec3 fwd, right, up;
  cube_face_basis(c, f, &fwd, &right, &up);
  memset(out, 0, sizeof *out);
  out->type = RR_CAMERA_PERSPECTIVE, out->planar = true;
  out->width = out->height = c->face;
  out->sx0 = c->sx0, out->sy0 = c->sy0;
  out->eye = c->eye, out->fwd = fwd, out->right = right, out->up = up;
  out->tan_half_h = out->tan_half_w = 1.0f; /* 90° exactly */
  out->fov_deg = 90.0f;
  out->dir_len_max = 1;
  perspective_basis(out);
}

/* The ray of pixel (x, y) of a cube camera: its face's (rr_cam_cube_face's d0, dx,
 * dy, without the rest of the face camera), zero in the cross's gaps. */
static vec3 cube_dir(const camera *c, int x, int y) {
  const int f = rr_cam_cube_face_at(c, x, y);
  if (f < 0) return v3(0, 0, 0);
  vec3 fwd, right, up, d0, dx, dy;
  cube_face_basis(c, f, &fwd, &right, &up);
  perspective_rays(fwd, right, up, 1.0f, 1.0f, c->face, c->face, &d0, &dx, &dy);
  const float sx = (float)(x - cube_cols[f] * c->face) + c->sx0, sy = (float)(y - cube_rows[f] * c->face) + c->sy0;
  return v3_add(d0, v3_add(v3_scale(dx, sx), v3_scale(dy, sy))); /* camera_dir's operations */
}

/* The lat-long map's angles of column x and row y, and its direction from the
 * horizontal one of the column and the row's sine and cosine: written once for
 * curved_dir and the table (ray_rows, which takes the sines a column and a row at
 * a time), so both give the same bits. */
static double latlong_phi(const camera *c, int x) {
  return 2 * RR_PI * (x + (double)c->sx0) / c->width - RR_PI;
}
static double latlong_theta(const camera *c, int y) { return RR_PI * (y + (double)c->sy0) / c->height; }
static vec3 latlong_horiz(const camera *c, int x) {
  const double phi = latlong_phi(c, x);
  return v3_add(v3_scale(c->right, (float)sin(phi)), v3_scale(c->fwd, (float)cos(phi)));
}
static vec3 latlong_dir(vec3 horiz, vec3 up, float sin_theta, float cos_theta) {
  return v3_add(v3_scale(horiz, sin_theta), v3_scale(up, cos_theta));
}
/* The image's coordinates in [-1, 1] of column x and row y (up positive). */
static double image_u(const camera *c, int x) { return 2 * (x + (double)c->sx0) / c->width - 1; }
static double image_v(const camera *c, int y) { return 1 - 2 * (y + (double)c->sy0) / c->height; }

/* The parabolic map's direction from the column's part right·u, the row's up·v
 * and u² + v² (inside the disk): written once, like latlong_dir. */
static vec3 parabolic_dir(vec3 right_u, vec3 up_v, vec3 fwd, double rr) {
  return v3_add(v3_add(right_u, up_v), v3_scale(fwd, (float)(0.5 - 0.5 * rr)));
}

/* The direction of pixel (x, y) of a curved camera; zero where it has no ray.
 * With dd, also its derivatives with respect to the sample position, per pixel
 * step in x (dd[0]) and y (dd[1]): each mapping differentiated in closed form. */
static vec3 curved_dir(const camera *c, int x, int y, vec3 *dd) {
  double W = c->width, H = c->height, sx = x + (double)c->sx0, sy = y + (double)c->sy0;
  double u = image_u(c, x), v = image_v(c, y), du = 2 / W, dv = -2 / H; /* du/dsx, dv/dsy */
  vec3 r = c->right, up = c->up, f = c->fwd;
  switch (c->type) {
  case RR_CAMERA_PARABOLIC: {
    double rr = u * u + v * v;
    if (rr > 1) return v3(0, 0, 0);
    if (dd) { /* ∂d/∂u = right − u·fwd, ∂d/∂v = up − v·fwd */
      dd[0] = v3_scale(v3_sub(r, v3_scale(f, (float)u)), (float)du);
      dd[1] = v3_scale(v3_sub(up, v3_scale(f, (float)v)), (float)dv);
    }
    return parabolic_dir(v3_scale(r, (float)u), v3_scale(up, (float)v), f, rr);
  }
  case RR_CAMERA_LATLONG: {
    double phi = latlong_phi(c, x), theta = latlong_theta(c, y);
    vec3 horiz = latlong_horiz(c, x);
    if (dd) { /* ∂d/∂φ = sin θ (cos φ right − sin φ fwd), ∂d/∂θ = cos θ horiz − sin θ up */
      vec3 dphi = v3_sub(v3_scale(r, (float)cos(phi)), v3_scale(f, (float)sin(phi)));
      dd[0] = v3_scale(dphi, (float)(sin(theta) * 2 * RR_PI / W));
      dd[1] = v3_scale(v3_sub(v3_scale(horiz, (float)cos(theta)), v3_scale(up, (float)sin(theta))),
                       (float)(RR_PI / H));
    }
    return latlong_dir(horiz, up, (float)sin(theta), (float)cos(theta));
  }
  case RR_CAMERA_FISHEYE: {
    double rad = sqrt(u * u + v * v);
    if (rad > 1) return v3(0, 0, 0);
    double k = c->fov_deg * RR_PI / 360, a = rad * c->fov_deg * RR_PI / 360, psi = atan2(v, u); /* a = k·rad */
    vec3 radial = v3_add(v3_scale(r, (float)cos(psi)), v3_scale(up, (float)sin(psi)));
    if (dd) {
      /* In polar form: ∂d/∂rad = k (cos a radial − sin a fwd), ∂d/∂ψ = sin a tangential,
       * with ∂rad/∂(u, v) = (cos ψ, sin ψ) and ∂ψ/∂(u, v) = (−sin ψ, cos ψ)/rad;
       * sin a / rad tends to k at the centre, where ψ is 0. */
      vec3 tang = v3_sub(v3_scale(up, (float)cos(psi)), v3_scale(r, (float)sin(psi)));
      vec3 drad = v3_scale(v3_sub(v3_scale(radial, (float)cos(a)), v3_scale(f, (float)sin(a))), (float)k);
      double s = rad > 0 ? sin(a) / rad : k;
      dd[0] = v3_scale(v3_sub(v3_scale(drad, (float)cos(psi)), v3_scale(tang, (float)(s * sin(psi)))), (float)du);
      dd[1] = v3_scale(v3_add(v3_scale(drad, (float)sin(psi)), v3_scale(tang, (float)(s * cos(psi)))), (float)dv);
    }
    return v3_add(v3_scale(radial, (float)sin(a)), v3_scale(f, (float)cos(a)));
  }
  case RR_CAMERA_CUBE: {
    /* the ray of the face's own perspective camera (rr_cam_cube_face), in camera_dir's operations */
    int f = rr_cam_cube_face_at(c, x, y);
    if (f < 0) return v3(0, 0, 0);
    if (dd) {
      camera fc;
      rr_cam_cube_face(c, f, &fc);
      dd[0] = fc.dx, dd[1] = fc.dy;
    }
    return cube_dir(c, x, y);
  }
  case RR_CAMERA_OPENCV:
  case RR_CAMERA_OPENCV_FISHEYE: {
    /* OpenCV's image point of the sample: pixel centres at integers */
    double d[3], dd2[2][3];
    if (!rr_lens_unproject(&c->lens, c->lens_fold, sx - 0.5, sy - 0.5, d, dd ? dd2 : NULL)) return v3(0, 0, 0);
    vec3 down = v3_neg(up); /* camera axes: x right, y down, z forward */
    for (int j = 0; dd && j < 2; j++)
      dd[j] = v3_add(v3_add(v3_scale(r, (float)dd2[j][0]), v3_scale(down, (float)dd2[j][1])),
                     v3_scale(f, (float)dd2[j][2]));
    return v3_add(v3_add(v3_scale(r, (float)d[0]), v3_scale(down, (float)d[1])), v3_scale(f, (float)d[2]));
  }
  default:
    return v3(0, 0, 0);
  }
}

bool rr_cam_dir_at(const camera *c, double sx, double sy, double d[3]) {
  double W = c->width, H = c->height, u = 2 * sx / W - 1, v = 1 - 2 * sy / H, cr, cu, cf;
  switch (c->type) {
  case RR_CAMERA_PARABOLIC:
    cr = u, cu = v, cf = 0.5 - 0.5 * (u * u + v * v);
    break;
  case RR_CAMERA_LATLONG: {
    double phi = 2 * RR_PI * sx / W - RR_PI, theta = RR_PI * sy / H;
    cr = sin(theta) * sin(phi), cu = cos(theta), cf = sin(theta) * cos(phi);
    break;
  }
  case RR_CAMERA_FISHEYE: {
    double k = c->fov_deg * RR_PI / 360, rad = sqrt(u * u + v * v), s = rad > 0 ? sin(k * rad) / rad : k;
    cr = s * u, cu = s * v, cf = cos(k * rad);
    break;
  }
  default:
    return false;
  }
  const vec3 r = c->right, up = c->up, f = c->fwd;
  d[0] = cr * r.x + cu * up.x + cf * f.x;
  d[1] = cr * r.y + cu * up.y + cf * f.y;
  d[2] = cr * r.z + cu * up.z + cf * f.z;
  return true;
}

/* The longest chord between the unit rays of samples one pixel apart (in x or y)
 * of a curved camera, from rows [y0, y1): its angle, over the whole image, is the
 * measured Lipschitz constant of the maps without a closed-form bound (the OpenCV
 * lenses). Along a staircase path of such steps the angle between any two samples
 * is at most that times their L1 distance, so √2 times it bounds the angle per
 * pixel of Euclidean distance. */
static float longest_chord(const camera *c, int y0, int y1) {
  float worst = 0;
  for (int y = y0; y < y1; y++)
    for (int x = 0; x < c->width; x++) {
      vec3 d = c->dirs[(size_t)y * c->width + x];
      if (d.x == 0 && d.y == 0 && d.z == 0) continue;
      for (int k = 0; k < 2; k++) {
        int nx = x + (k == 0), ny = y + (k == 1);
        if (nx >= c->width || ny >= c->height) continue;
        vec3 e = c->dirs[(size_t)ny * c->width + nx];
        if (e.x == 0 && e.y == 0 && e.z == 0) continue;
        worst = fmaxf(worst, v3_len(v3_sub(d, e)));
      }
    }
  return worst;
}

/* At least the angle between unit a and d, about unit itself (within 1e-7 of
 * length, as the stored rays and axes): the chord c, and asin(c/2) <= tan asin(c/2),
 * so the angle 2 asin(c/2) <= c / √(1 − c²/4), tight for the small angles of
 * cells (c²/8 relative) and with no library call; π beyond the range. */
static double angle_over(const double a[3], vec3 d) {
  const double x = a[0] - d.x, y = a[1] - d.y, z = a[2] - d.z, c2 = x * x + y * y + z * z;
  return c2 < 3.9 ? sqrt(c2 / (1 - c2 / 4)) + 2e-7 : RR_PI;
}

static bool has_ray(vec3 d) { return d.x != 0 || d.y != 0 || d.z != 0; }

/* d over its length, in double (d not zero). */
static void unit_of(vec3 d, double a[3]) {
  const double x = d.x, y = d.y, z = d.z, len = sqrt(x * x + y * y + z * z);
  a[0] = x / len, a[1] = y / len, a[2] = z / len;
}

/* c->fine, cell rows [cy0, cy1): each CAMERA_FINE² cell's cone, about its centre
 * sample's ray (else its first ray), as wide as its farthest ray. A lens's stretch varies over the
 * image, without bound towards a fold inside it (a square root's slope): a cone
 * grown from the centre ray by one Lipschitz constant would be wide everywhere,
 * and one per cell still wide at the fold, where a cell's last step turns many
 * times more than its others. */
static void measure_cells(camera *c, int cy0, int cy1) {
  const int n = CAMERA_FINE;
  for (int cy = cy0; cy < cy1 && cy * n < c->height; cy++)
    for (int cx = 0; cx * n < c->width; cx++) {
      const int x0 = cx * n, y0 = cy * n, x1 = x0 + n < c->width ? x0 + n : c->width;
      const int y1 = y0 + n < c->height ? y0 + n : c->height;
      float *cell = c->fine + 4 * ((size_t)cy * c->fine_x + cx);
      vec3 d = c->dirs[(size_t)((y0 + y1 - 1) / 2) * c->width + (x0 + x1 - 1) / 2];
      for (int i = 0; i < (x1 - x0) * (y1 - y0) && !has_ray(d); i++)
        d = c->dirs[(size_t)(y0 + i / (x1 - x0)) * c->width + x0 + i % (x1 - x0)];
      cell[0] = cell[1] = cell[2] = 0, cell[3] = -1;
      if (!has_ray(d)) continue;
      double a[3], e[3], least = 1; /* the cosine: its acos is within 3e-8 of the angle */
      unit_of(d, a);
      for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
          if (has_ray(c->dirs[(size_t)y * c->width + x])) {
            unit_of(c->dirs[(size_t)y * c->width + x], e);
            least = fmin(least, a[0] * e[0] + a[1] * e[1] + a[2] * e[2]);
          }
      /* (float rounding of the axis and angle: rr_cam_rect_cone's 1e-5 holds it) */
      cell[0] = (float)a[0], cell[1] = (float)a[1], cell[2] = (float)a[2];
      cell[3] = (float)(acos(fmax(-1.0, least)) + 1e-7);
    }
}

/* A curved camera's table of rays, RAY_ROWS rows a job: curved_dir's, with the
 * columns' parts of the lat-long and parabolic maps (col) computed once; and a
 * lens's cones of the cells in those rows. */
enum { RAY_ROWS = 16 };
typedef struct ray_table {
  camera *c;
  const vec3 *col;
} ray_table;

static void ray_rows(int job, int thread, void *arg) {
  (void)thread;
  const ray_table *rt = arg;
  camera *c = rt->c;
  const int y1 = (job + 1) * RAY_ROWS < c->height ? (job + 1) * RAY_ROWS : c->height;
  for (int y = job * RAY_ROWS; y < y1; y++) {
    vec3 *row = c->dirs + (size_t)y * c->width;
    if (c->type == RR_CAMERA_LATLONG) {
      const double theta = latlong_theta(c, y);
      const float st = (float)sin(theta), ct = (float)cos(theta);
      for (int x = 0; x < c->width; x++) row[x] = latlong_dir(rt->col[x], c->up, st, ct);
    } else if (c->type == RR_CAMERA_PARABOLIC) {
      const double v = image_v(c, y);
      const vec3 up_v = v3_scale(c->up, (float)v);
      for (int x = 0; x < c->width; x++) {
        const double u = image_u(c, x), rr = u * u + v * v;
        row[x] = rr > 1 ? v3(0, 0, 0) : parabolic_dir(rt->col[x], up_v, c->fwd, rr);
      }
    } else {
      for (int x = 0; x < c->width; x++) row[x] = curved_dir(c, x, y, NULL);
    }
  }
  /* a lens's cells of these rows, which hold whole cells */
  _Static_assert(RAY_ROWS % CAMERA_FINE == 0, "a band of rays holds whole cells");
  if (c->fine) measure_cells(c, job * (RAY_ROWS / CAMERA_FINE), (job + 1) * (RAY_ROWS / CAMERA_FINE));
}

/* A band's longest chord (longest_chord), once the table is whole: the lenses'
 * Lipschitz constant, measured. */
typedef struct chord_rows {
  const camera *c;
  float *worst; /* per band */
} chord_rows;

static void chords_of_rows(int job, int thread, void *arg) {
  (void)thread;
  const chord_rows *cr = arg;
  const int y1 = (job + 1) * RAY_ROWS < cr->c->height ? (job + 1) * RAY_ROWS : cr->c->height;
  cr->worst[job] = longest_chord(cr->c, job * RAY_ROWS, y1);
}

rr_error rr_cam_setup(rr_device *dev, const rr_camera *in, int width, int height, camera *c) {
  static const float centre[2] = {0.5f, 0.5f};
  return rr_cam_setup_at(dev, in, width, height, centre, c);
}

rr_error rr_cam_setup_at(rr_device *dev, const rr_camera *in, int width, int height, const float sample[2],
                         camera *c) {
  return rr_cam_setup_threads(dev, in, width, height, sample, 1, c);
}

rr_error rr_cam_setup_threads(rr_device *dev, const rr_camera *in, int width, int height, const float sample[2],
                              int threads, camera *c) {
  memset(c, 0, sizeof *c);
  rr_error e = rr_camera_check(dev, in);
  if (e) return e;
  if (!(sample[0] >= 0.0f && sample[0] < 1.0f && sample[1] >= 0.0f && sample[1] < 1.0f))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad sample position (%g, %g) (each in [0, 1))", (double)sample[0],
                   (double)sample[1]);
  c->sx0 = sample[0], c->sy0 = sample[1];
  if (width < 1 || height < 1 || width > RR_MAX_SIZE || height > RR_MAX_SIZE)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad image size %dx%d (1..%d per side)", width, height, RR_MAX_SIZE);
  if (in->type == RR_CAMERA_CUBE && (width != height / 3 * 4 || height % 3))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "a cube camera needs a 4:3 image of six square faces (e.g. 1024x768), not %dx%d",
                   width, height);
  c->type = in->type;
  c->width = width;
  c->height = height;
  c->eye = v3_load(in->eye);
  c->fov_deg = in->fov_deg;
  c->fwd = v3_norm(v3_sub(v3_load(in->target), c->eye));
  c->right = v3_norm(v3_cross(c->fwd, v3_load(in->up)));
  c->up = v3_cross(c->right, c->fwd);
  c->tan_half_h = tanf(in->fov_deg * (float)RR_PI / 360.0f);
  c->tan_half_w = c->tan_half_h * (float)width / (float)height;
  c->planar = in->type == RR_CAMERA_PERSPECTIVE || in->type == RR_CAMERA_ORTHOGRAPHIC;
  c->dir_len_max = 1;
  if (in->type == RR_CAMERA_PERSPECTIVE) {
    perspective_basis(c);
    return rr_ok(dev);
  }
  if (in->type == RR_CAMERA_ORTHOGRAPHIC) {
    float h = in->ortho_height > 0 ? in->ortho_height
                                   : 2 * v3_len(v3_sub(v3_load(in->target), c->eye)) * c->tan_half_h;
    float w = h * (float)width / (float)height;
    c->o0 = v3_sub(v3_scale(c->up, h / 2), v3_scale(c->right, w / 2));
    c->ox = v3_scale(c->right, w / (float)width);
    c->oy = v3_scale(c->up, -h / (float)height);
    c->d0 = c->fwd;
    c->tan_half_h = h / 2, c->tan_half_w = w / 2; /* half extents of the view */
    return rr_ok(dev);
  }
  if (in->type == RR_CAMERA_CUBE) { /* its faces are perspective cameras: no table of rays, no cells */
    c->face = height / 3;
    c->lipschitz = 2.0f / (float)c->face * 1.001f; /* a 90° face, atan' <= 1 on its [-1, 1] image plane */
    c->dir_len_max = sqrtf(3.0f);
    return rr_ok(dev);
  }
  /* Curved: one direction per sample, computed once, and the largest angle between
   * directions of samples one pixel apart (the map's Lipschitz constant). */
  c->dirs = malloc((size_t)width * height * sizeof *c->dirs);
  if (!c->dirs) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the camera's %dx%d rays", width, height);
  c->face = height / 3;
  if (in->type == RR_CAMERA_OPENCV || in->type == RR_CAMERA_OPENCV_FISHEYE) {
    c->lens = *in, c->lens_fold = rr_lens_fold(in);
    if (in->fx == 0 && in->fy == 0) { /* the perspective camera's intrinsics */
      c->lens.fx = c->lens.fy = 0.5f * (float)height / c->tan_half_h;
      c->lens.cx = 0.5f * (float)width - 0.5f, c->lens.cy = 0.5f * (float)height - 0.5f;
    }
    c->lens_field = rr_lens_field(&c->lens, c->lens_fold, width, height);
    c->fine_x = (width + CAMERA_FINE - 1) / CAMERA_FINE; /* (measured with the rays) */
    c->fine = malloc((size_t)c->fine_x * ((height + CAMERA_FINE - 1) / CAMERA_FINE) * 4 * sizeof *c->fine);
    if (!c->fine) {
      rr_cam_release(c);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the camera's %dx%d rays", width, height);
    }
  }
  /* curved_dir's rays, with what depends on the column alone computed once a
   * column, in bands of rows on the threads */
  ray_table rt = {c, NULL};
  if (in->type == RR_CAMERA_LATLONG || in->type == RR_CAMERA_PARABOLIC) {
    vec3 *col = malloc((size_t)width * sizeof *col);
    if (!col) {
      rr_cam_release(c);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the camera's %dx%d rays", width, height);
    }
    for (int x = 0; x < width; x++)
      col[x] = in->type == RR_CAMERA_LATLONG ? latlong_horiz(c, x) : v3_scale(c->right, (float)image_u(c, x));
    rt.col = col;
  }
  rr_parallel_for((height + RAY_ROWS - 1) / RAY_ROWS, threads, ray_rows, &rt);
  free((void *)rt.col);
  switch (in->type) {
  case RR_CAMERA_PARABOLIC: /* conformal, angle = 2 atan(r): at most 2 radians per unit of u */
    c->lipschitz = 2.0f * 2.0f / (float)(width < height ? width : height);
    break;
  case RR_CAMERA_LATLONG: /* ds² = dθ² + sin²θ dφ² <= dθ² + dφ² */
    c->lipschitz = fmaxf(2.0f * (float)RR_PI / (float)width, (float)RR_PI / (float)height);
    break;
  case RR_CAMERA_FISHEYE: /* angle = r·fov/2; the tangential rate sin(a)/r is smaller */
    c->lipschitz = in->fov_deg * (float)RR_PI / 360.0f * 2.0f / (float)(width < height ? width : height);
    break;
  case RR_CAMERA_OPENCV:
  case RR_CAMERA_OPENCV_FISHEYE: { /* the longest chord, band by band on the threads */
    const int bands = (height + RAY_ROWS - 1) / RAY_ROWS;
    float *worst = malloc((size_t)bands * sizeof *worst), most = 0;
    if (!worst) {
      rr_cam_release(c);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the camera's %dx%d rays", width, height);
    }
    rr_parallel_for(bands, threads, chords_of_rows, &(chord_rows){c, worst});
    for (int b = 0; b < bands; b++) most = fmaxf(most, worst[b]);
    free(worst);
    c->lipschitz = 2.0f * asinf(fminf(1.0f, 0.5f * most)) * sqrtf(2.0f);
    break;
  }
  default:
    break;
  }
  c->lipschitz *= 1.001f;
  /* The maps' second derivatives, for binning (vis/traverse.c): per sample step,
   * the square of u, v's (2/W, 2/H) or φ, θ's (2π/W, π/H) step times the bound in
   * those variables. Parabolic: d is quadratic in (u, v), d_uu = d_vv = −fwd.
   * Lat-long: |d_φφ| = sin θ, |d_θθ| = 1. Fisheye, d = (s u, s v, cos kρ) with
   * s = sin(kρ)/ρ = k sinc(kρ): d_uu = (s_uu u + 2 s_u, s_uu v, (cos kρ)_uu), where
   * |s_u| <= |s'| <= 0.44 k², |s_uu| <= max(|s''|, |s'/ρ|) <= k³/3 (sinc's bounds),
   * |(cos kρ)_uu| <= k²; so |d_uu| <= k² (kρ/3 + 1.9) with ρ <= √2 in the image. */
  switch (in->type) {
  case RR_CAMERA_PARABOLIC:
    c->bend_x = 4.0 / ((double)width * width), c->bend_y = 4.0 / ((double)height * height);
    break;
  case RR_CAMERA_LATLONG:
    c->bend_x = 4 * RR_PI * RR_PI / ((double)width * width), c->bend_y = RR_PI * RR_PI / ((double)height * height);
    break;
  case RR_CAMERA_FISHEYE: {
    double k = in->fov_deg * RR_PI / 360, b = k * k * (k * sqrt(2.0) / 3 + 1.9);
    c->bend_x = 4 * b / ((double)width * width), c->bend_y = 4 * b / ((double)height * height);
    break;
  }
  default:
    break;
  }
  /* Cones of coarse cells, for the screen bounds of triangles in curved views. */
  c->cells_x = (width + CAMERA_CELL - 1) / CAMERA_CELL, c->cells_y = (height + CAMERA_CELL - 1) / CAMERA_CELL;
  c->cells = malloc((size_t)c->cells_x * c->cells_y * 4 * sizeof *c->cells);
  if (!c->cells) {
    rr_cam_release(c);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the camera's %dx%d rays", width, height);
  }
  for (int cy = 0; cy < c->cells_y; cy++)
    for (int cx = 0; cx < c->cells_x; cx++) {
      float *cell = c->cells + 4 * ((size_t)cy * c->cells_x + cx);
      int x1 = (cx + 1) * CAMERA_CELL < width ? (cx + 1) * CAMERA_CELL : width;
      int y1 = (cy + 1) * CAMERA_CELL < height ? (cy + 1) * CAMERA_CELL : height;
      vec3 axis = v3(0, 0, 0);
      float angle;
      int cone = rr_cam_rect_cone(c, cx * CAMERA_CELL, cy * CAMERA_CELL, x1, y1, &axis, &angle);
      cell[0] = axis.x, cell[1] = axis.y, cell[2] = axis.z;
      /* no rays, a cone, no bound */
      cell[3] = cone < 0 ? -1.0f : cone > 0 && angle < CAMERA_NO_CONE ? angle : CAMERA_NO_CONE;
    }
  return rr_ok(dev);
}

void rr_cam_release(camera *c) {
  free(c->dirs), free(c->cells), free(c->fine);
  c->dirs = NULL, c->cells = NULL, c->fine = NULL;
}

bool rr_cam_ray(const camera *c, int x, int y, vec3 *origin, vec3 *dir) {
  float sx = (float)x + c->sx0, sy = (float)y + c->sy0;
  *origin = c->eye;
  switch (c->type) {
  case RR_CAMERA_PERSPECTIVE:
    *dir = camera_dir(c, sx, sy);
    return true;
  case RR_CAMERA_ORTHOGRAPHIC:
    *origin = v3_add(c->eye, v3_add(c->o0, v3_add(v3_scale(c->ox, sx), v3_scale(c->oy, sy))));
    *dir = c->fwd;
    return true;
  case RR_CAMERA_CUBE:
    *dir = cube_dir(c, x, y);
    return dir->x != 0 || dir->y != 0 || dir->z != 0;
  default:
    *dir = c->dirs[(size_t)y * c->width + x];
    return dir->x != 0 || dir->y != 0 || dir->z != 0;
  }
}

bool rr_cam_ray_diff(const camera *c, int x, int y, vec3 *origin, vec3 *dir, vec3 do_dxy[2], vec3 dd_dxy[2]) {
  bool has = rr_cam_ray(c, x, y, origin, dir);
  do_dxy[0] = do_dxy[1] = dd_dxy[0] = dd_dxy[1] = v3(0, 0, 0);
  switch (c->type) {
  case RR_CAMERA_PERSPECTIVE: dd_dxy[0] = c->dx, dd_dxy[1] = c->dy; break;
  case RR_CAMERA_ORTHOGRAPHIC: do_dxy[0] = c->ox, do_dxy[1] = c->oy; break;
  default:
    if (has) curved_dir(c, x, y, dd_dxy);
    break;
  }
  return has;
}

bool rr_cam_project(const camera *c, vec3 p, float *sx, float *sy) {
  float z = v3_dot(p, c->fwd);
  if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
    if (!(z > 0)) return false;
    *sx = (v3_dot(p, c->right) / c->tan_half_w + 1.0f) * 0.5f * (float)c->width;
    *sy = (1.0f - v3_dot(p, c->up) / c->tan_half_h) * 0.5f * (float)c->height;
    return true;
  }
  if (c->type != RR_CAMERA_PERSPECTIVE || !(z > 0)) return false;
  float u = v3_dot(p, c->right) / (z * c->tan_half_w), v = v3_dot(p, c->up) / (z * c->tan_half_h);
  *sx = (u + 1.0f) * 0.5f * (float)c->width;
  *sy = (1.0f - v) * 0.5f * (float)c->height;
  return true;
}

/* rr_cam_rect_cone from camera.fine: about the centre sample's ray (else the
 * first cell's axis), the cones of the cells the rectangle meets, each within
 * the angle between its axis and ours. */
static int fine_cone(const camera *c, int x0, int y0, int x1, int y1, vec3 *axis, float *angle) {
  const int n = CAMERA_FINE;
  vec3 d = c->dirs[(size_t)((y0 + y1 - 1) / 2) * c->width + (x0 + x1 - 1) / 2];
  for (int y = y0 / n; y <= (y1 - 1) / n && !has_ray(d); y++)
    for (int x = x0 / n; x <= (x1 - 1) / n && !has_ray(d); x++) {
      const float *cell = c->fine + 4 * ((size_t)y * c->fine_x + x);
      if (cell[3] >= 0) d = v3(cell[0], cell[1], cell[2]);
    }
  if (!has_ray(d)) return -1;
  double a[3], worst = 0;
  unit_of(d, a);
  for (int y = y0 / n; y <= (y1 - 1) / n; y++)
    for (int x = x0 / n; x <= (x1 - 1) / n; x++) {
      const float *cell = c->fine + 4 * ((size_t)y * c->fine_x + x);
      if (cell[3] >= 0) worst = fmax(worst, angle_over(a, v3(cell[0], cell[1], cell[2])) + cell[3]);
    }
  *axis = v3_norm(d);
  *angle = (float)worst + 1e-5f;
  return 1;
}

float rr_cam_rect_pixel_angle(const camera *c, int x0, int y0, int x1, int y1, int cone, float angle) {
  const float hx = (float)(x1 - x0) * 0.5f + 0.5f, hy = (float)(y1 - y0) * 0.5f + 0.5f;
  return c->fine && cone > 0 ? angle / sqrtf(hx * hx + hy * hy) : c->lipschitz;
}

int rr_cam_rect_cone(const camera *c, int x0, int y0, int x1, int y1, vec3 *axis, float *angle) {
  if (c->planar) return 0;
  if (c->fine) return fine_cone(c, x0, y0, x1, y1, axis, angle);
  if (c->type == RR_CAMERA_CUBE && (x0 / c->face != (x1 - 1) / c->face || y0 / c->face != (y1 - 1) / c->face))
    return 0; /* the cross is discontinuous between faces */
  /* The centre sample's direction and the Lipschitz bound over the half-diagonal
   * (plus half a pixel: every sample lies within that distance of the centre). */
  int cx = (x0 + x1 - 1) / 2, cy = (y0 + y1 - 1) / 2;
  vec3 d = c->dirs[(size_t)cy * c->width + cx];
  float hx = (float)(x1 - x0) * 0.5f + 0.5f, hy = (float)(y1 - y0) * 0.5f + 0.5f;
  if (d.x == 0 && d.y == 0 && d.z == 0) {
    /* No ray at the centre (the rim of a disk, the gaps of a cross): start from
     * any sample that has one, with the whole diagonal as radius. */
    bool found = false;
    for (int y = y0; y < y1 && !found; y++)
      for (int x = x0; x < x1 && !found; x++) {
        d = c->dirs[(size_t)y * c->width + x];
        found = d.x != 0 || d.y != 0 || d.z != 0;
      }
    if (!found) return -1;
    hx *= 2, hy *= 2;
  }
  *axis = v3_norm(d);
  *angle = c->lipschitz * sqrtf(hx * hx + hy * hy) + 1e-5f;
  return 1;
}

rr_error rr_camera_frame(rr_device *dev, const rr_scene *s, int width, int height, rr_camera *cam) {
  if (!s || !cam) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_camera_frame: NULL argument");
  if (s->ntris == 0) return rr_fail(dev, RR_ERROR_EMPTY, "cannot frame an empty scene");
  if (width < 1 || height < 1) return rr_fail(dev, RR_ERROR_ARGUMENT, "bad image size %dx%d", width, height);
  if (s->has_view) { /* a built-in that comes with its own view */
    v3_store(cam->eye, s->view_eye), v3_store(cam->target, s->view_target), v3_store(cam->up, s->up);
    return rr_ok(dev);
  }
  vec3 centre = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
  float th = cam->fov_deg > 0 && cam->fov_deg < 180 ? tanf(cam->fov_deg * (float)RR_PI / 360.0f) : 0.41f;
  float tw = th * (float)width / (float)height, fill = 0.94f;
  /* Look at the model's front from a little above (for a Y-up file from +Z and
   * +Y); back off until every corner of the bounding box is inside the view: for a
   * corner at offset o from the centre, at depth D - o·dir, |o·right| <= depth·tw
   * and |o·up| <= depth·th. */
  vec3 dir = v3_norm(v3_add(s->front, v3_scale(s->up, 0.5f)));
  vec3 right = v3_norm(v3_cross(v3_neg(dir), s->up)), up = v3_cross(right, v3_neg(dir));
  float dist = 0;
  for (int k = 0; k < 8; k++) {
    vec3 o = v3_sub(v3(k & 1 ? s->bmax.x : s->bmin.x, k & 2 ? s->bmax.y : s->bmin.y, k & 4 ? s->bmax.z : s->bmin.z),
                    centre);
    float along = v3_dot(o, dir);
    dist = fmaxf(dist, along + fabsf(v3_dot(o, right)) / (tw * fill));
    dist = fmaxf(dist, along + fabsf(v3_dot(o, up)) / (th * fill));
    dist = fmaxf(dist, along * 1.01f);
  }
  if (!(dist > 0)) dist = 1;
  vec3 eye = v3_add(centre, v3_scale(dir, dist));
  cam->eye[0] = eye.x, cam->eye[1] = eye.y, cam->eye[2] = eye.z;
  cam->target[0] = centre.x, cam->target[1] = centre.y, cam->target[2] = centre.z;
  v3_store(cam->up, s->up);
  return rr_ok(dev);
}

rr_error rr_scene_get_camera(rr_device *dev, const rr_scene *s, uint32_t index, int width, int height,
                             rr_camera *cam) {
  if (!s || !cam) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_scene_get_camera: NULL argument");
  if (index >= s->ncameras)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "camera %u out of range (the scene has %u)", index, s->ncameras);
  if (width < 1 || height < 1) return rr_fail(dev, RR_ERROR_ARGUMENT, "bad image size %dx%d", width, height);
  const file_camera *c = &s->cameras[index];
  rr_camera_init(cam);
  vec3 target = v3_add(c->eye, c->fwd);
  v3_store(cam->eye, c->eye), v3_store(cam->target, target), v3_store(cam->up, c->up);
  float aspect = (float)width / (float)height;
  if (c->ortho_width > 0) {
    cam->type = RR_CAMERA_ORTHOGRAPHIC;
    cam->ortho_height = c->ortho_width / aspect;
  } else {
    /* tan(fov_y / 2) = tan(fov_x / 2) / aspect: the file's width fills the image's */
    cam->fov_deg = (c->fov_vertical ? c->fov : 2.0f * atanf(tanf(0.5f * c->fov) / aspect)) * 180.0f / (float)RR_PI;
  }
  return rr_camera_check(dev, cam);
}

const char *rr_scene_camera_name(const rr_scene *s, uint32_t index) {
  return s && index < s->ncameras ? s->cameras[index].name : NULL;
}

rr_error rr_scene_find_camera(rr_device *dev, const rr_scene *s, const char *name, uint32_t *index) {
  if (!s || !name || !index) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_scene_find_camera: NULL argument");
  for (uint32_t i = 0; i < s->ncameras; i++)
    if (s->cameras[i].name && strcmp(s->cameras[i].name, name) == 0) return *index = i, rr_ok(dev);
  char *end;
  unsigned long i = strtoul(name, &end, 10);
  if (*name >= '0' && *name <= '9' && !*end && i < s->ncameras) return *index = (uint32_t)i, rr_ok(dev);
  if (!s->ncameras) return rr_fail(dev, RR_ERROR_ARGUMENT, "no camera '%s': the scene defines no cameras", name);
  /* one line naming them all (indices for the unnamed), cut short on a huge list */
  char list[512] = "";
  size_t len = 0;
  for (uint32_t c = 0; c < s->ncameras && len < sizeof list; c++) {
    const char *nm = s->cameras[c].name;
    int n = nm ? snprintf(list + len, sizeof list - len, "%s'%s'", c ? ", " : "", nm)
               : snprintf(list + len, sizeof list - len, "%s%u (unnamed)", c ? ", " : "", c);
    len += n > 0 ? (size_t)n : 0;
  }
  return rr_fail(dev, RR_ERROR_ARGUMENT, "no camera '%s' (the scene's %u: %s%s)", name, s->ncameras, list,
                 len >= sizeof list ? "..." : "");
}

void rr_cam_for_ray(const float org[3], const float dir[3], camera *out) {
  memset(out, 0, sizeof *out);
  vec3 d = v3_load(dir);
  out->eye = v3_load(org);
  out->d0 = d;
  /* dx: perpendicular to d in the plane of its two largest components; dy = d × dx. */
  float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
  vec3 u = ax <= ay && ax <= az ? v3(0, d.z, -d.y) : ay <= az ? v3(-d.z, 0, d.x) : v3(d.y, -d.x, 0);
  out->dx = u;
  out->dy = v3_cross(d, u);
  out->fwd = d;
}

rr_error rr_camera_set_extrinsics(rr_device *dev, rr_camera *cam, const float R[9], const float t[3]) {
  if (!cam || !R || !t) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_camera_set_extrinsics: NULL argument");
  double err = 0, det = 0;
  for (int i = 0; i < 12; i++)
    if (!isfinite(i < 9 ? R[i] : t[i - 9])) return rr_fail(dev, RR_ERROR_ARGUMENT, "extrinsics must be finite");
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) { /* R·Rᵀ = I */
      double dot = 0;
      for (int k = 0; k < 3; k++) dot += (double)R[3 * i + k] * R[3 * j + k];
      err = fmax(err, fabs(dot - (i == j)));
    }
  for (int i = 0; i < 3; i++)
    det += R[i] * ((double)R[3 + (i + 1) % 3] * R[6 + (i + 2) % 3] - (double)R[3 + (i + 2) % 3] * R[6 + (i + 1) % 3]);
  if (!(err <= 1e-3) || !(det > 0))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "R is not a rotation (|R·Rt - I| = %g, det %g)", err, det);
  /* eye = -Rᵀt; the camera's z row is forward, its y row down. The target lies as far
   * ahead as the eye is from the origin (at least 1), so that target - eye in floats
   * keeps the direction to float precision wherever the camera is. */
  double e[3] = {0, 0, 0}, len = 0;
  for (int i = 0; i < 3; i++) {
    for (int k = 0; k < 3; k++) e[i] -= (double)R[3 * k + i] * t[k];
    len += e[i] * e[i];
  }
  double ahead = fmax(1.0, sqrt(len));
  for (int i = 0; i < 3; i++) {
    cam->eye[i] = (float)e[i];
    cam->target[i] = (float)(e[i] + ahead * R[6 + i]);
    cam->up[i] = -R[3 + i];
  }
  return rr_ok(dev);
}

rr_error rr_camera_rays(rr_device *dev, const rr_camera *cam, int width, int height, float *org, float *dir) {
  camera c;
  rr_error e = rr_cam_setup(dev, cam, width, height, &c);
  if (e) return e;
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++) {
      vec3 o, d;
      size_t i = (size_t)y * width + x;
      if (!rr_cam_ray(&c, x, y, &o, &d)) d = v3(0, 0, 0);
      if (org) v3_store(org + 3 * i, o);
      if (dir) v3_store(dir + 3 * i, v3_norm(d));
    }
  rr_cam_release(&c);
  return rr_ok(dev);
}
