/* The BVH: invariants of the tree (every triangle in exactly one leaf, bounds that
 * enclose, the layout the traversals rely on), the same tree for any thread count,
 * rr_intersect / rr_occluded against brute force with the same sample test (rays
 * from inside, rays parallel to faces, rays through shared vertices), and bad
 * input: empty scenes, degenerate triangles, huge and tiny coordinates; the 4- and
 * 8-wide copies (slots, boxes, the 8-wide leaves and their corners). */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

static bool encloses(const bvh_node *outer, const float lo[3], const float hi[3]) {
  for (int a = 0; a < 3; a++)
    if (!(outer->lo[a] <= lo[a] && hi[a] <= outer->hi[a])) return false;
  return true;
}

/* Checks the tree's invariants; returns false at the first broken one. */
static bool check_tree(const rr_scene *s, const char *name) {
  const rr_bvh *b = s->bvh;
  if (s->ntris == 0) {
    CHECK(b == NULL, "%s: an empty scene has no tree", name);
    return b == NULL;
  }
  CHECK(b != NULL && b->nprims == s->ntris, "%s: a tree over all triangles", name);
  if (!b) return false;
  uint8_t *seen = calloc(s->ntris, 1);
  uint32_t leaves = 0, bad = 0, maxdepth = 0;
  uint32_t *depth = calloc(b->nnodes, sizeof *depth);
  for (uint32_t k = 0; k < b->nnodes && !bad; k++) {
    const bvh_node *n = &b->nodes[k];
    if (n->count) {
      leaves++;
      maxdepth = depth[k] > maxdepth ? depth[k] : maxdepth;
      if (n->count > (uint32_t)b->leaf_size || n->first + n->count > b->nprims) {
        bad = 1;
        CHECK(0, "%s: leaf %u holds %u triangles from %u", name, k, n->count, n->first);
        break;
      }
      for (uint32_t i = n->first; i < n->first + n->count; i++) {
        uint32_t t = b->prims[i];
        if (t >= s->ntris || seen[t]++) {
          bad = 1;
          CHECK(0, "%s: triangle %u in a second leaf (or out of range)", name, t);
          break;
        }
        float lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
          lo[a] = fminf(s->p[0][a][t], fminf(s->p[1][a][t], s->p[2][a][t]));
          hi[a] = fmaxf(s->p[0][a][t], fmaxf(s->p[1][a][t], s->p[2][a][t]));
        }
        if (!encloses(n, lo, hi)) {
          bad = 1;
          CHECK(0, "%s: leaf %u does not enclose triangle %u", name, k, t);
        }
      }
    } else {
      /* Children: a sibling pair at an odd index after the parent (the layout
       * the traversals and the per-frame bounds rely on). */
      if (n->first % 2 != 1 || n->first <= k || n->first + 1 >= b->nnodes) {
        bad = 1;
        CHECK(0, "%s: inner node %u has children at %u", name, k, n->first);
        break;
      }
      for (int c = 0; c < 2; c++) {
        const bvh_node *ch = &b->nodes[n->first + c];
        depth[n->first + c] = depth[k] + 1;
        if (!encloses(n, ch->lo, ch->hi)) {
          bad = 1;
          CHECK(0, "%s: node %u does not enclose its child %u", name, k, n->first + c);
        }
      }
    }
  }
  /* The 4-wide copy: every binary node but the root in exactly one slot, with its
   * bounds and contents. */
  uint32_t *slots = calloc(b->nnodes, sizeof *slots);
  for (uint32_t w = 0; w < b->nwide && !bad; w++)
    for (int i = 0; i < 4; i++) {
      uint32_t k = b->wide_node[4 * w + i];
      const bvh_wide *wn = &b->wide[w];
      if (k == UINT32_MAX) {
        if (wn->ref[i] != UINT32_MAX || wn->lo[0][i] <= wn->hi[0][i]) bad = 1;
        continue;
      }
      const bvh_node *n = &b->nodes[k];
      slots[k]++;
      for (int a = 0; a < 3; a++) bad |= wn->lo[a][i] != n->lo[a] || wn->hi[a][i] != n->hi[a];
      bad |= wn->count[i] != n->count || (n->count && wn->ref[i] != n->first) || (!n->count && wn->ref[i] >= b->nwide);
    }
  uint32_t wrong = 0;
  for (uint32_t k = 0; k < b->nnodes; k++) wrong += slots[k] > 1 || (slots[k] == 0 && b->nodes[k].count);
  CHECK(!bad && wrong == 0, "%s: the 4-wide copy is wrong (%u nodes misplaced)", name, wrong);
  free(slots);
  /* The 8-wide copy of the ray queries: its leaves cover prims once, in order
   * within each, each leaf's box holds its corners, which leaf_v8 holds in its
   * layout; every node is reached once from the root, its slots' boxes inside
   * nothing smaller than the leaves' corners. */
  uint32_t *cover = calloc(b->nprims + 1, sizeof *cover), *reached = calloc(b->nwide8, sizeof *reached);
  uint32_t bad8 = 0;
  reached[0] = 1;
  for (uint32_t w = 0; w < b->nwide8; w++)
    for (int i = 0; i < 8; i++) {
      const bvh_wide8 *wn = &b->wide8[w];
      if (wn->ref[i] == UINT32_MAX) {
        bad8 += wn->lo[0][i] <= wn->hi[0][i] || wn->count[i];
        continue;
      }
      if (!wn->count[i]) {
        bad8 += wn->ref[i] <= w || wn->ref[i] >= b->nwide8;
        if (wn->ref[i] > w && wn->ref[i] < b->nwide8) reached[wn->ref[i]]++;
        continue;
      }
      uint32_t first = wn->ref[i], count = wn->count[i];
      bad8 += first + count > b->nprims;
      for (uint32_t t = 0; t < count && first + t < b->nprims; t++) {
        cover[first + t]++;
        for (int m = 0; m < 9; m++) {
          float c = b->leaf_v8[(size_t)9 * first + (size_t)m * count + t];
          bad8 += c != s->p[m / 3][m % 3][b->prims[first + t]] || c < wn->lo[m % 3][i] || c > wn->hi[m % 3][i];
        }
      }
    }
  for (uint32_t t = 0; t < b->nprims; t++) bad8 += cover[t] != 1;
  for (uint32_t w = 0; w < b->nwide8; w++) bad8 += reached[w] != 1;
  CHECK(bad8 == 0, "%s: the 8-wide copy is wrong (%u faults)", name, bad8);
  bad |= bad8 != 0;
  free(cover), free(reached);
  uint32_t missing = 0;
  for (uint32_t t = 0; t < s->ntris && !bad; t++) missing += !seen[t];
  CHECK(!bad && missing == 0, "%s: %u triangles in no leaf", name, missing);
  CHECK(leaves == b->nleaves && b->nnodes == 2 * leaves - 1, "%s: %u nodes, %u leaves (reported %u)", name,
        b->nnodes, leaves, b->nleaves);
  CHECK(maxdepth == b->depth && b->depth < BVH_STACK, "%s: depth %u (reported %u)", name, maxdepth, b->depth);
  CHECK(isfinite(b->sah_cost) && b->sah_cost >= 0, "%s: SAH cost %g", name, b->sah_cost);
  free(seen), free(depth);
  return !bad && missing == 0;
}

static void commit_with(rr_device *dev, rr_scene *s, int threads, int bins, int leaf) {
  rr_build_options o;
  rr_build_options_init(&o);
  o.threads = threads, o.bins = bins, o.leaf_size = leaf;
  CHECK(rr_device_set_build_options(dev, &o) == RR_OK, "build options: %s", rr_device_message(dev));
  CHECK(rr_scene_commit(s) == RR_OK, "commit: %s", rr_device_message(dev));
}

/* The same tree, byte for byte, whatever the thread count. */
static void check_threads(rr_device *dev, rr_scene *s, const char *name) {
  commit_with(dev, s, 1, 0, 0);
  check_tree(s, name);
  size_t nb = (size_t)s->bvh->nnodes * sizeof(bvh_node), pb = (size_t)s->ntris * 4;
  bvh_node *nodes = malloc(nb);
  uint32_t *prims = malloc(pb);
  memcpy(nodes, s->bvh->nodes, nb), memcpy(prims, s->bvh->prims, pb);
  for (int threads = 2; threads <= 3; threads++) {
    commit_with(dev, s, threads, 0, 0);
    CHECK(s->bvh->nnodes * sizeof(bvh_node) == nb && memcmp(nodes, s->bvh->nodes, nb) == 0 &&
              memcmp(prims, s->bvh->prims, pb) == 0,
          "%s: the tree on %d threads differs from the one on 1", name, threads);
  }
  printf("%s: %u triangles, %u nodes, depth %u, SAH %.2f, build %.1f ms\n", name, s->ntris, s->bvh->nnodes,
         s->bvh->depth, s->bvh->sah_cost, s->bvh->build_ms);
  free(nodes), free(prims);
  /* Other bin counts and leaf sizes build valid trees too. */
  const int opts[][2] = {{2, 1}, {16, 2}, {64, 8}, {32, 64}};
  for (int i = 0; i < 4; i++) {
    commit_with(dev, s, 2, opts[i][0], opts[i][1]);
    char label[128];
    snprintf(label, sizeof label, "%s bins %d leaf %d", name, opts[i][0], opts[i][1]);
    check_tree(s, label);
  }
  rr_device_set_build_options(dev, &(rr_build_options){0});
  rr_scene_commit(s);
}

static rr_scene *random_scene(rr_device *dev, uint32_t n, float spread, float size) {
  rr_scene *s;
  rr_scene_new(dev, &s);
  float *pos = malloc(sizeof(float) * 9 * n);
  uint32_t *idx = malloc(sizeof(uint32_t) * 3 * n);
  for (uint32_t t = 0; t < n; t++) {
    float c[3];
    /* Half spread uniformly, half in a few tight clusters: uneven like real scenes. */
    for (int a = 0; a < 3; a++) c[a] = t % 2 ? test_randf(-spread, spread) : (float)(t % 7) - 3 + test_randf(-0.1f, 0.1f);
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) pos[9 * t + 3 * k + a] = c[a] + test_randf(-size, size);
    for (int k = 0; k < 3; k++) idx[3 * t + k] = 3 * t + k;
  }
  const float rgb[3] = {1, 1, 1};
  CHECK(rr_scene_add_mesh(s, pos, 3 * (size_t)n, idx, n, rgb) == RR_OK, "add mesh: %s", rr_device_message(dev));
  free(pos), free(idx);
  return s;
}

static int rays_checked, rays_hit;

static void check_ray(const rr_scene *s, const rr_ray *ray, const char *name) {
  rr_hit h;
  int occ, any;
  rr_hit ref = test_brute_ray(s, ray, &any);
  CHECK(rr_intersect(s->dev, s, ray, &h) == RR_OK, "%s: rr_intersect failed", name);
  CHECK(rr_occluded(s->dev, s, ray, &occ) == RR_OK, "%s: rr_occluded failed", name);
  bool same = h.prim == ref.prim && memcmp(&h.t, &ref.t, 4) == 0 && memcmp(&h.l1, &ref.l1, 4) == 0 &&
              memcmp(&h.l2, &ref.l2, 4) == 0;
  CHECK(same, "%s: ray (%g %g %g) + t (%g %g %g): rr_intersect %u t=%.9g, brute force %u t=%.9g", name, ray->org[0],
        ray->org[1], ray->org[2], ray->dir[0], ray->dir[1], ray->dir[2], h.prim, h.t, ref.prim, ref.t);
  CHECK(occ == any, "%s: rr_occluded %d, brute force %d", name, occ, any);
  rays_checked++;
  rays_hit += ref.prim != RR_MISS;
}

static void random_rays(const rr_scene *s, const char *name, int n) {
  vec3 lo = s->bmin, hi = s->bmax, ext = v3_sub(hi, lo);
  for (int r = 0; r < n; r++) {
    rr_ray ray;
    /* A third from inside the bounds, the rest from around them. */
    float m = r % 3 == 0 ? 0.0f : 1.0f;
    vec3 o = v3(test_randf(lo.x - m * ext.x, hi.x + m * ext.x), test_randf(lo.y - m * ext.y, hi.y + m * ext.y),
                test_randf(lo.z - m * ext.z, hi.z + m * ext.z));
    vec3 target = v3(test_randf(lo.x, hi.x), test_randf(lo.y, hi.y), test_randf(lo.z, hi.z));
    vec3 d = v3_sub(target, o);
    if (r % 5 == 1) d = v3_norm(d);
    if (r % 7 == 2) d.y = 0; /* parallel to the y planes */
    memcpy(ray.org, &o, 12), memcpy(ray.dir, &d, 12);
    ray.tmin = r % 4 == 3 ? test_randf(0, 0.5f) : 0;
    ray.tmax = r % 6 == 5 ? test_randf(0.2f, 1.5f) : INFINITY;
    if (d.x == 0 && d.y == 0 && d.z == 0) continue;
    check_ray(s, &ray, name);
  }
}

/* The plane:N scene: rays straight down through vertices and edge midpoints must
 * hit exactly one triangle (watertight), and rays in the plane's own plane or
 * parallel to it just above hit nothing, without trouble. */
static void plane_rays(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "plane:8", &s) != RR_OK) {
    CHECK(0, "plane:8: %s", rr_device_message(dev));
    return;
  }
  int holes = 0;
  for (int j = -3; j <= 3; j++)
    for (int i = -3; i <= 3; i++)
      for (int h = 0; h < 3; h++) {
        rr_ray ray = {{(float)i + (h == 1 ? 0.5f : 0), 2, (float)j + (h == 2 ? 0.5f : 0)}, {0, -1, 0}, 0, INFINITY};
        if (h == 0 && (i + j) % 2) ray.dir[0] = 0.25f, ray.org[0] -= 0.5f; /* oblique through the vertex */
        rr_hit hit;
        rr_intersect(dev, s, &ray, &hit);
        holes += hit.prim == RR_MISS;
        check_ray(s, &ray, "plane:8 vertices");
      }
  CHECK(holes == 0, "plane:8: %d rays through shared vertices or edges fell through", holes);
  for (int k = 0; k < 20; k++) {
    float y = k < 10 ? 0.0f : 1e-3f;
    rr_ray ray = {{test_randf(-5, 5), y, test_randf(-5, 5)}, {test_randf(-1, 1), 0, test_randf(-1, 1)}, 0, INFINITY};
    check_ray(s, &ray, "plane:8 grazing");
  }
  rr_scene_release(s);
}

static void bad_input(rr_device *dev) {
  const float rgb[3] = {1, 1, 1};
  /* Empty scene: commit works, rays miss, the ray casters give an empty image. */
  rr_scene *s;
  rr_scene_new(dev, &s);
  CHECK(rr_scene_commit(s) == RR_OK, "empty commit: %s", rr_device_message(dev));
  check_tree(s, "empty");
  rr_ray ray = {{0, 0, 5}, {0, 0, -1}, 0, INFINITY};
  rr_hit hit;
  int occ;
  CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == RR_MISS && isinf(hit.t), "empty scene: a miss");
  CHECK(rr_occluded(dev, s, &ray, &occ) == RR_OK && occ == 0, "empty scene: not occluded");
  rr_camera cam;
  rr_camera_init(&cam);
  for (int m = RR_METHOD_RC_BVH; m <= RR_METHOD_RC_PACKET; m++) {
    rr_render_options opt;
    rr_render_options_init(&opt);
    opt.method = (rr_method)m, opt.width = 33, opt.height = 17;
    rr_frame *f = NULL;
    CHECK(rr_render(dev, s, &cam, &opt, &f) == RR_OK, "empty scene %s: %s", rr_method_name(m), rr_device_message(dev));
    int hits = 0;
    for (int k = 0; f && k < 33 * 17; k++) hits += f->vb.id[k] != RR_MISS;
    CHECK(f && hits == 0, "empty scene %s: %d hits", rr_method_name(m), hits);
    rr_frame_release(f);
  }
  /* Only degenerate triangles: all dropped, still an empty scene. */
  const float deg[] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 0, 0, 0};
  const uint32_t didx[] = {0, 1, 2, 0, 0, 3, 1, 1, 1};
  CHECK(rr_scene_add_mesh(s, deg, 4, didx, 3, rgb) == RR_OK && s->ntris == 0, "degenerate triangles dropped");
  CHECK(rr_scene_commit(s) == RR_OK && s->bvh == NULL, "degenerate-only commit");
  CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == RR_MISS, "degenerate-only scene: a miss");
  /* A scene changed after its commit: a clear message, not a stale tree. */
  const float tri[] = {-1, -1, 0, 1, -1, 0, 0, 1, 0};
  const uint32_t tidx[] = {0, 1, 2};
  rr_scene_add_mesh(s, tri, 3, tidx, 1, rgb);
  CHECK(rr_intersect(dev, s, &ray, &hit) != RR_OK && strstr(rr_device_message(dev), "rr_scene_commit"),
        "uncommitted scene: '%s'", rr_device_message(dev));
  rr_scene_commit(s);
  /* its id counts the three dropped faces before it (the documented convention) */
  CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == 3 && hit.t == 5.0f,
        "one triangle: hit id 3 at t=5 (%u, %g)", hit.prim, hit.t);
  /* Bad rays. */
  rr_ray nan_ray = {{0, 0, NAN}, {0, 0, -1}, 0, INFINITY}, zero = {{0, 0, 5}, {0, 0, 0}, 0, INFINITY};
  CHECK(rr_intersect(dev, s, &nan_ray, &hit) == RR_ERROR_ARGUMENT, "NaN origin refused");
  CHECK(rr_occluded(dev, s, &zero, &occ) == RR_ERROR_ARGUMENT, "zero direction refused");
  CHECK(rr_intersect(dev, s, &ray, NULL) == RR_ERROR_ARGUMENT && rr_intersect(dev, NULL, &ray, &hit) == RR_ERROR_ARGUMENT,
        "NULL arguments refused");
  rr_build_options bad = {.threads = -1};
  CHECK(rr_device_set_build_options(dev, &bad) == RR_ERROR_ARGUMENT, "bad build options refused");
  bad = (rr_build_options){.bins = 1000};
  CHECK(rr_device_set_build_options(dev, &bad) == RR_ERROR_ARGUMENT, "bad bin count refused");
  rr_scene_release(s);

  /* Huge and tiny coordinates, apart and in one scene: builds, rays and renders.
   * Triangles whose area overflows or underflows (vertices at 1e30, or 1e-30
   * apart) are dropped at load; those at 1e18 and 1e-20 are kept. */
  for (int k = 0; k < 3; k++) {
    rr_scene_new(dev, &s);
    float pos[9 * 64];
    uint32_t idx[3 * 64];
    for (int t = 0; t < 64; t++) {
      int kind = t % 8 == 7 ? 3 : k < 2 ? k : t % 3; /* 0 huge, 1 tiny, 2 unit, 3 dropped */
      float sc = kind == 0 ? 1e18f : kind == 1 ? 1e-20f : kind == 2 ? 1.0f : (t % 2 ? 1e30f : 1e-30f);
      for (int v = 0; v < 9; v++) pos[9 * t + v] = sc * (test_randf(-1, 1) + (float)(t % 4));
      for (int v = 0; v < 3; v++) idx[3 * t + v] = 3 * t + v;
    }
    rr_scene_add_mesh(s, pos, 192, idx, 64, rgb);
    char name[64];
    snprintf(name, sizeof name, "coordinates %s", k == 0 ? "1e18 and 1e30" : k == 1 ? "1e-20 and 1e-30" : "mixed");
    CHECK(s->ntris == 56 && s->skipped == 8, "%s: %u kept, %llu dropped", name, s->ntris,
          (unsigned long long)s->skipped);
    CHECK(rr_scene_commit(s) == RR_OK, "%s: commit: %s", name, rr_device_message(dev));
    check_tree(s, name);
    random_rays(s, name, 100);
    rr_camera_init(&cam);
    if (rr_camera_frame(dev, s, 48, 32, &cam) == RR_OK && rr_camera_check(dev, &cam) == RR_OK) {
      rr_frame *ref = NULL, *f = NULL;
      rr_render_options opt;
      rr_render_options_init(&opt);
      opt.width = 48, opt.height = 32, opt.method = RR_METHOD_RC;
      rr_error e1 = rr_render(dev, s, &cam, &opt, &ref);
      for (int m = RR_METHOD_RC_BVH; m <= RR_METHOD_RC_PACKET && !e1; m++) {
        opt.method = (rr_method)m;
        rr_error e2 = rr_render(dev, s, &cam, &opt, &f);
        CHECK(e2 == RR_OK, "%s: %s: %s", name, rr_method_name(m), rr_device_message(dev));
        if (!e2)
          CHECK(memcmp(ref->vb.id, f->vb.id, 48 * 32 * 4) == 0 && memcmp(ref->vb.t, f->vb.t, 48 * 32 * 4) == 0,
                "%s: %s differs from rc", name, rr_method_name(m));
        rr_frame_release(f), f = NULL;
      }
      if (e1) printf("%s: rc refuses the view: %s\n", name, rr_device_message(dev));
      rr_frame_release(ref);
    } else {
      printf("%s: no camera: %s\n", name, rr_device_message(dev));
    }
    rr_scene_release(s);
  }
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s = random_scene(dev, 2000, 4, 0.3f);
  check_threads(dev, s, "random 2k");
  random_rays(s, "random 2k", 2000);
  rr_scene_release(s);
  int q = test_quick(); /* the sanitizer run: fewer rays, the same paths */
  s = random_scene(dev, 90000, 10, 0.2f); /* big enough for the chunked parallel paths */
  check_threads(dev, s, "random 90k");
  random_rays(s, "random 90k", q ? 50 : 300);
  rr_scene_release(s);
  plane_rays(dev);
  const char *reals[] = {"stanford-bunny.obj", "teapot.obj"};
  for (int m = 0; m < 2; m++) {
    const char *p = test_model(reals[m]);
    if (!p || rr_scene_load(dev, p, &s) != RR_OK) continue;
    check_threads(dev, s, reals[m]);
    random_rays(s, reals[m], q ? 100 : m == 0 ? 300 : 1500);
    rr_scene_release(s);
  }
  if (rr_scene_load(dev, "sphere:32", &s) == RR_OK) {
    random_rays(s, "sphere:32", 2000);
    rr_scene_release(s);
  }
  if (rr_scene_load(dev, "box:4", &s) == RR_OK) {
    random_rays(s, "box:4", 2000);
    rr_scene_release(s);
  }
  bad_input(dev);
  printf("%d rays against brute force, %d hit\n", rays_checked, rays_hit);
  rr_device_release(dev);
  return test_done();
}
