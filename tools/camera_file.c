/* Camera files (--camera-file, --save-camera): one JSON object, read by the library
 * (rr_camera_load) and written here through cJSON. Either the camera's own fields
 *   {"type": "perspective", "eye": [x, y, z], "target": [x, y, z], "up": [x, y, z],
 *    "fov": 45, "ortho_height": 0, "width": 1024, "height": 768}
 * (width and height record the image the camera was made for; reading ignores
 * them; the OpenCV cameras add "intrinsics": [fx, fy, cx, cy] and "distortion":
 * [up to 8 coefficients]) or a camera-to-world matrix in the OpenGL convention, four rows of four
 * numbers: columns right (+X), up (+Y) and back (+Z; the camera looks down -Z),
 * then the position, bottom row 0 0 0 1:
 *   {"matrix": [[1,0,0,0], [0,1,0,0], [0,0,1,5], [0,0,0,1]], "fov": 40}
 * Numbers are written with the digits that give back the same float, so a saved
 * camera renders the same bits.
 *
 * --camera-file also takes a reconstruction's camera (rr_camera_import): PATH[:IMAGE],
 * PATH a COLMAP text model (its directory, or its images.txt or cameras.txt) or a NeRF
 * transforms .json, IMAGE an image's name (a frame's file_path) or 0-based index
 * (default: the first; a NeRF file needs it, else it is read as a camera file). */
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static bool ends_with(const char *s, const char *suffix) {
  size_t n = strlen(s), m = strlen(suffix);
  return n >= m && !strcmp(s + n - m, suffix);
}

unsigned camera_file_read(rr_device *dev, const char *arg, rr_camera *cam, int *width, int *height) {
  *width = *height = 0;
  /* PATH[:IMAGE]: the whole argument when it exists, else split at the first ':'
   * whose left side exists (image names may hold ':' too) */
  struct stat st;
  char *path = strdup(arg);
  if (!path) die(EXIT_INPUT, "out of memory");
  const char *select = NULL;
  if (stat(arg, &st) != 0)
    for (char *c = strchr(path, ':'); c; c = strchr(c + 1, ':')) {
      *c = 0;
      if (stat(path, &st) == 0) {
        select = c + 1;
        break;
      }
      *c = ':';
    }
  bool is_dir = stat(path, &st) == 0 && S_ISDIR(st.st_mode);
  unsigned fields = 0;
  if (is_dir || ends_with(path, "images.txt") || ends_with(path, "cameras.txt") || (select && ends_with(path, ".json"))) {
    rr_imported_camera ic;
    if (rr_camera_import(dev, path, select, &ic, 1, NULL) != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
    *cam = ic.camera, *width = ic.width, *height = ic.height;
    fields = CAM_TYPE | CAM_EYE | CAM_TARGET | CAM_UP | CAM_LENS;
  } else if (select) {
    die(EXIT_INPUT, "--camera-file '%s': an image is selected only in a COLMAP model or a NeRF .json", arg);
  } else if (rr_camera_load(dev, path, cam, &fields) != RR_OK) {
    die(EXIT_INPUT, "%s", rr_device_message(dev));
  }
  free(path);
  return fields;
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
