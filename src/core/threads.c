/* A thread pool for one parallel loop at a time: jobs are dealt out dynamically
 * through an atomic counter, so uneven tiles balance themselves. The workers live
 * as long as the process, since a frame runs many short loops (a batch of
 * triangles is two of them) and starting threads for each would cost more than
 * some loops do. A loop started while the pool is busy (another caller's thread,
 * or a loop inside a job) runs on threads of its own instead.
 *
 * The pool is the library's one piece of shared mutable state, shared by every
 * device on purpose (threads are a resource of the process). It is safe from any
 * number of threads: `busy` lets one caller's loop in at a time (the others run
 * their own threads, so no device ever waits for another), everything else in it
 * is read and written under `mu`, and a caller leaves only when no worker is still
 * inside its loop, whose state lives on that caller's stack. A loop reaches no
 * caller data but through fn and arg, and its progress span, which only the
 * caller's own thread (thread 0) reads: progress is reported from there alone. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, sysconf, pthreads */

#include "core/core.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <time.h>
#include <unistd.h>

typedef struct {
  atomic_int next;
  int njobs;
  rr_parallel_fn fn;
  void *arg;
  const progress_span *span; /* reported by thread 0, the caller's */
} loop;

/* Beside the pool, whose caller makes the reports. */
void rr_progress(const progress_span *span, double fraction) {
  rr_device *dev = span->dev;
  if (!dev || !dev->progress) return;
  double f = span->lo + (span->hi - span->lo) * fraction;
  if (f > 0 && f < 1) { /* an inner fraction: rarely enough not to matter */
    double now = rr_now_ms();
    if (now - dev->progress_ms < RR_PROGRESS_MS) return;
    dev->progress_ms = now;
  }
  dev->progress(dev->progress_user, span->stage, f < 0 ? 0 : f > 1 ? 1 : f);
}

static void run_jobs(loop *l, int thread) {
  for (;;) {
    int job = atomic_fetch_add(&l->next, 1);
    if (job >= l->njobs) break;
    l->fn(job, thread, l->arg);
    if (thread == 0 && l->span) { /* the share taken; the loop's end is its caller's to report */
      int taken = atomic_load_explicit(&l->next, memory_order_relaxed);
      if (taken < l->njobs) rr_progress(l->span, (double)taken / l->njobs);
    }
  }
}

typedef struct {
  pthread_mutex_t busy; /* held by the caller whose loop the pool runs */
  pthread_mutex_t mu;   /* guards what follows */
  pthread_cond_t go, done;
  int workers;          /* started so far: threads 1..workers */
  unsigned gen;         /* bumped for every loop */
  loop *cur;            /* the loop workers may join, NULL once its caller ran out of jobs */
  int want;             /* threads 1..want-1 may take part in it */
  int active;           /* workers inside it */
} pool;

#define POOL_INIT                                                                                     \
  {                                                                                                   \
    .busy = PTHREAD_MUTEX_INITIALIZER, .mu = PTHREAD_MUTEX_INITIALIZER, .go = PTHREAD_COND_INITIALIZER, \
    .done = PTHREAD_COND_INITIALIZER                                                                  \
  }
static pool P = POOL_INIT;

static void *pool_worker(void *arg) {
  int id = (int)(intptr_t)arg;
  unsigned seen = 0;
  pthread_mutex_lock(&P.mu);
  for (;;) {
    while (P.gen == seen) pthread_cond_wait(&P.go, &P.mu);
    seen = P.gen;
    if (id >= P.want || !P.cur) continue; /* woke too late: the loop is over */
    loop *l = P.cur;
    P.active++;
    pthread_mutex_unlock(&P.mu);
    run_jobs(l, id);
    pthread_mutex_lock(&P.mu);
    if (--P.active == 0 && !P.cur) pthread_cond_signal(&P.done);
  }
  return NULL;
}

/* A forked child has none of the parent's workers. */
static void pool_after_fork(void) {
  pool fresh = POOL_INIT;
  P = fresh;
}

static pthread_once_t atfork_once = PTHREAD_ONCE_INIT;
static void register_atfork(void) { pthread_atfork(NULL, NULL, pool_after_fork); }

/* The fallback: threads started for this loop alone. */
typedef struct {
  loop *l;
  int thread;
} own_arg;

static void *own_thread(void *arg) {
  own_arg *a = arg;
  run_jobs(a->l, a->thread);
  return NULL;
}

static void run_own_threads(loop *l, int threads) {
  pthread_t tid[RR_MAX_THREADS];
  own_arg a[RR_MAX_THREADS];
  int started = 0;
  for (int i = 1; i < threads; i++) {
    a[i] = (own_arg){l, i};
    if (pthread_create(&tid[i], NULL, own_thread, &a[i]) != 0) break;
    started = i;
  }
  run_jobs(l, 0);
  for (int i = 1; i <= started; i++) pthread_join(tid[i], NULL);
}

void rr_parallel_for(int njobs, int threads, rr_parallel_fn fn, void *arg) {
  rr_parallel_for_progress(njobs, threads, fn, arg, NULL);
}

void rr_parallel_for_progress(int njobs, int threads, rr_parallel_fn fn, void *arg, const progress_span *span) {
  if (threads > njobs) threads = njobs;
  if (threads < 1) threads = 1;
  if (threads > RR_MAX_THREADS) threads = RR_MAX_THREADS;
  loop l = {.njobs = njobs, .fn = fn, .arg = arg, .span = span && span->dev && span->dev->progress ? span : NULL};
  atomic_init(&l.next, 0);
  if (threads == 1) {
    run_jobs(&l, 0);
    return;
  }
  if (pthread_mutex_trylock(&P.busy) != 0) {
    run_own_threads(&l, threads);
    return;
  }
  pthread_once(&atfork_once, register_atfork);
  pthread_mutex_lock(&P.mu);
  while (P.workers < threads - 1) {
    pthread_t tid;
    if (pthread_create(&tid, NULL, pool_worker, (void *)(intptr_t)(P.workers + 1)) != 0) break;
    pthread_detach(tid);
    P.workers++;
  }
  P.cur = &l, P.want = P.workers + 1 < threads ? P.workers + 1 : threads, P.active = 0, P.gen++;
  pthread_cond_broadcast(&P.go);
  pthread_mutex_unlock(&P.mu);
  run_jobs(&l, 0);
  /* Wait only for the workers inside the loop: one that a busy machine has not
   * scheduled yet would find no job, and waiting for it would cost its delay. */
  pthread_mutex_lock(&P.mu);
  P.cur = NULL;
  while (P.active > 0) pthread_cond_wait(&P.done, &P.mu);
  pthread_mutex_unlock(&P.mu);
  pthread_mutex_unlock(&P.busy);
}

int rr_cpu_count(void) {
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n < 1 ? 1 : n > RR_MAX_THREADS ? RR_MAX_THREADS : (int)n;
}

static double clock_ms(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double rr_cpu_ms(void) { return clock_ms(CLOCK_PROCESS_CPUTIME_ID); }

double rr_now_ms(void) { return clock_ms(CLOCK_MONOTONIC); }
