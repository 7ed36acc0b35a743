/* auto's cost model: the depth complexity D it estimates from the looked-at
 * triangles (vis/auto.c) is high for a stack of layers and low for one layer of as
 * many triangles, also when it looks at only some of them, and S/D follows; the
 * setups a front-to-back pass leaves (F) are one layer's, seen from either side (the
 * pass takes the nearest first, not the first in the scene); the per-frame figure is 1;
 * a cube's figures are those of its six faces' perspective views, summed. */
#include "testutil.h"
#include "vis/vis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* `layers` squares [-1, 1]² at z = 0, -0.1, ..., each a grid of n × n cells of two
 * triangles facing +z (layer l of n_l × n_l when n_l is given): every point of the
 * square is covered by 2 · layers triangle rectangles (a right triangle's rectangle
 * is its cell). */
static rr_scene *stack_of(rr_device *dev, int layers, const int *n_l) {
  int nv = 0, nt = 0;
  for (int l = 0; l < layers; l++) nv += (n_l[l] + 1) * (n_l[l] + 1), nt += n_l[l] * n_l[l] * 2;
  float *p = malloc(sizeof *p * 3 * (size_t)nv);
  uint32_t *ix = malloc(sizeof *ix * 3 * (size_t)nt);
  rr_scene *s = NULL;
  if (p && ix && rr_scene_new(dev, &s) == RR_OK) {
    for (int l = 0, v = 0, t = 0; l < layers; l++) {
      int n = n_l[l], first = v;
      for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++, v++)
          p[3 * v] = -1 + 2.0f * i / n, p[3 * v + 1] = -1 + 2.0f * j / n, p[3 * v + 2] = -0.1f * l;
      for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++, t += 2) {
          uint32_t a = (uint32_t)(first + j * (n + 1) + i), b = a + 1, c = a + (uint32_t)n + 1, d = c + 1;
          uint32_t q[6] = {a, b, d, a, d, c};
          for (int k = 0; k < 6; k++) ix[3 * t + k] = q[k];
        }
    }
    if (rr_scene_add_mesh(s, p, (size_t)nv, ix, (size_t)nt, NULL) != RR_OK || rr_scene_commit(s) != RR_OK)
      rr_scene_release(s), s = NULL;
  }
  free(p), free(ix);
  return s;
}

static rr_scene *stack(rr_device *dev, int layers, int n) {
  int n_l[8];
  for (int l = 0; l < layers && l < 8; l++) n_l[l] = n;
  return stack_of(dev, layers < 8 ? layers : 8, n_l);
}

/* D and the figures of an orthographic view along z (from +z, or from -z when
 * `behind`) that the square fills. */
static bool predict(rr_device *dev, const rr_scene *s, bool behind, auto_prediction *p) {
  rr_camera cam;
  rr_camera_init(&cam);
  cam.type = RR_CAMERA_ORTHOGRAPHIC;
  cam.eye[0] = 0, cam.eye[1] = 0, cam.eye[2] = behind ? -5.0f : 5.0f;
  cam.target[0] = 0, cam.target[1] = 0, cam.target[2] = 0;
  cam.ortho_height = 2;
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = opt.height = 128, opt.threads = 1;
  return rr_auto_predict(dev, s, &cam, &opt, p) == RR_OK;
}

/* A cube camera inside a stack of layers against the six perspective views of
 * 90° along its faces: S, A and F (and T, P) are their sums. */
static void cube_is_six_faces(rr_device *dev) {
  rr_scene *s = stack(dev, 4, 8);
  const float eye[3] = {0.3f, 0.2f, -0.15f}, r[3] = {1, 0, 0}, u[3] = {0, 1, 0}, w[3] = {0, 0, -1};
  const float *fwd[6] = {w, r, NULL, NULL, u, NULL}, *up[6] = {u, u, u, u, NULL, w};
  const float nw[3] = {0, 0, 1}, nr[3] = {-1, 0, 0}, nu[3] = {0, -1, 0};
  fwd[2] = nw, fwd[3] = nr, fwd[5] = nu, up[4] = nw; /* back, left, bottom; the top's up */
  rr_camera cam;
  rr_camera_init(&cam);
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.threads = 1;
  double sum[AUTO_NFIG] = {0};
  auto_prediction p;
  bool ok = s != NULL;
  for (int f = 0; f < 6 && ok; f++) {
    cam.type = RR_CAMERA_PERSPECTIVE, cam.fov_deg = 90;
    for (int k = 0; k < 3; k++) cam.eye[k] = eye[k], cam.target[k] = eye[k] + fwd[f][k], cam.up[k] = up[f][k];
    opt.width = opt.height = 64;
    ok = rr_auto_predict(dev, s, &cam, &opt, &p) == RR_OK;
    for (int k = 0; k < AUTO_NFIG; k++) sum[k] += p.fig[k];
  }
  cam.type = RR_CAMERA_CUBE;
  for (int k = 0; k < 3; k++) cam.target[k] = eye[k] + w[k], cam.up[k] = u[k];
  opt.width = 4 * 64, opt.height = 3 * 64;
  ok = ok && rr_auto_predict(dev, s, &cam, &opt, &p) == RR_OK;
  CHECK(ok, "cube: %s", rr_device_message(dev));
  printf("cube: %s\n", p.figures);
  const int figs[] = {AUTO_S, AUTO_A, AUTO_F, AUTO_P};
  for (int k = 0; ok && k < 4; k++) {
    double x = p.fig[figs[k]], y = sum[figs[k]];
    CHECK(y > 0 && fabs(x - y) <= 0.02 * y, "cube's %s %g, six faces' %g", rr_auto_fig_names[figs[k]], x, y);
  }
  CHECK(!ok || p.fig[AUTO_T] == sum[AUTO_T] / 6, "cube's T %g", p.fig[AUTO_T]);
  rr_scene_release(s);
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
    CHECK(s && predict(dev, s, false, &p), "%d layers: %s", scenes[k].layers, rr_device_message(dev));
    if (!s) continue;
    d[k] = p.depth, sd[k] = p.fig[AUTO_SD];
    printf("%d layers of %d² cells: %s\n", scenes[k].layers, scenes[k].n, p.figures);
    CHECK(p.depth >= scenes[k].lo && p.depth <= scenes[k].hi, "%d layers of %d² cells: D = %g, not in [%g, %g]",
          scenes[k].layers, scenes[k].n, p.depth, scenes[k].lo, scenes[k].hi);
    CHECK(fabs(p.fig[AUTO_SD] * p.depth - p.fig[AUTO_S]) <= 1e-9 * p.fig[AUTO_S] && p.fig[AUTO_S] > 0,
          "%d layers: S/D = %g, S = %g, D = %g", scenes[k].layers, p.fig[AUTO_SD], p.fig[AUTO_S], p.depth);
    CHECK(p.fig[AUTO_ONE] == 1, "the per-frame figure is %g", p.fig[AUTO_ONE]);
    CHECK(strstr(p.figures, "D=") != NULL, "D not in '%s'", p.figures);
    /* one layer's setups are left, within the sampling's spread (one triangle in
     * 2.25 looked at for the big stack) */
    for (int side = 0; side < 2; side++) {
      auto_prediction q;
      if (side && !predict(dev, s, true, &q)) continue;
      const auto_prediction *x = side ? &q : &p;
      double layer = x->fig[AUTO_S] / scenes[k].layers;
      CHECK(x->fig[AUTO_F] >= 0.8 * layer && x->fig[AUTO_F] <= 1.5 * layer,
            "%d layers, seen from %s: F = %g, one layer's setups %g", scenes[k].layers, side ? "behind" : "the front",
            x->fig[AUTO_F], layer);
    }
    rr_scene_release(s);
  }
  /* as many triangles, as much area: the stack shows 8 layers, its front layer is
   * an eighth of its setups */
  CHECK(d[0] > 4 * d[1], "D of 8 layers %g, of one %g", d[0], d[1]);
  CHECK(sd[0] < sd[1] / 4, "S/D of 8 layers %g, of one %g", sd[0], sd[1]);

  /* a fine layer (4608 triangles) in front of a coarse one (288), the fine one
   * first in the scene: F is the nearer layer's setups, from either side */
  rr_scene *two = stack_of(dev, 2, (const int[]){48, 12});
  for (int side = 0; two && side < 2; side++) {
    auto_prediction p;
    CHECK(predict(dev, two, side, &p), "two layers: %s", rr_device_message(dev));
    printf("two layers from %s: %s\n", side ? "behind" : "the front", p.figures);
    double fine = 4608, coarse = 288;
    CHECK(side ? p.fig[AUTO_F] < coarse + 0.2 * fine : p.fig[AUTO_F] > 0.9 * fine,
          "two layers seen from %s: F = %g", side ? "behind" : "the front", p.fig[AUTO_F]);
  }
  rr_scene_release(two);
  cube_is_six_faces(dev);
  rr_device_release(dev);
  return test_done();
}
