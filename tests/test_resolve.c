/* The resolve stage and the outputs of several samples per pixel: every filter keeps
 * a constant image constant (border included, with per-sample weights), the box of
 * one sample is the identity, and so is that of samples of one colour (resolve_one),
 * the wide filters spread a bright sample into the
 * neighbours, alpha is the coverage with the colour straight; the per-sample AOVs
 * are the frame's layers (checked against one-sample frames at each position), the
 * per-pixel AOVs follow their rules, the resolved colour is the mean of the
 * one-sample images; the CLI takes --aa-filter and --alpha and refuses bad values. */
#define _POSIX_C_SOURCE 200809L

#include "testutil.h"
#include "shade/resolve.h"

#include <math.h>
#include <string.h>
#include <unistd.h>

static rr_device *dev;

/* Rotated grid with a fifth sample nearest the centre (index 4). */
static const float pattern[5][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f},
                                    {0.45f, 0.55f}};

enum { W = 9, H = 7, N = 5 };

static rr_image resolve(const resolve_input *in, rr_filter f, float radius, int threads) {
  rr_shade_options o;
  rr_shade_options_init(&o);
  o.filter = f, o.radius = radius;
  rr_image img = {0};
  rr_error e = rr_resolve_image(dev, in, &o, threads, &img);
  CHECK(e == RR_OK, "resolve with %s: %s", rr_filter_name(f), rr_device_message(dev));
  return img;
}

static const struct {
  rr_filter f;
  float radius;
} filters[] = {{RR_FILTER_BOX, 0},  {RR_FILTER_MITCHELL, 0}, {RR_FILTER_MITCHELL, 0.5f}, {RR_FILTER_MITCHELL, 4},
               {RR_FILTER_BLACKMAN_HARRIS, 0}, {RR_FILTER_BLACKMAN_HARRIS, 3}};
enum { NFILTERS = sizeof filters / sizeof filters[0] };

/* A constant per-sample image resolves to the constant everywhere, whatever the
 * filter, the per-sample weights (a few 0) and the alpha (all 1: alpha 1). */
static void test_constant(void) {
  static float rgb[W * H * N * 3], weight[W * H * N], alpha[W * H * N];
  const float c[3] = {0.3f, 0.6f, 0.9f};
  for (int i = 0; i < W * H * N; i++) {
    for (int k = 0; k < 3; k++) rgb[3 * i + k] = c[k];
    weight[i] = i % 11 == 3 ? 0.0f : 0.5f + (float)(test_rand() % 100) / 10.0f;
    alpha[i] = 1;
  }
  for (int v = 0; v < 3; v++) {
    resolve_input in = {W, H, N, pattern, rgb, v >= 1 ? weight : NULL, v == 2 ? alpha : NULL};
    for (int i = 0; i < NFILTERS; i++) {
      rr_image img = resolve(&in, filters[i].f, filters[i].radius, 2);
      if (!img.data) continue;
      CHECK(img.channels == (v == 2 ? 4 : 3) && img.kind == RR_IMAGE_COLOR, "%d channels", img.channels);
      const float *p = img.data;
      double worst = 0;
      for (int k = 0; k < W * H; k++) {
        for (int ch = 0; ch < 3; ch++) worst = fmax(worst, fabs(p[img.channels * k + ch] - c[ch]) / c[ch]);
        if (v == 2) worst = fmax(worst, fabs(p[4 * k + 3] - 1.0));
      }
      CHECK(worst <= 2e-7, "%s radius %g (variant %d): a constant image off by %g relative",
            rr_filter_name(filters[i].f), (double)filters[i].radius, v, worst);
      rr_image_free(&img);
    }
  }
}

/* The box of one sample per pixel gives the samples back bit for bit, at any position. */
static void test_box_identity(void) {
  static float rgb[W * H * 3];
  for (int i = 0; i < W * H * 3; i++) rgb[i] = (float)test_rand() / 4294967296.0f * 3.0f;
  for (int s = 0; s < N; s++) {
    resolve_input in = {W, H, 1, &pattern[s], rgb, NULL, NULL};
    rr_image img = resolve(&in, RR_FILTER_BOX, 0, 1);
    CHECK(img.data && !memcmp(img.data, rgb, sizeof rgb), "box of one sample at (%g, %g) is not the identity",
          (double)pattern[s][0], (double)pattern[s][1]);
    rr_image_free(&img);
  }
}

/* A pixel whose samples share one colour (shading's shortcut, resolve_one) resolves to
 * resolve_own's bits: every count of samples, csaa's whole weights (coverage samples
 * at 0), alpha or none, hit or miss, and colours of every kind (0, -0, negative,
 * tiny, subnormal, huge, infinite, NaN). */
static void test_one_colour(void) {
  const float values[] = {0.0f, -0.0f, 0.5f, 0.1f, 1.0f / 3, -0.25f, 1e-30f, 1e-45f, 3e38f, 0.99999994f,
                          INFINITY, -INFINITY, NAN};
  const int nv = sizeof values / sizeof *values;
  int bad = 0, cases = 0;
  for (int n = 1; n <= 16; n *= 2)
    for (int csaa = 0; csaa < 2; csaa++)
      for (int channels = 3; channels <= 4; channels++)
        for (int hit = 0; hit < 2; hit++)
          for (int v = 0; v < nv; v++) {
            float rgb[16][3], w[16], a[16], own[4] = {0}, one[4] = {0};
            for (int k = 0; k < n; k++) {
              /* csaa: the first quarter stored, weighing 1 + their votes; the rest weigh 0
               * and carry black, as shading leaves them */
              int stored = n / 4 > 0 ? n / 4 : 1;
              w[k] = !csaa ? 1.0f : k < stored ? 1.0f + (float)((n - stored) / stored) : 0.0f;
              for (int c = 0; c < 3; c++) rgb[k][c] = w[k] > 0 ? values[(v + c) % nv] : 0.0f;
              a[k] = channels == 4 && !hit ? 0.0f : 1.0f;
            }
            resolve_own(n, rgb[0], 3, csaa ? w : NULL, channels == 4 ? a : NULL, 1, channels, own);
            resolve_one(rgb[0], channels == 3 || hit, channels, one);
            bad += memcmp(own, one, sizeof own) != 0, cases++;
          }
  CHECK(bad == 0, "resolve_one differs from resolve_own in %d of %d cases", bad, cases);
}

/* One bright sample: the box keeps it in its pixel, the wide filters spread it to
 * the neighbours (left and right alike: the sample is central, the borders as far),
 * and nothing goes below zero. */
static void test_spread(void) {
  static float rgb[W * H * 3];
  const float centre[1][2] = {{0.5f, 0.5f}};
  memset(rgb, 0, sizeof rgb);
  int cx = 4, cy = 3;
  for (int k = 0; k < 3; k++) rgb[3 * (cy * W + cx) + k] = 1.0f;
  resolve_input in = {W, H, 1, centre, rgb, NULL, NULL};
  for (int i = 0; i < NFILTERS; i++) {
    rr_image img = resolve(&in, filters[i].f, filters[i].radius, 1);
    if (!img.data) continue;
    const float *p = img.data;
    int lit = 0;
    bool negative = false;
    for (int k = 0; k < W * H; k++) lit += p[3 * k] > 0, negative |= p[3 * k] < 0;
    float left = p[3 * (cy * W + cx - 1)], right = p[3 * (cy * W + cx + 1)], up = p[3 * ((cy - 1) * W + cx)];
    const char *name = rr_filter_name(filters[i].f);
    CHECK(!negative, "%s: a negative colour", name);
    CHECK(p[3 * (cy * W + cx)] > 0, "%s: the bright pixel went dark", name);
    if (filters[i].f == RR_FILTER_BOX || filters[i].radius == 0.5f)
      CHECK(lit == 1, "%s radius %g: %d pixels lit, 1 expected", name, (double)filters[i].radius, lit);
    else
      CHECK(lit > 1 && left > 0 && left == right && up > 0, "%s radius %g: %d lit, neighbours %g %g %g", name,
            (double)filters[i].radius, lit, (double)left, (double)right, (double)up);
    rr_image_free(&img);
  }
}

/* Half the samples of every pixel hit: alpha 0.5 (box), the colour the mean of the
 * hits alone; no hit: alpha 0 and black; a bad radius or filter is refused. */
static void test_alpha(void) {
  static float rgb[W * H * 4 * 3], alpha[W * H * 4];
  for (int s = 0; s < 4; s++)
    for (int k = 0; k < W * H; k++) {
      size_t i = (size_t)s * W * H + k;
      alpha[i] = k == 0 ? 0.0f : s % 2 == 0; /* samples 0 and 2 hit, pixel 0 none */
      for (int c = 0; c < 3; c++) rgb[3 * i + c] = s % 2 == 0 ? 0.25f * (1 + s / 2) : 7.0f; /* hits 0.25, 0.5 */
    }
  resolve_input in = {W, H, 4, pattern, rgb, NULL, alpha};
  rr_image img = resolve(&in, RR_FILTER_BOX, 0, 2);
  if (img.data) {
    const float *p = img.data;
    CHECK(p[0] == 0 && p[3] == 0, "no hit: colour %g alpha %g", (double)p[0], (double)p[3]);
    bool ok = true;
    for (int k = 1; k < W * H; k++) ok &= p[4 * k + 3] == 0.5f && p[4 * k] == 0.375f;
    CHECK(ok, "half covered: alpha %g colour %g (0.5, 0.375 expected)", (double)p[7], (double)p[4]);
  }
  rr_image_free(&img);
  rr_shade_options o;
  rr_shade_options_init(&o);
  o.radius = 4.5f;
  CHECK(rr_resolve_image(dev, &in, &o, 1, &img) == RR_ERROR_ARGUMENT && strstr(rr_device_message(dev), "radius"),
        "radius 4.5: %s", rr_device_message(dev));
  o.radius = 0, o.filter = RR_FILTER_COUNT;
  CHECK(rr_resolve_image(dev, &in, &o, 1, &img) == RR_ERROR_ARGUMENT, "bad filter: %s", rr_device_message(dev));
  CHECK(rr_filter_from_name("mitchell") == RR_FILTER_MITCHELL && rr_filter_from_name("gauss") < 0 &&
            !strcmp(rr_filter_name(RR_FILTER_BLACKMAN_HARRIS), "blackman-harris"),
        "filter names");
}

static rr_image aov(const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_aov a) {
  rr_image img = {0};
  CHECK(rr_frame_aov(dev, s, cam, f, a, &img) == RR_OK, "AOV %d: %s", (int)a, rr_device_message(dev));
  return img;
}

/* A frame of the N positions against N one-sample frames at them. */
static void test_frame_outputs(void) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, "sphere", &s) != RR_OK) {
    CHECK(0, "sphere: %s", rr_device_message(dev));
    return;
  }
  enum { FW = 40, FH = 30 };
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, FW, FH, &cam);
  rr_render_options o;
  rr_render_options_init(&o);
  o.width = FW, o.height = FH, o.threads = 2, o.samples = N;
  memcpy(o.sample_pos, pattern, sizeof pattern);
  rr_frame *f = test_render_opt(dev, s, &cam, &o), *one[N] = {0};
  for (int k = 0; k < N; k++) {
    o.samples = 1;
    memcpy(o.sample_pos[0], pattern[k], sizeof pattern[k]);
    one[k] = test_render_opt(dev, s, &cam, &o);
  }
  size_t npix = (size_t)FW * FH;
  if (!f || !one[N - 1]) goto done;
  float pos[RR_MAX_SAMPLES][2];
  CHECK(rr_frame_get_sample_pos(f, pos) == RR_OK && !memcmp(pos, pattern, sizeof pattern), "sample positions");

  /* per-sample AOVs: channel k is the one-sample frame's AOV at position k */
  static const rr_aov per_sample[3][2] = {
      {RR_AOV_SAMPLE_ID, RR_AOV_ID}, {RR_AOV_SAMPLE_DEPTH, RR_AOV_DEPTH}, {RR_AOV_SAMPLE_MESH, RR_AOV_MESH}};
  for (int a = 0; a < 3; a++) {
    rr_image all = aov(s, &cam, f, per_sample[a][0]);
    CHECK(all.channels == N && all.width == FW && all.height == FH, "sample AOV %d: %d channels", a, all.channels);
    for (int k = 0; all.data && k < N; k++) {
      rr_image single = aov(s, &cam, one[k], per_sample[a][1]);
      int differ = 0;
      for (size_t p = 0; single.data && p < npix; p++)
        differ += memcmp((uint32_t *)all.data + p * N + k, (uint32_t *)single.data + p, 4) != 0;
      CHECK(differ == 0, "sample AOV %d, sample %d: %d pixels differ from its one-sample frame", a, k, differ);
      rr_image_free(&single);
    }
    if (a == 0 && all.data) { /* ...and the frame's layers */
      const uint32_t *ids = rr_frame_ids(f);
      int differ = 0;
      for (int k = 0; k < N; k++)
        for (size_t p = 0; p < npix; p++) differ += ((uint32_t *)all.data)[p * N + k] != ids[p * N + k];
      CHECK(differ == 0, "sample-id: %d samples differ from the layers", differ);
    }
    rr_image_free(&all);
  }

  /* per-pixel rules: the centre's sample (index 4) for id and normal, the nearest depth */
  const rr_aov centred[] = {RR_AOV_ID, RR_AOV_NORMAL, RR_AOV_BARY, RR_AOV_MESH};
  for (size_t a = 0; a < sizeof centred / sizeof centred[0]; a++) {
    rr_image x = aov(s, &cam, f, centred[a]), y = aov(s, &cam, one[4], centred[a]);
    CHECK(x.data && y.data && x.channels == y.channels &&
              !memcmp(x.data, y.data, npix * x.channels * 4),
          "AOV %d is not the centre sample's", (int)centred[a]);
    rr_image_free(&x), rr_image_free(&y);
  }
  rr_image depth = aov(s, &cam, f, RR_AOV_DEPTH), cover = aov(s, &cam, f, RR_AOV_COVERAGE), d[N];
  bool have = depth.data && cover.data;
  for (int k = 0; k < N; k++) d[k] = aov(s, &cam, one[k], RR_AOV_DEPTH), have &= d[k].data != NULL;
  int bad_depth = 0, bad_cover = 0, partial = 0;
  for (size_t p = 0; have && p < npix; p++) {
    float near = INFINITY;
    int hits = 0;
    for (int k = 0; k < N; k++) {
      near = fminf(near, ((float *)d[k].data)[p]);
      hits += rr_frame_ids(f)[p * N + k] != RR_MISS;
    }
    bad_depth += ((float *)depth.data)[p] != near;
    float c = ((float *)cover.data)[p];
    bad_cover += fabsf(c - (float)hits / N) > 1e-6f;
    partial += c > 0 && c < 1;
  }
  CHECK(bad_depth == 0, "depth: %d pixels not the nearest sample's", bad_depth);
  CHECK(bad_cover == 0 && partial > 0, "coverage: %d pixels wrong, %d partial", bad_cover, partial);
  rr_image_free(&depth), rr_image_free(&cover);
  for (int k = 0; k < N; k++) rr_image_free(&d[k]);

  /* the resolved colour (box) is the mean of the one-sample images */
  rr_image c = {0}, ci[N] = {{0}};
  bool ok = rr_shade(dev, s, &cam, f, RR_SHADE_LAMBERT, &c) == RR_OK;
  for (int k = 0; ok && k < N; k++) ok = rr_shade(dev, s, &cam, one[k], RR_SHADE_LAMBERT, &ci[k]) == RR_OK;
  CHECK(ok, "shade: %s", rr_device_message(dev));
  double worst = 0;
  for (size_t i = 0; ok && i < npix * 3; i++) {
    double mean = 0;
    for (int k = 0; k < N; k++) mean += ((float *)ci[k].data)[i];
    worst = fmax(worst, fabs(((float *)c.data)[i] - mean / N));
  }
  CHECK(ok && worst < 1e-6, "resolved colour off the mean of the samples by %g", worst);

  /* the one shading call: NULL options are rr_shade's Lambert; options and stats */
  rr_image c2 = {0};
  rr_shade_stats st;
  CHECK(rr_shade_frame(dev, s, &cam, f, NULL, &c2, &st) == RR_OK && c.data && c2.channels == 3 &&
            !memcmp(c.data, c2.data, npix * 3 * sizeof(float)),
        "rr_shade_frame(NULL options) differs from rr_shade: %s", rr_device_message(dev));
  CHECK(st.shades > 0 && st.shades <= N * npix && st.shade_ms >= 0 && st.resolve_ms >= 0, "stats: %llu shades",
        (unsigned long long)st.shades);
  rr_image_free(&c2);
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_NORMAL, so.filter = RR_FILTER_MITCHELL, so.alpha = 1;
  CHECK(rr_shade_frame(dev, s, &cam, f, &so, &c2, NULL) == RR_OK && c2.channels == 4 && c2.kind == RR_IMAGE_COLOR,
        "normal, mitchell, alpha: %s", rr_device_message(dev));
  rr_image_free(&c2);
  so.radius = 9;
  CHECK(rr_shade_frame(dev, s, &cam, f, &so, &c2, NULL) == RR_ERROR_ARGUMENT && !c2.data &&
            strstr(rr_device_message(dev), "radius"),
        "radius 9 accepted: %s", rr_device_message(dev));
  so.radius = 0, so.mode = (rr_shade_mode)99;
  CHECK(rr_shade_frame(dev, s, &cam, f, &so, &c2, NULL) == RR_ERROR_ARGUMENT && !c2.data, "shade mode 99 accepted");
  rr_image_free(&c);
  for (int k = 0; k < N; k++) rr_image_free(&ci[k]);

  /* files: H×W×N in NPY, a channel per sample in EXR */
  rr_image ids = aov(s, &cam, f, RR_AOV_SAMPLE_ID);
  char dir[] = "/tmp/rr_resolve_XXXXXX", path[256];
  if (ids.data && mkdtemp(dir)) {
    snprintf(path, sizeof path, "%s/ids.npy", dir);
    CHECK(rr_image_write(dev, &ids, path) == RR_OK, "write npy: %s", rr_device_message(dev));
    char head[128] = {0};
    FILE *fp = fopen(path, "rb");
    if (fp) fread(head, 1, sizeof head - 1, fp), fclose(fp);
    CHECK(strstr(head + 10, "'shape': (30, 40, 5)") != NULL, "npy header: %s", head + 10);
    remove(path);
    snprintf(path, sizeof path, "%s/ids.exr", dir);
    CHECK(rr_image_write(dev, &ids, path) == RR_OK, "write exr: %s", rr_device_message(dev));
    test_exr_file x;
    if (test_exr_load(path, &x)) {
      CHECK(x.h.num_channels == N && !strcmp(x.h.channels[0].name, "id.s00") &&
                !strcmp(x.h.channels[4].name, "id.s04") && x.h.pixel_types[0] == TINYEXR_PIXELTYPE_UINT,
            "exr channels: %d, %s", x.h.num_channels, x.h.channels[0].name);
      int off = 0;
      for (size_t p = 0; x.h.num_channels == N && p < npix; p++)
        off += memcmp((uint32_t *)x.img.images[3] + p, rr_frame_ids(f) + p * N + 3, 4) != 0;
      CHECK(x.h.num_channels == N && off == 0, "exr channel id.s03 is not sample 3: %d pixels differ", off);
    }
    test_exr_free(&x);
    remove(path);
    snprintf(path, sizeof path, "%s/ids.png", dir);
    CHECK(rr_image_write(dev, &ids, path) == RR_ERROR_UNSUPPORTED, "per-sample ids as PNG: %s", rr_device_message(dev));
    rmdir(dir);
  }
  rr_image_free(&ids);
done:
  rr_frame_release(f);
  for (int k = 0; k < N; k++) rr_frame_release(one[k]);
  rr_scene_release(s);
}

/* The CLI: --aa-filter's values, --alpha as PNG RGBA, per-sample AOVs, bad values exit 2. */
static void test_cli(void) {
  char dir[] = "/tmp/rr_resolve_cli_XXXXXX", out[4096], path[256];
  if (!mkdtemp(dir)) return;
  static const char *const bad[] = {"gauss", "mitchell:9", "mitchell:abc", "box:0.1", "mitchell:", ""};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char args[256];
    snprintf(args, sizeof args, "render sphere --size 8x6 -o a.png --aa-filter '%s'", bad[i]);
    int rc = test_run_cli(dir, args, true, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--aa-filter") && strchr(out, '\n') == out + strlen(out) - 1,
          "--aa-filter '%s': exit %d, '%s'", bad[i], rc, out);
  }
  int rc = test_run_cli(dir,
                        "render sphere --size 24x18 --aa-filter blackman-harris:1.5 --alpha -o a.png "
                        "--aov sample-id,sample-depth=s.exr --aov coverage=c.npy --aov sample-mesh=m.npy",
                        true, out, sizeof out);
  CHECK(rc == 0, "--alpha: exit %d: %s", rc, out);
  rr_image img = {0};
  snprintf(path, sizeof path, "%s/a.png", dir);
  if (rc == 0 && rr_image_read(dev, path, &img) == RR_OK) {
    int clear = 0, solid = 0;
    for (int k = 0; k < 24 * 18; k++) clear += ((uint8_t *)img.data)[4 * k + 3] == 0, solid += ((uint8_t *)img.data)[4 * k + 3] == 255;
    CHECK(img.channels == 4 && clear > 0 && solid > 0, "a.png: %d channels, %d clear, %d solid", img.channels, clear,
          solid);
  }
  rr_image_free(&img);
  snprintf(path, sizeof path, "%s/m.npy", dir);
  char head[128] = {0};
  FILE *fp = fopen(path, "rb");
  if (fp) fread(head, 1, sizeof head - 1, fp), fclose(fp);
  CHECK(strstr(head + 10, "'shape': (18, 24, 1)") != NULL, "sample-mesh npy header: %s", head + 10);
  snprintf(out, sizeof out, "rm -rf '%s'", dir);
  CHECK(system(out) == 0, "cleanup");
}

int main(void) {
  if (!(dev = rr_device_new())) return 1;
  test_constant();
  test_box_identity();
  test_one_colour();
  test_spread();
  test_alpha();
  test_frame_outputs();
  test_cli();
  rr_device_release(dev);
  return test_done();
}
