/* Shared helpers of the benchmark programs (not part of the library). */
#ifndef RR_BENCHUTIL_H
#define RR_BENCHUTIL_H
#include "rastray.h"

#include <stdbool.h>

/* Resolves a benchmark scene name: built-in names and existing paths pass through,
 * other names are looked up in the shared model directory (also inside grid:NAME:N).
 * Returns a static buffer. */
const char *bench_scene_path(const char *name);
/* Loads a scene or exits with a message. */
rr_scene *bench_load(rr_device *dev, const char *name, double *load_ms);
/* A scene auto-framed with a 50° field of view. */
void bench_camera(rr_device *dev, const rr_scene *scene, int w, int h, rr_camera *cam);
/* The benchmark view of scene `name`: auto-framed, or from inside a corner room of rooms scenes. */
void bench_view(rr_device *dev, const char *name, const rr_scene *scene, int w, int h, rr_camera *cam);
/* Renders `reps` times and returns the median frame time; *out keeps the last frame. */
double bench_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                    int reps, rr_frame **out);
/* Median of n values (sorts them). */
double bench_median(double *v, int n);
/* Milliseconds on a monotonic clock. */
double bench_now_ms(void);

/* Agreement of two visibility results given as ids and eye distances (+inf on a miss). */
typedef struct {
  double same_id;    /* share of samples with the same id (hit or miss) */
  double same_hit;   /* share of samples where both hit or both miss */
  double depth_ok;   /* share of samples hit by both whose depths agree within 1e-4 relative */
} bench_agreement;
bench_agreement bench_compare(const uint32_t *id_a, const float *depth_a, const uint32_t *id_b, const float *depth_b,
                              size_t n);
/* Eye distances of a frame (t times the length of each sample's ray direction). */
float *bench_depths(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_frame *frame);

/* ---- memory -------------------------------------------------------------- */

/* Bytes malloc has handed out and not taken back, over all arenas and mmapped
 * chunks (mallinfo2): what a data structure holds, to the byte, when measured
 * before and after making it. Blind to memory mapped without malloc. */
double bench_heap_bytes(void);
/* Gives freed memory back to the system and restarts the kernel's peak resident
 * set (/proc/self/clear_refs), so that bench_rss_peak() then reports the most
 * memory resident above this point. False when the restart is not allowed. */
bool bench_rss_mark(void);
/* Bytes of the peak resident set since bench_rss_mark above the resident set at
 * the mark; page-granular, and counts every allocator, thread stack and mapping. */
double bench_rss_peak(void);

/* ---- instruction counts (valgrind's callgrind) --------------------------- */

/* Whether this process runs under valgrind (false when built without its headers). */
bool bench_on_valgrind(void);
/* bench_render's counterpart under callgrind: renders one frame to warm up, then
 * one more whose instructions callgrind counts and dumps as a part named `name`
 * (nothing is counted outside callgrind). Returns that frame's ms (meaningless under
 * valgrind); *out keeps the frame. Exits on failure. */
double bench_count_frame(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                         const char *name, rr_frame **out);
/* The same around any code: zero and start counting, then stop and dump as `name`. */
void bench_count_start(void);
void bench_count_stop(const char *name);
/* Runs this program's executable with argv[1..] under callgrind, instrumentation off
 * until bench_count_start, its stdout discarded (timings under valgrind mean
 * nothing); the parts go to a new directory whose path is written to dir.
 * Returns the exit status, or -1 when valgrind could not be started. */
int bench_callgrind_run(char *const argv[], char *dir, size_t dir_size);
/* Calls fn(name, instructions, arg) for each part a callgrind run dumped in dir;
 * returns how many there were. */
int bench_callgrind_parts(const char *dir, void (*fn)(const char *name, uint64_t instructions, void *arg),
                          void *arg);
/* --instructions of a benchmark program not under valgrind: runs it again under
 * callgrind (where it counts one frame per method with bench_count_*), then
 * prints every part and its instructions. Returns the exit code for main. */
int bench_instructions_main(char *const argv[]);

/* Command-line values of the benchmarks, checked: false after a one-line message
 * naming the program and the option. --size WxH, each side min .. RR_MAX_SIZE; a
 * whole number lo .. hi. */
bool bench_arg_size(const char *prog, const char *v, int min, int *w, int *h);
bool bench_arg_int(const char *prog, const char *opt, const char *v, int lo, int hi, int *out);
#endif
