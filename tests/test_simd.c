/* The AVX2 kernels that work on eight triangles at once (corner bounds, triangle
 * setup) against their scalar definitions, byte for byte: random triangles,
 * triangles sharing edges and vertices (the canonical edge order's ties), equal
 * coordinates, corners behind the eye, tiny and huge coordinates, perspective and
 * orthographic cameras (the setup's AVX2 path is perspective only). The sample loop's AVX2
 * path is compared with the scalar one through whole frames in test_continuum. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

enum { N = 4000 };

/* A vertex from a small lattice (many equal coordinates, shared vertices) or at random. */
static vec3 vertex(int kind, float scale) {
  if (kind == 0) return v3((float)(test_rand() % 5) - 2, (float)(test_rand() % 5) - 2, (float)(test_rand() % 5) - 2);
  return v3(test_randf(-scale, scale), test_randf(-scale, scale), test_randf(-scale, scale));
}

static rr_scene *random_scene(rr_device *dev, float scale) {
  rr_scene *s;
  rr_scene_new(dev, &s);
  static float pos[N * 9];
  static uint32_t idx[N * 3];
  for (int t = 0; t < N; t++) {
    int kind = t % 3;
    vec3 p[3] = {vertex(kind, scale), vertex(kind, scale), vertex(kind, scale)};
    if (t % 7 == 0 && t > 0) p[0] = v3(pos[(t - 1) * 9 + 3], pos[(t - 1) * 9 + 4], pos[(t - 1) * 9 + 5]);
    for (int k = 0; k < 3; k++) {
      pos[t * 9 + k * 3] = p[k].x, pos[t * 9 + k * 3 + 1] = p[k].y, pos[t * 9 + k * 3 + 2] = p[k].z;
      idx[t * 3 + k] = (uint32_t)(t * 3 + k);
    }
    /* every fifth triangle shares the previous one's edge, run the other way */
    if (t % 5 == 1) {
      memcpy(&pos[t * 9], &pos[(t - 1) * 9 + 3], 3 * sizeof(float));
      memcpy(&pos[t * 9 + 3], &pos[(t - 1) * 9], 3 * sizeof(float));
    }
  }
  CHECK(rr_scene_add_mesh(s, pos, N * 3, idx, N, NULL) == RR_OK, "add_mesh: %s", rr_device_message(dev));
  return s;
}

static bool random_camera(rr_device *dev, rr_camera_type type, float scale, int w, int h, camera *c) {
  rr_camera rc;
  rr_camera_init(&rc);
  rc.type = type;
  float d = test_randf(0.2f, 4.0f) * scale; /* sometimes inside the cloud: corners behind the eye */
  rc.eye[0] = test_randf(-1, 1) * d, rc.eye[1] = test_randf(-1, 1) * d, rc.eye[2] = d;
  rc.target[0] = test_randf(-0.3f, 0.3f) * scale, rc.target[1] = 0, rc.target[2] = 0;
  rc.fov_deg = test_randf(20, 110);
  rc.ortho_height = 2 * scale;
  return rr_cam_setup(dev, &rc, w, h, c) == RR_OK;
}

static void check_bounds(const rr_scene *s, const camera *c, const char *what) {
  static tri_bound a[N], b[N];
  uint32_t first = test_rand() % 5, n = s->ntris - first - test_rand() % 7; /* unaligned starts and tails */
  uint32_t na = rr_tri_corner_bounds(s, first, NULL, n, c, false, a);
  uint32_t nb = rr_tri_corner_bounds(s, first, NULL, n, c, true, b);
  CHECK(na == nb && memcmp(a, b, na * sizeof *a) == 0, "%s: AVX2 bounds differ from scalar (%u vs %u kept)", what, nb,
        na);
  CHECK(na > 0, "%s: no triangle bounded on screen", what);
  /* lists of ids (a BVH leaf's), of every length up to 20: gathers and padded lanes */
  static uint32_t ids[20];
  int differ = 0;
  for (uint32_t len = 1; len <= 20; len++) {
    for (uint32_t k = 0; k < len; k++) ids[k] = test_rand() % s->ntris;
    na = rr_tri_corner_bounds(s, 0, ids, len, c, false, a), nb = rr_tri_corner_bounds(s, 0, ids, len, c, true, b);
    differ += na != nb || memcmp(a, b, na * sizeof *a) != 0;
  }
  CHECK(differ == 0, "%s: AVX2 bounds of id lists differ from scalar for %d lengths", what, differ);
}

static void check_setup(const rr_scene *s, const camera *c, bool cull, const char *what) {
  static uint32_t ids[N];
  static tri_setup a[N], b[N];
  static int fa[N], fb[N];
  int n = (int)s->ntris - (int)(test_rand() % 9);
  for (int k = 0; k < n; k++) ids[k] = test_rand() % s->ntris;
  memset(a, 0, sizeof a), memset(b, 0, sizeof b);
  rr_tri_setup_run(s, ids, n, c, cull, false, a, fa);
  rr_tri_setup_run(s, ids, n, c, cull, true, b, fb);
  int faces = 0, setups = 0, culled = 0;
  for (int k = 0; k < n; k++) {
    faces += fa[k] != fb[k];
    setups += fa[k] != SETUP_CULLED && memcmp(&a[k], &b[k], sizeof a[k]) != 0;
    culled += fa[k] == SETUP_CULLED;
  }
  CHECK(faces == 0 && setups == 0, "%s: AVX2 setup differs from scalar: %d faces, %d setups of %d", what, faces,
        setups, n);
  CHECK(culled < n && (!cull || culled > 0), "%s: %d of %d culled (the case mix is not exercised)", what, culled, n);
}

int main(void) {
  if (!__builtin_cpu_supports("avx2")) {
    test_skip("no AVX2 on this processor: the scalar kernels are the only ones");
    return test_done();
  }
  rr_device *dev = rr_device_new();
  const float scales[] = {1.0f, 1e-3f, 1e4f};
  for (int sc = 0; sc < 3; sc++) {
    rr_scene *s = random_scene(dev, scales[sc]);
    for (int v = 0; v < (test_quick() ? 4 : 16); v++) {
      char what[96];
      for (int type = 0; type < 2; type++) {
        camera c;
        rr_camera_type ct = type ? RR_CAMERA_ORTHOGRAPHIC : RR_CAMERA_PERSPECTIVE;
        if (!random_camera(dev, ct, scales[sc], 97 + v, 61 + 3 * v, &c)) continue;
        snprintf(what, sizeof what, "scale %g view %d %s", scales[sc], v, rr_camera_name(ct));
        check_bounds(s, &c, what);
        check_setup(s, &c, v % 2 == 1, what);
        rr_cam_release(&c);
      }
    }
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return test_done();
}
