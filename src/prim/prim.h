/* Primitive kinds. Every geometry of a scene holds primitives of one kind, and a kind
 * plugs into every method with its setup and sample test, bounds and t floor
 * (triangles: prim/triangle.h; spheres, planes and boxes come later). The kinds are
 * the public rr_geometry_kind, so the API reports a geometry's kind as stored.
 *
 * What a kind provides, and the triangle's of each (prim/triangle.h):
 *   world bounds, for the BVH                     rr_tri_box
 *   setup for an eye or a ray's origin            rr_tri_setup, rr_tri_setup_run (W at a time)
 *   the one sample test on a setup                sample_test_w (vis/: shade_sample_w)
 *   screen bounds (planar), for binning/culling   rr_tri_corner_bounds, rr_tri_screen_bounds
 *   cone bounds (curved views)                    rr_tri_cone_setup, rr_cone_excludes
 *   the least t over an image, for early-z        rr_tri_bounds
 * Methods call these per leaf or per batch of one kind; with triangles the only kind
 * they call the triangle's directly, and the second kind adds the dispatch. */
#ifndef RR_PRIM_H
#define RR_PRIM_H

#include "rastray.h"

typedef rr_geometry_kind prim_kind;

/* The kind's name, NULL when out of range. */
static inline const char *prim_kind_name(int kind) {
  static const char *const names[RR_GEOMETRY_KIND_COUNT] = {"triangle"};
  return kind >= 0 && kind < RR_GEOMETRY_KIND_COUNT ? names[kind] : NULL;
}

#endif
