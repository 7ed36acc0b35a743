/* The one traversal of the 4-wide BVH, shared by every ray caster: primary rays
 * and 8x8 packets of them (vis/rc_bvh.c), arbitrary rays (vis/ray_query.c).
 *
 * The stack, the order in which slots are entered and the rule that drops a
 * stacked slot are written once, in bvh_trace(). What is traced, one ray or a
 * packet, is a policy of three functions passed as constants (the kernel and
 * the policy are inlined together, so each caller gets its own specialised loop):
 * - node: which slots of a wide node to enter, with the key that orders them
 *   (nearest entered first, the others stacked farthest first), the key that
 *   drops a stacked slot on pop and, for a packet, the lanes that enter it;
 * - leaf: tests a leaf's triangles; true ends the traversal (an any-hit query);
 * - best: the best t so far (a packet: its lanes' largest), above which a
 *   stacked slot is dropped on pop.
 * A policy only reads the tree and writes its own state: one traversal touches
 * nothing shared. Nodes and leaves are references of accel/bvh_levels.h (with
 * instances, an instance's node comes moved to world space; a leaf's positions
 * go through bvh_leaf_at or bvh_prim_at). */
#ifndef RR_BVH_TRACE_H
#define RR_BVH_TRACE_H

#include "accel/bvh_levels.h"
#include "core/simd.h"
#include "vis/vis.h"

#include <stddef.h>
#include <string.h>

#define RAY_MARGIN 0x1p-10f /* relative widening of box intervals (about 1e-3) */

/* A ray prepared for the slab tests of a wide node: origin and inverse direction
 * broadcast to four lanes, and per axis the byte offsets in a bvh_wide of the
 * near and far planes' lanes (lo or hi, by the direction's sign). */
typedef struct {
  rr_vf4 o[3], inv[3];
  int wn[3], wf[3];
} ray_q;

KERNEL void ray_q_init(ray_q *q, vec3 o, vec3 d) {
  float dv[3] = {d.x, d.y, d.z}, ov[3] = {o.x, o.y, o.z};
  for (int a = 0; a < 3; a++) {
    float inv = 1.0f / dv[a]; /* ±inf for a zero component, by its sign */
    bool neg = inv < 0;
    q->wn[a] = (int)(neg ? offsetof(bvh_wide, hi[a]) : offsetof(bvh_wide, lo[a]));
    q->wf[a] = (int)(neg ? offsetof(bvh_wide, lo[a]) : offsetof(bvh_wide, hi[a]));
    q->o[a] = rr_vf4_splat(ov[a]);
    q->inv[a] = rr_vf4_splat(inv);
  }
}

/* The slab test of the ray against the four boxes of a wide node, the interval
 * widened by RAY_MARGIN relative to t. Returns the slots whose box the ray meets
 * with exit >= tmin and whose `key` (per slot) is not above `best`; the widened
 * entries go to tn. A NaN slab (0·inf: the origin on a plane the ray runs in)
 * is ignored: min and max keep their second operand. */
KERNEL int wide_test(const bvh_wide *w, const ray_q *q, float tmin, rr_vf4 key, float best, rr_vf4 *tn) {
  const char *base = (const char *)w;
  rr_vf4 t0 = rr_vf4_splat(-INFINITY), t1 = rr_vf4_splat(INFINITY);
  for (int a = 0; a < 3; a++) {
    rr_vf4 tnear = (rr_vf4_load_aligned((const float *)(base + q->wn[a])) - q->o[a]) * q->inv[a];
    rr_vf4 tfar = (rr_vf4_load_aligned((const float *)(base + q->wf[a])) - q->o[a]) * q->inv[a];
    t0 = rr_vf4_max(tnear, t0);
    t1 = rr_vf4_min(tfar, t1);
  }
  const rr_vf4 margin = rr_vf4_splat(RAY_MARGIN);
  t0 = t0 - rr_vf4_abs(t0) * margin;
  t1 = t1 + rr_vf4_abs(t1) * margin;
  *tn = t0;
  return rr_vi4_bits((t0 <= t1) & (t1 >= rr_vf4_splat(tmin)) & (key <= rr_vf4_splat(best)));
}

/* What a policy's node test says of the slots it enters (bit i of its result). */
typedef struct {
  rr_vf4 order;      /* the nearest is entered, the others stacked farthest first */
  rr_vf4 key;        /* a stacked slot is dropped on pop when its key is above best() */
  uint64_t lanes[4]; /* the lanes that enter each slot (a single ray: left as they are) */
  const uint32_t *ref, *count; /* the slots' references, from a node test that reads no node (bvh_trace_nodes) */
} trace_slots;

/* The policy: q is the traced ray's or packet's state, `lanes` the lanes of it
 * that reached this node or leaf. */
typedef int (*trace_node_fn)(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s);
typedef bool (*trace_leaf_fn)(void *q, uint32_t first, uint32_t count, uint64_t lanes);
typedef float (*trace_best_fn)(const void *q);

/* The non-empty slots of a wide node's references: what N counts for a node test. */
KERNEL uint64_t refs_slots(const uint32_t ref[4]) {
  rr_vi4 r;
  memcpy(&r, ref, sizeof r);
  /* one compare for the four; the count of the four bits from a table of nibbles */
  return 0x4332322132212110ull >> (4 * rr_vi4_bits(r != -1)) & 0xF;
}

KERNEL uint64_t wide_slots(const bvh_wide *w) { return refs_slots(w->ref); }

/* Front-to-back traversal of the 4-wide tree from its root with `lanes`: the
 * slots the node test enters, in order, the nearest visited and the others
 * stacked, each dropped on pop when best() is already nearer than its key
 * (strictly: an equal t with a lower id still wins). True when leaf() ended it.
 * `boxes` false: the tree is not read at all; node() gets no node (w NULL) and
 * gives the slots' references itself in s->ref, s->count (a per-frame copy next
 * to its own bounds: one read, and an instance's references moved once a frame
 * rather than at every visit). */
KERNEL bool bvh_trace_nodes(const rr_bvh *b, void *q, uint64_t lanes, trace_node_fn node, trace_leaf_fn leaf,
                            trace_best_fn best, const bool boxes) {
  struct {
    uint32_t ref, count;
    float key;
  } stack[3 * BVH_STACK];
  uint64_t stack_lanes[3 * BVH_STACK]; /* apart: a single ray never reads it and its stack stays small */
  int sp = 0;
  uint32_t ref = 0, count = 0; /* wide node 0 */
  for (;;) {
    if (count) {
      if (leaf(q, ref, count, lanes)) return true;
    } else {
      BVH_NODE_ALIGN bvh_wide buf; /* an instance's node, moved to world space (accel/bvh_levels.h) */
      const bvh_wide *w = boxes ? bvh_wide_at(b, ref, &buf) : NULL;
      trace_slots s = {.lanes = {lanes, lanes, lanes, lanes}};
      int hits = node(q, w, ref, lanes, &s);
      const uint32_t *wref = boxes ? w->ref : s.ref, *wcount = boxes ? w->count : s.count;
      if (hits) {
        int i = __builtin_ctz(hits), rest = hits & (hits - 1);
        if (rest && !(rest & (rest - 1))) { /* two (the common case): the nearer entered, the other stacked */
          int k = __builtin_ctz(rest), far = s.order[i] < s.order[k] ? k : i;
          i ^= k ^ far;
          stack[sp].ref = wref[far], stack[sp].count = wcount[far], stack[sp].key = s.key[far];
          stack_lanes[sp++] = s.lanes[far];
        } else if (rest) { /* more: the nearest entered, the others stacked farthest first */
          int order[4], n = 0;
          for (int h = hits; h; h &= h - 1) {
            int k = __builtin_ctz(h), j = n++;
            for (; j > 0 && s.order[order[j - 1]] < s.order[k]; j--) order[j] = order[j - 1];
            order[j] = k;
          }
          for (int j = 0; j < n - 1; j++) {
            int k = order[j];
            stack[sp].ref = wref[k], stack[sp].count = wcount[k], stack[sp].key = s.key[k];
            stack_lanes[sp++] = s.lanes[k];
          }
          i = order[n - 1];
        }
        ref = wref[i], count = wcount[i], lanes = s.lanes[i];
        continue;
      }
    }
    for (;;) {
      if (!sp) return false;
      sp--;
      if (!(stack[sp].key > best(q))) break; /* equal t may still win on id */
    }
    ref = stack[sp].ref, count = stack[sp].count, lanes = stack_lanes[sp];
  }
}

/* bvh_trace_nodes for a node test that reads the boxes. */
KERNEL bool bvh_trace(const rr_bvh *b, void *q, uint64_t lanes, trace_node_fn node, trace_leaf_fn leaf,
                      trace_best_fn best) {
  return bvh_trace_nodes(b, q, lanes, node, leaf, best, true);
}

#endif
