/* The paper's Table 1 on this machine: primary visibility at 1024x1024 with
 * backface culling (the paper's set-up; shading is not timed) for every method,
 * plus Embree and llvmpipe when the build found them, on real meshes and on a
 * generated scene of large triangles and high depth complexity. Writes the table
 * as Markdown and CSV: frame ms (median), S, E, N per method and scene.
 *
 *   bench_table [--threads N] [--reps N] [--size N] [--out PREFIX] [SCENE...] */
#include "benchutil.h"
#include "rr.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif
#ifdef RR_HAVE_OSMESA
#include "peer_osmesa.h"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_SCENES = 16, ROW_EMBREE1 = RR_METHOD_COUNT, ROW_EMBREE8, ROW_LLVMPIPE, ROW_AUTO, ROWS };

typedef struct {
  bool done;
  double ms;
  rr_stats st;
} cell;

static const char *row_name(int r) {
  if (r < RR_METHOD_COUNT) return rr_method_name(r);
  static const char *peers[] = {"embree rtcIntersect1", "embree rtcIntersect8", "llvmpipe (OSMesa)", "auto"};
  return peers[r - RR_METHOD_COUNT];
}

/* The view of a scene: auto-framed, or from inside a corner room of `rooms`. */
static void scene_camera(rr_device *dev, const char *name, const rr_scene *s, int size, rr_camera *cam) {
  bench_camera(dev, s, size, size, cam);
  if (strncmp(name, "rooms", 5) == 0) {
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    float eye[3] = {1.2f, 1.6f, 1.4f}, target[3] = {in.bounds_max[0], 1.2f, in.bounds_max[2] * 0.7f};
    memcpy(cam->eye, eye, sizeof eye), memcpy(cam->target, target, sizeof target);
    cam->fov_deg = 70;
  }
}

static void fmt_count(char *buf, size_t n, uint64_t v) {
  if (v >= 10000) snprintf(buf, n, "%.0fk", v / 1000.0);
  else snprintf(buf, n, "%llu", (unsigned long long)v);
}

int main(int argc, char **argv) {
  int threads = 1, reps = 5, size = 1024;
  const char *out = "docs/table1";
  const char *scenes[MAX_SCENES];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = atoi(argv[++i]);
    else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
    else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) size = atoi(argv[++i]);
    else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) out = argv[++i];
    else if (argv[i][0] == '-') {
      fprintf(stderr, "usage: bench_table [--threads N] [--reps N] [--size N] [--out PREFIX] [SCENE...]\n");
      return 2;
    } else if (nscenes < MAX_SCENES) scenes[nscenes++] = argv[i];
  }
  if (threads < 1 || reps < 1 || reps > 64 || size < 16 || size > 16384) {
    fprintf(stderr, "bench_table: bad --threads, --reps or --size\n");
    return 2;
  }
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj", "grid:teapot.obj:19", "rooms:8"};
    for (int i = 0; i < 5; i++) scenes[nscenes++] = def[i];
  }
  static cell table[ROWS][MAX_SCENES];
  uint64_t tris[MAX_SCENES];
  double build_rr[MAX_SCENES] = {0}, build_embree[MAX_SCENES] = {0};
  int auto_pick[MAX_SCENES];
  rr_device *dev = rr_device_new();
  for (int sc = 0; sc < nscenes; sc++) {
    rr_scene *s = bench_load(dev, scenes[sc], NULL);
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    tris[sc] = in.triangles;
    build_rr[sc] = in.bvh_build_ms;
    rr_camera cam;
    scene_camera(dev, scenes[sc], s, size, &cam);
    fprintf(stderr, "%s: %llu triangles\n", scenes[sc], (unsigned long long)in.triangles);
    for (int m = 0; m < RR_METHOD_COUNT; m++) {
      if (m == RR_METHOD_RC) continue; /* every sample × every triangle: hours at this size */
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = (rr_method)m, opt.width = size, opt.height = size, opt.threads = threads, opt.cull_backfaces = 1;
      rr_frame *f;
      cell *c = &table[m][sc];
      c->ms = bench_render(dev, s, &cam, &opt, reps, &f);
      rr_frame_get_stats(f, &c->st);
      c->done = true;
      rr_frame_release(f);
      fprintf(stderr, "  %-10s %9.1f ms\n", rr_method_name(m), c->ms);
    }
    {
      /* auto: its trial is not timed, only the frame of the method it picked */
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = RR_METHOD_AUTO, opt.width = size, opt.height = size, opt.threads = threads, opt.cull_backfaces = 1;
      rr_frame *f;
      cell *c = &table[ROW_AUTO][sc];
      c->ms = bench_render(dev, s, &cam, &opt, reps, &f);
      rr_frame_get_stats(f, &c->st);
      c->done = true;
      auto_pick[sc] = c->st.method;
      rr_frame_release(f);
      fprintf(stderr, "  auto       %9.1f ms (%s: %s)\n", c->ms, rr_method_name(auto_pick[sc]), c->st.why);
    }
#ifdef RR_HAVE_EMBREE
    {
      double build;
      peer_embree *e = peer_embree_new(s, threads, 2, &build);
      build_embree[sc] = build;
      camera c;
      if (e && camera_setup(dev, &cam, size, size, &c) == RR_OK) {
        uint32_t *ids = malloc((size_t)size * size * sizeof *ids);
        float *t = malloc((size_t)size * size * sizeof *t);
        for (int w = 0; w < 2; w++) {
          double ms[64];
          for (int r = 0; r < reps; r++) ms[r] = peer_embree_cast(e, &c, w ? 8 : 1, threads, ids, t);
          cell *cl = &table[RR_METHOD_COUNT + w][sc];
          cl->ms = bench_median(ms, reps), cl->done = true;
          fprintf(stderr, "  embree-%d   %9.1f ms\n", w ? 8 : 1, cl->ms);
        }
        free(ids), free(t);
        camera_release(&c);
      }
      peer_embree_release(e);
    }
#endif
#ifdef RR_HAVE_OSMESA
    {
      osmesa_peer *p = osmesa_new(size, size, threads);
      if (p && osmesa_load(p, s) == 0) {
        cell *cl = &table[RR_METHOD_COUNT + 2][sc];
        cl->ms = osmesa_render(p, &cam, 1, reps), cl->done = true;
        fprintf(stderr, "  llvmpipe   %9.1f ms\n", cl->ms);
      }
      osmesa_release(p);
    }
#endif
    rr_scene_release(s);
  }

  char path[4096];
  snprintf(path, sizeof path, "%s.md", out);
  FILE *md = fopen(path, "w");
  snprintf(path, sizeof path, "%s.csv", out);
  FILE *csv = fopen(path, "w");
  if (!md || !csv) {
    fprintf(stderr, "bench_table: cannot write %s.md / .csv\n", out);
    return 1;
  }
  fprintf(md, "| %dx%d, %d thread%s, backface culling | ", size, size, threads, threads > 1 ? "s" : "");
  for (int sc = 0; sc < nscenes; sc++) {
    char t[32];
    fmt_count(t, sizeof t, tris[sc]);
    fprintf(md, "%s T=%s |", scenes[sc], t);
  }
  fprintf(md, "\n|---|");
  for (int sc = 0; sc < nscenes; sc++) fprintf(md, "---|");
  fprintf(md, "\n");
  fprintf(csv, "scene,triangles,method,threads,frame_ms,setups,edge_evals,nodes\n");
  for (int r = 0; r < ROWS; r++) {
    bool any = false;
    for (int sc = 0; sc < nscenes; sc++) any |= table[r][sc].done;
    if (!any) continue;
    fprintf(md, "| %s |", row_name(r));
    for (int sc = 0; sc < nscenes; sc++) {
      const cell *c = &table[r][sc];
      if (!c->done) {
        fprintf(md, " – |");
        continue;
      }
      fprintf(md, " %.1f ms", c->ms);
      if (r == ROW_AUTO) fprintf(md, " (%s)", rr_method_name(auto_pick[sc]));
      if (r < RR_METHOD_COUNT) {
        char S[32], E[32], N[32];
        fmt_count(S, sizeof S, c->st.setups), fmt_count(E, sizeof E, c->st.edge_evals),
            fmt_count(N, sizeof N, c->st.nodes);
        fprintf(md, "<br>S=%s E=%s", S, E);
        if (c->st.nodes) fprintf(md, " N=%s", N);
      }
      fprintf(md, " |");
      fprintf(csv, "%s,%llu,%s,%d,%.3f,%llu,%llu,%llu\n", scenes[sc], (unsigned long long)tris[sc], row_name(r),
              threads, c->ms, (unsigned long long)c->st.setups, (unsigned long long)c->st.edge_evals,
              (unsigned long long)c->st.nodes);
    }
    fprintf(md, "\n");
  }
  /* The targets of the speed issue, as ratios in this one run. */
  fprintf(md, "| BVH build, rastray / Embree (HIGH) |");
  for (int sc = 0; sc < nscenes; sc++)
    fprintf(md, build_embree[sc] > 0 ? " %.1f / %.1f ms = %.2f× |" : " %.1f ms |", build_rr[sc], build_embree[sc],
            build_embree[sc] > 0 ? build_rr[sc] / build_embree[sc] : 0);
  fprintf(md, "\n| fastest exact method / Embree's best |");
  for (int sc = 0; sc < nscenes; sc++) {
    int best = -1;
    for (int m = 0; m < RR_METHOD_COUNT; m++)
      if (table[m][sc].done && m != RR_METHOD_2DR_BB && m != RR_METHOD_2DR_BIN &&
          (best < 0 || table[m][sc].ms < table[best][sc].ms))
        best = m;
    double emb = 0;
    for (int r = ROW_EMBREE1; r <= ROW_EMBREE8; r++)
      if (table[r][sc].done && (emb == 0 || table[r][sc].ms < emb)) emb = table[r][sc].ms;
    if (best >= 0 && emb > 0) fprintf(md, " %s %.2f× |", rr_method_name(best), table[best][sc].ms / emb);
    else fprintf(md, " – |");
  }
  fprintf(md, "\n| slowest 3dr method / llvmpipe |");
  for (int sc = 0; sc < nscenes; sc++) {
    int worst = -1;
    for (int m = RR_METHOD_3DR_BB; m <= RR_METHOD_3DR_FULL; m++)
      if (table[m][sc].done && (worst < 0 || table[m][sc].ms > table[worst][sc].ms)) worst = m;
    const cell *lp = &table[ROW_LLVMPIPE][sc];
    if (worst >= 0 && lp->done) fprintf(md, " %s %.2f× |", rr_method_name(worst), table[worst][sc].ms / lp->ms);
    else fprintf(md, " – |");
  }
  fprintf(md, "\n");
  fclose(md), fclose(csv);
  fprintf(stderr, "wrote %s.md and %s.csv\n", out, out);
  rr_device_release(dev);
  return 0;
}
