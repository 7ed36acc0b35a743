#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

int test_passed, test_failed;
static int skipped;

int test_done(void) {
  if (skipped && test_passed == 0 && test_failed == 0) {
    printf("0 passed, 0 failed, 1 skipped\n");
    return 77;
  }
  printf("%d passed, %d failed\n", test_passed, test_failed);
  return test_failed ? 1 : 0;
}

void test_skip(const char *why) {
  fprintf(stderr, "skipped: %s\n", why);
  skipped = 1;
}

const char *test_model(const char *name) {
  static char path[4][1024];
  static int slot;
  char *p = path[slot++ & 3];
  snprintf(p, sizeof path[0], "%s/%s", RR_MODELS_DIR, name);
  if (access(p, R_OK) != 0) {
    fprintf(stderr, "note: %s absent, its checks are skipped\n", p);
    skipped = 1;
    return NULL;
  }
  return p;
}

bool test_quick(void) {
  const char *q = getenv("RR_TEST_QUICK");
  return q && *q && strcmp(q, "0") != 0;
}

static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
unsigned test_rand(void) {
  rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
  return (unsigned)(rng_state >> 33);
}
float test_randf(float lo, float hi) { return lo + (hi - lo) * (test_rand() / 2147483648.0f); }

int test_frames_differ(const rr_frame *a, const rr_frame *b) {
  if (a->samples != b->samples) return a->vb.width * a->vb.height * (a->samples > b->samples ? a->samples : b->samples);
  size_t n = (size_t)a->vb.width * a->vb.height * a->samples; /* every sample layer */
  int d = 0;
  for (size_t k = 0; k < n; k++)
    d += a->vb.id[k] != b->vb.id[k] || memcmp(&a->vb.t[k], &b->vb.t[k], 4) || memcmp(&a->vb.l1[k], &b->vb.l1[k], 4) ||
         memcmp(&a->vb.l2[k], &b->vb.l2[k], 4);
  return d;
}

rr_render_options test_pattern(rr_method m, int w, int h, int threads, int n, const float (*pos)[2]) {
  rr_render_options o;
  rr_render_options_init(&o);
  o.method = m, o.width = w, o.height = h, o.threads = threads, o.samples = n;
  memcpy(o.sample_pos, pos, (size_t)n * sizeof o.sample_pos[0]);
  return o;
}

void test_check_layers(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *o,
                       rr_method one, const rr_frame *multi, const char *what) {
  size_t npix = (size_t)o->width * o->height;
  for (int k = 0; k < o->samples; k++) {
    rr_render_options o1 = test_pattern(one, o->width, o->height, o->threads, 1, &o->sample_pos[k]);
    rr_frame *f = test_render_opt(dev, s, cam, &o1);
    if (!f) continue;
    bool same = true; /* sample k of each pixel (a pixel's samples side by side) */
    for (size_t p = 0; p < npix; p++) {
      size_t m = p * (size_t)o->samples + k;
      same &= memcmp(&f->vb.id[p], &multi->vb.id[m], 4) == 0 && memcmp(&f->vb.t[p], &multi->vb.t[m], 4) == 0 &&
              memcmp(&f->vb.l1[p], &multi->vb.l1[m], 4) == 0 && memcmp(&f->vb.l2[p], &multi->vb.l2[m], 4) == 0;
    }
    CHECK(same, "%s: layer %d of %d is not %s's frame of one sample at (%g, %g)", what, k, o->samples,
          rr_method_name(one), o->sample_pos[k][0], o->sample_pos[k][1]);
    rr_frame_release(f);
  }
}

int test_frame_hits(const rr_frame *f) {
  size_t n = (size_t)f->vb.width * f->vb.height * f->samples;
  int hits = 0;
  for (size_t k = 0; k < n; k++) hits += f->vb.id[k] != RR_MISS;
  return hits;
}

rr_frame *test_render_opt(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt) {
  rr_frame *f = NULL;
  rr_error e = rr_render(dev, s, cam, opt, &f);
  CHECK(e == RR_OK, "%s (%s camera, %dx%d, %d threads%s%s): %s", rr_method_name(opt->method),
        rr_camera_name(cam->type), opt->width, opt->height, opt->threads, opt->oracles ? ", oracles " : "",
        opt->oracles ? opt->oracles : "", rr_device_message(dev));
  if (e == RR_OK) return f;
  rr_frame_release(f);
  return NULL;
}

rr_frame *test_render(rr_device *dev, const rr_scene *s, const rr_camera *cam, rr_method m, int threads, int w, int h,
                      int cull) {
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = m, opt.width = w, opt.height = h, opt.threads = threads, opt.cull_backfaces = cull;
  return test_render_opt(dev, s, cam, &opt);
}

const int test_threads[TEST_NTHREADS] = {1, 2, 8};

/* Which of S, E and N a method keeps on any number of threads (*any) and on any
 * number above one (*several). The ray casters trace every ray and packet alike in
 * tiles of a fixed size; rasterization from the root (3dr-bb, 3dr-bin) sets each
 * triangle up once and draws whole blocks of rows that no two threads share;
 * 2dr-bb and 2dr-bin set up in chunks and draw bands of whole blocks; 3dr-fc starts
 * from frusta of 256 samples on any number of threads: all three on any number.
 * 3dr-fs and 3dr-full start from the whole image on one thread but from tiles of
 * 256 samples on several, so only several threads agree among themselves (and
 * with one thread on an image of one tile). auto times its candidates and may
 * choose another method. */
enum { SAME_S = 1, SAME_E = 2, SAME_N = 4, SAME_ALL = 7 };
static void same_stats(rr_method m, int *any, int *several) {
  *any = *several = 0;
  switch (m) {
  case RR_METHOD_AUTO: return;
  case RR_METHOD_3DR_FS:
  case RR_METHOD_3DR_FULL: *several = SAME_ALL; return;
  default: *any = SAME_ALL; return;
  }
}

/* Checks the statistics of b (on b->stats.threads threads) against a's. */
static void check_same_stats(const rr_frame *a, const rr_frame *b, int same, const char *what) {
  const rr_stats *x = &a->stats, *y = &b->stats;
  const char *name = rr_method_name(y->method);
  CHECK(!(same & SAME_S) || x->setups == y->setups, "%s: %s sets up S = %llu triangles on %d threads, %llu on %d",
        what, name, (unsigned long long)y->setups, y->threads, (unsigned long long)x->setups, x->threads);
  CHECK(!(same & SAME_E) || x->edge_evals == y->edge_evals, "%s: %s evaluates E = %llu on %d threads, %llu on %d",
        what, name, (unsigned long long)y->edge_evals, y->threads, (unsigned long long)x->edge_evals, x->threads);
  CHECK(!(same & SAME_N) || x->nodes == y->nodes, "%s: %s visits N = %llu nodes on %d threads, %llu on %d", what,
        name, (unsigned long long)y->nodes, y->threads, (unsigned long long)x->nodes, x->threads);
}

rr_frame *test_render_threads(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_render_options *opt,
                              const rr_frame *ref, const char *what) {
  rr_render_options o = *opt;
  rr_frame *one = NULL, *several = NULL; /* the frames on 1 thread and on the first count above */
  int any, on_several;
  same_stats(o.method, &any, &on_several);
  for (int k = 0; k < TEST_NTHREADS; k++) {
    o.threads = test_threads[k];
    rr_frame *f = test_render_opt(dev, s, cam, &o);
    if (!f) continue;
    const rr_frame *base = ref ? ref : one;
    if (base) {
      int d = test_frames_differ(base, f);
      CHECK(d == 0, "%s: %s on %d threads differs from %s at %d of %d samples", what, rr_method_name(o.method),
            o.threads, ref ? rr_method_name(ref->stats.method) : "its frame on 1 thread", d,
            f->vb.width * f->vb.height);
    }
    if (one && any) check_same_stats(one, f, any, what);
    if (several && on_several) check_same_stats(several, f, on_several, what);
    if (o.threads == 1 && !one) one = f;
    else if (o.threads > 1 && !several) several = f;
    else rr_frame_release(f);
  }
  if (!one) return several;
  rr_frame_release(several);
  return one;
}

rr_camera test_random_view(const rr_scene *s, float dist_lo, float dist_hi, float aim, float fov_lo, float fov_hi) {
  rr_camera cam;
  rr_camera_init(&cam);
  vec3 c = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
  float r = 0.5f * v3_len(v3_sub(s->bmax, s->bmin));
  vec3 dir = v3_norm(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)));
  vec3 eye = v3_add(c, v3_scale(dir, r * (dist_lo == dist_hi ? dist_lo : test_randf(dist_lo, dist_hi))));
  vec3 target = v3_add(c, v3_scale(v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1)), aim * r));
  memcpy(cam.eye, &eye, 12), memcpy(cam.target, &target, 12);
  cam.fov_deg = fov_lo == fov_hi ? fov_lo : test_randf(fov_lo, fov_hi);
  return cam;
}

rr_camera test_random_camera(const rr_scene *s, rr_camera_type type, bool inside) {
  float fov = type == RR_CAMERA_FISHEYE ? 200 : 70;
  rr_camera cam = test_random_view(s, inside ? 0.05f : 1.2f, inside ? 0.5f : 2.5f, 0.3f, fov, fov);
  cam.type = type;
  cam.ortho_height = 8;
  return cam;
}

const char *test_write_file(const char *dir, const char *name, const char *text) {
  static char path[8][512];
  static int slot;
  char *p = path[slot++ & 7];
  snprintf(p, sizeof path[0], "%s/%s", dir, name);
  FILE *f = fopen(p, "wb");
  if (f) fputs(text, f), fclose(f);
  return p;
}

bool test_exr_load(const char *path, test_exr_file *x) {
  EXRVersion v;
  const char *err = NULL;
  InitEXRHeader(&x->h);
  InitEXRImage(&x->img);
  x->ok = ParseEXRVersionFromFile(&v, path) == TINYEXR_SUCCESS &&
          ParseEXRHeaderFromFile(&x->h, &v, path, &err) == TINYEXR_SUCCESS &&
          LoadEXRImageFromFile(&x->img, &x->h, path, &err) == TINYEXR_SUCCESS;
  CHECK(x->ok, "tinyexr cannot read %s: %s", path, err ? err : "");
  if (err) FreeEXRErrorMessage(err);
  return x->ok;
}

void test_exr_free(test_exr_file *x) {
  if (x->ok) FreeEXRImage(&x->img);
  FreeEXRHeader(&x->h);
}

int test_exr_find(const test_exr_file *x, const char *name) {
  for (int k = 0; k < x->h.num_channels; k++)
    if (!strcmp(x->h.channels[k].name, name)) return k;
  return -1;
}

int test_run_cli(const char *dir, const char *args, bool with_stderr, char *out, size_t cap) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "cd '%s' && %s %s %s", dir, RR_CLI, args, with_stderr ? "2>&1" : "2>/dev/null");
  FILE *p = popen(cmd, "r");
  size_t n = p ? fread(out, 1, cap - 1, p) : 0;
  out[n] = 0;
  int st = p ? pclose(p) : -1;
  return st != -1 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

rr_hit test_brute_ray(const rr_scene *s, const rr_ray *ray, int *any) {
  camera rc;
  rr_cam_for_ray(ray->org, ray->dir, &rc);
  rr_hit h = rr_scene_hit(s, RR_MISS, INFINITY, 0, 0);
  *any = 0;
  for (uint32_t i = 0; i < s->ntris; i++) {
    float t, l1, l2;
    if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) { /* analytic: the one test on the float ray */
      ana_ray ar = ana_ray_of(ray->org, ray->dir);
      if (!rr_ana_hit(s, i, &ar, &t, &l1, &l2) || !(t >= ray->tmin && t <= ray->tmax)) continue;
    } else if (!rr_tri_ray_hit(s, i, &rc, false, ray->tmin, ray->tmax, &t, &l1, &l2)) continue;
    *any = 1;
    if (depth_wins(t, i, h.t, h.prim)) h = rr_scene_hit(s, i, t, l1, l2);
  }
  return h;
}

bool test_depth_errors(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                       test_depth_stats *out) {
  camera c;
  if (rr_cam_setup(dev, cam, f->vb.width, f->vb.height, &c) != RR_OK) return false;
  bool ok = rr_depth_errors(s, &c, f->vb.id, f->vb.t, out);
  rr_cam_release(&c);
  return ok;
}

rr_camera test_camera(rr_camera_type type, vec3 eye, vec3 target, float fov) {
  rr_camera c;
  rr_camera_init(&c);
  c.type = type;
  memcpy(c.eye, &eye, 12), memcpy(c.target, &target, 12);
  c.fov_deg = fov;
  return c;
}

int test_check_rays(rr_device *dev, const rr_scene *s, void (*each)(const rr_hit *h, void *arg), void *arg,
                    int *hits) {
  int bad = 0, n = 0;
  *hits = 0;
  for (int v = 0; v < 6; v++) {
    rr_camera cam = test_random_view(s, v % 2 ? 0.1f : 1.2f, v % 2 ? 0.6f : 2.5f, 0.3f, 70, 70);
    camera c;
    if (rr_cam_setup(dev, &cam, 24, 18, &c) != RR_OK) continue;
    for (int y = 0; y < 18; y++)
      for (int x = 0; x < 24; x++) {
        vec3 o, d;
        if (!rr_cam_ray(&c, x, y, &o, &d)) continue;
        rr_ray ray = {{o.x, o.y, o.z}, {d.x, d.y, d.z}, 0, INFINITY};
        if (v == 5) ray.tmin = test_randf(0, 5), ray.tmax = ray.tmin + test_randf(0, 10);
        rr_hit a, b;
        int any, occ = -1;
        CHECK(rr_intersect(dev, s, &ray, &a) == RR_OK, "rr_intersect");
        b = test_brute_ray(s, &ray, &any);
        n++, *hits += a.prim != RR_MISS;
        if (memcmp(&a, &b, sizeof a) != 0 && bad++ < 4)
          CHECK(0, "view %d ray (%d, %d): rr_intersect %u t %a, brute force %u t %a", v, x, y, a.prim, a.t, b.prim, b.t);
        CHECK(rr_occluded(dev, s, &ray, &occ) == RR_OK && occ == any, "rr_occluded %d, brute force %d", occ, any);
        if (each) each(&a, arg);
      }
    rr_cam_release(&c);
  }
  CHECK(bad == 0, "%d of %d rays differ from brute force", bad, n);
  return n;
}
