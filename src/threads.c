/* A minimal thread pool for one parallel loop at a time: jobs are dealt out
 * dynamically through an atomic counter, so uneven tiles balance themselves. */
#include "rr.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>
#include <unistd.h>

typedef struct {
  atomic_int next;
  int njobs;
  parallel_fn fn;
  void *arg;
} pool;

typedef struct {
  pool *p;
  int thread;
} worker;

static void *work(void *w_) {
  worker *w = w_;
  for (;;) {
    int job = atomic_fetch_add(&w->p->next, 1);
    if (job >= w->p->njobs) break;
    w->p->fn(job, w->thread, w->p->arg);
  }
  return NULL;
}

void parallel_for(int njobs, int threads, parallel_fn fn, void *arg) {
  if (threads > njobs) threads = njobs;
  if (threads < 1) threads = 1;
  pool p = {.njobs = njobs, .fn = fn, .arg = arg};
  atomic_init(&p.next, 0);
  pthread_t tid[256];
  worker w[256];
  if (threads > 256) threads = 256;
  int started = 0;
  for (int i = 1; i < threads; i++) {
    w[i] = (worker){&p, i};
    if (pthread_create(&tid[i], NULL, work, &w[i]) != 0) break; /* run with fewer */
    started = i;
  }
  w[0] = (worker){&p, 0};
  work(&w[0]);
  for (int i = 1; i <= started; i++) pthread_join(tid[i], NULL);
}

int cpu_count(void) {
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n < 1 ? 1 : n > 256 ? 256 : (int)n;
}

double now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}
