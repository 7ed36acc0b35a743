#include "benchutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

double bench_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n) {
  qsort(v, n, sizeof *v, cmp);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

const char *bench_scene_path(const char *name) {
  static char buf[4096];
  if (access(name, R_OK) == 0 || strchr(name, '/')) return name;
  if (strncmp(name, "grid:", 5) == 0) {
    const char *last = strrchr(name, ':');
    char mesh[1024];
    snprintf(mesh, sizeof mesh, "%.*s", (int)(last - name - 5), name + 5);
    if (access(mesh, R_OK) != 0) {
      snprintf(buf, sizeof buf, "grid:%s/%s%s", RR_MODELS_DIR, mesh, last);
      return buf;
    }
    return name;
  }
  if (strchr(name, '.')) {
    snprintf(buf, sizeof buf, "%s/%s", RR_MODELS_DIR, name);
    return buf;
  }
  return name; /* a built-in name */
}

rr_scene *bench_load(rr_device *dev, const char *name, double *load_ms) {
  double t0 = bench_now_ms();
  rr_scene *s;
  if (rr_scene_load(dev, bench_scene_path(name), &s) != RR_OK) {
    fprintf(stderr, "bench: %s\n", rr_device_message(dev));
    exit(1);
  }
  if (load_ms) *load_ms = bench_now_ms() - t0;
  return s;
}

void bench_camera(rr_device *dev, const rr_scene *scene, int w, int h, rr_camera *cam) {
  rr_camera_init(cam);
  cam->fov_deg = 50;
  rr_camera_frame(dev, scene, w, h, cam);
}

double bench_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *opt,
                    int reps, rr_frame **out) {
  double t[64];
  if (reps > 64) reps = 64;
  rr_frame *f = NULL;
  for (int r = 0; r < reps; r++) {
    rr_frame_release(f);
    if (rr_render(dev, scene, cam, opt, &f) != RR_OK) {
      fprintf(stderr, "bench: %s\n", rr_device_message(dev));
      exit(1);
    }
    rr_stats st;
    rr_frame_get_stats(f, &st);
    t[r] = st.frame_ms;
  }
  if (out) *out = f;
  else rr_frame_release(f);
  return bench_median(t, reps);
}

bench_agreement bench_compare(const uint32_t *ia, const float *da, const uint32_t *ib, const float *db, size_t n) {
  size_t same_id = 0, same_hit = 0, both = 0, depth_ok = 0;
  for (size_t k = 0; k < n; k++) {
    bool ha = ia[k] != RR_MISS, hb = ib[k] != RR_MISS;
    same_id += ia[k] == ib[k];
    same_hit += ha == hb;
    if (ha && hb) {
      both++;
      depth_ok += fabsf(da[k] - db[k]) <= 1e-4f * fmaxf(fabsf(da[k]), fabsf(db[k]));
    }
  }
  bench_agreement a = {(double)same_id / n, (double)same_hit / n, both ? (double)depth_ok / both : 1.0};
  return a;
}

float *bench_depths(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_frame *frame) {
  rr_image img;
  if (rr_frame_aov(dev, scene, cam, frame, RR_AOV_DEPTH, &img) != RR_OK) {
    fprintf(stderr, "bench: %s\n", rr_device_message(dev));
    exit(1);
  }
  return img.data; /* caller frees */
}
