/* Cameras beyond the pinhole, measured: for a scene seen from inside, the frame time
 * of every camera with rc-bvh and 3dr-full (median of N), the share of bins that
 * curved binning refines without finding the triangle, and what setting triangles
 * up once for a cube map saves against six separate perspective renders.
 *
 *   bench_cameras [--threads N] [--reps N] [--size N] [SCENE EYE TARGET] */
#include "benchutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool parse3(const char *s, float v[3]) { return sscanf(s, "%f,%f,%f", &v[0], &v[1], &v[2]) == 3; }

static double run(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int w, int h, int threads,
                  int reps, rr_stats *st) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = w, opt.height = h, opt.threads = threads;
  rr_frame *f;
  double ms = bench_render(dev, s, cam, &opt, reps, &f);
  rr_frame_get_stats(f, st);
  rr_frame_release(f);
  return ms;
}

int main(int argc, char **argv) {
  int threads = 1, reps = 5, size = 1024;
  const char *scene = "grid:teapot.obj:7";
  float eye[3] = {20.6f, 2.4f, 13.2f}, target[3] = {30, 1.2f, 20};
  int pos = 0;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = atoi(argv[++i]);
    else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
    else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) size = atoi(argv[++i]);
    else if (pos == 0) scene = argv[i], pos++;
    else if (pos == 1 && parse3(argv[i], eye)) pos++;
    else if (pos == 2 && parse3(argv[i], target)) pos++;
    else {
      fprintf(stderr, "usage: bench_cameras [--threads N] [--reps N] [--size N] [SCENE EYE TARGET]\n");
      return 2;
    }
  }
  if (threads < 1 || reps < 1 || reps > 64 || size < 48 || size > 8192) return 2;
  rr_device *dev = rr_device_new();
  rr_scene *s = bench_load(dev, scene, NULL);
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  printf("%s, %llu triangles, eye (%g,%g,%g), %d thread(s), median of %d\n\n", scene,
         (unsigned long long)in.triangles, eye[0], eye[1], eye[2], threads, reps);
  printf("| camera | size | rc-bvh ms | 3dr-full ms | 3dr-bin ms | 3dr-full bins refined, empty | 3dr-bin bins refined, empty |\n");
  printf("|---|---|---|---|---|---|---|\n");
  for (int type = 0; type < RR_CAMERA_COUNT; type++) {
    rr_camera cam;
    rr_camera_init(&cam);
    cam.type = (rr_camera_type)type;
    memcpy(cam.eye, eye, sizeof eye), memcpy(cam.target, target, sizeof target);
    cam.fov_deg = type == RR_CAMERA_FISHEYE ? 180 : 70;
    int w = size, h = size;
    if (type == RR_CAMERA_LATLONG) h = size / 2;
    if (type == RR_CAMERA_CUBE) h = size / 4 * 3;
    rr_stats a, b, c;
    double t_rc = run(dev, s, &cam, RR_METHOD_RC_BVH, w, h, threads, reps, &a);
    double t_full = run(dev, s, &cam, RR_METHOD_3DR_FULL, w, h, threads, reps, &b);
    double t_bin = run(dev, s, &cam, RR_METHOD_3DR_BIN, w, h, threads, reps, &c);
    printf("| %s | %dx%d | %.1f | %.1f | %.1f | %llu, %.1f%% | %llu, %.1f%% |\n", rr_camera_name(type), w, h, t_rc,
           t_full, t_bin, (unsigned long long)b.bins, b.bins ? 100.0 * b.bins_empty / b.bins : 0.0,
           (unsigned long long)c.bins, c.bins ? 100.0 * c.bins_empty / c.bins : 0.0);
  }

  /* Cube map: one render of the cross (setups shared by the six faces) against six
   * 90° perspective renders of the faces. */
  int face = size / 4;
  rr_camera cube;
  rr_camera_init(&cube);
  cube.type = RR_CAMERA_CUBE;
  memcpy(cube.eye, eye, sizeof eye), memcpy(cube.target, target, sizeof target);
  printf("\n| cube map, faces of %d² | method | ms | S |\n|---|---|---|---|\n", face);
  for (int m = 0; m < 2; m++) {
    rr_method method = m ? RR_METHOD_3DR_FULL : RR_METHOD_3DR_BB;
    rr_stats st;
    double t_cube = run(dev, s, &cube, method, 4 * face, 3 * face, threads, reps, &st);
    printf("| one cube camera | %s | %.1f | %llu |\n", rr_method_name(method), t_cube, (unsigned long long)st.setups);
    /* the six faces as perspective cameras, from the cube's own basis */
    float f[3], up[3] = {0, 1, 0}, r[3];
    for (int a = 0; a < 3; a++) f[a] = target[a] - eye[a];
    float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int a = 0; a < 3; a++) f[a] /= lf;
    r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2], r[2] = f[0] * up[1] - f[1] * up[0];
    float lr = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int a = 0; a < 3; a++) r[a] /= lr;
    float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    const float *dirs[6][2] = {{f, u}, {r, u}, {NULL, u}, {NULL, u}, {u, NULL}, {NULL, f}};
    float nf[3], nr[3], nu[3];
    for (int a = 0; a < 3; a++) nf[a] = -f[a], nr[a] = -r[a], nu[a] = -u[a];
    dirs[2][0] = nf, dirs[3][0] = nr, dirs[4][1] = nf, dirs[5][0] = nu;
    double total = 0;
    uint64_t setups = 0;
    for (int k = 0; k < 6; k++) {
      rr_camera p;
      rr_camera_init(&p);
      p.fov_deg = 90;
      memcpy(p.eye, eye, sizeof eye);
      for (int a = 0; a < 3; a++) p.target[a] = eye[a] + dirs[k][0][a], p.up[a] = dirs[k][1][a];
      total += run(dev, s, &p, method, face, face, threads, reps, &st);
      setups += st.setups;
    }
    printf("| six perspective renders | %s | %.1f | %llu |\n", rr_method_name(method), total,
           (unsigned long long)setups);
  }
  rr_scene_release(s);
  rr_device_release(dev);
  return 0;
}
