/* bench_overdraw: does a pre-Z pass pay in the 2D pipeline? Shading is deferred
 * over the visibility buffer, so a sample the z-buffer later overwrites cost its
 * write (id, t, λ1, λ2) and no shading; a pre-Z pass would run setup, coverage and
 * the depth test of every triangle once more to save those writes. This bench
 * measures both sides per scene:
 *
 *   - overdraw: for every pixel centre, every triangle along its ray (the ray
 *     re-cast past each hit until it leaves the scene) in the 2D pipeline's
 *     submission order (triangle index); the z-buffer writes of that order are the
 *     hits nearer than every earlier one, and the writes later overwritten are
 *     the writes minus the samples that hit;
 *   - the price of a pass: 2dr-bb's frame (one thread, median wall time of --runs;
 *     under callgrind its instructions, part "2dr-bb-NAME").
 *
 *   bench_overdraw [--size WxH] [--runs N] [SCENE...]   (default: demo,
 *   stanford-bunny.obj, grid:teapot.obj:19 at 512x512) */
#include "benchutil.h"
#include "camera/camera.h"
#include "scene/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_LAYERS = 4096 };

typedef struct {
  uint32_t idx;
  float t;
} layer;

/* Every hit along each pixel centre's ray, in order of t: rounds of one stream of
 * the rays still inside, each restarted just past its last hit. */
static void overdraw(rr_device *dev, const rr_scene *s, const camera *c, int w, int h, const char *name, double frame_ms,
                     uint64_t setups) {
  size_t n = (size_t)w * h;
  rr_ray *rays = malloc(n * sizeof *rays);
  rr_hit *hits = malloc(n * sizeof *hits);
  size_t *who = malloc(n * sizeof *who);
  layer *lay = malloc(n * 64 * sizeof *lay); /* up to 64 layers a pixel kept; deeper ones are counted */
  uint32_t *nl = calloc(n, sizeof *nl);
  if (!rays || !hits || !who || !lay || !nl) exit(1);
  size_t live = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      vec3 o, d;
      if (!rr_cam_ray(c, x, y, &o, &d)) continue;
      rays[live] = (rr_ray){{o.x, o.y, o.z}, {d.x, d.y, d.z}, 0, INFINITY};
      who[live++] = (size_t)y * w + x;
    }
  uint64_t deep = 0;
  for (int round = 0; live && round < MAX_LAYERS; round++) {
    rr_ray_stream rs = rr_ray_stream_aos(rays, live);
    rr_intersect_stream(dev, s, &rs, 2, hits);
    size_t keep = 0;
    for (size_t k = 0; k < live; k++) {
      uint32_t idx = rr_scene_index_of(s, hits[k].prim);
      if (idx == RR_MISS) continue;
      size_t p = who[k];
      if (nl[p] < 64) lay[p * 64 + nl[p]] = (layer){idx, hits[k].t};
      else deep++;
      nl[p]++;
      rays[keep] = rays[k], who[keep] = p;
      rays[keep].tmin = nextafterf(hits[k].t, INFINITY); /* past this hit */
      keep++;
    }
    live = keep;
  }
  /* the z-buffer in submission order: a write wherever a triangle is nearer than
   * every earlier one at the sample */
  uint64_t hit_px = 0, layers = 0, writes = 0;
  for (size_t p = 0; p < n; p++) {
    if (!nl[p]) continue;
    hit_px++, layers += nl[p];
    layer *l = lay + p * 64;
    int m = nl[p] < 64 ? (int)nl[p] : 64;
    for (int a = 1; a < m; a++) /* by index */
      for (int b = a; b > 0 && l[b - 1].idx > l[b].idx; b--) {
        layer t = l[b - 1];
        l[b - 1] = l[b], l[b] = t;
      }
    float near = INFINITY;
    for (int a = 0; a < m; a++)
      if (l[a].t < near) near = l[a].t, writes++;
  }
  printf("| %s | %llu | %.2f | %llu | %llu | %.1f%% | %.2f | %.1f | %llu |%s\n", name, (unsigned long long)hit_px,
         (double)layers / (hit_px ? hit_px : 1), (unsigned long long)writes, (unsigned long long)(writes - hit_px),
         100.0 * (writes - hit_px) / (writes ? writes : 1), (double)writes / (hit_px ? hit_px : 1), frame_ms,
         (unsigned long long)setups, deep ? " (layers past 64 not ordered)" : "");
  fflush(stdout);
  free(rays), free(hits), free(who), free(lay), free(nl);
}

int main(int argc, char **argv) {
  int w = 512, h = 512, runs = 5, nscenes = 0;
  const char *scenes[16];
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (!bench_arg_size("bench_overdraw", argv[++i], 1, &w, &h)) return 2;
    } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_overdraw", "--runs", argv[++i], 1, 64, &runs)) return 2;
    } else if (argv[i][0] != '-' && nscenes < 16) {
      scenes[nscenes++] = argv[i];
    } else {
      fprintf(stderr, "usage: bench_overdraw [--size WxH] [--runs N] [SCENE...]\n");
      return 2;
    }
  }
  if (!nscenes) scenes[nscenes++] = "demo", scenes[nscenes++] = "stanford-bunny.obj", scenes[nscenes++] = "grid:teapot.obj:19";
  rr_device *dev = rr_device_new();
  bool counting = bench_on_valgrind();
  printf("%dx%d, one sample per pixel: the 2D pipeline's z-buffer writes in submission order (triangle index) and\n"
         "those later overwritten; 2dr-bb's frame on one thread (median of %d runs, ms)\n\n", w, h, counting ? 1 : runs);
  printf("| scene | samples hit | layers per hit sample | z-buffer writes | overwritten | of the writes | "
         "writes per hit sample | 2dr-bb frame (ms) | triangle setups |\n|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < nscenes; i++) {
    rr_scene *s = bench_load(dev, scenes[i], NULL);
    rr_camera cam;
    bench_view(dev, scenes[i], s, w, h, &cam);
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_2DR_BB, opt.width = w, opt.height = h, opt.threads = 1;
    rr_frame *f;
    char part[300];
    snprintf(part, sizeof part, "2dr-bb-%s", scenes[i]);
    double ms = counting ? bench_count_frame(dev, s, &cam, &opt, part, &f) : bench_render(dev, s, &cam, &opt, runs, &f);
    rr_stats st;
    rr_frame_get_stats(f, &st);
    camera c;
    if (rr_cam_setup(dev, &cam, w, h, &c) != RR_OK) {
      fprintf(stderr, "bench_overdraw: %s\n", rr_device_message(dev));
      return 1;
    }
    if (!counting) overdraw(dev, s, &c, w, h, scenes[i], ms, st.setups);
    else printf("| %s | (counted: part %s) |\n", scenes[i], part);
    rr_cam_release(&c);
    rr_frame_release(f);
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return 0;
}
