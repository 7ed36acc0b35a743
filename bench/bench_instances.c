/* bench_instances: a grid of instances against the same grid written out.
 *
 *   bench_instances [MODEL] [--n N] [--size WxH] [--threads N] [--reps N] [--instructions]
 *
 * Loads grid:MODEL:N (N² instances of the mesh, stored once) and grid-flat:MODEL:N
 * (the N²·T triangles written out; default teapot.obj, N = 19) and prints for each:
 * the scene's and the BVH's bytes (rr_scene_info), the heap the loaded and committed
 * scene holds (mallinfo2, before and after), the BVH build (median of --reps
 * rr_scene_commit), and the frame of rc-packet and 3dr-bb (default 1024², 2 threads;
 * medians of --reps frames taken in turns, instanced and flat, so that load on the
 * machine hits both alike), with a check that both frames are the same bits.
 * --instructions: instead, callgrind's instructions of one build and one frame per
 * method and scene (repeatable on a loaded machine). With Embree found at build
 * time, also Embree's memory, build and rtcIntersect8 frame on the same view, with
 * its own instancing against the copies written out. */
#include "benchutil.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { REPS_MAX = 64, NMETHODS = 2 };
static const rr_method methods[NMETHODS] = {RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB};

static void usage(void) {
  fprintf(stderr, "usage: bench_instances [MODEL] [--n N] [--size WxH] [--threads N] [--reps N] [--instructions]\n");
  exit(2);
}

int main(int argc, char **argv) {
  const char *model = "teapot.obj";
  int n = 19, w = 1024, h = 1024, threads = 2, reps = 5;
  bool count = false;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--instructions") == 0) count = true;
    else if (strcmp(a, "--n") == 0 && v) {
      if (!bench_arg_int("bench_instances", a, v, 1, 1000, &n)) return 2;
      i++;
    } else if (strcmp(a, "--size") == 0 && v) {
      if (!bench_arg_size("bench_instances", v, 1, &w, &h)) return 2;
      i++;
    } else if (strcmp(a, "--threads") == 0 && v) {
      if (!bench_arg_int("bench_instances", a, v, 1, 256, &threads)) return 2;
      i++;
    } else if (strcmp(a, "--reps") == 0 && v) {
      if (!bench_arg_int("bench_instances", a, v, 1, REPS_MAX, &reps)) return 2;
      i++;
    } else if (a[0] != '-') model = a;
    else usage();
  }
  if (count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (count) reps = 1;
  rr_device *dev = rr_device_new();
  rr_build_options bo;
  rr_build_options_init(&bo);
  bo.threads = threads;
  rr_device_set_build_options(dev, &bo);
  const char *kind[2] = {"grid", "grid-flat"};
  rr_scene *s[2];
  rr_scene_info info[2];
  double heap[2], build[2];
  for (int k = 0; k < 2; k++) {
    char name[600];
    snprintf(name, sizeof name, "%s:%s:%d", kind[k], bench_scene_path(model), n);
    double h0 = bench_heap_bytes();
    s[k] = bench_load(dev, name, NULL);
    heap[k] = bench_heap_bytes() - h0;
    double t[REPS_MAX];
    for (int r = 0; r < reps; r++) {
      if (count) bench_count_start();
      if (rr_scene_commit(s[k]) != RR_OK) {
        fprintf(stderr, "bench_instances: %s\n", rr_device_message(dev));
        return 1;
      }
      if (count) {
        char part[64];
        snprintf(part, sizeof part, "%s build", kind[k]);
        bench_count_stop(part);
      }
      rr_scene_get_info(s[k], &info[k]);
      t[r] = info[k].bvh_build_ms;
    }
    build[k] = bench_median(t, reps);
  }
  rr_camera cam;
  bench_camera(dev, s[0], w, h, &cam);
  double ms[2][NMETHODS], t[2][NMETHODS][REPS_MAX];
  bool same[NMETHODS];
  for (int m = 0; m < NMETHODS; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = methods[m], opt.width = w, opt.height = h, opt.threads = threads;
    rr_frame *f[2] = {NULL, NULL};
    for (int r = 0; r <= reps; r++) /* round 0 warms up */
      for (int k = 0; k < 2; k++) {
        rr_frame_release(f[k]);
        f[k] = NULL;
        char part[64];
        snprintf(part, sizeof part, "%s %s", kind[k], rr_method_name(methods[m]));
        if (count && r) bench_count_start();
        double t0 = bench_now_ms();
        if (rr_render(dev, s[k], &cam, &opt, &f[k]) != RR_OK) {
          fprintf(stderr, "bench_instances: %s\n", rr_device_message(dev));
          return 1;
        }
        if (r) t[k][m][r - 1] = bench_now_ms() - t0;
        if (count && r) bench_count_stop(part);
      }
    for (int k = 0; k < 2; k++) ms[k][m] = bench_median(t[k][m], reps);
    size_t ns = (size_t)w * h;
    same[m] = memcmp(rr_frame_ids(f[0]), rr_frame_ids(f[1]), ns * sizeof(uint32_t)) == 0 &&
              memcmp(rr_frame_t(f[0]), rr_frame_t(f[1]), ns * sizeof(float)) == 0;
    rr_frame_release(f[0]), rr_frame_release(f[1]);
  }
  printf("%s, %d² instances, %llu triangles, %dx%d, %d threads, medians of %d\n", model, n,
         (unsigned long long)info[0].triangles, w, h, threads, reps);
  printf("| scene | scene MiB | BVH MiB | heap MiB | build ms | rc-packet ms | 3dr-bb ms |\n|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < 2; k++)
    printf("| %s | %.2f | %.2f | %.2f | %.1f | %.1f | %.1f |\n", kind[k], info[k].scene_bytes / 1048576.0,
           info[k].bvh_bytes / 1048576.0, heap[k] / 1048576.0, build[k], ms[k][0], ms[k][1]);
  printf("| flat / instanced | %.1fx | %.2fx | %.2fx | %.2fx | %.2fx | %.2fx |\n",
         (double)info[1].scene_bytes / info[0].scene_bytes, (double)info[1].bvh_bytes / info[0].bvh_bytes,
         heap[1] / heap[0], build[1] / build[0], ms[1][0] / ms[0][0], ms[1][1] / ms[0][1]);
  for (int m = 0; m < NMETHODS; m++)
    printf("%s: instanced and flat frames %s\n", rr_method_name(methods[m]), same[m] ? "bit-identical" : "DIFFER");
#ifdef RR_HAVE_EMBREE
  /* Embree on the same view: its instancing (a scene of the mesh, one instance
   * geometry per copy) against the copies written out, MEDIUM build, rtcIntersect8 */
  if (!count) {
    camera c;
    if (rr_cam_setup(dev, &cam, w, h, &c) != RR_OK) return 1;
    size_t ns = (size_t)w * h;
    uint32_t *ids = malloc(ns * sizeof *ids);
    float *tt = malloc(ns * sizeof *tt);
    printf("| Embree | memory MiB | build ms | rtcIntersect8 ms |\n|---|---|---|---|\n");
    for (int k = 0; ids && tt && k < 2; k++) {
      double bt[REPS_MAX], ft[REPS_MAX], b = 0;
      peer_embree *e = NULL;
      for (int r = 0; r < reps; r++) {
        peer_embree_release(e);
        e = peer_embree_new(s[k], threads, 1, &bt[r]);
        if (!e) return 1;
      }
      peer_embree_cast(e, &c, 8, threads, ids, tt); /* warm-up */
      for (int r = 0; r < reps; r++) ft[r] = peer_embree_cast(e, &c, 8, threads, ids, tt);
      b = bench_median(bt, reps);
      printf("| %s | %.2f | %.1f | %.1f |\n", kind[k], peer_embree_bytes(e).scene / 1048576.0, b, bench_median(ft, reps));
      peer_embree_release(e);
    }
    free(ids), free(tt);
    rr_cam_release(&c);
  }
#endif
  rr_scene_release(s[0]), rr_scene_release(s[1]);
  rr_device_release(dev);
  return same[0] && same[1] ? 0 : 1;
}
