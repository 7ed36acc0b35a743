/* Ray casting through the BVH: rc-bvh (one ray per sample), rc-packet (8x8
 * packets of primary rays) and the public queries rr_intersect / rr_occluded.
 *
 * Leaves run the project's one sample test, so these methods produce the same
 * bits as rc and 3dr-bb: a primary ray tests a triangle with tri_setup_planar()
 * for the camera (computed once per frame, on first use, and kept in leaf order)
 * and shade_sample() at its sample (x + 0.5, y + 0.5). Traversal only decides
 * which (sample, triangle) pairs are visited, so it must never skip the winner:
 * - box tests are conservative: the slab interval is widened by RAY_MARGIN
 *   relative to t on both ends, and a slab the ray runs inside of exactly
 *   (0 · inf = NaN) is ignored rather than taken as a miss;
 * - a box is pruned only when its widened entry t is strictly greater than the
 *   best t found, because an equal t with a lower id still wins (depth_wins).
 * The margin covers the rounding of the box test and the difference between a
 * triangle's computed t (V / ΣV_i, with rounding) and the exact entry distance of
 * its box; a triangle whose plane passes within rounding of the eye can compute a
 * t arbitrarily far from its box (its samples are numerical noise in every
 * method) and is the one case the margin does not bound. */
#include "rr.h"

#include <emmintrin.h>
#include <stddef.h>
#include <string.h>

#define RAY_MARGIN 0x1p-10f /* relative widening of box intervals (about 1e-3) */
/* The kernels take constant mode flags: forcing them inline specialises each use. */
#define KERNEL static inline __attribute__((always_inline))

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

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const camera *cam;
  bool cull;
  leaf_tri *ts;   /* by position in b->prims */
  float *tlo;     /* by node */
  float *tlo4;    /* by wide node and slot (+inf for an empty slot) */
} frame_setups;

/* The least t that sample_test() can return for ts at any sample of camera c.
 *
 * Planar cameras evaluate e_i = a + sx·b + sy·c in float, with an error below
 * u_i = 4u·(|a| + |sx·b| + |sy·c|) (u = 2^-24, bounded over the image); a passing
 * sample has every computed e_i >= 0, so it lies in P = {E_i >= -u_i} for the
 * exact edge functions E_i of the setup values, and the computed sum is at most
 * (1+u)^2 Σ(E_i + u_i). That sum is affine, so its maximum over P is at a vertex
 * of P; at the vertex where E_i + u_i and E_j + u_j vanish it equals
 * det[a' b c] / (b_i·c_j - b_j·c_i) (Cramer; a' = a + u), and P is that bounded
 * triangle when the three values are positive; otherwise the maximum over the
 * image rectangle bounds it. Curved cameras evaluate e_i = n_i·d with |d| at most
 * the camera's longest ray, so the sum is at most |Σn_i|·|d| plus the error. The
 * volume (constant but for orthographic views) is bounded below over the image
 * the same way, and t = vol·(1/sum) is at least vol·(1-u)^2 / max sum. Double
 * arithmetic carries a relative slack far above its own rounding. */
float tri_t_lower_bound(const tri_setup *ts, const camera *cam) {
  const double u = 0x1p-24, slack = 1e-12;
  int w = cam->width, h = cam->height;
  double smax = -INFINITY;
  if (cam->planar) {
    double a[3], b[3], c[3];
    for (int i = 0; i < 3; i++) {
      b[i] = ts->b[i], c[i] = ts->c[i];
      a[i] = ts->a[i] + 4 * u * (fabs(ts->a[i]) + w * fabs(b[i]) + h * fabs(c[i]));
    }
    double m[3], mag_m[3];
    for (int k = 0; k < 3; k++) {
      int i = (k + 1) % 3, j = (k + 2) % 3;
      m[k] = b[i] * c[j] - b[j] * c[i], mag_m[k] = fabs(b[i] * c[j]) + fabs(b[j] * c[i]);
    }
    double det = a[0] * m[0] + a[1] * m[1] + a[2] * m[2];
    double mag_d = fabs(a[0]) * mag_m[0] + fabs(a[1]) * mag_m[1] + fabs(a[2]) * mag_m[2];
    /* Bounded when det and the three minors share a sign (either: it depends on
     * how the triangle's projection turns on screen), each clear of the slack. */
    double sg = det < 0 ? -1 : 1;
    bool bounded = sg * det > slack * mag_d;
    for (int k = 0; k < 3 && bounded; k++) {
      bounded = sg * m[k] > slack * mag_m[k];
      if (bounded) {
        double v = (sg * det + slack * mag_d) / (sg * m[k] - slack * mag_m[k]);
        smax = v > smax ? v : smax;
      }
    }
    if (!bounded) {
      double A = a[0] + a[1] + a[2], B = b[0] + b[1] + b[2], C = c[0] + c[1] + c[2];
      smax = A + fmax(0.5 * B, (w - 0.5) * B) + fmax(0.5 * C, (h - 0.5) * C);
      smax += slack * (fabs(A) + w * fabs(B) + h * fabs(C));
    }
  } else {
    double dmax = (double)cam->dir_len_max * (1 + 1e-6), nx = 0, ny = 0, nz = 0, err = 0;
    for (int i = 0; i < 3; i++) {
      nx += ts->a[i], ny += ts->b[i], nz += ts->c[i];
      err += 4 * u * (fabs(ts->a[i]) + fabs(ts->b[i]) + fabs(ts->c[i]));
    }
    smax = (sqrt(nx * nx + ny * ny + nz * nz) + err) * dmax * (1 + slack);
  }
  if (!(smax > 0)) return INFINITY; /* no sample can pass */
  double vmin = ts->vol; /* exact when vol_x = vol_y = 0: vol + 0 + 0 */
  if (ts->vol_x != 0 || ts->vol_y != 0) {
    double v0 = ts->vol, vx = ts->vol_x, vy = ts->vol_y;
    vmin = v0 + fmin(0.5 * vx, (w - 0.5) * vx) + fmin(0.5 * vy, (h - 0.5) * vy);
    vmin -= 4 * u * (fabs(v0) + w * fabs(vx) + h * fabs(vy)) + slack * fabs(v0);
  }
  if (!(vmin > 0)) return 0;
  double t = vmin * (1 - u) * (1 - u) / (smax * (1 + u) * (1 + u)) * (1 - 1e-9);
  float f = (float)t;
  return (double)f > t ? nextafterf(f, 0) : f;
}

typedef struct {
  frame_setups *fs;
  int chunk;
} setup_job;

enum { SETUP_CHUNK = 4096 };

/* Sets up the triangles of the leaves among nodes [job·chunk, (job+1)·chunk). */
static void setup_leaves(int job, int thread, void *arg) {
  (void)thread;
  frame_setups *fs = ((setup_job *)arg)->fs;
  const rr_bvh *b = fs->b;
  uint32_t n0 = (uint32_t)job * SETUP_CHUNK, n1 = n0 + SETUP_CHUNK < b->nnodes ? n0 + SETUP_CHUNK : b->nnodes;
  for (uint32_t k = n0; k < n1; k++) {
    const bvh_node *n = &b->nodes[k];
    if (!n->count) continue;
    float tlo = INFINITY;
    for (uint32_t i = n->first; i < n->first + n->count; i++) {
      bool live = tri_setup_planar(fs->s, b->prims[i], fs->cam, fs->cull, &fs->ts[i].ts) != SETUP_CULLED;
      fs->ts[i].id = live ? b->prims[i] : RR_MISS;
      if (!live) continue;
      float t = tri_t_lower_bound(&fs->ts[i].ts, fs->cam);
      tlo = t < tlo ? t : tlo;
    }
    fs->tlo[k] = tlo;
  }
}

static rr_error setups_init(rr_device *dev, frame_setups *fs, const render_ctx *ctx, const rr_bvh *b) {
  *fs = (frame_setups){.s = ctx->scene, .b = b, .cam = ctx->cam, .cull = ctx->opt->cull_backfaces != 0};
  size_t n = b->nprims;
  fs->ts = malloc(n * sizeof *fs->ts + 1);
  fs->tlo = malloc((size_t)b->nnodes * sizeof *fs->tlo + 1);
  fs->tlo4 = aligned_alloc(16, (size_t)b->nwide * 4 * sizeof *fs->tlo4);
  if (!fs->ts || !fs->tlo || !fs->tlo4) {
    free(fs->ts), free(fs->tlo), free(fs->tlo4);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %zu triangle setups", n);
  }
  setup_job sj = {fs, SETUP_CHUNK};
  parallel_for((int)((b->nnodes + SETUP_CHUNK - 1) / SETUP_CHUNK), ctx->threads, setup_leaves, &sj);
  /* Children come after their parent in the array: one backward pass. */
  for (uint32_t k = b->nnodes; k-- > 0;) {
    const bvh_node *nd = &b->nodes[k];
    if (nd->count) continue;
    float l = fs->tlo[nd->first], r = fs->tlo[nd->first + 1];
    fs->tlo[k] = l < r ? l : r;
  }
  for (size_t k = 0; k < 4 * (size_t)b->nwide; k++)
    fs->tlo4[k] = b->wide_node[k] == UINT32_MAX ? INFINITY : fs->tlo[b->wide_node[k]];
  ctx->stats->setups += n;
  return RR_OK;
}

static void setups_free(frame_setups *fs) { free(fs->ts), free(fs->tlo), free(fs->tlo4); }

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

enum { MODE_PRIMARY, MODE_CLOSEST, MODE_ANY };

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
    if (mode == MODE_PRIMARY) {
      const leaf_tri *lt = &r->fs->ts[i];
      if (lt->id == RR_MISS) continue;
      r->evals++;
      visbuf one = {1, 1, &r->id, &r->t, &r->l1, &r->l2};
      shade_sample_w(&lt->ts, lt->id, r->w, r->sx, r->sy, &one, 0);
    } else {
      uint32_t id = b->prims[i];
      float t, l1, l2;
      r->setups++, r->evals++;
      if (!ray_tri_hit(r->s, id, r->rcam, false, r->tmin, r->t, &t, &l1, &l2)) continue;
      if (mode == MODE_ANY) return true;
      if (depth_wins(t, id, r->t, r->id)) r->t = t, r->id = id, r->l1 = l1, r->l2 = l2;
    }
  }
  return false;
}

/* Front-to-back traversal of one ray over the 4-wide tree: the hit slots in
 * order of entry, the nearest visited and the others stacked, each dropped on pop
 * when the best t is already nearer than its key (primary rays: the node's exact
 * bound, other rays: the box entry). */
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
      if (mode == MODE_PRIMARY) {
        keyv = _mm_load_ps(&r->fs->tlo4[4 * (size_t)ref]);
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

void ray_camera(const float org[3], const float dir[3], camera *out) {
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

bool ray_tri_hit(const rr_scene *s, uint32_t i, const camera *ray, bool cull, float tmin, float tmax, float *t,
                 float *l1, float *l2) {
  tri_setup ts;
  if (tri_setup_planar(s, i, ray, cull, &ts) == SETUP_CULLED) return false;
  float e[3];
  tri_edges(&ts, 0.0f, 0.0f, e); /* = a[i]: the edge functions along the ray itself */
  if (!sample_test(e, ts.tie, ts.vol, t, l1, l2)) return false;
  return *t >= tmin && *t <= tmax;
}

static rr_error ray_begin(const rr_scene *s, const rr_ray *ray, const rr_bvh **b, bool *empty) {
  if (!s || !ray) return RR_ERROR_ARGUMENT;
  for (int a = 0; a < 3; a++)
    if (!isfinite(ray->org[a]) || !isfinite(ray->dir[a]))
      return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a non-finite origin or direction");
  if (ray->dir[0] == 0 && ray->dir[1] == 0 && ray->dir[2] == 0)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a zero direction");
  if (isnan(ray->tmin) || isnan(ray->tmax)) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "ray with a NaN range");
  *b = bvh_of(s->dev, s, empty);
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
  *hit = (rr_hit){RR_MISS, INFINITY, 0, 0};
  const rr_bvh *b = NULL;
  bool empty = false;
  rr_error e = ray_begin(s, ray, &b, &empty);
  if (e || empty) return e;
  camera rc;
  ray_camera(ray->org, ray->dir, &rc);
  ray_state r;
  ray_state_init(&r, s, ray, &rc);
  trace1(b, &r, MODE_CLOSEST);
  if (r.id != RR_MISS) *hit = (rr_hit){r.id, r.t, r.l1, r.l2};
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
  ray_camera(ray->org, ray->dir, &rc);
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
  int tiles_x;
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
      r.sx = (float)x + 0.5f, r.sy = (float)y + 0.5f;
      r.t = INFINITY, r.id = RR_MISS, r.l1 = r.l2 = 0;
      vec3 o, d;
      if (camera_ray(c, x, y, &o, &d)) { /* else a pixel without a ray: a miss */
        ray_q_init(&r.q, o, d);
        r.w = camera_w(c, x, y), r.tmin = 0;
        trace1(j->b, &r, MODE_PRIMARY);
      }
      size_t i = (size_t)y * vb->width + x;
      vb->id[i] = r.id, vb->t[i] = r.t, vb->l1[i] = r.l1, vb->l2[i] = r.l2;
    }
  thread_stats *st = &j->st[thread];
  st->evals += r.evals, st->nodes += r.nodes;
}

/* ---- packets of 8x8 primary rays ---------------------------------------------- */

/* A packet: the rays' inverse directions and near-plane masks (lanes of 4), their
 * best hits, and which lanes are samples of the image. `uniform` when every ray
 * has the same direction signs, so near and far planes are the same for all. */
typedef struct {
  __m128 inv[3][PN / 4], neg[3][PN / 4];
  float o[3];
  bool uniform;
  int nr[3], fr[3]; /* near / far plane of each axis when uniform */
  float t[PN], l1[PN], l2[PN];
  uint32_t id[PN];
  int x0, y0;
  uint64_t valid;
} packet;

static inline __m128 select_ps(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }

/* The lanes of `mask` whose rays meet the box and whose best t is not below the
 * node's bound tlo; *tnear is the smallest widened entry t among them. The same
 * arithmetic as box_test. */
KERNEL uint64_t packet_box(const packet *p, const bvh_node *n, float tlo, uint64_t mask, float *tnear,
                                  const bool uniform) {
  const float *f = (const float *)n;
  const __m128 margin = _mm_set1_ps(RAY_MARGIN), abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
  __m128 lo[3], hi[3];
  for (int a = 0; a < 3; a++) {
    if (uniform) {
      lo[a] = _mm_set1_ps(f[p->nr[a]] - p->o[a]);
      hi[a] = _mm_set1_ps(f[p->fr[a]] - p->o[a]);
    } else {
      lo[a] = _mm_set1_ps(f[a] - p->o[a]);
      hi[a] = _mm_set1_ps(f[3 + a] - p->o[a]);
    }
  }
  __m128 tmin_all = _mm_set1_ps(INFINITY);
  uint64_t hit = 0;
  for (int g = 0; g < PN / 4; g++) {
    if (!((mask >> (4 * g)) & 15)) continue;
    __m128 t0 = _mm_set1_ps(-INFINITY), t1 = _mm_set1_ps(INFINITY);
    for (int a = 0; a < 3; a++) {
      __m128 ta = _mm_mul_ps(lo[a], p->inv[a][g]), tb = _mm_mul_ps(hi[a], p->inv[a][g]);
      __m128 tn = uniform ? ta : select_ps(p->neg[a][g], tb, ta);
      __m128 tf = uniform ? tb : select_ps(p->neg[a][g], ta, tb);
      t0 = _mm_max_ps(tn, t0); /* a NaN tn yields t0: ignored */
      t1 = _mm_min_ps(tf, t1);
    }
    t0 = _mm_sub_ps(t0, _mm_mul_ps(_mm_and_ps(t0, abs_mask), margin));
    t1 = _mm_add_ps(t1, _mm_mul_ps(_mm_and_ps(t1, abs_mask), margin));
    __m128 best = _mm_loadu_ps(&p->t[4 * g]);
    __m128 ok = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(t0, t1), _mm_cmple_ps(_mm_set1_ps(tlo), best)),
                           _mm_cmpge_ps(t1, _mm_setzero_ps()));
    uint64_t bits = (uint64_t)_mm_movemask_ps(ok) & ((mask >> (4 * g)) & 15);
    if (!bits) continue;
    hit |= bits << (4 * g);
    __m128 lane_on = _mm_castsi128_ps(
        _mm_set_epi32(-(int)((bits >> 3) & 1), -(int)((bits >> 2) & 1), -(int)((bits >> 1) & 1), -(int)(bits & 1)));
    tmin_all = _mm_min_ps(tmin_all, select_ps(lane_on, t0, _mm_set1_ps(INFINITY)));
  }
  float tm[4];
  _mm_storeu_ps(tm, tmin_all);
  *tnear = fminf(fminf(tm[0], tm[1]), fminf(tm[2], tm[3]));
  return hit;
}

KERNEL void packet_leaf(frame_job *j, packet *p, const bvh_node *n, uint64_t mask, ray_state *acc) {
  visbuf pvb = {PK, PK, p->id, p->t, p->l1, p->l2};
  int cnt = __builtin_popcountll(mask);
  for (uint32_t i = n->first, end = n->first + n->count; i < end; i++) {
    if (j->fs.ts[i].id == RR_MISS) continue;
    const tri_setup *ts = &j->fs.ts[i].ts;
    uint32_t id = j->fs.ts[i].id;
    acc->evals += cnt;
    for (uint64_t m = mask; m; m &= m - 1) {
      int k = __builtin_ctzll(m);
      int x = p->x0 + (k & 7), y = p->y0 + (k >> 3);
      shade_sample_w(ts, id, camera_w(j->ctx->cam, x, y), (float)x + 0.5f, (float)y + 0.5f, &pvb, k);
    }
  }
}

KERNEL void packet_trace(frame_job *j, packet *p, ray_state *acc, const bool uniform) {
  const bvh_node *nodes = j->b->nodes;
  struct {
    uint32_t node;
    uint64_t mask;
  } stack[BVH_STACK];
  int sp = 0;
  float tn0, tn1;
  acc->nodes++;
  const float *tlo = j->fs.tlo;
  uint64_t mask = packet_box(p, &nodes[0], tlo[0], p->valid, &tn0, uniform);
  uint32_t cur = 0;
  while (mask) {
    const bvh_node *n = &nodes[cur];
    if (n->count) {
      packet_leaf(j, p, n, mask, acc);
    } else {
      const bvh_node *c = &nodes[n->first];
      uint64_t m0 = packet_box(p, &c[0], tlo[n->first], mask, &tn0, uniform);
      uint64_t m1 = packet_box(p, &c[1], tlo[n->first + 1], mask, &tn1, uniform);
      acc->nodes += 2;
      if (m0 && m1) {
        bool swap = tn1 < tn0;
        stack[sp].node = n->first + !swap, stack[sp].mask = swap ? m0 : m1, sp++;
        cur = n->first + swap, mask = swap ? m1 : m0;
        continue;
      }
      if (m0 | m1) {
        cur = n->first + (m0 ? 0 : 1), mask = m0 | m1;
        continue;
      }
    }
    /* Pop, narrowing the stacked lanes to those whose best t still allows the box. */
    mask = 0;
    while (sp && !mask) {
      sp--;
      cur = stack[sp].node;
      acc->nodes++;
      mask = packet_box(p, &nodes[cur], tlo[cur], stack[sp].mask, &tn0, uniform);
    }
  }
}

static void rc_packet_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  const camera *c = j->ctx->cam;
  visbuf *vb = j->ctx->vb;
  int tx0 = job % j->tiles_x * TILE, ty0 = job / j->tiles_x * TILE;
  ray_state acc;
  memset(&acc, 0, sizeof acc);
  packet pk, *p = &pk;
  for (int py = ty0; py < ty0 + TILE && py < vb->height; py += PK)
    for (int px = tx0; px < tx0 + TILE && px < vb->width; px += PK) {
      p->x0 = px, p->y0 = py, p->valid = 0;
      p->o[0] = c->eye.x, p->o[1] = c->eye.y, p->o[2] = c->eye.z;
      int negs[3] = {0, 0, 0};
      float inv[3][PN], neg[3][PN];
      for (int k = 0; k < PN; k++) {
        int x = px + (k & 7), y = py + (k >> 3);
        p->t[k] = INFINITY, p->id[k] = RR_MISS, p->l1[k] = p->l2[k] = 0;
        vec3 o, d = v3(1, 1, 1);
        bool in = x < vb->width && y < vb->height && camera_ray(c, x, y, &o, &d);
        float dv[3] = {d.x, d.y, d.z};
        if (in) p->valid |= 1ull << k;
        for (int a = 0; a < 3; a++) {
          inv[a][k] = 1.0f / dv[a];
          bool ng = inv[a][k] < 0;
          uint32_t m = ng ? 0xFFFFFFFFu : 0;
          memcpy(&neg[a][k], &m, 4);
          negs[a] += in && ng;
        }
      }
      int nvalid = __builtin_popcountll(p->valid);
      p->uniform = true;
      for (int a = 0; a < 3; a++) {
        bool all_neg = negs[a] == nvalid, none = negs[a] == 0;
        p->uniform = p->uniform && (all_neg || none);
        p->nr[a] = all_neg ? 3 + a : a, p->fr[a] = all_neg ? a : 3 + a;
        for (int g = 0; g < PN / 4; g++) {
          p->inv[a][g] = _mm_loadu_ps(&inv[a][4 * g]);
          p->neg[a][g] = _mm_loadu_ps(&neg[a][4 * g]);
        }
      }
      if (p->uniform) packet_trace(j, p, &acc, true);
      else packet_trace(j, p, &acc, false);
      for (int k = 0; k < PN; k++) {
        if (!((p->valid >> k) & 1)) continue;
        size_t i = (size_t)(py + (k >> 3)) * vb->width + px + (k & 7);
        vb->id[i] = p->id[k], vb->t[i] = p->t[k], vb->l1[i] = p->l1[k], vb->l2[i] = p->l2[k];
      }
    }
  thread_stats *st = &j->st[thread];
  st->evals += acc.evals, st->nodes += acc.nodes;
}

static rr_error run_frame(rr_device *dev, render_ctx *ctx, parallel_fn tile_fn) {
  /* Packets share the eye as origin; orthographic rays do not: one ray each. */
  if (tile_fn == rc_packet_tile && ctx->cam->type == RR_CAMERA_ORTHOGRAPHIC) tile_fn = rc_bvh_tile;
  bool empty;
  const rr_bvh *b = bvh_of(dev, ctx->scene, &empty);
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
  parallel_for(tiles, ctx->threads, tile_fn, j);
  for (int t = 0; t < 256; t++) {
    ctx->stats->edge_evals += j->st[t].evals;
    ctx->stats->nodes += j->st[t].nodes;
  }
  setups_free(&j->fs);
  free(j);
  return RR_OK;
}

rr_error vis_rc_bvh(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_bvh_tile); }

rr_error vis_rc_packet(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_packet_tile); }
