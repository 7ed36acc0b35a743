/* Scene storage: triangles in structure-of-arrays form, geometries, materials, bounds,
 * and the cameras and lights of a file. */
#define _POSIX_C_SOURCE 200809L /* strdup */

#include "accel/bvh.h"
#include "prim/analytic.h"

#include <string.h>

rr_error rr_scene_new(rr_device *dev, rr_scene **out) {
  if (!out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_scene_new: out is NULL");
  *out = NULL;
  rr_scene *s = calloc(1, sizeof *s);
  if (!s) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory creating a scene");
  s->dev = dev;
  s->bmin = v3(INFINITY, INFINITY, INFINITY);
  s->bmax = v3(-INFINITY, -INFINITY, -INFINITY);
  s->up = v3(0, 1, 0), s->front = v3(0, 0, 1);
  *out = s;
  return rr_ok(dev);
}

void rr_scene_release(rr_scene *s) {
  if (!s) return;
  for (int k = 0; k < 3; k++) {
    for (int c = 0; c < 3; c++) free(s->p[k][c]), free(s->n[k][c]), free(s->col[k][c]);
    for (int c = 0; c < 2; c++) free(s->uv[k][c]);
  }
  free(s->material);
  free(s->file_id);
  free(s->inf);
  free(s->kind), free(s->ana);
  for (uint32_t m = 0; m < s->nmaterials; m++) {
    free(s->materials[m].name);
    free(s->materials[m].texture_path);
    rr_texture_clear(&s->materials[m].texture);
    for (int k = 0; k < RR_MAP_COUNT; k++) free(s->materials[m].maps[k]);
  }
  free(s->materials);
  free(s->geoms);
  free(s->names);
  for (uint32_t c = 0; c < s->ncameras; c++) free(s->cameras[c].name);
  free(s->cameras);
  for (uint32_t l = 0; l < s->nlights; l++) free((char *)s->lights[l].name);
  free(s->lights);
  rr_bvh_release(s->bvh);
  rr_instance_free(s->inst);
  free(s);
}

static bool resize(rr_scene *s, uint32_t cap, bool add_n, bool add_uv);

static bool grow(float **arr, uint32_t cap) {
  float *p = realloc(*arr, (size_t)cap * sizeof **arr);
  if (!p) return false;
  *arr = p;
  return true;
}

rr_error rr_scene_reserve(rr_scene *s, uint32_t more, bool with_normals, bool with_uvs) {
  uint64_t need = (uint64_t)scene_stored(s) + more;
  if (scene_faces(s) + more > UINT32_MAX - 1) /* every id, dropped faces' too, below RR_MISS */
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "scene too large: %llu triangles",
                   (unsigned long long)(scene_faces(s) + more));
  if (s->max_tris && need > s->max_tris)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "scene too large: %llu triangles, over the limit of %llu",
                   (unsigned long long)need, (unsigned long long)s->max_tris);
  /* Attribute arrays appear when the first mesh that has them arrives; earlier
   * triangles get zeros so the arrays stay aligned with the positions. */
  bool add_n = with_normals && !s->n[0][0], add_uv = with_uvs && !s->uv[0][0];
  uint32_t cap = s->cap;
  if (need > cap) {
    cap = cap ? cap : 1024;
    while (cap < need) cap = cap > UINT32_MAX / 2 ? UINT32_MAX - 1 : cap * 2;
  }
  if (cap == s->cap && !add_n && !add_uv) return RR_OK;
  if (!resize(s, cap, add_n, add_uv))
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for %llu triangles", (unsigned long long)need);
  return RR_OK;
}

rr_error rr_scene_reserve_inf(rr_scene *s) {
  if (s->inf) return RR_OK;
  s->inf = calloc(s->cap ? s->cap : 1, 1); /* earlier triangles are finite */
  return s->inf ? RR_OK : rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for corners at infinity");
}

rr_error rr_scene_reserve_ids(rr_scene *s) {
  if (s->file_id) return RR_OK;
  s->file_id = malloc((s->cap ? s->cap : 1) * sizeof *s->file_id);
  if (!s->file_id) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the ids of %u triangles", s->ntris);
  /* nothing was dropped before them: id = index, which scene_face_id gives for storage = id (instance.h) */
  for (uint32_t i = 0; i < scene_stored(s); i++) s->file_id[i] = i;
  return RR_OK;
}

rr_error rr_scene_reserve_colors(rr_scene *s) {
  if (s->col[0][0]) return RR_OK;
  size_t cap = s->cap ? s->cap : 1;
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 3; c++) {
      s->col[k][c] = malloc(cap * sizeof(float));
      if (!s->col[k][c]) {
        for (int j = 0; j < 9; j++) free(s->col[j / 3][j % 3]), s->col[j / 3][j % 3] = NULL;
        return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for vertex colours");
      }
      for (uint32_t i = 0; i < scene_stored(s); i++) s->col[k][c][i] = 1.0f; /* white changes nothing */
    }
  return RR_OK;
}

void rr_scene_trim(rr_scene *s) {
  if (scene_stored(s) && scene_stored(s) < s->cap) resize(s, scene_stored(s), false, false); /* on failure the arrays stay as they were */
}

/* Every per-triangle array to cap entries; add_n / add_uv start those arrays.
 * On failure each array holds at least min(cap, s->cap) entries, which s->cap then
 * says, and the arrays it was to start are not there. */
static bool resize(rr_scene *s, uint32_t cap, bool add_n, bool add_uv) {
  bool ok = true;
  for (int k = 0; k < 3; k++) {
    for (int c = 0; c < 3; c++) {
      ok = ok && grow(&s->p[k][c], cap);
      if (s->col[k][c]) ok = ok && grow(&s->col[k][c], cap);
      if (s->n[k][c] || add_n) {
        bool fresh = !s->n[k][c];
        ok = ok && grow(&s->n[k][c], cap);
        if (ok && fresh) memset(s->n[k][c], 0, (size_t)scene_stored(s) * sizeof(float));
      }
    }
    for (int c = 0; c < 2; c++) {
      if (s->uv[k][c] || add_uv) {
        bool fresh = !s->uv[k][c];
        ok = ok && grow(&s->uv[k][c], cap);
        if (ok && fresh) memset(s->uv[k][c], 0, (size_t)scene_stored(s) * sizeof(float));
      }
    }
  }
  if (ok && s->inf && cap != s->cap) {
    uint8_t *f = realloc(s->inf, cap);
    if (f) s->inf = f;
    ok = f != NULL;
  }
  if (ok && s->kind && cap != s->cap) {
    uint8_t *k = realloc(s->kind, cap);
    if (k) s->kind = k;
    float *a = k ? realloc(s->ana, (size_t)cap * ANA_FLOATS * sizeof *a) : NULL;
    if (a) s->ana = a;
    ok = a != NULL;
    /* new room is triangles: loaders that write primitives straight into the arrays
     * (copies of a mesh) then need not know about kinds */
    if (ok && cap > s->cap) memset(s->kind + s->cap, RR_GEOMETRY_TRIANGLE, cap - s->cap);
  }
  if (ok && s->file_id && cap != s->cap) {
    uint32_t *f = realloc(s->file_id, (size_t)cap * sizeof *f);
    if (f) s->file_id = f;
    ok = f != NULL;
  }
  uint32_t *m = ok ? realloc(s->material, (size_t)cap * sizeof *m) : NULL;
  if (!m) {
    for (int k = 0; k < 3; k++) {
      for (int c = 0; c < 3 && add_n; c++) free(s->n[k][c]), s->n[k][c] = NULL;
      for (int c = 0; c < 2 && add_uv; c++) free(s->uv[k][c]), s->uv[k][c] = NULL;
    }
    if (cap < s->cap) s->cap = cap;
    return false;
  }
  s->material = m;
  s->cap = cap;
  return true;
}

/* The stored id of the next primitive (the one scene_face_id turns into the next id). */
static uint32_t stored_id(const rr_scene *s) {
  return (uint32_t)(scene_faces(s) - (s->inst ? (uint64_t)(s->inst->n - 1) * s->inst->F : 0));
}

static bool finite3(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* The plane's normal from the edge vectors out of the first finite corner f: for a
 * finite corner k, p_k − p_f; for one at infinity, its direction. */
static vec3 homog_normal(const vec3 p[3], unsigned inf) {
  if (!inf) return v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
  int f = !(inf & 1u) ? 0 : !(inf & 2u) ? 1 : 2;
  int a = (f + 1) % 3, b = (f + 2) % 3;
  vec3 u = inf >> a & 1u ? p[a] : v3_sub(p[a], p[f]), v = inf >> b & 1u ? p[b] : v3_sub(p[b], p[f]);
  return v3_cross(u, v);
}

vec3 rr_scene_tri_normal(const rr_scene *s, uint32_t i) {
  vec3 p[3] = {scene_vertex(s, 0, i), scene_vertex(s, 1, i), scene_vertex(s, 2, i)};
  return homog_normal(p, scene_inf(s, i));
}

bool rr_scene_push(rr_scene *s, const vec3 p[3], const vec3 *n, const float (*uv)[2], uint32_t mat) {
  return rr_scene_push_inf(s, p, 0, n, uv, NULL, mat);
}

bool rr_scene_push_inf(rr_scene *s, const vec3 p[3], unsigned inf, const vec3 *n, const float (*uv)[2],
                       const vec3 *col, uint32_t mat) {
  /* A triangle with a non-finite coordinate or no area can never be hit
   * consistently; it is dropped and counted, not fatal. So is one whose three
   * corners are all at infinity (it lies on the plane at infinity). */
  vec3 cr = homog_normal(p, inf);
  if (!finite3(p[0]) || !finite3(p[1]) || !finite3(p[2]) || !finite3(cr) ||
      (cr.x == 0 && cr.y == 0 && cr.z == 0) || (inf & 7u) == 7u) {
    s->skipped++;
    return false;
  }
  if (scene_stored(s) >= s->cap && rr_scene_reserve(s, 1, n != NULL, uv != NULL) != RR_OK) return false;
  if ((n && !s->n[0][0]) || (uv && !s->uv[0][0]))
    if (rr_scene_reserve(s, 0, n != NULL, uv != NULL) != RR_OK) return false;
  if (inf && rr_scene_reserve_inf(s) != RR_OK) return false;
  if (col && rr_scene_reserve_colors(s) != RR_OK) return false;
  if (s->skipped && rr_scene_reserve_ids(s) != RR_OK) return false;
  if (!s->ngeoms && rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, NULL) != RR_OK) return false;
  uint32_t i = scene_stored(s);
  if (s->file_id) s->file_id[i] = stored_id(s); /* reserve keeps ids below RR_MISS */
  s->ntris++;
  if (s->inf) s->inf[i] = (uint8_t)(inf & 7u);
  for (int k = 0; k < 3; k++) {
    s->p[k][0][i] = p[k].x, s->p[k][1][i] = p[k].y, s->p[k][2][i] = p[k].z;
    if (s->n[0][0]) {
      vec3 nk = n ? n[k] : v3(0, 0, 0);
      s->n[k][0][i] = nk.x, s->n[k][1][i] = nk.y, s->n[k][2][i] = nk.z;
    }
    if (s->uv[0][0]) {
      s->uv[k][0][i] = uv ? uv[k][0] : 0;
      s->uv[k][1][i] = uv ? uv[k][1] : 0;
    }
    if (s->col[0][0]) {
      vec3 ck = col ? col[k] : v3(1, 1, 1);
      s->col[k][0][i] = ck.x, s->col[k][1][i] = ck.y, s->col[k][2][i] = ck.z;
    }
    if (inf >> k & 1u) continue;
    s->bmin = v3_min(s->bmin, p[k]);
    s->bmax = v3_max(s->bmax, p[k]);
  }
  s->material[i] = mat;
  if (s->kind) s->kind[i] = RR_GEOMETRY_TRIANGLE;
  return true;
}

uint32_t rr_scene_add_material(rr_scene *s, const float color[3], const char *texture_path) {
  rr_material *m = realloc(s->materials, (s->nmaterials + 1) * sizeof *m);
  if (!m) return UINT32_MAX;
  s->materials = m;
  rr_material *mat = &m[s->nmaterials];
  memset(mat, 0, sizeof *mat);
  memcpy(mat->color, color, sizeof mat->color);
  mat->params = (rr_material_params){.model = RR_MATERIAL_PHONG, .opacity = 1, .illum = -1, .metallic = 1, .roughness = 1};
  if (texture_path && *texture_path) {
    mat->texture_path = malloc(strlen(texture_path) + 1);
    if (!mat->texture_path) return UINT32_MAX;
    strcpy(mat->texture_path, texture_path);
  }
  return s->nmaterials++;
}

/* A malloc'd copy of name in *out (NULL for NULL or ""); false when out of memory. */
static bool copy_name(const char *name, char **out) {
  *out = NULL;
  if (!name || !*name) return true;
  *out = strdup(name);
  return *out != NULL;
}

rr_error rr_scene_name_material(rr_scene *s, uint32_t m, const char *name) {
  char *copy;
  if (!copy_name(name, &copy)) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory naming a material");
  free(s->materials[m].name);
  s->materials[m].name = copy;
  return RR_OK;
}

rr_error rr_scene_add_camera(rr_scene *s, const char *name, const file_camera *cam) {
  file_camera *p = realloc(s->cameras, (s->ncameras + 1) * sizeof *p);
  char *copy = NULL;
  if (p) s->cameras = p;
  if (!p || !copy_name(name, &copy)) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the file's cameras");
  p[s->ncameras] = *cam;
  p[s->ncameras++].name = copy;
  return RR_OK;
}

rr_error rr_scene_append_light(rr_scene *s, const rr_light_info *light) {
  rr_light_info *p = realloc(s->lights, (s->nlights + 1) * sizeof *p);
  char *name = NULL;
  if (p) s->lights = p;
  if (!p || !copy_name(light->name, &name)) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the file's lights");
  p[s->nlights] = *light;
  p[s->nlights++].name = name;
  return RR_OK;
}

/* Appends name to the name pool and gives its offset (NO_NAME for NULL or ""). */
static rr_error intern_name(rr_scene *s, const char *name, uint32_t *out) {
  if (!name || !*name) {
    *out = NO_NAME;
    return RR_OK;
  }
  size_t len = strlen(name) + 1;
  if (s->names_len + len >= NO_NAME)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "geometry names longer than 4 GiB in all");
  if (s->names_len + len > s->names_cap) {
    size_t cap = s->names_cap ? 2 * s->names_cap : 256;
    if (cap < s->names_len + len) cap = s->names_len + len;
    char *p = realloc(s->names, cap);
    if (!p) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory naming a geometry");
    s->names = p, s->names_cap = cap;
  }
  memcpy(s->names + s->names_len, name, len);
  *out = (uint32_t)s->names_len;
  s->names_len += len;
  return RR_OK;
}

static rr_error append_geometry(rr_scene *s, scene_geometry g) {
  if (s->ngeoms == s->geoms_cap) {
    uint32_t cap = s->geoms_cap ? 2 * s->geoms_cap : 16;
    scene_geometry *p = s->geoms_cap <= UINT32_MAX / 2 ? realloc(s->geoms, (size_t)cap * sizeof *p) : NULL;
    if (!p) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for %u geometries", s->ngeoms + 1);
    s->geoms = p, s->geoms_cap = cap;
  }
  s->geoms[s->ngeoms++] = g;
  return RR_OK;
}

rr_error rr_scene_open_geometry(rr_scene *s, prim_kind kind, uint32_t material, const char *name) {
  uint32_t off;
  rr_error e = intern_name(s, name, &off);
  return e ? e : append_geometry(s, (scene_geometry){s->ntris, (uint32_t)scene_faces(s), material, kind, off});
}

rr_error rr_scene_repeat_geometry(rr_scene *s, uint32_t g, uint32_t first, uint32_t face) {
  scene_geometry copy = s->geoms[g]; /* by value: appending may move the table */
  copy.first = first, copy.face = face;
  return append_geometry(s, copy);
}

rr_error rr_scene_name_geometry(rr_scene *s, uint32_t g, const char *name) {
  return intern_name(s, name, &s->geoms[g].name);
}

/* The last geometry whose first index (by_id: first id) is at or below x. geoms[0]
 * starts at 0 in both; an empty geometry starts where the next does (by index), so
 * the search passes over it. */
static uint32_t find_geometry(const rr_scene *s, uint32_t x, bool by_id) {
  uint32_t lo = 0, n = s->ngeoms;
  while (n > 1) {
    uint32_t half = n / 2;
    const scene_geometry *g = &s->geoms[lo + half];
    if ((by_id ? g->face : g->first) <= x) lo += half;
    n -= half;
  }
  return lo;
}

uint32_t rr_scene_geometry_of(const rr_scene *s, uint32_t prim) {
  return prim < s->ntris ? find_geometry(s, prim, false) : RR_MISS;
}

rr_hit rr_scene_hit(const rr_scene *s, uint32_t prim, float t, float l1, float l2) {
  if (prim == RR_MISS) return (rr_hit){.prim = RR_MISS, .t = t, .l1 = l1, .l2 = l2, .geom = RR_MISS, .inst = RR_MISS};
  return (rr_hit){.prim = scene_face_id(s, prim), .t = t, .l1 = l1, .l2 = l2, .geom = rr_scene_geometry_of(s, prim),
                  .inst = scene_instance_of(s, prim)};
}

const char *rr_geometry_kind_name(int kind) { return prim_kind_name(kind); }

rr_error rr_scene_get_geometry(const rr_scene *s, uint32_t prim, uint32_t *geom, uint32_t *local) {
  if (!s) return RR_ERROR_ARGUMENT;
  /* prim is an id: dropped faces have ids too, in the geometry they were loaded into */
  uint32_t g = prim < scene_faces(s) && s->ngeoms ? find_geometry(s, prim, true) : RR_MISS;
  if (geom) *geom = g;
  if (local) *local = g == RR_MISS ? RR_MISS : prim - s->geoms[g].face;
  if (g == RR_MISS && prim != RR_MISS)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_geometry: primitive %u out of range (%llu in the scene)",
                   prim, (unsigned long long)scene_faces(s));
  return RR_OK;
}

rr_error rr_scene_get_geometry_info(const rr_scene *s, uint32_t geom, rr_geometry_info *info) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (!info) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_geometry_info: info is NULL");
  if (geom >= s->ngeoms)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_geometry_info: geometry %u out of range (%u in the scene)",
                   geom, s->ngeoms);
  const scene_geometry *g = &s->geoms[geom];
  uint32_t end = geom + 1 < s->ngeoms ? s->geoms[geom + 1].face : (uint32_t)scene_faces(s);
  *info = (rr_geometry_info){g->kind, g->face, end - g->face, g->material,
                             g->name == NO_NAME ? NULL : s->names + g->name};
  return RR_OK;
}

void rr_scene_update_bounds(rr_scene *s) {
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t i = 0; i < s->ntris; i++)
    for (int k = 0; k < 3; k++) {
      if (scene_inf(s, i) >> k & 1u) continue;
      vec3 p = scene_vertex(s, k, i);
      lo = v3_min(lo, p);
      hi = v3_max(hi, p);
    }
  for (uint32_t i = 0; s->kind && i < s->ntris; i++)
    if (scene_kind(s, i) == RR_GEOMETRY_SPHERE || scene_kind(s, i) == RR_GEOMETRY_BOX) {
      float blo[3], bhi[3];
      rr_ana_box(s, i, blo, bhi);
      lo = v3_min(lo, v3_load(blo)), hi = v3_max(hi, v3_load(bhi));
    }
  s->bmin = lo;
  s->bmax = hi;
}

/* Appends an indexed mesh of `stride` floats per vertex: xyz, or xyzw where w = 0
 * is a point at infinity in direction xyz and other w are divided through, with
 * optional linear RGB vertex colours. The indices are checked first, so a bad mesh
 * adds nothing. */
static rr_error add_mesh(rr_scene *s, const char *api, const float *pos, int stride, size_t nvert,
                         const uint32_t *idx, size_t ntri, const float rgb[3], const float *vrgb) {
  if (!s) return RR_ERROR_ARGUMENT;
  if ((!pos && nvert) || (!idx && ntri)) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: NULL positions or indices", api);
  if (ntri > UINT32_MAX) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: too many triangles", api);
  bool inf = false;
  for (size_t t = 0; t < 3 * ntri; t++) {
    if (idx[t] >= nvert)
      return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: index %u of triangle %zu out of range (%zu vertices)", api,
                     idx[t], t / 3, nvert);
    inf = inf || (stride == 4 && pos[4 * (size_t)idx[t] + 3] == 0);
  }
  for (size_t c = 0; vrgb && c < 3 * nvert; c++)
    if (!isfinite(vrgb[c])) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: vertex colour %zu is not finite", api, c / 3);
  /* Vertex colours multiply into the base colour: white unless the caller says. */
  float grey[3] = {SCENE_GREY, SCENE_GREY, SCENE_GREY}, white[3] = {1, 1, 1};
  uint32_t mat = rr_scene_add_material(s, rgb ? rgb : vrgb ? white : grey, NULL);
  if (mat == UINT32_MAX) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding a material");
  rr_error e = rr_scene_reserve(s, (uint32_t)ntri, false, false);
  if (!e && inf) e = rr_scene_reserve_inf(s);
  if (!e && vrgb) e = rr_scene_reserve_colors(s);
  if (!e) e = rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, NULL);
  if (e) return e;
  for (size_t t = 0; t < ntri; t++) {
    vec3 p[3], col[3];
    unsigned inf = 0;
    for (int k = 0; k < 3; k++) {
      const float *v = pos + stride * (size_t)idx[3 * t + k];
      if (vrgb) col[k] = v3_load(vrgb + 3 * (size_t)idx[3 * t + k]);
      float w = stride == 4 ? v[3] : 1.0f;
      if (w == 0) inf |= 1u << k, p[k] = v3(v[0], v[1], v[2]); /* a point at infinity: its direction */
      else p[k] = v3(v[0] / w, v[1] / w, v[2] / w); /* exact for w = 1 */
    }
    rr_scene_push_inf(s, p, inf, NULL, NULL, vrgb ? col : NULL, mat);
  }
  return rr_ok(s->dev);
}

rr_error rr_scene_add_mesh(rr_scene *s, const float *pos, size_t nvert, const uint32_t *idx, size_t ntri,
                           const float rgb[3]) {
  return add_mesh(s, "rr_scene_add_mesh", pos, 3, nvert, idx, ntri, rgb, NULL);
}

rr_error rr_scene_add_mesh_colors(rr_scene *s, const float *pos, size_t nvert, const uint32_t *idx, size_t ntri,
                                  const float rgb[3], const float *vertex_rgb) {
  return add_mesh(s, "rr_scene_add_mesh_colors", pos, 3, nvert, idx, ntri, rgb, vertex_rgb);
}

rr_error rr_scene_add_mesh4(rr_scene *s, const float *xyzw, size_t nvert, const uint32_t *idx, size_t ntri,
                            const float rgb[3]) {
  return add_mesh(s, "rr_scene_add_mesh4", xyzw, 4, nvert, idx, ntri, rgb, NULL);
}

/* Starts the kinds and parameters of analytic primitives (those so far are
 * triangles), which then grow with the other arrays. */
static rr_error reserve_kinds(rr_scene *s) {
  if (s->kind) return RR_OK;
  size_t cap = s->cap ? s->cap : 1;
  s->kind = calloc(cap, 1); /* RR_GEOMETRY_TRIANGLE is 0 */
  s->ana = calloc(cap * ANA_FLOATS, sizeof *s->ana);
  if (s->kind && s->ana) return RR_OK;
  free(s->kind), free(s->ana), s->kind = NULL, s->ana = NULL;
  return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for analytic primitives");
}

/* A box's axes (floats 6..11 of its input) made unit and orthogonal, x first (Gram–
 * Schmidt in double; the store rounds them to float, and rr_ana_box_frame's z = x × y
 * keeps the frame right-handed); false when x is zero or y is parallel to it. */
static bool box_axes(const float *a, double ax[3][3]) {
  double x[3] = {a[6], a[7], a[8]}, y[3] = {a[9], a[10], a[11]};
  double lx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  if (!(lx > 0 && lx < INFINITY)) return false;
  for (int k = 0; k < 3; k++) x[k] /= lx;
  double d = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
  for (int k = 0; k < 3; k++) y[k] -= d * x[k];
  double ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]), ly0 = sqrt((double)a[9] * a[9] + (double)a[10] * a[10] + (double)a[11] * a[11]);
  if (!(ly > 1e-6 * ly0 && ly < INFINITY)) return false;
  for (int k = 0; k < 3; k++) ax[0][k] = x[k], ax[1][k] = y[k] / ly;
  return true;
}

/* Appends `count` analytic primitives of one kind, `per` floats each, as one
 * geometry; every one is checked first (finite; a positive radius; a non-zero
 * normal), so bad input adds nothing and the message names the primitive. */
static rr_error add_analytic(rr_scene *s, const char *api, prim_kind kind, const float *v, size_t count,
                             const float rgb[3]) {
  if (!s) return RR_ERROR_ARGUMENT;
  const char *what = kind == RR_GEOMETRY_SPHERE ? "sphere" : kind == RR_GEOMETRY_PLANE ? "plane" : "box";
  int per = kind == RR_GEOMETRY_SPHERE ? 4 : kind == RR_GEOMETRY_PLANE ? 6 : 12;
  if (!v && count) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: NULL array", api);
  if (count > UINT32_MAX) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: too many %ss", api, what);
  for (size_t k = 0; k < count; k++) {
    const float *a = v + per * k;
    for (int c = 0; c < per; c++)
      if (!isfinite(a[c])) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: %s %zu has a value that is not finite", api, what, k);
    if (kind == RR_GEOMETRY_SPHERE && !(a[3] > 0))
      return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: sphere %zu has radius %g (must be positive)", api, k, (double)a[3]);
    if (kind == RR_GEOMETRY_PLANE &&
        !((double)a[3] * a[3] + (double)a[4] * a[4] + (double)a[5] * a[5] > 0)) /* (finite: checked above) */
      return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: plane %zu has a zero normal", api, k);
    if (kind == RR_GEOMETRY_BOX) {
      if (!(a[3] > 0 && a[4] > 0 && a[5] > 0))
        return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: box %zu has a half size that is not positive", api, k);
      double ax[3][3];
      if (!box_axes(a, ax))
        return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: box %zu has axes that are zero or parallel", api, k);
    }
  }
  for (size_t c = 0; rgb && c < 3; c++)
    if (!(rgb[c] >= 0 && isfinite(rgb[c]))) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "%s: a colour that is negative or not finite", api);
  float grey[3] = {SCENE_GREY, SCENE_GREY, SCENE_GREY};
  uint32_t mat = rr_scene_add_material(s, rgb ? rgb : grey, NULL);
  if (mat == UINT32_MAX) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding a material");
  rr_error e = rr_scene_reserve(s, (uint32_t)count, false, false);
  if (!e) e = reserve_kinds(s);
  if (!e && s->skipped) e = rr_scene_reserve_ids(s);
  if (!e) e = rr_scene_open_geometry(s, kind, mat, NULL);
  if (e) return e;
  for (size_t k = 0; k < count; k++) {
    const float *a = v + per * k;
    uint32_t i = scene_stored(s);
    if (s->file_id) s->file_id[i] = stored_id(s);
    s->ntris++;
    /* the triangle corners all at the centre (point): a triangle every triangle path drops */
    for (int c = 0; c < 3; c++)
      for (int j = 0; j < 3; j++) s->p[c][j][i] = a[j];
    for (int c = 0; c < 3; c++) {
      for (int j = 0; j < 3; j++) {
        if (s->n[c][j]) s->n[c][j][i] = 0;
        if (s->col[c][j]) s->col[c][j][i] = 1;
      }
      for (int j = 0; j < 2; j++)
        if (s->uv[c][j]) s->uv[c][j][i] = 0;
    }
    if (s->inf) s->inf[i] = 0;
    s->material[i] = mat;
    s->kind[i] = (uint8_t)kind;
    float *out = s->ana + (size_t)ANA_FLOATS * i;
    for (int c = 0; c < ANA_FLOATS; c++) out[c] = 0;
    if (kind == RR_GEOMETRY_SPHERE) {
      for (int c = 0; c < 4; c++) out[c] = a[c];
      s->nspheres++;
    } else if (kind == RR_GEOMETRY_BOX) {
      double ax[3][3];
      box_axes(a, ax);
      for (int c = 0; c < 6; c++) out[c] = a[c];
      for (int c = 0; c < 3; c++) out[6 + c] = (float)ax[0][c], out[9 + c] = (float)ax[1][c];
      s->nboxes++;
    } else {
      double l = sqrt((double)a[3] * a[3] + (double)a[4] * a[4] + (double)a[5] * a[5]);
      for (int c = 0; c < 3; c++) out[c] = a[c], out[3 + c] = (float)(a[3 + c] / l);
      s->nplanes++;
    }
  }
  rr_scene_update_bounds(s);
  return rr_ok(s->dev);
}

rr_error rr_scene_add_spheres(rr_scene *s, const float *spheres, size_t count, const float rgb[3]) {
  return add_analytic(s, "rr_scene_add_spheres", RR_GEOMETRY_SPHERE, spheres, count, rgb);
}

rr_error rr_scene_add_planes(rr_scene *s, const float *planes, size_t count, const float rgb[3]) {
  return add_analytic(s, "rr_scene_add_planes", RR_GEOMETRY_PLANE, planes, count, rgb);
}

rr_error rr_scene_add_boxes(rr_scene *s, const float *boxes, size_t count, const float rgb[3]) {
  return add_analytic(s, "rr_scene_add_boxes", RR_GEOMETRY_BOX, boxes, count, rgb);
}

rr_error rr_scene_get_info(const rr_scene *s, rr_scene_info *info) {
  if (!s || !info) return RR_ERROR_ARGUMENT;
  memset(info, 0, sizeof *info);
  info->triangles = s->ntris - s->nspheres - s->nplanes - s->nboxes;
  info->spheres = s->nspheres, info->planes = s->nplanes, info->boxes = s->nboxes;
  info->skipped = s->skipped;
  info->materials = s->nmaterials;
  info->geometries = s->ngeoms;
  info->bounds_min[0] = s->bmin.x, info->bounds_min[1] = s->bmin.y, info->bounds_min[2] = s->bmin.z;
  info->bounds_max[0] = s->bmax.x, info->bounds_max[1] = s->bmax.y, info->bounds_max[2] = s->bmax.z;
  for (uint32_t m = 0; m < s->nmaterials; m++) {
    rr_texture_status st = s->materials[m].texture_status;
    info->textures += st != RR_TEXTURE_NONE;
    info->textures_missing += st == RR_TEXTURE_MISSING || st == RR_TEXTURE_UNREADABLE;
  }
  info->cameras = s->ncameras, info->lights = s->nlights;
  for (uint32_t m = 0; m < s->nmaterials; m++) {
    const rr_texture *t = &s->materials[m].texture;
    info->texture_bytes += (uint64_t)t->width * t->height * (3 + (t->alpha != NULL));
    for (int l = 0; l < t->nlevels; l++) info->texture_bytes += (uint64_t)t->levels[l].width * t->levels[l].height * 8;
  }
  v3_store(info->up, s->up), v3_store(info->front, s->front);
  info->instances = s->inst ? s->inst->n : 0;
  info->stored_triangles = scene_stored(s) - s->nspheres - s->nplanes - s->nboxes;
  /* per stored primitive: positions, and what the scene has of normals, UVs, colours,
   * material, id, corners at infinity, kinds and analytic parameters */
  uint64_t per = 9 * 4 + 4 + (s->n[0][0] ? 36 : 0) + (s->uv[0][0] ? 24 : 0) + (s->col[0][0] ? 36 : 0) +
                 (s->file_id ? 4 : 0) + (s->inf ? 1 : 0) + (s->kind ? 1 + 4 * ANA_FLOATS : 0);
  info->scene_bytes = per * scene_stored(s) + rr_instance_bytes(s->inst);
  rr_bvh_fill_info(s->bvh, info);
  return RR_OK;
}

static const char *const texture_status_names[RR_TEXTURE_STATUS_COUNT] = {"none", "file", "embedded", "missing",
                                                                          "unreadable"};

void rr_texture_clear(rr_texture *t) {
  for (int l = 0; l < t->nlevels; l++) free(t->levels[l].texels);
  free(t->levels), free(t->rgb), free(t->alpha);
  t->levels = NULL, t->rgb = t->alpha = NULL, t->nlevels = t->width = t->height = 0;
}

const char *rr_texture_status_name(int status) {
  return status >= 0 && status < RR_TEXTURE_STATUS_COUNT ? texture_status_names[status] : NULL;
}

rr_error rr_scene_get_material_info(const rr_scene *s, uint32_t material, rr_material_info *info) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (!info) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_material_info: info is NULL");
  if (material >= s->nmaterials)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_material_info: material %u out of range (%u in the scene)",
                   material, s->nmaterials);
  const rr_material *m = &s->materials[material];
  *info = (rr_material_info){m->name, {m->color[0], m->color[1], m->color[2]}, m->texture_path, m->texture_status,
                             m->texture.width, m->texture.height, m->params, {NULL}};
  for (int k = 0; k < RR_MAP_COUNT; k++) info->maps[k] = m->maps[k];
  return rr_ok(s->dev);
}

static const char *const light_names[RR_LIGHT_TYPE_COUNT] = {"undefined", "directional", "point", "spot", "ambient",
                                                             "area"};

uint32_t rr_scene_index_of(const rr_scene *s, uint32_t id) {
  if (!s->file_id) return id < s->ntris ? id : RR_MISS;
  uint32_t lo = 0, hi = s->ntris;
  while (lo < hi) {
    uint32_t mid = lo + (hi - lo) / 2;
    if (scene_face_id(s, mid) < id) lo = mid + 1;
    else hi = mid;
  }
  return lo < s->ntris && scene_face_id(s, lo) == id ? lo : RR_MISS;
}

/* Why a caller's material cannot be set, or NULL. */
static const char *material_problem(const float color[3], const rr_material_params *p) {
  const float *rgb[] = {color, p ? p->specular : NULL, p ? p->ambient : NULL, p ? p->emission : NULL};
  for (int k = 0; k < 4; k++)
    for (int c = 0; rgb[k] && c < 3; c++)
      if (!(rgb[k][c] >= 0 && isfinite(rgb[k][c]))) return "a colour that is negative or not finite";
  if (!p) return NULL;
  if ((int)p->model < 0 || p->model >= RR_MATERIAL_MODEL_COUNT) return "an unknown model";
  if (!(p->shininess >= 0 && p->shininess <= 10000)) return "a shininess outside 0 .. 10000";
  if (!(p->metallic >= 0 && p->metallic <= 1 && p->roughness >= 0 && p->roughness <= 1 && p->opacity >= 0 &&
        p->opacity <= 1))
    return "a metallic, roughness or opacity outside 0 .. 1";
  return NULL;
}

rr_error rr_scene_set_material(rr_scene *s, uint32_t material, const float color[3], const rr_material_params *params) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (material >= s->nmaterials)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_set_material: material %u out of range (%u in the scene)",
                   material, s->nmaterials);
  const char *why = material_problem(color, params);
  if (why) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_set_material: %s", why);
  if (color) memcpy(s->materials[material].color, color, 3 * sizeof *color);
  if (params) s->materials[material].params = *params;
  return rr_ok(s->dev);
}

/* Why a caller's light cannot be added, or NULL; fills the unit direction and the default cone into *l. */
static const char *light_problem(rr_light_info *l) {
  if (l->type != RR_LIGHT_DIRECTIONAL && l->type != RR_LIGHT_POINT && l->type != RR_LIGHT_SPOT &&
      l->type != RR_LIGHT_AMBIENT)
    return "a type other than directional, point, spot or ambient";
  const float *v[] = {l->position, l->direction, l->color, l->ground};
  for (int k = 0; k < 4; k++)
    for (int c = 0; c < 3; c++)
      if (!isfinite(v[k][c])) return "a non-finite value";
  for (int c = 0; c < 3; c++)
    if (l->color[c] < 0 || l->ground[c] < 0) return "a negative colour";
  if (l->type == RR_LIGHT_DIRECTIONAL || l->type == RR_LIGHT_SPOT) {
    vec3 d = v3_load(l->direction);
    if (!(v3_dot(d, d) > 0)) return "a zero direction";
    v3_store(l->direction, v3_norm(d));
  }
  if (l->type == RR_LIGHT_SPOT) {
    if (l->inner_cone_deg == 0 && l->outer_cone_deg == 0) l->outer_cone_deg = 45;
    if (!(l->inner_cone_deg >= 0 && l->inner_cone_deg <= l->outer_cone_deg && l->outer_cone_deg <= 90))
      return "cone angles outside 0 <= inner <= outer <= 90 degrees";
  }
  return NULL;
}

rr_error rr_scene_add_light(rr_scene *s, const rr_light_info *light) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (!light) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_light: light is NULL");
  rr_light_info l = *light;
  const char *why = light_problem(&l);
  if (why) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_add_light: a light with %s", why);
  rr_error e = rr_scene_append_light(s, &l);
  return e ? e : rr_ok(s->dev);
}

const char *rr_material_model_name(int model) {
  static const char *const names[RR_MATERIAL_MODEL_COUNT] = {"phong", "pbr"};
  return model >= 0 && model < RR_MATERIAL_MODEL_COUNT ? names[model] : NULL;
}

const char *rr_light_type_name(int type) { return type >= 0 && type < RR_LIGHT_TYPE_COUNT ? light_names[type] : NULL; }

rr_error rr_scene_get_light(const rr_scene *s, uint32_t index, rr_light_info *info) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (!info) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_light: info is NULL");
  if (index >= s->nlights)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_light: light %u out of range (%u in the scene)", index,
                   s->nlights);
  *info = s->lights[index];
  return rr_ok(s->dev);
}

/* The scene is complete: give back spare room and build the BVH with the device's options. */
rr_error rr_scene_commit(rr_scene *s) {
  if (!s) return RR_ERROR_ARGUMENT;
  rr_build_options opt;
  rr_build_options_init(&opt);
  if (s->dev) opt = s->dev->build;
  rr_scene_trim(s);
  struct rr_bvh *b;
  rr_error e = s->inst ? rr_bvh_build_instanced(s, &opt, &b) : rr_bvh_build(s, &opt, &b); /* accel/bvh_instance.c */
  if (e) return e;
  rr_bvh_release(s->bvh);
  s->bvh = b;
  return rr_ok(s->dev);
}

rr_error rr_scene_get_normals(const rr_scene *s, const uint32_t *prims, size_t n, float *normals) {
  if (!s) return RR_ERROR_ARGUMENT;
  if (n && (!prims || !normals)) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "rr_scene_get_normals: NULL array");
  for (size_t k = 0; k < n; k++) {
    uint32_t i = rr_scene_index_of(s, prims[k]);
    prim_kind kind = i == RR_MISS ? RR_GEOMETRY_TRIANGLE : scene_kind(s, i);
    /* a sphere's normal depends on the hit (rr_ana_normal): zero here, like a miss */
    vec3 n = i == RR_MISS || kind == RR_GEOMETRY_SPHERE || kind == RR_GEOMETRY_BOX ? v3(0, 0, 0)
             : kind == RR_GEOMETRY_PLANE ? rr_ana_normal(s, i, 0, 0) : v3_norm(rr_scene_tri_normal(s, i));
    v3_store(normals + 3 * k, n);
  }
  return rr_ok(s->dev);
}
