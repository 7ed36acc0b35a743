/* auto: the exact method for a view, from a cost model of the scene and the view,
 * with a short trial only where the model is unsure and the frames to come repay it. */
#include "vis/vis.h"

#include <stdio.h>
#include <string.h>

/* What the model knows of a view before rendering anything: T, and for planar
 * cameras S and A estimated from an even sample of the triangles (corner bounds and
 * setup, what 3dr-bb does first), scaled up to the whole scene. */
typedef struct view_figures {
  double tris;    /* T: triangles in the scene */
  double setups;  /* S: triangles whose screen rectangle holds a sample and that are not culled, per pass */
  double area;    /* A: samples in those rectangles, summed over the triangles, per pass */
  double edges;   /* R: their widths plus heights, summed (binning's work follows the edges) */
  double whole;   /* U: of those, triangles not bounded on screen (crossing the eye's plane): whole-image rectangles */
  double samples; /* P: samples per pass (pixels) */
  int passes;     /* samples per pixel: every method runs once per sample position */
  int threads;
  bool planar;
} view_figures;

enum { MODEL_SAMPLE = 4096, RR_WHY = sizeof ((rr_stats *)0)->why }; /* triangles looked at: ~0.1 ms, S and A within a few % on meshes */

static rr_error measure_view(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                             view_figures *v) {
  *v = (view_figures){.tris = s->ntris, .samples = (double)opt->width * opt->height, .passes = opt->samples,
                      .threads = opt->threads ? opt->threads : rr_cpu_count(),
                      .planar = cam->type == RR_CAMERA_PERSPECTIVE || cam->type == RR_CAMERA_ORTHOGRAPHIC};
  if (!v->planar || !s->ntris) return RR_OK; /* curved views: T and P say enough (see predict) */
  camera c;
  rr_error e = rr_cam_setup_at(dev, cam, opt->width, opt->height, opt->sample_pos[0], &c);
  if (e) return e;
  uint32_t n = s->ntris < MODEL_SAMPLE ? s->ntris : MODEL_SAMPLE, ids[256];
  tri_bound b[256];
  for (uint32_t first = 0; first < n; first += 256) {
    uint32_t m = n - first < 256 ? n - first : 256;
    for (uint32_t k = 0; k < m; k++) ids[k] = (uint32_t)((uint64_t)(first + k) * s->ntris / n);
    uint32_t kept = rr_tri_corner_bounds(s, 0, ids, m, &c, !opt->scalar, b);
    for (uint32_t k = 0; k < kept; k++) {
      tri_setup ts;
      if (rr_tri_setup(s, b[k].id, &c, opt->cull_backfaces != 0, &ts) == SETUP_CULLED) continue;
      v->setups += 1;
      double w = b[k].bb[2] - b[k].bb[0] + 1, h = b[k].bb[3] - b[k].bb[1] + 1;
      if (w * h >= v->samples) v->whole += 1; /* not in A: their rows are mostly skipped */
      else v->area += w * h, v->edges += w + h;
    }
  }
  rr_cam_release(&c);
  double scale = (double)s->ntris / n;
  v->setups *= scale, v->area *= scale, v->edges *= scale, v->whole *= scale;
  return RR_OK;
}

/* Predicted milliseconds of a method for a view: counts times costs in ns, least-
 * squares fits (on relative error) to the CPU times of 72 planar views on one thread
 * of this machine: bench_table's scenes and the teapot grid from inside, perspective
 * and orthographic, 256² to 1024², culling on and off (docs/auto.md). Rays pay per
 * sample, a curved camera's rays four times as much (incoherent packets); the 3dr
 * methods set every triangle up against a curved camera's cells at some 5 µs a
 * triangle. Every method gained 1.55–2× from a second thread, none clearly more. */
static double predict(rr_method m, const view_figures *v) {
  double T = v->tris, S = v->setups, A = v->area, R = v->edges, P = v->samples, ns;
  double UP = v->whole * P; /* whole-image rectangles: their samples are mostly skipped, ~0.3 ns each */
  bool rays = m == RR_METHOD_RC_PACKET || m == RR_METHOD_RC_BVH;
  if (rays) ns = (171 * T + (v->planar ? 15 : 100) * P) * (m == RR_METHOD_RC_BVH ? (v->planar ? 2 : 0.9) : 1);
  else if (!v->planar) ns = (5000 * T + 300 * P) * (m == RR_METHOD_3DR_FC ? 1.3 : m == RR_METHOD_3DR_FULL ? 1.2 : 1);
  else if (m == RR_METHOD_3DR_BB) ns = 10 * T + 65 * S + 2.0 * A + 0.28 * UP + 0.14 * P;
  else if (m == RR_METHOD_3DR_BIN) ns = 5 * T + 76 * S + 0.43 * A + 14 * R + 1.3 * P;
  /* what fc and full save is occlusion, which no count here shows: their fits miss
   * by up to 3×, so they must be predicted 1.5× faster than bin to be chosen */
  else if (m == RR_METHOD_3DR_FC) ns = 1.5 * (23 * T + 350 * S + 0.84 * A + 3.4 * P);
  else ns = 1.5 * (130 * S + 6.6 * R + 9.4 * P);
  int cores = rr_cpu_count(), threads = v->threads < cores ? v->threads : cores;
  return ns * 1e-6 * v->passes / (1 + 0.75 * (threads - 1));
}

/* The usual winners first: on a tie the earlier one is kept. */
static const rr_method planar[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL,
                                   RR_METHOD_RC_PACKET};
static const rr_method curved[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC,
                                   RR_METHOD_3DR_FULL};

/* The model is unsure when another candidate is predicted within this factor of the
 * best: its predictions miss by up to ±50% on the views it was fitted to. */
#define AUTO_MARGIN 1.5
/* A wrong pick among close candidates costs up to the margin on every frame; a
 * trial costs about a quarter frame per close candidate and round (two rounds). */

static bool same_view(const struct auto_choice *a, const struct auto_choice *b) {
  return a->scene == b->scene && a->bvh == b->bvh && a->ntris == b->ntris &&
         memcmp(&a->cam, &b->cam, sizeof a->cam) == 0 && a->width == b->width && a->height == b->height &&
         a->threads == b->threads && a->cull == b->cull && a->scalar == b->scalar;
}

/* Renders the view with each of cand[0..n-1] at half the resolution in each
 * direction, twice (the first round also warms the caches; a candidate more than
 * twice as slow as the best so far gets no second); *best is the fastest. Writes
 * "trial: <ms of each> ms at WxH; " and then `model` to why. */
static rr_error trial(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                      const rr_method *cand, int n, const char *model, int *best, char why[RR_WHY]) {
  rr_render_options t = *opt;
  t.width = opt->width > 1 ? opt->width / 2 : 1, t.height = opt->height > 1 ? opt->height / 2 : 1;
  if (cam->type == RR_CAMERA_CUBE) t.width = t.height / 3 * 4, t.height = t.height / 3 * 3;
  if (t.height < 3) t = *opt;
  t.heat = 0, t.oracles = NULL;
  double best_ms = INFINITY;
  char got[96] = "";
  *best = -1;
  for (int i = 0; i < n; i++) {
    t.method = cand[i];
    double ms = INFINITY;
    for (int round = 0; round < 2 && (round == 0 || !(ms > 2 * best_ms)); round++) {
      rr_frame *f;
      rr_error e = rr_render(dev, scene, cam, &t, &f);
      if (e) return e;
      ms = f->stats.frame_ms < ms ? f->stats.frame_ms : ms;
      rr_frame_release(f);
    }
    size_t len = strlen(got);
    snprintf(got + len, sizeof got - len, "%s%s %.3g", i ? ", " : "", rr_method_name(cand[i]), ms);
    if (ms < best_ms) best_ms = ms, *best = cand[i];
  }
  snprintf(why, RR_WHY, "trial: %s ms at %dx%d; %.140s", got, t.width, t.height, model);
  return RR_OK;
}

rr_error rr_render_auto(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                        rr_frame **out) {
  if (opt->oracles && *opt->oracles)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "oracles apply to the 3dr methods: choose one instead of auto");
  struct auto_choice key = {.scene = scene, .bvh = scene->bvh, .ntris = scene->ntris, .cam = *cam,
                            .width = opt->width, .height = opt->height, .threads = opt->threads,
                            .cull = opt->cull_backfaces != 0, .scalar = opt->scalar != 0};
  struct auto_choice *last = dev ? &dev->auto_choice : NULL;
  rr_render_options t = *opt;
  char why[RR_WHY];
  if (last && last->scene && same_view(last, &key)) { /* a trial's verdict for this view */
    t.method = (rr_method)last->method;
    snprintf(why, sizeof why, "%s", last->why);
  } else {
    view_figures v;
    rr_error e = measure_view(dev, scene, cam, opt, &v);
    if (e) return e;
    const rr_method *cand = v.planar ? planar : curved;
    int n = 5, close = 0; /* close: how many in near[] after the best */
    double ms[5], best_ms = INFINITY;
    for (int i = 0; i < n; i++) {
      ms[i] = predict(cand[i], &v);
      if (ms[i] < best_ms) best_ms = ms[i], t.method = cand[i];
    }
    /* the close candidates, the best first, and what a trial among them would cost */
    rr_method near[5] = {t.method};
    double trial_ms = 0;
    for (int i = 0; i < n; i++) {
      if (!(ms[i] <= AUTO_MARGIN * best_ms)) continue;
      trial_ms += 0.5 * ms[i];
      if (cand[i] != t.method) near[++close] = cand[i];
    }
    close++;
    int frames = opt->frames_hint > 1 ? opt->frames_hint : 1;
    int w = snprintf(why, sizeof why, "model:");
    for (int i = 0; i < n && w >= 0 && (size_t)w < sizeof why; i++)
      w += snprintf(why + w, sizeof why - w, "%s %s %.3g", i ? "," : "", rr_method_name(cand[i]), ms[i]);
    if (w >= 0 && (size_t)w < sizeof why)
      snprintf(why + w, sizeof why - w, " ms predicted (T=%.0f S=%.0f A=%.0f R=%.0f U=%.0f)", v.tris, v.setups, v.area, v.edges, v.whole);
    if (close > 1 && frames * (AUTO_MARGIN - 1) * best_ms > trial_ms) {
      int best;
      char model[RR_WHY];
      memcpy(model, why, sizeof model);
      e = trial(dev, scene, cam, opt, near, close, model, &best, why);
      if (e) return e;
      t.method = (rr_method)best;
      if (last) {
        key.method = best;
        snprintf(key.why, sizeof key.why, "%s", why);
        *last = key;
      }
    }
  }
  rr_error e = rr_render(dev, scene, cam, &t, out);
  if (!e) snprintf((*out)->stats.why, sizeof (*out)->stats.why, "%s", why);
  return e;
}
