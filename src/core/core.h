/* rastray core: devices and errors, threads, the small vector algebra every stage uses. */
#ifndef RR_CORE_H
#define RR_CORE_H

#include "rastray.h"
#include "core/vec.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

/* Hot kernels written once and specialised by their constant arguments. */
#define KERNEL static inline __attribute__((always_inline))

/* The per-frame work buffers a device keeps from one render to the next (see
 * rr_scratch_take), one of each use. */
enum {
  SCRATCH_RC_SETUPS, /* rc-bvh / rc-packet: leaf triangles' setups */
  SCRATCH_RC_SLOTS,  /* rc-bvh / rc-packet: their index by BVH position */
  SCRATCH_RC_BOUNDS, /* rc-bvh / rc-packet: wide nodes' bounds */
  SCRATCH_SM_PRIMS,  /* sort-middle: a batch's set-up primitives */
  SCRATCH_SM_SPANS,  /* sort-middle: their blocks of rows */
  SCRATCH_CUBE,      /* the cube camera: its faces' visibility buffers */
  SCRATCH_EYES,      /* the cube camera drawn by frusta: its triangles' eye parts (tri_eyes) */
  SCRATCH_COUNT
};
typedef struct rr_scratch {
  void *p;
  size_t cap;       /* bytes at p */
  atomic_bool busy; /* taken: another take gets a fresh buffer */
} rr_scratch;

struct rr_device {
  rr_error error;
  char message[512];
  rr_build_options build; /* used by rr_scene_commit; zeros mean defaults */
  rr_import_limits import; /* rr_device_set_import_limits's, when import_set; else the defaults */
  bool import_set;
  int import_hook;         /* tests only: an import_test_hook of io/import_guard.h */
  struct auto_choice {    /* auto's last trial: the same view again reuses its choice */
    const void *scene, *bvh;
    uint32_t ntris;
    rr_camera cam;
    int width, height, threads, cull, scalar;
    int method;
    char why[256];
  } auto_choice;
  rr_progress_fn progress; /* rr_device_set_progress; NULL: none */
  void *progress_user;
  double progress_ms;      /* when it was last told an inner fraction */
  rr_scratch scratch[SCRATCH_COUNT];
};

/* Records a failure in dev (when not NULL) and returns its code. */
rr_error rr_fail(rr_device *dev, rr_error code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Records success. */
rr_error rr_ok(rr_device *dev);

/* The part [lo, hi] of a stage's progress that a pass or loop covers; dev NULL,
 * or a device without a progress function, takes no reports. */
typedef struct progress_span {
  rr_device *dev;
  rr_progress_stage stage;
  double lo, hi;
} progress_span;
/* Reports lo + (hi - lo)·fraction of the span's stage to its device's progress
 * function: the stage's 0 and 1 always, inner fractions at most every
 * RR_PROGRESS_MS. Only on the thread that called the library (its contract). */
void rr_progress(const progress_span *span, double fraction);
/* The part [a, b] of a span (fractions of it). */
static inline progress_span rr_progress_part(const progress_span *span, double a, double b) {
  progress_span p = *span;
  p.lo = span->lo + (span->hi - span->lo) * a, p.hi = span->lo + (span->hi - span->lo) * b;
  return p;
}

/* Runs fn(job, thread, arg) for job = 0..njobs-1, dealt out dynamically to
 * `threads` threads (the caller's thread is one of them; at most RR_MAX_THREADS,
 * which sizes every per-thread array, so thread < RR_MAX_THREADS). */
typedef void (*rr_parallel_fn)(int job, int thread, void *arg);
void rr_parallel_for(int njobs, int threads, rr_parallel_fn fn, void *arg);
/* The same, reporting the share of jobs taken as the span's progress from the
 * caller's thread (thread 0), which takes jobs like the others; span may be NULL.
 * Call it from the thread that called the library, not from inside a job. */
void rr_parallel_for_progress(int njobs, int threads, rr_parallel_fn fn, void *arg, const progress_span *span);
/* malloc for buffers of many megabytes: in huge pages where the system offers them
 * (fewer page faults); free() releases it. */
void *rr_alloc_large(size_t bytes);
/* A work buffer of at least `bytes` (64-byte aligned, uninitialised), from the
 * device's buffer for `use` when it is free: the pages a frame touched stay mapped
 * for the next frame (fresh pages cost a fault each: the teapot grid's rc-bvh setups
 * are 264 MB). The buffer grows by half at least, and lives until the device is
 * released. With dev NULL, the buffer taken (concurrent renders of one device, or
 * nested takes) or a failed growth, a fresh allocation; NULL when out of memory. */
typedef struct rr_buf {
  void *p;
  int use; /* the device's buffer it is, or -1: a fresh one */
} rr_buf;
rr_buf rr_scratch_take(rr_device *dev, int use, size_t bytes);
/* Gives back rr_scratch_take's buffer (frees a fresh one); b.p NULL does nothing. */
void rr_scratch_give(rr_device *dev, rr_buf b);
/* Frees the device's buffers (rr_device_release). */
void rr_scratch_free(rr_device *dev);
/* Number of cores available. */
int rr_cpu_count(void);
/* Milliseconds on a monotonic clock. */
double rr_now_ms(void);
double rr_cpu_ms(void); /* processor time of the whole process */

#endif
