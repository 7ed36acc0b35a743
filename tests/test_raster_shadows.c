/* Shadows by rasterization from the light (vis/shadow_raster.c) against shadow
 * rays: the same occlusion bit as rr_occluded for every ray of a light, on random
 * lights (outside the scene, inside its bounds, inside a closed mesh, exactly on a
 * surface) and target points (surface points seen from random views, inside views
 * too, and rays through vertices and edges, where the tie rule decides), on 1, 2
 * and 8 threads; lit images with point and spot lights the same bits with
 * --shadows rays, raster and auto; an empty scene. The same on a scene mixing
 * triangles with analytic spheres, boxes and infinite planes (prim/analytic.h),
 * lights inside spheres and boxes too, where some rays are occluded only by an
 * analytic primitive; and on that scene with a mesh drawn as instances. */
#include "prim/analytic.h"
#include "vis/shadow_raster.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

static rr_device *dev;
static uint32_t rng = 0x2545F491u;

static float frand(void) { /* [0, 1) */
  rng ^= rng << 13, rng ^= rng >> 17, rng ^= rng << 5;
  return (float)(rng >> 8) / 16777216.0f;
}

static rr_scene *load(const char *name) {
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, name, &s) == RR_OK, "%s: %s", name, rr_device_message(dev));
  return s;
}

static vec3 corner(const rr_scene *s, int k, uint32_t i) { return scene_vertex(s, k, i); }

/* The scene's bounds, widened by a tenth of their diagonal (a plane's have no
 * height): a point at (fx, fy, fz) of them. */
static vec3 in_bounds(const rr_scene *s, float fx, float fy, float fz) {
  vec3 e = v3_sub(s->bmax, s->bmin);
  float pad = 0.1f * v3_len(e);
  vec3 lo = v3_sub(s->bmin, v3(pad, pad, pad));
  e = v3_add(e, v3(2 * pad, 2 * pad, 2 * pad));
  return v3(lo.x + fx * e.x, lo.y + fy * e.y, lo.z + fz * e.z);
}

/* Target points: surface points seen by random rays from `eye` (their hit points,
 * pulled towards the light by a little, as shading's offset does, or exact),
 * triangles' corners and edge midpoints (rays through vertices and edges), and
 * points beyond corners (rays that graze a vertex on their way). */
static size_t targets(const rr_scene *s, vec3 eye, vec3 light, vec3 *out, size_t n) {
  size_t m = 0;
  for (size_t k = 0; k < n; k++) {
    float kind = frand();
    uint32_t i = (uint32_t)(frand() * (float)s->ntris) % s->ntris;
    vec3 p;
    if (kind < 0.6f) {
      vec3 d = v3(frand() - 0.5f, frand() - 0.5f, frand() - 0.5f);
      rr_ray r = {{eye.x, eye.y, eye.z}, {d.x, d.y, d.z}, 0, INFINITY};
      rr_hit h;
      if (rr_intersect(dev, s, &r, &h) != RR_OK || h.prim == RR_MISS) continue;
      p = v3_add(eye, v3_scale(d, h.t));
      if (kind < 0.45f) p = v3_add(p, v3_scale(v3_sub(light, p), 1e-4f));
    } else if (kind < 0.75f) {
      p = corner(s, (int)(frand() * 3) % 3, i);
    } else if (kind < 0.9f) {
      p = v3_scale(v3_add(corner(s, 0, i), corner(s, 1, i)), 0.5f);
    } else {
      p = v3_add(light, v3_scale(v3_sub(corner(s, 2, i), light), 1.5f));
    }
    out[m++] = p;
  }
  return m;
}

/* The shadow rays of every point towards a light, through rr_occluded_raster on 1, 2
 * and 8 threads against rr_occluded ray by ray. A point light (light not NULL): rays
 * from the light to the points; a directional one: rays from every point along
 * `towards`, unbounded (parallel rays: an orthographic camera). Adds the occluded and
 * lit counts to seen[0..1], and to seen[2] the occluded rays whose nearest hit is an
 * analytic primitive; and on that scene with a mesh drawn as instances. */
static void check_rays(const rr_scene *s, const vec3 *light, vec3 towards, const vec3 *pts, size_t n,
                       const char *what, size_t seen[3]) {
  rr_ray *rays = malloc(n * sizeof *rays);
  int *ref = malloc(n * sizeof *ref), *got = malloc(n * sizeof *got);
  if (!rays || !ref || !got) {
    CHECK(0, "out of memory");
    free(rays), free(ref), free(got);
    return;
  }
  for (size_t k = 0; k < n; k++) {
    if (light) {
      vec3 d = v3_sub(pts[k], *light);
      rays[k] = (rr_ray){{light->x, light->y, light->z}, {d.x, d.y, d.z}, 0, 1};
    } else {
      rays[k] = (rr_ray){{pts[k].x, pts[k].y, pts[k].z}, {towards.x, towards.y, towards.z}, 0, INFINITY};
    }
    ref[k] = 0;
    rr_occluded(NULL, s, &rays[k], &ref[k]);
    seen[ref[k] != 0]++;
    rr_hit h;
    if (ref[k] && s->kind && rr_intersect(NULL, s, &rays[k], &h) == RR_OK && h.prim != RR_MISS &&
        scene_kind(s, h.prim) != RR_GEOMETRY_TRIANGLE)
      seen[2]++;
  }
  bool empty;
  const rr_bvh *b = rr_bvh_of(dev, s, &empty);
  for (int ti = 0; ti < TEST_NTHREADS; ti++) {
    rr_shadow_counts c;
    bool ok = rr_occluded_raster(s, b, rays, n, test_threads[ti], got, &c);
    size_t diff = 0, first = 0;
    for (size_t k = 0; k < n; k++)
      if ((got[k] != 0) != (ref[k] != 0)) first = diff++ ? first : k;
    CHECK(ok && diff == 0, "%s, %d threads: %zu of %zu %srays differ from rr_occluded (first: ray %zu, raster %d)",
          what, test_threads[ti], diff, n, light ? "" : "parallel ", first, got[first]);
    CHECK(!light || empty || c.bins > 0, "%s: no bins", what);
  }
  free(rays), free(ref), free(got);
}

/* Random lights and targets in scene s. */
static void check_lights(const rr_scene *s, const char *name, int lights, size_t npts) {
  vec3 *pts = malloc(npts * sizeof *pts);
  size_t seen[3] = {0, 0, 0}, seen_dir[3] = {0, 0, 0};
  char what[160];
  for (int l = 0; l < lights && pts; l++) {
    vec3 light, eye;
    const char *where;
    int kind = l % 4;
    if (kind == 0) { /* outside, above */
      light = in_bounds(s, frand() * 3 - 1, 1.5f + frand(), frand() * 3 - 1), where = "outside";
    } else if (kind == 1) { /* inside the bounds */
      light = in_bounds(s, frand(), frand(), frand()), where = "inside the bounds";
    } else if (kind == 2) { /* exactly on a corner of a triangle */
      light = corner(s, 0, (uint32_t)(frand() * (float)s->ntris) % s->ntris), where = "on a vertex";
    } else { /* on a triangle (within its plane's rounding) */
      uint32_t i = (uint32_t)(frand() * (float)s->ntris) % s->ntris;
      vec3 p0 = corner(s, 0, i);
      light = v3_add(p0, v3_add(v3_scale(v3_sub(corner(s, 1, i), p0), 0.25f), v3_scale(v3_sub(corner(s, 2, i), p0), 0.5f)));
      where = "on a surface";
    }
    /* targets seen from an eye inside or outside the bounds */
    eye = l % 2 ? in_bounds(s, 0.3f + 0.4f * frand(), 0.3f + 0.4f * frand(), 0.3f + 0.4f * frand())
                : in_bounds(s, frand() * 3 - 1, frand() * 3 - 1, frand() * 3 - 1);
    size_t n = targets(s, eye, light, pts, npts);
    snprintf(what, sizeof what, "%s, light %d %s (%g, %g, %g)", name, l, where, light.x, light.y, light.z);
    check_rays(s, &light, light, pts, n, what, seen);
    /* the same points under a directional light from where the point light was (an
     * axis now and then: zero components) */
    vec3 towards = l % 3 == 0 ? v3(0, 1, 0) : v3_sub(light, v3_scale(v3_add(s->bmin, s->bmax), 0.5f));
    if (l % 5 == 4) towards = v3(frand() - 0.5f, 0, frand() - 0.5f);
    snprintf(what, sizeof what, "%s, directional light %d towards (%g, %g, %g)", name, l, towards.x, towards.y,
             towards.z);
    check_rays(s, NULL, towards, pts, n, what, seen_dir);
  }
  CHECK(seen[0] > 0 && seen[1] > 0, "%s: %zu lit and %zu occluded rays: the test sees only one kind", name, seen[0],
        seen[1]);
  CHECK(seen_dir[0] > 0 && seen_dir[1] > 0, "%s: %zu lit and %zu occluded parallel rays: only one kind", name,
        seen_dir[0], seen_dir[1]);
  CHECK(!s->kind || (seen[2] > 0 && seen_dir[2] > 0),
        "%s: %zu point and %zu parallel rays occluded first by an analytic primitive: the test misses them", name,
        seen[2], seen_dir[2]);
  free(pts);
}

static void check_scene(const char *name, int lights, size_t npts) {
  rr_scene *s = load(name);
  if (!s) return;
  check_lights(s, name, lights, npts);
  rr_scene_release(s);
}

/* Random triangles, spheres (some crossing the ground), boxes (half of them turned),
 * a ground plane y = 0 and an oblique plane off to the side, ids interleaving kinds. */
/* Triangles, spheres, boxes and planes; with `instances`, the last mesh is drawn
 * as four instances (translated, rotated and scaled, sheared: the two-level BVH). */
static rr_scene *mixed_scene(int ntri, int nsph, bool instances) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "%s", rr_device_message(dev));
  float *pos = malloc(sizeof(float) * 9 * (size_t)ntri), *sp = malloc(sizeof(float) * 4 * (size_t)nsph);
  uint32_t *idx = malloc(sizeof(uint32_t) * 3 * (size_t)ntri);
  if (!s || !pos || !sp || !idx) {
    CHECK(0, "out of memory");
    free(pos), free(sp), free(idx);
    if (s) rr_scene_release(s);
    return NULL;
  }
  for (int t = 0; t < ntri; t++) {
    float cx = test_randf(-4, 4), cy = test_randf(0, 3), cz = test_randf(-4, 4), sz = test_randf(0.3f, 1.5f);
    for (int k = 0; k < 9; k++) pos[9 * t + k] = (k % 3 == 0 ? cx : k % 3 == 1 ? cy : cz) + sz * test_randf(-1, 1);
    for (int k = 0; k < 3; k++) idx[3 * t + k] = (uint32_t)(3 * t + k);
  }
  CHECK(rr_scene_add_mesh(s, pos, (size_t)3 * ntri, idx, (size_t)ntri, NULL) == RR_OK, "%s", rr_device_message(dev));
  for (int k = 0; k < nsph; k++)
    sp[4 * k] = test_randf(-4, 4), sp[4 * k + 1] = test_randf(-0.5f, 3), sp[4 * k + 2] = test_randf(-4, 4),
            sp[4 * k + 3] = test_randf(0.2f, 1.2f);
  CHECK(rr_scene_add_spheres(s, sp, (size_t)nsph, NULL) == RR_OK, "%s", rr_device_message(dev));
  float bx[12 * 8];
  for (int k = 0; k < 8; k++) {
    float *b = bx + 12 * k;
    b[0] = test_randf(-4, 4), b[1] = test_randf(0, 2.5f), b[2] = test_randf(-4, 4);
    for (int c = 3; c < 6; c++) b[c] = test_randf(0.3f, 1.2f);
    for (int c = 0; c < 6; c++) b[6 + c] = k % 2 ? test_randf(-1, 1) : (c == 0 || c == 4);
  }
  CHECK(rr_scene_add_boxes(s, bx, 8, NULL) == RR_OK, "%s", rr_device_message(dev));
  const float planes[12] = {0, 0, 0, 0, 1, 0, 0, 0, -9, 0.3f, 0.2f, 1};
  CHECK(rr_scene_add_planes(s, planes, 2, NULL) == RR_OK, "%s", rr_device_message(dev));
  for (int k = 0; k < 9 * ntri; k++) pos[k] *= 0.5f; /* more triangles after the analytic geometries */
  const float xf[4][12] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0},
                           {0.6f, 0, 0.9f, 2.5f, 0, 1.1f, 0, 0.5f, -0.9f, 0, 0.6f, -1},
                           {1, 0.25f, 0, -3, 0, 0.9f, -0.2f, 1, 0, 0, 1, 2},
                           {1, 0, 0, 0.75f, 0, 1, 0, 0.125f, 0, 0, 1, -3.5f}};
  if (instances)
    CHECK(rr_scene_add_instances(s, pos, (size_t)3 * ntri, idx, (size_t)ntri, NULL, &xf[0][0], 4) == RR_OK, "%s",
          rr_device_message(dev));
  else
    CHECK(rr_scene_add_mesh(s, pos, (size_t)3 * ntri, idx, (size_t)ntri, NULL) == RR_OK, "%s", rr_device_message(dev));
  free(pos), free(sp), free(idx);
  CHECK(rr_scene_commit(s) == RR_OK, "%s", rr_device_message(dev));
  return s;
}

/* Point lights at the centres of spheres and boxes (inside them: every ray that
 * leaves is occluded by its own primitive, unless its target is inside too) and a
 * directional light on points inside them, against rr_occluded. */
static void check_inside_ana(const rr_scene *s, size_t npts) {
  vec3 *pts = malloc(npts * sizeof *pts);
  size_t seen[3] = {0, 0, 0}, seen_dir[3] = {0, 0, 0}, lights = 0;
  char what[160];
  for (uint32_t i = 0; pts && i < s->ntris && lights < 6; i++) {
    prim_kind k = scene_kind(s, i);
    if (k != RR_GEOMETRY_SPHERE && k != RR_GEOMETRY_BOX) continue;
    if (lights >= 3 && k == RR_GEOMETRY_SPHERE) continue; /* three of each */
    vec3 light = corner(s, 0, i), eye = in_bounds(s, frand(), frand(), frand());
    size_t n = targets(s, eye, light, pts, npts);
    for (size_t m = 0; m < n / 8; m++) /* and points around the light, inside or just outside */
      pts[m] = v3_add(light, v3((frand() - 0.5f) * 2, (frand() - 0.5f) * 2, (frand() - 0.5f) * 2));
    lights++;
    snprintf(what, sizeof what, "mixed, light inside %s %u", k == RR_GEOMETRY_SPHERE ? "sphere" : "box", i);
    check_rays(s, &light, light, pts, n, what, seen);
    vec3 towards = v3(frand() - 0.5f, frand(), frand() - 0.5f);
    for (size_t m = 0; m < n; m++) pts[m] = v3_add(light, v3((frand() - 0.5f) * 0.5f, (frand() - 0.5f) * 0.5f, 0));
    snprintf(what, sizeof what, "mixed, directional light from inside %s %u", k == RR_GEOMETRY_SPHERE ? "sphere" : "box", i);
    check_rays(s, NULL, towards, pts, n, what, seen_dir);
  }
  CHECK(lights == 6 && seen[2] > 0 && seen_dir[2] > 0,
        "lights inside analytic primitives: %zu lights, %zu and %zu rays occluded first by an analytic one", lights,
        seen[2], seen_dir[2]);
  free(pts);
}

/* Lit images: shadows by rays, raster and auto give the same bits on random views
 * (inside ones too) with a point and a spot light, frames on 1, 2, 8 threads;
 * raster in waves of a few rows (one at 16 samples) too. The lit AOVs made with
 * the colour (rr_shade_frame_aovs, raster) equal rr_frame_aov's (rays). */
static void check_lit_scene(rr_scene *s, const char *name, bool inside) {
  vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f), ext = v3_sub(s->bmax, s->bmin);
  rr_light_info pt = {.type = RR_LIGHT_POINT, .color = {2, 2, 2}};
  v3_store(pt.position, inside ? v3_add(c, v3_scale(ext, 0.2f)) : v3_add(c, v3(0.3f * ext.x, ext.y, 0.4f * ext.z)));
  rr_light_info sp = {.type = RR_LIGHT_SPOT, .color = {3, 2, 1}, .inner_cone_deg = 10, .outer_cone_deg = 35};
  v3_store(sp.position, inside ? v3_sub(c, v3_scale(ext, 0.2f)) : v3_add(c, v3(-0.5f * ext.x, 0.8f * ext.y, 0)));
  v3_store(sp.direction, v3_sub(c, v3_load(sp.position)));
  rr_light_info dl = {.type = RR_LIGHT_DIRECTIONAL, .direction = {0.3f, -1, -0.2f}, .color = {0.5f, 0.5f, 0.6f}};
  CHECK(rr_scene_add_light(s, &pt) == RR_OK && rr_scene_add_light(s, &sp) == RR_OK && rr_scene_add_light(s, &dl) == RR_OK,
        "%s", rr_device_message(dev));
  /* a view without shadow rays (from inside a closed primitive) is replaced, a few times */
  int views = test_quick() ? 1 : 3, lit_views = 0;
  for (int v = 0; v < views; v++) {
    bool shadowed = false;
    rr_camera cam = inside ? test_random_view(s, 0.1f, 0.3f, 0.2f, 60, 90) : test_random_view(s, 1.5f, 3, 0.3f, 30, 60);
    for (int ti = 0; ti < TEST_NTHREADS + 2; ti++) {
      /* then ssaa:16 (a pass long enough for auto to rasterize) and msaa:8 */
      rr_render_options o;
      rr_render_options_init(&o);
      o.method = RR_METHOD_3DR_BB, o.width = 96, o.height = 72, o.threads = test_threads[ti % TEST_NTHREADS];
      if (ti == TEST_NTHREADS)
        CHECK(rr_render_options_set_aa(dev, &o, RR_AA_SSAA, 16, 0, RR_AA_STANDARD, 0) == RR_OK, "%s",
              rr_device_message(dev));
      if (ti == TEST_NTHREADS + 1) /* groups of samples shaded once, waves of 13 rows for raster */
        CHECK(rr_render_options_set_aa(dev, &o, RR_AA_MSAA, 8, 0, RR_AA_STANDARD, 0) == RR_OK, "%s",
              rr_device_message(dev));
      rr_frame *f = test_render_opt(dev, s, &cam, &o);
      if (!f) continue;
      float *img[3] = {NULL, NULL, NULL};
      rr_shadow_mode modes[3] = {RR_SHADOWS_RAYS, RR_SHADOWS_RASTER, RR_SHADOWS_AUTO};
      uint64_t rays = 0;
      for (int m = 0; m < 3; m++) {
        rr_shade_options so;
        rr_shade_options_init(&so);
        so.mode = RR_SHADE_LIT, so.shadows = modes[m], so.max_depth = 1;
        if (m == 1) so.wave_points = 96 * 13; /* waves of 13 rows, the last of 7; ssaa:16 one row */
        rr_image im = {0};
        rr_shade_stats st;
        CHECK(rr_shade_frame(dev, s, &cam, f, &so, &im, &st) == RR_OK, "%s", rr_device_message(dev));
        img[m] = im.data;
        if (m == 0) rays = st.shadow_rays;
        CHECK(st.shadow_rays == rays, "%s: mode %d traced %llu shadow rays, rays %llu", name, m,
              (unsigned long long)st.shadow_rays, (unsigned long long)rays);
        CHECK(st.shadow_rays_raster == (m == 1 ? rays : m == 0 ? 0 : st.shadow_rays_raster),
              "%s: mode %d rasterized %llu of %llu shadow rays", name, m, (unsigned long long)st.shadow_rays_raster,
              (unsigned long long)rays);
      }
      for (int m = 1; m < 3; m++) {
        size_t diff = 0;
        for (size_t k = 0; img[0] && img[m] && k < (size_t)96 * 72 * 3; k++) diff += memcmp(&img[0][k], &img[m][k], 4) != 0;
        CHECK(img[0] && img[m] && diff == 0, "%s view %d, %d threads%s: %zu channels of the %s image differ from rays",
              name, v, test_threads[ti % TEST_NTHREADS], ti == TEST_NTHREADS ? ", ssaa:16" : ti > TEST_NTHREADS ? ", msaa:8" : "", diff,
              m == 1 ? "raster" : "auto");
      }
      shadowed |= rays > 0;
      if (ti == 0) { /* one sample per pixel */
        rr_shade_options so;
        rr_shade_options_init(&so);
        so.mode = RR_SHADE_LIT, so.shadows = RR_SHADOWS_RASTER, so.max_depth = 1;
        rr_image im = {0}, aovs[RR_AOV_COUNT] = {{0}};
        unsigned want = 1u << RR_AOV_SHADOW | 1u << RR_AOV_DIRECT;
        CHECK(rr_shade_frame_aovs(dev, s, &cam, f, &so, want, aovs, &im, NULL) == RR_OK, "%s", rr_device_message(dev));
        CHECK(im.data && img[0] && memcmp(im.data, img[0], sizeof(float) * 96 * 72 * 3) == 0,
              "%s view %d: the colour of rr_shade_frame_aovs differs", name, v);
        for (int a = RR_AOV_DIRECT; a <= RR_AOV_SHADOW; a += RR_AOV_SHADOW - RR_AOV_DIRECT) {
          rr_image ref = {0};
          int ch = a == RR_AOV_SHADOW ? 1 : 3;
          CHECK(rr_frame_aov(dev, s, &cam, f, (rr_aov)a, &ref) == RR_OK, "%s", rr_device_message(dev));
          CHECK(ref.data && aovs[a].data && aovs[a].channels == ch &&
                    memcmp(ref.data, aovs[a].data, sizeof(float) * 96 * 72 * ch) == 0,
                "%s view %d: AOV %d from the raster pass differs from rr_frame_aov's", name, v, a);
          rr_image_free(&ref), rr_image_free(&aovs[a]);
        }
        rr_image_free(&im);
      }
      for (int m = 0; m < 3; m++) free(img[m]);
      rr_frame_release(f);
    }
    lit_views += shadowed;
    if (!shadowed && views < 8) views++;
  }
  CHECK(lit_views >= (test_quick() ? 1 : 3), "%s: %d views with shadow rays", name, lit_views);
}

static void check_lit(const char *name, bool inside) {
  rr_scene *s = load(name);
  if (!s) return;
  check_lit_scene(s, name, inside);
  rr_scene_release(s);
}

/* An empty scene: nothing occludes, and the lit mode shades it. */
static void check_empty(void) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK && rr_scene_commit(s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  rr_ray r[3] = {{{0, 0, 0}, {1, 0, 0}, 0, 1}, {{0, 0, 0}, {0, 0, 0}, 0, 1}, {{1, 0, 0}, {0, 1, 0}, 0, 1}};
  int occ[3] = {7, 7, 7};
  bool empty;
  CHECK(rr_occluded_raster(s, rr_bvh_of(dev, s, &empty), r, 3, 2, occ, NULL) && !occ[0] && !occ[1] && !occ[2],
        "empty scene: %d %d %d", occ[0], occ[1], occ[2]);
  rr_light_info pt = {.type = RR_LIGHT_POINT, .position = {0, 1, 0}, .color = {1, 1, 1}};
  CHECK(rr_scene_add_light(s, &pt) == RR_OK, "%s", rr_device_message(dev));
  rr_camera cam;
  rr_camera_init(&cam);
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, 16, 16, 0);
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.shadows = RR_SHADOWS_RASTER;
  rr_image im = {0};
  CHECK(f && rr_shade_frame(dev, s, &cam, f, &so, &im, NULL) == RR_OK && im.data, "empty lit: %s",
        rr_device_message(dev));
  free(im.data);
  rr_frame_release(f);
  rr_scene_release(s);
}

int main(void) {
  dev = rr_device_new();
  bool quick = test_quick();
  size_t npts = quick ? 1500 : 20000;
  check_scene("demo", quick ? 4 : 16, npts);
  check_scene("sphere:24", quick ? 4 : 8, npts); /* closed: lights and eyes inside it */
  check_scene("plane:16", 4, npts);              /* shared vertices and edges on a regular grid */
  check_scene("box:3", 8, npts);
  if (!quick) {
    const char *bunny = test_model("stanford-bunny.obj");
    if (bunny) check_scene(bunny, 4, npts);
  }
  check_lit("demo", false);
  check_lit("sphere:24", true);
  for (int inst = 0; inst < 2; inst++) {
    const char *name = inst ? "mixed with instances" : "mixed";
    rr_scene *mixed = mixed_scene(quick ? 60 : 200, quick ? 16 : 40, inst);
    if (!mixed) continue;
    size_t n = inst ? npts / 4 : npts; /* (the instances: the same paths, fewer points) */
    check_lights(mixed, name, quick || inst ? 4 : 16, n);
    check_inside_ana(mixed, n / 2);
    check_lit_scene(mixed, name, false);
    check_lit_scene(mixed, name, true);
    rr_scene_release(mixed);
  }
  check_empty();
  rr_device_release(dev);
  return test_done();
}
