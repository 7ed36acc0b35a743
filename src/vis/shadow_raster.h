/* Shadows by rasterization from the light (vis/shadow_raster.c). */
#ifndef RR_SHADOW_RASTER_H
#define RR_SHADOW_RASTER_H

#include "accel/bvh.h"

/* What a rasterization from the light did: bins of samples, BVH slots tested,
 * triangles and analytic primitives set up for a bin (S), edge tests at a sample or
 * a bin's corners (E). */
typedef struct rr_shadow_counts {
  uint64_t bins, nodes, setups, edge_evals;
} rr_shadow_counts;

/* occluded[k] for rays[0..n-1] through s's tree b (NULL: an empty scene), the
 * same bit rr_occluded gives each ray, on `threads` threads. The rays that share
 * the first valid ray's origin (a point light: a camera there) or, when the second
 * shares its direction and not its origin, its direction (a directional light: an
 * orthographic camera) are
 * rasterized; the others are traced one at a time, and a ray rr_occluded refuses
 * is not occluded (rr_occluded_stream's rule). False when memory runs out
 * (occluded is then incomplete). counts may be NULL. */
bool rr_occluded_raster(const rr_scene *s, const rr_bvh *b, const rr_ray *rays, size_t n, int threads, int *occluded,
                        rr_shadow_counts *counts);

#endif
