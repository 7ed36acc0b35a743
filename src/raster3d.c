/* 3dr-bb: 3D rasterization, every triangle × the samples of its screen bounding
 * box (paper sect. 5). A triangle that crosses the eye plane has no bounded
 * projection and is tested over the whole screen; 3D edge functions need no
 * clipping for that. */
#include "rr.h"

/* Samples a set-up triangle may cover, as an inclusive pixel rectangle. Returns
 * false when it covers none. Projected bounds get a one-pixel margin so rounding
 * in the edge functions can never put a hit outside the box. */
bool tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, int r[4]) {
  float x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  int behind = 0, projected = 0;
  for (int k = 0; k < 3; k++) {
    vec3 q = v3_sub(scene_vertex(s, k, i), c->eye);
    float sx, sy;
    if (!(v3_dot(q, c->fwd) > 0)) behind++;
    else if (camera_project(c, q, &sx, &sy) && isfinite(sx) && isfinite(sy)) {
      projected++;
      x0 = fminf(x0, sx), x1 = fmaxf(x1, sx), y0 = fminf(y0, sy), y1 = fmaxf(y1, sy);
    }
  }
  if (behind == 3) return false; /* every camera ray has d·fwd > 0: unreachable */
  if (projected == 3) {
    /* Sample (x + 0.5) lies in [x0, x1] for x in [ceil(x0 - 0.5), floor(x1 - 0.5)]. */
    float m = 1.0f;
    float lx = fmaxf(ceilf(x0 - 0.5f - m), 0.0f), hx = fminf(floorf(x1 - 0.5f + m), (float)(c->width - 1));
    float ly = fmaxf(ceilf(y0 - 0.5f - m), 0.0f), hy = fminf(floorf(y1 - 0.5f + m), (float)(c->height - 1));
    if (lx > hx || ly > hy) return false;
    r[0] = (int)lx, r[1] = (int)ly, r[2] = (int)hx, r[3] = (int)hy;
    return true;
  }
  r[0] = 0, r[1] = 0, r[2] = c->width - 1, r[3] = c->height - 1;
  return true;
}

/* Tests every sample of rectangle r against one triangle; returns the evaluations. */
uint64_t raster_rect(const tri_setup *ts, uint32_t id, const int r[4], visbuf *vb) {
  for (int y = r[1]; y <= r[3]; y++) {
    float sy = (float)y + 0.5f;
    size_t row = (size_t)y * vb->width;
    for (int x = r[0]; x <= r[2]; x++) shade_sample(ts, id, (float)x + 0.5f, sy, vb, row + x);
  }
  return (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
}

typedef struct {
  tri_setup ts;
  int rect[4];
  uint32_t id;
} bb_tri;

typedef struct {
  render_ctx *ctx;
  const bb_tri *tris;
  uint32_t n;
  int band_rows;
  uint64_t evals[256];
} bb_job;

/* One horizontal band of the image: its own rows, so no sample has two writers. */
static void bb_band(int band, int thread, void *arg) {
  bb_job *job = arg;
  int y0 = band * job->band_rows, y1 = y0 + job->band_rows - 1;
  if (y1 >= job->ctx->vb->height) y1 = job->ctx->vb->height - 1;
  uint64_t e = 0;
  for (uint32_t j = 0; j < job->n; j++) {
    const bb_tri *t = &job->tris[j];
    int r[4] = {t->rect[0], t->rect[1] > y0 ? t->rect[1] : y0, t->rect[2], t->rect[3] < y1 ? t->rect[3] : y1};
    if (r[1] <= r[3]) e += raster_rect(&t->ts, t->id, r, job->ctx->vb);
  }
  job->evals[thread] += e;
}

rr_error vis_3dr_bb(rr_device *dev, render_ctx *ctx) {
  const rr_scene *s = ctx->scene;
  const camera *c = ctx->cam;
  ctx->stats->setups += s->ntris;
  if (ctx->threads <= 1) {
    /* One thread: set up and rasterize each triangle in turn, nothing stored. */
    uint64_t e = 0;
    for (uint32_t i = 0; i < s->ntris; i++) {
      tri_setup ts;
      int r[4];
      if (tri_setup_planar(s, i, c, ctx->opt->cull_backfaces, &ts) == SETUP_CULLED) continue;
      if (tri_screen_bounds(s, i, c, r)) e += raster_rect(&ts, i, r, ctx->vb);
    }
    ctx->stats->edge_evals += e;
    return RR_OK;
  }
  bb_tri *tris = malloc((size_t)s->ntris * sizeof *tris + 1);
  if (!tris) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %u triangle setups", s->ntris);
  uint32_t n = 0;
  for (uint32_t i = 0; i < s->ntris; i++) {
    bb_tri *t = &tris[n];
    if (tri_setup_planar(s, i, c, ctx->opt->cull_backfaces, &t->ts) == SETUP_CULLED) continue;
    if (!tri_screen_bounds(s, i, c, t->rect)) continue;
    t->id = i;
    n++;
  }
  bb_job job = {.ctx = ctx, .tris = tris, .n = n};
  int bands = ctx->threads * 4;
  job.band_rows = (c->height + bands - 1) / bands;
  bands = (c->height + job.band_rows - 1) / job.band_rows;
  parallel_for(bands, ctx->threads, bb_band, &job);
  for (int t = 0; t < 256; t++) ctx->stats->edge_evals += job.evals[t];
  free(tris);
  return RR_OK;
}
