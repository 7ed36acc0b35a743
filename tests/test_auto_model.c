/* auto's cost model: the depth complexity D it estimates from the looked-at
 * triangles (vis/auto.c) is high for a stack of layers and low for one layer of as
 * many triangles, also when it looks at only some of them, and its occlusion
 * figure S/D follows; the per-frame figure is 1. */
#include "testutil.h"
#include "vis/vis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* `layers` squares [-1, 1]² at z = 0, -0.1, ..., each a grid of n × n cells of two
 * triangles facing +z: every point of the square is covered by 2 · layers
 * triangle rectangles (a right triangle's rectangle is its cell). */
static rr_scene *stack(rr_device *dev, int layers, int n) {
  int nv = layers * (n + 1) * (n + 1), nt = layers * n * n * 2;
  float *p = malloc(sizeof *p * 3 * (size_t)nv);
  uint32_t *ix = malloc(sizeof *ix * 3 * (size_t)nt);
  rr_scene *s = NULL;
  if (p && ix && rr_scene_new(dev, &s) == RR_OK) {
    for (int l = 0, v = 0; l < layers; l++)
      for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++, v++)
          p[3 * v] = -1 + 2.0f * i / n, p[3 * v + 1] = -1 + 2.0f * j / n, p[3 * v + 2] = -0.1f * l;
    for (int l = 0, t = 0; l < layers; l++)
      for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++, t += 2) {
          uint32_t a = (uint32_t)(l * (n + 1) * (n + 1) + j * (n + 1) + i), b = a + 1, c = a + (uint32_t)n + 1,
                   d = c + 1;
          uint32_t q[6] = {a, b, d, a, d, c};
          for (int k = 0; k < 6; k++) ix[3 * t + k] = q[k];
        }
    if (rr_scene_add_mesh(s, p, (size_t)nv, ix, (size_t)nt, NULL) != RR_OK || rr_scene_commit(s) != RR_OK)
      rr_scene_release(s), s = NULL;
  }
  free(p), free(ix);
  return s;
}

/* D and the figures of an orthographic view straight down -z that the square fills. */
static bool predict(rr_device *dev, const rr_scene *s, auto_prediction *p) {
  rr_camera cam;
  rr_camera_init(&cam);
  cam.type = RR_CAMERA_ORTHOGRAPHIC;
  cam.eye[0] = 0, cam.eye[1] = 0, cam.eye[2] = 5;
  cam.target[0] = 0, cam.target[1] = 0, cam.target[2] = 0;
  cam.ortho_height = 2;
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = opt.height = 128, opt.threads = 1;
  return rr_auto_predict(dev, s, &cam, &opt, p) == RR_OK;
}

int main(void) {
  rr_device *dev = rr_device_new();
  /* 8 layers of 24² cells (9216 triangles: more than the model looks at) against
   * one layer of 68² cells (9248), and a small stack the model sees whole */
  struct {
    int layers, n;
    double lo, hi; /* D expected: 2 · layers, within the sampling's spread */
  } scenes[] = {{8, 24, 13, 19}, {1, 68, 1.5, 2.5}, {4, 8, 7, 9}, {1, 8, 1.9, 2.1}};
  double d[4] = {0}, sd[4] = {0};
  for (int k = 0; k < 4; k++) {
    rr_scene *s = stack(dev, scenes[k].layers, scenes[k].n);
    auto_prediction p;
    CHECK(s && predict(dev, s, &p), "%d layers: %s", scenes[k].layers, rr_device_message(dev));
    if (!s) continue;
    d[k] = p.depth, sd[k] = p.fig[AUTO_SD];
    printf("%d layers of %d² cells: %s\n", scenes[k].layers, scenes[k].n, p.figures);
    CHECK(p.depth >= scenes[k].lo && p.depth <= scenes[k].hi, "%d layers of %d² cells: D = %g, not in [%g, %g]",
          scenes[k].layers, scenes[k].n, p.depth, scenes[k].lo, scenes[k].hi);
    CHECK(fabs(p.fig[AUTO_SD] * p.depth - p.fig[AUTO_S]) <= 1e-9 * p.fig[AUTO_S] && p.fig[AUTO_S] > 0,
          "%d layers: S/D = %g, S = %g, D = %g", scenes[k].layers, p.fig[AUTO_SD], p.fig[AUTO_S], p.depth);
    CHECK(p.fig[AUTO_ONE] == 1, "the per-frame figure is %g", p.fig[AUTO_ONE]);
    CHECK(strstr(p.figures, "D=") != NULL, "D not in '%s'", p.figures);
    rr_scene_release(s);
  }
  /* as many triangles, as much area: the stack shows 8 layers, its front layer is
   * an eighth of its setups */
  CHECK(d[0] > 4 * d[1], "D of 8 layers %g, of one %g", d[0], d[1]);
  CHECK(sd[0] < sd[1] / 4, "S/D of 8 layers %g, of one %g", sd[0], sd[1]);
  rr_device_release(dev);
  return test_done();
}
