/* Bounding volume hierarchy: a binary BVH built with the binned surface area
 * heuristic over triangle bounds (paper sect. 4.4: the spatial index every
 * traversal of the continuum shares).
 *
 * Determinism: a node's split depends only on the triangle references of its
 * range, in their order. Binning merges per-chunk bins with min/max and integer
 * counts (exact, so the merge order does not matter); big ranges are partitioned
 * stably by fixed-size chunks whatever the thread count; small ranges in place by
 * one thread. Which path a node takes depends on its size only, and nodes are
 * numbered in a fixed order, so the tree is the same for any number of threads.
 *
 * Layout: the root is node 0, every split allocates its two children as a pair
 * at an odd index; the array starts 32 bytes past a 64-byte boundary so a pair
 * shares one cache line. The top of the tree (ranges too big for one task) comes
 * first, then each task's subtree in depth-first order. */
#include "accel/bvh.h"

#include "core/simd.h"

#include <float.h>
#include <string.h>

enum {
  BVH_MAX_BINS = 64,
  BVH_TASK_MAX = 4096,  /* ranges at most this big are built whole by one thread */
  BVH_PAR_MIN = 32768,  /* ranges at least this big bin and partition by chunks */
  BVH_CHUNK = 8192,     /* references per chunk (a constant: part of the result) */
  BVH_SAH_DEPTH = 48,   /* below this depth split at the median: bounds the depth */
};

/* Inlined into its callers, the subtree builder's AVX2 copy among them. */
#define BVH_INLINE static inline __attribute__((always_inline))

/* SAH costs of a traversal step and a triangle test (relative). */
#define BVH_COST_NODE 1.0
#define BVH_COST_TRI 1.0

/* A triangle reference: its bounds; the id and the bins sit in lanes that are
 * masked off. bin: its bin on each axis, as the binning of the range it is in put
 * it, so that the partition that follows need not bin it again. */
typedef struct {
  float lo[3];
  uint32_t id;
  float hi[3];
  uint8_t bin[4];
} pref;

typedef struct {
  rr_vf4 lo, hi;
} box4;

static inline box4 box_empty(void) {
  box4 b = {rr_vf4_splat(INFINITY), rr_vf4_splat(-INFINITY)};
  return b;
}

static inline rr_vi4 xyz_mask(void) { return (rr_vi4){-1, -1, -1, 0}; }

static inline void ref_load(const pref *r, rr_vf4 *lo, rr_vf4 *hi) {
  rr_vi4 m = xyz_mask();
  *lo = (rr_vf4)((rr_vi4)rr_vf4_load(r->lo) & m);
  *hi = (rr_vf4)((rr_vi4)rr_vf4_load(r->hi) & m);
}

static inline void box_grow(box4 *b, rr_vf4 lo, rr_vf4 hi) {
  b->lo = rr_vf4_min(b->lo, lo);
  b->hi = rr_vf4_max(b->hi, hi);
}

static inline void box_merge(box4 *b, box4 o) { box_grow(b, o.lo, o.hi); }

/* Half the surface area: in float lanes, and again in double when that overflows
 * (boxes wider than about 1e19). An empty box has none. */
static inline double half_area(box4 b) {
  rr_vf4 e = b.hi - b.lo, p = e * rr_vf4_yzx(e);
  float a = p[0] + p[1] + p[2];
  uint32_t bits;
  memcpy(&bits, &a, sizeof bits);
  if (bits <= 0x7F7FFFFFu) return a; /* +0 to FLT_MAX: one test for the common case */
  if (a >= 0 && a <= FLT_MAX) return a; /* -0 (NaN fails both) */
  if (!(e[0] >= 0)) return 0; /* empty (or NaN) */
  double x = (double)b.hi[0] - b.lo[0], y = (double)b.hi[1] - b.lo[1], z = (double)b.hi[2] - b.lo[2];
  return x * y + y * z + z * x;
}

/* Maps centroids to bins: bin = clamp((c - cmin) * scale, 0, nb - 1), per axis. */
typedef struct {
  rr_vf4 cmin, scale, top;
  int nb;
  bool ok[3]; /* axis has extent */
} binmap;

BVH_INLINE binmap binmap_make(box4 cbox, int nb) {
  binmap m;
  /* per axis: ok when 0 < ext <= FLT_MAX and nb / ext is finite (NaN fails all) */
  rr_vf4 ext = cbox.hi - cbox.lo, s = rr_vf4_splat((float)nb) / ext;
  rr_vi4 ok = (ext > 0) & (ext <= FLT_MAX) & (rr_vf4_abs(s) <= FLT_MAX) & xyz_mask();
  int bits = rr_vi4_bits(ok);
  for (int a = 0; a < 3; a++) m.ok[a] = bits >> a & 1;
  m.cmin = (rr_vf4)((rr_vi4)cbox.lo & xyz_mask());
  m.scale = (rr_vf4)((rr_vi4)s & ok);
  m.top = rr_vf4_splat((float)(nb - 1));
  m.nb = nb;
  return m;
}

static inline rr_vf4 centroid(rr_vf4 lo, rr_vf4 hi) { return (lo + hi) * rr_vf4_splat(0.5f); }

/* Bin indices of a centroid on the three axes (NaN lands in bin 0). */
static inline rr_vi4 bin_of(const binmap *m, rr_vf4 c) {
  rr_vf4 f = (c - m->cmin) * m->scale;
  f = rr_vf4_min(rr_vf4_max(f, rr_vf4_splat(0.0f)), m->top);
  return rr_vi4_trunc(f);
}

/* A bin's box is kept as its lower corner and its upper corner negated, so that
 * both grow by a min (one eight-lane min under AVX2). -min(-a, -b) is max(a, b)
 * to the bit, NaN and signed zeros included (both give b when they tie). */
typedef struct {
  rr_vf4 lo, nhi;
} nbox;

static inline rr_vf4 neg(rr_vf4 v) { return (rr_vf4)((rr_vi4)v ^ (rr_vi4)rr_vf4_splat(-0.0f)); }

static inline nbox nbox_empty(void) {
  nbox b = {rr_vf4_splat(INFINITY), rr_vf4_splat(INFINITY)};
  return b;
}

static inline void nbox_merge(nbox *b, nbox o) {
  b->lo = rr_vf4_min(b->lo, o.lo);
  b->nhi = rr_vf4_min(b->nhi, o.nhi);
}

static inline box4 nbox_box(nbox b) {
  box4 r = {b.lo, neg(b.nhi)};
  return r;
}

/* half_area of an nbox without negating: lo + nhi is lo - hi, which is
 * -(hi - lo) to the bit but where hi == lo (+0 both), so the products are
 * half_area's but for the sign of a zero one, and the sum differs at most in
 * the sign of a zero area, which no cost comparison or sum can see. */
static inline double nbox_area(nbox b) {
  rr_vf4 s = b.lo + b.nhi, p = s * rr_vf4_yzx(s);
  float a = p[0] + p[1] + p[2];
  uint32_t bits;
  memcpy(&bits, &a, sizeof bits);
  if (bits <= 0x7F7FFFFFu) return a;
  return half_area(nbox_box(b));
}

typedef struct {
  nbox box[3][BVH_MAX_BINS];
  uint32_t n[3][BVH_MAX_BINS + 8]; /* room to read eight from any bin */
} bins;

static void bins_clear(bins *b, int nb) {
  for (int a = 0; a < 3; a++)
    for (int i = 0; i < nb; i++) b->box[a][i] = nbox_empty(), b->n[a][i] = 0;
}

#ifdef RR_SIMD_X86
/* bin_range with a reference's box (upper corner negated) and a bin's as one
 * eight-lane vector each: a bin grows by one min. */
RR_TARGET_AVX2 static inline void bin_grow8(bins *b, int a, uint32_t k, __m256 v) {
  float *bx = (float *)&b->box[a][k];
  _mm256_storeu_ps(bx, _mm256_min_ps(_mm256_loadu_ps(bx), v));
  b->n[a][k]++;
}

RR_TARGET_AVX2 static void bin_range_avx2(pref *r, uint32_t n, const binmap *m, bins *b) {
  /* bins_clear with a bin's box as one vector, the counts eight at a time */
  __m256 empty = _mm256_set1_ps(INFINITY);
  __m256 neg_hi = _mm256_setr_ps(0, 0, 0, 0, -0.0f, -0.0f, -0.0f, -0.0f);
  for (int a = 0; a < 3; a++) {
    for (int i = 0; i < m->nb; i += 2) /* two at a time: BVH_MAX_BINS is even */
      _mm256_storeu_ps((float *)&b->box[a][i], empty), _mm256_storeu_ps((float *)&b->box[a][i + 1], empty);
    for (int i = 0; i < m->nb; i += 8) _mm256_storeu_si256((__m256i *)&b->n[a][i], _mm256_setzero_si256());
  }
  for (uint32_t i = 0; i < n; i++) {
    __m256 v = _mm256_loadu_ps(r[i].lo); /* lanes 3 and 7 (id, bins): as in bin_range */
    __m128 lo = _mm256_castps256_ps128(v), hi = _mm256_extractf128_ps(v, 1);
    v = _mm256_xor_ps(v, neg_hi);
    __m128i idx = (__m128i)bin_of(m, centroid((rr_vf4)lo, (rr_vf4)hi));
    __m128i pk = _mm_packs_epi32(idx, idx);
    uint32_t packed = (uint32_t)_mm_cvtsi128_si32(_mm_packus_epi16(pk, pk));
    memcpy(r[i].bin, &packed, 4);
    bin_grow8(b, 0, (uint32_t)_mm_cvtsi128_si32(idx), v);
    bin_grow8(b, 1, (uint32_t)_mm_extract_epi32(idx, 1), v);
    bin_grow8(b, 2, (uint32_t)_mm_extract_epi32(idx, 2), v);
  }
}
#endif

/* Bins a range, noting each reference's bins in it (pref.bin). */
static void bin_range(pref *r, uint32_t n, const binmap *m, bins *b) {
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) {
    bin_range_avx2(r, n, m, b);
    return;
  }
#endif
  bins_clear(b, m->nb);
  for (uint32_t i = 0; i < n; i++) {
    /* Lane 3 (id, bins) unmasked: it only reaches lanes 3 of the bin boxes,
     * which nothing reads (half_area, store_box and the bins use lanes 0-2). */
    rr_vf4 lo = rr_vf4_load(r[i].lo), hi = rr_vf4_load(r[i].hi);
    rr_vi4 idx = bin_of(m, centroid(lo, hi));
    uint32_t i0 = (uint32_t)idx[0], i1 = (uint32_t)idx[1], i2 = (uint32_t)idx[2]; /* written out: no loop */
#ifdef RR_SIMD_X86
    /* the four lanes packed to bytes (lane 3, garbage, saturates) and stored at once */
    __m128i pk = _mm_packs_epi32((__m128i)idx, (__m128i)idx);
    uint32_t packed = (uint32_t)_mm_cvtsi128_si32(_mm_packus_epi16(pk, pk));
    memcpy(r[i].bin, &packed, 4);
#else
    r[i].bin[0] = (uint8_t)i0, r[i].bin[1] = (uint8_t)i1, r[i].bin[2] = (uint8_t)i2;
#endif
    nbox rb = {lo, neg(hi)};
    nbox_merge(&b->box[0][i0], rb), b->n[0][i0]++;
    nbox_merge(&b->box[1][i1], rb), b->n[1][i1]++;
    nbox_merge(&b->box[2][i2], rb), b->n[2][i2]++;
  }
}

static void bins_merge(bins *into, const bins *b, int nb) {
  for (int a = 0; a < 3; a++)
    for (int i = 0; i < nb; i++) nbox_merge(&into->box[a][i], b->box[a][i]), into->n[a][i] += b->n[a][i];
}

/* A range of references waiting to become a subtree rooted at `node`; they lie
 * in bd->buf[buf] (a big range's split moves them to the other buffer). */
typedef struct {
  uint32_t start, count, node;
  uint16_t depth, buf;
  box4 box, cbox;
} task;

/* How a range is split: on `axis`, bins < pos go left; `mid` is the size of
 * the left part; leaf when mid == 0. */
typedef struct {
  uint32_t mid;
  task l, r;
} split;

typedef struct {
  pref *buf[2]; /* references, and room to partition big ranges into */
  int bins, leaf_size, threads;
  bool oom; /* an allocation failed (only the building thread splits big ranges, which allocate) */
} builder;

/* best_split on axis a: the candidates there, after those of the axes before. */
BVH_INLINE void best_split_axis(const bins *b, int a, int nb, bool *found, int *axis, int *pos, double *cost) {
  /* Only splits at a nonempty bin i with triangles left of it are candidates,
   * so the right costs are needed at nonempty bins only, and the left ones at
   * candidates only; the first of equal candidates wins. */
  double rcost[BVH_MAX_BINS];
  nbox acc = nbox_empty();
  uint32_t cnt = 0;
  for (int i = nb - 1; i > 0; i--)
    if (b->n[a][i]) nbox_merge(&acc, b->box[a][i]), cnt += b->n[a][i], rcost[i] = nbox_area(acc) * cnt;
  acc = nbox_empty(), cnt = 0;
  for (int i = 1; i < nb; i++) {
    nbox_merge(&acc, b->box[a][i - 1]), cnt += b->n[a][i - 1]; /* an empty bin's box changes nothing */
    if (!cnt || !b->n[a][i]) continue;
    double c = nbox_area(acc) * cnt + rcost[i];
    if (!*found || c < *cost) *found = true, *cost = c, *axis = a, *pos = i;
  }
}

/* Chooses the cheapest binned SAH split; returns false when every centroid falls
 * into one bin on every axis. *cost is the SAH cost of the split (unnormalised). */
BVH_INLINE bool best_split(const bins *b, const binmap *m, int *axis, int *pos, double *cost) {
  bool found = false;
  for (int a = 0; a < 3; a++)
    if (m->ok[a]) best_split_axis(b, a, m->nb, &found, axis, pos, cost);
  return found;
}

#ifdef RR_SIMD_X86
/* The areas of eight boxes given as lo + nhi (nbox_area's s) at p[0..7]: their
 * lanes transposed, then (x·y + y·z) + z·x as nbox_area sums them. *bad: lanes
 * whose area is not in [+0, FLT_MAX], where nbox_area would take half_area. */
RR_TARGET_AVX2 static inline __m256 areas8(float (*p)[4], int *bad) {
  __m256 r0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(p[0])), _mm_load_ps(p[4]), 1);
  __m256 r1 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(p[1])), _mm_load_ps(p[5]), 1);
  __m256 r2 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(p[2])), _mm_load_ps(p[6]), 1);
  __m256 r3 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(p[3])), _mm_load_ps(p[7]), 1);
  __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpacklo_ps(r2, r3);
  __m256 t2 = _mm256_unpackhi_ps(r0, r1), t3 = _mm256_unpackhi_ps(r2, r3);
  __m256 x = _mm256_shuffle_ps(t0, t1, 0x44), y = _mm256_shuffle_ps(t0, t1, 0xEE), z = _mm256_shuffle_ps(t2, t3, 0x44);
  __m256 a = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, y), _mm256_mul_ps(y, z)), _mm256_mul_ps(z, x));
  __m256i bits = _mm256_castps_si256(a);
  __m256i out = _mm256_or_si256(_mm256_cmpgt_epi32(bits, _mm256_set1_epi32(0x7F7FFFFF)),
                                _mm256_cmpgt_epi32(_mm256_setzero_si256(), bits));
  *bad = _mm256_movemask_ps(_mm256_castsi256_ps(out));
  return a;
}

/* area · count per lane in double, as best_split multiplies them. */
RR_TARGET_AVX2 static inline void costs8(__m256 a, const int32_t *n, __m256d c[2]) {
  c[0] = _mm256_mul_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(a)), _mm256_cvtepi32_pd(_mm_loadu_si128((const __m128i *)n)));
  c[1] = _mm256_mul_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(a, 1)),
                       _mm256_cvtepi32_pd(_mm_loadu_si128((const __m128i *)(n + 4))));
}

/* best_split with the costs of eight candidates at a time: one pass each way
 * makes every bin's left box (bins < i) and right box (bins >= i) as lo + nhi
 * with their counts, then areas and costs as lanes, then a scan of the
 * candidates in best_split's order. The same operations on the same values, so
 * the same costs to the bit; an axis where a candidate's area is not a finite
 * float (or is -0) takes best_split's loop instead. */
RR_TARGET_AVX2 static bool best_split_avx2(const bins *b, const binmap *m, int *axis, int *pos, double *cost) {
  enum { N = BVH_MAX_BINS + 8 }; /* bins 1 .. nb - 1 in groups of eight */
  bool found = false;
  int nb = m->nb;
  for (int a = 0; a < 3; a++) {
    if (!m->ok[a]) continue;
    float ls[N][4] __attribute__((aligned(16))), rs[N][4] __attribute__((aligned(16)));
    int32_t lc[N], rc[N];
    double c[N];
    nbox acc = nbox_empty();
    uint32_t cnt = 0;
    for (int i = nb - 1; i > 0; i--) {
      nbox_merge(&acc, b->box[a][i]), cnt += b->n[a][i];
      rr_vf4_store(rs[i], acc.lo + acc.nhi), rc[i] = (int32_t)cnt;
    }
    acc = nbox_empty(), cnt = 0;
    for (int i = 1; i < nb; i++) {
      nbox_merge(&acc, b->box[a][i - 1]), cnt += b->n[a][i - 1];
      rr_vf4_store(ls[i], acc.lo + acc.nhi), lc[i] = (int32_t)cnt;
    }
    for (int i = nb; i < nb + 8; i++) /* the last group's lanes past the bins: defined, never candidates */
      rr_vf4_store(ls[i], rr_vf4_splat(0)), rr_vf4_store(rs[i], rr_vf4_splat(0)), lc[i] = rc[i] = 0;
    uint64_t cand = 0;
    int bad = 0;
    for (int i = 1; i < nb; i += 8) {
      /* candidates: lanes i + k < nb with a nonempty bin and references left of it */
      __m256i lane = _mm256_add_epi32(_mm256_set1_epi32(i), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
      __m256i in = _mm256_cmpgt_epi32(_mm256_set1_epi32(nb), lane);
      __m256i zero = _mm256_setzero_si256();
      __m256i nz = _mm256_andnot_si256(_mm256_cmpeq_epi32(_mm256_loadu_si256((const __m256i *)&b->n[a][i]), zero),
                                       _mm256_andnot_si256(_mm256_cmpeq_epi32(_mm256_loadu_si256((const __m256i *)&lc[i]), zero), in));
      int ok = _mm256_movemask_ps(_mm256_castsi256_ps(nz)), bl, br;
      __m256 al = areas8(&ls[i], &bl), ar = areas8(&rs[i], &br);
      bad |= (bl | br) & ok;
      __m256d cl[2], cr[2];
      costs8(al, &lc[i], cl), costs8(ar, &rc[i], cr);
      _mm256_storeu_pd(&c[i], _mm256_add_pd(cl[0], cr[0])), _mm256_storeu_pd(&c[i + 4], _mm256_add_pd(cl[1], cr[1]));
      cand |= (uint64_t)ok << i;
    }
    if (bad) {
      best_split_axis(b, a, nb, &found, axis, pos, cost);
      continue;
    }
    for (; cand; cand &= cand - 1) {
      int i = __builtin_ctzll(cand);
      if (!found || c[i] < *cost) found = true, *cost = c[i], *axis = a, *pos = i;
    }
  }
  return found;
}
#endif

/* Whether a binned reference goes right of the split (bin >= pos on `axis`); *c is
 * its centroid, lane 3 unmasked: it only reaches the lanes 3 of centroid bounds,
 * which binmap_make masks off. */
static inline bool ref_right(const pref *r, int axis, int pos, rr_vf4 *c) {
  *c = centroid(rr_vf4_load(r->lo), rr_vf4_load(r->hi));
  return r->bin[axis] >= pos;
}

/* Bounds and centroid bounds of a range. */
static void range_bounds(const pref *r, uint32_t n, box4 *box, box4 *cbox) {
  *box = box_empty(), *cbox = box_empty();
  for (uint32_t i = 0; i < n; i++) {
    rr_vf4 lo, hi;
    ref_load(&r[i], &lo, &hi);
    box_grow(box, lo, hi);
    rr_vf4 c = centroid(lo, hi);
    box_grow(cbox, c, c);
  }
}

/* ref_right with *c twice the centroid, lo + hi: halving is monotonic and keeps
 * signs, so bounds over lo + hi halved are the centroids' bounds but for the sign
 * of a zero that underflowed, which no bin map can tell from the other zero. */
static inline bool ref_right2(const pref *r, int axis, int pos, rr_vf4 *c) {
  *c = rr_vf4_load(r->lo) + rr_vf4_load(r->hi);
  return r->bin[axis] >= pos;
}

/* In-place partition of a small range (one thread): left = bin < pos. Two-sided:
 * each reference is looked at once, and only those on the wrong side move. */

BVH_INLINE uint32_t partition_small(pref *r, uint32_t n, int axis, int pos, box4 cb[2]) {
  cb[0] = box_empty(), cb[1] = box_empty();
  uint32_t i = 0, j = n;
  for (;;) {
    rr_vf4 ci = {0}, cj = {0}; /* set by the scans before use */
    while (i < j && !ref_right2(&r[i], axis, pos, &ci)) box_grow(&cb[0], ci, ci), i++;
    while (i < j && ref_right2(&r[j - 1], axis, pos, &cj)) box_grow(&cb[1], cj, cj), j--;
    if (i == j) {
      for (int k = 0; k < 2; k++) cb[k].lo *= 0.5f, cb[k].hi *= 0.5f;
      return i;
    }
    /* r[i] goes right and r[j - 1] left (j - 1 > i: r[i] stopped the left scan) */
    pref tmp = r[i];
    r[i++] = r[--j], r[j] = tmp;
    box_grow(&cb[0], cj, cj), box_grow(&cb[1], ci, ci);
  }
}

/* ---- chunked work on big ranges (parallel, result independent of threads) -- */

typedef struct {
  builder *bd;
  const task *t;
  const binmap *m;
  int axis, pos;
  bins *chunk_bins;   /* one per chunk */
  uint32_t *nleft;    /* per chunk */
  uint32_t *offset;   /* per chunk: where its left / right parts go */
  box4 *ccb;          /* per chunk: centroid bounds left, right */
} chunk_job;

static void chunk_bin(int c, int thread, void *arg) {
  (void)thread;
  chunk_job *j = arg;
  uint32_t s = (uint32_t)c * BVH_CHUNK, n = j->t->count - s < BVH_CHUNK ? j->t->count - s : BVH_CHUNK;
  bin_range(j->bd->buf[j->t->buf] + j->t->start + s, n, j->m, &j->chunk_bins[c]);
}

static void chunk_count(int c, int thread, void *arg) {
  (void)thread;
  chunk_job *j = arg;
  uint32_t s = (uint32_t)c * BVH_CHUNK, n = j->t->count - s < BVH_CHUNK ? j->t->count - s : BVH_CHUNK;
  const pref *r = j->bd->buf[j->t->buf] + j->t->start + s;
  uint32_t k = 0;
  for (uint32_t i = 0; i < n; i++) {
    rr_vf4 cen;
    k += !ref_right(&r[i], j->axis, j->pos, &cen);
  }
  j->nleft[c] = k;
}

static void chunk_scatter(int c, int thread, void *arg) {
  (void)thread;
  chunk_job *j = arg;
  int nchunks = (int)((j->t->count + BVH_CHUNK - 1) / BVH_CHUNK);
  uint32_t s = (uint32_t)c * BVH_CHUNK, n = j->t->count - s < BVH_CHUNK ? j->t->count - s : BVH_CHUNK;
  const pref *r = j->bd->buf[j->t->buf] + j->t->start + s;
  pref *out = j->bd->buf[!j->t->buf] + j->t->start;
  uint32_t li = j->offset[c], ri = j->offset[nchunks + c];
  box4 cb[2] = {box_empty(), box_empty()};
  for (uint32_t i = 0; i < n; i++) {
    rr_vf4 cen;
    int side = ref_right(&r[i], j->axis, j->pos, &cen);
    box_grow(&cb[side], cen, cen);
    out[side ? ri++ : li++] = r[i];
  }
  j->ccb[2 * c] = cb[0], j->ccb[2 * c + 1] = cb[1];
}

/* ---- splitting one range ---------------------------------------------------- */

static int bins_for(const builder *bd, uint32_t count) {
  /* Half as many bins as references (at least 4, at most bd->bins): one per
   * reference costs a sweep step per reference and axis for nearly the same
   * splits (SAH cost within 0.03% on the bunny, nefertiti and a teapot grid; a
   * third or a quarter as many bins cost 0.1-0.2%). */
  uint32_t want = count / 2;
  int nb = want < (uint32_t)bd->bins ? (int)want : bd->bins;
  return nb < 4 ? (bd->bins < 4 ? bd->bins : 4) : nb;
}

static void median_split(builder *bd, const task *t, split *sp) {
  sp->mid = t->count / 2;
  const pref *r = bd->buf[t->buf] + t->start;
  range_bounds(r, sp->mid, &sp->l.box, &sp->l.cbox);
  range_bounds(r + sp->mid, t->count - sp->mid, &sp->r.box, &sp->r.cbox);
}

/* split_task for a range of two references, which is most of the bottom of the
 * tree, without bins and with the same result. Their centroids span the centroid
 * box, so on every axis with extent one is in bin 0 and the other in bin nb - 1:
 * each such axis offers the one split (one reference each side) at the same cost,
 * and the first such axis wins. */
BVH_INLINE void split_pair(builder *bd, const task *t, int nb, split *sp) {
  pref *r = bd->buf[t->buf] + t->start;
  binmap m = binmap_make(t->cbox, nb);
  int axis = -1;
  for (int a = 2; a >= 0; a--)
    if (m.ok[a]) axis = a;
  if (axis < 0) { /* no split found: a leaf, or split at the median */
    if (t->count > (uint32_t)bd->leaf_size) median_split(bd, t, sp);
    return;
  }
  box4 b[2];
  ref_load(&r[0], &b[0].lo, &b[0].hi), ref_load(&r[1], &b[1].lo, &b[1].hi);
  double cost = half_area(b[0]) * 1 + half_area(b[1]) * 1, area = half_area(t->box);
  if (t->count <= (uint32_t)bd->leaf_size && BVH_COST_TRI * t->count * area <= BVH_COST_NODE * area + BVH_COST_TRI * cost)
    return;
  rr_vf4 c[2] = {centroid(b[0].lo, b[0].hi), centroid(b[1].lo, b[1].hi)};
  int left = c[0][axis] < c[1][axis] ? 0 : 1; /* bin 0; they differ on an axis with extent */
  if (left) {
    pref tmp = r[0];
    r[0] = r[1], r[1] = tmp;
  }
  sp->l.box = b[left], sp->r.box = b[!left];
  sp->l.cbox = (box4){c[left], c[left]}, sp->r.cbox = (box4){c[!left], c[!left]};
  sp->mid = 1;
}

/* Decides how to split t (or not) and partitions its references; `threads` only
 * says how many threads may help with a big range. Out of memory, t stays a leaf
 * and bd->oom is set. */
BVH_INLINE void split_task_inl(builder *bd, const task *t, int threads, split *sp, bool avx2) {
  sp->mid = 0;
  uint16_t buf = t->buf;
  if (t->count <= 1) return;
  bool big = t->count >= BVH_PAR_MIN;
  if (t->depth >= BVH_SAH_DEPTH) {
    if (t->count > (uint32_t)bd->leaf_size) median_split(bd, t, sp);
    goto children;
  }
  int nb = bins_for(bd, t->count);
  if (t->count == 2) {
    split_pair(bd, t, nb, sp);
    goto children;
  }
  binmap m = binmap_make(t->cbox, nb);
  bins bins_local, *b = &bins_local;
  int nchunks = big ? (int)((t->count + BVH_CHUNK - 1) / BVH_CHUNK) : 1;
  chunk_job job = {.bd = bd, .t = t, .m = &m};
  if (big) {
    job.chunk_bins = malloc(sizeof(bins) * nchunks);
    if (!job.chunk_bins) {
      bd->oom = true;
      return;
    }
    rr_parallel_for(nchunks, threads, chunk_bin, &job);
    bins_clear(b, nb);
    for (int c = 0; c < nchunks; c++) bins_merge(b, &job.chunk_bins[c], nb);
    free(job.chunk_bins);
  } else {
    bin_range(bd->buf[t->buf] + t->start, t->count, &m, b);
  }
  int axis = 0, pos = 0;
  double cost = 0;
#ifdef RR_SIMD_X86
  /* eight candidates at a time pay from 12 bins on; its counts are int32 lanes */
  bool wide = avx2 && nb >= 12 && t->count <= INT32_MAX;
  bool found = wide ? best_split_avx2(b, &m, &axis, &pos, &cost) : best_split(b, &m, &axis, &pos, &cost);
#else
  (void)avx2;
  bool found = best_split(b, &m, &axis, &pos, &cost);
#endif
  double area = half_area(t->box);
  /* Leaf when small enough and no split is cheaper (costs scaled by the area). */
  if (t->count <= (uint32_t)bd->leaf_size &&
      (!found || BVH_COST_TRI * t->count * area <= BVH_COST_NODE * area + BVH_COST_TRI * cost)) {
    return;
  }
  if (!found) {
    median_split(bd, t, sp);
    goto children;
  }
  nbox lr[2] = {nbox_empty(), nbox_empty()};
  for (int i = 0; i < nb; i++)
    if (b->n[axis][i]) nbox_merge(&lr[i >= pos], b->box[axis][i]);
  sp->l.box = nbox_box(lr[0]), sp->r.box = nbox_box(lr[1]);
  if (big) {
    job.axis = axis, job.pos = pos;
    job.nleft = malloc(sizeof(uint32_t) * nchunks);
    job.offset = malloc(sizeof(uint32_t) * 2 * nchunks);
    job.ccb = malloc(sizeof(box4) * 2 * nchunks);
    if (!job.nleft || !job.offset || !job.ccb) {
      free(job.nleft), free(job.offset), free(job.ccb);
      bd->oom = true;
      return;
    }
    rr_parallel_for(nchunks, threads, chunk_count, &job);
    uint32_t nl = 0;
    for (int c = 0; c < nchunks; c++) job.offset[c] = nl, nl += job.nleft[c];
    uint32_t nr = nl;
    for (int c = 0; c < nchunks; c++) {
      job.offset[nchunks + c] = nr;
      nr += (c == nchunks - 1 ? t->count - (uint32_t)c * BVH_CHUNK : BVH_CHUNK) - job.nleft[c];
    }
    /* Into the other buffer, where the children stay (no copy back). */
    rr_parallel_for(nchunks, threads, chunk_scatter, &job);
    buf = !t->buf;
    sp->l.cbox = box_empty(), sp->r.cbox = box_empty();
    for (int c = 0; c < nchunks; c++) box_merge(&sp->l.cbox, job.ccb[2 * c]), box_merge(&sp->r.cbox, job.ccb[2 * c + 1]);
    sp->mid = nl;
    free(job.nleft), free(job.offset), free(job.ccb);
  } else {
    box4 cb[2];
    sp->mid = partition_small(bd->buf[t->buf] + t->start, t->count, axis, pos, cb);
    sp->l.cbox = cb[0], sp->r.cbox = cb[1];
  }
children:
  if (!sp->mid) return;
  sp->l.start = t->start, sp->l.count = sp->mid;
  sp->r.start = t->start + sp->mid, sp->r.count = t->count - sp->mid;
  sp->l.depth = sp->r.depth = t->depth + 1;
  sp->l.buf = sp->r.buf = buf;
}

#ifdef RR_SIMD_X86
/* split_task_inl compiled for AVX2 (three-operand forms: fewer register copies);
 * the same operations, so the same tree. */
RR_TARGET_AVX2 static void split_task_avx2(builder *bd, const task *t, int threads, split *sp) {
  split_task_inl(bd, t, threads, sp, true);
}
#endif

static void split_task(builder *bd, const task *t, int threads, split *sp) {
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) {
    split_task_avx2(bd, t, threads, sp);
    return;
  }
#endif
  split_task_inl(bd, t, threads, sp, false);
}

static void store_box(bvh_node *n, box4 b) {
  memcpy(n->lo, &b.lo, 12), memcpy(n->hi, &b.hi, 12);
}

/* ---- growable arrays ---------------------------------------------------------- */

typedef struct {
  bvh_node *v;
  uint32_t n, cap;
  bool oom;
} node_vec;

static uint32_t node_pair(node_vec *nv) {
  if (nv->n + 2 > nv->cap) {
    uint32_t cap = nv->cap ? nv->cap * 2 : 64;
    bvh_node *p = realloc(nv->v, (size_t)cap * sizeof *p);
    if (!p) {
      nv->oom = true;
      return UINT32_MAX;
    }
    nv->v = p, nv->cap = cap;
  }
  nv->n += 2;
  return nv->n - 2;
}

typedef struct {
  task *v;
  uint32_t n, cap;
  bool oom;
} task_vec;

static void task_push(task_vec *tv, task t) {
  if (tv->n == tv->cap) {
    uint32_t cap = tv->cap ? tv->cap * 2 : 64;
    task *p = realloc(tv->v, (size_t)cap * sizeof *p);
    if (!p) {
      tv->oom = true;
      return;
    }
    tv->v = p, tv->cap = cap;
  }
  tv->v[tv->n++] = t;
}

/* ---- subtrees: one thread builds a whole small range ------------------------ */

typedef struct {
  builder *bd;
  bvh_node *top;   /* the task roots live here */
  task *tasks;
  node_vec *local; /* per task: its nodes below the root; inner `first` local */
  uint32_t *leaves, *depth;
} sub_job;

BVH_INLINE void build_subtree_inl(int ti, sub_job *j, bool avx2) {
  node_vec *nv = &j->local[ti];
  /* Room for the whole subtree at once (at most 2 count - 2 nodes below the root):
   * no regrowing copies. */
  nv->cap = 2 * j->tasks[ti].count;
  nv->v = malloc((size_t)nv->cap * sizeof *nv->v);
  if (!nv->v) {
    nv->cap = 0, nv->oom = true;
    return;
  }
  task stack[2 * 128];
  int sp = 0;
  stack[sp++] = j->tasks[ti];
  uint32_t leaves = 0, depth = 0;
  /* The root's node is in the top array; its descendants' nodes are local and
   * are told apart by the high bit until relocation. */
  while (sp) {
    task t = stack[--sp];
    bvh_node *n = (t.node & 0x80000000u) ? &nv->v[t.node & 0x7FFFFFFFu] : &j->top[t.node];
    split s;
    split_task_inl(j->bd, &t, 1, &s, avx2);
    store_box(n, t.box);
    if (!s.mid) {
      n->first = t.start, n->count = t.count;
      leaves++;
      depth = t.depth > depth ? t.depth : depth;
      continue;
    }
    uint32_t p = node_pair(nv);
    if (p == UINT32_MAX) return;
    n = (t.node & 0x80000000u) ? &nv->v[t.node & 0x7FFFFFFFu] : &j->top[t.node]; /* realloc may move it */
    n->first = p, n->count = 0;
    s.l.node = p | 0x80000000u, s.r.node = (p + 1) | 0x80000000u;
    stack[sp++] = s.r; /* left first: depth-first order */
    stack[sp++] = s.l;
  }
  j->leaves[ti] = leaves, j->depth[ti] = depth;
}

#ifdef RR_SIMD_X86
/* The subtree loop with split_task_inl in it, compiled for AVX2 as split_task_avx2. */
RR_TARGET_AVX2 static void build_subtree_avx2(int ti, sub_job *j) { build_subtree_inl(ti, j, true); }
#endif

static void build_subtree(int ti, int thread, void *arg) {
  (void)thread;
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) {
    build_subtree_avx2(ti, arg);
    return;
  }
#endif
  build_subtree_inl(ti, arg, false);
}

/* ---- the top of the tree: big ranges, split one level at a time ------------ */

typedef struct {
  builder *bd;
  task *t;
  split *s;
} level_job;

static void split_one(int i, int thread, void *arg) {
  (void)thread;
  level_job *j = arg;
  split_task(j->bd, &j->t[i], 1, &j->s[i]);
}

/* ---- prim bounds ---------------------------------------------------------------- */

typedef struct {
  const rr_scene *s;
  pref *refs;
  box4 *cb; /* per chunk: bounds, centroid bounds */
} ref_job;

static void make_refs(int c, int thread, void *arg) {
  (void)thread;
  ref_job *j = arg;
  const rr_scene *s = j->s;
  uint32_t a = (uint32_t)c * BVH_CHUNK, e = s->ntris - a < BVH_CHUNK ? s->ntris : a + BVH_CHUNK;
  box4 b = box_empty(), cb = box_empty();
  float *const *p = &s->p[0][0]; /* the nine coordinate arrays */
  uint32_t i = a;
#ifdef RR_SIMD_X86
  if (!s->kind && !s->inf && !s->inst) /* plain triangles: four at a time */
    for (; i + 4 <= e; i += 4) {
      /* per axis, the four triangles' bounds as lanes (the same min and max as
       * below), then turned into four references */
      __m128 lo[4], hi[4];
      for (int x = 0; x < 3; x++) {
        __m128 v0 = _mm_loadu_ps(p[x] + i), v1 = _mm_loadu_ps(p[3 + x] + i), v2 = _mm_loadu_ps(p[6 + x] + i);
        lo[x] = _mm_min_ps(v0, _mm_min_ps(v1, v2)), hi[x] = _mm_max_ps(v0, _mm_max_ps(v1, v2));
      }
      lo[3] = _mm_castsi128_ps(_mm_add_epi32(_mm_set1_epi32((int32_t)i), _mm_setr_epi32(0, 1, 2, 3))); /* ids */
      hi[3] = _mm_setzero_ps();                                                                      /* bins */
      _MM_TRANSPOSE4_PS(lo[0], lo[1], lo[2], lo[3]);
      _MM_TRANSPOSE4_PS(hi[0], hi[1], hi[2], hi[3]);
      for (int k = 0; k < 4; k++) {
        pref *r = &j->refs[i + k];
        _mm_storeu_ps(r->lo, lo[k]), _mm_storeu_ps(r->hi, hi[k]);
        rr_vf4 l = (rr_vf4)((rr_vi4)lo[k] & xyz_mask()), h = (rr_vf4)hi[k]; /* ref_load's (bins are 0) */
        box_grow(&b, l, h);
        rr_vf4 cen = centroid(l, h);
        box_grow(&cb, cen, cen);
      }
    }
#endif
  for (; i < e; i++) {
    pref *r = &j->refs[i];
    rr_vf4 lo, hi;
    if (scene_kind(s, i) == RR_GEOMETRY_TRIANGLE && !scene_inf(s, i)) {
      /* rr_tri_box's fminf / fmaxf as lanes: the same bits for finite corners
       * (the scene holds no others), an equal pair giving the second as both do */
      rr_vf4 v0 = {p[0][i], p[1][i], p[2][i], 0}, v1 = {p[3][i], p[4][i], p[5][i], 0};
      rr_vf4 v2 = {p[6][i], p[7][i], p[8][i], 0};
      lo = rr_vf4_min(v0, rr_vf4_min(v1, v2)), hi = rr_vf4_max(v0, rr_vf4_max(v1, v2));
      memcpy(r->lo, &lo, 12), memcpy(r->hi, &hi, 12);
    } else {
      if (scene_kind(s, i) == RR_GEOMETRY_TRIANGLE) rr_tri_box(s, i, r->lo, r->hi);
      else rr_ana_box(s, i, r->lo, r->hi);
    }
    r->id = i, memset(r->bin, 0, sizeof r->bin);
    ref_load(r, &lo, &hi);
    box_grow(&b, lo, hi);
    rr_vf4 cen = centroid(lo, hi);
    box_grow(&cb, cen, cen);
  }
  j->cb[2 * c] = b, j->cb[2 * c + 1] = cb;
}

/* Memory on 64-byte cache lines, rounded up to whole lines (as aligned_alloc requires). */
static void *alloc_lines(size_t bytes) { return aligned_alloc(64, (bytes + 63) & ~(size_t)63); }

/* ---- the 4-wide copy ------------------------------------------------------------ */

static double node_area(const bvh_node *n) {
  double x = (double)n->hi[0] - n->lo[0], y = (double)n->hi[1] - n->lo[1], z = (double)n->hi[2] - n->lo[2];
  return x * y + y * z + z * x;
}

/* The slots of a wide node made from binary node k: k's children, then the inner
 * slot with the largest area opened into its two children until `width` slots are
 * used (or only leaves are left). Returns how many. */
static uint32_t open_slots(const rr_bvh *b, uint32_t k, uint32_t width, uint32_t *slot) {
  uint32_t n = 0;
  double area[8]; /* per slot: its area, or -1 for a leaf (never opened) */
  const bvh_node *nk = &b->nodes[k];
  if (nk->count) slot[n++] = k; /* a leaf root */
  else slot[n++] = nk->first, slot[n++] = nk->first + 1;
  for (uint32_t i = 0; i < n; i++) area[i] = b->nodes[slot[i]].count ? -1 : node_area(&b->nodes[slot[i]]);
  while (n < width) {
    int open = -1;
    double best = -1;
    for (uint32_t i = 0; i < n; i++)
      if (area[i] > best) best = area[i], open = (int)i;
    if (open < 0) break;
    uint32_t first = b->nodes[slot[open]].first;
    for (uint32_t i = n; i > (uint32_t)open + 1; i--) slot[i] = slot[i - 1], area[i] = area[i - 1];
    slot[open] = first, slot[open + 1] = first + 1, n++;
    for (uint32_t i = (uint32_t)open; i < (uint32_t)open + 2; i++)
      area[i] = b->nodes[slot[i]].count ? -1 : node_area(&b->nodes[slot[i]]);
  }
  return n;
}

/* Makes wide node w from binary node k (open_slots with four). */
static void collapse_node(rr_bvh *b, uint32_t w, uint32_t k, uint32_t *next) {
  uint32_t slot[4], n = open_slots(b, k, 4, slot);
  bvh_wide *wn = &b->wide[w];
  for (uint32_t i = n; i < 4; i++) { /* empty slots */
    b->wide_node[4 * w + i] = UINT32_MAX;
    for (int a = 0; a < 3; a++) wn->lo[a][i] = INFINITY, wn->hi[a][i] = -INFINITY;
    wn->ref[i] = UINT32_MAX, wn->count[i] = 0;
  }
  for (uint32_t i = 0; i < n; i++) {
    const bvh_node *c = &b->nodes[slot[i]];
    b->wide_node[4 * w + i] = slot[i];
    for (int a = 0; a < 3; a++) wn->lo[a][i] = c->lo[a], wn->hi[a][i] = c->hi[a];
    wn->count[i] = c->count;
    if (c->count) {
      wn->ref[i] = c->first;
    } else {
      wn->ref[i] = (*next)++;
      collapse_node(b, wn->ref[i], slot[i], next);
    }
  }
}

/* The corners of the triangles prims[first .. first + count) into v: corner k's
 * axis x of the j-th at v[(3k + x)·count + j] (the layout of rr_bvh.leaf_v). An
 * instance's corners are moved to world space (scene_corners), the rest copied. */
static inline void copy_corners_p(const float *const *sp, const uint32_t *prims, uint32_t first, uint32_t count,
                                  float *v);

static void copy_corners(const rr_scene *s, const uint32_t *prims, uint32_t first, uint32_t count, float *v) {
  if (s->inst) {
    for (uint32_t j = 0; j < count; j++) {
      vec3 c[3];
      scene_corners(s, prims[first + j], c);
      for (int k = 0; k < 3; k++)
        v[(3 * k) * count + j] = c[k].x, v[(3 * k + 1) * count + j] = c[k].y, v[(3 * k + 2) * count + j] = c[k].z;
    }
    return;
  }
  copy_corners_p((const float *const *)&s->p[0][0], prims, first, count, v);
}

/* copy_corners of a scene without instances, given its nine coordinate arrays
 * (hoisted out of the leaf loops). */
/* copy_corners_p's loop; inlined with a constant count for the common leaves. */
BVH_INLINE void copy_corners_n(const float *const *p, const uint32_t *prims, uint32_t count, float *v) {
  for (uint32_t j = 0; j < count; j++) {
    uint32_t t = prims[j];
    float *o = v + j;
    o[0] = p[0][t], o[count] = p[1][t], o[2 * count] = p[2][t];
    o[3 * count] = p[3][t], o[4 * count] = p[4][t], o[5 * count] = p[5][t];
    o[6 * count] = p[6][t], o[7 * count] = p[7][t], o[8 * count] = p[8][t];
  }
}

static inline void copy_corners_p(const float *const *sp, const uint32_t *prims, uint32_t first, uint32_t count,
                                  float *v) {
  const float *p[9]; /* in locals: the stores into v cannot change them */
  memcpy(p, sp, sizeof p);
  prims += first;
  switch (count) { /* the offsets folded for leaves of one to four */
  case 1: copy_corners_n(p, prims, 1, v); break;
  case 2: copy_corners_n(p, prims, 2, v); break;
  case 3: copy_corners_n(p, prims, 3, v); break;
  case 4: copy_corners_n(p, prims, 4, v); break;
  default: copy_corners_n(p, prims, count, v);
  }
}

/* The corners of the leaves' triangles, leaf by leaf (rr_bvh.leaf_v). */
static bool copy_leaf_corners(rr_bvh *b, const rr_scene *s) {
  size_t n = (size_t)9 * b->nprims;
  b->leaf_v = alloc_lines((n + BVH_LEAF_PAD) * sizeof(float));
  if (!b->leaf_v) return false;
  memset(b->leaf_v + n, 0, BVH_LEAF_PAD * sizeof(float));
  const float *const *p = (const float *const *)&s->p[0][0];
  for (uint32_t i = 0; i < b->nnodes; i++) {
    const bvh_node *nd = &b->nodes[i];
    if (!nd->count || nd->count == BVH_INST) continue; /* (an instance's leaf has no corners of its own) */
    if (s->inst) copy_corners(s, b->prims, nd->first, nd->count, b->leaf_v + (size_t)9 * nd->first);
    else copy_corners_p(p, b->prims, nd->first, nd->count, b->leaf_v + (size_t)9 * nd->first);
  }
  return true;
}

void rr_bvh_count_wide(rr_bvh *b) {
  for (uint32_t w = b->nwide; w-- > 0;) {
    const bvh_wide *n = &b->wide[w];
    uint32_t sum = 0;
    for (int i = 0; i < 4; i++) {
      uint32_t r = n->ref[i], c = n->count[i];
      if (r == UINT32_MAX || c == BVH_INST) continue; /* empty, or an instance not yet linked */
      sum += c ? c : r < b->nwide ? b->wide_tris[r] : b->obj->wide_tris[(r - b->nwide) % b->obj->nwide];
    }
    b->wide_tris[w] = sum;
  }
}

static bool collapse_wide(rr_bvh *b) {
  /* At most one wide node per inner binary node (plus a leaf root). */
  uint32_t cap = (b->nnodes - 1) / 2 + 1;
  b->wide = alloc_lines((size_t)cap * sizeof(bvh_wide));
  b->wide_node = malloc((size_t)cap * 4 * sizeof(uint32_t));
  if (!b->wide || !b->wide_node) return false;
  uint32_t next = 1;
  collapse_node(b, 0, 0, &next);
  b->nwide = next;
  /* about half of the room is used: keep what is */
  bvh_wide *exact = alloc_lines((size_t)next * sizeof(bvh_wide));
  uint32_t *exact_node = malloc((size_t)next * 4 * sizeof(uint32_t));
  if (exact && exact_node) {
    memcpy(exact, b->wide, (size_t)next * sizeof(bvh_wide));
    memcpy(exact_node, b->wide_node, (size_t)next * 4 * sizeof(uint32_t));
    free(b->wide), free(b->wide_node);
    b->wide = exact, b->wide_node = exact_node;
  } else {
    free(exact), free(exact_node);
  }
  b->wide_tris = malloc((size_t)next * sizeof *b->wide_tris);
  if (!b->wide_tris) return false;
  rr_bvh_count_wide(b);
  return true;
}

/* ---- the 8-wide copy for the ray queries ------------------------------------------
 * Made from the binary tree as the 4-wide one is, but a subtree of at most four
 * triangles becomes one leaf: the ray queries test a leaf's triangles four at a
 * time for the price of one (the binary leaves hold fewer than two on average).
 * A subtree's triangles are consecutive in prims, so such a leaf is a range too,
 * and its corners are copied as leaf_v's are (rr_bvh.leaf_v8). The nodes are
 * written depth first (a node's children after it). */
typedef struct {
  rr_bvh *b;
  const rr_scene *s;
  uint32_t *first, *count; /* per binary node: its subtree's prims (count 0: not consecutive) */
  uint32_t next, cap;      /* the next free node; room in b->wide8 */
  bool oom;
} wide8_build;

/* A new wide8 node's index, the array grown by doubling when full (UINT32_MAX
 * when out of memory). Growing as it goes costs less than counting first. */
static uint32_t wide8_new(wide8_build *j) {
  if (j->next == j->cap) {
    uint32_t cap = j->cap * 2;
    bvh_wide8 *p = cap > j->cap ? alloc_lines((size_t)cap * sizeof *p) : NULL;
    if (!p) {
      j->oom = true;
      return UINT32_MAX;
    }
    memcpy(p, j->b->wide8, (size_t)j->next * sizeof *p);
    free(j->b->wide8);
    j->b->wide8 = p, j->cap = cap;
  }
  return j->next++;
}

/* The prims under each binary node k into j->first[k], j->count[k]; the count is
 * left 0 where they are not one range (never, for the builder's trees; checked).
 * Children come after their parent in the builder's layout, so one backward pass
 * sees them first. */
static void subtree_ranges(wide8_build *j) {
  for (uint32_t k = j->b->nnodes; k-- > 0;) {
    const bvh_node *n = &j->b->nodes[k];
    if (n->count) {
      j->first[k] = n->first, j->count[k] = n->count;
      continue;
    }
    uint32_t l = n->first, r = n->first + 1;
    bool joined = j->count[l] && j->count[r] && j->first[l] + j->count[l] == j->first[r] &&
                  j->count[l] != BVH_INST && j->count[r] != BVH_INST;
    j->first[k] = j->first[l], j->count[k] = joined ? j->count[l] + j->count[r] : 0;
  }
}

/* Whether binary node c is a leaf of wide8: a leaf, or a subtree of at most four triangles. */
static bool leaf8(const wide8_build *j, uint32_t c) {
  return j->b->nodes[c].count || (j->count[c] && j->count[c] <= 4);
}

/* open_slots with eight, where leaf8 tells the leaves. */
static uint32_t open_slots8(const wide8_build *j, uint32_t k, uint32_t *slot) {
  const bvh_node *nodes = j->b->nodes;
  uint32_t n = 0;
  double area[8]; /* per slot: its area, or -1 for a leaf of wide8 (never opened) */
  if (leaf8(j, k)) slot[n++] = k; /* a leaf root */
  else slot[n++] = nodes[k].first, slot[n++] = nodes[k].first + 1;
  for (uint32_t i = 0; i < n; i++) area[i] = leaf8(j, slot[i]) ? -1 : node_area(&nodes[slot[i]]);
  while (n < 8) {
    int open = -1;
    double best = -1;
    for (uint32_t i = 0; i < n; i++)
      if (area[i] > best) best = area[i], open = (int)i;
    if (open < 0) break;
    uint32_t first = nodes[slot[open]].first;
    for (uint32_t i = n; i > (uint32_t)open + 1; i--) slot[i] = slot[i - 1], area[i] = area[i - 1];
    slot[open] = first, slot[open + 1] = first + 1, n++;
    for (uint32_t i = (uint32_t)open; i < (uint32_t)open + 2; i++)
      area[i] = leaf8(j, slot[i]) ? -1 : node_area(&nodes[slot[i]]);
  }
  return n;
}

static void collapse_node8(wide8_build *j, uint32_t w, uint32_t k) {
  rr_bvh *b = j->b;
  uint32_t slot[8], n = open_slots8(j, k, slot);
  bvh_wide8 *wn = &b->wide8[w]; /* moves when a child grows the array */
  for (uint32_t i = 0; i < 8; i++) {
    const bvh_node *c = i < n ? &b->nodes[slot[i]] : NULL;
    for (int a = 0; a < 3; a++) wn->lo[a][i] = c ? c->lo[a] : INFINITY, wn->hi[a][i] = c ? c->hi[a] : -INFINITY;
    wn->ref[i] = UINT32_MAX, wn->count[i] = 0;
  }
  for (uint32_t i = 0; i < n; i++) {
    uint32_t c = slot[i];
    if (leaf8(j, c)) { /* a leaf: its corners as leaf_v's */
      uint32_t first = j->first[c], count = j->count[c];
      float *v = b->leaf_v8 + (size_t)9 * first;
      if (count == BVH_INST) /* an instance's leaf has no corners of its own */
        ;
      else if (j->s->inst) copy_corners(j->s, b->prims, first, count, v);
      else copy_corners_p((const float *const *)&j->s->p[0][0], b->prims, first, count, v);
      wn->ref[i] = first, wn->count[i] = count;
    } else {
      uint32_t r = wide8_new(j);
      if (r == UINT32_MAX) return;
      collapse_node8(j, r, c);
      b->wide8[w].ref[i] = r;
      wn = &b->wide8[w];
    }
  }
}

static bool collapse_wide8(rr_bvh *b, const rr_scene *s) {
  size_t nv = (size_t)9 * b->nprims;
  wide8_build j = {.b = b, .s = s, .next = 1, .cap = 64};
  j.first = malloc((size_t)b->nnodes * sizeof(uint32_t));
  j.count = malloc((size_t)b->nnodes * sizeof(uint32_t));
  b->leaf_v8 = alloc_lines((nv + BVH_LEAF_PAD) * sizeof(float));
  bool ok = j.first && j.count && b->leaf_v8;
  if (ok) {
    memset(b->leaf_v8 + nv, 0, BVH_LEAF_PAD * sizeof(float));
    subtree_ranges(&j);
    b->wide8 = alloc_lines((size_t)j.cap * sizeof(bvh_wide8));
    ok = b->wide8 != NULL;
  }
  if (ok) collapse_node8(&j, 0, 0), ok = !j.oom;
  b->nwide8 = j.next;
  free(j.first), free(j.count);
  return ok;
}

void rr_bvh_release(rr_bvh *b) {
  if (!b) return;
  free(b->node_mem), free(b->prims), free(b->wide), free(b->wide_node), free(b->wide_tris), free(b->wide8), free(b->leaf_v8), free(b->leaf_v);
  rr_bvh_release(b->obj);
  free(b);
}


void rr_build_options_init(rr_build_options *opt) {
  if (!opt) return;
  *opt = (rr_build_options){.threads = 0, .bins = BVH_DEFAULT_BINS, .leaf_size = BVH_DEFAULT_LEAF};
}

rr_error rr_device_set_build_options(rr_device *dev, const rr_build_options *opt) {
  if (!dev || !opt) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_device_set_build_options: NULL argument");
  if (opt->threads < 0 || opt->threads > RR_MAX_THREADS)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad build thread count %d (0 for all cores, at most %d)", opt->threads,
                   RR_MAX_THREADS);
  if (opt->bins != 0 && (opt->bins < 2 || opt->bins > BVH_MAX_BINS))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad SAH bin count %d (2..%d)", opt->bins, BVH_MAX_BINS);
  if (opt->leaf_size != 0 && (opt->leaf_size < 1 || opt->leaf_size > BVH_MAX_LEAF))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad leaf size %d (1..%d)", opt->leaf_size, BVH_MAX_LEAF);
  dev->build = *opt;
  return rr_ok(dev);
}

/* Fills a built tree's totals: SAH cost (relative to the root's area). */
static double sah_cost(const struct rr_bvh *b) {
  double sum = 0;
  for (uint32_t i = 0; i < b->nnodes; i++) {
    const bvh_node *n = &b->nodes[i];
    double x = (double)n->hi[0] - n->lo[0], y = (double)n->hi[1] - n->lo[1], z = (double)n->hi[2] - n->lo[2];
    double a = x * y + y * z + z * x;
    sum += n->count && n->count != BVH_INST ? BVH_COST_TRI * n->count * a : BVH_COST_NODE * a;
  }
  const bvh_node *r = &b->nodes[0];
  double x = (double)r->hi[0] - r->lo[0], y = (double)r->hi[1] - r->lo[1], z = (double)r->hi[2] - r->lo[2];
  double ra = x * y + y * z + z * x;
  return ra > 0 ? sum / ra : 0;
}

/* The copies made from the finished binary tree, side by side: each reads the
 * tree and writes its own arrays. */
typedef struct {
  rr_bvh *b;
  const rr_scene *s;
  bool ok[3];
} finish_job;

static void finish_part(int part, int thread, void *arg) {
  (void)thread;
  finish_job *j = arg;
  if (part == 0) j->ok[0] = collapse_wide8(j->b, j->s); /* the biggest first */
  else if (part == 1) j->ok[1] = collapse_wide(j->b);
  else j->ok[2] = copy_leaf_corners(j->b, j->s), j->b->sah_cost = sah_cost(j->b);
}

bool rr_bvh_finish(rr_bvh *b, const rr_scene *s, int threads) {
  finish_job fj = {b, s, {false, false, false}};
  /* small trees on the calling thread, as the build keeps them: no pool is started
   * for them (a process with threads imports in process under the sanitizers) */
  rr_parallel_for(3, b->nprims >= BVH_PAR_MIN ? threads : 1, finish_part, &fj);
  if (!fj.ok[0] || !fj.ok[1] || !fj.ok[2]) return false;
  uint32_t n = b->nprims;
  b->bytes = sizeof *b + (uint64_t)b->nnodes * sizeof(bvh_node) + (uint64_t)n * sizeof *b->prims +
             (uint64_t)b->nwide * (sizeof(bvh_wide) + 5 * sizeof(uint32_t)) +
             (uint64_t)b->nwide8 * sizeof(bvh_wide8) + 2 * ((uint64_t)9 * n + BVH_LEAF_PAD) * sizeof(float);
  b->ntop = b->vpos = n, b->vnodes = b->nnodes, b->vwide = b->nwide, b->vwide8 = b->nwide8;
  return true;
}

rr_error rr_bvh_build(rr_scene *s, const rr_build_options *opt, struct rr_bvh **out) {
  *out = NULL;
  double t0 = rr_now_ms();
  builder bd = {.bins = opt->bins ? opt->bins : BVH_DEFAULT_BINS,
                .leaf_size = opt->leaf_size ? opt->leaf_size : BVH_DEFAULT_LEAF,
                .threads = opt->threads ? opt->threads : rr_cpu_count()};
  struct rr_bvh *b = calloc(1, sizeof *b);
  if (!b) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the BVH");
  b->nprims = s->ntris;
  b->bins = bd.bins, b->leaf_size = bd.leaf_size;
  if (s->ntris == 0) { /* an empty scene has no tree: every ray misses */
    free(b);
    return RR_OK;
  }
  uint32_t n = s->ntris;
  bd.buf[0] = alloc_lines((size_t)n * sizeof(pref));
  bd.buf[1] = alloc_lines((size_t)n * sizeof(pref));
  int nchunks = (int)((n + BVH_CHUNK - 1) / BVH_CHUNK);
  box4 *cb = malloc(sizeof(box4) * 2 * nchunks);
  task_vec frontier = {0}, next = {0}, small = {0};
  node_vec top = {0}, *local = NULL;
  uint32_t *leaves = NULL, *depths = NULL;
  split *splits = NULL;
  rr_error err = RR_OK;
  if (!bd.buf[0] || !bd.buf[1] || !cb) goto oom;
  /* Every level of the tree costs about the same: the fraction done is the levels
   * done out of about log2(n / leaf size) + 1. */
  progress_span progress = {s->dev, RR_PROGRESS_BUILD, 0, 1};
  double levels = log2((double)n / bd.leaf_size) + 1, built = 0;
  rr_progress(&progress, 0);

  ref_job rj = {s, bd.buf[0], cb};
  rr_parallel_for(nchunks, bd.threads, make_refs, &rj);
  task root = {.start = 0, .count = n, .node = 0, .depth = 0, .box = cb[0], .cbox = cb[1]};
  for (int c = 1; c < nchunks; c++) box_merge(&root.box, cb[2 * c]), box_merge(&root.cbox, cb[2 * c + 1]);
  /* The root sits alone before the pairs, so pairs start at odd indices. */
  top.v = malloc(64 * sizeof *top.v), top.cap = 64, top.n = 1;
  if (!top.v) goto oom;
  uint32_t top_leaves = 0, top_depth = 0;
  if (root.count > BVH_TASK_MAX) task_push(&frontier, root);
  else task_push(&small, root);
  if (frontier.oom || small.oom) goto oom;

  while (frontier.n) {
    split *grown = realloc(splits, sizeof *splits * frontier.n);
    if (!grown) goto oom;
    splits = grown;
    /* Big ranges one at a time with all threads inside; the rest one per thread. */
    level_job lj = {&bd, frontier.v, splits};
    int nmid = 0;
    for (uint32_t i = 0; i < frontier.n; i++) {
      if (frontier.v[i].count >= BVH_PAR_MIN) split_task(&bd, &frontier.v[i], bd.threads, &splits[i]);
      else nmid++;
    }
    if (bd.oom) goto oom;
    if (nmid) {
      /* Ranges below BVH_PAR_MIN, in parallel; a range is split the same way
       * whichever thread does it. */
      task *mt = malloc(sizeof *mt * nmid);
      split *ms = malloc(sizeof *ms * nmid);
      if (!mt || !ms) {
        free(mt), free(ms);
        goto oom;
      }
      int k = 0;
      for (uint32_t i = 0; i < frontier.n; i++)
        if (frontier.v[i].count < BVH_PAR_MIN) mt[k++] = frontier.v[i];
      lj.t = mt, lj.s = ms;
      rr_parallel_for(nmid, bd.threads, split_one, &lj);
      k = 0;
      for (uint32_t i = 0; i < frontier.n; i++)
        if (frontier.v[i].count < BVH_PAR_MIN) splits[i] = ms[k++];
      free(mt), free(ms);
    }
    next.n = 0;
    for (uint32_t i = 0; i < frontier.n; i++) {
      task *t = &frontier.v[i];
      split *sp = &splits[i];
      store_box(&top.v[t->node], t->box);
      if (!sp->mid) { /* cannot happen for ranges this big, but stay correct */
        if (t->buf) memcpy(bd.buf[0] + t->start, bd.buf[1] + t->start, t->count * sizeof(pref));
        top.v[t->node].first = t->start, top.v[t->node].count = t->count;
        top_leaves++;
        top_depth = t->depth > top_depth ? t->depth : top_depth;
        continue;
      }
      uint32_t p = node_pair(&top);
      if (p == UINT32_MAX) goto oom;
      top.v[t->node].first = p, top.v[t->node].count = 0;
      sp->l.node = p, sp->r.node = p + 1;
      task_push(sp->l.count > BVH_TASK_MAX ? &next : &small, sp->l);
      task_push(sp->r.count > BVH_TASK_MAX ? &next : &small, sp->r);
    }
    if (next.oom || small.oom) goto oom;
    task_vec tmp = frontier;
    frontier = next, next = tmp;
    built = fmin(built + 1 / levels, 0.9);
    rr_progress(&progress, built);
  }

  /* Small ranges: one subtree per task, in parallel. */
  local = calloc(small.n, sizeof *local);
  leaves = calloc(small.n, sizeof *leaves);
  depths = calloc(small.n, sizeof *depths);
  if (!local || !leaves || !depths) goto oom;
  sub_job sj = {&bd, top.v, small.v, local, leaves, depths};
  progress_span subtrees = rr_progress_part(&progress, built, 1);
  rr_parallel_for_progress((int)small.n, bd.threads, build_subtree, &sj, &subtrees);

  /* Assemble: the top, then each task's nodes with their child indices moved. */
  uint64_t total = top.n;
  for (uint32_t i = 0; i < small.n; i++) {
    if (local[i].oom) goto oom;
    total += local[i].n;
  }
  if (total > UINT32_MAX / 2) goto oom;
  b->node_mem = alloc_lines((size_t)(total + 2) * sizeof(bvh_node));
  b->prims = malloc((size_t)n * sizeof *b->prims);
  if (!b->node_mem || !b->prims) goto oom;
  b->nodes = (bvh_node *)b->node_mem + 1;
  memcpy(b->nodes, top.v, top.n * sizeof *top.v);
  uint32_t off = top.n;
  b->nleaves = top_leaves, b->depth = top_depth;
  for (uint32_t i = 0; i < small.n; i++) {
    bvh_node *root_node = &b->nodes[small.v[i].node];
    if (!root_node->count) root_node->first += off;
    bvh_node *dst = b->nodes + off;
    for (uint32_t k = 0; k < local[i].n; k++) {
      dst[k] = local[i].v[k];
      if (!dst[k].count) dst[k].first += off;
    }
    off += local[i].n;
    b->nleaves += leaves[i];
    b->depth = depths[i] > b->depth ? depths[i] : b->depth;
  }
  b->nnodes = (uint32_t)total;
  /* Every range ends in a top leaf (in buffer 0) or a task's subtree (in its buffer). */
  for (uint32_t i = 0; i < n; i++) b->prims[i] = bd.buf[0][i].id;
  for (uint32_t i = 0; i < small.n; i++)
    if (small.v[i].buf)
      for (uint32_t k = small.v[i].start; k < small.v[i].start + small.v[i].count; k++) b->prims[k] = bd.buf[1][k].id;
  if (!rr_bvh_finish(b, s, bd.threads)) goto oom;
  b->build_ms = rr_now_ms() - t0;
  rr_progress(&progress, 1);
  *out = b;
  b = NULL;
  goto done;
oom:
  err = rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory building the BVH of %u triangles", n);
done:
  for (uint32_t i = 0; local && i < small.n; i++) free(local[i].v);
  free(local), free(leaves), free(depths), free(splits);
  free(frontier.v), free(next.v), free(small.v), free(top.v);
  free(bd.buf[0]), free(bd.buf[1]), free(cb);
  rr_bvh_release(b);
  return err;
}


const rr_bvh *rr_bvh_of(rr_device *dev, const rr_scene *s, bool *empty) {
  *empty = s->ntris == 0;
  if (*empty) return NULL;
  if (!s->bvh || s->bvh->nprims != s->ntris) {
    rr_fail(dev, RR_ERROR_ARGUMENT, "the scene has no current BVH (call rr_scene_commit after adding meshes)");
    return NULL;
  }
  return s->bvh;
}

void rr_bvh_fill_info(const rr_bvh *b, rr_scene_info *info) {
  if (!b) return;
  info->bvh_nodes = b->nnodes + (b->obj ? b->obj->nnodes : 0); /* stored ones */
  info->bvh_leaves = b->nleaves;
  info->bvh_depth = b->depth;
  info->bvh_sah_cost = b->sah_cost;
  info->bvh_build_ms = b->build_ms;
  info->bvh_bytes = b->bytes;
}
