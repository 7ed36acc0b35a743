/* The sort-middle driver (vis/sortmiddle.h): batches, setup jobs, bands. */
#include "vis/sortmiddle.h"

#include <string.h>

/* Sets up chunk k of batch sm->set and works out once which blocks each primitive
 * meets, so that the bands only compare (one band has nothing to work out). */
static void setup_chunk(int k, int thread, sortmiddle *sm) {
  sm_batch *b = &sm->set;
  uint32_t first = b->first + (uint32_t)k * sm->chunk, end = b->first + b->count;
  uint32_t n = end - first < sm->chunk ? end - first : sm->chunk;
  size_t at = (size_t)k * sm->chunk * sm->out_max;
  char *prims = b->prims + at * sm->size;
  uint32_t kept = sm->setup(sm->arg, thread, first, n, prims);
  b->kept[k] = kept;
  if (sm->bands == 1) return;
  /* the bands' lists (sm_batch.order), by a counting sort: group g < bands holds
   * the primitives of one block of band g, group `bands` those of several */
  const int bands = sm->bands;
  uint16_t *start = b->start + (size_t)k * (bands + 2), *order = b->order + at;
  memset(start, 0, (bands + 2) * sizeof *start);
  for (uint32_t q = 0; q < kept; q++) {
    sm_span *s = &b->span[at + q];
    sm->rows(prims + q * sm->size, &s->first, &s->last);
    s->first /= sm->block_rows, s->last /= sm->block_rows, s->band = s->first % bands;
    start[(s->first == s->last ? s->band : bands) + 1]++;
  }
  for (int g = 1; g < bands + 2; g++) start[g] += start[g - 1];
  uint16_t at_group[SM_BANDS_MAX + 1];
  memcpy(at_group, start, (bands + 1) * sizeof *start);
  for (uint32_t q = 0; q < kept; q++) {
    const sm_span *s = &b->span[at + q];
    order[at_group[s->first == s->last ? s->band : bands]++] = (uint16_t)q;
  }
}

static int nchunks(const sortmiddle *sm, const sm_batch *b) { return (int)((b->count + sm->chunk - 1) / sm->chunk); }

/* One loop's jobs: the bands of batch sm->draw first (the larger jobs, dealt out
 * first), then the setup chunks of batch sm->set, which fill the threads' time
 * while the last bands finish. */
static void batch_job(int job, int thread, void *arg) {
  sortmiddle *sm = arg;
  const int bands = sm->draw.count ? sm->bands : 0;
  if (job < bands) sm->band(job, thread, sm);
  else setup_chunk(job - bands, thread, sm);
}

/* One loop: the bands of sm->draw and the setup chunks of sm->set (either may be empty). */
static void run_loop(sortmiddle *sm, uint32_t n, int threads) {
  const sm_batch *d = &sm->draw;
  const int draws = d->count ? sm->bands : 0, jobs = draws + nchunks(sm, &sm->set);
  /* progress: by the batch being drawn */
  progress_span part = sm->progress && draws ? rr_progress_part(sm->progress, (double)d->first / n,
                                                                (double)(d->first + d->count) / n)
                                             : (progress_span){0};
  rr_parallel_for_progress(jobs, threads, batch_job, sm, draws ? &part : NULL);
}

bool rr_sortmiddle(sortmiddle *sm, uint32_t n, int height, int align, int threads) {
  /* On several threads, two batches in flight, one drawn while the next is set up:
   * the loop that draws a batch has no tail in which a thread waits for another's
   * last band. One thread draws each batch right after its setup, while it is in
   * cache. */
  const bool pipe = threads > 1 && n > sm->batch;
  const int nbuf = pipe ? 2 : 1;
  const size_t cap = (size_t)sm->batch * sm->out_max, nk = (sm->batch + sm->chunk - 1) / sm->chunk;
  rr_buf prims = rr_scratch_take(sm->dev, SCRATCH_SM_PRIMS, nbuf * cap * sm->size);
  rr_buf span = rr_scratch_take(sm->dev, SCRATCH_SM_SPANS, nbuf * cap * sizeof(sm_span));
  uint32_t *kept = malloc(nbuf * nk * sizeof *kept);
  const int bands = threads > 1 ? 4 * threads : 1;
  uint16_t *order = bands > 1 ? malloc(nbuf * cap * sizeof *order) : NULL;
  uint16_t *start = bands > 1 ? malloc(nbuf * nk * (bands + 2) * sizeof *start) : NULL;
  bool ok = prims.p && span.p && kept && (bands == 1 || (order && start));
  /* blocks of whole z-buffer blocks and bins: long runs of a band's primitives lie
   * together in the batch (few straddle two blocks); 4 bands a thread deal the
   * work out finely enough */
  sm->bands = bands;
  sm->block_rows = threads > 1 ? align : height;
  sm->height = height;
  sm->draw = (sm_batch){0};
  for (uint32_t first = 0, k = 0; ok && (first < n || sm->draw.count); first += sm->batch, k++) {
    const int buf = (int)(k % (uint32_t)nbuf);
    sm->set = (sm_batch){.first = first,
                         .count = first >= n ? 0 : n - first < sm->batch ? n - first : sm->batch,
                         .prims = (char *)prims.p + buf * cap * sm->size,
                         .span = (sm_span *)span.p + buf * cap,
                         .kept = kept + buf * nk,
                         .order = order ? order + buf * cap : NULL,
                         .start = start ? start + buf * nk * (bands + 2) : NULL};
    run_loop(sm, n, threads);
    sm->draw = sm->set;
    if (!pipe && sm->draw.count) { /* drawn now, from the one buffer */
      sm->set = (sm_batch){0};
      run_loop(sm, n, threads);
      sm->draw = (sm_batch){0};
    }
  }
  rr_scratch_give(sm->dev, prims), rr_scratch_give(sm->dev, span), free(kept), free(order), free(start);
  sm->draw = sm->set = (sm_batch){0};
  return ok;
}
