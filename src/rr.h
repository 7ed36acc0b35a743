/* rastray internal header: the data of each pipeline stage and the one sample test.
 *
 * Data flows one way: scene → BVH → camera → visibility → shading → image. */
#ifndef RR_INTERNAL_H
#define RR_INTERNAL_H

#include "rastray.h"

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

/* ---- device and errors --------------------------------------------------- */

struct rr_device {
  rr_error error;
  char message[512];
  rr_build_options build; /* used by rr_scene_commit; zeros mean defaults */
  struct auto_choice {    /* auto's last trial: the same view again reuses its choice */
    const void *scene, *bvh;
    uint32_t ntris;
    rr_camera cam;
    int width, height, threads, cull, scalar;
    int method;
    char why[160];
  } auto_choice;
};

/* Records a failure in dev (when not NULL) and returns its code. */
rr_error rr_fail(rr_device *dev, rr_error code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Records success. */
rr_error rr_ok(rr_device *dev);

/* ---- small vector algebra ------------------------------------------------ */

typedef struct { float x, y, z; } vec3;

static inline vec3 v3(float x, float y, float z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline vec3 v3_norm(vec3 a) { float l = v3_len(a); return l > 0 ? v3_scale(a, 1.0f / l) : a; }
/* Plain comparisons: fminf/fmaxf handle NaN and are library calls at -O2. */
/* Hot kernels written once and specialised by their constant arguments. */
#define KERNEL static inline __attribute__((always_inline))

static inline float minf(float a, float b) { return a < b ? a : b; }
static inline float maxf(float a, float b) { return a > b ? a : b; }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }
static inline float v3_get(vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
static inline vec3 v3_load(const float *p) { return v3(p[0], p[1], p[2]); }

/* ---- scene --------------------------------------------------------------- */

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
vec3 scene_tri_normal(const rr_scene *s, uint32_t i);

/* Grows the scene to hold `more` triangles; with_normals/with_uvs allocate those arrays. */
rr_error scene_reserve(rr_scene *s, uint32_t more, bool with_normals, bool with_uvs);
/* Gives back the room reserve doubled into (at commit: the scene is complete). */
void scene_trim(rr_scene *s);
/* Appends one triangle (positions, optional corner normals/uvs); drops and counts
 * degenerate or non-finite ones. Returns true when kept. */
bool scene_push(rr_scene *s, const vec3 p[3], const vec3 *n, const float (*uv)[2], uint32_t mat);
/* The same with corners at infinity (bit k of inf: p[k] is a direction); a triangle
 * with all three at infinity is dropped and counted. */
bool scene_push_inf(rr_scene *s, const vec3 p[3], unsigned inf, const vec3 *n, const float (*uv)[2], uint32_t mat);
/* Adds a material and returns its index (UINT32_MAX when out of memory). */
uint32_t scene_add_material(rr_scene *s, const float color[3], const char *texture_path);
/* Recomputes bounds. */
void scene_update_bounds(rr_scene *s);

/* Loaders: assimp files and the built-in scenes. */
rr_error scene_load_file(rr_scene *s, const char *path);
/* Returns RR_OK when `name` named a built-in scene (and fills s), RR_ERROR_UNSUPPORTED
 * when it is not a built-in name; other codes are real failures. */
rr_error scene_load_builtin(rr_scene *s, const char *name);
/* Loads the textures named by the materials (missing files leave textures empty). */
void scene_load_textures(rr_scene *s, const char *base_dir);

/* ---- BVH --------------------------------------------------------------------- */

/* 32-byte node with its own bounds. A leaf (count > 0) holds triangles
 * bvh->prims[first .. first + count); an inner node's children are nodes[first]
 * and nodes[first + 1]. The root is node 0. */
typedef struct bvh_node {
  float lo[3], hi[3];
  uint32_t first, count;
} bvh_node;

typedef struct rr_bvh {
  bvh_node *nodes;
  uint32_t nnodes, nleaves, depth;
  uint32_t *prims; /* triangle ids in leaf order */
  double sah_cost, build_ms;
  uint64_t bytes;
  void *node_mem;  /* the allocation behind nodes (sibling pairs share a cache line) */
  uint32_t nprims; /* triangles the tree was built over (== scene->ntris when current) */
  int bins, leaf_size;
  struct bvh_wide *wide; /* the same tree collapsed to 4 children per node, for single rays */
  uint32_t *wide_node;   /* per wide node, per slot: the node of `nodes` it is (UINT32_MAX: empty) */
  uint32_t nwide;
} rr_bvh;

/* A 4-wide node: up to four of the binary tree's nodes side by side, bounds as
 * lanes per axis (an empty slot has an empty box). A slot with count > 0 is a leaf
 * holding prims [ref, ref + count); with count 0 it is wide node `ref`. Root: 0. */
typedef struct bvh_wide {
  float lo[3][4], hi[3][4];
  uint32_t ref[4], count[4];
} bvh_wide;

enum { BVH_DEFAULT_BINS = 32, BVH_DEFAULT_LEAF = 4, BVH_MAX_LEAF = 64, BVH_STACK = 128 };

/* Builds a binned-SAH BVH over the scene's triangles (src/bvh.c); the tree is the
 * same for any opt->threads. An empty scene gets NULL. */
rr_error bvh_build(rr_scene *s, const rr_build_options *opt, rr_bvh **out);
/* The scene's BVH when it is current, else NULL with a message in dev (an empty
 * scene also gives NULL, with *empty set: every ray misses). */
const rr_bvh *bvh_of(rr_device *dev, const rr_scene *s, bool *empty);
typedef struct camera camera;
/* A pseudo-camera for one arbitrary ray: eye = origin, d0 = direction and dx, dy
 * two fixed directions perpendicular to it, so tri_setup_planar() sets a triangle
 * up for the ray, and its edge functions at sample (0, 0) are the ray's. The tie
 * bits (top-left rule) then come from the derivatives along dx, then dy: a ray
 * through a shared edge or vertex hits exactly one triangle. */
void ray_camera(const float org[3], const float dir[3], camera *out);
/* The one sample test for an arbitrary ray set up by ray_camera(): true on a hit
 * with t in [tmin, tmax] (t along the unnormalised direction). */
bool ray_tri_hit(const rr_scene *s, uint32_t i, const camera *ray, bool cull_backfaces, float tmin, float tmax,
                 float *t, float *l1, float *l2);

/* Frees the scene's BVH (if any). */
void scene_free_bvh(rr_scene *s);
/* Adds the BVH's figures to a scene's info. */
void bvh_fill_info(const rr_scene *s, rr_scene_info *info);

/* ---- camera -------------------------------------------------------------- */

/* A camera resolved for an image. Sample (sx, sy) of pixel (x, y) is
 * (x + 0.5, y + 0.5), row 0 at the top. Planar cameras (perspective, orthographic)
 * have edge functions linear in (sx, sy): a perspective ray leaves the eye along
 * d0 + sx·dx + sy·dy; an orthographic ray leaves eye + o0 + sx·ox + sy·oy along fwd.
 * Curved cameras (parabolic, lat-long, fisheye, cube) keep one direction per
 * sample in `dirs` (zero where the image has no ray), and bound the directions of
 * a rectangle of samples by a cone whose half-angle grows by `lipschitz` radians
 * per pixel of distance. */
typedef struct camera {
  rr_camera_type type;
  int width, height;
  bool planar;
  vec3 eye, right, up, fwd;
  vec3 d0, dx, dy;
  vec3 col_n0, col_n1, row_n0, row_n1; /* perspective: n0 + x·n1 is the plane of column x, */
                                      /* row y likewise, facing increasing x (y) */
  vec3 o0, ox, oy;
  float tan_half_h, tan_half_w;
  vec3 *dirs;
  float lipschitz;
  float dir_len_max; /* longest |d| of the camera's rays */
  int face;          /* cube: side of a face in pixels */
  int cells_x, cells_y; /* curved: cones of CAMERA_CELL² cells of samples, 4 floats each: */
  float *cells;         /* unit axis and half-angle; no bound when >= 1.5, no rays when < 0 */
} camera;

#define CAMERA_CELL 32

/* Resolves a public camera for an image size; camera_release frees it. */
rr_error camera_setup(rr_device *dev, const rr_camera *in, int width, int height, camera *out);
void camera_release(camera *c);
/* The ray of sample (sx, sy) of a planar perspective camera (unnormalised). */
static inline vec3 camera_dir(const camera *c, float sx, float sy) {
  return v3_add(c->d0, v3_add(v3_scale(c->dx, sx), v3_scale(c->dy, sy)));
}
/* The ray of pixel (x, y) for any camera: origin and (unnormalised) direction;
 * false when the pixel has no ray (outside a hemisphere's disk, a cube's cross). */
bool camera_ray(const camera *c, int x, int y, vec3 *origin, vec3 *dir);
/* What a triangle's edge functions are evaluated against at pixel (x, y):
 * (1, sx, sy) for planar cameras, the ray direction for curved ones. */
static inline vec3 camera_w(const camera *c, int x, int y) {
  return c->planar ? v3(1.0f, (float)x + 0.5f, (float)y + 0.5f) : c->dirs[(size_t)y * c->width + x];
}
/* Projects a point given relative to the eye to sample coordinates (planar
 * cameras); false when it is not strictly in front of the image plane. */
bool camera_project(const camera *c, vec3 p, float *sx, float *sy);
/* A cone (unit axis, half-angle) holding the directions of the samples
 * [x0, x1) × [y0, y1) of a curved camera: 1 when found, 0 when none is known,
 * -1 when none of the samples has a ray. */
int camera_rect_cone(const camera *c, int x0, int y0, int x1, int y1, vec3 *axis, float *angle);

/* ---- triangle setup and the one sample test ----------------------------- */

/* A triangle set up for a camera (paper eqs. 1–3 and appendix). Its edge functions
 * at a sample are V_i = a[i]·w.x + b[i]·w.y + c[i]·w.z for the camera's w
 * (camera_w): for planar cameras that is a + sx·b + sy·c (eq. 3), for curved ones
 * (a, b, c) is the edge normal n_i and V_i = n_i·d. The volume at the sample is
 * vol + sx·vol_x + sy·vol_y (constant but for orthographic views, whose ray origin
 * moves). Everything is sign-normalised so that the inside is positive whichever
 * face is seen. */
typedef struct tri_setup {
  float a[3], b[3], c[3];
  float vol, vol_x, vol_y;
  uint32_t tie; /* bit i: a sample exactly on edge i belongs to this triangle */
  float w[3];   /* homogeneous w of vertex i (1, or 0 at infinity): the sum is Σ w_i V_i */
} tri_setup;

enum { SETUP_CULLED = 0, SETUP_FRONT = 1, SETUP_BACK = 2 };

/* Sets up triangle `i` of `s` for camera `c`. Returns SETUP_FRONT, SETUP_BACK, or
 * SETUP_CULLED when the triangle cannot be seen (edge-on, or a back face and
 * cull_backfaces is set). */
int tri_setup_camera(const rr_scene *s, uint32_t i, const camera *c, bool cull_backfaces, tri_setup *out);
#define tri_setup_planar tri_setup_camera
/* tri_setup_camera for triangles ids[0..n-1] into out[k], face[k]; with simd, eight
 * at a time (AVX2) where the camera is perspective and no corner is at infinity,
 * with the same bits. */
void tri_setup_run(const rr_scene *s, const uint32_t *ids, int n, const camera *c, bool cull_backfaces, bool simd,
                   tri_setup *out, int *face);

/* The three edge functions of a set-up triangle for evaluation vector w. The
 * order of operations is fixed (the build uses -ffp-contract=off: a fused
 * multiply-add would change the bits) so every method computes the same values
 * for the same (triangle, sample). */
static inline void tri_edges_w(const tri_setup *t, vec3 w, float e[3]) {
  for (int i = 0; i < 3; i++) e[i] = t->a[i] * w.x + t->b[i] * w.y + t->c[i] * w.z;
}
/* The same for a planar camera's sample (sx, sy): w = (1, sx, sy), same bits. */
static inline void tri_edges(const tri_setup *t, float sx, float sy, float e[3]) {
  tri_edges_w(t, v3(1.0f, sx, sy), e);
}
/* The volume term at sample (sx, sy). */
static inline float tri_vol(const tri_setup *t, float sx, float sy) {
  return t->vol + sx * t->vol_x + sy * t->vol_y;
}

/* The one sample test (paper eq. 2 with the top-left rule of sect. 4.2).
 * e: sign-normalised edge values at the sample; tie: bit i set when the sample
 * belongs to this triangle if it lies exactly on edge i; vol: the sign-normalised
 * volume at the sample (positive when the hit lies ahead of the ray origin).
 * w: the vertices' homogeneous w (appendix eqs. 5–11: a vertex at infinity has
 * w = 0 and leaves the sum). On a hit returns true with t = V / Σw_iV_i and
 * λ_i = V_i / Σw_iV_i. */
static inline bool sample_test_w(const float e[3], const float w[3], uint32_t tie, float vol,
                                 float *t, float *l1, float *l2) {
  bool in0 = e[0] > 0.0f || (e[0] == 0.0f && (tie & 1u));
  bool in1 = e[1] > 0.0f || (e[1] == 0.0f && (tie & 2u));
  bool in2 = e[2] > 0.0f || (e[2] == 0.0f && (tie & 4u));
  if (!(in0 & in1 & in2)) return false;
  /* Appendix eq. 10: only finite vertices count, Σ w_i V_i; e·1 == e exactly, so
   * ordinary triangles keep the bits of e0 + e1 + e2. */
  float sum = e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
  /* sum == 0: all three on their edges (a degenerate sliver) or a pixel with no ray */
  if (!(sum > 0.0f) || !(vol > 0.0f)) return false;
  float inv = 1.0f / sum;
  *t = vol * inv;
  *l1 = e[1] * inv;
  *l2 = e[2] * inv;
  return true;
}
/* The same for a triangle of finite vertices (every w = 1). */
static inline bool sample_test(const float e[3], uint32_t tie, float vol, float *t, float *l1, float *l2) {
  static const float ones[3] = {1.0f, 1.0f, 1.0f};
  return sample_test_w(e, ones, tie, vol, t, l1, l2);
}

/* ---- visibility buffer and frames --------------------------------------- */

typedef struct visbuf {
  int width, height;
  uint32_t *id;
  float *t, *l1, *l2;
} visbuf;

/* The depth test shared by every method: nearer wins; on equal t the lower id wins,
 * so the result does not depend on the order in which triangles are visited. */
static inline bool depth_wins(float t, uint32_t id, float best_t, uint32_t best_id) {
  return t < best_t || (t == best_t && id < best_id);
}

/* Tests one set-up triangle at pixel k, whose sample is (sx, sy) with evaluation
 * vector w, and keeps it when it is nearer. Returns 0 when the triangle does not
 * cover the sample, 1 when it covers it behind what is stored, 2 when it is kept. */
static inline int shade_sample_w(const tri_setup *ts, uint32_t id, vec3 w, float sx, float sy, visbuf *vb,
                                 size_t k) {
  float e[3], t, l1, l2;
  tri_edges_w(ts, w, e);
  if (!sample_test_w(e, ts->w, ts->tie, tri_vol(ts, sx, sy), &t, &l1, &l2)) return 0;
  if (!depth_wins(t, id, vb->t[k], vb->id[k])) return 1;
  vb->t[k] = t;
  vb->id[k] = id;
  vb->l1[k] = l1;
  vb->l2[k] = l2;
  return 2;
}

/* The same for a planar camera's sample (sx, sy). */
static inline int shade_sample(const tri_setup *ts, uint32_t id, float sx, float sy, visbuf *vb, size_t k) {
  return shade_sample_w(ts, id, v3(1.0f, sx, sy), sx, sy, vb, k);
}

struct rr_frame {
  visbuf vb;
  float *heat_e, *heat_n; /* per-pixel E and N, when options.heat was set */
  rr_stats stats;
  rr_method method;
};

/* A pass of a method: fills vb (cleared to misses) and adds to stats. */
typedef struct render_ctx {
  const rr_scene *scene;
  const camera *cam;
  const rr_render_options *opt;
  int threads;
  visbuf *vb;
  rr_stats *stats;
  float *heat_e, *heat_n; /* optional per-pixel E and N charges */
  const struct oracles *oracles; /* the traversal's settings, for the 3dr methods */
} render_ctx;

/* The oracles of the continuum's traversal (paper Fig. 8), as settings. */
typedef struct oracles {
  int frustum_size;  /* side of the initial frusta; 0: whole image (tiles on several threads) */
  bool leaves;       /* generateSamples at BVH leaves (false: at the root, plain rasterization) */
  bool cull_outside; /* isOutside: frustum culling of BVH nodes */
  bool cull_occluded;/* isOccluded: hierarchical z-buffer test of BVH nodes */
  int split_min;     /* splitFrustum down to this side (0: never split) */
  float split_ratio; /* split when a node's projected area is below ratio × the frustum's */
  bool binning;      /* rasterize hierarchically in bins rather than every sample of the bounds */
  bool early_z;      /* reject bins hidden behind the stored depths */
  int bin_size;      /* top bin side */
  int bin_min;       /* bins this small are tested sample by sample */
} oracles;

/* The continuum's one traversal, steered by ctx->oracles (src/traverse.c). */
rr_error vis_traverse(rr_device *dev, render_ctx *ctx);
/* isOutside: may the box be culled from the frustum of samples [x0, x1) × [y0, y1)? */
bool oracle_outside(const camera *c, int x0, int y0, int x1, int y1, const bvh_node *box);
/* isOccluded: may the box be culled when the farthest depth stored in a frustum is `farthest`? */
bool oracle_occluded(const camera *c, const bvh_node *box, float farthest);

typedef rr_error (*vis_method_fn)(rr_device *dev, render_ctx *ctx);

rr_error vis_rc(rr_device *dev, render_ctx *ctx);
/* rc-bvh and rc-packet: single rays and 8x8 ray packets through the BVH (src/vis_rc_bvh.c). */
rr_error vis_rc_bvh(rr_device *dev, render_ctx *ctx);
rr_error vis_rc_packet(rr_device *dev, render_ctx *ctx);
/* The least t that sample_test() can return for a set-up triangle at any sample of
 * camera c, and (planar cameras) a rectangle x0, y0, x1, y1 of sample coordinates
 * holding every sample where it can pass: the exact culling of rc-bvh, rc-packet. */
float tri_bounds(const tri_setup *ts, const camera *c, float rect[4]);
/* 2dr-bb and 2dr-bin: projection, clipping, fixed-point 2D edge functions (src/raster2d.c). */
rr_error vis_2dr_bb(rr_device *dev, render_ctx *ctx);
rr_error vis_2dr_bin(rr_device *dev, render_ctx *ctx);
/* Test hook: runs the 2D pipeline (binning when `bin`) over every triangle but, instead
 * of the z test, counts in front[k] / back[k] every triangle that claims sample k. */
rr_error raster2d_claims(const rr_scene *s, const camera *c, bool bin, int threads, uint8_t *front, uint8_t *back);
/* Test hook: where the 2D pipeline's vertex stage puts world point p on the screen;
 * false when p is behind its near plane. */
bool raster2d_project(const rr_scene *s, const camera *c, vec3 p, double *sx, double *sy);
/* The inclusive pixel rectangle a set-up triangle's samples may lie in; false when
 * none. For curved cameras it is the bounding box of the cells whose cone of
 * directions no edge plane excludes. */
bool tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, int rect[4]);
/* Planar cameras bound a triangle from its corners alone, before its setup: most
 * triangles of a detailed mesh fall between samples. tri_corner_bounds bounds triangles
 * ids[0..n-1] (first..first+n-1 when ids is NULL), 8 at a time with AVX2 when
 * simd, and writes those whose rectangle holds a sample to out; returns how many. */
typedef struct tri_bound {
  uint32_t id;
  int bb[4]; /* inclusive pixel rectangle, as tri_screen_bounds */
} tri_bound;
uint32_t tri_corner_bounds(const rr_scene *s, uint32_t first, const uint32_t *ids, uint32_t n, const camera *c,
                           bool simd, tri_bound *out);
/* Tests every sample of an inclusive rectangle against one set-up triangle and
 * returns the number of edge-function evaluations; adds the samples the
 * triangle covers to *covered. simd: use AVX2 where the processor has it. */
/* Curved cameras: what bounds a triangle's directions from the eye. */
typedef struct tri_cone {
  float len[4];      /* lengths of the three edge normals and of their sum */
  vec3 cap_axis;     /* a cap holding the triangle's directions, */
  float cap_angle;   /* or a negative angle when none under 90° does */
} tri_cone;
void tri_cone_setup(const rr_scene *s, uint32_t i, const camera *c, const tri_setup *ts, tri_cone *tc);
/* May a triangle be excluded from a cone of directions (unit axis, half-angle)? */
bool cone_excludes(const tri_cone *tc, const tri_setup *ts, vec3 axis, float angle);
uint64_t raster_rect(const tri_setup *ts, uint32_t id, const int rect[4], const camera *c, visbuf *vb,
                     uint64_t *covered, bool simd);

/* ---- threads --------------------------------------------------------------- */

/* Runs fn(job, thread, arg) for job = 0..njobs-1, dealt out dynamically to
 * `threads` threads (the caller's thread is one of them). */
typedef void (*parallel_fn)(int job, int thread, void *arg);
void parallel_for(int njobs, int threads, parallel_fn fn, void *arg);
/* Number of cores available. */
int cpu_count(void);
/* Milliseconds on a monotonic clock. */
double now_ms(void);
double cpu_ms(void); /* processor time of the whole process */

/* ---- images ---------------------------------------------------------------- */

/* Writers and readers by extension, in image_io.c. */
rr_error image_write_file(rr_device *dev, const rr_image *img, const char *path);
rr_error image_read_file(rr_device *dev, const char *path, rr_image *out);

#endif
