/* The progress line (progress.h). Its state is the process's, like stderr: the
 * device's callback (on the main thread) and the ticker change and draw it under
 * one mutex. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, pthreads */

#include "progress.h"
#include "cli.h"

#include <pthread.h>
#include <semaphore.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

enum {
  SHOW_AFTER_MS = 1000, /* on a terminal, the line appears once a command has run this long */
  TICK_MS = 250,        /* the ticker's redraws */
  REDRAW_MS = 100,      /* the least time between two draws for reports */
};

static struct {
  pthread_mutex_t mu;
  pthread_cond_t wake;
  pthread_t ticker;
  bool on, ticking, stopping, forced, tty;
  double start_ms;  /* progress_start */
  char label[48];   /* the stage running; "": none */
  double fraction;  /* of it, < 0: unknown */
  double stage_ms;  /* when it (or frame 0 of --repeat) started */
  int frame, frames;
  double frames_ms; /* when frame 0 started */
  double drawn_ms;
  int width; /* of the line on screen; 0: none */
} P = {.mu = PTHREAD_MUTEX_INITIALIZER, .wake = PTHREAD_COND_INITIALIZER, .frames = 1};

static void format_time(char *buf, size_t size, double ms) {
  int s = (int)(ms / 1000);
  if (ms < 60000) snprintf(buf, size, "%.1f s", ms / 1000);
  else if (s < 3600) snprintf(buf, size, "%d:%02d", s / 60, s % 60);
  else snprintf(buf, size, "%d:%02d:%02d", s / 3600, s / 60 % 60, s % 60);
}

/* Under P.mu. */
static void draw(double now) {
  if (!P.label[0] || (!P.forced && now - P.start_ms < SHOW_AFTER_MS)) return;
  char line[160], elapsed[32], left[32];
  double ms = now - P.stage_ms, f = P.fraction;
  int n = snprintf(line, sizeof line, "%-20s", P.label);
  if (f >= 0) {
    enum { BAR = 20 };
    char bar[BAR + 1];
    for (int i = 0; i < BAR; i++) bar[i] = i < (int)(f * BAR) ? '#' : '.';
    bar[BAR] = 0;
    n += snprintf(line + n, sizeof line - n, " %3d%% [%s]", (int)(f * 100), bar);
  }
  format_time(elapsed, sizeof elapsed, ms);
  n += snprintf(line + n, sizeof line - n, " %s", elapsed);
  if (f > 0.02 && f < 1) { /* a guess from the share done so far, once there is one */
    format_time(left, sizeof left, ms * (1 - f) / f);
    snprintf(line + n, sizeof line - n, ", ~%s left", left);
  }
  int len = (int)strlen(line);
  fprintf(stderr, "\r%s%*s", line, P.width > len ? P.width - len : 0, "");
  P.width = len, P.drawn_ms = now;
}

/* Under P.mu. */
static void clear(void) {
  if (!P.width) return;
  if (P.tty) fprintf(stderr, "\r%*s\r", P.width, "");
  else fputc('\n', stderr); /* a log keeps the last state */
  P.width = 0;
}

static void on_report(void *user, rr_progress_stage stage, double fraction) {
  (void)user;
  static const char *const names[RR_PROGRESS_STAGE_COUNT] = {"loading", "building the BVH", "rendering"};
  pthread_mutex_lock(&P.mu);
  double now = now_ms();
  if (stage == RR_PROGRESS_RENDER && P.frames > 1) {
    snprintf(P.label, sizeof P.label, "frame %d/%d", P.frame + 1, P.frames);
    P.fraction = (P.frame + fraction) / P.frames, P.stage_ms = P.frames_ms;
  } else {
    if (fraction == 0 || strcmp(P.label, names[stage]) != 0) P.stage_ms = now;
    snprintf(P.label, sizeof P.label, "%s", names[stage]);
    P.fraction = stage == RR_PROGRESS_LOAD ? -1 : fraction; /* a file gives only its start and end */
  }
  if (fraction >= 1 || now - P.drawn_ms >= REDRAW_MS) draw(now); /* and every stage's end */
  if (fraction >= 1) P.label[0] = 0;
  pthread_mutex_unlock(&P.mu);
}

static sem_t tick_ready;
static void *tick(void *arg) {
  (void)arg;
  sem_post(&tick_ready);
  pthread_mutex_lock(&P.mu);
  while (!P.stopping) {
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += TICK_MS * 1000000L;
    if (ts.tv_nsec >= 1000000000L) ts.tv_sec++, ts.tv_nsec -= 1000000000L;
    pthread_cond_timedwait(&P.wake, &P.mu, &ts);
    if (!P.stopping) draw(now_ms());
  }
  pthread_mutex_unlock(&P.mu);
  return NULL;
}

void progress_start(rr_device *dev, bool forced) {
  bool tty = isatty(STDERR_FILENO);
  if (!forced && !tty) return;
  P.on = true, P.forced = forced, P.tty = tty, P.start_ms = now_ms();
  rr_device_set_progress(dev, on_report, NULL);
  /* without it, reports still draw; waited for, as the watcher is (rastray.c) */
  P.ticking = sem_init(&tick_ready, 0, 0) == 0 && pthread_create(&P.ticker, NULL, tick, NULL) == 0;
  while (P.ticking && sem_wait(&tick_ready) != 0) continue;
}

void progress_stage(const char *label) {
  if (!P.on) return;
  pthread_mutex_lock(&P.mu);
  snprintf(P.label, sizeof P.label, "%s", label);
  P.fraction = -1, P.stage_ms = now_ms();
  draw(P.stage_ms);
  pthread_mutex_unlock(&P.mu);
}

void progress_frame(int frame, int frames) {
  if (!P.on) return;
  pthread_mutex_lock(&P.mu);
  P.frame = frame, P.frames = frames;
  if (frame == 0) P.frames_ms = now_ms();
  pthread_mutex_unlock(&P.mu);
}

void progress_clear(void) {
  if (!P.on) return;
  pthread_mutex_lock(&P.mu);
  clear();
  pthread_mutex_unlock(&P.mu);
}

void progress_stop(void) {
  if (!P.on) return;
  pthread_mutex_lock(&P.mu);
  clear();
  P.stopping = true, P.label[0] = 0;
  pthread_cond_signal(&P.wake);
  pthread_mutex_unlock(&P.mu);
  if (P.ticking) pthread_join(P.ticker, NULL);
  P.on = P.ticking = false;
}
