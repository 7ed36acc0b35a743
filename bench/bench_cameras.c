/* Cameras beyond the pinhole, measured against the pinhole: for a scene seen from
 * inside, every camera with rc-bvh and the 3D rasterizers, beside a perspective
 * camera of the same view and pixel count; the share of the bins that binning
 * refines without finding the triangle; and a cube camera against six perspective
 * renders of its faces (time and S: the cube sets a triangle up once for all of
 * its faces in 3dr-bb and 3dr-bin).
 *
 * Times are medians of --reps frames; --instructions counts one frame of each
 * (after a warm-up) under callgrind instead and lists them by part, "CAMERA
 * WxH METHOD", "cube METHOD" and "cube face K METHOD", which repeat from run to
 * run where times on a shared machine do not.
 *
 * --cube runs the cube map's table alone; --cpu reports the median processor time
 * of the frames (all threads) instead of wall time, steadier on a loaded machine.
 *
 *   bench_cameras [--threads N] [--reps N] [--size N] [--instructions] [--cube] [--cpu] [SCENE EYE TARGET] */
#include "benchutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool parse3(const char *s, float v[3]) { return sscanf(s, "%f,%f,%f", &v[0], &v[1], &v[2]) == 3; }

enum { NM = 4 };
static const rr_method methods[NM] = {RR_METHOD_RC_BVH, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FULL};

typedef struct bench {
  rr_device *dev;
  const rr_scene *s;
  int threads, reps;
  bool count; /* under callgrind: one counted frame per part */
  bool cpu;   /* processor time (all threads) instead of wall time: on a loaded machine */
} bench;

/* bench_render with the median of the frames' processor time (rr_stats.cpu_ms). */
static double render_cpu(const bench *b, const rr_camera *cam, const rr_render_options *opt, rr_frame **out) {
  double t[64];
  const int reps = b->reps < 64 ? b->reps : 64;
  rr_frame *f = NULL;
  for (int r = 0; r < reps; r++) {
    rr_frame_release(f);
    if (rr_render(b->dev, b->s, cam, opt, &f) != RR_OK) {
      fprintf(stderr, "bench_cameras: %s\n", rr_device_message(b->dev));
      exit(1);
    }
    rr_stats st;
    rr_frame_get_stats(f, &st);
    t[r] = st.cpu_ms;
  }
  *out = f;
  return bench_median(t, reps);
}

/* Milliseconds of method m on camera cam at w×h, and its stats (under callgrind:
 * one frame counted as the part "`part` METHOD"). */
static double run(const bench *b, const rr_camera *cam, rr_method m, int w, int h, const char *part, rr_stats *st) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = w, opt.height = h, opt.threads = b->threads;
  rr_frame *f;
  char name[128];
  snprintf(name, sizeof name, "%s %s", part, rr_method_name(m));
  double ms = b->count ? bench_count_frame(b->dev, b->s, cam, &opt, name, &f)
             : b->cpu  ? render_cpu(b, cam, &opt, &f)
                       : bench_render(b->dev, b->s, cam, &opt, b->reps, &f);
  rr_frame_get_stats(f, st);
  rr_frame_release(f);
  return ms;
}

static double share(const rr_stats *st) { return st->bins ? 100.0 * st->bins_empty / st->bins : 0.0; }

/* One row: the camera's four methods; ms[] and the fastest 3D method's time. */
static double row(const bench *b, const rr_camera *cam, int w, int h, double ms[NM], rr_stats st[NM]) {
  char part[96];
  snprintf(part, sizeof part, "%s %dx%d", rr_camera_name(cam->type), w, h);
  double best = INFINITY;
  for (int m = 0; m < NM; m++) {
    ms[m] = run(b, cam, methods[m], w, h, part, &st[m]);
    if (m > 0 && ms[m] < best) best = ms[m];
  }
  return best;
}

/* Every camera beside a perspective camera of the same view and pixel count. */
static void cameras_table(const bench *b, const float eye[3], const float target[3], int size) {
  printf("Each camera beside a perspective camera (fov 70°) of the same view and pixel count; ms, and the fastest\n"
         "3D method against rc-bvh on the same camera and against the fastest 3D method on the perspective one.\n\n");
  printf("| camera | size | rc-bvh ms | 3dr-bb ms | 3dr-bin ms | 3dr-full ms | fastest 3D / rc-bvh | fastest 3D / "
         "perspective's | S (3dr-bb) | empty bins 3dr-bin, 3dr-full |\n");
  printf("|---|---|---|---|---|---|---|---|---|---|\n");
  /* the perspective view at each size a camera uses: square, 2:1 (lat-long), 4:3 (cube) */
  int sizes[3][2] = {{size, size}, {size, size / 2}, {size, size / 4 * 3}};
  double persp_best[3];
  for (int k = 0; k < 3; k++) {
    rr_camera cam;
    rr_camera_init(&cam);
    memcpy(cam.eye, eye, 3 * sizeof *eye), memcpy(cam.target, target, 3 * sizeof *target);
    cam.fov_deg = 70;
    double ms[NM];
    rr_stats st[NM];
    persp_best[k] = row(b, &cam, sizes[k][0], sizes[k][1], ms, st);
    printf("| perspective | %dx%d | %.1f | %.1f | %.1f | %.1f | %.2f× | 1 | %llu | %.1f%%, %.1f%% |\n", sizes[k][0],
           sizes[k][1], ms[0], ms[1], ms[2], ms[3], persp_best[k] / ms[0], (unsigned long long)st[1].setups,
           share(&st[2]), share(&st[3]));
  }
  for (int type = 0; type < RR_CAMERA_COUNT; type++) {
    if (type == RR_CAMERA_PERSPECTIVE) continue;
    rr_camera cam;
    rr_camera_init(&cam);
    cam.type = (rr_camera_type)type;
    memcpy(cam.eye, eye, 3 * sizeof *eye), memcpy(cam.target, target, 3 * sizeof *target);
    cam.fov_deg = type == RR_CAMERA_FISHEYE ? 180 : 70;
    int k = type == RR_CAMERA_LATLONG ? 1 : type == RR_CAMERA_CUBE ? 2 : 0;
    double ms[NM];
    rr_stats st[NM];
    double best = row(b, &cam, sizes[k][0], sizes[k][1], ms, st);
    printf("| %s | %dx%d | %.1f | %.1f | %.1f | %.1f | %.2f× | %.2f× | %llu | %.1f%%, %.1f%% |\n", rr_camera_name(type),
           sizes[k][0], sizes[k][1], ms[0], ms[1], ms[2], ms[3], best / ms[0], best / persp_best[k],
           (unsigned long long)st[1].setups, share(&st[2]), share(&st[3]));
  }
}

int main(int argc, char **argv) {
  int threads = 1, reps = 5, size = 512;
  bool count = false, cube_only = false, cpu = false;
  const char *scene = "grid:teapot.obj:7";
  float eye[3] = {20.6f, 2.4f, 13.2f}, target[3] = {30, 1.2f, 20};
  int pos = 0;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_cameras", "--threads", argv[++i], 1, RR_MAX_THREADS, &threads)) return 2;
    } else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_cameras", "--reps", argv[++i], 1, 64, &reps)) return 2;
    } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_cameras", "--size", argv[++i], 48, 8192, &size)) return 2;
    } else if (strcmp(argv[i], "--instructions") == 0) {
      count = true;
    } else if (strcmp(argv[i], "--cube") == 0) {
      cube_only = true;
    } else if (strcmp(argv[i], "--cpu") == 0) {
      cpu = true;
    } else if (pos == 0 && argv[i][0] != '-') {
      scene = argv[i], pos++;
    } else if (pos == 1 && parse3(argv[i], eye)) {
      pos++;
    } else if (pos == 2 && parse3(argv[i], target)) {
      pos++;
    } else {
      fprintf(stderr, "usage: bench_cameras [--threads N] [--reps N] [--size N] [--instructions] [--cube] [--cpu] "
                      "[SCENE EYE TARGET]\n");
      return 2;
    }
  }
  if (count && !bench_on_valgrind()) return bench_instructions_main(argv);
  rr_device *dev = rr_device_new();
  rr_scene *s = bench_load(dev, scene, NULL);
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  bench b = {dev, s, threads, reps, count, cpu};
  printf("%s, %llu triangles, eye (%g,%g,%g), target (%g,%g,%g), %d thread(s), median of %d%s\n\n", scene,
         (unsigned long long)in.triangles, eye[0], eye[1], eye[2], target[0], target[1], target[2], threads, reps,
         cpu ? " (processor ms, all threads)" : "");
  if (!cube_only) cameras_table(&b, eye, target, size);

  /* Cube map: one render of the cross against six 90° perspective renders of the
   * faces, from the cube's own basis. */
  int face = size / 4;
  rr_camera cube;
  rr_camera_init(&cube);
  cube.type = RR_CAMERA_CUBE;
  memcpy(cube.eye, eye, sizeof eye), memcpy(cube.target, target, sizeof target);
  float f[3], up[3] = {0, 1, 0}, r[3];
  for (int a = 0; a < 3; a++) f[a] = target[a] - eye[a];
  float lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (int a = 0; a < 3; a++) f[a] /= lf;
  r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2], r[2] = f[0] * up[1] - f[1] * up[0];
  float lr = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int a = 0; a < 3; a++) r[a] /= lr;
  float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
  float nf[3], nr[3], nu[3];
  for (int a = 0; a < 3; a++) nf[a] = -f[a], nr[a] = -r[a], nu[a] = -u[a];
  const float *dirs[6][2] = {{f, u}, {r, u}, {nf, u}, {nr, u}, {u, nf}, {nu, f}};
  printf("\n| cube map, faces of %d² | method | one cube camera ms | six perspective renders ms | ratio | S cube | S "
         "six | empty bins cube, six |\n|---|---|---|---|---|---|---|---|\n",
         face);
  for (int m = 0; m < NM; m++) {
    rr_stats st;
    double t_cube = run(&b, &cube, methods[m], 4 * face, 3 * face, "cube", &st);
    uint64_t s_cube = st.setups, s_six = 0, bins_six = 0, empty_six = 0;
    const double share_cube = share(&st);
    double total = 0;
    for (int k = 0; k < 6; k++) {
      rr_camera p;
      rr_camera_init(&p);
      p.fov_deg = 90;
      memcpy(p.eye, eye, sizeof eye);
      for (int a = 0; a < 3; a++) p.target[a] = eye[a] + dirs[k][0][a], p.up[a] = dirs[k][1][a];
      char part[32];
      snprintf(part, sizeof part, "cube face %d", k);
      total += run(&b, &p, methods[m], face, face, part, &st);
      s_six += st.setups, bins_six += st.bins, empty_six += st.bins_empty;
    }
    printf("| %dx%d | %s | %.1f | %.1f | %.2f | %llu | %llu | %.1f%%, %.1f%% |\n", 4 * face, 3 * face,
           rr_method_name(methods[m]), t_cube, total, t_cube / total, (unsigned long long)s_cube,
           (unsigned long long)s_six, share_cube, bins_six ? 100.0 * empty_six / bins_six : 0.0);
  }
  rr_scene_release(s);
  rr_device_release(dev);
  return 0;
}
