/* Bounding volume hierarchy: not built yet (the ray-casting issue adds it). */
#include "rr.h"

rr_error rr_scene_commit(rr_scene *s) {
  if (!s) return RR_ERROR_ARGUMENT;
  return rr_ok(s->dev);
}

void scene_free_bvh(rr_scene *s) { (void)s; }

void bvh_fill_info(const rr_scene *s, rr_scene_info *info) { (void)s, (void)info; }
