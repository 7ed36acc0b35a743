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
/* The benchmark view of a scene: auto-framed, or from inside for rooms scenes. */
void bench_camera(rr_device *dev, const rr_scene *scene, int w, int h, rr_camera *cam);
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
#endif
