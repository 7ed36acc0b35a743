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
 * camera renders the same bits. */
#include "cli.h"

#include <cjson/cJSON.h>

unsigned camera_file_read(rr_device *dev, const char *path, rr_camera *cam) {
  unsigned fields = 0;
  if (rr_camera_load(dev, path, cam, &fields) != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
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
