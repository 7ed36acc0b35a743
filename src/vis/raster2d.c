/* 2dr-bb and 2dr-bin: the classic 2D pipeline that 3D rasterization is measured
 * against (paper sect. 3.1; slides "Graphics Pipeline & Rasterization II").
 *
 *   vertex stage  world → eye (view matrix) → clip (projection matrix), in double
 *   clipping      near plane and a guard band, in homogeneous space
 *   setup         vertices snapped to 8 sub-pixel bits; Pineda edge functions in
 *                 exact 64-bit integers with the top-left fill rule
 *   raster        2dr-bb: every sample of the bounding box; 2dr-bin: 64² tiles,
 *                 16² and 4² blocks rejected or accepted whole by their corner
 *                 samples, early-z against per-block farthest depths
 *   samples       a pattern of N positions in one pass: every triangle is
 *                 projected, clipped and set up once, then rasterized at each
 *                 position into its layer (the snapped vertices moved by the
 *                 position's shift are a translation: the edge coefficients stay,
 *                 the constants move by integers)
 *   sample        coverage from the integer edge values; depth and barycentrics
 *                 perspective-correct from the planes of 1/w, t/w and λ/w given by
 *                 the inverse of the matrix of homogeneous vertices (Olano & Greer,
 *                 the slides' interpolation matrix)
 *
 * The edge values are exact integers, so evaluating them directly (at a tile corner)
 * or incrementally (along a row) gives the same numbers: 2dr-bin produces the same
 * visibility buffer as 2dr-bb bit for bit, and a sample on an edge shared by two
 * triangles is claimed by exactly one of them. */
#include "vis/hiz.h"
#include "vis/sortmiddle.h"

#include <string.h>

#define SUBPIX_BITS 8
#define SUBPIX (1 << SUBPIX_BITS)
/* Guard band: clip only where the projection leaves ±GUARD_PX pixels around the
 * screen centre. With screens up to 16384 pixels, snapped coordinates stay below
 * 2^24, edge coefficients below 2^25 and edge values below 2^51: int64 is exact. */
#define GUARD_PX 32768.0
#define MAX_POLY 9 /* a triangle clipped by 5 planes has at most 8 vertices */
#define MAX_SUB (MAX_POLY - 2)
#define BATCH 16384 /* triangles set up before they are rasterized */
#define CHUNK 2048  /* triangles per setup job */
_Static_assert(CHUNK * MAX_SUB <= SM_CHUNK_MAX, "a band lists a chunk's sub-triangles by 16-bit index");

/* ---- vertex stage ---------------------------------------------------------- */

/* The fixed state of the pipeline for one camera and scene. */
typedef struct pipe2d {
  double clip[4][4]; /* world → homogeneous clip coordinates: projection × view */
  double depth[4];   /* world → t, the ray parameter along the camera's unnormalised ray */
  double kx, ky;     /* guard band in clip units: |x| ≤ kx·w, |y| ≤ ky·w */
  double hw, hh;     /* half the image size: the viewport transform */
  double near;       /* z_c = t − near */
  bool depth_is_w;   /* pinhole: t = w_c, so the vertex stage skips the depth row */
  int width, height;
  bool cull;
  /* The kernels test samples at sub-pixel SUBPIX/2 of each pixel; position s of
   * the pattern (sx0, sy0), snapped to sub-pixels like the vertices, is reached by
   * moving the snapped vertices by `shift` (0 for the centre). */
  int samples;
  int64_t shift_x[RR_MAX_SAMPLES], shift_y[RR_MAX_SAMPLES];
  int64_t shift_lo[2], shift_hi[2]; /* their range in x and y */
  double sx0[RR_MAX_SAMPLES], sy0[RR_MAX_SAMPLES];
} pipe2d;

static void mat4_mul(double r[4][4], const double a[4][4], const double b[4][4]) {
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      double s = 0;
      for (int k = 0; k < 4; k++) s += a[i][k] * b[k][j];
      r[i][j] = s;
    }
}

/* The near plane: tiny against the scene, since 3D rasterization has none; only
 * geometry closer to the eye than 1e-9 of the scene's diagonal is lost. Depth and
 * barycentrics do not depend on it (they come from the unclipped triangle). */
static double near_distance(const rr_scene *s) {
  double d = v3_len(v3_sub(s->bmax, s->bmin));
  return d > 0 && isfinite(d) ? 1e-9 * d : 1e-30;
}

/* Inverse of the 3×3 matrix with columns a, b, c (false when singular). */
static bool inverse3(const double a[3], const double b[3], const double c[3], double inv[3][3]) {
  const double *col[3] = {a, b, c};
  for (int i = 0; i < 3; i++) {
    const double *u = col[(i + 1) % 3], *v = col[(i + 2) % 3];
    inv[i][0] = u[1] * v[2] - u[2] * v[1], inv[i][1] = u[2] * v[0] - u[0] * v[2], inv[i][2] = u[0] * v[1] - u[1] * v[0];
  }
  double det = a[0] * inv[0][0] + a[1] * inv[0][1] + a[2] * inv[0][2];
  if (!(det != 0) || !isfinite(det)) return false;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) inv[i][j] /= det;
  return true;
}

/* View matrix: world → eye space, x along right, y along up, z along fwd. The
 * projection inverts the camera's own rays, so every point of the ray of sample
 * (sx, sy) lands on (sx, sy) exactly:
 *   pinhole:      q = w·(d0 + sx·dx + sy·dy), so (sx·w, sy·w, w) = [dx dy d0]⁻¹·q and
 *                 the ray parameter t is w (for this orthonormal camera it is the
 *                 usual frustum matrix: x_e/tan_w, y_e/tan_h, w = z_e);
 *   orthographic: q = o0 + sx·ox + sy·oy + t·fwd, so (sx, sy, t) = [ox oy fwd]⁻¹·(q − o0)
 *                 and w = 1.
 * Clip space is OpenGL's for x and y (x/w, y/w in [-1, 1] on screen, y up); the near
 * plane is z_c = t − near ≥ 0. */
static bool pipe_setup(pipe2d *pp, const rr_scene *s, const camera *cams, int samples, bool cull) {
  const camera *c = cams; /* the cameras of a pattern differ in (sx0, sy0) only */
  bool ortho = c->type == RR_CAMERA_ORTHOGRAPHIC;
  if (c->type != RR_CAMERA_PERSPECTIVE && !ortho) return false; /* curved views have no projection */
  pp->samples = samples;
  pp->shift_lo[0] = pp->shift_lo[1] = INT64_MAX, pp->shift_hi[0] = pp->shift_hi[1] = INT64_MIN;
  for (int k = 0; k < samples; k++) {
    int64_t x = SUBPIX / 2 - (int64_t)lround(cams[k].sx0 * SUBPIX), y = SUBPIX / 2 - (int64_t)lround(cams[k].sy0 * SUBPIX);
    pp->shift_x[k] = x, pp->shift_y[k] = y;
    pp->sx0[k] = (double)(SUBPIX / 2 - x) / SUBPIX, pp->sy0[k] = (double)(SUBPIX / 2 - y) / SUBPIX;
    pp->shift_lo[0] = x < pp->shift_lo[0] ? x : pp->shift_lo[0], pp->shift_hi[0] = x > pp->shift_hi[0] ? x : pp->shift_hi[0];
    pp->shift_lo[1] = y < pp->shift_lo[1] ? y : pp->shift_lo[1], pp->shift_hi[1] = y > pp->shift_hi[1] ? y : pp->shift_hi[1];
  }
  vec3 axis[3] = {c->right, c->up, c->fwd};
  double view[4][4] = {{0}}, proj[4][4] = {{0}};
  for (int r = 0; r < 3; r++) {
    double a[3] = {axis[r].x, axis[r].y, axis[r].z};
    view[r][0] = a[0], view[r][1] = a[1], view[r][2] = a[2];
    view[r][3] = -(a[0] * c->eye.x + a[1] * c->eye.y + a[2] * c->eye.z);
  }
  view[3][3] = 1;
  /* The camera's sample parameterization in eye space, and its inverse. */
  vec3 d[4] = {ortho ? c->ox : c->dx, ortho ? c->oy : c->dy, c->d0, ortho ? c->o0 : v3(0, 0, 0)};
  double de[4][3], inv[3][3];
  for (int k = 0; k < 4; k++)
    for (int r = 0; r < 3; r++)
      de[k][r] = (double)d[k].x * axis[r].x + (double)d[k].y * axis[r].y + (double)d[k].z * axis[r].z;
  if (!inverse3(de[0], de[1], de[2], inv)) return false;
  /* Rows over eye space (x, y, z, 1): X = sx·w, Y = sy·w, W = w, T = t. */
  double X[4], Y[4], W[4] = {0, 0, 0, 1}, T[4];
  for (int j = 0; j < 3; j++) X[j] = inv[0][j], Y[j] = inv[1][j], T[j] = inv[2][j];
  X[3] = -(inv[0][0] * de[3][0] + inv[0][1] * de[3][1] + inv[0][2] * de[3][2]);
  Y[3] = -(inv[1][0] * de[3][0] + inv[1][1] * de[3][1] + inv[1][2] * de[3][2]);
  T[3] = -(inv[2][0] * de[3][0] + inv[2][1] * de[3][1] + inv[2][2] * de[3][2]);
  if (!ortho) memcpy(W, T, sizeof W);
  double hw = 0.5 * c->width, hh = 0.5 * c->height, near = near_distance(s);
  for (int j = 0; j < 4; j++) {
    proj[0][j] = X[j] / hw - W[j]; /* x_c = sx·w/hw − w */
    proj[1][j] = W[j] - Y[j] / hh; /* y_c = w − sy·w/hh */
    proj[2][j] = T[j];             /* z_c = t − near */
    proj[3][j] = W[j];             /* w_c = w */
  }
  proj[2][3] -= near;
  mat4_mul(pp->clip, proj, view);
  for (int j = 0; j < 4; j++) pp->depth[j] = T[0] * view[0][j] + T[1] * view[1][j] + T[2] * view[2][j] + T[3] * view[3][j];
  pp->near = near;
  pp->depth_is_w = !ortho;
  pp->width = c->width, pp->height = c->height;
  pp->hw = hw, pp->hh = hh;
  pp->kx = GUARD_PX / hw, pp->ky = GUARD_PX / hh;
  pp->cull = cull;
  return true;
}

/* A vertex in clip space and its depth t, which clipping interpolates too. */
enum { CX, CY, CZ, CW, CT, NCOMP };
typedef struct cvert {
  double v[NCOMP];
} cvert;

static inline void vertex_stage(const pipe2d *pp, vec3 p, cvert *out) {
  double x = p.x, y = p.y, z = p.z;
  const double(*m)[4] = pp->clip;
  out->v[CX] = m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3];
  out->v[CY] = m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3];
  out->v[CW] = m[3][0] * x + m[3][1] * y + m[3][2] * z + m[3][3];
  out->v[CT] = pp->depth_is_w ? out->v[CW] : pp->depth[0] * x + pp->depth[1] * y + pp->depth[2] * z + pp->depth[3];
  out->v[CZ] = out->v[CT] - pp->near; /* the clip matrix's z row, without recomputing t */
}

/* ---- clipping -------------------------------------------------------------- */

/* Planes as signed distances, inside when ≥ 0: near, the guard band (clipped), and
 * the screen's sides (only to reject triangles that are wholly off screen). */
enum { P_NEAR, P_GUARD_L, P_GUARD_R, P_GUARD_T, P_GUARD_B, P_LEFT, P_RIGHT, P_TOP, P_BOTTOM, NPLANES };
#define CLIP_PLANES 5

static double plane_dist(const pipe2d *pp, int plane, const double *v) {
  switch (plane) {
  case P_NEAR: return v[CZ];
  case P_GUARD_L: return pp->kx * v[CW] + v[CX];
  case P_GUARD_R: return pp->kx * v[CW] - v[CX];
  case P_GUARD_T: return pp->ky * v[CW] - v[CY];
  case P_GUARD_B: return pp->ky * v[CW] + v[CY];
  case P_LEFT: return v[CW] + v[CX];
  case P_RIGHT: return v[CW] - v[CX];
  case P_TOP: return v[CW] - v[CY];
  default: return v[CW] + v[CY];
  }
}

KERNEL unsigned outcode(const pipe2d *pp, const cvert *v) {
  double x = v->v[CX], y = v->v[CY], w = v->v[CW], gx = pp->kx * w, gy = pp->ky * w;
  return (unsigned)(v->v[CZ] < 0) << P_NEAR | (unsigned)(gx + x < 0) << P_GUARD_L |
         (unsigned)(gx - x < 0) << P_GUARD_R | (unsigned)(gy - y < 0) << P_GUARD_T |
         (unsigned)(gy + y < 0) << P_GUARD_B | (unsigned)(w + x < 0) << P_LEFT | (unsigned)(w - x < 0) << P_RIGHT |
         (unsigned)(w - y < 0) << P_TOP | (unsigned)(w + y < 0) << P_BOTTOM;
}

/* Sutherland–Hodgman against one plane. A new vertex is interpolated from the
 * edge's inside end towards its outside end, whichever way the polygon runs the
 * edge, so the two triangles of a shared edge make bit-identical vertices. */
static int clip_plane(const pipe2d *pp, int plane, const cvert *in, int n, cvert *out) {
  int m = 0;
  for (int k = 0; k < n; k++) {
    const cvert *a = &in[k], *b = &in[(k + 1) % n];
    double da = plane_dist(pp, plane, a->v), db = plane_dist(pp, plane, b->v);
    if (da >= 0) out[m++] = *a;
    if ((da >= 0) != (db >= 0)) {
      const cvert *i = da >= 0 ? a : b, *o = da >= 0 ? b : a;
      double di = da >= 0 ? da : db, dout = da >= 0 ? db : da;
      double s = di / (di - dout);
      for (int c = 0; c < NCOMP; c++) out[m].v[c] = i->v[c] + s * (o->v[c] - i->v[c]);
      m++;
    }
  }
  return m;
}

/* ---- triangle setup -------------------------------------------------------- */

/* A (sub-)triangle ready for rasterization. Coverage: edge i (opposite vertex i) is
 * E_i(X, Y) = a[i]·X + b[i]·Y + c[i] at fixed-point sample position (X, Y), positive
 * inside whichever way the triangle faces; c is biased by −1 on edges that do not
 * own their samples, so a sample is covered when E_0, E_1, E_2 ≥ 0. Interpolation:
 * planes (value at the sample of pixel (rect[0], rect[1]), d/dx, d/dy) of 1/w, t/w,
 * λ1/w and λ2/w of the original triangle. */
typedef struct tri2d {
  int64_t c[3];
  int32_t a[3], b[3];
  float pw[3], pt[3], p1[3], p2[3];
  float tmin, tmax; /* depth range of the (sub-)triangle: interpolated depths are clamped to it */
  int16_t rect[4];  /* inclusive sample rectangle on screen */
  uint32_t id;
  bool back;        /* seen from behind */
} tri2d;

/* The original triangle's interpolation planes at the screen origin: with the
 * homogeneous screen positions (X, Y, W) = (sx·w, sy·w, w) of its vertices as the
 * columns of M, M⁻¹·(sx, sy, 1) = (λ0, λ1, λ2)/w at every sample. Row i of M⁻¹ is
 * the cross product of the other two columns over det M. No division by w: the
 * planes stay exact for vertices behind the eye or at the near plane. */
typedef struct planes {
  double w[3], t[3], l1[3], l2[3];
} planes;

KERNEL bool interpolation_planes(const pipe2d *pp, const cvert v[3], planes *pl) {
  double col[3][3];
  for (int k = 0; k < 3; k++) {
    col[k][0] = (v[k].v[CX] + v[k].v[CW]) * pp->hw;
    col[k][1] = (v[k].v[CW] - v[k].v[CY]) * pp->hh;
    col[k][2] = v[k].v[CW];
  }
  double r[3][3];
  for (int i = 0; i < 3; i++) {
    const double *a = col[(i + 1) % 3], *b = col[(i + 2) % 3];
    r[i][0] = a[1] * b[2] - a[2] * b[1], r[i][1] = a[2] * b[0] - a[0] * b[2], r[i][2] = a[0] * b[1] - a[1] * b[0];
  }
  double det = col[0][0] * r[0][0] + col[0][1] * r[0][1] + col[0][2] * r[0][2];
  if (!(det != 0) || !isfinite(det)) return false; /* the triangle's plane holds the eye */
  /* M⁻¹ has rows r_i/det with columns (coefficient of sx, of sy, constant). */
  double inv = 1.0 / det;
  for (int j = 0; j < 3; j++) {
    double r0 = r[0][j] * inv, r1 = r[1][j] * inv, r2 = r[2][j] * inv;
    pl->w[j] = r0 + r1 + r2;
    pl->t[j] = v[0].v[CT] * r0 + v[1].v[CT] * r1 + v[2].v[CT] * r2;
    pl->l1[j] = r1, pl->l2[j] = r2;
  }
  return true;
}

/* A plane re-referenced to the sample (sx, sy), where float keeps the most
 * precision for the triangle's own samples. */
static void plane_at(const double p[3], double sx, double sy, float out[3]) {
  out[0] = (float)(p[2] + p[0] * sx + p[1] * sy);
  out[1] = (float)p[0], out[2] = (float)p[1];
}

/* The planes of t at its reference sample: that of pixel (rect[0], rect[1]) at
 * position s. */
KERNEL void planes_at(const pipe2d *pp, tri2d *t, const planes *pl, int s) {
  double sx = t->rect[0] + pp->sx0[s], sy = t->rect[1] + pp->sy0[s];
  plane_at(pl->w, sx, sy, t->pw);
  plane_at(pl->t, sx, sy, t->pt);
  plane_at(pl->l1, sx, sy, t->p1);
  plane_at(pl->l2, sx, sy, t->p2);
}

/* A (sub-)triangle set up for every position of a pattern: t's edges are those of
 * the unshifted vertices and its rectangle the union of the positions' (which the
 * bands are sorted by); each position's tri2d follows from the snapped vertices'
 * bounds and the planes (tri2d_at). */
typedef struct tri2dm {
  tri2d t;
  int32_t box[4]; /* x0, y0, x1, y1 of the snapped vertices, in sub-pixels */
  planes pl;
} tri2dm;

static int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/* Viewport transform and snapping to 8 sub-pixel bits (round half away from zero). */
KERNEL void snap(const pipe2d *pp, const cvert *c, int64_t *x, int64_t *y) {
  double iw = 1.0 / c->v[CW];
  double sx = (c->v[CX] * iw * pp->hw + pp->hw) * SUBPIX, sy = (pp->hh - c->v[CY] * iw * pp->hh) * SUBPIX;
  *x = (int64_t)(sx >= 0 ? sx + 0.5 : sx - 0.5);
  *y = (int64_t)(sy >= 0 ? sy + 0.5 : sy - 0.5);
}

/* The samples (x + 0.5, y + 0.5) inside the snapped vertices' bounds `box` moved by
 * lo (its low sides) and hi (its high sides), on screen; false when there are none. */
KERNEL bool sample_rect(const pipe2d *pp, const int32_t box[4], const int64_t lo[2], const int64_t hi[2],
                     int16_t rect[4]) {
  int64_t x0 = -floor_div(SUBPIX / 2 - (box[0] + lo[0]), SUBPIX), y0 = -floor_div(SUBPIX / 2 - (box[1] + lo[1]), SUBPIX);
  int64_t x1 = floor_div(box[2] + hi[0] - SUBPIX / 2, SUBPIX), y1 = floor_div(box[3] + hi[1] - SUBPIX / 2, SUBPIX);
  if (x0 < 0) x0 = 0;
  if (y0 < 0) y0 = 0;
  if (x1 > pp->width - 1) x1 = pp->width - 1;
  if (y1 > pp->height - 1) y1 = pp->height - 1;
  if (x0 > x1 || y0 > y1) return false;
  rect[0] = (int16_t)x0, rect[1] = (int16_t)y0, rect[2] = (int16_t)x1, rect[3] = (int16_t)y1;
  return true;
}

/* Position s of a pattern's triangle m: its vertices moved by the position's shift,
 * which moves the edge constants by exact integers. False when it covers no sample. */
static bool tri2d_at(const pipe2d *pp, const tri2dm *m, int s, tri2d *t) {
  const int64_t shift[2] = {pp->shift_x[s], pp->shift_y[s]};
  *t = m->t;
  if (!sample_rect(pp, m->box, shift, shift, t->rect)) return false;
  for (int i = 0; i < 3; i++) t->c[i] -= t->a[i] * shift[0] + t->b[i] * shift[1];
  planes_at(pp, t, &m->pl, s);
  return true;
}

/* Sets up the coverage of one (sub-)triangle of snapped vertices, and their bounds
 * in box; false when it covers no sample of the pattern (degenerate after snapping,
 * culled, or between sample positions). One position: t is that position's; more:
 * t's edges are the unshifted vertices' and its rectangle the positions' union. */
KERNEL bool setup_tri(const pipe2d *pp, const int64_t X[3], const int64_t Y[3], tri2d *t, int32_t box[4], const bool all) {
  /* Twice the signed area, y down: negative for a triangle that is counter-clockwise
   * as the viewer sees it, the front face (as rr_tri_setup decides it). */
  int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
  if (area == 0) return false;
  t->back = area > 0;
  if (t->back && pp->cull) return false;
  int64_t x0 = X[0], x1 = X[0], y0 = Y[0], y1 = Y[0];
  for (int k = 1; k < 3; k++) {
    x0 = X[k] < x0 ? X[k] : x0, x1 = X[k] > x1 ? X[k] : x1;
    y0 = Y[k] < y0 ? Y[k] : y0, y1 = Y[k] > y1 ? Y[k] : y1;
  }
  box[0] = (int32_t)x0, box[1] = (int32_t)y0, box[2] = (int32_t)x1, box[3] = (int32_t)y1;
  const int64_t shift[2] = {pp->shift_x[0], pp->shift_y[0]};
  if (!sample_rect(pp, box, all ? pp->shift_lo : shift, all ? pp->shift_hi : shift, t->rect)) return false;
  int64_t shx = all ? 0 : shift[0], shy = all ? 0 : shift[1];
  int64_t sign = area > 0 ? 1 : -1;
  for (int i = 0; i < 3; i++) {
    int p = (i + 1) % 3, q = (i + 2) % 3;
    int64_t a = -(Y[q] - Y[p]) * sign, b = (X[q] - X[p]) * sign;
    t->a[i] = (int32_t)a, t->b[i] = (int32_t)b;
    t->c[i] = -(a * (X[p] + shx) + b * (Y[p] + shy));
    /* Top-left rule: a sample on the edge belongs to the triangle whose inside
     * lies to its right (a > 0), or below for a horizontal edge (b > 0). */
    if (!(a > 0 || (a == 0 && b > 0))) t->c[i] -= 1;
  }
  return true;
}

/* Sets up the interpolation of a (sub-)triangle that covers samples: its planes
 * for one position, or kept whole for tri2d_at (a tri2dm). */
KERNEL void setup_interp(const pipe2d *pp, tri2d *t, const planes *pl, const int32_t box[4], const double depth[3],
                     uint32_t id, const bool all) {
  planes_at(pp, t, pl, 0); /* a pattern's slopes are its positions' too */
  if (all) {
    tri2dm *m = (tri2dm *)t;
    memcpy(m->box, box, sizeof m->box);
    m->pl = *pl;
  }
  /* Depth is linear on the triangle, so its range is that of the vertices. The
   * clamp also makes early-z exact: no sample of the triangle is nearer than tmin. */
  double lo = depth[0] < depth[1] ? depth[0] : depth[1], hi = depth[0] > depth[1] ? depth[0] : depth[1];
  t->tmin = (float)(lo < depth[2] ? lo : depth[2]);
  t->tmax = (float)(hi > depth[2] ? hi : depth[2]);
  t->id = id;
}

/* The bytes of a set-up triangle: a tri2d for one position, a tri2dm for more. */
static size_t prim_size(const pipe2d *pp) { return pp->samples == 1 ? sizeof(tri2d) : sizeof(tri2dm); }

/* Vertex stage, clipping and setup of scene triangle i; appends up to MAX_SUB
 * set-up triangles (prim_size bytes each) to out and returns their number.
 * *setups counts the triangles that reached setup. */
KERNEL int setup_scene_tri(const pipe2d *pp, const rr_scene *s, uint32_t i, char *out, uint64_t *setups, const bool pattern) {
  cvert poly[2][MAX_POLY];
  unsigned all = ~0u, any = 0;
  for (int k = 0; k < 3; k++) {
    vertex_stage(pp, scene_vertex(s, k, i), &poly[0][k]);
    unsigned code = outcode(pp, &poly[0][k]);
    all &= code, any |= code;
  }
  if (all) return 0; /* wholly beyond one plane: off screen or behind the near plane */
  /* The interpolation planes come from the unclipped triangle, and only once a
   * part of it covers a sample (most triangles of a large scene cover none). */
  const cvert *orig = poly[0];
  cvert saved[3];
  if (any & ((1u << CLIP_PLANES) - 1)) memcpy(saved, poly[0], sizeof saved), orig = saved;
  planes pl;
  bool have_planes = false;
  int n = 3, cur = 0;
  for (int p = 0; p < CLIP_PLANES && n >= 3; p++) {
    if (!(any & (1u << p))) continue;
    n = clip_plane(pp, p, poly[cur], n, poly[cur ^ 1]);
    cur ^= 1;
  }
  int64_t X[MAX_POLY], Y[MAX_POLY];
  for (int k = 0; k < n; k++) snap(pp, &poly[cur][k], &X[k], &Y[k]);
  /* A fan over the clipped polygon; its inner edges are shared by consecutive
   * triangles and the fill rule gives each of their samples to one of them. */
  int m = 0;
  for (int k = 1; k + 1 < n; k++) {
    int64_t tx[3] = {X[0], X[k], X[k + 1]}, ty[3] = {Y[0], Y[k], Y[k + 1]};
    ++*setups;
    tri2d *t = (tri2d *)(out + m * (pattern ? sizeof(tri2dm) : sizeof(tri2d)));
    int32_t box[4];
    if (!setup_tri(pp, tx, ty, t, box, pattern)) continue;
    if (!have_planes && !(have_planes = interpolation_planes(pp, orig, &pl))) return 0;
    double depth[3] = {poly[cur][0].v[CT], poly[cur][k].v[CT], poly[cur][k + 1].v[CT]};
    setup_interp(pp, t, &pl, box, depth, i, pattern);
    m++;
  }
  return m;
}

/* ---- the per-sample kernel --------------------------------------------------- */

/* Where samples go: the visibility buffer (depth test), or, for the watertightness
 * tests, a count of every triangle that claims each sample. */
typedef struct target {
  visbuf *vb;
  uint8_t *front, *back;
  float *heat; /* optional: edge evaluations charged to each sample (heat maps) */
} target;

/* Shades covered sample k at (dx, dy) pixels from the triangle's reference sample;
 * qr, tr, r1, r2: the planes' values at the start of the row. count: claims mode. */
KERNEL bool shade2d(const tri2d *t, float dx, float qr, float tr, float r1, float r2, const target *tg, size_t k,
                    const bool count) {
  if (count) {
    uint8_t *claims = t->back ? tg->back : tg->front;
    claims[k]++;
    return true;
  }
  float w = 1.0f / (qr + dx * t->pw[1]);
  float depth = (tr + dx * t->pt[1]) * w;
  depth = depth < t->tmin ? t->tmin : depth > t->tmax ? t->tmax : depth;
  visbuf *vb = tg->vb;
  k *= (size_t)vb->ns; /* the position's layer: pixel k's sample */
  if (!depth_wins(depth, t->id, vb->t[k], vb->id[k])) return false;
  vb->t[k] = depth;
  vb->id[k] = t->id;
  vb->l1[k] = (r1 + dx * t->p1[1]) * w;
  vb->l2[k] = (r2 + dx * t->p2[1]) * w;
  return true;
}

/* Samples x0..x1 of row y, stepping the edge values in integers. test: check
 * coverage (off inside an accepted block). Returns true when a sample was written. */
KERNEL bool raster_row(const tri2d *t, int x0, int x1, int y, const target *tg, const bool test, const bool count) {
  int64_t px = (int64_t)x0 * SUBPIX + SUBPIX / 2, py = (int64_t)y * SUBPIX + SUBPIX / 2;
  int64_t e0 = t->a[0] * px + t->b[0] * py + t->c[0];
  int64_t e1 = t->a[1] * px + t->b[1] * py + t->c[1];
  int64_t e2 = t->a[2] * px + t->b[2] * py + t->c[2];
  int64_t s0 = (int64_t)t->a[0] * SUBPIX, s1 = (int64_t)t->a[1] * SUBPIX, s2 = (int64_t)t->a[2] * SUBPIX;
  /* Planes evaluated directly at each sample (not stepped), so every traversal
   * computes the same bits for the same sample. */
  float dy = (float)(y - t->rect[1]);
  float qr = t->pw[0] + dy * t->pw[2], tr = t->pt[0] + dy * t->pt[2];
  float r1 = t->p1[0] + dy * t->p1[2], r2 = t->p2[0] + dy * t->p2[2];
  size_t row = (size_t)y * (size_t)tg->vb->width;
  bool wrote = false;
  /* Coverage of up to 64 samples as a bit mask first, without branches, then the
   * covered samples: a coverage branch per sample would mispredict half the time. */
  for (int xs = x0; xs <= x1; xs += 64) {
    int n = x1 - xs + 1 < 64 ? x1 - xs + 1 : 64;
    uint64_t mask = n == 64 ? ~0ull : (1ull << n) - 1;
    if (test) {
      mask = 0;
      for (int i = 0; i < n; i++, e0 += s0, e1 += s1, e2 += s2) mask |= (uint64_t)((e0 | e1 | e2) >= 0) << i;
    }
    for (; mask; mask &= mask - 1) {
      int x = xs + __builtin_ctzll(mask);
      wrote |= shade2d(t, (float)(x - t->rect[0]), qr, tr, r1, r2, tg, row + (size_t)x, count);
    }
  }
  return wrote;
}

/* ---- 2dr-bb ------------------------------------------------------------------ */

KERNEL uint64_t raster_bb(const tri2d *t, int y0, int y1, const target *tg, const bool count) {
  for (int y = y0; y <= y1; y++) raster_row(t, t->rect[0], t->rect[2], y, tg, true, count);
  return (uint64_t)(t->rect[2] - t->rect[0] + 1) * (uint64_t)(y1 - y0 + 1);
}

/* ---- 2dr-bin: hierarchical binning and early-z --------------------------------- */

/* Block sizes by level: 4², 16², 64² samples (a level-2 block is a tile); the
 * hierarchical z-buffer keeps the farthest depth of each. */
#define LEVELS 3
static inline int block_shift(int level) { return 2 + 2 * level; }
static inline int block_size(int level) { return 1 << block_shift(level); }

typedef struct bin_ctx {
  const target *tg;
  hiz *hz; /* NULL in claims mode */
  uint64_t evals;
  const struct pass2d *pass;
  int sample; /* the position of a pattern being drawn */
} bin_ctx;

/* One block of `level` with top-left sample (bx, by): skipped when the triangle is
 * behind everything stored there, rejected when one edge is negative at all of its
 * corner samples, accepted when every edge is non-negative at all of them, else
 * split (or tested sample by sample at level 0). Linear functions take their
 * extremes over a rectangle of samples at its corners, and the integer values make
 * these tests exact. */
static void bin_block_z(const tri2d *t, int level, int bx, int by, bin_ctx *bc);
static void bin_block_claims(const tri2d *t, int level, int bx, int by, bin_ctx *bc);

KERNEL void bin_block(const tri2d *t, int level, int bx, int by, bin_ctx *bc, const bool count) {
  const visbuf *vb = bc->tg->vb;
  int s = block_size(level);
  if (!count && t->tmin > hiz_get(bc->hz, level, bx >> block_shift(level), by >> block_shift(level))) return;
  int ex = bx + s - 1 < vb->width - 1 ? bx + s - 1 : vb->width - 1;
  int ey = by + s - 1 < vb->height - 1 ? by + s - 1 : vb->height - 1;
  int64_t px = (int64_t)bx * SUBPIX + SUBPIX / 2, py = (int64_t)by * SUBPIX + SUBPIX / 2;
  int64_t dx = (int64_t)(ex - bx) * SUBPIX, dy = (int64_t)(ey - by) * SUBPIX;
  bool accept = true;
  int64_t hi = 0;
  for (int i = 0; i < 3; i++) {
    int64_t e = t->a[i] * px + t->b[i] * py + t->c[i];
    int64_t ax = t->a[i] * dx, by_ = t->b[i] * dy;
    int64_t lo = e + (ax < 0 ? ax : 0) + (by_ < 0 ? by_ : 0);
    hi = e + (ax > 0 ? ax : 0) + (by_ > 0 ? by_ : 0);
    if (hi < 0) break;
    accept &= lo >= 0;
  }
  bc->evals += 4; /* counted as the four corners, as 3dr-bin counts a bin */
  heat_charge_corners(bc->tg->heat, vb->width, bx, by, ex + 1, ey + 1);
  if (hi < 0) return;
  int x0 = bx, y0 = by, x1 = ex, y1 = ey;
  bool wrote = false;
  if (accept) {
    for (int y = y0; y <= y1; y++) wrote |= raster_row(t, x0, x1, y, bc->tg, false, count);
  } else if (level == 0) {
    x0 = x0 > t->rect[0] ? x0 : t->rect[0], x1 = x1 < t->rect[2] ? x1 : t->rect[2];
    y0 = y0 > t->rect[1] ? y0 : t->rect[1], y1 = y1 < t->rect[3] ? y1 : t->rect[3];
    for (int y = y0; y <= y1; y++) wrote |= raster_row(t, x0, x1, y, bc->tg, true, count);
  } else {
    /* children that meet the triangle's rectangle */
    int c = block_size(level - 1), m = ~(c - 1);
    int cx0 = t->rect[0] > bx ? t->rect[0] & m : bx, cy0 = t->rect[1] > by ? t->rect[1] & m : by;
    int cx1 = t->rect[2] < ex ? t->rect[2] : ex, cy1 = t->rect[3] < ey ? t->rect[3] : ey;
    for (int cy = cy0; cy <= cy1; cy += c)
      for (int cx = cx0; cx <= cx1; cx += c) {
        if (count) bin_block_claims(t, level - 1, cx, cy, bc);
        else bin_block_z(t, level - 1, cx, cy, bc);
      }
    return;
  }
  int n = (x1 - x0 + 1) * (y1 - y0 + 1);
  bc->evals += (uint64_t)n;
  heat_charge(bc->tg->heat, vb->width, x0, y0, x1 + 1, y1 + 1, (float)n);
  if (!count && wrote) hiz_mark(bc->hz, x0, y0, x1 + 1, y1 + 1);
}

static void bin_block_z(const tri2d *t, int level, int bx, int by, bin_ctx *bc) {
  bin_block(t, level, bx, by, bc, false);
}

static void bin_block_claims(const tri2d *t, int level, int bx, int by, bin_ctx *bc) {
  bin_block(t, level, bx, by, bc, true);
}

/* The blocks of rows y0..y1 (a tile-aligned band) that meet a triangle's rectangle.
 * The hierarchy starts at the smallest blocks at least half as large as the
 * rectangle (it meets at most 3×3 of them): larger ones could not reject more
 * samples, nor cull more by depth (a block's farthest depth is at most its
 * parent's), and would only add tests. */
KERNEL void raster_bin(const tri2d *t, int y0, int y1, bin_ctx *bc, const bool count) {
  int ry0 = y0 > t->rect[1] ? y0 : t->rect[1], ry1 = y1 < t->rect[3] ? y1 : t->rect[3];
  /* the level from the whole rectangle, not its part in this band: the same
   * blocks on any number of bands, so E does not depend on the thread count */
  int h = t->rect[3] - t->rect[1], extent = t->rect[2] - t->rect[0] > h ? t->rect[2] - t->rect[0] : h;
  int level = 0;
  while (level < LEVELS - 1 && extent >= 2 * block_size(level)) level++;
  const int s = block_size(level), m = ~(s - 1);
  for (int by = ry0 & m; by <= ry1; by += s)
    for (int bx = t->rect[0] & m; bx <= t->rect[2]; bx += s) bin_block(t, level, bx, by, bc, count);
}

/* ---- the pass: sort-middle (vis/sortmiddle.h) ------------------------------------ */

typedef struct pass2d {
  const rr_scene *scene;
  const pipe2d *pp;
  bool bin;
  visbuf layer[RR_MAX_SAMPLES]; /* position s's layer of the buffer */
  target tg[RR_MAX_SAMPLES];    /* and where its samples go */
  hiz *hz;                      /* one per position; NULL unless 2dr-bin tests depths */
  uint64_t setups[RR_MAX_THREADS], evals[RR_MAX_THREADS];
} pass2d;

static uint32_t setup2d(void *arg, int thread, uint32_t first, uint32_t n, void *out) {
  pass2d *p = arg;
  char *t = out;
  uint32_t m = 0;
  uint64_t setups = 0;
  if (p->pp->samples > 1) /* each with its own inlined setup */
    for (uint32_t i = first; i < first + n; i++) m += setup_scene_tri(p->pp, p->scene, i, t + m * sizeof(tri2dm), &setups, true);
  else
    for (uint32_t i = first; i < first + n; i++) m += setup_scene_tri(p->pp, p->scene, i, t + m * sizeof(tri2d), &setups, false);
  p->setups[thread] += setups;
  return m;
}

static void rows2d(const void *prim, int *y0, int *y1) {
  const tri2d *t = prim; /* a tri2dm starts with its tri2d, whose rows are the pattern's */
  *y0 = t->rect[1], *y1 = t->rect[3];
}

/* Rows [y0, y1) of a set-up triangle: every sample of its rectangle there, or bins. */
KERNEL void draw2d(bin_ctx *bc, const tri2d *t, int y0, int y1, const bool bin, const bool count) {
  if (bin) {
    raster_bin(t, y0, y1 - 1, bc, count);
    return;
  }
  int ry0 = y0 > t->rect[1] ? y0 : t->rect[1], ry1 = y1 - 1 < t->rect[3] ? y1 - 1 : t->rect[3];
  uint64_t n = raster_bb(t, ry0, ry1, bc->tg, count);
  bc->evals += n;
  if (bc->tg->heat) /* tested here, so that the common case does not convert n */
    heat_charge(bc->tg->heat, bc->tg->vb->width, t->rect[0], ry0, t->rect[2] + 1, ry1 + 1, (float)n);
}

/* Bit s: position s (of n) is covered, every edge value e_i + off[i][s] >= 0. Two
 * positions a step where x86 has SIMD: the sign bits of the OR of their edge values. */
KERNEL uint32_t covered_mask(int64_t e0, int64_t e1, int64_t e2, const int64_t off[3][RR_MAX_SAMPLES], int n) {
  uint32_t out = 0;
#ifdef RR_SIMD_X86
  __m128i v0 = _mm_set1_epi64x(e0), v1 = _mm_set1_epi64x(e1), v2 = _mm_set1_epi64x(e2);
  for (int s = 0; s < n; s += 2) {
    __m128i o = _mm_or_si128(_mm_or_si128(_mm_add_epi64(v0, _mm_load_si128((const __m128i *)&off[0][s])),
                                          _mm_add_epi64(v1, _mm_load_si128((const __m128i *)&off[1][s]))),
                             _mm_add_epi64(v2, _mm_load_si128((const __m128i *)&off[2][s])));
    out |= (uint32_t)_mm_movemask_pd(_mm_castsi128_pd(o)) << s;
  }
  return ~out & ((2u << (n - 1)) - 1);
#else
  for (int s = 0; s < n; s++) out |= (uint32_t)(((e0 + off[0][s]) | (e1 + off[1][s]) | (e2 + off[2][s])) >= 0) << s;
  return out;
#endif
}

/* 2dr-bb at every position of a pattern at once: rows y0..y1 of the positions'
 * union rectangle, each pixel's edge values computed once and moved by each
 * position's constant offset, a bit mask of the positions covered; a covered
 * sample is shaded as raster_row shades it at that position (its planes referenced
 * to its own rectangle, made when the position is first covered), so each layer
 * gets the bits of its one-position frame. */
KERNEL void raster_bb_all(const tri2dm *m, int y0, int y1, bin_ctx *bc, const bool count) {
  const pass2d *p = bc->pass;
  const pipe2d *pp = p->pp;
  const tri2d *t = &m->t;
  int n = pp->samples;
  /* position s's edge values are the pixel's plus off[i][s]; an odd pattern's last
   * pair is padded with a position no edge value reaches */
  int64_t off[3][RR_MAX_SAMPLES] __attribute__((aligned(16)));
  for (int s = 0; s < n; s++)
    for (int i = 0; i < 3; i++) off[i][s] = -(t->a[i] * pp->shift_x[s] + t->b[i] * pp->shift_y[s]);
  if (n & 1)
    for (int i = 0; i < 3; i++) off[i][n] = INT64_MIN / 2;
  tri2d at[RR_MAX_SAMPLES]; /* position s's triangle, once bit s of `made` is set */
  uint32_t made = 0;
  int64_t s0 = (int64_t)t->a[0] * SUBPIX, s1 = (int64_t)t->a[1] * SUBPIX, s2 = (int64_t)t->a[2] * SUBPIX;
  int x0 = t->rect[0], x1 = t->rect[2], width = pp->width;
  for (int y = y0; y <= y1; y++) {
    int64_t px = (int64_t)x0 * SUBPIX + SUBPIX / 2, py = (int64_t)y * SUBPIX + SUBPIX / 2;
    int64_t e0 = t->a[0] * px + t->b[0] * py + t->c[0];
    int64_t e1 = t->a[1] * px + t->b[1] * py + t->c[1];
    int64_t e2 = t->a[2] * px + t->b[2] * py + t->c[2];
    for (int x = x0; x <= x1; x++, e0 += s0, e1 += s1, e2 += s2) {
      uint32_t mask = covered_mask(e0, e1, e2, off, n);
      for (; mask; mask &= mask - 1) {
        int s = __builtin_ctz(mask);
        tri2d *ts = &at[s];
        if (!(made >> s & 1)) made |= 1u << s, tri2d_at(pp, m, s, ts); /* covered: its rectangle is not empty */
        float dy = (float)(y - ts->rect[1]);
        float qr = ts->pw[0] + dy * ts->pw[2], tr = ts->pt[0] + dy * ts->pt[2];
        float r1 = ts->p1[0] + dy * ts->p1[2], r2 = ts->p2[0] + dy * ts->p2[2];
        shade2d(ts, (float)(x - ts->rect[0]), qr, tr, r1, r2, &p->tg[s], (size_t)y * width + x, count);
      }
    }
  }
  uint64_t evals = (uint64_t)(x1 - x0 + 1) * (uint64_t)(y1 - y0 + 1) * (uint64_t)n;
  bc->evals += evals;
  heat_charge(p->tg[0].heat, width, x0, y0, x1 + 1, y1 + 1, (float)evals);
}

/* The same at position bc->sample of a pattern's triangle (2dr-bin), or at all of
 * them (2dr-bb). */
KERNEL void draw2d_all(bin_ctx *bc, const tri2dm *m, int y0, int y1, const bool bin, const bool count) {
  if (!bin) {
    int ry0 = y0 > m->t.rect[1] ? y0 : m->t.rect[1], ry1 = y1 - 1 < m->t.rect[3] ? y1 - 1 : m->t.rect[3];
    raster_bb_all(m, ry0, ry1, bc, count);
    return;
  }
  tri2d t;
  if (tri2d_at(bc->pass->pp, m, bc->sample, &t)) draw2d(bc, &t, y0, y1, bin, count);
}

/* draw2d for each mode, as the band loop takes them */
#define DRAW2D(name, bin, count)                                                                                      \
  KERNEL void name(void *bc, const void *t, int y0, int y1) { draw2d(bc, t, y0, y1, bin, count); }                  \
  KERNEL void name##_all(void *bc, const void *t, int y0, int y1) { draw2d_all(bc, t, y0, y1, bin, count); }
DRAW2D(draw_bb_z, false, false)
DRAW2D(draw_bb_claims, false, true)
DRAW2D(draw_bin_z, true, false)
DRAW2D(draw_bin_claims, true, true)

/* A pattern's band is drawn by 2dr-bin one position after the other, each into its
 * own layer and depth blocks (a position's samples of the band stay in cache while
 * the batch streams past). */
KERNEL void band2d(const sortmiddle *sm, int b, int thread, void (*draw)(void *, const void *, int, int)) {
  pass2d *p = sm->arg;
  bin_ctx bc = {.pass = p};
  for (int s = 0; s < (p->bin ? p->pp->samples : 1); s++) { /* 2dr-bb takes all positions at once */
    bc.tg = &p->tg[s], bc.hz = p->hz ? &p->hz[s] : NULL, bc.sample = s;
    sm_draw_band(sm, b, &bc, draw);
  }
  p->evals[thread] += bc.evals;
}

/* The band job of one position or of a pattern, each mode with its own inlined draw. */
KERNEL void band_jobs(int b, int thread, void *arg, const bool all) {
  const sortmiddle *sm = arg;
  const pass2d *p = sm->arg;
  switch (p->bin << 1 | (p->tg[0].front != NULL)) {
  case 0: band2d(sm, b, thread, all ? draw_bb_z_all : draw_bb_z); break;
  case 1: band2d(sm, b, thread, all ? draw_bb_claims_all : draw_bb_claims); break;
  case 2: band2d(sm, b, thread, all ? draw_bin_z_all : draw_bin_z); break;
  default: band2d(sm, b, thread, all ? draw_bin_claims_all : draw_bin_claims); break;
  }
}
static void band_job(int b, int thread, void *arg) { band_jobs(b, thread, arg, false); }
static void band_job_all(int b, int thread, void *arg) { band_jobs(b, thread, arg, true); }

/* A pattern of `samples` positions (cams[s] for position s) in one pass; tg's
 * buffers hold every position: the visibility buffer a pixel's samples side by side
 * (vis.h), the claim counts a layer per position. */
static rr_error run2d(rr_device *dev, const progress_span *progress, const rr_scene *s, const camera *cams, int samples,
                      bool cull, bool bin, int threads, target tg, rr_stats *stats) {
  pipe2d pp;
  if (s->inf)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                   "2D rasterization does not take vertices at infinity (w = 0); use a 3D method "
                   "(rc, rc-bvh, rc-packet, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full)");
  if (!pipe_setup(&pp, s, cams, samples, cull))
    return rr_fail(dev, RR_ERROR_UNSUPPORTED, "2D rasterization needs a planar camera (perspective or orthographic)");
  pass2d *p = calloc(1, sizeof *p);
  bool need_hiz = bin && !tg.front;
  hiz *hz = need_hiz ? calloc((size_t)samples, sizeof *hz) : NULL;
  bool ok = p && (!need_hiz || hz);
  if (ok) {
    *p = (pass2d){.scene = s, .pp = &pp, .bin = bin, .hz = hz};
    size_t npix = (size_t)tg.vb->width * tg.vb->height;
    const visbuf *vb = tg.vb;
    for (int k = 0; k < samples; k++) { /* position k's part of each buffer the target has */
      size_t o = (size_t)k * npix;
      p->layer[k] = visbuf_layer(vb, k);
      p->tg[k] = (target){&p->layer[k], tg.front ? tg.front + o : NULL, tg.back ? tg.back + o : NULL, tg.heat};
      if (need_hiz) ok &= rr_hiz_init(&hz[k], &p->layer[k], block_shift(0), LEVELS);
    }
  }
  if (ok) {
    sortmiddle sm = {.arg = p,
                     .size = prim_size(&pp),
                     .batch = BATCH,
                     .chunk = CHUNK,
                     .out_max = MAX_SUB,
                     .setup = setup2d,
                     .rows = rows2d,
                     .band = samples > 1 ? band_job_all : band_job,
                     .progress = progress,
                     .dev = dev};
    /* blocks of whole tiles, the largest bins and depth blocks */
    ok = rr_sortmiddle(&sm, s->ntris, pp.height, block_size(LEVELS - 1), threads);
    for (int t = 0; t < RR_MAX_THREADS; t++) stats->setups += p->setups[t], stats->edge_evals += p->evals[t];
  }
  for (int k = 0; hz && k < samples; k++) rr_hiz_free(&hz[k]);
  free(hz), free(p);
  return ok ? RR_OK : rr_fail(dev, RR_ERROR_MEMORY, "out of memory for 2D rasterization");
}

/* ---- impostors: analytic primitives (prim/analytic.h) ------------------------ */

/* As GPUs draw spheres: a screen rectangle per primitive (rr_ana_screen_bounds,
 * which holds every sample where it can pass), and at each of its samples the
 * kind's one exact test (rr_ana_hit, the ray from the camera as every method
 * takes it) against the z-buffer with the depth test of every method. The
 * triangles went first; depth_wins does not depend on the order, so a sample an
 * analytic primitive wins holds the bits the 3D methods give it. 2dr-bin adds
 * early-z: a sample whose stored t lies below the primitive's floor
 * (rr_ana_t_floor) is not tested. Bands of rows are dealt to the threads. */
enum { IMPOSTOR_BAND = 16 };

typedef struct {
  const rr_scene *s;
  const camera *cams;
  int samples;
  bool bin;
  visbuf *vb;
  uint32_t n, *ids;
  int (*rect)[4];
  float *floor;
  uint64_t evals[RR_MAX_THREADS];
} impostors;

static void impostor_band(int b, int thread, void *arg) {
  impostors *im = arg;
  int y0 = b * IMPOSTOR_BAND, y1 = y0 + IMPOSTOR_BAND < im->vb->height ? y0 + IMPOSTOR_BAND : im->vb->height;
  uint64_t evals = 0;
  for (uint32_t j = 0; j < im->n; j++) {
    const int *r = im->rect[j];
    int ya = r[1] > y0 ? r[1] : y0, yb = r[3] + 1 < y1 ? r[3] + 1 : y1;
    for (int s = 0; s < im->samples; s++) {
      const camera *c = &im->cams[s];
      visbuf vb = visbuf_layer(im->vb, s);
      for (int y = ya; y < yb; y++)
        for (int x = r[0]; x <= r[2]; x++) {
          size_t k = ((size_t)y * vb.width + x) * vb.ns;
          if (im->bin && vb.t[k] < im->floor[j]) continue;
          evals++;
          ana_shade_sample(im->s, c, im->ids[j], camera_w(c, x, y), (float)x + c->sx0, (float)y + c->sy0, &vb, k);
        }
    }
  }
  im->evals[thread] += evals;
}

static rr_error draw_impostors(rr_device *dev, render_ctx *ctx, bool bin) {
  const rr_scene *s = ctx->scene;
  impostors im = {.s = s, .cams = ctx->cams, .samples = ctx->samples, .bin = bin, .vb = ctx->vb};
  im.ids = malloc((size_t)s->ntris * sizeof *im.ids + 1);
  im.rect = malloc((size_t)s->ntris * sizeof *im.rect + 1);
  im.floor = malloc((size_t)s->ntris * sizeof *im.floor + 1);
  if (!im.ids || !im.rect || !im.floor) {
    free(im.ids), free(im.rect), free(im.floor);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %u impostors", s->ntris);
  }
  for (uint32_t i = 0; i < s->ntris; i++) {
    if (scene_kind(s, i) == RR_GEOMETRY_TRIANGLE) continue;
    ctx->stats->setups++;
    if (!rr_ana_screen_bounds(s, i, ctx->cam, im.rect[im.n])) continue;
    im.floor[im.n] = rr_ana_t_floor(s, i, ctx->cam);
    im.ids[im.n++] = i;
  }
  rr_parallel_for((ctx->vb->height + IMPOSTOR_BAND - 1) / IMPOSTOR_BAND, ctx->threads, impostor_band, &im);
  for (int t = 0; t < RR_MAX_THREADS; t++) ctx->stats->edge_evals += im.evals[t];
  free(im.ids), free(im.rect), free(im.floor);
  return RR_OK;
}

static rr_error render2d(rr_device *dev, render_ctx *ctx, bool bin) {
  target tg = {.vb = ctx->vb, .heat = ctx->heat_e};
  rr_error e = run2d(dev, &ctx->progress, ctx->scene, ctx->cams, ctx->samples, ctx->opt->cull_backfaces, bin,
                     ctx->threads, tg, ctx->stats);
  return e || !ctx->scene->kind ? e : draw_impostors(dev, ctx, bin);
}

rr_error rr_vis_2dr_bb(rr_device *dev, render_ctx *ctx) { return render2d(dev, ctx, false); }
rr_error rr_vis_2dr_bin(rr_device *dev, render_ctx *ctx) { return render2d(dev, ctx, true); }

rr_error rr_raster2d_claims(const rr_scene *s, const camera *cams, int samples, bool bin, int threads, uint8_t *front,
                            uint8_t *back) {
  size_t n = (size_t)cams->width * cams->height * samples;
  memset(front, 0, n), memset(back, 0, n);
  visbuf vb = {.width = cams->width, .height = cams->height, .ns = samples};
  target tg = {.vb = &vb, .front = front, .back = back};
  rr_stats st = {0};
  return run2d(NULL, NULL, s, cams, samples, false, bin, threads < 1 ? 1 : threads, tg, &st);
}

bool rr_raster2d_project(const rr_scene *s, const camera *c, vec3 p, double *sx, double *sy) {
  pipe2d pp;
  if (!pipe_setup(&pp, s, c, 1, false)) return false;
  cvert v;
  vertex_stage(&pp, p, &v);
  if (v.v[CZ] < 0) return false;
  *sx = v.v[CX] / v.v[CW] * pp.hw + pp.hw;
  *sy = pp.hh - v.v[CY] / v.v[CW] * pp.hh;
  return true;
}
