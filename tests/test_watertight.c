/* Watertightness: every triangle that claims a sample is counted (not only the
 * nearest). On a tessellated plane and on closed meshes, with views that put many
 * pixel centres exactly on vertices and edges, each sample on the surface must be
 * claimed exactly once, by rc's loop (all samples) and by 3dr-bb's (bounding boxes). */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

typedef struct {
  int holes, doubles, front_ne_back, on_edge;
} tally;

/* Counts claims of front and back faces per sample, visiting as rc (use_bounds
 * false) or 3dr-bb (true) does. */
static void count_claims(const rr_scene *s, const camera *c, bool use_bounds, uint8_t *front, uint8_t *back,
                         int *on_edge) {
  size_t n = (size_t)c->width * c->height;
  memset(front, 0, n), memset(back, 0, n);
  for (uint32_t i = 0; i < s->ntris; i++) {
    tri_setup ts;
    int face = rr_tri_setup(s, i, c, false, &ts);
    if (face == SETUP_CULLED) continue;
    int r[4] = {0, 0, c->width - 1, c->height - 1};
    if (use_bounds && !rr_tri_screen_bounds(s, i, c, &ts, r)) continue;
    for (int y = r[1]; y <= r[3]; y++)
      for (int x = r[0]; x <= r[2]; x++) {
        float e[3], t, l1, l2;
        tri_edges(&ts, x + 0.5f, y + 0.5f, e);
        if (!sample_test(&ts, e, x + 0.5f, y + 0.5f, &t, &l1, &l2)) continue;
        if (e[0] == 0 || e[1] == 0 || e[2] == 0) (*on_edge)++;
        (face == SETUP_FRONT ? front : back)[(size_t)y * c->width + x]++;
      }
  }
}

static camera make_cam(rr_device *dev, vec3 eye, vec3 target, vec3 up, float fov, int w, int h) {
  rr_camera rc = {.type = RR_CAMERA_PERSPECTIVE, .fov_deg = fov};
  memcpy(rc.eye, &eye, 12), memcpy(rc.target, &target, 12), memcpy(rc.up, &up, 12);
  camera c;
  rr_error e = rr_cam_setup(dev, &rc, w, h, &c);
  CHECK(e == RR_OK, "camera: %s", rr_device_message(dev));
  return c;
}

/* mode 0: every sample claimed exactly once in total; mode 1: samples inside the
 * plane (away from its border) exactly once, none twice; mode 2 (closed mesh seen
 * from outside): each ray enters as often as it leaves, never twice. */
static void check_view(const rr_scene *s, const camera *c, int mode, const char *what) {
  size_t n = (size_t)c->width * c->height;
  uint8_t *front = malloc(n), *back = malloc(n);
  for (int m = 0; m < 2; m++) {
    tally t = {0};
    count_claims(s, c, m == 1, front, back, &t.on_edge);
    for (size_t k = 0; k < n; k++) {
      int total = front[k] + back[k];
      if (mode == 0) {
        t.holes += total == 0, t.doubles += total > 1;
      } else if (mode == 1) {
        t.doubles += total > 1;
        /* the ray of sample k in double precision, against the plane y = 0 */
        int x = (int)(k % c->width), y = (int)(k / c->width);
        vec3 d = camera_dir(c, x + 0.5f, y + 0.5f);
        double tt = -(double)c->eye.y / d.y;
        double hx = c->eye.x + tt * d.x, hz = c->eye.z + tt * d.z;
        double half = 0.5 * sqrt((double)s->ntris / 2);
        if (tt > 0 && fabs(hx) < half - 1e-3 && fabs(hz) < half - 1e-3) t.holes += total == 0;
      } else {
        t.doubles += front[k] > 1 || back[k] > 1;
        t.front_ne_back += front[k] != back[k];
      }
    }
    CHECK(t.holes == 0 && t.doubles == 0 && t.front_ne_back == 0,
          "%s (%s): %d holes, %d double claims, %d rays entering and leaving unequally", what, m ? "3dr-bb" : "rc",
          t.holes, t.doubles, t.front_ne_back);
    if (m == 0) printf("%s: %d claims decided on an edge or vertex\n", what, t.on_edge);
  }
  free(front), free(back);
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *plane, *sphere, *box;
  CHECK(rr_scene_load(dev, "plane:64", &plane) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_scene_load(dev, "sphere:48", &sphere) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_scene_load(dev, "box:8", &box) == RR_OK, "%s", rr_device_message(dev));
  if (!plane || !sphere || !box) return test_done();

  /* Straight down on the plane: with tan(45°) = 1 and 64 pixels, pixel centres land
   * exactly on the integer vertices, and all arithmetic is exact. */
  camera c = make_cam(dev, v3(-0.5f, 32, -0.5f), v3(-0.5f, 0, -0.5f), v3(0, 0, -1), 90, 64, 64);
  CHECK(c.tan_half_h == 1.0f, "tan(45°) rounds to %.9g", c.tan_half_h);
  check_view(plane, &c, 0, "plane, pixel centres on vertices");
  int exact_edges = 0;
  {
    uint8_t f[64 * 64], b[64 * 64];
    count_claims(plane, &c, false, f, b, &exact_edges);
  }
  CHECK(exact_edges >= 64 * 64 / 2, "only %d of 4096 samples fell on an edge or vertex", exact_edges);

  /* Same, off-centre by half a cell in one axis: centres on edges, not vertices. */
  c = make_cam(dev, v3(0, 32, -0.5f), v3(0, 0, -0.5f), v3(0, 0, -1), 90, 64, 64);
  check_view(plane, &c, 1, "plane, pixel centres on edges");

  /* Random oblique views of the plane. */
  for (int v = 0; v < 6; v++) {
    vec3 eye = v3(test_randf(-20, 20), test_randf(2, 30), test_randf(-20, 20));
    vec3 target = v3(test_randf(-10, 10), 0, test_randf(-10, 10));
    c = make_cam(dev, eye, target, v3(0, 1, 0), test_randf(30, 100), 96, 72);
    check_view(plane, &c, 1, "plane, random view");
  }

  /* Inside the closed box with the eye offset by 1/64 so that pixel centres hit the
   * 0.25-spaced vertex grid of the far face exactly; then random inside views. */
  c = make_cam(dev, v3(-0.015625f, 0.015625f, 0), v3(-0.015625f, 0.015625f, -1), v3(0, 1, 0), 90, 64, 64);
  check_view(box, &c, 0, "inside box, centres on vertices");
  for (int v = 0; v < 6; v++) {
    const rr_scene *s = v & 1 ? sphere : box;
    vec3 eye = v3(test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f), test_randf(-0.4f, 0.4f));
    vec3 target = v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1));
    c = make_cam(dev, eye, target, v3(test_randf(-1, 1), 1, test_randf(-1, 1)), test_randf(40, 120), 80, 60);
    check_view(s, &c, 0, v & 1 ? "inside sphere" : "inside box");
  }
  /* From outside: every ray that enters also leaves. */
  for (int v = 0; v < 6; v++) {
    const rr_scene *s = v & 1 ? sphere : box;
    vec3 eye = v3_scale(v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1))), test_randf(2, 5));
    c = make_cam(dev, eye, v3(0, 0, 0), v3(0, 1, 0), test_randf(30, 70), 80, 60);
    check_view(s, &c, 2, v & 1 ? "sphere from outside" : "box from outside");
  }
  rr_scene_release(plane), rr_scene_release(sphere), rr_scene_release(box);
  rr_device_release(dev);
  return test_done();
}
