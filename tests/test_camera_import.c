/* rr_camera_import: COLMAP text models and NeRF transforms.json written here with known
 * poses give the cameras of the known K, R, t (the same rays), for every camera model;
 * malformed files fail with a message naming the file and the line or key. */
#define _XOPEN_SOURCE 700 /* mkdtemp */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

enum { W = 40, H = 30 };

static rr_device *dev;
static char dir[64];

static void write_file(const char *name, const char *text) {
  char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  fputs(text, f);
  fclose(f);
}

/* Rotation about a unit axis (Rodrigues), row-major, and its quaternion (w x y z). */
static void axis_angle(const double a[3], double th, double R[9], double q[4]) {
  double c = cos(th), s = sin(th), C = 1 - c;
  double x = a[0], y = a[1], z = a[2];
  double M[9] = {c + x * x * C,     x * y * C - z * s, x * z * C + y * s, y * x * C + z * s, c + y * y * C,
                 y * z * C - x * s, z * x * C - y * s, z * y * C + x * s, c + z * z * C};
  memcpy(R, M, sizeof M);
  q[0] = cos(th / 2), q[1] = x * sin(th / 2), q[2] = y * sin(th / 2), q[3] = z * sin(th / 2);
}

/* The largest difference between the rays of two cameras (origins and directions); 1e9
 * when a pixel has a ray in one and none in the other. */
static double ray_diff(const rr_camera *a, const rr_camera *b, int w, int h) {
  size_t n = (size_t)w * h * 3;
  float *oa = malloc(n * 4), *da = malloc(n * 4), *ob = malloc(n * 4), *db = malloc(n * 4);
  double d = 1e9;
  if (rr_camera_rays(dev, a, w, h, oa, da) == RR_OK && rr_camera_rays(dev, b, w, h, ob, db) == RR_OK) {
    d = 0;
    for (size_t i = 0; i < n; i++) d = fmax(d, fmax(fabs(oa[i] - ob[i]), fabs(da[i] - db[i])));
  }
  free(oa), free(da), free(ob), free(db);
  return d;
}

static rr_camera reference(bool fisheye, double fx, double fy, double cx, double cy, const double *dist,
                           const double R[9], const double t[3]) {
  rr_camera c;
  rr_camera_init(&c);
  c.type = fisheye ? RR_CAMERA_OPENCV_FISHEYE : RR_CAMERA_OPENCV;
  c.fx = (float)fx, c.fy = (float)fy, c.cx = (float)cx, c.cy = (float)cy;
  for (int i = 0; i < 8; i++) c.dist[i] = (float)dist[i];
  float Rf[9], tf[3];
  for (int i = 0; i < 9; i++) Rf[i] = (float)R[i];
  for (int i = 0; i < 3; i++) tf[i] = (float)t[i];
  rr_camera_set_extrinsics(dev, &c, Rf, tf);
  return c;
}

/* Every COLMAP model: its parameter line and the OpenCV camera it is (cx, cy - 0.5). */
static const struct {
  const char *model, *params;
  bool fisheye;
  double fx, fy, cx, cy, dist[8];
} models[] = {
    {"SIMPLE_PINHOLE", "35 20.5 15.5", false, 35, 35, 20, 15, {0}},
    {"PINHOLE", "35 37 20.5 15.5", false, 35, 37, 20, 15, {0}},
    {"SIMPLE_RADIAL", "35 19.5 16 -0.1", false, 35, 35, 19, 15.5, {-0.1}},
    {"RADIAL", "35 19.5 16 -0.1 0.02", false, 35, 35, 19, 15.5, {-0.1, 0.02}},
    {"OPENCV", "35 36 20 15 -0.1 0.02 0.001 -0.002", false, 35, 36, 19.5, 14.5, {-0.1, 0.02, 0.001, -0.002}},
    {"FULL_OPENCV", "35 36 20 15 -0.1 0.02 0.001 -0.002 0.003 0.01 0.002 0.001", false, 35, 36, 19.5, 14.5,
     {-0.1, 0.02, 0.001, -0.002, 0.003, 0.01, 0.002, 0.001}},
    {"OPENCV_FISHEYE", "15 16 20 15 0.05 -0.01 0.002 -0.001", true, 15, 16, 19.5, 14.5, {0.05, -0.01, 0.002, -0.001}},
    {"SIMPLE_RADIAL_FISHEYE", "15 20 15 0.05", true, 15, 15, 19.5, 14.5, {0.05}},
    {"RADIAL_FISHEYE", "15 20 15 0.05 -0.01", true, 15, 15, 19.5, 14.5, {0.05, -0.01}},
};
enum { NMODELS = sizeof models / sizeof models[0] };

static void test_colmap(void) {
  char cams[2048] = "# Camera list with one line of data per camera:\n", imgs[4096] = "# Image list\n", line[256];
  double R[NMODELS][9], t[NMODELS][3];
  for (int i = 0; i < NMODELS; i++) {
    snprintf(line, sizeof line, "%d %s %d %d %s\n", 10 + i, models[i].model, W, H, models[i].params);
    strcat(cams, line);
    double axis[3] = {0.3, -0.5 + 0.1 * i, 0.8}, len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]), q[4];
    for (int k = 0; k < 3; k++) axis[k] /= len;
    axis_angle(axis, 0.2 + 0.4 * i, R[i], q);
    t[i][0] = 0.3 * i - 1, t[i][1] = -0.2, t[i][2] = 2 + 0.1 * i;
    /* the quaternion written unnormalised (COLMAP normalises); an empty points line but the last */
    snprintf(line, sizeof line, "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d img_%d.png\n%s", 100 + i, 2 * q[0], 2 * q[1],
             2 * q[2], 2 * q[3], t[i][0], t[i][1], t[i][2], 10 + i, i, i % 2 ? "\n" : "1.5 2.5 -1 3 4 17\n");
    strcat(imgs, line);
  }
  write_file("cameras.txt", cams);
  write_file("images.txt", imgs);

  rr_imported_camera all[NMODELS + 1];
  int n = -1;
  CHECK(rr_camera_import(dev, dir, NULL, all, NMODELS + 1, &n) == RR_OK, "%s", rr_device_message(dev));
  CHECK(n == NMODELS, "%d images", n);
  for (int i = 0; i < NMODELS && i < n; i++) {
    rr_camera ref = reference(models[i].fisheye, models[i].fx, models[i].fy, models[i].cx, models[i].cy, models[i].dist,
                              R[i], t[i]);
    char name[32];
    snprintf(name, sizeof name, "img_%d.png", i);
    CHECK(!strcmp(all[i].name, name) && all[i].width == W && all[i].height == H, "%s: %s %dx%d", models[i].model,
          all[i].name, all[i].width, all[i].height);
    CHECK(all[i].camera.type == ref.type, "%s: type %d", models[i].model, all[i].camera.type);
    double d = ray_diff(&all[i].camera, &ref, W, H);
    CHECK(d < 1e-5, "%s: rays differ by %g", models[i].model, d);
    /* and the pixel centre convention: COLMAP's principal point (cx, cy) is rastray's
     * sample (cx, cy), whose ray is the optical axis */
    float org[3 * W * H], dir3[3 * W * H];
    rr_camera_rays(dev, &all[i].camera, W, H, org, dir3);
    if (i == 1) { /* PINHOLE: pixel (20, 15) has its centre at COLMAP's (20.5, 15.5) = the principal point */
      const float *dd = dir3 + 3 * (15 * W + 20);
      double dot = dd[0] * R[i][6] + dd[1] * R[i][7] + dd[2] * R[i][8];
      CHECK(dot > 1 - 1e-6, "the principal point's ray is off the axis (cos %g)", dot);
    }
  }
  /* selection by name, by index; images.txt itself as the path; a count without output */
  rr_imported_camera one;
  char path[128];
  snprintf(path, sizeof path, "%s/images.txt", dir);
  CHECK(rr_camera_import(dev, path, "img_3.png", &one, 1, &n) == RR_OK && n == 1 && !strcmp(one.name, "img_3.png"),
        "%s", rr_device_message(dev));
  CHECK(rr_camera_import(dev, dir, "4", &one, 1, &n) == RR_OK && !strcmp(one.name, "img_4.png"), "%s", one.name);
  CHECK(rr_camera_import(dev, dir, NULL, NULL, 0, &n) == RR_OK && n == NMODELS, "count %d", n);
  CHECK(rr_camera_import(dev, dir, "nope.png", &one, 1, &n) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "no image 'nope.png'"),
        "%s", rr_device_message(dev));
  CHECK(rr_camera_import(dev, dir, "9", &one, 1, &n) == RR_ERROR_ARGUMENT, "index out of range accepted");

  /* a scene file's camera from the model (relative to the file), its size the render size */
  write_file("scene.json", "{\"meshes\": [{\"builtin\": \"plane:2\"}], \"camera\": {\"colmap\": \".\", \"image\": 6}}");
  snprintf(path, sizeof path, "%s/scene.json", dir);
  rr_scene *scene = NULL;
  rr_scene_settings st;
  CHECK(rr_scene_load_file(dev, path, NULL, &scene, &st) == RR_OK, "%s", rr_device_message(dev));
  if (scene) {
    double d = ray_diff(&st.camera, &all[6].camera, W, H);
    CHECK(d == 0 && (st.camera_given & RR_CAMERA_FIELD_LENS) && (st.given & RR_SETTING_SIZE) && st.render.width == W &&
              st.render.height == H, "scene file camera: rays differ by %g, size %dx%d", d, st.render.width, st.render.height);
    rr_scene_release(scene);
  }
  write_file("scene.json", "{\"meshes\": [{\"builtin\": \"plane:2\"}], \"camera\": {\"colmap\": \".\", \"image\": \"x.png\"}}");
  CHECK(rr_scene_load_file(dev, path, NULL, &scene, &st) != RR_OK &&
            strstr(rr_device_message(dev), "scene.json': 'camera.colmap': COLMAP model") &&
            strstr(rr_device_message(dev), "no image 'x.png'"),
        "%s", rr_device_message(dev));
  unlink(path);

  /* the command line: --camera-file DIR:NAME, the image's size without --size */
  char cmd[1024], png[128], saved[128];
  snprintf(png, sizeof png, "%s/x.png", dir), snprintf(saved, sizeof saved, "%s/cam.json", dir);
  snprintf(cmd, sizeof cmd, "%s render plane:2 --camera-file %s:img_2.png --save-camera %s -o %s -q", RR_CLI, dir, saved, png);
  CHECK(system(cmd) == 0, "%s", cmd);
  rr_camera c;
  rr_camera_init(&c);
  CHECK(rr_camera_load(dev, saved, &c, NULL) == RR_OK && ray_diff(&c, &all[2].camera, W, H) < 1e-6, "saved camera: %s",
        rr_device_message(dev));
  unsigned char head[24] = {0};
  FILE *f = fopen(png, "rb");
  if (f) fread(head, 1, sizeof head, f), fclose(f);
  int pw = head[16] << 24 | head[17] << 16 | head[18] << 8 | head[19], ph = head[20] << 24 | head[21] << 16 | head[22] << 8 | head[23];
  CHECK(pw == W && ph == H, "the image is %dx%d, not the model's %dx%d", pw, ph, W, H);
  unlink(png), unlink(saved);
  snprintf(cmd, sizeof cmd, "%s render plane:2 --camera-file %s/images.txt:nope.png -o %s 2>/dev/null", RR_CLI, dir, png);
  int status = system(cmd);
  CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 1 && access(png, F_OK) != 0, "an unknown image: status %d", status);
}

static void test_nerf(void) {
  double axis[3] = {0.6, 0.0, 0.8}, R[9], q[4], t[3] = {0.4, -0.3, 3.0};
  axis_angle(axis, 0.7, R, q);
  /* camera to world, OpenGL's axes: columns R's rows x, -y, -z; position -Rᵀt */
  double c2w[16] = {0};
  for (int i = 0; i < 3; i++) {
    c2w[4 * i + 0] = R[0 + i], c2w[4 * i + 1] = -R[3 + i], c2w[4 * i + 2] = -R[6 + i];
    c2w[4 * i + 3] = -(R[i] * t[0] + R[3 + i] * t[1] + R[6 + i] * t[2]);
  }
  c2w[15] = 1;
  char m[512], text[4096];
  snprintf(m, sizeof m, "[[%.17g,%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g,%.17g],[0,0,0,1]]", c2w[0],
           c2w[1], c2w[2], c2w[3], c2w[4], c2w[5], c2w[6], c2w[7], c2w[8], c2w[9], c2w[10], c2w[11]);
  double ax = 0.9, fx = 0.5 * W / tan(0.5 * ax);
  snprintf(text, sizeof text,
           "{\"camera_angle_x\": %.17g, \"w\": %d, \"h\": %d, \"k1\": -0.05, \"p2\": 0.001, \"aabb_scale\": 4, \"frames\": ["
           "{\"file_path\": \"./train/r_0\", \"transform_matrix\": %s},"
           "{\"file_path\": \"./train/r_1\", \"fl_x\": 50, \"fl_y\": 52, \"cx\": 19, \"cy\": 16, \"k1\": 0, \"transform_matrix\": %s}]}",
           ax, W, H, m, m);
  write_file("transforms.json", text);
  char path[128];
  snprintf(path, sizeof path, "%s/transforms.json", dir);
  rr_imported_camera c[2];
  int n = 0;
  CHECK(rr_camera_import(dev, path, NULL, c, 2, &n) == RR_OK && n == 2, "%s", rr_device_message(dev));
  double d0[8] = {-0.05, 0, 0, 0.001}, d1[8] = {0, 0, 0, 0.001};
  rr_camera r0 = reference(false, fx, fx, W / 2.0, H / 2.0, d0, R, t), r1 = reference(false, 50, 52, 19, 16, d1, R, t);
  CHECK(!strcmp(c[0].name, "./train/r_0") && c[0].width == W && c[0].height == H, "%s", c[0].name);
  double e0 = ray_diff(&c[0].camera, &r0, W, H), e1 = ray_diff(&c[1].camera, &r1, W, H);
  CHECK(e0 < 1e-5, "frame 0: rays differ by %g", e0);
  CHECK(e1 < 1e-5, "frame 1 (its own intrinsics): rays differ by %g", e1);
  CHECK(rr_camera_import(dev, path, "./train/r_1", c, 1, &n) == RR_OK && c[0].camera.fx == 50, "%s", rr_device_message(dev));
  rr_camera cf;
  CHECK(rr_camera_load(dev, path, &cf, NULL) != RR_OK && strstr(rr_device_message(dev), "'frames': a NeRF transforms file"),
        "rr_camera_load of a NeRF file: %s", rr_device_message(dev));
  /* nerfstudio's fisheye */
  snprintf(text, sizeof text,
           "{\"camera_model\": \"OPENCV_FISHEYE\", \"fl_x\": 15, \"fl_y\": 16, \"cx\": 20, \"cy\": 15, \"w\": %d, \"h\": %d,"
           " \"k1\": 0.05, \"k2\": -0.01, \"k3\": 0.002, \"k4\": -0.001, \"frames\": [{\"file_path\": \"a\", \"transform_matrix\": %s}]}",
           W, H, m);
  write_file("fish.json", text);
  snprintf(path, sizeof path, "%s/fish.json", dir);
  double df[8] = {0.05, -0.01, 0.002, -0.001};
  rr_camera rf = reference(true, 15, 16, 20, 15, df, R, t);
  CHECK(rr_camera_import(dev, path, "0", c, 1, &n) == RR_OK, "%s", rr_device_message(dev));
  double ef = ray_diff(&c[0].camera, &rf, W, H);
  CHECK(c[0].camera.type == RR_CAMERA_OPENCV_FISHEYE && ef < 1e-5, "fisheye: type %d, rays differ by %g", c[0].camera.type, ef);
}

/* Malformed files: each fails (no crash) with one line holding `want`. */
static void expect_fail(const char *path, const char *want) {
  rr_imported_camera c;
  int n;
  rr_error e = rr_camera_import(dev, path, NULL, &c, 1, &n);
  const char *msg = rr_device_message(dev);
  CHECK(e != RR_OK && strstr(msg, want) && !strchr(msg, '\n'), "%s: expected '%s', got '%s'", path, want, msg);
}

static void test_malformed(void) {
  static const struct {
    const char *cameras, *images, *want;
  } colmap[] = {
      {"1 THIN_PRISM_FISHEYE 40 30 1 2 3 4 5 6 7 8 9 10 11 12\n", "", "cameras.txt' line 1: camera model THIN_PRISM_FISHEYE"},
      {"# c\n1 PINHOLE 40 30 35 35 20\n", "", "cameras.txt' line 2: camera 1: PINHOLE takes 4 parameters, not 3"},
      {"1 PINHOLE 40 30 35 35 20 x\n", "", "line 1: camera 1: bad parameter 'x'"},
      {"1 PINHOLE 40 30 35 nan 20 15\n", "", "bad parameter 'nan'"},
      {"1 PINHOLE 0 30 35 35 20 15\n", "", "bad image size '0 30'"},
      {"1 PINHOLE 40\n", "", "line 1: expected CAMERA_ID MODEL WIDTH HEIGHT"},
      {"-1 PINHOLE 40 30 35 35 20 15\n", "", "bad camera id '-1'"},
      {"1 PINHOLE 40 30 0 35 20 15\n", "", "focal length must be > 0"},
      {"1 PINHOLE 40 30 35 35 20 15\n1 PINHOLE 40 30 35 35 20 15\n", "", "line 2: camera 1 given twice"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 1 0 0 0 0 0 1 2 a.png\n\n", "images.txt' line 1: image 1: camera 2 is not in cameras.txt"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 1 0 0 0 0 0 1 1\n", "images.txt' line 1: expected IMAGE_ID QW"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 0 0 0 0 0 0 1 1 a.png\n", "image 1: a zero quaternion"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 1 0 0 q 0 0 1 1 a.png\n", "bad quaternion 'q'"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 1 0 0 0 0 0 1e999 1 a.png\n", "bad translation '1e999'"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "1 1 0 0 0 0 0 1 1 a.png\n2 1 0 0 0 0 0 1 1 b.png\n",
       "images.txt' line 2: expected the 2D points of image 1"},
      {"1 PINHOLE 40 30 35 35 20 15\n", "# nothing\n", "has no images"},
  };
  char path[128];
  for (size_t i = 0; i < sizeof colmap / sizeof colmap[0]; i++) {
    write_file("cameras.txt", colmap[i].cameras);
    write_file("images.txt", colmap[i].images);
    expect_fail(dir, colmap[i].want);
  }
  snprintf(path, sizeof path, "%s/missing", dir);
  expect_fail(path, "missing");
  snprintf(path, sizeof path, "%s/empty", dir);
  mkdir(path, 0700);
  expect_fail(path, "empty/cameras.txt'");
  rmdir(path);

  static const char *const M = "[[1,0,0,0],[0,1,0,0],[0,0,1,3],[0,0,0,1]]";
  static const struct {
    const char *json, *want; /* json: %s takes M */
  } nerf[] = {
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": %s}", "line"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1}", "'frames': expected an array"},
      {"{\"w\": 40, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": %s}]}", "expected the image size 'w' and 'h'"},
      {"{\"w\": 40, \"h\": 30.5, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": %s}]}", "'h': expected the image size"},
      {"{\"w\": 40, \"h\": 30, \"frames\": [{\"transform_matrix\": %s}]}", "'camera_angle_x': missing (or 'fl_x')"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": \"wide\", \"frames\": [{\"transform_matrix\": %s}]}", "'camera_angle_x'"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": %s}, {\"fl_x\": -3, \"transform_matrix\": %s}]}",
       "'frames[1].fl_x'"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": [[1,0,0],[0,1,0],[0,0,1]]}]}",
       "'frames[0].transform_matrix': expected four rows"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,\"x\"],[0,0,0,1]]}]}",
       "'frames[0].transform_matrix[2]'"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"transform_matrix\": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]}",
       "'frames[0].transform_matrix': R is not a rotation"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [{\"file_path\": 3, \"transform_matrix\": %s}]}", "'frames[0].file_path'"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"camera_model\": \"EQUIRECTANGULAR\", \"frames\": [{\"transform_matrix\": %s}]}",
       "'camera_model': 'EQUIRECTANGULAR' is not an OpenCV camera"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": [3]}", "'frames[0]': expected an object"},
      {"{\"w\": 40, \"h\": 30, \"camera_angle_x\": 1, \"frames\": []}", "has no images"},
  };
  snprintf(path, sizeof path, "%s/bad.json", dir);
  for (size_t i = 0; i < sizeof nerf / sizeof nerf[0]; i++) {
    char text[1024];
    snprintf(text, sizeof text, nerf[i].json, M, M);
    write_file("bad.json", text);
    expect_fail(path, nerf[i].want);
  }
  expect_fail(path, "NeRF file '"); /* the last one's message names the file */
  snprintf(path, sizeof path, "%s/cameras.bin", dir);
  expect_fail(path, "neither a COLMAP text model");
}

int main(void) {
  dev = rr_device_new();
  snprintf(dir, sizeof dir, "/tmp/rr_camimport_XXXXXX");
  if (!mkdtemp(dir)) return 1;
  test_colmap();
  test_nerf();
  test_malformed();
  const char *files[] = {"cameras.txt", "images.txt", "transforms.json", "fish.json", "bad.json"};
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
    char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, files[i]);
    unlink(path);
  }
  rmdir(dir);
  rr_device_release(dev);
  return test_done();
}
