/* Texture coordinates at a hit and their exact derivatives per pixel step, from
 * the camera's ray differentials: the footprint texture filtering reads. */
#ifndef RR_TEXCOORD_H
#define RR_TEXCOORD_H

#include "camera/camera.h"
#include "prim/analytic.h"
#include "shade/texture.h"

/* Whether primitive i of s has texture coordinates: a triangle when the scene has
 * UVs, an analytic primitive always (its own map, texcoord.c). */
static inline bool rr_has_texcoord(const rr_scene *s, uint32_t i) {
  return s->uv[0][0] || scene_kind(s, i) != RR_GEOMETRY_TRIANGLE;
}

/* The texture coordinates of primitive i of s (rr_has_texcoord) at the hit with
 * barycentrics (l1, l2) (an analytic primitive's: its coordinates from rr_ana_hit)
 * at parameter t along the ray (o, d), and their derivatives per pixel step from the ray's differentials do_dxy, dd_dxy (rr_cam_ray_diff;
 * NULL: derivatives 0). A corner at infinity (w = 0) holds UVs that are the change
 * of (u, v) per unit along its direction, as a point at infinity enters homogeneous
 * interpolation: a plane through the origin with corners (1, 0, 0) of UV (s, 0)
 * and (0, 0, -1) of UV (0, s) maps (x, 0, z) to s·(x, -z). */
tex_coord rr_texcoord(const rr_scene *s, uint32_t i, float l1, float l2, float t, vec3 o, vec3 d,
                      const vec3 do_dxy[2], const vec3 dd_dxy[2]);

#endif
