/* bench_rays: incoherent secondary rays through rastray's ray queries against
 * Embree 3 on the very same rays, in one process, rounds interleaved.
 *
 *   bench_rays [SCENE...] [--rays N] [--reps N] [--instructions]
 *
 * Per scene two ray sets, both from random points of its surface (area-weighted
 * triangles, uniform barycentrics): AO rays (closest hit), cosine-distributed
 * about the triangle's normal, and shadow rays (any hit) to a point light above
 * the scene. tmin is 1e-4 of the scene's radius, so a ray does not find the
 * triangle it starts on. Modes: rr_intersect / rr_occluded per ray, the streams
 * on 1 and 2 threads, Embree's rtcIntersect1 / rtcOccluded1 and rtcIntersect8 /
 * rtcOccluded8 (8 consecutive rays) on 1 thread. Per mode: the median ms of
 * --reps (default 5), Mrays/s, the ratio to Embree's width-1 call, agreement
 * with it (same hit/miss; closest hit: t within 1e-4 relative, same triangle), and whether the results
 * are bit-identical to the single calls'. --instructions: the instructions of
 * one pass of each mode under callgrind (use fewer --rays), a measure that a busy
 * machine does not blur. */
#include "benchutil.h"
#include "vis/vis.h"
#ifdef RR_HAVE_EMBREE
#include "peer_embree.h"
#endif

#include <stdio.h>
#include <string.h>

typedef struct {
  size_t nrays;
  int reps;
  bool count; /* under callgrind for --instructions */
} bench_rays_opts;

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static float rnd(void) { /* xorshift64*: reproducible rays */
  rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
  return (float)((rng_state * 0x2545F4914F6CDD1Dull) >> 40) * 0x1p-24f;
}

/* Random surface points with their triangle's unit normal: n rays of each set. */
static void make_rays(const rr_scene *s, size_t n, rr_ray *ao, rr_ray *shadow) {
  double *cdf = malloc(s->ntris * sizeof *cdf), total = 0;
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t i = 0; i < s->ntris; i++) {
    vec3 p0 = scene_vertex(s, 0, i);
    total += 0.5 * v3_len(v3_cross(v3_sub(scene_vertex(s, 1, i), p0), v3_sub(scene_vertex(s, 2, i), p0)));
    cdf[i] = total;
    for (int k = 0; k < 3; k++) lo = v3_min(lo, scene_vertex(s, k, i)), hi = v3_max(hi, scene_vertex(s, k, i));
  }
  float radius = 0.5f * v3_len(v3_sub(hi, lo)), eps = 1e-4f * radius;
  vec3 centre = v3_scale(v3_add(lo, hi), 0.5f), light = v3_add(centre, v3(0.3f * radius, 2 * radius, 0.5f * radius));
  for (size_t r = 0; r < n; r++) {
    double u = rnd() * total;
    size_t a = 0, b = s->ntris - 1;
    while (a < b) { /* the first triangle whose cumulative area reaches u */
      size_t m = (a + b) / 2;
      if (cdf[m] < u) a = m + 1; else b = m;
    }
    uint32_t i = (uint32_t)a;
    float b1 = rnd(), b2 = rnd();
    if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
    vec3 p0 = scene_vertex(s, 0, i), e1 = v3_sub(scene_vertex(s, 1, i), p0), e2 = v3_sub(scene_vertex(s, 2, i), p0);
    vec3 p = v3_add(p0, v3_add(v3_scale(e1, b1), v3_scale(e2, b2))), nrm = v3_norm(v3_cross(e1, e2));
    /* cosine-distributed about nrm: a uniform disc point lifted to the hemisphere */
    vec3 t = v3_norm(v3_cross(fabsf(nrm.x) < 0.9f ? v3(1, 0, 0) : v3(0, 1, 0), nrm)), bt = v3_cross(nrm, t);
    float phi = 6.2831853f * rnd(), r2 = rnd(), rr = sqrtf(r2);
    vec3 d = v3_add(v3_add(v3_scale(t, rr * cosf(phi)), v3_scale(bt, rr * sinf(phi))), v3_scale(nrm, sqrtf(1 - r2)));
    ao[r] = (rr_ray){{p.x, p.y, p.z}, {d.x, d.y, d.z}, eps, INFINITY};
    vec3 l = v3_sub(light, p);
    shadow[r] = (rr_ray){{p.x, p.y, p.z}, {l.x, l.y, l.z}, eps / v3_len(l), 1.0f};
  }
  free(cdf);
}

typedef struct {
  const char *name;
  double ms[64];
  uint32_t *ids;
  float *t;
} bench_mode;

enum { M_SINGLE, M_STREAM1, M_STREAM2, M_EMB1, M_EMB8, M_COUNT };
static const char *mode_names[2][M_COUNT] = {
    {"rr_intersect", "stream 1t", "stream 2t", "rtcIntersect1", "rtcIntersect8"},
    {"rr_occluded", "stream 1t", "stream 2t", "rtcOccluded1", "rtcOccluded8"}};

/* Runs mode m on the rays once: ids (RR_MISS on a miss; any: 0 when occluded), t. */
static double run_mode(rr_device *dev, const rr_scene *s, void *emb, int m, bool any, const rr_ray *rays, size_t n,
                       rr_hit *hits, int *occ, uint32_t *ids, float *t) {
  double t0 = bench_now_ms();
  rr_ray_stream rs = rr_ray_stream_aos(rays, n);
  switch (m) {
  case M_SINGLE:
    for (size_t i = 0; i < n; i++)
      if (any)
        rr_occluded(NULL, s, &rays[i], &occ[i]);
      else
        rr_intersect(NULL, s, &rays[i], &hits[i]);
    break;
  case M_STREAM1:
  case M_STREAM2:
    if ((any ? rr_occluded_stream(dev, s, &rs, m == M_STREAM1 ? 1 : 2, occ)
             : rr_intersect_stream(dev, s, &rs, m == M_STREAM1 ? 1 : 2, hits)) != RR_OK) {
      fprintf(stderr, "bench_rays: %s\n", rr_device_message(dev));
      exit(1);
    }
    break;
  default:
#ifdef RR_HAVE_EMBREE
    return peer_embree_rays(emb, rays, n, any, m == M_EMB1 ? 1 : 8, 1, ids, t);
#endif
    (void)emb;
    return -1;
  }
  double ms = bench_now_ms() - t0;
  for (size_t i = 0; i < n; i++) {
    ids[i] = any ? (occ[i] ? 0 : RR_MISS) : hits[i].prim;
    if (!any) t[i] = hits[i].t;
  }
  return ms;
}

static void bench_rays_set(rr_device *dev, const char *scene, const rr_scene *s, void *emb, bool any,
                           const rr_ray *rays, const bench_rays_opts *o) {
  size_t n = o->nrays;
  rr_hit *hits = malloc(n * sizeof *hits);
  int *occ = malloc(n * sizeof *occ);
  bench_mode modes[M_COUNT];
  int nmodes = emb ? M_COUNT : M_EMB1;
  for (int m = 0; m < nmodes; m++) {
    modes[m] = (bench_mode){.name = mode_names[any][m], .ids = malloc(n * sizeof(uint32_t)),
                            .t = malloc(n * sizeof(float))};
    memset(modes[m].t, 0, n * sizeof(float));
  }
  if (o->count) {
    for (int m = 0; m < nmodes; m++) {
      char part[256];
      snprintf(part, sizeof part, "%s %s %s", scene, any ? "shadow" : "ao", modes[m].name);
      run_mode(dev, s, emb, m, any, rays, n, hits, occ, modes[m].ids, modes[m].t); /* warm-up, uncounted */
      bench_count_start();
      run_mode(dev, s, emb, m, any, rays, n, hits, occ, modes[m].ids, modes[m].t);
      bench_count_stop(part);
    }
  } else {
    for (int r = 0; r < o->reps; r++) /* interleaved rounds: a busy moment hits every mode alike */
      for (int m = 0; m < nmodes; m++)
        modes[m].ms[r] = run_mode(dev, s, emb, m, any, rays, n, hits, occ, modes[m].ids, modes[m].t);
  }
  printf("  %s rays (%s), %zu rays, 1 thread unless said\n", any ? "shadow" : "AO", any ? "any hit" : "closest hit",
         n);
  printf("  %-16s %9s %8s %8s   %-30s %s\n", "mode", "ms", "Mrays/s", "ratio", "agree (hit, t, id)", "= single");
  double ref = emb ? bench_median(modes[M_EMB1].ms, o->reps) : 0;
  for (int m = 0; m < nmodes; m++) {
    double ms = bench_median(modes[m].ms, o->reps);
    char ratio[32] = "-", ag[64] = "-";
    if (ref > 0) snprintf(ratio, sizeof ratio, "%.2fx", ms / ref);
    if (emb) {
      bench_agreement a = bench_compare(modes[m].ids, modes[m].t, modes[M_EMB1].ids, modes[M_EMB1].t, n);
      snprintf(ag, sizeof ag, "%.4f%% %.4f%% %.4f%%", 100 * a.same_hit, 100 * a.depth_ok, 100 * a.same_id);
    }
    const char *same = "";
    if (m < M_EMB1)
      same = memcmp(modes[m].ids, modes[M_SINGLE].ids, n * sizeof(uint32_t)) ||
                     memcmp(modes[m].t, modes[M_SINGLE].t, n * sizeof(float))
                 ? "DIFFERENT"
                 : "identical";
    printf("  %-16s %9.1f %8.2f %8s   %-30s %s\n", modes[m].name, ms, (double)n / ms / 1000.0, ratio, ag, same);
  }
  for (int m = 0; m < nmodes; m++) free(modes[m].ids), free(modes[m].t);
  free(hits), free(occ);
}

static void bench_rays_scene(rr_device *dev, const char *name, const bench_rays_opts *o) {
  rr_scene *s = bench_load(dev, name, NULL);
  rr_ray *ao = malloc(o->nrays * sizeof *ao), *shadow = malloc(o->nrays * sizeof *shadow);
  make_rays(s, o->nrays, ao, shadow);
  void *emb = NULL;
#ifdef RR_HAVE_EMBREE
  double build_ms;
  emb = peer_embree_new(s, 1, 1, &build_ms);
#endif
  printf("%s: %u triangles\n", name, s->ntris);
  bench_rays_set(dev, name, s, emb, false, ao, o);
  bench_rays_set(dev, name, s, emb, true, shadow, o);
#ifdef RR_HAVE_EMBREE
  peer_embree_release(emb);
#endif
  free(ao), free(shadow);
  rr_scene_release(s);
}

int main(int argc, char **argv) {
  bench_rays_opts o = {.nrays = 200000, .reps = 5};
  const char *scenes[16];
  int nscenes = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(a, "--rays") == 0 && v) o.nrays = (size_t)atol(v), i++;
    else if (strcmp(a, "--reps") == 0 && v) o.reps = atoi(v), i++;
    else if (strcmp(a, "--instructions") == 0) o.count = true;
    else if (a[0] != '-' && nscenes < 16) scenes[nscenes++] = a;
    else {
      fprintf(stderr, "usage: bench_rays [SCENE...] [--rays N] [--reps N] [--instructions]\n");
      return 2;
    }
  }
  if (o.count && !bench_on_valgrind()) return bench_instructions_main(argv);
  if (o.reps < 1 || o.reps > 64) o.reps = 5;
  if (o.nrays < 1) o.nrays = 200000;
  if (!nscenes) {
    static const char *def[] = {"stanford-bunny.obj", "grid:teapot.obj:19"};
    for (int i = 0; i < 2; i++) scenes[nscenes++] = def[i];
  }
#ifndef RR_HAVE_EMBREE
  printf("Embree 3 not found at build time (install libembree-dev): rastray's modes only\n");
#endif
  printf("rastray %s bench_rays: ratios are time / Embree's width-1 call's time; agreement with it:\n"
         "same hit/miss, t within 1e-4 relative, same triangle id; '= single': bit-identical to one rr_intersect/rr_occluded per ray\n",
         RR_VERSION);
  rr_device *dev = rr_device_new();
  for (int i = 0; i < nscenes; i++) bench_rays_scene(dev, scenes[i], &o);
  rr_device_release(dev);
  return 0;
}
