/* Coincident and near-coincident surfaces, the rule every method follows: the
 * sample keeps the nearest depth it computed, and on equal depths the lower id.
 * - Two copies of one mesh (same vertices, the second's ids after the first's):
 *   every method, the 2D pipeline included, shows the first copy only.
 * - The second copy scaled about the eye by 1 - δ (nearer by δ of the distance
 *   along every ray, over the same samples): the nearer copy wins wherever the
 *   two depths differ by more than the method's depth error (the 3D methods'
 *   from the plane, the 2D pipeline's from interpolated 1/w). Measured: every
 *   method shows it on every sample from δ = 1e-6 (asserted from 1e-5, a tenfold
 *   margin); at 1e-7 rounding decides sample by sample (printed for the record).
 * - Real meshes at small sizes: 2dr-bb agrees with 3dr-bb on ids as
 *   test_raster2d measures (printed per file).
 */
#include "testutil.h"

#include <math.h>
#include <string.h>

static rr_device *dev;

/* A bumpy n×n height field over [-1, 1]², as arrays for rr_scene_add_mesh. */
static void height_field(int n, float *pos, uint32_t *idx) {
  for (int j = 0; j <= n; j++)
    for (int i = 0; i <= n; i++) {
      float x = -1 + 2.0f * i / n, z = -1 + 2.0f * j / n;
      float *p = pos + 3 * (j * (n + 1) + i);
      p[0] = x, p[1] = 0.15f * sinf(5 * x) * cosf(4 * z), p[2] = z;
    }
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1, *t = idx + 6 * (j * n + i);
      t[0] = a, t[1] = c, t[2] = b, t[3] = b, t[4] = c, t[5] = d;
    }
}

/* Copies of the height field: the first as it is (unless second_only), the second
 * scaled about `eye` by 1 - shrink: nearer to the eye by that fraction along every
 * ray, covering the same samples. */
static rr_scene *two_copies(int n, const float eye[3], double shrink, bool second_only) {
  size_t nv = (size_t)(n + 1) * (n + 1), nt = (size_t)2 * n * n;
  float *pos = malloc(nv * 3 * sizeof *pos), *moved = malloc(nv * 3 * sizeof *moved);
  uint32_t *idx = malloc(nt * 3 * sizeof *idx);
  height_field(n, pos, idx);
  for (size_t v = 0; v < nv; v++)
    for (int k = 0; k < 3; k++) moved[3 * v + k] = (float)(eye[k] + (1 - shrink) * ((double)pos[3 * v + k] - eye[k]));
  rr_scene *s = NULL;
  rr_error e = rr_scene_new(dev, &s);
  if (!e && !second_only) e = rr_scene_add_mesh(s, pos, nv, idx, nt, NULL);
  if (!e) e = rr_scene_add_mesh(s, moved, nv, idx, nt, NULL);
  if (!e) e = rr_scene_commit(s);
  CHECK(e == RR_OK, "scene: %s", rr_device_message(dev));
  free(pos), free(moved), free(idx);
  return e ? NULL : s;
}

static const rr_method methods[] = {RR_METHOD_RC_BVH, RR_METHOD_3DR_BB, RR_METHOD_3DR_FULL, RR_METHOD_2DR_BB,
                                    RR_METHOD_2DR_BIN};
enum { NM = sizeof methods / sizeof *methods, W = 96, H = 72 };

/* Of the samples that hit in f (those that `alone` hits, when given), the share
 * showing the copy `want` (0 first, 1 second). */
static double share_of(const rr_frame *f, const rr_frame *alone, uint32_t per_copy, int want) {
  size_t n = (size_t)f->vb.width * f->vb.height, hits = 0, good = 0;
  for (size_t k = 0; k < n; k++) {
    uint32_t id = f->vb.id[k];
    if (id == RR_MISS || (alone && alone->vb.id[k] == RR_MISS)) continue;
    hits++;
    good += (int)(id >= per_copy) == want;
  }
  return hits ? (double)good / hits : 1;
}

static void coincident(int views) {
  const int n = 24;
  const uint32_t per_copy = 2u * n * n;
  rr_scene *s = two_copies(n, (const float[3]){0, 0, 0}, 0, false);
  if (!s) return;
  for (int v = 0; v < views; v++) {
    rr_camera cam = test_random_view(s, 1.5f, 4, 0.3f, 30, 70);
    for (int m = 0; m < NM; m++) {
      rr_frame *f = test_render(dev, s, &cam, methods[m], 2, W, H, 0);
      if (!f) continue;
      double first = share_of(f, NULL, per_copy, 0);
      CHECK(first == 1.0, "coincident copies, view %d, %s: the second copy shows on %.4f%% of hits", v,
            rr_method_name(methods[m]), 100 * (1 - first));
      rr_frame_release(f);
    }
  }
  rr_scene_release(s);
}

/* The second copy scaled about the eye by 1 - δ; returns, per method, the worst
 * share (over views) of the samples the nearer copy covers on its own that show it
 * with both copies there. */
static void near_coincident(double delta, double worst[NM], int views) {
  const int n = 24;
  const uint32_t per_copy = 2u * n * n;
  for (int m = 0; m < NM; m++) worst[m] = 1;
  for (int v = 0; v < views; v++) {
    float az = test_randf(0, 6.2831853f), el = test_randf(0.35f, 1.2f), dist = test_randf(2, 4);
    float eye[3] = {dist * cosf(el) * cosf(az), dist * sinf(el), dist * cosf(el) * sinf(az)};
    rr_scene *s = two_copies(n, eye, delta, false), *near = two_copies(n, eye, delta, true);
    if (!s || !near) return;
    rr_camera cam;
    rr_camera_init(&cam);
    memcpy(cam.eye, eye, sizeof eye);
    cam.target[0] = cam.target[1] = cam.target[2] = 0;
    cam.fov_deg = 50;
    for (int m = 0; m < NM; m++) {
      rr_frame *f = test_render(dev, s, &cam, methods[m], 2, W, H, 0);
      rr_frame *alone = test_render(dev, near, &cam, methods[m], 2, W, H, 0);
      if (f && alone) worst[m] = fmin(worst[m], share_of(f, alone, per_copy, 1));
      rr_frame_release(f), rr_frame_release(alone);
    }
    rr_scene_release(s), rr_scene_release(near);
  }
}

/* 2dr-bb against 3dr-bb on ids, on the real meshes at a small size. */
static void real_meshes(int views) {
  static const char *const names[] = {"stanford-bunny.obj", "teapot.obj", "spot.obj",  "cow.obj",
                                      "suzanne.obj",        "ogre.obj",   "nefertiti.obj"};
  printf("2dr-bb ids equal to 3dr-bb's, %dx%d, %d random views each:\n", W, H, views);
  for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
    const char *path = test_model(names[i]);
    if (!path) continue;
    rr_scene *s = NULL;
    if (rr_scene_load(dev, path, &s) != RR_OK) {
      CHECK(0, "load %s: %s", names[i], rr_device_message(dev));
      continue;
    }
    size_t same = 0, total = 0;
    for (int v = 0; v < views; v++) {
      rr_camera cam = test_random_view(s, 1.2f, 3, 0.3f, 30, 60);
      rr_frame *a = test_render(dev, s, &cam, RR_METHOD_2DR_BB, 2, W, H, 0);
      rr_frame *b = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, W, H, 0);
      for (size_t k = 0; a && b && k < (size_t)W * H; k++) same += a->vb.id[k] == b->vb.id[k], total++;
      rr_frame_release(a), rr_frame_release(b);
    }
    double share = total ? (double)same / total : 1;
    printf("  %-20s %.4f%%\n", names[i], 100 * share);
    /* snapping to the 2D grid moves edges by up to 1/256 pixel: a few samples per edge crossing */
    CHECK(share >= 0.99, "%s: 2dr-bb ids agree with 3dr-bb on %.4f%% of samples", names[i], 100 * share);
    rr_scene_release(s);
  }
}

int main(void) {
  dev = rr_device_new();
  int views = test_quick() ? 2 : 6;
  coincident(views);
  static const double deltas[] = {1e-7, 1e-6, 1e-5, 1e-4, 1e-3};
  printf("near-coincident copies: worst share of hits showing the nearer one, %d views\n  delta   ", views);
  for (int m = 0; m < NM; m++) printf(" %9s", rr_method_name(methods[m]));
  printf("\n");
  for (size_t d = 0; d < sizeof deltas / sizeof *deltas; d++) {
    double worst[NM];
    near_coincident(deltas[d], worst, views);
    printf("  %-7.0e ", deltas[d]);
    for (int m = 0; m < NM; m++) printf(" %8.4f%%", 100 * worst[m]);
    printf("\n");
    for (int m = 0; m < NM; m++) {
      if (deltas[d] >= 1e-5)
        CHECK(worst[m] == 1.0, "delta %g, %s: the nearer copy shows on only %.4f%% of hits", deltas[d],
              rr_method_name(methods[m]), 100 * worst[m]);
    }
  }
  real_meshes(test_quick() ? 1 : 3);
  rr_device_release(dev);
  return test_done();
}
