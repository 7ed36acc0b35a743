/* rc: Durand's loop, every sample × every triangle. The reference method; it
 * calls the same sample test as every other method, in the other loop order. */
#include "vis/vis.h"

typedef struct {
  render_ctx *ctx;
  const tri_setup *setup;
  const uint32_t *ids;
  uint32_t n;
  const uint32_t *ana; /* the analytic primitives, tested with their own test (prim/analytic.h) */
  uint32_t nana;
  uint64_t evals[RR_MAX_THREADS];
} rc_job;

static void rc_row(int y, int thread, void *arg) {
  rc_job *job = arg;
  visbuf *vb = job->ctx->vb;
  const camera *c = job->ctx->cam;
  float sy = (float)y + c->sy0;
  for (int x = 0; x < vb->width; x++) {
    size_t k = (size_t)y * vb->width + x;
    float sx = (float)x + c->sx0;
    vec3 w = camera_w(c, x, y);
    for (uint32_t j = 0; j < job->n; j++) shade_sample_w(&job->setup[j], job->ids[j], w, sx, sy, vb, k);
    for (uint32_t j = 0; j < job->nana; j++) ana_shade_sample(job->ctx->scene, c, job->ana[j], w, sx, sy, vb, k);
  }
  if (job->ctx->heat_e)
    for (int x = 0; x < vb->width; x++) job->ctx->heat_e[(size_t)y * vb->width + x] += (float)(job->n + job->nana);
  job->evals[thread] += (uint64_t)vb->width * (job->n + job->nana);
}

rr_error rr_vis_rc(rr_device *dev, render_ctx *ctx) {
  const rr_scene *s = ctx->scene;
  /* One setup per triangle for the eye, reused by every ray (the paper's
   * "at the cost of additional per-triangle storage"). */
  tri_setup *setup = malloc((size_t)s->ntris * sizeof *setup + 1);
  uint32_t *ids = malloc((size_t)s->ntris * sizeof *ids + 1);
  uint32_t *ana = malloc((size_t)s->ntris * sizeof *ana + 1);
  if (!setup || !ids || !ana) {
    free(setup), free(ids), free(ana);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %u triangle setups", s->ntris);
  }
  uint32_t n = 0, nana = 0;
  for (uint32_t i = 0; i < s->ntris; i++)
    if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) ana[nana++] = i;
    else if (rr_tri_setup(s, i, ctx->cam, ctx->opt->cull_backfaces, &setup[n]) != SETUP_CULLED) ids[n++] = i;
  ctx->stats->setups += s->ntris;
  rc_job job = {.ctx = ctx, .setup = setup, .ids = ids, .n = n, .ana = ana, .nana = nana};
  rr_parallel_for_progress(ctx->vb->height, ctx->threads, rc_row, &job, &ctx->progress);
  for (int t = 0; t < RR_MAX_THREADS; t++) ctx->stats->edge_evals += job.evals[t];
  free(setup), free(ids), free(ana);
  return RR_OK;
}
