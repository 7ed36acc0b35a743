/* rastray: the command-line tool. Everything it does goes through rastray.h.
 * Exit codes: 0 success, 1 bad input (files, scenes), 2 bad usage (flags, values).
 * man/rastray.1 documents it; tests/test_cli_help.c keeps the two in step. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, mkstemp, fchmod, fdopen */

#include "cli.h"
#include "progress.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static int verbosity; /* -1: --quiet, 0, 1: --verbose */

/* What a run holds, so that every exit releases it: die() on a refusal, and the
 * signal watcher on SIGINT, SIGTERM or SIGHUP. The output set's temporaries are
 * removed on either; `lock` is held while the set changes, so a signal never
 * meets it half made. */
static struct {
  pthread_mutex_t lock;
  rr_device *dev;
  rr_scene *scene;
  rr_frame *frame;
  rr_output *set;
  rr_image *images; /* the run's images in the making, nimages of them */
  int nimages;
  atomic_bool committing; /* the set's temporaries are renamed (at once) and its streams written */
} run = {.lock = PTHREAD_MUTEX_INITIALIZER};

static void run_release(void) {
  pthread_mutex_lock(&run.lock);
  rr_output_release(run.set); /* removes its temporaries */
  run.set = NULL;
  pthread_mutex_unlock(&run.lock);
  for (int i = 0; i < run.nimages; i++) rr_image_free(&run.images[i]);
  rr_frame_release(run.frame);
  rr_scene_release(run.scene);
  rr_device_release(run.dev);
  run.frame = NULL, run.scene = NULL, run.dev = NULL;
}

/* Waits for the signals main() blocked in every thread; on one, removes the
 * output set's temporaries and exits with 128 + the signal (130 for SIGINT). The
 * rest of the run is the kernel's to free. */
static sem_t watcher_ready;
static void *watch_signals(void *arg) {
  sem_post(&watcher_ready);
  int sig;
  if (sigwait(arg, &sig) != 0) return NULL;
  /* An add ends in bounded time: wait for it. A commit renames the temporaries at
   * once, then may block on a pipe that is not read: nothing is left to remove. */
  for (;;) {
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 50000000;
    if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
    if (pthread_mutex_timedlock(&run.lock, &ts) == 0) {
      rr_output_release(run.set);
      break;
    }
    if (atomic_load(&run.committing)) break;
  }
  static const char msg[] = "\nrastray: interrupted\n";
  ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
  (void)ignored;
  _exit(128 + sig);
}

void die(int code, const char *fmt, ...) {
  progress_stop();
  va_list ap;
  va_start(ap, fmt);
  fputs("rastray: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  run_release();
  exit(code);
}

void note(int level, const char *fmt, ...) {
  if (verbosity < level) return;
  progress_clear();
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
}

double now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static void output_failed(rr_device *dev, rr_output *set);

void json_add(rr_device *dev, rr_output *set, cJSON *root, const char *path) {
  char *text = cJSON_Print(root);
  cJSON_Delete(root);
  if (!text) die(EXIT_INPUT, "out of memory writing '%s'", path);
  size_t n = strlen(text);
  text[n] = '\n'; /* over the terminating NUL: the bytes are counted */
  pthread_mutex_lock(&run.lock);
  rr_error e = rr_output_add_bytes(set, text, n + 1, path);
  pthread_mutex_unlock(&run.lock);
  cJSON_free(text);
  if (e) output_failed(dev, set);
}

#define STRING(x) #x
#define VALUE(x) STRING(x) /* a macro's value as a string literal */

/* ---- options --------------------------------------------------------------
 * Each command has one table of options; getopt_long reads it (--opt=value and
 * --opt value, unique prefixes, options and operands in any order) and the
 * command's usage is printed from it. A new option is one table entry and one
 * case in its command's switch. */

enum { /* keys of the options without a short form (above every char) */
  OPT_METHOD = 256, OPT_ORACLES, OPT_SIZE, OPT_CAMERA, OPT_ORTHO_HEIGHT, OPT_CUBE_FACES, OPT_EYE, OPT_TARGET,
  OPT_UP, OPT_FOV, OPT_SHADE, OPT_AOV, OPT_THREADS, OPT_REPEAT, OPT_STATS, OPT_STATS_JSON, OPT_CULL_BACKFACES,
  OPT_CAMERA_FROM_FILE, OPT_CAMERA_FILE, OPT_SAVE_CAMERA, OPT_PROGRESS, OPT_AA, OPT_AA_PATTERN, OPT_AA_FILTER,
  OPT_ALPHA, OPT_TEXTURE_FILTER, OPT_LOD_BIAS, OPT_LIGHT, OPT_SHADOWS, OPT_MAX_DEPTH, OPT_BACKGROUND,
  OPT_IMPORT_TIMEOUT, OPT_MAX_MEMORY,
  OPT_INTRINSICS, OPT_DISTORTION, OPT_EXTRINSICS,
};

typedef struct cli_option {
  const char *name; /* long name, without "--" */
  int key;          /* its short letter, or an OPT_ key */
  const char *arg;  /* the value's name in the usage; NULL: the option takes no value */
  const char *help; /* "\n" starts a continuation line */
} cli_option;

typedef struct cli_command cli_command;
struct cli_command {
  const char *name;
  const char *operands; /* in the usage line */
  const char *summary;  /* one line */
  const char *notes;    /* printed before the options, or NULL */
  const cli_option *options; /* ends with a NULL name */
  int (*run)(rr_device *dev, const cli_command *cmd, int argc, char **argv); /* argv[0]: the command's name */
};

#define HELP_OPTION {"help", 'h', NULL, "print this help and exit"}
/* Every command's last options; next_option handles them. */
#define COMMON_OPTIONS                                                                                    \
  {"import-timeout", OPT_IMPORT_TIMEOUT, "SECONDS",                                                     \
   "longest a scene file's import may take (default 60; 0: no limit)"},                                \
      {"max-memory", OPT_MAX_MEMORY, "BYTES[K|M|G]",                                                    \
       "most memory a scene file's import may allocate (default: half the\n"                           \
       "physical memory; 0: no limit); files are imported in a child process"},                        \
  {"progress", OPT_PROGRESS, NULL,                                                                      \
   "show progress on stderr even when it is not a terminal (on a terminal it\n"                        \
   "appears by itself once a command runs longer than a second)"},                                     \
      {"quiet", 'q', NULL, "print nothing on stderr but errors (and --stats when asked)"},              \
      {"verbose", 'v', NULL, "also print what was loaded, the BVH, the method and why, the outputs\n"   \
                             "written and the time of each step"},                                      \
      HELP_OPTION

static const char scenes_note[] =
    "scenes: a file assimp reads (.obj .ply .gltf .glb .dae .3ds ...), a scene file (.json:\n"
    "        meshes, transforms, materials, lights, camera and settings, which options\n"
    "        override; docs/scene-file.md), or demo, plane[:N], sphere[:N], box[:N], torus[:N],\n"
    "        rooms[:N], grid:PATH:N (N×N instances of a mesh; grid-flat:PATH:N written\n"
    "        out), ground (an infinite plane\n"
    "        through points at infinity, with a sphere and a box; 3D methods), checker (an\n"
    "        infinite checkerboard-textured plane seen at a grazing angle)\n";

static const cli_option render_options[] = {
    {"method", OPT_METHOD, "NAME",
     "visibility method: auto (default: chosen by a cost model of the view), rc,\n"
     "rc-bvh, rc-packet, 2dr-bb, 2dr-bin, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full"},
    {"oracles", OPT_ORACLES, "K=V,...",
     "override a 3dr method's traversal: frustum=N leaves=0|1 outside=0|1\n"
     "occluded=0|1 split=N split-ratio=F binning=0|1 early-z=0|1 bin=N bin-min=N"},
    {"size", OPT_SIZE, "WxH", "image size (default 1024x768, at most " VALUE(RR_MAX_SIZE) " a side)"},
    {"camera", OPT_CAMERA, "NAME",
     "perspective (default), orthographic, parabolic, latlong, fisheye, cube,\n"
     "opencv, opencv-fisheye (OpenCV's models: --intrinsics, --distortion)"},
    {"intrinsics", OPT_INTRINSICS, "FX,FY,CX,CY",
     "OpenCV intrinsics in pixels (pixel centres at integers); alone: --camera opencv"},
    {"distortion", OPT_DISTORTION, "K1,K2,...",
     "OpenCV distortion: k1,k2,p1,p2[,k3[,k4,k5,k6]] (opencv) or k1,k2,k3,k4\n(opencv-fisheye)"},
    {"extrinsics", OPT_EXTRINSICS, "R,T|FILE",
     "world-to-camera pose x_cam = R·x + t (x right, y down, z forward): 12\n"
     "numbers R11,R12,...,R33,T1,T2,T3, or a file holding them (in place of\n--eye/--target/--up)"},
    {"ortho-height", OPT_ORTHO_HEIGHT, "H", "orthographic view height (default 2·|target-eye|·tan(fov/2))"},
    {"cube-faces", OPT_CUBE_FACES, "DIR", "cube camera: also write the six faces as DIR/front.png, right, back, ..."},
    {"eye", OPT_EYE, "X,Y,Z", "camera position; without --eye/--target the scene is framed automatically"},
    {"target", OPT_TARGET, "X,Y,Z", "the point the camera looks at (goes with --eye)"},
    {"up", OPT_UP, "X,Y,Z", "the camera's up direction (default 0,1,0)"},
    {"fov", OPT_FOV, "DEG", "vertical field of view (default 45; fisheye: the full angle, up to 360)"},
    {"camera-file", OPT_CAMERA_FILE, "FILE[:IMAGE]",
     "read the camera from a JSON file (as --save-camera writes, or a 4x4\n"
     "camera-to-world \"matrix\" and \"fov\"), or a COLMAP text model (its\n"
     "directory) or NeRF transforms.json with an image's name or index (the\n"
     "image's size unless --size); camera flags override its values"},
    {"save-camera", OPT_SAVE_CAMERA, "FILE", "write the camera used (after automatic framing) as JSON"},
    {"camera-from-file", OPT_CAMERA_FROM_FILE, "NAME|INDEX",
     "look through a camera the scene file defines (see info); --camera may\nchange its projection"},
    {"shade", OPT_SHADE, "MODE",
     "lit (default: the scene's lights, or a key light and a sky when it has none,\n"
     "with shadows and mirror reflections; see docs/shading.md), lambert (a\n"
     "headlight), id, normal, depth, heat-evals, heat-nodes"},
    {"light", OPT_LIGHT, "SPEC",
     "add a light (repeatable; the default rig is then off): point:X,Y,Z:R,G,B[:I]\n"
     "(I candela, default 1), dir:DX,DY,DZ:R,G,B[:E] (shining along D, E lux),\n"
     "spot:X,Y,Z:DX,DY,DZ:R,G,B[:I[:INNER[:OUTER]]] (half-angles, default 0 and 45\n"
     "degrees), sky:R,G,B[:R,G,B] (radiance from above[, from below: a gradient])"},
    {"shadows", OPT_SHADOWS, "MODE", "lit: none, rays (default: shadow rays through the ray streams), raster\n"
                                     "(the same rays rasterized from the light, the same bits), auto"},
    {"max-depth", OPT_MAX_DEPTH, "N", "lit: most mirror bounces, 0.." VALUE(RR_MAX_DEPTH) " (default 2)"},
    {"aa", OPT_AA, "MODE",
     "anti-aliasing: none (default), ssaa:N (N samples, each shaded), msaa:N (shaded\n"
     "once per pixel per primitive), csaa:K/N (N coverage samples, K with colour);\n"
     "N, K: 1, 2, 4, 8 or 16"},
    {"aa-pattern", OPT_AA_PATTERN, "NAME",
     "sample positions: standard (default: Direct3D's and Vulkan's), rotated (a\n"
     "rotated grid), jitter[:SEED] (one random position per cell; seed default 1)"},
    {"aa-filter", OPT_AA_FILTER, "NAME[:R]",
     "resolve filter of a pixel's samples: box (default: the mean of its own),\n"
     "mitchell (B=C=1/3, radius R default 2), blackman-harris (R default 1.5);\n"
     "R in pixels, 0.5..4; wide filters read the neighbours' samples too"},
    {"alpha", OPT_ALPHA, NULL,
     "give the colour image an alpha channel: the coverage of the pixel's samples\n"
     "(filtered), colour straight (PNG RGBA, EXR R G B A)"},
    {"background", OPT_BACKGROUND, "R,G,B", "the colour behind misses, linear RGB (default: a grey-blue gradient)"},
    {"texture-filter", OPT_TEXTURE_FILTER, "NAME[:N]",
     "how textures are read over a pixel's footprint (exact derivatives for every\n"
     "camera): nearest, bilinear (level 0; they alias), trilinear, aniso[:N] (up\n"
     "to N trilinear probes along the footprint, N 1..16; default aniso:16), ewa"},
    {"lod-bias", OPT_LOD_BIAS, "F", "added to the texture's MIP level (default 0; > 0 blurs, < 0 sharpens)"},
    {"output", 'o', "PATH",
     "colour image: .png (sRGB), .exr or .pfm (linear light); default rastray.png\n"
     "unless --aov is given. PATH may be - (stdout, PNG), FMT:PATH (png:-, exr:-),\n"
     "or a device or FIFO such as /dev/null"},
    {"aov", OPT_AOV, "LIST=PATH",
     "write AOVs as .npy, .pfm or .exr (stdout: - as NPY, or FMT:-); repeatable.\n"
     "LIST: one NAME, NAME,NAME,... or all, as the layers of one EXR. NAME: color\n"
     "(the shaded image), depth (EXR Z), normal (N.X N.Y N.Z), bary (bary.u bary.v),\n"
     "id (triangle), mesh (geometry id), material (index), instance (ids: EXR UINT),\n"
     "evals,\n"
     "nodes, coverage (fraction of samples hit), sample-id, sample-depth,\n"
     "sample-mesh (H×W×N, one per sample: EXR id.s00.., Z.s00.., mesh.s00..), uv\n"
     "(texture coordinates: uv.u uv.v), uv-deriv (their derivatives per pixel:\n"
     "uvdx.u uvdx.v uvdy.u uvdy.v); all: color to nodes (evals, nodes with heat).\n"
     "With several samples id, mesh, material, normal, bary, uv, uv-deriv are the\n"
     "sample nearest the centre's, depth the nearest.\n"
     "The lit shading's parts, as Blender Cycles' passes (the centre sample's, default\n"
     "shadows and depth): albedo, direct, reflection, emission (EXR NAME.R/G/B; colour =\n"
     "direct + reflection + emission), shadow (fraction of the lights reaching a point),\n"
     "shadow-lights (H×W×L, 1 where light i reaches it: EXR shadow.l00..; shadow is\n"
     "their mean; at most " VALUE(RR_MAX_SHADOW_LIGHTS) " lights).\n"
     "z-depth: distance along the optical axis (EXR zdepth; depth is the eye distance).\n"
     "Outputs are all or nothing"},
    {"threads", OPT_THREADS, "N", "threads, at most " VALUE(RR_MAX_THREADS) " (default 0: all cores)"},
    {"repeat", OPT_REPEAT, "N", "run the visibility pass N times, report the median time"},
    {"stats", OPT_STATS, NULL, "print key=value statistics to stderr, with the time of each step"},
    {"stats-json", OPT_STATS_JSON, "PATH", "write the statistics as one JSON object"},
    {"cull-backfaces", OPT_CULL_BACKFACES, NULL, "triangles seen from behind are invisible"},
    COMMON_OPTIONS,
    {NULL, 0, NULL, NULL},
};

static const cli_option info_options[] = {
    {"threads", OPT_THREADS, "N", "threads building the BVH, at most " VALUE(RR_MAX_THREADS) " (default 0: all cores)"},
    COMMON_OPTIONS,
    {NULL, 0, NULL, NULL},
};

static int cmd_render(rr_device *dev, const cli_command *cmd, int argc, char **argv);
static int cmd_info(rr_device *dev, const cli_command *cmd, int argc, char **argv);
static int cmd_help(rr_device *dev, const cli_command *cmd, int argc, char **argv);

static const cli_option help_options[] = {
    HELP_OPTION,
    {NULL, 0, NULL, NULL},
};

static const cli_command commands[] = {
    {"render", "[SCENE] [options]", "render SCENE (a mesh file or built-in name; default demo)", scenes_note,
     render_options, cmd_render},
    {"info", "SCENE [options]", "print the scene's triangles, geometries and BVH figures", scenes_note, info_options,
     cmd_info},
    {"help", "[COMMAND]", "print the commands, or a command's options", NULL, help_options, cmd_help},
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

/* The command named `name`; an unknown one ends the program with a usage error. */
static const cli_command *find_command(const char *name) {
  for (int c = 0; c < NCOMMANDS; c++)
    if (strcmp(name, commands[c].name) == 0) return &commands[c];
  char names[256] = "";
  for (int c = 0; c < NCOMMANDS; c++)
    snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", commands[c].name,
             c == NCOMMANDS - 1 ? "" : c == NCOMMANDS - 2 ? " or " : ", ");
  die(EXIT_USAGE, "unknown command '%s' (expected %s; see --help)", name, names);
}

/* The overview: the commands and where their options are. */
static void print_overview(FILE *f) {
  fputs("usage: rastray COMMAND [options]\n       rastray --help | --version\n\ncommands:\n", f);
  for (int c = 0; c < NCOMMANDS; c++) fprintf(f, "  %-8s %s\n", commands[c].name, commands[c].summary);
  fputs("\n'rastray COMMAND --help' or 'rastray help COMMAND' lists a command's options.\n"
        "Exit status: 0 success, 1 bad input (files, scenes), 2 bad usage (options, values).\n",
        f);
}

static void print_usage(FILE *f, const cli_command *cmd) {
  fprintf(f, "usage: rastray %s %s\n%s\n", cmd->name, cmd->operands, cmd->summary);
  if (cmd->notes) fprintf(f, "\n%s", cmd->notes);
  fputs("\noptions:\n", f);
  enum { COLUMN = 24 }; /* where the help text starts */
  for (const cli_option *o = cmd->options; o->name; o++) {
    int n = o->key < 256 ? fprintf(f, "  -%c, ", o->key) : fprintf(f, "  ");
    n += fprintf(f, "--%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
    if (n + 2 > COLUMN) fprintf(f, "\n%*s", COLUMN, "");
    else fprintf(f, "%*s", COLUMN - n, "");
    for (const char *h = o->help; *h; h++) {
      fputc(*h, f);
      if (*h == '\n') fprintf(f, "%*s", COLUMN, "");
    }
    fputc('\n', f);
  }
}

static char option_name[64]; /* the option being handled, "--name", for messages */
static bool force_progress; /* --progress */
static rr_import_limits import_limits; /* --import-timeout, --max-memory; rr_import_limits_init's by main */

/* --import-timeout's value: seconds, 0 (no limit) up to a year. */
static double parse_seconds(const char *flag, const char *s) {
  char *end;
  double v = strtod(s, &end);
  if (!*s || *end || !(v >= 0) || v > 3.2e7) die(EXIT_USAGE, "bad value '%s' for %s (expected seconds, 0..3.2e7)", s, flag);
  return v;
}

/* --max-memory's value: bytes with an optional K, M or G (powers of 1024). */
static uint64_t parse_bytes(const char *flag, const char *s) {
  char *end;
  double v = strtod(s, &end);
  double unit = 1;
  if (*end && !end[1]) unit = *end == 'K' || *end == 'k' ? 1024.0 : *end == 'M' || *end == 'm' ? 1048576.0
                              : *end == 'G' || *end == 'g' ? 1073741824.0 : 0;
  else if (*end) unit = 0;
  if (end == s || unit == 0 || !(v >= 0) || v * unit > 1.8e19 || !isfinite(v))
    die(EXIT_USAGE, "bad value '%s' for %s (expected bytes, with K, M or G for KiB, MiB, GiB)", s, flag);
  return (uint64_t)(v * unit);
}

/* The next option of the command's argv (argv[0] is the command's name): its key,
 * its value in optarg; -1 after the last (the operands are then argv[optind..]).
 * Unknown options and missing values end the program with a usage error; --help
 * prints the command's usage and ends it. */
static int next_option(const cli_command *cmd, int argc, char **argv) {
  static struct option longopts[64];
  static char shortopts[64] = ":"; /* ':': a missing value is reported as ':', not '?' */
  if (!longopts[0].name) { /* one command per process: build its table once */
    int n = 0, s = 1;
    for (const cli_option *o = cmd->options; o->name; o++, n++) {
      longopts[n] = (struct option){o->name, o->arg ? required_argument : no_argument, NULL, o->key};
      if (o->key < 256) {
        shortopts[s++] = (char)o->key;
        if (o->arg) shortopts[s++] = ':';
      }
    }
    opterr = 0; /* the messages are ours */
  }
  int key = getopt_long(argc, argv, shortopts, longopts, NULL);
  if (key == -1) return -1;
  /* getopt leaves the key of a known option that failed in optopt (0 for an unknown long one) */
  const cli_option *o = cmd->options;
  while (o->name && o->key != (key == '?' || key == ':' ? optopt : key)) o++;
  if (o->name) snprintf(option_name, sizeof option_name, "--%s", o->name);
  if (key == '?' && o->name) die(EXIT_USAGE, "%s takes no value (see --help)", option_name);
  if (key == '?' && optopt) die(EXIT_USAGE, "unknown option '-%c' (see --help)", optopt);
  if (key == '?') die(EXIT_USAGE, "unknown option '%s' (see --help)", argv[optind - 1]);
  if (key == ':') die(EXIT_USAGE, "%s needs a value (see --help)", argv[optind - 1]);
  switch (key) {
  case 'h': print_usage(stdout, cmd), exit(0);
  case 'q': verbosity = -1; return next_option(cmd, argc, argv);
  case 'v': verbosity = 1; return next_option(cmd, argc, argv);
  case OPT_PROGRESS: force_progress = true; return next_option(cmd, argc, argv);
  case OPT_IMPORT_TIMEOUT: import_limits.timeout_s = parse_seconds(option_name, optarg); return next_option(cmd, argc, argv);
  case OPT_MAX_MEMORY: import_limits.max_memory = parse_bytes(option_name, optarg); return next_option(cmd, argc, argv);
  }
  return key;
}

static long parse_int(const char *flag, const char *s, long lo, long hi) {
  char *end;
  double v = s ? strtod(s, &end) : 0;
  if (!s || !*s || *end || !isfinite(v) || v != floor(v))
    die(EXIT_USAGE, "bad value '%s' for %s (expected an integer)", s ? s : "", flag);
  if (v < lo || v > hi) die(EXIT_USAGE, "bad value '%s' for %s (expected %ld..%ld)", s, flag, lo, hi);
  return (long)v;
}

static float parse_float(const char *flag, const char *s) {
  char *end;
  double v = s ? strtod(s, &end) : 0;
  if (!s || !*s || *end || !isfinite(v) || fabs(v) > 1e30)
    die(EXIT_USAGE, "bad value '%s' for %s (expected a finite number)", s ? s : "", flag);
  return (float)v;
}

static void parse_vec(const char *flag, const char *s, float out[3]) {
  char buf[256];
  if (!s || strlen(s) >= sizeof buf) die(EXIT_USAGE, "bad vector '%s' for %s (expected X,Y,Z)", s ? s : "", flag);
  strcpy(buf, s);
  char *save = NULL, *tok = strtok_r(buf, ",", &save);
  int n = 0;
  for (; tok && n < 3; tok = strtok_r(NULL, ",", &save)) {
    char *end;
    double v = strtod(tok, &end);
    if (!*tok || *end || !isfinite(v) || fabs(v) > 1e30) break;
    out[n++] = (float)v;
  }
  if (n != 3 || tok || s[strlen(s) - 1] == ',' || s[0] == ',')
    die(EXIT_USAGE, "bad vector '%s' for %s (expected X,Y,Z with finite numbers)", s, flag);
}

/* The most samples a frame may have: 2^27, e.g. 16384x8192 with one sample per pixel
 * or 4096x2048 with 16 (a frame of 2^27 samples takes about a minute on two cores). */
#define SAMPLE_BUDGET (1u << 27)
/* Bytes a frame takes per pixel and per sample, about (visibility buffer, shading,
 * resolve; measured with /usr/bin/time -v on cube views of a plane). */
enum { PIXEL_BYTES = 16, SAMPLE_BYTES = 32 };

/* Refuses a frame whose sample count or estimated memory exceeds the budget: half of
 * the physical memory, SAMPLE_BUDGET samples. */
static void check_frame_budget(const rr_render_options *opt) {
  uint64_t pixels = (uint64_t)opt->width * (uint64_t)opt->height, samples = pixels * (uint64_t)opt->samples;
  uint64_t bytes = pixels * PIXEL_BYTES + samples * SAMPLE_BYTES;
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  uint64_t half = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page / 2 : 0;
  if (samples > SAMPLE_BUDGET)
    die(EXIT_USAGE, "a %dx%d image with %d sample%s per pixel has %llu samples, more than the budget of %u "
        "(lower --size or the --aa samples)", opt->width, opt->height, opt->samples, opt->samples == 1 ? "" : "s",
        (unsigned long long)samples, SAMPLE_BUDGET);
  if (half && bytes > half)
    die(EXIT_USAGE, "a %dx%d image with %d sample%s per pixel needs about %.1f GiB, more than half the physical "
        "memory (%.1f GiB; lower --size or the --aa samples)", opt->width, opt->height, opt->samples,
        opt->samples == 1 ? "" : "s", bytes / 1073741824.0, half / 1073741824.0);
}

/* Up to max comma-separated finite numbers (whitespace too, for files); their count. */
static int parse_floats(const char *flag, const char *s, float *out, int max) {
  int n = 0;
  const char *p = s;
  for (;;) {
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') p++;
    if (!*p) break;
    char *end;
    double v = strtod(p, &end);
    if (end == p || !isfinite(v) || fabs(v) > 1e30 || n == max)
      die(EXIT_USAGE, "bad value '%s' for %s (expected at most %d finite numbers separated by commas)", s, flag, max);
    out[n++] = (float)v;
    p = end;
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') p++;
    if (*p == ',') p++;
  }
  return n;
}

/* --extrinsics: 12 numbers, given or in a file. */
static void parse_extrinsics(rr_device *dev, const char *s, rr_camera *cam) {
  float v[12];
  char text[4096];
  const char *src = s;
  if (strchr(s, ',') == NULL) { /* a file */
    FILE *f = fopen(s, "rb");
    if (!f) die(EXIT_INPUT, "cannot open extrinsics file '%s': %s", s, strerror(errno));
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = 0;
    src = text;
  }
  if (parse_floats("--extrinsics", src, v, 12) != 12)
    die(EXIT_USAGE, "bad value '%s' for --extrinsics (expected 12 numbers: R row by row, then t)", s);
  if (rr_camera_set_extrinsics(dev, cam, v, v + 9) != RR_OK) die(EXIT_USAGE, "--extrinsics: %s", rr_device_message(dev));
}

static void parse_size(const char *s, int *w, int *h) {
  char buf[64];
  if (!s || strlen(s) >= sizeof buf) die(EXIT_USAGE, "bad size '%s' (expected WxH, e.g. 1024x768)", s ? s : "");
  strcpy(buf, s);
  char *x = strchr(buf, 'x');
  if (!x) die(EXIT_USAGE, "bad size '%s' (expected WxH, e.g. 1024x768)", s);
  *x = 0;
  char *end;
  long a = strtol(buf, &end, 10);
  bool bad = !*buf || *end;
  long b = strtol(x + 1, &end, 10);
  bad = bad || !x[1] || *end;
  if (bad) die(EXIT_USAGE, "bad size '%s' (expected WxH, e.g. 1024x768)", s);
  if (a < 1 || b < 1 || a > RR_MAX_SIZE || b > RR_MAX_SIZE)
    die(EXIT_USAGE, "bad size '%s' (each side must be 1..%d)", s, RR_MAX_SIZE);
  *w = (int)a, *h = (int)b;
}

/* An --aa MODE: the mode, its samples N and (csaa) stored samples K. */
typedef struct {
  rr_aa_mode mode;
  int samples, stored;
} aa_spec;

/* A sample count of --aa: 1, 2, 4, 8 or 16, the whole of s. */
static bool parse_count(const char *s, char **end, int *n) {
  long v = strtol(s, end, 10);
  *n = (int)v;
  return *end != s && (v == 1 || v == 2 || v == 4 || v == 8 || v == 16);
}

static aa_spec parse_aa(const char *arg) {
  aa_spec a = {RR_AA_NONE, 1, 0};
  char *end = NULL;
  bool ok;
  if (!strcmp(arg, "none")) return a;
  if (!strncmp(arg, "ssaa:", 5) || !strncmp(arg, "msaa:", 5)) {
    a.mode = arg[0] == 's' ? RR_AA_SSAA : RR_AA_MSAA;
    ok = parse_count(arg + 5, &end, &a.samples) && !*end;
  } else if (!strncmp(arg, "csaa:", 5)) {
    a.mode = RR_AA_CSAA;
    ok = parse_count(arg + 5, &end, &a.stored) && *end == '/' && parse_count(end + 1, &end, &a.samples) && !*end &&
         a.stored <= a.samples;
  } else {
    die(EXIT_USAGE, "unknown --aa '%s' (expected none, ssaa:N, msaa:N or csaa:K/N)", arg);
  }
  if (!ok) die(EXIT_USAGE, "bad --aa '%s' (N and K: 1, 2, 4, 8 or 16, K at most N)", arg);
  return a;
}

static rr_aa_pattern parse_aa_pattern(const char *arg, uint32_t *seed) {
  if (!strcmp(arg, "standard")) return RR_AA_STANDARD;
  if (!strcmp(arg, "rotated")) return RR_AA_ROTATED;
  if (!strcmp(arg, "jitter")) return RR_AA_JITTER;
  if (!strncmp(arg, "jitter:", 7)) {
    *seed = (uint32_t)parse_int("--aa-pattern's seed", arg + 7, 0, UINT32_MAX);
    return RR_AA_JITTER;
  }
  die(EXIT_USAGE, "unknown --aa-pattern '%s' (expected standard, rotated or jitter[:SEED])", arg);
}

/* An --aov: the images written as one file (several: the layers of one EXR). */
enum { COLOR_BIT = 1u << RR_AOV_COUNT }; /* the shaded image, beside AOV a's bit 1 << a */
typedef struct {
  unsigned images; /* COLOR_BIT and AOV bits */
  bool all;        /* `all`: resolved once heat is known */
  const char *path;
} aov_out;

/* Parses --aov LIST=PATH. */
static aov_out parse_aov(const char *arg) {
  const char *eq = strchr(arg, '=');
  char list[256];
  if (!eq || eq == arg || !eq[1] || (size_t)(eq - arg) >= sizeof list)
    die(EXIT_USAGE, "bad --aov '%s' (expected LIST=PATH)", arg);
  memcpy(list, arg, eq - arg), list[eq - arg] = 0;
  aov_out a = {0, false, eq + 1};
  char *save = NULL;
  for (char *name = strtok_r(list, ",", &save); name; name = strtok_r(NULL, ",", &save)) {
    int k = rr_aov_from_name(name);
    if (!strcmp(name, "all")) a.all = true;
    else if (!strcmp(name, "color")) a.images |= COLOR_BIT;
    else if (k >= 0) a.images |= 1u << k;
    else
      die(EXIT_USAGE,
          "unknown AOV '%s' (expected color, depth, id, mesh, material, normal, bary, evals, nodes, coverage, "
          "sample-id, sample-depth, sample-mesh, uv, uv-deriv, albedo, direct, reflection, shadow, emission, "
          "z-depth, shadow-lights, instance or all)",
          name);
  }
  if (!a.images && !a.all) die(EXIT_USAGE, "bad --aov '%s' (expected LIST=PATH)", arg);
  return a;
}

/* Parses --light (see its help) into a light for rr_scene_add_light. */
static rr_light_info parse_light(const char *arg) {
  static const char usage[] = "(expected point:X,Y,Z:R,G,B[:I], dir:DX,DY,DZ:R,G,B[:E], "
                              "spot:X,Y,Z:DX,DY,DZ:R,G,B[:I[:INNER[:OUTER]]] or sky:R,G,B[:R,G,B])";
  char buf[512], *field[8];
  int n = 0;
  if (strlen(arg) >= sizeof buf) die(EXIT_USAGE, "bad light '%.40s...' for --light %s", arg, usage);
  strcpy(buf, arg);
  for (char *p = buf; n < 8; n++) {
    field[n] = p;
    if (!(p = strchr(p, ':'))) {
      n++;
      break;
    }
    *p++ = 0;
  }
  rr_light_info l = {0};
  const char *kind = field[0];
  int vectors = 0, least = 0, most = 0; /* the X,Y,Z fields; the fewest and most fields in all */
  if (strcmp(kind, "point") == 0) l.type = RR_LIGHT_POINT, vectors = 2, least = 3, most = 4;
  else if (strcmp(kind, "dir") == 0) l.type = RR_LIGHT_DIRECTIONAL, vectors = 2, least = 3, most = 4;
  else if (strcmp(kind, "spot") == 0) l.type = RR_LIGHT_SPOT, vectors = 3, least = 4, most = 7;
  else if (strcmp(kind, "sky") == 0) l.type = RR_LIGHT_AMBIENT, vectors = 2, least = 2, most = 3;
  if (!vectors || n < least || n > most) die(EXIT_USAGE, "bad light '%s' for --light %s", arg, usage);
  float *vec[3] = {l.position, l.direction, l.color}; /* the fields' places by kind: spot's */
  if (l.type == RR_LIGHT_POINT) vec[1] = l.color;
  if (l.type == RR_LIGHT_DIRECTIONAL) vec[0] = l.direction, vec[1] = l.color;
  if (l.type == RR_LIGHT_AMBIENT) vec[0] = l.color, vec[1] = l.ground;
  for (int k = 1; k < n && k <= vectors; k++) parse_vec("--light", field[k], vec[k - 1]);
  float scale = 1, inner = 0, outer = 45;
  if (l.type != RR_LIGHT_AMBIENT && n > vectors + 1) scale = parse_float("--light", field[vectors + 1]);
  if (n > vectors + 2) inner = parse_float("--light", field[vectors + 2]);
  if (n > vectors + 3) outer = parse_float("--light", field[vectors + 3]);
  for (int c = 0; c < 3; c++) l.color[c] *= scale;
  if (!(scale >= 0)) die(EXIT_USAGE, "bad light '%s' for --light: a negative intensity", arg);
  for (int c = 0; c < 3; c++)
    if (l.color[c] < 0 || l.ground[c] < 0) die(EXIT_USAGE, "bad light '%s' for --light: a negative colour", arg);
  if ((l.type == RR_LIGHT_DIRECTIONAL || l.type == RR_LIGHT_SPOT) && !l.direction[0] && !l.direction[1] && !l.direction[2])
    die(EXIT_USAGE, "bad light '%s' for --light: a zero direction", arg);
  if (l.type == RR_LIGHT_SPOT && !(inner >= 0 && inner <= outer && outer <= 90 && outer > 0))
    die(EXIT_USAGE, "bad light '%s' for --light: cone angles outside 0 <= inner <= outer <= 90 degrees", arg);
  l.inner_cone_deg = inner, l.outer_cone_deg = outer;
  return l;
}

/* NAME[:REST]: NAME looked up by from_name (-1 when unknown); *rest is what
 * follows the colon, NULL without one. */
static int name_and_rest(const char *arg, int (*from_name)(const char *), const char **rest) {
  char name[32];
  const char *colon = strchr(arg, ':');
  size_t len = colon ? (size_t)(colon - arg) : strlen(arg);
  *rest = colon ? colon + 1 : NULL;
  if (len >= sizeof name) return -1;
  memcpy(name, arg, len), name[len] = 0;
  return from_name(name);
}

/* Parses --aa-filter NAME[:RADIUS]. */
static void parse_filter(const char *arg, rr_shade_options *ro) {
  const char *radius;
  int f = name_and_rest(arg, rr_filter_from_name, &radius);
  if (f < 0) die(EXIT_USAGE, "unknown filter '%s' for --aa-filter (expected box, mitchell or blackman-harris)", arg);
  ro->filter = (rr_filter)f;
  if (!radius) return;
  ro->radius = parse_float(option_name, radius);
  if (!(ro->radius >= 0.5f && ro->radius <= RR_FILTER_MAX_RADIUS))
    die(EXIT_USAGE, "bad radius '%s' for --aa-filter (expected 0.5..%g pixels)", radius, (double)RR_FILTER_MAX_RADIUS);
}

/* Parses --texture-filter NAME[:N] (N: aniso's probes). */
static void parse_texture_filter(const char *arg, rr_shade_options *ro) {
  const char *probes;
  int f = name_and_rest(arg, rr_texture_filter_from_name, &probes);
  if (f < 0)
    die(EXIT_USAGE,
        "unknown texture filter '%s' for --texture-filter (expected nearest, bilinear, trilinear, aniso[:N] or ewa)",
        arg);
  ro->texture_filter = (rr_texture_filter)f;
  if (!probes) return;
  if (f != RR_TEXTURE_ANISO) die(EXIT_USAGE, "bad --texture-filter '%s' (only aniso takes :N)", arg);
  ro->aniso = (int)parse_int("--texture-filter aniso:N", probes, 1, 16);
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Loads a scene, its BVH built on `threads` threads; *load_ms is the time of the
 * load without the build. Progress shows from here on: loading is the first long step. */
/* Whether a scene name is a scene file (rr_scene_load_file), by its extension. */
static bool is_scene_file(const char *name) {
  size_t n = strlen(name);
  return n > 5 && strcmp(name + n - 5, ".json") == 0;
}

/* Loads a scene (exits when it cannot); a scene file's settings go to *settings
 * (which may be NULL), given 0 for other scenes. */
static rr_scene *load_scene(rr_device *dev, const char *name, int threads, double *load_ms,
                            rr_scene_settings *settings) {
  if (verbosity >= 0) progress_start(dev, force_progress);
  rr_build_options build;
  rr_build_options_init(&build);
  build.threads = threads;
  rr_device_set_build_options(dev, &build);
  double t0 = now_ms();
  rr_scene *scene;
  if (settings) settings->given = settings->camera_given = 0;
  import_limits.importer_log = verbosity > 0;
  rr_device_set_import_limits(dev, &import_limits);
  rr_error e = is_scene_file(name) ? rr_scene_load_file(dev, name, NULL, &scene, settings)
                                   : rr_scene_load(dev, name, &scene);
  if (e != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
  run.scene = scene;
  rr_scene_info in;
  rr_scene_get_info(scene, &in);
  *load_ms = now_ms() - t0 - in.bvh_build_ms;
  note(1, "loaded %s: %llu triangles (%llu skipped), %u geometries, %u materials in %.1f ms\n", name,
       (unsigned long long)in.triangles, (unsigned long long)in.skipped, in.geometries, in.materials, *load_ms);
  note(1, "bvh: %llu nodes, %llu leaves, depth %u, SAH cost %.3f, %.2f MiB, built in %.1f ms\n",
       (unsigned long long)in.bvh_nodes, (unsigned long long)in.bvh_leaves, in.bvh_depth, in.bvh_sah_cost,
       in.bvh_bytes / 1048576.0, in.bvh_build_ms);
  if (in.textures_missing) /* rendered without them: say so, not only in info */
    note(0, "rastray: warning: %u of %u textures missing or unreadable (rastray info '%s' lists them)\n",
         in.textures_missing, in.textures, name);
  return scene;
}

/* Ends the run on a failed output (the set's device holds why); die() removes the set's temporaries. */
static void output_failed(rr_device *dev, rr_output *set) {
  (void)set;
  die(rr_device_error(dev) == RR_ERROR_ARGUMENT ? EXIT_USAGE : EXIT_INPUT, "%s", rr_device_message(dev));
}

static rr_error set_add(rr_output *set, const rr_image *images, int n, const char *path) {
  pthread_mutex_lock(&run.lock);
  rr_error e = rr_output_add(set, images, n, path);
  pthread_mutex_unlock(&run.lock);
  return e;
}

static void add_output(rr_device *dev, rr_output *set, const rr_image *images, int n, const char *path) {
  if (set_add(set, images, n, path)) output_failed(dev, set);
}

/* Cuts the six faces out of a cube camera's cross and adds DIR/<face>.png to the set. */
static void add_cube_faces(rr_device *dev, rr_output *set, const rr_image *cross, const char *dir) {
  static const struct {
    const char *name;
    int col, row;
  } faces[6] = {{"front", 1, 1}, {"right", 2, 1}, {"back", 3, 1}, {"left", 0, 1}, {"top", 1, 0}, {"bottom", 1, 2}};
  int n = cross->height / 3;
  for (int f = 0; f < 6; f++) {
    rr_image img = {n, n, 3, RR_PIXEL_F32, malloc((size_t)n * n * 3 * sizeof(float)), cross->kind};
    if (!img.data) die(EXIT_INPUT, "out of memory");
    for (int y = 0; y < n; y++)
      memcpy((float *)img.data + (size_t)y * n * 3,
             (const float *)cross->data + ((size_t)(faces[f].row * n + y) * cross->width + faces[f].col * n) * 3,
             (size_t)n * 3 * sizeof(float));
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.png", dir, faces[f].name);
    rr_error e = set_add(set, &img, 1, path);
    free(img.data);
    if (e) output_failed(dev, set);
  }
}

/* The times of a render's steps, in milliseconds. */
typedef struct {
  double load, build, frame, cpu, shade, resolve, write, total;
  uint64_t shades; /* shading invocations of the colour image */
  uint64_t shadow_rays, shadow_rays_raster, reflection_rays; /* lit: rays shading tested, and the passes' times */
  double direct, shadow, reflection;
} timings;

/* Adds the run's images to its output set. The colour image and each AOV are made
 * once (shade_ms), whatever number of files hold them, and encoded (write_ms). */
static void add_images(rr_device *dev, rr_output *set, const rr_scene *scene, const rr_camera *cam,
                       const rr_frame *frame, const rr_shade_options *shading, const char *out,
                       const char *cube_dir, const aov_out *aovs, int naov, timings *ms) {
  unsigned need = out || cube_dir ? COLOR_BIT : 0;
  for (int k = 0; k < naov; k++) need |= aovs[k].images;
  rr_image images[RR_AOV_COUNT + 1] = {{0}}; /* AOV a at a, the colour last */
  rr_image *colour = &images[RR_AOV_COUNT];
  run.images = images, run.nimages = RR_AOV_COUNT + 1;
  progress_stage("shading");
  double t = now_ms();
  /* lit: the lit AOVs come from the colour's own passes (its lights and shadow mode) */
  unsigned lit_parts = 0;
  for (int a = RR_AOV_ALBEDO; a <= RR_AOV_EMISSION; a++) lit_parts |= 1u << a;
  lit_parts |= 1u << RR_AOV_SHADOW_LIGHTS;
  bool together = shading->mode == RR_SHADE_LIT && (need & lit_parts);
  if (together) need |= COLOR_BIT;
  for (int a = 0; a <= RR_AOV_COUNT; a++) {
    if (!(need & 1u << a) || (together && (lit_parts & 1u << a))) continue;
    rr_shade_stats st = {0};
    rr_error e = a == RR_AOV_COUNT && together
                     ? rr_shade_frame_aovs(dev, scene, cam, frame, shading, need & lit_parts, images, colour, &st)
                 : a == RR_AOV_COUNT ? rr_shade_frame(dev, scene, cam, frame, shading, colour, &st)
                                     : rr_frame_aov(dev, scene, cam, frame, (rr_aov)a, &images[a]);
    ms->resolve += st.resolve_ms, ms->shades += st.shades;
    ms->shadow_rays += st.shadow_rays, ms->reflection_rays += st.reflection_rays;
    ms->shadow += st.shadow_ms, ms->reflection += st.reflection_ms;
    ms->direct += st.direct_ms, ms->shadow_rays_raster += st.shadow_rays_raster;
    if (e) die(EXIT_INPUT, "%s", rr_device_message(dev));
  }
  ms->shade = now_ms() - t - ms->resolve; /* shading the samples and the AOVs */
  progress_stage("writing");
  t = now_ms();
  if (out) add_output(dev, set, colour, 1, out);
  if (cube_dir) add_cube_faces(dev, set, colour, cube_dir);
  for (int k = 0; k < naov; k++) {
    rr_image layers[RR_AOV_COUNT + 1];
    int n = 0;
    for (int a = RR_AOV_COUNT; a >= 0; a--) /* the colour first, as in the help */
      if (aovs[k].images & 1u << a) layers[n++] = images[a];
    add_output(dev, set, layers, n, aovs[k].path);
  }
  ms->write = now_ms() - t;
  for (int a = 0; a <= RR_AOV_COUNT; a++) rr_image_free(&images[a]);
  run.images = NULL, run.nimages = 0;
}

/* The shading inputs of a material (rastray info), on one indented line, and the textures it names but shading does not use yet. */
static void print_params(const rr_material_info *mi) {
  const rr_material_params *p = &mi->params;
  printf("      %s", rr_material_model_name(p->model));
  if (p->model == RR_MATERIAL_PBR) printf(", metallic %.3g, roughness %.3g", p->metallic, p->roughness);
  else printf(", specular (%.3g, %.3g, %.3g), shininess %.3g", p->specular[0], p->specular[1], p->specular[2], p->shininess);
  if (p->ambient[0] || p->ambient[1] || p->ambient[2]) printf(", ambient (%.3g, %.3g, %.3g)", p->ambient[0], p->ambient[1], p->ambient[2]);
  if (p->emission[0] || p->emission[1] || p->emission[2])
    printf(", emission (%.3g, %.3g, %.3g)", p->emission[0], p->emission[1], p->emission[2]);
  if (p->opacity != 1) printf(", opacity %.3g", p->opacity);
  if (p->illum >= 0) printf(", illum %d%s", p->illum, p->illum == 3 ? " (mirror)" : "");
  static const char *const maps[RR_MAP_COUNT] = {"specular", "normal", "occlusion", "emissive", "metallic-roughness"};
  for (int k = 0; k < RR_MAP_COUNT; k++)
    if (mi->maps[k]) printf(", %s map '%s' (unused)", maps[k], mi->maps[k]);
  putchar('\n');
}

static int cmd_info(rr_device *dev, const cli_command *cmd, int argc, char **argv) {
  int threads = 0;
  for (int key; (key = next_option(cmd, argc, argv)) != -1;)
    if (key == OPT_THREADS) threads = (int)parse_int(option_name, optarg, 0, RR_MAX_THREADS);
  if (argc - optind != 1) die(EXIT_USAGE, "info takes one scene (see --help)");
  const char *scene_name = argv[optind];
  double load_ms;
  rr_scene *scene = load_scene(dev, scene_name, threads, &load_ms, NULL);
  progress_stop();
  rr_scene_info in;
  rr_scene_get_info(scene, &in);
  printf("scene        %s\n", scene_name);
  printf("triangles    %llu (%llu degenerate or non-finite skipped)\n", (unsigned long long)in.triangles,
         (unsigned long long)in.skipped);
  if (in.spheres || in.planes || in.boxes)
    printf("analytic     %llu spheres, %llu planes, %llu boxes\n", (unsigned long long)in.spheres,
           (unsigned long long)in.planes, (unsigned long long)in.boxes);
  if (in.instances)
    printf("instances    %u of one mesh (%llu triangles stored)\n", in.instances,
           (unsigned long long)in.stored_triangles);
  printf("materials    %u\n", in.materials);
  printf("geometries   %u\n", in.geometries);
  enum { LISTED = 32 }; /* a scene of more lists none: the list would drown the rest */
  for (uint32_t g = 0; in.geometries <= LISTED && g < in.geometries; g++) {
    rr_geometry_info gi;
    rr_scene_get_geometry_info(scene, g, &gi);
    printf("  %-4u %-24s %u %s%s, material %u\n", g, gi.name ? gi.name : "-", gi.count,
           rr_geometry_kind_name(gi.kind), gi.count == 1 ? "" : "s", gi.material);
  }
  /* Materials with their textures, then every texture that is not there (even
   * when the materials are too many to list). */
  for (uint32_t m = 0; in.materials <= LISTED && m < in.materials; m++) {
    rr_material_info mi;
    rr_scene_get_material_info(scene, m, &mi);
    printf("  material %-3u %-20s colour (%.3g, %.3g, %.3g)", m, mi.name ? mi.name : "-", mi.color[0], mi.color[1],
           mi.color[2]);
    if (mi.texture && mi.texture_width)
      printf(", texture '%s' (%s, %dx%d)", mi.texture, rr_texture_status_name(mi.texture_status), mi.texture_width,
             mi.texture_height);
    else if (mi.texture) printf(", texture '%s' (%s)", mi.texture, rr_texture_status_name(mi.texture_status));
    putchar('\n');
    print_params(&mi);
  }
  printf("textures     %u (%u missing or unreadable), %.2f MiB with MIP chains\n", in.textures, in.textures_missing,
         in.texture_bytes / 1048576.0);
  for (uint32_t m = 0; in.textures_missing && m < in.materials; m++) {
    rr_material_info mi;
    rr_scene_get_material_info(scene, m, &mi);
    if (mi.texture_status == RR_TEXTURE_MISSING || mi.texture_status == RR_TEXTURE_UNREADABLE)
      printf("  %-10s '%s' (material %u)\n", rr_texture_status_name(mi.texture_status), mi.texture, m);
  }
  printf("cameras      %u\n", in.cameras);
  for (uint32_t c = 0; c < in.cameras; c++) {
    rr_camera fc;
    const char *name = rr_scene_camera_name(scene, c);
    if (rr_scene_get_camera(dev, scene, c, 1, 1, &fc) != RR_OK) { /* a file's camera the library cannot use */
      printf("  %-4u %-24s unusable: %s\n", c, name ? name : "-", rr_device_message(dev));
      continue;
    }
    printf("  %-4u %-24s %s, eye (%g, %g, %g), looking along (%g, %g, %g)", c, name ? name : "-", rr_camera_name(fc.type),
           fc.eye[0], fc.eye[1], fc.eye[2], fc.target[0] - fc.eye[0], fc.target[1] - fc.eye[1], fc.target[2] - fc.eye[2]);
    if (fc.type == RR_CAMERA_PERSPECTIVE) printf(", %.1f° at 1:1", fc.fov_deg);
    putchar('\n');
  }
  printf("lights       %u\n", in.lights);
  for (uint32_t l = 0; l < in.lights; l++) {
    rr_light_info li;
    rr_scene_get_light(scene, l, &li);
    printf("  %-4u %-24s %s, at (%g, %g, %g), towards (%g, %g, %g), colour (%g, %g, %g)", l, li.name ? li.name : "-",
           rr_light_type_name(li.type), li.position[0], li.position[1], li.position[2], li.direction[0],
           li.direction[1], li.direction[2], li.color[0], li.color[1], li.color[2]);
    if (li.type == RR_LIGHT_SPOT) printf(", cone %.1f°..%.1f°", li.inner_cone_deg, li.outer_cone_deg);
    putchar('\n');
  }
  printf("up, front    (%g, %g, %g), (%g, %g, %g)\n", in.up[0], in.up[1], in.up[2], in.front[0], in.front[1],
         in.front[2]);
  printf("bounds       (%g, %g, %g) .. (%g, %g, %g)\n", in.bounds_min[0], in.bounds_min[1], in.bounds_min[2],
         in.bounds_max[0], in.bounds_max[1], in.bounds_max[2]);
  printf("bvh nodes    %llu\n", (unsigned long long)in.bvh_nodes);
  printf("bvh leaves   %llu\n", (unsigned long long)in.bvh_leaves);
  printf("bvh depth    %u\n", in.bvh_depth);
  printf("bvh sah cost %.3f\n", in.bvh_sah_cost);
  printf("bvh build    %.1f ms\n", in.bvh_build_ms);
  printf("bvh memory   %.2f MiB\n", in.bvh_bytes / 1048576.0);
  printf("scene memory %.2f MiB (primitives%s)\n", in.scene_bytes / 1048576.0, in.instances ? " and instances" : "");
  return 0;
}

/* The fields of src named in `fields` (CAM_ bits) copied into dst. */
static void camera_take(rr_camera *dst, const rr_camera *src, unsigned fields) {
  if (fields & CAM_TYPE) dst->type = src->type;
  if (fields & CAM_EYE) memcpy(dst->eye, src->eye, sizeof dst->eye);
  if (fields & CAM_TARGET) memcpy(dst->target, src->target, sizeof dst->target);
  if (fields & CAM_UP) memcpy(dst->up, src->up, sizeof dst->up);
  if (fields & CAM_FOV) dst->fov_deg = src->fov_deg;
  if (fields & CAM_ORTHO) dst->ortho_height = src->ortho_height;
  if (fields & CAM_LENS) {
    dst->fx = src->fx, dst->fy = src->fy, dst->cx = src->cx, dst->cy = src->cy;
    memcpy(dst->dist, src->dist, sizeof dst->dist);
  }
}

/* --stats-json: the statistics as one JSON object. */
static void add_stats_json(rr_device *dev, rr_output *set, const char *path, const char *scene_name, const rr_camera *cam, const rr_render_options *opt,
                           int repeat, const rr_scene_info *info, const rr_stats *st, const timings *ms) {
  cJSON *o = cJSON_CreateObject();
  cJSON_AddStringToObject(o, "scene", scene_name);
  cJSON_AddStringToObject(o, "method", rr_method_name(st->method));
  cJSON_AddStringToObject(o, "camera", rr_camera_name(cam->type));
  cJSON_AddStringToObject(o, "aa", rr_aa_mode_name(opt->aa));
  const struct {
    const char *key;
    double value;
  } numbers[] = {{"triangles", (double)info->triangles}, {"skipped", (double)info->skipped},
                 {"width", opt->width}, {"height", opt->height}, {"threads", st->threads}, {"repeat", repeat},
                 {"samples", opt->samples}, {"load_ms", ms->load}, {"build_ms", ms->build}, {"frame_ms", ms->frame},
                 {"vis_ms", ms->frame}, {"cpu_ms", ms->cpu}, {"shade_ms", ms->shade}, {"resolve_ms", ms->resolve},
                 {"write_ms", ms->write}, {"total_ms", ms->total}, {"shades", (double)ms->shades},
                 {"direct_ms", ms->direct}, {"shadow_rays", (double)ms->shadow_rays},
                 {"shadow_rays_raster", (double)ms->shadow_rays_raster}, {"shadow_ms", ms->shadow},
                 {"reflection_rays", (double)ms->reflection_rays}, {"reflection_ms", ms->reflection},
                 {"setups", (double)st->setups}, {"edge_evals", (double)st->edge_evals}, {"nodes", (double)st->nodes},
                 {"bins", (double)st->bins}, {"bins_empty", (double)st->bins_empty}};
  for (size_t k = 0; k < sizeof numbers / sizeof *numbers; k++) /* times to the microsecond */
    cJSON_AddNumberToObject(o, numbers[k].key, round(numbers[k].value * 1000) / 1000);
  cJSON_AddStringToObject(o, "auto", st->why);
  json_add(dev, set, o, path);
}

#define FLAG(key) (1ull << ((key) - 256))

/* A scene file's render settings, each where no flag gave it (flags: FLAG bits). */
static void take_settings(const rr_scene_settings *file, uint64_t flags, rr_render_options *opt,
                          rr_shade_options *shading, int *shade, aa_spec *aa) {
  const rr_render_options *fr = &file->render;
  const rr_shade_options *fs = &file->shade;
  unsigned take = file->given;
  const struct {
    unsigned setting;
    int flag;
  } flag_of[] = {{RR_SETTING_SIZE, OPT_SIZE}, {RR_SETTING_METHOD, OPT_METHOD}, {RR_SETTING_AA, OPT_AA},
                 {RR_SETTING_CULL, OPT_CULL_BACKFACES}, {RR_SETTING_SHADE, OPT_SHADE},
                 {RR_SETTING_SHADOWS, OPT_SHADOWS}, {RR_SETTING_MAX_DEPTH, OPT_MAX_DEPTH},
                 {RR_SETTING_FILTER, OPT_AA_FILTER}, {RR_SETTING_TEXTURE_FILTER, OPT_TEXTURE_FILTER},
                 {RR_SETTING_LOD_BIAS, OPT_LOD_BIAS}, {RR_SETTING_ALPHA, OPT_ALPHA},
                 {RR_SETTING_BACKGROUND, OPT_BACKGROUND}};
  for (size_t k = 0; k < sizeof flag_of / sizeof *flag_of; k++)
    if (flags & FLAG(flag_of[k].flag)) take &= ~flag_of[k].setting;
  if (take & RR_SETTING_SIZE) opt->width = fr->width, opt->height = fr->height;
  if (take & RR_SETTING_METHOD) opt->method = fr->method;
  if (take & RR_SETTING_AA) *aa = (aa_spec){fr->aa, fr->samples, fr->aa_stored};
  if (take & RR_SETTING_CULL) opt->cull_backfaces = fr->cull_backfaces;
  if (take & RR_SETTING_SHADE) *shade = fs->mode;
  if (take & RR_SETTING_SHADOWS) shading->shadows = fs->shadows;
  if (take & RR_SETTING_MAX_DEPTH) shading->max_depth = fs->max_depth;
  if (take & RR_SETTING_FILTER) shading->filter = fs->filter, shading->radius = fs->radius;
  if (take & RR_SETTING_TEXTURE_FILTER) shading->texture_filter = fs->texture_filter, shading->aniso = fs->aniso;
  if (take & RR_SETTING_LOD_BIAS) shading->lod_bias = fs->lod_bias;
  if (take & RR_SETTING_ALPHA) shading->alpha = fs->alpha;
  if (take & RR_SETTING_DEFAULT_LIGHTS) shading->default_lights = fs->default_lights;
  if (take & RR_SETTING_BACKGROUND) {
    shading->has_background = fs->has_background;
    memcpy(shading->background, fs->background, sizeof shading->background);
  }
}

static int cmd_render(rr_device *dev, const cli_command *cmd, int argc, char **argv) {
  double t_start = now_ms();
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_AUTO;
  rr_camera cam;
  rr_camera_init(&cam);
  const char *scene_name = NULL, *out = NULL, *json = NULL, *cube_dir = NULL, *camera_file = NULL, *save_camera = NULL;
  const char *file_cam = NULL; /* --camera-from-file */
  unsigned given = 0;           /* the camera's fields set by flags */
  unsigned lens = 0;            /* --intrinsics (1), --distortion (2), --extrinsics (4) given */
  bool stats = false;
  int shade = RR_SHADE_LIT, repeat = 1, naov = 0, nlights = 0;
  rr_light_info lights[32];
  aa_spec aa = {RR_AA_NONE, 1, 0};
  rr_aa_pattern pattern = RR_AA_STANDARD;
  uint32_t seed = 1;
  bool pattern_given = false;
  aov_out aovs[16];
  rr_shade_options shading;
  rr_shade_options_init(&shading);
  uint64_t flags = 0; /* bit key - 256: the long options given, which override a scene file's settings */
  for (int key; (key = next_option(cmd, argc, argv)) != -1;) {
    if (key >= 256 && key < 256 + 64) flags |= 1ull << (key - 256);
    switch (key) {
    case OPT_METHOD: {
      int m = rr_method_from_name(optarg);
      if (m < 0) die(EXIT_USAGE, "unknown method '%s' (see --help)", optarg);
      opt.method = (rr_method)m;
      break;
    }
    case OPT_SIZE: parse_size(optarg, &opt.width, &opt.height); break;
    case OPT_CAMERA: {
      int type = rr_camera_from_name(optarg);
      if (type < 0)
        die(EXIT_USAGE,
            "unknown camera '%s' (expected perspective, orthographic, parabolic, latlong, fisheye, cube, opencv or "
            "opencv-fisheye)",
            optarg);
      cam.type = (rr_camera_type)type, given |= CAM_TYPE;
      break;
    }
    case OPT_ORTHO_HEIGHT:
      cam.ortho_height = parse_float(option_name, optarg), given |= CAM_ORTHO;
      if (!(cam.ortho_height > 0)) die(EXIT_USAGE, "bad value '%s' for --ortho-height (expected > 0)", optarg);
      break;
    case OPT_CUBE_FACES: cube_dir = optarg; break;
    case OPT_EYE: parse_vec(option_name, optarg, cam.eye), given |= CAM_EYE; break;
    case OPT_TARGET: parse_vec(option_name, optarg, cam.target), given |= CAM_TARGET; break;
    case OPT_UP: parse_vec(option_name, optarg, cam.up), given |= CAM_UP; break;
    case OPT_CAMERA_FROM_FILE: file_cam = optarg; break;
    case OPT_INTRINSICS: {
      float k[4];
      if (parse_floats(option_name, optarg, k, 4) != 4)
        die(EXIT_USAGE, "bad value '%s' for --intrinsics (expected FX,FY,CX,CY)", optarg);
      cam.fx = k[0], cam.fy = k[1], cam.cx = k[2], cam.cy = k[3], lens |= 1;
      break;
    }
    case OPT_DISTORTION:
      memset(cam.dist, 0, sizeof cam.dist);
      if (parse_floats(option_name, optarg, cam.dist, 8) < 1)
        die(EXIT_USAGE, "bad value '%s' for --distortion (expected k1,k2,p1,p2[,k3[,k4,k5,k6]])", optarg);
      lens |= 2;
      break;
    case OPT_EXTRINSICS: parse_extrinsics(dev, optarg, &cam), given |= CAM_EYE | CAM_TARGET | CAM_UP, lens |= 4; break;
    case OPT_FOV:
      cam.fov_deg = parse_float(option_name, optarg), given |= CAM_FOV;
      if (!(cam.fov_deg >= RR_FOV_MIN && cam.fov_deg <= 360))
        die(EXIT_USAGE, "bad value '%s' for --fov (expected %g <= fov < 180, or up to 360 for fisheye)", optarg,
            (double)RR_FOV_MIN);
      break;
    case OPT_SHADE:
      shade = rr_shade_from_name(optarg);
      if (shade < 0)
        die(EXIT_USAGE,
            "unknown shade mode '%s' (expected lit, lambert, id, normal, depth, heat-evals or heat-nodes)", optarg);
      break;
    case OPT_LIGHT:
      if (nlights == 32) die(EXIT_USAGE, "too many --light (at most 32)");
      lights[nlights++] = parse_light(optarg);
      break;
    case OPT_SHADOWS: {
      int m = rr_shadows_from_name(optarg);
      if (m < 0) die(EXIT_USAGE, "unknown shadow mode '%s' for --shadows (expected none, rays, raster or auto)", optarg);
      shading.shadows = (rr_shadow_mode)m;
      break;
    }
    case OPT_MAX_DEPTH: shading.max_depth = (int)parse_int(option_name, optarg, 0, RR_MAX_DEPTH); break;
    case 'o': out = optarg; break;
    case OPT_AOV:
      if (naov == 16) die(EXIT_USAGE, "too many --aov (at most 16)");
      aovs[naov++] = parse_aov(optarg);
      break;
    case OPT_THREADS: opt.threads = (int)parse_int(option_name, optarg, 0, RR_MAX_THREADS); break;
    case OPT_REPEAT: repeat = (int)parse_int(option_name, optarg, 1, 1000); break;
    case OPT_STATS: stats = true; break;
    case OPT_STATS_JSON: json = optarg; break;
    case OPT_ORACLES: opt.oracles = optarg; break;
    case OPT_CULL_BACKFACES: opt.cull_backfaces = 1; break;
    case OPT_AA: aa = parse_aa(optarg); break;
    case OPT_AA_PATTERN: pattern = parse_aa_pattern(optarg, &seed), pattern_given = true; break;
    case OPT_AA_FILTER: parse_filter(optarg, &shading); break;
    case OPT_ALPHA: shading.alpha = 1; break;
    case OPT_BACKGROUND:
      parse_vec(option_name, optarg, shading.background), shading.has_background = 1;
      if (!(shading.background[0] >= 0 && shading.background[1] >= 0 && shading.background[2] >= 0))
        die(EXIT_USAGE, "bad value '%s' for --background (expected R,G,B at least 0)", optarg);
      break;
    case OPT_TEXTURE_FILTER: parse_texture_filter(optarg, &shading); break;
    case OPT_LOD_BIAS:
      shading.lod_bias = parse_float(option_name, optarg);
      if (fabsf(shading.lod_bias) > 64) die(EXIT_USAGE, "bad value '%s' for --lod-bias (expected -64..64 levels)", optarg);
      break;
    case OPT_CAMERA_FILE: camera_file = optarg; break;
    case OPT_SAVE_CAMERA: save_camera = optarg; break;
    }
  }
  if (optind < argc) scene_name = argv[optind];
  if (argc - optind > 1) die(EXIT_USAGE, "more than one scene given ('%s' and '%s')", scene_name, argv[optind + 1]);
  if (!(given & CAM_EYE) != !(given & CAM_TARGET)) die(EXIT_USAGE, "--eye and --target go together");
  if ((lens & 1) && !(given & CAM_TYPE)) cam.type = RR_CAMERA_OPENCV, given |= CAM_TYPE;
  if ((lens & 4) && (file_cam || camera_file)) die(EXIT_USAGE, "--extrinsics gives the pose: no camera file with it");
  if (lens) given |= CAM_LENS;
  if (file_cam && (given & (CAM_EYE | CAM_TARGET | CAM_UP | CAM_FOV)))
    die(EXIT_USAGE, "--camera-from-file takes the view from the file: no --eye, --target, --up or --fov with it");
  if (file_cam && camera_file) die(EXIT_USAGE, "--camera-from-file and --camera-file exclude each other");
  if (!scene_name) scene_name = "demo";
  timings ms = {0};
  rr_scene_settings file = {0}; /* a scene file's settings, where no flag gave them: read first */
  rr_scene *scene = is_scene_file(scene_name) ? load_scene(dev, scene_name, opt.threads, &ms.load, &file) : NULL;
  take_settings(&file, flags, &opt, &shading, &shade, &aa);
  if (pattern_given && aa.mode == RR_AA_NONE) die(EXIT_USAGE, "--aa-pattern needs --aa other than none");
  if (rr_render_options_set_aa(dev, &opt, aa.mode, aa.samples, aa.stored, pattern, seed) != RR_OK)
    die(EXIT_USAGE, "%s", rr_device_message(dev));
  check_frame_budget(&opt);
  if ((file.given & RR_SETTING_AA) && !(flags & FLAG(OPT_AA)) && !pattern_given) /* the file's pattern too */
    memcpy(opt.sample_pos, file.render.sample_pos, sizeof opt.sample_pos);
  if (!out && naov == 0) out = "rastray.png";
  if (shade == RR_SHADE_HEAT_EVALS || shade == RR_SHADE_HEAT_NODES) opt.heat = 1;
  const unsigned heat_aovs = 1u << RR_AOV_EVALS | 1u << RR_AOV_NODES;
  for (int k = 0; k < naov; k++) opt.heat |= (aovs[k].images & heat_aovs) != 0;
  const unsigned by_name = 1u << RR_AOV_COVERAGE | 1u << RR_AOV_SAMPLE_ID | 1u << RR_AOV_SAMPLE_DEPTH |
                           1u << RR_AOV_SAMPLE_MESH | 1u << RR_AOV_UV | 1u << RR_AOV_UV_DERIV |
                           1u << RR_AOV_ALBEDO | 1u << RR_AOV_DIRECT | 1u << RR_AOV_REFLECTION |
                           1u << RR_AOV_SHADOW | 1u << RR_AOV_EMISSION | 1u << RR_AOV_ZDEPTH |
                           1u << RR_AOV_SHADOW_LIGHTS | 1u << RR_AOV_INSTANCE; /* the AA and texture outputs,
                                                              the lit parts and instances: asked for by name */
  for (int k = 0; k < naov; k++) /* all: every per-pixel AOV of the visibility the frame has */
    if (aovs[k].all) aovs[k].images = (COLOR_BIT | ((1u << RR_AOV_COUNT) - 1)) & ~by_name & ~(opt.heat ? 0 : heat_aovs);
  if (camera_file) { /* the file's values, where no flag gave one */
    rr_camera from_file = cam;
    int w, h;
    unsigned fields = camera_file_read(dev, camera_file, &from_file, &w, &h);
    if (w > 0 && !(flags & FLAG(OPT_SIZE))) { /* the image the imported camera belongs to */
      opt.width = w, opt.height = h;
      check_frame_budget(&opt);
    }
    camera_take(&cam, &from_file, fields & ~given);
    given |= fields;
  }
  if (!file_cam) { /* then the scene file's camera */
    camera_take(&cam, &file.camera, file.camera_given & ~given);
    given |= file.camera_given;
  }
  if ((lens & 3) && cam.type != RR_CAMERA_OPENCV && cam.type != RR_CAMERA_OPENCV_FISHEYE)
    die(EXIT_USAGE, "--intrinsics and --distortion go with --camera opencv or opencv-fisheye");
  if (!scene) scene = load_scene(dev, scene_name, opt.threads, &ms.load, NULL);

  for (int k = 0; k < nlights; k++)
    if (rr_scene_add_light(scene, &lights[k]) != RR_OK) die(EXIT_USAGE, "--light: %s", rr_device_message(dev));
  if (file_cam) { /* the file's camera; --camera may change its projection */
    rr_camera_type type = cam.type;
    uint32_t index;
    if (rr_scene_find_camera(dev, scene, file_cam, &index) != RR_OK ||
        rr_scene_get_camera(dev, scene, index, opt.width, opt.height, &cam) != RR_OK)
      die(EXIT_INPUT, "%s", rr_device_message(dev));
    if (given & CAM_TYPE) cam.type = type;
  } else if (!(given & CAM_EYE) && rr_camera_frame(dev, scene, opt.width, opt.height, &cam) != RR_OK) {
    die(EXIT_INPUT, "%s", rr_device_message(dev));
  }
  if (rr_camera_check(dev, &cam) != RR_OK) {
    if (camera_file) die(EXIT_INPUT, "camera file '%s': %s", camera_file, rr_device_message(dev));
    die(EXIT_USAGE, "%s", rr_device_message(dev));
  }
  if (cube_dir && cam.type != RR_CAMERA_CUBE) die(EXIT_USAGE, "--cube-faces needs --camera cube");

  double *times = malloc(sizeof(double) * repeat), *cpus = malloc(sizeof(double) * repeat);
  if (!times || !cpus) free(times), free(cpus), die(EXIT_INPUT, "out of memory for %d repeats", repeat);
  rr_frame *frame = NULL;
  opt.frames_hint = repeat; /* auto weighs a trial against the frames to come */
  for (int r = 0; r < repeat; r++) {
    rr_frame_release(frame);
    run.frame = frame = NULL;
    progress_frame(r, repeat);
    rr_error e = rr_render(dev, scene, &cam, &opt, &frame);
    run.frame = frame;
    if (e) free(times), free(cpus), die(e == RR_ERROR_ARGUMENT || e == RR_ERROR_UNSUPPORTED ? EXIT_USAGE : EXIT_INPUT, "%s", rr_device_message(dev));
    rr_stats st;
    rr_frame_get_stats(frame, &st);
    times[r] = st.frame_ms, cpus[r] = st.cpu_ms;
  }
  ms.frame = median(times, repeat), ms.cpu = median(cpus, repeat);
  free(times), free(cpus);
  rr_stats st;
  rr_frame_get_stats(frame, &st);
  const char *method = rr_method_name(st.method);
  if (st.why[0]) note(1, "auto chose %s: %s\n", method, st.why);
  else note(1, "method %s (as asked)\n", method);

  /* Every file of the run goes into one output set: all of them appear, or none. */
  rr_output *set;
  if (rr_output_new(dev, &set) != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
  pthread_mutex_lock(&run.lock);
  run.set = set;
  pthread_mutex_unlock(&run.lock);
  shading.mode = (rr_shade_mode)shade;
  add_images(dev, set, scene, &cam, frame, &shading, out, cube_dir, aovs, naov, &ms);
  if (save_camera) camera_file_add(dev, set, save_camera, &cam, opt.width, opt.height);
  rr_scene_info info;
  rr_scene_get_info(scene, &info);
  ms.build = info.bvh_build_ms;
  ms.total = now_ms() - t_start;
  if (json) add_stats_json(dev, set, json, scene_name, &cam, &opt, repeat, &info, &st, &ms);
  pthread_mutex_lock(&run.lock);
  atomic_store(&run.committing, true);
  rr_error committed = rr_output_commit(set);
  atomic_store(&run.committing, false);
  pthread_mutex_unlock(&run.lock);
  if (committed != RR_OK) output_failed(dev, set);
  progress_stop();
  if (stats)
    fprintf(stderr,
            "method=%s camera=%s triangles=%llu width=%d height=%d threads=%d aa=%s samples=%d frame_ms=%.3f "
            "vis_ms=%.3f cpu_ms=%.3f load_ms=%.1f build_ms=%.1f shade_ms=%.1f resolve_ms=%.1f write_ms=%.1f "
            "total_ms=%.1f shades=%llu direct_ms=%.1f shadow_rays=%llu shadow_rays_raster=%llu shadow_ms=%.1f "
            "reflection_rays=%llu reflection_ms=%.1f "
            "setups=%llu edge_evals=%llu nodes=%llu bins=%llu bins_empty=%llu\n",
            method, rr_camera_name(cam.type), (unsigned long long)info.triangles, opt.width, opt.height, st.threads,
            rr_aa_mode_name(opt.aa), opt.samples, ms.frame, ms.frame, ms.cpu, ms.load, ms.build, ms.shade, ms.resolve,
            ms.write, ms.total, (unsigned long long)ms.shades, ms.direct, (unsigned long long)ms.shadow_rays,
            (unsigned long long)ms.shadow_rays_raster, ms.shadow,
            (unsigned long long)ms.reflection_rays, ms.reflection, (unsigned long long)st.setups,
            (unsigned long long)st.edge_evals, (unsigned long long)st.nodes, (unsigned long long)st.bins,
            (unsigned long long)st.bins_empty);
  if (stats && st.why[0]) fprintf(stderr, "auto chose %s: %s\n", method, st.why);
  if (out) note(1, "wrote %s\n", out);
  if (cube_dir) note(1, "wrote %s/{front,right,back,left,top,bottom}.png\n", cube_dir);
  for (int k = 0; k < naov; k++) note(1, "wrote %s\n", aovs[k].path);
  if (save_camera) note(1, "wrote %s\n", save_camera);
  if (json) note(1, "wrote %s\n", json);
  note(1,
       "times: load %.1f ms, build %.1f ms, visibility %.1f ms%s, shade %.1f ms, resolve %.1f ms, write %.1f ms, "
       "total %.1f ms\n",
       ms.load, ms.build, ms.frame, repeat > 1 ? " (median)" : "", ms.shade, ms.resolve, ms.write, ms.total);
  if (out && !stats && verbosity == 0)
    note(0, "wrote %s (%dx%d, %s, %.1f ms)\n", out, opt.width, opt.height, method, ms.frame);
  return 0;
}

/* help [COMMAND]: the overview, or a command's usage. */
static int cmd_help(rr_device *dev, const cli_command *cmd, int argc, char **argv) {
  (void)dev;
  while (next_option(cmd, argc, argv) != -1) {
  }
  if (argc - optind > 1) die(EXIT_USAGE, "help takes at most one command");
  if (argc - optind == 0) {
    print_overview(stdout);
    return 0;
  }
  print_usage(stdout, find_command(argv[optind]));
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    print_overview(argc < 2 ? stderr : stdout);
    return argc < 2 ? EXIT_USAGE : 0;
  }
  if (strcmp(argv[1], "--version") == 0) {
    printf("rastray %s\n", RR_VERSION);
    return 0;
  }
  const cli_command *cmd = find_command(argv[1]);
  rr_import_limits_init(&import_limits);
  /* Blocked before any thread starts, so every thread inherits it and only the watcher takes them. */
  static sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT), sigaddset(&signals, SIGTERM), sigaddset(&signals, SIGHUP);
  pthread_t watcher;
  if (sem_init(&watcher_ready, 0, 0) != 0 || pthread_sigmask(SIG_BLOCK, &signals, NULL) != 0 ||
      pthread_create(&watcher, NULL, watch_signals, &signals) != 0)
    die(EXIT_INPUT, "cannot start the signal watcher");
  /* Running before anything else: a thread still starting may hold the allocator's
   * locks (ASan's do not survive a fork), and the import forks (import_guard.c). */
  while (sem_wait(&watcher_ready) != 0) continue;
  pthread_detach(watcher);
  run.dev = rr_device_new();
  if (!run.dev) die(EXIT_INPUT, "out of memory");
  int rc = cmd->run(run.dev, cmd, argc - 1, argv + 1); /* the command's name stands as getopt's argv[0] */
  run_release();
  return rc;
}
