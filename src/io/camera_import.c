/* Cameras of reconstruction tools (rr_camera_import): COLMAP's text model and NeRF's
 * transforms.json, as OpenCV cameras of the library.
 *
 * COLMAP puts the centre of the top-left pixel at (0.5, 0.5), OpenCV (and rr_camera)
 * at (0, 0): cx, cy lose 0.5. Its pose is world-to-camera, a unit quaternion (w x y z)
 * and t, in OpenCV's axes. NeRF's cx, cy count pixel centres at integers already (as
 * its rays); its pose is camera-to-world in OpenGL's axes (x right, y up, z back).
 * The whole file is read and checked whatever is selected: a bad line is an error
 * even when the image asked for comes before it. */
#define _XOPEN_SOURCE 700 /* getline */
#include "io/io.h"
#include "io/json_read.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

enum { MAX_JSON_BYTES = 64 << 20, NAME_CAP = sizeof(((rr_imported_camera *)0)->name) };

/* The cameras read so far (a growing array). */
typedef struct cam_list {
  rr_imported_camera *v;
  int n, cap;
} cam_list;

static rr_imported_camera *list_add(rr_device *dev, cam_list *l) {
  if (l->n == l->cap) {
    int cap = l->cap ? 2 * l->cap : 16;
    rr_imported_camera *v = l->cap < INT_MAX / 2 ? realloc(l->v, sizeof *v * (size_t)cap) : NULL;
    if (!v) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %d cameras", l->n), NULL;
    l->v = v, l->cap = cap;
  }
  memset(&l->v[l->n], 0, sizeof l->v[0]);
  return &l->v[l->n++];
}

/* Sets the lens of *cam: kind, fx fy cx cy (OpenCV's pixel convention), dist. */
static void set_lens(rr_camera *cam, bool fisheye, double fx, double fy, double cx, double cy, const double *dist,
                     int ndist) {
  rr_camera_init(cam);
  cam->type = fisheye ? RR_CAMERA_OPENCV_FISHEYE : RR_CAMERA_OPENCV;
  cam->fx = (float)fx, cam->fy = (float)fy, cam->cx = (float)cx, cam->cy = (float)cy;
  for (int i = 0; i < ndist; i++) cam->dist[i] = (float)dist[i];
}

/* ---- COLMAP ------------------------------------------------------------------------ */

/* A model's parameters after the focal length(s) and centre: where each goes in dist. */
typedef struct colmap_model {
  const char *name;
  int nparams;      /* all of them, the focal length(s) and centre included */
  bool one_f;       /* f for both fx and fy */
  bool fisheye;     /* Kannala–Brandt: dist holds k1..k4 */
  int8_t slot[8];   /* slot[i]: the dist index of the i-th parameter after cx, cy */
} colmap_model;

/* COLMAP's models that are OpenCV's (the fisheye ones with one or two radial terms
 * are OpenCV's fisheye with the others zero). */
static const colmap_model colmap_models[] = {
    {"SIMPLE_PINHOLE", 3, true, false, {0}},
    {"PINHOLE", 4, false, false, {0}},
    {"SIMPLE_RADIAL", 4, true, false, {0}},
    {"RADIAL", 5, true, false, {0, 1}},
    {"OPENCV", 8, false, false, {0, 1, 2, 3}},
    {"FULL_OPENCV", 12, false, false, {0, 1, 2, 3, 4, 5, 6, 7}},
    {"OPENCV_FISHEYE", 8, false, true, {0, 1, 2, 3}},
    {"SIMPLE_RADIAL_FISHEYE", 4, true, true, {0}},
    {"RADIAL_FISHEYE", 5, true, true, {0, 1}},
};
#define COLMAP_NAMES \
  "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV, OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE or RADIAL_FISHEYE"

/* A text file read line by line. */
typedef struct text_file {
  FILE *f;
  const char *path;
  char *line;
  size_t line_cap;
  long lineno;
} text_file;

/* The next line (false at the end or on a read error, *err set then). */
static bool next_line(text_file *t, rr_device *dev, rr_error *err) {
  errno = 0;
  if (getline(&t->line, &t->line_cap, t->f) < 0) {
    if (ferror(t->f)) *err = rr_fail(dev, RR_ERROR_IO, "COLMAP file '%s': read error after line %ld", t->path, t->lineno);
    return false;
  }
  t->lineno++;
  return true;
}

/* Splits s into whitespace-separated fields; returns how many there are (fields
 * beyond cap are counted, not stored). */
static int split(char *s, char **field, int cap) {
  int n = 0;
  for (char *p = s;;) {
    p += strspn(p, " \t\r\n");
    if (!*p) return n;
    char *end = p + strcspn(p, " \t\r\n");
    if (n < cap) field[n] = p;
    n++;
    if (*end) *end++ = 0;
    p = end;
  }
}

static bool is_comment_or_blank(const char *s) {
  s += strspn(s, " \t\r\n");
  return !*s || *s == '#';
}

/* A finite number that is the whole field. */
static bool parse_double(const char *s, double *out) {
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (end == s || *end || errno == ERANGE || !isfinite(v)) return false;
  *out = v;
  return true;
}

/* A decimal integer in [lo, hi] that is the whole field. */
static bool parse_long(const char *s, long lo, long hi, long *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (end == s || *end || errno == ERANGE || v < lo || v > hi) return false;
  *out = v;
  return true;
}

/* A COLMAP camera: its id, lens and image size. */
typedef struct colmap_camera {
  long id;
  rr_camera cam;
  int width, height;
} colmap_camera;

static rr_error colmap_fail(rr_device *dev, const text_file *t, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static rr_error colmap_fail(rr_device *dev, const text_file *t, const char *fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return rr_fail(dev, RR_ERROR_PARSE, "COLMAP file '%s' line %ld: %s", t->path, t->lineno, msg);
}

static rr_error open_text(rr_device *dev, text_file *t, const char *path) {
  *t = (text_file){.path = path};
  t->f = fopen(path, "r");
  if (!t->f) return rr_fail(dev, RR_ERROR_IO, "COLMAP file '%s': %s", path, strerror(errno));
  return RR_OK;
}

static void close_text(text_file *t) {
  if (t->f) fclose(t->f);
  free(t->line);
}

/* cameras.txt: CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] per line. */
static rr_error colmap_cameras(rr_device *dev, const char *path, colmap_camera **out, int *nout) {
  text_file t;
  rr_error e = open_text(dev, &t, path);
  colmap_camera *v = NULL;
  int n = 0, cap = 0;
  while (!e && next_line(&t, dev, &e)) {
    if (is_comment_or_blank(t.line)) continue;
    char *w[17];
    int nw = split(t.line, w, 17);
    if (nw < 4) {
      e = colmap_fail(dev, &t, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
      break;
    }
    long id, width, height;
    if (!parse_long(w[0], 0, LONG_MAX, &id)) {
      e = colmap_fail(dev, &t, "bad camera id '%s' (expected an integer >= 0)", w[0]);
      break;
    }
    const colmap_model *m = NULL;
    for (size_t i = 0; i < sizeof colmap_models / sizeof colmap_models[0]; i++)
      if (!strcmp(w[1], colmap_models[i].name)) m = &colmap_models[i];
    if (!m) {
      e = colmap_fail(dev, &t, "camera model %s has no OpenCV equivalent (expected " COLMAP_NAMES ")", w[1]);
      break;
    }
    if (!parse_long(w[2], 1, RR_MAX_SIZE, &width) || !parse_long(w[3], 1, RR_MAX_SIZE, &height)) {
      e = colmap_fail(dev, &t, "bad image size '%s %s' (expected WIDTH HEIGHT, 1..%d)", w[2], w[3], RR_MAX_SIZE);
      break;
    }
    if (nw - 4 != m->nparams) {
      e = colmap_fail(dev, &t, "camera %ld: %s takes %d parameters, not %d", id, m->name, m->nparams, nw - 4);
      break;
    }
    double p[12], dist[8] = {0};
    for (int i = 0; i < m->nparams && !e; i++)
      if (!parse_double(w[4 + i], &p[i])) e = colmap_fail(dev, &t, "camera %ld: bad parameter '%s'", id, w[4 + i]);
    if (e) break;
    double fx = p[0], fy = m->one_f ? p[0] : p[1];
    const double *rest = p + (m->one_f ? 1 : 2); /* cx, cy, then the distortion */
    if (!(fx > 0 && fy > 0)) {
      e = colmap_fail(dev, &t, "camera %ld: the focal length must be > 0", id);
      break;
    }
    for (int i = 0; i < m->nparams - (m->one_f ? 3 : 4); i++) dist[m->slot[i]] = rest[2 + i];
    for (int i = 0; i < n; i++)
      if (v[i].id == id) e = colmap_fail(dev, &t, "camera %ld given twice", id);
    if (e) break;
    if (n == cap) {
      colmap_camera *nv = realloc(v, sizeof *v * (size_t)(cap = cap ? 2 * cap : 8));
      if (!nv) {
        e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for COLMAP cameras");
        break;
      }
      v = nv;
    }
    colmap_camera *c = &v[n++];
    c->id = id, c->width = (int)width, c->height = (int)height;
    set_lens(&c->cam, m->fisheye, fx, fy, rest[0] - 0.5, rest[1] - 0.5, dist, 8);
  }
  close_text(&t);
  if (e) free(v), v = NULL, n = 0;
  *out = v, *nout = n;
  return e;
}

/* The rotation of the quaternion (w x y z), normalised, row-major. */
static void quat_to_R(const double q[4], double R[9]) {
  double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - z * w), R[2] = 2 * (x * z + y * w);
  R[3] = 2 * (x * y + z * w), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - x * w);
  R[6] = 2 * (x * z - y * w), R[7] = 2 * (y * z + x * w), R[8] = 1 - 2 * (x * x + y * y);
}

/* Poses a camera from world-to-camera R (double, row-major) and t. */
static rr_error pose(rr_device *dev, rr_camera *cam, const double R[9], const double t[3]) {
  float Rf[9], tf[3];
  for (int i = 0; i < 9; i++) Rf[i] = (float)R[i];
  for (int i = 0; i < 3; i++) tf[i] = (float)t[i];
  return rr_camera_set_extrinsics(dev, cam, Rf, tf);
}

/* images.txt: per image IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then a line of
 * its 2D points (X Y POINT3D_ID triples; may be empty), as COLMAP writes and reads it. */
static rr_error colmap_images(rr_device *dev, const char *path, const colmap_camera *cams, int ncams, cam_list *out) {
  text_file t;
  rr_error e = open_text(dev, &t, path);
  while (!e && next_line(&t, dev, &e)) {
    if (is_comment_or_blank(t.line)) continue;
    char *w[10];
    int nw = split(t.line, w, 10);
    if (nw != 10) {
      e = colmap_fail(dev, &t, "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME (%d fields, not 10)", nw);
      break;
    }
    double q[4], tv[3], qn = 0;
    long id, cam_id;
    for (int i = 0; i < 7 && !e; i++)
      if (!parse_double(w[1 + i], i < 4 ? &q[i] : &tv[i - 4]))
        e = colmap_fail(dev, &t, "bad %s '%s' (expected a finite number)", i < 4 ? "quaternion" : "translation", w[1 + i]);
    if (e) break;
    if (!parse_long(w[0], 0, LONG_MAX, &id) || !parse_long(w[8], 0, LONG_MAX, &cam_id)) {
      e = colmap_fail(dev, &t, "bad image id '%s' or camera id '%s' (expected integers >= 0)", w[0], w[8]);
      break;
    }
    for (int i = 0; i < 4; i++) qn += q[i] * q[i];
    if (!(qn > 1e-12) || !isfinite(qn)) {
      e = colmap_fail(dev, &t, "image %ld: a zero quaternion", id);
      break;
    }
    const colmap_camera *c = NULL;
    for (int i = 0; i < ncams; i++)
      if (cams[i].id == cam_id) c = &cams[i];
    if (!c) {
      e = colmap_fail(dev, &t, "image %ld: camera %ld is not in cameras.txt", id, cam_id);
      break;
    }
    if (strlen(w[9]) >= NAME_CAP) {
      e = colmap_fail(dev, &t, "image %ld: name longer than %d bytes", id, (int)NAME_CAP - 1);
      break;
    }
    rr_imported_camera *ic = list_add(dev, out);
    if (!ic) {
      e = RR_ERROR_MEMORY;
      break;
    }
    ic->camera = c->cam, ic->width = c->width, ic->height = c->height;
    strcpy(ic->name, w[9]);
    double R[9];
    qn = sqrt(qn);
    for (int i = 0; i < 4; i++) q[i] /= qn;
    quat_to_R(q, R);
    if ((e = pose(dev, &ic->camera, R, tv))) {
      char msg[256];
      snprintf(msg, sizeof msg, "%s", rr_device_message(dev));
      e = colmap_fail(dev, &t, "image %ld: %s", id, msg);
      break;
    }
    /* its points line: absent only at the end of the file */
    if (!next_line(&t, dev, &e)) break;
    int np = split(t.line, w, 0);
    if (np % 3 != 0 && !is_comment_or_blank(t.line))
      e = colmap_fail(dev, &t, "expected the 2D points of image %ld (X Y POINT3D_ID triples, or an empty line)", id);
  }
  close_text(&t);
  return e;
}

static bool is_dir(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static bool ends_with(const char *s, const char *suffix) {
  size_t n = strlen(s), m = strlen(suffix);
  return n >= m && !strcmp(s + n - m, suffix);
}

/* The model in `dir` (cameras.txt and images.txt). */
static rr_error colmap_read(rr_device *dev, const char *dir, cam_list *out) {
  size_t n = strlen(dir);
  char *cp = malloc(n + 16), *ip = malloc(n + 16);
  rr_error e = RR_OK;
  if (!cp || !ip) e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory");
  colmap_camera *cams = NULL;
  int ncams = 0;
  if (!e) {
    const char *sep = n && dir[n - 1] == '/' ? "" : "/";
    sprintf(cp, "%s%scameras.txt", dir, sep), sprintf(ip, "%s%simages.txt", dir, sep);
    e = colmap_cameras(dev, cp, &cams, &ncams);
  }
  if (!e) e = colmap_images(dev, ip, cams, ncams, out);
  free(cams), free(cp), free(ip);
  return e;
}

/* ---- NeRF transforms.json ----------------------------------------------------------- */

/* The number `key` of the frame, else of the file (instant-ngp lets frames override
 * the intrinsics); *found tells whether either had it. */
static rr_error nerf_num(json_reader *r, const cJSON *root, const cJSON *frame, int fi, const char *key, double lo,
                         double hi, double *out, bool *found) {
  const cJSON *obj = rr_json_get(frame, key) ? frame : rr_json_get(root, key) ? root : NULL;
  if (found) *found = obj != NULL;
  if (!obj) return RR_OK;
  size_t len = obj == frame ? rr_json_enter(r, "frames", 0) : 0;
  if (obj == frame) rr_json_enter(r, NULL, fi);
  rr_error e = rr_json_double(r, obj, key, lo, hi, out);
  if (obj == frame) rr_json_leave(r, len);
  return e;
}

static rr_error nerf_frame(json_reader *r, const cJSON *root, const cJSON *frame, int fi, rr_imported_camera *ic) {
  rr_device *dev = r->dev;
  rr_error e;
  size_t len = rr_json_enter(r, "frames", 0);
  rr_json_enter(r, NULL, fi);
  if (!cJSON_IsObject(frame)) e = rr_json_fail(r, NULL, "expected an object with a 'transform_matrix'");
  else {
    const char *name = NULL;
    e = rr_json_string(r, frame, "file_path", &name);
    if (!e && name && strlen(name) >= NAME_CAP) e = rr_json_fail(r, "file_path", "longer than %d bytes", (int)NAME_CAP - 1);
    if (!e) snprintf(ic->name, NAME_CAP, "%s", name ? name : "");
    if (!name) snprintf(ic->name, NAME_CAP, "%d", fi);
  }
  rr_json_leave(r, len);
  if (e) return e;

  double w = 0, h = 0, fx = 0, fy = 0, ax, cx, cy, dist[8] = {0};
  bool has_w, has_h, has_fx, has_fy, has_ax, has_ay, has_cx, has_cy;
  if ((e = nerf_num(r, root, frame, fi, "w", 1, RR_MAX_SIZE, &w, &has_w)) ||
      (e = nerf_num(r, root, frame, fi, "h", 1, RR_MAX_SIZE, &h, &has_h)))
    return e;
  if (!has_w || !has_h || w != floor(w) || h != floor(h))
    return rr_json_fail(r, has_w && w == floor(w) ? "h" : "w", "expected the image size 'w' and 'h' (whole pixels)");
  /* a camera model as nerfstudio names it; instant-ngp's files have none */
  bool fisheye = false;
  const cJSON *model = rr_json_get(frame, "camera_model") ? rr_json_get(frame, "camera_model") : rr_json_get(root, "camera_model");
  if (model) {
    const char *s = cJSON_IsString(model) ? model->valuestring : "";
    fisheye = !strcmp(s, "OPENCV_FISHEYE");
    if (!fisheye && strcmp(s, "OPENCV") && strcmp(s, "PINHOLE") && strcmp(s, "SIMPLE_PINHOLE"))
      return rr_json_fail(r, "camera_model", "'%s' is not an OpenCV camera (expected OPENCV, OPENCV_FISHEYE or PINHOLE)", s);
  }
  const cJSON *ngp_fish = rr_json_get(root, "is_fisheye");
  if (cJSON_IsTrue(ngp_fish)) return rr_json_fail(r, "is_fisheye", "instant-ngp's equidistant fisheye is not supported");
  if ((e = nerf_num(r, root, frame, fi, "fl_x", 0, 1e30, &fx, &has_fx)) ||
      (e = nerf_num(r, root, frame, fi, "fl_y", 0, 1e30, &fy, &has_fy)))
    return e;
  if (!has_fx || fx == 0) {
    if ((e = nerf_num(r, root, frame, fi, "camera_angle_x", 1e-6, 3.14159, &ax, &has_ax))) return e;
    if (!has_ax) return rr_json_fail(r, "camera_angle_x", "missing (or 'fl_x')");
    fx = 0.5 * w / tan(0.5 * ax);
  }
  if (!has_fy || fy == 0) {
    double ay;
    if ((e = nerf_num(r, root, frame, fi, "camera_angle_y", 1e-6, 3.14159, &ay, &has_ay))) return e;
    fy = has_ay ? 0.5 * h / tan(0.5 * ay) : fx;
  }
  cx = w / 2, cy = h / 2;
  if ((e = nerf_num(r, root, frame, fi, "cx", -1e30, 1e30, &cx, &has_cx)) ||
      (e = nerf_num(r, root, frame, fi, "cy", -1e30, 1e30, &cy, &has_cy)))
    return e;
  static const char *const brown[] = {"k1", "k2", "p1", "p2", "k3"}, *const kb[] = {"k1", "k2", "k3", "k4"};
  for (int i = 0; i < (fisheye ? 4 : 5) && !e; i++)
    e = nerf_num(r, root, frame, fi, fisheye ? kb[i] : brown[i], -1e30, 1e30, &dist[i], NULL);
  if (e) return e;
  set_lens(&ic->camera, fisheye, fx, fy, cx, cy, dist, 8);
  ic->width = (int)w, ic->height = (int)h;

  /* camera-to-world in OpenGL's axes → world-to-camera in OpenCV's: R = (C·diag(1,-1,-1))ᵀ, t = -R·c */
  len = rr_json_enter(r, "frames", 0);
  rr_json_enter(r, NULL, fi);
  const cJSON *m = rr_json_get(frame, "transform_matrix");
  double row[4][4];
  if (!cJSON_IsArray(m) || cJSON_GetArraySize(m) != 4)
    e = rr_json_fail(r, "transform_matrix", "expected four rows of four numbers (camera to world, OpenGL's axes)");
  size_t l2 = rr_json_enter(r, "transform_matrix", 0);
  for (int i = 0; i < 4 && !e; i++) {
    size_t l3 = rr_json_enter(r, NULL, i);
    e = rr_json_array_doubles(r, cJSON_GetArrayItem(m, i), 4, -1e30, 1e30, row[i]);
    rr_json_leave(r, l3);
  }
  rr_json_leave(r, l2);
  if (!e) {
    double R[9], t[3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) R[3 * i + j] = row[j][i] * (i == 0 ? 1 : -1);
    for (int i = 0; i < 3; i++) t[i] = -(R[3 * i] * row[0][3] + R[3 * i + 1] * row[1][3] + R[3 * i + 2] * row[2][3]);
    if (pose(dev, &ic->camera, R, t)) {
      char msg[256];
      snprintf(msg, sizeof msg, "%s", rr_device_message(dev));
      e = rr_json_fail(r, "transform_matrix", "%s", msg);
    }
  }
  rr_json_leave(r, len);
  return e;
}

static rr_error nerf_read(rr_device *dev, const char *path, cam_list *out) {
  char what[320];
  snprintf(what, sizeof what, "NeRF file '%s'", path);
  json_reader r = {.dev = dev, .what = what};
  cJSON *root;
  rr_error e = rr_json_parse_file(&r, path, MAX_JSON_BYTES, &root);
  if (e) return e;
  const cJSON *frames = rr_json_get(root, "frames");
  if (!cJSON_IsArray(frames)) e = rr_json_fail(&r, "frames", "expected an array of frames");
  int fi = 0;
  for (const cJSON *f = frames ? frames->child : NULL; f && !e; f = f->next, fi++) {
    rr_imported_camera *ic = list_add(dev, out);
    e = ic ? nerf_frame(&r, root, f, fi, ic) : RR_ERROR_MEMORY;
  }
  cJSON_Delete(root);
  return e;
}

/* ---- the API ----------------------------------------------------------------------- */

rr_error rr_camera_import(rr_device *dev, const char *path, const char *select, rr_imported_camera *out, int cap,
                          int *count) {
  if (!path || (cap > 0 && !out) || cap < 0)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_camera_import: NULL argument or negative capacity");
  cam_list l = {0};
  rr_error e;
  const char *kind = "COLMAP model";
  if (is_dir(path)) e = colmap_read(dev, path, &l);
  else if (ends_with(path, "images.txt") || ends_with(path, "cameras.txt")) {
    size_t n = strlen(path) - strlen("images.txt");
    char *dir = malloc(n + 2);
    if (!dir) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory");
    if (n) memcpy(dir, path, n), dir[n] = 0;
    else strcpy(dir, ".");
    e = colmap_read(dev, dir, &l);
    free(dir);
  } else if (ends_with(path, ".json")) e = nerf_read(dev, path, &l), kind = "NeRF file";
  else
    e = rr_fail(dev, RR_ERROR_ARGUMENT,
                "'%s' is neither a COLMAP text model (a directory with cameras.txt and images.txt, or one of them) "
                "nor a NeRF transforms .json", path);
  if (!e && l.n == 0) e = rr_fail(dev, RR_ERROR_EMPTY, "%s '%s' has no images", kind, path);
  if (!e && select) {
    long k = -1, idx;
    for (int i = 0; i < l.n && k < 0; i++)
      if (!strcmp(l.v[i].name, select)) k = i;
    if (k < 0 && parse_long(select, 0, (long)l.n - 1, &idx)) k = idx;
    if (k < 0) {
      e = rr_fail(dev, RR_ERROR_ARGUMENT, "%s '%s' has no image '%s' (%d images: give a name or an index 0..%d%s%s)",
                  kind, path, select, l.n, l.n - 1, l.n ? ", the first is " : "", l.n ? l.v[0].name : "");
    } else {
      l.v[0] = l.v[k], l.n = 1;
    }
  }
  if (!e) {
    if (cap > 0) memcpy(out, l.v, sizeof *out * (size_t)(l.n < cap ? l.n : cap));
    if (count) *count = l.n;
  }
  free(l.v);
  return e ? e : rr_ok(dev);
}
