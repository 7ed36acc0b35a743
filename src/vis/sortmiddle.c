/* The sort-middle driver (vis/sortmiddle.h): batches, setup jobs, bands. */
#include "vis/sortmiddle.h"

/* Sets up chunk k of the batch and works out once which blocks each primitive
 * meets, so that the bands only compare (one band has nothing to work out). */
static void setup_chunk(int k, int thread, void *arg) {
  sortmiddle *sm = arg;
  uint32_t first = sm->first + (uint32_t)k * sm->chunk, end = sm->first + sm->count;
  uint32_t n = end - first < sm->chunk ? end - first : sm->chunk;
  size_t at = (size_t)k * sm->chunk * sm->out_max;
  char *prims = sm->prims + at * sm->size;
  uint32_t kept = sm->setup(sm->arg, thread, first, n, prims);
  for (uint32_t q = 0; q < kept && sm->bands > 1; q++) {
    sm_span *s = &sm->span[at + q];
    sm->rows(prims + q * sm->size, &s->first, &s->last);
    s->first /= sm->block_rows, s->last /= sm->block_rows, s->band = s->first % sm->bands;
  }
  sm->kept[k] = kept;
}

bool rr_sortmiddle(sortmiddle *sm, uint32_t n, int height, int align, int threads) {
  size_t cap = (size_t)sm->batch * sm->out_max;
  rr_buf prims = rr_scratch_take(sm->dev, SCRATCH_SM_PRIMS, cap * sm->size);
  rr_buf span = rr_scratch_take(sm->dev, SCRATCH_SM_SPANS, cap * sizeof *sm->span);
  sm->prims = prims.p, sm->span = span.p;
  sm->kept = malloc((sm->batch + sm->chunk - 1) / sm->chunk * sizeof *sm->kept);
  bool ok = sm->prims && sm->span && sm->kept;
  /* blocks of whole z-buffer blocks and bins: long runs of a band's primitives lie
   * together in the batch (few straddle two blocks); 4 bands a thread deal the
   * work out finely enough */
  sm->bands = threads > 1 ? 4 * threads : 1;
  sm->block_rows = threads > 1 ? align : height;
  sm->height = height;
  for (uint32_t first = 0; ok && first < n; first += sm->batch) {
    sm->first = first, sm->count = n - first < sm->batch ? n - first : sm->batch;
    rr_parallel_for((int)((sm->count + sm->chunk - 1) / sm->chunk), threads, setup_chunk, sm);
    progress_span part = sm->progress ? rr_progress_part(sm->progress, (double)first / n, (double)(first + sm->count) / n)
                                      : (progress_span){0};
    rr_parallel_for_progress(sm->bands, threads, sm->band, sm, &part);
  }
  rr_scratch_give(sm->dev, prims), rr_scratch_give(sm->dev, span), free(sm->kept);
  sm->prims = NULL, sm->span = NULL, sm->kept = NULL;
  return ok;
}
