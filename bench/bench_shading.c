/* bench_shading: the paper's Fig. 7 row — shading by one shadow ray and one
 * reflection ray per shaded sample on top of primary visibility — for no AA,
 * msaa:16 and csaa:4/16, with the frame split into its passes (visibility,
 * shading, of which shadow rays and reflection rays, resolve) and each total's
 * ratio to no AA's beside the paper's (11.0× for 16× MSAA, 4.3× for CSAA 4/16).
 * The lit mode shades in passes (light.h): the frame's points, then per light one
 * occlusion pass over all its shadow rays, then the reflection bounce; the table
 * gives each pass's wall time. First, each scene's shadow rays of the frame
 * (towards a point light, and along a directional one) rasterized from the light,
 * traced by the streams and by Embree's rtcOccluded8, and its reflection rays by
 * the streams and rtcIntersect8; with a sweep of run lengths N (the crossover that
 * --shadows auto uses). Under callgrind (one thread, one run) every part is
 * counted in instructions, named by CALLGRIND_DUMP_STATS_AT.
 * Scenes, each under one point light and a sky: the built-in demo (no mirror, so
 * no reflection rays), and the Stanford bunny on a mirror plane (MTL illum 3),
 * which the bench writes as an OBJ beside a copy of the bunny. Auto-framed at --size (default 1024x1024) on --threads (default 2),
 * method auto, medians of --runs rounds (default 3) in which the modes take turns.
 *
 *   bench_shading [--size WxH] [--threads N] [--runs N] [--shadows rays|raster|auto] [--wave POINTS]
 *                 [--rays-only] */
#include "benchutil.h"
#include "camera/camera.h"
#include "vis/shadow_raster.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define COUNT_BEGIN() do { CALLGRIND_ZERO_STATS; CALLGRIND_START_INSTRUMENTATION; } while (0)
#define COUNT_END(name) do { CALLGRIND_STOP_INSTRUMENTATION; CALLGRIND_DUMP_STATS_AT(name); } while (0)
#else
#define COUNT_BEGIN() ((void)0)
#define COUNT_END(name) ((void)(name))
#endif

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
enum { VIS, POINTS, DIRECT, SHADOW, REFLECT, RESOLVE, TOTAL, NPARTS };

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

/* ---- the frame's rays, three ways ---------------------------------------- */

/* The shadow rays of light `light` for the centre samples of frame f (3dr-bb, one
 * sample), as the lit mode makes them: from the light to the hit point offset
 * along its geometric normal (towards the light) by 1e-5·(|p|∞ + the scene's
 * diagonal), for points whose geometric normal faces the light; and, for hits on
 * geometry `mirror` (-1: none), the mirrored view ray from the point offset the
 * same way; and the shadow rays of a directional light from the scene's centre
 * towards `light` (parallel rays from the points). Counts in *ns, *nr, *np. */
static void frame_rays(const rr_scene *s, const camera *c, const rr_frame *f, vec3 light, int mirror, rr_ray *shadow,
                       size_t *ns, rr_ray *refl, size_t *nr, rr_ray *par, size_t *np) {
  vec3 towards = v3_norm(v3_sub(light, v3_scale(v3_add(s->bmin, s->bmax), 0.5f))); /* the directional light */
  vec3 ext = v3_sub(s->bmax, s->bmin);
  float diag = 1e-5f * v3_len(ext);
  *ns = *nr = *np = 0;
  for (int y = 0; y < f->vb.height; y++)
    for (int x = 0; x < f->vb.width; x++) {
      size_t k = (size_t)y * f->vb.width + x;
      uint32_t id = f->vb.id[k];
      vec3 o, d;
      if (id >= s->ntris || !rr_cam_ray(c, x, y, &o, &d)) continue;
      vec3 p = v3_add(o, v3_scale(d, f->vb.t[k])), p0 = scene_vertex(s, 0, id);
      vec3 ng = v3_norm(v3_cross(v3_sub(scene_vertex(s, 1, id), p0), v3_sub(scene_vertex(s, 2, id), p0)));
      if (v3_dot(ng, d) > 0) ng = v3_neg(ng);
      float eps = 1e-5f * fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z))) + diag;
      vec3 off = v3_add(p, v3_scale(ng, eps));
      if (v3_dot(ng, v3_sub(light, p)) > 0) {
        vec3 sd = v3_sub(off, light);
        shadow[(*ns)++] = (rr_ray){{light.x, light.y, light.z}, {sd.x, sd.y, sd.z}, 0, 1};
      }
      if (v3_dot(ng, towards) > 0) par[(*np)++] = (rr_ray){{off.x, off.y, off.z}, {towards.x, towards.y, towards.z}, 0, INFINITY};
      if (mirror >= 0 && rr_scene_geometry_of(s, id) == (uint32_t)mirror) {
        vec3 v = v3_norm(d), r = v3_sub(v, v3_scale(ng, 2 * v3_dot(ng, v)));
        refl[(*nr)++] = (rr_ray){{off.x, off.y, off.z}, {r.x, r.y, r.z}, 0, INFINITY};
      }
    }
}

/* Where raster starts to pay: the same rays in pixel-order runs of N rays (as a
 * pass of the lit mode holds), one thread; under callgrind the instructions of each
 * run length (parts raster-KIND-N, stream-KIND-N). occ_r, occ_s: room for n. */
static void sweep(rr_device *dev, const rr_scene *s, const rr_bvh *bvh, const char *kind, const rr_ray *rays, size_t n,
                  int *occ_r, int *occ_s, bool counting) {
  printf("<!-- %s light, one thread, %zu rays in runs of N: raster / streams ms:", kind, n);
  for (size_t run = 1024; run <= n * 4 && run <= ((size_t)1 << 22); run *= 4) {
    size_t len = run < n ? run : n;
    char part[64];
    double t0 = bench_now_ms();
    snprintf(part, sizeof part, "raster-%s-%zu", kind, len);
    if (counting) COUNT_BEGIN();
    for (size_t k = 0; k < n; k += len) rr_occluded_raster(s, bvh, rays + k, n - k < len ? n - k : len, 1, occ_r + k, NULL);
    if (counting) COUNT_END(part);
    double t1 = bench_now_ms();
    snprintf(part, sizeof part, "stream-%s-%zu", kind, len);
    if (counting) COUNT_BEGIN();
    for (size_t k = 0; k < n; k += len) {
      rr_ray_stream st = rr_ray_stream_aos(rays + k, n - k < len ? n - k : len);
      rr_occluded_stream(dev, s, &st, 1, occ_s + k);
    }
    if (counting) COUNT_END(part);
    printf(" N=%zu %.1f/%.1f", len, t1 - t0, bench_now_ms() - t1);
    if (len == n) break;
  }
  size_t differ = 0;
  for (size_t k = 0; k < n; k++) differ += (occ_r[k] != 0) != (occ_s[k] != 0);
  printf(" (raster != streams: %zu) -->\n", differ);
}

/* Shadow rays by rasterization from the light, by the ray streams and by Embree's
 * rtcOccluded8; reflection rays by the streams and by rtcIntersect8: medians of
 * `runs`, and under callgrind the instructions of each on one thread. */
static void compare_rays(rr_device *dev, const char *name, const rr_scene *s, const rr_camera *cam, int w, int h,
                         int threads, int runs, vec3 light, int mirror) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_3DR_BB, opt.width = w, opt.height = h, opt.threads = threads;
  rr_frame *f;
  camera c;
  if (rr_render(dev, s, cam, &opt, &f) != RR_OK || rr_cam_setup(dev, cam, w, h, &c) != RR_OK) {
    fprintf(stderr, "bench_shading: %s\n", rr_device_message(dev));
    exit(1);
  }
  size_t npix = (size_t)w * h, ns, nr, np;
  rr_ray *shadow = malloc(npix * sizeof *shadow), *refl = malloc(npix * sizeof *refl), *par = malloc(npix * sizeof *par);
  int *occ_r = malloc(npix * sizeof(int)), *occ_s = malloc(npix * sizeof(int));
  rr_hit *hits = malloc(npix * sizeof *hits);
  uint32_t *ids = malloc(npix * sizeof *ids);
  float *ts = malloc(npix * sizeof *ts);
  if (!shadow || !refl || !par || !occ_r || !occ_s || !hits || !ids || !ts) exit(1);
  frame_rays(s, &c, f, light, mirror, shadow, &ns, refl, &nr, par, &np);
  bool empty;
  const rr_bvh *bvh = rr_bvh_of(dev, s, &empty);
  rr_ray_stream ss = rr_ray_stream_aos(shadow, ns), rs = rr_ray_stream_aos(refl, nr);
  enum { RASTER, STREAM, EMB_SHADOW, RSTREAM, EMB_REFL, NWAYS };
  static double ms[NWAYS][MAX_RUNS];
  double med[NWAYS];
  for (int k = 0; k < NWAYS; k++) med[k] = -1;
  rr_shadow_counts cnt;
#ifdef RR_HAVE_EMBREE
  double build;
  peer_embree *e = peer_embree_new(s, threads, 1, &build);
#endif
  bool counting = bench_on_valgrind();
  for (int r = 0; r < (counting ? 1 : runs); r++) {
    int th = counting ? 1 : threads;
    double t0 = bench_now_ms();
    if (counting) COUNT_BEGIN();
    rr_occluded_raster(s, bvh, shadow, ns, th, occ_r, &cnt);
    if (counting) COUNT_END("shadows-raster");
    ms[RASTER][r] = bench_now_ms() - t0;
    t0 = bench_now_ms();
    if (counting) COUNT_BEGIN();
    rr_occluded_stream(dev, s, &ss, th, occ_s);
    if (counting) COUNT_END("shadows-stream");
    ms[STREAM][r] = bench_now_ms() - t0;
    if (nr) {
      t0 = bench_now_ms();
      if (counting) COUNT_BEGIN();
      rr_intersect_stream(dev, s, &rs, th, hits);
      if (counting) COUNT_END("reflections-stream");
      ms[RSTREAM][r] = bench_now_ms() - t0;
    }
#ifdef RR_HAVE_EMBREE
    if (e) {
      if (counting) COUNT_BEGIN();
      ms[EMB_SHADOW][r] = peer_embree_rays(e, shadow, ns, true, 8, th, ids, NULL);
      if (counting) COUNT_END("shadows-embree8");
      if (nr) {
        if (counting) COUNT_BEGIN();
        ms[EMB_REFL][r] = peer_embree_rays(e, refl, nr, false, 8, th, ids, ts);
        if (counting) COUNT_END("reflections-embree8");
      }
    }
#endif
  }
  int n = counting ? 1 : runs;
  med[RASTER] = bench_median(ms[RASTER], n), med[STREAM] = bench_median(ms[STREAM], n);
  if (nr) med[RSTREAM] = bench_median(ms[RSTREAM], n);
#ifdef RR_HAVE_EMBREE
  if (e) {
    med[EMB_SHADOW] = bench_median(ms[EMB_SHADOW], n);
    if (nr) med[EMB_REFL] = bench_median(ms[EMB_REFL], n);
    peer_embree_release(e);
  }
#endif
  size_t differ = 0, occluded = 0;
  for (size_t k = 0; k < ns; k++) differ += (occ_r[k] != 0) != (occ_s[k] != 0), occluded += occ_s[k] != 0;
  printf("| %s | %zu (%.0f%% occluded) | %.1f | %.1f | %.2fx | ", name, ns, 100.0 * occluded / (ns ? ns : 1), med[RASTER],
         med[STREAM], med[STREAM] / med[RASTER]);
  if (med[EMB_SHADOW] >= 0) printf("%.1f | %.2fx | ", med[EMB_SHADOW], med[EMB_SHADOW] / med[RASTER]);
  else printf("- | - | ");
  printf("%zu | ", differ);
  if (nr) {
    printf("%zu | %.1f | ", nr, med[RSTREAM]);
    if (med[EMB_REFL] >= 0) printf("%.1f | %.2fx |\n", med[EMB_REFL], med[RSTREAM] / med[EMB_REFL]);
    else printf("- | - |\n");
  } else {
    printf("0 | - | - | - |\n");
  }
  sweep(dev, s, bvh, "point", shadow, ns, occ_r, occ_s, counting);
  sweep(dev, s, bvh, "directional", par, np, occ_r, occ_s, counting);
  printf("<!-- raster: %llu bins, %llu BVH slots, %llu triangle setups, %llu edge tests -->\n",
         (unsigned long long)cnt.bins, (unsigned long long)cnt.nodes, (unsigned long long)cnt.setups,
         (unsigned long long)cnt.edge_evals);
  fflush(stdout);
  free(shadow), free(refl), free(par), free(occ_r), free(occ_s), free(hits), free(ids), free(ts);
  rr_cam_release(&c);
  rr_frame_release(f);
}

/* One frame: its passes' times (ms) and rays; under callgrind the instructions of
 * its visibility and of its shading (parts vis-NAME, shade-NAME). */
static void frame(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                  const rr_shade_options *so, const char *name, double part[NPARTS], uint64_t rays[3]) {
  bool counting = bench_on_valgrind();
  char label[128];
  double t0 = bench_now_ms();
  rr_frame *f;
  rr_image img;
  rr_shade_stats st;
  snprintf(label, sizeof label, "vis-%s", name);
  if (counting) COUNT_BEGIN();
  rr_error e = rr_render(dev, s, cam, opt, &f);
  if (counting) COUNT_END(label);
  snprintf(label, sizeof label, "shade-%s", name);
  if (counting) COUNT_BEGIN();
  if (!e) e = rr_shade_frame(dev, s, cam, f, so, &img, &st);
  if (counting) COUNT_END(label);
  if (e != RR_OK) {
    fprintf(stderr, "bench_shading: %s\n", rr_device_message(dev));
    exit(1);
  }
  part[TOTAL] = bench_now_ms() - t0;
  rr_stats vs;
  rr_frame_get_stats(f, &vs);
  /* the passes: visibility; shading = making the points + the light passes (of
   * which the occlusion tests) + the bounces; resolve */
  part[VIS] = vs.frame_ms, part[RESOLVE] = st.resolve_ms;
  part[DIRECT] = st.direct_ms, part[SHADOW] = st.shadow_ms, part[REFLECT] = st.reflection_ms;
  part[POINTS] = st.shade_ms - st.direct_ms - st.reflection_ms;
  rays[0] = st.shadow_rays, rays[1] = st.shadow_rays_raster, rays[2] = st.reflection_rays;
  rr_image_free(&img);
  rr_frame_release(f);
}

static void measure(rr_device *dev, const char *name, const rr_scene *s, const rr_camera *cam, int w, int h,
                    int threads, int runs, rr_shadow_mode shadows, int wave) {
  static double ms[NMODES][NPARTS][MAX_RUNS];
  uint64_t rays[NMODES][3];
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.max_depth = 1; /* one reflection ray per shaded sample on a mirror */
  so.shadows = shadows, so.wave_points = wave;
  bool counting = bench_on_valgrind();
  if (counting) runs = 1, threads = 1;
  for (int r = 0; r < runs; r++)
    for (int m = 0; m < NMODES; m++) {
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.method = RR_METHOD_AUTO, opt.width = w, opt.height = h, opt.threads = threads, opt.frames_hint = 100;
      rr_render_options_set_aa(dev, &opt, modes[m].mode, modes[m].samples, modes[m].stored, RR_AA_STANDARD, 0);
      double part[NPARTS];
      char label[64];
      snprintf(label, sizeof label, "%s-%s-%s", name[0] == 'd' ? "demo" : "bunny", modes[m].name,
               shadows == RR_SHADOWS_RASTER ? "raster" : shadows == RR_SHADOWS_AUTO ? "auto" : "rays");
      frame(dev, s, cam, &opt, &so, label, part, rays[m]);
      for (int p = 0; p < NPARTS; p++) ms[m][p][r] = part[p];
    }
  double none = 0;
  for (int m = 0; m < NMODES; m++) {
    double med[NPARTS];
    for (int p = 0; p < NPARTS; p++) med[p] = bench_median(ms[m][p], runs);
    /* the passes (visibility + shading + resolve): the total also holds auto's trial and the buffers' allocation */
    double passes = med[VIS] + med[POINTS] + med[DIRECT] + med[REFLECT] + med[RESOLVE];
    if (m == 0) none = passes;
    printf("| %s | %s | %.1f | %.1f | %.1f | %llu (%llu raster) in %.1f | %llu in %.1f | %.1f | %.1f | %.1f | %.2fx | %s |\n",
           name, modes[m].name, med[VIS], med[POINTS], med[DIRECT], (unsigned long long)rays[m][0],
           (unsigned long long)rays[m][1], med[SHADOW], (unsigned long long)rays[m][2], med[REFLECT], med[RESOLVE],
           passes, med[TOTAL], passes / none, modes[m].paper);
    fflush(stdout);
  }
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 2, runs = 3, shadows = RR_SHADOWS_RAYS, wave = 0;
  bool rays_only = false;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (!bench_arg_size("bench_shading", argv[++i], 1, &w, &h)) return 2;
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_shading", "--threads", argv[++i], 1, RR_MAX_THREADS, &threads)) return 2;
    } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_shading", "--runs", argv[++i], 1, MAX_RUNS, &runs)) return 2;
    } else if (strcmp(argv[i], "--shadows") == 0 && i + 1 < argc) {
      shadows = rr_shadows_from_name(argv[++i]);
      if (shadows < 0) {
        fprintf(stderr, "bench_shading: bad --shadows '%s'\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--wave") == 0 && i + 1 < argc) {
      wave = atoi(argv[++i]);
      if (wave < 0) {
        fprintf(stderr, "bench_shading: bad --wave '%s'\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--rays-only") == 0) {
      rays_only = true;
    } else {
      fprintf(stderr, "usage: bench_shading [--size WxH] [--threads N] [--runs N] [--shadows MODE] [--wave POINTS] [--rays-only]\n");
      return 2;
    }
  }
  char dir[] = "/tmp/bench_shading_XXXXXX";
  if (!mkdtemp(dir)) return 1;
  const char *bunny = bunny_on_mirror(dir);
  rr_device *dev = rr_device_new();
  const char *scenes[2] = {"demo", bunny};
  rr_scene *sc[2] = {NULL, NULL};
  rr_camera cams[2];
  vec3 lights[2];
  for (int i = 0; i < 2; i++) {
    if (!scenes[i]) {
      fprintf(stderr, "bench_shading: no stanford-bunny.obj in the models directory: the mirror scene is skipped\n");
      continue;
    }
    rr_scene *s = sc[i] = bench_load(dev, scenes[i], NULL);
    /* one point light: above and in front of the bunny; above the demo's table, to the left; and a sky */
    vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f), e = v3_sub(s->bmax, s->bmin);
    lights[i] = i ? v3(0.15f, 0.45f, 0.25f) : v3_add(c, v3(-0.3f * e.x, 1.5f * e.y, 0.4f * e.z));
    float bright = i ? 0.35f : 4.0f * v3_dot(e, e);
    rr_light_info l = {.type = RR_LIGHT_POINT, .color = {bright, bright, bright}};
    v3_store(l.position, lights[i]);
    rr_light_info sky = {.type = RR_LIGHT_AMBIENT, .color = {0.2f, 0.22f, 0.26f}, .ground = {0.06f, 0.06f, 0.05f}};
    if (rr_scene_add_light(s, &l) != RR_OK || rr_scene_add_light(s, &sky) != RR_OK)
      fprintf(stderr, "bench_shading: %s\n", rr_device_message(dev));
    bench_camera(dev, s, w, h, &cams[i]);
  }
  printf("%dx%d, %d threads: the shadow rays of the frame's visible points towards its one point light, and the\n"
         "reflection rays of its mirror's points, each set traced three ways; medians of %d runs (ms)\n\n",
         w, h, threads, runs);
  printf("| scene | shadow rays | raster | streams | streams / raster | Embree rtcOccluded8 | Embree / raster | "
         "raster != streams | reflection rays | streams | Embree rtcIntersect8 | streams / Embree |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < 2; i++)
    if (sc[i]) compare_rays(dev, i ? "bunny on a mirror" : "demo", sc[i], &cams[i], w, h, threads, runs, lights[i], i ? 0 : -1);
  if (!rays_only) {
    printf("\n%dx%d, %d threads, method auto, lit shading (1 shadow ray per light and shaded sample, --shadows %s;\n"
           "1 reflection ray on mirrors), box resolve, medians of %d runs (ms, wall time of each pass)\n\n",
           w, h, threads, shadows == RR_SHADOWS_RASTER ? "raster" : shadows == RR_SHADOWS_AUTO ? "auto" : "rays", runs);
    printf("| scene | AA | visibility | points | light passes | of which occlusion tests | reflection pass | resolve | "
           "passes | total | passes / none | paper (Fig. 7) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < 2; i++)
      if (sc[i]) measure(dev, i ? "bunny on a mirror" : "demo", sc[i], &cams[i], w, h, threads, runs, (rr_shadow_mode)shadows, wave);
  }
  for (int i = 0; i < 2; i++) rr_scene_release(sc[i]);
  rr_device_release(dev);
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0) fprintf(stderr, "bench_shading: could not remove %s\n", dir);
  return 0;
}
