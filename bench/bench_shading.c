/* bench_shading: the paper's Fig. 7 row — shading by one shadow ray and one
 * reflection ray per shaded sample on top of primary visibility — for no AA,
 * msaa:16 and csaa:4/16, with the frame split into its passes (visibility,
 * shading, of which shadow rays and reflection rays, resolve) and each total's
 * ratio to no AA's beside the paper's (11.0× for 16× MSAA, 4.3× for CSAA 4/16).
 * Scenes: the demo under its default rig (a key light with shadows and a sky; no
 * mirror, so no reflection rays), and the Stanford bunny on a mirror plane (MTL
 * illum 3) under one point light, which the bench writes as an OBJ beside a copy
 * of the bunny. Auto-framed at --size (default 1024x1024) on --threads (default 2),
 * method auto, medians of --runs rounds (default 3) in which the modes take turns.
 *
 *   bench_shading [--size WxH] [--threads N] [--runs N] */
#include "benchutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const struct {
  const char *name;
  rr_aa_mode mode;
  int samples, stored;
  const char *paper; /* Fig. 7's ratio to no AA */
} modes[] = {{"none", RR_AA_NONE, 1, 0, "1.0x"},
             {"msaa:16", RR_AA_MSAA, 16, 0, "11.0x"},
             {"csaa:4/16", RR_AA_CSAA, 16, 4, "4.3x"}};
enum { NMODES = sizeof modes / sizeof *modes, MAX_RUNS = 64 };
enum { VIS, SHADE, SHADOW, REFLECT, RESOLVE, TOTAL, NPARTS };

/* The bunny on a mirror plane as dir/bunny-mirror.obj (its path, or NULL). */
static const char *bunny_on_mirror(char *dir) {
  static char path[600];
  const char *bunny = bench_scene_path("stanford-bunny.obj");
  FILE *in = bunny ? fopen(bunny, "r") : NULL;
  snprintf(path, sizeof path, "%s/bunny-mirror.mtl", dir);
  FILE *mtl = fopen(path, "w");
  snprintf(path, sizeof path, "%s/bunny-mirror.obj", dir);
  FILE *out = fopen(path, "w");
  if (!in || !mtl || !out) {
    if (in) fclose(in);
    if (mtl) fclose(mtl);
    if (out) fclose(out);
    return NULL;
  }
  fputs("newmtl mirror\nKd 0.3 0.3 0.3\nKs 0.6 0.6 0.6\nillum 3\nnewmtl bunny\nKd 0.8 0.6 0.45\nKs 0.2 0.2 0.2\nNs 30\n", mtl);
  /* the plane first (4 vertices), just under the bunny's feet (y = 0.0330) */
  fputs("mtllib bunny-mirror.mtl\no plane\nusemtl mirror\nv -0.4 0.033 -0.4\nv -0.4 0.033 0.4\nv 0.4 0.033 0.4\n"
        "v 0.4 0.033 -0.4\nf 1 2 3 4\no bunny\nusemtl bunny\n", out);
  char line[512];
  while (fgets(line, sizeof line, in)) {
    int a, b, c;
    if (line[0] == 'v' && line[1] == ' ') fputs(line, out);
    else if (sscanf(line, "f %d %d %d", &a, &b, &c) == 3) fprintf(out, "f %d %d %d\n", a + 4, b + 4, c + 4);
  }
  fclose(in), fclose(mtl), fclose(out);
  return path;
}

static void frame(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                  const rr_shade_options *so, double part[NPARTS], uint64_t rays[2]) {
  double t0 = bench_now_ms();
  rr_frame *f;
  rr_image img;
  rr_shade_stats st;
  if (rr_render(dev, s, cam, opt, &f) != RR_OK || rr_shade_frame(dev, s, cam, f, so, &img, &st) != RR_OK) {
    fprintf(stderr, "bench_shading: %s\n", rr_device_message(dev));
    exit(1);
  }
  part[TOTAL] = bench_now_ms() - t0;
  rr_stats vs;
  rr_frame_get_stats(f, &vs);
  part[VIS] = vs.frame_ms, part[SHADE] = st.shade_ms, part[RESOLVE] = st.resolve_ms;
  /* the rays' times are summed over the shading threads: per thread of the pass */
  part[SHADOW] = st.shadow_ms / (vs.threads > 0 ? vs.threads : 1);
  part[REFLECT] = st.reflection_ms / (vs.threads > 0 ? vs.threads : 1);
  rays[0] = st.shadow_rays, rays[1] = st.reflection_rays;
  rr_image_free(&img);
  rr_frame_release(f);
}

static void measure(rr_device *dev, const char *name, const rr_scene *s, const rr_camera *cam, int w, int h,
                    int threads, int runs) {
  static double ms[NMODES][NPARTS][MAX_RUNS];
  uint64_t rays[NMODES][2];
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.max_depth = 1; /* one reflection ray per shaded sample on a mirror */
  for (int r = 0; r < runs; r++)
    for (int m = 0; m < NMODES; m++) {
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = RR_METHOD_AUTO, opt.width = w, opt.height = h, opt.threads = threads, opt.frames_hint = 100;
      rr_render_options_set_aa(dev, &opt, modes[m].mode, modes[m].samples, modes[m].stored, RR_AA_STANDARD, 0);
      double part[NPARTS];
      frame(dev, s, cam, &opt, &so, part, rays[m]);
      for (int p = 0; p < NPARTS; p++) ms[m][p][r] = part[p];
    }
  double none = 0;
  for (int m = 0; m < NMODES; m++) {
    double med[NPARTS];
    for (int p = 0; p < NPARTS; p++) med[p] = bench_median(ms[m][p], runs);
    if (m == 0) none = med[TOTAL];
    printf("| %s | %s | %.1f | %.1f | %llu in %.1f | %llu in %.1f | %.1f | %.1f | %.2fx | %s |\n", name,
           modes[m].name, med[VIS], med[SHADE], (unsigned long long)rays[m][0], med[SHADOW],
           (unsigned long long)rays[m][1], med[REFLECT], med[RESOLVE], med[TOTAL], med[TOTAL] / none,
           modes[m].paper);
    fflush(stdout);
  }
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 2, runs = 3;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (sscanf(argv[++i], "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > RR_MAX_SIZE || h > RR_MAX_SIZE) {
        fprintf(stderr, "bench_shading: bad --size '%s' (expected WxH)\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      threads = atoi(argv[++i]);
      if (threads < 1 || threads > RR_MAX_THREADS) {
        fprintf(stderr, "bench_shading: bad --threads '%s'\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      runs = atoi(argv[++i]);
      if (runs < 1 || runs > MAX_RUNS) {
        fprintf(stderr, "bench_shading: bad --runs '%s' (1..%d)\n", argv[i], MAX_RUNS);
        return 2;
      }
    } else {
      fprintf(stderr, "usage: bench_shading [--size WxH] [--threads N] [--runs N]\n");
      return 2;
    }
  }
  char dir[] = "/tmp/bench_shading_XXXXXX";
  if (!mkdtemp(dir)) return 1;
  const char *bunny = bunny_on_mirror(dir);
  rr_device *dev = rr_device_new();
  printf("%dx%d, %d threads, method auto, lit shading (1 shadow ray per light and shaded sample, 1 reflection\n"
         "ray on mirrors), box resolve, medians of %d runs (ms; ray times per thread of the pass)\n\n",
         w, h, threads, runs);
  printf("| scene | AA | visibility | shading | shadow rays | reflection rays | resolve | total | total / none | "
         "paper (Fig. 7) |\n|---|---|---|---|---|---|---|---|---|---|\n");
  const char *scenes[2] = {"demo", bunny};
  for (int i = 0; i < 2; i++) {
    if (!scenes[i]) {
      fprintf(stderr, "bench_shading: no stanford-bunny.obj in the models directory: the mirror scene is skipped\n");
      continue;
    }
    rr_scene *s = bench_load(dev, scenes[i], NULL);
    if (i == 1) { /* one point light above and in front of the bunny */
      rr_light_info l = {.type = RR_LIGHT_POINT, .position = {0.15f, 0.45f, 0.25f}, .color = {0.35f, 0.35f, 0.35f}};
      if (rr_scene_add_light(s, &l) != RR_OK) fprintf(stderr, "bench_shading: %s\n", rr_device_message(dev));
    }
    rr_camera cam;
    bench_camera(dev, s, w, h, &cam);
    measure(dev, i ? "bunny on a mirror" : "demo", s, &cam, w, h, threads, runs);
    rr_scene_release(s);
  }
  rr_device_release(dev);
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0) fprintf(stderr, "bench_shading: could not remove %s\n", dir);
  return 0;
}
