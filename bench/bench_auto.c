/* auto's choice against the fastest exact method, view by view: for bench_table's
 * scenes and the cameras of docs/cameras.md, the median frame time of every
 * candidate auto weighs, the method auto picks for a single frame (its cost model,
 * no trial) and the ratio chosen / fastest. The target is 1.3× or better everywhere.
 *
 * The candidates take turns, frame by frame, so that a change of load on a shared
 * machine hits them alike; --cpu times frames by the process's CPU time (steadier
 * under load, meaningful on one thread). The teapot grid of 310k triangles is seen
 * from inside, as in docs/cameras.md; the curved cameras are left out above a
 * million triangles (seconds a frame for the 3dr methods).
 *
 *   bench_auto [--threads N] [--reps N] [--size N] [--cull] [--cpu] [SCENE...] */
#include "benchutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* auto's candidates (vis/auto.c) and rc-bvh: "fastest" is the fastest of these. */
static const rr_method cands[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL,
                                  RR_METHOD_RC_PACKET, RR_METHOD_RC_BVH};
enum { NCAND = sizeof cands / sizeof cands[0] };

/* The view of a scene for a camera type: bench_table's view (a corner room of rooms
 * scenes seen from inside), the teapot grid from inside as in docs/cameras.md. */
static void view(rr_device *dev, const char *name, const rr_scene *s, int type, int w, int h, rr_camera *cam) {
  bench_view(dev, name, s, w, h, cam);
  if (strcmp(name, "grid:teapot.obj:7") == 0) {
    float eye[3] = {20.6f, 2.4f, 13.2f}, target[3] = {30, 1.2f, 20};
    memcpy(cam->eye, eye, sizeof eye), memcpy(cam->target, target, sizeof target);
    cam->fov_deg = 70;
  }
  cam->type = (rr_camera_type)type;
  if (type == RR_CAMERA_FISHEYE) cam->fov_deg = 180;
}

int main(int argc, char **argv) {
  int threads = 1, reps = 5, size = 512, cull = 0, cpu = 0, nscenes = 0;
  const char *scenes[16];
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = atoi(argv[++i]);
    else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
    else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) size = atoi(argv[++i]);
    else if (strcmp(argv[i], "--cull") == 0) cull = 1;
    else if (strcmp(argv[i], "--cpu") == 0) cpu = 1;
    else if (argv[i][0] != '-' && nscenes < 16) scenes[nscenes++] = argv[i];
    else {
      fprintf(stderr, "usage: bench_auto [--threads N] [--reps N] [--size N] [--cull] [--cpu] [SCENE...]\n");
      return 2;
    }
  }
  if (threads < 1 || reps < 1 || reps > 64 || size < 48 || size > 8192) return 2;
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19", "rooms:8",
                                "grid:teapot.obj:7"};
    for (int i = 0; i < 6; i++) scenes[nscenes++] = def[i];
  }
  printf("%dx%d (latlong 2:1, cube 4:3), %d thread(s), %s, median %s of %d\n\n", size, size, threads,
         cull ? "backface culling" : "no culling", cpu ? "CPU ms" : "ms", reps);
  printf("| scene | camera |");
  for (int c = 0; c < NCAND; c++) printf(" %s ms |", rr_method_name(cands[c]));
  printf(" auto's pick | chosen / fastest | auto's reason |\n|---|---|");
  for (int c = 0; c < NCAND; c++) printf("---|");
  printf("---|---|---|\n");
  double worst = 0;
  rr_device *dev = rr_device_new();
  for (int sc = 0; sc < nscenes; sc++) {
    rr_scene *s = bench_load(dev, scenes[sc], NULL);
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      bool planar = type == RR_CAMERA_PERSPECTIVE || type == RR_CAMERA_ORTHOGRAPHIC;
      if (!planar && in.triangles > 1000000) continue;
      int w = size, h = type == RR_CAMERA_LATLONG ? size / 2 : type == RR_CAMERA_CUBE ? size / 4 * 3 : size;
      rr_camera cam;
      view(dev, scenes[sc], s, type, w, h, &cam);
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.width = w, opt.height = h, opt.threads = threads, opt.cull_backfaces = cull;
      /* auto's pick for one frame: what a single CLI call gets */
      opt.method = RR_METHOD_AUTO;
      rr_frame *f;
      if (rr_render(dev, s, &cam, &opt, &f) != RR_OK) {
        fprintf(stderr, "bench_auto: %s\n", rr_device_message(dev));
        return 1;
      }
      rr_stats st;
      rr_frame_get_stats(f, &st);
      rr_frame_release(f);
      double t[NCAND][64], ms[NCAND], best = INFINITY, chosen = NAN;
      for (int r = 0; r < reps; r++)
        for (int c = 0; c < NCAND; c++) {
          if (cands[c] == RR_METHOD_3DR_BB && !planar) continue; /* projects onto a plane */
          opt.method = cands[c];
          if (rr_render(dev, s, &cam, &opt, &f) != RR_OK) {
            fprintf(stderr, "bench_auto: %s\n", rr_device_message(dev));
            return 1;
          }
          rr_stats fs;
          rr_frame_get_stats(f, &fs);
          rr_frame_release(f);
          t[c][r] = cpu ? fs.cpu_ms : fs.frame_ms;
        }
      printf("| %s | %s |", scenes[sc], rr_camera_name(type));
      for (int c = 0; c < NCAND; c++) {
        if (cands[c] == RR_METHOD_3DR_BB && !planar) {
          printf(" – |");
          continue;
        }
        ms[c] = bench_median(t[c], reps);
        if (ms[c] < best) best = ms[c];
        if ((int)cands[c] == st.method) chosen = ms[c];
        printf(" %.1f |", ms[c]);
      }
      double ratio = chosen / best;
      if (ratio > worst) worst = ratio;
      printf(" %s | %.2f× %s | %s |\n", rr_method_name(st.method), ratio, ratio <= 1.3 ? "✓" : "✗", st.why);
      fflush(stdout);
    }
    rr_scene_release(s);
  }
  rr_device_release(dev);
  printf("\nworst chosen / fastest: %.2f×\n", worst);
  return 0;
}
