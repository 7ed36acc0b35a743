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
