/* Instances: one mesh of a scene drawn n times, each copy with its own affine
 * transform (Embree's instance geometry, one level deep).
 *
 * Index space. The mesh is stored once, at storage indices [base, base + T); in the
 * index space every method sees (the BVH's references, the visibility buffer,
 * shading) it takes [base, base + n·T): instance k's triangle i is base + k·T + i,
 * and the primitives stored after the mesh follow at base + n·T onwards. So the
 * indices, ids and geometries are those of the same mesh copied n times in a row
 * (the grid built-in's flattened scene), and every method that reads a triangle
 * through scene_vertex and friends (scene/scene.h) works unchanged.
 *
 * Bit-identity. An instance triangle's corners are its stored corners moved to world
 * space by inst_point alone, and then go through the ordinary world setup: every
 * method sees the very floats a flattened scene built with inst_point holds, so the
 * methods agree bit for bit, edges stay watertight and the bounds' proofs hold. */
#ifndef RR_INSTANCE_H
#define RR_INSTANCE_H

#include "core/core.h"

typedef struct scene_instances {
  uint32_t base; /* storage (and index) of the mesh's first triangle */
  uint32_t T;    /* triangles of the mesh (kept ones) */
  uint32_t F;    /* faces of the mesh, dropped ones too: instance k's ids are its ids + k·F */
  uint32_t face0; /* the id of the mesh's first face (instance 0's) */
  uint32_t G;    /* geometries of the mesh: instance k's are the mesh's + k·G */
  uint32_t n;    /* instances */
  float (*xf)[12];  /* per instance: the 3×4 row-major transform object -> world */
  float (*nxf)[9];  /* per instance: the inverse transpose of its 3×3 part, for normals */
  uint8_t *shift;   /* per instance: 1 when the 3×3 part is the identity (a translation) */
} scene_instances;

/* A point p moved by transform m (shift: m is a translation). The one function every
 * path uses for instance corners, and the flattened grid for its copies. */
static inline vec3 inst_point(const float m[12], bool shift, vec3 p) {
  if (shift) return v3(p.x + m[3], p.y + m[7], p.z + m[11]);
  return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* A direction d moved by a 3×3 matrix n (row-major), e.g. a normal by nxf. */
static inline vec3 inst_dir(const float n[9], vec3 d) {
  return v3(n[0] * d.x + n[1] * d.y + n[2] * d.z, n[3] * d.x + n[4] * d.y + n[5] * d.z,
            n[6] * d.x + n[7] * d.y + n[8] * d.z);
}

/* Why transform m (3×4 row-major) cannot place an instance (not finite, singular,
 * mirroring, or taking the box lo..hi beyond 1e30), or NULL. */
const char *rr_instance_problem(const float m[12], vec3 lo, vec3 hi);

/* Turns the triangles stored from index `first` to the end (one mesh just loaded, F
 * faces counted from its first id, its geometries from g0 on) into n instances with
 * transforms xf[k] (12 floats each, checked by rr_instance_problem; the message
 * names instance k). The geometries are repeated per instance. The scene may hold
 * one instanced mesh, with triangles only (no analytic primitives, no corners at
 * infinity). Nothing changes on failure. */
rr_error rr_scene_instance(rr_scene *s, uint32_t first, uint64_t F, uint32_t g0, uint32_t n, const float (*xf)[12]);

/* Instance k's transform to m (12 floats, checked by rr_instance_problem); the
 * caller updates the scene's bounds (rr_scene_update_bounds) after the last. */
rr_error rr_instance_set(rr_scene *s, uint32_t k, const float m[12]);

/* Bytes the instances take (their transforms). */
static inline uint64_t rr_instance_bytes(const scene_instances *in) {
  return in ? sizeof *in + (uint64_t)in->n * (sizeof *in->xf + sizeof *in->nxf + sizeof *in->shift) : 0;
}

static inline void rr_instance_free(scene_instances *in) {
  if (!in) return;
  free(in->xf), free(in->nxf), free(in->shift);
  free(in);
}

#endif
