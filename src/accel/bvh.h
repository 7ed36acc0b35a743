/* Acceleration: the binned-SAH BVH over a scene's triangles, its 4- and 8-wide forms
 * and leaf corner copies. A scene with instances has two levels (rr_bvh.obj: the
 * instanced mesh's tree once, in object space, under a small top tree); traversals
 * read either kind through accel/bvh_levels.h. */
#ifndef RR_BVH_H
#define RR_BVH_H

#include "prim/analytic.h"
#include "prim/triangle.h"

/* 32-byte node with its own bounds. A leaf (count > 0) holds triangles
 * bvh->prims[first .. first + count); an inner node's children are nodes[first]
 * and nodes[first + 1]. The root is node 0. */
typedef struct bvh_node {
  float lo[3], hi[3];
  uint32_t first, count;
} bvh_node;

typedef struct rr_bvh {
  bvh_node *nodes;
  uint32_t nnodes, nleaves, depth;
  uint32_t *prims; /* triangle ids in leaf order */
  double sah_cost, build_ms;
  uint64_t bytes;
  void *node_mem;  /* the allocation behind nodes (sibling pairs share a cache line) */
  uint32_t nprims; /* triangles the tree was built over (== scene->ntris when current) */
  int bins, leaf_size;
  struct bvh_wide *wide; /* the same tree collapsed to 4 children per node, for single rays */
  uint32_t *wide_node;   /* per wide node, per slot: the node of `nodes` it is (UINT32_MAX: empty) */
  uint32_t *wide_tris;   /* per wide node: the triangles of its subtree (rr_bvh_count_wide) */
  uint32_t nwide;
  struct bvh_wide8 *wide8; /* the tree collapsed to 8 children per node for the ray queries,
                             subtrees of at most four triangles joined into one leaf */
  uint32_t nwide8;
  /* The triangles' corners in leaf order, for the ray queries' leaf tests: a leaf
   * holding prims [first, first + count) has corner k's axis x of its j-th triangle
   * at leaf_v[9·first + (3k + x)·count + j], then BVH_LEAF_PAD zeros at the end, so
   * that four lanes may be loaded from any triangle. */
  float *leaf_v;
  float *leaf_v8; /* the same for the leaves of wide8, which may join a few binary leaves */
  /* Two levels (a scene with instances, accel/bvh_instance.c): the arrays above are a
   * small top tree, and a reference past them names a node of `obj`, the instanced
   * mesh's tree stored once in object space, as instance k's: binary node nnodes +
   * k·obj->nnodes + j, wide node nwide + k·obj->nwide + j, wide8 node nwide8 +
   * k·obj->nwide8 + j, leaf position ntop + k·obj->nprims + j (accel/bvh_levels.h reads
   * them). The v* totals count every reference (the arrays' own counts for one
   * level): what per-frame arrays indexed by node or position are sized by. */
  struct rr_bvh *obj;
  const struct scene_instances *inst;
  uint32_t ntop; /* positions of the top's own prims (nprims for one level) */
  uint32_t vnodes, vwide, vwide8, vpos;
} rr_bvh;

/* Marks a top leaf of a two-level tree while it is built: count BVH_INST, prims[first]
 * the instance (rr_bvh_finish skips its corners; the build then makes it a reference). */
#define BVH_INST 0x80000000u

/* A 4-wide node: up to four of the binary tree's nodes side by side, bounds as
 * lanes per axis (an empty slot has an empty box). A slot with count > 0 is a leaf
 * holding prims [ref, ref + count); with count 0 it is wide node `ref`. Root: 0. */
typedef struct bvh_wide {
  float lo[3][4], hi[3][4];
  uint32_t ref[4], count[4];
} bvh_wide;

/* An 8-wide node: up to eight of the binary tree's nodes, laid out as bvh_wide
 * (lanes per axis, an empty slot has an empty box; count > 0: a leaf holding prims
 * [ref, ref + count), else wide8 node `ref`). Four cache lines; the ray queries
 * (vis/ray_query.c) test it with one eight-lane vector per plane under AVX2, two
 * four-lane ones otherwise. Root: 0. */
typedef struct bvh_wide8 {
  float lo[3][8], hi[3][8];
  uint32_t ref[8], count[8];
} bvh_wide8;

enum { BVH_DEFAULT_BINS = 32, BVH_DEFAULT_LEAF = 4, BVH_MAX_LEAF = 64, BVH_STACK = 128, BVH_LEAF_PAD = 8 };

/* Builds a binned-SAH BVH over the scene's triangles (accel/bvh.c); the tree is the
 * same for any opt->threads. An empty scene gets NULL. (A scene with instances takes
 * rr_bvh_build_instanced, which rr_scene_commit calls: far quicker, the same hits.) */
rr_error rr_bvh_build(rr_scene *s, const rr_build_options *opt, rr_bvh **out);
/* The BVH of a scene with instances (accel/bvh_instance.c): the mesh's tree built once
 * in its own space, under a small tree over the instances and the other primitives
 * whose instance leaves refer to it (rr_bvh.obj); traversals read its nodes through
 * accel/bvh_levels.h, which moves them to world space on the way. */
rr_error rr_bvh_build_instanced(rr_scene *s, const rr_build_options *opt, rr_bvh **out);
/* Completes a binary tree (nodes, prims, nnodes, nprims set): the 4- and 8-wide
 * forms, the leaves' corners (side by side on `threads`), the SAH cost and the
 * bytes. False when out of memory. */
bool rr_bvh_finish(rr_bvh *b, const rr_scene *s, int threads);
/* Fills rr_bvh.wide_tris from the wide nodes' slots, the children first (an inner
 * slot's node always comes after its parent); a slot past the top's own nodes
 * counts the object tree's node (whose own counts must be filled). */
void rr_bvh_count_wide(rr_bvh *b);
/* The scene's BVH when it is current, else NULL with a message in dev (an empty
 * scene also gives NULL, with *empty set: every ray misses). */
const rr_bvh *rr_bvh_of(rr_device *dev, const rr_scene *s, bool *empty);

/* Frees a BVH (NULL is ignored). */
void rr_bvh_release(rr_bvh *b);
/* Adds a BVH's figures to a scene's info (NULL adds nothing). */
void rr_bvh_fill_info(const rr_bvh *b, rr_scene_info *info);

#endif
