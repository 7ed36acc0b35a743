/* Ray casting through the BVH: rc-bvh (one ray per sample) and rc-packet (8x8
 * packets of primary rays), both through the one traversal of vis/bvh_trace.h
 * (the public queries rr_intersect / rr_occluded use it too: vis/ray_query.c).
 *
 * Leaves run the project's one sample test, so the methods produce the same bits
 * as rc and 3dr-bb: a primary ray tests a triangle set up by rr_tri_setup()
 * for the camera (once per frame, kept in leaf order) with shade_sample_w() at
 * its sample. Traversal only decides which (sample, triangle) pairs are visited,
 * and for primary rays it never skips the winner, by construction:
 * - each triangle gets, per frame, a lower bound of the t that sample_test() can
 *   compute for it and (planar cameras) a screen rectangle holding every sample
 *   where it can pass, both from the float error of the edge functions; nodes
 *   take the least bound and the union of rectangles;
 * - a ray skips a node whose rectangle does not hold its sample, or whose bound
 *   is greater than its best t (strictly: an equal t with a lower id still wins);
 * - needles (slivers whose rectangle reaches far beyond their projection) would
 *   widen every ancestor's rectangle: they are taken out of the tree for the frame
 *   and tested over their rectangles afterwards (the loose pass), merged by the
 *   same depth_wins().
 * The price of exactness is that setup: every triangle, every frame (S = T).
 * Box entry distances would not do: a triangle seen at a grazing angle can compute
 * a t well in front of its own box (measured: 2.4% at sin = 0.004 on the ogre), and
 * rc and 3dr-bb keep such hits. Curved cameras use 3D box tests widened by
 * RAY_MARGIN relative to t (NaN slabs ignored) besides the exact bounds. */
#include "vis/bvh_trace.h"

#include <string.h>

/* ---- per-frame triangle setups and exact pruning bounds ------------------------ */

/* Every triangle is set up once per frame (S = triangles), in leaf order, with a
 * lower bound `tlo` of the t that sample_test() can compute for it at any sample
 * of the image; a node's tlo is the least of its triangles'. A primary ray prunes
 * a node only when the node's tlo is greater than its best t, which is exact:
 * box entry distances are not, because at a grazing angle the t a triangle
 * computes may lie in front of its own box (rarely now that t comes from the plane,
 * but unboundedly in TRI_DEPTH's fallback), and rc / 3dr-bb keep such hits. Box
 * tests then only cull rays that miss. */
/* A triangle's setup with its id (RR_MISS when culled for this camera): the one
 * stream of memory a leaf reads. */
typedef struct {
  tri_setup ts;
  uint32_t id;
} leaf_tri;

/* Per wide node and slot: the screen rectangle (planar cameras) and the bound;
 * an empty slot has an empty rectangle and an infinite bound. */
typedef struct {
  rr_vf4 x0, y0, x1, y1, tlo;
} wide_bounds;

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const camera *cam;
  bool cull, simd;
  leaf_tri *ts;      /* by position in b->prims */
  float (*trect)[4]; /* by position: the triangle's rectangle x0, y0, x1, y1 */
  float *tlo;        /* by node */
  float (*rect)[4];  /* by node */
  wide_bounds *wb;   /* by wide node */
  uint8_t *loose;    /* by position: a needle left to the loose pass */
  uint32_t *loose_pos, nloose;
  leaf_tri *loose_ts;
} frame_setups;

typedef struct {
  frame_setups *fs;
  int chunk;
} setup_job;

enum { SETUP_CHUNK = 4096 };

/* A needle: a sliver whose rectangle reaches far beyond its projection (the
 * enlarged lines of two nearly parallel edges meet far away). Kept in the tree it
 * would widen every ancestor's rectangle, so it goes to the loose pass instead. */
static bool is_needle(const frame_setups *fs, uint32_t id, const float r[4]) {
  float area = (r[2] - r[0]) * (r[3] - r[1]);
  if (!(area > 256)) return false;
  float x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (int k = 0; k < 3; k++) {
    float sx, sy;
    if (!rr_cam_project(fs->cam, scene_q(fs->s, k, id, fs->cam->eye), &sx, &sy)) return false;
    x0 = fminf(x0, sx), y0 = fminf(y0, sy), x1 = fmaxf(x1, sx), y1 = fmaxf(y1, sy);
  }
  return area > 4 * (x1 - x0 + 2) * (y1 - y0 + 2);
}

/* Finishes leaves[0..nl-1], whose triangles ts/face hold in leaf order: each
 * triangle's setup, id and rectangle, each leaf's least t and rectangle. */
static void finish_leaves(frame_setups *fs, const uint32_t *leaves, int nl, const tri_setup *ts, const int *face) {
  const rr_bvh *b = fs->b;
  for (int q = 0; q < nl; q++) {
    const bvh_node *n = &b->nodes[leaves[q]];
    float tlo = INFINITY, r[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = n->first; i < n->first + n->count; i++, ts++, face++) {
      bool live = *face != SETUP_CULLED;
      if (live) fs->ts[i].ts = *ts;
      fs->ts[i].id = live ? b->prims[i] : RR_MISS;
      fs->loose[i] = 0;
      float *tr = fs->trect[i];
      if (!live) {
        tr[0] = tr[1] = INFINITY, tr[2] = tr[3] = -INFINITY;
        continue;
      }
      float t = rr_tri_bounds(&fs->ts[i].ts, fs->cam, tr);
      fs->loose[i] = fs->cam->planar && is_needle(fs, b->prims[i], tr);
      if (fs->loose[i]) continue;
      tlo = t < tlo ? t : tlo;
      r[0] = fminf(r[0], tr[0]), r[1] = fminf(r[1], tr[1]), r[2] = fmaxf(r[2], tr[2]), r[3] = fmaxf(r[3], tr[3]);
    }
    fs->tlo[leaves[q]] = tlo;
    memcpy(fs->rect[leaves[q]], r, sizeof r);
  }
}

/* Sets up the triangles of the leaves among nodes [job·chunk, (job+1)·chunk).
 * Leaves hold a few triangles each, so those of several leaves are set up
 * together, eight lanes at a time where there is AVX2 (lanes never mix: the
 * same bits as one at a time). */
static void setup_leaves(int job, int thread, void *arg) {
  (void)thread;
  frame_setups *fs = ((setup_job *)arg)->fs;
  const rr_bvh *b = fs->b;
  uint32_t n0 = (uint32_t)job * SETUP_CHUNK, n1 = n0 + SETUP_CHUNK < b->nnodes ? n0 + SETUP_CHUNK : b->nnodes;
  enum { BATCH = 2 * BVH_MAX_LEAF };
  tri_setup ts[BATCH];
  int face[BATCH], nids = 0, nl = 0;
  uint32_t ids[BATCH], leaves[BATCH];
  for (uint32_t k = n0; k < n1; k++) {
    const bvh_node *n = &b->nodes[k];
    if (!n->count) continue;
    if (nids + (int)n->count > BATCH) {
      rr_tri_setup_run(fs->s, ids, nids, fs->cam, fs->cull, fs->simd, ts, face);
      finish_leaves(fs, leaves, nl, ts, face);
      nids = nl = 0;
    }
    memcpy(ids + nids, b->prims + n->first, n->count * sizeof *ids);
    nids += (int)n->count, leaves[nl++] = k;
  }
  rr_tri_setup_run(fs->s, ids, nids, fs->cam, fs->cull, fs->simd, ts, face);
  finish_leaves(fs, leaves, nl, ts, face);
}

static void setups_free(frame_setups *fs) {
  free(fs->ts), free(fs->trect), free(fs->tlo), free(fs->rect), free(fs->wb), free(fs->loose);
  free(fs->loose_pos), free(fs->loose_ts);
}

static rr_error setups_init(rr_device *dev, frame_setups *fs, const render_ctx *ctx, const rr_bvh *b) {
  *fs = (frame_setups){.s = ctx->scene, .b = b, .cam = ctx->cam, .cull = ctx->opt->cull_backfaces != 0,
                        .simd = !ctx->opt->scalar};
  size_t n = b->nprims;
  fs->ts = malloc(n * sizeof *fs->ts + 1);
  fs->trect = malloc(n * sizeof *fs->trect + 1);
  fs->tlo = malloc((size_t)b->nnodes * sizeof *fs->tlo + 1);
  fs->rect = malloc((size_t)b->nnodes * sizeof *fs->rect + 1);
  fs->wb = aligned_alloc(16, (size_t)b->nwide * sizeof *fs->wb);
  fs->loose = malloc(n + 1);
  if (!fs->ts || !fs->trect || !fs->tlo || !fs->rect || !fs->wb || !fs->loose) {
    free(fs->ts), free(fs->trect), free(fs->tlo), free(fs->rect), free(fs->wb), free(fs->loose);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %zu triangle setups", n);
  }
  setup_job sj = {fs, SETUP_CHUNK};
  rr_parallel_for((int)((b->nnodes + SETUP_CHUNK - 1) / SETUP_CHUNK), ctx->threads, setup_leaves, &sj);
  /* Needles leave the tree for the loose pass (in leaf order: deterministic). */
  uint32_t nl = 0;
  for (size_t i = 0; i < n; i++) nl += fs->loose[i];
  fs->loose_pos = malloc((size_t)nl * sizeof *fs->loose_pos + 1);
  fs->loose_ts = malloc((size_t)nl * sizeof *fs->loose_ts + 1);
  if (!fs->loose_pos || !fs->loose_ts) {
    setups_free(fs);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %zu triangle setups", n);
  }
  for (size_t i = 0; i < n; i++)
    if (fs->loose[i]) {
      fs->loose_pos[fs->nloose] = (uint32_t)i, fs->loose_ts[fs->nloose++] = fs->ts[i];
      fs->ts[i].id = RR_MISS;
    }
  /* Children come after their parent in the array: one backward pass. */
  for (uint32_t k = b->nnodes; k-- > 0;) {
    const bvh_node *nd = &b->nodes[k];
    if (nd->count) continue;
    uint32_t l = nd->first, r = nd->first + 1;
    fs->tlo[k] = fminf(fs->tlo[l], fs->tlo[r]);
    fs->rect[k][0] = fminf(fs->rect[l][0], fs->rect[r][0]), fs->rect[k][1] = fminf(fs->rect[l][1], fs->rect[r][1]);
    fs->rect[k][2] = fmaxf(fs->rect[l][2], fs->rect[r][2]), fs->rect[k][3] = fmaxf(fs->rect[l][3], fs->rect[r][3]);
  }
  for (uint32_t w = 0; w < b->nwide; w++)
    for (int i = 0; i < 4; i++) {
      uint32_t k = b->wide_node[4 * (size_t)w + i];
      wide_bounds *wb = &fs->wb[w];
      bool e = k == UINT32_MAX;
      wb->tlo[i] = e ? INFINITY : fs->tlo[k];
      wb->x0[i] = e ? INFINITY : fs->rect[k][0], wb->y0[i] = e ? INFINITY : fs->rect[k][1];
      wb->x1[i] = e ? -INFINITY : fs->rect[k][2], wb->y1[i] = e ? -INFINITY : fs->rect[k][3];
    }
  ctx->stats->setups += n;
  return RR_OK;
}

/* ---- primary rays: tiles of the image dealt to threads -------------------------- */

enum { TILE = 32, PK = 8, PN = PK * PK };

typedef struct {
  uint64_t evals, nodes;
  char pad[48]; /* one cache line per thread */
} thread_stats;

typedef struct {
  render_ctx *ctx;
  const rr_bvh *b;
  frame_setups fs;
  int tiles_x, band_rows;
  thread_stats st[RR_MAX_THREADS];
} frame_job;

/* ---- one ray per sample: the traversal's policy ------------------------------ */

/* A primary ray: its best hit, its sample with the evaluation vector, and for
 * curved cameras its 3D ray for the box tests. */
typedef struct {
  float t, l1, l2; /* best hit so far */
  uint32_t id;
  float sx, sy;
  vec3 w;
  ray_q q;
  const frame_setups *fs;
  uint64_t evals, nodes;
} primary_ray;

/* Planar cameras: the slots whose rectangle holds the sample and whose bound is
 * not above the best t, nearest bound first (rectangles only: no 3D test). */
KERNEL int ray_node_planar(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)lanes;
  primary_ray *r = q;
  const wide_bounds *wb = &r->fs->wb[ref];
  rr_vf4 x = rr_vf4_splat(r->sx), y = rr_vf4_splat(r->sy);
  rr_vi4 in = (wb->x0 <= x) & (x <= wb->x1) & (wb->y0 <= y) & (y <= wb->y1);
  r->nodes += wide_slots(w);
  s->order = s->key = wb->tlo;
  return rr_vi4_bits(in & (wb->tlo <= rr_vf4_splat(r->t)));
}

/* Curved cameras: the slots whose box the ray meets and whose bound is not above
 * the best t, nearest box entry first. */
KERNEL int ray_node_curved(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)lanes;
  primary_ray *r = q;
  r->nodes += wide_slots(w);
  s->key = r->fs->wb[ref].tlo;
  return wide_test(w, &r->q, 0, s->key, r->t, &s->order);
}

/* Tests the leaf's triangles, set up for the frame, at the ray's sample. */
KERNEL bool ray_leaf(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  (void)lanes;
  primary_ray *r = q;
  visbuf one = {1, 1, &r->id, &r->t, &r->l1, &r->l2};
  for (uint32_t i = first; i < first + count; i++) {
    const leaf_tri *lt = &r->fs->ts[i];
    if (lt->id == RR_MISS) continue;
    r->evals++;
    shade_sample_w(&lt->ts, lt->id, r->w, r->sx, r->sy, &one, 0);
  }
  return false;
}

KERNEL float ray_best(const void *q) { return ((const primary_ray *)q)->t; }

static void rc_bvh_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  const camera *c = j->ctx->cam;
  visbuf *vb = j->ctx->vb;
  int x0 = job % j->tiles_x * TILE, y0 = job / j->tiles_x * TILE;
  int x1 = x0 + TILE < vb->width ? x0 + TILE : vb->width, y1 = y0 + TILE < vb->height ? y0 + TILE : vb->height;
  primary_ray r = {.fs = &j->fs};
  /* 4x4 blocks in the tile: neighbouring rays run one after the other and find
   * the nodes and setups their neighbour just loaded still in cache. */
  for (int by = y0; by < y1; by += 4)
    for (int bx = x0; bx < x1; bx += 4)
      for (int k = 0; k < 16; k++) {
        int x = bx + (k & 3), y = by + (k >> 2);
        if (x >= x1 || y >= y1) continue;
        r.sx = (float)x + c->sx0, r.sy = (float)y + c->sy0;
        r.t = INFINITY, r.id = RR_MISS, r.l1 = r.l2 = 0;
        r.w = camera_w(c, x, y);
        vec3 o, d;
        uint64_t e0 = r.evals, n0 = r.nodes;
        if (c->planar) bvh_trace(j->b, &r, 1, ray_node_planar, ray_leaf, ray_best);
        else if (rr_cam_ray(c, x, y, &o, &d)) { /* else a pixel without a ray: a miss */
          ray_q_init(&r.q, o, d);
          bvh_trace(j->b, &r, 1, ray_node_curved, ray_leaf, ray_best);
        }
        size_t i = (size_t)y * vb->width + x;
        if (j->ctx->heat_e) j->ctx->heat_e[i] += (float)(r.evals - e0), j->ctx->heat_n[i] += (float)(r.nodes - n0);
        vb->id[i] = r.id, vb->t[i] = r.t, vb->l1[i] = r.l1, vb->l2[i] = r.l2;
      }
  thread_stats *st = &j->st[thread];
  st->evals += r.evals, st->nodes += r.nodes;
}

/* ---- packets of 8x8 primary rays (planar cameras): the traversal's policy ------ */

/* A packet: its samples' best hits, which lanes are samples of the image, and the
 * sample coordinates of its columns and rows (4 lanes each, two halves). */
typedef struct {
  float t[PN], l1[PN], l2[PN];
  uint32_t id[PN];
  int x0, y0;
  uint64_t valid;
  rr_vf4 sx[2], sy[2];
  float maxbest; /* the largest best t of the lanes: no lane can use a node whose bound is above */
  bool heat; /* charge E and N to the lanes (a node test is shared by its lanes) */
  float heat_e[PN], heat_n[PN];
  const frame_setups *fs;
  uint64_t evals, nodes;
} packet;

/* The lanes whose sample lies in the rectangle [x0, x1] × [y0, y1]: a run of
 * columns times a run of rows, the same comparisons as a single ray makes. */
KERNEL uint64_t rect_lanes(const packet *p, float x0, float y0, float x1, float y1) {
  rr_vf4 a0 = rr_vf4_splat(x0), a1 = rr_vf4_splat(x1), b0 = rr_vf4_splat(y0), b1 = rr_vf4_splat(y1);
  int cols = rr_vi4_bits((a0 <= p->sx[0]) & (p->sx[0] <= a1)) | rr_vi4_bits((a0 <= p->sx[1]) & (p->sx[1] <= a1)) << 4;
  int rows = rr_vi4_bits((b0 <= p->sy[0]) & (p->sy[0] <= b1)) | rr_vi4_bits((b0 <= p->sy[1]) & (p->sy[1] <= b1)) << 4;
  if (!cols || !rows) return 0;
  int r0 = __builtin_ctz(rows), r1 = 31 - __builtin_clz(rows); /* a run: the rectangle is convex */
  uint64_t rowmask = (~0ull >> (8 * (7 - r1))) & (~0ull << (8 * r0));
  return (uint64_t)cols * 0x0101010101010101ull & rowmask;
}

/* The slots whose bound is not above every lane's best t, each with the lanes
 * whose samples lie in its rectangle, nearest bound first. */
KERNEL int packet_node(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  packet *p = q;
  const wide_bounds *wb = &p->fs->wb[ref];
  int hits = 0;
  for (int i = 0; i < 4; i++) {
    s->lanes[i] = wb->tlo[i] > p->maxbest ? 0 : lanes & rect_lanes(p, wb->x0[i], wb->y0[i], wb->x1[i], wb->y1[i]);
    hits |= (s->lanes[i] != 0) << i;
  }
  s->order = s->key = wb->tlo;
  uint64_t tested = wide_slots(w);
  p->nodes += tested;
  if (p->heat) {
    float share = (float)tested / (float)__builtin_popcountll(lanes);
    for (uint64_t l = lanes; l; l &= l - 1) p->heat_n[__builtin_ctzll(l)] += share;
  }
  return hits;
}

/* Tests the lanes in each triangle's rectangle, then finds the largest best t again. */
KERNEL bool packet_leaf(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  packet *p = q;
  const frame_setups *fs = p->fs;
  visbuf pvb = {PK, PK, p->id, p->t, p->l1, p->l2};
  for (uint32_t i = first; i < first + count; i++) {
    const leaf_tri *lt = &fs->ts[i];
    if (lt->id == RR_MISS) continue;
    const float *tr = fs->trect[i];
    uint64_t in = lanes & rect_lanes(p, tr[0], tr[1], tr[2], tr[3]);
    p->evals += (uint64_t)__builtin_popcountll(in);
    for (; in; in &= in - 1) {
      int k = __builtin_ctzll(in);
      p->heat_e[k] += 1;
      float sx = (float)(p->x0 + (k & 7)) + fs->cam->sx0, sy = (float)(p->y0 + (k >> 3)) + fs->cam->sy0;
      shade_sample_w(&lt->ts, lt->id, v3(1.0f, sx, sy), sx, sy, &pvb, k);
    }
  }
  rr_vf4 m = rr_vf4_load_aligned(p->t);
  for (int g = 1; g < PN / 4; g++) m = rr_vf4_max(m, rr_vf4_load_aligned(&p->t[4 * g]));
  p->maxbest = rr_vf4_hmax(m);
  return false;
}

KERNEL float packet_best(const void *q) { return ((const packet *)q)->maxbest; }

static void rc_packet_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  visbuf *vb = j->ctx->vb;
  int tx0 = job % j->tiles_x * TILE, ty0 = job / j->tiles_x * TILE;
  packet pk = {.fs = &j->fs, .heat = j->ctx->heat_e != NULL}, *p = &pk;
  for (int py = ty0; py < ty0 + TILE && py < vb->height; py += PK)
    for (int px = tx0; px < tx0 + TILE && px < vb->width; px += PK) {
      p->x0 = px, p->y0 = py, p->valid = 0, p->maxbest = INFINITY;
      float cx[PK], cy[PK];
      for (int k = 0; k < PK; k++) cx[k] = (float)(px + k) + j->ctx->cam->sx0, cy[k] = (float)(py + k) + j->ctx->cam->sy0;
      p->sx[0] = rr_vf4_load(cx), p->sx[1] = rr_vf4_load(cx + 4);
      p->sy[0] = rr_vf4_load(cy), p->sy[1] = rr_vf4_load(cy + 4);
      for (int k = 0; k < PN; k++) {
        p->t[k] = INFINITY, p->id[k] = RR_MISS, p->l1[k] = p->l2[k] = 0, p->heat_e[k] = p->heat_n[k] = 0;
        if (px + (k & 7) < vb->width && py + (k >> 3) < vb->height) p->valid |= 1ull << k;
      }
      bvh_trace(j->b, p, p->valid, packet_node, packet_leaf, packet_best);
      for (int k = 0; k < PN; k++) {
        if (!((p->valid >> k) & 1)) continue;
        size_t i = (size_t)(py + (k >> 3)) * vb->width + px + (k & 7);
        vb->id[i] = p->id[k], vb->t[i] = p->t[k], vb->l1[i] = p->l1[k], vb->l2[i] = p->l2[k];
        if (j->ctx->heat_e) j->ctx->heat_e[i] += p->heat_e[k], j->ctx->heat_n[i] += p->heat_n[k];
      }
    }
  thread_stats *st = &j->st[thread];
  st->evals += p->evals, st->nodes += p->nodes;
}

/* The loose pass: every sample of a needle's rectangle in one band of rows, with
 * the same sample test; depth_wins() merges it with what the rays found. */
static void loose_band(int band, int thread, void *arg) {
  frame_job *j = arg;
  visbuf *vb = j->ctx->vb;
  const camera *c = j->ctx->cam;
  int y0 = band * j->band_rows, y1 = y0 + j->band_rows < vb->height ? y0 + j->band_rows : vb->height;
  uint64_t e = 0;
  for (uint32_t q = 0; q < j->fs.nloose; q++) {
    const float *r = j->fs.trect[j->fs.loose_pos[q]];
    const leaf_tri *lt = &j->fs.loose_ts[q];
    /* Samples x + sx0 in [r0, r2]: x from ceil(r0 - sx0) to floor(r2 - sx0), clipped. */
    float fx0 = fmaxf(ceilf(r[0] - c->sx0), 0), fx1 = fminf(floorf(r[2] - c->sx0), (float)(vb->width - 1));
    float fy0 = fmaxf(ceilf(r[1] - c->sy0), (float)y0), fy1 = fminf(floorf(r[3] - c->sy0), (float)(y1 - 1));
    if (!(fx0 <= fx1 && fy0 <= fy1)) continue;
    for (int y = (int)fy0; y <= (int)fy1; y++)
      for (int x = (int)fx0; x <= (int)fx1; x++) {
        float sx = (float)x + c->sx0, sy = (float)y + c->sy0;
        size_t k = (size_t)y * vb->width + x;
        shade_sample_w(&lt->ts, lt->id, v3(1.0f, sx, sy), sx, sy, vb, k);
        e++;
        if (j->ctx->heat_e) j->ctx->heat_e[k] += 1;
      }
  }
  j->st[thread].evals += e;
}

static rr_error run_frame(rr_device *dev, render_ctx *ctx, rr_parallel_fn tile_fn) {
  /* Packets work on screen rectangles: curved cameras cast one ray per sample. */
  if (tile_fn == rc_packet_tile && !ctx->cam->planar) tile_fn = rc_bvh_tile;
  bool empty;
  const rr_bvh *b = rr_bvh_of(dev, ctx->scene, &empty);
  if (empty) return RR_OK; /* the visibility buffer is already all misses */
  if (!b) return dev ? dev->error : RR_ERROR_ARGUMENT;
  frame_job *j = calloc(1, sizeof *j);
  if (!j) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory");
  j->ctx = ctx, j->b = b;
  rr_error e = setups_init(dev, &j->fs, ctx, b);
  if (e) {
    free(j);
    return e;
  }
  const visbuf *vb = ctx->vb;
  j->tiles_x = (vb->width + TILE - 1) / TILE;
  int tiles = j->tiles_x * ((vb->height + TILE - 1) / TILE);
  rr_parallel_for_progress(tiles, ctx->threads, tile_fn, j, &ctx->progress);
  if (j->fs.nloose) { /* the needles, over their rectangles, by bands of rows */
    j->band_rows = (vb->height + 4 * ctx->threads - 1) / (4 * ctx->threads);
    rr_parallel_for((vb->height + j->band_rows - 1) / j->band_rows, ctx->threads, loose_band, j);
  }
  for (int t = 0; t < RR_MAX_THREADS; t++) {
    ctx->stats->edge_evals += j->st[t].evals;
    ctx->stats->nodes += j->st[t].nodes;
  }
  setups_free(&j->fs);
  free(j);
  return RR_OK;
}

rr_error rr_vis_rc_bvh(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_bvh_tile); }

rr_error rr_vis_rc_packet(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_packet_tile); }
