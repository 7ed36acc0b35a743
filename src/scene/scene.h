/* Scene storage: triangles in structure-of-arrays form, materials and textures, bounds. */
#ifndef RR_SCENE_H
#define RR_SCENE_H

#include "core/core.h"

struct rr_bvh;

typedef struct rr_texture {
  int width, height; /* 0 when the file could not be read */
  uint8_t *rgb;      /* 3 bytes per texel, row 0 at the top */
} rr_texture;

typedef struct rr_material {
  float color[3];
  char *texture_path; /* NULL when the material names no texture */
  rr_texture texture;
} rr_material;

/* Triangles in structure-of-arrays form: component c of vertex k of triangle i is
 * p[k][c][i]. Normals and UVs are per triangle corner and may be NULL. */
struct rr_scene {
  rr_device *dev;
  uint32_t ntris, cap;
  float *p[3][3];
  float *n[3][3];  /* optional vertex normals */
  float *uv[3][2]; /* optional texture coordinates */
  uint32_t *material;
  rr_material *materials;
  uint32_t nmaterials;
  uint64_t skipped;
  /* Homogeneous input: bit k of inf[i] set when corner k of triangle i is a point at
   * infinity (w = 0), whose p then holds its direction; NULL when there is none. */
  uint8_t *inf;
  vec3 bmin, bmax; /* of the finite corners */
  struct rr_bvh *bvh; /* built by rr_scene_commit */
};

static inline vec3 scene_vertex(const rr_scene *s, int k, uint32_t i) {
  return v3(s->p[k][0][i], s->p[k][1][i], s->p[k][2][i]);
}

/* Which corners of triangle i lie at infinity (bit k: corner k); 0 for most. */
static inline unsigned scene_inf(const rr_scene *s, uint32_t i) { return s->inf ? s->inf[i] : 0u; }
/* Corner k of triangle i seen from `eye`: p - eye for a finite corner, the
 * direction itself for a point at infinity (where every ray from eye meets it). */
static inline vec3 scene_q(const rr_scene *s, int k, uint32_t i, vec3 eye) {
  vec3 p = scene_vertex(s, k, i);
  return scene_inf(s, i) >> k & 1u ? p : v3_sub(p, eye);
}
/* The (unnormalised) normal of triangle i's plane, for finite and infinite corners. */
vec3 rr_scene_tri_normal(const rr_scene *s, uint32_t i);

/* Grows the scene to hold `more` triangles; with_normals/with_uvs allocate those arrays. */
rr_error rr_scene_reserve(rr_scene *s, uint32_t more, bool with_normals, bool with_uvs);
/* Gives back the room reserve doubled into (at commit: the scene is complete). */
void rr_scene_trim(rr_scene *s);
/* Appends one triangle (positions, optional corner normals/uvs); drops and counts
 * degenerate or non-finite ones. Returns true when kept. */
bool rr_scene_push(rr_scene *s, const vec3 p[3], const vec3 *n, const float (*uv)[2], uint32_t mat);
/* The same with corners at infinity (bit k of inf: p[k] is a direction); a triangle
 * with all three at infinity is dropped and counted. */
bool rr_scene_push_inf(rr_scene *s, const vec3 p[3], unsigned inf, const vec3 *n, const float (*uv)[2], uint32_t mat);
/* Adds a material and returns its index (UINT32_MAX when out of memory). */
uint32_t rr_scene_add_material(rr_scene *s, const float color[3], const char *texture_path);
/* Recomputes bounds. */
void rr_scene_update_bounds(rr_scene *s);

#endif
