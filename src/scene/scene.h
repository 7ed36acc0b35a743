/* Scene storage: triangles in structure-of-arrays form, the geometries they form,
 * materials and textures, bounds. */
#ifndef RR_SCENE_H
#define RR_SCENE_H

#include "core/core.h"
#include "prim/prim.h"
#include "scene/instance.h"

struct rr_bvh;

/* The base colour of a mesh that names none (every channel). */
#define SCENE_GREY 0.8f
/* One level of a texture's MIP chain: premultiplied linear-light RGBA, 16 bits a
 * channel (0 .. 65535 for 0 .. 1), row 0 at the top. */
typedef struct tex_level {
  int width, height;
  float sx, sy;     /* width and height over level 0's */
  uint16_t *texels; /* 4 per texel */
} tex_level;

typedef struct rr_texture {
  int width, height; /* 0 when the file could not be read */
  uint8_t *rgb;      /* 3 bytes per texel (sRGB as the file has them), row 0 at the top */
  uint8_t *alpha;    /* 1 byte per texel (linear coverage); NULL when opaque */
  rr_texture_wrap wrap[2]; /* in u, in v */
  /* The MIP chain built from rgb and alpha (rr_texture_prepare): level 0 at full size,
   * each next one half as large (rounded down, at least 1), down to 1×1. */
  int nlevels;
  tex_level *levels;
} rr_texture;

/* Frees what a texture holds (its texels and MIP chain) and empties it. */
void rr_texture_clear(rr_texture *t);

typedef struct rr_material {
  char *name;         /* NULL when the file gives none */
  float color[3];
  char *texture_path; /* NULL when the material names no texture */
  rr_texture texture;
  rr_texture_status texture_status; /* where the texels came from, or why there are none */
  rr_material_params params;        /* the shading model's inputs (docs/shading.md) */
  char *maps[RR_MAP_COUNT];         /* other textures the file names (read but not yet used); NULL: none */
} rr_material;

/* A camera of the file, in world space: it looks along fwd with up (both unit and
 * orthogonal); fov is the full angle across the width (horizontal) or the height
 * (vertical, glTF's yfov), ortho_width the full width of an orthographic view (0:
 * perspective). */
typedef struct file_camera {
  char *name;
  vec3 eye, fwd, up;
  float fov; /* radians */
  bool fov_vertical;
  float ortho_width;
} file_camera;


/* A geometry: a run of primitives of one kind that a loader opened (a file's
 * node/mesh pair, an rr_scene_add_mesh call, a built-in object). Its primitives are
 * the indices from `first` up to the next geometry's first (the last one's up to
 * ntris); the geometries tile [0, ntris) in order, and an empty one (every triangle
 * dropped) has the same first as the next. Its faces (ids, below) likewise run
 * from `face` to the next one's face (the last one's to scene_faces). */
typedef struct scene_geometry {
  uint32_t first;
  uint32_t face; /* the id of its first face: faces of the scene before it, dropped ones too */
  uint32_t material; /* the material of every primitive in it */
  prim_kind kind;
  uint32_t name; /* offset of its name in the scene's name pool, NO_NAME when none */
} scene_geometry;

#define NO_NAME UINT32_MAX

/* Triangles in structure-of-arrays form: component c of vertex k of triangle i is
 * p[k][c][i]. Normals and UVs are per triangle corner and may be NULL.
 *
 * Indices and ids. The arrays hold the kept triangles only, at indices 0 .. ntris - 1,
 * and everything inside the library (BVH, methods, the visibility buffer, shading)
 * works with those indices. A triangle's id, the number users see, is its face's
 * index in load order after fan triangulation, dropped faces counted: id =
 * file_id[i] (i itself while nothing was dropped: file_id is NULL). The map only
 * grows, so the order of ids is the order of indices and ties to the lower index
 * are ties to the lower id. Ids leave the library through scene_face_id alone:
 * rr_scene_hit (ray queries), the frame's ids and the id AOV and colours, and the
 * geometry table (scene_geometry.face). */
struct rr_scene {
  rr_device *dev;
  uint32_t ntris, cap;
  float *p[3][3];
  float *n[3][3];  /* optional vertex normals */
  float *uv[3][2]; /* optional texture coordinates */
  float *col[3][3]; /* optional corner colours, linear RGB multiplied into the base colour */
  uint32_t *material; /* per triangle: its geometry's material, read per pixel by shading */
  rr_material *materials;
  uint32_t nmaterials;
  scene_geometry *geoms; /* at least one once there is a triangle */
  uint32_t ngeoms, geoms_cap;
  char *names; /* the geometries' names, each ending in a NUL */
  size_t names_len, names_cap;
  uint64_t skipped;   /* faces dropped (degenerate or non-finite); ids count them */
  uint32_t *file_id;  /* per triangle: its id; NULL while none was dropped (id = index) */
  /* Homogeneous input: bit k of inf[i] set when corner k of triangle i is a point at
   * infinity (w = 0), whose p then holds its direction; NULL when there is none. */
  uint8_t *inf;
  /* Analytic primitives (prim/analytic.h): kind[i] the kind of primitive i and
   * ana[12i .. 12i+11] its parameters; both NULL while every primitive is a triangle. */
  uint8_t *kind;
  float *ana;
  uint32_t nspheres, nplanes, nboxes;
  vec3 bmin, bmax; /* of the finite corners */
  vec3 up, front;  /* unit: the model's up and the side it faces (+Y, +Z unless the file says) */
  bool has_view;              /* a built-in's own default view, which rr_camera_frame takes */
  vec3 view_eye, view_target; /* (the checker scene's grazing view) */
  file_camera *cameras;
  uint32_t ncameras;
  rr_light_info *lights; /* in world space; names are the scene's copies */
  uint32_t nlights;
  scene_instances *inst; /* NULL, or the instanced mesh (scene/instance.h): then ntris counts
                            indices (every instance's triangles), the arrays hold storage */
  struct rr_bvh *bvh; /* built by rr_scene_commit */
  uint64_t max_tris;  /* most triangles rr_scene_reserve grants (a scene file's budget); 0: no limit */
};

/* Where index i is stored (scene/instance.h), and in *inst its instance (RR_MISS when
 * i is no instance's). Without instances: i itself. */
static inline uint32_t scene_locate(const rr_scene *s, uint32_t i, uint32_t *inst) {
  const scene_instances *in = s->inst;
  *inst = RR_MISS;
  if (!in || i < in->base) return i;
  uint32_t r = i - in->base;
  if (r < in->n * in->T) return *inst = r / in->T, in->base + r % in->T;
  return i - (in->n - 1) * in->T;
}
static inline uint32_t scene_st(const rr_scene *s, uint32_t i) {
  uint32_t k;
  return scene_locate(s, i, &k);
}
/* The instance holding index i, RR_MISS when none does. */
static inline uint32_t scene_instance_of(const rr_scene *s, uint32_t i) {
  uint32_t k;
  scene_locate(s, i, &k);
  return i < s->ntris ? k : RR_MISS;
}
/* Triangles stored (index space minus the instances' copies): where the next goes. */
static inline uint32_t scene_stored(const rr_scene *s) {
  return s->inst ? s->ntris - (s->inst->n - 1) * s->inst->T : s->ntris;
}

/* Corner k of the triangle stored at j (an instance's: in its mesh's own space). */
static inline vec3 scene_stored_vertex(const rr_scene *s, int k, uint32_t j) {
  return v3(s->p[k][0][j], s->p[k][1][j], s->p[k][2][j]);
}

/* For kernels that load w lanes of corners (triangle i = ids[l] in lane l): where each
 * is stored (st[l]), the translation of its instance (tr[a·w + l], axis a; 0 where
 * none) and whether one moves it (mask[l] = -1, else 0); so that stored + tr is
 * inst_point's corner, the same float addition. False when some lane's instance is
 * more than a translation: then the caller moves its corners with scene_vertex. */
static inline bool scene_lanes(const rr_scene *s, const int32_t *ids, int w, int32_t *st, float *tr, int32_t *mask) {
  bool shift = true;
  /* The last lane's instance: its indices lo .. lo + len, whether it is a translation
   * and by what (read once: the stores to tr could otherwise alias the transforms). */
  uint32_t lo = 0, len = 0;
  int32_t m = 0;
  float t[3] = {0, 0, 0};
  for (int l = 0; l < w; l++) {
    uint32_t k, i = (uint32_t)ids[l];
    if (i - lo < len) { /* the same instance as the last lane (neighbours mostly are): no division */
      st[l] = (int32_t)(s->inst->base + (i - lo));
    } else {
      st[l] = (int32_t)scene_locate(s, i, &k);
      m = k == RR_MISS ? 0 : -1;
      if (k != RR_MISS) {
        lo = i - (uint32_t)st[l] + s->inst->base, len = s->inst->T;
        shift = shift && s->inst->shift[k];
        for (int a = 0; a < 3; a++) t[a] = s->inst->xf[k][4 * a + 3];
      } else {
        len = 0, t[0] = t[1] = t[2] = 0;
      }
    }
    mask[l] = m;
    for (int a = 0; a < 3; a++) tr[a * w + l] = t[a];
  }
  return shift;
}

/* The three corners of triangle i in world space (one look-up for the three). */
static inline void scene_corners(const rr_scene *s, uint32_t i, vec3 c[3]) {
  uint32_t in, j = scene_locate(s, i, &in);
  for (int k = 0; k < 3; k++) {
    c[k] = v3(s->p[k][0][j], s->p[k][1][j], s->p[k][2][j]);
    if (in != RR_MISS) c[k] = inst_point(s->inst->xf[in], s->inst->shift[in], c[k]);
  }
}

/* Corner k of triangle i in world space. */
static inline vec3 scene_vertex(const rr_scene *s, int k, uint32_t i) {
  uint32_t in, j = scene_locate(s, i, &in);
  vec3 p = v3(s->p[k][0][j], s->p[k][1][j], s->p[k][2][j]);
  return in == RR_MISS ? p : inst_point(s->inst->xf[in], s->inst->shift[in], p);
}

/* Axis x of corner k of triangle i in world space. */
static inline float scene_coord(const rr_scene *s, int k, int x, uint32_t i) {
  if (!s->inst) return s->p[k][x][i];
  vec3 p = scene_vertex(s, k, i);
  return x == 0 ? p.x : x == 1 ? p.y : p.z;
}

/* The id of triangle i (RR_MISS and other indices past the last stay as they are). */
static inline uint32_t scene_face_id(const rr_scene *s, uint32_t i) {
  if (i >= s->ntris) return i;
  if (!s->inst) return s->file_id ? s->file_id[i] : i;
  if (!s->file_id) return i;
  uint32_t in, j = scene_locate(s, i, &in);
  /* stored ids are those of the first instance; later ones (and what follows) move on by F each */
  uint32_t k = in != RR_MISS ? in : i < s->inst->base ? 0 : s->inst->n - 1;
  return s->file_id[j] + k * s->inst->F;
}
/* The index of the kept triangle whose id is `id` (file_id grows, so a binary
 * search); RR_MISS for RR_MISS and for ids no kept triangle has. */
uint32_t rr_scene_index_of(const rr_scene *s, uint32_t id);
/* Faces loaded so far, kept and dropped: ids run from 0 to this. */
static inline uint64_t scene_faces(const rr_scene *s) { return s->ntris + s->skipped; }

/* Which corners of triangle i lie at infinity (bit k: corner k); 0 for most. */
static inline unsigned scene_inf(const rr_scene *s, uint32_t i) { return s->inf ? s->inf[scene_st(s, i)] : 0u; }
/* Corner k of triangle i seen from `eye`: p - eye for a finite corner, the
 * direction itself for a point at infinity (where every ray from eye meets it). */
static inline vec3 scene_q(const rr_scene *s, int k, uint32_t i, vec3 eye) {
  vec3 p = scene_vertex(s, k, i);
  return scene_inf(s, i) >> k & 1u ? p : v3_sub(p, eye);
}
/* The material of triangle i. */
static inline uint32_t scene_material(const rr_scene *s, uint32_t i) { return s->material[scene_st(s, i)]; }
/* Corner k's shading normal of triangle i in world space (unnormalised; zero when the
 * scene has none: s->n NULL). */
static inline vec3 scene_normal(const rr_scene *s, int k, uint32_t i) {
  uint32_t in, j = scene_locate(s, i, &in);
  vec3 n = v3(s->n[k][0][j], s->n[k][1][j], s->n[k][2][j]);
  return in == RR_MISS || s->inst->shift[in] ? n : inst_dir(s->inst->nxf[in], n);
}
/* The three corners' shading normals of triangle i, as scene_normal gives each (one
 * look-up for the three). */
static inline void scene_normals(const rr_scene *s, uint32_t i, vec3 n[3]) {
  uint32_t in, j = scene_locate(s, i, &in);
  for (int k = 0; k < 3; k++) {
    n[k] = v3(s->n[k][0][j], s->n[k][1][j], s->n[k][2][j]);
    if (in != RR_MISS && !s->inst->shift[in]) n[k] = inst_dir(s->inst->nxf[in], n[k]);
  }
}
/* The (unnormalised) normal of triangle i's plane, for finite and infinite corners. */
vec3 rr_scene_tri_normal(const rr_scene *s, uint32_t i);

/* Grows the scene to hold `more` triangles; with_normals/with_uvs allocate those arrays. */
rr_error rr_scene_reserve(rr_scene *s, uint32_t more, bool with_normals, bool with_uvs);
/* Starts the flags of corners at infinity (those so far are finite), which then
 * grow with the other arrays: after it, with room reserved, pushing such a triangle
 * cannot run out of memory. */
rr_error rr_scene_reserve_inf(rr_scene *s);
/* Starts the map from triangle index to id (before it, every id was its index);
 * it then grows with the other arrays. */
rr_error rr_scene_reserve_ids(rr_scene *s);
/* Starts the corner colours, which then grow with the other arrays; the corners
 * so far are white (the colour that changes nothing). */
rr_error rr_scene_reserve_colors(rr_scene *s);
/* Gives back the room reserve doubled into (at commit: the scene is complete). */
void rr_scene_trim(rr_scene *s);
/* Appends one triangle (positions, optional corner normals/uvs); drops and counts
 * degenerate or non-finite ones. Returns true when kept. */
bool rr_scene_push(rr_scene *s, const vec3 p[3], const vec3 *n, const float (*uv)[2], uint32_t mat);
/* The same with corners at infinity (bit k of inf: p[k] is a direction; a triangle
 * with all three at infinity is dropped and counted) and corner colours col (linear
 * RGB, may be NULL: white where the scene has colours). */
bool rr_scene_push_inf(rr_scene *s, const vec3 p[3], unsigned inf, const vec3 *n, const float (*uv)[2],
                       const vec3 *col, uint32_t mat);
/* Opens a geometry: the primitives pushed from now on, until the next opens, are
 * its. name may be NULL or "" (none). A push into a scene without geometries opens
 * an unnamed one with the triangle's material. */
rr_error rr_scene_open_geometry(rr_scene *s, prim_kind kind, uint32_t material, const char *name);
/* Opens a geometry like g (kind, material, name) whose primitives start at index
 * `first` and id `face`, for loaders that write primitives straight into the arrays
 * (copies of a mesh); neither may be below the last geometry's. */
rr_error rr_scene_repeat_geometry(rr_scene *s, uint32_t g, uint32_t first, uint32_t face);
/* Names geometry g (name NULL or "": none). */
rr_error rr_scene_name_geometry(rr_scene *s, uint32_t g, const char *name);
/* The geometry of triangle index prim (binary search: shading asks per pixel);
 * RR_MISS when prim is RR_MISS or out of range. */
uint32_t rr_scene_geometry_of(const rr_scene *s, uint32_t prim);
/* A ray query's answer for triangle index prim (RR_MISS: a miss, s may then be
 * NULL) hit at t with barycentrics l1, l2: the rr_hit with prim's id and geometry. */
rr_hit rr_scene_hit(const rr_scene *s, uint32_t prim, float t, float l1, float l2);
/* Adds a material and returns its index (UINT32_MAX when out of memory). */
uint32_t rr_scene_add_material(rr_scene *s, const float color[3], const char *texture_path);
/* Names material m (NULL or "": none). */
rr_error rr_scene_name_material(rr_scene *s, uint32_t m, const char *name);
/* Appends a camera or a light of a file (copied, names too; cam->name is ignored);
 * a file's light is kept as it is (rr_scene_add_light checks the caller's). */
rr_error rr_scene_add_camera(rr_scene *s, const char *name, const file_camera *cam);
rr_error rr_scene_append_light(rr_scene *s, const rr_light_info *light);
/* Recomputes bounds. */
void rr_scene_update_bounds(rr_scene *s);

#endif
