#include "benchutil.h"

#include <fcntl.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
/* Without valgrind's headers (Debian package valgrind) the bench still builds,
 * and --instructions says it cannot count. */
#if defined(__has_include)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define BENCH_HAVE_CALLGRIND 1
#endif
#endif

double bench_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n) {
  qsort(v, n, sizeof *v, cmp);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

const char *bench_scene_path(const char *name) {
  static char buf[4096];
  if (access(name, R_OK) == 0 || strchr(name, '/')) return name;
  size_t pre = strncmp(name, "grid:", 5) == 0 ? 5 : strncmp(name, "grid-flat:", 10) == 0 ? 10 : 0;
  if (pre) { /* grid:MESH:N, grid-flat:MESH:N: MESH from the models when not a file here */
    const char *last = strrchr(name, ':');
    char mesh[1024];
    snprintf(mesh, sizeof mesh, "%.*s", (int)(last - name - pre), name + pre);
    if (access(mesh, R_OK) != 0) {
      snprintf(buf, sizeof buf, "%.*s%s/%s%s", (int)pre, name, RR_MODELS_DIR, mesh, last);
      return buf;
    }
    return name;
  }
  if (strchr(name, '.')) {
    snprintf(buf, sizeof buf, "%s/%s", RR_MODELS_DIR, name);
    return buf;
  }
  return name; /* a built-in name */
}

rr_scene *bench_load(rr_device *dev, const char *name, double *load_ms) {
  double t0 = bench_now_ms();
  rr_scene *s;
  if (rr_scene_load(dev, bench_scene_path(name), &s) != RR_OK) {
    fprintf(stderr, "bench: %s\n", rr_device_message(dev));
    exit(1);
  }
  if (load_ms) *load_ms = bench_now_ms() - t0;
  return s;
}

void bench_camera(rr_device *dev, const rr_scene *scene, int w, int h, rr_camera *cam) {
  rr_camera_init(cam);
  cam->fov_deg = 50;
  rr_camera_frame(dev, scene, w, h, cam);
}

void bench_view(rr_device *dev, const char *name, const rr_scene *s, int w, int h, rr_camera *cam) {
  bench_camera(dev, s, w, h, cam);
  if (strncmp(name, "rooms", 5) == 0) {
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    float eye[3] = {1.2f, 1.6f, 1.4f}, target[3] = {in.bounds_max[0], 1.2f, in.bounds_max[2] * 0.7f};
    memcpy(cam->eye, eye, sizeof eye), memcpy(cam->target, target, sizeof target);
    cam->fov_deg = 70;
  }
}

static void check(rr_device *dev, rr_error e) {
  if (e == RR_OK) return;
  fprintf(stderr, "bench: %s\n", rr_device_message(dev));
  exit(1);
}

double bench_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                    int reps, rr_frame **out) {
  double t[64];
  if (reps > 64) reps = 64;
  rr_frame *f = NULL;
  for (int r = 0; r < reps; r++) {
    rr_frame_release(f);
    check(dev, rr_render(dev, scene, cam, opt, &f));
    rr_stats st;
    rr_frame_get_stats(f, &st);
    t[r] = st.frame_ms;
  }
  if (out) *out = f;
  else rr_frame_release(f);
  return bench_median(t, reps);
}

bench_agreement bench_compare(const uint32_t *ia, const float *da, const uint32_t *ib, const float *db, size_t n) {
  size_t same_id = 0, same_hit = 0, both = 0, depth_ok = 0;
  for (size_t k = 0; k < n; k++) {
    bool ha = ia[k] != RR_MISS, hb = ib[k] != RR_MISS;
    same_id += ia[k] == ib[k];
    same_hit += ha == hb;
    if (ha && hb) {
      both++;
      depth_ok += fabsf(da[k] - db[k]) <= 1e-4f * fmaxf(fabsf(da[k]), fabsf(db[k]));
    }
  }
  bench_agreement a = {(double)same_id / n, (double)same_hit / n, both ? (double)depth_ok / both : 1.0};
  return a;
}

float *bench_depths(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_frame *frame) {
  rr_image img;
  if (rr_frame_aov(dev, scene, cam, frame, RR_AOV_DEPTH, &img) != RR_OK) {
    fprintf(stderr, "bench: %s\n", rr_device_message(dev));
    exit(1);
  }
  return img.data; /* caller frees */
}

/* ---- memory ---- */

double bench_heap_bytes(void) {
#ifdef __GLIBC__
  struct mallinfo2 m = mallinfo2();
  return (double)m.uordblks + (double)m.hblkhd;
#else
  return -1;
#endif
}

/* A "Key:   N kB" line of /proc/self/status, in bytes (-1 when absent). */
static double status_bytes(const char *key) {
  FILE *f = fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  double v = -1;
  size_t n = strlen(key);
  while (fgets(line, sizeof line, f))
    if (strncmp(line, key, n) == 0 && line[n] == ':') v = atof(line + n + 1) * 1024;
  fclose(f);
  return v;
}

static double rss_at_mark = -1;

bool bench_rss_mark(void) {
#ifdef __GLIBC__
  malloc_trim(0); /* freed pages would otherwise be reused without showing in the peak */
#endif
  FILE *f = fopen("/proc/self/clear_refs", "w");
  bool ok = f && fputs("5", f) >= 0; /* 5: reset the peak resident set to the current one */
  if (f) ok &= fclose(f) == 0;
  rss_at_mark = ok ? status_bytes("VmRSS") : -1;
  return ok && rss_at_mark >= 0;
}

double bench_rss_peak(void) {
  double hwm = status_bytes("VmHWM");
  return rss_at_mark < 0 || hwm < 0 ? -1 : hwm - rss_at_mark;
}

/* ---- instruction counts ---- */

bool bench_on_valgrind(void) {
#ifdef BENCH_HAVE_CALLGRIND
  return RUNNING_ON_VALGRIND != 0;
#else
  return false;
#endif
}

void bench_count_start(void) {
#ifdef BENCH_HAVE_CALLGRIND
  CALLGRIND_ZERO_STATS;
  CALLGRIND_START_INSTRUMENTATION;
#endif
}

void bench_count_stop(const char *name) {
#ifdef BENCH_HAVE_CALLGRIND
  CALLGRIND_STOP_INSTRUMENTATION;
  CALLGRIND_DUMP_STATS_AT(name);
#else
  (void)name;
#endif
}

double bench_count_frame(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                         const char *name, rr_frame **out) {
  bench_render(dev, scene, cam, opt, 1, NULL); /* first-use costs stay out of the count */
  bench_count_start();
  rr_error e = rr_render(dev, scene, cam, opt, out);
  bench_count_stop(name);
  check(dev, e);
  rr_stats st;
  rr_frame_get_stats(*out, &st);
  return st.frame_ms;
}

int bench_callgrind_run(char *const argv[], char *dir, size_t dir_size) {
#ifndef BENCH_HAVE_CALLGRIND
  (void)argv, (void)dir, (void)dir_size;
  fprintf(stderr, "bench: built without valgrind's headers (install valgrind): no instruction counts\n");
  return -1;
#else
  char exe[4096], out[4200];
  ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  snprintf(dir, dir_size, "/tmp/rastray-callgrind-XXXXXX");
  if (len <= 0 || !mkdtemp(dir)) return -1;
  exe[len] = 0;
  snprintf(out, sizeof out, "--callgrind-out-file=%s/callgrind.out", dir);
  int argc = 0;
  while (argv[argc]) argc++;
  char **args = calloc((size_t)argc + 6, sizeof *args);
  if (!args) return -1;
  char *head[] = {"valgrind", "-q", "--tool=callgrind", "--instr-atstart=no", out, exe};
  memcpy(args, head, sizeof head);
  for (int i = 1; i < argc; i++) args[5 + i] = argv[i];
  fflush(stdout), fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, STDOUT_FILENO);
    execvp(args[0], args);
    _exit(127);
  }
  free(args);
  int status;
  if (pid < 0 || waitpid(pid, &status, 0) < 0) return -1;
  int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 127) fprintf(stderr, "bench: cannot run valgrind (install valgrind)\n");
  return code == 127 ? -1 : code;
#endif
}

/* One part file: the name its client request gave it and its instruction total. */
static bool read_part(const char *path, char name[1024], uint64_t *ir) {
  static const char trigger[] = "desc: Trigger: Client Request: ";
  FILE *f = fopen(path, "r");
  if (!f) return false;
  char line[1024];
  bool named = false, counted = false;
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = 0;
    if (strncmp(line, trigger, sizeof trigger - 1) == 0)
      snprintf(name, 1024, "%s", line + sizeof trigger - 1), named = true;
    else if (strncmp(line, "totals: ", 8) == 0)
      *ir = strtoull(line + 8, NULL, 10), counted = true;
  }
  fclose(f);
  return named && counted;
}

int bench_callgrind_parts(const char *dir, void (*fn)(const char *name, uint64_t instructions, void *arg),
                          void *arg) {
  /* Callgrind numbers the dumps of one run .1, .2, ... in the order they were made. */
  int k = 1;
  for (;; k++) {
    char path[4200], name[1024];
    uint64_t ir = 0;
    snprintf(path, sizeof path, "%s/callgrind.out.%d", dir, k);
    if (access(path, R_OK) != 0) break;
    if (read_part(path, name, &ir)) fn(name, ir, arg);
  }
  return k - 1;
}

static void print_part(const char *name, uint64_t ir, void *arg) {
  (void)arg;
  printf("  %-40s %12.3f M\n", name, ir / 1e6);
}

int bench_instructions_main(char *const argv[]) {
  char dir[256];
  int code = bench_callgrind_run(argv, dir, sizeof dir);
  if (code != 0) return code < 0 ? 2 : code;
  printf("instructions of one frame (after an uncounted warm-up), counted by callgrind\n");
  int n = bench_callgrind_parts(dir, print_part, NULL);
  printf("%d parts in %s (callgrind_annotate FILE shows where they went)\n", n, dir);
  return 0;
}

bool bench_arg_size(const char *prog, const char *v, int min, int *w, int *h) {
  int a, b;
  char end;
  if (sscanf(v, "%dx%d%c", &a, &b, &end) == 2 && a >= min && b >= min && a <= RR_MAX_SIZE && b <= RR_MAX_SIZE) {
    *w = a, *h = b;
    return true;
  }
  fprintf(stderr, "%s: bad --size '%s' (expected WxH, %d to %d a side)\n", prog, v, min, RR_MAX_SIZE);
  return false;
}

bool bench_arg_int(const char *prog, const char *opt, const char *v, int lo, int hi, int *out) {
  char *end;
  long n = strtol(v, &end, 10);
  if (end != v && !*end && n >= lo && n <= hi) {
    *out = (int)n;
    return true;
  }
  fprintf(stderr, "%s: bad %s '%s' (%d..%d)\n", prog, opt, v, lo, hi);
  return false;
}
