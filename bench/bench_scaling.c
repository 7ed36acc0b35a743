/* bench_scaling: frame time against scene size. Primary visibility of the teapot
 * grids 1², 3², 7², 13² and 19² (auto-framed, as bench_table and bench_rc) with
 * every method and Embree 3's rtcIntersect1 and rtcIntersect8 on the very same
 * rays (bench_rc's: origin = eye, direction = camera_dir of each sample), at 1
 * and 2 threads. No backface culling: Embree (Debian's build) has none, so all
 * modes compute the same visibility (the 2D pipeline aside, which is not exact).
 *
 *   bench_scaling [--threads N]... [--reps N] [--size N] [--cap-ms MS] [--out PREFIX] [SCENE...]
 *
 * Per scene and thread count, after one untimed frame each, the modes take turns
 * frame by frame (--reps rounds, default 5) so that a change of load on a shared
 * machine hits them alike; the median counts. A mode whose frame is estimated to
 * take more than --cap-ms (default 5000) is skipped and its estimate reported:
 * the smaller of the last measured scene's frame scaled by the triangle ratio and
 * a frame at 1/16 of the width and height scaled by the pixel ratio, both upper
 * bounds while a frame grows no faster than its triangles or its samples (a method
 * whose data outgrow the cache grows faster, and may run somewhat over the cap).
 * A skipped mode stays skipped on larger scenes. Writes PREFIX.csv (default
 * docs/scaling-size) with one row per mode, scene and thread count, and PREFIX.md
 * with a table per thread count and the ratio of the fastest exact method to
 * Embree's best mode; bench/plot_scaling.py draws the CSV, bench/scaling_size.sh
 * does all of it. */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Rows: the methods by rr_method, then Embree's two widths. */
enum { MAX_SCENES = 16, MAX_THREADS = 4, ROW_EMBREE1 = RR_METHOD_COUNT, ROW_EMBREE8, ROWS };

typedef struct {
  bool done;  /* measured */
  double ms;  /* median frame ms */
  double est; /* ms estimated for a skipped mode (0: not skipped) */
} cell;

typedef struct {
  const char *name;
  uint64_t tris;
  cell c[MAX_THREADS][ROWS];
} scene_result;

typedef struct {
  int threads[MAX_THREADS], nthreads, reps, size;
  double cap_ms;
  const char *out;
  const char *scenes[MAX_SCENES];
  int nscenes;
} options;

static const char *row_name(int r) {
  return r < RR_METHOD_COUNT ? rr_method_name(r) : r == ROW_EMBREE1 ? "embree rtcIntersect1" : "embree rtcIntersect8";
}

/* Methods with Embree's visibility (bit-identical to ray casting): the 2D pipeline is not. */
static bool exact(int r) { return r < RR_METHOD_COUNT && r != RR_METHOD_2DR_BB && r != RR_METHOD_2DR_BIN; }

static rr_render_options frame_options(int method, int size, int threads) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = (rr_method)method, opt.width = opt.height = size, opt.threads = threads;
  return opt;
}

/* ---- measuring ----------------------------------------------------------- */

/* What one scene and thread count needs to render any mode. */
typedef struct {
  rr_device *dev;
  const rr_scene *s;
  const rr_camera *cam;
  const camera *c; /* cam resolved at the bench size, for Embree */
  int threads;
#ifdef RR_HAVE_EMBREE
  peer_embree *e;
#endif
  uint32_t *ids; /* Embree's output */
  float *t;
} stage;

/* One frame of row r at size x size: its ms. */
static double frame(const stage *st, int r, int size) {
#ifdef RR_HAVE_EMBREE
  if (r >= ROW_EMBREE1) return peer_embree_cast(st->e, st->c, r == ROW_EMBREE8 ? 8 : 1, st->threads, st->ids, st->t);
#endif
  rr_render_options opt = frame_options(r, size, st->threads);
  return bench_render(st->dev, st->s, st->cam, &opt, 1, NULL);
}

/* The estimated frame ms of method r (see the head of the file); prev is the same
 * cell of the scene measured before (NULL for the first). */
static double estimate(const stage *st, int r, const options *o, const scene_result *prev, uint64_t tris, int ti) {
  double est = INFINITY;
  if (prev) {
    const cell *p = &prev->c[ti][r];
    double grow = tris > prev->tris ? (double)tris / prev->tris : 1.0;
    if (p->est > 0) return p->est * grow; /* skipped there: no trial on a larger scene */
    if (p->done) est = p->ms * grow;
  }
  if (est <= o->cap_ms) return est;
  int small = o->size / 16 < 16 ? 16 : o->size / 16;
  double scale = (double)o->size * o->size / ((double)small * small);
  return fmin(est, frame(st, r, small) * scale);
}

/* Every mode of one thread count: the estimates, one untimed frame each, then
 * --reps rounds in which the modes take turns. */
static void run_threads(stage *st, const options *o, int ti, const scene_result *prev, scene_result *res) {
  bool run[ROWS] = {0};
  for (int r = 0; r < ROWS; r++) {
    cell *c = &res->c[ti][r];
    if (r >= ROW_EMBREE1) {
#ifdef RR_HAVE_EMBREE
      run[r] = st->e != NULL;
#endif
      continue;
    }
    double est = estimate(st, r, o, prev, res->tris, ti);
    if (est > o->cap_ms) {
      c->est = est;
      fprintf(stderr, "  %-22s skipped (est. %.1f s)\n", row_name(r), est / 1000);
    } else {
      run[r] = true;
    }
  }
  for (int r = 0; r < ROWS; r++)
    if (run[r]) frame(st, r, o->size);
  static double t[ROWS][64];
  for (int k = 0; k < o->reps; k++)
    for (int r = 0; r < ROWS; r++)
      if (run[r]) t[r][k] = frame(st, r, o->size);
  for (int r = 0; r < ROWS; r++) {
    if (!run[r]) continue;
    cell *c = &res->c[ti][r];
    c->ms = bench_median(t[r], o->reps), c->done = true;
    fprintf(stderr, "  %-22s %9.1f ms\n", row_name(r), c->ms);
  }
}

static void run_scene(rr_device *dev, const options *o, int sc, scene_result *res) {
  res->name = o->scenes[sc];
  rr_scene *s = bench_load(dev, res->name, NULL);
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  res->tris = in.triangles;
  rr_camera cam;
  bench_view(dev, res->name, s, o->size, o->size, &cam);
  camera c;
  if (rr_cam_setup(dev, &cam, o->size, o->size, &c) != RR_OK) {
    fprintf(stderr, "bench_scaling: %s\n", rr_device_message(dev));
    exit(1);
  }
  size_t n = (size_t)o->size * o->size;
  stage st = {.dev = dev, .s = s, .cam = &cam, .c = &c, .ids = malloc(n * sizeof *st.ids), .t = malloc(n * sizeof *st.t)};
  if (!st.ids || !st.t) {
    fprintf(stderr, "bench_scaling: out of memory\n");
    exit(1);
  }
  for (int ti = 0; ti < o->nthreads; ti++) {
    st.threads = o->threads[ti];
    fprintf(stderr, "%s: %llu triangles, %dx%d, %d thread%s\n", res->name, (unsigned long long)res->tris, o->size,
            o->size, st.threads, st.threads > 1 ? "s" : "");
#ifdef RR_HAVE_EMBREE
    /* HIGH quality: the BVH Embree traverses fastest, its best mode. */
    double build;
    st.e = peer_embree_new(s, st.threads, 2, &build);
#endif
    run_threads(&st, o, ti, sc > 0 ? res - 1 : NULL, res);
#ifdef RR_HAVE_EMBREE
    peer_embree_release(st.e);
#endif
  }
  free(st.ids), free(st.t);
  rr_cam_release(&c);
  rr_scene_release(s);
}

/* ---- writing ------------------------------------------------------------- */

static void fmt_count(char *buf, size_t n, uint64_t v) {
  if (v >= 1000000) snprintf(buf, n, "%.2fM", v / 1e6);
  else if (v >= 10000) snprintf(buf, n, "%.0fk", v / 1000.0);
  else snprintf(buf, n, "%llu", (unsigned long long)v);
}

/* The fastest measured row among rastray's exact methods (want_embree false) or
 * Embree's modes (true); -1 when none ran. */
static int fastest(const cell *c, bool want_embree) {
  int best = -1;
  for (int r = 0; r < ROWS; r++)
    if (c[r].done && (want_embree ? r >= ROW_EMBREE1 : exact(r)) && (best < 0 || c[r].ms < c[best].ms)) best = r;
  return best;
}

static void md_table(FILE *md, const options *o, const scene_result *res, int ti) {
  int threads = o->threads[ti], n = o->nscenes;
  fprintf(md, "\n%d thread%s, frame ms:\n\n| method |", threads, threads > 1 ? "s" : "");
  for (int sc = 0; sc < n; sc++) {
    char t[32];
    fmt_count(t, sizeof t, res[sc].tris);
    fprintf(md, " %s T=%s |", res[sc].name, t);
  }
  fprintf(md, "\n|---|");
  for (int sc = 0; sc < n; sc++) fprintf(md, "---:|");
  fprintf(md, "\n");
  for (int r = 0; r < ROWS; r++) {
    bool any = false;
    for (int sc = 0; sc < n; sc++) any |= res[sc].c[ti][r].done || res[sc].c[ti][r].est > 0;
    if (!any) continue;
    fprintf(md, "| %s%s |", row_name(r), exact(r) || r >= ROW_EMBREE1 ? "" : " (not exact)");
    for (int sc = 0; sc < n; sc++) {
      const cell *c = &res[sc].c[ti][r];
      if (c->done) fprintf(md, " %.1f |", c->ms);
      else if (c->est > 0) /* %.3g alone would write 1.07e+04 */
        fprintf(md, c->est < 1e5 ? " skipped (est. %.3g s) |" : " skipped (est. %.0f s) |", c->est / 1000);
      else fprintf(md, " – |");
    }
    fprintf(md, "\n");
  }
  fprintf(md, "| **fastest exact method / Embree's best** (target ≤ 0.5×) |");
  for (int sc = 0; sc < n; sc++) {
    const cell *c = res[sc].c[ti];
    int a = fastest(c, false), b = fastest(c, true);
    if (a < 0 || b < 0) fprintf(md, " – |");
    else
      fprintf(md, " %s / %s: **%.2f×** %s |", row_name(a), b == ROW_EMBREE8 ? "embree-8" : "embree-1",
              c[a].ms / c[b].ms, c[a].ms <= 0.5 * c[b].ms ? "✓" : "✗");
  }
  fprintf(md, "\n");
}

static void write_csv(FILE *csv, const options *o, const scene_result *res) {
  fprintf(csv, "scene,triangles,method,threads,size,frame_ms,estimate_ms\n");
  for (int ti = 0; ti < o->nthreads; ti++)
    for (int r = 0; r < ROWS; r++)
      for (int sc = 0; sc < o->nscenes; sc++) {
        const cell *c = &res[sc].c[ti][r];
        if (!c->done && !(c->est > 0)) continue;
        fprintf(csv, "%s,%llu,%s,%d,%d,", res[sc].name, (unsigned long long)res[sc].tris, row_name(r),
                o->threads[ti], o->size);
        if (c->done) fprintf(csv, "%.3f,\n", c->ms);
        else fprintf(csv, ",%.0f\n", c->est);
      }
}

static int write_tables(const options *o, const scene_result *res, double load, double minutes) {
  char path[4096];
  snprintf(path, sizeof path, "%s.md", o->out);
  FILE *md = fopen(path, "w");
  snprintf(path, sizeof path, "%s.csv", o->out);
  FILE *csv = fopen(path, "w");
  if (!md || !csv) {
    fprintf(stderr, "bench_scaling: cannot write %s.md / .csv\n", o->out);
    if (md) fclose(md);
    if (csv) fclose(csv);
    return 1;
  }
  char day[32];
  time_t now = time(NULL);
  strftime(day, sizeof day, "%Y-%m-%d", gmtime(&now));
  fprintf(md, "%dx%d, no backface culling, median of %d frame%s (modes taking turns); skipped: estimated above "
              "%.0f ms a frame. Embree at HIGH build quality. Made %s on %d cores, load average %.2f at the "
              "start, in %.1f minutes.\n",
          o->size, o->size, o->reps, o->reps > 1 ? "s" : "", o->cap_ms, day, rr_cpu_count(), load, minutes);
  for (int ti = 0; ti < o->nthreads; ti++) md_table(md, o, res, ti);
  write_csv(csv, o, res);
  fclose(md), fclose(csv);
  fprintf(stderr, "wrote %s.md and %s.csv\n", o->out, o->out);
  return 0;
}

/* ---- main ---------------------------------------------------------------- */

static bool parse_options(int argc, char **argv, options *o) {
  *o = (options){.reps = 5, .size = 1024, .cap_ms = 5000, .out = "docs/scaling-size"};
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    bool more = i + 1 < argc;
    if (strcmp(a, "--threads") == 0 && more) {
      if (o->nthreads == MAX_THREADS) return false;
      o->threads[o->nthreads++] = atoi(argv[++i]);
    } else if (strcmp(a, "--reps") == 0 && more) o->reps = atoi(argv[++i]);
    else if (strcmp(a, "--size") == 0 && more) o->size = atoi(argv[++i]);
    else if (strcmp(a, "--cap-ms") == 0 && more) o->cap_ms = atof(argv[++i]);
    else if (strcmp(a, "--out") == 0 && more) o->out = argv[++i];
    else if (a[0] == '-') return false;
    else if (o->nscenes < MAX_SCENES) o->scenes[o->nscenes++] = a;
    else return false;
  }
  if (!o->nthreads) o->threads[0] = 1, o->threads[1] = 2, o->nthreads = 2;
  for (int ti = 0; ti < o->nthreads; ti++)
    if (o->threads[ti] < 1 || o->threads[ti] > 1024) return false;
  if (o->reps < 1 || o->reps > 64 || o->size < 16 || o->size > RR_MAX_SIZE || !(o->cap_ms > 0)) return false;
  if (!o->nscenes) {
    static const char *def[] = {"grid:teapot.obj:1", "grid:teapot.obj:3", "grid:teapot.obj:7", "grid:teapot.obj:13",
                                "grid:teapot.obj:19"};
    for (int i = 0; i < 5; i++) o->scenes[o->nscenes++] = def[i];
  }
  return true;
}

int main(int argc, char **argv) {
  options o;
  if (!parse_options(argc, argv, &o)) {
    fprintf(stderr, "usage: bench_scaling [--threads N]... [--reps N] [--size N] [--cap-ms MS] [--out PREFIX] "
                    "[SCENE...]\n  (scenes in growing size; up to %d thread counts and %d scenes)\n",
            MAX_THREADS, MAX_SCENES);
    return 2;
  }
#ifndef RR_HAVE_EMBREE
  fprintf(stderr, "bench_scaling: Embree 3 not found at build time (install libembree-dev): rastray's methods only\n");
#endif
  double load = -1, t0 = bench_now_ms();
  FILE *la = fopen("/proc/loadavg", "r");
  if (la) {
    if (fscanf(la, "%lf", &load) != 1) load = -1;
    fclose(la);
  }
  static scene_result res[MAX_SCENES];
  rr_device *dev = rr_device_new();
  for (int sc = 0; sc < o.nscenes; sc++) run_scene(dev, &o, sc, &res[sc]);
  rr_device_release(dev);
  return write_tables(&o, res, load, (bench_now_ms() - t0) / 60000);
}
