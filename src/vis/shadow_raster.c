/* Shadows by 3D rasterization from the light (the paper's idea carried to shadows;
 * known as the irregular z-buffer): shadow rays that share their origin, a point
 * or spot light, are the samples of a non-planar camera at the light whose
 * directions are those towards the shaded points. Rasterizing the scene from
 * there visits (sample, triangle) pairs in the other order than one ray at a time:
 *
 *   bin the directions by cube-map face and, inside a face, along a Morton curve
 *   of a 64×64 grid, into bins of at most 64 samples;
 *   per bin, traverse the BVH (vis/bvh_trace.h) culling nodes by the bin's
 *   frustum (four planes through the light) and the box of its segments;
 *   at a leaf, set up four triangles' edges from the light once (tri4_edges_setup),
 *   reject those an edge plane keeps from the whole bin (its four corner
 *   directions, the bin test of 3D rasterization), and test each live sample of
 *   the bin with the one test of a ray (vis/ray_test.h) until every sample is
 *   occluded; the leaf's analytic primitives (which those steps drop as edge-on)
 *   through rr_ana_hit with each live sample's ray, as query_leaf tests them.
 *
 * The test of each (sample, triangle) pair is rr_occluded's, operation for
 * operation: the pre-test's edge values come from the same normals of the same
 * corners relative to the same origin, and the pairs it lets through go through
 * ray_tri_test with the sample's own ray. The culling is conservative (relative
 * margins), so a pair that rr_occluded finds is found here: the same bit for every
 * ray. The one exception is rr_occluded's: a hit whose t is computed far from the
 * exact one (a ray within rounding of a triangle's plane, TRI_DEPTH's fallback)
 * may lie outside the boxes both culls use.
 *
 * A directional light's rays share their direction instead (an orthographic
 * camera): they are binned by where their origins cross a plane across the
 * direction, a bin's frustum is the prism of four planes along it, and each ray
 * keeps its own edge pre-test (tri_ray_may_hit4 from its origin: the edge normals
 * depend on it), so only the traversal is shared. */
#include "prim/analytic.h"
#include "vis/bvh_trace.h"
#include "vis/ray_test.h"
#include "vis/shadow_raster.h"

#include <string.h>

enum { SR_BIN = 32, SR_GRID = 64, SR_BINS_PER_JOB = 16 };

/* One bin being rasterized: its samples, its frustum, its live samples. */
typedef struct sr_state {
  const rr_scene *s;
  const rr_bvh *b;
  const rr_ray *rays;
  const uint32_t *idx; /* the bin's rays: rays[idx[k]], k < n */
  int n;
  int *occluded;
  uint64_t live; /* bit k: sample k is not yet known to be occluded */
  bool parallel;           /* rays of a directional light: one direction, origins apart */
  float org[3];            /* the light (point) or 0 (parallel): boxes are taken relative to it */
  rr_vf4 eye[3];
  rr_vf4 lo[3], hi[3];     /* the box of the bin's segments, padded */
  rr_vf4 plane[4][3];      /* inward normals of the frustum's side planes (through the light, */
  float off[4];            /* or parallel to the rays: n·x ≥ off) */
  rr_vf4 corner[4][3];     /* the frustum's corner directions (point lights) */
  rr_vf4 axis[3];          /* parallel: the rays' direction */
  rr_vf4 dir[SR_BIN][3];   /* each sample's direction, broadcast */
  rr_vf4 from[SR_BIN][3];  /* parallel: each sample's origin, broadcast */
  rr_vf4 og[SR_BIN / 4][3]; /* samples 4k..4k+3: their origins relative to org (point lights: 0) */
  /* samples 4k..4k+3 side by side: their inverse directions, near planes' factor
   * shrunk and far planes' grown by the margin (as query_node's), and their tmax */
  rr_vf4 inv_near[SR_BIN / 4][3], inv_far[SR_BIN / 4][3], tmax[SR_BIN / 4];
  rr_vi4 neg[SR_BIN / 4][3]; /* the direction is negative: the near plane is the box's hi */
  ray_cam rc[SR_BIN];      /* each sample's pseudo-camera, when its first triangle passes */
  rr_shadow_counts st;
} sr_state;

/* The slots whose box meets the bin's segment box and lies not wholly outside a
 * side plane; nearest to the light first (an occluder near the light ends a
 * sample's search soonest, any one does). Nothing is dropped on pop. */
KERNEL int sr_node(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s, const bool parallel) {
  (void)ref;
  sr_state *b = q;
  b->st.nodes += wide_slots(w);
  rr_vf4 lo[3], hi[3], d2 = rr_vf4_splat(0);
  rr_vi4 in = (rr_vi4)rr_vf4_splat(0) == 0;
  for (int a = 0; a < 3; a++) {
    lo[a] = rr_vf4_load_aligned(w->lo[a]) - b->eye[a], hi[a] = rr_vf4_load_aligned(w->hi[a]) - b->eye[a];
    in &= (lo[a] <= b->hi[a]) & (hi[a] >= b->lo[a]);
    /* nearest first: the distance from the light, or (parallel) along the rays */
    rr_vf4 g = rr_vf4_max(rr_vf4_max(lo[a], -hi[a]), rr_vf4_splat(0));
    d2 += parallel ? rr_vf4_min(lo[a] * b->axis[a], hi[a] * b->axis[a]) : g * g;
  }
  for (int p = 0; p < 4; p++) { /* (planes through the light have off 0) */
    rr_vf4 m = rr_vf4_splat(parallel ? -b->off[p] : 0.0f), mag = rr_vf4_splat(parallel ? fabsf(b->off[p]) : 0.0f);
    for (int a = 0; a < 3; a++) {
      rr_vf4 l = b->plane[p][a] * lo[a], h = b->plane[p][a] * hi[a];
      m += rr_vf4_max(l, h), mag += rr_vf4_abs(l) + rr_vf4_abs(h);
    }
    in &= ~(m < rr_vf4_splat(-1e-5f) * mag); /* (NaN keeps the box) */
  }
  s->order = d2, s->key = rr_vf4_splat(0);
  int hits = rr_vi4_bits(in);
  /* a slot is entered by the samples whose segment meets its box (query_node's
   * slab test, four samples at a time), a packet under the bin's frustum */
  for (int h = hits; h; h &= h - 1) {
    int k = __builtin_ctz(h);
    uint64_t m = 0;
    for (int g = 0; g < (b->n + 3) / 4; g++) {
      if (!((lanes & b->live) >> (4 * g) & 15u)) continue;
      rr_vf4 t0 = rr_vf4_splat(0), t1 = b->tmax[g];
      for (int a = 0; a < 3; a++) { /* (a NaN slab is ignored, as in query_node) */
        rr_vf4 l = rr_vf4_splat(lo[a][k]), u = rr_vf4_splat(hi[a][k]);
        if (parallel) l -= b->og[g][a], u -= b->og[g][a]; /* (from the light, the origins are 0) */
        t0 = rr_vf4_max(rr_vf4_select(b->neg[g][a], u, l) * b->inv_near[g][a], t0);
        t1 = rr_vf4_min(rr_vf4_select(b->neg[g][a], l, u) * b->inv_far[g][a], t1);
      }
      m |= (uint64_t)rr_vi4_bits(t0 <= t1) << (4 * g);
    }
    s->lanes[k] = m & lanes;
    if (!s->lanes[k]) hits &= ~(1 << k);
  }
  return hits;
}

KERNEL float sr_best(const void *q) {
  (void)q;
  return INFINITY;
}

/* A leaf's analytic primitives (prim/analytic.h), which every triangle path above
 * drops as edge-on, against the bin's live samples: each pair through rr_ana_hit
 * with the sample's own ray and query_leaf's range rule (t in [tmin, tmax]), so the
 * bit is rr_occluded's. True when every sample is occluded. */
static bool sr_leaf_ana(sr_state *b, uint32_t first, uint32_t count, uint64_t lanes) {
  const rr_scene *s = b->s;
  for (uint32_t j = 0; j < count; j++) {
    uint32_t id = bvh_prim_at(b->b, first + j);
    if (scene_kind(s, id) == RR_GEOMETRY_TRIANGLE) continue;
    b->st.setups++;
    for (uint64_t live = b->live & lanes; live; live &= live - 1) {
      int k = __builtin_ctzll(live);
      const rr_ray *r = &b->rays[b->idx[k]];
      ana_ray ar = ana_ray_of(r->org, r->dir);
      float t, u, v;
      if (!rr_ana_hit(s, id, &ar, &t, &u, &v) || !(t >= r->tmin && t <= r->tmax)) continue;
      b->occluded[b->idx[k]] = 1;
      b->live &= ~(1ull << k);
    }
    if (!b->live) return true;
  }
  return false;
}

/* A leaf's triangles against the bin's live samples, four triangles at a time,
 * then its analytic primitives. */
KERNEL bool sr_leaf(void *q, uint32_t first, uint32_t count, uint64_t lanes, const bool parallel) {
  sr_state *b = q;
  const rr_scene *s = b->s;
  if (s->kind && sr_leaf_ana(b, first, count, lanes)) return true;
  float vbuf[9 * BVH_MAX_LEAF + BVH_LEAF_PAD]; /* an instance's leaf, in world space */
  uint32_t ibuf[BVH_MAX_LEAF];
  const uint32_t *ids;
  const float *v = bvh_leaf_at(b->b, false, first, count, vbuf, ibuf, &ids);
  for (uint32_t j = 0; j < count; j += 4) {
    uint32_t n = count - j < 4 ? count - j : 4;
    int inf = 0;
    if (s->inf)
      for (uint32_t k = 0; k < n; k++) inf |= (scene_inf(s, ids[j + k]) != 0) << k;
    tri4_edges te;
    b->st.setups += n;
    if (parallel) { /* each ray its own pre-test: the edges depend on its origin */
      for (uint64_t live = b->live & lanes; live; live &= live - 1) {
        int k = __builtin_ctzll(live);
        const rr_ray *r = &b->rays[b->idx[k]];
        rr_vf4 pre[4];
        int may = (tri_ray_may_hit4(v + j, count, NULL, b->from[k], b->dir[k], pre) & ((1 << n) - 1)) | inf;
        b->st.edge_evals++;
        for (; may; may &= may - 1) {
          int lane = __builtin_ctz(may);
          float t, l1, l2;
          const float e[4] = {pre[0][lane], pre[1][lane], pre[2][lane], pre[3][lane]};
          if (!ray_tri_test(s, ids[j + lane], &b->rc[k], r->org, r->dir, e, r->tmin, r->tmax, &t,
                            &l1, &l2))
            continue;
          b->occluded[b->idx[k]] = 1;
          b->live &= ~(1ull << k);
          break;
        }
      }
      if (!b->live) return true;
      continue;
    }
    tri4_edges_setup(v + j, count, NULL, b->eye, &te);
    /* The bin test: an edge whose value is below -slack at the four corners is
     * negative at every sample of the bin (each direction is a positive
     * combination of the corners), where the pre-test fails. The slack covers the
     * rounding of the corner values and of the samples' (a few ulps of |m|₁·|d|∞,
     * corners of |c|∞ just above 1). */
    int cand = rr_vi4_bits(te.ok) & ((1 << n) - 1) & ~inf;
    if (cand) {
      rr_vf4 val[4][4];
      for (int c = 0; c < 4; c++) tri4_edges_test(&te, b->corner[c], val[c]);
      rr_vi4 out = (rr_vi4)rr_vf4_splat(0);
      for (int e = 0; e < 3; e++) {
        rr_vf4 slack = rr_vf4_splat(-2e-5f) * (rr_vf4_abs(te.m[e].x) + rr_vf4_abs(te.m[e].y) + rr_vf4_abs(te.m[e].z));
        out |= (val[0][e] < slack) & (val[1][e] < slack) & (val[2][e] < slack) & (val[3][e] < slack);
      }
      b->st.edge_evals += 4;
      cand &= ~rr_vi4_bits(out);
    }
    if (!(cand | inf)) continue;
    for (uint64_t live = b->live & lanes; live; live &= live - 1) {
      int k = __builtin_ctzll(live);
      const rr_ray *r = &b->rays[b->idx[k]];
      rr_vf4 pre[4];
      int may = (tri4_edges_test(&te, b->dir[k], pre) & cand) | inf;
      b->st.edge_evals++;
      for (; may; may &= may - 1) {
        int lane = __builtin_ctz(may);
        float t, l1, l2;
        const float e[4] = {pre[0][lane], pre[1][lane], pre[2][lane], pre[3][lane]};
        if (!ray_tri_test(s, ids[j + lane], &b->rc[k], r->org, r->dir, e, r->tmin, r->tmax, &t, &l1,
                          &l2))
          continue;
        b->occluded[b->idx[k]] = 1;
        b->live &= ~(1ull << k);
        break;
      }
    }
    if (!b->live) return true;
  }
  return false;
}

/* The policies of bvh_trace, specialised for a camera at a light and for parallel rays. */
KERNEL int sr_node_point(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  return sr_node(q, w, ref, lanes, s, false);
}
KERNEL int sr_node_parallel(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  return sr_node(q, w, ref, lanes, s, true);
}
KERNEL bool sr_leaf_point(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  return sr_leaf(q, first, count, lanes, false);
}
KERNEL bool sr_leaf_parallel(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  return sr_leaf(q, first, count, lanes, true);
}

/* Where a direction falls: its cube-map face (major axis a, sign), and its
 * coordinates u = d_(a+1) / |d_a|, v = d_(a+2) / |d_a| in [-1, 1]. */
static int sr_face(const float d[3], float *u, float *v) {
  float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
  int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
  float m = fabsf(d[a]);
  *u = d[(a + 1) % 3] / m, *v = d[(a + 2) % 3] / m;
  return 2 * a + (d[a] < 0);
}

/* Spreads the 6 bits of x to the even bits 0, 2, .., 10. */
static uint32_t sr_spread(uint32_t x) {
  x = (x | x << 4) & 0x0F0Fu;
  x = (x | x << 2) & 0x3333u;
  return (x | x << 1) & 0x5555u;
}
/* Bit-interleaves two 6-bit cells into a 12-bit Morton code. */
static uint32_t sr_morton(uint32_t x, uint32_t y) { return sr_spread(x) | sr_spread(y) << 1; }

static int sr_cell(float u) {
  int c = (int)((u + 1.0f) * 0.5f * SR_GRID);
  return c < 0 ? 0 : c >= SR_GRID ? SR_GRID - 1 : c;
}

/* A parallel ray's origin seen along the rays' major axis a: where it crosses the
 * plane x_a = 0, u = o_(a+1) − o_a·r1, v = o_(a+2) − o_a·r2 with r = d / d_a. */
typedef struct {
  int a;
  float r1, r2;
} sr_proj;
static sr_proj sr_proj_of(const float d[3]) {
  float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
  int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
  return (sr_proj){a, d[(a + 1) % 3] / d[a], d[(a + 2) % 3] / d[a]};
}
static void sr_project(const sr_proj *p, const float o[3], float *u, float *v) {
  *u = o[(p->a + 1) % 3] - o[p->a] * p->r1, *v = o[(p->a + 2) % 3] - o[p->a] * p->r2;
}

/* Prepares bin b for the samples rays[idx[0..n-1]] (one face, or parallel rays). */
static void sr_bin_init(sr_state *b, const rr_ray *rays, const uint32_t *idx, int n) {
  b->idx = idx, b->n = n, b->live = n == 64 ? ~0ull : (1ull << n) - 1;
  float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY, lo[3], hi[3], big = 0;
  int face = 0;
  sr_proj pj = sr_proj_of(rays[idx[0]].dir);
  for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
  if (!b->parallel)
    for (int a = 0; a < 3; a++) lo[a] = hi[a] = 0; /* the light */
  for (int k = 0; k < n; k++) {
    const rr_ray *r = &rays[idx[k]];
    float u, v;
    if (b->parallel) {
      sr_project(&pj, r->org, &u, &v);
      big = maxf(big, fabsf(r->org[(pj.a + 1) % 3]) + fabsf(r->org[pj.a] * pj.r1));
      big = maxf(big, fabsf(r->org[(pj.a + 2) % 3]) + fabsf(r->org[pj.a] * pj.r2));
    } else {
      face = sr_face(r->dir, &u, &v);
    }
    u0 = minf(u0, u), u1 = maxf(u1, u), v0 = minf(v0, v), v1 = maxf(v1, v);
    for (int a = 0; a < 3; a++) {
      /* the segment, t in [0, tmax] (every hit has t ≥ 0), relative to org */
      float d = r->dir[a], o = r->org[a] - b->org[a], e = d == 0 || !(r->tmax > 0) ? 0 : r->tmax * d;
      lo[a] = minf(lo[a], minf(o, o + e)), hi[a] = maxf(hi[a], maxf(o, o + e));
      b->dir[k][a] = rr_vf4_splat(d);
      if (b->parallel) b->from[k][a] = rr_vf4_splat(r->org[a]);
    }
    b->rc[k].ready = false;
  }
  for (int k = 0; k < (n + 3) / 4 * 4; k++) { /* lanes past n: an empty range, never entered */
    const rr_ray *r = &rays[idx[k < n ? k : 0]];
    for (int a = 0; a < 3; a++) {
      float inv = 1.0f / r->dir[a];
      b->inv_near[k / 4][a][k % 4] = inv * (1 - 2 * RAY_MARGIN), b->inv_far[k / 4][a][k % 4] = inv * (1 + 2 * RAY_MARGIN);
      b->neg[k / 4][a][k % 4] = inv < 0 ? -1 : 0;
      b->og[k / 4][a][k % 4] = r->org[a] - b->org[a];
    }
    b->tmax[k / 4][k % 4] = k < n ? r->tmax : -1.0f;
  }
  /* pad the box for hits computed a few ulps beyond the segment and edge values a
   * few ulps inside a triangle (an infinite side stays infinite) */
  float ext = 0;
  for (int a = 0; a < 3; a++)
    if (hi[a] - lo[a] < INFINITY) ext = maxf(ext, hi[a] - lo[a]);
  for (int a = 0; a < 3; a++) {
    float far = hi[a] - lo[a] < INFINITY ? maxf(fabsf(lo[a]), fabsf(hi[a])) : 0;
    float pad = 1e-4f * ext + 1e-6f * (fabsf(b->org[a]) + far) + 1e-30f;
    b->lo[a] = rr_vf4_splat(lo[a] - pad), b->hi[a] = rr_vf4_splat(hi[a] + pad);
  }
  int a = b->parallel ? pj.a : face / 2, ia = (a + 1) % 3, ib = (a + 2) % 3;
  float pl[4][3] = {{0}};
  if (b->parallel) {
    /* the rays run in the prism u0 ≤ x_ia − x_a·r1 ≤ u1, v0 ≤ x_ib − x_a·r2 ≤ v1 (padded
     * for the rounding of u, v and of r along a ray) */
    float pad = 1e-6f * (big + u1 - u0 + v1 - v0) + 1e-30f;
    u0 -= pad, u1 += pad, v0 -= pad, v1 += pad;
    pl[0][ia] = 1, pl[0][a] = -pj.r1, b->off[0] = u0;
    pl[1][ia] = -1, pl[1][a] = pj.r1, b->off[1] = -u1;
    pl[2][ib] = 1, pl[2][a] = -pj.r2, b->off[2] = v0;
    pl[3][ib] = -1, pl[3][a] = pj.r2, b->off[3] = -v1;
    for (int p = 0; p < 4; p++)
      for (int x = 0; x < 3; x++) b->plane[p][x] = rr_vf4_splat(pl[p][x]);
    for (int x = 0; x < 3; x++) b->axis[x] = rr_vf4_splat(rays[idx[0]].dir[x]);
    return;
  }
  /* the rectangle padded for the rounding of u and v */
  u0 -= 1e-6f * (1 + fabsf(u0)), u1 += 1e-6f * (1 + fabsf(u1));
  v0 -= 1e-6f * (1 + fabsf(v0)), v1 += 1e-6f * (1 + fabsf(v1));
  float sg = face & 1 ? -1.0f : 1.0f;
  /* u ≥ u0: d_ia − u0·sg·d_a ≥ 0, and likewise */
  float uv[4][2] = {{u0, v0}, {u1, v0}, {u0, v1}, {u1, v1}};
  pl[0][a] = -u0 * sg, pl[0][ia] = 1;
  pl[1][a] = u1 * sg, pl[1][ia] = -1;
  pl[2][a] = -v0 * sg, pl[2][ib] = 1;
  pl[3][a] = v1 * sg, pl[3][ib] = -1;
  for (int p = 0; p < 4; p++) {
    float c[3];
    c[a] = sg, c[ia] = uv[p][0], c[ib] = uv[p][1];
    b->off[p] = 0;
    for (int x = 0; x < 3; x++) b->plane[p][x] = rr_vf4_splat(pl[p][x]), b->corner[p][x] = rr_vf4_splat(c[x]);
  }
}

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const rr_ray *rays;
  const uint32_t *order;  /* the shared-origin rays, sorted into bins */
  const uint32_t *bin;    /* bin i holds order[bin[i] .. bin[i + 1]) */
  uint32_t nbins;
  bool parallel;
  float org[3]; /* the light, or 0 for parallel rays */
  int *occluded;
  rr_shadow_counts *st; /* per thread */
} sr_job;

KERNEL void sr_run_body(int job, int thread, void *arg) {
  sr_job *j = arg;
  sr_state *b = malloc(sizeof *b);
  if (!b) { /* the rays one at a time, as rr_occluded traces them */
    for (uint32_t i = (uint32_t)job * SR_BINS_PER_JOB; i < j->nbins && i < (uint32_t)(job + 1) * SR_BINS_PER_JOB; i++)
      for (uint32_t k = j->bin[i]; k < j->bin[i + 1]; k++)
        rr_occluded(NULL, j->s, &j->rays[j->order[k]], &j->occluded[j->order[k]]);
    return;
  }
  b->s = j->s, b->b = j->b, b->rays = j->rays, b->occluded = j->occluded;
  memset(&b->st, 0, sizeof b->st);
  memcpy(b->org, j->org, sizeof b->org);
  b->parallel = j->parallel;
  for (int a = 0; a < 3; a++) b->eye[a] = rr_vf4_splat(j->org[a]);
  for (uint32_t i = (uint32_t)job * SR_BINS_PER_JOB; i < j->nbins && i < (uint32_t)(job + 1) * SR_BINS_PER_JOB; i++) {
    sr_bin_init(b, j->rays, j->order + j->bin[i], (int)(j->bin[i + 1] - j->bin[i]));
    b->st.bins++;
    if (b->parallel) bvh_trace(j->b, b, b->live, sr_node_parallel, sr_leaf_parallel, sr_best);
    else bvh_trace(j->b, b, b->live, sr_node_point, sr_leaf_point, sr_best);
  }
  rr_shadow_counts *c = &j->st[thread];
  c->bins += b->st.bins, c->nodes += b->st.nodes, c->setups += b->st.setups, c->edge_evals += b->st.edge_evals;
  free(b);
}

static void sr_run(int job, int thread, void *arg) { sr_run_body(job, thread, arg); }
#ifdef RR_SIMD_X86
/* The same code with AVX2's encodings, the same lane operations and bits (as ray_query.c). */
RR_TARGET_AVX2 static void sr_run_avx2(int job, int thread, void *arg) { sr_run_body(job, thread, arg); }
#endif

/* Sorts the m keys (bin key << 32 | ray) by their 15-bit bin key, stably (the
 * rays stay in their order within a cell): two passes of an LSD radix sort
 * through tmp. */
static void sort_keys(uint64_t *key, uint64_t *tmp, size_t m) {
  if (m <= 256) { /* a batch's rays: insertion sort, without the passes' counters */
    for (size_t k = 1; k < m; k++) {
      uint64_t v = key[k];
      size_t i = k;
      for (; i > 0 && key[i - 1] > v; i--) key[i] = key[i - 1];
      key[i] = v;
    }
    return;
  }
  for (int pass = 0; pass < 2; pass++) {
    int shift = 32 + 8 * pass;
    size_t count[257] = {0};
    for (size_t k = 0; k < m; k++) count[(key[k] >> shift & 255u) + 1]++;
    for (int c = 0; c < 256; c++) count[c + 1] += count[c];
    for (size_t k = 0; k < m; k++) tmp[count[key[k] >> shift & 255u]++] = key[k];
    memcpy(key, tmp, m * sizeof *key);
  }
}

bool rr_occluded_raster(const rr_scene *s, const rr_bvh *b, const rr_ray *rays, size_t n, int threads, int *occluded,
                        rr_shadow_counts *counts) {
  if (counts) memset(counts, 0, sizeof *counts);
  if (n > UINT32_MAX) return false;
  for (size_t i = 0; i < n; i++) occluded[i] = 0;
  if (!b || !n) return true; /* an empty scene: every ray misses */
  uint64_t *key = malloc(2 * n * sizeof *key);
  uint32_t *order = malloc(n * sizeof *order), *bin = malloc((n + 1) * sizeof *bin);
  if (!key || !order || !bin) {
    free(key), free(order), free(bin);
    return false;
  }
  /* The rays of one light are binned: those from the first valid ray's origin (a
   * point or spot light) or, when the second valid ray shares its direction and
   * not its origin, those along it (a directional light, an orthographic camera);
   * the others go one at a time, and a refused ray is a miss (rr_occluded_stream's
   * rule). */
  const rr_ray *r0 = NULL, *r1 = NULL; /* the first two valid rays */
  for (size_t i = 0; i < n && !r1; i++) {
    const rr_ray *r = &rays[i];
    if (ray_problem(r->org, r->dir, r->tmin, r->tmax)) continue;
    if (!r0) r0 = r;
    else r1 = r;
  }
  bool parallel = r1 && memcmp(r0->org, r1->org, sizeof r1->org) != 0 && memcmp(r0->dir, r1->dir, sizeof r1->dir) == 0;
  sr_proj pj = r0 ? sr_proj_of(r0->dir) : (sr_proj){0, 0, 0};
  float ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY, vhi = -INFINITY; /* parallel: the origins' extent */
  for (size_t i = 0; parallel && i < n; i++) {
    const rr_ray *r = &rays[i];
    if (ray_problem(r->org, r->dir, r->tmin, r->tmax) || memcmp(r0->dir, r->dir, sizeof r->dir) != 0) continue;
    float u, v;
    sr_project(&pj, r->org, &u, &v);
    ulo = minf(ulo, u), uhi = maxf(uhi, u), vlo = minf(vlo, v), vhi = maxf(vhi, v);
  }
  size_t m = 0;
  for (size_t i = 0; i < n; i++) {
    const rr_ray *r = &rays[i];
    if (ray_problem(r->org, r->dir, r->tmin, r->tmax)) continue;
    if (parallel ? memcmp(r0->dir, r->dir, sizeof r->dir) != 0 : memcmp(r0->org, r->org, sizeof r->org) != 0) {
      rr_occluded(NULL, s, r, &occluded[i]);
      continue;
    }
    float u, v;
    uint32_t face = 0, cu, cv;
    if (parallel) {
      sr_project(&pj, r->org, &u, &v);
      cu = (uint32_t)sr_cell(uhi > ulo ? 2 * (u - ulo) / (uhi - ulo) - 1 : 0);
      cv = (uint32_t)sr_cell(vhi > vlo ? 2 * (v - vlo) / (vhi - vlo) - 1 : 0);
    } else {
      face = (uint32_t)sr_face(r->dir, &u, &v);
      cu = (uint32_t)sr_cell(u), cv = (uint32_t)sr_cell(v);
    }
    key[m++] = (uint64_t)(face << 12 | sr_morton(cu, cv)) << 32 | i;
  }
  sort_keys(key, key + n, m);
  uint32_t nbins = 0;
  for (size_t k = 0; k < m; k++) {
    order[k] = (uint32_t)key[k];
    if (k == 0 || k - bin[nbins - 1] == SR_BIN || key[k] >> 44 != key[k - 1] >> 44) bin[nbins++] = (uint32_t)k;
  }
  bin[nbins] = (uint32_t)m;
  threads = threads < 1 ? 1 : threads > RR_MAX_THREADS ? RR_MAX_THREADS : threads;
  sr_job job = {.s = s, .b = b, .rays = rays, .order = order, .bin = bin, .nbins = nbins, .occluded = occluded,
                .st = calloc((size_t)threads, sizeof(rr_shadow_counts))}, *j = &job;
  if (!j->st) {
    free(key), free(order), free(bin);
    return false;
  }
  j->parallel = parallel;
  if (r0 && !parallel) memcpy(j->org, r0->org, sizeof j->org);
  rr_parallel_fn run = sr_run;
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) run = sr_run_avx2;
#endif
  rr_parallel_for((int)((nbins + SR_BINS_PER_JOB - 1) / SR_BINS_PER_JOB), threads, run, j);
  if (counts)
    for (int t = 0; t < threads; t++) {
      counts->bins += j->st[t].bins, counts->nodes += j->st[t].nodes;
      counts->setups += j->st[t].setups, counts->edge_evals += j->st[t].edge_evals;
    }
  free(j->st), free(key), free(order), free(bin);
  return true;
}
