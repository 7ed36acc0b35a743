/* Scene files (docs/scene-file.md): a JSON object that composes a scene from mesh
 * files and built-ins, each placed by a transform and optionally given new
 * material values, with lights, a camera and render settings. Also camera files,
 * whose fields a scene file's "camera" shares.
 *
 * Every mesh is loaded into the one scene and its new triangles (and the cameras
 * and lights its file brought) are then moved by the mesh's transform, computed
 * in double precision and rounded once. The whole file is read before the scene
 * is handed out: a failure leaves nothing behind. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "io/io.h"
#include "io/json_read.h"
#include "prim/analytic.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_FILE_BYTES = 16 << 20, MAX_PATH = 4096 };
#define MAX_COORD 1e30 /* largest coordinate accepted: floats reach 3.4e38 */

void rr_load_options_init(rr_load_options *opt) {
  if (opt) *opt = (rr_load_options){.base_dir = NULL, .sandbox = 0, .builtins = 1, .max_tris = 0};
}

/* ---- cameras -------------------------------------------------------------------- */

/* The camera of a camera-to-world matrix in the OpenGL convention (columns right,
 * up, back, position; bottom row 0 0 0 1): the eye, a target one back-vector ahead. */
static rr_error camera_matrix(json_reader *r, const cJSON *obj, rr_camera *cam) {
  const cJSON *m = rr_json_get(obj, "matrix");
  if (!cJSON_IsArray(m) || cJSON_GetArraySize(m) != 4)
    return rr_json_fail(r, "matrix", "expected four rows of four numbers (camera to world, OpenGL convention)");
  double row[4][4];
  size_t len = rr_json_enter(r, "matrix", 0);
  rr_error e = RR_OK;
  for (int i = 0; i < 4 && !e; i++) {
    size_t l2 = rr_json_enter(r, NULL, i);
    e = rr_json_array_doubles(r, cJSON_GetArrayItem(m, i), 4, -MAX_COORD, MAX_COORD, row[i]);
    rr_json_leave(r, l2);
  }
  rr_json_leave(r, len);
  if (e) return e;
  if (row[3][0] != 0 || row[3][1] != 0 || row[3][2] != 0 || row[3][3] != 1)
    return rr_json_fail(r, "matrix", "the bottom row must be 0 0 0 1");
  for (int i = 0; i < 3; i++)
    cam->eye[i] = (float)row[i][3], cam->target[i] = (float)row[i][3] - (float)row[i][2], cam->up[i] = (float)row[i][1];
  return RR_OK;
}

/* A camera object into *cam; *fields gets what it gave. need_view: eye and target
 * (or a matrix) must be there (camera files); else they may both be absent. */
static rr_error read_camera(json_reader *r, const cJSON *obj, rr_camera *cam, unsigned *fields, bool need_view) {
  static const char *const keys[] = {"type", "eye", "target", "up", "fov", "ortho_height", "matrix", "width", "height",
                                     "intrinsics", "distortion", NULL};
  rr_error e = rr_json_keys(r, obj, keys);
  if (e) return e;
  rr_camera c = *cam;
  unsigned given = 0;
  int type = c.type;
  e = rr_json_named(r, obj, "type", rr_camera_from_name, "perspective, orthographic, parabolic, latlong, fisheye, cube, opencv or opencv-fisheye",
                 &type);
  if (e) return e;
  c.type = (rr_camera_type)type;
  given |= rr_json_get(obj, "type") ? RR_CAMERA_FIELD_TYPE : 0;
  if (rr_json_get(obj, "matrix")) {
    if (rr_json_get(obj, "eye") || rr_json_get(obj, "target") || rr_json_get(obj, "up"))
      return rr_json_fail(r, NULL, "give either 'matrix' or 'eye', 'target' and 'up', not both");
    if ((e = camera_matrix(r, obj, &c))) return e;
    given |= RR_CAMERA_FIELD_EYE | RR_CAMERA_FIELD_TARGET | RR_CAMERA_FIELD_UP;
  } else {
    if ((e = rr_json_floats(r, obj, "eye", 3, -MAX_COORD, MAX_COORD, c.eye)) ||
        (e = rr_json_floats(r, obj, "target", 3, -MAX_COORD, MAX_COORD, c.target)) ||
        (e = rr_json_floats(r, obj, "up", 3, -MAX_COORD, MAX_COORD, c.up)))
      return e;
    bool eye = rr_json_get(obj, "eye"), target = rr_json_get(obj, "target");
    if ((need_view || eye) && !target) return rr_json_fail(r, NULL, "missing 'target' (or a 'matrix')");
    if ((need_view || target) && !eye) return rr_json_fail(r, NULL, "missing 'eye' (or a 'matrix')");
    given |= (eye ? RR_CAMERA_FIELD_EYE | RR_CAMERA_FIELD_TARGET : 0) | (rr_json_get(obj, "up") ? RR_CAMERA_FIELD_UP : 0);
  }
  if ((e = rr_json_float(r, obj, "fov", RR_FOV_MIN, 360, &c.fov_deg))) return e;
  if ((e = rr_json_float(r, obj, "ortho_height", 0, MAX_COORD, &c.ortho_height))) return e;
  given |= (rr_json_get(obj, "fov") ? RR_CAMERA_FIELD_FOV : 0) | (rr_json_get(obj, "ortho_height") ? RR_CAMERA_FIELD_ORTHO : 0);
  float k[4];
  if (rr_json_get(obj, "intrinsics")) {
    if ((e = rr_json_floats(r, obj, "intrinsics", 4, -MAX_COORD, MAX_COORD, k))) return e;
    c.fx = k[0], c.fy = k[1], c.cx = k[2], c.cy = k[3], given |= RR_CAMERA_FIELD_LENS;
  }
  const cJSON *dist = rr_json_get(obj, "distortion");
  if (dist) { /* OpenCV's 4, 5 or 8 coefficients (or fewer: the rest are zero) */
    int n = cJSON_IsArray(dist) ? cJSON_GetArraySize(dist) : -1;
    if (n < 0 || n > 8) return rr_json_fail(r, "distortion", "must be an array of at most 8 numbers");
    memset(c.dist, 0, sizeof c.dist);
    if (n > 0 && (e = rr_json_floats(r, obj, "distortion", n, -MAX_COORD, MAX_COORD, c.dist))) return e;
    given |= RR_CAMERA_FIELD_LENS;
  }
  int size; /* the image the camera was saved for: for reference only, but still a number */
  if ((e = rr_json_int(r, obj, "width", 0, INT_MAX, &size)) || (e = rr_json_int(r, obj, "height", 0, INT_MAX, &size)))
    return e;
  if (given & RR_CAMERA_FIELD_EYE) {
    rr_camera check = c;
    if (rr_camera_check(r->dev, &check) != RR_OK) {
      char msg[256];
      snprintf(msg, sizeof msg, "%s", rr_device_message(r->dev));
      return rr_json_fail(r, NULL, "%s", msg);
    }
  }
  *cam = c;
  *fields = given;
  return RR_OK;
}

rr_error rr_camera_load(rr_device *dev, const char *path, rr_camera *cam, unsigned *fields) {
  if (!path || !cam) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_camera_load: NULL argument");
  char what[320];
  snprintf(what, sizeof what, "camera file '%s'", path);
  json_reader r = {.dev = dev, .what = what};
  cJSON *root;
  rr_error e = rr_json_parse_file(&r, path, 1 << 20, &root);
  unsigned given = 0;
  if (!e && cJSON_IsArray(rr_json_get(root, "frames")))
    e = rr_json_fail(&r, "frames", "a NeRF transforms file: its cameras are read by rr_camera_import (--camera-file FILE:FRAME)");
  if (!e) e = read_camera(&r, root, cam, &given, true);
  cJSON_Delete(root);
  if (e) return e;
  if (fields) *fields = given;
  return rr_ok(dev);
}

/* ---- render settings -------------------------------------------------------------- */

/* Splits "NAME[:ARG]" at its first ':' into name (truncated to cap) and arg (NULL: none). */
static void split_name(const char *text, char *name, size_t cap, const char **arg) {
  const char *colon = strchr(text, ':');
  size_t n = colon ? (size_t)(colon - text) : strlen(text);
  if (n >= cap) n = cap - 1;
  memcpy(name, text, n);
  name[n] = 0;
  *arg = colon ? colon + 1 : NULL;
}

/* A decimal count in [lo, hi], digits only. */
static bool count_in(const char *text, long lo, long hi, long *out) {
  if (!text || !*text || strlen(text) > 9 || strspn(text, "0123456789") != strlen(text)) return false;
  *out = strtol(text, NULL, 10);
  return *out >= lo && *out <= hi;
}

/* A number "F" in [lo, hi]. */
static bool float_in(const char *text, double lo, double hi, float *out) {
  char *end;
  double v = text && *text ? strtod(text, &end) : NAN;
  if (!(text && *text && *end == 0 && v >= lo && v <= hi)) return false;
  *out = (float)v;
  return true;
}

static int find_name(const char *name, const char *(*name_of)(int), int count) {
  for (int i = 0; i < count; i++)
    if (strcmp(name, name_of(i)) == 0) return i;
  return -1;
}

/* "aa": none, ssaa:N, msaa:N, csaa:K/N, with "aa_pattern": standard, rotated, jitter[:SEED]. */
static rr_error read_aa(json_reader *r, const cJSON *obj, rr_render_options *ro) {
  const char *aa = "none", *pattern = "standard", *arg;
  rr_error e = rr_json_string(r, obj, "aa", &aa);
  if (!e) e = rr_json_string(r, obj, "aa_pattern", &pattern);
  if (e) return e;
  char name[16];
  split_name(aa, name, sizeof name, &arg);
  int mode = find_name(name, rr_aa_mode_name, RR_AA_MODE_COUNT);
  long samples = 1, stored = 0;
  const char *slash = arg ? strchr(arg, '/') : NULL;
  bool ok = mode == RR_AA_NONE ? !arg : mode == RR_AA_CSAA ? slash != NULL : mode > 0 && arg;
  if (ok && mode == RR_AA_CSAA) {
    char k[12];
    snprintf(k, sizeof k, "%.*s", (int)(slash - arg < 11 ? slash - arg : 11), arg);
    ok = count_in(k, 1, 16, &stored) && count_in(slash + 1, 1, 16, &samples);
  } else if (ok && arg) {
    ok = count_in(arg, 1, 16, &samples);
  }
  if (!ok) return rr_json_fail(r, "aa", "expected none, ssaa:N, msaa:N or csaa:K/N (N, K: 1, 2, 4, 8 or 16)");
  split_name(pattern, name, sizeof name, &arg);
  int pat = find_name(name, rr_aa_pattern_name, RR_AA_PATTERN_COUNT);
  long seed = 1;
  if (pat < 0 || (arg && (pat != RR_AA_JITTER || !count_in(arg, 0, 999999999, &seed))))
    return rr_json_fail(r, "aa_pattern", "expected standard, rotated or jitter[:SEED]");
  if (rr_json_get(obj, "aa_pattern") && mode == RR_AA_NONE) return rr_json_fail(r, "aa_pattern", "needs an 'aa' other than none");
  if (rr_render_options_set_aa(r->dev, ro, (rr_aa_mode)mode, (int)samples, (int)stored, (rr_aa_pattern)pat,
                               (uint32_t)seed) != RR_OK) {
    char msg[256];
    snprintf(msg, sizeof msg, "%s", rr_device_message(r->dev));
    return rr_json_fail(r, "aa", "%s", msg);
  }
  return RR_OK;
}

/* The "render" object into settings. */
static rr_error read_render(json_reader *r, const cJSON *obj, rr_scene_settings *st) {
  static const char *const keys[] = {"size", "method", "aa", "aa_pattern", "aa_filter", "cull_backfaces", "shade",
                                     "shadows", "max_depth", "texture_filter", "lod_bias", "alpha", "default_lights",
                                     "background", NULL};
  rr_error e = rr_json_keys(r, obj, keys);
  if (e) return e;
  rr_render_options *ro = &st->render;
  rr_shade_options *so = &st->shade;
  const cJSON *size = rr_json_get(obj, "size");
  if (size) {
    size_t len = rr_json_enter(r, "size", 0);
    e = !cJSON_IsArray(size) || cJSON_GetArraySize(size) != 2
            ? rr_json_fail(r, NULL, "expected [width, height]")
            : RR_OK;
    for (int i = 0; i < 2 && !e; i++) {
      const cJSON *v = cJSON_GetArrayItem(size, i);
      if (!cJSON_IsNumber(v) || !(v->valuedouble >= 1 && v->valuedouble <= RR_MAX_SIZE) ||
          v->valuedouble != floor(v->valuedouble))
        e = rr_json_fail(r, NULL, "expected [width, height], integers 1..%d", RR_MAX_SIZE);
      else if (i == 0) ro->width = (int)v->valuedouble;
      else ro->height = (int)v->valuedouble;
    }
    rr_json_leave(r, len);
    if (e) return e;
    st->given |= RR_SETTING_SIZE;
  }
  int v = ro->method;
  if ((e = rr_json_named(r, obj, "method", rr_method_from_name,
                      "auto, rc, rc-bvh, rc-packet, 2dr-bb, 2dr-bin, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs or 3dr-full", &v)))
    return e;
  ro->method = (rr_method)v;
  if (rr_json_get(obj, "aa") || rr_json_get(obj, "aa_pattern")) {
    if ((e = read_aa(r, obj, ro))) return e;
    st->given |= RR_SETTING_AA;
  }
  if ((e = rr_json_bool(r, obj, "cull_backfaces", &ro->cull_backfaces))) return e;
  v = so->mode;
  if ((e = rr_json_named(r, obj, "shade", rr_shade_from_name, "lit, lambert, id, normal, depth, heat-evals or heat-nodes",
                      &v)))
    return e;
  so->mode = (rr_shade_mode)v;
  v = so->shadows;
  if ((e = rr_json_named(r, obj, "shadows", rr_shadows_from_name, "none, rays, raster or auto", &v))) return e;
  so->shadows = (rr_shadow_mode)v;
  if ((e = rr_json_int(r, obj, "max_depth", 0, RR_MAX_DEPTH, &so->max_depth))) return e;
  const char *text, *arg;
  char name[32];
  if (rr_json_get(obj, "aa_filter")) {
    if ((e = rr_json_string(r, obj, "aa_filter", &text))) return e;
    split_name(text, name, sizeof name, &arg);
    int f = rr_filter_from_name(name);
    float radius = 0;
    if (f < 0 || (arg && !float_in(arg, 0.5, RR_FILTER_MAX_RADIUS, &radius)))
      return rr_json_fail(r, "aa_filter", "expected box, mitchell[:R] or blackman-harris[:R] (R 0.5..4)");
    so->filter = (rr_filter)f, so->radius = radius;
    st->given |= RR_SETTING_FILTER;
  }
  if (rr_json_get(obj, "texture_filter")) {
    if ((e = rr_json_string(r, obj, "texture_filter", &text))) return e;
    split_name(text, name, sizeof name, &arg);
    int f = rr_texture_filter_from_name(name);
    long aniso = so->aniso;
    if (f < 0 || (arg && (f != RR_TEXTURE_ANISO || !count_in(arg, 1, 16, &aniso))))
      return rr_json_fail(r, "texture_filter", "expected nearest, bilinear, trilinear, aniso[:N] (N 1..16) or ewa");
    so->texture_filter = (rr_texture_filter)f, so->aniso = (int)aniso;
    st->given |= RR_SETTING_TEXTURE_FILTER;
  }
  if ((e = rr_json_float(r, obj, "lod_bias", -64, 64, &so->lod_bias))) return e;
  if ((e = rr_json_bool(r, obj, "alpha", &so->alpha))) return e;
  if ((e = rr_json_bool(r, obj, "default_lights", &so->default_lights))) return e;
  if ((e = rr_json_floats(r, obj, "background", 3, 0, MAX_COORD, so->background))) return e;
  so->has_background |= rr_json_get(obj, "background") != NULL;
  static const struct {
    const char *key;
    unsigned bit;
  } bits[] = {{"method", RR_SETTING_METHOD}, {"cull_backfaces", RR_SETTING_CULL}, {"shade", RR_SETTING_SHADE},
              {"shadows", RR_SETTING_SHADOWS}, {"max_depth", RR_SETTING_MAX_DEPTH}, {"lod_bias", RR_SETTING_LOD_BIAS},
              {"alpha", RR_SETTING_ALPHA}, {"default_lights", RR_SETTING_DEFAULT_LIGHTS},
              {"background", RR_SETTING_BACKGROUND}};
  for (size_t k = 0; k < sizeof bits / sizeof *bits; k++)
    if (rr_json_get(obj, bits[k].key)) st->given |= bits[k].bit;
  return RR_OK;
}

/* ---- transforms ------------------------------------------------------------------- */

/* An affine map x -> m x + t in double precision. */
typedef struct xform {
  double m[3][3], t[3];
} xform;

static void mat_mul(double out[3][3], const double a[3][3], const double b[3][3]) {
  double o[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) o[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
  memcpy(out, o, sizeof o);
}

static double det3(const double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* The mesh's transform: "matrix" (4 rows of 4, acting on column vectors, bottom row
 * 0 0 0 1), or scale, then rotate (degrees about X, then Y, then Z), then translate. */
/* m turned by deg degrees about X, then Y, then Z (the fixed world axes): Rz·Ry·Rx·m. */
static void rotate_by(const double deg[3], double m[3][3]) {
  for (int axis = 0; axis < 3; axis++) {
    double a = deg[axis] * (RR_PI / 180), c = cos(a), sn = sin(a);
    int p = (axis + 1) % 3, q = (axis + 2) % 3; /* rotates p towards q: right-handed about `axis` */
    double rm[3][3] = {{0}};
    rm[axis][axis] = 1, rm[p][p] = c, rm[q][q] = c, rm[p][q] = -sn, rm[q][p] = sn;
    mat_mul(m, rm, m);
  }
}

static rr_error read_xform(json_reader *r, const cJSON *obj, xform *x) {
  *x = (xform){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  const cJSON *matrix = rr_json_get(obj, "matrix");
  rr_error e = RR_OK;
  if (matrix) {
    if (rr_json_get(obj, "translate") || rr_json_get(obj, "rotate") || rr_json_get(obj, "scale"))
      return rr_json_fail(r, NULL, "give either 'matrix' or 'translate', 'rotate' and 'scale', not both");
    if (!cJSON_IsArray(matrix) || cJSON_GetArraySize(matrix) != 4)
      return rr_json_fail(r, "matrix", "expected four rows of four numbers");
    double row[4][4];
    size_t len = rr_json_enter(r, "matrix", 0);
    int i = 0;
    for (const cJSON *rw = matrix->child; rw && !e; rw = rw->next, i++) {
      size_t l2 = rr_json_enter(r, NULL, i);
      e = rr_json_array_doubles(r, rw, 4, -MAX_COORD, MAX_COORD, row[i]);
      rr_json_leave(r, l2);
    }
    rr_json_leave(r, len);
    if (e) return e;
    if (row[3][0] != 0 || row[3][1] != 0 || row[3][2] != 0 || row[3][3] != 1)
      return rr_json_fail(r, "matrix", "the bottom row must be 0 0 0 1");
    for (i = 0; i < 3; i++) {
      for (int j = 0; j < 3; j++) x->m[i][j] = row[i][j];
      x->t[i] = row[i][3];
    }
  } else {
    /* doubles throughout: the file's own digits, not the floats nearest them */
    double s[3] = {1, 1, 1}, deg[3] = {0, 0, 0};
    if (cJSON_IsNumber(rr_json_get(obj, "scale"))) {
      e = rr_json_double(r, obj, "scale", -MAX_COORD, MAX_COORD, &s[0]);
      s[1] = s[2] = s[0];
    } else {
      e = rr_json_doubles(r, obj, "scale", 3, -MAX_COORD, MAX_COORD, s);
    }
    if (e || (e = rr_json_doubles(r, obj, "rotate", 3, -1e6, 1e6, deg)) ||
        (e = rr_json_doubles(r, obj, "translate", 3, -MAX_COORD, MAX_COORD, x->t)))
      return e;
    double m[3][3] = {{s[0], 0, 0}, {0, s[1], 0}, {0, 0, s[2]}};
    rotate_by(deg, m);
    memcpy(x->m, m, sizeof m);
  }
  double m[3][3]; /* (a copy: GCC's inliner misjudges x->m's size otherwise) */
  memcpy(m, x->m, sizeof m);
  double d = det3(m);
  if (!(fabs(d) > 1e-300) || !isfinite(d)) return rr_json_fail(r, NULL, "the transform is singular (a zero scale?)");
  return RR_OK;
}

static vec3 xf_point(const xform *x, vec3 p, bool direction) {
  double o[3];
  for (int i = 0; i < 3; i++)
    o[i] = x->m[i][0] * p.x + x->m[i][1] * p.y + x->m[i][2] * p.z + (direction ? 0 : x->t[i]);
  return v3((float)o[0], (float)o[1], (float)o[2]);
}

/* A unit vector through a 3×3 matrix, normalised in double. */
static vec3 xf_unit(const double m[3][3], vec3 v) {
  double o[3], l = 0;
  for (int i = 0; i < 3; i++) o[i] = m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z, l += o[i] * o[i];
  l = l > 0 ? 1 / sqrt(l) : 0;
  return v3((float)(o[0] * l), (float)(o[1] * l), (float)(o[2] * l));
}

/* Moves triangles t0.. and the cameras and lights from c0, l0 on by x. Normals go
 * through the inverse transpose; a mirroring transform swaps corners 1 and 2 so
 * that front faces stay front faces. */
static void swapf(float *a, float *b) {
  float t = *a;
  *a = *b, *b = t;
}

static bool is_identity(const xform *x) {
  static const xform id = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  return memcmp(x, &id, sizeof id) == 0;
}

/* An analytic primitive i (a built-in's) moved by x (nm: its cofactor matrix): a
 * plane's point and normal (by the inverse transpose); a sphere's centre, and its
 * radius by the scale, which must be uniform (a sphere stays a sphere). */
static rr_error xform_analytic(json_reader *r, rr_scene *s, const xform *x, const double nm[3][3], uint32_t i) {
  uint32_t j = scene_st(s, i);
  float *a = s->ana + (size_t)ANA_FLOATS * j;
  vec3 c = xf_point(x, v3(a[0], a[1], a[2]), false);
  if (!(fabsf(c.x) <= 1e30f && fabsf(c.y) <= 1e30f && fabsf(c.z) <= 1e30f))
    return rr_json_fail(r, NULL, "the transform takes vertices beyond 1e30");
  for (int k = 0; k < 3; k++) s->p[k][0][j] = c.x, s->p[k][1][j] = c.y, s->p[k][2][j] = c.z;
  a[0] = c.x, a[1] = c.y, a[2] = c.z;
  if (scene_kind(s, i) == RR_GEOMETRY_BOX) return rr_json_fail(r, NULL, "boxes are placed by 'boxes', not moved");
  if (scene_kind(s, i) == RR_GEOMETRY_PLANE) {
    vec3 n = xf_unit(nm, v3(a[3], a[4], a[5]));
    a[3] = n.x, a[4] = n.y, a[5] = n.z;
    return RR_OK;
  }
  /* uniform: the columns of m orthogonal and of one length */
  double len[3], dev = 0;
  for (int j = 0; j < 3; j++) len[j] = sqrt(x->m[0][j] * x->m[0][j] + x->m[1][j] * x->m[1][j] + x->m[2][j] * x->m[2][j]);
  for (int j = 0; j < 3; j++) {
    int k = (j + 1) % 3;
    double dot = x->m[0][j] * x->m[0][k] + x->m[1][j] * x->m[1][k] + x->m[2][j] * x->m[2][k];
    dev = fmax(dev, fmax(fabs(len[j] - len[0]), fabs(dot) / len[0]));
  }
  if (!(dev <= 1e-6 * len[0])) return rr_json_fail(r, NULL, "a sphere takes only a uniform scale (rotation, translation)");
  double rad = a[3] * len[0];
  if (!(rad > 0 && rad <= 1e30)) return rr_json_fail(r, NULL, "the transform takes a sphere's radius out of range");
  a[3] = (float)rad;
  return RR_OK;
}

static rr_error apply_xform(json_reader *r, rr_scene *s, const xform *x, uint32_t t0, uint32_t c0, uint32_t l0) {
  if (is_identity(x)) return RR_OK; /* the mesh as its file has it, normals' bits too */
  double d = det3(x->m), nm[3][3]; /* the cofactor matrix: the inverse transpose times det */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      nm[i][j] = (x->m[i1][j1] * x->m[i2][j2] - x->m[i1][j2] * x->m[i2][j1]) * (d < 0 ? -1 : 1);
    }
  for (uint32_t i = t0; i < s->ntris; i++) {
    uint32_t in, j = scene_locate(s, i, &in);
    if (in != RR_MISS) continue; /* an instance: its transform moves (below) */
    if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) {
      rr_error e = xform_analytic(r, s, x, nm, i);
      if (e) return e;
      continue;
    }
    unsigned inf = scene_inf(s, i);
    for (int k = 0; k < 3; k++) {
      vec3 p = xf_point(x, scene_vertex(s, k, i), inf >> k & 1u);
      if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z) || fabsf(p.x) > 1e30f || fabsf(p.y) > 1e30f ||
          fabsf(p.z) > 1e30f)
        return rr_json_fail(r, NULL, "the transform takes vertices beyond 1e30");
      s->p[k][0][j] = p.x, s->p[k][1][j] = p.y, s->p[k][2][j] = p.z;
      if (s->n[0][0]) {
        vec3 n = xf_unit(nm, v3(s->n[k][0][j], s->n[k][1][j], s->n[k][2][j]));
        s->n[k][0][j] = n.x, s->n[k][1][j] = n.y, s->n[k][2][j] = n.z;
      }
    }
    if (d < 0) {
      for (int c = 0; c < 3; c++) {
        swapf(&s->p[1][c][j], &s->p[2][c][j]);
        if (s->n[0][0]) swapf(&s->n[1][c][j], &s->n[2][c][j]);
        if (s->col[0][0]) swapf(&s->col[1][c][j], &s->col[2][c][j]);
        if (c < 2 && s->uv[0][0]) swapf(&s->uv[1][c][j], &s->uv[2][c][j]);
      }
      if (s->inf) s->inf[j] = (uint8_t)((inf & 1u) | (inf >> 1 & 2u) | (inf << 1 & 4u));
    }
  }
  if (s->inst && s->inst->base >= t0) /* instances loaded with the object: x after their transforms */
    for (uint32_t k = 0; k < s->inst->n; k++) {
      float *m = s->inst->xf[k], o[12];
      for (int r0 = 0; r0 < 3; r0++)
        for (int c = 0; c < 4; c++)
          o[4 * r0 + c] = (float)(x->m[r0][0] * m[c] + x->m[r0][1] * m[4 + c] + x->m[r0][2] * m[8 + c] +
                                  (c == 3 ? x->t[r0] : 0));
      rr_error e = rr_instance_set(s, k, o);
      if (e) return rr_json_fail(r, NULL, "%s", rr_device_message(s->dev));
      if (k + 1 == s->inst->n) rr_scene_update_bounds(s);
    }
  for (uint32_t c = c0; c < s->ncameras; c++) {
    file_camera *fc = &s->cameras[c];
    fc->eye = xf_point(x, fc->eye, false);
    fc->fwd = xf_unit(x->m, fc->fwd);
    vec3 up = xf_unit(x->m, fc->up);
    fc->up = v3_norm(v3_sub(up, v3_scale(fc->fwd, v3_dot(up, fc->fwd))));
  }
  for (uint32_t l = l0; l < s->nlights; l++) {
    rr_light_info *li = &s->lights[l];
    vec3 p = xf_point(x, v3(li->position[0], li->position[1], li->position[2]), false);
    vec3 dir = xf_unit(x->m, v3(li->direction[0], li->direction[1], li->direction[2]));
    li->position[0] = p.x, li->position[1] = p.y, li->position[2] = p.z;
    li->direction[0] = dir.x, li->direction[1] = dir.y, li->direction[2] = dir.z;
  }
  return RR_OK;
}

/* ---- meshes ---------------------------------------------------------------------- */

/* What the items of a scene file read besides their JSON: the scene, and where
 * their files are found. */
typedef struct mesh_arg {
  rr_scene *s;
  const char *base_dir;
  const rr_load_options *opt;
} mesh_arg;

static rr_error resolve_path(json_reader *r, const char *key, const char *base_dir, const char *rel, bool sandbox,
                             char out[MAX_PATH]);

/* The material override of a mesh or primitive, applied to materials m0.. (those
 * its load added): each key given replaces that value, the rest stay. A "texture"
 * (an image file, relative to the scene file) replaces the base colour texture and
 * must be readable: a scene that names one is not drawn without it. */
static int model_from_name(const char *name) {
  return find_name(name, rr_material_model_name, RR_MATERIAL_MODEL_COUNT);
}

static rr_error read_material(json_reader *r, const cJSON *obj, const mesh_arg *a, uint32_t m0) {
  static const char *const keys[] = {"model", "color", "specular", "shininess", "emission", "opacity", "metallic",
                                     "roughness", "mirror", "texture", NULL};
  rr_scene *s = a->s;
  const char *texture = NULL;
  char path[MAX_PATH];
  rr_error e = rr_json_keys(r, obj, keys);
  if (!e) e = rr_json_string(r, obj, "texture", &texture);
  if (!e && texture) e = resolve_path(r, "texture", a->base_dir, texture, a->opt->sandbox, path);
  for (uint32_t m = m0; !e && m < s->nmaterials; m++) {
    rr_material_info mi;
    rr_scene_get_material_info(s, m, &mi);
    float color[3] = {mi.color[0], mi.color[1], mi.color[2]};
    rr_material_params p = mi.params;
    int model = p.model, mirror = p.illum == 3;
    if ((e = rr_json_named(r, obj, "model", model_from_name, "phong or pbr", &model)) ||
        (e = rr_json_floats(r, obj, "color", 3, 0, MAX_COORD, color)) ||
        (e = rr_json_floats(r, obj, "specular", 3, 0, MAX_COORD, p.specular)) ||
        (e = rr_json_float(r, obj, "shininess", 0, 10000, &p.shininess)) ||
        (e = rr_json_floats(r, obj, "emission", 3, 0, MAX_COORD, p.emission)) ||
        (e = rr_json_float(r, obj, "opacity", 0, 1, &p.opacity)) || (e = rr_json_float(r, obj, "metallic", 0, 1, &p.metallic)) ||
        (e = rr_json_float(r, obj, "roughness", 0, 1, &p.roughness)) || (e = rr_json_bool(r, obj, "mirror", &mirror)))
      break;
    p.model = (rr_material_model)model;
    if (rr_json_get(obj, "mirror")) p.illum = mirror ? 3 : (p.illum == 3 ? -1 : p.illum);
    if (rr_scene_set_material(s, m, color, &p) != RR_OK) {
      char msg[256];
      snprintf(msg, sizeof msg, "%s", rr_device_message(s->dev));
      e = rr_json_fail(r, NULL, "%s", msg);
    } else if (texture && !rr_material_texture_file(&s->materials[m], path, texture))
      e = rr_json_fail(r, "texture", "cannot read the image '%.200s'", texture);
  }
  return e;
}

/* base_dir/rel (rel itself when absolute) into out; with the sandbox, only a path
 * that resolves (symbolic links followed) inside base_dir. */
static rr_error resolve_path(json_reader *r, const char *key, const char *base_dir, const char *rel, bool sandbox,
                             char out[MAX_PATH]) {
  int n = rel[0] == '/' ? snprintf(out, MAX_PATH, "%s", rel) : snprintf(out, MAX_PATH, "%s/%s", base_dir, rel);
  if (n < 0 || n >= MAX_PATH) return rr_json_fail(r, key, "path too long");
  if (!sandbox) return RR_OK;
  char base_real[PATH_MAX], real[PATH_MAX];
  if (!realpath(base_dir, base_real)) return rr_json_fail(r, key, "cannot resolve the base directory '%s'", base_dir);
  if (!realpath(out, real)) return rr_json_fail(r, key, "cannot open '%.200s'", rel);
  size_t b = strlen(base_real);
  if (strncmp(real, base_real, b) != 0 || (real[b] != '/' && !(b == 1 && base_real[0] == '/')))
    return rr_json_fail(r, key, "'%.200s' is outside the scene file's directory (sandbox)", rel);
  snprintf(out, MAX_PATH, "%s", real);
  return RR_OK;
}

static rr_error read_instances(json_reader *r, const cJSON *list, rr_scene *s, uint32_t t0, uint64_t faces, uint32_t g0);

/* A mesh: "file" or "builtin", "name", a transform, "material"; or, instanced, the
 * same with "transforms" (one per instance) in place of the transform. */
static rr_error read_mesh(json_reader *r, const cJSON *obj, const mesh_arg *a, bool instanced) {
  rr_scene *s = a->s;
  const char *base_dir = a->base_dir;
  const rr_load_options *opt = a->opt;
  static const char *const keys[] = {"file",   "builtin", "name",     "translate", "rotate",
                                     "scale",  "matrix",  "material", "smooth",    NULL};
  static const char *const inst_keys[] = {"file", "builtin", "name", "transforms", "material", "smooth", NULL};
  rr_error e = rr_json_keys(r, obj, instanced ? inst_keys : keys);
  if (e) return e;
  const char *file = NULL, *builtin = NULL, *name = NULL;
  if ((e = rr_json_string(r, obj, "file", &file)) || (e = rr_json_string(r, obj, "builtin", &builtin)) ||
      (e = rr_json_string(r, obj, "name", &name)))
    return e;
  if (!file == !builtin) return rr_json_fail(r, NULL, "expected one of 'file' (a path) and 'builtin' (a name)");
  xform x;
  if ((e = read_xform(r, obj, &x))) return e;
  int smooth = 0;
  if ((e = rr_json_bool(r, obj, "smooth", &smooth))) return e;
  const cJSON *material = rr_json_get(obj, "material");
  uint32_t t0 = s->ntris, g0 = s->ngeoms, m0 = s->nmaterials, c0 = s->ncameras, l0 = s->nlights;
  uint64_t faces = scene_faces(s);
  char path[MAX_PATH];
  if (builtin) {
    if (!opt->builtins) return rr_json_fail(r, "builtin", "built-in meshes are not allowed here");
    if (opt->sandbox && (strncmp(builtin, "grid:", 5) == 0 || strncmp(builtin, "grid-flat:", 10) == 0))
      return rr_json_fail(r, "builtin", "grid: reads a file, which the sandbox does not allow (use 'file' and a transform)");
    e = rr_scene_load_builtin(s, builtin);
    if (e == RR_ERROR_UNSUPPORTED)
      return rr_json_fail(r, "builtin", "unknown built-in '%.64s' (expected demo, plane[:N], sphere[:N], box[:N], "
                                     "torus[:N], rooms[:N], spheres[:N], ground, ground:inf, checker, grid:PATH:N or grid-flat:PATH:N)", builtin);
  } else {
    if (!file[0]) return rr_json_fail(r, "file", "empty path");
    if (strlen(file) >= MAX_PATH) return rr_json_fail(r, "file", "path too long");
    if ((e = resolve_path(r, "file", base_dir, file, opt->sandbox, path))) return e;
    e = rr_scene_import_guarded(s, path);
  }
  if (e) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", rr_device_message(s->dev));
    return rr_json_fail(r, builtin ? "builtin" : "file", "%s", msg);
  }
  if (scene_faces(s) == faces) return rr_json_fail(r, builtin ? "builtin" : "file", "no triangles");
  for (uint32_t g = g0; name && g < s->ngeoms; g++)
    if ((e = rr_scene_name_geometry(s, g, name))) return e;
  if (instanced && (e = read_instances(r, rr_json_get(obj, "transforms"), s, t0, faces, g0))) return e;
  if ((e = apply_xform(r, s, &x, t0, c0, l0))) return e;
  if (smooth && (e = rr_scene_smooth_normals(s, t0, s->ntris))) return e;
  if (material) {
    size_t len = rr_json_enter(r, "material", 0);
    e = read_material(r, material, a, m0);
    rr_json_leave(r, len);
  }
  return e;
}

/* "transforms": one transform object per instance of the mesh stored from t0 on. */
static rr_error read_instances(json_reader *r, const cJSON *list, rr_scene *s, uint32_t t0, uint64_t faces, uint32_t g0) {
  static const char *const keys[] = {"translate", "rotate", "scale", "matrix", NULL};
  if (!list) return rr_json_fail(r, NULL, "missing 'transforms'");
  int n = cJSON_GetArraySize(list);
  if (!cJSON_IsArray(list) || n < 1) return rr_json_fail(r, "transforms", "expected an array of transform objects");
  if (s->inst) return rr_json_fail(r, NULL, "a scene holds one instanced mesh");
  if (s->ntris == t0) return rr_json_fail(r, NULL, "no triangles kept");
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t j = t0; j < s->ntris; j++)
    for (int k = 0; k < 3; k++) lo = v3_min(lo, scene_stored_vertex(s, k, j)), hi = v3_max(hi, scene_stored_vertex(s, k, j));
  float (*xf)[12] = malloc((size_t)n * sizeof *xf);
  if (!xf) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for %d instances", n);
  rr_error e = RR_OK;
  int i = 0;
  xform x;
  for (const cJSON *item = list->child; item && !e; item = item->next, i++) {
    size_t len = rr_json_enter(r, "transforms", 0);
    rr_json_enter(r, NULL, i);
    e = !cJSON_IsObject(item) ? rr_json_fail(r, NULL, "expected a transform object") : rr_json_keys(r, item, keys);
    if (!e) e = read_xform(r, item, &x);
    for (int row = 0; !e && row < 3; row++)
      for (int c = 0; c < 4; c++) xf[i][4 * row + c] = (float)(c < 3 ? x.m[row][c] : x.t[row]);
    const char *why = e ? NULL : rr_instance_problem(xf[i], lo, hi);
    if (why) e = rr_json_fail(r, NULL, "%s", why);
    rr_json_leave(r, len);
  }
  if (!e && rr_scene_instance(s, t0, scene_faces(s) - faces, g0, (uint32_t)n, (const float (*)[12])xf) != RR_OK) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", rr_device_message(s->dev));
    e = rr_json_fail(r, NULL, "%s", msg);
  }
  free(xf);
  return e;
}

/* ---- analytic primitives ----------------------------------------------------------- */

/* A sphere ("center", "radius"), a plane ("point", "normal") or a box ("center",
 * "size", "rotate"), with "name" and "material": one geometry of one primitive,
 * after the meshes. */
static rr_error read_analytic(json_reader *r, const cJSON *obj, const mesh_arg *ma, prim_kind kind) {
  rr_scene *s = ma->s;
  static const char *const sphere_keys[] = {"center", "radius", "name", "material", NULL};
  static const char *const plane_keys[] = {"point", "normal", "name", "material", NULL};
  static const char *const box_keys[] = {"center", "size", "rotate", "name", "material", NULL};
  bool sphere = kind == RR_GEOMETRY_SPHERE, box = kind == RR_GEOMETRY_BOX;
  rr_error e = rr_json_keys(r, obj, sphere ? sphere_keys : box ? box_keys : plane_keys);
  if (e) return e;
  const char *need[2] = {sphere || box ? "center" : "point", sphere ? "radius" : box ? "size" : "normal"}, *name = NULL;
  for (int k = 0; k < 2; k++)
    if (!rr_json_get(obj, need[k])) return rr_json_fail(r, NULL, "missing '%s'", need[k]);
  float v[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  if ((e = rr_json_floats(r, obj, need[0], 3, -MAX_COORD, MAX_COORD, v)) || (e = rr_json_string(r, obj, "name", &name)))
    return e;
  if (box) {
    double size[3], deg[3] = {0, 0, 0}, m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if ((e = rr_json_doubles(r, obj, "size", 3, 0, MAX_COORD, size)) ||
        (e = rr_json_doubles(r, obj, "rotate", 3, -1e6, 1e6, deg)))
      return e;
    rotate_by(deg, m);
    for (int k = 0; k < 3; k++) {
      v[3 + k] = (float)(size[k] / 2);
      if (!(v[3 + k] > 0)) return rr_json_fail(r, "size", "every size must be positive");
      v[6 + k] = (float)m[k][0], v[9 + k] = (float)m[k][1]; /* the turned x and y axes */
    }
  } else if (sphere) {
    const cJSON *rad = rr_json_get(obj, "radius");
    if (cJSON_IsNumber(rad) && !(rad->valuedouble > 0))
      return rr_json_fail(r, "radius", "must be positive, not %g", rad->valuedouble);
    e = rr_json_float(r, obj, "radius", 0, MAX_COORD, &v[3]);
    if (!e && !(v[3] > 0)) e = rr_json_fail(r, "radius", "must be positive");
  } else {
    e = rr_json_floats(r, obj, "normal", 3, -MAX_COORD, MAX_COORD, v + 3);
    if (!e && v[3] == 0 && v[4] == 0 && v[5] == 0) e = rr_json_fail(r, "normal", "a zero normal");
  }
  if (e) return e;
  uint32_t m0 = s->nmaterials, g0 = s->ngeoms;
  e = sphere ? rr_scene_add_spheres(s, v, 1, NULL) : box ? rr_scene_add_boxes(s, v, 1, NULL) : rr_scene_add_planes(s, v, 1, NULL);
  if (e) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", rr_device_message(s->dev));
    return rr_json_fail(r, NULL, "%s", msg);
  }
  if (name && (e = rr_scene_name_geometry(s, g0, name))) return e;
  const cJSON *material = rr_json_get(obj, "material");
  if (material) {
    size_t len = rr_json_enter(r, "material", 0);
    e = read_material(r, material, ma, m0);
    rr_json_leave(r, len);
  }
  return e;
}

static rr_error sphere_item(json_reader *r, const cJSON *item, void *arg) {
  return read_analytic(r, item, arg, RR_GEOMETRY_SPHERE);
}
static rr_error plane_item(json_reader *r, const cJSON *item, void *arg) {
  return read_analytic(r, item, arg, RR_GEOMETRY_PLANE);
}
static rr_error box_item(json_reader *r, const cJSON *item, void *arg) {
  return read_analytic(r, item, arg, RR_GEOMETRY_BOX);
}

/* ---- lights ---------------------------------------------------------------------- */

static rr_error read_light(json_reader *r, const cJSON *obj, rr_scene *s) {
  static const char *const keys[] = {"type", "name", "position", "direction", "color", "intensity", "inner", "outer",
                                     "ground", NULL};
  rr_error e = rr_json_keys(r, obj, keys);
  if (e) return e;
  const char *type = NULL, *name = NULL;
  if ((e = rr_json_string(r, obj, "type", &type)) || (e = rr_json_string(r, obj, "name", &name))) return e;
  if (!type) return rr_json_fail(r, NULL, "missing 'type' (point, directional, spot or sky)");
  rr_light_info l = {.name = name, .color = {1, 1, 1}, .outer_cone_deg = 45};
  /* the keys each type takes, besides type, name, color and intensity */
  static const struct {
    const char *name;
    rr_light_type type;
    bool position, direction, cone, ground;
  } types[] = {{"point", RR_LIGHT_POINT, true, false, false, false},
               {"directional", RR_LIGHT_DIRECTIONAL, false, true, false, false},
               {"spot", RR_LIGHT_SPOT, true, true, true, false},
               {"sky", RR_LIGHT_AMBIENT, false, false, false, true}};
  int t = 0;
  while (t < 4 && strcmp(type, types[t].name) != 0) t++;
  if (t == 4) return rr_json_fail(r, "type", "expected point, directional, spot or sky");
  l.type = types[t].type;
  const char *needs[] = {"position", "direction"};
  bool takes[] = {types[t].position, types[t].direction};
  for (int k = 0; k < 2; k++) {
    if (takes[k] && !rr_json_get(obj, needs[k])) return rr_json_fail(r, NULL, "a %s light needs '%s'", type, needs[k]);
    if (!takes[k] && rr_json_get(obj, needs[k])) return rr_json_fail(r, needs[k], "not used by a %s light", type);
  }
  const char *only[] = {"inner", "outer", "ground"};
  bool used[] = {types[t].cone, types[t].cone, types[t].ground};
  for (int k = 0; k < 3; k++)
    if (!used[k] && rr_json_get(obj, only[k])) return rr_json_fail(r, only[k], "not used by a %s light", type);
  float intensity = 1;
  if ((e = rr_json_floats(r, obj, "position", 3, -MAX_COORD, MAX_COORD, l.position)) ||
      (e = rr_json_floats(r, obj, "direction", 3, -MAX_COORD, MAX_COORD, l.direction)) ||
      (e = rr_json_floats(r, obj, "color", 3, 0, MAX_COORD, l.color)) ||
      (e = rr_json_float(r, obj, "intensity", 0, MAX_COORD, &intensity)) ||
      (e = rr_json_float(r, obj, "inner", 0, 90, &l.inner_cone_deg)) ||
      (e = rr_json_float(r, obj, "outer", 0, 90, &l.outer_cone_deg)) ||
      (e = rr_json_floats(r, obj, "ground", 3, 0, MAX_COORD, l.ground)))
    return e;
  for (int c = 0; c < 3; c++) l.color[c] *= intensity;
  if (l.type == RR_LIGHT_SPOT && !(l.inner_cone_deg <= l.outer_cone_deg && l.outer_cone_deg > 0))
    return rr_json_fail(r, NULL, "expected 0 <= inner <= outer <= 90 degrees, outer > 0");
  if (rr_scene_add_light(s, &l) != RR_OK) {
    char msg[256];
    snprintf(msg, sizeof msg, "%s", rr_device_message(s->dev));
    return rr_json_fail(r, NULL, "%s", msg);
  }
  return RR_OK;
}

/* ---- the file ---------------------------------------------------------------------- */

/* Runs `read` over every element of the array obj[key] (absent: nothing). */
static rr_error each(json_reader *r, const cJSON *root, const char *key, bool required,
                     rr_error (*read)(json_reader *, const cJSON *, void *), void *arg) {
  const cJSON *list = rr_json_get(root, key);
  if (!list && required) return rr_json_fail(r, NULL, "missing '%s'", key);
  if (!list) return RR_OK;
  if (!cJSON_IsArray(list)) return rr_json_fail(r, key, "expected an array of objects");
  int i = 0;
  rr_error e = RR_OK;
  for (const cJSON *item = list->child; item && !e; item = item->next, i++) {
    size_t len = rr_json_enter(r, key, 0);
    rr_json_enter(r, NULL, i);
    e = cJSON_IsObject(item) ? read(r, item, arg) : rr_json_fail(r, NULL, "expected an object");
    rr_json_leave(r, len);
  }
  return e;
}

static rr_error mesh_item(json_reader *r, const cJSON *item, void *arg) {
  return read_mesh(r, item, arg, false);
}

static rr_error light_item(json_reader *r, const cJSON *item, void *arg) { return read_light(r, item, arg); }

/* The settings' defaults: the library's, with auto and lit as the command line has them. */
static void settings_init(rr_scene_settings *st) {
  memset(st, 0, sizeof *st);
  rr_camera_init(&st->camera);
  rr_render_options_init(&st->render);
  rr_shade_options_init(&st->shade);
  st->render.method = RR_METHOD_AUTO;
  st->shade.mode = RR_SHADE_LIT;
}

/* A reconstruction's camera ({"colmap": DIR, "image": NAME|INDEX} or {"nerf": FILE,
 * "frame": FILE_PATH|INDEX}; rr_camera_import): the camera, and its image's size as
 * the render size unless "render" gave one. */
static rr_error import_camera(json_reader *r, const cJSON *obj, const char *base_dir, const rr_load_options *opt,
                              rr_scene_settings *st) {
  bool colmap = rr_json_get(obj, "colmap") != NULL;
  const char *key = colmap ? "colmap" : "nerf", *sel_key = colmap ? "image" : "frame";
  static const char *const colmap_keys[] = {"colmap", "image", NULL}, *const nerf_keys[] = {"nerf", "frame", NULL};
  rr_error e = rr_json_keys(r, obj, colmap ? colmap_keys : nerf_keys);
  const char *file = NULL;
  if (!e) e = rr_json_string(r, obj, key, &file);
  if (e) return e;
  const cJSON *sel = rr_json_get(obj, sel_key);
  char index[32];
  const char *select = NULL;
  if (cJSON_IsString(sel)) select = sel->valuestring;
  else if (cJSON_IsNumber(sel) && sel->valuedouble >= 0 && sel->valuedouble <= INT_MAX && sel->valuedouble == (int)sel->valuedouble)
    snprintf(index, sizeof index, "%d", (int)sel->valuedouble), select = index;
  else if (sel) return rr_json_fail(r, sel_key, "expected a name or an index >= 0");
  char path[MAX_PATH];
  if ((e = resolve_path(r, key, base_dir, file, opt->sandbox, path))) return e;
  rr_imported_camera ic;
  if (rr_camera_import(r->dev, path, select ? select : "0", &ic, 1, NULL) != RR_OK) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", rr_device_message(r->dev));
    return rr_json_fail(r, key, "%s", msg);
  }
  st->camera = ic.camera;
  st->camera_given = RR_CAMERA_FIELD_TYPE | RR_CAMERA_FIELD_EYE | RR_CAMERA_FIELD_TARGET | RR_CAMERA_FIELD_UP |
                     RR_CAMERA_FIELD_LENS;
  if (!(st->given & RR_SETTING_SIZE)) st->render.width = ic.width, st->render.height = ic.height, st->given |= RR_SETTING_SIZE;
  return RR_OK;
}

/* Everything of the file but the commit. */
static rr_error read_scene(json_reader *r, const cJSON *root, rr_scene *s, const char *base_dir,
                           const rr_load_options *opt, rr_scene_settings *st) {
  static const char *const keys[] = {"meshes", "instances", "spheres", "planes", "boxes", "lights", "camera", "render", "comment", NULL};
  rr_error e = rr_json_keys(r, root, keys);
  const char *comment;
  if (!e) e = rr_json_string(r, root, "comment", &comment);
  const cJSON *item;
  if (!e && (item = rr_json_get(root, "render"))) {
    size_t len = rr_json_enter(r, "render", 0);
    e = read_render(r, item, st);
    rr_json_leave(r, len);
  }
  if (!e && (item = rr_json_get(root, "camera"))) {
    size_t len = rr_json_enter(r, "camera", 0);
    if (cJSON_IsObject(item) && (rr_json_get(item, "colmap") || rr_json_get(item, "nerf")))
      e = import_camera(r, item, base_dir, opt, st);
    else
      e = read_camera(r, item, &st->camera, &st->camera_given, false);
    rr_json_leave(r, len);
  }
  mesh_arg ma = {s, base_dir, opt};
  /* meshes may be left out when spheres or planes are given */
  bool analytic = rr_json_get(root, "spheres") || rr_json_get(root, "planes") || rr_json_get(root, "boxes") ||
                  rr_json_get(root, "instances");
  if (!e) e = each(r, root, "meshes", !analytic, mesh_item, &ma);
  if (!e && (item = rr_json_get(root, "instances"))) { /* one instanced mesh, after the meshes */
    size_t len = rr_json_enter(r, "instances", 0);
    e = cJSON_IsObject(item) ? read_mesh(r, item, &ma, true) : rr_json_fail(r, NULL, "expected an object");
    rr_json_leave(r, len);
  }
  if (!e) e = each(r, root, "spheres", false, sphere_item, &ma);
  if (!e) e = each(r, root, "planes", false, plane_item, &ma);
  if (!e) e = each(r, root, "boxes", false, box_item, &ma);
  /* the scene file's world is Y-up, its front +Z, whatever the files' axes */
  s->up = v3(0, 1, 0), s->front = v3(0, 0, 1);
  if (!e) e = each(r, root, "lights", false, light_item, s);
  if (!e && s->ntris == 0)
    e = rr_fail(s->dev, RR_ERROR_EMPTY, "%s has no triangles%s", r->what,
                s->skipped ? " (all were degenerate or non-finite)" : "");
  return e;
}

rr_error rr_scene_load_file(rr_device *dev, const char *path, const rr_load_options *opt, rr_scene **out,
                            rr_scene_settings *settings) {
  if (!path || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_scene_load_file: NULL argument");
  *out = NULL;
  rr_load_options o;
  rr_load_options_init(&o);
  if (opt) o = *opt;
  char what[320], base[MAX_PATH];
  snprintf(what, sizeof what, "scene file '%s'", path);
  const char *slash = strrchr(path, '/');
  if (o.base_dir) snprintf(base, sizeof base, "%s", o.base_dir);
  else if (!slash) snprintf(base, sizeof base, ".");
  else snprintf(base, sizeof base, "%.*s", slash == path ? 1 : (int)(slash - path), path);
  json_reader r = {.dev = dev, .what = what};
  progress_span progress = {dev, RR_PROGRESS_LOAD, 0, 1};
  rr_progress(&progress, 0);
  cJSON *root;
  rr_error e = rr_json_parse_file(&r, path, MAX_FILE_BYTES, &root);
  if (e) return e;
  rr_scene *s;
  if ((e = rr_scene_new(dev, &s))) {
    cJSON_Delete(root);
    return e;
  }
  s->max_tris = o.max_tris;
  rr_scene_settings st;
  settings_init(&st);
  e = read_scene(&r, root, s, base, &o, &st);
  cJSON_Delete(root);
  if (!e) {
    rr_scene_update_bounds(s);
    rr_progress(&progress, 1);
    e = rr_scene_commit(s);
  }
  if (e) {
    rr_scene_release(s);
    return e;
  }
  if (settings) *settings = st;
  *out = s;
  return rr_ok(dev);
}
