/* The BVH of a scene with instances (accel/bvh.h, scene/instance.h).
 *
 * The instanced mesh's tree is built once, by rr_bvh_build, over a view of its stored
 * triangles (object space). Each instance gets a copy of it whose boxes are moved to
 * world space and whose leaves name the instance's triangles (base + k·T + i); a tree
 * over the items (the instances' world boxes and the scene's other primitives, split
 * at the median of the widest axis of their centres) holds the copies. The result is
 * an ordinary binary tree (children in pairs, the root alone at 0, each subtree's
 * primitives one range of prims), finished by rr_bvh_finish like any other, so every
 * traversal reads it unchanged.
 *
 * A moved box holds the world corners of its triangles (inst_point's floats), which
 * is all the traversals assume of a box: for a translation, fl(lo + t) <= fl(p + t)
 * <= fl(hi + t) for lo <= p <= hi (rounding is monotonic); for other maps, interval
 * arithmetic in double widened by far more than inst_point's rounding (five roundings
 * of at most 2^-24 of the terms' magnitudes) and rounded outward. */
#include "accel/bvh.h"
#include "scene/scene.h"

#include <string.h>

/* World box of an object-space box lo..hi under instance k. */
static void world_box(const scene_instances *in, uint32_t k, const float lo[3], const float hi[3], float wlo[3],
                      float whi[3]) {
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

typedef struct item {
  float lo[3], hi[3];
  float key;      /* the centre along the axis being sorted on (twice it) */
  uint32_t ref;   /* an instance, or an index of the scene (a primitive of its own) */
  bool instance;
} item;

typedef struct graft {
  const rr_scene *s;
  const rr_bvh *ob; /* the mesh's tree, in object space */
  rr_bvh *b;
  uint32_t next_node; /* the next free pair */
  uint32_t next_prim; /* the next free range of prims */
} graft;

/* Copies object node `o` of ob's tree as instance k's into slot `at`. */
static void copy_subtree(graft *g, uint32_t k, uint32_t o, uint32_t at, uint32_t prim0, uint32_t depth) {
  const bvh_node *src = &g->ob->nodes[o];
  bvh_node *dst = &g->b->nodes[at];
  world_box(g->s->inst, k, src->lo, src->hi, dst->lo, dst->hi);
  if (src->count) {
    dst->first = prim0 + src->first, dst->count = src->count;
    g->b->nleaves++;
    g->b->depth = depth > g->b->depth ? depth : g->b->depth;
    return;
  }
  uint32_t p = g->next_node;
  g->next_node += 2;
  dst->first = p, dst->count = 0;
  copy_subtree(g, k, src->first, p, prim0, depth + 1);
  copy_subtree(g, k, src->first + 1, p + 1, prim0, depth + 1);
}

static int by_key(const void *a, const void *b) {
  const item *x = a, *y = b;
  return (x->key > y->key) - (x->key < y->key);
}

/* The tree over items[0 .. n) into slot `at`. */
static void build_top(graft *g, item *items, uint32_t n, uint32_t at, uint32_t depth) {
  bvh_node *dst = &g->b->nodes[at];
  if (n == 1) {
    const item *it = items;
    if (it->instance) { /* the instance's copy of the mesh's tree, its triangles the next T prims */
      const scene_instances *in = g->s->inst;
      uint32_t prim0 = g->next_prim;
      for (uint32_t i = 0; i < in->T; i++) g->b->prims[prim0 + i] = in->base + it->ref * in->T + g->ob->prims[i];
      g->next_prim += in->T;
      copy_subtree(g, it->ref, 0, at, prim0, depth);
    } else {
      memcpy(dst->lo, it->lo, sizeof dst->lo), memcpy(dst->hi, it->hi, sizeof dst->hi);
      g->b->prims[g->next_prim] = it->ref;
      dst->first = g->next_prim++, dst->count = 1;
      g->b->nleaves++;
      g->b->depth = depth > g->b->depth ? depth : g->b->depth;
    }
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
  uint64_t nnodes = 2 * (uint64_t)nitems - 1 - in->n + (uint64_t)in->n * ob->nnodes;
  rr_bvh *b = calloc(1, sizeof *b);
  item *items = malloc((size_t)nitems * sizeof *items);
  if (b) {
    b->nprims = s->ntris, b->bins = ob->bins, b->leaf_size = ob->leaf_size;
    b->node_mem = nnodes < UINT32_MAX / 2 ? aligned_alloc(64, ((nnodes + 2) * sizeof(bvh_node) + 63) & ~(size_t)63) : NULL;
    b->prims = malloc((size_t)s->ntris * sizeof *b->prims);
  }
  if (!b || !items || !b->node_mem || !b->prims) {
    free(items), rr_bvh_release(b), rr_bvh_release(ob);
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory building the BVH of %u instances", in->n);
  }
  b->nodes = (bvh_node *)b->node_mem + 1; /* pairs start at odd indices: each on one cache line */
  b->nnodes = (uint32_t)nnodes;
  uint32_t m = 0;
  for (uint32_t k = 0; k < in->n; k++, m++) {
    items[m] = (item){.ref = k, .instance = true};
    world_box(in, k, ob->nodes[0].lo, ob->nodes[0].hi, items[m].lo, items[m].hi);
  }
  for (uint32_t i = 0; i < s->ntris; i++) {
    if (i == in->base) i += in->n * in->T;
    if (i >= s->ntris) break;
    items[m] = (item){.ref = i, .instance = false};
    if (scene_kind(s, i) == RR_GEOMETRY_TRIANGLE) rr_tri_box(s, i, items[m].lo, items[m].hi);
    else rr_ana_box(s, i, items[m].lo, items[m].hi);
    m++;
  }
  graft g = {.s = s, .ob = ob, .b = b, .next_node = 1};
  build_top(&g, items, nitems, 0, 0);
  free(items);
  rr_bvh_release(ob);
  if (!rr_bvh_finish(b, s, opt->threads ? opt->threads : rr_cpu_count())) {
    rr_bvh_release(b);
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory building the BVH of %u instances", in->n);
  }
  b->build_ms = rr_now_ms() - t0;
  *out = b;
  return RR_OK;
}
