/* The continuum (paper sect. 4.4, Fig. 8): one traversal of frusta F through BVH
 * nodes N, steered by oracles. Every configuration calls the same sample test, so
 * every configuration yields the same visibility buffer; only the order and number
 * of (sample, triangle) pairs visited change.
 *
 *   traverse(F, N):
 *     if isOutside(F, N) or isOccluded(F, N): return
 *     if splitFrustum(F, N): traverse(F_i, N) for each quadrant F_i; return
 *     if generateSamples(F, N): rasterize N's triangles into F (binning or not); return
 *     traverse(F, child) for N's children, front to back
 *
 * Depth here is the ray parameter t along d(x, y) = d0 + x dx + y dy; for the
 * perspective camera d·fwd = 1, so t is also the distance along fwd. Culling
 * decisions keep a relative safety margin so they never remove a winning triangle. */
#include "accel/bvh_levels.h"
#include "core/simd.h"
#include "vis/hiz.h"
#include "vis/sortmiddle.h"

#include <float.h>
#include <string.h>

#define HIZ_SHIFT 3
#define HIZ (1 << HIZ_SHIFT) /* hierarchical z-buffer tile size: frusta split down to it */
/* Relative slack of the node occlusion test. The t of TRI_DEPTH is num / den, both
 * rounded from double-exact values (a few ulps) and den's terms about a sample
 * near the triangle: a hit lies below its exact t, which its box bounds, by more
 * than 2% only where den's rounding (about 4u of its terms' magnitudes, the
 * magnitudes at most the triangle's screen extent times |pb|, |pc| beyond |den|)
 * reaches 2% of den, i.e. rays within ~1e-5 of the plane of a large triangle, or
 * in TRI_DEPTH's fallback (num or den not positive: rays within ulps of the plane).
 * Early-z per triangle uses a proven floor (computed_t_floor); a node knows no
 * triangle, so it keeps this slack. */
#define DEPTH_MARGIN 2e-2f

typedef struct tile_rect { int x0, y0, x1, y1; } tile_rect; /* samples [x0, x1) × [y0, y1) */

enum { PEND_DRAW = 16 }; /* see trav.pend */

typedef struct trav {
  const rr_scene *s;
  const camera *c;    /* cams[0]: what does not depend on the sample position */
  const camera *cams; /* one per sample position, ns of them (render_ctx) */
  int ns;
  float span[4];      /* the positions' extent: x0, y0, x1, y1 of their (sx0, sy0) */
  float pos[RR_MAX_SAMPLES][2]; /* the positions: (sx0, sy0) of each camera */
  float ox[RR_MAX_SAMPLES], oy[RR_MAX_SAMPLES]; /* the same by component, padded with the first */
  const oracles *o;
  visbuf *vb;
  bool cull_back, simd;
  bool avx2;         /* simd and the CPU runs AVX2 (asked once a frame) */
  rr_pixels_kernel pixels; /* rr_raster_pixels' kernel for avx2 */
  bool direct;       /* several positions, nothing kept but the visibility buffer:
                      * planar small draws go straight to the kernel (pixels) */
  bool hiz_used;     /* occlusion culling or early-z read the z tiles: keep them current */
  hiz *hz;           /* one level of HIZ×HIZ tiles */
  float *heat_e, *heat_n; /* optional per-pixel E and N charges */
  rr_stats st;
  /* Leaves of one frustum waiting to be drawn, so that their triangles are
   * bounded and set up together, eight lanes at a time (a leaf holds about four,
   * of which corner bounds keep about two). They are drawn once PEND_DRAW
   * triangles wait: later nodes' occlusion tests do not see them until then, and
   * a few leaves are enough to fill the lanes. Bits do not depend on the order. */
  uint32_t pend[PEND_DRAW + BVH_MAX_LEAF];
  uint32_t npend;
  tile_rect pend_r;
  /* A cube camera in one pass (render_ctx.faces): c, cams, vb, hz and the charges
   * point at face `face`'s (use_face); face f at position s is face_cams[f·ns + s],
   * at position 0 also face_cams0[f] (for the setups, which share the eye). */
  int faces, face;
  const camera *face_cams, *face_cams0;
  visbuf *face_vb;
  hiz *face_hz;
  float *face_heat_e, *face_heat_n;
  int face_rows; /* rows of the stack of faces the root pass sorts into bands, per face */
  tri_eyes *eyes; /* drawn by frusta: the eye parts of the setups, which the faces share */
  const uint8_t *seen; /* a curved view's root pass: 0 for triangles no sample can see (mark_seen) */
} trav;

/* Points t at face f of a cube camera drawn in one pass (nothing otherwise). */
static void use_face(trav *t, int f) {
  if (!t->faces || t->face == f) return;
  const size_t n = (size_t)t->face_vb[0].width * t->face_vb[0].height;
  t->face = f;
  t->c = t->cams = &t->face_cams[f * t->ns];
  t->vb = &t->face_vb[f];
  t->hz = &t->face_hz[f];
  if (t->heat_e) t->heat_e = t->face_heat_e + f * n, t->heat_n = t->face_heat_n + f * n;
}

/* ---- rasterizing one triangle into a frustum ---------------------------- */

/* Two cache lines, the setup in the first: drawing reads a job that another
 * thread set up, and each line it touches is a miss. */
typedef struct tri_job {
  _Alignas(64) tri_setup ts; /* (not used by an analytic primitive) */
  uint32_t id;
  bool ana;        /* an analytic primitive (prim/analytic.h): its own test, bounds and floor */
  uint8_t face;    /* a cube camera in one pass: the face (trav.faces), whose rows start */
  int face_y;      /* at face_y in the stack of faces the pass sorts into bands */
  float zmin;      /* a floor under any t computed for the triangle (0: none known) */
  int bb[4];       /* inclusive screen bounds */
  union {
    struct {         /* planar: */
      float slack[3]; /* how far below zero a rounded corner value may fall for an inside sample */
      tri_pos_bits pos; /* several positions: each one's rectangle within bb */
    };
    tri_cone cone;   /* curved: what bounds the triangle's directions */
  };
  tri_plane pl;      /* planar, several positions: how ts moves to each (rr_tri_setup_at) */
} tri_job;

/* Tests every sample of r at every position (mv: the setup moved to each, NULL
 * for one); the one kernel every generateSamples path ends in. Returns the
 * samples the triangle covers. */
/* An analytic primitive at every sample of r at every position. */
static uint64_t ana_raster(trav *t, uint32_t id, tile_rect r, uint64_t *covered) {
  for (int s = 0; s < t->ns; s++) {
    const camera *c = &t->cams[s];
    visbuf vb = visbuf_layer(t->vb, s);
    for (int y = r.y0; y < r.y1; y++)
      for (int x = r.x0; x < r.x1; x++)
        *covered += ana_shade_sample(t->s, c, id, camera_w(c, x, y), (float)x + c->sx0, (float)y + c->sy0, &vb,
                                     ((size_t)y * vb.width + x) * vb.ns) != 0;
  }
  return (uint64_t)(r.x1 - r.x0) * (uint64_t)(r.y1 - r.y0) * (uint64_t)t->ns;
}

KERNEL uint64_t raster_samples(trav *t, const tri_job *j, tri_moves *mv, tile_rect r) {
  int rect[4] = {r.x0, r.y0, r.x1 - 1, r.y1 - 1};
  uint64_t covered = 0;
  if (j->ana) { /* every position over the whole rectangle: no moved setup */
    t->st.edge_evals += ana_raster(t, j->id, r, &covered);
    if (t->heat_e)
      heat_charge(t->heat_e, t->vb->width, r.x0, r.y0, r.x1, r.y1, (float)((r.x1 - r.x0) * (r.y1 - r.y0) * t->ns));
    if (t->hiz_used) hiz_mark(t->hz, r.x0, r.y0, r.x1, r.y1);
    return covered;
  }
  t->st.edge_evals += !mv ? rr_raster_rect(&j->ts, j->id, rect, t->c, t->vb, &covered, t->simd)
                           : rr_raster_rect_samples(&j->ts, mv, j->id, rect, t->cams, t->ns, t->vb, &covered, t->simd);
  if (t->heat_e && !mv)
    heat_charge(t->heat_e, t->vb->width, r.x0, r.y0, r.x1, r.y1, (float)((r.x1 - r.x0) * (r.y1 - r.y0)));
  /* several positions: each over its own rectangle */
  if (t->heat_e && mv) rr_tri_moves_ready(&j->ts, mv, t->cams, t->ns, t->simd);
  for (uint32_t live = t->heat_e && mv ? mv->live : 0; live; live &= live - 1) {
    const int p = __builtin_ctz(live), q[4] = {mv->r[0][p], mv->r[1][p], mv->r[2][p], mv->r[3][p]};
    int x0 = q[0] > r.x0 ? q[0] : r.x0, y0 = q[1] > r.y0 ? q[1] : r.y0;
    int x1 = q[2] + 1 < r.x1 ? q[2] + 1 : r.x1, y1 = q[3] + 1 < r.y1 ? q[3] + 1 : r.y1;
    if (x0 < x1 && y0 < y1) heat_charge(t->heat_e, t->vb->width, x0, y0, x1, y1, (float)((x1 - x0) * (y1 - y0)));
  }
  if (t->hiz_used) hiz_mark(t->hz, r.x0, r.y0, r.x1, r.y1);
  return covered;
}

/* Curved views bend edges into arcs, so corners prove nothing. Bound the bin's
 * rays by a cone instead: edge e rejects the bin when its plane leaves the whole
 * cone on the outside, n·axis < -|n| sin(angle) (paper sect. 4.1 does the same for
 * the parabolic map by shifting the corners); with several positions, every
 * position's cone. 1: rejected, 0: kept, -1: no rays there. */
static int cone_rejects(trav *t, const tri_job *j, tile_rect b) {
  int rays = 0;
  for (int s = 0; s < t->ns; s++) {
    vec3 axis;
    float angle;
    int cone = rr_cam_rect_cone(&t->cams[s], b.x0, b.y0, b.x1, b.y1, &axis, &angle);
    if (cone < 0) continue;
    rays = 1;
    if (!(cone > 0 && angle < CAMERA_NO_CONE)) return 0;
    t->st.edge_evals += 1;
    int cx = (b.x0 + b.x1) / 2, cy = (b.y0 + b.y1) / 2;
    heat_charge(t->heat_e, t->vb->width, cx, cy, cx + 1, cy + 1, 1.0f);
    if (j->ana ? !rr_ana_cone_excludes(t->s, j->id, &t->cams[s], axis, angle) : !rr_cone_excludes(&j->cone, &j->ts, axis, angle))
      return 0;
  }
  return rays ? 1 : -1;
}

/* Curved views whose map bends boundedly (camera.bend_x, bend_y: the polar maps):
 * over a bin of samples spanning hx × hy, an edge function V = n·d differs from the
 * bilinear interpolation of its four corner values by at most
 * |n| (bend_x·hx² + bend_y·hy²) / 8 (the error of linear interpolation, along x
 * then y), and that interpolation never exceeds the greatest corner value. An edge
 * whose corner values all lie below minus that, and minus the rounding of the
 * stored rays and of the sample test (1e-5 |n| |d|), is negative at every sample
 * of the bin (paper sect. 4.1: the corners shifted by the bend). The bound shrinks
 * with the square of the bin, where a cone shrinks with its side. 1: rejected,
 * 0: kept, -1: no rays in the bin (wholly outside the disk). */
static int bend_rejects(trav *t, const tri_job *j, tile_rect b) {
  const camera *c = t->c;
  const double xs[2] = {(double)b.x0 + t->span[0], (double)(b.x1 - 1) + t->span[2]};
  const double ys[2] = {(double)b.y0 + t->span[1], (double)(b.y1 - 1) + t->span[3]};
  if (c->type != RR_CAMERA_LATLONG) { /* the disk: the bin's point nearest the centre */
    double u0 = 2 * xs[0] / c->width - 1, u1 = 2 * xs[1] / c->width - 1;
    double v0 = 1 - 2 * ys[1] / c->height, v1 = 1 - 2 * ys[0] / c->height;
    double u = u0 > 0 ? u0 : u1 < 0 ? u1 : 0, v = v0 > 0 ? v0 : v1 < 0 ? v1 : 0;
    if (u * u + v * v > 1 + 1e-6) return -1;
  }
  double d[4][3];
  for (int k = 0; k < 4; k++) rr_cam_dir_at(c, xs[k & 1], ys[k >> 1], d[k]);
  const double hx = xs[1] - xs[0], hy = ys[1] - ys[0];
  const double bend = (c->bend_x * hx * hx + c->bend_y * hy * hy) / 8, round = 1e-5 * c->dir_len_max;
  t->st.edge_evals += 4;
  heat_charge_corners(t->heat_e, t->vb->width, b.x0, b.y0, b.x1, b.y1);
  /* the three edges, and their sum Σ w_i n_i: a hit needs Σ w_i e_i > 0 too, and
   * where each edge is only a little negative (around the triangle's antipode,
   * which every one of its great circles passes near) the sum is strongly so; its
   * rounding is that of the three edge values */
  double n[4][3] = {{0}}, lim[4];
  for (int e = 0; e < 3; e++) {
    n[e][0] = j->ts.a[e], n[e][1] = j->ts.b[e], n[e][2] = j->ts.c[e];
    for (int a = 0; a < 3; a++) n[3][a] += j->ts.w[e] * n[e][a];
    lim[e] = -(bend + round) * j->cone.len[e];
  }
  lim[3] = -bend * j->cone.len[3] - round * (j->cone.len[0] + j->cone.len[1] + j->cone.len[2]);
  for (int e = 0; e < 4; e++) {
    bool all_out = true;
    for (int k = 0; k < 4 && all_out; k++) all_out = n[e][0] * d[k][0] + n[e][1] * d[k][1] + n[e][2] * d[k][2] < lim[e];
    if (all_out) return 1;
  }
  return 0;
}

/* Hierarchical binning: a bin is rejected when one edge function is negative at
 * all four corners of its samples (the edges are linear in the sample position
 * for planar cameras; with several positions, the corners of their extent) or when
 * early-z shows it is hidden; otherwise it is refined by 4 in each direction down
 * to single pixels. Accepted samples still go through the sample test, which keeps
 * the result bit-identical. */
static uint64_t bin_raster(trav *t, const tri_job *j, tri_moves *mv, tile_rect r, int size) {
  uint64_t covered = 0;
  for (int by = r.y0 - r.y0 % size; by < r.y1; by += size)
    for (int bx = r.x0 - r.x0 % size; bx < r.x1; bx += size) {
      tile_rect b = {bx > r.x0 ? bx : r.x0, by > r.y0 ? by : r.y0, bx + size < r.x1 ? bx + size : r.x1,
                     by + size < r.y1 ? by + size : r.y1};
      /* small bins go to the samples: a curved bin's test costs as much as about
       * sixteen samples (four rays in double, sines for the lat-long and fisheye) */
      if (size <= t->o->bin_min || (b.x1 - b.x0) * (b.y1 - b.y0) <= (t->c->planar ? 4 : 16)) {
        covered += raster_samples(t, j, mv, b);
        continue;
      }
      bool out = false;
      if (t->c->planar && j->ana) {
        /* an analytic primitive's bins are bounded by its rectangle and early-z */
      } else if (t->c->planar) {
        /* the corners of the bin's samples */
        float xs[2] = {(float)b.x0 + t->span[0], (float)(b.x1 - 1) + t->span[2]};
        float ys[2] = {(float)b.y0 + t->span[1], (float)(b.y1 - 1) + t->span[3]};
        for (int e = 0; e < 3 && !out; e++) {
          bool all_out = true;
          for (int k = 0; k < 4 && all_out; k++)
            all_out = j->ts.a[e] + xs[k & 1] * j->ts.b[e] + ys[k >> 1] * j->ts.c[e] < -j->slack[e];
          out = all_out;
        }
        t->st.edge_evals += 4;
        heat_charge_corners(t->heat_e, t->vb->width, b.x0, b.y0, b.x1, b.y1);
      } else {
        /* the cone (with the triangle's cap: slivers seen edge-on, whose three
         * planes nearly coincide, are bounded by it alone), then the bend */
        int rejects = cone_rejects(t, j, b);
        if (rejects == 0 && t->c->bend_x > 0 && !j->ana) rejects = bend_rejects(t, j, b);
        if (rejects < 0) continue; /* no rays here: nothing to refine */
        out = rejects > 0;
      }
      if (out) continue;
      if (t->o->early_z && hiz_nearer(t->hz, b.x0, b.y0, b.x1, b.y1, j->zmin)) continue;
      /* refined: count the bins that turn out to hold none of the triangle */
      uint64_t in = bin_raster(t, j, mv, b, size / 4 > 1 ? size / 4 : 1);
      t->st.bins++;
      t->st.bins_empty += in == 0;
      covered += in;
    }
  return covered;
}

/* A floor under a t of the form num / den that sample_test() computes for a
 * triangle at any sample, from the floor zmin of the exact t: den carries an error
 * of at most ~5 ulps of `mag` (the sum of its terms' magnitudes) and num one or two
 * ulps, so the computed t >= num / (num / zmin + err) less a few ulps. Seen at a
 * grazing angle the error can be large, and early-z must not drop a hit that rc
 * keeps. TRI_DEPTH computes t = num0 / (plane's den) or, where either is not
 * positive, vol / Σ e_i: the floor is the lesser of the two (tri_t_floor). */
static float computed_t_floor(float zmin, float mag, float vol) {
  if (!(zmin > 0) || !(vol > 0)) return 0;
  float err = 6.0f * FLT_EPSILON * mag;
  float floor_t = zmin / (1.0f + err * zmin / vol) * (1.0f - 8.0f * FLT_EPSILON);
  return floor_t > 0 && isfinite(floor_t) ? floor_t : 0;
}
/* mag, mag_p: the magnitudes of Σ e_i's and of den's terms */
static float tri_t_floor(float zmin, float mag, float mag_p, const tri_setup *ts) {
  return minf(computed_t_floor(zmin, mag, ts->vol), computed_t_floor(zmin, mag_p, ts->num0));
}

/* The largest |pa| of a planar setup over the positions whose samples may meet
 * it (the others test none): the size of den's terms. */
static float max_pa(const trav *t, const tri_job *j) {
  float pa = fabsf(j->ts.pa);
  for (int s = 1; s < t->ns; s++) {
    float m[4];
    if (j->pos.none >> s & 1) continue;
    tri_moved(&j->ts, &j->pl, &t->cams[s], m);
    pa = maxf(pa, fabsf(m[0]));
  }
  return pa;
}

static bool finish_binning(const trav *t, uint32_t id, tri_job *j);

/* Completes a set-up triangle j with what binning and early-z need (inlined: most
 * methods draw from the root without binning, where this is four stores); false
 * when binning shows that it covers no sample. */
static inline __attribute__((always_inline)) bool finish_setup(const trav *t, uint32_t id, tri_job *j) {
  j->id = id, j->ana = false, j->face = (uint8_t)t->face, j->face_y = t->face * t->face_rows;
  return !t->o->binning || finish_binning(t, id, j);
}

/* A planar triangle at one position with a vertex behind the eye has the whole
 * image for rectangle (its corners bound nothing), and where its three edge lines
 * cross far from the region they enclose, bins of every size pass the edge test
 * with nothing to find (the cube's top and bottom faces, grazed by triangles
 * across the eye's level, refined only such bins). The samples it may cover pass
 * every edge test, e_i >= -slack_i (bin_raster's reject, for one sample): their
 * region is bb clipped by the three lines, bounded here in double with twice the
 * slack and a pixel more. False: no sample. */
static bool clip_to_edges(const trav *t, tri_job *j) {
  const double ox = t->span[0], oy = t->span[1]; /* a pixel's sample position, less the pixel */
  double p[8][2] = {{j->bb[0] + ox, j->bb[1] + oy}, {j->bb[2] + ox, j->bb[1] + oy}, {j->bb[2] + ox, j->bb[3] + oy},
                    {j->bb[0] + ox, j->bb[3] + oy}};
  int n = 4;
  for (int e = 0; e < 3 && n; e++) { /* Sutherland-Hodgman: at most one more vertex an edge */
    double q[8][2], v[8];
    int m = 0;
    for (int k = 0; k < n; k++) {
      v[k] = j->ts.a[e] + p[k][0] * (double)j->ts.b[e] + p[k][1] * (double)j->ts.c[e] + 2.0 * j->slack[e];
      if (!isfinite(v[k])) return true; /* no bound to trust: keep the rectangle */
    }
    for (int k = 0; k < n; k++) {
      const int l = (k + 1) % n;
      if (v[k] >= 0) q[m][0] = p[k][0], q[m][1] = p[k][1], m++;
      if ((v[k] >= 0) != (v[l] >= 0)) {
        const double s = v[k] / (v[k] - v[l]);
        q[m][0] = p[k][0] + s * (p[l][0] - p[k][0]), q[m][1] = p[k][1] + s * (p[l][1] - p[k][1]), m++;
      }
    }
    memcpy(p, q, sizeof q), n = m;
  }
  if (!n) return false;
  double lo[2] = {p[0][0], p[0][1]}, hi[2] = {p[0][0], p[0][1]};
  for (int k = 1; k < n; k++)
    for (int a = 0; a < 2; a++) lo[a] = fmin(lo[a], p[k][a]), hi[a] = fmax(hi[a], p[k][a]);
  const int x0 = (int)floor(lo[0] - ox) - 1, y0 = (int)floor(lo[1] - oy) - 1;
  const int x1 = (int)ceil(hi[0] - ox) + 1, y1 = (int)ceil(hi[1] - oy) + 1;
  j->bb[0] = x0 > j->bb[0] ? x0 : j->bb[0], j->bb[1] = y0 > j->bb[1] ? y0 : j->bb[1];
  j->bb[2] = x1 < j->bb[2] ? x1 : j->bb[2], j->bb[3] = y1 < j->bb[3] ? y1 : j->bb[3];
  return j->bb[0] <= j->bb[2] && j->bb[1] <= j->bb[3];
}

static bool finish_binning(const trav *t, uint32_t id, tri_job *j) {
  const camera *c = t->c;
  if (c->planar) {
    float zmin = INFINITY;
    unsigned inf = scene_inf(t->s, id); /* a point at infinity: +inf ahead, -inf behind */
    for (int k = 0; k < 3; k++) {
      float z = v3_dot(scene_q(t->s, k, id, c->eye), c->fwd);
      zmin = minf(zmin, inf >> k & 1u ? (z >= 0 ? INFINITY : -INFINITY) : z);
    }
    float W = (float)t->vb->width + 1, H = (float)t->vb->height + 1, mag = 0;
    for (int e = 0; e < 3; e++) {
      float m = fabsf(j->ts.a[e]) + W * fabsf(j->ts.b[e]) + H * fabsf(j->ts.c[e]);
      j->slack[e] = 1e-5f * m;
      mag += m;
    }
    float mag_p = (t->ns > 1 ? max_pa(t, j) : fabsf(j->ts.pa)) + W * fabsf(j->ts.pb) + H * fabsf(j->ts.pc);
    j->zmin = c->type == RR_CAMERA_PERSPECTIVE ? tri_t_floor(zmin, mag, mag_p, &j->ts) : 0;
    if (t->ns == 1 && c->type == RR_CAMERA_PERSPECTIVE && zmin <= 0) return clip_to_edges(t, j);
  } else {
    /* the distance to the triangle's plane bounds every hit's distance from below */
    unsigned inf = scene_inf(t->s, id);
    int f = !(inf & 1u) ? 0 : !(inf & 2u) ? 1 : 2; /* a finite corner */
    vec3 q0 = scene_q(t->s, 0, id, c->eye), q1 = scene_q(t->s, 1, id, c->eye), q2 = scene_q(t->s, 2, id, c->eye);
    vec3 nrm = inf ? rr_scene_tri_normal(t->s, id) : v3_cross(v3_sub(q1, q0), v3_sub(q2, q0));
    float dist = fabsf(v3_dot(f == 0 ? q0 : f == 1 ? q1 : q2, nrm)) / v3_len(nrm);
    rr_tri_cone_setup(t->s, id, c, &j->ts, &j->cone);
    float mag = (j->cone.len[0] + j->cone.len[1] + j->cone.len[2]) * c->dir_len_max * 1.7321f;
    float mag_p = (fabsf(j->ts.pa) + fabsf(j->ts.pb) + fabsf(j->ts.pc)) * c->dir_len_max;
    j->zmin = dist > 0 && isfinite(dist) ? tri_t_floor(dist / c->dir_len_max, mag, mag_p, &j->ts) : 0;
  }
  return true;
}

/* Sets up the bounded triangles b[0..nb-1] of a planar camera, eight at a time
 * (a cube's faces drawn by frusta: through their eye parts, t->eyes), into out;
 * returns how many can be seen. */
static uint32_t setup_bounded(trav *t, const tri_bound *b, uint32_t nb, tri_job *out) {
  enum { STEP = 8 };
  uint32_t kept = 0;
  for (uint32_t q = 0; q < nb; q += STEP) {
    int m = nb - q < STEP ? (int)(nb - q) : STEP, face[STEP], order[STEP];
    uint32_t ids[STEP];
    tri_setup ts[STEP];
    tri_plane pls[STEP], *pl = t->ns > 1 ? pls : NULL;
    for (int l = 0; l < m; l++) ids[l] = b[q + l].id, order[l] = l;
    if (t->eyes) { /* a cube's face: S counts the eye parts no face had made (setups in `order`) */
      t->st.setups += (uint64_t)rr_tri_setup_kept(t->s, t->eyes, ids, m, t->c, t->cull_back, t->simd, ts, face, pl,
                                                  order);
    } else {
      t->st.setups += (uint64_t)m;
      rr_tri_setup_planes(t->s, ids, m, t->c, t->cull_back, t->simd, ts, face, pl);
    }
    for (int l = 0; l < m; l++) {
      if (face[l] == SETUP_CULLED) continue;
      const tri_bound *bl = &b[q + order[l]];
      tri_job *j = out + kept;
      j->ts = ts[l];
      if (pl) j->pl = pl[l], j->pos = bl->pos;
      memcpy(j->bb, bl->bb, sizeof j->bb);
      kept += finish_setup(t, bl->id, j);
    }
  }
  return kept;
}

/* Does the inclusive rectangle bb meet the samples of r? */
static bool meets(const int bb[4], tile_rect r) {
  return bb[0] < r.x1 && bb[2] >= r.x0 && bb[1] < r.y1 && bb[3] >= r.y0;
}

/* A curved camera's screen bounds of a set-up triangle (its rr_tri_spheres), over
 * every position's rays (their cones differ); false when none may see it. */
static bool curved_bounds(const trav *t, uint32_t id, const tri_setup *ts, const tri_sphere *sp, int bb[4]) {
  bool any = false;
  for (int s = 0; s < t->ns; s++) {
    int r[4], lanes = rr_tri_sphere_decided(&t->cams[s], sp, r); /* (the common case, at once) */
    if (lanes == 0 || (lanes < 0 && !rr_tri_screen_bounds_sph(t->s, id, &t->cams[s], ts, sp, r))) continue;
    if (!any) memcpy(bb, r, sizeof r);
    bb[0] = r[0] < bb[0] ? r[0] : bb[0], bb[1] = r[1] < bb[1] ? r[1] : bb[1];
    bb[2] = r[2] > bb[2] ? r[2] : bb[2], bb[3] = r[3] > bb[3] ? r[3] : bb[3];
    any = true;
  }
  return any;
}

/* Before their setup: the triangles ids[0..n-1] (first..first+n-1 when ids is
 * NULL) whose corner cap (rr_tri_corner_cap, with the slack of mark_seen) may show
 * a sample of r at some position, into out; four caps' images a step in lanes.
 * Returns how many. */
static __attribute__((noinline)) uint32_t corner_caps_meet(const trav *t, uint32_t first, const uint32_t *ids,
                                                           uint32_t n, tile_rect r, uint32_t *out) {
  const int rr[4] = {r.x0, r.y0, r.x1, r.y1};
  uint32_t kept = 0;
  for (uint32_t q = 0; q < n; q += 4) {
    const int m = n - q < 4 ? (int)(n - q) : 4;
    double axis[3][4] = {{0}}, rho[4] = {0};
    unsigned used = 0, show = 0;
    for (int l = 0; l < m; l++) {
      const uint32_t id = ids ? ids[q + l] : first + q + l;
      if (rr_tri_corner_cap_lane(t->s, id, t->c, 1e-4, axis, rho, l) > 0) used |= 1u << l;
      else show |= 1u << l; /* no bound */
    }
    if (used) show |= rr_cam_caps_show4(t->cams, t->ns, (const double(*)[4])axis, rho, used, rr, t->simd);
    for (int l = 0; l < m; l++)
      if (show >> l & 1) out[kept++] = ids ? ids[q + l] : first + q + l;
  }
  return kept;
}

/* Triangle setup: triangles ids[0..n-1] (first..first+n-1 when ids is NULL) into
 * out, keeping those that may cover a sample of *r (of the image when r is NULL);
 * returns how many. Planar cameras bound the triangles from their corners first
 * (into scratch, room for n), so the many that fall between samples or beside r (a
 * leaf's box reaches into frusta its triangles do not) cost no setup; curved
 * cameras bound a set-up triangle by its cone. S counts the setups done. */
static uint32_t setup_tris(trav *t, uint32_t first, const uint32_t *ids, uint32_t n, const tile_rect *r,
                           tri_bound *scratch, tri_job *out);
/* The analytic primitives among ids[0..n-1] (first..first+n-1) into out: their
 * rectangle (over every position: rr_ana_screen_bounds holds for any) and floor
 * (rr_ana_t_floor, likewise). Their triangle corners, all at one point, never pass
 * the triangles' setup (prim/analytic.h), so the two together fit in room for n. */
static uint32_t setup_analytic(trav *t, uint32_t first, const uint32_t *ids, uint32_t n, const tile_rect *r,
                               tri_job *out) {
  uint32_t kept = 0;
  for (uint32_t k = 0; k < n; k++) {
    uint32_t id = ids ? ids[k] : first + k;
    if (scene_kind(t->s, id) == RR_GEOMETRY_TRIANGLE) continue;
    tri_job *j = out + kept;
    t->st.setups++;
    if (!rr_ana_screen_bounds(t->s, id, t->c, j->bb) || (r && !meets(j->bb, *r))) continue;
    j->id = id, j->ana = true, j->face = (uint8_t)t->face, j->face_y = t->face * t->face_rows;
    j->zmin = rr_ana_t_floor(t->s, id, t->c);
    kept++;
  }
  return kept;
}

/* A cube camera's triangles first..first+n-1 (trav.faces): each one's rectangle in
 * every face from its corners, then, for those that meet a face, the part of the
 * setup that depends on the eye once and the rest for each face met, a face's
 * triangles together in the lanes (rr_tri_setup_shared): one job per triangle and
 * face, S once per triangle. The setups go straight into the jobs, which are then
 * finished in place (a dropped one leaves no gap). */
static uint32_t setup_faces(trav *t, uint32_t first, uint32_t n, tri_job *out) {
  enum { GROUP = TRI_SHARED_MAX };
  uint32_t kept = 0;
  for (uint32_t g = first; g < first + n; g += GROUP) {
    const uint32_t m = first + n - g < GROUP ? first + n - g : GROUP;
    tri_bound b[6][GROUP];
    int nb[6];
    int16_t at[GROUP]; /* triangle g + i's place in ids, -1 when it meets no face */
    memset(at, 0xFF, sizeof at);
    for (int f = 0; f < 6; f++) {
      nb[f] = (int)rr_tri_corner_bounds_at(t->s, g, NULL, m, &t->face_cams[f * t->ns], t->ns, t->pos, t->simd, b[f]);
      for (int k = 0; k < nb[f]; k++) at[b[f][k].id - g] = 0;
    }
    uint32_t ids[GROUP];
    int q = 0;
    for (uint32_t i = 0; i < m; i++)
      if (!at[i]) at[i] = (int16_t)q, ids[q++] = g + i;
    if (!q) continue;
    t->st.setups += (uint64_t)q;
    int32_t sel[6 * GROUP];
    int face[6 * GROUP], pairs = 0;
    for (int f = 0; f < 6; f++)
      for (int k = 0; k < nb[f]; k++) sel[pairs++] = at[b[f][k].id - g];
    tri_job *jobs = out + kept; /* room for 6 a triangle: kept + pairs <= 6 (g + m - first) */
    const bool several = t->ns > 1;
    rr_tri_setup_shared(t->s, ids, q, t->face_cams0, 6, sel, nb, t->cull_back, t->simd, &jobs->ts, sizeof *jobs, face,
                        several ? &jobs->pl : NULL, sizeof *jobs);
    for (int f = 0, p = 0; f < 6; f++)
      for (int k = 0; k < nb[f]; k++, p++) {
        if (face[p] == SETUP_CULLED) continue;
        tri_job *j = out + kept;
        use_face(t, f);
        if (j != &jobs[p]) {
          j->ts = jobs[p].ts;
          if (several) j->pl = jobs[p].pl;
        }
        if (several) j->pos = b[f][k].pos;
        memcpy(j->bb, b[f][k].bb, sizeof j->bb);
        kept += finish_setup(t, ids[sel[p]], j);
      }
  }
  if (t->s->kind) { /* analytic primitives: bounded in every face, S once */
    for (uint32_t id = first; id < first + n; id++) {
      if (scene_kind(t->s, id) == RR_GEOMETRY_TRIANGLE) continue;
      t->st.setups++;
      for (int f = 0; f < 6; f++) {
        use_face(t, f);
        tri_job *j = out + kept;
        if (!rr_ana_screen_bounds(t->s, id, t->c, j->bb)) continue;
        j->id = id, j->ana = true, j->face = (uint8_t)f, j->face_y = f * t->face_rows;
        j->zmin = rr_ana_t_floor(t->s, id, t->c);
        kept++;
      }
    }
  }
  return kept;
}

static uint32_t setup_triangles(trav *t, uint32_t first, const uint32_t *ids, uint32_t n, const tile_rect *r,
                                tri_bound *scratch, tri_job *out) {
  if (t->faces && !ids) return setup_faces(t, first, n, out); /* (the root pass; frusta draw a face at a time) */
  uint32_t kept = setup_tris(t, first, ids, n, r, scratch, out);
  return t->s->kind ? kept + setup_analytic(t, first, ids, n, r, out + kept) : kept;
}

static uint32_t setup_tris(trav *t, uint32_t first, const uint32_t *ids, uint32_t n, const tile_rect *r,
                           tri_bound *scratch, tri_job *out) {
  if (t->c->planar) {
    uint32_t nb = rr_tri_corner_bounds_at(t->s, first, ids, n, t->c, t->ns, t->pos, t->simd, scratch), kept = 0;
    if (r) {
      for (uint32_t k = 0; k < nb; k++)
        if (meets(scratch[k].bb, *r)) scratch[kept++] = scratch[k];
      nb = kept;
    }
    return setup_bounded(t, scratch, nb, out);
  }
  uint32_t kept = 0, near[PEND_DRAW + BVH_MAX_LEAF];
  if (r && !t->seen && n <= PEND_DRAW + BVH_MAX_LEAF) /* (a frustum's leaves: no more) */
    n = corner_caps_meet(t, first, ids, n, *r, near), ids = near;
  for (uint32_t q = 0; q < n;) { /* eight lanes at a time, the bits of one */
    int m = 0, face[8];
    uint32_t lid[8];
    tri_setup ts[8];
    for (; q < n && m < 8; q++) {
      uint64_t none = 0; /* (the root pass: eight unseen at a step) */
      while (!ids && t->seen && q + 8 <= n && (memcpy(&none, t->seen + first + q, 8), !none)) q += 8;
      if (q >= n) break;
      uint32_t id = ids ? ids[q] : first + q;
      if (t->seen && !t->seen[id]) continue;
      lid[m++] = id;
    }
    t->st.setups += (uint64_t)m;
    rr_tri_setup_run(t->s, lid, m, t->c, t->cull_back, t->simd, ts, face);
    tri_sphere sp[8]; /* culled lanes too: a pass of four lanes costs the same */
    rr_tri_spheres_cam(ts, m, t->c, t->simd, sp); /* with the caps' images, for every position */
    for (int l = 0; l < m; l++) {
      tri_job *j = out + kept;
      if (face[l] == SETUP_CULLED || !curved_bounds(t, lid[l], &ts[l], &sp[l], j->bb) || (r && !meets(j->bb, *r)))
        continue;
      j->ts = ts[l];
      kept += finish_setup(t, lid[l], j);
    }
  }
  return kept;
}

/* Rasterizes a prepared triangle into the samples r, with its setup moved to
 * each position (mv; NULL for one position). */
KERNEL void draw_rect(trav *t, const tri_job *j, tri_moves *mv, tile_rect r) {
  /* Curved views start from bins of at most 16² samples: the bend bound grows with
   * the square of the bin, and a lat-long bin of 64² spans a quarter of the sphere. */
  if (t->o->binning)
    bin_raster(t, j, mv, r, !t->c->planar && t->c->bend_x > 0 && t->o->bin_size > 16 ? 16 : t->o->bin_size);
  else raster_samples(t, j, mv, r);
}

/* Several positions: each over its own rectangle (planar: the one-position
 * frame's, tri_pos_rect; curved: the union), which the kernel keeps to; what
 * moves with the position is made by the kernel when it needs it, once a draw. */
static void draw_moved(trav *t, const tri_job *j, int x0, int y0, int x1, int y1) {
  /* (by corners: a tile_rect by value went through vector registers, ~10 instructions) */
  const tile_rect r = {x0, y0, x1, y1};
  tri_moves mv; /* (no initializer: the per-position arrays are filled when needed) */
  mv.ox = t->ox, mv.oy = t->oy, mv.pl = NULL, mv.ready = false;
  mv.draw[0] = r.x0, mv.draw[1] = r.y0, mv.draw[2] = r.x1 - 1, mv.draw[3] = r.y1 - 1;
  mv.bb = j->bb;
  if (t->c->planar) {
    /* drawn when some position's own rectangle meets r: any does when r holds bb */
    uint32_t todo = ~(uint32_t)j->pos.none & ((1u << t->ns) - 1);
    const bool whole = r.x0 <= j->bb[0] && r.x1 > j->bb[2] && r.y0 <= j->bb[1] && r.y1 > j->bb[3];
    for (int q[4]; todo && !whole; todo &= todo - 1)
      if (tri_pos_rect(&j->pos, j->bb, __builtin_ctz(todo), q) && meets(q, r)) break;
    if (!todo) return;
    mv.pl = &j->pl, mv.pos = &j->pos;
    /* most draws of a detailed mesh: no call chain, no per-draw checks of options */
    if (t->direct && rr_raster_few_pixels(mv.draw, t->ns)) {
      t->pixels(&j->ts, &mv, j->id, mv.draw, t->c, t->ns, t->vb, &t->st.edge_evals);
      return;
    }
  }
  draw_rect(t, j, &mv, r);
}

/* Rasterizes a prepared triangle into the samples of f it may cover. */
KERNEL void draw(trav *t, const tri_job *j, tile_rect f) {
  tile_rect r = {j->bb[0] > f.x0 ? j->bb[0] : f.x0, j->bb[1] > f.y0 ? j->bb[1] : f.y0,
                 j->bb[2] + 1 < f.x1 ? j->bb[2] + 1 : f.x1, j->bb[3] + 1 < f.y1 ? j->bb[3] + 1 : f.y1};
  if (r.x0 >= r.x1 || r.y0 >= r.y1) return;
  if (t->ns > 1 && !j->ana) draw_moved(t, j, r.x0, r.y0, r.x1, r.y1);
  else draw_rect(t, j, NULL, r);
}

/* ---- frusta against boxes ---------------------------------------------- */

typedef struct frustum {
  tile_rect r;
  int nplanes;       /* planar cameras: inward side planes n·p + off >= 0, */
  rr_vf4 nx, ny, nz, off; /* four at once, stored by component for the box test */
  int has_cone;      /* curved cameras: 1 with a cone of the frustum's directions, -1 without rays */
  vec3 axis;
  float angle;
  float pixel;       /* curved cameras: rr_cam_rect_pixel_angle of r */
  bool has_ray;      /* the centre sample's ray, and 1 / its direction (0 where it is 0) */
  bool one_ray;      /* one sample: the frustum is that ray */
  rr_vf4 origin, dir, inv;
} frustum;

static rr_vf4 vf4_v3(vec3 v) { return (rr_vf4){v.x, v.y, v.z, 0}; }

static void set_plane(frustum *f, int i, vec3 n, vec3 point) {
  f->nx[i] = n.x, f->ny[i] = n.y, f->nz[i] = n.z, f->off[i] = -v3_dot(n, point);
}

static frustum make_frustum(const camera *c, int ns, tile_rect r) {
  frustum f = {.r = r, .one_ray = ns == 1 && r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1};
  vec3 o, d;
  f.has_ray = rr_cam_ray(c, (r.x0 + r.x1 - 1) / 2, (r.y0 + r.y1 - 1) / 2, &o, &d);
  f.origin = vf4_v3(o), f.dir = vf4_v3(d);
  for (int a = 0; a < 3; a++) f.inv[a] = f.dir[a] != 0 ? 1.0f / f.dir[a] : 0;
  if (c->type == RR_CAMERA_PERSPECTIVE) {
    /* Planes through the eye and the outer pixel edges: half a pixel beyond the
     * outer sample centres, conservative for every sample. With rays
     * d = d0 + x·dx + y·dy, the plane of column x has normal (d0 + x·dx) × dy, and
     * its dot with d(x', y) is det(dx, dy, d0)·(x - x'); rows likewise
     * (rr_cam_setup keeps these normals, turned to face increasing x and y). */
    float x0 = (float)r.x0, x1 = (float)r.x1, y0 = (float)r.y0, y1 = (float)r.y1;
    f.nplanes = 4;
    set_plane(&f, 0, v3_add(c->col_n0, v3_scale(c->col_n1, x0)), c->eye);
    set_plane(&f, 1, v3_neg(v3_add(c->col_n0, v3_scale(c->col_n1, x1))), c->eye);
    set_plane(&f, 2, v3_add(c->row_n0, v3_scale(c->row_n1, y0)), c->eye);
    set_plane(&f, 3, v3_neg(v3_add(c->row_n0, v3_scale(c->row_n1, y1))), c->eye);
  } else if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
    /* Parallel rays: a box-shaped prism along fwd over the rectangle's origins. */
    vec3 lo = v3_add(c->eye, v3_add(c->o0, v3_add(v3_scale(c->ox, (float)r.x0), v3_scale(c->oy, (float)r.y0))));
    vec3 hi = v3_add(c->eye, v3_add(c->o0, v3_add(v3_scale(c->ox, (float)r.x1), v3_scale(c->oy, (float)r.y1))));
    f.nplanes = 4;
    set_plane(&f, 0, c->right, lo), set_plane(&f, 1, v3_neg(c->right), hi);
    set_plane(&f, 2, c->up, hi), set_plane(&f, 3, v3_neg(c->up), lo);
  } else {
    f.has_cone = rr_cam_rect_cone(c, r.x0, r.y0, r.x1, r.y1, &f.axis, &f.angle);
    f.pixel = rr_cam_rect_pixel_angle(c, r.x0, r.y0, r.x1, r.y1, f.has_cone, f.angle);
  }
  return f;
}

/* A box's corners as vectors (lanes x, y, z; the fourth is not used). */
static rr_vf4 box_lo(const bvh_node *b) { return rr_vf4_load(b->lo); }
static rr_vf4 box_hi(const bvh_node *b) { return (rr_vf4){b->hi[0], b->hi[1], b->hi[2], 0}; }

/* The sum of lanes x, y, z after `first`, in that order. */
static float sum3(float first, rr_vf4 v) { return first + v[0] + v[1] + v[2]; }

/* Is the box wholly behind the plane through the eye facing fwd (with slack)? */
static bool box_behind(const bvh_node *b, const camera *c) {
  rr_vf4 f = vf4_v3(c->fwd), lo = f * box_lo(b), hi = f * box_hi(b);
  float off = -v3_dot(c->fwd, c->eye);
  return sum3(off, rr_vf4_max(lo, hi)) <= -1e-6f * sum3(fabsf(off), rr_vf4_abs(lo) + rr_vf4_abs(hi));
}

/* Does the box lie wholly outside one of the four side planes? Each plane's
 * largest value over the box, n·p + off, four planes in the lanes, against a
 * slack from the magnitudes of its terms. */
static bool box_outside_sides(const frustum *f, const bvh_node *b) {
  rr_vf4 lx = f->nx * rr_vf4_splat(b->lo[0]), hx = f->nx * rr_vf4_splat(b->hi[0]);
  rr_vf4 ly = f->ny * rr_vf4_splat(b->lo[1]), hy = f->ny * rr_vf4_splat(b->hi[1]);
  rr_vf4 lz = f->nz * rr_vf4_splat(b->lo[2]), hz = f->nz * rr_vf4_splat(b->hi[2]);
  rr_vf4 m = f->off + rr_vf4_max(lx, hx) + rr_vf4_max(ly, hy) + rr_vf4_max(lz, hz);
  rr_vf4 s = rr_vf4_abs(f->off) + (rr_vf4_abs(lx) + rr_vf4_abs(hx)) + (rr_vf4_abs(ly) + rr_vf4_abs(hy)) +
             (rr_vf4_abs(lz) + rr_vf4_abs(hz));
  return rr_vi4_bits(m < rr_vf4_splat(-1e-5f) * s) != 0;
}

/* A lower bound of the ray parameter t of any hit inside the box, in the units of
 * the stored depths: the distance along fwd for planar cameras (d·fwd = 1), the
 * distance from the eye over the longest ray direction for curved ones. */
static float box_tmin(const bvh_node *b, const camera *c) {
  rr_vf4 e = vf4_v3(c->eye), lo = box_lo(b) - e, hi = box_hi(b) - e;
  if (c->planar) {
    rr_vf4 f = vf4_v3(c->fwd);
    return sum3(0, rr_vf4_min(f * lo, f * hi));
  }
  rr_vf4 d = rr_vf4_max(rr_vf4_max(lo, -hi), rr_vf4_splat(0));
  return sqrtf(sum3(0, d * d)) / c->dir_len_max;
}

/* The ray of the centre sample meets the box (slab test with slack)? An axis the
 * direction does not move along is a slab the origin must lie in. */
static bool centre_hits(const frustum *f, const bvh_node *b) {
  if (!f->has_ray) return false;
  rr_vf4 lo = box_lo(b), hi = box_hi(b);
  rr_vf4 pad = rr_vf4_splat(1e-4f) * (hi - lo) + rr_vf4_splat(1e-6f) * rr_vf4_abs(f->origin);
  lo -= pad, hi += pad;
  rr_vf4 ta = (lo - f->origin) * f->inv, tb = (hi - f->origin) * f->inv;
  rr_vf4 near = rr_vf4_min(ta, tb), far = rr_vf4_max(ta, tb);
  rr_vi4 flat = f->dir == rr_vf4_splat(0), in = (f->origin >= lo) & (f->origin <= hi);
  near = rr_vf4_select(flat, rr_vf4_select(in, rr_vf4_splat(-INFINITY), rr_vf4_splat(INFINITY)), near);
  far = rr_vf4_select(flat, rr_vf4_select(in, rr_vf4_splat(INFINITY), rr_vf4_splat(-INFINITY)), far);
  float t0 = maxf(maxf(maxf(0, near[0]), near[1]), near[2]);
  float t1 = minf(minf(minf(INFINITY, far[0]), far[1]), far[2]);
  return t0 <= t1 * 1.0001f;
}

/* Is the box outside a cone of directions from the eye (rr_cam_rect_cone's
 * has_cone, axis, angle)? Its bounding sphere against the cone. */
static bool outside_cone(int has_cone, vec3 axis, float angle, const bvh_node *b, const camera *c) {
  if (has_cone <= 0) return has_cone < 0;
  vec3 lo = v3_load(b->lo), hi = v3_load(b->hi);
  vec3 v = v3_sub(v3_scale(v3_add(lo, hi), 0.5f), c->eye);
  float rad = 0.5f * v3_len(v3_sub(hi, lo)) * 1.0001f, dist = v3_len(v);
  if (dist <= rad || !(dist > 0)) return false;
  float beta = asinf(rad / dist), phi = acosf(maxf(-1.0f, minf(1.0f, v3_dot(v, axis) / dist)));
  return phi > angle + beta + 1e-4f;
}

/* May a sample of r at one of the ns positions of a curved view polar about an
 * axis look into box n? (rr_cam_boxes_show4: its ball's cap.) */
static bool box_cap_meets(const camera *cams, int ns, const bvh_node *n, const tile_rect *r) {
  float lo[3][4], hi[3][4];
  for (int a = 0; a < 3; a++)
    for (int l = 0; l < 4; l++) lo[a][l] = n->lo[a], hi[a][l] = n->hi[a];
  const int rr[4] = {r->x0, r->y0, r->x1, r->y1};
  return rr_cam_boxes_show4(cams, ns, (const float(*)[4])lo, (const float(*)[4])hi, 1, NULL, rr, true) != 0;
}

/* isOutside: the box (box_tmin tmin) lies wholly outside one side plane, behind
 * the image plane, or outside the cone of directions (of every one of the ns
 * positions of cams; the side planes run along pixel edges, which hold any). */
static bool is_outside(const frustum *f, const bvh_node *b, const camera *cams, int ns, float tmin) {
  const camera *c = cams;
  /* A frustum of one sample is its ray: the classic ray-box test. */
  if (f->one_ray) return !centre_hits(f, b);
  /* (a box whose box_tmin is positive lies in front of the eye) */
  if (f->nplanes) return (!(tmin > 0) && box_behind(b, c)) || box_outside_sides(f, b);
  if (c->bend_x > 0 && !box_cap_meets(cams, ns, b, &f->r)) return true; /* the polar maps */
  if (!outside_cone(f->has_cone, f->axis, f->angle, b, c)) return false;
  for (int s = 1; s < ns; s++) {
    vec3 axis = v3(0, 0, 0);
    float angle = 0;
    int has = rr_cam_rect_cone(&cams[s], f->r.x0, f->r.y0, f->r.x1, f->r.y1, &axis, &angle);
    if (!outside_cone(has, axis, angle, b, c)) return false;
  }
  return true;
}

static float frustum_area(const frustum *f) { return (float)(f->r.x1 - f->r.x0) * (float)(f->r.y1 - f->r.y0); }

/* Does box b (box_tmin z) look small in frustum f? Its size in pixels (curved
 * cameras: f's, which vary over a lens's image), squared, against split_ratio
 * times f's area. */
static bool looks_small(const trav *t, const frustum *f, const bvh_node *b, float z) {
  const camera *c = t->c;
  float diag = v3_len(v3(b->hi[0] - b->lo[0], b->hi[1] - b->lo[1], b->hi[2] - b->lo[2])), px;
  if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
    px = diag / (2.0f * c->tan_half_h / (float)c->height);
  } else {
    if (!(z > 0)) return false;
    px = c->planar ? diag / (z * 2.0f * c->tan_half_h / (float)c->height) : diag / (z * f->pixel);
  }
  return px * px < t->o->split_ratio * frustum_area(f);
}

/* Is f as small as splitting makes it? */
static bool at_split_min(const trav *t, const frustum *f) {
  int m = t->o->split_min;
  return m && f->r.x1 - f->r.x0 <= m && f->r.y1 - f->r.y0 <= m;
}

/* splitFrustum: the centre ray misses the node, or the node looks small in F. */
static bool should_split(const trav *t, const frustum *f, const bvh_node *b, float z) {
  if (!t->o->split_min || at_split_min(t, f)) return false;
  return !centre_hits(f, b) || looks_small(t, f, b, z);
}

/* The depth in front of which a hit inside a box of box_tmin z may lie (0: anywhere). */
static float occlusion_depth(float z) { return z > 0 ? z * (1 - DEPTH_MARGIN) : 0; }

bool rr_oracle_occluded(const camera *c, const bvh_node *b, float farthest) {
  return farthest < occlusion_depth(box_tmin(b, c));
}

bool rr_oracle_outside(const camera *c, int x0, int y0, int x1, int y1, const bvh_node *b) {
  tile_rect r = {x0, y0, x1, y1};
  frustum f = make_frustum(c, 1, r);
  return is_outside(&f, b, c, 1, box_tmin(b, c));
}

static void traverse(trav *t, const frustum *f, uint32_t node, float tmin);

static void split(trav *t, const frustum *f, uint32_t node, float tmin) {
  const tile_rect r = f->r;
  /* Quadrants aligned to the hierarchical z tiles. */
  int mx = r.x1 - r.x0 > t->o->split_min ? (r.x0 + (r.x1 - r.x0) / 2 + HIZ - 1) / HIZ * HIZ : r.x1;
  int my = r.y1 - r.y0 > t->o->split_min ? (r.y0 + (r.y1 - r.y0) / 2 + HIZ - 1) / HIZ * HIZ : r.y1;
  if (mx >= r.x1) mx = r.x1;
  if (my >= r.y1) my = r.y1;
  tile_rect q[4] = {{r.x0, r.y0, mx, my}, {mx, r.y0, r.x1, my}, {r.x0, my, mx, r.y1}, {mx, my, r.x1, r.y1}};
  for (int i = 0; i < 4; i++) {
    if (q[i].x0 >= q[i].x1 || q[i].y0 >= q[i].y1) continue;
    frustum sub = make_frustum(t->c, t->ns, q[i]);
    traverse(t, &sub, node, tmin);
  }
}

/* Draws the waiting leaves' triangles into their frustum. */
static void flush(trav *t) {
  tri_bound b[PEND_DRAW + BVH_MAX_LEAF];
  tri_job j[PEND_DRAW + BVH_MAX_LEAF];
  uint32_t kept = setup_triangles(t, 0, t->pend, t->npend, &t->pend_r, b, j);
  for (uint32_t k = 0; k < kept; k++) draw(t, &j[k], t->pend_r);
  t->npend = 0;
}

/* Nodes are references of accel/bvh_levels.h: with instances, a node past the top's
 * is an instance's node moved to world space, so the oracles see world boxes. */
static void generate(trav *t, const frustum *f, uint32_t node) {
  const rr_bvh *bvh = t->s->bvh;
  bvh_node buf;
  const bvh_node *n = bvh_node_at(bvh, node, &buf);
  if (n->count) {
    const tile_rect r = f->r, p = t->pend_r;
    if (t->npend && (r.x0 != p.x0 || r.y0 != p.y0 || r.x1 != p.x1 || r.y1 != p.y1)) flush(t);
    for (uint32_t i = 0; i < n->count; i++) t->pend[t->npend + i] = bvh_prim_at(bvh, n->first + i);
    t->npend += n->count, t->pend_r = r;
    if (t->npend >= PEND_DRAW) flush(t);
    return;
  }
  generate(t, f, n->first);
  generate(t, f, n->first + 1);
}

/* tmin: the node's box_tmin, which its parent knew already */
static void traverse(trav *t, const frustum *f, uint32_t node, float tmin) {
  const rr_bvh *bvh = t->s->bvh;
  bvh_node buf, ba, bb;
  const bvh_node *n = bvh_node_at(bvh, node, &buf);
  const oracles *o = t->o;
  t->st.nodes++;
  heat_charge(t->heat_n, t->vb->width, f->r.x0, f->r.y0, f->r.x1, f->r.y1, 1.0f);
  if (o->cull_outside && is_outside(f, n, t->cams, t->ns, tmin)) return;
  if (o->cull_occluded && hiz_nearer(t->hz, f->r.x0, f->r.y0, f->r.x1, f->r.y1, occlusion_depth(tmin))) return;
  if (should_split(t, f, n, tmin)) {
    split(t, f, node, tmin);
    return;
  }
  /* generateSamples for a whole inner node too when it looks small in a frustum
   * that cannot split any more: testing its descendants against F would cost more
   * than bounding their triangles, which drops those beside F or between samples. */
  if (n->count || (at_split_min(t, f) && looks_small(t, f, n, tmin))) {
    generate(t, f, node);
    return;
  }
  /* Children front to back: nearer box first along the view direction. */
  uint32_t a = n->first, b = n->first + 1;
  float za = box_tmin(bvh_node_at(bvh, a, &ba), t->c), zb = box_tmin(bvh_node_at(bvh, b, &bb), t->c);
  if (zb < za) {
    traverse(t, f, b, zb);
    traverse(t, f, a, za);
  } else {
    traverse(t, f, a, za);
    traverse(t, f, b, zb);
  }
}

/* ---- driving it ------------------------------------------------------------ */

static void add_stats(rr_stats *to, const rr_stats *s) {
  to->setups += s->setups, to->edge_evals += s->edge_evals, to->nodes += s->nodes;
  to->bins += s->bins, to->bins_empty += s->bins_empty;
}

/* generateSamples at the root is plain rasterization; on any number of threads it
 * runs sort-middle, like the 2D pipeline (vis/sortmiddle.h): the triangles are
 * bounded and set up in parallel chunks, then drawn in parallel bands of rows. */
#define ROOT_BATCH 131072 /* triangles set up before they are drawn */
#define ROOT_CHUNK 2048  /* triangles per setup job */

typedef struct root_pass {
  trav proto; /* the frame's settings; every job works on its own copy */
  rr_stats st[RR_MAX_THREADS];
} root_pass;

static uint32_t root_setup(void *arg, int thread, uint32_t first, uint32_t n, void *out) {
  root_pass *rp = arg;
  trav t = rp->proto;
  tri_bound scratch[ROOT_CHUNK];
  uint32_t kept = setup_triangles(&t, first, NULL, n, NULL, scratch, out);
  add_stats(&rp->st[thread], &t.st);
  return kept;
}

static void root_rows(const void *prim, int *y0, int *y1) {
  const tri_job *j = prim;
  *y0 = j->bb[1] + j->face_y, *y1 = j->bb[3] + j->face_y;
}

KERNEL void draw_rows(void *state, const void *prim, int y0, int y1) {
  trav *t = state;
  const tri_job *j = prim;
  use_face(t, j->face);
  draw(t, j, (tile_rect){0, y0 - j->face_y, t->vb->width, y1 - j->face_y});
}

static void root_band(int b, int thread, void *arg) {
  const sortmiddle *sm = arg;
  root_pass *rp = sm->arg;
  trav t = rp->proto;
  sm_draw_band(sm, b, &t, draw_rows);
  add_stats(&rp->st[thread], &t.st);
}

/* A curved view polar about an axis (or an OpenCV lens), drawn from the root: the triangles of the
 * BVH leaves whose box may show a sample (box_cap_meets), marked in seen (1)
 * before any setup, so that most of a detailed mesh's triangles (behind a
 * hemisphere, or between the samples) cost no setup. */
static void mark_seen(const trav *t, uint8_t *seen) {
  const rr_bvh *bvh = t->s->bvh;
  uint32_t stack[512], sp = 0;
  const cam_cap_shortcut sc = rr_cam_cap_shortcut(t->c);
  const int all[4] = {0, 0, t->c->width, t->c->height};
  stack[sp++] = 0;
  while (sp) { /* four nodes a step, their caps in lanes */
    bvh_node buf[4];
    const bvh_node *n[4];
    float lo[3][4] = {{0}}, hi[3][4] = {{0}};
    int m = 0;
    for (; sp && m < 4; m++) {
      n[m] = bvh_node_at(bvh, stack[--sp], &buf[m]);
      for (int a = 0; a < 3; a++) lo[a][m] = n[m]->lo[a], hi[a][m] = n[m]->hi[a];
    }
    const unsigned show =
        rr_cam_boxes_show4(t->cams, t->ns, (const float(*)[4])lo, (const float(*)[4])hi, (1u << m) - 1, &sc, all, t->simd);
    for (int i = 0; i < m; i++) {
      if (!(show >> i & 1)) continue;
      if (n[i]->count) {
        for (uint32_t q = 0; q < n[i]->count; q++) seen[bvh_prim_at(bvh, n[i]->first + q)] = 1;
      } else if (sp + 2 <= sizeof stack / sizeof *stack) {
        stack[sp++] = n[i]->first + 1, stack[sp++] = n[i]->first;
      } else { /* (deeper than any tree built) everything */
        memset(seen, 1, t->s->ntris);
        return;
      }
    }
  }
}

static rr_error rasterize_root(rr_device *dev, render_ctx *ctx, const trav *proto) {
  root_pass *rp = calloc(1, sizeof *rp);
  if (!rp) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for triangle setups");
  rp->proto = *proto;
  uint8_t *seen = NULL;
  const rr_camera_type type = proto->c->type;
  if (!proto->faces && ctx->scene->bvh && ctx->scene->bvh->nprims == ctx->scene->ntris &&
      (type == RR_CAMERA_PARABOLIC || type == RR_CAMERA_LATLONG || type == RR_CAMERA_FISHEYE ||
       type == RR_CAMERA_OPENCV || type == RR_CAMERA_OPENCV_FISHEYE)) {
    seen = calloc(ctx->scene->ntris, 1);
    if (!seen) {
      free(rp);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for triangle setups");
    }
    mark_seen(&rp->proto, seen);
    rp->proto.seen = seen;
  }
  sortmiddle sm = {.arg = rp,
                   .size = sizeof(tri_job),
                   .batch = proto->faces ? ROOT_BATCH / 4 : ROOT_BATCH,
                   .chunk = ROOT_CHUNK,
                   .out_max = proto->faces ? 6 : 1, /* a cube's triangle meets at most five faces */
                   .setup = root_setup,
                   .rows = root_rows,
                   .band = root_band,
                   .progress = &ctx->progress,
                   .dev = dev};
  /* blocks of whole top-level bins, else of 8 z tiles */
  const oracles *o = ctx->oracles;
  int align = o->binning && o->bin_size > HIZ ? (o->bin_size + HIZ - 1) / HIZ * HIZ : 8 * HIZ;
  /* a cube's faces stacked, each from a block's first row: no block, z tile or bin
   * holds rows of two faces */
  int height = ctx->vb->height;
  if (proto->faces) rp->proto.face_rows = (height + align - 1) / align * align, height = 6 * rp->proto.face_rows;
  bool ok = rr_sortmiddle(&sm, ctx->scene->ntris, height, align, ctx->threads);
  for (int i = 0; i < RR_MAX_THREADS; i++) add_stats(ctx->stats, &rp->st[i]);
  free(rp), free(seen);
  return ok ? RR_OK : rr_fail(dev, RR_ERROR_MEMORY, "out of memory for triangle setups");
}

typedef struct trav_job {
  trav proto;
  int tile, tiles_x, tiles_y, frustum;
  rr_stats st[RR_MAX_THREADS];
} trav_job;

/* One job: a tile of the image (of a cube's face), cut into the initial frusta. */
static void run_tile(int job, int thread, void *arg) {
  trav_job *tj = arg;
  trav t = tj->proto;
  use_face(&t, job / (tj->tiles_x * tj->tiles_y));
  job %= tj->tiles_x * tj->tiles_y;
  int tx = job % tj->tiles_x, ty = job / tj->tiles_x;
  tile_rect r = {tx * tj->tile, ty * tj->tile, (tx + 1) * tj->tile, (ty + 1) * tj->tile};
  if (r.x1 > t.vb->width) r.x1 = t.vb->width;
  if (r.y1 > t.vb->height) r.y1 = t.vb->height;
  int fs = tj->frustum < tj->tile ? tj->frustum : tj->tile;
  for (int y = r.y0; y < r.y1; y += fs)
    for (int x = r.x0; x < r.x1; x += fs) {
      tile_rect q = {x, y, x + fs < r.x1 ? x + fs : r.x1, y + fs < r.y1 ? y + fs : r.y1};
      frustum f = make_frustum(t.c, t.ns, q);
      traverse(&t, &f, 0, box_tmin(&t.s->bvh->nodes[0], t.c));
    }
  if (t.npend) flush(&t);
  add_stats(&tj->st[thread], &t.st);
}

rr_error rr_vis_traverse(rr_device *dev, render_ctx *ctx) {
  const oracles *o = ctx->oracles;
  const visbuf *vb = ctx->vb;
  if (ctx->scene->ntris == 0) return RR_OK; /* nothing to see: the cleared buffer is the image */
  if (!ctx->scene->bvh && o->leaves)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "this method needs the scene's BVH (call rr_scene_commit)");
  if (ctx->faces && ctx->faces != 6)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED, "a cube has six faces, not %d", ctx->faces);
  /* z tiles: one set per face of a cube drawn in one pass */
  hiz hz[6];
  const int nhz = ctx->faces ? 6 : 1;
  camera cams0[6];
  for (int f = 0; f < nhz; f++) {
    if (!rr_hiz_init(&hz[f], ctx->faces ? &ctx->face_vb[f] : vb, HIZ_SHIFT, 1)) {
      while (f > 0) rr_hiz_free(&hz[--f]);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the hierarchical z-buffer");
    }
    hz[f].layers = ctx->samples; /* a tile's farthest depth over every position */
    if (ctx->faces) cams0[f] = ctx->face_cams[f * ctx->samples];
  }
  trav proto = {.s = ctx->scene,
                .c = ctx->cam,
                .cams = ctx->cams,
                .ns = ctx->samples,
                .o = o,
                .vb = ctx->vb,
                .cull_back = ctx->opt->cull_backfaces != 0,
                .simd = !ctx->opt->scalar,
                .hiz_used = o->cull_occluded || (o->binning && o->early_z),
                .direct = ctx->samples > 1 && !o->binning && !ctx->heat_e && !ctx->face_heat_e &&
                          !(o->cull_occluded || (o->binning && o->early_z)),
                .hz = &hz[0],
                .heat_e = ctx->heat_e,
                .heat_n = ctx->heat_n,
                .faces = ctx->faces,
                .face_cams = ctx->face_cams,
                .face_cams0 = cams0,
                .face_vb = ctx->face_vb,
                .face_hz = hz,
                .face_heat_e = ctx->face_heat_e,
                .face_heat_n = ctx->face_heat_n};
  if (ctx->faces) /* face 0 to start with */
    proto.c = proto.cams = ctx->face_cams, proto.vb = &ctx->face_vb[0],
    proto.heat_e = ctx->face_heat_e, proto.heat_n = ctx->face_heat_n;
#ifdef RR_SIMD_X86
  proto.avx2 = proto.simd && __builtin_cpu_supports("avx2");
#endif
  proto.pixels = rr_raster_pixels_kernel(proto.avx2);
  proto.span[0] = proto.span[2] = ctx->cams[0].sx0, proto.span[1] = proto.span[3] = ctx->cams[0].sy0;
  for (int s = 0; s < ctx->samples; s++) proto.pos[s][0] = ctx->cams[s].sx0, proto.pos[s][1] = ctx->cams[s].sy0;
  for (int s = 0; s < RR_MAX_SAMPLES; s++)
    proto.ox[s] = proto.pos[s < ctx->samples ? s : 0][0], proto.oy[s] = proto.pos[s < ctx->samples ? s : 0][1];
  for (int s = 1; s < ctx->samples; s++) {
    proto.span[0] = minf(proto.span[0], ctx->cams[s].sx0), proto.span[1] = minf(proto.span[1], ctx->cams[s].sy0);
    proto.span[2] = maxf(proto.span[2], ctx->cams[s].sx0), proto.span[3] = maxf(proto.span[3], ctx->cams[s].sy0);
  }
  rr_error err = RR_OK;
  if (!o->leaves) {
    err = rasterize_root(dev, ctx, &proto);
  } else {
    /* A cube's faces, frustum by frustum: each triangle's eye part recorded by the
     * first face that sets it up, for the others (tri_eyes; records found by
     * 32-bit offsets) */
    const size_t ntris = ctx->scene->ntris, recs = (ntris * sizeof(float[TRI_EYE_REC]) + 63) / 64 * 64;
    const bool keep = ctx->faces && ntris < INT32_MAX / TRI_EYE_REC;
    rr_buf eb = keep ? rr_scratch_take(dev, SCRATCH_EYES, recs + ntris * sizeof(uint32_t)) : (rr_buf){0};
    tri_eyes eyes = {0};
    if (eb.p) {
      eyes.rec = eb.p, eyes.slot = (_Atomic uint32_t *)((char *)eb.p + recs);
      memset((void *)eyes.slot, 0, ntris * sizeof *eyes.slot);
      atomic_init(&eyes.used, 0);
      proto.eyes = &eyes;
    }
    trav_job *tj = calloc(1, sizeof *tj);
    if (!tj || (keep && !eb.p)) {
      free(tj), rr_scratch_give(dev, eb);
      for (int f = 0; f < nhz; f++) rr_hiz_free(&hz[f]);
      return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the traversal");
    }
    /* Initial frusta: the whole image (each face's) on one thread (the paper's
     * set-up), else tiles aligned to the z tiles dealt out to the threads (no z
     * tile has two writers); frustum_size forces a tile size. */
    int whole = vb->width > vb->height ? vb->width : vb->height;
    int frustum = o->frustum_size > 0 ? o->frustum_size : whole;
    /* On several threads a job is a tile of 128..256 samples: whole-image frusta
     * start there (one job would leave the other threads idle), small ones are
     * grouped. */
    int tile = ctx->threads > 1 ? (frustum < 128 ? 128 : frustum > 256 ? 256 : frustum)
                                : (frustum < whole ? frustum : whole);
    tile = (tile + HIZ - 1) / HIZ * HIZ;
    tj->proto = proto, tj->tile = tile, tj->frustum = frustum;
    tj->tiles_x = (vb->width + tile - 1) / tile, tj->tiles_y = (vb->height + tile - 1) / tile;
    rr_parallel_for_progress(tj->tiles_x * tj->tiles_y * nhz, ctx->threads, run_tile, tj, &ctx->progress);
    for (int i = 0; i < RR_MAX_THREADS; i++) add_stats(ctx->stats, &tj->st[i]);
    free(tj), rr_scratch_give(dev, eb);
  }
  for (int f = 0; f < nhz; f++) rr_hiz_free(&hz[f]);
  return err;
}
