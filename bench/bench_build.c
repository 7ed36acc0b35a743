/* bench_build: BVH build time against Embree 3's build in one process, on the
 * same triangles and thread count.
 *
 *   bench_build [SCENE...] [--threads N]... [--reps N] [--quality medium|high] [--no-peer] [--instructions]
 *
 * Per scene and thread count: rastray's build (rr_scene_commit: the binary tree,
 * its 4-wide form and its SAH figures) and Embree's rtcCommitScene (default
 * quality MEDIUM), each the median of --reps builds (default 7) taken in turns, so
 * that load on the machine hits both alike; the ratio is rastray / Embree. The
 * cpu columns are the process's processor time over the same builds (rastray's
 * over rr_scene_commit, which also frees the previous tree): on a loaded machine
 * steadier than wall time; at one thread the same work, at more the work of all
 * threads (a thread that spins while waiting counts).
 * --no-peer: rastray's builds alone (to profile them, e.g. with perf).
 * --instructions: instead, the instructions of one rastray build per scene and
 * thread count, counted by running this again under callgrind. */
#include "benchutil.h"
#include "core/core.h" /* rr_cpu_ms */
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <stdio.h>
#include <string.h>

enum { REPS_MAX = 64 };

typedef struct {
  int reps, quality;
  bool count;   /* under callgrind for --instructions: count one build per row */
  bool no_peer; /* rastray's builds only */
  int threads[8], nthreads;
} bench_build_opts;

/* One rastray build of s with `threads`; its ms as the library measured it, and
 * the processor ms of the commit into *cpu_ms. */
static double rastray_build(rr_device *dev, rr_scene *s, int threads, rr_scene_info *info, double *cpu_ms) {
  rr_build_options bo;
  rr_build_options_init(&bo);
  bo.threads = threads;
  rr_device_set_build_options(dev, &bo);
  double c0 = rr_cpu_ms();
  rr_error err = rr_scene_commit(s);
  *cpu_ms = rr_cpu_ms() - c0;
  if (err != RR_OK) {
    fprintf(stderr, "bench_build: %s\n", rr_device_message(dev));
    exit(1);
  }
  rr_scene_get_info(s, info);
  return info->bvh_build_ms;
}

/* One Embree build of s; its ms (and processor ms into *cpu_ms), or -1 without Embree. */
static double embree_build(const rr_scene *s, int threads, const bench_build_opts *o, double *cpu_ms) {
  double ms = -1;
  *cpu_ms = -1;
#ifdef RR_HAVE_EMBREE
  if (o->no_peer) return -1;
  peer_embree *e = peer_embree_new(s, threads, o->quality, &ms);
  if (!e) return -1;
  *cpu_ms = peer_embree_build_cpu_ms(e);
  peer_embree_release(e);
#else
  (void)s, (void)threads, (void)o;
#endif
  return ms;
}

static void bench_build_scene(rr_device *dev, const char *name, const bench_build_opts *o) {
  rr_scene *s = bench_load(dev, name, NULL);
  for (int ti = 0; ti < o->nthreads; ti++) {
    int threads = o->threads[ti];
    rr_scene_info info;
    double rr_ms[REPS_MAX], emb_ms[REPS_MAX], rr_cpu[REPS_MAX], emb_cpu[REPS_MAX], cpu;
    if (o->count) {
      rastray_build(dev, s, threads, &info, &cpu); /* warm-up, as bench_count_frame */
      char part[160];
      snprintf(part, sizeof part, "%s %dt build", name, threads);
      bench_count_start();
      rastray_build(dev, s, threads, &info, &cpu);
      bench_count_stop(part);
      continue;
    }
    /* A first build of each, not counted: page faults and thread start-up. */
    rastray_build(dev, s, threads, &info, &cpu);
    embree_build(s, threads, o, &cpu);
    for (int r = 0; r < o->reps; r++) {
      rr_ms[r] = rastray_build(dev, s, threads, &info, &rr_cpu[r]);
      emb_ms[r] = embree_build(s, threads, o, &emb_cpu[r]);
    }
    double a = bench_median(rr_ms, o->reps), b = bench_median(emb_ms, o->reps);
    double ca = bench_median(rr_cpu, o->reps), cb = bench_median(emb_cpu, o->reps);
    char ratio[32] = "-", emb[32] = "-", cratio[32] = "-";
    if (b > 0) snprintf(emb, sizeof emb, "%.1f", b), snprintf(ratio, sizeof ratio, "%.2fx", a / b);
    if (cb > 0) snprintf(cratio, sizeof cratio, "%.2fx", ca / cb);
    printf("  %-22s %8llu %3d %9.1f %9s %7s %9.1f %7s %9llu %8.1f\n", name, (unsigned long long)info.triangles,
           threads, a, emb, ratio, ca, cratio, (unsigned long long)info.bvh_nodes, info.bvh_sah_cost);
  }
  rr_scene_release(s);
}

int main(int argc, char **argv) {
  bench_build_opts o = {.reps = 7, .quality = 1};
  const char *scenes[64];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--threads") == 0 && v && o.nthreads < 8) o.threads[o.nthreads++] = atoi(v), i++;
    else if (strcmp(a, "--reps") == 0 && v) o.reps = atoi(v), i++;
    else if (strcmp(a, "--quality") == 0 && v) o.quality = strcmp(v, "high") == 0 ? 2 : 1, i++;
    else if (strcmp(a, "--no-peer") == 0) o.no_peer = true;
    else if (strcmp(a, "--instructions") == 0) o.count = true;
    else if (a[0] == '-') {
      fprintf(stderr, "usage: bench_build [SCENE...] [--threads N]... [--reps N] [--quality medium|high] "
                      "[--no-peer] [--instructions]\n");
      return 2;
    } else if (nscenes < 64) scenes[nscenes++] = a;
  }
  if (o.count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (o.reps < 1) o.reps = 1;
  if (o.reps > REPS_MAX) o.reps = REPS_MAX;
  if (!o.nthreads) {
    o.threads[o.nthreads++] = 1;
    if (rr_cpu_count() > 1) o.threads[o.nthreads++] = rr_cpu_count();
  }
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19"};
    for (int i = 0; i < 4; i++) scenes[nscenes++] = def[i];
  }
#ifndef RR_HAVE_EMBREE
  printf("Embree 3 not found at build time (install libembree-dev): rastray's builds only\n");
#endif
  printf("rastray %s bench_build: medians of %d builds each, taken in turns; ratio = rastray / Embree (%s)\n",
         RR_VERSION, o.reps, o.quality >= 2 ? "high" : "medium");
  printf("  %-22s %8s %3s %9s %9s %7s %9s %7s %9s %8s\n", "scene", "tris", "thr", "rastray", "embree", "ratio",
         "cpu", "cpu", "nodes", "SAH");
  rr_device *dev = rr_device_new();
  for (int i = 0; i < nscenes; i++) bench_build_scene(dev, scenes[i], &o);
  rr_device_release(dev);
  return 0;
}
