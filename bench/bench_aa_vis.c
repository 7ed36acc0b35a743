/* bench_aa_vis: the visibility cost of anti-aliasing. For each scene (default: the
 * bunny and the teapot grid 19²), auto-framed at --size (default 1024x1024) on
 * --threads (default 2): rastray's visibility time (rr_render's frame_ms) for
 * 3dr-bb, 2dr-bb and the fastest 3dr method (picked at one sample) at 1, 4 and 16
 * samples per pixel (Direct3D's standard 4x and 16x positions), the medians of
 * --runs rounds (default 5) in which every mode takes one turn, with ratios to one
 * sample; and Mesa llvmpipe's frame (draw + glFinish) at 1 and 4 samples through
 * OSMesa (a multisample framebuffer object), its resolve timed apart, and its ratio.
 * The target (issue 14): rastray's 4x/1x ratio no worse than llvmpipe's.
 *
 *   bench_aa_vis [SCENE...] [--size WxH] [--threads N] [--runs N] [--instructions]
 *
 * --instructions: callgrind's instructions of one frame of each rastray mode. */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_OSMESA
#include "peer_osmesa.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Direct3D's (and Vulkan's) standard positions, in 1/16 pixel from the centre, y
 * down like rastray's rows. (Kept here until the public API has its patterns.) */
static const int d3d4[4][2] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
static const int d3d16[16][2] = {{1, 1},   {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},   {5, 3},   {3, -5},
                                 {-2, 6},  {0, -7},  {-4, -6}, {-6, 4}, {-8, 0}, {7, -4}, {6, 7}, {-7, -8}};

static void set_pattern(rr_render_options *o, int n) {
  o->samples = n;
  for (int s = 0; s < n; s++) {
    const int *d = n == 16 ? d3d16[s] : n == 4 ? d3d4[s] : (const int[2]){0, 0};
    o->sample_pos[s][0] = 0.5f + d[0] / 16.0f, o->sample_pos[s][1] = 0.5f + d[1] / 16.0f;
  }
}

enum { NMETHODS = 3, NPATTERNS = 3, RUNS_MAX = 64 };
static const int patterns[NPATTERNS] = {1, 4, 16};

typedef struct opts {
  int w, h, threads, runs;
  bool count;
} opts;

static double render_ms(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *o) {
  rr_frame *f = NULL;
  if (rr_render(dev, s, cam, o, &f) != RR_OK) {
    fprintf(stderr, "bench_aa_vis: %s\n", rr_device_message(dev));
    exit(1);
  }
  double ms = f->stats.frame_ms;
  rr_frame_release(f);
  return ms;
}

/* The 3dr method of the lowest median one-sample time over three interleaved rounds. */
static rr_method fastest_3dr(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_render_options o) {
  static const rr_method cand[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FS,
                                   RR_METHOD_3DR_FULL};
  enum { NC = sizeof cand / sizeof *cand };
  double ms[NC][3];
  set_pattern(&o, 1);
  for (int r = 0; r < 3; r++)
    for (int i = 0; i < NC; i++) o.method = cand[i], ms[i][r] = render_ms(dev, s, cam, &o);
  int best = 0;
  double best_ms = INFINITY;
  for (int i = 0; i < NC; i++) {
    double m = bench_median(ms[i], 3);
    if (m < best_ms) best_ms = m, best = i;
  }
  return cand[best];
}

static void bench_scene(rr_device *dev, const char *name, const opts *op) {
  rr_scene *s = bench_load(dev, name, NULL);
  rr_camera cam;
  bench_view(dev, name, s, op->w, op->h, &cam);
  rr_render_options o;
  rr_render_options_init(&o);
  o.width = op->w, o.height = op->h, o.threads = op->threads;
  rr_method methods[NMETHODS] = {RR_METHOD_3DR_BB, RR_METHOD_2DR_BB,
                                 op->count ? RR_METHOD_3DR_FULL : fastest_3dr(dev, s, &cam, o)};
  printf("\n%s: %u triangles, %dx%d, %d threads, medians of %d runs\n", name, s->ntris, op->w, op->h, op->threads,
         op->runs);
  static double ms[NMETHODS][NPATTERNS][RUNS_MAX];
  for (int r = 0; r < (op->count ? 1 : op->runs); r++)
    for (int m = 0; m < NMETHODS; m++)
      for (int p = 0; p < NPATTERNS; p++) {
        o.method = methods[m];
        set_pattern(&o, patterns[p]);
        if (op->count) {
          char part[64];
          snprintf(part, sizeof part, "%s %s %dx", name, rr_method_name(methods[m]), patterns[p]);
          rr_frame *f = NULL;
          bench_count_frame(dev, s, &cam, &o, part, &f);
          rr_frame_release(f);
        } else {
          ms[m][p][r] = render_ms(dev, s, &cam, &o);
        }
      }
  if (op->count) {
    rr_scene_release(s);
    return;
  }
  printf("| method | 1x ms | 4x ms | 16x ms | 4x / 1x | 16x / 1x |\n|---|---|---|---|---|---|\n");
  double rastray4[NMETHODS];
  for (int m = 0; m < NMETHODS; m++) {
    double med[NPATTERNS];
    for (int p = 0; p < NPATTERNS; p++) med[p] = bench_median(ms[m][p], op->runs);
    rastray4[m] = med[1] / med[0];
    printf("| %s%s | %.1f | %.1f | %.1f | %.2f | %.2f |\n", rr_method_name(methods[m]),
           m == 2 ? " (fastest 3dr)" : "", med[0], med[1], med[2], med[1] / med[0], med[2] / med[0]);
  }
#ifdef RR_HAVE_OSMESA
  osmesa_peer *gl = osmesa_new(op->w, op->h, op->threads);
  if (gl && osmesa_load(gl, s) == 0) {
    double gms[2][RUNS_MAX], res[RUNS_MAX];
    bool ok = true;
    for (int r = 0; r < op->runs && ok; r++)
      for (int k = 0; k < 2 && ok; k++) {
        ok = osmesa_set_samples(gl, k ? 4 : 1) == (k ? 4 : 1);
        gms[k][r] = osmesa_render(gl, &cam, 0, 1);
        if (k) res[r] = osmesa_resolve_ms(gl);
      }
    if (ok) {
      double g1 = bench_median(gms[0], op->runs), g4 = bench_median(gms[1], op->runs), gr = bench_median(res, op->runs);
      printf("| llvmpipe (%s) | %.1f | %.1f (+%.1f resolve) | - | %.2f | - |\n", osmesa_renderer(gl), g1, g4, gr,
             g4 / g1);
      printf("4x target (ratio no worse than llvmpipe's %.2f):", g4 / g1);
      for (int m = 0; m < NMETHODS; m++)
        printf(" %s %.2f %s", rr_method_name(methods[m]), rastray4[m], rastray4[m] <= g4 / g1 ? "met" : "missed");
      printf("\n");
    }
  }
  osmesa_release(gl);
#else
  (void)rastray4;
  printf("llvmpipe: not measured (OSMesa not found at build time; install libosmesa6-dev)\n");
#endif
  rr_scene_release(s);
}

int main(int argc, char **argv) {
  opts op = {.w = 1024, .h = 1024, .threads = 2, .runs = 5};
  const char *scenes[16];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--size") == 0 && v && sscanf(v, "%dx%d", &op.w, &op.h) == 2) i++;
    else if (strcmp(a, "--threads") == 0 && v) op.threads = atoi(v), i++;
    else if (strcmp(a, "--runs") == 0 && v) op.runs = atoi(v), i++;
    else if (strcmp(a, "--instructions") == 0) op.count = true;
    else if (a[0] != '-' && nscenes < 16) scenes[nscenes++] = a;
    else {
      fprintf(stderr, "usage: bench_aa_vis [SCENE...] [--size WxH] [--threads N] [--runs N] [--instructions]\n");
      return 2;
    }
  }
  if (op.w < 1 || op.h < 1 || op.w > RR_MAX_SIZE || op.h > RR_MAX_SIZE || op.threads < 1 ||
      op.threads > RR_MAX_THREADS || op.runs < 1 || op.runs > RUNS_MAX) {
    fprintf(stderr, "bench_aa_vis: bad --size, --threads or --runs\n");
    return 2;
  }
  if (op.count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (!nscenes) scenes[nscenes++] = "stanford-bunny.obj", scenes[nscenes++] = "grid:teapot.obj:19";
  printf("rastray %s bench_aa_vis: visibility time at 1, 4 and 16 samples per pixel (Direct3D's standard positions)\n",
         RR_VERSION);
  rr_device *dev = rr_device_new();
  for (int i = 0; i < nscenes; i++) bench_scene(dev, scenes[i], &op);
  rr_device_release(dev);
  return 0;
}
