/* The box kind (slides 003, ray–box: the slabs of three pairs of planes), axis-aligned
 * or oriented: the sample test in double in the box's own frame. */
#include "prim/analytic.h"

/* The box's frame: rows x, y of a (stored unit and orthogonal) and z = x × y. */
void rr_ana_box_frame(const float *b, double R[3][3]) {
  for (int k = 0; k < 3; k++) R[0][k] = b[6 + k], R[1][k] = b[9 + k];
  R[2][0] = R[0][1] * R[1][2] - R[0][2] * R[1][1];
  R[2][1] = R[0][2] * R[1][0] - R[0][0] * R[1][2];
  R[2][2] = R[0][0] * R[1][1] - R[0][1] * R[1][0];
}

/* The slab test (Kay–Kajiya): in the box's frame (o' = R(o − c), d' = R·d) each
 * axis a bounds t to [(−h − o'_a) / d'_a, (h − o'_a) / d'_a] (sorted); the ray
 * meets the box where the three intervals overlap, from the largest entry to the
 * least exit. A direction parallel to a slab keeps it only when the origin lies
 * inside it. The hit is the entry when it lies ahead (t > 0), else the exit (the
 * origin inside). Its face is 2a + (side > 0) for the axis a where it lies, and
 * (u, v) its position on that face over [0, 1]², u along axis (a + 1) mod 3, v
 * along (a + 2) mod 3; l1 = face + u·(1 − 2⁻¹⁶) keeps the face in its integer part. */
bool rr_ana_box_hit(const float *b, const ana_ray *r, float *t, float *u, float *v) {
  double R[3][3], o[3], d[3];
  rr_ana_box_frame(b, R);
  for (int a = 0; a < 3; a++) {
    o[a] = R[a][0] * (r->o[0] - b[0]) + R[a][1] * (r->o[1] - b[1]) + R[a][2] * (r->o[2] - b[2]);
    d[a] = R[a][0] * r->d[0] + R[a][1] * r->d[1] + R[a][2] * r->d[2];
  }
  double tn = -INFINITY, tf = INFINITY;
  int an = -1, af = -1;
  for (int a = 0; a < 3; a++) {
    double h = b[3 + a];
    if (d[a] == 0) {
      if (!(fabs(o[a]) <= h)) return false;
      continue;
    }
    double t0 = (-h - o[a]) / d[a], t1 = (h - o[a]) / d[a];
    if (t0 > t1) {
      double x = t0;
      t0 = t1, t1 = x;
    }
    if (t0 > tn) tn = t0, an = a;
    if (t1 < tf) tf = t1, af = a;
  }
  if (!(tn <= tf) || !(tf > 0)) return false;
  double th = tn > 0 ? tn : tf;
  int a = tn > 0 ? an : af;
  float tfl = (float)th;
  if (a < 0 || !(tfl > 0) || !(tfl < INFINITY)) return false;
  double p[3];
  for (int k = 0; k < 3; k++) p[k] = o[k] + th * d[k];
  int face = 2 * a + (p[a] > 0), b1 = (a + 1) % 3, b2 = (a + 2) % 3;
  double fu = (p[b1] / b[3 + b1] + 1) / 2, fv = (p[b2] / b[3 + b2] + 1) / 2;
  fu = fu < 0 ? 0 : fu > 1 ? 1 : fu, fv = fv < 0 ? 0 : fv > 1 ? 1 : fv;
  *t = tfl;
  *u = (float)(face + fu * (1 - 0x1p-16));
  *v = (float)fv;
  return true;
}
