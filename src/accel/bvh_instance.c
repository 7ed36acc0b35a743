/* The BVH of a scene with instances (accel/bvh.h, scene/instance.h): two levels.
 *
 * The instanced mesh's tree is built once, by rr_bvh_build, over a view of its stored
 * triangles (object space), with every form the traversals read (binary, 4- and
 * 8-wide nodes, the leaves' corners): rr_bvh.obj. Over it, a small top tree of the
 * items (the instances' world boxes and the scene's other primitives, split at the
 * median of the widest axis of their centres), finished by rr_bvh_finish like any
 * other tree with each instance a leaf marked BVH_INST. Then each such leaf becomes a
 * reference to instance k's copy of the object tree's root, in all three forms: a
 * binary node takes the root's world node itself (its children then instance k's),
 * a wide slot names instance k's root wide node. Nothing is copied per instance:
 * traversals make instance k's nodes and leaves on the way (accel/bvh_levels.h, which
 * also says why its world boxes hold what they must).
 *
 * Depth: the top's median split is at most 32 deep and the object tree's at most
 * BVH_SAH_DEPTH (48, accel/bvh.c) + 32, so a traversal's path stays within BVH_STACK levels.
 *
 * Memory: the object tree once, the top's few nodes, and per instance nothing but its
 * transform (in the scene). Per-frame state indexed by node or position (rc-bvh's
 * bounds) is sized by the references (rr_bvh.vwide, vpos), as for the scene written
 * out. */
#include "accel/bvh.h"
#include "accel/bvh_levels.h"
#include "scene/scene.h"

#include <string.h>

typedef struct item {
  float lo[3], hi[3];
  float key;      /* the centre along the axis being sorted on (twice it) */
  uint32_t ref;   /* an instance, or an index of the scene (a primitive of its own) */
  bool instance;
} item;

typedef struct top_build {
  const rr_scene *s;
  rr_bvh *b;
  uint32_t next_node; /* the next free pair */
  uint32_t next_prim; /* the next free range of prims */
} top_build;

static int by_key(const void *a, const void *b) {
  const item *x = a, *y = b;
  return (x->key > y->key) - (x->key < y->key);
}

/* The tree over items[0 .. n) into slot `at`. */
static void build_top(top_build *g, item *items, uint32_t n, uint32_t at, uint32_t depth) {
  bvh_node *dst = &g->b->nodes[at];
  if (n == 1) {
    const item *it = items;
    /* a leaf: one primitive, or an instance (BVH_INST, its number in prims) */
    memcpy(dst->lo, it->lo, sizeof dst->lo), memcpy(dst->hi, it->hi, sizeof dst->hi);
    g->b->prims[g->next_prim] = it->ref;
    dst->first = g->next_prim++, dst->count = it->instance ? BVH_INST : 1;
    g->b->nleaves++;
    g->b->depth = depth > g->b->depth ? depth : g->b->depth;
    return;
  }
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) {
      lo[a] = fminf(lo[a], items[i].lo[a]), hi[a] = fmaxf(hi[a], items[i].hi[a]);
      float c = items[i].lo[a] + items[i].hi[a];
      clo[a] = fminf(clo[a], c), chi[a] = fmaxf(chi[a], c);
    }
  int axis = 0;
  for (int a = 1; a < 3; a++)
    if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
  for (uint32_t i = 0; i < n; i++) items[i].key = items[i].lo[axis] + items[i].hi[axis];
  qsort(items, n, sizeof *items, by_key);
  memcpy(dst->lo, lo, sizeof lo), memcpy(dst->hi, hi, sizeof hi);
  uint32_t p = g->next_node;
  g->next_node += 2;
  dst->first = p, dst->count = 0;
  build_top(g, items, n / 2, p, depth + 1);
  build_top(g, items + n / 2, n - n / 2, p + 1, depth + 1);
}

static double half_area(const float lo[3], const float hi[3]) {
  double x = (double)hi[0] - lo[0], y = (double)hi[1] - lo[1], z = (double)hi[2] - lo[2];
  return x * y + y * z + z * x;
}

/* The SAH cost of the tree the traversals see: the top's, and per instance the
 * object tree's with its areas scaled as its root's (exact for translations). */
static double two_level_sah(const rr_bvh *b, const rr_bvh *ob, const scene_instances *in) {
  double top = half_area(b->nodes[0].lo, b->nodes[0].hi), root = half_area(ob->nodes[0].lo, ob->nodes[0].hi);
  if (!(top > 0) || !(root > 0)) return b->sah_cost;
  double sum = b->sah_cost * top, per = ob->sah_cost; /* the object tree's sum over its root's area */
  for (uint32_t k = 0; k < in->n; k++) {
    float lo[3], hi[3];
    bvh_inst_box(in, k, ob->nodes[0].lo, ob->nodes[0].hi, lo, hi);
    sum += per * half_area(lo, hi);
  }
  return sum / top;
}

/* Makes the finished top tree b two-level: ob (the object tree) becomes b->obj, and
 * each instance leaf (BVH_INST) a reference to its instance's copy of ob's root. */
static void link_instances(rr_bvh *b, rr_bvh *ob, const scene_instances *in) {
  b->obj = ob, b->inst = in;
  b->vnodes = b->nnodes + in->n * ob->nnodes, b->vwide = b->nwide + in->n * ob->nwide;
  b->vwide8 = b->nwide8 + in->n * ob->nwide8, b->vpos = b->ntop + in->n * ob->nprims;
  for (uint32_t i = 0; i < b->nnodes; i++) {
    bvh_node *n = &b->nodes[i], root;
    if (n->count == BVH_INST) *n = *bvh_node_at(b, b->nnodes + b->prims[n->first] * ob->nnodes, &root);
  }
  for (uint32_t w = 0; w < b->nwide; w++)
    for (int i = 0; i < 4; i++)
      if (b->wide[w].count[i] == BVH_INST)
        b->wide[w].ref[i] = b->nwide + b->prims[b->wide[w].ref[i]] * ob->nwide, b->wide[w].count[i] = 0;
  for (uint32_t w = 0; w < b->nwide8; w++)
    for (int i = 0; i < 8; i++)
      if (b->wide8[w].count[i] == BVH_INST)
        b->wide8[w].ref[i] = b->nwide8 + b->prims[b->wide8[w].ref[i]] * ob->nwide8, b->wide8[w].count[i] = 0;
  rr_bvh_count_wide(b); /* again, with the instances' subtrees */
}

rr_error rr_bvh_build_instanced(rr_scene *s, const rr_build_options *opt, rr_bvh **out) {
  *out = NULL;
  double t0 = rr_now_ms();
  const scene_instances *in = s->inst;
  /* the mesh alone, as stored: a scene without instances over the same arrays */
  rr_scene view = *s;
  view.inst = NULL, view.bvh = NULL, view.ntris = in->T;
  view.inf = NULL, view.kind = NULL, view.ana = NULL, view.file_id = NULL;
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 3; c++) view.p[k][c] = s->p[k][c] + in->base;
  rr_bvh *ob = NULL;
  rr_error e = rr_bvh_build(&view, opt, &ob);
  if (e) return e;
  uint32_t nown = s->ntris - in->n * in->T, nitems = in->n + nown;
  /* every reference a traversal may meet must fit in 32 bits */
  uint64_t vnodes = 2 * (uint64_t)nitems + (uint64_t)in->n * ob->nnodes;
  uint64_t vwide8 = 2 * (uint64_t)nitems + (uint64_t)in->n * ob->nwide8;
  uint64_t vpos = nitems + (uint64_t)in->n * in->T;
  if (vnodes >= UINT32_MAX / 2 || vwide8 >= UINT32_MAX / 2 || vpos >= UINT32_MAX / 2) {
    rr_bvh_release(ob);
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%u instances of %u triangles are too many for one BVH", in->n, in->T);
  }
  rr_bvh *b = calloc(1, sizeof *b);
  item *items = malloc((size_t)nitems * sizeof *items);
  if (b) {
    b->nprims = nitems, b->bins = ob->bins, b->leaf_size = ob->leaf_size;
    b->node_mem = aligned_alloc(64, ((2 * (size_t)nitems + 2) * sizeof(bvh_node) + 63) & ~(size_t)63);
    b->prims = malloc((size_t)nitems * sizeof *b->prims);
  }
  if (!b || !items || !b->node_mem || !b->prims) {
    free(items), rr_bvh_release(b), rr_bvh_release(ob);
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory building the BVH of %u instances", in->n);
  }
  b->nodes = (bvh_node *)b->node_mem + 1; /* pairs start at odd indices: each on one cache line */
  b->nnodes = 2 * nitems - 1;
  uint32_t m = 0;
  for (uint32_t k = 0; k < in->n; k++, m++) {
    items[m] = (item){.ref = k, .instance = true};
    bvh_inst_box(in, k, ob->nodes[0].lo, ob->nodes[0].hi, items[m].lo, items[m].hi);
  }
  for (uint32_t i = 0; i < s->ntris; i++) {
    if (i == in->base) i += in->n * in->T;
    if (i >= s->ntris) break;
    items[m] = (item){.ref = i, .instance = false};
    if (scene_kind(s, i) == RR_GEOMETRY_TRIANGLE) rr_tri_box(s, i, items[m].lo, items[m].hi);
    else rr_ana_box(s, i, items[m].lo, items[m].hi);
    m++;
  }
  top_build g = {.s = s, .b = b, .next_node = 1};
  build_top(&g, items, nitems, 0, 0);
  free(items);
  if (!rr_bvh_finish(b, s, opt->threads ? opt->threads : rr_cpu_count())) {
    rr_bvh_release(b), rr_bvh_release(ob);
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory building the BVH of %u instances", in->n);
  }
  b->sah_cost = two_level_sah(b, ob, in);
  link_instances(b, ob, in);
  b->nprims = s->ntris;
  b->bytes += ob->bytes;
  b->nleaves += ob->nleaves - in->n; /* stored ones, as the nodes */
  b->depth += ob->depth;
  b->build_ms = rr_now_ms() - t0;
  *out = b;
  return RR_OK;
}
