/* Sort-middle rasterization on any number of threads, the driver of 2dr-bb, 2dr-bin
 * and of 3dr-bb and 3dr-bin (generateSamples at the root): a batch of primitives is
 * set up in parallel chunks, then drawn in parallel bands of rows while the next
 * batch is set up (one loop of both kinds of job: the short setup jobs fill the
 * time in which a thread would wait for another's last band).
 *
 * The image is cut into blocks of rows dealt out round robin: band b draws the
 * blocks k with k % bands == b. A block is whole z-buffer blocks and top-level bins,
 * so no sample, depth block or bin has two writers, and within a block the
 * primitives are drawn in batch order: bits and stats do not depend on the thread
 * count. Each primitive is set up once, so S does not either. */
#ifndef RR_VIS_SORTMIDDLE_H
#define RR_VIS_SORTMIDDLE_H

#include "core/core.h"

/* The most set-up primitives a chunk may hold, chunk × out_max (a band lists them
 * by 16-bit index). */
#define SM_CHUNK_MAX 16384
#define SM_BANDS_MAX (4 * RR_MAX_THREADS)

/* The blocks of rows a set-up primitive meets, first to last, and the first's band. */
typedef struct sm_span {
  int first, last, band;
} sm_span;

/* A batch of primitives: first..first+count-1, set up by chunks. */
typedef struct sm_batch {
  uint32_t first, count;
  char *prims;          /* chunk k's set-up primitives from prims + k × chunk × out_max × size, */
  sm_span *span;        /* their spans from the same index, */
  uint32_t *kept;       /* and kept[k] of them; on several bands, */
  uint16_t *order;      /* chunk k's kept primitives (indices in the chunk) from order + k × chunk ×
                         * out_max, grouped: those meeting one block by band, then those meeting
                         * several, each group in batch order; */
  uint16_t *start;      /* where each group starts, bands + 2 a chunk from start + k × (bands + 2) */
} sm_batch;

typedef struct sortmiddle sortmiddle;
struct sortmiddle {
  /* Filled by the method. */
  void *arg;            /* the method's pass */
  size_t size;          /* bytes of a set-up primitive */
  uint32_t batch;       /* primitives set up before any is drawn */
  uint32_t chunk;       /* primitives a setup job takes */
  uint32_t out_max;     /* set-up primitives one primitive may yield (clipping) */
  /* Sets up primitives first..first+n-1 into out (room for n × out_max); returns
   * how many were kept. On `thread`, for per-thread stats. */
  uint32_t (*setup)(void *arg, int thread, uint32_t first, uint32_t n, void *out);
  /* The first and last row of samples a set-up primitive may cover. */
  void (*rows)(const void *prim, int *y0, int *y1);
  /* Draws band `job` of the batch in this struct (arg), with sm_draw_band. */
  rr_parallel_fn band;
  const progress_span *progress; /* the pass's, reported batch by batch and band by band; NULL: none */
  rr_device *dev;       /* keeps the batch's buffers for the next pass (rr_scratch_take); NULL: fresh ones */
  /* Filled by rr_sortmiddle: the blocks, the batch being drawn and the next one,
   * set up meanwhile (in a buffer of its own). */
  int bands, block_rows, height;
  sm_batch draw, set;
};

/* Runs the pass over primitives 0..n-1 of an image `height` rows high, on `threads`
 * threads. Blocks are `align` rows (a multiple of every block a band must own
 * alone), four bands a thread; one band of the whole image on one thread. Returns
 * false when out of memory. */
bool rr_sortmiddle(sortmiddle *sm, uint32_t n, int height, int align, int threads);

/* Draws band b of the current batch: draw(state, prim, y0, y1) for every set-up
 * primitive and every block of the band it meets, rows [y0, y1) of the block, in
 * batch order. Inlined with the method's own draw, so the hot loop has no calls. */
KERNEL void sm_draw_band(const sortmiddle *sm, int b, void *state,
                         void (*draw)(void *state, const void *prim, int y0, int y1)) {
  const sm_batch *bt = &sm->draw;
  uint32_t cap = sm->chunk * sm->out_max;
  int nchunks = (int)((bt->count + sm->chunk - 1) / sm->chunk);
  if (sm->bands == 1) { /* one thread: every primitive meets the one block, in order */
    for (int k = 0; k < nchunks; k++)
      for (uint32_t q = 0; q < bt->kept[k]; q++) draw(state, bt->prims + ((size_t)k * cap + q) * sm->size, 0, sm->height);
    return;
  }
  const int rows = sm->block_rows, height = sm->height, bands = sm->bands;
  for (int k = 0; k < nchunks; k++) {
    const char *prims = bt->prims + (size_t)k * cap * sm->size;
    const sm_span *span = bt->span + (size_t)k * cap;
    /* The band's primitives of one block and those of several, two lists in batch
     * order (sm_batch.order), merged; each fetched a few ahead of its drawing (the
     * lists are scattered through the chunk, often in another core's cache). */
    const uint16_t *order = bt->order + (size_t)k * cap, *start = bt->start + (size_t)k * (bands + 2);
    const uint16_t *one = order + start[b], *one_end = order + start[b + 1];
    const uint16_t *wide = order + start[bands], *wide_end = order + start[bands + 1];
    while (one < one_end || wide < wide_end) {
      if (wide == wide_end || (one < one_end && *one < *wide)) {
        if (one + 6 < one_end) {
          const char *ahead = prims + (size_t)one[6] * sm->size;
          __builtin_prefetch(ahead), __builtin_prefetch(ahead + 64);
        }
        const int q = *one++, blk = span[q].first;
        draw(state, prims + (size_t)q * sm->size, blk * rows, (blk + 1) * rows < height ? (blk + 1) * rows : height);
      } else {
        const int q = *wide++;
        int s = b - span[q].band; /* blocks from its first to band b's first */
        if (s < 0) s += bands;
        for (int blk = span[q].first + s; blk <= span[q].last; blk += bands)
          draw(state, prims + (size_t)q * sm->size, blk * rows, (blk + 1) * rows < height ? (blk + 1) * rows : height);
      }
    }
  }
}

#endif
