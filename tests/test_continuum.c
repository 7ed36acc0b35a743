/* The continuum: every method is one traversal order of the same (sample,
 * triangle) tests, so every method gives a visibility buffer bit-identical to rc's,
 * on built-in scenes and real meshes at random views (from inside too). Also: the
 * oracles are conservative, statistics are deterministic and add up per pixel. */
#include "rr.h"
#include "testutil.h"

#include <string.h>

static const rr_method all3d[] = {RR_METHOD_RC_BVH,  RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                  RR_METHOD_3DR_FC,  RR_METHOD_3DR_FS,    RR_METHOD_3DR_FULL};

static int scalar; /* nonzero: render without SIMD kernels */

static rr_frame *render(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int threads, int w,
                        int h, int cull, const char *oracles, int heat) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.scalar = scalar;
  opt.method = m, opt.width = w, opt.height = h, opt.threads = threads, opt.cull_backfaces = cull;
  opt.oracles = oracles, opt.heat = heat;
  rr_frame *f = NULL;
  rr_error e = rr_render(dev, s, cam, &opt, &f);
  if (e == RR_ERROR_UNSUPPORTED) return NULL; /* a method this build lacks: reported by its own test */
  CHECK(e == RR_OK, "render %s: %s", rr_method_name(m), rr_device_message(dev));
  return f;
}

static void random_view(const rr_scene *s, rr_camera *cam, bool inside) {
  rr_camera_init(cam);
  vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
  float r = 0.5f * v3_len(v3_sub(s->bmax, s->bmin));
  vec3 dir = v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)));
  vec3 eye = v3_add(c, v3_scale(dir, r * (inside ? test_randf(0.05f, 0.6f) : test_randf(1.2f, 3))));
  vec3 target = v3_add(c, v3_scale(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)), 0.4f * r));
  memcpy(cam->eye, &eye, 12), memcpy(cam->target, &target, 12);
  cam->fov_deg = test_randf(30, 110);
}

static int methods_seen[RR_METHOD_COUNT];

static void check_scene(rr_device *dev, const char *name, int views, int w, int h) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    return;
  }
  for (int v = 0; v < views; v++) {
    rr_camera cam;
    random_view(s, &cam, v % 2 == 0);
    int cull = v % 3 == 2, threads = 1 + v % 2;
    rr_frame *ref = render(dev, s, &cam, RR_METHOD_RC, 2, w, h, cull, NULL, 0);
    if (!ref) continue;
    for (size_t m = 0; m < sizeof all3d / sizeof all3d[0]; m++) {
      rr_frame *f = render(dev, s, &cam, all3d[m], threads, w, h, cull, NULL, 0);
      if (!f) continue;
      methods_seen[all3d[m]]++;
      int d = test_frames_differ(ref, f);
      CHECK(d == 0, "%s view %d (%s, %d threads): %s differs from rc at %d samples", name, v,
            v % 2 == 0 ? "inside" : "outside", threads, rr_method_name(all3d[m]), d);
      rr_frame_release(f);
    }
    /* auto picks one of the methods, says why, and so gives the same picture */
    rr_frame *fa = render(dev, s, &cam, RR_METHOD_AUTO, threads, w, h, cull, NULL, 0);
    if (fa) {
      CHECK(fa->stats.method >= 0 && fa->stats.method < RR_METHOD_COUNT && fa->stats.why[0], "auto chose %d (%s)",
            fa->stats.method, fa->stats.why);
      CHECK(test_frames_differ(ref, fa) == 0, "%s view %d: auto (%s) differs from rc", name, v, rr_method_name(fa->stats.method));
      rr_frame_release(fa);
    }
    /* the scalar kernels give the same bits as the SIMD ones */
    scalar = 1;
    for (int k = 0; k < 2; k++) {
      rr_frame *f = render(dev, s, &cam, k ? RR_METHOD_3DR_FULL : RR_METHOD_3DR_BB, threads, w, h, cull, NULL, 0);
      if (!f) continue;
      int d = test_frames_differ(ref, f);
      CHECK(d == 0, "%s view %d: scalar %s differs from rc at %d samples", name, v, k ? "3dr-full" : "3dr-bb", d);
      rr_frame_release(f);
    }
    scalar = 0;
    /* points between the named methods */
    const char *mixes[] = {"frustum=1,leaves=1,outside=1", "frustum=32,leaves=1,outside=1,occluded=1,binning=1",
                           "leaves=1,split=16,split-ratio=2,binning=1,bin=16,bin-min=1", "binning=1,early-z=0,bin=8"};
    for (int k = 0; k < 4; k++) {
      rr_frame *f = render(dev, s, &cam, RR_METHOD_3DR_BB, threads, w, h, cull, mixes[k], 0);
      if (!f) continue;
      int d = test_frames_differ(ref, f);
      CHECK(d == 0, "%s view %d: oracles %s differ from rc at %d samples", name, v, mixes[k], d);
      rr_frame_release(f);
    }
    rr_frame_release(ref);
  }
  rr_scene_release(s);
}

/* isOutside never culls a box that a sample ray of the frustum meets. */
static void check_outside_oracle(rr_device *dev) {
  int culled = 0, kept = 0;
  for (int iter = 0; iter < 3000; iter++) {
    rr_camera rc;
    rr_camera_init(&rc);
    vec3 eye = v3(test_randf(-2, 2), test_randf(-2, 2), test_randf(-2, 2));
    memcpy(rc.eye, &eye, 12);
    rc.target[0] = test_randf(-1, 1), rc.target[1] = test_randf(-1, 1), rc.target[2] = test_randf(-1, 1);
    rc.fov_deg = test_randf(20, 120);
    camera c;
    if (camera_setup(dev, &rc, 48, 32, &c) != RR_OK) continue;
    int x0 = test_rand() % 40, y0 = test_rand() % 28;
    int x1 = x0 + 1 + test_rand() % (48 - x0), y1 = y0 + 1 + test_rand() % (32 - y0);
    if (iter % 5 == 0) x1 = x0 + 1, y1 = y0 + 1;
    bvh_node b;
    for (int a = 0; a < 3; a++) {
      float m = test_randf(-2.5f, 2.5f), e = test_randf(0.001f, 0.8f);
      b.lo[a] = m - e, b.hi[a] = m + e;
    }
    bool hit = false;
    for (int y = y0; y < y1 && !hit; y++)
      for (int x = x0; x < x1 && !hit; x++) {
        vec3 d = camera_dir(&c, x + 0.5f, y + 0.5f);
        double t0 = 0, t1 = 1e30;
        const double o[3] = {c.eye.x, c.eye.y, c.eye.z}, dd[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; a++) {
          double ta = (b.lo[a] - o[a]) / dd[a], tb = (b.hi[a] - o[a]) / dd[a];
          t0 = fmax(t0, fmin(ta, tb)), t1 = fmin(t1, fmax(ta, tb));
        }
        hit = t0 <= t1;
      }
    bool out = oracle_outside(&c, x0, y0, x1, y1, &b);
    CHECK(!(hit && out), "iter %d: a box met by a sample ray of [%d,%d)x[%d,%d) was culled", iter, x0, x1, y0, y1);
    culled += out, kept += !out;
  }
  printf("isOutside: %d boxes culled, %d kept\n", culled, kept);
  CHECK(culled > 500 && kept > 300, "the oracle test needs both outcomes: %d culled, %d kept", culled, kept);
}

/* isOccluded never culls a node holding a triangle visible in the frustum. */
static void check_occluded_oracle(rr_device *dev, const char *name) {
  rr_scene *s;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s", name);
    return;
  }
  if (!s->bvh) {
    CHECK(0, "%s has no BVH", name);
    rr_scene_release(s);
    return;
  }
  uint32_t *leaf_of = malloc(sizeof(uint32_t) * s->ntris);
  for (uint32_t n = 0; n < s->bvh->nnodes; n++)
    if (s->bvh->nodes[n].count)
      for (uint32_t k = 0; k < s->bvh->nodes[n].count; k++) leaf_of[s->bvh->prims[s->bvh->nodes[n].first + k]] = n;
  int tested = 0, culled = 0;
  for (int v = 0; v < 4; v++) {
    rr_camera cam;
    random_view(s, &cam, v % 2 == 0);
    rr_frame *f = render(dev, s, &cam, RR_METHOD_RC_BVH, 2, 96, 72, 0, NULL, 0);
    if (!f) f = render(dev, s, &cam, RR_METHOD_3DR_BB, 2, 96, 72, 0, NULL, 0);
    camera c;
    camera_setup(dev, &cam, 96, 72, &c);
    for (int y0 = 0; y0 < 72; y0 += 8)
      for (int x0 = 0; x0 < 96; x0 += 8) {
        float far = 0;
        for (int y = y0; y < y0 + 8; y++)
          for (int x = x0; x < x0 + 8; x++) far = fmaxf(far, f->vb.t[y * 96 + x]);
        for (int y = y0; y < y0 + 8; y++)
          for (int x = x0; x < x0 + 8; x++) {
            uint32_t id = f->vb.id[y * 96 + x];
            if (id == RR_MISS) continue;
            tested++;
            bool occ = oracle_occluded(&c, &s->bvh->nodes[leaf_of[id]], far);
            CHECK(!occ, "%s: the leaf of visible triangle %u was culled as occluded", name, id);
          }
        /* and it does cull: a box well behind everything in the tile */
        bvh_node behind = s->bvh->nodes[0];
        vec3 shift = v3_scale(c.fwd, 3 * far + 10 * v3_len(v3_sub(s->bmax, s->bmin)));
        for (int a = 0; a < 3; a++) behind.lo[a] += v3_get(shift, a), behind.hi[a] += v3_get(shift, a);
        culled += isfinite(far) && oracle_occluded(&c, &behind, far);
      }
    rr_frame_release(f);
  }
  printf("isOccluded: %d visible leaves kept, %d hidden boxes culled\n", tested, culled);
  CHECK(tested > 100 && culled > 0, "too few cases: %d, %d", tested, culled);
  free(leaf_of);
  rr_scene_release(s);
}

/* Stats are deterministic per thread count, zero where they must be, and the
 * per-pixel charges add up to the totals. */
static void check_stats(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "demo", &s) != RR_OK) return;
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, 160, 120, &cam);
  for (size_t m = 0; m < sizeof all3d / sizeof all3d[0]; m++) {
    rr_method method = all3d[m];
    rr_frame *a = render(dev, s, &cam, method, 2, 160, 120, 1, NULL, 1);
    rr_frame *b = render(dev, s, &cam, method, 2, 160, 120, 1, NULL, 1);
    if (!a || !b) {
      rr_frame_release(a), rr_frame_release(b);
      continue;
    }
    const char *name = rr_method_name(method);
    CHECK(a->stats.setups == b->stats.setups && a->stats.edge_evals == b->stats.edge_evals &&
              a->stats.nodes == b->stats.nodes,
          "%s: stats differ between two runs", name);
    CHECK(a->stats.setups > 0 && a->stats.edge_evals > 0, "%s: S and E are positive", name);
    bool bvh_method = method != RR_METHOD_3DR_BB && method != RR_METHOD_3DR_BIN;
    CHECK((a->stats.nodes > 0) == bvh_method, "%s: N = %llu", name, (unsigned long long)a->stats.nodes);
    double se = 0, sn = 0;
    for (int k = 0; k < 160 * 120; k++) se += a->heat_e[k], sn += a->heat_n[k];
    CHECK(fabs(se - a->stats.edge_evals) <= 1e-3 * a->stats.edge_evals + 1,
          "%s: per-pixel E adds to %.0f, total %llu", name, se, (unsigned long long)a->stats.edge_evals);
    CHECK(fabs(sn - a->stats.nodes) <= 1e-3 * a->stats.nodes + 1, "%s: per-pixel N adds to %.0f, total %llu", name,
          sn, (unsigned long long)a->stats.nodes);
    rr_frame_release(a), rr_frame_release(b);
  }
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  check_outside_oracle(dev);
  check_stats(dev);
  check_occluded_oracle(dev, "demo");
  int q = test_quick();
  check_scene(dev, "demo", q ? 2 : 4, 80, 60);
  check_scene(dev, "rooms:3", q ? 2 : 4, 80, 60);
  check_scene(dev, "sphere:24", 2, 64, 48);
  const char *meshes[] = {"suzanne.obj", "spot.obj", "cow.obj", "stanford-bunny.obj", "ogre.obj", "nefertiti.obj"};
  for (int m = 0; m < (q ? 2 : 6); m++) {
    const char *p = test_model(meshes[m]);
    if (p) check_scene(dev, p, 3, 64, 48);
  }
  for (size_t m = 0; m < sizeof all3d / sizeof all3d[0]; m++)
    printf("%s compared on %d views\n", rr_method_name(all3d[m]), methods_seen[all3d[m]]);
  rr_device_release(dev);
  return test_done();
}
