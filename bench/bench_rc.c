/* bench_rc: primary visibility at 1024x1024 with rastray's ray casters (and 3dr-bb)
 * against Embree 3 casting the very same rays (origin = eye, direction =
 * camera_dir of each sample: rtcIntersect1 per ray and rtcIntersect8 on 2x4
 * packets), in one process, on the same scene, camera and thread count.
 *
 *   bench_rc [SCENE...] [--threads N]... [--method NAME]... [--reps N] [--size WxH]
 *            [--quality medium|high] [--instructions]
 *
 * Per mode: build ms, frame ms (median of --reps, default 5), Mrays/s, time ratio
 * to Embree's rtcIntersect1 (frame; build for the build column), agreement with
 * Embree's rtcIntersect1 (same hit/miss; depth within 1e-4 relative where both
 * hit; same triangle) and whether the visibility buffer is bit-identical to 3dr-bb.
 * --instructions: instead, the instructions of one frame (or cast) of each mode,
 * counted by running this again under callgrind (use a smaller --size).
 * Analytic spheres go to Embree as its own spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT):
 * `bench_rc spheres:10000` is issue 17's sphere benchmark. */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <stdio.h>
#include <string.h>

typedef struct {
  int reps, w, h, quality;
  bool count; /* under callgrind for --instructions: count one frame per mode */
  int threads[8], nthreads;
  int methods[RR_METHOD_COUNT], nmethods;
} bench_rc_opts;

static void bench_rc_row(const char *mode, double build_ms, double build_ref, double ms, double ref_ms, int w, int h,
                         const bench_agreement *a, const char *same_bb) {
  char b[32] = "-", r[32] = "-", ag[64] = "-";
  if (build_ms >= 0) snprintf(b, sizeof b, "%.1f", build_ms);
  if (build_ms >= 0 && build_ref > 0) snprintf(b + strlen(b), sizeof b - strlen(b), " (%.2fx)", build_ms / build_ref);
  if (ref_ms > 0) snprintf(r, sizeof r, "%.2fx", ms / ref_ms);
  if (a) snprintf(ag, sizeof ag, "%.4f%% %.4f%% %.4f%%", 100 * a->same_hit, 100 * a->depth_ok, 100 * a->same_id);
  printf("  %-18s %-16s %9.1f %8.2f %8s   %-32s %s\n", mode, b, ms, (double)w * h / ms / 1000.0, r, ag,
         same_bb ? same_bb : "");
}

static void bench_rc_scene(rr_device *dev, const char *name, const bench_rc_opts *o) {
  rr_scene *s = bench_load(dev, name, NULL);
  rr_camera cam;
  bench_camera(dev, s, o->w, o->h, &cam);
  camera c;
  if (rr_cam_setup(dev, &cam, o->w, o->h, &c) != RR_OK) {
    fprintf(stderr, "bench_rc: %s\n", rr_device_message(dev));
    exit(1);
  }
  size_t n = (size_t)o->w * o->h;
  uint32_t *eids = malloc(n * sizeof *eids), *bb_ids = malloc(n * sizeof *bb_ids);
  float *et = malloc(n * sizeof *et), *bb_t = malloc(n * sizeof *bb_t);
  for (int ti = 0; ti < o->nthreads; ti++) {
    int threads = o->threads[ti];
    rr_build_options bo;
    rr_build_options_init(&bo);
    bo.threads = threads;
    rr_device_set_build_options(dev, &bo);
    if (rr_scene_commit(s) != RR_OK) {
      fprintf(stderr, "bench_rc: %s\n", rr_device_message(dev));
      exit(1);
    }
    rr_scene_info info;
    rr_scene_get_info(s, &info);
    printf("\n%s: %llu triangles, %dx%d, %d thread%s; BVH %llu nodes, SAH %.1f, %.2f MiB\n", name,
           (unsigned long long)info.triangles, o->w, o->h, threads, threads > 1 ? "s" : "",
           (unsigned long long)info.bvh_nodes, info.bvh_sah_cost, info.bvh_bytes / 1048576.0);
    printf("  %-18s %-16s %9s %8s %8s   %-32s %s\n", "mode", "build ms", "frame ms", "Mrays/s", "vs emb1",
           "agree: hit/miss depth id", "= 3dr-bb");
    double emb_ms = 0, emb_build = 0;
    bool have_embree = false;
#ifdef RR_HAVE_EMBREE
    peer_embree *e = peer_embree_new(s, threads, o->quality, &emb_build);
    if (e) {
      have_embree = true;
      const int widths[2] = {1, 8};
      for (int wi = 0; wi < 2; wi++) {
        char mode[64], part[160];
        snprintf(mode, sizeof mode, "embree-%d (%s)", widths[wi], o->quality >= 2 ? "high" : "medium");
        snprintf(part, sizeof part, "%s %dt %s", name, threads, mode);
        double t[64];
        if (o->count) peer_embree_cast(e, &c, widths[wi], threads, eids, et); /* warm-up, as bench_count_frame */
        for (int r = 0; r < o->reps; r++) {
          if (o->count) bench_count_start(); /* the single rep under callgrind */
          t[r] = peer_embree_cast(e, &c, widths[wi], threads, eids, et);
          if (o->count) bench_count_stop(part);
        }
        double ms = bench_median(t, o->reps);
        if (wi == 0) emb_ms = ms;
        bench_rc_row(mode, wi == 0 ? emb_build : -1, 0, ms, emb_ms, o->w, o->h, NULL, NULL);
      }
      /* Keep rtcIntersect1's result as the reference. */
      peer_embree_cast(e, &c, 1, threads, eids, et);
      peer_embree_release(e);
    }
#endif
    bool have_bb = false;
    for (int mi = 0; mi < o->nmethods; mi++) {
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = (rr_method)o->methods[mi], opt.width = o->w, opt.height = o->h, opt.threads = threads;
      rr_frame *f = NULL;
      char part[160];
      snprintf(part, sizeof part, "%s %dt %s", name, threads, rr_method_name(opt.method));
      double ms = o->count ? bench_count_frame(dev, s, &cam, &opt, part, &f)
                           : bench_render(dev, s, &cam, &opt, o->reps, &f);
      const uint32_t *ids = rr_frame_ids(f);
      const float *t = rr_frame_t(f);
      bench_agreement a;
      if (have_embree) a = bench_compare(ids, t, eids, et, n);
      const char *same = NULL;
      if (opt.method == RR_METHOD_3DR_BB) {
        memcpy(bb_ids, ids, n * sizeof *ids), memcpy(bb_t, t, n * sizeof *t);
        have_bb = true;
        same = "(reference)";
      } else if (have_bb) {
        same = memcmp(bb_ids, ids, n * sizeof *ids) || memcmp(bb_t, t, n * sizeof *t) ? "DIFFERS" : "identical";
      }
      bool uses_bvh = opt.method != RR_METHOD_RC && opt.method != RR_METHOD_2DR_BB && opt.method != RR_METHOD_2DR_BIN &&
                      opt.method != RR_METHOD_3DR_BB && opt.method != RR_METHOD_3DR_BIN;
      bench_rc_row(rr_method_name(opt.method), uses_bvh ? info.bvh_build_ms : -1, emb_build, ms, emb_ms, o->w, o->h,
                   have_embree ? &a : NULL, same);
      rr_frame_release(f);
    }
  }
  free(eids), free(et), free(bb_ids), free(bb_t);
  rr_cam_release(&c);
  rr_scene_release(s);
}

int main(int argc, char **argv) {
  bench_rc_opts o = {.reps = 5, .w = 1024, .h = 1024, .quality = 1};
  const char *scenes[64];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--threads") == 0 && v && o.nthreads < 8) o.threads[o.nthreads++] = atoi(v), i++;
    else if (strcmp(a, "--method") == 0 && v && rr_method_from_name(v) >= 0 && o.nmethods < RR_METHOD_COUNT)
      o.methods[o.nmethods++] = rr_method_from_name(v), i++;
    else if (strcmp(a, "--reps") == 0 && v) o.reps = atoi(v), i++;
    else if (strcmp(a, "--size") == 0 && v && sscanf(v, "%dx%d", &o.w, &o.h) == 2) i++;
    else if (strcmp(a, "--quality") == 0 && v) o.quality = strcmp(v, "high") == 0 ? 2 : 1, i++;
    else if (strcmp(a, "--instructions") == 0) o.count = true;
    else if (a[0] == '-') {
      fprintf(stderr, "usage: bench_rc [SCENE...] [--threads N]... [--method NAME]... [--reps N] [--size WxH] "
                      "[--quality medium|high] [--instructions]\n");
      return 2;
    } else if (nscenes < 64) scenes[nscenes++] = a;
  }
  if (o.count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (o.count) o.reps = 1;
  if (o.reps < 1) o.reps = 1;
  if (o.reps > 64) o.reps = 64;
  if (o.w < 1 || o.h < 1 || o.w > RR_MAX_SIZE || o.h > RR_MAX_SIZE) o.w = o.h = 1024;
  if (!o.nthreads) {
    o.threads[o.nthreads++] = 1;
    if (rr_cpu_count() > 1) o.threads[o.nthreads++] = rr_cpu_count();
  }
  if (!o.nmethods) {
    o.methods[o.nmethods++] = RR_METHOD_3DR_BB; /* first: the bitwise reference */
    o.methods[o.nmethods++] = RR_METHOD_RC_BVH;
    o.methods[o.nmethods++] = RR_METHOD_RC_PACKET;
  }
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19"};
    for (int i = 0; i < 4; i++) scenes[nscenes++] = def[i];
  }
#ifndef RR_HAVE_EMBREE
  printf("Embree 3 not found at build time (install libembree-dev): rastray's modes only\n");
#endif
  printf("rastray %s bench_rc: ratios are time / Embree rtcIntersect1's time (build: / Embree's build);\n"
         "agreement with rtcIntersect1: same hit/miss, depth within 1e-4 relative where both hit, same triangle id\n",
         RR_VERSION);
  rr_device *dev = rr_device_new();
  for (int i = 0; i < nscenes; i++) bench_rc_scene(dev, scenes[i], &o);
  rr_device_release(dev);
  return 0;
}
