/* Primitive kinds. Every geometry of a scene holds primitives of one kind, and a kind
 * plugs into every method with its setup and sample test, bounds and t floor
 * (triangles: prim/triangle.h; spheres and planes: prim/analytic.h). The kinds are
 * the public rr_geometry_kind, so the API reports a geometry's kind as stored.
 *
 * What a kind provides, and the triangle's of each (prim/triangle.h):
 *   world bounds, for the BVH                     rr_tri_box
 *   setup for an eye or a ray's origin            rr_tri_setup, rr_tri_setup_run (W at a time)
 *   the one sample test on a setup                sample_test_w (vis/: shade_sample_w)
 *   screen bounds (planar), for binning/culling   rr_tri_corner_bounds, rr_tri_screen_bounds
 *   cone bounds (curved views)                    rr_tri_cone_setup, rr_cone_excludes
 *   the least t over an image, for early-z        rr_tri_bounds
 * Methods call these per leaf or per batch; the analytic kinds' (rr_ana_hit, rr_ana_box,
 * rr_ana_screen_bounds, rr_ana_cone_excludes, rr_ana_t_floor) beside the triangle's where a
 * scene holds them (s->kind not NULL), see prim/analytic.h. */
#ifndef RR_PRIM_H
#define RR_PRIM_H

#include "rastray.h"

typedef rr_geometry_kind prim_kind;

/* The kind's name, NULL when out of range. */
static inline const char *prim_kind_name(int kind) {
  static const char *const names[RR_GEOMETRY_KIND_COUNT] = {"triangle", "sphere", "plane", "box"};
  return kind >= 0 && kind < RR_GEOMETRY_KIND_COUNT ? names[kind] : NULL;
}

#endif
