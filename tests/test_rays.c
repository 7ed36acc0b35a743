/* Ray streams: rr_intersect_stream / rr_occluded_stream give, ray for ray, the
 * bits of rr_intersect / rr_occluded, which give those of brute force over every
 * triangle with the setup and sample test of rc (rr_tri_ray_hit) — on random rays
 * (some with tmin/tmax cutting hits), rays through the shared edges and vertices
 * of plane:8, rays from the bunny's surface, rays through leaves of up to
 * 13 triangles (also as instances: the two-level BVH) and through a ground with
 * corners at infinity, in both layouts, on 1, 2 and 8
 * threads; and bad input: NaN/inf components (a miss and an error naming the
 * ray), count 0, bad strides, thread counts and NULL arrays; the queries' bounds on t
 * before the full test (ray_t_outside, ray_t_inside) against the full test. */
#include "vis/vis.h"
#include "io/io.h"
#include "vis/ray_test.h"
#include "testutil.h"

#include <string.h>

static bool same_hit(const rr_hit *a, const rr_hit *b) { return memcmp(a, b, sizeof *a) == 0; }

/* The single-ray path's cut setup (rr_tri_ray_hit1) against the full one
 * (rr_tri_ray_hit) on every finite triangle of s for every ray: the same verdict
 * and, on a hit, the same bits of t and barycentrics. */
static void check_tri_paths(const rr_scene *s, const rr_ray *rays, size_t n, const char *what) {
  size_t bad = 0, hits = 0;
  for (size_t r = 0; r < n; r++) {
    camera rc;
    rr_cam_for_ray(rays[r].org, rays[r].dir, &rc);
    for (uint32_t i = 0; i < s->ntris; i++) {
      if (scene_inf(s, i)) continue;
      float t[2] = {0, 0}, l1[2] = {0, 0}, l2[2] = {0, 0};
      bool a = rr_tri_ray_hit(s, i, &rc, false, rays[r].tmin, rays[r].tmax, &t[0], &l1[0], &l2[0]);
      bool b = rr_tri_ray_hit1(s, i, &rc, rays[r].tmin, rays[r].tmax, &t[1], &l1[1], &l2[1]);
      hits += a;
      bool same = a == b && (!a || (memcmp(&t[0], &t[1], sizeof t[0]) == 0 && memcmp(&l1[0], &l1[1], sizeof l1[0]) == 0 &&
                                    memcmp(&l2[0], &l2[1], sizeof l2[0]) == 0));
      if (!same && bad++ < 4)
        CHECK(0, "%s: ray %zu, triangle %u: full setup %d t %a l %a %a, ray setup %d t %a l %a %a", what, r, i, a,
              t[0], l1[0], l2[0], b, t[1], l1[1], l2[1]);
    }
  }
  CHECK(bad == 0 && hits > 0, "%s: %zu of the triangle tests differ (%zu hits)", what, bad, hits);
}

/* ray_t_outside and ray_t_inside, the queries' bounds on t before the full test,
 * against the full test (rr_tri_ray_hit) on every finite triangle of s for every
 * ray whose edge pre-test passes with all values positive: where ray_t_outside
 * says t lies outside the ray's range, the full test finds no hit in it, and it
 * never says so of the range [t, t] around a hit's own t; where ray_t_inside says
 * t lies inside, the full test hits in the range, and it never says so of a range
 * that starts just above or ends just below a hit's t. Returns how often
 * ray_t_outside cut a test, and in *proved how often ray_t_inside proved a hit. */
static size_t check_t_bound(const rr_scene *s, const rr_ray *rays, size_t n, const char *what, size_t *proved) {
  size_t bad = 0, cut = 0, hits = 0, sure = 0;
  for (size_t r = 0; r < n; r++) {
    camera rc;
    rr_cam_for_ray(rays[r].org, rays[r].dir, &rc);
    rr_vf4 eye[3], dir[3];
    float dmax = 0;
    for (int a = 0; a < 3; a++) {
      eye[a] = rr_vf4_splat(rays[r].org[a]), dir[a] = rr_vf4_splat(rays[r].dir[a]);
      dmax = fmaxf(dmax, fabsf(rays[r].dir[a]));
    }
    for (uint32_t i = 0; i < s->ntris; i++) {
      if (scene_inf(s, i)) continue;
      float v[9 * 4]; /* the triangle in lane 0 of four (stride 4), as the leaves hold it */
      for (int m = 0; m < 9; m++)
        for (int j = 0; j < 4; j++) v[4 * m + j] = s->p[m / 3][m % 3][i];
      rr_vf4 pre[4];
      if (!(tri_ray_may_hit4(v, 4, NULL, eye, dir, pre) & 1)) continue;
      const float e[4] = {pre[0][0], pre[1][0], pre[2][0], pre[3][0]};
      if (!(e[0] > 0 && e[1] > 0 && e[2] > 0)) continue;
      float t, l1, l2;
      bool hit = rr_tri_ray_hit(s, i, &rc, false, 0, INFINITY, &t, &l1, &l2);
      bool in = hit && t >= rays[r].tmin && t <= rays[r].tmax;
      float S = ray_corner_extent(v, 4, NULL, rays[r].org);
      bool out = ray_t_outside(S, dmax, e, rays[r].tmin, rays[r].tmax);
      bool inside = ray_t_inside(S, dmax, e, rays[r].tmin, rays[r].tmax);
      hits += hit, cut += out, sure += inside;
      if (((out && in) || (hit && ray_t_outside(S, dmax, e, t, t))) && bad++ < 4)
        CHECK(0, "%s: ray %zu, triangle %u: t %a in [%a, %a]: the bound cuts it", what, r, i, t, rays[r].tmin,
              rays[r].tmax);
      if (((inside && !in) || (hit && (ray_t_inside(S, dmax, e, nextafterf(t, INFINITY), INFINITY) ||
                                       ray_t_inside(S, dmax, e, -INFINITY, nextafterf(t, -INFINITY))))) &&
          bad++ < 4)
        CHECK(0, "%s: ray %zu, triangle %u: hit %d t %a, [%a, %a]: the bound proves a hit wrongly", what, r, i, hit,
              t, rays[r].tmin, rays[r].tmax);
    }
  }
  CHECK(bad == 0 && hits > 0, "%s: the t bounds failed %zu times (%zu hits)", what, bad, hits);
  if (proved) *proved = sure;
  return cut;
}

/* The rays as separate arrays (structure of arrays). */
typedef struct {
  float *c[8]; /* ox oy oz dx dy dz tmin tmax */
} soa_rays;

static rr_ray_stream to_soa(const rr_ray *rays, size_t n, soa_rays *a) {
  for (int k = 0; k < 8; k++) {
    a->c[k] = malloc((n ? n : 1) * sizeof(float));
    for (size_t i = 0; i < n; i++)
      a->c[k][i] = k < 3 ? rays[i].org[k] : k < 6 ? rays[i].dir[k - 3] : k == 6 ? rays[i].tmin : rays[i].tmax;
  }
  return (rr_ray_stream){.count = n,
                         .stride = sizeof(float),
                         .org = {a->c[0], a->c[1], a->c[2]},
                         .dir = {a->c[3], a->c[4], a->c[5]},
                         .tmin = a->c[6],
                         .tmax = a->c[7]};
}

/* Checks rays[0..n-1]: single calls against brute force for every `brute_every`-th
 * ray, streams in both layouts on 1, 2 and 8 threads against the single calls. */
static void check_rays(rr_device *dev, const rr_scene *s, const rr_ray *rays, size_t n, size_t brute_every,
                       const char *name) {
  rr_hit *ref = malloc(n * sizeof *ref), *hits = malloc(n * sizeof *hits);
  int *occ_ref = malloc(n * sizeof *occ_ref), *occ = malloc(n * sizeof *occ);
  size_t nhit = 0, bad = 0;
  for (size_t i = 0; i < n; i++) {
    CHECK(rr_intersect(dev, s, &rays[i], &ref[i]) == RR_OK, "%s: rr_intersect: %s", name, rr_device_message(dev));
    CHECK(rr_occluded(dev, s, &rays[i], &occ_ref[i]) == RR_OK, "%s: rr_occluded: %s", name, rr_device_message(dev));
    nhit += ref[i].prim != RR_MISS;
    if (i % brute_every) continue;
    int any;
    rr_hit b = test_brute_ray(s, &rays[i], &any);
    bad += !same_hit(&b, &ref[i]) || any != occ_ref[i];
    if (!same_hit(&b, &ref[i]) && bad < 4)
      fprintf(stderr, "%s ray %zu: rr_intersect %u t=%.9g, brute force %u t=%.9g\n", name, i, ref[i].prim, ref[i].t,
              b.prim, b.t);
  }
  CHECK(bad == 0, "%s: %zu rays differ from brute force", name, bad);
  CHECK(nhit > 0, "%s: no ray hit", name);
  soa_rays a;
  rr_ray_stream layouts[2] = {rr_ray_stream_aos(rays, n), to_soa(rays, n, &a)};
  const int threads[3] = {1, 2, 8};
  for (int l = 0; l < 2; l++)
    for (int k = 0; k < 3; k++) {
      memset(hits, 0xAB, n * sizeof *hits), memset(occ, 0xAB, n * sizeof *occ);
      CHECK(rr_intersect_stream(dev, s, &layouts[l], threads[k], hits) == RR_OK, "%s: %s", name,
            rr_device_message(dev));
      CHECK(rr_occluded_stream(dev, s, &layouts[l], threads[k], occ) == RR_OK, "%s: %s", name,
            rr_device_message(dev));
      size_t diff = 0;
      for (size_t i = 0; i < n; i++) diff += !same_hit(&hits[i], &ref[i]) || occ[i] != occ_ref[i];
      CHECK(diff == 0, "%s: %s stream on %d threads: %zu rays differ from single calls", name, l ? "SoA" : "AoS",
            threads[k], diff);
    }
  printf("%s: %zu rays, %zu hit, every %zu-th against brute force\n", name, n, nhit, brute_every);
  for (int k = 0; k < 8; k++) free(a.c[k]);
  free(ref), free(hits), free(occ_ref), free(occ);
}

/* Random rays from inside and around the bounds, some normalised, some parallel
 * to a coordinate plane, a quarter with tmin above 0 and a sixth with a finite tmax. */
static rr_ray *random_rays(const rr_scene *s, size_t n) {
  rr_ray *rays = malloc(n * sizeof *rays);
  vec3 lo = s->bmin, hi = s->bmax, ext = v3_sub(hi, lo);
  for (size_t r = 0; r < n; r++) {
    float m = r % 3 == 0 ? 0.0f : 1.0f;
    vec3 o = v3(test_randf(lo.x - m * ext.x, hi.x + m * ext.x), test_randf(lo.y - m * ext.y, hi.y + m * ext.y),
                test_randf(lo.z - m * ext.z, hi.z + m * ext.z));
    vec3 d = v3_sub(v3(test_randf(lo.x, hi.x), test_randf(lo.y, hi.y), test_randf(lo.z, hi.z)), o);
    if (r % 5 == 1) d = v3_norm(d);
    if (r % 7 == 2) d.y = 0;
    if (d.x == 0 && d.y == 0 && d.z == 0) d.x = 1;
    float len = v3_len(ext) / v3_len(d);
    rays[r] = (rr_ray){{o.x, o.y, o.z}, {d.x, d.y, d.z}, r % 4 == 3 ? test_randf(0, len) : 0,
                       r % 6 == 5 ? test_randf(0, 2 * len) : INFINITY};
  }
  return rays;
}

/* Rays through plane:8's vertices and edge midpoints, straight and oblique, from
 * above and below, and a ray's exact hit t as tmin and as tmax (t in [tmin, tmax]). */
static void plane_rays(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "plane:8", &s) != RR_OK) {
    CHECK(0, "plane:8: %s", rr_device_message(dev));
    return;
  }
  rr_ray rays[7 * 7 * 3 * 2];
  size_t n = 0;
  for (int j = -3; j <= 3; j++)
    for (int i = -3; i <= 3; i++)
      for (int h = 0; h < 3; h++)
        for (int up = 0; up < 2; up++) {
          rr_ray r = {{(float)i + (h == 1 ? 0.5f : 0), up ? -2.0f : 2.0f, (float)j + (h == 2 ? 0.5f : 0)},
                      {0, up ? 1.0f : -1.0f, 0}, 0, INFINITY};
          if ((i + j + h) % 2) r.dir[0] = 0.25f, r.org[0] -= 0.5f; /* oblique through the same point */
          rays[n++] = r;
        }
  check_rays(dev, s, rays, n, 1, "plane:8 edges and vertices");
  check_tri_paths(s, rays, n, "plane:8 edges and vertices");
  rr_hit hit;
  for (size_t i = 0; i < n; i++) {
    rr_intersect(dev, s, &rays[i], &hit);
    CHECK(hit.prim != RR_MISS, "plane:8: ray %zu through a shared edge or vertex fell through", i);
  }
  /* the range is inclusive at both ends, and nothing outside it counts */
  rr_ray r = rays[0];
  rr_intersect(dev, s, &r, &hit);
  float t = hit.t;
  rr_ray in = r, above = r, below = r;
  in.tmin = in.tmax = t, above.tmin = nextafterf(t, INFINITY), below.tmax = nextafterf(t, 0);
  rr_ray_stream rs[3] = {rr_ray_stream_aos(&in, 1), rr_ray_stream_aos(&above, 1), rr_ray_stream_aos(&below, 1)};
  for (int k = 0; k < 3; k++) {
    int occ = -1;
    rr_intersect_stream(dev, s, &rs[k], 2, &hit);
    rr_occluded_stream(dev, s, &rs[k], 2, &occ);
    CHECK((hit.prim != RR_MISS) == (k == 0) && occ == (k == 0), "plane:8: range %d: hit %u, occluded %d", k, hit.prim,
          occ);
  }
  rr_scene_release(s);
}

/* ray_valid (the queries' four-lane check) agrees with ray_problem on every
 * component set to each special value, alone and in pairs. */
static void valid_rays(void) {
  const float special[] = {0, -0.0f, 1, -2, 1e30f, -1e-40f, INFINITY, -INFINITY, NAN};
  const int ns = (int)(sizeof special / sizeof special[0]);
  int bad = 0, valid = 0, n = 0;
  for (int c0 = 0; c0 < 8; c0++)
    for (int c1 = c0; c1 < 8; c1++)
      for (int a = 0; a < ns; a++)
        for (int b = 0; b < ns; b++) {
          rr_ray ray = {{0.5f, 1, 2}, {0, -1, 0}, 0, INFINITY};
          float *f[8] = {&ray.org[0], &ray.org[1], &ray.org[2], &ray.dir[0], &ray.dir[1], &ray.dir[2], &ray.tmin,
                         &ray.tmax};
          *f[c0] = special[a], *f[c1] = special[b];
          bool ok = ray_problem(ray.org, ray.dir, ray.tmin, ray.tmax) == NULL;
          bad += ray_valid(&ray) != ok, valid += ok, n++;
        }
  CHECK(bad == 0 && valid > 0 && valid < n, "ray_valid differs from ray_problem on %d of %d rays", bad, n);
}

/* Bad rays are misses and an error naming the lowest; bad streams are refused. */
static void bad_input(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "plane:8", &s) != RR_OK) return;
  enum { N = 600 };
  rr_ray rays[N];
  for (int i = 0; i < N; i++) rays[i] = (rr_ray){{test_randf(-3, 3), 2, test_randf(-3, 3)}, {0, -1, 0}, 0, INFINITY};
  rays[400].dir[1] = NAN, rays[300].org[0] = INFINITY, rays[500].dir[1] = 0, rays[550].tmax = NAN;
  rays[590].tmin = -INFINITY; /* a valid range */
  rr_ray_stream rs = rr_ray_stream_aos(rays, N);
  rr_hit hits[N];
  int occ[N];
  for (int threads = 1; threads <= 8; threads *= 2) {
    CHECK(rr_intersect_stream(dev, s, &rs, threads, hits) == RR_ERROR_ARGUMENT &&
              strstr(rr_device_message(dev), "ray 300 "),
          "the lowest bad ray named: '%s'", rr_device_message(dev));
    CHECK(rr_occluded_stream(dev, s, &rs, threads, occ) == RR_ERROR_ARGUMENT &&
              strstr(rr_device_message(dev), "ray 300 "),
          "the lowest bad ray named: '%s'", rr_device_message(dev));
    int wrong = 0;
    for (int i = 0; i < N; i++) {
      bool broken = i == 300 || i == 400 || i == 500 || i == 550;
      wrong += broken ? hits[i].prim != RR_MISS || !isinf(hits[i].t) || occ[i] != 0
                      : hits[i].prim == RR_MISS || occ[i] != 1;
    }
    CHECK(wrong == 0, "bad rays miss, the others hit (%d wrong, %d threads)", wrong, threads);
  }
  rr_ray_stream empty = {.count = 0};
  CHECK(rr_intersect_stream(dev, s, &empty, 0, NULL) == RR_ERROR_ARGUMENT, "NULL hits refused");
  CHECK(rr_intersect_stream(dev, s, &empty, 0, hits) == RR_OK && rr_occluded_stream(dev, s, &empty, 2, occ) == RR_OK,
        "count 0: nothing to do (%s)", rr_device_message(dev));
  CHECK(rr_intersect_stream(dev, NULL, &rs, 1, hits) == RR_ERROR_ARGUMENT, "NULL scene refused");
  CHECK(rr_intersect_stream(dev, s, NULL, 1, hits) == RR_ERROR_ARGUMENT, "NULL stream refused");
  CHECK(rr_intersect_stream(dev, s, &rs, -1, hits) == RR_ERROR_ARGUMENT, "-1 threads refused");
  CHECK(rr_occluded_stream(dev, s, &rs, RR_MAX_THREADS + 1, occ) == RR_ERROR_ARGUMENT, "too many threads refused");
  rr_ray_stream odd = rs;
  odd.stride = 6;
  CHECK(rr_intersect_stream(dev, s, &odd, 1, hits) == RR_ERROR_ARGUMENT && strstr(rr_device_message(dev), "stride"),
        "a stride of 6 bytes refused: '%s'", rr_device_message(dev));
  rr_ray_stream hole = rs;
  hole.dir[1] = NULL;
  CHECK(rr_occluded_stream(dev, s, &hole, 1, occ) == RR_ERROR_ARGUMENT && strstr(rr_device_message(dev), "NULL"),
        "a NULL component refused: '%s'", rr_device_message(dev));
  rr_ray_stream none = rr_ray_stream_aos(NULL, 3);
  CHECK(rr_occluded_stream(dev, s, &none, 1, occ) == RR_ERROR_ARGUMENT, "no rays for a count of 3 refused");
  /* an empty scene: every ray misses */
  rr_scene *e;
  rr_scene_new(dev, &e);
  rr_scene_commit(e);
  hits[7].prim = 0, occ[7] = 1;
  rays[300].org[0] = 0;
  CHECK(rr_intersect_stream(dev, e, &rs, 2, hits) == RR_ERROR_ARGUMENT && hits[7].prim == RR_MISS,
        "empty scene: misses");
  rr_scene_release(e);
  rr_scene_release(s);
}

/* Rays from the bunny's surface: AO-like (random directions) and to a light. */
static void bunny_rays(rr_device *dev) {
  const char *path = test_model("stanford-bunny.obj");
  rr_scene *s;
  if (!path || rr_scene_load(dev, path, &s) != RR_OK) return;
  size_t n = test_quick() ? 300 : 3000;
  rr_ray *rays = malloc(n * sizeof *rays);
  float radius = 0.5f * v3_len(v3_sub(s->bmax, s->bmin));
  for (size_t r = 0; r < n; r++) {
    uint32_t i = test_rand() % s->ntris;
    float b1 = test_randf(0, 0.5f), b2 = test_randf(0, 0.5f);
    vec3 p0 = scene_vertex(s, 0, i), p = v3_add(p0, v3_add(v3_scale(v3_sub(scene_vertex(s, 1, i), p0), b1),
                                                          v3_scale(v3_sub(scene_vertex(s, 2, i), p0), b2)));
    vec3 d = r % 2 ? v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1))
                   : v3_sub(v3(0.3f * radius, 3 * radius, 0.2f * radius), p);
    rays[r] = (rr_ray){{p.x, p.y, p.z}, {d.x, d.y, d.z}, r % 3 ? 1e-4f : 0, r % 2 ? INFINITY : 1.0f};
  }
  check_rays(dev, s, rays, n, test_quick() ? 30 : 100, "bunny surface");
  check_tri_paths(s, rays, test_quick() ? 4 : 16, "bunny surface"); /* every triangle: a few rays */
  /* rays from a surface point: the bound drops the start triangle (t about 0 < tmin) */
  size_t proved, cut = check_t_bound(s, rays, test_quick() ? 12 : 48, "bunny surface", &proved);
  CHECK(cut > 0, "bunny surface: the t bound never cut a test");
  CHECK(proved > 0, "bunny surface: the t bound never proved a hit");
  free(rays);
  rr_scene_release(s);
}

int main(void) {
  rr_device *dev = rr_device_new();
  rr_scene *s;
  if (rr_scene_load(dev, "sphere:16", &s) == RR_OK) {
    size_t n = test_quick() ? 500 : 3000;
    rr_ray *rays = random_rays(s, n);
    check_rays(dev, s, rays, n, 1, "random rays");
    check_tri_paths(s, rays, n, "random rays");
    check_t_bound(s, rays, n, "random rays", NULL);
    free(rays);
    rr_scene_release(s);
  } else {
    CHECK(0, "built-in scene: %s", rr_device_message(dev));
  }
  /* leaves of up to 13 triangles (several groups of four, one part full): a fan of
   * triangles through one axis, whose boxes overlap so that no split pays; and a
   * scene with corners at infinity, which the leaves' pre-test leaves to the full test */
  rr_build_options opt;
  rr_build_options_init(&opt);
  opt.leaf_size = 13;
  rr_device_set_build_options(dev, &opt);
  enum { FAN = 40 };
  float fan[FAN * 9];
  uint32_t idx[FAN * 3];
  for (int i = 0; i < FAN; i++) {
    float a = 3.14159265f * (float)i / FAN, c = cosf(a), sn = sinf(a);
    const float v[9] = {-c, -1, -sn, c, -1, sn, 0.1f * c, 1, 0.1f * sn};
    memcpy(&fan[9 * i], v, sizeof v);
    for (int k = 0; k < 3; k++) idx[3 * i + k] = (uint32_t)(3 * i + k);
  }
  /* and the fan as instances (translated, rotated and scaled, sheared): the two-level
   * tree's leaves made in the traversal's buffers */
  const float xf[3][12] = {{1, 0, 0, 0.5f, 0, 1, 0, 0.25f, 0, 0, 1, -2},
                           {0.6f, 0, 0.9f, 2.5f, 0, 1.1f, 0, 0.5f, -0.9f, 0, 0.6f, -1},
                           {1, 0.25f, 0, -3, 0, 0.9f, -0.2f, 1, 0, 0, 1, 2}};
  const char *names[3] = {"fan, leaves of up to 13", "ground (corners at infinity)", "fan as instances"};
  for (int k = 0; k < 3; k++) {
    rr_error e = k == 1 ? rr_scene_load(dev, "ground:inf", &s) : rr_scene_new(dev, &s);
    if (k == 0 && !e) e = rr_scene_add_mesh(s, fan, 3 * FAN, idx, FAN, NULL);
    if (k == 2 && !e) e = rr_scene_add_instances(s, fan, 3 * FAN, idx, FAN, NULL, &xf[0][0], 3);
    if (k != 1 && !e) e = rr_scene_commit(s);
    if (e) {
      CHECK(0, "%s: %s", names[k], rr_device_message(dev));
      continue;
    }
    const rr_bvh *b = s->bvh->obj ? s->bvh->obj : s->bvh; /* (the instanced mesh's own tree) */
    uint32_t widest = 0;
    for (uint32_t i = 0; i < b->nnodes; i++) widest = b->nodes[i].count > widest ? b->nodes[i].count : widest;
    CHECK(k == 1 || widest > 4, "%s: no leaf beyond four triangles (at most %u)", names[k], widest);
    CHECK(k != 2 || s->bvh->obj, "%s: two levels", names[k]);
    rr_ray *rays = random_rays(s, 500);
    check_rays(dev, s, rays, 500, 1, names[k]);
    free(rays);
    rr_scene_release(s);
  }
  rr_build_options_init(&opt);
  rr_device_set_build_options(dev, &opt);
  plane_rays(dev);
  bad_input(dev);
  valid_rays();
  bunny_rays(dev);
  rr_device_release(dev);
  return test_done();
}
