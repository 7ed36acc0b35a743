/* The command-line tool end to end: outputs that round-trip, statistics, and every
 * bad input giving a one-line message, its exit code and no output file. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_cli_XXXXXX";
static char err[4096];

/* Runs the CLI with `args`; returns its exit code and leaves stderr in err. */
static int run(const char *args) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cd %s && %s %s 2>%s/err.txt >/dev/null", dir, RR_CLI, args, dir);
  int st = system(cmd);
  char path[600];
  snprintf(path, sizeof path, "%s/err.txt", dir);
  FILE *f = fopen(path, "r");
  size_t n = f ? fread(err, 1, sizeof err - 1, f) : 0;
  err[n] = 0;
  if (f) fclose(f);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static bool exists(const char *name) {
  char path[600];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return access(path, F_OK) == 0;
}

static int count_files(void) {
  char cmd[600];
  snprintf(cmd, sizeof cmd, "ls -A %s | grep -v '^err.txt$' | grep -v '^tri.obj$' | grep -v '^bad.obj$' | wc -l", dir);
  FILE *p = popen(cmd, "r");
  int n = -1;
  if (p && fscanf(p, "%d", &n) != 1) n = -1;
  if (p) pclose(p);
  return n;
}

static bool one_line(void) {
  size_t n = strlen(err);
  return n > 0 && err[n - 1] == '\n' && strchr(err, '\n') == err + n - 1;
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  rr_device *dev = rr_device_new();
  char path[600];
  snprintf(path, sizeof path, "%s/tri.obj", dir);
  FILE *f = fopen(path, "w");
  fputs("v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n", f);
  fclose(f);
  snprintf(path, sizeof path, "%s/bad.obj", dir);
  f = fopen(path, "w");
  fputs("v 1 2\nf 7 8 9 10 zz\n", f);
  fclose(f);

  CHECK(run("--version") == 0, "--version");
  CHECK(run("--help") == 0, "--help");

  /* A good render with every output kind. */
  int rc = run("render tri.obj --size 32x24 --method rc -o c.png --aov depth=d.pfm --aov id=i.npy --aov normal=n.exr "
               "--aov bary=b.npy --aov uv,uv-deriv=u.exr --texture-filter aniso:4 --lod-bias -0.5 --stats --stats-json s.json");
  CHECK(rc == 0, "render exit %d: %s", rc, err);
  CHECK(strstr(err, "method=rc") && strstr(err, "setups=1 ") && strstr(err, "edge_evals=768"),
        "--stats line: %s", err);
  rr_image img;
  snprintf(path, sizeof path, "%s/c.png", dir);
  CHECK(rr_image_read(dev, path, &img) == RR_OK && img.width == 32 && img.height == 24, "colour png");
  rr_image_free(&img);
  snprintf(path, sizeof path, "%s/i.npy", dir);
  if (rr_image_read(dev, path, &img) == RR_OK) {
    const uint32_t *id = img.data;
    CHECK(img.type == RR_PIXEL_U32 && id[0] == RR_MISS && id[12 * 32 + 16] == 0, "id AOV: miss at corner, hit at centre");
    rr_image_free(&img);
  } else CHECK(0, "id npy unreadable: %s", rr_device_message(dev));
  snprintf(path, sizeof path, "%s/d.pfm", dir);
  if (rr_image_read(dev, path, &img) == RR_OK) {
    const float *d = img.data;
    CHECK(isinf(d[0]) && d[12 * 32 + 16] > 0 && isfinite(d[12 * 32 + 16]), "depth AOV: +inf at a miss, finite at a hit");
    rr_image_free(&img);
  } else CHECK(0, "depth pfm unreadable: %s", rr_device_message(dev));
  CHECK(exists("n.exr") && exists("b.npy") && exists("u.exr"), "normal, bary and uv AOVs written");
  snprintf(path, sizeof path, "%s/s.json", dir);
  f = fopen(path, "r");
  char json[2048] = {0};
  if (f) fread(json, 1, sizeof json - 1, f), fclose(f);
  const char *keys[] = {"\"method\"", "\"camera\"", "\"triangles\"", "\"width\"", "\"height\"", "\"threads\"",
                        "\"frame_ms\"", "\"total_ms\"", "\"setups\"", "\"edge_evals\"", "\"nodes\""};
  for (int k = 0; k < 11; k++) CHECK(strstr(json, keys[k]), "stats JSON lacks %s: %s", keys[k], json);

  /* Bad input: message, exit code, and nothing written. */
  char cmd[700];
  snprintf(cmd, sizeof cmd, "cd %s && rm -f c.png d.pfm i.npy n.exr b.npy u.exr s.json", dir);
  CHECK(system(cmd) == 0, "clean");
  struct {
    const char *args;
    int code;
    const char *needle;
  } bad[] = {
      {"render missing.obj -o o.png", 1, "missing.obj"},
      {"render bad.obj -o o.png", 1, "bad.obj"},
      {"render tri.obj --method nope -o o.png", 2, "nope"},
      {"render tri.obj --shade sepia -o o.png", 2, "sepia"},
      {"render tri.obj --size 0x10 -o o.png", 2, "0x10"},
      {"render tri.obj --size -5x5 -o o.png", 2, "-5x5"},
      {"render tri.obj --size 20000x10 -o o.png", 2, "20000x10"},
      {"render tri.obj --size 12 -o o.png", 2, "'12'"},
      {"render tri.obj --size 10x10x -o o.png", 2, "10x10x"},
      {"render tri.obj --eye 1,2 --target 0,0,0 -o o.png", 2, "1,2"},
      {"render tri.obj --eye 1,2,nan --target 0,0,0 -o o.png", 2, "1,2,nan"},
      {"render tri.obj --eye 1,1,1 --target 1,1,1 -o o.png", 2, "eye equals target"},
      {"render tri.obj --eye 0,0,3 --target 0,0,0 --up 0,0,1 -o o.png", 2, "parallel"},
      {"render tri.obj --fov 0 -o o.png", 2, "--fov"},
      {"render tri.obj --threads 257 -o o.png", 2, "--threads"},
      {"render tri.obj --repeat x -o o.png", 2, "'x'"},
      {"render tri.obj --aov colour=x.npy", 2, "colour"},
      {"render tri.obj --aov depth", 2, "depth"},
      {"render tri.obj -o o.bmp", 2, ".bmp"},
      {"render tri.obj -o /nonexistent/dir/o.png", 1, "/nonexistent/dir/o.png"},
      {"render tri.obj --frobnicate -o o.png", 2, "--frobnicate"},
      {"render tri.obj --method", 2, "--method"},
      {"render tri.obj other.obj -o o.png", 2, "other.obj"},
      {"render tri.obj --texture-filter cubic -o o.png", 2, "cubic"},
      {"render tri.obj --texture-filter '' -o o.png", 2, "--texture-filter"},
      {"render tri.obj --texture-filter aniso:0 -o o.png", 2, "'0'"},
      {"render tri.obj --texture-filter aniso:17 -o o.png", 2, "'17'"},
      {"render tri.obj --texture-filter aniso:2.5 -o o.png", 2, "'2.5'"},
      {"render tri.obj --texture-filter aniso: -o o.png", 2, "aniso:N"},
      {"render tri.obj --texture-filter trilinear:4 -o o.png", 2, "trilinear:4"},
      {"render tri.obj --texture-filter anisotropic -o o.png", 2, "anisotropic"},
      {"render tri.obj --lod-bias nan -o o.png", 2, "--lod-bias"},
      {"render tri.obj --lod-bias 100 -o o.png", 2, "'100'"},
      {"render tri.obj --aov uvw=x.npy", 2, "uvw"},
      {"paint tri.obj", 2, "paint"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    rc = run(bad[i].args);
    CHECK(rc == bad[i].code, "'%s' exits %d, expected %d: %s", bad[i].args, rc, bad[i].code, err);
    CHECK(one_line() && strstr(err, bad[i].needle), "'%s': message should be one line naming '%s': %s", bad[i].args,
          bad[i].needle, err);
    CHECK(count_files() == 0, "'%s' left a file behind", bad[i].args);
  }
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  rr_device_release(dev);
  return test_done();
}
