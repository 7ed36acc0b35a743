/* The paper's Table 1 on this machine: primary visibility at 1024x1024 with
 * backface culling (the paper's set-up; shading is not timed) for every method,
 * plus Embree and llvmpipe when the build found them, on real meshes and on a
 * generated scene of large triangles and high depth complexity. Writes the table
 * as Markdown and CSV: frame ms (median), S, E, N per method and scene.
 *
 * Embree (Debian's build) has no backface culling, so a second pass renders the
 * 3D methods, auto and llvmpipe without culling too, and the ratios against
 * Embree come from that pass. Both BVHs are built on --threads threads. Below the
 * table: build times, memory, and the speed targets as ratios of this one run.
 * --instructions adds a table of instructions per frame (one thread, a smaller
 * size, counted by callgrind: stable where times on a shared machine are not).
 *
 *   bench_table [--threads N] [--reps N] [--size N] [--out PREFIX]
 *               [--instructions] [--instr-size N] [SCENE...] */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif
#ifdef RR_HAVE_OSMESA
#include "peer_osmesa.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Rows: the methods by rr_method, then auto and the peers. */
enum { MAX_SCENES = 16, ROW_AUTO = RR_METHOD_COUNT, ROW_EMBREE1, ROW_EMBREE8, ROW_LLVMPIPE, ROWS };
/* Passes: Table 1's (back faces culled) and Embree's visibility (no culling). */
enum { CULLED, UNCULLED, PASSES };
#define MIB (1024.0 * 1024.0)

typedef struct {
  bool done;
  double ms;
  rr_stats st;
  uint64_t instructions; /* of one frame under callgrind (CULLED pass only); 0: not counted */
} cell;

typedef struct {
  const char *name;
  uint64_t tris;
  cell c[PASSES][ROWS];
  double build_rr, build_embree[2]; /* ms; Embree's [0] at MEDIUM, [1] at HIGH quality */
  double held, bvh;                 /* bytes rastray's scene + BVH hold, and its BVH alone */
  double auto_ref[PASSES];          /* ms of the fastest exact method, timed alternating with auto */
  double frame_peak;                /* most resident above that during a frame (-1: unknown) */
  int frame_peak_row;               /* the method of that frame */
  double emb_scene, emb_bvh;        /* bytes Embree's HIGH scene holds (0: no Embree) */
} scene_result;

typedef struct {
  int threads, reps, size, instr_size;
  bool instructions;
  const char *out;
  const char *scenes[MAX_SCENES];
  int nscenes;
} options;

static const char *row_name(int r) {
  if (r < RR_METHOD_COUNT) return rr_method_name(r);
  static const char *peers[] = {"auto", "embree rtcIntersect1", "embree rtcIntersect8", "llvmpipe (OSMesa)"};
  return peers[r - RR_METHOD_COUNT];
}

/* The methods that see through 3D edge functions or rays: exact (bit-identical to
 * ray casting), candidates of "fastest exact", and run in both passes. rc is left
 * out: every sample × every triangle takes hours at this size. */
static bool exact_3d(int r) {
  return r < RR_METHOD_COUNT && r != RR_METHOD_RC && r != RR_METHOD_2DR_BB && r != RR_METHOD_2DR_BIN;
}

/* Rows rastray renders in a pass (the 2D pipeline only in Table 1's). */
static bool rastray_row(int r, int pass) {
  return r == ROW_AUTO || exact_3d(r) || (pass == CULLED && r < RR_METHOD_COUNT && r != RR_METHOD_RC);
}

static rr_render_options frame_options(int row, bool cull, int size, int threads) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = row == ROW_AUTO ? RR_METHOD_AUTO : (rr_method)row;
  opt.width = opt.height = size, opt.threads = threads, opt.cull_backfaces = cull;
  return opt;
}


/* The fastest exact method of a pass (-1 when none ran). */
static int fastest(const scene_result *res, int pass) {
  int best = -1;
  for (int r = 0; r < RR_METHOD_COUNT; r++)
    if (exact_3d(r) && res->c[pass][r].done && (best < 0 || res->c[pass][r].ms < res->c[pass][best].ms)) best = r;
  return best;
}

/* ---- measuring ----------------------------------------------------------- */

static void log_cell(const cell *c, int r, int pass) {
  fprintf(stderr, "  %-10s %9.1f ms%s", row_name(r), c->ms, pass == CULLED ? "" : " (no culling)");
  if (r == ROW_AUTO) fprintf(stderr, " (%s: %s)", rr_method_name(c->st.method), c->st.why);
  fprintf(stderr, "\n");
}

/* auto and the fastest exact method of the pass so far, timed in alternation so
 * that a change of load on this shared machine hits both alike. Only the frame of
 * the method auto picks is timed, not the cost model's look at the view (~0.1 ms). */
static void run_auto(rr_device *dev, const rr_scene *s, const rr_camera *cam, const options *o, int pass,
                     scene_result *res) {
  int best = fastest(res, pass);
  if (best < 0) return;
  rr_render_options a = frame_options(ROW_AUTO, pass == CULLED, o->size, o->threads);
  rr_render_options b = frame_options(best, pass == CULLED, o->size, o->threads);
  cell *c = &res->c[pass][ROW_AUTO];
  double ta[64], tb[64];
  for (int r = 0; r < o->reps; r++) {
    rr_frame *f;
    ta[r] = bench_render(dev, s, cam, &a, 1, &f);
    rr_frame_get_stats(f, &c->st);
    rr_frame_release(f);
    tb[r] = bench_render(dev, s, cam, &b, 1, NULL);
  }
  c->ms = bench_median(ta, o->reps), c->done = true;
  res->auto_ref[pass] = bench_median(tb, o->reps);
  log_cell(c, ROW_AUTO, pass);
}

static void run_pass(rr_device *dev, const rr_scene *s, const rr_camera *cam, const options *o, int pass,
                     scene_result *res) {
  for (int r = 0; r < RR_METHOD_COUNT; r++) {
    if (!rastray_row(r, pass)) continue;
    rr_render_options opt = frame_options(r, pass == CULLED, o->size, o->threads);
    rr_frame *f;
    cell *c = &res->c[pass][r];
    c->ms = bench_render(dev, s, cam, &opt, o->reps, &f);
    rr_frame_get_stats(f, &c->st);
    c->done = true;
    rr_frame_release(f);
    log_cell(c, r, pass);
  }
  run_auto(dev, s, cam, o, pass, res);
}

/* The resident memory a frame of the fastest method adds: its visibility buffer
 * and whatever the method allocates on the way. */
static void measure_frame_memory(rr_device *dev, const rr_scene *s, const rr_camera *cam, const options *o,
                                 scene_result *res) {
  res->frame_peak_row = fastest(res, CULLED);
  res->frame_peak = -1;
  if (res->frame_peak_row < 0) return;
  rr_render_options opt = frame_options(res->frame_peak_row, true, o->size, o->threads);
  rr_frame *f;
  if (!bench_rss_mark()) return;
  bench_render(dev, s, cam, &opt, 1, &f);
  res->frame_peak = bench_rss_peak();
  rr_frame_release(f);
}

#ifdef RR_HAVE_EMBREE
static void run_embree(rr_device *dev, const rr_scene *s, const rr_camera *cam, const options *o,
                       scene_result *res) {
  /* MEDIUM (Embree's default) only for its build time; HIGH is the BVH traversed. */
  double build;
  peer_embree *e = peer_embree_new(s, o->threads, 1, &build);
  if (e) res->build_embree[0] = build;
  peer_embree_release(e);
  e = peer_embree_new(s, o->threads, 2, &build);
  camera c;
  if (!e || rr_cam_setup(dev, cam, o->size, o->size, &c) != RR_OK) {
    peer_embree_release(e);
    return;
  }
  res->build_embree[1] = build;
  peer_embree_memory m = peer_embree_bytes(e);
  res->emb_scene = m.scene, res->emb_bvh = m.bvh;
  fprintf(stderr, "  embree HIGH: %.1f MiB (BVH %.1f), %.1f MiB at the peak of its build\n", m.scene / MIB, m.bvh / MIB,
          m.build_peak / MIB);
  size_t n = (size_t)o->size * o->size;
  uint32_t *ids = malloc(n * sizeof *ids);
  float *t = malloc(n * sizeof *t);
  for (int w = 0; w < 2 && ids && t; w++) {
    double ms[64];
    for (int r = 0; r < o->reps; r++) ms[r] = peer_embree_cast(e, &c, w ? 8 : 1, o->threads, ids, t);
    cell *cl = &res->c[UNCULLED][ROW_EMBREE1 + w];
    cl->ms = bench_median(ms, o->reps), cl->done = true;
    fprintf(stderr, "  embree-%d   %9.1f ms (no culling)\n", w ? 8 : 1, cl->ms);
  }
  free(ids), free(t);
  rr_cam_release(&c);
  peer_embree_release(e);
}
#endif

#ifdef RR_HAVE_OSMESA
static void run_llvmpipe(const rr_scene *s, const rr_camera *cam, const options *o, scene_result *res) {
  osmesa_peer *p = osmesa_new(o->size, o->size, o->threads);
  if (p && osmesa_load(p, s) == 0)
    for (int pass = 0; pass < PASSES; pass++) {
      cell *cl = &res->c[pass][ROW_LLVMPIPE];
      cl->ms = osmesa_render(p, cam, pass == CULLED, o->reps), cl->done = true;
      fprintf(stderr, "  llvmpipe   %9.1f ms%s\n", cl->ms, pass == CULLED ? "" : " (no culling)");
    }
  osmesa_release(p);
}
#endif

static void run_scene(rr_device *dev, const options *o, int sc, scene_result *res) {
  res->name = o->scenes[sc];
  double heap0 = bench_heap_bytes();
  rr_scene *s = bench_load(dev, res->name, NULL);
  res->held = bench_heap_bytes() - heap0; /* what the loader leaves: the scene and its BVH */
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  res->tris = in.triangles, res->build_rr = in.bvh_build_ms, res->bvh = (double)in.bvh_bytes;
  rr_camera cam;
  bench_view(dev, res->name, s, o->size, o->size, &cam);
  fprintf(stderr, "%s: %llu triangles, BVH built in %.1f ms on %d thread%s\n", res->name,
          (unsigned long long)in.triangles, in.bvh_build_ms, o->threads, o->threads > 1 ? "s" : "");
  for (int pass = 0; pass < PASSES; pass++) run_pass(dev, s, &cam, o, pass, res);
  measure_frame_memory(dev, s, &cam, o, res);
#ifdef RR_HAVE_EMBREE
  run_embree(dev, s, &cam, o, res);
#endif
#ifdef RR_HAVE_OSMESA
  run_llvmpipe(s, &cam, o, res);
#endif
  rr_scene_release(s);
}

/* ---- instructions -------------------------------------------------------- */

/* Under callgrind: one counted frame per method of Table 1's pass, each dumped as a
 * part named "SCENE-INDEX METHOD"; nothing else is measured or written. Not auto:
 * it renders with one of the methods counted. */
static int count_main(const options *o) {
  rr_device *dev = rr_device_new();
  for (int sc = 0; sc < o->nscenes; sc++) {
    rr_scene *s = bench_load(dev, o->scenes[sc], NULL);
    rr_camera cam;
    bench_view(dev, o->scenes[sc], s, o->size, o->size, &cam);
    fprintf(stderr, "counting instructions: %s\n", o->scenes[sc]);
    for (int r = 0; r < RR_METHOD_COUNT; r++) {
      if (!rastray_row(r, CULLED)) continue;
      rr_render_options opt = frame_options(r, true, o->size, 1);
      char name[64];
      rr_frame *f;
      snprintf(name, sizeof name, "%d %s", sc, row_name(r));
      bench_count_frame(dev, s, &cam, &opt, name, &f);
      rr_frame_release(f);
    }
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return 0;
}

static void store_part(const char *name, uint64_t instructions, void *arg) {
  scene_result *res = arg;
  int sc, len = 0;
  if (sscanf(name, "%d %n", &sc, &len) < 1 || sc < 0 || sc >= MAX_SCENES || !res[sc].name) return;
  for (int r = 0; r < RR_METHOD_COUNT; r++)
    if (strcmp(name + len, row_name(r)) == 0) res[sc].c[CULLED][r].instructions = instructions;
}

/* Runs this program again under callgrind at --instr-size on one thread and files
 * the counts into the culled pass's cells. False when that could not be done. */
static bool count_instructions(const options *o, char *argv0, scene_result *res) {
  char size[16], dir[256];
  snprintf(size, sizeof size, "%d", o->instr_size);
  char *args[MAX_SCENES + 8] = {argv0, "--instructions", "--threads", "1", "--size", size};
  for (int sc = 0; sc < o->nscenes; sc++) args[6 + sc] = (char *)o->scenes[sc];
  fprintf(stderr, "instructions: running under callgrind at %dx%d, 1 thread\n", o->instr_size, o->instr_size);
  if (bench_callgrind_run(args, dir, sizeof dir) != 0) return false;
  int n = bench_callgrind_parts(dir, store_part, res);
  fprintf(stderr, "instructions: %d parts in %s (callgrind_annotate FILE shows where they went)\n", n, dir);
  return n > 0;
}

/* ---- writing ------------------------------------------------------------- */

static void fmt_count(char *buf, size_t n, uint64_t v) {
  if (v >= 10000) snprintf(buf, n, "%.0fk", v / 1000.0);
  else snprintf(buf, n, "%llu", (unsigned long long)v);
}

static bool row_ran(const scene_result *res, int n, int pass, int r) {
  for (int sc = 0; sc < n; sc++)
    if (res[sc].c[pass][r].done) return true;
  return false;
}

static void md_header(FILE *md, const char *what, const scene_result *res, int n) {
  fprintf(md, "| %s |", what);
  for (int sc = 0; sc < n; sc++) {
    char t[32];
    fmt_count(t, sizeof t, res[sc].tris);
    fprintf(md, " %s T=%s |", res[sc].name, t);
  }
  fprintf(md, "\n|---|");
  for (int sc = 0; sc < n; sc++) fprintf(md, "---|");
  fprintf(md, "\n");
}

static void md_cell(FILE *md, const cell *c, int r) {
  if (!c->done) {
    fprintf(md, " – |");
    return;
  }
  fprintf(md, " %.1f ms", c->ms);
  if (r == ROW_AUTO) fprintf(md, " (%s)", rr_method_name(c->st.method));
  if (r < RR_METHOD_COUNT) {
    char S[32], E[32], N[32];
    fmt_count(S, sizeof S, c->st.setups), fmt_count(E, sizeof E, c->st.edge_evals), fmt_count(N, sizeof N, c->st.nodes);
    fprintf(md, "<br>S=%s E=%s", S, E);
    if (c->st.nodes) fprintf(md, " N=%s", N);
  }
  fprintf(md, " |");
}

static void md_times(FILE *md, const scene_result *res, int n) {
  for (int pass = 0; pass < PASSES; pass++)
    for (int r = 0; r < ROWS; r++) {
      if (!row_ran(res, n, pass, r)) continue;
      fprintf(md, "| %s%s |", row_name(r), pass == CULLED ? "" : ", no culling");
      for (int sc = 0; sc < n; sc++) md_cell(md, &res[sc].c[pass][r], r);
      fprintf(md, "\n");
    }
}

static void md_build(FILE *md, const options *o, const scene_result *res, int n) {
  fprintf(md, "| BVH build ms on %d thread%s: rastray, / Embree HIGH (the BVH traversed), / Embree MEDIUM |",
          o->threads, o->threads > 1 ? "s" : "");
  for (int sc = 0; sc < n; sc++) {
    const scene_result *x = &res[sc];
    fprintf(md, " %.1f", x->build_rr);
    for (int q = 1; q >= 0; q--)
      if (x->build_embree[q] > 0)
        fprintf(md, "<br>/ %.1f = %.2f×", x->build_embree[q], x->build_rr / x->build_embree[q]);
    fprintf(md, " |");
  }
  fprintf(md, "\n");
}

static void md_memory(FILE *md, const scene_result *res, int n) {
  fprintf(md, "| memory MiB: rastray scene + BVH (BVH), + peak during a frame of the fastest culled method "
              "/ Embree HIGH scene (BVH) |");
  for (int sc = 0; sc < n; sc++) {
    const scene_result *x = &res[sc];
    fprintf(md, " %.1f (%.1f)", x->held / MIB, x->bvh / MIB);
    if (x->frame_peak >= 0) fprintf(md, "<br>+ %.1f %s", x->frame_peak / MIB, row_name(x->frame_peak_row));
    if (x->emb_scene > 0)
      fprintf(md, "<br>/ %.1f (%.1f) = %.2f×", x->emb_scene / MIB, x->emb_bvh / MIB, x->held / x->emb_scene);
    fprintf(md, " |");
  }
  fprintf(md, "\n");
}

/* The fastest exact method against Embree's faster width, both without culling. */
static void md_embree_target(FILE *md, const scene_result *res, int n) {
  fprintf(md, "| fastest exact method / Embree's best, both without culling (same visibility) |");
  for (int sc = 0; sc < n; sc++) {
    const cell *c = res[sc].c[UNCULLED];
    int best = fastest(&res[sc], UNCULLED);
    int emb = c[ROW_EMBREE8].done && (!c[ROW_EMBREE1].done || c[ROW_EMBREE8].ms < c[ROW_EMBREE1].ms) ? ROW_EMBREE8
              : c[ROW_EMBREE1].done                                                                ? ROW_EMBREE1
                                                                                                   : -1;
    if (best >= 0 && emb >= 0) fprintf(md, " %s %.2f× |", row_name(best), c[best].ms / c[emb].ms);
    else fprintf(md, " – |");
  }
  fprintf(md, "\n");
}

static void md_llvmpipe_target(FILE *md, const scene_result *res, int n, int pass) {
  fprintf(md, "| slowest 3dr method / llvmpipe, both %s |", pass == CULLED ? "culled" : "without culling");
  for (int sc = 0; sc < n; sc++) {
    const cell *c = res[sc].c[pass];
    int worst = -1;
    for (int m = RR_METHOD_3DR_BB; m <= RR_METHOD_3DR_FULL; m++)
      if (c[m].done && (worst < 0 || c[m].ms > c[worst].ms)) worst = m;
    if (worst >= 0 && c[ROW_LLVMPIPE].done)
      fprintf(md, " %s %.2f× |", row_name(worst), c[worst].ms / c[ROW_LLVMPIPE].ms);
    else fprintf(md, " – |");
  }
  fprintf(md, "\n");
}

/* auto chooses by its cost model (not timed here); the frame it then renders should be
 * within 10% of the fastest exact method's, timed alternating with it. When auto
 * picked another method, that method's own row against the fastest's tells a
 * wrong pick from noise. */
static void md_auto_target(FILE *md, const scene_result *res, int n, int pass) {
  fprintf(md, "| auto / fastest exact method, %s, timed alternately (✓ within 10%%) |",
          pass == CULLED ? "culled" : "no culling");
  for (int sc = 0; sc < n; sc++) {
    const cell *c = res[sc].c[pass];
    int best = fastest(&res[sc], pass), pick = c[ROW_AUTO].st.method;
    if (best < 0 || !c[ROW_AUTO].done) {
      fprintf(md, " – |");
      continue;
    }
    double q = c[ROW_AUTO].ms / res[sc].auto_ref[pass];
    fprintf(md, " %.1f / %.1f ms = %.2f× %s<br>", c[ROW_AUTO].ms, res[sc].auto_ref[pass], q, q <= 1.10 ? "✓" : "✗");
    if (pick == best) fprintf(md, "picked %s, the fastest |", row_name(best));
    else fprintf(md, "picked %s: %.2f× %s |", row_name(pick), c[pick].ms / c[best].ms, row_name(best));
  }
  fprintf(md, "\n");
}

static void md_instructions(FILE *md, const options *o, const scene_result *res, int n) {
  char what[160];
  snprintf(what, sizeof what,
           "instructions (M) of one frame, %dx%d, 1 thread, backface culling (callgrind)", o->instr_size,
           o->instr_size);
  fprintf(md, "\n");
  md_header(md, what, res, n);
  for (int r = 0; r < RR_METHOD_COUNT; r++) {
    if (!rastray_row(r, CULLED)) continue;
    fprintf(md, "| %s |", row_name(r));
    for (int sc = 0; sc < n; sc++) {
      uint64_t v = res[sc].c[CULLED][r].instructions;
      fprintf(md, v ? " %.1f |" : " – |", v / 1e6);
    }
    fprintf(md, "\n");
  }
}

/* One line per cell; instructions (and the size they were counted at) stay empty
 * where they were not counted. */
static void write_csv(FILE *csv, const options *o, const scene_result *res, int n) {
  fprintf(csv, "scene,triangles,method,threads,size,cull,frame_ms,setups,edge_evals,nodes,instructions,"
               "instructions_size\n");
  for (int pass = 0; pass < PASSES; pass++)
    for (int r = 0; r < ROWS; r++)
      for (int sc = 0; sc < n; sc++) {
        const cell *c = &res[sc].c[pass][r];
        if (!c->done) continue;
        fprintf(csv, "%s,%llu,%s,%d,%d,%d,%.3f,%llu,%llu,%llu,", res[sc].name, (unsigned long long)res[sc].tris,
                row_name(r), o->threads, o->size, pass == CULLED, c->ms, (unsigned long long)c->st.setups,
                (unsigned long long)c->st.edge_evals, (unsigned long long)c->st.nodes);
        if (c->instructions) fprintf(csv, "%llu,%d", (unsigned long long)c->instructions, o->instr_size);
        else fprintf(csv, ",");
        fprintf(csv, "\n");
      }
}

static int write_tables(const options *o, const scene_result *res, bool counted) {
  char path[4096];
  snprintf(path, sizeof path, "%s.md", o->out);
  FILE *md = fopen(path, "w");
  snprintf(path, sizeof path, "%s.csv", o->out);
  FILE *csv = fopen(path, "w");
  if (!md || !csv) {
    fprintf(stderr, "bench_table: cannot write %s.md / .csv\n", o->out);
    return 1;
  }
  int n = o->nscenes;
  char what[128];
  snprintf(what, sizeof what, "%dx%d, %d thread%s, backface culling unless the row says otherwise", o->size,
           o->size, o->threads, o->threads > 1 ? "s" : "");
  md_header(md, what, res, n);
  md_times(md, res, n);
  /* The targets of the speed issue, as ratios in this one run. */
  md_build(md, o, res, n);
  md_memory(md, res, n);
  md_embree_target(md, res, n);
  for (int pass = 0; pass < PASSES; pass++) md_llvmpipe_target(md, res, n, pass);
  for (int pass = 0; pass < PASSES; pass++) md_auto_target(md, res, n, pass);
  if (counted) md_instructions(md, o, res, n);
  write_csv(csv, o, res, n);
  fclose(md), fclose(csv);
  fprintf(stderr, "wrote %s.md and %s.csv\n", o->out, o->out);
  return 0;
}

/* ---- main ---------------------------------------------------------------- */

static bool parse_options(int argc, char **argv, options *o) {
  *o = (options){.threads = 1, .reps = 5, .size = 1024, .instr_size = 0, .out = "docs/table1"};
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    bool more = i + 1 < argc;
    if (strcmp(a, "--threads") == 0 && more) o->threads = atoi(argv[++i]);
    else if (strcmp(a, "--reps") == 0 && more) o->reps = atoi(argv[++i]);
    else if (strcmp(a, "--size") == 0 && more) o->size = atoi(argv[++i]);
    else if (strcmp(a, "--out") == 0 && more) o->out = argv[++i];
    else if (strcmp(a, "--instr-size") == 0 && more) o->instr_size = atoi(argv[++i]);
    else if (strcmp(a, "--instructions") == 0) o->instructions = true;
    else if (a[0] == '-') return false;
    else if (o->nscenes < MAX_SCENES) o->scenes[o->nscenes++] = a;
  }
  /* Under callgrind a frame runs some 50 times slower: 512x512 by default. */
  if (!o->instr_size) o->instr_size = o->size < 512 ? o->size : 512;
  if (o->threads < 1 || o->reps < 1 || o->reps > 64 || o->size < 16 || o->size > 16384 || o->instr_size < 16 ||
      o->instr_size > 16384) {
    fprintf(stderr, "bench_table: bad --threads, --reps, --size or --instr-size\n");
    return false;
  }
  if (!o->nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19", "rooms:8"};
    for (int i = 0; i < 5; i++) o->scenes[o->nscenes++] = def[i];
  }
  return true;
}

int main(int argc, char **argv) {
  options o;
  if (!parse_options(argc, argv, &o)) {
    fprintf(stderr, "usage: bench_table [--threads N] [--reps N] [--size N] [--out PREFIX] [--instructions] "
                    "[--instr-size N] [SCENE...]\n");
    return 2;
  }
  if (o.instructions && bench_on_valgrind()) return count_main(&o);
  static scene_result res[MAX_SCENES];
  rr_device *dev = rr_device_new();
  /* rastray's BVH on the thread count Embree gets, for a like-for-like build time. */
  rr_build_options bo;
  rr_build_options_init(&bo);
  bo.threads = o.threads;
  if (rr_device_set_build_options(dev, &bo) != RR_OK) {
    fprintf(stderr, "bench_table: %s\n", rr_device_message(dev));
    return 2;
  }
  for (int sc = 0; sc < o.nscenes; sc++) run_scene(dev, &o, sc, &res[sc]);
  rr_device_release(dev);
  bool counted = o.instructions && count_instructions(&o, argv[0], res);
  if (o.instructions && !counted) fprintf(stderr, "bench_table: no instruction counts\n");
  return write_tables(&o, res, counted);
}
