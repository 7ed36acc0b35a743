/* Camera files (--camera-file, --save-camera): one JSON object, read and written
 * through cJSON. Either the camera's own fields
 *   {"type": "perspective", "eye": [x, y, z], "target": [x, y, z], "up": [x, y, z],
 *    "fov": 45, "ortho_height": 0, "width": 1024, "height": 768}
 * (width and height record the image the camera was made for; reading ignores
 * them; the OpenCV cameras add "intrinsics": [fx, fy, cx, cy] and "distortion":
 * [up to 8 coefficients]) or a camera-to-world matrix in the OpenGL convention, four rows of four
 * numbers: columns right (+X), up (+Y) and back (+Z; the camera looks down -Z),
 * then the position, bottom row 0 0 0 1:
 *   {"matrix": [[1,0,0,0], [0,1,0,0], [0,0,1,5], [0,0,0,1]], "fov": 40}
 * Numbers are written with the digits that give back the same float, so a saved
 * camera renders the same bits. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stddef.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *path_;
static char *text_; /* the file being read and its parse, freed when it is refused */
static cJSON *root_;

static void bad(const char *fmt, ...) __attribute__((noreturn, format(printf, 1, 2)));
static void bad(const char *fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  cJSON_Delete(root_), free(text_);
  root_ = NULL, text_ = NULL;
  die(EXIT_INPUT, "camera file '%s': %s", path_, msg);
}

static float number(const cJSON *item, const char *key) {
  if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || fabs(item->valuedouble) > 1e30)
    bad("'%s' must be a finite number", key);
  return (float)item->valuedouble;
}

/* An array of n finite numbers. */
static void numbers(const cJSON *item, const char *key, int n, float *out) {
  if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n) bad("'%s' must be an array of %d numbers", key, n);
  for (int i = 0; i < n; i++) out[i] = number(cJSON_GetArrayItem(item, i), key);
}

/* The matrix's camera: the position, a target one back-vector ahead, its up. */
static void from_matrix(const cJSON *item, rr_camera *cam) {
  float m[4][4];
  if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 4)
    bad("'matrix' must be four rows of four numbers (camera to world, OpenGL convention)");
  for (int r = 0; r < 4; r++) numbers(cJSON_GetArrayItem(item, r), "matrix", 4, m[r]);
  if (m[3][0] != 0 || m[3][1] != 0 || m[3][2] != 0 || m[3][3] != 1) bad("the matrix's bottom row must be 0 0 0 1");
  for (int i = 0; i < 3; i++)
    cam->eye[i] = m[i][3], cam->target[i] = m[i][3] - m[i][2], cam->up[i] = m[i][1];
}

unsigned camera_file_read(const char *path, rr_camera *cam) {
  path_ = path;
  FILE *f = fopen(path, "rb");
  if (!f) die(EXIT_INPUT, "cannot open camera file '%s'", path);
  enum { MAX_BYTES = 1 << 20 }; /* a camera is a few hundred */
  char *text = text_ = malloc(MAX_BYTES + 1);
  size_t n = text ? fread(text, 1, MAX_BYTES + 1, f) : 0;
  bool failed = ferror(f);
  fclose(f);
  if (!text || failed) bad("cannot read it");
  if (n > MAX_BYTES) bad("larger than %d bytes", MAX_BYTES);
  text[n] = 0;
  const char *end = NULL;
  cJSON *root = root_ = cJSON_ParseWithOpts(text, &end, 1);
  if (!root) {
    int line = 1;
    for (const char *p = text; end && p < end; p++) line += *p == '\n';
    bad("not valid JSON (line %d)", line);
  }
  if (!cJSON_IsObject(root)) bad("not a JSON object");
  static const char *const keys[] = {"type", "eye", "target", "up", "fov", "ortho_height", "matrix", "width", "height",
                                     "intrinsics", "distortion"};
  for (const cJSON *k = root->child; k; k = k->next) {
    size_t i = 0;
    while (i < sizeof keys / sizeof *keys && strcmp(k->string, keys[i]) != 0) i++;
    if (i == sizeof keys / sizeof *keys)
      bad("unknown key '%s' (expected type, eye, target, up, fov, ortho_height, width, height, intrinsics, "
          "distortion, or matrix and fov)",
          k->string);
  }
  unsigned given = 0;
  const cJSON *item;
  if ((item = cJSON_GetObjectItemCaseSensitive(root, "type"))) {
    int type = cJSON_IsString(item) ? rr_camera_from_name(item->valuestring) : -1;
    if (type < 0) bad("'type' must be perspective, orthographic, parabolic, latlong, fisheye, cube, opencv or opencv-fisheye");
    cam->type = (rr_camera_type)type, given |= CAM_TYPE;
  }
  const cJSON *matrix = cJSON_GetObjectItemCaseSensitive(root, "matrix");
  if (matrix) {
    if (cJSON_HasObjectItem(root, "eye") || cJSON_HasObjectItem(root, "target") || cJSON_HasObjectItem(root, "up"))
      bad("give either 'matrix' or 'eye', 'target' and 'up', not both");
    from_matrix(matrix, cam);
    given |= CAM_EYE | CAM_TARGET | CAM_UP;
  } else {
    static const struct {
      const char *key;
      unsigned field;
      size_t offset;
    } vectors[] = {{"eye", CAM_EYE, offsetof(rr_camera, eye)},
                   {"target", CAM_TARGET, offsetof(rr_camera, target)},
                   {"up", CAM_UP, offsetof(rr_camera, up)}};
    for (int v = 0; v < 3; v++) {
      if ((item = cJSON_GetObjectItemCaseSensitive(root, vectors[v].key))) {
        numbers(item, vectors[v].key, 3, (float *)((char *)cam + vectors[v].offset));
        given |= vectors[v].field;
      } else if (vectors[v].field != CAM_UP) {
        bad("missing '%s' (or a 'matrix')", vectors[v].key);
      }
    }
  }
  if ((item = cJSON_GetObjectItemCaseSensitive(root, "fov"))) {
    cam->fov_deg = number(item, "fov"), given |= CAM_FOV;
    if (!(cam->fov_deg >= RR_FOV_MIN && cam->fov_deg <= 360)) bad("'fov' must be in [%g, 360]", (double)RR_FOV_MIN);
  }
  if ((item = cJSON_GetObjectItemCaseSensitive(root, "ortho_height"))) {
    cam->ortho_height = number(item, "ortho_height"), given |= CAM_ORTHO;
    if (!(cam->ortho_height >= 0)) bad("'ortho_height' must be >= 0 (0: from the distance and fov)");
  }
  if ((item = cJSON_GetObjectItemCaseSensitive(root, "intrinsics"))) {
    float k[4];
    numbers(item, "intrinsics", 4, k);
    cam->fx = k[0], cam->fy = k[1], cam->cx = k[2], cam->cy = k[3], given |= CAM_LENS;
  }
  if ((item = cJSON_GetObjectItemCaseSensitive(root, "distortion"))) {
    int n = cJSON_IsArray(item) ? cJSON_GetArraySize(item) : -1;
    if (n < 0 || n > 8) bad("'distortion' must be an array of at most 8 numbers");
    memset(cam->dist, 0, sizeof cam->dist);
    numbers(item, "distortion", n, cam->dist);
    given |= CAM_LENS;
  }
  for (int k = 0; k < 2; k++) /* for reference only, but a wrong type is still a bad file */
    if ((item = cJSON_GetObjectItemCaseSensitive(root, k ? "height" : "width")) && !cJSON_IsNumber(item))
      bad("'%s' must be a number", k ? "height" : "width");
  cJSON_Delete(root), free(text);
  root_ = NULL, text_ = NULL;
  return given;
}

void camera_file_add(rr_device *dev, rr_output *set, const char *path, const rr_camera *cam, int width, int height) {
  cJSON *root = cJSON_CreateObject();
  cJSON_AddStringToObject(root, "type", rr_camera_name(cam->type));
  cJSON_AddItemToObject(root, "eye", cJSON_CreateFloatArray(cam->eye, 3));
  cJSON_AddItemToObject(root, "target", cJSON_CreateFloatArray(cam->target, 3));
  cJSON_AddItemToObject(root, "up", cJSON_CreateFloatArray(cam->up, 3));
  if (cam->type == RR_CAMERA_OPENCV || cam->type == RR_CAMERA_OPENCV_FISHEYE) {
    const float k[4] = {cam->fx, cam->fy, cam->cx, cam->cy};
    cJSON_AddItemToObject(root, "intrinsics", cJSON_CreateFloatArray(k, 4));
    cJSON_AddItemToObject(root, "distortion", cJSON_CreateFloatArray(cam->dist, 8));
  }
  cJSON_AddNumberToObject(root, "fov", cam->fov_deg);
  cJSON_AddNumberToObject(root, "ortho_height", cam->ortho_height);
  cJSON_AddNumberToObject(root, "width", width);
  cJSON_AddNumberToObject(root, "height", height);
  json_add(dev, set, root, path);
}
