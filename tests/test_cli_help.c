/* The command line as a Unix tool: help for every command on stdout, the man page
 * in step with it, --opt=value, --threads 0, --quiet, --verbose, the progress line
 * (with --progress, never in a pipe without it), statistics JSON that parses
 * whatever the scene's path, and camera files: the round trip to the same bits,
 * matrices, flags over the file, and every bad file a one-line message. */
#include "testutil.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_cli_help_XXXXXX";
static char out[1 << 16], err[1 << 16]; /* the last run's stdout and stderr */

static void slurp(const char *name, char *buf, size_t size) {
  char path[600];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "rb");
  size_t n = f ? fread(buf, 1, size - 1, f) : 0;
  buf[n] = 0;
  if (f) fclose(f);
}

/* Runs the CLI in dir with stdout and stderr to files (pipes, not terminals);
 * returns its exit code and leaves what it printed in out and err. */
static int cli(const char *args) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "cd %s && %s %s >stdout.txt 2>stderr.txt", dir, RR_CLI, args);
  int st = system(cmd);
  slurp("stdout.txt", out, sizeof out);
  slurp("stderr.txt", err, sizeof err);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static bool one_line(const char *s) {
  size_t n = strlen(s);
  return n > 0 && s[n - 1] == '\n' && strchr(s, '\n') == s + n - 1;
}

/* A file's bytes (malloc'd, NUL-terminated), or NULL. */
static char *read_file(const char *name, size_t *size) {
  char path[600];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *buf = malloc(n + 1);
  if (buf && fread(buf, 1, n, f) != (size_t)n) free(buf), buf = NULL;
  fclose(f);
  if (buf) buf[n] = 0;
  if (size) *size = (size_t)n;
  return buf;
}

static bool same_files(const char *a, const char *b) {
  size_t na, nb;
  char *x = read_file(a, &na), *y = read_file(b, &nb);
  bool same = x && y && na == nb && memcmp(x, y, na) == 0;
  free(x), free(y);
  return same;
}

static cJSON *read_json(const char *name) {
  char *text = read_file(name, NULL);
  cJSON *j = text ? cJSON_Parse(text) : NULL;
  free(text);
  return j;
}

/* Whether the long option "--name" (or a word) is in text. */
static bool has_option(const char *text, const char *opt) {
  size_t n = strlen(opt);
  for (const char *p = strstr(text, opt); p; p = strstr(p + 1, opt))
    if (!(p[n] == '-' || (p[n] >= 'a' && p[n] <= 'z'))) return true;
  return false;
}

/* Every "--word" of `from` must be in `in` (what names the two in messages). */
static void options_in(const char *from, const char *in, const char *what) {
  for (const char *p = strstr(from, "--"); p; p = strstr(p + 2, "--")) {
    char opt[64];
    size_t n = 2;
    while (n < sizeof opt - 1 && ((p[n] >= 'a' && p[n] <= 'z') || p[n] == '-')) n++;
    if (n == 2) continue;
    memcpy(opt, p, n), opt[n] = 0;
    CHECK(has_option(in, opt), "%s: %s is missing", what, opt);
  }
}

static void help_and_man(void) {
  /* Help on every command, on stdout, exit 0, nothing on stderr. */
  const char *helps[] = {"--help", "-h", "help", "help render", "help info", "help help", "render --help",
                         "render -h", "info --help", "info -h", "help --help", "render tri.obj --size=1x1 -h"};
  for (size_t i = 0; i < sizeof helps / sizeof *helps; i++) {
    int rc = cli(helps[i]);
    CHECK(rc == 0 && strstr(out, "usage: rastray") && !err[0], "'%s': exit %d, stdout '%.60s', stderr '%s'", helps[i],
          rc, out, err);
  }
  CHECK(cli("render --help") == 0 && strstr(out, "--threads") && strstr(out, "--camera-file") &&
            strstr(out, "--progress"),
        "render's help lists its options: %s", out);
  CHECK(cli("--version") == 0 && strncmp(out, "rastray ", 8) == 0, "--version: %s", out);
  CHECK(cli("") == 2 && strstr(err, "usage:") && !out[0], "no command: usage on stderr, exit 2");

  /* The man page names every option of every command, and no other. */
  char man_path[600];
  snprintf(man_path, sizeof man_path, "%s/../man/rastray.1", RR_DATA_DIR);
  FILE *f = fopen(man_path, "rb");
  CHECK(f != NULL, "no man page at %s", man_path);
  if (!f) return;
  static char man[1 << 17], helps_all[1 << 16];
  size_t n = fread(man, 1, sizeof man - 1, f);
  fclose(f);
  man[n] = 0;
  size_t k = 0; /* roff writes a minus sign as \- */
  for (size_t i = 0; i < n; i++) {
    if (man[i] == '\\' && man[i + 1] == '-') i++;
    man[k++] = man[i];
  }
  man[k] = 0;
  helps_all[0] = 0;
  const char *commands[] = {"", "render", "info", "help"};
  for (int c = 0; c < 4; c++) {
    char args[64];
    snprintf(args, sizeof args, "help %s", commands[c]);
    CHECK(cli(args) == 0, "%s", args);
    char what[96];
    snprintf(what, sizeof what, "man page (from '%s')", args);
    options_in(out, man, what);
    strncat(helps_all, out, sizeof helps_all - strlen(helps_all) - 1);
    if (c) CHECK(strstr(man, commands[c]), "the man page does not name the command %s", commands[c]);
  }
  options_in(man, helps_all, "rastray help COMMAND (from the man page)");
  CHECK(strstr(man, ".SH EXIT STATUS") && strstr(man, ".SH EXAMPLES") && strstr(man, ".SH FILES"),
        "the man page has exit status, examples and files");
  /* It renders without a warning, where groff is installed. */
  if (system("command -v groff >/dev/null 2>&1") == 0) {
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "groff -man -ww -Tutf8 -z %s 2>%s/groff.txt", man_path, dir);
    int rc = system(cmd);
    slurp("groff.txt", err, sizeof err);
    CHECK(rc == 0 && !err[0], "groff warns about the man page: %s", err);
  }
}

static void usage_errors(void) {
  const struct {
    const char *args, *needle;
  } bad[] = {
      {"paint", "'paint'"},
      {"help paint", "'paint'"},
      {"render tri.obj --frobnicate", "'--frobnicate'"},
      {"render tri.obj -x", "'-x'"},
      {"info tri.obj --size 8x8", "'--size'"},
      {"render tri.obj --stats=1", "--stats takes no value"},
      {"render tri.obj --size", "--size needs a value"},
      {"render tri.obj --threads=-1", "'-1'"},
      {"render tri.obj --quiet --method nope", "'nope'"}, /* --quiet keeps errors */
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    int rc = cli(bad[i].args);
    CHECK(rc == 2 && one_line(err) && strstr(err, bad[i].needle) && !out[0],
          "'%s': exit %d, expected 2 and one line naming %s: %s", bad[i].args, rc, bad[i].needle, err);
  }
}

static void options(void) {
  /* --opt=value and --opt value alike; --threads 0 is every core. */
  int rc = cli("render --size=32x24 --method=rc --output=a.png tri.obj --threads 0 --stats");
  CHECK(rc == 0, "--opt=value: %s", err);
  rr_device *dev = rr_device_new();
  char path[600];
  snprintf(path, sizeof path, "%s/a.png", dir);
  rr_image img;
  if (rr_image_read(dev, path, &img) == RR_OK) {
    CHECK(img.width == 32 && img.height == 24, "--size=32x24 gave %dx%d", img.width, img.height);
    rr_image_free(&img);
  } else CHECK(0, "--output=a.png: %s", rr_device_message(dev));
  rr_device_release(dev);
  int threads = 0;
  const char *t = strstr(err, "threads=");
  CHECK(t && sscanf(t, "threads=%d", &threads) == 1 && threads >= 1, "--threads 0 ran on %d threads: %s", threads,
        err);
  const char *timings[] = {"load_ms=", "build_ms=", "frame_ms=", "shade_ms=", "write_ms=", "total_ms="};
  for (int i = 0; i < 6; i++) CHECK(strstr(err, timings[i]), "--stats lacks %s: %s", timings[i], err);

  /* --quiet: nothing on stderr; --verbose: the steps. */
  CHECK(cli("render tri.obj --size 16x16 -o q.png --quiet") == 0 && !err[0], "--quiet printed: %s", err);
  CHECK(cli("render tri.obj --size 16x16 -o q.png -q --progress") == 0 && !err[0], "--quiet --progress: %s", err);
  CHECK(cli("info tri.obj -q") == 0 && !err[0] && strstr(out, "triangles"), "info -q: %s", err);
  rc = cli("render tri.obj --size 16x16 -o v.png --aov depth=v.pfm -v");
  const char *steps[] = {"loaded tri.obj", "bvh:", "auto chose", "wrote v.png", "wrote v.pfm", "times:"};
  for (int i = 0; i < 6; i++) CHECK(rc == 0 && strstr(err, steps[i]), "--verbose lacks '%s': %s", steps[i], err);

  /* The progress line: with --progress, and never in a pipe without it. */
  rc = cli("render tri.obj --size 64x64 -o p.png --progress");
  CHECK(rc == 0 && strchr(err, '\r') && strstr(err, "rendering") && strstr(err, "100%"),
        "--progress shows no line: %s", err);
  rc = cli("render tri.obj --size 64x64 -o p.png --repeat 3 --progress");
  CHECK(rc == 0 && strstr(err, "frame 3/3"), "--repeat's frames: %s", err);
  rc = cli("render tri.obj --size 64x64 -o p.png --repeat 3 --stats -v");
  CHECK(rc == 0 && !strchr(err, '\r'), "a progress line in a pipe without --progress: %s", err);
  rc = cli("info tri.obj --progress");
  CHECK(rc == 0 && strchr(err, '\r') && strstr(err, "building the BVH"), "info --progress: %s", err);
}

/* Statistics JSON with a path that needs escaping, parsed back. */
static void stats_json(void) {
  char cmd[700];
  snprintf(cmd, sizeof cmd, "cp %s/tri.obj '%s/a\"b\\c.obj'", dir, dir);
  CHECK(system(cmd) == 0, "copy");
  int rc = cli("render 'a\"b\\c.obj' --size 16x16 -o s.png --stats-json s.json --repeat 2");
  CHECK(rc == 0, "render: %s", err);
  cJSON *j = read_json("s.json");
  CHECK(j != NULL, "s.json does not parse");
  const cJSON *scene = cJSON_GetObjectItemCaseSensitive(j, "scene");
  CHECK(cJSON_IsString(scene) && strcmp(scene->valuestring, "a\"b\\c.obj") == 0, "scene: %s",
        cJSON_IsString(scene) ? scene->valuestring : "(none)");
  const char *keys[] = {"load_ms", "build_ms", "frame_ms", "shade_ms", "write_ms", "total_ms", "triangles", "repeat"};
  for (int i = 0; i < 8; i++) {
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(j, keys[i]);
    CHECK(cJSON_IsNumber(v) && v->valuedouble >= 0, "%s in the JSON", keys[i]);
  }
  const cJSON *repeat = cJSON_GetObjectItemCaseSensitive(j, "repeat");
  CHECK(cJSON_IsNumber(repeat) && repeat->valueint == 2, "repeat");
  cJSON_Delete(j);
  /* No temporary file is left beside it. */
  DIR *d = opendir(dir);
  for (struct dirent *e; d && (e = readdir(d));) CHECK(!strstr(e->d_name, ".rastray-"), "left behind: %s", e->d_name);
  if (d) closedir(d);
}

static void write_text(const char *name, const char *text) { test_write_file(dir, name, text); }

static void cameras(void) {
  /* The saved camera renders the same bits, framed automatically or not, for each kind. */
  const char *kinds[] = {"perspective", "orthographic", "fisheye --fov 200"};
  for (int k = 0; k < 3; k++) {
    char args[512];
    snprintf(args, sizeof args,
             "render box:2 --size 64x48 --camera %s -o c1.png --aov id=c1.npy --save-camera c.json", kinds[k]);
    CHECK(cli(args) == 0, "%s: %s", args, err);
    CHECK(cli("render box:2 --size 64x48 -o c2.png --aov id=c2.npy --camera-file c.json") == 0, "%s", err);
    CHECK(same_files("c1.png", "c2.png") && same_files("c1.npy", "c2.npy"), "%s: the saved camera renders other bits",
          kinds[k]);
  }
  cJSON *j = read_json("c.json");
  const char *keys[] = {"type", "eye", "target", "up", "fov", "ortho_height", "width", "height"};
  for (int i = 0; i < 8; i++) CHECK(cJSON_HasObjectItem(j, keys[i]), "the camera file lacks %s", keys[i]);
  cJSON_Delete(j);

  /* Flags over the file: --fov replaces the file's, the rest stays. */
  CHECK(cli("render box:2 --size 64x48 -o c3.png --camera-file c.json --fov 90 --save-camera d.json") == 0, "%s", err);
  cJSON *c = read_json("c.json"), *d = read_json("d.json");
  const cJSON *fov = cJSON_GetObjectItemCaseSensitive(d, "fov");
  CHECK(cJSON_IsNumber(fov) && fov->valuedouble == 90, "--fov over the file");
  CHECK(cJSON_Compare(cJSON_GetObjectItemCaseSensitive(c, "eye"), cJSON_GetObjectItemCaseSensitive(d, "eye"), 1) &&
            cJSON_Compare(cJSON_GetObjectItemCaseSensitive(c, "type"), cJSON_GetObjectItemCaseSensitive(d, "type"), 1),
        "the file's eye and type are kept");
  cJSON_Delete(c), cJSON_Delete(d);

  /* A camera-to-world matrix (OpenGL: looking down -Z, +Y up) is the same camera as its flags. */
  write_text("m.json", "{\"matrix\": [[1, 0, 0, 0.5], [0, 1, 0, 0.25], [0, 0, 1, 6], [0, 0, 0, 1]], \"fov\": 40}");
  CHECK(cli("render demo --size 64x48 -o m1.png --camera-file m.json") == 0, "matrix: %s", err);
  CHECK(cli("render demo --size 64x48 -o m2.png --eye 0.5,0.25,6 --target 0.5,0.25,5 --up 0,1,0 --fov 40") == 0, "%s",
        err);
  CHECK(same_files("m1.png", "m2.png"), "the matrix's camera differs from its flags");

  /* Bad files: one line naming the file, exit 1, no image. */
  const struct {
    const char *text, *needle;
  } bad[] = {
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0]", "JSON"},
      {"[1, 2, 3]", "object"},
      {"{\"eye\": [0, 0, 5]}", "'target'"},
      {"{\"eye\": [0, 5], \"target\": [0, 0, 0]}", "'eye'"},
      {"{\"eye\": [0, \"0\", 5], \"target\": [0, 0, 0]}", "'eye'"},
      {"{\"eye\": [0, 0, 1e999], \"target\": [0, 0, 0]}", "finite"},
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": \"wide\"}", "'fov'"},
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 0}", "'fov'"},
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"type\": \"pinhole\"}", "'type'"},
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"eyes\": 1}", "'eyes'"},
      {"{\"eye\": [0, 0, 5], \"target\": [0, 0, 5]}", "eye"},
      {"{\"matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5]]}", "'matrix'"},
      {"{\"matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 1, 1]]}", "bottom row"},
      {"{\"matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 0, 1]], \"eye\": [0, 0, 5]}", "not both"},
      {"", "JSON"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    write_text("bad.json", bad[i].text);
    int rc = cli("render box:2 --size 16x16 -o x.png --camera-file bad.json");
    CHECK(rc == 1 && one_line(err) && strstr(err, "'bad.json'") && strstr(err, bad[i].needle),
          "'%s': exit %d, expected 1 and one line naming the file and %s: %s", bad[i].text, rc, bad[i].needle, err);
    char path[600];
    snprintf(path, sizeof path, "%s/x.png", dir);
    CHECK(access(path, F_OK) != 0, "'%s' left an image", bad[i].text);
  }
  int rc = cli("render box:2 --size 16x16 -o x.png --camera-file missing.json");
  CHECK(rc == 1 && one_line(err) && strstr(err, "missing.json"), "missing camera file: %d %s", rc, err);
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  write_text("tri.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
  help_and_man();
  usage_errors();
  options();
  stats_json();
  cameras();
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  return test_done();
}
