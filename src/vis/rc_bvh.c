/* Ray casting through the BVH: rc-bvh (one ray per sample), rc-packet (8x8
 * packets of primary rays) and the public queries rr_intersect / rr_occluded.
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
 * rc and 3dr-bb keep such hits. Curved cameras and arbitrary rays use 3D box tests
 * widened by RAY_MARGIN relative to t (NaN slabs ignored); arbitrary rays also
 * prune by box entry, which is exact but for triangles whose plane passes within
 * rounding of the ray's origin (their hits are numerical noise in any method). */
#include "vis/vis.h"

#include <emmintrin.h>
#include <stddef.h>
#include <string.h>

#define RAY_MARGIN 0x1p-10f /* relative widening of box intervals (about 1e-3) */

/* ---- per-frame triangle setups and exact pruning bounds ------------------------ */

/* Every triangle is set up once per frame (S = triangles), in leaf order, with a
 * lower bound `tlo` of the t that sample_test() can compute for it at any sample
 * of the image; a node's tlo is the least of its triangles'. A primary ray prunes
 * a node only when the node's tlo is greater than its best t, which is exact:
 * box entry distances are not, because a triangle seen at a grazing angle can
 * compute a t well in front of its own box (measured: 2.4% at sin = 0.004 on the
 * ogre), and rc / 3dr-bb keep such hits. Box tests then only cull rays that miss. */
/* A triangle's setup with its id (RR_MISS when culled for this camera): the one
 * stream of memory a leaf reads. */
typedef struct {
  tri_setup ts;
  uint32_t id;
} leaf_tri;

/* Per wide node and slot: the screen rectangle (planar cameras) and the bound;
 * an empty slot has an empty rectangle and an infinite bound. */
typedef struct {
  float x0[4], y0[4], x1[4], y1[4], tlo[4];
} wide_bounds;

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const camera *cam;
  bool cull;
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

/* Sets up the triangles of the leaves among nodes [job·chunk, (job+1)·chunk). */
static void setup_leaves(int job, int thread, void *arg) {
  (void)thread;
  frame_setups *fs = ((setup_job *)arg)->fs;
  const rr_bvh *b = fs->b;
  uint32_t n0 = (uint32_t)job * SETUP_CHUNK, n1 = n0 + SETUP_CHUNK < b->nnodes ? n0 + SETUP_CHUNK : b->nnodes;
  for (uint32_t k = n0; k < n1; k++) {
    const bvh_node *n = &b->nodes[k];
    if (!n->count) continue;
    float tlo = INFINITY, r[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = n->first; i < n->first + n->count; i++) {
      bool live = rr_tri_setup(fs->s, b->prims[i], fs->cam, fs->cull, &fs->ts[i].ts) != SETUP_CULLED;
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
    fs->tlo[k] = tlo;
    memcpy(fs->rect[k], r, sizeof r);
  }
}

static void setups_free(frame_setups *fs) {
  free(fs->ts), free(fs->trect), free(fs->tlo), free(fs->rect), free(fs->wb), free(fs->loose);
  free(fs->loose_pos), free(fs->loose_ts);
}

static rr_error setups_init(rr_device *dev, frame_setups *fs, const render_ctx *ctx, const rr_bvh *b) {
  *fs = (frame_setups){.s = ctx->scene, .b = b, .cam = ctx->cam, .cull = ctx->opt->cull_backfaces != 0};
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


/* ---- one ray ------------------------------------------------------------------ */

/* A ray prepared for slab tests: the near plane of axis a is node float near[a]
 * (0..2: lo, 3..5: hi), the far plane far[a]. */
typedef struct {
  float o[3], inv[3];
  int nr[3], fr[3];
  __m128 vo[3], vinv[3]; /* the same, broadcast, for 4-wide tests */
  int wn[3], wf[3];      /* byte offsets of the near / far lanes in a bvh_wide */
} ray_q;

KERNEL void ray_q_init(ray_q *q, vec3 o, vec3 d) {
  float dv[3] = {d.x, d.y, d.z}, ov[3] = {o.x, o.y, o.z};
  for (int a = 0; a < 3; a++) {
    q->o[a] = ov[a];
    q->inv[a] = 1.0f / dv[a]; /* ±inf for a zero component, by its sign */
    bool neg = q->inv[a] < 0;
    q->nr[a] = neg ? 3 + a : a;
    q->fr[a] = neg ? a : 3 + a;
    q->wn[a] = (int)(neg ? offsetof(bvh_wide, hi[a]) : offsetof(bvh_wide, lo[a]));
    q->wf[a] = (int)(neg ? offsetof(bvh_wide, lo[a]) : offsetof(bvh_wide, hi[a]));
    q->vo[a] = _mm_set1_ps(ov[a]);
    q->vinv[a] = _mm_set1_ps(q->inv[a]);
  }
}

/* box_test() for the four slots of a wide node at once (same operations, same
 * order). Returns the slots whose box the ray meets with exit >= tmin and whose
 * `key` (per slot) is not above `best`; the widened entries go to tn. */
KERNEL int wide_test(const bvh_wide *w, const ray_q *q, float tmin, __m128 key, float best, __m128 *tn) {
  const char *base = (const char *)w;
  __m128 t0 = _mm_set1_ps(-INFINITY), t1 = _mm_set1_ps(INFINITY);
  for (int a = 0; a < 3; a++) {
    __m128 tnear = _mm_mul_ps(_mm_sub_ps(_mm_load_ps((const float *)(base + q->wn[a])), q->vo[a]), q->vinv[a]);
    __m128 tfar = _mm_mul_ps(_mm_sub_ps(_mm_load_ps((const float *)(base + q->wf[a])), q->vo[a]), q->vinv[a]);
    t0 = _mm_max_ps(tnear, t0); /* a NaN lane yields t0: ignored, as in box_test */
    t1 = _mm_min_ps(tfar, t1);
  }
  const __m128 margin = _mm_set1_ps(RAY_MARGIN), abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
  t0 = _mm_sub_ps(t0, _mm_mul_ps(_mm_and_ps(t0, abs_mask), margin));
  t1 = _mm_add_ps(t1, _mm_mul_ps(_mm_and_ps(t1, abs_mask), margin));
  __m128 ok = _mm_and_ps(_mm_cmple_ps(t0, t1), _mm_cmpge_ps(t1, _mm_set1_ps(tmin)));
  ok = _mm_and_ps(ok, _mm_cmple_ps(key, _mm_set1_ps(best)));
  *tn = t0;
  return _mm_movemask_ps(ok);
}

/* Primary rays of planar cameras (screen rectangles), of curved cameras (3D
 * boxes), both with the exact bounds; arbitrary rays, closest or any hit. */
enum { MODE_PLANAR, MODE_CURVED, MODE_CLOSEST, MODE_ANY };

typedef struct {
  ray_q q;
  float tmin;
  float t, l1, l2; /* best hit so far; t starts at tmax */
  uint32_t id;
  /* primary rays: the sample, its evaluation vector and the frame's setups */
  float sx, sy;
  vec3 w;
  const frame_setups *fs;
  /* arbitrary rays: the ray's pseudo-camera */
  const rr_scene *s;
  const camera *rcam;
  uint64_t setups, evals, nodes;
} ray_state;

/* Tests a leaf's triangles; true when an any-hit query is answered. */
KERNEL bool leaf_test(const rr_bvh *b, const bvh_node *n, ray_state *r, const int mode) {
  for (uint32_t i = n->first, end = n->first + n->count; i < end; i++) {
    if (mode == MODE_PLANAR || mode == MODE_CURVED) {
      const leaf_tri *lt = &r->fs->ts[i];
      if (lt->id == RR_MISS) continue;
      r->evals++;
      visbuf one = {1, 1, &r->id, &r->t, &r->l1, &r->l2};
      shade_sample_w(&lt->ts, lt->id, r->w, r->sx, r->sy, &one, 0);
    } else {
      uint32_t id = b->prims[i];
      float t, l1, l2;
      r->setups++, r->evals++;
      if (!rr_tri_ray_hit(r->s, id, r->rcam, false, r->tmin, r->t, &t, &l1, &l2)) continue;
      if (mode == MODE_ANY) return true;
      if (depth_wins(t, id, r->t, r->id)) r->t = t, r->id = id, r->l1 = l1, r->l2 = l2;
    }
  }
  return false;
}

/* Front-to-back traversal of one ray over the 4-wide tree: the slots it may
 * meet in order (planar primary rays: of their bound; others: of box entry), the
 * nearest visited and the others stacked, each dropped on pop when the best t is
 * already nearer than its key (primary rays: the exact bound, others: the box
 * entry). */
KERNEL bool trace1(const rr_bvh *b, ray_state *r, const int mode) {
  struct {
    uint32_t ref, count;
    float key;
  } stack[3 * BVH_STACK];
  int sp = 0;
  uint32_t ref = 0, count = 0; /* wide node 0 */
  for (;;) {
    if (count) {
      bvh_node leaf = {.first = ref, .count = count};
      if (leaf_test(b, &leaf, r, mode) && mode == MODE_ANY) return true;
    } else {
      const bvh_wide *w = &b->wide[ref];
      __m128 tnv, keyv;
      int hits;
      if (mode == MODE_PLANAR) {
        const wide_bounds *wb = &r->fs->wb[ref];
        __m128 x = _mm_set1_ps(r->sx), y = _mm_set1_ps(r->sy);
        keyv = _mm_load_ps(wb->tlo), tnv = keyv;
        __m128 in = _mm_and_ps(_mm_cmple_ps(_mm_load_ps(wb->x0), x), _mm_cmple_ps(x, _mm_load_ps(wb->x1)));
        in = _mm_and_ps(in, _mm_and_ps(_mm_cmple_ps(_mm_load_ps(wb->y0), y), _mm_cmple_ps(y, _mm_load_ps(wb->y1))));
        hits = _mm_movemask_ps(_mm_and_ps(in, _mm_cmple_ps(keyv, _mm_set1_ps(r->t))));
      } else if (mode == MODE_CURVED) {
        keyv = _mm_load_ps(r->fs->wb[ref].tlo);
        hits = wide_test(w, &r->q, r->tmin, keyv, r->t, &tnv);
      } else {
        hits = wide_test(w, &r->q, r->tmin, _mm_setzero_ps(), INFINITY, &tnv);
        /* the key is the entry itself */
        __m128 ok = _mm_cmple_ps(tnv, _mm_set1_ps(r->t));
        hits &= _mm_movemask_ps(ok);
        keyv = tnv;
      }
      for (int i = 0; i < 4; i++) r->nodes += w->ref[i] != UINT32_MAX;
      if (hits) {
        float tn[4], key[4];
        _mm_storeu_ps(tn, tnv), _mm_storeu_ps(key, keyv);
        int order[4], n = 0;
        for (int i = 0; i < 4; i++) {
          if (!(hits >> i & 1)) continue;
          int j = n++;
          for (; j > 0 && tn[order[j - 1]] < tn[i]; j--) order[j] = order[j - 1]; /* farthest first */
          order[j] = i;
        }
        for (int j = 0; j < n - 1; j++) {
          int i = order[j];
          stack[sp].ref = w->ref[i], stack[sp].count = w->count[i], stack[sp].key = key[i], sp++;
        }
        int i = order[n - 1];
        ref = w->ref[i], count = w->count[i];
        continue;
      }
    }
    for (;;) {
      if (!sp) return false;
      sp--;
      if (!(stack[sp].key > r->t)) break; /* equal t may still win on id */
    }
    ref = stack[sp].ref, count = stack[sp].count;
  }
}

/* ---- arbitrary rays -------------------------------------------------------------- */



static rr_error ray_begin(const rr_scene *s, const rr_ray *ray, const rr_bvh **b, bool *empty) {
  if (!s || !ray) return RR_ERROR_ARGUMENT;
  for (int a = 0; a < 3; a++)
    if (!isfinite(ray->org[a]) || !isfinite(ray->dir[a]))
      return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a non-finite origin or direction");
  if (ray->dir[0] == 0 && ray->dir[1] == 0 && ray->dir[2] == 0)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a zero direction");
  if (isnan(ray->tmin) || isnan(ray->tmax)) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a NaN range");
  *b = rr_bvh_of(s->dev, s, empty);
  return *b || *empty ? RR_OK : s->dev ? s->dev->error : RR_ERROR_ARGUMENT;
}

static void ray_state_init(ray_state *r, const rr_scene *s, const rr_ray *ray, const camera *rc) {
  memset(r, 0, sizeof *r);
  ray_q_init(&r->q, rc->eye, rc->d0);
  r->tmin = ray->tmin, r->t = ray->tmax, r->id = RR_MISS;
  r->s = s, r->rcam = rc;
}

rr_error rr_intersect(const rr_scene *s, const rr_ray *ray, rr_hit *hit) {
  if (!hit) return s ? rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_intersect: hit is NULL") : RR_ERROR_ARGUMENT;
  *hit = rr_scene_hit(s, RR_MISS, INFINITY, 0, 0);
  const rr_bvh *b = NULL;
  bool empty = false;
  rr_error e = ray_begin(s, ray, &b, &empty);
  if (e || empty) return e;
  camera rc;
  rr_cam_for_ray(ray->org, ray->dir, &rc);
  ray_state r;
  ray_state_init(&r, s, ray, &rc);
  trace1(b, &r, MODE_CLOSEST);
  if (r.id != RR_MISS) *hit = rr_scene_hit(s, r.id, r.t, r.l1, r.l2);
  return RR_OK;
}

rr_error rr_occluded(const rr_scene *s, const rr_ray *ray, int *occluded) {
  if (!occluded) return s ? rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_occluded: result is NULL") : RR_ERROR_ARGUMENT;
  *occluded = 0;
  const rr_bvh *b = NULL;
  bool empty = false;
  rr_error e = ray_begin(s, ray, &b, &empty);
  if (e || empty) return e;
  camera rc;
  rr_cam_for_ray(ray->org, ray->dir, &rc);
  ray_state r;
  ray_state_init(&r, s, ray, &rc);
  *occluded = trace1(b, &r, MODE_ANY);
  return RR_OK;
}

/* ---- primary rays: tiles of the image dealt to threads ---------------------------- */

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
  thread_stats st[256];
} frame_job;

static void rc_bvh_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  const camera *c = j->ctx->cam;
  visbuf *vb = j->ctx->vb;
  int x0 = job % j->tiles_x * TILE, y0 = job / j->tiles_x * TILE;
  int x1 = x0 + TILE < vb->width ? x0 + TILE : vb->width, y1 = y0 + TILE < vb->height ? y0 + TILE : vb->height;
  ray_state r;
  memset(&r, 0, sizeof r);
  r.fs = &j->fs;
  /* 4x4 blocks in the tile: neighbouring rays run one after the other and find
   * the nodes and setups their neighbour just loaded still in cache. */
  for (int by = y0; by < y1; by += 4)
    for (int bx = x0; bx < x1; bx += 4)
      for (int k = 0; k < 16; k++) {
      int x = bx + (k & 3), y = by + (k >> 2);
      if (x >= x1 || y >= y1) continue;
      r.sx = (float)x + c->sx0, r.sy = (float)y + c->sy0;
      r.t = INFINITY, r.id = RR_MISS, r.l1 = r.l2 = 0;
      r.w = camera_w(c, x, y), r.tmin = 0;
          vec3 o, d;
      uint64_t e0 = r.evals, n0 = r.nodes;
      if (c->planar) trace1(j->b, &r, MODE_PLANAR); /* rectangles only: no 3D test */
      else if (rr_cam_ray(c, x, y, &o, &d)) { /* else a pixel without a ray: a miss */
        ray_q_init(&r.q, o, d);
        trace1(j->b, &r, MODE_CURVED);
      }
      size_t i = (size_t)y * vb->width + x;
      if (j->ctx->heat_e) j->ctx->heat_e[i] += (float)(r.evals - e0), j->ctx->heat_n[i] += (float)(r.nodes - n0);
      vb->id[i] = r.id, vb->t[i] = r.t, vb->l1[i] = r.l1, vb->l2[i] = r.l2;
    }
  thread_stats *st = &j->st[thread];
  st->evals += r.evals, st->nodes += r.nodes;
}

/* ---- packets of 8x8 primary rays (planar cameras) ---------------------------- */

/* A packet: its samples' best hits, which lanes are samples of the image, and the
 * sample coordinates of its columns and rows (4 lanes each, two halves). */
typedef struct {
  float t[PN], l1[PN], l2[PN];
  uint32_t id[PN];
  int x0, y0;
  uint64_t valid;
  __m128 sx[2], sy[2];
  float heat_e[PN], heat_n[PN]; /* E and N charged to each lane (a node test is shared by its lanes) */
} packet;

/* The lanes whose sample lies in the rectangle [x0, x1] × [y0, y1]: a run of
 * columns times a run of rows, the same comparisons as a single ray makes. */
KERNEL uint64_t rect_lanes(const packet *p, float x0, float y0, float x1, float y1) {
  __m128 a0 = _mm_set1_ps(x0), a1 = _mm_set1_ps(x1), b0 = _mm_set1_ps(y0), b1 = _mm_set1_ps(y1);
  int cols = _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(a0, p->sx[0]), _mm_cmple_ps(p->sx[0], a1))) |
             _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(a0, p->sx[1]), _mm_cmple_ps(p->sx[1], a1))) << 4;
  int rows = _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(b0, p->sy[0]), _mm_cmple_ps(p->sy[0], b1))) |
             _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(b0, p->sy[1]), _mm_cmple_ps(p->sy[1], b1))) << 4;
  if (!cols || !rows) return 0;
  int r0 = __builtin_ctz(rows), r1 = 31 - __builtin_clz(rows); /* a run: the rectangle is convex */
  uint64_t rowmask = (~0ull >> (8 * (7 - r1))) & (~0ull << (8 * r0));
  return (uint64_t)cols * 0x0101010101010101ull & rowmask;
}

/* The largest best t of the packet: no lane can use a node whose bound is above. */
KERNEL float packet_max_t(const packet *p) {
  __m128 m = _mm_load_ps(p->t);
  for (int g = 1; g < PN / 4; g++) m = _mm_max_ps(m, _mm_load_ps(&p->t[4 * g]));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}

KERNEL void packet_leaf(const frame_setups *fs, packet *p, uint32_t first, uint32_t count, uint64_t mask,
                        ray_state *acc) {
  visbuf pvb = {PK, PK, p->id, p->t, p->l1, p->l2};
  for (uint32_t i = first; i < first + count; i++) {
    const leaf_tri *lt = &fs->ts[i];
    if (lt->id == RR_MISS) continue;
    const float *tr = fs->trect[i];
    uint64_t lanes = mask & rect_lanes(p, tr[0], tr[1], tr[2], tr[3]);
    acc->evals += (uint64_t)__builtin_popcountll(lanes);
    for (; lanes; lanes &= lanes - 1) {
      int k = __builtin_ctzll(lanes);
      p->heat_e[k] += 1;
      float sx = (float)(p->x0 + (k & 7)) + fs->cam->sx0, sy = (float)(p->y0 + (k >> 3)) + fs->cam->sy0;
      shade_sample_w(&lt->ts, lt->id, v3(1.0f, sx, sy), sx, sy, &pvb, k);
    }
  }
}

/* The packet through the 4-wide tree: a slot is entered with the lanes whose
 * samples lie in its rectangle, nearest bound first; a slot or stacked entry is
 * dropped when its bound is above every lane's best t. */
static void packet_trace(frame_job *j, packet *p, ray_state *acc) {
  const rr_bvh *b = j->b;
  const frame_setups *fs = &j->fs;
  struct {
    uint32_t ref, count;
    uint64_t mask;
    float key;
  } stack[3 * BVH_STACK];
  int sp = 0;
  uint32_t ref = 0, count = 0;
  uint64_t mask = p->valid;
  float maxbest = INFINITY;
  for (;;) {
    if (count) {
      packet_leaf(fs, p, ref, count, mask, acc);
      maxbest = packet_max_t(p);
    } else {
      const bvh_wide *w = &b->wide[ref];
      const wide_bounds *wb = &fs->wb[ref];
      uint64_t m[4];
      int order[4], n = 0, tested = 0;
      for (int i = 0; i < 4; i++) {
        tested += w->ref[i] != UINT32_MAX;
        if (wb->tlo[i] > maxbest) continue;
        m[i] = mask & rect_lanes(p, wb->x0[i], wb->y0[i], wb->x1[i], wb->y1[i]);
        if (!m[i]) continue;
        int q = n++;
        for (; q > 0 && wb->tlo[order[q - 1]] < wb->tlo[i]; q--) order[q] = order[q - 1]; /* farthest first */
        order[q] = i;
      }
      acc->nodes += (uint64_t)tested;
      float share = (float)tested / (float)__builtin_popcountll(mask);
      for (uint64_t l = mask; l; l &= l - 1) p->heat_n[__builtin_ctzll(l)] += share;
      if (n) {
        for (int q = 0; q < n - 1; q++) {
          int i = order[q];
          stack[sp].ref = w->ref[i], stack[sp].count = w->count[i], stack[sp].mask = m[i], stack[sp].key = wb->tlo[i];
          sp++;
        }
        int i = order[n - 1];
        ref = w->ref[i], count = w->count[i], mask = m[i];
        continue;
      }
    }
    for (;;) {
      if (!sp) return;
      sp--;
      if (!(stack[sp].key > maxbest)) break; /* equal t may still win on id */
    }
    ref = stack[sp].ref, count = stack[sp].count, mask = stack[sp].mask;
  }
}

static void rc_packet_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  visbuf *vb = j->ctx->vb;
  int tx0 = job % j->tiles_x * TILE, ty0 = job / j->tiles_x * TILE;
  ray_state acc;
  memset(&acc, 0, sizeof acc);
  packet pk, *p = &pk;
  for (int py = ty0; py < ty0 + TILE && py < vb->height; py += PK)
    for (int px = tx0; px < tx0 + TILE && px < vb->width; px += PK) {
      p->x0 = px, p->y0 = py, p->valid = 0;
      float cx[PK], cy[PK];
      for (int k = 0; k < PK; k++) cx[k] = (float)(px + k) + j->ctx->cam->sx0, cy[k] = (float)(py + k) + j->ctx->cam->sy0;
      p->sx[0] = _mm_loadu_ps(cx), p->sx[1] = _mm_loadu_ps(cx + 4);
      p->sy[0] = _mm_loadu_ps(cy), p->sy[1] = _mm_loadu_ps(cy + 4);
      for (int k = 0; k < PN; k++) {
        p->t[k] = INFINITY, p->id[k] = RR_MISS, p->l1[k] = p->l2[k] = 0, p->heat_e[k] = p->heat_n[k] = 0;
        if (px + (k & 7) < vb->width && py + (k >> 3) < vb->height) p->valid |= 1ull << k;
      }
      packet_trace(j, p, &acc);
      for (int k = 0; k < PN; k++) {
        if (!((p->valid >> k) & 1)) continue;
        size_t i = (size_t)(py + (k >> 3)) * vb->width + px + (k & 7);
        vb->id[i] = p->id[k], vb->t[i] = p->t[k], vb->l1[i] = p->l1[k], vb->l2[i] = p->l2[k];
        if (j->ctx->heat_e) j->ctx->heat_e[i] += p->heat_e[k], j->ctx->heat_n[i] += p->heat_n[k];
      }
    }
  thread_stats *st = &j->st[thread];
  st->evals += acc.evals, st->nodes += acc.nodes;
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
  rr_parallel_for(tiles, ctx->threads, tile_fn, j);
  if (j->fs.nloose) { /* the needles, over their rectangles, by bands of rows */
    j->band_rows = (vb->height + 4 * ctx->threads - 1) / (4 * ctx->threads);
    rr_parallel_for((vb->height + j->band_rows - 1) / j->band_rows, ctx->threads, loose_band, j);
  }
  for (int t = 0; t < 256; t++) {
    ctx->stats->edge_evals += j->st[t].evals;
    ctx->stats->nodes += j->st[t].nodes;
  }
  setups_free(&j->fs);
  free(j);
  return RR_OK;
}

rr_error rr_vis_rc_bvh(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_bvh_tile); }

rr_error rr_vis_rc_packet(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_packet_tile); }
