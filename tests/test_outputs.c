/* The command line's outputs: -o and --aov lists and `all` as multi-layer EXR files
 * whose channels tinyexr reads back with the single files' names, types and bits;
 * colour linear in EXR and sRGB in PNG; /dev/null and standard output; a run whose
 * last output fails leaves nothing; identical runs at once do not collide. */
#define _POSIX_C_SOURCE 200809L

#include "testutil.h"

#include <dirent.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>


static char dir[] = "/tmp/rr_outputs_XXXXXX";
static char err[4096];

/* dir/name in one of a few rotating buffers. */
static const char *tpath(const char *name) {
  static char buf[8][600];
  static int slot;
  char *p = buf[slot++ & 7];
  snprintf(p, sizeof buf[0], "%s/%s", dir, name);
  return p;
}

/* Runs `rastray ARGS` in dir with stdout to dir/stdout.bin and stderr to err;
 * returns the exit code. */
static int run(const char *args) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cd %s && %s %s >stdout.bin 2>err.txt", dir, RR_CLI, args);
  int st = system(cmd);
  FILE *f = fopen(tpath("err.txt"), "r");
  size_t n = f ? fread(err, 1, sizeof err - 1, f) : 0;
  err[n] = 0;
  if (f) fclose(f);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static bool exists(const char *name) { return access(tpath(name), F_OK) == 0; }

/* Files in dir other than the runs' own stdout.bin and err.txt (temporaries included). */
static int outputs(void) {
  DIR *d = opendir(dir);
  int n = 0;
  for (struct dirent *e; d && (e = readdir(d)) != NULL;)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strcmp(e->d_name, "stdout.bin") &&
         strcmp(e->d_name, "err.txt");
  if (d) closedir(d);
  return n;
}

static void remove_outputs(void) {
  DIR *d = opendir(dir);
  for (struct dirent *e; d && (e = readdir(d)) != NULL;)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) unlink(tpath(e->d_name));
  if (d) closedir(d);
}

/* The start of dir/stdout.bin matches `magic`. */
static bool stdout_starts(const char *magic, size_t len) {
  FILE *f = fopen(tpath("stdout.bin"), "rb");
  char buf[16] = {0};
  size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
  if (f) fclose(f);
  return n >= len && memcmp(buf, magic, len) == 0;
}

/* The channel names of an EXR, space-separated, as tinyexr lists them. */
static void exr_names(const test_exr_file *x, char *out, size_t cap) {
  out[0] = 0;
  for (int k = 0; k < x->h.num_channels; k++)
    snprintf(out + strlen(out), cap - strlen(out), "%s%s", k ? " " : "", x->h.channels[k].name);
}

/* Every channel of the single file `one` is in `all` with its type and bits. */
static void same_channels(const test_exr_file *all, const char *one_name) {
  test_exr_file one;
  if (test_exr_load(tpath(one_name), &one)) {
    size_t bytes = (size_t)one.img.width * one.img.height * 4;
    for (int k = 0; k < one.h.num_channels; k++) {
      const char *ch = one.h.channels[k].name;
      int j = test_exr_find(all, ch);
      CHECK(j >= 0, "the layered file lacks %s of %s", ch, one_name);
      if (j < 0) continue;
      CHECK(all->h.pixel_types[j] == one.h.pixel_types[k], "type of %s", ch);
      CHECK(all->img.width == one.img.width && memcmp(all->img.images[j], one.img.images[k], bytes) == 0,
            "values of %s differ from %s", ch, one_name);
    }
  }
  test_exr_free(&one);
}

static void test_layers(void) {
  int rc = run("render sphere --size 40x30 --method rc-bvh -o c.exr --aov all=all.exr --aov depth=d.exr "
               "--aov id=i.exr --aov normal=n.exr --aov bary=b.exr --aov mesh=m.exr --aov material=t.exr "
               "--aov depth,normal=dn.exr");
  CHECK(rc == 0, "layered render exits %d: %s", rc, err);
  test_exr_file all, x;
  char names[512];
  if (test_exr_load(tpath("all.exr"), &all)) {
    exr_names(&all, names, sizeof names);
    CHECK(!strcmp(names, "B G N.X N.Y N.Z R Z bary.u bary.v id material mesh"), "all.exr channels: %s", names);
    static const char *const uints[] = {"id", "mesh", "material"};
    for (int k = 0; k < 3; k++) {
      int j = test_exr_find(&all, uints[k]);
      CHECK(j >= 0 && all.h.pixel_types[j] == TINYEXR_PIXELTYPE_UINT, "%s is not a UINT channel", uints[k]);
    }
    CHECK(all.h.pixel_types[test_exr_find(&all, "Z")] == TINYEXR_PIXELTYPE_FLOAT, "Z is not FLOAT");
    const char *singles[] = {"c.exr", "d.exr", "i.exr", "n.exr", "b.exr", "m.exr", "t.exr"};
    for (int k = 0; k < 7; k++) same_channels(&all, singles[k]);
  }
  test_exr_free(&all);
  if (test_exr_load(tpath("dn.exr"), &x)) {
    exr_names(&x, names, sizeof names);
    CHECK(!strcmp(names, "N.X N.Y N.Z Z"), "dn.exr channels: %s", names);
  }
  test_exr_free(&x);
  if (test_exr_load(tpath("d.exr"), &x)) {
    exr_names(&x, names, sizeof names);
    CHECK(!strcmp(names, "Z"), "depth channel: %s", names);
  }
  test_exr_free(&x);
  remove_outputs();

  /* with heat: evals and nodes join `all` */
  rc = run("render sphere --size 40x30 --shade heat-evals --aov all=h.exr");
  CHECK(rc == 0, "heat render exits %d: %s", rc, err);
  if (test_exr_load(tpath("h.exr"), &x)) CHECK(test_exr_find(&x, "evals") >= 0 && test_exr_find(&x, "nodes") >= 0, "evals, nodes in all");
  test_exr_free(&x);
  remove_outputs();

  CHECK(run("render sphere --size 8x8 --aov depth,normal=dn.npy") != 0 && strstr(err, "dn.npy"), "layers as NPY: %s", err);
  CHECK(run("render sphere --size 8x8 --aov depth,colour=x.exr") == 2 && strstr(err, "colour"), "unknown in a list: %s",
        err);
  CHECK(outputs() == 0, "refused lists left files");
}

/* sRGB encoding of linear light, to 8 bits, written out independently. */
static double srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055; }

static void test_colour(void) {
  int rc = run("render sphere --size 40x30 -o c.png --aov color=c.exr");
  CHECK(rc == 0, "colour render exits %d: %s", rc, err);
  rr_device *dev = rr_device_new();
  rr_image png, exr;
  if (rr_image_read(dev, tpath("c.png"), &png) == RR_OK && rr_image_read(dev, tpath("c.exr"), &exr) == RR_OK) {
    CHECK(exr.kind == RR_IMAGE_COLOR && exr.channels == 3 && png.channels == 3, "colour kinds");
    int bad = 0, mid = 0;
    for (size_t i = 0; i < (size_t)40 * 30 * 3; i++) {
      double lin = ((const float *)exr.data)[i];
      int want = (int)floor(srgb(lin) * 255 + 0.5), got = ((const uint8_t *)png.data)[i];
      bad += abs(got - want) > 1;
      mid += lin > 0.1 && lin < 0.5 && abs(got - (int)floor(lin * 255 + 0.5)) > 20;
    }
    CHECK(bad == 0, "%d PNG samples are not the sRGB encoding of the EXR's", bad);
    CHECK(mid > 100, "only %d mid-tone samples tell linear from encoded", mid);
    rr_image_free(&png);
    rr_image_free(&exr);
  } else {
    CHECK(0, "colour files: %s", rr_device_message(dev));
  }
  rr_device_release(dev);
  remove_outputs();
}

static void test_streams(void) {
  CHECK(run("render sphere --size 16x12 -o /dev/null --aov all=/dev/null --aov depth=/dev/null") == 0,
        "/dev/null: %s", err);
  CHECK(outputs() == 0, "/dev/null made a file");
  CHECK(run("render sphere --size 16x12 -o -") == 0 && stdout_starts("\x89PNG", 4), "-o -: %s", err);
  CHECK(run("render sphere --size 16x12 -o exr:-") == 0 && stdout_starts("\x76\x2f\x31\x01", 4), "-o exr:-: %s", err);
  CHECK(run("render sphere --size 16x12 --aov depth=-") == 0 && stdout_starts("\x93NUMPY", 6), "--aov depth=-: %s", err);
  CHECK(run("render sphere --size 16x12 --aov all=- -o c.png") == 0 && stdout_starts("\x76\x2f\x31\x01", 4) &&
            exists("c.png"),
        "--aov all=-: %s", err);
  remove_outputs();
  CHECK(run("render sphere --size 16x12 -o - --aov depth=npy:- --aov id=i.npy") == 2 && strstr(err, "standard output"),
        "two outputs to stdout: %s", err);
  CHECK(outputs() == 0, "two stdouts left files");
}

/* A run whose last output fails leaves none of the others, and no temporaries. */
static void test_all_or_nothing(void) {
  const char *runs[] = {
      "render sphere --size 16x12 -o c.png --aov depth=d.exr --aov normal=n.npy --aov all=a.exr --aov id=i.pfm",
      "render sphere --size 16x12 -o c.png --aov depth=d.exr --aov normal=n.npy --aov id=nodir/i.exr",
      "render sphere --size 16x12 -o c.png --aov depth=d.exr --aov bary=b.pfm",
  };
  for (int i = 0; i < 3; i++) {
    int rc = run(runs[i]);
    CHECK(rc == 1, "'%s' exits %d: %s", runs[i], rc, err);
    CHECK(outputs() == 0, "'%s' left %d files", runs[i], outputs());
    remove_outputs();
  }
}

/* Identical runs at once: each exits 0, the files are whole, no temporary stays. */
static void test_concurrent(void) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd,
           "cd %s && for i in 1 2 3 4 5 6; do (%s render sphere --size 64x48 -o c.png --aov all=a.exr "
           "--aov depth=d.npy 2>/dev/null || echo fail >>fails.txt) & done; wait",
           dir, RR_CLI);
  CHECK(system(cmd) == 0, "concurrent runs");
  CHECK(!exists("fails.txt"), "a concurrent run failed");
  CHECK(outputs() == 3, "%d files after concurrent runs (3 expected, no temporaries)", outputs());
  rr_device *dev = rr_device_new();
  rr_image img;
  const char *names[] = {"c.png", "d.npy"};
  for (int k = 0; k < 2; k++) {
    CHECK(rr_image_read(dev, tpath(names[k]), &img) == RR_OK && img.width == 64, "%s: %s", names[k], rr_device_message(dev));
    rr_image_free(&img);
  }
  test_exr_file x;
  test_exr_load(tpath("a.exr"), &x);
  test_exr_free(&x);
  rr_device_release(dev);
  remove_outputs();
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  test_layers();
  test_colour();
  test_streams();
  test_all_or_nothing();
  test_concurrent();
  remove_outputs();
  rmdir(dir);
  return test_done();
}
