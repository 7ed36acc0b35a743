/* The ray queries' traversal of the 8-wide tree (rr_bvh.wide8), written once and
 * included by vis/ray_query.c once per vector width: with AVX2 a node's eight
 * slots are one vector per plane, otherwise two four-lane halves. The template
 * reads RQ_LANES (4 or 8), RQ_VF, RQ_VI (float and int vectors of that many
 * lanes), RQ_(op) for their helpers of core/simd.h (splat, load_aligned, min,
 * max, bits), RQ_TARGET and RQ_NAME (the functions RQ_NAME_closest and
 * RQ_NAME_any); it clears them at the end.
 *
 * Front to back: the slots a node's test enters are taken nearest entry first
 * (closest hit; an any-hit query takes them from the far end of the slot order,
 * as any hit ends it),
 * the others stacked with their entry, and a stacked slot is dropped on pop when
 * the best hit is already nearer (strictly: an equal t with a lower id still
 * wins). Leaves go to query_tris, the one place a leaf's triangles are tested
 * (through query_leaf, which adds the analytic primitives, for the scene's tree). */

RQ_TARGET static bool RR_CAT(RQ_NAME, _inst_any)(query_ray *r, uint32_t root, uint32_t k);
RQ_TARGET static bool RR_CAT(RQ_NAME, _inst_closest)(query_ray *r, uint32_t root, uint32_t k);

/* The traversal from wide8 node `root` of the scene's tree or, `inst`, of the
 * object tree (rr_bvh.obj) as translated instance k's: its nodes and leaves read
 * in place, the translation added as their planes and corners are loaded (the
 * additions of bvh_levels.h's copies, so the same bits), its references left in
 * the object tree's numbering. The scene's traversal hands each translated
 * instance it enters to an instance traversal (as Embree does with an instance's
 * tree) and walks the others through bvh_levels.h's copies. */
RQ_TARGET static inline __attribute__((always_inline)) bool RR_CAT(RQ_NAME, _body)(query_ray *r, const bool any,
                                                                                     const bool inst, uint32_t root,
                                                                                     uint32_t k) {
  struct {
    uint32_t ref, count;
    float key;
  } stack[7 * BVH_STACK]; /* a level pushes at most seven; the tree is less than BVH_STACK deep */
  RQ_VF org[3], inv_n[3], inv_f[3];
#pragma GCC unroll 3
  for (int a = 0; a < 3; a++)
    org[a] = RQ_(splat)(r->org[a]), inv_n[a] = RQ_(splat)(r->inv_n[a]), inv_f[a] = RQ_(splat)(r->inv_f[a]);
  const RQ_VF tlo = RQ_(splat)(r->tlo);
  const rr_bvh *b = r->b, *o = b->obj;
  const float *shift = NULL; /* inst: the translation, x, y, z at [0], [4], [8] */
  RQ_VF sh[3];
  uint32_t idbase = 0;
  if (inst) {
    shift = b->inst->xf[k] + 3, idbase = b->inst->base + k * b->inst->T;
    for (int a = 0; a < 3; a++) sh[a] = RQ_(splat)(shift[4 * a]);
  }
  int sp = 0;
  uint32_t ref = root, count = 0;
  for (;;) {
    if (count) {
      if (inst ? query_tris(r, o->leaf_v8 + (size_t)9 * ref, o->prims + ref, idbase, shift, count, any)
               : query_leaf(r, ref, count, any))
        return true;
    } else if (!inst && ref >= b->nwide8 && b->inst->shift[k = bvh_inst_of(ref, b->nwide8, o->nwide8, &root)]) {
      /* a translated instance's root: its own traversal */
      if (any ? RR_CAT(RQ_NAME, _inst_any)(r, root, k) : RR_CAT(RQ_NAME, _inst_closest)(r, root, k)) return true;
    } else {
      /* The slab test (vis/ray_query.c: query_ray), slots in lanes. */
      BVH_NODE_ALIGN bvh_wide8 buf; /* another instance's node, moved to world space (accel/bvh_levels.h) */
      const bvh_wide8 *w = inst ? &o->wide8[ref] : bvh_wide8_at(b, ref, &buf);
      const char *base = (const char *)w;
      const RQ_VF best = RQ_(splat)(r->t);
      float entry[8] __attribute__((aligned(32)));
      unsigned hits = 0;
#pragma GCC unroll 2
      for (int h = 0; h < 8; h += RQ_LANES) {
        RQ_VF t0 = tlo, t1 = best;
#pragma GCC unroll 3
        for (int a = 0; a < 3; a++) {
          RQ_VF pn = RQ_(load_aligned)((const float *)(base + r->wn[a]) + h);
          RQ_VF pf = RQ_(load_aligned)((const float *)(base + r->wf[a]) + h);
          if (inst) pn = pn + sh[a], pf = pf + sh[a];
          t0 = RQ_(max)((pn - org[a]) * inv_n[a], t0);
          t1 = RQ_(min)((pf - org[a]) * inv_f[a], t1);
        }
        memcpy(entry + h, &t0, sizeof t0);
        hits |= (unsigned)RQ_(bits)(t0 <= t1) << h;
      }
      if (hits) {
#define RQ_PUSH(k) (stack[sp].ref = w->ref[k], stack[sp].count = w->count[k], stack[sp++].key = entry[k])
        int i = __builtin_ctz(hits);
        unsigned rest = hits & (hits - 1);
        if (rest && any) {
          /* Any hit: the far end first. A shadow ray leaves the surface it starts
           * on (which tmin excludes), and its blockers lie more often away from its
           * origin than near it. Slots keep the binary tree's order (left before
           * right along each split), so they run roughly along or against the ray:
           * the first and last entered slots' entries tell which, and the slots are
           * taken from the far end without a sort. */
          int l = 31 - __builtin_clz(hits);
          if (entry[l] > entry[i]) { /* the last entered, the others stacked first to last */
            for (rest = hits & ~(1u << l); rest; rest &= rest - 1) RQ_PUSH(__builtin_ctz(rest));
            i = l;
          } else { /* the first entered, the others stacked last to first */
            for (; rest; rest &= ~(1u << l)) {
              l = 31 - __builtin_clz(rest);
              RQ_PUSH(l);
            }
          }
        } else if (rest && (rest & (rest - 1))) { /* three or more: the nearest entered, the others stacked farthest first */
          int order[8], n = 0;
          for (unsigned m = hits; m; m &= m - 1) {
            int k = __builtin_ctz(m), j = n++;
            for (; j > 0 && entry[order[j - 1]] < entry[k]; j--) order[j] = order[j - 1];
            order[j] = k;
          }
          i = order[n - 1];
          for (int j = 0; j < n - 1; j++) RQ_PUSH(order[j]);
        } else if (rest) { /* two (the common case): the nearer entered, the other stacked */
          int k = __builtin_ctz(rest), far = entry[i] < entry[k] ? k : i;
          i ^= k ^ far;
          RQ_PUSH(far);
        }
#undef RQ_PUSH
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

/* Specialised for the two queries, the scene's tree and a translated instance's. */
RQ_TARGET static bool RR_CAT(RQ_NAME, _closest)(query_ray *r) { return RR_CAT(RQ_NAME, _body)(r, false, false, 0, 0); }
RQ_TARGET static bool RR_CAT(RQ_NAME, _any)(query_ray *r) { return RR_CAT(RQ_NAME, _body)(r, true, false, 0, 0); }
RQ_TARGET static __attribute__((noinline)) bool RR_CAT(RQ_NAME, _inst_closest)(query_ray *r, uint32_t root,
                                                                                 uint32_t k) {
  return RR_CAT(RQ_NAME, _body)(r, false, true, root, k);
}
RQ_TARGET static __attribute__((noinline)) bool RR_CAT(RQ_NAME, _inst_any)(query_ray *r, uint32_t root, uint32_t k) {
  return RR_CAT(RQ_NAME, _body)(r, true, true, root, k);
}

#undef RQ_LANES
#undef RQ_VF
#undef RQ_VI
#undef RQ_
#undef RQ_TARGET
#undef RQ_NAME
