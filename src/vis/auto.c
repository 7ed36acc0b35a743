/* auto's cost model: each candidate method's time for a view, predicted from counts
 * that are cheap to know before rendering (render.c chooses, and runs a trial when
 * the model is unsure and the frames to come repay it). */
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
  int threads;    /* threads that run at once (no more than the cores) */
  bool planar;
} view_figures;

/* Triangles the model looks at (~0.1 ms). */
enum { MODEL_SAMPLE = 4096 };

/* The figures of a view: every triangle of a small scene, an even spread of
 * MODEL_SAMPLE triangles of a large one. */
static rr_error measure_view(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                             view_figures *v) {
  int cores = rr_cpu_count();
  *v = (view_figures){.tris = s->ntris, .samples = (double)opt->width * opt->height, .passes = opt->samples,
                      .threads = opt->threads && opt->threads < cores ? opt->threads : cores,
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
  /* single rays: twice rc-packet's time on planar views, 0.8–1.0× on curved ones */
  if (rays) ns = (171 * T + (v->planar ? 15 : 100) * P) * (m == RR_METHOD_RC_BVH ? (v->planar ? 2 : 0.9) : 1);
  else if (!v->planar) ns = (5000 * T + 300 * P) * (m == RR_METHOD_3DR_FC ? 1.3 : m == RR_METHOD_3DR_FULL ? 1.2 : 1);
  else if (m == RR_METHOD_3DR_BB) ns = 10 * T + 65 * S + 2.0 * A + 0.28 * UP + 0.14 * P;
  else if (m == RR_METHOD_3DR_BIN) ns = 5 * T + 76 * S + 0.43 * A + 14 * R + 1.3 * P;
  /* what fc and full save is occlusion, which no count here shows: their fits miss
   * by up to 3×, so they must be predicted 1.5× faster than bin to be chosen */
  else if (m == RR_METHOD_3DR_FC) ns = 1.5 * (23 * T + 350 * S + 0.84 * A + 3.4 * P);
  else ns = 1.5 * (130 * S + 6.6 * R + 9.4 * P);
  return ns * 1e-6 * v->passes / (1 + 0.75 * (v->threads - 1));
}

/* The candidates: exact methods (bit-identical to ray casting; the 2D pipeline's
 * snapped vertices are for comparison) that win somewhere; 3dr-bb's screen
 * rectangles only on planar views. On a tie the earlier one is kept. */
static const rr_method planar[AUTO_NCAND] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL,
                                   RR_METHOD_RC_PACKET};
static const rr_method curved[AUTO_NCAND] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC,
                                   RR_METHOD_3DR_FULL};

rr_error rr_auto_predict(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                         auto_prediction *out) {
  view_figures v;
  rr_error e = measure_view(dev, scene, cam, opt, &v);
  if (e) return e;
  for (int i = 0; i < AUTO_NCAND; i++) {
    out->method[i] = (v.planar ? planar : curved)[i];
    out->ms[i] = predict(out->method[i], &v);
  }
  snprintf(out->figures, sizeof out->figures, "T=%.0f S=%.0f A=%.0f R=%.0f U=%.0f", v.tris, v.setups, v.area,
           v.edges, v.whole);
  return RR_OK;
}
