/* auto's choice against the fastest exact method, view by view, and the cost model's
 * predictions against measured frame times: for bench_table's scenes and the cameras
 * of docs/cameras.md, the median frame time of every candidate auto weighs (and, in
 * brackets, what the model predicted), the method auto picks, the fastest, the ratio
 * chosen / fastest and whether it is within 1.15× (issue 13's target).
 *
 * The candidates take turns, frame by frame, so that a change of load on a shared
 * machine hits them alike; a candidate more than 3× the fastest in the first round
 * (3dr on curved cameras) is timed once, as it cannot be the fastest. --cpu times
 * one-thread frames by the process's CPU time (steadier under load); --cpu-all on
 * more threads too (the work of all threads, blind to a method's serial parts).
 * --load starts a process that spins on one core (pinned to none) for the bench's
 * duration: the target's "another process keeps one core busy". --frames N passes
 * N as frames_hint, so that auto may run its trial. The teapot grid of 310k
 * triangles is seen from inside, as in docs/cameras.md; the curved cameras are left
 * out above a million triangles (seconds a frame for the 3dr methods).
 *
 * --calibrate re-derives the model's costs (src/vis/auto_costs.h) from CPU times on
 * one thread: planar views at 256², 512² and 1024², culling off and on, curved ones
 * at 256² and 512²; a least-squares fit on relative error, costs kept ≥ 0, one for
 * the planar views and one for each curved camera type. With
 * --threads N (N > 1) it also times every view on N threads against one (wall
 * clock: run it on a quiet machine) for the gain of a further thread; --keep-gains
 * writes the gains in use instead (for a calibration on a loaded machine). It prints
 * the fit's error per method and writes the header to --out FILE (stdout by default).
 * --times FILE keeps the measured times: views found in FILE are not timed again,
 * the others are timed and added to it, so that a change of the figures (not of a
 * method's speed) is re-fitted in seconds.
 *
 *   bench_auto [--threads N[,N]] [--reps N] [--size N] [--cull] [--cpu] [--cpu-all] [--load]
 *              [--frames N] [--planar] [--calibrate [--out FILE] [--keep-gains] [--times FILE]]
 *              [SCENE...] */
#define _GNU_SOURCE /* getopt_long */
#include "benchutil.h"
#include "vis/vis.h"

#include <getopt.h>
#include <malloc.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

/* auto's candidates (vis/auto.c) and rc-bvh: "fastest" is the fastest of these. */
static const rr_method cands[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL,
                                  RR_METHOD_RC_PACKET, RR_METHOD_RC_BVH};
static const char *const cand_enums[] = {"RR_METHOD_3DR_BB", "RR_METHOD_3DR_BIN", "RR_METHOD_3DR_FC",
                                        "RR_METHOD_3DR_FULL", "RR_METHOD_RC_PACKET", "RR_METHOD_RC_BVH"};
enum { NCAND = sizeof cands / sizeof cands[0], BIN = 1 /* 3dr-bin in cands */, MAX_REPS = 64, MAX_VIEWS = 512 };

/* ---- --load: one busy process ----------------------------------------------- */

static pid_t spinner = 0;

static void stop_load(void) {
  if (spinner > 0) kill(spinner, SIGKILL), waitpid(spinner, NULL, 0);
  spinner = 0;
}

/* A child that spins until the bench ends: stop_load at exit, and the kernel's
 * parent-death signal if the bench dies without exiting (a crash, a kill). */
static void start_load(void) {
  pid_t parent = getpid();
  spinner = fork();
  if (spinner < 0) {
    perror("bench_auto: fork");
    exit(1);
  }
  if (spinner == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(0);
    for (volatile unsigned long n = 0;; n++) {}
  }
  atexit(stop_load);
}

/* ---- views ------------------------------------------------------------------- */

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

static bool is_planar(int type) { return type == RR_CAMERA_PERSPECTIVE || type == RR_CAMERA_ORTHOGRAPHIC; }

static rr_frame *render_or_exit(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *o) {
  rr_frame *f;
  if (rr_render(dev, s, cam, o, &f) != RR_OK) {
    fprintf(stderr, "bench_auto: %s\n", rr_device_message(dev));
    exit(1);
  }
  return f;
}

/* Median ms of each candidate in `reps` interleaved rounds (NAN where it cannot draw
 * the camera); a candidate more than 3× the fastest of the first round is timed
 * once. cpu: CPU time, else wall time. */
static void time_candidates(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_render_options opt, int reps,
                            bool cpu, double ms[NCAND]) {
  double t[NCAND][MAX_REPS];
  int n[NCAND] = {0};
  bool planar = is_planar(cam->type);
  double first_best = INFINITY;
  for (int r = 0; r < reps; r++)
    for (int c = 0; c < NCAND; c++) {
      if (cands[c] == RR_METHOD_3DR_BB && !planar) continue; /* projects onto a plane */
      if (r > 0 && t[c][0] > 3 * first_best) continue;
      opt.method = cands[c];
      rr_frame *f = render_or_exit(dev, s, cam, &opt);
      rr_stats st;
      rr_frame_get_stats(f, &st);
      rr_frame_release(f);
      t[c][n[c]++] = cpu ? st.cpu_ms : st.frame_ms;
      if (r == 0 && t[c][0] < first_best) first_best = t[c][0];
    }
  for (int c = 0; c < NCAND; c++) ms[c] = n[c] ? bench_median(t[c], n[c]) : NAN;
}

/* The model's prediction for candidate c, NAN when c is not one of auto's candidates here. */
static double predicted(const auto_prediction *p, int c) {
  for (int i = 0; i < AUTO_NCAND; i++)
    if (p->method[i] == cands[c]) return p->ms[i];
  return NAN;
}

static void predict_or_exit(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_render_options opt,
                            auto_prediction *p) {
  opt.method = RR_METHOD_AUTO;
  if (rr_auto_predict(dev, s, cam, &opt, p) != RR_OK) {
    fprintf(stderr, "bench_auto: %s\n", rr_device_message(dev));
    exit(1);
  }
}

/* ---- the table: auto against the fastest --------------------------------------- */

typedef struct {
  int reps, size, cull, cpu, frames, planar_only;
} bench_cfg;

/* One table for one thread count; returns the worst chosen / fastest. */
static double table(rr_device *dev, const char *const *scenes, int nscenes, int threads, const bench_cfg *cfg,
                    int *misses, int *views) {
  /* --cpu: CPU time on one thread; on more only with --cpu-all (the work of all
   * threads: steadier under load, but blind to a method's serial parts) */
  bool cpu = cfg->cpu > 1 || (cfg->cpu && threads == 1);
  printf("%dx%d (latlong 2:1, cube 4:3), %d thread(s), %s, median %s of %d%s; cells: measured (predicted)\n\n",
         cfg->size, cfg->size, threads, cfg->cull ? "backface culling" : "no culling", cpu ? "CPU ms" : "ms",
         cfg->reps, spinner > 0 ? ", one core kept busy by another process" : "");
  printf("| scene | camera |");
  for (int c = 0; c < NCAND; c++) printf(" %s ms |", rr_method_name(cands[c]));
  printf(" auto's pick | fastest | chosen / fastest |\n|---|---|");
  for (int c = 0; c < NCAND; c++) printf("---|");
  printf("---|---|---|\n");
  double worst = 0;
  for (int sc = 0; sc < nscenes; sc++) {
    rr_scene *s = bench_load(dev, scenes[sc], NULL);
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      bool planar = is_planar(type);
      if (!planar && (cfg->planar_only || in.triangles > 1000000)) continue;
      int w = cfg->size, h = type == RR_CAMERA_LATLONG ? w / 2 : type == RR_CAMERA_CUBE ? w / 4 * 3 : w;
      rr_camera cam;
      view(dev, scenes[sc], s, type, w, h, &cam);
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.width = w, opt.height = h, opt.threads = threads, opt.cull_backfaces = cfg->cull;
      auto_prediction p;
      predict_or_exit(dev, s, &cam, opt, &p);
      /* auto's pick: what a CLI call with --repeat FRAMES gets */
      opt.method = RR_METHOD_AUTO, opt.frames_hint = cfg->frames;
      rr_frame *f = render_or_exit(dev, s, &cam, &opt);
      rr_stats st;
      rr_frame_get_stats(f, &st);
      rr_frame_release(f);
      opt.frames_hint = 0;
      double ms[NCAND], best = INFINITY, chosen = NAN;
      int fastest = 0;
      time_candidates(dev, s, &cam, opt, cfg->reps, cpu, ms);
      printf("| %s | %s |", scenes[sc], rr_camera_name(type));
      for (int c = 0; c < NCAND; c++) {
        if (isnan(ms[c])) {
          printf(" – |");
          continue;
        }
        if (ms[c] < best) best = ms[c], fastest = c;
        if ((int)cands[c] == st.method) chosen = ms[c];
        double pr = predicted(&p, c);
        if (isnan(pr)) printf(" %.1f |", ms[c]);
        else printf(" %.1f (%.1f) |", ms[c], pr);
      }
      double ratio = chosen / best;
      if (!(ratio <= worst)) worst = ratio;
      bool ok = ratio <= 1.15;
      *misses += !ok, (*views)++;
      printf(" %s%s | %s | %.2f× %s |\n", rr_method_name(st.method), strncmp(st.why, "trial", 5) ? "" : " (trial)",
             rr_method_name(cands[fastest]), ratio, ok ? "✓" : "✗");
      fflush(stdout);
    }
    rr_scene_release(s);
  }
  printf("\nworst chosen / fastest on %d thread(s): %.2f×\n\n", threads, worst);
  return worst;
}

/* ---- --calibrate: the costs from measurements ----------------------------------- */

/* The cost tables: planar views share one (its kind is RR_CAMERA_PERSPECTIVE's),
 * each curved camera type has its own (how its rays map to 3dr's cells differs). */
static int kind_of(int type) { return is_planar(type) ? RR_CAMERA_PERSPECTIVE : type; }
static const char *const camera_enums[RR_CAMERA_COUNT] = {
    "RR_CAMERA_PERSPECTIVE", "RR_CAMERA_ORTHOGRAPHIC", "RR_CAMERA_PARABOLIC", "RR_CAMERA_LATLONG",
    "RR_CAMERA_FISHEYE",     "RR_CAMERA_CUBE",         "RR_CAMERA_OPENCV",    "RR_CAMERA_OPENCV_FISHEYE"};
_Static_assert(RR_CAMERA_COUNT == 8, "camera_enums names every camera type");

typedef struct {
  double fig[AUTO_NFIG];
  bool planar;
  int kind;              /* kind_of(camera type) */
  double ms[NCAND];      /* CPU ms on one thread */
  double pred[NCAND];    /* what the model in use predicted, or NAN */
  double gain[NCAND];    /* wall ms on one thread / on N threads, or NAN */
  double look_ms;        /* the model's look at the view (rr_auto_predict), the least of 5 */
} sample_view;

/* Solves the n×n system a·x = b (row-major, destroyed) by elimination with partial
 * pivoting; false when singular. */
static bool solve(double *a, double *b, double *x, int n) {
  for (int k = 0; k < n; k++) {
    int p = k;
    for (int i = k + 1; i < n; i++)
      if (fabs(a[i * n + k]) > fabs(a[p * n + k])) p = i;
    if (!(fabs(a[p * n + k]) > 1e-12)) return false;
    for (int j = 0; j < n; j++) {
      double t = a[k * n + j];
      a[k * n + j] = a[p * n + j], a[p * n + j] = t;
    }
    double t = b[k];
    b[k] = b[p], b[p] = t;
    for (int i = k + 1; i < n; i++) {
      double f = a[i * n + k] / a[k * n + k];
      for (int j = k; j < n; j++) a[i * n + j] -= f * a[k * n + j];
      b[i] -= f * b[k];
    }
  }
  for (int k = n - 1; k >= 0; k--) {
    double s = b[k];
    for (int j = k + 1; j < n; j++) s -= a[k * n + j] * x[j];
    x[k] = s / a[k * n + k];
  }
  return true;
}

/* Costs (ns per unit of each figure in `uses`) minimising the squared relative
 * error of predicted against measured ns over the views of one kind where c was
 * timed; a cost that comes out negative is dropped and the rest fitted again. */
static void fit(const sample_view *v, int nv, int kind, int c, unsigned uses, double cost[AUTO_NFIG]) {
  for (;;) {
    int col[AUTO_NFIG], n = 0;
    for (int f = 0; f < AUTO_NFIG; f++)
      if (uses >> f & 1) col[n++] = f;
    double a[AUTO_NFIG * AUTO_NFIG] = {0}, b[AUTO_NFIG] = {0}, x[AUTO_NFIG], scale[AUTO_NFIG] = {0};
    for (int i = 0; i < nv; i++) /* columns scaled to unit size: figures differ by 10⁶ */
      if (v[i].kind == kind && !isnan(v[i].ms[c]))
        for (int k = 0; k < n; k++) scale[k] = fmax(scale[k], v[i].fig[col[k]] / (v[i].ms[c] * 1e6));
    for (int i = 0; i < nv; i++) {
      if (v[i].kind != kind || isnan(v[i].ms[c])) continue;
      double row[AUTO_NFIG];
      for (int k = 0; k < n; k++) row[k] = scale[k] > 0 ? v[i].fig[col[k]] / (v[i].ms[c] * 1e6) / scale[k] : 0;
      for (int k = 0; k < n; k++) {
        b[k] += row[k];
        for (int j = 0; j < n; j++) a[k * n + j] += row[k] * row[j];
      }
    }
    for (int f = 0; f < AUTO_NFIG; f++) cost[f] = 0;
    for (int k = 0; k < n; k++) /* a figure that is 0 on every view is dropped */
      if (!(scale[k] > 0)) a[k * n + k] = 1, b[k] = 0;
    if (!n || !solve(a, b, x, n)) return;
    int worst = -1;
    for (int k = 0; k < n; k++)
      if (x[k] < 0 && (worst < 0 || x[k] < x[worst])) worst = k;
    if (worst < 0) {
      for (int k = 0; k < n; k++) cost[col[k]] = scale[k] > 0 ? x[k] / scale[k] : 0;
      return;
    }
    uses &= ~(1u << col[worst]);
  }
}

/* Median and largest |predicted / measured − 1| of c on the planar or the curved
 * views, of costs (by kind), or (costs NULL) of the model in use. */
static void fit_error(const sample_view *v, int nv, bool planar, int c, double (*costs)[NCAND][AUTO_NFIG],
                      double *med, double *max) {
  double e[MAX_VIEWS];
  int n = 0;
  for (int i = 0; i < nv; i++) {
    if (v[i].planar != planar || isnan(v[i].ms[c]) || (!costs && isnan(v[i].pred[c]))) continue;
    const double *cost = costs ? costs[v[i].kind][c] : NULL;
    double ns = cost ? 0 : v[i].pred[c] * 1e6;
    for (int f = 0; cost && f < AUTO_NFIG; f++) ns += cost[f] * v[i].fig[f];
    e[n++] = fabs(ns / (v[i].ms[c] * 1e6) - 1);
  }
  *max = 0;
  for (int i = 0; i < n; i++) *max = fmax(*max, e[i]);
  *med = n ? bench_median(e, n) : NAN;
}

static void print_costs(FILE *out, const char *indent, double cost[][AUTO_NFIG], bool planar) {
  for (int c = 0; c < NCAND; c++) {
    if (!planar && cands[c] == RR_METHOD_3DR_BB) continue; /* not a candidate */
    fprintf(out, "%s[%s] = {", indent, cand_enums[c]);
    for (int f = 0; f < AUTO_NFIG; f++) fprintf(out, "%s%.4g", f ? ", " : "", cost[c][f]);
    fprintf(out, "},\n");
  }
}

/* --times: one line a view, "scene camera width height cull", then the CPU ms and the
 * gains of cands (nan where none). */
typedef struct {
  char key[128];
  double ms[NCAND], gain[NCAND];
} timed_view;

static void view_key(char key[128], const char *scene, int type, int w, int h, int cull) {
  snprintf(key, 128, "%s %d %d %d %d", scene, type, w, h, cull);
}

static int read_times(const char *path, timed_view *t, int max) {
  FILE *f = path ? fopen(path, "r") : NULL;
  if (!f) return 0;
  int n = 0;
  char line[1024];
  while (n < max && fgets(line, sizeof line, f)) {
    char name[96];
    int type, w, h, cull, used;
    if (sscanf(line, "%95s %d %d %d %d%n", name, &type, &w, &h, &cull, &used) != 5) continue;
    const char *p = line + used;
    bool ok = true;
    for (int c = 0; c < 2 * NCAND && ok; c++) {
      double x;
      int k;
      ok = sscanf(p, "%lf%n", &x, &k) == 1;
      p += ok ? k : 0;
      (c < NCAND ? t[n].ms : t[n].gain)[c % NCAND] = x;
    }
    if (!ok) continue;
    view_key(t[n].key, name, type, w, h, cull);
    n++;
  }
  fclose(f);
  return n;
}

static int calibrate(rr_device *dev, const char *const *scenes, int nscenes, int threads, int reps,
                     const char *out_path, bool keep_gains, const char *times_path) {
  static sample_view v[MAX_VIEWS];
  static timed_view known[MAX_VIEWS];
  int nv = 0, nknown = read_times(times_path, known, MAX_VIEWS);
  FILE *times = times_path ? fopen(times_path, "a") : NULL;
  if (times_path && !times) {
    fprintf(stderr, "bench_auto: cannot write %s\n", times_path);
    return 1;
  }
  static const int sizes[] = {256, 512, 1024};
  fprintf(stderr, "bench_auto: calibrating on %d scene(s), %d thread(s)...\n", nscenes, threads);
  for (int sc = 0; sc < nscenes; sc++) {
    rr_scene *s = bench_load(dev, scenes[sc], NULL);
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    for (int type = 0; type < RR_CAMERA_COUNT; type++)
      for (int z = 0; z < 3; z++)
        for (int cull = 0; cull < 2; cull++) {
          bool planar = is_planar(type);
          /* curved views: 3dr takes seconds a frame at 1024² or above a million triangles */
          if (!planar && (in.triangles > 1000000 || z == 2 || cull)) continue;
          if (nv == MAX_VIEWS) break;
          int w = sizes[z], h = type == RR_CAMERA_LATLONG ? w / 2 : type == RR_CAMERA_CUBE ? w / 4 * 3 : w;
          rr_camera cam;
          view(dev, scenes[sc], s, type, w, h, &cam);
          rr_render_options opt;
          rr_render_options_init(&opt);
          opt.width = w, opt.height = h, opt.threads = 1, opt.cull_backfaces = cull;
          auto_prediction p;
          predict_or_exit(dev, s, &cam, opt, &p);
          sample_view *x = &v[nv++];
          x->look_ms = INFINITY;
          for (int r = 0; r < 5; r++) {
            double t0 = bench_now_ms();
            predict_or_exit(dev, s, &cam, opt, &p);
            x->look_ms = fmin(x->look_ms, bench_now_ms() - t0);
          }
          memcpy(x->fig, p.fig, sizeof x->fig);
          x->planar = planar, x->kind = kind_of(type);
          for (int c = 0; c < NCAND; c++) x->pred[c] = predicted(&p, c);
          char key[128];
          view_key(key, scenes[sc], type, w, h, cull);
          int k = 0;
          while (k < nknown && strcmp(known[k].key, key)) k++;
          if (k < nknown) {
            memcpy(x->ms, known[k].ms, sizeof x->ms), memcpy(x->gain, known[k].gain, sizeof x->gain);
          } else {
            time_candidates(dev, s, &cam, opt, reps, true, x->ms);
            for (int c = 0; c < NCAND; c++) x->gain[c] = NAN;
            if (threads > 1 && !keep_gains) {
              double one[NCAND], many[NCAND];
              time_candidates(dev, s, &cam, opt, reps, false, one);
              opt.threads = threads;
              time_candidates(dev, s, &cam, opt, reps, false, many);
              for (int c = 0; c < NCAND; c++) x->gain[c] = one[c] / many[c];
            }
            if (times) {
              fprintf(times, "%s", key);
              for (int c = 0; c < 2 * NCAND; c++) fprintf(times, " %.6g", c < NCAND ? x->ms[c] : x->gain[c - NCAND]);
              fprintf(times, "\n"), fflush(times);
            }
          }
          fprintf(stderr, "  %s %s %dx%d%s: %s; ms%s", scenes[sc], rr_camera_name(type), w, h, cull ? " culled" : "",
                  p.figures, k < nknown ? " (from --times)" : "");
          for (int c = 0; c < NCAND; c++) fprintf(stderr, " %.3g", x->ms[c]);
          fprintf(stderr, "\n");
        }
    rr_scene_release(s);
  }
  if (times) fclose(times);
  static double cost[RR_CAMERA_COUNT][NCAND][AUTO_NFIG];
  double gain[NCAND];
  printf("fit to %d views (CPU ms, one thread, median of %d): |predicted / measured − 1| of the fit and of\n"
         "the model in use\n\n", nv, reps);
  printf("| method | planar: median, max | curved: median, max | in use: planar | in use: curved | gain of a "
         "further thread |\n|---|---|---|---|---|---|\n");
  for (int k = 0; k < RR_CAMERA_COUNT; k++)
    for (int c = 0; c < NCAND; c++)
      if (kind_of(k) == k) fit(v, nv, k, c, rr_auto_uses(cands[c], (rr_camera_type)k), cost[k][c]);
  for (int c = 0; c < NCAND; c++) {
    double g[MAX_VIEWS];
    int n = 0;
    for (int i = 0; i < nv; i++)
      if (!isnan(v[i].gain[c])) g[n++] = v[i].gain[c];
    /* (t1 / tN − 1) / (N − 1): what each further thread adds */
    gain[c] = keep_gains ? rr_auto_thread_gain(cands[c]) : n ? (bench_median(g, n) - 1) / (threads - 1) : 0.75;
    double e[4][2]; /* fit planar, fit curved, in use planar, in use curved: median, max */
    for (int k = 0; k < 4; k++) fit_error(v, nv, k % 2 == 0, c, k < 2 ? cost : NULL, &e[k][0], &e[k][1]);
    printf("| %s |", rr_method_name(cands[c]));
    for (int k = 0; k < 4; k++)
      if (isnan(e[k][0])) printf(" – |"); /* not timed, or no candidate there */
      else printf(" %.0f%%, %.0f%% |", 100 * e[k][0], 100 * e[k][1]);
    printf(" %.2f%s |\n", gain[c], keep_gains ? " (kept)" : n ? "" : " (not measured: --threads 2)");
  }
  double look[MAX_VIEWS], look_max = 0;
  for (int i = 0; i < nv; i++) look[i] = v[i].look_ms, look_max = fmax(look_max, look[i]);
  printf("\nthe model's look at a view (rr_auto_predict, wall, least of 5): median %.3f ms, largest %.3f ms\n",
         nv ? bench_median(look, nv) : NAN, look_max);
  FILE *out = out_path ? fopen(out_path, "w") : stdout;
  if (!out) {
    fprintf(stderr, "bench_auto: cannot write %s\n", out_path);
    return 1;
  }
  fprintf(out, "\n/* auto's costs: written by `bench_auto --calibrate%s` (%d views, median of %d);\n"
               " * see vis/auto.c and docs/auto.md.%s Figures: ",
          keep_gains ? " --keep-gains" : threads > 1 ? " --threads 2" : "", nv, reps,
          keep_gains ? " The thread gains are those of the calibration before." : "");
  for (int f = 0; f < AUTO_NFIG; f++) fprintf(out, "%s%s", f ? ", " : "", rr_auto_fig_names[f]);
  fprintf(out, ". */\n");
  fprintf(out, "static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {\n");
  print_costs(out, "    ", cost[RR_CAMERA_PERSPECTIVE], true);
  fprintf(out, "};\nstatic const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {\n");
  for (int k = 0; k < RR_CAMERA_COUNT; k++) {
    bool fitted = false; /* a type no view was timed on stays all 0 */
    for (int c = 0; c < NCAND; c++)
      for (int f = 0; f < AUTO_NFIG; f++) fitted |= cost[k][c][f] != 0;
    if (is_planar(k) || !fitted) continue;
    fprintf(out, "    [%s] = {\n", camera_enums[k]);
    print_costs(out, "        ", cost[k], false);
    fprintf(out, "    },\n");
  }
  fprintf(out, "};\n");
  fprintf(out, "static const double thread_gain[RR_METHOD_COUNT] = {");
  for (int c = 0; c < NCAND; c++) fprintf(out, "\n    [%s] = %.3g,", cand_enums[c], gain[c]);
  fprintf(out, "\n};\n");
  if (out != stdout) fclose(out);
  return 0;
}

/* ---- main ------------------------------------------------------------------------ */

static int usage(void) {
  fprintf(stderr, "usage: bench_auto [--threads N[,N]] [--reps N] [--size N] [--cull] [--cpu] [--cpu-all] [--load]\n"
                  "                  [--frames N] [--planar] [--calibrate [--out FILE] [--keep-gains] [--times FILE]]\n"
                  "                  [SCENE...]\n");
  return 2;
}

int main(int argc, char **argv) {
  bench_cfg cfg = {.reps = 5, .size = 512, .frames = 1};
  int threads[2] = {1, 0}, nthreads = 1, load = 0, cal = 0, keep_gains = 0;
  const char *out_path = NULL, *times_path = NULL;
  static const struct option longs[] = {
      {"threads", required_argument, 0, 't'}, {"reps", required_argument, 0, 'r'},
      {"size", required_argument, 0, 's'},    {"cull", no_argument, 0, 'c'},
      {"cpu", no_argument, 0, 'C'},           {"load", no_argument, 0, 'l'},
      {"frames", required_argument, 0, 'f'},  {"planar", no_argument, 0, 'p'},
      {"calibrate", no_argument, 0, 'k'},     {"out", required_argument, 0, 'o'},
      {"cpu-all", no_argument, 0, 'A'},       {"keep-gains", no_argument, 0, 'g'},
      {"times", required_argument, 0, 'T'},
      {0, 0, 0, 0}};
  for (int o; (o = getopt_long(argc, argv, "", longs, NULL)) != -1;) {
    switch (o) {
    case 't': nthreads = sscanf(optarg, "%d,%d", &threads[0], &threads[1]); break;
    case 'r': cfg.reps = atoi(optarg); break;
    case 's': cfg.size = atoi(optarg); break;
    case 'c': cfg.cull = 1; break;
    case 'C': cfg.cpu = cfg.cpu > 1 ? 2 : 1; break;
    case 'A': cfg.cpu = 2; break;
    case 'l': load = 1; break;
    case 'f': cfg.frames = atoi(optarg); break;
    case 'p': cfg.planar_only = 1; break;
    case 'k': cal = 1; break;
    case 'o': out_path = optarg; break;
    case 'g': keep_gains = 1; break;
    case 'T': times_path = optarg; break;
    default: return usage();
    }
  }
  for (int i = 0; i < nthreads; i++)
    if (threads[i] < 1 || threads[i] > 64) return usage();
  if (nthreads < 1 || cfg.reps < 1 || cfg.reps > MAX_REPS || cfg.size < 48 || cfg.size > 8192 || cfg.frames < 0)
    return usage();
  const char *scenes[16];
  int nscenes = 0;
  for (int i = optind; i < argc && nscenes < 16; i++) scenes[nscenes++] = argv[i];
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19", "rooms:8",
                                "grid:teapot.obj:7"};
    for (int i = 0; i < 6; i++) scenes[nscenes++] = def[i];
  }
  /* The heap is kept (no trimming, no fresh mappings up to 32 MB): taking turns,
   * a method whose per-frame buffers land on pages another method's free gave
   * back to the system pays their page faults (3dr-bb's 13 MB of setups on the
   * bunny: 7 ms a frame became 53 ms), a cost of the turns, not of the method;
   * an application rendering with one method reuses its heap. */
  mallopt(M_MMAP_THRESHOLD, 32 << 20), mallopt(M_TRIM_THRESHOLD, 1 << 30);
  if (load) start_load();
  rr_device *dev = rr_device_new();
  int code = 0;
  if (cal) code = calibrate(dev, scenes, nscenes, threads[nthreads - 1], cfg.reps, out_path, keep_gains, times_path);
  else {
    int misses = 0, views = 0;
    double worst = 0;
    for (int i = 0; i < nthreads; i++) worst = fmax(worst, table(dev, scenes, nscenes, threads[i], &cfg, &misses, &views));
    printf("within 1.15× of the fastest: %d of %d views (worst %.2f×)\n", views - misses, views, worst);
  }
  rr_device_release(dev);
  return code;
}
