/* rastray core: devices and errors, threads, the small vector algebra every stage uses. */
#ifndef RR_CORE_H
#define RR_CORE_H

#include "rastray.h"
#include "core/vec.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

/* Hot kernels written once and specialised by their constant arguments. */
#define KERNEL static inline __attribute__((always_inline))

struct rr_device {
  rr_error error;
  char message[512];
  rr_build_options build; /* used by rr_scene_commit; zeros mean defaults */
  struct auto_choice {    /* auto's last trial: the same view again reuses its choice */
    const void *scene, *bvh;
    uint32_t ntris;
    rr_camera cam;
    int width, height, threads, cull, scalar;
    int method;
    char why[256];
  } auto_choice;
};

/* Records a failure in dev (when not NULL) and returns its code. */
rr_error rr_fail(rr_device *dev, rr_error code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Records success. */
rr_error rr_ok(rr_device *dev);

/* Runs fn(job, thread, arg) for job = 0..njobs-1, dealt out dynamically to
 * `threads` threads (the caller's thread is one of them; at most RR_MAX_THREADS,
 * which sizes every per-thread array, so thread < RR_MAX_THREADS). */
typedef void (*rr_parallel_fn)(int job, int thread, void *arg);
void rr_parallel_for(int njobs, int threads, rr_parallel_fn fn, void *arg);
/* Number of cores available. */
int rr_cpu_count(void);
/* Milliseconds on a monotonic clock. */
double rr_now_ms(void);
double rr_cpu_ms(void); /* processor time of the whole process */

#endif
