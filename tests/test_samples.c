/* Sample positions are data: a pattern of N positions inside the pixel gives N
 * layers of the visibility buffer, and every method and camera takes the
 * positions as they are. The 3D methods and ray casters stay bit-identical at any
 * position (the OpenCV cameras with distortion); a layer is the frame of one
 * sample at that position; positions mean
 * what they say (a 2x2 grid in W×H is the centre of 2W×2H); the 2D pipeline, which
 * snaps positions to 1/256 pixel like its vertices, agrees with them. */
#include "testutil.h"

#include <string.h>

/* Rotated-grid positions, none at the centre. */
static const float rgss[4][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};

/* Every exact method against rc-bvh over all layers, and each layer against a
 * one-sample frame at its position. */
static void check_methods(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h, const char *what) {
  bool planar = cam->type == RR_CAMERA_PERSPECTIVE || cam->type == RR_CAMERA_ORTHOGRAPHIC;
  rr_render_options o = test_pattern(RR_METHOD_RC_BVH, w, h, 2, 4, rgss);
  rr_frame *ref = test_render_opt(dev, s, cam, &o);
  if (!ref) return;
  CHECK(ref->samples == 4, "%s: %d layers", what, ref->samples);
  CHECK(test_frame_hits(ref) > 0, "%s: the view hits nothing", what);
  /* rc, the slow reference, is held to rc-bvh by test_equivalence */
  const rr_method ms[] = {RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                          RR_METHOD_3DR_FC, RR_METHOD_3DR_FS, RR_METHOD_3DR_FULL};
  for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) {
    if (ms[i] == RR_METHOD_RC_PACKET && !planar) continue;
    o.method = ms[i];
    rr_frame *f = test_render_opt(dev, s, cam, &o);
    if (!f) continue;
    int d = test_frames_differ(ref, f);
    CHECK(d == 0, "%s: %s differs from rc-bvh in %d of %d samples", what, rr_method_name(ms[i]), d, 4 * w * h);
    rr_frame_release(f);
  }
  test_check_layers(dev, s, cam, &o, RR_METHOD_3DR_BIN, ref, what);
  rr_frame_release(ref);
}

/* A 2x2 grid of W×H samples is the centre grid of 2W×2H: the same rays up to
 * rounding of the directions, so nearly every id agrees. */
static void check_positions(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h) {
  const float grid[4][2] = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}, {0.75f, 0.75f}};
  rr_render_options o = test_pattern(RR_METHOD_3DR_BB, w, h, 2, 4, grid);
  rr_frame *a = test_render_opt(dev, s, cam, &o);
  rr_render_options big = test_pattern(RR_METHOD_3DR_BB, 2 * w, 2 * h, 2, 1, grid);
  big.sample_pos[0][0] = big.sample_pos[0][1] = 0.5f;
  rr_frame *b = test_render_opt(dev, s, cam, &big);
  rr_render_options mid = test_pattern(RR_METHOD_3DR_BB, w, h, 2, 1, grid);
  mid.sample_pos[0][0] = mid.sample_pos[0][1] = 0.5f;
  rr_frame *c = test_render_opt(dev, s, cam, &mid);
  if (a && b && c) {
    int agree = 0, moved = 0, n = 4 * w * h;
    for (int k = 0; k < 4; k++)
      for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
          uint32_t id = a->vb.id[((size_t)y * w + x) * 4 + k];
          agree += id == b->vb.id[(size_t)(2 * y + k / 2) * 2 * w + 2 * x + k % 2];
          moved += id != c->vb.id[(size_t)y * w + x];
        }
    CHECK(agree >= n * 99 / 100, "2x2 grid vs centres of the doubled image: %d of %d ids agree", agree, n);
    CHECK(moved > 0, "the grid's samples see the same ids as the centre everywhere: positions unused?");
    printf("2x2 grid: %d of %d ids as in the doubled image; %d differ from the centre\n", agree, n, moved);
  }
  rr_frame_release(a), rr_frame_release(b), rr_frame_release(c);
}

/* A 4x4 grid rotated by atan(1/4), all positions in [0, 1), none at the centre; its
 * projections on both axes are 16 distinct sixteenths. */
static void rotated_grid16(float pos[16][2]) {
  for (int k = 0; k < 16; k++) {
    int i = k % 4, j = k / 4;
    pos[k][0] = (float)(4 * i + j) / 16 + 1.0f / 32, pos[k][1] = (float)(4 * j + 3 - i) / 16 + 1.0f / 32;
  }
}

/* The 2D pipeline at the same positions agrees with 3D rasterization on ids, and
 * each of its layers (all positions drawn in one pass) is its frame of one sample
 * at that position, bit for bit. */
static void check_2d_pattern(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h, int n,
                             const float (*pos)[2]) {
  rr_render_options o = test_pattern(RR_METHOD_3DR_BB, w, h, 2, n, pos);
  rr_frame *a = test_render_opt(dev, s, cam, &o);
  for (int m = 0; m < 2; m++) {
    o.method = m ? RR_METHOD_2DR_BIN : RR_METHOD_2DR_BB;
    rr_frame *b = test_render_opt(dev, s, cam, &o);
    if (a && b) {
      int all = n * w * h, agree = 0;
      for (int k = 0; k < all; k++) agree += a->vb.id[k] == b->vb.id[k];
      CHECK(agree >= all * 995 / 1000, "%s agrees with 3dr-bb on %d of %d ids at %d positions", rr_method_name(o.method),
            agree, all, n);
    }
    if (b) test_check_layers(dev, s, cam, &o, o.method, b, rr_method_name(o.method));
    rr_frame_release(b);
  }
  rr_frame_release(a);
}

static void check_2d(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h) {
  check_2d_pattern(dev, s, cam, w, h, 4, rgss);
  float grid16[16][2];
  rotated_grid16(grid16);
  check_2d_pattern(dev, s, cam, w, h, 16, grid16);
}

static void check_bad(rr_device *dev, const rr_scene *s, const rr_camera *cam) {
  rr_render_options o = test_pattern(RR_METHOD_3DR_BB, 8, 8, 2, 4, rgss);
  const float bad[][2] = {{1.0f, 0.5f}, {-0.1f, 0.5f}, {0.5f, NAN}, {0.5f, INFINITY}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    rr_render_options b = o;
    b.sample_pos[3][0] = bad[i][0], b.sample_pos[3][1] = bad[i][1];
    rr_frame *f = (rr_frame *)1;
    CHECK(rr_render(dev, s, cam, &b, &f) == RR_ERROR_ARGUMENT && f == NULL, "position (%g, %g) accepted",
          (double)bad[i][0], (double)bad[i][1]);
  }
  const int counts[] = {0, -1, RR_MAX_SAMPLES + 1};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    rr_render_options b = o;
    b.samples = counts[i];
    rr_frame *f = (rr_frame *)1;
    CHECK(rr_render(dev, s, cam, &b, &f) == RR_ERROR_ARGUMENT && f == NULL, "%d samples accepted", counts[i]);
  }
  rr_render_options d;
  rr_render_options_init(&d);
  CHECK(d.samples == 1 && d.sample_pos[0][0] == 0.5f && d.sample_pos[0][1] == 0.5f, "default: one centre sample");
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s = NULL;
  const char *bunny = test_model("stanford-bunny.obj");
  if (rr_scene_load(dev, bunny && !test_quick() ? bunny : "demo", &s) != RR_OK) {
    CHECK(0, "load: %s", rr_device_message(dev));
    return test_done();
  }
  for (int type = 0; type < RR_CAMERA_COUNT; type++) {
    rr_camera cam;
    rr_camera_init(&cam);
    rr_camera_frame(dev, s, 64, 48, &cam);
    cam.type = (rr_camera_type)type;
    if (type >= RR_CAMERA_PARABOLIC) { /* from inside, looking around */
      float c[3];
      for (int a = 0; a < 3; a++) c[a] = 0.5f * (v3_get(s->bmin, a) + v3_get(s->bmax, a));
      memcpy(cam.eye, c, sizeof c);
      cam.target[0] = c[0] + 1, cam.target[1] = c[1], cam.target[2] = c[2];
      cam.fov_deg = type >= RR_CAMERA_OPENCV ? 120 : 200; /* the OpenCV cameras are pinholes */
    }
    /* the OpenCV cameras with real distortion: Brown–Conrady with its rational terms
     * (k1 k2 p1 p2 k3 k4 k5 k6), and Kannala–Brandt */
    static const float brown[8] = {-0.25f, 0.06f, 0.0015f, -0.001f, -0.005f, 0.02f, 0.001f, 0},
                       kb[8] = {-0.05f, 0.01f, -0.002f, 0.0005f};
    if (type == RR_CAMERA_OPENCV) memcpy(cam.dist, brown, sizeof brown);
    if (type == RR_CAMERA_OPENCV_FISHEYE) memcpy(cam.dist, kb, sizeof kb);
    bool curved = type >= RR_CAMERA_PARABOLIC; /* exact but slow: smaller images */
    check_methods(dev, s, &cam, curved ? 32 : 64, curved ? 24 : 48, rr_camera_name(type));
  }
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, 96, 72, &cam);
  check_positions(dev, s, &cam, 96, 72);
  check_2d(dev, s, &cam, 96, 72);
  check_bad(dev, s, &cam);
  rr_scene_release(s);
  rr_device_release(dev);
  return test_done();
}
