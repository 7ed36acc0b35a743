/* rc-bvh and rc-packet traverse the BVH but call the same sample test as rc and
 * 3dr-bb: their visibility buffers (ids, t, λ1, λ2) must be bit-identical, at
 * random views of real meshes (some with the eye inside the bounds), on built-in
 * scenes with shared edges through pixel centres, at full size, on 1, 2 and 8 threads. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

/* Renders a view with the reference and with rc-bvh / rc-packet on 1, 2 and 8
 * threads: the same bits as the reference, and the same S, E and N on each. */
static void check_view(rr_device *dev, const rr_scene *s, const char *name, int v, const rr_camera *cam,
                       rr_method ref_method, int w, int h, int cull) {
  rr_frame *ref = test_render(dev, s, cam, ref_method, 2, w, h, cull);
  if (!ref) return;
  const rr_method ms[2] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET};
  char what[256];
  snprintf(what, sizeof what, "%s view %d (%dx%d, cull %d)", name, v, w, h, cull);
  for (int m = 0; m < 2; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = ms[m], opt.width = w, opt.height = h, opt.cull_backfaces = cull;
    rr_frame *f = test_render_threads(dev, s, cam, &opt, ref, what);
    if (!f) continue;
    CHECK(f->stats.setups <= s->ntris, "S counts distinct setups (%llu > %u)", (unsigned long long)f->stats.setups,
          s->ntris);
    CHECK(f->stats.nodes > 0, "N counted");
    if (m == 0)
      printf("%s: %d hits, S=%llu E=%llu N=%llu\n", what, test_frame_hits(ref), (unsigned long long)f->stats.setups,
             (unsigned long long)f->stats.edge_evals, (unsigned long long)f->stats.nodes);
    rr_frame_release(f);
  }
  rr_frame_release(ref);
}

static void check_scene(rr_device *dev, const char *path, const char *name, int views_rc, int views_bb) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, path, &s) != RR_OK) {
    CHECK(0, "load %s: %s", path, rr_device_message(dev));
    return;
  }
  for (int v = 0; v < views_rc + views_bb; v++) {
    rr_camera cam = test_random_view(s, v % 3 == 0 ? 0.1f : 1.0f, v % 3 == 0 ? 0.9f : 3.0f, 0.3f, 30, 100);
    if (v < views_rc) check_view(dev, s, name, v, &cam, RR_METHOD_RC, 42, 30, v % 2); /* rc-packet: partial packets both ways */
    else check_view(dev, s, name, v, &cam, RR_METHOD_3DR_BB, 200, 150, v % 2);
  }
  rr_scene_release(s);
}

/* The culling bounds themselves: at every sample where a triangle passes the
 * sample test, its t is at least the bound of rr_tri_bounds() and the sample lies in
 * its rectangle; grazing views stress them most. */
static void check_bound(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h, const char *name) {
  camera c;
  if (rr_cam_setup(dev, cam, w, h, &c) != RR_OK) return;
  long checked = 0, broken = 0;
  uint32_t step = s->ntris > 20000 ? s->ntris / 20000 : 1;
  for (uint32_t i = 0; i < s->ntris; i += step) {
    tri_setup ts;
    if (rr_tri_setup(s, i, &c, false, &ts) == SETUP_CULLED) continue;
    float rect[4], lo = rr_tri_bounds(&ts, &c, rect);
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        float e[3], t, l1, l2;
        tri_edges(&ts, (float)x + 0.5f, (float)y + 0.5f, e);
        if (!sample_test(&ts, e, (float)x + 0.5f, (float)y + 0.5f, &t, &l1, &l2)) continue;
        checked++;
        float sx = (float)x + 0.5f, sy = (float)y + 0.5f;
        bool in = rect[0] <= sx && sx <= rect[2] && rect[1] <= sy && sy <= rect[3];
        if (!in && broken++ < 5) fprintf(stderr, "%s: triangle %u passes at (%d, %d) outside its rectangle\n", name, i, x, y);
        if (t < lo && broken++ < 5) fprintf(stderr, "%s: triangle %u at (%d, %d): t %.9g below its bound %.9g\n", name, i, x, y, t, lo);
      }
  }
  printf("%s: %ld hits at or above the pruning bound\n", name, checked);
  CHECK(broken == 0, "%s: %ld of %ld hits below the pruning bound", name, broken, checked);
  rr_cam_release(&c);
}

static void bound_views(rr_device *dev) {
  const char *scenes[] = {"plane:16", "sphere:24", "box:4"};
  for (int k = 0; k < 3; k++) {
    rr_scene *s;
    if (rr_scene_load(dev, scenes[k], &s) != RR_OK) continue;
    for (int v = 0; v < 6; v++) {
      rr_camera cam;
      rr_camera_init(&cam);
      /* Eyes just above (or in) the plane y = 0 and random views. */
      float hgt = v < 3 ? (v == 0 ? 1e-6f : v == 1 ? 1e-3f : 0.05f) : test_randf(-3, 3);
      cam.eye[0] = test_randf(-9, 9), cam.eye[1] = hgt, cam.eye[2] = test_randf(-9, 9);
      cam.target[0] = test_randf(-2, 2), cam.target[1] = 0, cam.target[2] = test_randf(-2, 2);
      cam.fov_deg = test_randf(30, 100);
      char name[64];
      snprintf(name, sizeof name, "%s bound view %d", scenes[k], v);
      check_bound(dev, s, &cam, 64, 48, name);
      check_view(dev, s, name, v, &cam, RR_METHOD_3DR_BB, 64, 48, 0);
    }
    rr_scene_release(s);
  }
  const char *p = test_model("stanford-bunny.obj");
  rr_scene *s;
  if (p && rr_scene_load(dev, p, &s) == RR_OK) {
    for (int v = 0; v < 3; v++) {
      rr_camera cam = test_random_view(s, v == 0 ? 0.2f : 1.0f, v == 0 ? 0.8f : 2.0f, 0.3f, 30, 100);
      check_bound(dev, s, &cam, 64, 48, "bunny bound");
    }
    rr_scene_release(s);
  }
}

/* A view that sees a few cells of a plane: the frame sets up only the triangles
 * its samples reach, however large the plane (S per frame grows with the view,
 * not with N), with the same bits as 3dr-bb. */
static void small_part(rr_device *dev) {
  unsigned long long S[2] = {0, 0};
  uint32_t N[2] = {0, 0};
  const char *scenes[2] = {"plane:64", "plane:512"};
  for (int k = 0; k < 2; k++) {
    rr_scene *s;
    if (rr_scene_load(dev, scenes[k], &s) != RR_OK) {
      CHECK(0, "load %s: %s", scenes[k], rr_device_message(dev));
      continue;
    }
    rr_camera cam;
    rr_camera_init(&cam);
    /* straight down: the eye's plane is parallel to the plane (a tilted view's
     * eye plane would cut a line of far cells, whose corners project nowhere and
     * which are set up to be bounded by their polygons: S would grow as √N) */
    cam.eye[0] = 0.3f, cam.eye[1] = 3, cam.eye[2] = 0.2f;
    cam.target[0] = 0.3f, cam.target[1] = 0, cam.target[2] = 0.2f;
    cam.up[0] = 0, cam.up[1] = 0, cam.up[2] = 1;
    cam.fov_deg = 40;
    check_view(dev, s, scenes[k], 0, &cam, RR_METHOD_3DR_BB, 64, 48, 0);
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = RR_METHOD_RC_BVH, opt.width = 64, opt.height = 48;
    rr_frame *f = test_render_opt(dev, s, &cam, &opt);
    if (f) S[k] = f->stats.setups, N[k] = s->ntris, rr_frame_release(f);
    rr_scene_release(s);
  }
  printf("small part of a plane: S = %llu of %u triangles, %llu of %u\n", S[0], N[0], S[1], N[1]);
  CHECK(S[1] > 0 && S[1] * 1000 < N[1], "S = %llu of %u triangles for a view of a few cells", S[1], N[1]);
  CHECK(S[1] <= S[0] + S[0] / 10, "S grows with the scene (%llu -> %llu) for the same view", S[0], S[1]);
}

/* Adds an n×n grid of cells (two triangles each) over the parallelogram o + u·a + v·b,
 * u, v in [0, 1]. */
static void add_sheet(rr_scene *s, int n, const float o[3], const float a[3], const float b[3]) {
  size_t nv = (size_t)(n + 1) * (n + 1);
  float *p = malloc(nv * 3 * sizeof *p);
  uint32_t *idx = malloc((size_t)n * n * 6 * sizeof *idx);
  if (!p || !idx) {
    CHECK(0, "out of memory");
    free(p), free(idx);
    return;
  }
  for (int j = 0; j <= n; j++)
    for (int i = 0; i <= n; i++)
      for (int k = 0; k < 3; k++) p[3 * (j * (n + 1) + i) + k] = o[k] + a[k] * (float)i / (float)n + b[k] * (float)j / (float)n;
  size_t t = 0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      uint32_t v = (uint32_t)(j * (n + 1) + i), r = (uint32_t)(n + 1);
      uint32_t q[6] = {v, v + 1, v + r, v + 1, v + r + 1, v + r};
      memcpy(idx + 6 * t++, q, sizeof q);
    }
  CHECK(rr_scene_add_mesh(s, p, nv, idx, t, NULL) == RR_OK, "add a sheet");
  free(p), free(idx);
}

/* Pruning at grazing angles: a wall of many small cells (more triangles than
 * samples, so perspective frames walk down to the boxes that may hold a sample)
 * with sheets just in front of and behind it, tilted by a few thousandths, seen
 * nearly edge-on so that many hits lie within rounding of each other in depth:
 * a box pruned or a floor set too high anywhere shows as a sample that differs
 * from rc's. */
static void grazing_sheets(rr_device *dev) {
  rr_scene *s = NULL;
  if (rr_scene_new(dev, &s) != RR_OK) {
    CHECK(0, "rr_scene_new: %s", rr_device_message(dev));
    return;
  }
  const float o[3] = {-1, 0, 0}, a[3] = {2, 0, 0}, b[3] = {0, 1, 0};
  add_sheet(s, 40, o, a, b); /* the wall, z = 0 */
  const float o1[3] = {-1, 0, 1e-4f}, b1[3] = {0, 1, -3e-3f}; /* crossing it, in front then behind */
  add_sheet(s, 32, o1, a, b1);
  const float o2[3] = {-1, 0.01f, -2e-5f}, a2[3] = {2, 0, 4e-5f}; /* just behind, tilted along x */
  add_sheet(s, 24, o2, a2, b);
  if (rr_scene_commit(s) != RR_OK) {
    CHECK(0, "commit: %s", rr_device_message(dev));
    rr_scene_release(s);
    return;
  }
  for (int v = 0; v < (test_quick() ? 4 : 8); v++) {
    rr_camera cam;
    rr_camera_init(&cam);
    /* eyes just beyond the wall's edge, a little in front of or behind its plane,
     * looking along it at a point of it */
    float h = v < 2 ? 0.01f : test_randf(0.02f, 0.3f), side = v % 2 ? 1.0f : -1.0f;
    cam.eye[0] = side * test_randf(1.05f, 1.5f), cam.eye[1] = test_randf(0.2f, 0.8f), cam.eye[2] = v % 3 ? h : -h;
    cam.target[0] = side * test_randf(-0.5f, 0.5f), cam.target[1] = test_randf(0.3f, 0.7f), cam.target[2] = 0;
    cam.fov_deg = test_randf(15, 60);
    check_view(dev, s, "grazing sheets", v, &cam, RR_METHOD_RC, 48, 32, v % 2);
  }
  rr_scene_release(s);
}

/* A device keeps its renders' large work buffers (rr_scratch_take): a frame drawn
 * on kept buffers, grown from a smaller scene's, filled with garbage beforehand, or
 * taken meanwhile (a fresh buffer then) has the bits of one drawn by a new device. */
static void kept_buffers(void) {
  rr_device *d = rr_device_new(), *fresh = rr_device_new();
  rr_scene *small = NULL, *big = NULL;
  if (!d || !fresh || rr_scene_load(d, "sphere:24", &small) || rr_scene_load(d, "plane:64", &big)) {
    CHECK(0, "kept buffers: set-up failed");
    rr_scene_release(small), rr_scene_release(big), rr_device_release(d), rr_device_release(fresh);
    return;
  }
  const rr_method ms[3] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB};
  const int uses[3] = {SCRATCH_RC_SETUPS, SCRATCH_RC_SETUPS, SCRATCH_SM_PRIMS};
  for (int m = 0; m < 3; m++) {
    rr_scene *seq[3] = {small, big, big};
    rr_camera cams[2] = {test_random_view(small, 1.0f, 2.0f, 0.3f, 30, 100),
                         test_random_view(big, 1.0f, 2.0f, 0.3f, 30, 100)};
    for (int k = 0; k < 4; k++) {
      rr_scene *s = seq[k < 3 ? k : 2];
      const rr_camera *cam = &cams[s == big];
      rr_frame *want = test_render(fresh, s, cam, ms[m], 2, 64, 48, 0);
      rr_scratch_free(fresh);
      rr_scratch *kept = &d->scratch[uses[m]];
      void *before = kept->p;
      size_t cap = kept->cap;
      if (kept->p) memset(kept->p, 0xA5, kept->cap);
      rr_buf taken = {0};
      if (k == 3) taken = rr_scratch_take(d, uses[m], 1); /* the render's take gets a fresh buffer */
      rr_frame *f = test_render(d, s, cam, ms[m], 2, 64, 48, 0);
      if (want && f)
        CHECK(!test_frames_differ(want, f), "%s on kept buffers, frame %d: other bits", rr_method_name(ms[m]), k);
      CHECK(kept->p, "%s, frame %d: the device keeps its buffer", rr_method_name(ms[m]), k);
      if (k >= 2) CHECK(kept->p == before && kept->cap == cap, "%s, frame %d: the same scene again reallocated",
                        rr_method_name(ms[m]), k);
      rr_scratch_give(d, taken);
      rr_frame_release(want), rr_frame_release(f);
    }
  }
  rr_scene_release(small), rr_scene_release(big), rr_device_release(d), rr_device_release(fresh);
}

int main(void) {
  rr_device *dev = rr_device_new();
  kept_buffers();
  bound_views(dev);
  small_part(dev);
  grazing_sheets(dev);
  int q = test_quick(); /* the sanitizer run: fewer views and meshes, the same paths */
  check_scene(dev, "demo", "demo", 3, 3);
  check_scene(dev, "sphere:24", "sphere:24", 3, 3);
  check_scene(dev, "plane:64", "plane:64", 2, 4);
  check_scene(dev, "box:8", "box:8", 2, 4);
  const char *meshes[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj"};
  for (int m = 0; m < (q ? 1 : 3); m++) {
    const char *p = test_model(meshes[m]);
    if (p) check_scene(dev, p, meshes[m], q ? 1 : 2, q ? 3 : 8);
  }
  /* The teapot has needles (slivers at its poles) whose footprints reach far: they
   * take the loose pass, which must merge bit-exactly too. */
  const char *teapot = test_model("teapot.obj");
  rr_scene *tp = NULL;
  if (teapot && rr_scene_load(dev, teapot, &tp) == RR_OK) {
    for (int v = 0; v < (q ? 1 : 3); v++) {
      rr_camera cam = test_random_view(tp, 1.0f, 2.0f, 0.3f, 30, 100);
      check_view(dev, tp, "teapot", v, &cam, RR_METHOD_3DR_BB, 512, 384, v % 2);
    }
    rr_scene_release(tp);
  }
  /* Full size against 3dr-bb on the bunny: the framed view and one from inside. */
  const char *bunny = test_model("stanford-bunny.obj");
  rr_scene *s = NULL;
  if (bunny && rr_scene_load(dev, bunny, &s) == RR_OK) {
    rr_camera cam;
    rr_camera_init(&cam);
    cam.fov_deg = 50;
    rr_camera_frame(dev, s, 1024, 1024, &cam);
    check_view(dev, s, "bunny framed", 0, &cam, RR_METHOD_3DR_BB, 1024, 1024, 0);
    cam = test_random_view(s, 0.2f, 0.5f, 0.3f, 30, 100);
    if (!q) check_view(dev, s, "bunny inside", 1, &cam, RR_METHOD_3DR_BB, 1024, 1024, 1);
    rr_scene_release(s);
  }
  rr_device_release(dev);
  return test_done();
}
