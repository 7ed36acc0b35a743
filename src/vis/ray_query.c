/* The public ray queries rr_intersect and rr_occluded: one arbitrary ray through
 * the committed scene's BVH, by the traversal of every ray caster
 * (vis/bvh_trace.h). Each triangle a leaf holds is set up for the ray (a
 * pseudo-camera at its origin, rr_cam_for_ray) and tested with the project's one
 * sample test, so a ray through a shared edge hits exactly one triangle.
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
 * so any number of threads may trace rays through one committed scene. */
#include "vis/bvh_trace.h"

/* An arbitrary ray: its slab-test form, range, best hit and pseudo-camera. */
typedef struct {
  ray_q q;
  float tmin;
  float t, l1, l2; /* best hit so far; t starts at tmax */
  uint32_t id;
  const rr_scene *s;
  const rr_bvh *b; /* NULL for an empty scene: every ray misses */
  camera cam;
} query_ray;

/* The slots whose box the ray meets within [tmin, best t], nearest entry first;
 * the entry is also the key that drops a stacked slot. */
KERNEL int query_node(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)ref, (void)lanes;
  query_ray *r = q;
  int hits = wide_test(w, &r->q, r->tmin, rr_vf4_splat(0), INFINITY, &s->order);
  s->key = s->order;
  return hits & rr_vi4_bits(s->order <= rr_vf4_splat(r->t));
}

/* Tests a leaf's triangles, keeping the nearest hit; `any`: stops at the first. */
KERNEL bool query_leaf(query_ray *r, uint32_t first, uint32_t count, const bool any) {
  for (uint32_t i = first; i < first + count; i++) {
    uint32_t id = r->b->prims[i];
    float t, l1, l2;
    if (!rr_tri_ray_hit(r->s, id, &r->cam, false, r->tmin, r->t, &t, &l1, &l2)) continue;
    if (any) return true;
    if (depth_wins(t, id, r->t, r->id)) r->t = t, r->id = id, r->l1 = l1, r->l2 = l2;
  }
  return false;
}

KERNEL bool query_leaf_closest(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  (void)lanes;
  return query_leaf(q, first, count, false);
}

KERNEL bool query_leaf_any(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  (void)lanes;
  return query_leaf(q, first, count, true);
}

KERNEL float query_best(const void *q) { return ((const query_ray *)q)->t; }

/* Checks a query's arguments and prepares its ray; errors go to dev only. */
static rr_error query_begin(rr_device *dev, const char *fn, const rr_scene *s, const rr_ray *ray, const void *out,
                            query_ray *r) {
  if (!s || !ray || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: NULL scene, ray or result", fn);
  for (int a = 0; a < 3; a++)
    if (!isfinite(ray->org[a]) || !isfinite(ray->dir[a]))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: ray with a non-finite origin or direction", fn);
  if (ray->dir[0] == 0 && ray->dir[1] == 0 && ray->dir[2] == 0)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: ray with a zero direction", fn);
  if (isnan(ray->tmin) || isnan(ray->tmax)) return rr_fail(dev, RR_ERROR_ARGUMENT, "%s: ray with a NaN range", fn);
  bool empty;
  r->b = rr_bvh_of(dev, s, &empty);
  if (!r->b && !empty) return RR_ERROR_ARGUMENT; /* a scene changed since its commit: rr_bvh_of said so */
  r->s = s;
  rr_cam_for_ray(ray->org, ray->dir, &r->cam);
  ray_q_init(&r->q, r->cam.eye, r->cam.d0);
  r->tmin = ray->tmin, r->t = ray->tmax, r->id = RR_MISS, r->l1 = r->l2 = 0;
  return RR_OK;
}

rr_error rr_intersect(rr_device *dev, const rr_scene *scene, const rr_ray *ray, rr_hit *hit) {
  if (hit) *hit = rr_scene_hit(scene, RR_MISS, INFINITY, 0, 0);
  query_ray r;
  rr_error e = query_begin(dev, "rr_intersect", scene, ray, hit, &r);
  if (e) return e;
  if (r.b) bvh_trace(r.b, &r, 1, query_node, query_leaf_closest, query_best);
  if (r.id != RR_MISS) *hit = rr_scene_hit(scene, r.id, r.t, r.l1, r.l2);
  return rr_ok(dev);
}

rr_error rr_occluded(rr_device *dev, const rr_scene *scene, const rr_ray *ray, int *occluded) {
  if (occluded) *occluded = 0;
  query_ray r;
  rr_error e = query_begin(dev, "rr_occluded", scene, ray, occluded, &r);
  if (e) return e;
  if (r.b) *occluded = bvh_trace(r.b, &r, 1, query_node, query_leaf_any, query_best);
  return rr_ok(dev);
}
