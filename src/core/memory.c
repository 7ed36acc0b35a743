/* Large buffers (a frame's per-sample arrays) in huge pages where the system gives
 * them on request: each fresh 4 KiB page costs a fault, and a 1024² frame of 16
 * samples holds 256 MB of visibility and 200 MB of colour. free() releases them. */
#define _DEFAULT_SOURCE /* madvise */
#include "core/core.h"

#include <stdlib.h>
#include <sys/mman.h>

void *rr_alloc_large(size_t bytes) {
  enum { HUGE_PAGE = 2 << 20 };
  if (bytes < HUGE_PAGE) return malloc(bytes);
  void *p = NULL;
  if (posix_memalign(&p, HUGE_PAGE, bytes)) return NULL;
#ifdef MADV_HUGEPAGE
  madvise(p, bytes, MADV_HUGEPAGE); /* advice: without it the pages are small */
#endif
  return p;
}

/* 64-byte aligned (cache lines, SIMD rows). Not in huge pages: a frame touches
 * part of its buffer (rc-bvh's setups of the triangles in view), and a huge page
 * zeroes 2 MB at its first touch (the teapot grid's first rc-bvh frame: 30% slower). */
static void *alloc_aligned(size_t bytes) {
  return aligned_alloc(64, (bytes + 64) / 64 * 64); /* a multiple of the alignment, never 0 */
}

rr_buf rr_scratch_take(rr_device *dev, int use, size_t bytes) {
  rr_scratch *s = dev ? &dev->scratch[use] : NULL;
  if (!s || atomic_exchange_explicit(&s->busy, true, memory_order_acquire))
    return (rr_buf){alloc_aligned(bytes), -1};
  if (s->cap < bytes) {
    size_t cap = s->cap + s->cap / 2 > bytes ? s->cap + s->cap / 2 : bytes;
    free(s->p);
    s->p = alloc_aligned(cap), s->cap = s->p ? cap : 0;
    if (!s->p) {
      atomic_store_explicit(&s->busy, false, memory_order_release);
      return (rr_buf){alloc_aligned(bytes), -1}; /* the growth failed: maybe the exact size fits */
    }
  }
  return (rr_buf){s->p, use};
}

void rr_scratch_give(rr_device *dev, rr_buf b) {
  if (b.use < 0) free(b.p);
  else if (b.p) atomic_store_explicit(&dev->scratch[b.use].busy, false, memory_order_release);
}

void rr_scratch_free(rr_device *dev) {
  for (int u = 0; u < SCRATCH_COUNT; u++) free(dev->scratch[u].p), dev->scratch[u].p = NULL, dev->scratch[u].cap = 0;
}
