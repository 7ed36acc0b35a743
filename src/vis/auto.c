/* auto's model and choice: each candidate method's time for a view, predicted from
 * counts that are cheap to know before rendering; the fastest, or, where the model is
 * unsure and the frames to come repay it, the candidates of a trial (render.c runs
 * it). The costs come from `bench_auto --calibrate` (docs/auto.md). */
#include "vis/vis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What the model knows of a view before rendering anything: T, and for planar
 * cameras and a cube's faces S, A, R, U, D and F estimated from an even sample of the triangles (corner
 * bounds and setup, what 3dr-bb does first), scaled up to the whole scene. */
typedef struct view_figures {
  double tris;          /* T: triangles in the scene */
  double setups;        /* S: triangles whose screen rectangle holds a sample and that are not culled, per pass */
  double area;          /* A: samples in those rectangles, summed over the triangles, per pass */
  double edges;         /* R: their widths plus heights, summed (binning's work follows the edges) */
  double whole;         /* U: of those, triangles not bounded on screen (crossing the eye's plane): whole-image rectangles */
  double whole_samples; /* U·P: the samples of their images */
  double front_layer;   /* S/D, D the depth complexity: rectangles over a covered sample (≥ 1; see depth_complexity) */
  double front;         /* F: setups not hidden behind nearer rectangles (see hidden_rects) */
  double samples;       /* P: samples per pass (pixels; a cube's faces') */
  int passes;           /* samples per pixel: every method runs once per sample position */
  int threads;          /* threads that run at once (no more than the cores) */
  rr_camera_type type;
  bool planar;
} view_figures;

/* Triangles the model looks at (~0.1 ms). */
enum { MODEL_SAMPLE = 4096 };

/* ---- depth complexity -------------------------------------------------------- */

/* What hiding saves the frustum methods: with depth complexity D, about one
 * triangle in D is in front, and a front-to-back traversal that skips what is hidden
 * sets up about S / D. D is the average, over the covered samples, of how many
 * rectangles cover a sample, counted on a coarse grid of cells: each looked-at
 * rectangle adds the share x of each cell it overlaps; with c a cell's sum,
 * D = Σc² / Σc (a sample's view weighted by how much is drawn there: empty
 * background does not dilute it). Looking at one triangle in s, ĉ = s·Σx
 * overestimates c² by (s − 1)·Σx² on average, which is taken off (q = s²·Σx²
 * estimates s·Σx²): without that, a sparse sample of a big scene would show
 * depth where there is none. Whole-image rectangles (U) are left out: how much of
 * the image they cover is unknown. */
enum { DEPTH_CELLS = 16 };
typedef struct depth_grid {
  int w, h, gx, gy;
  double cover[DEPTH_CELLS * DEPTH_CELLS], square[DEPTH_CELLS * DEPTH_CELLS];
} depth_grid;

static void depth_add(depth_grid *g, const int bb[4]) {
  for (int cy = bb[1] * g->gy / g->h; cy <= bb[3] * g->gy / g->h; cy++) {
    int y0 = cy * g->h / g->gy, y1 = (cy + 1) * g->h / g->gy; /* the cell's rows [y0, y1) */
    int oy = (bb[3] + 1 < y1 ? bb[3] + 1 : y1) - (bb[1] > y0 ? bb[1] : y0);
    for (int cx = bb[0] * g->gx / g->w; cx <= bb[2] * g->gx / g->w; cx++) {
      int x0 = cx * g->w / g->gx, x1 = (cx + 1) * g->w / g->gx;
      int ox = (bb[2] + 1 < x1 ? bb[2] + 1 : x1) - (bb[0] > x0 ? bb[0] : x0);
      if (ox <= 0 || oy <= 0) continue;
      double x = (double)ox * oy / ((double)(x1 - x0) * (y1 - y0));
      g->cover[cy * DEPTH_CELLS + cx] += x, g->square[cy * DEPTH_CELLS + cx] += x * x;
    }
  }
}

/* What a front-to-back pass with occlusion culling (3dr-full) skips depends on
 * more than D: on whether near surfaces fill the tiles (a teapot grid seen from
 * inside in perspective, its near teapots large, hides 79% of its setups; the same
 * grid in an orthographic view, every teapot small, 56%, at the same D). The
 * looked-at rectangles are taken nearest first (by the least t of their triangle)
 * on the grid of depth_add; one whose every cell is already covered twice over (a
 * mesh's rectangles are about twice its triangles) counts as hidden. F = S less
 * those, scaled up like S. */
typedef struct near_rect {
  float t;
  int bb[4];
} near_rect;

static int nearer(const void *a, const void *b) {
  float x = ((const near_rect *)a)->t, y = ((const near_rect *)b)->t;
  return x < y ? -1 : x > y;
}

static double hidden_rects(near_rect *r, int n, int w, int h, double scale) {
  qsort(r, (size_t)n, sizeof *r, nearer);
  depth_grid g = {.w = w, .h = h, .gx = w < DEPTH_CELLS ? w : DEPTH_CELLS, .gy = h < DEPTH_CELLS ? h : DEPTH_CELLS};
  double hidden = 0;
  for (int i = 0; i < n; i++) {
    const int *bb = r[i].bb;
    bool covered = true;
    for (int cy = bb[1] * g.gy / h; cy <= bb[3] * g.gy / h && covered; cy++)
      for (int cx = bb[0] * g.gx / w; cx <= bb[2] * g.gx / w && covered; cx++)
        covered = scale * g.cover[cy * DEPTH_CELLS + cx] >= 2;
    hidden += covered;
    depth_add(&g, bb);
  }
  return hidden;
}

/* D for one looked-at triangle in `scale` (≥ 1). */
static double depth_complexity(const depth_grid *g, double scale) {
  double sum = 0, sum2 = 0;
  for (int k = 0; k < DEPTH_CELLS * DEPTH_CELLS; k++) {
    double c = scale * g->cover[k];
    sum += c, sum2 += c * c - (scale - 1) * scale * g->square[k];
  }
  return sum > 0 && sum2 > sum ? sum2 / sum : 1;
}

/* The planar figures of one planar camera c of w × h samples (a view, or a face of a
 * cube), added to v: setups, area, edges and whole-image rectangles summed, the front
 * layer's setups (S/D of the face) into v->front_layer, F into v->front. */
static rr_error look_planar(rr_device *dev, const rr_scene *s, const camera *c, int w, int h,
                            const rr_render_options *opt, view_figures *v) {
  uint32_t n = s->ntris < MODEL_SAMPLE ? s->ntris : MODEL_SAMPLE, ids[256];
  tri_bound b[256];
  near_rect *near = malloc(sizeof *near * n);
  if (!near) return rr_fail(dev, RR_ERROR_MEMORY, "auto: out of memory");
  int nnear = 0;
  double setups = 0, samples = (double)w * h;
  depth_grid g = {.w = w, .h = h, .gx = w < DEPTH_CELLS ? w : DEPTH_CELLS, .gy = h < DEPTH_CELLS ? h : DEPTH_CELLS};
  double scale = (double)s->ntris / n;
  for (uint32_t first = 0; first < n; first += 256) {
    uint32_t m = n - first < 256 ? n - first : 256;
    for (uint32_t k = 0; k < m; k++) ids[k] = (uint32_t)((uint64_t)(first + k) * s->ntris / n);
    uint32_t kept = rr_tri_corner_bounds(s, 0, ids, m, c, !opt->scalar, b);
    for (uint32_t k = 0; k < kept; k++) {
      tri_setup ts;
      if (rr_tri_setup(s, b[k].id, c, opt->cull_backfaces != 0, &ts) == SETUP_CULLED) continue;
      setups += scale;
      double bw = b[k].bb[2] - b[k].bb[0] + 1, bh = b[k].bb[3] - b[k].bb[1] + 1;
      if (bw * bh >= samples) { /* not in A: their rows are mostly skipped */
        v->whole += scale, v->whole_samples += scale * samples;
      } else {
        v->area += scale * bw * bh, v->edges += scale * (bw + bh), depth_add(&g, b[k].bb);
        float rect[4];
        near[nnear].t = rr_tri_bounds(&ts, c, rect);
        memcpy(near[nnear++].bb, b[k].bb, sizeof b[k].bb);
      }
    }
  }
  v->setups += setups;
  v->front_layer += setups / depth_complexity(&g, scale);
  v->front += setups - scale * hidden_rects(near, nnear, w, h, scale);
  free(near);
  return RR_OK;
}

/* The figures of a view: every triangle of a small scene, an even spread of
 * MODEL_SAMPLE triangles of a large one. A cube is its six faces' planar views
 * (what its methods draw: docs/cameras.md), each figure summed over them. */
static rr_error measure_view(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                             view_figures *v) {
  int cores = rr_cpu_count();
  *v = (view_figures){.tris = s->ntris, .samples = (double)opt->width * opt->height, .passes = opt->samples,
                      .threads = opt->threads && opt->threads < cores ? opt->threads : cores,
                      .type = cam->type,
                      .planar = cam->type == RR_CAMERA_PERSPECTIVE || cam->type == RR_CAMERA_ORTHOGRAPHIC};
  /* other curved views: T and P say enough (see rr_auto_uses) */
  if (!(v->planar || cam->type == RR_CAMERA_CUBE) || !s->ntris) return RR_OK;
  camera c;
  rr_error e = rr_cam_setup_at(dev, cam, opt->width, opt->height, opt->sample_pos[0], &c);
  if (e) return e;
  if (c.type != RR_CAMERA_CUBE) e = look_planar(dev, s, &c, opt->width, opt->height, opt, v);
  else {
    v->samples = 6.0 * c.face * c.face;
    for (int f = 0; f < 6 && !e; f++) {
      camera face;
      rr_cam_cube_face(&c, f, &face);
      e = look_planar(dev, s, &face, c.face, c.face, opt, v);
    }
  }
  rr_cam_release(&c);
  return e;
}

const char *const rr_auto_fig_names[AUTO_NFIG] = {"T", "S", "A", "R", "UP", "P", "PlogT", "S/D", "F", "1"};

/* The costs: ns per unit of each figure on one thread, for planar cameras and for
 * each curved camera type (how its rays map to 3dr's cells differs: a cube's faces
 * are planes, OpenCV's distortions are not), and what each further thread adds to
 * one thread's speed. Written by `bench_auto --calibrate --threads 2 --out
 * src/vis/auto_costs.h` (docs/auto.md): re-derive them when a method's speed changes. */
#include "vis/auto_costs.h"

double rr_auto_thread_gain(rr_method m) { return m >= 0 && m < RR_METHOD_COUNT ? thread_gain[m] : 0; }

/* Every method pays a fixed cost a frame (1: the pool's start, buffers, the
 * per-frame passes), which weighs in small frames of small scenes. */
#define FIG(f) (1u << AUTO_##f)
unsigned rr_auto_uses(rr_method m, rr_camera_type type) {
  bool rays = m == RR_METHOD_RC_PACKET || m == RR_METHOD_RC_BVH;
  bool planar = type == RR_CAMERA_PERSPECTIVE || type == RR_CAMERA_ORTHOGRAPHIC;
  /* rays: a pass over every triangle (T), a descent per sample (P·log T), and on
   * planar views the setups of what traversal reaches (those on screen, S) and the
   * tests of the triangles whose boxes a ray passes (about their rectangles, A: big
   * overlapping triangles, as in rooms, cost rays dearly) */
  if (rays) return FIG(T) | FIG(P) | FIG(PLOGT) | FIG(ONE) | (planar ? FIG(S) | FIG(A) : 0);
  /* A cube's faces are looked at as planar views: 3dr-bin and 3dr-full follow
   * their rectangles (A) and what hiding leaves (F) more than the samples (leaving
   * one cube view out of the fit, the others predict it within 19% and 12%, median,
   * against 58% and 44% from T and P); ten calibration views carry no more. */
  if (type == RR_CAMERA_CUBE && (m == RR_METHOD_3DR_BIN || m == RR_METHOD_3DR_FULL))
    return FIG(T) | FIG(A) | FIG(F) | FIG(ONE);
  if (!planar) return FIG(T) | FIG(P) | FIG(ONE);
  switch (m) {
  case RR_METHOD_3DR_BB: return FIG(T) | FIG(S) | FIG(A) | FIG(UP) | FIG(P) | FIG(ONE);
  case RR_METHOD_3DR_BIN: return FIG(T) | FIG(S) | FIG(A) | FIG(R) | FIG(P) | FIG(ONE);
  /* The frustum methods skip part of what is hidden: their setups split into those
   * of every rectangle (S: the frusta still reach them) and those of the front:
   * 3dr-full, which culls occluded boxes front to back, the setups left by a like
   * pass over the looked-at rectangles (F); 3dr-fc, whose leaves' bins meet
   * early-z, those of the front layer (S/D), what its fit prefers. 3dr-bin's and
   * 3dr-bb's fits gain little from either (1 point of median error). */
  case RR_METHOD_3DR_FC: return FIG(T) | FIG(S) | FIG(SD) | FIG(A) | FIG(P) | FIG(ONE);
  default: return FIG(T) | FIG(S) | FIG(F) | FIG(A) | FIG(R) | FIG(P) | FIG(ONE);
  }
}

/* Predicted milliseconds of a method for a view. */
static double predict(rr_method m, const view_figures *v, const double fig[AUTO_NFIG]) {
  const double *c = v->planar ? cost_planar[m] : cost_curved[v->type][m];
  double ns = 0;
  for (int f = 0; f < AUTO_NFIG; f++) ns += c[f] * fig[f];
  return ns * 1e-6 * v->passes / (1 + thread_gain[m] * (v->threads - 1));
}

/* The candidates: exact methods (bit-identical to ray casting; the 2D pipeline's
 * snapped vertices are for comparison) that win somewhere; 3dr-bb's screen
 * rectangles only on planar views, single rays (2× rc-packet there) only on curved
 * ones. On a tie the earlier one is kept. */
static const rr_method planar[AUTO_NCAND] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC,
                                             RR_METHOD_3DR_FULL, RR_METHOD_RC_PACKET};
static const rr_method curved[AUTO_NCAND] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BIN,
                                             RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL};

rr_error rr_auto_predict(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                         auto_prediction *out) {
  view_figures v;
  rr_error e = measure_view(dev, scene, cam, opt, &v);
  if (e) return e;
  double *fig = out->fig;
  double depth = v.front_layer > 0 ? v.setups / v.front_layer : 1;
  fig[AUTO_T] = v.tris, fig[AUTO_S] = v.setups, fig[AUTO_A] = v.area, fig[AUTO_R] = v.edges;
  fig[AUTO_UP] = v.whole_samples, fig[AUTO_P] = v.samples, fig[AUTO_PLOGT] = v.samples * log2(v.tris + 1);
  fig[AUTO_SD] = v.front_layer, fig[AUTO_F] = v.front, fig[AUTO_ONE] = 1;
  out->planar = v.planar, out->depth = depth;
  for (int i = 0; i < AUTO_NCAND; i++) {
    out->method[i] = (v.planar ? planar : curved)[i];
    out->ms[i] = predict(out->method[i], &v, fig);
  }
  snprintf(out->figures, sizeof out->figures, "T=%.0f S=%.0f A=%.0f R=%.0f U=%.0f D=%.3g F=%.0f", v.tris,
           v.setups, v.area, v.edges, v.whole, depth, v.front);
  return RR_OK;
}

/* ---- the choice ----------------------------------------------------------- */

/* The model is unsure when another candidate is predicted within this factor of the
 * best: its predictions miss by up to ±50% on the views it was fitted to. */
#define AUTO_MARGIN 1.5

/* The options of a trial: half the resolution in each direction (a cube map keeps
 * its 4:3 faces), no extras. */
rr_render_options rr_auto_trial_options(const rr_camera *cam, const rr_render_options *opt) {
  rr_render_options t = *opt;
  t.width = opt->width > 1 ? opt->width / 2 : 1, t.height = opt->height > 1 ? opt->height / 2 : 1;
  if (cam->type == RR_CAMERA_CUBE) t.width = t.height / 3 * 4, t.height = t.height / 3 * 3;
  if (t.height < 3) t = *opt;
  t.heat = 0, t.oracles = NULL, t.frames_hint = 1;
  return t;
}

rr_error rr_auto_choose(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                        auto_prediction *pred, rr_method near[AUTO_NCAND], int *close, bool *repays) {
  rr_error e = rr_auto_predict(dev, scene, cam, opt, pred);
  if (e) return e;
  const auto_prediction p = *pred;
  int b = 0;
  for (int i = 1; i < AUTO_NCAND; i++)
    if (p.ms[i] < p.ms[b]) b = i;
  /* A candidate predicted r times the best may really be faster, by up to
   * best · (1 − r / margin) a frame: the most a trial can save. It costs its rounds
   * of every close candidate at the trial's size, predicted by the same model. */
  near[0] = p.method[b], *close = 1;
  double save = 0;
  for (int i = 0; i < AUTO_NCAND; i++) {
    double gain = p.ms[b] * (1 - p.ms[i] / (AUTO_MARGIN * p.ms[b]));
    if (i == b || !(gain > 0)) continue;
    near[(*close)++] = p.method[i];
    if (gain > save) save = gain;
  }
  *repays = false;
  int frames = opt->frames_hint > 1 ? opt->frames_hint : 1;
  if (*close > 1 && frames > 1) {
    rr_render_options t = rr_auto_trial_options(cam, opt);
    auto_prediction small;
    if ((e = rr_auto_predict(dev, scene, cam, &t, &small))) return e;
    double cost = 0;
    for (int i = 0; i < AUTO_NCAND; i++)
      for (int k = 0; k < *close; k++)
        if (small.method[i] == near[k]) cost += AUTO_TRIAL_ROUNDS * small.ms[i];
    *repays = frames * save > cost;
  }
  return RR_OK;
}

