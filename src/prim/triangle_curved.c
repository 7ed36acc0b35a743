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
#include "camera/lens.h"
#include "core/simd.h"

#include <math.h>
#include <string.h>

/* A cap rectangle of at most this many samples is kept without the arcs'
 * (they cost about ten times as much, and the few samples more cost less). */
#define CAP_ENOUGH 64
/* A cap rectangle of more samples than this is cut by the chart's too. */
#define CHART_FROM 16

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
/* atan2 within ATAN_ERR: Abramowitz & Stegun 4.4.49 (arctan x / x on [0, 1] by a
 * polynomial in x², |error| <= 2e-8; 1.4e-8 over a grid of 2e6 points), then the
 * octant's exact reflections. Five times cheaper than libm's, for the cap bounds,
 * which widen their ranges by ATAN_ERR. */
#define ATAN_ERR 1e-7
/* arctan a for a in [0, 1] (a and q = a², double or lanes of doubles) */
#define ATAN01(a, q)                                                                                              \
  ((a) * (1 + (q) * (-0.3333314528 + (q) * (0.1999355085 + (q) * (-0.1420889944 + (q) * (0.1065626393 +         \
          (q) * (-0.0752896400 + (q) * (0.0429096138 + (q) * (-0.0161657367 + (q) * 0.0028662257)))))))))
static double fast_atan2(double y, double x) {
  double ax = fabs(x), ay = fabs(y), hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
  if (!(hi > 0)) return 0;
  double a = lo / hi, q = a * a;
  double r = ATAN01(a, q);
  if (ay > ax) r = RR_PI / 2 - r;
  if (x < 0) r = RR_PI - r;
  return y < 0 ? -r : r;
}

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


/* The spherical triangle T of a setup's edge planes (rr_tri_spheres): unit
 * normals n, vertices v (vertex i lies on edges i+1 and i+2, inside edge i; its
 * interior angle θ_i is the angle between the inward normals' planes, cos θ_i =
 * −n̂_j·n̂_k, so 1 − cos θ_i = 2 sin²(θ_i / 2) = 1 + n̂_j·n̂_k), smin = sin(θ_min / 2)
 * and the widening E of the comment at the top; not ok when the setup is
 * degenerate or a sliver too thin to bound (smin <= 1e-6: E below 0.02 rad until
 * smin = 1e-3, then growing). And curved_cap's cap about the vertices' mean
 * direction, its radius with E (cap false where curved_cap gives -1). Computed
 * four lanes a pass, in double: the vertices come from cross products of
 * normals that may be nearly parallel (slivers, with the 1e-9 tests), where float
 * would lose the digits the margins above do not cover. */
typedef double vd4 __attribute__((vector_size(32)));
typedef int64_t vl4 __attribute__((vector_size(32)));
typedef int32_t vi4 __attribute__((vector_size(16)));
typedef float vf4 __attribute__((vector_size(16)));
/* macros, not functions: 32-byte vector arguments would change the ABI without AVX */
#define vd_splat(x) ((vd4){0} + (x))
#define vl_splat(x) ((vl4){0} + (x))
#define vsel(m, a, b) ((vd4)(((m) & (vl4)(a)) | (~(m) & (vl4)(b))))
#define vsel_l(m, a, b) (((m) & (a)) | (~(m) & (b)))
#define vmin(a, b) vsel((a) < (b), a, b) /* as mind, maxd: NaN gives b */
#define vmax(a, b) vsel((a) > (b), a, b)
#define vabs(a) ((vd4)((vl4)(a) & 0x7FFFFFFFFFFFFFFFLL))
#define vdot(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])
#define vcross(a, b, o)                                                                                           \
  ((o)[0] = (a)[1] * (b)[2] - (a)[2] * (b)[1], (o)[1] = (a)[2] * (b)[0] - (a)[0] * (b)[2],                        \
   (o)[2] = (a)[0] * (b)[1] - (a)[1] * (b)[0])

#define SPH_NAME spheres_plain
#define SPH_CAT(x) x##_plain
#define SPH_TARGET
/* f of each lane (plain C) */
#define SPH_LANES(f, x)                                                                                           \
  ({                                                                                                              \
    vd4 x_ = (x), r_;                                                                                             \
    for (int l_ = 0; l_ < 4; l_++) r_[l_] = f(x_[l_]);                                                            \
    r_;                                                                                                           \
  })
#define SPH_SQRT(x) SPH_LANES(sqrt, x)
#define SPH_FLOOR(x) SPH_LANES(floor, x)
#define SPH_CEIL(x) SPH_LANES(ceil, x)
#include "prim/triangle_sphere_tmp.h"
#undef SPH_NAME
#undef SPH_CAT
#undef SPH_TARGET
#undef SPH_SQRT
#undef SPH_FLOOR
#undef SPH_CEIL
#ifdef RR_SIMD_X86
#define SPH_NAME spheres_avx2
#define SPH_CAT(x) x##_avx2
#define SPH_TARGET RR_TARGET_AVX2
#define SPH_SQRT(x) ((vd4)_mm256_sqrt_pd((__m256d)(x)))
#define SPH_FLOOR(x) ((vd4)_mm256_floor_pd((__m256d)(x)))
#define SPH_CEIL(x) ((vd4)_mm256_ceil_pd((__m256d)(x)))
#include "prim/triangle_sphere_tmp.h"
#undef SPH_NAME
#undef SPH_CAT
#undef SPH_TARGET
#undef SPH_SQRT
#undef SPH_FLOOR
#undef SPH_CEIL
#endif

/* c (may be NULL): the camera whose cap images to compute in the lanes. */
static void spheres(const tri_setup *ts, int n, const camera *c, bool simd, tri_sphere *out, double (*nv)[2][3][3]) {
  const camera *pc =
      c && (c->type == RR_CAMERA_PARABOLIC || c->type == RR_CAMERA_LATLONG || c->type == RR_CAMERA_FISHEYE) ? c : NULL;
  for (int k = 0; k < n; k += 4) {
    int m = n - k < 4 ? n - k : 4;
#ifdef RR_SIMD_X86
    if (simd && __builtin_cpu_supports("avx2")) {
      spheres_avx2(ts + k, m, pc, out + k, nv ? nv + k : NULL);
      continue;
    }
#endif
    (void)simd;
    spheres_plain(ts + k, m, pc, out + k, nv ? nv + k : NULL);
  }
}
void rr_tri_spheres(const tri_setup *ts, int n, bool simd, tri_sphere *out) { spheres(ts, n, NULL, simd, out, NULL); }
void rr_tri_spheres_cam(const tri_setup *ts, int n, const camera *c, bool simd, tri_sphere *out) {
  spheres(ts, n, c, simd, out, NULL);
}

/* The inclusive pixel rectangle of the samples whose sample coordinates lie in
 * [x0, x1] × [y0, y1], with a hundredth of a pixel against the double rounding:
 * 1, or 0 when it holds none. */
static int ceil_in(double x, int n) { /* ceil(x) within [0, n], NaN as 0 */
  if (!(x > 0)) return 0;
  if (x >= n) return n;
  int i = (int)x;
  return i + (i < x);
}
static int floor_in(double x, int n) { /* floor(x) within [-1, n - 1], NaN as n - 1 */
  if (!(x < n)) return n - 1;
  if (x < 0) return -1;
  return (int)x;
}
static int sample_rect(const camera *c, double x0, double x1, double y0, double y1, int r[4]) {
  int lx = ceil_in(x0 - c->sx0 - 1e-2, c->width), hx = floor_in(x1 - c->sx0 + 1e-2, c->width);
  int ly = ceil_in(y0 - c->sy0 - 1e-2, c->height), hy = floor_in(y1 - c->sy0 + 1e-2, c->height);
  if (lx > hx || ly > hy) return 0;
  r[0] = lx, r[1] = ly, r[2] = hx, r[3] = hy;
  return 1;
}

/* The cap bound (cheap: no arcs, at most two atan2). T lies in the cap of its
 * vertices about their mean direction m, of radius r (a cap under 90° is
 * spherically convex and holds the vertices, so it holds their hull T), and every
 * passing sample's exact direction w within E of T, so within ρ = r + E of m.
 * With cos r = min m·v_i and the chord h = √(2 − 2 cos r), r = 2 asin(h/2) <=
 * h / √(1 − h²/4) (asin x <= tan asin x). The geodesic from m to w stays in that
 * cap, so the image of w lies within ρ·L of the image of m, L bounding the map's
 * differential over the cap (its largest stretch, image units per radian):
 *  - parabolic, the stereographic u + iv = tan(α/2) e^{iψ}: conformal, stretch
 *    (tan(α/2))' = 1 / (1 + cos α), greatest at the cap's largest α <= α_m + ρ,
 *    where cos(α_m + ρ) = cos α_m cos ρ − sin α_m sin ρ >= cos α_m·(1 − ρ²/2 when
 *    cos α_m >= 0, else 1) − sin α_m·ρ (that bound is <= −1 once α_m + ρ >= π:
 *    cos β + β sin β >= 1 on [0, π/2] for β = π − α_m; then no bound);
 *  - fisheye, u + iv = (α/k) e^{iψ}: radial stretch 1/k, tangential α / (k sin α),
 *    the larger, growing with α: at most (α_m + ρ) / (k·s) with s <= sin(α_m + ρ)
 *    = sin α_m cos ρ + cos α_m sin ρ >= sin α_m (1 − ρ²/2) + min(cos α_m, 0)·ρ;
 *  - lat-long, per axis: θ moves by at most the angle (|dθ| <= ds), φ by ds / sin θ,
 *    and over the cap sin θ >= sin(a − ρ) >= sin a (1 − ρ²/2) − cos a·ρ, a the
 *    angle from m to the nearer pole (sin a = sin θ_m, cos a = |cos θ_m|); with a
 *    pole in the cap, or φ's range across the seam, the whole width.
 * (1 − ρ²/2 <= cos ρ and sin ρ <= ρ for ρ >= 0.) The caps behind a hemisphere's
 * disk hold no ray: α >= α_m − ρ, so cos α <= cos α_m·(1 or 1 − ρ²/2) + sin α_m·ρ.
 * `scale` multiplies ρ (1; the tests see that a halved ρ misses samples).
 * 1 with r, 0 when no sample can pass, -1 when the cap bounds nothing. */
int rr_tri_curved_cap(const camera *c, const tri_setup *ts, double scale, int r[4]) {
  if (c->type != RR_CAMERA_LATLONG && c->type != RR_CAMERA_PARABOLIC && c->type != RR_CAMERA_FISHEYE) return -1;
  tri_sphere sp;
  rr_tri_spheres(ts, 1, true, &sp);
  return sp.cap ? rr_cam_cap_rect(c, sp.axis, sp.rho * scale, r) : -1;
}

/* The cap about unit vertices v for rr_tri_corner_cap, with widening E (the lanes
 * of rr_tri_spheres compute the same for set-up triangles): 1 with its axis and
 * radius in lane l, -1 when it bounds nothing. */
static int curved_cap(const dv3 v[3], double E, double axis[3][4], double rho[4], int l) {
  dv3 m = dv(v[0].x + v[1].x + v[2].x, v[0].y + v[1].y + v[2].y, v[0].z + v[1].z + v[2].z);
  double lm = dlen(m);
  if (!(lm > 1e-3)) return -1;
  m = dscale(m, 1 / lm);
  double cr = mind(ddot(m, v[0]), mind(ddot(m, v[1]), ddot(m, v[2])));
  if (!(cr > 0.1)) return -1; /* a cap beyond 84°: the arcs bound it better */
  double h2 = maxd(0.0, 2 - 2 * cr);
  rho[l] = sqrt(h2 / (1 - h2 / 4)) + E + 1e-9;
  axis[0][l] = m.x, axis[1][l] = m.y, axis[2][l] = m.z;
  return 1;
}

/* Four lanes a pass (triangle_sphere_tmp.h, cap_lanes: the argument of
 * rr_tri_curved_cap's comment). */
void rr_cam_cap_extents4(const camera *c, const double axis[3][4], const double rho[4], bool simd, double e[4][4],
                         int64_t k[4]) {
  if (c->type != RR_CAMERA_LATLONG && c->type != RR_CAMERA_PARABOLIC && c->type != RR_CAMERA_FISHEYE) {
    for (int l = 0; l < 4; l++) k[l] = -1; /* no bound known */
    return;
  }
  vd4 a[3], r, ext[4];
  vl4 img;
  memcpy(a, axis, sizeof a), memcpy(&r, rho, sizeof r);
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2")) cap_lanes_avx2(c, a, &r, ext, &img);
  else
#endif
    cap_lanes_plain(c, a, &r, ext, &img);
  (void)simd;
  memcpy(e, ext, sizeof ext), memcpy(k, &img, sizeof img);
}
static bool polar(const camera *c) {
  return c->type == RR_CAMERA_LATLONG || c->type == RR_CAMERA_PARABOLIC || c->type == RR_CAMERA_FISHEYE;
}
static bool lens(const camera *c) { return c->type == RR_CAMERA_OPENCV || c->type == RR_CAMERA_OPENCV_FISHEYE; }

/* The OpenCV lenses' rr_cam_caps_show4, a lane at a time: the caps' images
 * through the lens (rr_lens_cap_extent; a cap it cannot bound shows). */
static unsigned lens_caps_show(const camera *cams, int ns, const double axis[3][4], const double rho[4], unsigned used,
                               const int r[4]) {
  unsigned shown = 0;
  for (int l = 0; l < 4; l++)
    for (int p = 0; p < ns && (used >> l & 1) && !(shown >> l & 1); p++) {
      const camera *c = &cams[p];
      const dv3 m = dv(axis[0][l], axis[1][l], axis[2][l]);
      const double ax[3] = {ddot(m, dvf(c->right)), -ddot(m, dvf(c->up)), ddot(m, dvf(c->fwd))}; /* x right, y down */
      double e[4];
      int q[4], k = rr_lens_cap_extent(&c->lens, c->lens_fold, c->lens_field, ax, rho[l], e);
      if (k < 0 || (k > 0 && sample_rect(c, e[0], e[1], e[2], e[3], q) && q[0] < r[2] && q[2] >= r[0] &&
                    q[1] < r[3] && q[3] >= r[1]))
        shown |= 1u << l;
    }
  return shown;
}

unsigned rr_cam_caps_show4(const camera *cams, int ns, const double axis[3][4], const double rho[4], unsigned used,
                           const int r[4], bool simd) {
  if (lens(cams)) return lens_caps_show(cams, ns, axis, rho, used, r);
  if (!polar(cams)) return used; /* no bound known */
  vd4 a[3], q;
  memcpy(a, axis, sizeof a), memcpy(&q, rho, sizeof q);
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2")) return caps_show_avx2(cams, ns, a, &q, used, r);
#endif
  (void)simd;
  return caps_show_plain(cams, ns, a, &q, used, r);
}

/* The shortcut: a cap of radius rho_min or more (1.5 samples over the map's least
 * stretch, in samples a radian) wholly inside the image (the parabolic's and
 * fisheye's disk: cos α_m >= cos_min + rho·sin_min, above cos(α_rim − ρ)) shows
 * one; only the odd such box whose image falls between samples is taken for nothing. */
cam_cap_shortcut rr_cam_cap_shortcut(const camera *c) {
  cam_cap_shortcut q = {INFINITY, 1, 0};
  const double W = c->width, H = c->height;
  if (c->type == RR_CAMERA_LATLONG) { /* every direction; stretch H / π along θ, >= W / 2π along φ */
    q.rho_min = 1.5 / mind(H / RR_PI, W / (2 * RR_PI)), q.cos_min = -2;
  } else if (c->type == RR_CAMERA_PARABOLIC) { /* stretch 1 / (1 + cos α) >= 1/2 image half-widths */
    q.rho_min = 1.5 / (mind(W, H) / 4), q.cos_min = 0, q.sin_min = 1;
  } else if (c->type == RR_CAMERA_FISHEYE) { /* radial stretch 1 / k, the least */
    const double k = c->fov_deg * RR_PI / 360;
    q.rho_min = 1.5 / (mind(W, H) / (2 * k)), q.cos_min = cos(k), q.sin_min = sin(k);
  }
  return q;
}

/* A box lies in the ball about its centre b of its half-diagonal r, which from the
 * eye e (|b − e| > r) is the cap about b − e of radius asin(r / |b − e|) <=
 * s / √(1 − s²), s = r / |b − e| (asin x <= tan asin x); a triangle's corners, in
 * the box, look into that cap, and so do its spherical triangle (the cap is convex
 * under 90°) and, within the slack of the frustum traversal's cone test (1e-4 rad;
 * rays and edge values round to about 1e-6), the samples that pass its edge test.
 * cap_lanes bounds the cap's image. (The rounded planes of a near-degenerate
 * sliver, or of an edge seen end-on, can pass samples farther out, as far as its
 * setup's spherical triangle reaches; every box test of the BVH methods, the
 * frustum cone and rc-bvh's widened slabs, drops such samples alike: they are not
 * hits of the triangle in its box.) A box that holds the eye, or a cap it cannot
 * bound, may show a sample. */
unsigned rr_cam_boxes_show4(const camera *cams, int ns, const float lo[3][4], const float hi[3][4], unsigned used,
                            const cam_cap_shortcut *sc, const int r[4], bool simd) {
  if (lens(cams)) { /* boxes_show's caps, through the lens */
    vd4 m[3], q;
    vl4 nl;
    box_caps_plain(cams, lo, hi, m, &q, &nl);
    double axis[3][4], rho[4];
    memcpy(axis, m, sizeof axis), memcpy(rho, &q, sizeof rho);
    unsigned near = 0;
    for (int l = 0; l < 4; l++) near |= (unsigned)(nl[l] != 0) << l;
    near &= used;
    return near | (near == used ? 0 : lens_caps_show(cams, ns, (const double(*)[4])axis, rho, used & ~near, r));
  }
  if (!polar(cams)) return used;
#ifdef RR_SIMD_X86
  if (simd && __builtin_cpu_supports("avx2")) return boxes_show_avx2(cams, ns, lo, hi, used, sc, r);
#endif
  (void)simd;
  return boxes_show_plain(cams, ns, lo, hi, used, sc, r);
}

static int cap_extent(const camera *c, const double axis[3], double rho, double e[4]) {
  double a[3][4], r[4], ext[4][4];
  int64_t k[4];
  for (int l = 0; l < 4; l++) a[0][l] = axis[0], a[1][l] = axis[1], a[2][l] = axis[2], r[l] = rho;
  rr_cam_cap_extents4(c, a, r, true, ext, k);
  for (int j = 0; j < 4; j++) e[j] = ext[j][0];
  return (int)k[0];
}

/* The chart bound of the lat-long and fisheye (tighter than the cap's but for
 * round triangles: a thin one's cap is far wider than it). In the gnomonic chart
 * about the cap's axis m, x ↦ p = (m + x) / |m + x| (x ⊥ m), great circles are
 * straight lines: the spherical triangle T is the plane triangle of its
 * vertices' images x_i = v_i / (v_i·m) − m. A passing sample's exact direction w
 * has n̂_i·w >= −ε (the comment at the top) and lies in the cap (w·m >= cos ρ >=
 * 1 − ρ²/2), so its chart point x = w / (w·m) − m has n̂_i·(m + x) >= −ε / cos ρ:
 * T's edges shifted out by that, which meet at y_i = x_i + δ_i, δ_i ⊥ m with
 * n̂_j·δ_i = n̂_k·δ_i = −ε / cos ρ, δ_i = −(ε / cos ρ) m × (n̂_j − n̂_k) /
 * (m·(n̂_j × n̂_k)) (Cramer): x lies in the triangle Y of the y_i (tri_sphere.gx,
 * in the lanes), |x| <= t = max |y_i|. (A sliver's sharp corner moves far, along
 * the sliver only: the margin E of the cap widens it every way.) The map's image
 * coordinates g along the ray s·x̂ from 0 (the geodesic from m, arc length
 * σ = atan s, dσ/ds = 1 / (1 + s²) <= 1, |d²σ/ds²| <= 2s) have
 * g(x) = g(0) + Dg·x + R, |R| <= (M2 + 2t·M1)·t²/2 per coordinate, M1 and M2
 * bounding the first and second derivatives of g along unit-speed geodesics over
 * the cap. Dg·x over Y spans the box of its values at the y_i (linear), so the
 * samples' images lie in g(m) + box(Dg·y_i) ± R. M1, M2:
 *  - lat-long, θ from up and φ = atan2(d·right, d·fwd) on the sphere's metric
 *    dθ² + sin²θ dφ², geodesics θ'' = sin θ cos θ φ'², φ'' = −2 cot θ θ'φ' with
 *    θ'² + sin²θ φ'² = 1: |θ'| <= 1, |φ'| <= 1 / sin θ, |θ''| <= |cos θ| / sin θ,
 *    |φ''| <= |cos θ| / sin²θ (2|θ'||φ' sin θ| <= 1); over the cap sin θ >= slo
 *    (cap_extent's), and Dθ·x = −x·up / sin θ_m, Dφ·x = x·(m_f right − m_r fwd) /
 *    (m_r² + m_f²); the cap's conditions (no pole in it, φ off the seam) hold;
 *  - fisheye, the polar plane coordinates (α / k, ψ) of the direction's angle α
 *    from fwd: the image's acceleration along a geodesic (α'' = sin α cos α ψ'²,
 *    ψ'' = −2 cot α α'ψ') has radial part ψ'²(α − sin α cos α) <= 2α³ / (3 sin²α)
 *    (2α − sin 2α <= (2α)³ / 6) and tangential 2α'ψ'(1 − α cot α) <=
 *    (sin α − α cos α) / sin²α <= α³ / (3 sin²α) (the difference grows from 0 with
 *    derivative α(α − sin α)), so |g''| <= α³ / (k sin²α) and |g'| <= α / (k sin α),
 *    both growing with α: at most A³ / (k s²) and A / (k s) with A >= α_m + ρ and
 *    s <= sin(α_m + ρ) (cap_extent's). g = q(α) (d·right, d·up) / k, q = α / sin α,
 *    so Dg·x = (q (x·right, x·up) − c₂ (x·fwd) (m_r, m_u)) / k with
 *    c₂ = q'(α_m) / sin α_m = (sin α_m − α_m cos α_m) / sin³α_m; with α_m within
 *    ATAN_ERR, q and c₂ are within ATAN_ERR / sin α_m and (ATAN_ERR + 1e-15) /
 *    sin³α_m, which the margin carries (off the axis only: sin α_m > 1e-2).
 * Rounding: the chart's vertices carry a few ulps of t, far below the 1e-9 rad added.
 * rem_scale multiplies R (1; the tests see that 0 misses samples). 1 with the
 * sample-coordinate extents e, -1 when it knows no bound. */
static int chart_extent(const camera *c, const tri_sphere *sp, double rem_scale, double e[4]) {
  const double rho = sp->rho, t = sp->gt, W = c->width, H = c->height;
  if (!(rho < 1.5) || !(t < 1)) return -1;
  const dv3 m = dv(sp->axis[0], sp->axis[1], sp->axis[2]), R = dvf(c->right), U = dvf(c->up), F = dvf(c->fwd);
  const double mr = ddot(m, R), mu = ddot(m, U), mf = ddot(m, F);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}; /* Dg·x_i: x, y image coordinates */
  if (c->type == RR_CAMERA_LATLONG) {
    const double ct = mu, st = sqrt(maxd(0.0, 1 - ct * ct)), slo = st * (1 - rho * rho / 2) - fabs(ct) * rho;
    const double g2 = mr * mr + mf * mf;
    if (!(slo > 1e-6) || !(rho / slo < RR_PI) || !(g2 > 1e-12)) return -1;
    const double phi = fast_atan2(mr, mf), dphi = rho / slo + ATAN_ERR;
    if (phi - dphi < -RR_PI || phi + dphi > RR_PI) return -1; /* across the seam */
    const double theta = fast_atan2(st, ct);
    const dv3 G = dsub(dscale(R, mf), dscale(F, mr));
    for (int i = 0; i < 3; i++) {
      const dv3 x = dv(sp->gx[i][0], sp->gx[i][1], sp->gx[i][2]);
      const double dp = ddot(x, G) / g2, dt = -ddot(x, U) / st;
      lo[0] = mind(lo[0], dp), hi[0] = maxd(hi[0], dp), lo[1] = mind(lo[1], dt), hi[1] = maxd(hi[1], dt);
    }
    const double h = t * t / 2 * rem_scale;
    const double mp = (1 / (slo * slo) + 2 * t / slo) * h + 1e-9 / slo + ATAN_ERR;
    const double mt = (1 / slo + 2 * t) * h + 1e-9 + ATAN_ERR;
    /* φ = 2π sx / W − π, θ = π sy / H */
    e[0] = (phi + lo[0] - mp + RR_PI) * W / (2 * RR_PI), e[1] = (phi + hi[0] + mp + RR_PI) * W / (2 * RR_PI);
    e[2] = (theta + lo[1] - mt) * H / RR_PI, e[3] = (theta + hi[1] + mt) * H / RR_PI;
    return 1;
  }
  if (c->type != RR_CAMERA_FISHEYE) return -1;
  const double ca = mf, sa = sqrt(maxd(0.0, 1 - ca * ca)), k = c->fov_deg * RR_PI / 360;
  const double s = sa * (1 - rho * rho / 2) + mind(ca, 0.0) * rho; /* <= sin(α_m + ρ) */
  if (!(sa > 1e-2) || !(s > 1e-3)) return -1;
  const double am = fast_atan2(sa, ca), A = am + ATAN_ERR + rho, M1 = A / (k * s), M2 = A * A * A / (k * s * s);
  const double q = am / sa, c2 = (sa - am * ca) / (sa * sa * sa);
  for (int i = 0; i < 3; i++) {
    const dv3 x = dv(sp->gx[i][0], sp->gx[i][1], sp->gx[i][2]);
    const double xf = ddot(x, F), du = (q * ddot(x, R) - c2 * xf * mr) / k, dv_ = (q * ddot(x, U) - c2 * xf * mu) / k;
    lo[0] = mind(lo[0], du), hi[0] = maxd(hi[0], du), lo[1] = mind(lo[1], dv_), hi[1] = maxd(hi[1], dv_);
  }
  const double u = q * mr / k, vv = q * mu / k;
  const double mg = (M2 + 2 * t * M1) * t * t / 2 * rem_scale + 1e-9 * M1 +
                    (ATAN_ERR * (1 + t / sa + 2 * t / (sa * sa)) + 1e-12) / k;
  /* u = 2 sx / W − 1, v = 1 − 2 sy / H */
  e[0] = (u + lo[0] - mg + 1) * W / 2, e[1] = (u + hi[0] + mg + 1) * W / 2;
  e[2] = (1 - vv - hi[1] - mg) * H / 2, e[3] = (1 - vv - lo[1] + mg) * H / 2;
  return 1;
}

int rr_cam_extent_rect(const camera *c, const double e[4], int k, int r[4]) {
  return k > 0 ? sample_rect(c, e[0], e[1], e[2], e[3], r) : k;
}

int rr_cam_cap_rect(const camera *c, const double axis[3], double rho, int r[4]) {
  if (c->type != RR_CAMERA_LATLONG && c->type != RR_CAMERA_PARABOLIC && c->type != RR_CAMERA_FISHEYE) return -1;
  double e[4];
  int k = cap_extent(c, axis, rho, e);
  return k > 0 ? sample_rect(c, e[0], e[1], e[2], e[3], r) : k;
}

/* chart_extent's rectangle: 1 with r, 0 when it holds no sample, -1 when unknown. */
static int chart_rect(const camera *c, const tri_sphere *sp, double rem_scale, int r[4]) {
  double e[4];
  if (!sp->cap || chart_extent(c, sp, rem_scale, e) < 0) return -1;
  return sample_rect(c, e[0], e[1], e[2], e[3], r);
}

int rr_tri_curved_chart(const camera *c, const tri_setup *ts, double rem_scale, int r[4]) {
  tri_sphere sp;
  double nv[1][2][3][3];
  spheres(ts, 1, NULL, true, &sp, nv);
  return sp.ok ? chart_rect(c, &sp, rem_scale, r) : -1;
}

int rr_tri_sphere_cap_rect(const camera *c, const tri_sphere *sp, int r[4]) {
  if (!sp->cap) return -1;
  if (sp->img_k == TRI_CAP_UNSET) return rr_cam_cap_rect(c, sp->axis, sp->rho, r);
  return sp->img_k > 0 ? sample_rect(c, sp->img[0], sp->img[1], sp->img[2], sp->img[3], r) : sp->img_k;
}


/* The OpenCV lenses: the cap holds every passing sample's exact direction (the
 * comment at the top); its image through the lens (rr_lens_cap_extent). */
static int lens_rect(const camera *c, const tri_sphere *sp, int r[4]) {
  if (!sp->ok || !sp->cap) return -1;
  const dv3 m = dv(sp->axis[0], sp->axis[1], sp->axis[2]);
  const double axis[3] = {ddot(m, dvf(c->right)), -ddot(m, dvf(c->up)), ddot(m, dvf(c->fwd))}; /* x right, y down */
  double e[4];
  int k = rr_lens_cap_extent(&c->lens, c->lens_fold, c->lens_field, axis, sp->rho, e);
  if (k <= 0) return k;
  return sample_rect(c, e[0], e[1], e[2], e[3], r) ? (sp->smin > 1e-3 ? 1 : 2) : 0;
}

int rr_tri_curved_rect(const camera *c, const tri_setup *ts, int r[4]) {
  if (!polar(c) && !lens(c)) return -1;
  tri_sphere sp;
  rr_tri_spheres_cam(ts, 1, c, true, &sp);
  return rr_tri_curved_rect_sph(c, ts, &sp, r);
}

int rr_tri_curved_rect_sph(const camera *c, const tri_setup *ts, const tri_sphere *sp, int r[4]) {
  if (lens(c)) return lens_rect(c, sp, r);
  if (!polar(c)) return -1;
  const int lanes = rr_tri_sphere_decided(c, sp, r);
  if (lanes >= 0) return lanes;
  if (!sp->ok) return -1;
  const double E = sp->E;
  const int kind = sp->smin > 1e-3 ? 1 : 2;
  /* the cap first: enough for the small triangles of detailed meshes, and when
   * it is not, the arcs' rectangle within it */
  int cap[4], has_cap = rr_tri_sphere_cap_rect(c, sp, cap);
  if (has_cap == 0) return 0;
  /* the chart and the arcs need T's normals and vertices: this lane again, with them */
  tri_sphere again;
  double nv[1][2][3][3];
  bool full = false;
  if (has_cap > 0 && (cap[2] - cap[0] + 1) * (cap[3] - cap[1] + 1) > CHART_FROM &&
      (c->type == RR_CAMERA_LATLONG || c->type == RR_CAMERA_FISHEYE)) { /* and the chart's */
    spheres(ts, 1, NULL, true, &again, nv), full = true;
    int g[4], kg = chart_rect(c, &again, 1, g);
    if (kg == 0) return 0;
    if (kg > 0) {
      cap[0] = cap[0] > g[0] ? cap[0] : g[0], cap[1] = cap[1] > g[1] ? cap[1] : g[1];
      cap[2] = cap[2] < g[2] ? cap[2] : g[2], cap[3] = cap[3] < g[3] ? cap[3] : g[3];
      if (cap[0] > cap[2] || cap[1] > cap[3]) return 0;
    }
  }
  if (has_cap > 0 && (cap[2] - cap[0] + 1) * (cap[3] - cap[1] + 1) <= CAP_ENOUGH) {
    memcpy(r, cap, sizeof cap);
    return kind;
  }
  if (!full) spheres(ts, 1, NULL, true, &again, nv);
  dv3 n[3], v[3];
  for (int i = 0; i < 3; i++)
    n[i] = dv(nv[0][0][i][0], nv[0][0][i][1], nv[0][0][i][2]), v[i] = dv(nv[0][1][i][0], nv[0][1][i][1], nv[0][1][i][2]);
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
  if (!sample_rect(c, x0, x1, y0, y1, r)) return 0;
  if (has_cap > 0) { /* both hold every passing sample */
    r[0] = r[0] > cap[0] ? r[0] : cap[0], r[1] = r[1] > cap[1] ? r[1] : cap[1];
    r[2] = r[2] < cap[2] ? r[2] : cap[2], r[3] = r[3] < cap[3] ? r[3] : cap[3];
    if (r[0] > r[2] || r[1] > r[3]) return 0;
  }
  return kind;
}

int rr_tri_corner_cap_lane(const rr_scene *s, uint32_t i, const camera *c, double slack, double axis[3][4],
                           double rho[4], int l) {
  if (scene_inf(s, i)) return -1;
  vec3 p[3];
  scene_corners(s, i, p);
  dv3 v[3], e = dvf(c->eye);
  for (int k = 0; k < 3; k++) {
    v[k] = dsub(dvf(p[k]), e);
    double len = dlen(v[k]);
    if (!(len > 0) || !(len < INFINITY)) return -1;
    v[k] = dscale(v[k], 1 / len);
  }
  return curved_cap(v, slack, axis, rho, l);
}

int rr_tri_corner_cap(const rr_scene *s, uint32_t i, const camera *c, double slack, int r[4]) {
  double axis[3][4], rho[4];
  if (rr_tri_corner_cap_lane(s, i, c, slack, axis, rho, 0) < 0) return -1;
  const double a[3] = {axis[0][0], axis[1][0], axis[2][0]};
  return rr_cam_cap_rect(c, a, rho[0], r);
}
