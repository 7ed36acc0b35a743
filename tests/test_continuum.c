/* The continuum: every method is one traversal order of the same (sample,
 * triangle) tests, so every 3D method (and auto) gives a visibility buffer
 * bit-identical to rc's, on built-in scenes and real meshes at random views (from
 * inside too), on 1, 2 and 8 threads with the same S, E and N on each; the 2D
 * methods give their own on any number of threads. Also: the oracles are
 * conservative, statistics are deterministic and add up per pixel. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

static const rr_method all3d[] = {RR_METHOD_RC_BVH,  RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                  RR_METHOD_3DR_FC,  RR_METHOD_3DR_FS,    RR_METHOD_3DR_FULL};

static int methods_seen[RR_METHOD_COUNT];
static int views_done; /* picks the thread count of the scalar and oracle renders */

/* A random view from inside the scene's bounds or from outside. */
static rr_camera random_view(const rr_scene *s, bool inside) {
  return test_random_view(s, inside ? 0.05f : 1.2f, inside ? 0.6f : 3, 0.4f, 30, 110);
}

/* One view, on 1, 2 and 8 threads: every 3D method and auto against ref, and
 * the 2D methods against 2dr-bb on one thread. */
static void check_methods(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *base,
                          const rr_frame *ref, const char *what) {
  rr_render_options opt = *base;
  for (size_t m = 0; m < sizeof all3d / sizeof all3d[0]; m++) {
    opt.method = all3d[m];
    rr_frame *f = test_render_threads(dev, s, cam, &opt, ref, what);
    methods_seen[all3d[m]] += f != NULL;
    rr_frame_release(f);
  }
  /* auto picks one of the methods, says why, and so gives the same picture */
  opt.method = RR_METHOD_AUTO;
  rr_frame *fa = test_render_threads(dev, s, cam, &opt, ref, what);
  if (fa) {
    CHECK(fa->stats.method >= 0 && fa->stats.method < RR_METHOD_COUNT && fa->stats.why[0], "auto chose %d (%s)",
          fa->stats.method, fa->stats.why);
    rr_frame_release(fa);
  }
  /* the 2D pipeline snaps its vertices, so it is not rc's picture, but it is its
   * own on any number of threads, and 2dr-bin's is 2dr-bb's */
  opt.method = RR_METHOD_2DR_BB;
  rr_frame *bb = test_render_threads(dev, s, cam, &opt, NULL, what);
  if (bb) {
    methods_seen[RR_METHOD_2DR_BB]++;
    opt.method = RR_METHOD_2DR_BIN;
    rr_frame *bin = test_render_threads(dev, s, cam, &opt, bb, what);
    methods_seen[RR_METHOD_2DR_BIN] += bin != NULL;
    rr_frame_release(bin), rr_frame_release(bb);
  }
}

/* Views of a scene at w×h: every method against rc (check_methods); the scalar
 * kernels and mixes of oracles on one of the thread counts, in turn. Then views of
 * 384×288, large enough for several tiles, blocks of rows and bands on several
 * threads (rc-bvh's tiles, 3dr's four 256-sample tiles and five 64-row blocks,
 * 2dr's bands), where rc-bvh on one thread stands in for rc (rc would take
 * seconds; rc-bvh equals it on the small views). */
static void check_scene(rr_device *dev, const char *name, int views, int w, int h) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s: %s", name, rr_device_message(dev));
    return;
  }
  rr_render_options opt;
  rr_render_options_init(&opt);
  char what[256];
  for (int v = 0; v < views; v++) {
    bool inside = v % 2 == 0;
    rr_camera cam = random_view(s, inside);
    int cull = v % 3 == 2, threads = test_threads[views_done++ % TEST_NTHREADS];
    rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC, 2, w, h, cull);
    if (!ref) continue;
    snprintf(what, sizeof what, "%s view %d (%s, cull %d)", name, v, inside ? "inside" : "outside", cull);
    opt.width = w, opt.height = h, opt.cull_backfaces = cull;
    check_methods(dev, s, &cam, &opt, ref, what);
    /* the scalar kernels give the same bits as the SIMD ones */
    rr_render_options o = opt;
    o.threads = threads, o.scalar = 1;
    for (int k = 0; k < 2; k++) {
      o.method = k ? RR_METHOD_3DR_FULL : RR_METHOD_3DR_BB;
      rr_frame *f = test_render_opt(dev, s, &cam, &o);
      if (!f) continue;
      int d = test_frames_differ(ref, f);
      CHECK(d == 0, "%s: scalar %s on %d threads differs from rc at %d samples", what, rr_method_name(o.method),
            threads, d);
      rr_frame_release(f);
    }
    /* points between the named methods */
    const char *mixes[] = {"frustum=1,leaves=1,outside=1", "frustum=32,leaves=1,outside=1,occluded=1,binning=1",
                           "leaves=1,split=16,split-ratio=2,binning=1,bin=16,bin-min=1", "binning=1,early-z=0,bin=8"};
    o.scalar = 0, o.method = RR_METHOD_3DR_BB;
    for (int k = 0; k < 4; k++) {
      o.oracles = mixes[k];
      rr_frame *f = test_render_opt(dev, s, &cam, &o);
      if (!f) continue;
      int d = test_frames_differ(ref, f);
      CHECK(d == 0, "%s: oracles %s on %d threads differ from rc at %d samples", what, mixes[k], threads, d);
      rr_frame_release(f);
    }
    rr_frame_release(ref);
  }
  for (int v = 0; v < (test_quick() ? 1 : 2); v++) {
    rr_camera cam = random_view(s, v == 1);
    opt.width = 384, opt.height = 288, opt.cull_backfaces = v;
    rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC_BVH, 1, opt.width, opt.height, opt.cull_backfaces);
    if (!ref) continue;
    snprintf(what, sizeof what, "%s large view %d (%s, cull %d)", name, v, v == 1 ? "inside" : "outside", v);
    check_methods(dev, s, &cam, &opt, ref, what);
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
    if (rr_cam_setup(dev, &rc, 48, 32, &c) != RR_OK) continue;
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
    bool out = rr_oracle_outside(&c, x0, y0, x1, y1, &b);
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
    rr_camera cam = random_view(s, v % 2 == 0);
    rr_frame *f = test_render(dev, s, &cam, RR_METHOD_RC_BVH, 2, 96, 72, 0);
    if (!f) f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, 96, 72, 0);
    camera c;
    rr_cam_setup(dev, &cam, 96, 72, &c);
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
            bool occ = rr_oracle_occluded(&c, &s->bvh->nodes[leaf_of[id]], far);
            CHECK(!occ, "%s: the leaf of visible triangle %u was culled as occluded", name, id);
          }
        /* and it does cull: a box well behind everything in the tile */
        bvh_node behind = s->bvh->nodes[0];
        vec3 shift = v3_scale(c.fwd, 3 * far + 10 * v3_len(v3_sub(s->bmax, s->bmin)));
        for (int a = 0; a < 3; a++) behind.lo[a] += v3_get(shift, a), behind.hi[a] += v3_get(shift, a);
        culled += isfinite(far) && rr_oracle_occluded(&c, &behind, far);
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
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.width = 160, opt.height = 120, opt.threads = 2, opt.cull_backfaces = 1, opt.heat = 1;
  for (size_t m = 0; m < sizeof all3d / sizeof all3d[0]; m++) {
    rr_method method = opt.method = all3d[m];
    rr_frame *a = test_render_opt(dev, s, &cam, &opt);
    rr_frame *b = test_render_opt(dev, s, &cam, &opt);
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
  for (int m = RR_METHOD_RC_BVH; m < RR_METHOD_COUNT; m++)
    printf("%s compared on %d views\n", rr_method_name(m), methods_seen[m]);
  rr_device_release(dev);
  return test_done();
}
