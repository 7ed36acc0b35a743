/* The 3D rasterization methods take every sample position of a pattern in one
 * pass (render.c: all_samples): each triangle is set up once and moved to each
 * position (rr_tri_setup_at). Checked here: the moved setup is the setup at that
 * position, bit for bit; on a 16-position pattern every 3dr method, rc-packet and
 * rc (on the small scene) equal rc-bvh (one pass per position) for every camera,
 * the OpenCV ones with distortion, random and inside views, on one and two
 * threads, and a layer equals the one-sample frame at its position; and at
 * sample level the pipeline is watertight: positions on the vertices and edges of
 * a tessellated plane are each claimed exactly once. */
#include "vis/vis.h"
#include "testutil.h"

#include <string.h>

/* A 4x4 grid rotated by atan(1/2) about the pixel centre, wrapped into [0, 1):
 * sixteen distinct columns and rows, none at the centre. */
static float rg16[16][2];
static void make_rg16(void) {
  const float c = 2.0f / sqrtf(5.0f), s = 1.0f / sqrtf(5.0f);
  for (int i = 0; i < 16; i++) {
    float u = ((float)(i % 4) + 0.5f) / 4 - 0.5f, v = ((float)(i / 4) + 0.5f) / 4 - 0.5f;
    float x = 0.5f + c * u - s * v, y = 0.5f + s * u + c * v;
    rg16[i][0] = x - floorf(x), rg16[i][1] = y - floorf(y);
  }
}

static const rr_method methods3d[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FS,
                                      RR_METHOD_3DR_FULL};
enum { NMETHODS3D = sizeof methods3d / sizeof methods3d[0] };

/* rc tests every sample against every triangle: only on scenes this small */
enum { RC_MAX_TRIS = 4096 };

/* Every 3dr method, rc-packet (rc-bvh's traversal on curved cameras) and, on a small
 * scene, rc against rc-bvh on all 16 layers; with `layers`, each layer of 3dr-full
 * against a one-sample 3dr-bb frame at its position too. */
static void check_view(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h, int threads,
                       bool layers, const char *what) {
  rr_render_options o = test_pattern(RR_METHOD_RC_BVH, w, h, threads, 16, (const float (*)[2])rg16);
  rr_frame *ref = test_render_opt(dev, s, cam, &o);
  if (!ref) return;
  rr_frame *full = NULL;
  const rr_method others[NMETHODS3D + 2] = {RR_METHOD_RC, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                            RR_METHOD_3DR_FC, RR_METHOD_3DR_FS, RR_METHOD_3DR_FULL};
  for (int i = 0; i < NMETHODS3D + 2; i++) {
    o.method = others[i];
    if (o.method == RR_METHOD_RC && s->ntris > RC_MAX_TRIS) continue;
    rr_frame *f = test_render_opt(dev, s, cam, &o);
    if (!f) continue;
    int d = test_frames_differ(ref, f);
    CHECK(d == 0, "%s, %d threads: %s differs from rc-bvh in %d of %d samples", what, threads,
          rr_method_name(o.method), d, 16 * w * h);
    rr_stats st;
    rr_frame_get_stats(f, &st);
    CHECK(st.setups > 0 && (st.edge_evals > 0 || o.method == RR_METHOD_RC_PACKET), "%s: %s reports no work", what,
          rr_method_name(o.method));
    if (o.method == RR_METHOD_3DR_FULL) full = f;
    else rr_frame_release(f);
  }
  if (layers && full) test_check_layers(dev, s, cam, &o, RR_METHOD_3DR_BB, full, what);
  rr_frame_release(full);
  rr_frame_release(ref);
}

/* S counts setups per triangle, not per position: at 16 positions far fewer than
 * the 16 one-position frames together; E counts every sample evaluation. */
static void check_stats(rr_device *dev, const rr_scene *s, const rr_camera *cam) {
  for (int i = 0; i < NMETHODS3D; i++) {
    rr_render_options o16 = test_pattern(methods3d[i], 128, 96, 1, 16, (const float (*)[2])rg16);
    rr_frame *b = test_render_opt(dev, s, cam, &o16);
    if (!b) continue;
    uint64_t setups = 0, evals = 0;
    for (int k = 0; k < 16; k++) {
      rr_render_options o1 = test_pattern(methods3d[i], 128, 96, 1, 1, (const float (*)[2]) & rg16[k]);
      rr_frame *a = test_render_opt(dev, s, cam, &o1);
      if (!a) continue;
      rr_stats sa;
      rr_frame_get_stats(a, &sa);
      setups += sa.setups, evals += sa.edge_evals;
      rr_frame_release(a);
    }
    rr_stats sb;
    rr_frame_get_stats(b, &sb);
    CHECK(sb.setups > 0 && 2 * sb.setups < setups, "%s: S %llu at 16 positions, %llu in 16 one-position frames",
          rr_method_name(methods3d[i]), (unsigned long long)sb.setups, (unsigned long long)setups);
    CHECK(sb.edge_evals > evals / 4, "%s: E %llu at 16 positions, %llu in 16 one-position frames",
          rr_method_name(methods3d[i]), (unsigned long long)sb.edge_evals, (unsigned long long)evals);
    printf("%s: S %llu, E %llu at 16 positions; S %llu, E %llu in 16 frames\n", rr_method_name(methods3d[i]),
           (unsigned long long)sb.setups, (unsigned long long)sb.edge_evals, (unsigned long long)setups,
           (unsigned long long)evals);
    rr_frame_release(b);
  }
}

/* rr_tri_setup_at moves a setup to another position with the bits of a setup
 * made there, for every triangle of random planar views. */
static void check_moves(rr_device *dev, const rr_scene *s) {
  int moved = 0;
  for (int v = 0; v < 6; v++) {
    rr_camera rc = test_random_view(s, 0.3f, 3, 0.5f, 30, 100);
    rc.type = v & 1 ? RR_CAMERA_ORTHOGRAPHIC : RR_CAMERA_PERSPECTIVE;
    camera c0, cs;
    if (rr_cam_setup_at(dev, &rc, 40, 30, rg16[v], &c0) != RR_OK) continue;
    for (int k = 0; k < 16; k++) {
      if (rr_cam_setup_at(dev, &rc, 40, 30, rg16[k], &cs) != RR_OK) continue;
      for (uint32_t i = 0; i < s->ntris; i += 1 + s->ntris / 512) {
        tri_setup a, b, m;
        tri_plane pl;
        int fa, fb;
        rr_tri_setup_planes(s, &i, 1, &c0, false, v & 2, &a, &fa, &pl);
        fb = rr_tri_setup(s, i, &cs, false, &b);
        CHECK(fa == fb, "view %d, triangle %u: face %d at one position, %d at another", v, i, fa, fb);
        if (fa == SETUP_CULLED || fb == SETUP_CULLED) continue;
        rr_tri_setup_at(&a, &pl, &cs, &m);
        CHECK(memcmp(&m, &b, sizeof m) == 0, "view %d, triangle %u: the moved setup differs at position %d", v, i, k);
        moved++;
      }
      rr_cam_release(&cs);
    }
    rr_cam_release(&c0);
  }
  CHECK(moved > 1000, "only %d setups moved", moved);
}

/* Watertight at sample level: straight down on plane:66 (tan 45°, 64 pixels) sample
 * x + sx0 lies on world x = x + sx0 - 32, inside the plane's [-33, 33], so the
 * positions (0, 0), (0.5, 0), (0, 0.5) and (0.5, 0.5) fall on the vertices, on the
 * edges along either axis and on the cells' centres, which their diagonals cross.
 * Every claim is counted, as rc's loop and 3dr-bb's bounds over the positions
 * visit: each (pixel, position) exactly once; then the methods render it. */
static void check_watertight(rr_device *dev) {
  rr_scene *plane;
  if (rr_scene_load(dev, "plane:66", &plane) != RR_OK) {
    CHECK(0, "%s", rr_device_message(dev));
    return;
  }
  static const float on[4][2] = {{0.0f, 0.0f}, {0.5f, 0.0f}, {0.0f, 0.5f}, {0.5f, 0.5f}};
  rr_camera rc;
  rr_camera_init(&rc);
  const float eye[3] = {0, 32, 0}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  memcpy(rc.eye, eye, sizeof eye), memcpy(rc.target, target, sizeof target), memcpy(rc.up, up, sizeof up);
  rc.fov_deg = 90;
  enum { N = 64 };
  camera cams[4];
  for (int k = 0; k < 4; k++) CHECK(rr_cam_setup_at(dev, &rc, N, N, on[k], &cams[k]) == RR_OK, "camera");
  CHECK(cams[0].tan_half_h == 1.0f, "tan(45°) rounds to %.9g", cams[0].tan_half_h);
  static uint8_t claims[3][4][N * N];
  memset(claims, 0, sizeof claims);
  int on_edge = 0;
  for (uint32_t i = 0; i < plane->ntris; i++) {
    tri_setup ts;
    tri_plane pl;
    int face;
    rr_tri_setup_planes(plane, &i, 1, &cams[0], false, false, &ts, &face, &pl);
    if (face == SETUP_CULLED) continue;
    tri_bound b = {0, {0, 0, N - 1, N - 1}, {0, 0, 0, 0, 0}};
    /* m = 0: every pixel (rc); 1: the bounds over the positions; 2: each position's
     * own rectangle within them (what the kernel tests) */
    for (int m = 0; m < 3; m++) {
      if (m == 1 && !rr_tri_corner_bounds_at(plane, i, NULL, 1, &cams[0], 4, on, false, &b)) break;
      for (int k = 0; k < 4; k++) {
        tri_setup at;
        rr_tri_setup_at(&ts, &pl, &cams[k], &at);
        int r[4];
        memcpy(r, b.bb, sizeof r);
        if (m == 2 && !tri_pos_rect(&b.pos, b.bb, k, r)) continue;
        for (int y = r[1]; y <= r[3]; y++)
          for (int x = r[0]; x <= r[2]; x++) {
            float sx = (float)x + on[k][0], sy = (float)y + on[k][1], e[3], t, l1, l2;
            tri_edges(&at, sx, sy, e);
            if (!sample_test(&at, e, sx, sy, &t, &l1, &l2)) continue;
            on_edge += m == 0 && (e[0] == 0 || e[1] == 0 || e[2] == 0);
            claims[m][k][y * N + x]++;
          }
      }
    }
  }
  for (int m = 0; m < 3; m++) {
    int holes = 0, doubles = 0;
    for (int k = 0; k < 4; k++)
      for (int p = 0; p < N * N; p++) holes += claims[m][k][p] == 0, doubles += claims[m][k][p] > 1;
    CHECK(holes == 0 && doubles == 0, "plane at sample level (%s): %d holes, %d double claims",
          m == 2 ? "each position's rectangle" : m ? "bounds over the positions" : "every pixel", holes, doubles);
  }
  CHECK(on_edge >= 3 * N * N, "only %d of %d samples fell on an edge or vertex", on_edge, 4 * N * N);
  printf("plane: %d of %d samples decided on an edge or vertex\n", on_edge, 4 * N * N);
  for (int k = 0; k < 4; k++) rr_cam_release(&cams[k]);
  /* the methods: no sample misses the plane, and all agree */
  rr_render_options o = test_pattern(RR_METHOD_RC_BVH, N, N, 2, 4, on);
  rr_frame *ref = test_render_opt(dev, plane, &rc, &o);
  if (ref) {
    CHECK(test_frame_hits(ref) == 4 * N * N, "rc-bvh: %d of %d samples hit the plane", test_frame_hits(ref), 4 * N * N);
    for (int i = 0; i < NMETHODS3D; i++) {
      o.method = methods3d[i];
      rr_frame *f = test_render_opt(dev, plane, &rc, &o);
      if (!f) continue;
      CHECK(test_frame_hits(f) == 4 * N * N && test_frames_differ(ref, f) == 0, "%s on the plane: %d hits, %d differ",
            rr_method_name(methods3d[i]), test_frame_hits(f), test_frames_differ(ref, f));
      rr_frame_release(f);
    }
    rr_frame_release(ref);
  }
  rr_scene_release(plane);
}

int main(void) {
  make_rg16();
  rr_device *dev = rr_device_new();
  rr_scene *s = NULL;
  const char *bunny = test_model("stanford-bunny.obj");
  if (rr_scene_load(dev, bunny && !test_quick() ? bunny : "demo", &s) != RR_OK) {
    CHECK(0, "load: %s", rr_device_message(dev));
    return test_done();
  }
  rr_scene *light = NULL; /* curved views bound triangles coarsely: a lighter scene keeps them quick */
  if (rr_scene_load(dev, "sphere:32", &light) != RR_OK) {
    CHECK(0, "load: %s", rr_device_message(dev));
    return test_done();
  }
  check_moves(dev, s);
  check_watertight(dev);
  CHECK(light->ntris <= RC_MAX_TRIS, "sphere:32 has %u triangles: too many for rc", light->ntris);
  /* the OpenCV cameras with real distortion: Brown–Conrady barrel with tangential terms
   * (k1 k2 p1 p2 k3), and Kannala–Brandt */
  static const float brown[8] = {-0.12f, 0.03f, 0.001f, -0.0015f, -0.004f}, kb[8] = {0.03f, -0.01f, 0.004f, -0.001f};
  const int views = 1;
  for (int type = 0; type < RR_CAMERA_COUNT; type++) {
    bool curved = type >= RR_CAMERA_PARABOLIC;
    int w = curved ? 32 : 48, h = curved ? 24 : 36;
    /* curved views on the light scene only; planar ones on both (rc runs on the light one) */
    for (int sci = curved; sci < 2; sci++)
      for (int v = 0; v <= views; v++) {
        /* v = 0: inside the bounds, looking around; then random views from outside */
        const rr_scene *sc = sci ? light : s;
        rr_camera cam = v == 0 ? test_random_view(sc, 0.2f, 0.2f, 1, 90, 90) : test_random_view(sc, 1.2f, 3, 0.4f, 30, 80);
        cam.type = (rr_camera_type)type;
        if (type == RR_CAMERA_FISHEYE && v == 0) cam.fov_deg = 200;
        if (type == RR_CAMERA_OPENCV) memcpy(cam.dist, brown, sizeof brown);
        if (type == RR_CAMERA_OPENCV_FISHEYE) memcpy(cam.dist, kb, sizeof kb);
        if (type == RR_CAMERA_CUBE) w = 32, h = 24;
        char what[96];
        snprintf(what, sizeof what, "%s, %s, %s view %d", rr_camera_name(type), sci ? "sphere:32" : "mesh",
                 v ? "random" : "inside", v);
        for (int threads = 1; threads <= 2; threads++)
          check_view(dev, sc, &cam, w, h, threads, threads == 1 && v == 1, what);
      }
  }
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, 48, 36, &cam);
  check_stats(dev, s, &cam);
  rr_scene_release(s), rr_scene_release(light);
  rr_device_release(dev);
  return test_done();
}
