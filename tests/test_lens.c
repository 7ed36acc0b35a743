/* OpenCV's lens models inverted: every pixel's ray projects back onto the pixel
 * (OpenCV's forward formulas, rr_lens_project) within 1e-6 px, for mild, strong
 * and fisheye distortions, pixels beyond the fold having no ray; the ray
 * derivatives match central differences; the defaults (fx = fy = 0) give the
 * perspective camera's rays; rr_camera_set_extrinsics recovers OpenCV's pose;
 * every 3D method renders strongly distorted views (folding inside the image) bit
 * for bit as rc does; the cones of frusta and bins hold their rays and stay tight,
 * so the traversal's work does not grow with the distortion; bad intrinsics and
 * poses are refused. */
#include "camera/camera.h"
#include "camera/lens.h"
#include "testutil.h"

#include <string.h>

static rr_camera lens_camera(rr_camera_type type, float fx, float fy, float cx, float cy, const float *k, int n) {
  rr_camera c;
  rr_camera_init(&c);
  c.type = type, c.fx = fx, c.fy = fy, c.cx = cx, c.cy = cy;
  for (int i = 0; i < n; i++) c.dist[i] = k[i];
  return c;
}

/* Round trips over a grid of image points; returns the pixels with a ray. */
static int round_trip(const rr_camera *c, int W, int H, const char *what) {
  double fold = rr_lens_fold(c), worst = 0, worst_d = 0;
  int rays = 0;
  for (int y = 0; y < H; y += 3)
    for (int x = 0; x < W; x += 3) {
      double dir[3], dd[2][3], u, v;
      if (!rr_lens_unproject(c, fold, x, y, dir, dd)) continue;
      rays++;
      CHECK(fabs(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2] - 1) < 1e-12, "%s: ray not unit", what);
      if (dir[2] <= 1e-9) continue; /* behind the camera: OpenCV's projection does not reach it */
      CHECK(rr_lens_project(c, dir, &u, &v), "%s: ray (%d,%d) not in front", what, x, y);
      worst = fmax(worst, hypot(u - x, v - y));
      /* derivatives against central differences of the inversion itself */
      for (int j = 0; j < 2; j++) {
        double a[3], b[3], h = 1e-4;
        if (!rr_lens_unproject(c, fold, x + (j == 0 ? h : 0), y + (j == 1 ? h : 0), a, NULL) ||
            !rr_lens_unproject(c, fold, x - (j == 0 ? h : 0), y - (j == 1 ? h : 0), b, NULL))
          continue;
        for (int i = 0; i < 3; i++) {
          double fd = (a[i] - b[i]) / (2 * h);
          worst_d = fmax(worst_d, fabs(fd - dd[j][i]) / (1e-3 + fabs(fd)));
        }
      }
    }
  CHECK(worst < 1e-6, "%s: round trip off by %g px", what, worst);
  CHECK(worst_d < 1e-4, "%s: derivatives off by %g (relative)", what, worst_d);
  printf("%s: %d of %d points with a ray, round trip within %.2g px, derivatives within %.2g\n", what, rays,
         ((W + 2) / 3) * ((H + 2) / 3), worst, worst_d);
  return rays;
}

/* Every 3D method against rc on a lens that folds inside the image: the cells'
 * measured cones must keep the cones of curved binning and culling conservative. */
static void methods_agree(rr_device *dev, const rr_camera *cam, const char *what) {
  static const rr_method methods[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                      RR_METHOD_3DR_FC, RR_METHOD_3DR_FS,    RR_METHOD_3DR_FULL};
  rr_scene *s;
  if (rr_scene_load(dev, "sphere:24", &s) != RR_OK) {
    CHECK(0, "load: %s", rr_device_message(dev));
    return;
  }
  const int W = 80, H = 60;
  rr_frame *ref = test_render(dev, s, cam, RR_METHOD_RC, 1, W, H, 0);
  CHECK(ref && test_frame_hits(ref) > W * H / 8, "%s: the sphere is seen", what);
  for (size_t m = 0; ref && m < sizeof methods / sizeof *methods; m++)
    for (int threads = 1; threads <= 2; threads++) {
      rr_frame *f = test_render(dev, s, cam, methods[m], threads, W, H, 0);
      int diff = f ? test_frames_differ(ref, f) : -1;
      CHECK(diff == 0, "%s: %s on %d threads differs from rc at %d samples", what, rr_method_name(methods[m]),
            threads, diff);
      rr_frame_release(f);
    }
  rr_frame_release(ref);
  rr_scene_release(s);
}

/* The angle between unit a and d (not zero), in double. */
static double angle_between(const double a[3], vec3 d) {
  const double x = d.x, y = d.y, z = d.z, cx = a[1] * z - a[2] * y, cy = a[2] * x - a[0] * z, cz = a[0] * y - a[1] * x;
  return atan2(sqrt(cx * cx + cy * cy + cz * cz), a[0] * x + a[1] * y + a[2] * z);
}

/* rr_cam_rect_cone's largest angle from its axis to a ray of [x0, x1) × [y0, y1),
 * brute force; -1 when the cone is absent (0 or -1: checked against the rays). */
static double cone_slack(const camera *cc, int x0, int y0, int x1, int y1, float *angle, const char *what) {
  vec3 axis = v3(0, 0, 0);
  *angle = 0;
  int k = rr_cam_rect_cone(cc, x0, y0, x1, y1, &axis, angle), rays = 0;
  const double a[3] = {axis.x, axis.y, axis.z};
  double worst = 0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      vec3 d = cc->dirs[(size_t)y * cc->width + x];
      if (d.x == 0 && d.y == 0 && d.z == 0) continue;
      rays++;
      if (k > 0) worst = fmax(worst, angle_between(a, d));
    }
  CHECK(k != 0 && (rays == 0 || k > 0), "%s: rect %d,%d..%d,%d with %d rays has cone %d", what, x0, y0, x1, y1, rays, k);
  CHECK(k <= 0 || worst <= *angle, "%s: rect %d,%d..%d,%d: a ray %g rad from the axis, cone %g", what, x0, y0, x1,
        y1, worst, (double)*angle);
  return k > 0 && rays ? worst : -1;
}

/* The cones of a lens camera's rectangles of samples (frusta, bins): every ray of
 * the rectangle inside (random rectangles, the whole image), a cell's cone its
 * rays' own (the frusta's smallest), and the pixel a frustum at the centre judges
 * sizes by as the lens's there. A cone grown by one Lipschitz constant for the whole
 * image, wide where a strong barrel nears its fold, made every frustum's cone
 * wide and every box look small: 3dr-fs drew whole subtrees into each frustum. */
static void cones_hold(const rr_camera *in, int W, int H, const char *what) {
  rr_device *dev = rr_device_new();
  camera cc;
  if (rr_cam_setup(dev, in, W, H, &cc) != RR_OK) {
    CHECK(0, "%s: setup: %s", what, rr_device_message(dev));
    rr_device_release(dev);
    return;
  }
  float angle;
  double loose = 0;
  for (int y = 0; y < H; y += CAMERA_FINE)
    for (int x = 0; x < W; x += CAMERA_FINE) {
      const int x1 = x + CAMERA_FINE < W ? x + CAMERA_FINE : W, y1 = y + CAMERA_FINE < H ? y + CAMERA_FINE : H;
      double exact = cone_slack(&cc, x, y, x1, y1, &angle, what);
      if (exact >= 0) loose = fmax(loose, angle - exact);
    }
  CHECK(loose < 1e-4, "%s: a cell's cone %g rad wider than its rays'", what, loose);
  cone_slack(&cc, 0, 0, W, H, &angle, what);
  for (int i = 0; i < 400; i++) {
    int w = 1 + (int)(test_rand() % (unsigned)(i % 4 == 0 ? W : 24)), h = 1 + (int)(test_rand() % (unsigned)(i % 4 == 0 ? H : 24));
    w = w < W ? w : W, h = h < H ? h : H;
    int x0 = (int)(test_rand() % (unsigned)(W - w + 1)), y0 = (int)(test_rand() % (unsigned)(H - h + 1));
    cone_slack(&cc, x0, y0, x0 + w, y0 + h, &angle, what);
  }
  /* the pixel angle of the frustum at the principal point against the lens's there, 1/fx */
  const int x0 = (int)in->cx / CAMERA_FINE * CAMERA_FINE, y0 = (int)in->cy / CAMERA_FINE * CAMERA_FINE;
  vec3 axis;
  int k = rr_cam_rect_cone(&cc, x0, y0, x0 + CAMERA_FINE, y0 + CAMERA_FINE, &axis, &angle);
  float px = rr_cam_rect_pixel_angle(&cc, x0, y0, x0 + CAMERA_FINE, y0 + CAMERA_FINE, k, angle);
  CHECK(px < 1.5f / in->fx, "%s: a pixel at the centre judged %g rad, the lens's is %g", what, (double)px,
        1.0 / in->fx);
  printf("%s: cones hold their rays; cells within %.2g rad; centre pixel %.3g rad (lens %.3g)\n", what, loose,
         (double)px, 1.0 / in->fx);
  rr_cam_release(&cc);
  rr_device_release(dev);
}

/* The frustum traversal's work on a strongly distorted view against the same lens
 * undistorted (not timed: E and the bins refined, which wide cones inflate; one
 * thread, so the frusta are the same). */
static void traversal_work(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "demo", &s) != RR_OK) {
    CHECK(0, "load: %s", rr_device_message(dev));
    return;
  }
  const int W = 256, H = 200;
  const float plain[] = {0, 0, 0, 0}, barrel[] = {-0.45f, 0.1f, 0, 0}, folding[] = {-0.5f, 0, 0, 0};
  const float *dists[] = {plain, barrel, folding};
  rr_stats st[3][2];
  for (int d = 0; d < 3; d++)
    for (int m = 0; m < 2; m++) {
      rr_camera c = lens_camera(RR_CAMERA_OPENCV, 150, 150, 127.5f, 99.5f, dists[d], 4);
      CHECK(rr_camera_frame(dev, s, W, H, &c) == RR_OK, "frame: %s", rr_device_message(dev));
      rr_frame *f = test_render(dev, s, &c, m ? RR_METHOD_3DR_BIN : RR_METHOD_3DR_FULL, 1, W, H, 0);
      memset(&st[d][m], 0, sizeof st[d][m]);
      if (f) rr_frame_get_stats(f, &st[d][m]);
      rr_frame_release(f);
    }
  for (int d = 1; d < 3; d++)
    for (int m = 0; m < 2; m++) {
      const rr_stats *a = &st[d][m], *b = &st[0][m];
      const char *name = m ? "3dr-bin" : "3dr-full";
      CHECK(a->edge_evals < 1.25 * b->edge_evals, "k1 %g, %s: E %llu, undistorted %llu", (double)dists[d][0], name,
            (unsigned long long)a->edge_evals, (unsigned long long)b->edge_evals);
      CHECK(a->bins < 1.5 * b->bins, "k1 %g, %s: %llu bins refined, undistorted %llu", (double)dists[d][0], name,
            (unsigned long long)a->bins, (unsigned long long)b->bins);
      printf("k1 %g, %s: E %llu, bins %llu (undistorted %llu, %llu)\n", (double)dists[d][0], name,
             (unsigned long long)a->edge_evals, (unsigned long long)a->bins, (unsigned long long)b->edge_evals,
             (unsigned long long)b->bins);
    }
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  const int W = 320, H = 240, all = ((W + 2) / 3) * ((H + 2) / 3);
  const float mild[] = {-0.12f, 0.03f, 0.001f, -0.0015f, -0.004f};
  const float rational[] = {0.6f, -0.2f, 0.0005f, 0.001f, 0.01f, 0.8f, -0.1f, 0.02f};
  const float strong[] = {-0.45f, 0.05f, 0.002f, 0.001f, 0};   /* folds back inside the image */
  const float fish[] = {0.03f, -0.01f, 0.004f, -0.001f};
  const float fish_strong[] = {-0.3f, 0.02f, 0, 0};             /* θd stops growing before 180° */
  rr_camera c = lens_camera(RR_CAMERA_OPENCV, 280, 275, 161.3f, 118.7f, mild, 5);
  CHECK(round_trip(&c, W, H, "brown-conrady mild") == all, "a mild lens has a ray at every pixel");
  c = lens_camera(RR_CAMERA_OPENCV, 300, 300, 160, 120, rational, 8);
  CHECK(round_trip(&c, W, H, "brown-conrady rational") == all, "the rational lens has a ray at every pixel");
  c = lens_camera(RR_CAMERA_OPENCV, 300, 300, 160, 120, strong, 5);
  int n = round_trip(&c, W, H, "brown-conrady strong");
  CHECK(n > all / 2 && n < all, "a lens folding inside the image has rays inside the fold only (%d of %d)", n, all);
  c = lens_camera(RR_CAMERA_OPENCV_FISHEYE, 90, 92, 158, 121, fish, 4);
  round_trip(&c, W, H, "fisheye");
  c = lens_camera(RR_CAMERA_OPENCV_FISHEYE, 120, 120, 160, 120, fish_strong, 4);
  n = round_trip(&c, W, H, "fisheye strong");
  CHECK(n > all / 4 && n < all, "a fisheye folding inside the image (%d of %d)", n, all);

  /* Views of a sphere through the lenses that fold inside the image (the pose looks at it). */
  float pose_R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, pose_t[3] = {0, 0, 2.2f};
  c = lens_camera(RR_CAMERA_OPENCV, 60, 60, 39.5f, 29.5f, strong, 5);
  rr_camera_set_extrinsics(dev, &c, pose_R, pose_t);
  methods_agree(dev, &c, "brown-conrady strong");
  c = lens_camera(RR_CAMERA_OPENCV_FISHEYE, 45, 45, 39.5f, 29.5f, fish_strong, 4);
  rr_camera_set_extrinsics(dev, &c, pose_R, pose_t);
  methods_agree(dev, &c, "fisheye strong");

  /* The cones of frusta and bins through the strong lenses, and the work they save. */
  const float barrel[] = {-0.45f, 0.1f, 0, 0, 0};
  c = lens_camera(RR_CAMERA_OPENCV, 300, 300, 160, 120, barrel, 5);
  cones_hold(&c, W, H, "brown-conrady barrel");
  c = lens_camera(RR_CAMERA_OPENCV, 300, 300, 160, 120, strong, 5);
  cones_hold(&c, W, H, "brown-conrady strong");
  c = lens_camera(RR_CAMERA_OPENCV_FISHEYE, 120, 120, 160, 120, fish_strong, 4);
  cones_hold(&c, W, H, "fisheye strong");
  c = lens_camera(RR_CAMERA_OPENCV, 280, 275, 161.3f, 118.7f, mild, 5);
  cones_hold(&c, W, H, "brown-conrady mild");
  traversal_work(dev);

  /* No distortion and the perspective intrinsics: the perspective camera's rays. */
  rr_camera persp, cv;
  rr_camera_init(&persp);
  persp.fov_deg = 50;
  cv = persp, cv.type = RR_CAMERA_OPENCV;
  float *o1 = malloc(sizeof(float) * 3 * 64 * 48 * 4), *d1 = o1 + 3 * 64 * 48, *o2 = d1 + 3 * 64 * 48,
        *d2 = o2 + 3 * 64 * 48;
  CHECK(rr_camera_rays(dev, &persp, 64, 48, o1, d1) == RR_OK && rr_camera_rays(dev, &cv, 64, 48, o2, d2) == RR_OK,
        "rays: %s", rr_device_message(dev));
  double worst = 0;
  for (int i = 0; i < 64 * 48 * 3; i++) worst = fmax(worst, fabs(d1[i] - d2[i]));
  CHECK(worst < 1e-6, "opencv with the default intrinsics is the perspective camera (off by %g)", worst);
  free(o1);

  /* OpenCV's pose: R, t (world to camera) to eye/target/up and back. */
  float R[9] = {0.36f, 0.48f, -0.8f, -0.8f, 0.6f, 0, 0.48f, 0.64f, 0.6f}, t[3] = {1, -2, 5};
  CHECK(rr_camera_set_extrinsics(dev, &cv, R, t) == RR_OK, "extrinsics: %s", rr_device_message(dev));
  camera cc;
  CHECK(rr_cam_setup(dev, &cv, 64, 48, &cc) == RR_OK, "setup");
  for (int i = 0; i < 3; i++) {
    CHECK(fabsf(v3_get(cc.right, i) - R[i]) < 1e-6f && fabsf(v3_get(cc.up, i) + R[3 + i]) < 1e-6f &&
              fabsf(v3_get(cc.fwd, i) - R[6 + i]) < 1e-6f, "axis %d of the pose", i);
    double x = 0; /* R·eye + t = 0 */
    for (int k = 0; k < 3; k++) x += (double)R[3 * i + k] * cv.eye[k];
    CHECK(fabs(x + t[i]) < 1e-5, "eye: R·eye + t = %g", x + t[i]);
  }
  rr_cam_release(&cc);
  /* far from the origin the direction keeps float precision */
  const float far_t[3] = {3e4f, -2e4f, 5e4f};
  CHECK(rr_camera_set_extrinsics(dev, &cv, R, far_t) == RR_OK && rr_cam_setup(dev, &cv, 64, 48, &cc) == RR_OK,
        "far extrinsics: %s", rr_device_message(dev));
  for (int i = 0; i < 3; i++)
    CHECK(fabsf(v3_get(cc.fwd, i) - R[6 + i]) < 1e-6f && fabsf(v3_get(cc.right, i) - R[i]) < 1e-6f,
          "axis %d of a pose far from the origin: %g", i, v3_get(cc.fwd, i) - R[6 + i]);
  rr_cam_release(&cc);
  R[0] = 2;
  CHECK(rr_camera_set_extrinsics(dev, &cv, R, t) == RR_ERROR_ARGUMENT && strstr(rr_device_message(dev), "rotation"),
        "a matrix that is not a rotation is refused: %s", rr_device_message(dev));
  c = lens_camera(RR_CAMERA_OPENCV, -3, 300, 160, 120, mild, 5);
  CHECK(rr_camera_check(dev, &c) == RR_ERROR_ARGUMENT && strstr(rr_device_message(dev), "intrinsics"),
        "negative focal length refused: %s", rr_device_message(dev));
  c = lens_camera(RR_CAMERA_OPENCV_FISHEYE, 300, 300, 160, 120, rational, 8);
  CHECK(rr_camera_check(dev, &c) == RR_ERROR_ARGUMENT, "a fisheye with 8 coefficients refused");
  c = lens_camera(RR_CAMERA_OPENCV, 300, 300, 160, 120, mild, 5);
  c.dist[1] = NAN;
  CHECK(rr_camera_check(dev, &c) == RR_ERROR_ARGUMENT, "a NaN coefficient refused");
  rr_device_release(dev);
  return test_done();
}
