/* The kernel templates' AVX2 instances (eight lanes) against their plain ones
 * (one lane), byte for byte: the corner bounds, the triangle setup and the sample
 * loop. Random triangles, triangles sharing edges and vertices (the canonical edge
 * order's ties), equal coordinates, corners behind the eye and at infinity, tiny
 * and huge coordinates, perspective and orthographic cameras, backface culling,
 * unaligned runs, id lists of every length (padded lanes) and rectangles whose
 * width is no multiple of eight. The sample loop is also compared through whole
 * frames in test_continuum. */
#include "vis/vis.h"
#include "core/simd.h"
#include "io/io.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

enum { N = 4000 };

/* A vertex from a small lattice (many equal coordinates, shared vertices) or at random. */
static vec3 vertex(int kind, float scale) {
  if (kind == 0) return v3((float)(test_rand() % 5) - 2, (float)(test_rand() % 5) - 2, (float)(test_rand() % 5) - 2);
  return v3(test_randf(-scale, scale), test_randf(-scale, scale), test_randf(-scale, scale));
}

/* with_inf: some corners at infinity (w = 0: xyz is a direction) */
static rr_scene *random_scene(rr_device *dev, float scale, bool with_inf) {
  rr_scene *s;
  rr_scene_new(dev, &s);
  static float pos[N * 9], pos4[N * 12];
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
  if (!with_inf) {
    CHECK(rr_scene_add_mesh(s, pos, N * 3, idx, N, NULL) == RR_OK, "add_mesh: %s", rr_device_message(dev));
    return s;
  }
  for (int v = 0; v < N * 3; v++) {
    memcpy(&pos4[v * 4], &pos[v * 3], 3 * sizeof(float));
    pos4[v * 4 + 3] = v % 5 == 2 || v % 13 == 4 ? 0.0f : 1.0f;
  }
  CHECK(rr_scene_add_mesh4(s, pos4, N * 3, idx, N, NULL) == RR_OK, "add_mesh4: %s", rr_device_message(dev));
  CHECK(s->inf, "corners at infinity");
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

/* The sample loop over rectangles of set-up triangles into two visibility
 * buffers, one lane and eight at a time; the buffers start with random depths
 * and ids, so the depth test's ties (equal t, lower id) are met too. */
static void check_raster(const rr_scene *s, const camera *c, const char *what) {
  enum { TRIS = 300 };
  int w = c->width, h = c->height;
  size_t n = (size_t)w * h;
  visbuf vb[2];
  for (int k = 0; k < 2; k++) {
    vb[k] = (visbuf){w, h, malloc(n * sizeof(uint32_t)), malloc(n * sizeof(float)), calloc(n, sizeof(float)),
                     calloc(n, sizeof(float)), 1};
    CHECK(vb[k].id && vb[k].t && vb[k].l1 && vb[k].l2, "out of memory");
    if (!vb[k].id || !vb[k].t || !vb[k].l1 || !vb[k].l2) return;
  }
  for (size_t k = 0; k < n; k++) {
    vb[0].id[k] = vb[1].id[k] = test_rand() % 4 ? RR_MISS : test_rand() % s->ntris;
    vb[0].t[k] = vb[1].t[k] = test_rand() % 4 ? INFINITY : test_randf(0.0f, 2.0f);
  }
  uint64_t evals[2] = {0, 0}, covered[2] = {0, 0};
  int drawn = 0;
  for (int k = 0; k < TRIS; k++) {
    uint32_t id = test_rand() % s->ntris;
    tri_setup ts;
    int r[4];
    if (rr_tri_setup(s, id, c, false, &ts) == SETUP_CULLED || !rr_tri_screen_bounds(s, id, c, &ts, r)) continue;
    /* the triangle's rectangle, or a random one (samples outside it too) */
    if (k % 3 == 0) {
      r[0] = test_rand() % w, r[1] = test_rand() % h;
      r[2] = r[0] + (int)(test_rand() % (unsigned)(w - r[0])), r[3] = r[1] + (int)(test_rand() % (unsigned)(h - r[1]));
    }
    for (int simd = 0; simd < 2; simd++) evals[simd] += rr_raster_rect(&ts, id, r, c, &vb[simd], &covered[simd], simd);
    drawn++;
  }
  bool same = memcmp(vb[0].id, vb[1].id, n * sizeof(uint32_t)) == 0;
  same = same && memcmp(vb[0].t, vb[1].t, n * sizeof(float)) == 0;
  same = same && memcmp(vb[0].l1, vb[1].l1, n * sizeof(float)) == 0;
  same = same && memcmp(vb[0].l2, vb[1].l2, n * sizeof(float)) == 0;
  CHECK(same && evals[0] == evals[1] && covered[0] == covered[1],
        "%s: the AVX2 sample loop differs from the plain one (%llu vs %llu covered)", what,
        (unsigned long long)covered[1], (unsigned long long)covered[0]);
  CHECK(drawn > 0 && covered[0] > 0, "%s: no sample covered (the case mix is not exercised)", what);
  for (int k = 0; k < 2; k++) free(vb[k].id), free(vb[k].t), free(vb[k].l1), free(vb[k].l2);
}

#ifdef RR_SIMD_X86
/* The masked gathers (the depth test of the lanes over positions): eight lanes
 * against one lane each, masked-off lanes 0 and never read (indices past the table). */
RR_TARGET_AVX2 static void check_gathers(void) {
  float tf[64];
  int32_t ti[64];
  for (int k = 0; k < 64; k++) tf[k] = test_randf(-1e3f, 1e3f), ti[k] = (int32_t)test_rand();
  int bad = 0;
  for (int round = 0; round < 200; round++) {
    int32_t idx[8], m[8];
    for (int l = 0; l < 8; l++) m[l] = test_rand() % 3 ? -1 : 0, idx[l] = m[l] ? (int32_t)(test_rand() % 64) : 1 << 28;
    const rr_vi8 iv = rr_vi8_load(idx), mv = rr_vi8_load(m);
    const rr_vf8 f = rr_vf8_gather_masked(tf, iv, mv);
    const rr_vi8 i = rr_vi8_gather_masked(ti, iv, mv);
    for (int l = 0; l < 8; l++) {
      const rr_vi1 i1 = {idx[l]}, m1 = {m[l]};
      const rr_vf1 f1 = rr_vf1_gather_masked(tf, i1, m1);
      const rr_vi1 j1 = rr_vi1_gather_masked(ti, i1, m1);
      bad += memcmp(&f[l], &f1[0], sizeof f1[0]) != 0 || i[l] != j1[0] || (m[l] ? f[l] != tf[idx[l]] : f[l] != 0.0f);
    }
  }
  CHECK(bad == 0, "masked gathers: %d lanes differ from the one-lane gathers", bad);
}
#endif

int main(void) {
#ifdef RR_SIMD_X86
  if (!__builtin_cpu_supports("avx2")) {
    test_skip("no AVX2 on this processor: the plain kernels are the only ones");
    return test_done();
  }
#else
  test_skip("no AVX2 instances in this build: the plain kernels are the only ones");
  return test_done();
#endif
#ifdef RR_SIMD_X86
  check_gathers();
#endif
  rr_device *dev = rr_device_new();
  const float scales[] = {1.0f, 1e-3f, 1e4f};
  for (int sc = 0; sc < 4; sc++) {
    rr_scene *s = random_scene(dev, scales[sc % 3], sc == 3);
    for (int v = 0; v < (test_quick() ? 4 : 16); v++) {
      char what[96];
      for (int type = 0; type < 2; type++) {
        camera c;
        rr_camera_type ct = type ? RR_CAMERA_ORTHOGRAPHIC : RR_CAMERA_PERSPECTIVE;
        if (!random_camera(dev, ct, scales[sc % 3], 97 + v, 61 + 3 * v, &c)) continue;
        snprintf(what, sizeof what, "scale %g%s view %d %s", scales[sc % 3], sc == 3 ? " at infinity" : "", v,
                 rr_camera_name(ct));
        check_bounds(s, &c, what);
        check_setup(s, &c, v % 2 == 1, what);
        check_raster(s, &c, what);
        rr_cam_release(&c);
      }
    }
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return test_done();
}
