/* Primitive kinds. Every geometry of a scene holds primitives of one kind, and a kind
 * plugs into every method with its setup and sample test, bounds and t floor
 * (triangles: prim/triangle.h; spheres, planes and boxes come later). The kinds are
 * the public rr_geometry_kind, so the API reports a geometry's kind as stored. */
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
