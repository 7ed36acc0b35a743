/* Visibility at N samples per pixel: the frame time of each 3dr method at 1, 4
 * and 16 sample positions (the rotated grids of tests/test_samples.c and
 * test_samples3d.c) and its ratio to the one-sample frame; the 3dr methods take
 * every position in one pass (issue 14's targets: 16 samples <= 4x, 4 samples
 * <= 2x). Rounds interleave every method and count (median per cell).
 * --instructions: instead, the instructions of one frame of each, counted by
 * running this again under callgrind (use a smaller --size).
 *
 * --method NAME (repeatable): only these 3dr methods.
 *
 * usage: bench_samples [--size N|WxH] [--threads N] [--reps N] [--method NAME] [--instructions] [SCENE...]
 * SCENE as bench_raster's (default: stanford-bunny.obj grid:teapot.obj:19). */
#include "benchutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rr_method methods[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FS,
                              RR_METHOD_3DR_FULL};
enum { NM_ALL = sizeof methods / sizeof methods[0], NC = 3 };
static int NM = NM_ALL;
static const int counts[NC] = {1, 4, 16};

/* counts[c] positions: the centre, the 4 rotated-grid positions, or a 4x4 grid
 * rotated by atan(1/2) and wrapped into the pixel. */
static void positions(rr_render_options *o, int n) {
  static const float rg4[4][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};
  o->samples = n;
  if (n == 1) o->sample_pos[0][0] = o->sample_pos[0][1] = 0.5f;
  if (n == 4) memcpy(o->sample_pos, rg4, sizeof rg4);
  if (n == 16) {
    const float c = 2.0f / sqrtf(5.0f), s = 1.0f / sqrtf(5.0f);
    for (int i = 0; i < 16; i++) {
      float u = ((float)(i % 4) + 0.5f) / 4 - 0.5f, v = ((float)(i / 4) + 0.5f) / 4 - 0.5f;
      float x = 0.5f + c * u - s * v, y = 0.5f + s * u + c * v;
      o->sample_pos[i][0] = x - floorf(x), o->sample_pos[i][1] = y - floorf(y);
    }
  }
}

static void usage(void) {
  fprintf(stderr,
          "usage: bench_samples [--size N|WxH] [--threads N] [--reps N] [--method NAME] [--instructions] [SCENE...]\n");
  exit(2);
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 2, reps = 5;
  bool count = false;
  const char *scenes[16];
  int nscenes = 0, nchosen = 0;
  rr_method chosen[NM_ALL];
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (strcmp(a, "--size") == 0 && i + 1 < argc) {
      if (sscanf(argv[++i], "%dx%d", &w, &h) != 2) h = w = atoi(argv[i]);
    } else if (strcmp(a, "--threads") == 0 && i + 1 < argc) {
      threads = atoi(argv[++i]);
    } else if (strcmp(a, "--reps") == 0 && i + 1 < argc) {
      reps = atoi(argv[++i]);
    } else if (strcmp(a, "--method") == 0 && i + 1 < argc) {
      int m = rr_method_from_name(argv[++i]);
      bool known = false;
      for (int k = 0; k < NM_ALL; k++) known |= (int)methods[k] == m;
      if (!known || nchosen == NM_ALL) usage();
      chosen[nchosen++] = (rr_method)m;
    } else if (strcmp(a, "--instructions") == 0) {
      count = true;
    } else if (a[0] == '-' || nscenes == 16) {
      usage();
    } else {
      scenes[nscenes++] = a;
    }
  }
  if (w < 1 || h < 1 || threads < 1 || threads > 256 || reps < 1 || reps > 64) usage();
  if (nchosen) memcpy(methods, chosen, sizeof chosen[0] * (size_t)(NM = nchosen));
  if (count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (count) reps = 1;
  if (nscenes == 0) scenes[nscenes++] = "stanford-bunny.obj", scenes[nscenes++] = "grid:teapot.obj:19";
  rr_device *dev = rr_device_new();
  printf("bench_samples: %dx%d, %d thread%s, median of %d frames\n", w, h, threads, threads == 1 ? "" : "s", reps);
  for (int si = 0; si < nscenes; si++) {
    double load_ms;
    rr_scene *s = bench_load(dev, scenes[si], &load_ms);
    rr_camera cam;
    bench_view(dev, scenes[si], s, w, h, &cam);
    double t[NM_ALL][NC][64];
    rr_stats st[NM_ALL][NC];
    for (int rep = 0; rep <= reps; rep++) /* round 0 warms up */
      for (int m = 0; m < NM; m++)
        for (int c = 0; c < NC; c++) {
          rr_render_options o;
          rr_render_options_init(&o);
          o.method = methods[m], o.width = w, o.height = h, o.threads = threads;
          positions(&o, counts[c]);
          char part[160];
          snprintf(part, sizeof part, "%s %s %d", scenes[si], rr_method_name(methods[m]), counts[c]);
          rr_frame *f;
          if (count && rep) bench_count_start();
          rr_error e = rr_render(dev, s, &cam, &o, &f);
          if (count && rep) bench_count_stop(part);
          if (e != RR_OK) {
            fprintf(stderr, "bench_samples: %s\n", rr_device_message(dev));
            return 1;
          }
          rr_frame_get_stats(f, &st[m][c]);
          if (rep) t[m][c][rep - 1] = st[m][c].frame_ms;
          rr_frame_release(f);
        }
    printf("\n%s\n  %-9s", scenes[si], "method");
    for (int c = 0; c < NC; c++) printf(" %8d spp", counts[c]);
    printf(" %8s %8s %12s %12s %12s\n", "4/1", "16/1", "S 1", "S 16", "E 16/1");
    for (int m = 0; m < NM; m++) {
      double med[NC];
      printf("  %-9s", rr_method_name(methods[m]));
      for (int c = 0; c < NC; c++) printf(" %9.2f ms", med[c] = bench_median(t[m][c], reps));
      printf(" %7.2fx %7.2fx %12llu %12llu %11.2fx\n", med[1] / med[0], med[2] / med[0],
             (unsigned long long)st[m][0].setups, (unsigned long long)st[m][2].setups,
             (double)st[m][2].edge_evals / (double)st[m][0].edge_evals);
    }
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return 0;
}
