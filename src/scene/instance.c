/* Instances: one stored mesh drawn n times with affine transforms (scene/instance.h). */
#include "prim/analytic.h"
#include "scene/scene.h"

#include <string.h>

const char *rr_instance_problem(const float m[12], vec3 lo, vec3 hi) {
  for (int c = 0; c < 12; c++)
    if (!isfinite(m[c])) return "a transform with a value that is not finite";
  double a[3][3];
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) a[r][c] = m[4 * r + c];
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  double norm = 0;
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) norm = fmax(norm, fabs(a[r][c]));
  if (!(fabs(det) > 1e-12 * norm * norm * norm)) return "a singular transform";
  /* a mirror would turn front faces into back faces (instances keep the mesh's corner order) */
  if (det < 0) return "a mirroring transform (negative determinant)";
  for (int k = 0; k < 8; k++) { /* the box's corners: the instance's world box stays finite */
    vec3 p = inst_point(m, false, v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z));
    if (!(fabsf(p.x) <= 1e30f && fabsf(p.y) <= 1e30f && fabsf(p.z) <= 1e30f))
      return "a transform that takes the mesh beyond 1e30";
  }
  return NULL;
}


/* The inverse transpose of m's 3×3 part (the cofactors over the determinant). */
static void normal_matrix(const float m[12], float out[9]) {
  double a[3][3], det;
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) a[r][c] = m[4 * r + c];
  det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
        a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      out[3 * i + j] = (float)((a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det);
    }
}

/* The mesh's box in its own space. */
static void mesh_box(const rr_scene *s, uint32_t first, uint32_t T, vec3 *lo, vec3 *hi) {
  *lo = v3(INFINITY, INFINITY, INFINITY), *hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t j = first; j < first + T; j++)
    for (int k = 0; k < 3; k++) *lo = v3_min(*lo, scene_stored_vertex(s, k, j)), *hi = v3_max(*hi, scene_stored_vertex(s, k, j));
}

/* Instance k's transform to m (checked already). */
static void set_one(scene_instances *in, uint32_t k, const float m[12]) {
  static const float id3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  memcpy(in->xf[k], m, sizeof in->xf[k]);
  normal_matrix(m, in->nxf[k]);
  const float lin[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
  in->shift[k] = memcmp(lin, id3, sizeof lin) == 0;
}

rr_error rr_instance_set(rr_scene *s, uint32_t k, const float m[12]) {
  scene_instances *in = s->inst;
  if (!in || k >= in->n) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "instance %u out of range", k);
  vec3 lo, hi;
  mesh_box(s, in->base, in->T, &lo, &hi);
  const char *why = rr_instance_problem(m, lo, hi);
  if (why) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "instance %u has %s", k, why);
  set_one(in, k, m);
  return RR_OK;
}

rr_error rr_scene_instance(rr_scene *s, uint32_t first, uint64_t F, uint32_t g0, uint32_t n, const float (*xf)[12]) {
  if (s->inst) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "a scene holds one instanced mesh (instances of a second one)");
  if (n == 0) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "no instances");
  uint32_t T = s->ntris - first;
  if (T == 0) return rr_fail(s->dev, RR_ERROR_EMPTY, "instances of a mesh without triangles");
  for (uint32_t i = first; i < s->ntris; i++)
    if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE || scene_inf(s, i))
      return rr_fail(s->dev, RR_ERROR_UNSUPPORTED,
                     "instances hold triangle meshes only (no analytic primitives, no corners at infinity)");
  vec3 lo, hi;
  mesh_box(s, first, T, &lo, &hi);
  for (uint32_t k = 0; k < n; k++) {
    const char *why = rr_instance_problem(xf[k], lo, hi);
    if (why) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "instance %u has %s", k, why);
  }
  uint64_t faces = scene_faces(s), first_face = faces - F;
  if ((uint64_t)n * T > UINT32_MAX - 1 - first || first_face + (uint64_t)n * F > UINT32_MAX - 1)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%u instances of %u triangles: too many ids (at most %u)", n, T,
                   UINT32_MAX - 1);
  /* a scene file's budget counts every instance's triangles: the BVH holds them all */
  if (s->max_tris && first + (uint64_t)n * T > s->max_tris)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%u instances of %u triangles: over the limit of %llu triangles", n, T,
                   (unsigned long long)s->max_tris);
  scene_instances *in = calloc(1, sizeof *in);
  if (in) {
    in->xf = malloc((size_t)n * sizeof *in->xf), in->nxf = malloc((size_t)n * sizeof *in->nxf);
    in->shift = malloc(n);
  }
  rr_error e = in && in->xf && in->nxf && in->shift ? RR_OK : rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for %u instances", n);
  if (!e && F != T) e = rr_scene_reserve_ids(s); /* instances' ids then differ from their indices */
  uint32_t G = s->ngeoms - g0;
  for (uint32_t k = 1; !e && k < n; k++) /* each instance's geometries, numbered as copies' would be */
    for (uint32_t g = g0; !e && g < g0 + G; g++)
      e = rr_scene_repeat_geometry(s, g, s->geoms[g].first + k * T, s->geoms[g].face + (uint32_t)(k * F));
  if (e) {
    s->ngeoms = g0 + G;
    rr_instance_free(in);
    return e;
  }
  for (uint32_t k = 0; k < n; k++) set_one(in, k, xf[k]);
  in->face0 = (uint32_t)first_face;
  in->base = first, in->T = T, in->F = (uint32_t)F, in->G = G, in->n = n;
  s->skipped += (F - T) * (uint64_t)(n - 1); /* as loading the mesh n times would */
  s->inst = in;
  s->ntris = first + n * T;
  rr_scene_update_bounds(s);
  return RR_OK;
}

rr_error rr_scene_add_instances(rr_scene *s, const float *pos, size_t nvert, const uint32_t *idx, size_t ntri,
                                const float rgb[3], const float *xf, size_t count) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (!xf && count) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_instances: NULL transforms");
  if (count == 0 || count > UINT32_MAX) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_instances: %zu instances", count);
  if (s->inst) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_instances: the scene holds instances already (one instanced mesh)");
  /* the transforms are checked before anything is added (rr_scene_instance checks again, on the kept triangles) */
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (size_t t = 0; pos && idx && t < 3 * ntri; t++)
    if (idx[t] < nvert) lo = v3_min(lo, v3_load(pos + 3 * (size_t)idx[t])), hi = v3_max(hi, v3_load(pos + 3 * (size_t)idx[t]));
  for (size_t k = 0; k < count; k++) {
    const char *why = rr_instance_problem(xf + 12 * k, lo, hi);
    if (why) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_instances: instance %zu has %s", k, why);
  }
  uint32_t t0 = s->ntris, g0 = s->ngeoms, m0 = s->nmaterials;
  uint64_t f0 = scene_faces(s);
  rr_error e = rr_scene_add_mesh(s, pos, nvert, idx, ntri, rgb);
  if (e) return e;
  if (s->ntris == t0) return rr_ok(s->dev); /* every triangle skipped: nothing to draw */
  e = rr_scene_instance(s, t0, scene_faces(s) - f0, g0, (uint32_t)count, (const float (*)[12])xf);
  if (e) { /* (out of memory, or a mesh at infinity) take the mesh back out */
    s->skipped -= scene_faces(s) - s->ntris - (f0 - t0), s->ntris = t0, s->ngeoms = g0;
    s->nmaterials = m0; /* (add_mesh's material holds no texture) */
    rr_scene_update_bounds(s);
    return e;
  }
  return rr_ok(s->dev);
}

rr_error rr_scene_get_instance(const rr_scene *s, uint32_t prim, uint32_t *instance, uint32_t *local) {
  if (!s) return RR_ERROR_ARGUMENT;
  uint32_t k = RR_MISS, l = RR_MISS;
  if (prim != RR_MISS && prim >= scene_faces(s))
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_instance: primitive %u out of range (%llu in the scene)",
                   prim, (unsigned long long)scene_faces(s));
  if (s->inst && prim != RR_MISS) {
    /* by id (a skipped face's too): instance k's ids run from the first instance's by k·F */
    uint32_t first = s->inst->face0, F = s->inst->F;
    if (prim >= first && prim - first < (uint64_t)s->inst->n * F) k = (prim - first) / F, l = (prim - first) % F;
  }
  if (instance) *instance = k;
  if (local) *local = l;
  return rr_ok(s->dev);
}

