/* bench_python: the C side of the Python overhead measure (bench/python_overhead.sh).
 *
 *   bench_python render|rays N [SIZE]
 *
 * Loads `demo` (one thread), frames it at SIZE² (default 1024) and then N times
 * either renders with 3dr-bin and extracts the depth, id, normal and mesh AOVs (what
 * rastray.Scene.render does), or traces the camera's SIZE² rays (an (N, 6) float
 * array, as Python's) through rr_intersect_stream (what Scene.intersect does).
 * bench/python_overhead.py does the same through the Python package; callgrind's
 * instruction counts at N = 0 and N = 2 give the cost of one call on each side. */
#include "rastray.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
  if (argc < 3 || (strcmp(argv[1], "render") && strcmp(argv[1], "rays"))) {
    fprintf(stderr, "usage: bench_python render|rays N [SIZE]\n");
    return 2;
  }
  int n = atoi(argv[2]), size = argc > 3 ? atoi(argv[3]) : 1024;
  rr_device *dev = rr_device_new();
  rr_build_options bo;
  rr_build_options_init(&bo);
  bo.threads = 1;
  rr_device_set_build_options(dev, &bo);
  rr_scene *scene;
  if (rr_scene_load(dev, "demo", &scene)) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, scene, size, size, &cam);
  if (!strcmp(argv[1], "render")) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_3DR_BIN, opt.width = opt.height = size, opt.threads = 1;
    const rr_aov aovs[] = {RR_AOV_DEPTH, RR_AOV_ID, RR_AOV_NORMAL, RR_AOV_MESH};
    for (int r = 0; r < n; r++) {
      rr_frame *frame;
      if (rr_render(dev, scene, &cam, &opt, &frame)) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
      for (int a = 0; a < 4; a++) {
        rr_image img;
        if (rr_frame_aov(dev, scene, &cam, frame, aovs[a], &img)) return 1;
        rr_image_free(&img);
      }
      rr_frame_release(frame);
    }
  } else {
    size_t count = (size_t)size * size;
    float *org = malloc(count * 3 * sizeof *org), *dir = malloc(count * 3 * sizeof *dir);
    float *rays = malloc(count * 6 * sizeof *rays), *ranges = calloc(count * 6, sizeof *ranges);
    rr_hit *hits = malloc(count * sizeof *hits);
    if (!org || !dir || !rays || !ranges || !hits) return 1;
    rr_camera_rays(dev, &cam, size, size, org, dir);
    for (size_t i = 0; i < count; i++) {
      memcpy(rays + 6 * i, org + 3 * i, 3 * sizeof *rays), memcpy(rays + 6 * i + 3, dir + 3 * i, 3 * sizeof *rays);
      ranges[6 * i + 1] = INFINITY;
    }
    rr_ray_stream s = {.count = count, .stride = 6 * sizeof(float), .org = {rays, rays + 1, rays + 2},
                       .dir = {rays + 3, rays + 4, rays + 5}, .tmin = ranges, .tmax = ranges + 1};
    for (int r = 0; r < n; r++)
      if (rr_intersect_stream(dev, scene, &s, 1, hits)) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
    free(org), free(dir), free(rays), free(ranges), free(hits);
  }
  rr_scene_release(scene);
  rr_device_release(dev);
  return 0;
}
