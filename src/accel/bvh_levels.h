/* Reading a BVH of one or two levels (accel/bvh.h: rr_bvh.obj): every traversal
 * takes its nodes and leaves through these, so one code path reads both.
 *
 * A reference within the top's arrays is returned as it is stored. One past them
 * is instance k's copy of a node of the object tree, made on the way into the
 * caller's buffer: its boxes moved to world space, its references moved to
 * instance k's (children: k's nodes; leaves: k's positions, whose ids are
 * base + k·T + i). So a traversal sees the tree the copies would make, whose boxes
 * hold their triangles' world corners (inst_point's floats), which is all any
 * pruning proof assumes of a box:
 * - a translation (the fast path: the grid) adds t, and fl(lo + t) <= fl(p + t) <=
 *   fl(hi + t) for lo <= p <= hi, as rounding is monotonic: exact, and free;
 * - other maps take interval arithmetic in double, widened by far more than
 *   inst_point's rounding (five roundings of at most 2^-24 of the terms'
 *   magnitudes) and rounded outward.
 * A leaf's corners are the object tree's stored corners moved by inst_point (a
 * translation: leaf_v + t, the same floats), so every test sees the bits of the
 * scene written out. Buffers for wide nodes must be aligned as the arrays are
 * (BVH_NODE_ALIGN) for the traversals' vector loads. */
#ifndef RR_BVH_LEVELS_H
#define RR_BVH_LEVELS_H

#include "accel/bvh.h"
#include "core/simd.h"
#include "scene/instance.h"

#include <math.h>
#include <string.h>

#define BVH_NODE_ALIGN _Alignas(64)

/* The world box of the object box lo..hi under instance k (see the head comment). */
static inline void bvh_inst_box(const scene_instances *in, uint32_t k, const float lo[3], const float hi[3],
                                float wlo[3], float whi[3]) {
  const float *m = in->xf[k];
  for (int a = 0; a < 3; a++) {
    if (in->shift[k]) {
      wlo[a] = lo[a] + m[4 * a + 3], whi[a] = hi[a] + m[4 * a + 3];
      continue;
    }
    double l = m[4 * a + 3], h = l, mag = fabs(l);
    for (int j = 0; j < 3; j++) {
      double x = (double)m[4 * a + j] * lo[j], y = (double)m[4 * a + j] * hi[j];
      l += fmin(x, y), h += fmax(x, y), mag += fmax(fabs(x), fabs(y));
    }
    double pad = mag * 0x1p-20;
    wlo[a] = nextafterf((float)(l - pad), -INFINITY), whi[a] = nextafterf((float)(h + pad), INFINITY);
  }
}

/* The instance of reference r past `top` (per: references per instance), and in *j
 * the object tree's. */
static inline uint32_t bvh_inst_of(uint32_t r, uint32_t top, uint32_t per, uint32_t *j) {
  uint32_t v = r - top, k = v / per;
  *j = v - k * per;
  return k;
}

/* Binary node r (3D methods). */
static inline const bvh_node *bvh_node_at(const rr_bvh *b, uint32_t r, bvh_node *buf) {
  if (r < b->nnodes) return &b->nodes[r];
  const rr_bvh *o = b->obj;
  uint32_t j, k = bvh_inst_of(r, b->nnodes, o->nnodes, &j);
  const bvh_node *src = &o->nodes[j];
  const float *m = b->inst->xf[k];
  if (b->inst->shift[k]) /* (bvh_inst_box's translation, inline: the common grid's) */
    for (int a = 0; a < 3; a++) buf->lo[a] = src->lo[a] + m[4 * a + 3], buf->hi[a] = src->hi[a] + m[4 * a + 3];
  else bvh_inst_box(b->inst, k, src->lo, src->hi, buf->lo, buf->hi);
  buf->count = src->count;
  buf->first = src->first + (src->count ? b->ntop + k * o->nprims : b->nnodes + k * o->nnodes);
  return buf;
}

/* A wide node's references (W slots, a multiple of 4) moved: leaves by `leaves`,
 * inner slots by `inner`, empty ones (UINT32_MAX) kept. */
static inline __attribute__((always_inline)) void bvh_move_refs(int W, const uint32_t *sref, const uint32_t *scount,
                                                                uint32_t *ref, uint32_t *count, uint32_t leaves,
                                                                uint32_t inner) {
  const rr_vi4 vl = {(int32_t)leaves, (int32_t)leaves, (int32_t)leaves, (int32_t)leaves};
  const rr_vi4 vi = {(int32_t)inner, (int32_t)inner, (int32_t)inner, (int32_t)inner};
  for (int h = 0; h < W; h += 4) {
    rr_vi4 r, c;
    memcpy(&r, sref + h, sizeof r), memcpy(&c, scount + h, sizeof c);
    rr_vi4 leaf = c != 0, empty = r == -1;
    r += ((leaf & vl) | (~leaf & vi)) & ~empty;
    memcpy(ref + h, &r, sizeof r), memcpy(count + h, &c, sizeof c);
  }
}

/* Instance k's copy of wide node src (W slots, W a multiple of 4) into buf: leaves
 * move by `leaves`, inner slots by `inner`, empty slots (ref UINT32_MAX) keep their
 * empty boxes. A translation in four-lane steps (the same additions). */
static inline __attribute__((always_inline)) void bvh_wide_move(const scene_instances *in, uint32_t k, int W,
                                                                const float *slo, const float *shi,
                                                                const uint32_t *sref, const uint32_t *scount, float *lo,
                                                                float *hi, uint32_t *ref, uint32_t *count,
                                                                uint32_t leaves, uint32_t inner) {
  const float *m = in->xf[k];
  if (in->shift[k]) {
    for (int a = 0; a < 3; a++)
      for (int h = 0; h < W; h += 4) {
        rr_vf4 t = rr_vf4_splat(m[4 * a + 3]);
        rr_vf4_store(lo + a * W + h, rr_vf4_load(slo + a * W + h) + t);
        rr_vf4_store(hi + a * W + h, rr_vf4_load(shi + a * W + h) + t);
      }
  } else {
    for (int i = 0; i < W; i++) {
      float l[3] = {slo[i], slo[W + i], slo[2 * W + i]}, u[3] = {shi[i], shi[W + i], shi[2 * W + i]}, wl[3], wu[3];
      if (sref[i] != UINT32_MAX) bvh_inst_box(in, k, l, u, wl, wu);
      else memcpy(wl, l, sizeof l), memcpy(wu, u, sizeof u);
      for (int a = 0; a < 3; a++) lo[a * W + i] = wl[a], hi[a * W + i] = wu[a];
    }
  }
  bvh_move_refs(W, sref, scount, ref, count, leaves, inner);
}

/* Wide node r of a W-wide form (TYPE, the arrays ARR and counts N of rr_bvh). */
#define BVH_WIDE_AT(NAME, TYPE, W, ARR, N)                                                                     \
  static inline __attribute__((always_inline)) const TYPE *NAME(const rr_bvh *b, uint32_t r, TYPE *buf) {     \
    if (__builtin_expect(r < b->N, 1)) return &b->ARR[r];                                                     \
    const rr_bvh *o = b->obj;                                                                                 \
    uint32_t j, k = bvh_inst_of(r, b->N, o->N, &j);                                                           \
    const TYPE *src = &o->ARR[j];                                                                             \
    bvh_wide_move(b->inst, k, W, &src->lo[0][0], &src->hi[0][0], src->ref, src->count, &buf->lo[0][0],        \
                  &buf->hi[0][0], buf->ref, buf->count, b->ntop + k * o->nprims, b->N + k * o->N);            \
    return buf;                                                                                               \
  }
BVH_WIDE_AT(bvh_wide_at, bvh_wide, 4, wide, nwide)
BVH_WIDE_AT(bvh_wide8_at, bvh_wide8, 8, wide8, nwide8)
#undef BVH_WIDE_AT

/* The references alone of 4-wide node r (ref, count as bvh_wide's): for walks that
 * read no box. */
static inline __attribute__((always_inline)) void bvh_wide_refs(const rr_bvh *b, uint32_t r, uint32_t ref[4],
                                                                uint32_t count[4]) {
  if (r < b->nwide) {
    memcpy(ref, b->wide[r].ref, sizeof b->wide[r].ref), memcpy(count, b->wide[r].count, sizeof b->wide[r].count);
    return;
  }
  const rr_bvh *o = b->obj;
  uint32_t j, k = bvh_inst_of(r, b->nwide, o->nwide, &j);
  bvh_move_refs(4, o->wide[j].ref, o->wide[j].count, ref, count, b->ntop + k * o->nprims, b->nwide + k * o->nwide);
}

/* Wide node r for a walk that reads its references alone: the node itself, or
 * instance k's copy with its references moved and its boxes left unset in buf. */
static inline __attribute__((always_inline)) const bvh_wide *bvh_wide_refs_at(const rr_bvh *b, uint32_t r,
                                                                             bvh_wide *buf) {
  if (__builtin_expect(r < b->nwide, 1)) return &b->wide[r];
  const rr_bvh *o = b->obj;
  uint32_t j, k = bvh_inst_of(r, b->nwide, o->nwide, &j);
  bvh_move_refs(4, o->wide[j].ref, o->wide[j].count, buf->ref, buf->count, b->ntop + k * o->nprims,
                b->nwide + k * o->nwide);
  return buf;
}

/* The id at leaf position p. */
static inline uint32_t bvh_prim_at(const rr_bvh *b, uint32_t p) {
  if (p < b->ntop) return b->prims[p];
  uint32_t j, k = bvh_inst_of(p, b->ntop, b->obj->nprims, &j);
  return b->inst->base + k * b->inst->T + b->obj->prims[j];
}

/* The ids at leaf positions [first, first + count) (one leaf's) into out. */
static inline void bvh_prims_at(const rr_bvh *b, uint32_t first, uint32_t count, uint32_t *out) {
  if (first < b->ntop) {
    memcpy(out, b->prims + first, count * sizeof *out);
    return;
  }
  uint32_t j, k = bvh_inst_of(first, b->ntop, b->obj->nprims, &j), base = b->inst->base + k * b->inst->T;
  for (uint32_t i = 0; i < count; i++) out[i] = base + b->obj->prims[j + i];
}

/* The leaf at positions [first, first + count): its ids into *ids and its corners
 * in rr_bvh.leaf_v's layout (v8: leaf_v8's), returned; the tree's own arrays for
 * the top's leaves, else instance k's made in vbuf (9·count + BVH_LEAF_PAD floats)
 * and ibuf (count ids). */
static inline const float *bvh_leaf_at(const rr_bvh *b, bool v8, uint32_t first, uint32_t count, float *vbuf,
                                       uint32_t *ibuf, const uint32_t **ids) {
  if (first < b->ntop) {
    *ids = b->prims + first;
    return (v8 ? b->leaf_v8 : b->leaf_v) + (size_t)9 * first;
  }
  const rr_bvh *o = b->obj;
  const scene_instances *in = b->inst;
  uint32_t j, k = bvh_inst_of(first, b->ntop, o->nprims, &j), base = in->base + k * in->T;
  for (uint32_t i = 0; i < count; i++) ibuf[i] = base + o->prims[j + i];
  const float *src = (v8 ? o->leaf_v8 : o->leaf_v) + (size_t)9 * j, *m = in->xf[k];
  if (in->shift[k]) {
    for (uint32_t c = 0; c < 9; c++)
      for (uint32_t i = 0; i < count; i++) vbuf[c * count + i] = src[c * count + i] + m[4 * (c % 3) + 3];
  } else {
    for (uint32_t c = 0; c < 3; c++)
      for (uint32_t i = 0; i < count; i++) {
        const float *p = src + 3 * c * count + i;
        vec3 w = inst_point(m, false, v3(p[0], p[count], p[2 * count]));
        vbuf[3 * c * count + i] = w.x, vbuf[(3 * c + 1) * count + i] = w.y, vbuf[(3 * c + 2) * count + i] = w.z;
      }
  }
  memset(vbuf + (size_t)9 * count, 0, BVH_LEAF_PAD * sizeof *vbuf);
  *ids = ibuf;
  return vbuf;
}

#endif
