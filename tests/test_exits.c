/* Clean exits of the command line: a signal at any moment of a run removes the
 * outputs' temporaries and exits 128 + the signal, and refusals after the scene is
 * loaded exit with their own code (under the sanitizers a leak would turn it into
 * LeakSanitizer's). */
#define _POSIX_C_SOURCE 200809L
#include "testutil.h"

#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_exits_XXXXXX";

static double now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Runs the CLI in dir with the arguments of `args` (space-separated), sends `sig`
 * after delay_ms (never when delay_ms < 0), and returns its wait status. */
static int run_signalled(const char *args, double delay_ms, int sig) {
  char buf[1024], *argv[32];
  snprintf(buf, sizeof buf, "%s", args);
  int n = 0;
  argv[n++] = RR_CLI;
  for (char *save = NULL, *a = strtok_r(buf, " ", &save); a && n < 31; a = strtok_r(NULL, " ", &save)) argv[n++] = a;
  argv[n] = NULL;
  pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir) != 0 || !freopen("/dev/null", "w", stderr)) _exit(99);
    execv(RR_CLI, argv);
    _exit(98);
  }
  if (delay_ms >= 0) {
    struct timespec ts = {(time_t)(delay_ms / 1000), (long)(delay_ms * 1e6) % 1000000000L};
    nanosleep(&ts, NULL);
    kill(pid, sig);
  }
  int st = 0;
  waitpid(pid, &st, 0);
  return st;
}

/* Files in dir: the count of temporaries (NAME.tmp.XXXXXX) and of all files;
 * removes them all. */
static int clear_dir(int *temporaries) {
  DIR *d = opendir(dir);
  int all = 0;
  *temporaries = 0;
  for (struct dirent *e; d && (e = readdir(d));) {
    if (e->d_name[0] == '.') continue;
    all++;
    *temporaries += strstr(e->d_name, ".tmp.") != NULL;
    char path[600];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    unlink(path);
  }
  if (d) closedir(d);
  return all;
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  bool quick = test_quick();

  /* A run long enough in its writing to be caught there: every AOV as EXR layers
   * and NPY, the colour as PNG. One whole run times it; signals then land across it. */
  const char *args = "render sphere:64 --size 640x640 --aa msaa:4 -o c.png --aov all=a.exr --aov depth=b.npy "
                     "--stats-json s.json";
  double t0 = now_ms();
  int st = run_signalled(args, -1, 0);
  double whole = now_ms() - t0;
  int tmp, files = clear_dir(&tmp);
  CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0 && files == 4 && tmp == 0, "whole run: status %#x, %d files", st, files);
  int tries = quick ? 6 : 10, interrupted = 0;
  for (int i = 0; i < tries; i++) {
    int sig = i % 2 ? SIGTERM : SIGINT;
    st = run_signalled(args, whole * (i + 0.5) / tries, sig);
    files = clear_dir(&tmp);
    bool stopped = WIFEXITED(st) && WEXITSTATUS(st) == 128 + sig, done = WIFEXITED(st) && WEXITSTATUS(st) == 0;
    interrupted += stopped;
    CHECK(stopped || done, "signal %d at %.0f ms: status %#x", sig, whole * (i + 0.5) / tries, st);
    CHECK(tmp == 0, "signal %d at %.0f ms left %d temporaries", sig, whole * (i + 0.5) / tries, tmp);
    /* stopped before the renames: nothing; after them (writing standard output): everything */
    CHECK(done ? files == 4 : files == 0 || files == 4, "%d files", files);
  }
  CHECK(interrupted > 0, "no run of %d was interrupted", tries);

  /* Refusals after the scene is loaded: their own exit code, no output. */
  static const struct {
    const char *args;
    int code;
  } refusals[] = {
      {"render sphere --method 2dr-bb --camera latlong --size 64x32 -o r.png", 2},
      {"render sphere --camera cube --size 64x64 -o r.png", 2},
      {"render sphere --method 3dr-bin --oracles bin=0 --size 32x32 -o r.png", 2},
      {"render ground:inf --method 2dr-bb --size 32x32 -o r.png", 2},
      {"render sphere --method 3dr-bin --oracles leaves=2 --size 32x32 -o r.png", 2},
      {"render sphere --fov 1e-30 --size 32x32 -o r.png", 2},
      {"render sphere --size 32x32 --aov depth=r.png", 1},
      {"render sphere --size 32x32 -o r.png --aov id=r.png", 2},
  };
  for (size_t i = 0; i < sizeof refusals / sizeof *refusals; i++) {
    st = run_signalled(refusals[i].args, -1, 0);
    files = clear_dir(&tmp);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == refusals[i].code && files == 0, "'%s': status %#x, %d files",
              refusals[i].args, st, files);
  }
  rmdir(dir);
  return test_done();
}
