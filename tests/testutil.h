/* A tiny test harness: CHECK counts and reports, test_done prints the summary
 * line and returns the exit code (77 tells ctest the test was skipped). */
#ifndef RR_TESTUTIL_H
#define RR_TESTUTIL_H
#include <stdbool.h>
#include <stdio.h>

#include "vis/vis.h"
#include "io/io.h"

#include <tinyexr.h>

extern int test_passed, test_failed;

#define CHECK(cond, ...)                                                   \
  do {                                                                     \
    if (cond) {                                                            \
      test_passed++;                                                       \
    } else {                                                               \
      test_failed++;                                                       \
      fprintf(stderr, "%s:%d: FAILED: %s: ", __FILE__, __LINE__, #cond);   \
      fprintf(stderr, __VA_ARGS__);                                        \
      fputc('\n', stderr);                                                 \
    }                                                                      \
  } while (0)

/* Prints "N passed, N failed" and returns the process exit code. */
int test_done(void);
/* Marks the run skipped (printed by test_done) with a reason. */
void test_skip(const char *why);
/* Path of a shared model, or NULL (and a note) when it is absent. */
const char *test_model(const char *name);
/* True when RR_TEST_QUICK is set (the sanitizer run): property tests then visit
 * fewer views and smaller meshes, the same code paths. */
bool test_quick(void);
/* Samples where two visibility buffers differ in any byte of id, t, λ1 or λ2 (every
 * sample layer; frames of different sample counts differ everywhere). */
int test_frames_differ(const rr_frame *a, const rr_frame *b);
/* Options for method m at w×h on `threads` threads with the n sample positions pos. */
rr_render_options test_pattern(rr_method m, int w, int h, int threads, int n, const float (*pos)[2]);
/* Checks that every layer k of `multi` (rendered with options o) is, byte for byte
 * (id, t, λ1, λ2), the frame of one sample at o's position k drawn by method one. */
void test_check_layers(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *o,
                       rr_method one, const rr_frame *multi, const char *what);
/* Samples of a frame that hit a triangle. */
int test_frame_hits(const rr_frame *f);
/* Renders w×h with method m on `threads` threads (cull: back faces culled) and
 * checks that it succeeds; the frame, or NULL. */
rr_frame *test_render(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int threads, int w, int h,
                      int cull);
/* The same with every option given. */
rr_frame *test_render_opt(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt);
/* The thread counts of the bit-identity tests: one, two, and more threads than
 * cores (eight: tiles and bands are still dealt out dynamically on two cores). */
enum { TEST_NTHREADS = 3 };
extern const int test_threads[TEST_NTHREADS];
/* Renders as *opt says (opt->threads aside) on each of test_threads and checks that
 * every frame equals ref byte for byte (ids, t, λ1, λ2), or the one-thread frame
 * when ref is NULL, and that S, E and N do not depend on the thread count where
 * the method promises it (see testutil.c). `what` names the view in messages.
 * Returns the one-thread frame (the caller releases it), or NULL. */
rr_frame *test_render_threads(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                              const rr_frame *ref, const char *what);
/* A random view of s: the eye at dist_lo..dist_hi times the radius of the scene's
 * bounds from their centre, in a random direction (below 1: inside the bounds),
 * looking at a point within aim times that radius of the centre, with a field of
 * view of fov_lo..fov_hi degrees; the rest as rr_camera_init (perspective, y up).
 * A range of one value (lo == hi) draws no random number. */
rr_camera test_random_view(const rr_scene *s, float dist_lo, float dist_hi, float aim, float fov_lo, float fov_hi);
/* A random view of camera `type` from outside the scene, or from inside it (close
 * to its centre), with the fields every camera type needs (fisheye 200°, others 70°,
 * orthographic height 8). */
rr_camera test_random_camera(const rr_scene *s, rr_camera_type type, bool inside);
/* rr_depth_errors (vis/vis.h) of a frame's depth for camera cam; false when the
 * camera cannot be set up or is not planar. */
typedef rr_depth_stats test_depth_stats;
bool test_depth_errors(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                       test_depth_stats *out);
/* Writes `text` to the file dir/name and returns its path (one of eight rotating
 * buffers, so a few paths stay valid at once); a file that cannot be written is
 * left missing, for the test's load to report. */
const char *test_write_file(const char *dir, const char *name, const char *text);
/* Runs the CLI (RR_CLI) with args in directory dir: its exit status (-1 when it could not
 * run or was killed), its stdout in out (with stderr too when with_stderr). */
int test_run_cli(const char *dir, const char *args, bool with_stderr, char *out, size_t cap);
/* An EXR file read through tinyexr itself rather than rastray's reader (ok: it
 * loaded; a failure is CHECKed). test_exr_free releases it in either case. */
typedef struct test_exr_file {
  EXRHeader h;
  EXRImage img;
  bool ok;
} test_exr_file;
bool test_exr_load(const char *path, test_exr_file *x);
void test_exr_free(test_exr_file *x);
/* The index of the channel named `name`, -1 when absent. */
int test_exr_find(const test_exr_file *x, const char *name);
/* The reference of the ray queries: every triangle of s with the full setup and
 * sample test of rc (rr_tri_ray_hit), ties in t to the lower id; *any: whether
 * any triangle is hit in [tmin, tmax]. */
rr_hit test_brute_ray(const rr_scene *s, const rr_ray *ray, int *any);
/* rr_intersect and rr_occluded against test_brute_ray on the camera rays of six
 * random views of s (24×18; every other one close up, the last with random tmin and
 * tmax); fails on any difference. each (NULL: none) sees every rr_intersect result.
 * Returns the rays; *hits: those that hit. */
int test_check_rays(rr_device *dev, const rr_scene *s, void (*each)(const rr_hit *h, void *arg), void *arg,
                    int *hits);
/* A camera of `type` at eye looking at target, fov_deg fov, y up. */
rr_camera test_camera(rr_camera_type type, vec3 eye, vec3 target, float fov);
/* Deterministic random numbers for property tests. */
unsigned test_rand(void);
float test_randf(float lo, float hi);
#endif
