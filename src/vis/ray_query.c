/* The public ray queries rr_intersect and rr_occluded: one arbitrary ray through
 * the committed scene's BVH, collapsed to eight children a node for them
 * (rr_bvh.wide8, traversed by vis/ray_query_tmp.h; the binary tree's leaves and
 * boxes, so the same triangles are reached as through any other form). A leaf's triangles, whose corners the tree keeps in leaf
 * order (rr_bvh.leaf_v8), go four at a time through the edge signs of their setup
 * (tri_ray_may_hit4); those that pass are tested with the project's one sample
 * test for the ray (a pseudo-camera at its origin, rr_cam_for_ray), so a ray
 * through a shared edge hits exactly one triangle: with the pre-test's edge values
 * where all are positive (rr_tri_ray_finish), else with the part of the setup the
 * ray's one sample reads (rr_tri_ray_hit1), or, for corners at infinity, the full
 * setup (rr_tri_ray_hit) — the same bits each way.
 *
 * Boxes are tested in 3D, widened by RAY_MARGIN relative to t (NaN slabs
 * ignored), and prune by box entry, which is exact but for triangles whose plane
 * passes within rounding of the ray's origin or direction: a ray's t is num / den
 * (TRI_DEPTH) with num and den each one rounding of a double (den = pa at sample
 * (0, 0), cx = cy = 0), within 2 ulps of the exact hit, far inside the margin,
 * unless num or den rounds to zero or below (the fallback V / Σ w_i V_i).
 *
 * Thread safety: a query reads the scene and its BVH, keeps its state on its own
 * stack and writes only the caller's results and the caller's device (NULL: none),
 * so any number of threads may trace rays through one committed scene. A stream
 * (rr_intersect_stream, rr_occluded_stream) traces each ray the same way. */
#include "vis/bvh_trace.h"
#include "vis/ray_test.h"

#include <limits.h>
#include <stdatomic.h>

/* An arbitrary ray: its slab-test form, range, best hit and pseudo-camera. */
typedef struct {
  float org[3];
  float inv_n[3]; /* 1 / dir rounded towards zero by RAY_MARGIN: the near planes' factor */
  float inv_f[3]; /* and away from zero: the far planes' */
  int wn[3], wf[3]; /* per axis the byte offsets in a bvh_wide8 of the near and far planes */
  rr_vf4 o[3], d[3]; /* origin and direction broadcast (the leaf test) */
  float tlo;          /* max(tmin, 0): every hit has t > 0 */
  float dmax;         /* max |dir| per axis (ray_t_outside) */
  float tmin;
  float t, l1, l2; /* best hit so far; t starts at tmax */
  uint32_t id;
  const rr_scene *s;
  const rr_bvh *b; /* NULL for an empty scene: every ray misses */
  ray_cam rc;      /* made for the first full test (vis/ray_test.h) */
} query_ray;

/* The traversal (vis/ray_query_tmp.h) enters the slots of a node whose box the
 * ray meets within [max(tmin, 0), best t], with their entry, which orders them and
 * drops a stacked slot. The margin is in the inverse direction: a slab's entry shrinks
 * towards 0 and its exit grows by a factor 1 ∓ RAY_MARGIN (the box's interval
 * beyond 0 widened relatively, as wide_test widens it, for one multiplication
 * fewer a plane); a negative entry loses to tlo, a negative exit misses either
 * way. A NaN slab (0·inf: the origin on a plane the ray runs in) is ignored: min
 * and max keep their second operand. Empty slots (lo = inf, hi = −inf) never pass. */

/* Tests a leaf's count triangles, keeping the nearest hit; `any`: stops at the
 * first, which needs no full test where ray_t_inside proves it. Their corners
 * are at leaf in rr_bvh.leaf_v8's layout, their ids are ids[i] + idbase; shift
 * (NULL: none): a translated instance's leaf read in place, whose corners are
 * leaf's plus shift (x, y, z at shift[0], [4], [8]: a transform's last column),
 * the additions bvh_leaf_at's copy makes, so the same bits.
 * Four at a time through the edge pre-test, then the full test for the lanes
 * that pass it (and for triangles with corners at infinity, which it cannot
 * judge). The same triangles pass whatever the order, and depth_wins keeps the
 * nearest, lower id on a tie, so the hit does not depend on the order. */
KERNEL bool query_tris(query_ray *r, const float *leaf, const uint32_t *ids, uint32_t idbase, const float *shift,
                       uint32_t count, const bool any) {
  rr_vf4 sh[3]; /* the translation, added to each corner as it is loaded */
  if (shift)
    for (int a = 0; a < 3; a++) sh[a] = rr_vf4_splat(shift[4 * a]);
  for (uint32_t j = 0; j < count; j += 4) {
    uint32_t n = count - j < 4 ? count - j : 4;
    const float *v = leaf + j;
    size_t stride = count;
    rr_vf4 pre[4];
    int may = tri_ray_may_hit4(v, stride, shift ? sh : NULL, r->o, r->d, pre) & ((1 << n) - 1);
    if (r->s->inf)
      for (uint32_t k = 0; k < n; k++) may |= (scene_inf(r->s, ids[j + k] + idbase) != 0) << k;
    for (; may; may &= may - 1) {
      uint32_t lane = (uint32_t)__builtin_ctz(may), id = ids[j + lane] + idbase;
      float t, l1, l2, dir[3] = {r->d[0][0], r->d[1][0], r->d[2][0]};
      const float e[4] = {pre[0][lane], pre[1][lane], pre[2][lane], pre[3][lane]};
      if (e[0] > 0 && e[1] > 0 && e[2] > 0 && !(r->s->inf && scene_inf(r->s, id))) {
        const float S = ray_corner_extent(v + lane, stride, shift, r->org);
        if (ray_t_outside(S, r->dmax, e, r->tmin, r->t)) continue;
        if (any && ray_t_inside(S, r->dmax, e, r->tmin, r->t)) return true; /* a proven hit: the answer */
      }
      bool hit = ray_tri_test(r->s, id, &r->rc, r->org, dir, e, r->tmin, r->t, &t, &l1, &l2);
      if (!hit) continue;
      if (any) return true;
      if (depth_wins(t, id, r->t, r->id)) r->t = t, r->id = id, r->l1 = l1, r->l2 = l2;
    }
  }
  return false;
}

/* Tests the leaf at positions [first, first + count) of the scene's tree (an
 * instance's, other than a translation, through bvh_leaf_at's copy). */
KERNEL bool query_leaf(query_ray *r, uint32_t first, uint32_t count, const bool any) {
  float vbuf[9 * BVH_MAX_LEAF + BVH_LEAF_PAD]; /* an instance's leaf, in world space */
  uint32_t ibuf[BVH_MAX_LEAF];
  const uint32_t *ids;
  const float *v;
  if (first < r->b->ntop) /* the top's own leaf, bvh_leaf_at's first case without its call */
    ids = r->b->prims + first, v = r->b->leaf_v8 + (size_t)9 * first;
  else
    v = bvh_leaf_at(r->b, true, first, count, vbuf, ibuf, &ids);
  if (query_tris(r, v, ids, 0, NULL, count, any)) return true;
  if (r->s->kind) { /* analytic primitives, which the pre-test rejects as edge-on: their own test */
    const float dir[3] = {r->d[0][0], r->d[1][0], r->d[2][0]};
    ana_ray ar = ana_ray_of(r->org, dir);
    for (uint32_t j = 0; j < count; j++) {
      uint32_t id = ids[j];
      float t, u, v;
      if (scene_kind(r->s, id) == RR_GEOMETRY_TRIANGLE || !rr_ana_hit(r->s, id, &ar, &t, &u, &v)) continue;
      if (!(t >= r->tmin && t <= r->t)) continue;
      if (any) return true;
      if (depth_wins(t, id, r->t, r->id)) r->t = t, r->id = id, r->l1 = u, r->l2 = v;
    }
  }
  return false;
}

/* Prepares a valid ray against the scene's tree b (NULL: an empty scene); the
 * three axes written out, which the compiler does not unroll by itself. */
static inline __attribute__((always_inline)) void query_axis(query_ray *r, int a, float org, float dir) {
  float inv = 1.0f / dir; /* ±inf for a zero component, by its sign */
  int lo = (int)offsetof(bvh_wide8, lo[a]), hi = (int)offsetof(bvh_wide8, hi[a]);
  bool neg = inv < 0;
  r->wn[a] = neg ? hi : lo, r->wf[a] = neg ? lo : hi;
  r->org[a] = org, r->inv_n[a] = inv * (1 - RAY_MARGIN), r->inv_f[a] = inv * (1 + RAY_MARGIN);
  r->o[a] = rr_vf4_splat(org), r->d[a] = rr_vf4_splat(dir);
}
static inline __attribute__((always_inline)) void query_init(query_ray *r, const rr_scene *s, const rr_bvh *b,
                                                             const float org[3], const float dir[3], float tmin,
                                                             float tmax) {
  r->s = s, r->b = b, r->rc.ready = false;
  query_axis(r, 0, org[0], dir[0]), query_axis(r, 1, org[1], dir[1]), query_axis(r, 2, org[2], dir[2]);
  r->tlo = tmin > 0 ? tmin : 0;
  float d0 = fabsf(dir[0]), d1 = fabsf(dir[1]), d2 = fabsf(dir[2]), d01 = d0 > d1 ? d0 : d1;
  r->dmax = d01 > d2 ? d01 : d2;
  r->tmin = tmin, r->t = tmax, r->id = RR_MISS, r->l1 = r->l2 = 0;
}

/* The traversal, once per vector width. */
#define RQ_LANES 4
#define RQ_VF rr_vf4
#define RQ_VI rr_vi4
#define RQ_(op) rr_vf4_##op
#define rr_vf4_bits rr_vi4_bits
#define RQ_TARGET
#define RQ_NAME query_trace4
#include "vis/ray_query_tmp.h"
#undef rr_vf4_bits

#ifdef RR_SIMD_X86
/* Eight lanes with AVX2: a node's test in one vector per plane, and the leaf's
 * four-lane tests in AVX's encodings (three operands, blends), the same lane
 * operations and bits. */
#define RQ_LANES 8
#define RQ_VF rr_vf8
#define RQ_VI rr_vi8
#define RQ_(op) rr_vf8_##op
#define rr_vf8_bits rr_vi8_bits
#define RQ_TARGET RR_TARGET_AVX2
#define RQ_NAME query_trace8
#include "vis/ray_query_tmp.h"
#undef rr_vf8_bits
#endif

/* Traces a prepared ray: the nearest hit into r, or (any) whether there is one. */
static inline __attribute__((always_inline)) bool query_trace(query_ray *r, bool any) {
  if (!r->b) return false;
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) return any ? query_trace8_any(r) : (query_trace8_closest(r), r->id != RR_MISS);
#endif
  return any ? query_trace4_any(r) : (query_trace4_closest(r), r->id != RR_MISS);
}

/* The committed scene's tree (NULL for an empty scene) or an error in dev: a
 * current tree without rr_bvh_of's call, which says what is wrong otherwise. */
static inline __attribute__((always_inline)) rr_error query_scene(rr_device *dev, const char *fn, const rr_scene *s,
                                                                  const void *in, const void *out,
                                                                  const rr_bvh **b) {
  *b = NULL;
  if (__builtin_expect(!s || !in || !out, 0)) return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: NULL scene, ray or result", fn);
  if (__builtin_expect(s->ntris && s->bvh && s->bvh->nprims == s->ntris, 1)) {
    *b = s->bvh;
    return RR_OK;
  }
  bool empty;
  *b = rr_bvh_of(dev, s, &empty);
  if (!*b && !empty) return RR_ERROR_ARGUMENT; /* a scene changed since its commit: rr_bvh_of said so */
  return RR_OK;
}

/* Checks a query's arguments and prepares its ray; errors go to dev only. */
static inline __attribute__((always_inline)) rr_error query_begin(rr_device *dev, const char *fn, const rr_scene *s,
                                                                  const rr_ray *ray, const void *out,
                                                                  query_ray *r) {
  const rr_bvh *b;
  rr_error e = query_scene(dev, fn, s, ray, out, &b);
  if (e) return e;
  if (__builtin_expect(!ray_valid(ray), 0))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: ray with %s", fn,
                   ray_problem(ray->org, ray->dir, ray->tmin, ray->tmax));
  query_init(r, s, b, ray->org, ray->dir, ray->tmin, ray->tmax);
  return RR_OK;
}

/* rr_scene_hit's miss, without its call. */
static const rr_hit query_miss = {.prim = RR_MISS, .t = INFINITY, .geom = RR_MISS, .inst = RR_MISS};

rr_error rr_intersect(rr_device *dev, const rr_scene *scene, const rr_ray *ray, rr_hit *hit) {
  if (hit) *hit = query_miss;
  query_ray r;
  rr_error e = query_begin(dev, "rr_intersect", scene, ray, hit, &r);
  if (e) return e;
  if (query_trace(&r, false)) *hit = rr_scene_hit(scene, r.id, r.t, r.l1, r.l2);
  return rr_ok(dev);
}

rr_error rr_occluded(rr_device *dev, const rr_scene *scene, const rr_ray *ray, int *occluded) {
  if (occluded) *occluded = 0;
  query_ray r;
  rr_error e = query_begin(dev, "rr_occluded", scene, ray, occluded, &r);
  if (e) return e;
  *occluded = query_trace(&r, true);
  return rr_ok(dev);
}

/* ---- streams -------------------------------------------------------------
 * A stream is cut into chunks of consecutive rays dealt to the thread pool; each
 * ray is traced exactly as rr_intersect / rr_occluded trace it (so the results
 * cannot depend on the chunking), with the scene checked once per call instead
 * of once per ray. Packets (rc-packet's traversal) would pay only for coherent
 * rays and are left for later: a stream does not know its rays are coherent. */

rr_ray_stream rr_ray_stream_aos(const rr_ray *rays, size_t count) {
  if (!rays) return (rr_ray_stream){.count = count, .stride = sizeof(rr_ray)};
  return (rr_ray_stream){.count = count,
                         .stride = sizeof(rr_ray),
                         .org = {&rays->org[0], &rays->org[1], &rays->org[2]},
                         .dir = {&rays->dir[0], &rays->dir[1], &rays->dir[2]},
                         .tmin = &rays->tmin,
                         .tmax = &rays->tmax};
}

enum { STREAM_CHUNK = 256 }; /* rays per job: a few tens of microseconds of work */

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const rr_ray_stream *rays;
  size_t chunk;
  rr_hit *hits;      /* closest hit, or */
  int *occluded;     /* any hit */
  atomic_size_t bad; /* the lowest invalid ray, SIZE_MAX when none */
} stream_job;

/* A stream's eight component arrays, in rr_ray's order. */
typedef struct {
  const char *p[8];
} stream_src;

static stream_src stream_src_of(const rr_ray_stream *rs) {
  return (stream_src){{(const char *)rs->org[0], (const char *)rs->org[1], (const char *)rs->org[2],
                       (const char *)rs->dir[0], (const char *)rs->dir[1], (const char *)rs->dir[2],
                       (const char *)rs->tmin, (const char *)rs->tmax}};
}

/* Ray i of a stream, gathered into one rr_ray (eight floats in a row: ray_valid). */
static inline __attribute__((always_inline)) void stream_ray(const stream_src *src, size_t stride, size_t i,
                                                             rr_ray *ray) {
  float f[8];
  size_t at = i * stride;
#pragma GCC unroll 8
  for (int k = 0; k < 8; k++) memcpy(&f[k], src->p[k] + at, sizeof f[k]);
  memcpy(ray, f, sizeof *ray);
}

static void stream_chunk(int job, int thread, void *arg) {
  (void)thread;
  stream_job *j = arg;
  const rr_ray_stream *rs = j->rays;
  size_t lo = (size_t)job * j->chunk, hi = lo + j->chunk < rs->count ? lo + j->chunk : rs->count;
  const stream_src src = stream_src_of(rs);
  for (size_t i = lo; i < hi; i++) {
    rr_ray ray;
    stream_ray(&src, rs->stride, i, &ray);
    bool valid = ray_valid(&ray), hit = false;
    query_ray r;
    if (valid) {
      query_init(&r, j->s, j->b, ray.org, ray.dir, ray.tmin, ray.tmax);
      hit = query_trace(&r, j->occluded != NULL);
    } else {
      size_t bad = atomic_load(&j->bad);
      while (i < bad && !atomic_compare_exchange_weak(&j->bad, &bad, i)) {
      }
    }
    if (j->occluded)
      j->occluded[i] = hit;
    else
      j->hits[i] = hit ? rr_scene_hit(j->s, r.id, r.t, r.l1, r.l2) : query_miss;
  }
}

static rr_error stream_run(rr_device *dev, const char *fn, const rr_scene *s, const rr_ray_stream *rs, int threads,
                           rr_hit *hits, int *occluded) {
  const rr_bvh *b;
  rr_error e = query_scene(dev, fn, s, rs, hits ? (const void *)hits : (const void *)occluded, &b);
  if (e) return e;
  if (threads < 0 || threads > RR_MAX_THREADS)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: %d threads (0 for all cores, at most %d)", fn, threads,
                   RR_MAX_THREADS);
  if (rs->count == 0) return rr_ok(dev);
  if (rs->stride % sizeof(float))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: a stride of %zu bytes, not a multiple of %zu", fn, rs->stride,
                   sizeof(float));
  bool null = !rs->tmin || !rs->tmax;
  for (int a = 0; a < 3; a++) null |= !rs->org[a] || !rs->dir[a];
  if (null) return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: a NULL component array", fn);
  /* jobs are ints: a stream of more than INT_MAX chunks gets longer chunks */
  size_t chunk = rs->count / INT_MAX + 1 > STREAM_CHUNK ? rs->count / INT_MAX + 1 : STREAM_CHUNK;
  stream_job j = {.s = s, .b = b, .rays = rs, .chunk = chunk, .hits = hits, .occluded = occluded};
  atomic_init(&j.bad, SIZE_MAX);
  rr_parallel_for((int)((rs->count + chunk - 1) / chunk), threads ? threads : rr_cpu_count(), stream_chunk, &j);
  size_t bad = atomic_load(&j.bad);
  if (bad != SIZE_MAX) {
    rr_ray ray;
    const stream_src src = stream_src_of(rs);
    stream_ray(&src, rs->stride, bad, &ray);
    return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: ray %zu with %s (a miss)", fn, bad,
                   ray_problem(ray.org, ray.dir, ray.tmin, ray.tmax));
  }
  return rr_ok(dev);
}

rr_error rr_intersect_stream(rr_device *dev, const rr_scene *scene, const rr_ray_stream *rays, int threads,
                             rr_hit *hits) {
  return stream_run(dev, "rr_intersect_stream", scene, rays, threads, hits, NULL);
}

rr_error rr_occluded_stream(rr_device *dev, const rr_scene *scene, const rr_ray_stream *rays, int threads,
                            int *occluded) {
  return stream_run(dev, "rr_occluded_stream", scene, rays, threads, NULL, occluded);
}
