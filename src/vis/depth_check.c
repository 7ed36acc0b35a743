/* The depth's accuracy against the exact plane hit (vis.h: rr_depth_errors), for
 * tests/test_depth and bench/bench_depth: every 3D method and Embree measured the
 * same way. */
#include "vis/vis.h"

#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The exact t of the ray o + t·d with the plane of triangle id, or NAN when the ray
 * grazes it (|cos| < 1e-3). */
static double plane_t(const rr_scene *s, uint32_t id, const double o[3], const double d[3]) {
  /* the plane through finite corner p_f, spanned by r1, r2 (a corner at infinity: its direction) */
  unsigned inf = scene_inf(s, id);
  int f = !(inf & 1u) ? 0 : !(inf & 2u) ? 1 : 2;
  double p[3][3], r[2][3], n[3];
  for (int j = 0; j < 3; j++)
    for (int a = 0; a < 3; a++) p[j][a] = scene_coord(s, j, a, id);
  for (int j = 0; j < 2; j++) {
    int k = (f + 1 + j) % 3;
    for (int a = 0; a < 3; a++) r[j][a] = inf >> k & 1u ? p[k][a] : p[k][a] - p[f][a];
  }
  for (int a = 0; a < 3; a++) n[a] = r[0][(a + 1) % 3] * r[1][(a + 2) % 3] - r[0][(a + 2) % 3] * r[1][(a + 1) % 3];
  double nd = 0, nq = 0, nn = 0, dd = 0;
  for (int a = 0; a < 3; a++) nd += n[a] * d[a], nq += n[a] * (p[f][a] - o[a]), nn += n[a] * n[a], dd += d[a] * d[a];
  return fabs(nd) < 1e-3 * sqrt(nn * dd) ? NAN : nq / nd;
}

bool rr_depth_errors(const rr_scene *s, const camera *c, const uint32_t *ids, const float *t, rr_depth_stats *out) {
  memset(out, 0, sizeof *out);
  out->worst = -1;
  size_t npix = (size_t)c->width * c->height;
  double *err = malloc(npix * sizeof *err);
  if (!c->planar || !err) {
    free(err);
    return false;
  }
  const float *e = &c->eye.x, *o0 = &c->o0.x, *ox = &c->ox.x, *oy = &c->oy.x, *fwd = &c->fwd.x;
  const float *d0 = &c->d0.x, *dx = &c->dx.x, *dy = &c->dy.x;
  for (size_t k = 0; k < npix; k++) {
    if (ids[k] == RR_MISS) continue;
    double sx = (double)(k % c->width) + c->sx0, sy = (double)(k / c->width) + c->sy0, o[3], d[3];
    bool ortho = c->type == RR_CAMERA_ORTHOGRAPHIC;
    for (int a = 0; a < 3; a++) {
      o[a] = ortho ? (double)e[a] + o0[a] + sx * ox[a] + sy * oy[a] : e[a];
      d[a] = ortho ? fwd[a] : (double)d0[a] + sx * dx[a] + sy * dy[a];
    }
    double exact = plane_t(s, ids[k], o, d);
    if (isnan(exact)) continue;
    double rel = fabs((double)t[k] - exact) / fabs(exact);
    if (rel > out->max || out->worst < 0) out->max = rel, out->worst = (int)k;
    err[out->n++] = rel;
  }
  if (out->n) {
    qsort(err, (size_t)out->n, sizeof *err, cmp_double);
    out->p50 = err[out->n / 2];
    out->p999 = err[(size_t)((out->n - 1) * 0.999)];
  }
  free(err);
  return true;
}
