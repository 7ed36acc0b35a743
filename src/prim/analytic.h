/* The analytic kinds: spheres (prim/sphere.c), infinite planes (prim/plane.c) and
 * boxes, axis-aligned or oriented (prim/box.c).
 *
 * Storage. They share the triangles' index space (ids, geometries, materials, the
 * BVH's references, the visibility buffer): primitive i of an analytic geometry
 * keeps its parameters in s->ana[i] (sphere: centre, radius; plane: a point and
 * the unit normal; box: centre, half sizes, unit axes x and y, z = x × y) and its
 * kind in s->kind[i], and its three triangle corners
 * all at the centre (point). That degenerate triangle has volume 0, so every
 * triangle path (setup, corner bounds, edge pre-tests, the 2D pipeline, shadow
 * tests) drops it as edge-on by itself; the methods add the kind's own test
 * beside the triangles' at each leaf or batch (ana_* below), nothing else.
 *
 * The one sample test. Every method turns its sample into a ray in double with
 * ana_sample_ray (the same inputs it gives the triangle test: the camera, the
 * evaluation vector w and the sample (sx, sy)), and calls rr_ana_hit, which solves
 * in double and rounds t once to float. Same inputs, same arithmetic: the same
 * bits in every method, ray casters included; rr_intersect hands its float ray
 * to the same rr_ana_hit. Ties with other primitives: depth_wins, as for triangles
 * (nearest t, then the lower index), so a sphere resting on a plane is claimed by
 * exactly one of them at every sample.
 *
 * Planes are infinite: their BVH box reaches ±PRIM_FAR along the axes the plane
 * is not perpendicular to (the concession of triangles with corners at infinity,
 * prim/triangle.h), so they stay ordinary references of the one tree and every
 * traversal keeps its finite boxes. */
#ifndef RR_ANALYTIC_H
#define RR_ANALYTIC_H

#include "camera/camera.h"

/* Floats a primitive keeps in s->ana. */
enum { ANA_FLOATS = 12 };

/* The kind of primitive i (triangles unless the scene holds analytic ones). */
static inline prim_kind scene_kind(const rr_scene *s, uint32_t i) {
  return s->kind ? (prim_kind)s->kind[scene_st(s, i)] : RR_GEOMETRY_TRIANGLE;
}

/* The ANA_FLOATS parameters of analytic primitive i (where it is stored). */
static inline const float *rr_ana_params(const rr_scene *s, uint32_t i) {
  return s->ana + (size_t)ANA_FLOATS * scene_st(s, i);
}

/* A ray in double: origin o and (unnormalised) direction d. */
typedef struct ana_ray {
  double o[3], d[3];
} ana_ray;

/* The ray of sample (sx, sy) with evaluation vector w (camera_w) of camera c:
 * perspective o = eye, d = d0 + sx·dx + sy·dy; orthographic o = eye + o0 + sx·ox
 * + sy·oy, d = fwd; curved o = eye, d = w. All in double from the camera's floats,
 * so it is the same ray whichever method asks. False where the sample has no ray. */
static inline bool ana_sample_ray(const camera *c, vec3 w, float sx, float sy, ana_ray *r) {
  const float e[3] = {c->eye.x, c->eye.y, c->eye.z};
  if (c->type == RR_CAMERA_PERSPECTIVE && c->planar) {
    const float d0[3] = {c->d0.x, c->d0.y, c->d0.z}, dx[3] = {c->dx.x, c->dx.y, c->dx.z},
                dy[3] = {c->dy.x, c->dy.y, c->dy.z};
    for (int a = 0; a < 3; a++) r->o[a] = e[a], r->d[a] = (double)d0[a] + (double)sx * dx[a] + (double)sy * dy[a];
    return true;
  }
  if (c->type == RR_CAMERA_ORTHOGRAPHIC) {
    const float o0[3] = {c->o0.x, c->o0.y, c->o0.z}, ox[3] = {c->ox.x, c->ox.y, c->ox.z},
                oy[3] = {c->oy.x, c->oy.y, c->oy.z}, f[3] = {c->fwd.x, c->fwd.y, c->fwd.z};
    for (int a = 0; a < 3; a++)
      r->o[a] = (double)e[a] + ((double)o0[a] + (double)sx * ox[a] + (double)sy * oy[a]), r->d[a] = f[a];
    return true;
  }
  const float d[3] = {w.x, w.y, w.z};
  for (int a = 0; a < 3; a++) r->o[a] = e[a], r->d[a] = d[a];
  return d[0] != 0 || d[1] != 0 || d[2] != 0;
}

/* A float ray (rr_intersect's) in double. */
static inline ana_ray ana_ray_of(const float org[3], const float dir[3]) {
  return (ana_ray){{org[0], org[1], org[2]}, {dir[0], dir[1], dir[2]}};
}

/* The one sample test of analytic primitive i: true on a hit ahead of the origin
 * (t > 0 after rounding), with t (along the unnormalised direction, rounded once
 * from double) and the hit's parametric coordinates u, v (sphere: longitude and
 * colatitude over 2π and π; plane: the hit's offset from the stored point along
 * the plane's two axes, rr_ana_plane_axes). */
bool rr_ana_hit(const rr_scene *s, uint32_t i, const ana_ray *r, float *t, float *u, float *v);
bool rr_ana_sphere_hit(const float *sp, const ana_ray *r, float *t, float *u, float *v);
bool rr_ana_plane_hit(const float *pl, const ana_ray *r, float *t, float *u, float *v);
/* (box: u = face + position along the face's first axis, face = 2·axis + (side > 0)) */
bool rr_ana_box_hit(const float *b, const ana_ray *r, float *t, float *u, float *v);
/* A box's rotation: rows x, y, z of its frame in world space. */
void rr_ana_box_frame(const float *b, double R[3][3]);
/* The plane's axes in it (unit, right-handed with the normal): what u, v measure along. */
void rr_ana_plane_axes(const float n[3], double u[3], double v[3]);

/* The unit normal at the hit with coordinates u, v (the sphere's outward one;
 * the plane's as stored), for shading. */
vec3 rr_ana_normal(const rr_scene *s, uint32_t i, float u, float v);

/* The point with coordinates u, v on primitive i: what shading takes for the hit
 * (from the coordinates, like a triangle's from its barycentrics, so a hit that
 * averages samples' coordinates stays on the surface). */
vec3 rr_ana_point(const rr_scene *s, uint32_t i, float u, float v);

/* The world box of analytic primitive i, for the BVH (rounded outwards). */
void rr_ana_box(const rr_scene *s, uint32_t i, float lo[3], float hi[3]);

/* The inclusive pixel rectangle holding every sample of planar camera c, at any
 * position inside the pixel, where primitive i may pass rr_ana_hit; false when there
 * is none. Curved cameras: the whole image (their bins use rr_ana_cone_excludes). */
bool rr_ana_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, int rect[4]);
/* May the cone of directions (unit axis, half-angle) from c's eye exclude primitive i?
 * Curved cameras: a sphere's directions form a cone about the direction to its centre
 * of half-angle asin(r / distance), exactly; a plane is seen only along directions
 * pointing to its side of the eye, a half-space. */
bool rr_ana_cone_excludes(const rr_scene *s, uint32_t i, const camera *c, vec3 axis, float angle);
/* A floor under every t that rr_ana_hit can return for primitive i at any sample of
 * camera c (any position in the pixel); INFINITY when no sample can pass. The
 * proofs are at the kinds' definitions. */
float rr_ana_t_floor(const rr_scene *s, uint32_t i, const camera *c);

/* The four rays through the corners of c's image, (0, 0), (W, 0), (0, H), (W, H),
 * which bound the samples of every position (planar cameras: every quantity
 * below that is linear in (sx, sy) takes its extremes there). */
void rr_ana_corner_rays(const camera *c, ana_ray r[4]);
/* Rounds a positive double down to a float no greater, with a relative margin for
 * the per-sample arithmetic (both in double: 1e-9 covers it many times over). */
static inline float ana_floor_f(double t) {
  if (!(t > 0)) return 0;
  float f = (float)(t * (1 - 1e-9));
  return (double)f > t ? nextafterf(f, 0) : f;
}

#endif
