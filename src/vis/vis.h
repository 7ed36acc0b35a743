/* Visibility: the visibility buffer, the methods of the continuum and their shared kernels. */
#ifndef RR_VIS_H
#define RR_VIS_H

#include "accel/bvh.h"
#include "prim/analytic.h"
#include "prim/triangle.h"

/* Per sample: the hit's triangle index, t and barycentrics. A buffer of several
 * samples per pixel keeps a pixel's samples side by side (ns of them): sample s of
 * pixel k at k·ns + s, so a pixel's samples share cache lines and vectors. A layer
 * (visbuf_layer: one sample of every pixel) is a view of the same arrays, its
 * pixel k at k·ns. */
typedef struct visbuf {
  int width, height;
  uint32_t *id;
  float *t, *l1, *l2;
  int ns; /* the stride between pixels: samples per pixel of the buffer (1: one sample) */
} visbuf;

/* Layer s of a buffer of several samples: sample s of every pixel, pixel k at
 * k·ns (arrays the buffer lacks stay NULL). */
static inline visbuf visbuf_layer(const visbuf *vb, int s) {
  return (visbuf){vb->width, vb->height, vb->id ? vb->id + s : NULL, vb->t ? vb->t + s : NULL,
                  vb->l1 ? vb->l1 + s : NULL, vb->l2 ? vb->l2 + s : NULL, vb->ns};
}

/* The depth test shared by every method: nearer wins; on equal t the lower id wins,
 * so the result does not depend on the order in which triangles are visited. */
static inline bool depth_wins(float t, uint32_t id, float best_t, uint32_t best_id) {
  return t < best_t || (t == best_t && id < best_id);
}

/* Tests one set-up triangle at element k of vb (a layer's pixel p: k = p·ns),
 * whose sample is (sx, sy) with evaluation vector w, and keeps it when it is nearer. Returns 0 when the triangle does not
 * cover the sample, 1 when it covers it behind what is stored, 2 when it is kept. */
KERNEL int shade_sample_w(const tri_setup *ts, uint32_t id, vec3 w, float sx, float sy, visbuf *vb, size_t k) {
  float e[3], t, l1, l2;
  tri_edges_w(ts, w, e);
  if (!sample_test_w(e, ts->w, ts->tie, tri_vol(ts, sx, sy), tri_num(ts, sx, sy), tri_den_w(ts, w), &t, &l1, &l2))
    return 0;
  if (!depth_wins(t, id, vb->t[k], vb->id[k])) return 1;
  vb->t[k] = t;
  vb->id[k] = id;
  vb->l1[k] = l1;
  vb->l2[k] = l2;
  return 2;
}

/* The same for analytic primitive id (prim/analytic.h) of scene s seen by camera c:
 * the sample's ray in double, the kind's one test, the same depth test. */
KERNEL int ana_shade_sample(const rr_scene *s, const camera *c, uint32_t id, vec3 w, float sx, float sy, visbuf *vb,
                            size_t k) {
  ana_ray r;
  float t, u, v;
  if (!ana_sample_ray(c, w, sx, sy, &r) || !rr_ana_hit(s, id, &r, &t, &u, &v)) return 0;
  if (!depth_wins(t, id, vb->t[k], vb->id[k])) return 1;
  vb->t[k] = t;
  vb->id[k] = id;
  vb->l1[k] = u;
  vb->l2[k] = v;
  return 2;
}

/* Heat maps (per-pixel E and N; heat is NULL when none is kept): spreads `amount`
 * evenly over the samples [x0, x1) × [y0, y1). */
KERNEL void heat_charge(float *heat, int width, int x0, int y0, int x1, int y1, float amount) {
  if (!heat) return;
  float each = amount / (float)((x1 - x0) * (y1 - y0));
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) heat[(size_t)y * width + x] += each;
}

/* The same for a bin's corner test: one evaluation at each corner sample. */
KERNEL void heat_charge_corners(float *heat, int width, int x0, int y0, int x1, int y1) {
  if (!heat) return;
  heat[(size_t)y0 * width + x0] += 1, heat[(size_t)y0 * width + x1 - 1] += 1;
  heat[(size_t)(y1 - 1) * width + x0] += 1, heat[(size_t)(y1 - 1) * width + x1 - 1] += 1;
}

struct rr_frame {
  visbuf vb; /* triangle indices (scene.h), which shading reads the scene's arrays by */
  uint32_t *ids; /* vb's hits as ids, when the scene's ids differ from its indices (else NULL) */
  float *heat_e, *heat_n; /* per-pixel E and N, when options.heat was set */
  rr_stats stats;
  rr_method method;
  int samples; /* vb holds this many samples a pixel (vb.ns) */
  float sample_pos[RR_MAX_SAMPLES][2]; /* options.sample_pos: where sample s of each pixel lies */
  rr_aa_mode aa;                       /* how shading uses them (options.aa, aa_stored) */
  int aa_stored;
};

/* A pass of a method: fills vb (cleared to misses) and adds to stats. A method that
 * takes every sample position in one pass (all_samples in render.c's table) gets
 * samples > 1 cameras, cams[s] resolved for position s, and writes sample s of each
 * pixel of vb; any other method runs once per position with samples = 1 and a
 * buffer of one sample (render.c copies it into that sample of vb). */
typedef struct render_ctx {
  const rr_scene *scene;
  const camera *cam;  /* cams[0] */
  const camera *cams; /* one per sample position */
  int samples;
  const rr_render_options *opt;
  int threads;
  visbuf *vb;
  rr_stats *stats;
  float *heat_e, *heat_n; /* optional per-pixel E and N charges */
  const struct oracles *oracles; /* the traversal's settings, for the 3dr methods */
  progress_span progress;        /* this pass's share of the frame's progress: for its main loop */
  /* A cube camera drawn in one pass (render.c, rr_vis_traverse): its 6 faces, else 0;
   * face f at position s is the perspective camera face_cams[f·samples + s], drawn
   * into face_vb[f] (F × F pixels of samples each) and charging face_heat_e/n + f·F². */
  int faces;
  const camera *face_cams;
  visbuf *face_vb;
  float *face_heat_e, *face_heat_n;
} render_ctx;

/* The oracles of the continuum's traversal (paper Fig. 8), as settings. */
typedef struct oracles {
  int frustum_size;  /* side of the initial frusta; 0: whole image (tiles on several threads) */
  bool leaves;       /* generateSamples at BVH leaves (false: at the root, plain rasterization) */
  bool cull_outside; /* isOutside: frustum culling of BVH nodes */
  bool cull_occluded;/* isOccluded: hierarchical z-buffer test of BVH nodes */
  int split_min;     /* splitFrustum down to this side (0: never split) */
  float split_ratio; /* split when a node's projected area is below ratio × the frustum's */
  bool binning;      /* rasterize hierarchically in bins rather than every sample of the bounds */
  bool early_z;      /* reject bins hidden behind the stored depths */
  int bin_size;      /* top bin side */
  int bin_min;       /* bins this small are tested sample by sample */
} oracles;

/* The continuum's one traversal, steered by ctx->oracles (vis/traverse.c). */
rr_error rr_vis_traverse(rr_device *dev, render_ctx *ctx);
/* isOutside: may the box be culled from the frustum of samples [x0, x1) × [y0, y1)? */
bool rr_oracle_outside(const camera *c, int x0, int y0, int x1, int y1, const bvh_node *box);
/* isOccluded: may the box be culled when the farthest depth stored in a frustum is `farthest`? */
bool rr_oracle_occluded(const camera *c, const bvh_node *box, float farthest);

/* The model itself, for bench_auto: the candidate methods for a view (exact, able to
 * draw its camera), each one's predicted milliseconds, and the figures behind them
 * (per sample position; predicted ns = sum of figure × cost, see auto.c): T, S, A,
 * R, U·P, P, P·log₂T, S/D (the setups of the front layer, D the depth complexity),
 * F (the setups a front-to-back pass leaves) and 1 (a frame's fixed cost). */
enum { AUTO_NCAND = 5 };
enum { AUTO_T, AUTO_S, AUTO_A, AUTO_R, AUTO_UP, AUTO_P, AUTO_PLOGT, AUTO_SD, AUTO_F, AUTO_ONE, AUTO_NFIG };
typedef struct auto_prediction {
  rr_method method[AUTO_NCAND];
  double ms[AUTO_NCAND];
  double fig[AUTO_NFIG];
  double depth; /* D: how many rectangles cover a covered sample, on average (1 on curved views) */
  bool planar;
  char figures[128]; /* "T=... S=... A=... R=... U=... D=... F=..." */
} auto_prediction;
rr_error rr_auto_predict(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                         auto_prediction *out);
/* Which figures a method's cost may use (bit f for figure f), for fitting the costs. */
unsigned rr_auto_uses(rr_method m, rr_camera_type type);
/* auto's choice for a view (render.c renders it): near[0] the model's pick, near[1..
 * *close-1] the candidates it is unsure of; *repays whether a trial among them
 * (AUTO_TRIAL_ROUNDS interleaved rounds at rr_auto_trial_options' size) repays its
 * cost over opt->frames_hint frames; *pred the predictions behind it. */
enum { AUTO_WHY = sizeof ((rr_stats *)0)->why, AUTO_TRIAL_ROUNDS = 3 /* the median of three ignores one spoiled round */ };
rr_error rr_auto_choose(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                        auto_prediction *pred, rr_method near[AUTO_NCAND], int *close, bool *repays);
rr_render_options rr_auto_trial_options(const rr_camera *cam, const rr_render_options *opt);
extern const char *const rr_auto_fig_names[AUTO_NFIG];
/* The gain of a further thread in use for method m (bench_auto --keep-gains). */
double rr_auto_thread_gain(rr_method m);

typedef rr_error (*vis_method_fn)(rr_device *dev, render_ctx *ctx);

rr_error rr_vis_rc(rr_device *dev, render_ctx *ctx);
/* rc-bvh and rc-packet: single rays and 8x8 ray packets through the BVH (vis/rc_bvh.c). */
rr_error rr_vis_rc_bvh(rr_device *dev, render_ctx *ctx);
rr_error rr_vis_rc_packet(rr_device *dev, render_ctx *ctx);
/* 2dr-bb and 2dr-bin: projection, clipping, fixed-point 2D edge functions (vis/raster2d.c). */
rr_error rr_vis_2dr_bb(rr_device *dev, render_ctx *ctx);
rr_error rr_vis_2dr_bin(rr_device *dev, render_ctx *ctx);
/* Test hook: runs the 2D pipeline (binning when `bin`) over every triangle at the
 * `samples` positions of cams[] but, instead of the z test, counts in front[k] /
 * back[k] every triangle that claims sample k (a layer per position: sample s of
 * pixel p at s·width·height + p). */
rr_error rr_raster2d_claims(const rr_scene *s, const camera *cams, int samples, bool bin, int threads, uint8_t *front,
                            uint8_t *back);
/* Test hook: where the 2D pipeline's vertex stage puts world point p on the screen;
 * false when p is behind its near plane. */
bool rr_raster2d_project(const rr_scene *s, const camera *c, vec3 p, double *sx, double *sy);
/* Tests every sample of an inclusive rectangle against one set-up triangle and
 * returns the number of edge-function evaluations; adds the samples the
 * triangle covers to *covered. simd: use AVX2 where the processor has it. vb: a
 * buffer of one sample per pixel (ns = 1). */
uint64_t rr_raster_rect(const tri_setup *ts, uint32_t id, const int rect[4], const camera *c, visbuf *vb,
                        uint64_t *covered, bool simd);

/* A triangle at several sample positions. The caller says how it moves: the
 * positions' offsets ox, oy (the cameras' sx0, sy0, padded to RR_MAX_SAMPLES with
 * the first), the rectangle `draw` it is drawn into (inclusive) and, for a planar
 * camera, pl (rr_tri_setup_at) with the bounds' union bb and bits pos
 * (tri_pos_rect); pl NULL: a curved camera, every position as ts over bb. What
 * follows from that, by component for the lanes, is made on demand (ready, by
 * rr_tri_moves_ready): for each position s the setup values that move with it
 * (pa, num0, cx, cy) and its own rectangle (x0 = r[0][s] .. x1 = r[2][s], y0 =
 * r[1][s] .. y1 = r[3][s]); live bit s: that rectangle meets draw. A position
 * not live has an empty rectangle and tests none. A triangle of a few pixels
 * needs none of it: the kernel takes each position's rectangle from the bits and
 * moves the setup in its lanes at the first hit. */
typedef struct tri_moves {
  const float *ox, *oy;
  const tri_plane *pl;
  const tri_pos_bits *pos;
  const int *bb;
  int draw[4];
  bool ready;
  uint32_t live;
  float pa[RR_MAX_SAMPLES], num0[RR_MAX_SAMPLES], cx[RR_MAX_SAMPLES], cy[RR_MAX_SAMPLES];
  int32_t r[4][RR_MAX_SAMPLES];
} tri_moves;
/* Makes mv's per-position values for ts at the ns positions of cams (once). */
void rr_tri_moves_ready(const tri_setup *ts, tri_moves *mv, const camera *cams, int ns, bool simd);
/* rr_raster_rect at ns sample positions at once: each position over rect ∩ its
 * rectangle, with cams[s] and sample s of each pixel of vb (vb->ns = ns).
 * Returns the evaluations, one per sample of those rectangles. */
uint64_t rr_raster_rect_samples(const tri_setup *ts, tri_moves *mv, uint32_t id, const int rect[4],
                                const camera *cams, int ns, visbuf *vb, uint64_t *covered, bool simd);

/* Is the draw r (inclusive) at ns positions small enough for the lanes over
 * (position, pixel) pairs (planar cameras)? rr_raster_rect_samples' choice. */
static inline bool rr_raster_few_pixels(const int r[4], int ns) {
  const int w = r[2] - r[0] + 1, area = w * (r[3] - r[1] + 1);
  return ns <= 4 ? area <= 4 * ns || w <= 8 : area <= 2 * ns;
}
/* rr_raster_rect_samples for such a draw, called straight from the traversal
 * (planar camera c = cams[0]; mv needs only ox, oy, pl, pos and bb; avx2: the
 * eight-lane kernel, which the caller has checked the CPU runs). Returns the
 * evaluations; adds the covered samples to *covered. */
uint64_t rr_raster_pixels(const tri_setup *ts, const tri_moves *mv, uint32_t id, const int rect[4],
                          const camera *c, int ns, visbuf *vb, uint64_t *covered, bool avx2);
/* Its kernel, picked once a frame so that a draw calls it without the wrapper:
 * adds the evaluations to *tested and returns the covered samples. */
typedef uint64_t (*rr_pixels_kernel)(const tri_setup *ts, const tri_moves *mv, uint32_t id, const int rect[4],
                                     const camera *c, int ns, visbuf *vb, uint64_t *tested);
rr_pixels_kernel rr_raster_pixels_kernel(bool avx2);

/* Test and benchmark hook: the relative error of depths t (one per sample of the
 * planar camera c's image; ids: the hit triangle, RR_MISS for none) against the
 * exact hit of each sample's ray (from c's own d0, dx, dy or o0, ox, oy, in double)
 * with the plane of the triangle it hit, rays within |cos| < 1e-3 of the plane
 * aside: n of them, median, 99.9th percentile, maximum and the sample holding it.
 * False when c is not planar or memory runs out. */
typedef struct {
  int n, worst;
  double p50, p999, max;
} rr_depth_stats;
bool rr_depth_errors(const rr_scene *s, const camera *c, const uint32_t *ids, const float *t, rr_depth_stats *out);

#endif
