/* The rasterization end of the continuum against Mesa's llvmpipe: for each scene,
 * the frame time of 2dr-bb, 2dr-bin and 3dr-bb next to OpenGL through OSMesa (same
 * scene, camera, resolution and threads, in the same run), the ratio of each to
 * llvmpipe, and how often their triangle ids agree with llvmpipe's and 3dr-bb's.
 *
 * Methods are timed in interleaved rounds (median per method). --instructions:
 * instead, the instructions of one frame of each, counted by running this again
 * under callgrind (use a smaller --size).
 *
 * usage: bench_raster [--size N|WxH] [--threads N] [--reps N] [--cull] [--instructions] [SCENE...]
 * SCENE: a built-in name, a path, or a file of the shared model directory
 * (default: stanford-bunny.obj ogre.obj nefertiti.obj grid:teapot.obj:19). */
#include "benchutil.h"
#ifdef RR_HAVE_OSMESA
#include "peer_osmesa.h"
#endif

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NMETHODS 3
static const rr_method methods[NMETHODS] = {RR_METHOD_2DR_BB, RR_METHOD_2DR_BIN, RR_METHOD_3DR_BB};

typedef struct {
  const char *scene;
  uint64_t triangles;
  double ms[NMETHODS + 1];      /* the methods, then llvmpipe (< 0 when absent) */
  double same_gl[NMETHODS + 1]; /* share of samples whose id equals llvmpipe's */
  double same_3d[NMETHODS + 1]; /* ... equals 3dr-bb's */
  double hit_3d[NMETHODS + 1];  /* share of samples where hit/miss equals 3dr-bb's */
} result;

static double same_ids(const uint32_t *a, const uint32_t *b, size_t n) {
  size_t same = 0;
  for (size_t k = 0; k < n; k++) same += a[k] == b[k];
  return (double)same / n;
}

static double same_hits(const uint32_t *a, const uint32_t *b, size_t n) {
  size_t same = 0;
  for (size_t k = 0; k < n; k++) same += (a[k] == RR_MISS) == (b[k] == RR_MISS);
  return (double)same / n;
}

static void usage(void) {
  fprintf(stderr, "usage: bench_raster [--size N|WxH] [--threads N] [--reps N] [--cull] [--instructions] [SCENE...]\n");
  exit(2);
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 1, reps = 7, cull = 0;
  bool count = false; /* under callgrind for --instructions */
  const char *scenes[64];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (strcmp(a, "--size") == 0 && i + 1 < argc) {
      if (sscanf(argv[++i], "%dx%d", &w, &h) != 2) h = w = atoi(argv[i]);
    } else if (strcmp(a, "--threads") == 0 && i + 1 < argc) {
      threads = atoi(argv[++i]);
    } else if (strcmp(a, "--reps") == 0 && i + 1 < argc) {
      reps = atoi(argv[++i]);
    } else if (strcmp(a, "--cull") == 0) {
      cull = 1;
    } else if (strcmp(a, "--instructions") == 0) {
      count = true;
    } else if (a[0] == '-' || nscenes == 64) {
      usage();
    } else {
      scenes[nscenes++] = a;
    }
  }
  if (w < 1 || h < 1 || threads < 1 || threads > 256 || reps < 1) usage();
  if (count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (reps < 5) reps = 5; /* a median of at least five */
  if (count) reps = 1;    /* round 0 warms up, round 1 is counted */
  if (reps > 64) reps = 64;
  if (nscenes == 0) {
    static const char *defaults[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19"};
    for (int i = 0; i < 4; i++) scenes[nscenes++] = defaults[i];
  }
  rr_device *dev = rr_device_new();
  printf("bench_raster: %dx%d, %d thread%s, median of %d frames, back faces %s\n", w, h, threads,
         threads == 1 ? "" : "s", reps, cull ? "culled" : "drawn");
#ifdef RR_HAVE_OSMESA
  osmesa_peer *gl = osmesa_new(w, h, threads);
  if (gl) printf("llvmpipe: OSMesa, GL_RENDERER \"%s\", LP_NUM_THREADS=%d\n", osmesa_renderer(gl), threads);
#else
  printf("llvmpipe: not measured (OSMesa not found at build time; install libosmesa6-dev)\n");
#endif
  result res[64];
  size_t npix = (size_t)w * h;
  for (int si = 0; si < nscenes; si++) {
    result *r = &res[si];
    memset(r, 0, sizeof *r);
    r->scene = scenes[si];
    double load_ms;
    rr_scene *s = bench_load(dev, scenes[si], &load_ms);
    rr_scene_info info;
    rr_scene_get_info(s, &info);
    r->triangles = info.triangles;
    rr_camera cam;
    bench_camera(dev, s, w, h, &cam);
    printf("\n%s: %llu triangles (loaded in %.0f ms)\n", scenes[si], (unsigned long long)info.triangles, load_ms);
    printf("  %-9s %10s %10s %14s %14s\n", "method", "median ms", "min ms", "S", "E");
    rr_frame *frames[NMETHODS] = {0};
    rr_render_options opt[NMETHODS];
    for (int m = 0; m < NMETHODS; m++) {
      rr_render_options_init(&opt[m]);
      opt[m].method = methods[m], opt[m].width = w, opt[m].height = h;
      opt[m].threads = threads, opt[m].cull_backfaces = cull;
    }
    bool have_gl = false;
#ifdef RR_HAVE_OSMESA
    have_gl = gl && osmesa_load(gl, s) == 0;
#endif
    /* Rounds over all methods, so that a change of load on the machine hits them
     * alike; round 0 warms the caches (and llvmpipe's shader compiler) and is not
     * counted. */
    double t[NMETHODS + 1][64];
    for (int rep = 0; rep <= reps; rep++) {
      for (int m = 0; m < NMETHODS; m++) {
        rr_frame_release(frames[m]);
        char part[160];
        snprintf(part, sizeof part, "%s %s", scenes[si], rr_method_name(methods[m]));
        if (count && rep) bench_count_start();
        rr_error e = rr_render(dev, s, &cam, &opt[m], &frames[m]);
        if (count && rep) bench_count_stop(part);
        if (e != RR_OK) {
          fprintf(stderr, "bench_raster: %s\n", rr_device_message(dev));
          return 1;
        }
        rr_stats st;
        rr_frame_get_stats(frames[m], &st);
        if (rep) t[m][rep - 1] = st.frame_ms;
      }
#ifdef RR_HAVE_OSMESA
      if (have_gl) {
        char part[160];
        snprintf(part, sizeof part, "%s llvmpipe", scenes[si]);
        if (count && rep) bench_count_start();
        double ms = osmesa_render(gl, &cam, cull, 1);
        if (count && rep) bench_count_stop(part);
        if (rep) t[NMETHODS][rep - 1] = ms;
      }
#endif
    }
    /* bench_median sorts, so t[m][0] is the fastest frame afterwards: a loaded
     * machine shows in the gap between median and minimum. */
    for (int m = 0; m < NMETHODS; m++) {
      r->ms[m] = bench_median(t[m], reps);
      rr_stats st;
      rr_frame_get_stats(frames[m], &st);
      printf("  %-9s %10.2f %10.2f %14llu %14llu\n", rr_method_name(methods[m]), r->ms[m], t[m][0],
             (unsigned long long)st.setups, (unsigned long long)st.edge_evals);
    }
    const uint32_t *ref = rr_frame_ids(frames[NMETHODS - 1]), *glids = NULL;
    r->ms[NMETHODS] = -1;
#ifdef RR_HAVE_OSMESA
    if (have_gl) {
      r->ms[NMETHODS] = bench_median(t[NMETHODS], reps);
      glids = osmesa_ids(gl);
      printf("  %-9s %10.2f %10.2f\n", "llvmpipe", r->ms[NMETHODS], t[NMETHODS][0]);
    }
#endif
    for (int m = 0; m <= NMETHODS; m++) {
      const uint32_t *ids = m < NMETHODS ? rr_frame_ids(frames[m]) : glids;
      if (!ids) continue;
      r->same_gl[m] = glids ? same_ids(ids, glids, npix) : -1;
      r->same_3d[m] = same_ids(ids, ref, npix);
      r->hit_3d[m] = same_hits(ids, ref, npix);
    }
    for (int m = 0; m < NMETHODS; m++) rr_frame_release(frames[m]);
    rr_scene_release(s);
  }
  static const char *names[NMETHODS + 1] = {"2dr-bb", "2dr-bin", "3dr-bb", "llvmpipe"};
  printf("\nframe ms (ratio to llvmpipe), %dx%d, %d thread%s\n", w, h, threads, threads == 1 ? "" : "s");
  printf("%-22s %10s", "scene", "triangles");
  for (int m = 0; m <= NMETHODS; m++) printf(" %17s", names[m]);
  printf("\n");
  for (int si = 0; si < nscenes; si++) {
    result *r = &res[si];
    printf("%-22s %10llu", r->scene, (unsigned long long)r->triangles);
    for (int m = 0; m <= NMETHODS; m++) {
      if (r->ms[m] < 0) printf(" %17s", "-");
      else if (r->ms[NMETHODS] > 0) printf(" %8.2f (%5.2fx)", r->ms[m], r->ms[m] / r->ms[NMETHODS]);
      else printf(" %8.2f %8s", r->ms[m], "");
    }
    printf("\n");
  }
  printf("\nid agreement: same id as llvmpipe | same id as 3dr-bb | same hit/miss as 3dr-bb\n");
  printf("%-22s", "scene");
  for (int m = 0; m <= NMETHODS; m++) printf(" %28s", names[m]);
  printf("\n");
  for (int si = 0; si < nscenes; si++) {
    result *r = &res[si];
    printf("%-22s", r->scene);
    for (int m = 0; m <= NMETHODS; m++) {
      if (r->ms[m] < 0) {
        printf(" %28s", "-");
        continue;
      }
      char gl_s[16] = "-";
      if (r->same_gl[m] >= 0) snprintf(gl_s, sizeof gl_s, "%.3f%%", 100 * r->same_gl[m]);
      printf(" %8s | %7.3f%% | %7.3f%%", gl_s, 100 * r->same_3d[m], 100 * r->hit_3d[m]);
    }
    printf("\n");
  }
#ifdef RR_HAVE_OSMESA
  osmesa_release(gl);
#endif
  rr_device_release(dev);
  return 0;
}
