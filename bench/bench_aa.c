/* bench_aa: the cost of anti-aliasing. For each scene (default: the bunny, the
 * teapot grid 19² and spot, whose Lambert shading reads a texture), auto-framed at
 * --size (default 1024x1024) on --threads (default 2), with 3dr-bb and the method
 * auto picks for the view when it is another: the whole frame (visibility, shading
 * with Lambert, resolve) and its parts for none, msaa:4, msaa:16, csaa:4/16 and
 * ssaa:16 (standard positions), the medians of --runs rounds (default 5) in which
 * the modes take turns, so that a change of load hits them alike, and each total's
 * ratio to none's. Targets (issue 14): msaa:16 ≤ 4×, csaa:4/16 ≤ 2.5× none's total.
 *
 *   bench_aa [SCENE...] [--size WxH] [--threads N] [--runs N] */
#include "benchutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const struct {
  const char *name;
  rr_aa_mode mode;
  int samples, stored;
} modes[] = {{"none", RR_AA_NONE, 1, 0},
             {"msaa:4", RR_AA_MSAA, 4, 0},
             {"msaa:16", RR_AA_MSAA, 16, 0},
             {"csaa:4/16", RR_AA_CSAA, 16, 4},
             {"ssaa:16", RR_AA_SSAA, 16, 0}};
enum { NMODES = sizeof modes / sizeof *modes, MAX_RUNS = 64 };

/* The parts of one frame, in ms. */
enum { VIS, SHADE, RESOLVE, TOTAL, NPARTS };

static void frame(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                  double part[NPARTS], unsigned long long *shades) {
  double t0 = bench_now_ms();
  rr_frame *f;
  rr_image img;
  rr_shade_stats st;
  if (rr_render(dev, s, cam, opt, &f) != RR_OK ||
      rr_shade_frame(dev, s, cam, f, NULL, &img, &st) /* Lambert, box */ != RR_OK) {
    fprintf(stderr, "bench_aa: %s\n", rr_device_message(dev));
    exit(1);
  }
  part[TOTAL] = bench_now_ms() - t0;
  rr_stats vs;
  rr_frame_get_stats(f, &vs);
  part[VIS] = vs.frame_ms, part[SHADE] = st.shade_ms, part[RESOLVE] = st.resolve_ms;
  *shades = st.shades;
  rr_image_free(&img);
  rr_frame_release(f);
}

static void measure(rr_device *dev, const char *name, const rr_scene *s, const rr_camera *cam, rr_method method,
                    int w, int h, int threads, int runs) {
  static double ms[NMODES][NPARTS][MAX_RUNS];
  unsigned long long shades[NMODES];
  for (int r = 0; r < runs; r++)
    for (int m = 0; m < NMODES; m++) {
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = method, opt.width = w, opt.height = h, opt.threads = threads;
      rr_render_options_set_aa(dev, &opt, modes[m].mode, modes[m].samples, modes[m].stored, RR_AA_STANDARD, 0);
      double part[NPARTS];
      frame(dev, s, cam, &opt, part, &shades[m]);
      for (int p = 0; p < NPARTS; p++) ms[m][p][r] = part[p];
    }
  double none = 0;
  for (int m = 0; m < NMODES; m++) {
    double med[NPARTS];
    for (int p = 0; p < NPARTS; p++) med[p] = bench_median(ms[m][p], runs);
    if (m == 0) none = med[TOTAL];
    printf("| %s | %s | %s | %.1f | %.1f | %.1f | %.1f | %.2fx | %llu |\n", name, rr_method_name(method), modes[m].name,
           med[VIS], med[SHADE], med[RESOLVE], med[TOTAL], med[TOTAL] / none, shades[m]);
    fflush(stdout);
  }
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 2, runs = 5, nscenes = 0;
  const char *scenes[16];
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (!bench_arg_size("bench_aa", argv[++i], 1, &w, &h)) return 2;
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_aa", "--threads", argv[++i], 1, RR_MAX_THREADS, &threads)) return 2;
    } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_aa", "--runs", argv[++i], 1, MAX_RUNS, &runs)) return 2;
    } else if (argv[i][0] == '-' || nscenes == 16) {
      fprintf(stderr, "usage: bench_aa [SCENE...] [--size WxH] [--threads N] [--runs N]\n");
      return 2;
    } else {
      scenes[nscenes++] = argv[i];
    }
  }
  if (!nscenes) scenes[nscenes++] = "stanford-bunny.obj", scenes[nscenes++] = "grid:teapot.obj:19",
                scenes[nscenes++] = "spot.obj";
  rr_device *dev = rr_device_new();
  printf("%dx%d, %d threads, Lambert shading, box resolve, medians of %d runs (ms)\n\n", w, h, threads, runs);
  printf("| scene | method | AA | visibility | shading | resolve | total | total / none | shades |\n"
         "|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < nscenes; i++) {
    rr_scene *s = bench_load(dev, scenes[i], NULL);
    rr_camera cam;
    bench_view(dev, scenes[i], s, w, h, &cam);
    /* the fastest method for the view without AA, as auto's model and trial find it */
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_AUTO, opt.width = w, opt.height = h, opt.threads = threads, opt.frames_hint = 100;
    rr_frame *f = NULL;
    bench_render(dev, s, &cam, &opt, 1, &f);
    rr_stats st;
    rr_frame_get_stats(f, &st);
    rr_frame_release(f);
    measure(dev, scenes[i], s, &cam, RR_METHOD_3DR_BB, w, h, threads, runs);
    if (st.method != RR_METHOD_3DR_BB) measure(dev, scenes[i], s, &cam, (rr_method)st.method, w, h, threads, runs);
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return 0;
}
