/* rastray: the command-line tool. Everything it does goes through rastray.h.
 * Exit codes: 0 success, 1 bad input (files, scenes), 2 bad usage (flags, values). */
#include "rastray.h"

#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { EXIT_INPUT = 1, EXIT_USAGE = 2 };

static void die(int code, const char *fmt, ...) __attribute__((noreturn, format(printf, 2, 3)));
static void die(int code, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fputs("rastray: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  exit(code);
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
  OPT_CAMERA_FROM_FILE,
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

/* Every command's last options; next_option handles them. */
#define COMMON_OPTIONS                                                                                    \
  {"quiet", 'q', NULL, "print nothing on stderr but errors (and --stats when asked)"},                  \
      {"verbose", 'v', NULL, "also print what was loaded, the BVH, the method and why, the outputs"},   \
      {"help", 'h', NULL, "print this help and exit"}

static const char scenes_note[] =
    "scenes: a file assimp reads (.obj .ply .gltf .glb .dae .3ds ...), or demo, plane[:N],\n"
    "        sphere[:N], box[:N], rooms[:N], grid:PATH:N (N×N copies of a mesh), ground (an\n"
    "        infinite plane through points at infinity, with a sphere and a box; 3D methods)\n";

static const cli_option render_options[] = {
    {"method", OPT_METHOD, "NAME",
     "visibility method: auto (default: the fastest exact one in a trial), rc,\n"
     "rc-bvh, rc-packet, 2dr-bb, 2dr-bin, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full"},
    {"oracles", OPT_ORACLES, "K=V,...",
     "override a 3dr method's traversal: frustum=N leaves=0|1 outside=0|1\n"
     "occluded=0|1 split=N split-ratio=F binning=0|1 early-z=0|1 bin=N bin-min=N"},
    {"size", OPT_SIZE, "WxH", "image size (default 1024x768, at most " VALUE(RR_MAX_SIZE) " a side)"},
    {"camera", OPT_CAMERA, "NAME", "perspective (default), orthographic, parabolic, latlong, fisheye, cube"},
    {"ortho-height", OPT_ORTHO_HEIGHT, "H", "orthographic view height (default 2·|target-eye|·tan(fov/2))"},
    {"cube-faces", OPT_CUBE_FACES, "DIR", "cube camera: also write the six faces as DIR/front.png, right, back, ..."},
    {"eye", OPT_EYE, "X,Y,Z", "camera position; without --eye/--target the scene is framed automatically"},
    {"target", OPT_TARGET, "X,Y,Z", "the point the camera looks at (goes with --eye)"},
    {"up", OPT_UP, "X,Y,Z", "the camera's up direction (default 0,1,0)"},
    {"fov", OPT_FOV, "DEG", "vertical field of view (default 45; fisheye: the full angle, up to 360)"},
    {"camera-from-file", OPT_CAMERA_FROM_FILE, "NAME|INDEX",
     "look through a camera the scene file defines (see info); --camera may\nchange its projection"},
    {"shade", OPT_SHADE, "MODE", "lambert (default), id, normal, depth, heat-evals, heat-nodes"},
    {"output", 'o', "PATH",
     "colour image: .png (sRGB), .exr or .pfm (linear light); default rastray.png\n"
     "unless --aov is given. PATH may be - (stdout, PNG), FMT:PATH (png:-, exr:-),\n"
     "or a device or FIFO such as /dev/null"},
    {"aov", OPT_AOV, "LIST=PATH",
     "write AOVs as .npy, .pfm or .exr (stdout: - as NPY, or FMT:-); repeatable.\n"
     "LIST: one NAME, NAME,NAME,... or all, as the layers of one EXR. NAME: color\n"
     "(the shaded image), depth (EXR Z), normal (N.X N.Y N.Z), bary (bary.u bary.v),\n"
     "id (triangle), mesh (geometry id), material (index) (ids: EXR UINT), evals,\n"
     "nodes; all: every one (evals, nodes with heat). Outputs are all or nothing"},
    {"threads", OPT_THREADS, "N", "threads, at most " VALUE(RR_MAX_THREADS) " (default: all cores)"},
    {"repeat", OPT_REPEAT, "N", "run the visibility pass N times, report the median time"},
    {"stats", OPT_STATS, NULL, "print key=value statistics to stderr"},
    {"stats-json", OPT_STATS_JSON, "PATH", "write the statistics as one JSON object"},
    {"cull-backfaces", OPT_CULL_BACKFACES, NULL, "triangles seen from behind are invisible"},
    COMMON_OPTIONS,
    {NULL, 0, NULL, NULL},
};

static const cli_option info_options[] = {
    COMMON_OPTIONS,
    {NULL, 0, NULL, NULL},
};

static int cmd_render(rr_device *dev, const cli_command *cmd, int argc, char **argv);
static int cmd_info(rr_device *dev, const cli_command *cmd, int argc, char **argv);

static const cli_command commands[] = {
    {"render", "[SCENE] [options]", "render SCENE (a mesh file or built-in name; default demo)", scenes_note,
     render_options, cmd_render},
    {"info", "SCENE [options]", "print the scene's triangles, geometries and BVH figures", scenes_note, info_options,
     cmd_info},
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

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

static char flag[64]; /* the option being handled, "--name", for messages */
static int verbosity;  /* -1: --quiet, 0, 1: --verbose */

/* A message on stderr when the verbosity is at least `level` (0: unless --quiet). */
static void note(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void note(int level, const char *fmt, ...) {
  if (verbosity < level) return;
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
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
  if (o->name) snprintf(flag, sizeof flag, "--%s", o->name);
  if (key == '?' && o->name) die(EXIT_USAGE, "%s takes no value (see --help)", flag);
  if (key == '?' && optopt) die(EXIT_USAGE, "unknown option '-%c' (see --help)", optopt);
  if (key == '?') die(EXIT_USAGE, "unknown option '%s' (see --help)", argv[optind - 1]);
  if (key == ':') die(EXIT_USAGE, "%s needs a value (see --help)", argv[optind - 1]);
  switch (key) {
  case 'h': print_usage(stdout, cmd), exit(0);
  case 'q': verbosity = -1; return next_option(cmd, argc, argv);
  case 'v': verbosity = 1; return next_option(cmd, argc, argv);
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
          "unknown AOV '%s' (expected color, depth, id, mesh, material, normal, bary, evals, nodes or all)", name);
  }
  if (!a.images && !a.all) die(EXIT_USAGE, "bad --aov '%s' (expected LIST=PATH)", arg);
  return a;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static double now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static rr_scene *load_scene(rr_device *dev, const char *name) {
  rr_scene *scene;
  if (rr_scene_load(dev, name, &scene) != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
  rr_scene_info in;
  rr_scene_get_info(scene, &in);
  note(1, "loaded %s: %llu triangles (%llu skipped), %u geometries, %u materials\n", name,
       (unsigned long long)in.triangles, (unsigned long long)in.skipped, in.geometries, in.materials);
  note(1, "bvh: %llu nodes, %llu leaves, depth %u, SAH cost %.3f, %.2f MiB, built in %.1f ms\n",
       (unsigned long long)in.bvh_nodes, (unsigned long long)in.bvh_leaves, in.bvh_depth, in.bvh_sah_cost,
       in.bvh_bytes / 1048576.0, in.bvh_build_ms);
  return scene;
}

/* Ends the run on a failed output; the set's temporaries go first. */
static void output_failed(rr_device *dev, rr_output *set, rr_error e) {
  rr_output_release(set);
  die(e == RR_ERROR_ARGUMENT ? EXIT_USAGE : EXIT_INPUT, "%s", rr_device_message(dev));
}

static void add_output(rr_device *dev, rr_output *set, const rr_image *images, int n, const char *path) {
  rr_error e = rr_output_add(set, images, n, path);
  if (e) output_failed(dev, set, e);
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
    if (!img.data) {
      rr_output_release(set);
      die(EXIT_INPUT, "out of memory");
    }
    for (int y = 0; y < n; y++)
      memcpy((float *)img.data + (size_t)y * n * 3,
             (const float *)cross->data + ((size_t)(faces[f].row * n + y) * cross->width + faces[f].col * n) * 3,
             (size_t)n * 3 * sizeof(float));
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.png", dir, faces[f].name);
    rr_error e = rr_output_add(set, &img, 1, path);
    free(img.data);
    if (e) output_failed(dev, set, e);
  }
}

/* Writes every output of the run as one set: all of them, or none. The colour
 * image and each AOV are made once, whatever number of files hold them. */
static void write_outputs(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_frame *frame,
                          int shade, const char *out, const char *cube_dir, const aov_out *aovs, int naov) {
  unsigned need = out || cube_dir ? COLOR_BIT : 0;
  for (int k = 0; k < naov; k++) need |= aovs[k].images;
  rr_image images[RR_AOV_COUNT + 1] = {{0}}; /* AOV a at a, the colour last */
  rr_image *colour = &images[RR_AOV_COUNT];
  for (int a = 0; a <= RR_AOV_COUNT; a++) {
    if (!(need & 1u << a)) continue;
    rr_error e = a == RR_AOV_COUNT ? rr_shade(dev, scene, cam, frame, (rr_shade_mode)shade, colour)
                                   : rr_frame_aov(dev, scene, cam, frame, (rr_aov)a, &images[a]);
    if (e) die(EXIT_INPUT, "%s", rr_device_message(dev));
  }
  rr_output *set;
  if (rr_output_new(dev, &set) != RR_OK) die(EXIT_INPUT, "%s", rr_device_message(dev));
  if (out) add_output(dev, set, colour, 1, out);
  if (cube_dir) add_cube_faces(dev, set, colour, cube_dir);
  for (int k = 0; k < naov; k++) {
    rr_image layers[RR_AOV_COUNT + 1];
    int n = 0;
    for (int a = RR_AOV_COUNT; a >= 0; a--) /* the colour first, as in the help */
      if (aovs[k].images & 1u << a) layers[n++] = images[a];
    add_output(dev, set, layers, n, aovs[k].path);
  }
  rr_error e = rr_output_commit(set);
  if (e) output_failed(dev, set, e);
  rr_output_release(set);
  for (int a = 0; a <= RR_AOV_COUNT; a++) rr_image_free(&images[a]);
}

static int cmd_info(rr_device *dev, const cli_command *cmd, int argc, char **argv) {
  while (next_option(cmd, argc, argv) != -1) {
  }
  if (argc - optind != 1) die(EXIT_USAGE, "info takes one scene (see --help)");
  const char *scene_name = argv[optind];
  rr_scene *scene = load_scene(dev, scene_name);
  rr_scene_info in;
  rr_scene_get_info(scene, &in);
  printf("scene        %s\n", scene_name);
  printf("triangles    %llu (%llu degenerate or non-finite skipped)\n", (unsigned long long)in.triangles,
         (unsigned long long)in.skipped);
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
  }
  printf("textures     %u (%u missing or unreadable)\n", in.textures, in.textures_missing);
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
  rr_scene_release(scene);
  return 0;
}

static int cmd_render(rr_device *dev, const cli_command *cmd, int argc, char **argv) {
  double t_start = now_ms();
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_AUTO;
  rr_camera cam;
  rr_camera_init(&cam);
  const char *scene_name = NULL, *out = NULL, *json = NULL, *cube_dir = NULL;
  const char *file_cam = NULL;
  bool have_eye = false, have_target = false, have_type = false, have_pose = false, stats = false;
  int shade = RR_SHADE_LAMBERT, repeat = 1, naov = 0;
  aov_out aovs[16];
  for (int key; (key = next_option(cmd, argc, argv)) != -1;) {
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
        die(EXIT_USAGE, "unknown camera '%s' (expected perspective, orthographic, parabolic, latlong, fisheye or cube)",
            optarg);
      cam.type = (rr_camera_type)type, have_type = true;
      break;
    }
    case OPT_ORTHO_HEIGHT:
      cam.ortho_height = parse_float(flag, optarg);
      if (!(cam.ortho_height > 0)) die(EXIT_USAGE, "bad value '%s' for --ortho-height (expected > 0)", optarg);
      break;
    case OPT_CUBE_FACES: cube_dir = optarg; break;
    case OPT_EYE: parse_vec(flag, optarg, cam.eye), have_eye = true; break;
    case OPT_TARGET: parse_vec(flag, optarg, cam.target), have_target = true; break;
    case OPT_UP: parse_vec(flag, optarg, cam.up), have_pose = true; break;
    case OPT_CAMERA_FROM_FILE: file_cam = optarg; break;
    case OPT_FOV:
      cam.fov_deg = parse_float(flag, optarg), have_pose = true;
      if (!(cam.fov_deg > 0 && cam.fov_deg <= 360))
        die(EXIT_USAGE, "bad value '%s' for --fov (expected 0 < fov < 180, or up to 360 for fisheye)", optarg);
      break;
    case OPT_SHADE:
      shade = rr_shade_from_name(optarg);
      if (shade < 0)
        die(EXIT_USAGE, "unknown shade mode '%s' (expected lambert, id, normal, depth, heat-evals or heat-nodes)",
            optarg);
      break;
    case 'o': out = optarg; break;
    case OPT_AOV:
      if (naov == 16) die(EXIT_USAGE, "too many --aov (at most 16)");
      aovs[naov++] = parse_aov(optarg);
      break;
    case OPT_THREADS: opt.threads = (int)parse_int(flag, optarg, 1, RR_MAX_THREADS); break;
    case OPT_REPEAT: repeat = (int)parse_int(flag, optarg, 1, 1000); break;
    case OPT_STATS: stats = true; break;
    case OPT_STATS_JSON: json = optarg; break;
    case OPT_ORACLES: opt.oracles = optarg; break;
    case OPT_CULL_BACKFACES: opt.cull_backfaces = 1; break;
    }
  }
  if (optind < argc) scene_name = argv[optind];
  if (argc - optind > 1) die(EXIT_USAGE, "more than one scene given ('%s' and '%s')", scene_name, argv[optind + 1]);
  if (have_eye != have_target) die(EXIT_USAGE, "--eye and --target go together");
  if (file_cam && (have_eye || have_pose))
    die(EXIT_USAGE, "--camera-from-file takes the view from the file: no --eye, --target, --up or --fov with it");
  if (!scene_name) scene_name = "demo";
  if (!out && naov == 0) out = "rastray.png";
  if (shade == RR_SHADE_HEAT_EVALS || shade == RR_SHADE_HEAT_NODES) opt.heat = 1;
  const unsigned heat_aovs = 1u << RR_AOV_EVALS | 1u << RR_AOV_NODES;
  for (int k = 0; k < naov; k++) opt.heat |= (aovs[k].images & heat_aovs) != 0;
  for (int k = 0; k < naov; k++) /* all: every AOV the frame has */
    if (aovs[k].all) aovs[k].images = (COLOR_BIT | ((1u << RR_AOV_COUNT) - 1)) & ~(opt.heat ? 0 : heat_aovs);

  rr_build_options build; /* the BVH is built on the render's threads too */
  rr_build_options_init(&build);
  build.threads = opt.threads;
  rr_device_set_build_options(dev, &build);
  rr_scene *scene = load_scene(dev, scene_name);
  if (file_cam) {
    rr_camera_type type = cam.type;
    uint32_t index;
    if (rr_scene_find_camera(dev, scene, file_cam, &index) != RR_OK ||
        rr_scene_get_camera(dev, scene, index, opt.width, opt.height, &cam) != RR_OK)
      die(EXIT_INPUT, "%s", rr_device_message(dev));
    if (have_type) cam.type = type;
  } else if (!have_eye && rr_camera_frame(dev, scene, opt.width, opt.height, &cam) != RR_OK) {
    die(EXIT_INPUT, "%s", rr_device_message(dev));
  }
  if (rr_camera_check(dev, &cam) != RR_OK) die(EXIT_USAGE, "%s", rr_device_message(dev));
  if (cube_dir && cam.type != RR_CAMERA_CUBE) die(EXIT_USAGE, "--cube-faces needs --camera cube");

  double *times = malloc(sizeof(double) * repeat), *cpus = malloc(sizeof(double) * repeat);
  if (!times || !cpus) die(EXIT_INPUT, "out of memory for %d repeats", repeat);
  rr_frame *frame = NULL;
  for (int r = 0; r < repeat; r++) {
    rr_frame_release(frame);
    rr_error e = rr_render(dev, scene, &cam, &opt, &frame);
    if (e) die(e == RR_ERROR_ARGUMENT || e == RR_ERROR_UNSUPPORTED ? EXIT_USAGE : EXIT_INPUT, "%s", rr_device_message(dev));
    rr_stats st;
    rr_frame_get_stats(frame, &st);
    times[r] = st.frame_ms, cpus[r] = st.cpu_ms;
  }
  double frame_ms = median(times, repeat), cpu_ms = median(cpus, repeat);
  free(times), free(cpus);

  write_outputs(dev, scene, &cam, frame, shade, out, cube_dir, aovs, naov);

  rr_stats st;
  rr_frame_get_stats(frame, &st);
  rr_scene_info info;
  rr_scene_get_info(scene, &info);
  double total_ms = now_ms() - t_start;
  const char *method = rr_method_name(st.method);
  int threads = st.threads;
  if (stats)
    fprintf(stderr,
            "method=%s camera=%s triangles=%llu width=%d height=%d threads=%d frame_ms=%.3f cpu_ms=%.3f total_ms=%.1f "
            "setups=%llu edge_evals=%llu nodes=%llu bins=%llu bins_empty=%llu\n",
            method, rr_camera_name(cam.type), (unsigned long long)info.triangles, opt.width, opt.height, threads, frame_ms, cpu_ms,
            total_ms, (unsigned long long)st.setups, (unsigned long long)st.edge_evals, (unsigned long long)st.nodes,
            (unsigned long long)st.bins, (unsigned long long)st.bins_empty);
  if (stats && st.why[0]) fprintf(stderr, "auto chose %s: %s\n", method, st.why);
  else if (st.why[0]) note(1, "auto chose %s: %s\n", method, st.why);
  if (json) {
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", json);
    FILE *f = fopen(tmp, "w");
    if (!f) die(EXIT_INPUT, "cannot write '%s'", json);
    fprintf(f,
            "{\"scene\": \"%s\", \"method\": \"%s\", \"camera\": \"%s\", \"triangles\": %llu, "
            "\"skipped\": %llu, \"width\": %d, \"height\": %d, \"threads\": %d, \"repeat\": %d, "
            "\"frame_ms\": %.3f, \"cpu_ms\": %.3f, \"total_ms\": %.3f, \"setups\": %llu, \"edge_evals\": %llu, \"nodes\": %llu, "
            "\"bins\": %llu, \"bins_empty\": %llu, \"auto\": \"%s\"}\n",
            scene_name, method, rr_camera_name(cam.type), (unsigned long long)info.triangles, (unsigned long long)info.skipped, opt.width,
            opt.height, threads, repeat, frame_ms, cpu_ms, total_ms, (unsigned long long)st.setups,
            (unsigned long long)st.edge_evals, (unsigned long long)st.nodes, (unsigned long long)st.bins,
            (unsigned long long)st.bins_empty, st.why);
    if (fclose(f) != 0 || rename(tmp, json) != 0) {
      remove(tmp);
      die(EXIT_INPUT, "cannot write '%s'", json);
    }
  }
  if (out && !stats) note(0, "wrote %s (%dx%d, %s, %.1f ms)\n", out, opt.width, opt.height, method, frame_ms);
  rr_frame_release(frame);
  rr_scene_release(scene);
  return 0;
}

/* The overview: commands and where their options are. */
static void print_overview(FILE *f) {
  fputs("usage: rastray COMMAND [options]\n\ncommands:\n", f);
  for (int c = 0; c < NCOMMANDS; c++) fprintf(f, "  %-8s %s\n", commands[c].name, commands[c].summary);
  fputs("\n'rastray COMMAND --help' lists a command's options; 'rastray --version' prints the version.\n", f);
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
  const cli_command *cmd = NULL;
  for (int c = 0; c < NCOMMANDS; c++)
    if (strcmp(argv[1], commands[c].name) == 0) cmd = &commands[c];
  if (!cmd) die(EXIT_USAGE, "unknown command '%s' (expected render or info; see --help)", argv[1]);
  rr_device *dev = rr_device_new();
  if (!dev) die(EXIT_INPUT, "out of memory");
  int rc = cmd->run(dev, cmd, argc - 1, argv + 1); /* the command's name stands as getopt's argv[0] */
  rr_device_release(dev);
  return rc;
}
