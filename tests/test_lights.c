/* The lit shade mode: radiometry against closed forms (the E/π identity, the
 * inverse square law), shadows against an independent double-precision ray
 * test, mirror reflections against the mirrored scene rendered directly (a
 * textured one too, through the reflection rays' differentials), the
 * materials and lights of MTL, glTF and COLLADA files, and --light refusals. */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_lights_XXXXXX";
static rr_device *dev;

/* A scene of quads (4 corners each, in the order of a fan), each one mesh of colour rgb. */
static rr_scene *quads(int n, const float (*corners)[4][3], const float (*rgb)[3]) {
  rr_scene *s;
  if (rr_scene_new(dev, &s) != RR_OK) return NULL;
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  for (int q = 0; q < n; q++)
    CHECK(rr_scene_add_mesh(s, &corners[q][0][0], 4, idx, 2, rgb[q]) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_scene_commit(s) == RR_OK, "%s", rr_device_message(dev));
  return s;
}

static rr_camera view(float ex, float ey, float ez, float tx, float ty, float tz, float ux, float uy, float uz) {
  rr_camera c;
  rr_camera_init(&c);
  float e[3] = {ex, ey, ez}, t[3] = {tx, ty, tz}, u[3] = {ux, uy, uz};
  memcpy(c.eye, e, sizeof e), memcpy(c.target, t, sizeof t), memcpy(c.up, u, sizeof u);
  return c;
}

/* Renders (3dr-bb, one sample at pixel centres unless aa) and shades lit; the
 * linear RGB image (caller frees) and the frame in *frame (caller releases). */
static float *lit(const rr_scene *s, const rr_camera *cam, int w, int h, const rr_shade_options *so, rr_frame **frame,
                  rr_shade_stats *st) {
  rr_frame *f = test_render(dev, s, cam, RR_METHOD_3DR_BB, 2, w, h, 0);
  if (!f) return NULL;
  rr_shade_options def;
  if (!so) rr_shade_options_init(&def), def.mode = RR_SHADE_LIT, so = &def;
  rr_image img = {0};
  rr_shade_stats local;
  CHECK(rr_shade_frame(dev, s, cam, f, so, &img, st ? st : &local) == RR_OK, "lit: %s", rr_device_message(dev));
  if (frame) *frame = f;
  else rr_frame_release(f);
  return img.data;
}

static void add_light(rr_scene *s, rr_light_info l) {
  CHECK(rr_scene_add_light(s, &l) == RR_OK, "rr_scene_add_light: %s", rr_device_message(dev));
}

static bool near3(const float *v, float x, float y, float z, float tol) {
  return fabsf(v[0] - x) <= tol && fabsf(v[1] - y) <= tol && fabsf(v[2] - z) <= tol;
}

static float *aov(const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_aov a) {
  rr_image img = {0};
  CHECK(rr_frame_aov(dev, s, cam, f, a, &img) == RR_OK && img.channels == (a == RR_AOV_SHADOW ? 1 : 3) &&
            img.kind == RR_IMAGE_AOV + (int)a,
        "AOV %d: %s", (int)a, rr_device_message(dev));
  return img.data;
}

/* A white Lambert plane under a directional light of irradiance E has radiance
 * E cos θ / π, from every direction it is seen; shadow rays: one per pixel. */
static void check_radiance_identity(void) {
  static const float plane[1][4][3] = {{{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}}};
  static const float white[1][3] = {{1, 1, 1}};
  const float E[3] = {3.0f, 1.5f, 0.75f};
  for (int tilt = 0; tilt < 2; tilt++) {
    rr_scene *s = quads(1, plane, white);
    if (!s) return;
    double th = tilt ? RR_PI / 3 : 0; /* 60°: cos θ = 1/2 */
    rr_light_info l = {.type = RR_LIGHT_DIRECTIONAL, .direction = {(float)sin(th), (float)-cos(th), 0}};
    memcpy(l.color, E, sizeof E);
    add_light(s, l);
    rr_camera cams[2] = {view(0.2f, 3, 0.5f, 0, 0, 0, 0, 0, -1), view(-2, 1, 1.5f, 0, 0, 0, 0, 1, 0)};
    for (int c = 0; c < 2; c++) {
      enum { W = 48 };
      rr_frame *f = NULL;
      rr_shade_stats st;
      float *img = lit(s, &cams[c], W, W, NULL, &f, &st);
      int hits = 0, bad = 0;
      for (int k = 0; img && f && k < W * W; k++) {
        if (rr_frame_ids(f)[k] == RR_MISS) continue;
        hits++;
        for (int ch = 0; ch < 3; ch++) {
          double want = E[ch] * cos(th) / RR_PI;
          bad += fabs(img[3 * k + ch] - want) > 2e-6 * want;
        }
      }
      CHECK(hits > W * W / 8 && bad == 0, "tilt %d view %d: %d of %d pixels off E cos/pi", tilt, c, bad, hits);
      CHECK(st.shadow_rays == (uint64_t)hits && st.reflection_rays == 0, "%llu shadow rays for %d hits",
            (unsigned long long)st.shadow_rays, hits);
      free(img);
      rr_frame_release(f);
    }
    rr_scene_release(s);
  }
}

/* The world position of a frame's sample k, in double, from the quads' corners
 * and its barycentrics (ids are 2 per quad in order). */
static void sample_point(const rr_frame *f, int k, const float (*corners)[4][3], double p[3]) {
  uint32_t id = rr_frame_ids(f)[k];
  const float *q[4] = {corners[id / 2][0], corners[id / 2][1], corners[id / 2][2], corners[id / 2][3]};
  const float *v0 = q[0], *v1 = id % 2 ? q[2] : q[1], *v2 = id % 2 ? q[3] : q[2];
  double l1 = rr_frame_bary1(f)[k], l2 = rr_frame_bary2(f)[k], l0 = 1 - l1 - l2;
  for (int a = 0; a < 3; a++) p[a] = l0 * v0[a] + l1 * v1[a] + l2 * v2[a];
}

/* A point light's irradiance falls off as 1/d²: radiance I cos θ / (π d²) on a white plane. */
static void check_inverse_square(void) {
  static const float plane[1][4][3] = {{{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}}};
  static const float white[1][3] = {{1, 1, 1}};
  rr_scene *s = quads(1, plane, white);
  if (!s) return;
  const float I = 2.0f, L[3] = {0.3f, 1.0f, -0.2f};
  rr_light_info l = {.type = RR_LIGHT_POINT, .color = {I, I, I}};
  memcpy(l.position, L, sizeof L);
  add_light(s, l);
  rr_camera cam = view(0, 5, 0.01f, 0, 0, 0, 0, 0, -1);
  enum { W = 64 };
  rr_frame *f = NULL;
  float *img = lit(s, &cam, W, W, NULL, &f, NULL);
  int hits = 0, bad = 0;
  double near = INFINITY, far = 0;
  for (int k = 0; img && f && k < W * W; k++) {
    if (rr_frame_ids(f)[k] == RR_MISS) continue;
    double p[3], d[3], d2 = 0;
    sample_point(f, k, plane, p);
    for (int a = 0; a < 3; a++) d[a] = L[a] - p[a], d2 += d[a] * d[a];
    double want = I * (d[1] / sqrt(d2)) / (RR_PI * d2);
    hits++, near = fmin(near, d2), far = fmax(far, d2);
    bad += fabs(img[3 * k] - want) > 1e-4 * want;
  }
  CHECK(hits > W * W / 2 && far > 4 * near && bad == 0, "%d of %d pixels off I cos/(pi d^2) (d^2 %g..%g)", bad, hits,
        near, far);
  free(img);
  rr_frame_release(f);
  rr_scene_release(s);
}

/* A spot light: glTF's falloff, full inside the inner cone, the square of a linear
 * ramp in cos between the cones, nothing outside the outer one. */
static void check_spot(void) {
  static const float plane[1][4][3] = {{{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}}};
  static const float white[1][3] = {{1, 1, 1}};
  rr_scene *s = quads(1, plane, white);
  if (!s) return;
  const float I = 3.0f;
  rr_light_info l = {.type = RR_LIGHT_SPOT, .position = {0, 1, 0}, .direction = {0, -1, 0}, .color = {I, I, I},
                     .inner_cone_deg = 20, .outer_cone_deg = 40};
  add_light(s, l);
  rr_camera cam = view(0, 5, 0.01f, 0, 0, 0, 0, 0, -1);
  enum { W = 64 };
  rr_frame *f = NULL;
  float *img = lit(s, &cam, W, W, NULL, &f, NULL);
  int region[3] = {0, 0, 0}, bad = 0; /* outside, between, inside */
  double ci = cos(20 * RR_PI / 180), co = cos(40 * RR_PI / 180);
  for (int k = 0; img && f && k < W * W; k++) {
    if (rr_frame_ids(f)[k] == RR_MISS) continue;
    double p[3];
    sample_point(f, k, plane, p);
    double d2 = p[0] * p[0] + 1 + p[2] * p[2], cd = 1 / sqrt(d2); /* cos from the axis = cos from the normal */
    double t = fmin(fmax((cd - co) / (ci - co), 0), 1), want = I * t * t * cd / (RR_PI * d2);
    region[t <= 0 ? 0 : t >= 1 ? 2 : 1]++;
    bad += fabs(img[3 * k] - want) > 1e-4 * want + 1e-6;
  }
  CHECK(region[0] > 100 && region[1] > 100 && region[2] > 50 && bad == 0,
        "spot: %d of %d pixels off (%d outside, %d between, %d inside the cones)", bad,
        region[0] + region[1] + region[2], region[0], region[1], region[2]);
  free(img);
  rr_frame_release(f);
  rr_scene_release(s);
}

/* Möller–Trumbore in double: the t in (0, 1) where p + t·d meets triangle abc, or -1. */
static double ray_tri(const double p[3], const double d[3], const float *a, const float *b, const float *c) {
  double e1[3], e2[3], s[3], h[3], q[3];
  for (int k = 0; k < 3; k++) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], s[k] = p[k] - a[k];
  h[0] = d[1] * e2[2] - d[2] * e2[1], h[1] = d[2] * e2[0] - d[0] * e2[2], h[2] = d[0] * e2[1] - d[1] * e2[0];
  double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
  if (fabs(det) < 1e-300) return -1;
  double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
  q[0] = s[1] * e1[2] - s[2] * e1[1], q[1] = s[2] * e1[0] - s[0] * e1[2], q[2] = s[0] * e1[1] - s[1] * e1[0];
  double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
  double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
  return u >= 0 && v >= 0 && u + v <= 1 && t > 0 && t < 1 ? t : -1;
}

/* A quad over a plane under a point light: each plane pixel is dark exactly
 * where a double-precision segment test towards the light meets the quad (pixels
 * whose segment passes within 1e-4 of the quad's border are not judged), and
 * lit with I cos θ / (π d²) elsewhere. */
static void check_shadows(void) {
  static const float q[2][4][3] = {{{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}},
                                   {{-0.5f, 0.5f, -0.5f}, {-0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, -0.5f}}};
  static const float white[2][3] = {{1, 1, 1}, {1, 1, 1}};
  rr_scene *s = quads(2, q, white);
  if (!s) return;
  const float I = 4.0f, L[3] = {1.0f, 2.0f, 0.6f};
  rr_light_info l = {.type = RR_LIGHT_POINT, .color = {I, I, I}};
  memcpy(l.position, L, sizeof L);
  add_light(s, l);
  rr_camera cam = view(0, 5, 0.01f, 0, 0, 0, 0, 0, -1);
  enum { W = 160 };
  rr_frame *f = NULL;
  float *img = lit(s, &cam, W, W, NULL, &f, NULL), *shadow = f ? aov(s, &cam, f, RR_AOV_SHADOW) : NULL;
  int judged = 0, dark = 0, wrong = 0;
  for (int k = 0; img && f && k < W * W; k++) {
    if (rr_frame_ids(f)[k] >= 2) continue; /* the plane's */
    double p[3], d[3], d2 = 0;
    sample_point(f, k, q, p);
    for (int a = 0; a < 3; a++) d[a] = L[a] - p[a], d2 += d[a] * d[a];
    double t = fmax(ray_tri(p, d, q[1][0], q[1][1], q[1][2]), ray_tri(p, d, q[1][0], q[1][2], q[1][3]));
    double x = p[0] + (0.5 - p[1]) / d[1] * d[0], z = p[2] + (0.5 - p[1]) / d[1] * d[2]; /* at the quad's height */
    if (fabs(0.5 - fabs(x)) < 1e-4 || fabs(0.5 - fabs(z)) < 1e-4) continue;
    bool blocked = t > 0;
    double want = blocked ? 0 : I * (d[1] / sqrt(d2)) / (RR_PI * d2);
    judged++, dark += blocked;
    if (fabs(img[3 * k] - want) > 1e-4 * want + (blocked ? 0 : 1e-7) || !shadow || shadow[k] != !blocked) {
      if (wrong++ < 5) fprintf(stderr, "pixel %d (%g, %g): %g, expected %g\n", k, p[0], p[2], img[3 * k], want);
    }
  }
  printf("shadows: %d plane pixels judged, %d in shadow, %d wrong\n", judged, dark, wrong);
  CHECK(judged > W * W / 2 && dark > 300 && wrong == 0, "%d of %d plane pixels wrong (%d in shadow)", wrong, judged,
        dark);
  free(img), free(shadow);
  rr_frame_release(f);
  /* no shadows: no rays, every plane pixel lit */
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.shadows = RR_SHADOWS_NONE;
  rr_shade_stats st;
  free(lit(s, &cam, 32, 32, &so, NULL, &st));
  CHECK(st.shadow_rays == 0 && st.shades > 0, "shadows none traced %llu rays", (unsigned long long)st.shadow_rays);
  so.shadows = RR_SHADOWS_COUNT;
  rr_frame *fr = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, 8, 8, 0);
  rr_image im = {0};
  CHECK(fr && rr_shade_frame(dev, s, &cam, fr, &so, &im, NULL) == RR_ERROR_ARGUMENT && !im.data &&
            strstr(rr_device_message(dev), "shadow mode"),
        "unknown shadow mode: %s", rr_device_message(dev));
  so.shadows = RR_SHADOWS_RAYS, so.max_depth = RR_MAX_DEPTH + 1;
  CHECK(fr && rr_shade_frame(dev, s, &cam, fr, &so, &im, NULL) == RR_ERROR_ARGUMENT && !im.data, "max depth 17 accepted");
  rr_frame_release(fr);
  rr_scene_release(s);
}

static const char *write_file(const char *name, const char *text) { return test_write_file(dir, name, text); }

/* The shadow-lights AOV: a plane and a quad over it under a point light (blocked
 * where a double-precision segment test meets the quad), a directional light
 * along (-2, -1, 0) (blocked where the quad, shifted by -1 in x, covers the plane) and a spot pointing away (reaching
 * nothing); shadow is their mean, bit for bit as the passes add it; rays and
 * raster give the same bits, and asking for it changes no other image. */
static void check_shadow_lights(void) {
  static const float q[2][4][3] = {{{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}},
                                   {{-0.5f, 0.5f, -0.5f}, {-0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, -0.5f}}};
  static const float white[2][3] = {{1, 1, 1}, {1, 1, 1}};
  rr_scene *s = quads(2, q, white);
  if (!s) return;
  const float L[3] = {1.0f, 2.0f, 0.6f};
  add_light(s, (rr_light_info){.type = RR_LIGHT_POINT, .position = {L[0], L[1], L[2]}, .color = {4, 4, 4}});
  add_light(s, (rr_light_info){.type = RR_LIGHT_DIRECTIONAL, .direction = {-2, -1, 0}, .color = {1, 1, 1}});
  add_light(s, (rr_light_info){.type = RR_LIGHT_SPOT, .position = {0, 2, 0}, .direction = {0, 1, 0},
                               .color = {5, 5, 5}, .inner_cone_deg = 10, .outer_cone_deg = 30});
  rr_camera cam = view(0.1f, 5, 0.2f, 0, 0, 0, 0, 0, -1);
  enum { W = 96, NL = 3 };
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, W, W, 0);
  rr_image vis = {0};
  float *shadow = f ? aov(s, &cam, f, RR_AOV_SHADOW) : NULL;
  CHECK(f && rr_frame_aov(dev, s, &cam, f, RR_AOV_SHADOW_LIGHTS, &vis) == RR_OK && vis.channels == NL &&
            vis.type == RR_PIXEL_F32 && vis.kind == RR_IMAGE_AOV + RR_AOV_SHADOW_LIGHTS,
        "shadow-lights: %s", rr_device_message(dev));
  const float *v = vis.data;
  int judged = 0, blocked[2] = {0, 0}, wrong = 0, mean_wrong = 0;
  for (int k = 0; v && shadow && k < W * W; k++) {
    uint32_t id = rr_frame_ids(f)[k];
    const float *vk = v + NL * k;
    float mean = 0; /* as the passes add it: 1/L per light reaching, in order */
    for (int i = 0; i < NL; i++) mean += vk[i] != 0 ? 1.0f / NL : 0;
    mean_wrong += shadow[k] != (id == RR_MISS ? 0 : mean);
    if (id == RR_MISS) {
      wrong += vk[0] != 0 || vk[1] != 0 || vk[2] != 0;
      continue;
    }
    bool want[NL] = {true, true, false};
    if (id < 2) { /* the plane: blocked by the quad, judged away from its shadows' borders */
      double p[3], d[3];
      sample_point(f, k, q, p);
      for (int a = 0; a < 3; a++) d[a] = L[a] - p[a];
      double x = p[0] + (0.5 - p[1]) / d[1] * d[0], z = p[2] + (0.5 - p[1]) / d[1] * d[2];
      if (fabs(0.5 - fabs(x)) < 1e-4 || fabs(0.5 - fabs(z)) < 1e-4 || fabs(0.5 - fabs(p[0] + 1)) < 1e-4 ||
          fabs(0.5 - fabs(p[2])) < 1e-4)
        continue;
      want[0] = !(fmax(ray_tri(p, d, q[1][0], q[1][1], q[1][2]), ray_tri(p, d, q[1][0], q[1][2], q[1][3])) > 0);
      want[1] = !(fabs(p[0] + 1) < 0.5 && fabs(p[2]) < 0.5); /* the quad moved by 0.5 (2, 1, 0) */
    }
    judged++, blocked[0] += !want[0], blocked[1] += !want[1];
    for (int i = 0; i < NL; i++) wrong += vk[i] != (float)want[i];
  }
  printf("shadow-lights: %d pixels judged, %d and %d blocked from lights 0 and 1\n", judged, blocked[0], blocked[1]);
  CHECK(judged > W * W / 2 && blocked[0] > 100 && blocked[1] > 100 && wrong == 0,
        "%d wrong light visibilities of %d pixels (blocked %d, %d)", wrong, judged, blocked[0], blocked[1]);
  CHECK(mean_wrong == 0, "%d pixels where shadow is not the mean of shadow-lights", mean_wrong);
  /* from the colour's own passes: rays and raster the same bits as rr_frame_aov's; the
   * colour and shadow as without it */
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT;
  rr_image plain = {0};
  CHECK(f && rr_shade_frame(dev, s, &cam, f, &so, &plain, NULL) == RR_OK, "%s", rr_device_message(dev));
  for (int m = 0; f && m < 2; m++) {
    so.shadows = m ? RR_SHADOWS_RASTER : RR_SHADOWS_RAYS;
    rr_image aovs[RR_AOV_COUNT] = {{0}}, col = {0};
    unsigned want = 1u << RR_AOV_SHADOW | 1u << RR_AOV_SHADOW_LIGHTS;
    CHECK(rr_shade_frame_aovs(dev, s, &cam, f, &so, want, aovs, &col, NULL) == RR_OK, "%s", rr_device_message(dev));
    rr_image *sl = &aovs[RR_AOV_SHADOW_LIGHTS], *sh = &aovs[RR_AOV_SHADOW];
    CHECK(sl->data && sl->channels == NL && v && !memcmp(sl->data, v, sizeof(float) * NL * W * W),
          "shadows %d: shadow-lights differ from rr_frame_aov's", m);
    CHECK(sh->data && shadow && !memcmp(sh->data, shadow, sizeof(float) * W * W), "shadows %d: shadow differs", m);
    CHECK(col.data && plain.data && !memcmp(col.data, plain.data, sizeof(float) * 3 * W * W),
          "shadows %d: the colour changed with shadow-lights asked for", m);
    rr_image_free(sl), rr_image_free(sh), rr_image_free(&col);
  }
  rr_image_free(&plain), rr_image_free(&vis), free(shadow);
  /* no punctual light, or more than a channel each: refused, no image */
  rr_scene *bare = quads(1, q, white), *many = quads(1, q, white);
  for (int i = 0; many && i <= RR_MAX_SHADOW_LIGHTS; i++)
    add_light(many, (rr_light_info){.type = RR_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {0.1f, 0.1f, 0.1f}});
  so.shadows = RR_SHADOWS_RAYS, so.default_lights = 0;
  for (int k = 0; k < 2; k++) {
    rr_scene *t = k ? many : bare;
    rr_frame *g = t ? test_render(dev, t, &cam, RR_METHOD_3DR_BB, 1, 8, 8, 0) : NULL;
    rr_image aovs[RR_AOV_COUNT] = {{0}}, col = {0};
    CHECK(g && rr_shade_frame_aovs(dev, t, &cam, g, &so, 1u << RR_AOV_SHADOW_LIGHTS, aovs, &col, NULL) ==
                   RR_ERROR_ARGUMENT && !col.data && !aovs[RR_AOV_SHADOW_LIGHTS].data &&
              strstr(rr_device_message(dev), "shadow-lights"),
          "%s: %s", k ? "17 lights" : "no light", rr_device_message(dev));
    rr_frame_release(g);
  }
  rr_scene_release(bare), rr_scene_release(many);
  rr_frame_release(f);
  rr_scene_release(s);
  /* the CLI: an H×W×L .npy, an EXR layer, refused in PNG */
  write_file("sl.obj", "v -2 0 -2\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nv -0.5 0.5 -0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n"
                       "v 0.5 0.5 -0.5\nf 1 2 3 4\nf 5 6 7 8\n");
  char out[4096], path[600];
  int rc = test_run_cli(dir,
                        "render sl.obj --size 40x30 --shade lit --eye 0,5,0.2 --target 0,0,0 --up 0,0,-1 "
                        "--light point:1,2,0.6:1,1,1:4 --light dir:0,-1,0:1,1,1 --aov shadow-lights=sl.npy "
                        "--aov shadow,shadow-lights=sl.exr -o sl.png",
                        true, out, sizeof out);
  snprintf(path, sizeof path, "%s/sl.npy", dir);
  FILE *fp = fopen(path, "rb");
  char head[129] = {0};
  size_t n = fp ? fread(head, 1, 128, fp) : 0;
  long size = fp && fseek(fp, 0, SEEK_END) == 0 ? ftell(fp) : -1;
  if (fp) fclose(fp);
  CHECK(rc == 0 && n == 128 && strstr(head + 10, "'descr': '<f4'") && strstr(head + 10, "'shape': (30, 40, 2)") &&
            size == 128 + 30 * 40 * 2 * 4,
        "shadow-lights .npy: exit %d (%s), header '%s', %ld bytes", rc, out, head + 10, size);
  snprintf(path, sizeof path, "%s/sl.exr", dir);
  CHECK(access(path, F_OK) == 0, "no sl.exr");
  rc = test_run_cli(dir, "render sl.obj --size 8x8 --shade lit --aov shadow-lights=slb.png", true, out, sizeof out);
  snprintf(path, sizeof path, "%s/slb.png", dir);
  CHECK(rc != 0 && strstr(out, "PNG") && access(path, F_OK) != 0, "shadow-lights as PNG: exit %d: %s", rc, out);
}

/* OBJ text: a box [-0.4, 0.4] × [y0, y1] × [-0.4, 0.4] with material mtl (y0 > y1 mirrors it). */
static void box_obj(char *out, size_t cap, float y0, float y1, const char *mtl, int first_vertex) {
  int n = snprintf(out, cap, "o box\nusemtl %s\n", mtl);
  for (int v = 0; v < 8; v++)
    n += snprintf(out + n, cap - n, "v %g %g %g\n", v & 1 ? 0.4 : -0.4, v & 2 ? y1 : y0, v & 4 ? 0.4 : -0.4);
  static const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (int f = 0; f < 6; f++)
    n += snprintf(out + n, cap - n, "f %d %d %d %d\n", first_vertex + faces[f][0], first_vertex + faces[f][1],
                  first_vertex + faces[f][2], first_vertex + faces[f][3]);
}

/* The lit AOVs of the mirror scene: colour = direct + reflection + emission; the
 * box's albedo and emission are its MTL's Kd and Ke, the mirror's reflection is
 * the colour itself (Kd 0), and light reaches the box's top. */
static void check_parts(const rr_scene *s, const rr_camera *cam, const rr_frame *f, const float *colour) {
  float *albedo = aov(s, cam, f, RR_AOV_ALBEDO), *direct = aov(s, cam, f, RR_AOV_DIRECT),
        *refl = aov(s, cam, f, RR_AOV_REFLECTION), *emit = aov(s, cam, f, RR_AOV_EMISSION),
        *shadow = aov(s, cam, f, RR_AOV_SHADOW);
  int w, h, sums = 0, box = 0, mirror = 0, bad_sum = 0, bad_box = 0, bad_mirror = 0;
  rr_frame_get_size(f, &w, &h);
  for (int k = 0; albedo && direct && refl && emit && shadow && k < w * h; k++) {
    uint32_t g = RR_MISS;
    rr_scene_get_geometry(s, rr_frame_ids(f)[k], &g, NULL);
    if (g == RR_MISS) continue;
    rr_geometry_info gi;
    rr_scene_get_geometry_info(s, g, &gi);
    bool is_mirror = gi.name && strcmp(gi.name, "mirror") == 0;
    for (int c = 0; c < 3; c++) {
      float sum = direct[3 * k + c] + refl[3 * k + c] + emit[3 * k + c];
      bad_sum += fabsf(sum - colour[3 * k + c]) > 1e-5f * (1 + colour[3 * k + c]);
    }
    sums++;
    if (is_mirror) {
      mirror++;
      bad_mirror += !near3(albedo + 3 * k, 0, 0, 0, 0) || !near3(direct + 3 * k, 0, 0, 0, 0) ||
                    !near3(refl + 3 * k, colour[3 * k], colour[3 * k + 1], colour[3 * k + 2], 1e-6f);
    } else {
      box++;
      bad_box += !near3(albedo + 3 * k, 0.8f, 0.2f, 0.1f, 1e-6f) || !near3(emit + 3 * k, 0.05f, 0, 0, 1e-6f) ||
                 !near3(refl + 3 * k, 0, 0, 0, 0) || !(shadow[k] == 0 || shadow[k] == 1);
    }
  }
  CHECK(sums > 1000 && bad_sum == 0, "%d of %d pixels: colour != direct + reflection + emission", bad_sum, sums);
  CHECK(box > 100 && bad_box == 0, "%d of %d box pixels with wrong parts", bad_box, box);
  CHECK(mirror > 1000 && bad_mirror == 0, "%d of %d mirror pixels with wrong parts", bad_mirror, mirror);
  free(albedo), free(direct), free(refl), free(emit), free(shadow);
}

/* A mirror plane (MTL illum 3, Ks 1) under a glossy box shows what the box
 * mirrored in the plane, without the plane, shows directly (lights mirrored too). */
static void check_mirror(void) {
  write_file("m.mtl", "newmtl mirror\nKd 0 0 0\nKs 1 1 1\nillum 3\n"
                      "newmtl red\nKd 0.8 0.2 0.1\nKs 0.4 0.4 0.4\nNs 20\nKe 0.05 0 0\nillum 2\n");
  char a[4096], b[4096], box[2048];
  box_obj(box, sizeof box, 0.2f, 0.8f, "red", 5);
  snprintf(a, sizeof a, "mtllib m.mtl\no mirror\nusemtl mirror\nv -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3 4\n%s",
           box);
  box_obj(box, sizeof box, -0.2f, -0.8f, "red", 1);
  snprintf(b, sizeof b, "mtllib m.mtl\n%s", box);
  rr_scene *sa = NULL, *sb = NULL;
  CHECK(rr_scene_load(dev, write_file("a.obj", a), &sa) == RR_OK && rr_scene_load(dev, write_file("b.obj", b), &sb) == RR_OK,
        "mirror scenes: %s", rr_device_message(dev));
  if (!sa || !sb) goto done;
  rr_light_info sun = {.type = RR_LIGHT_DIRECTIONAL, .direction = {0.3f, -1, -0.4f}, .color = {3, 3, 3}};
  rr_light_info sky = {.type = RR_LIGHT_AMBIENT, .color = {0.2f, 0.2f, 0.25f}};
  add_light(sa, sun), add_light(sa, sky);
  sun.direction[1] = 1;
  add_light(sb, sun), add_light(sb, sky);
  rr_camera cam = view(0.3f, 1.2f, 3.0f, 0, -0.2f, 0, 0, 1, 0);
  enum { W = 96 };
  rr_frame *fa = NULL, *fb = NULL;
  rr_shade_stats st;
  float *ia = lit(sa, &cam, W, W, NULL, &fa, &st), *ib = lit(sb, &cam, W, W, NULL, &fb, NULL);
  int compared = 0, off = 0;
  double worst = 0;
  for (int k = 0; ia && ib && fa && fb && k < W * W; k++) {
    uint32_t g = RR_MISS;
    rr_scene_get_geometry(sa, rr_frame_ids(fa)[k], &g, NULL);
    rr_geometry_info gi;
    if (g == RR_MISS || rr_frame_ids(fb)[k] == RR_MISS || rr_scene_get_geometry_info(sa, g, &gi) != RR_OK ||
        !gi.name || strcmp(gi.name, "mirror") != 0)
      continue;
    compared++;
    for (int c = 0; c < 3; c++) {
      double e = fabs(ia[3 * k + c] - ib[3 * k + c]);
      worst = fmax(worst, e);
      off += e > 1e-3 + 1e-3 * ib[3 * k + c];
    }
  }
  printf("mirror: %d pixels compared, %d channels off, worst %g\n", compared, off, worst);
  CHECK(compared > 300 && off <= compared / 50, "mirror: %d of %d pixel channels differ from the mirrored scene (worst %g)",
        off, compared, worst);
  CHECK(st.reflection_rays > (uint64_t)compared, "%llu reflection rays", (unsigned long long)st.reflection_rays);
  check_parts(sa, &cam, fa, ia);
  /* max depth 0: no reflection rays, the mirror shows the sky */
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.max_depth = 0;
  free(lit(sa, &cam, 32, 32, &so, NULL, &st));
  CHECK(st.reflection_rays == 0, "max depth 0: %llu reflection rays", (unsigned long long)st.reflection_rays);
  free(ia), free(ib);
  rr_frame_release(fa), rr_frame_release(fb);
done:
  rr_scene_release(sa), rr_scene_release(sb);
}

/* The material of a file's first named material `name`, false when none. */
static bool material_named(const rr_scene *s, const char *name, rr_material_info *mi) {
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  for (uint32_t m = 0; m < in.materials; m++)
    if (rr_scene_get_material_info(s, m, mi) == RR_OK && mi->name && strcmp(mi->name, name) == 0) return true;
  return false;
}

static bool light_named(const rr_scene *s, const char *name, rr_light_info *li) {
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  for (uint32_t l = 0; l < in.lights; l++)
    if (rr_scene_get_light(s, l, li) == RR_OK && li->name && strcmp(li->name, name) == 0) return true;
  return false;
}

static void check_mtl(void) {
  write_file("p.mtl", "newmtl shiny\nKd 0.5 0.25 0.125\nKs 0.3 0.2 0.1\nKa 0.05 0.06 0.07\nKe 0 0.2 0\nNs 64\n"
                      "d 0.75\nillum 3\nmap_Ks spec.png\nmap_Bump bump.png\n"
                      "newmtl clear\nKd 1 1 1\nTr 0.25\n");
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_file("p.obj", "mtllib p.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl shiny\nf 1 2 3\n"
                                               "usemtl clear\nf 1 3 2\n"),
                      &s) == RR_OK,
        "%s", rr_device_message(dev));
  rr_material_info mi;
  if (s && material_named(s, "shiny", &mi)) {
    const rr_material_params *p = &mi.params;
    CHECK(p->model == RR_MATERIAL_PHONG && near3(mi.color, 0.5f, 0.25f, 0.125f, 1e-6f) &&
              near3(p->specular, 0.3f, 0.2f, 0.1f, 1e-6f) && near3(p->ambient, 0.05f, 0.06f, 0.07f, 1e-6f) &&
              near3(p->emission, 0, 0.2f, 0, 1e-6f) && p->shininess == 64 && fabsf(p->opacity - 0.75f) < 1e-6f &&
              p->illum == 3,
          "MTL shiny: model %d Ks %g Ns %g d %g illum %d", p->model, p->specular[0], p->shininess, p->opacity, p->illum);
    CHECK(mi.maps[RR_MAP_SPECULAR] && strcmp(mi.maps[RR_MAP_SPECULAR], "spec.png") == 0 && mi.maps[RR_MAP_NORMAL] &&
              strcmp(mi.maps[RR_MAP_NORMAL], "bump.png") == 0,
          "MTL maps: %s %s", mi.maps[RR_MAP_SPECULAR] ? mi.maps[RR_MAP_SPECULAR] : "-",
          mi.maps[RR_MAP_NORMAL] ? mi.maps[RR_MAP_NORMAL] : "-");
  } else {
    CHECK(0, "no material 'shiny'");
  }
  if (s && material_named(s, "clear", &mi))
    CHECK(fabsf(mi.params.opacity - 0.75f) < 1e-6f, "MTL Tr 0.25: opacity %g", mi.params.opacity);
  else CHECK(0, "no material 'clear'");
  rr_scene_release(s);
}

static void base64(const unsigned char *in, size_t n, char *out) {
  static const char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  size_t o = 0;
  for (size_t i = 0; i < n; i += 3) {
    unsigned v = in[i] << 16 | (i + 1 < n ? in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
    out[o++] = abc[v >> 18 & 63], out[o++] = abc[v >> 12 & 63];
    out[o++] = i + 1 < n ? abc[v >> 6 & 63] : '=', out[o++] = i + 2 < n ? abc[v & 63] : '=';
  }
  out[o] = 0;
}

static void check_gltf(void) {
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  char b64[64], text[4096];
  base64((const unsigned char *)pos, sizeof pos, b64);
  snprintf(text, sizeof text,
           "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
           "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
           "{\"type\":\"point\",\"color\":[1,0.5,0.25],\"intensity\":8,\"name\":\"bulb\"},"
           "{\"type\":\"spot\",\"intensity\":3,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.6},\"name\":\"cone\"},"
           "{\"type\":\"directional\",\"intensity\":2,\"name\":\"sun\"}]}},"
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3]}],"
           "\"nodes\":[{\"mesh\":0},{\"name\":\"bulb\",\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
           "{\"name\":\"cone\",\"translation\":[0,4,0],\"rotation\":[-0.70710678,0,0,0.70710678],"
           "\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
           "{\"name\":\"sun\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
           "\"materials\":[{\"name\":\"metal\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,0.125,1],"
           "\"metallicFactor\":0.25,\"roughnessFactor\":0.5},\"emissiveFactor\":[0.1,0.2,0.3]}],"
           "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
           "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
           b64);
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_file("l.gltf", text), &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  rr_material_info mi;
  if (material_named(s, "metal", &mi)) {
    const rr_material_params *p = &mi.params;
    CHECK(p->model == RR_MATERIAL_PBR && near3(mi.color, 0.5f, 0.25f, 0.125f, 1e-6f) && p->metallic == 0.25f &&
              p->roughness == 0.5f && near3(p->emission, 0.1f, 0.2f, 0.3f, 1e-6f),
          "glTF material: model %d metallic %g roughness %g emission %g", p->model, p->metallic, p->roughness,
          p->emission[0]);
  } else {
    CHECK(0, "no glTF material 'metal'");
  }
  rr_light_info li;
  CHECK(light_named(s, "bulb", &li) && li.type == RR_LIGHT_POINT && near3(li.color, 8, 4, 2, 1e-5f) &&
            near3(li.position, 1, 2, 3, 1e-5f),
        "glTF point light: type %d colour %g %g %g at %g %g %g", li.type, li.color[0], li.color[1], li.color[2],
        li.position[0], li.position[1], li.position[2]);
  CHECK(light_named(s, "cone", &li) && li.type == RR_LIGHT_SPOT && near3(li.color, 3, 3, 3, 1e-5f) &&
            near3(li.position, 0, 4, 0, 1e-5f) && near3(li.direction, 0, -1, 0, 1e-5f) &&
            fabsf(li.inner_cone_deg - 0.2f * 180 / (float)RR_PI) < 1e-3f &&
            fabsf(li.outer_cone_deg - 0.6f * 180 / (float)RR_PI) < 1e-3f,
        "glTF spot light: type %d dir %g %g %g cone %g %g", li.type, li.direction[0], li.direction[1], li.direction[2],
        li.inner_cone_deg, li.outer_cone_deg);
  CHECK(light_named(s, "sun", &li) && li.type == RR_LIGHT_DIRECTIONAL && near3(li.color, 2, 2, 2, 1e-5f) &&
            near3(li.direction, 0, 0, -1, 1e-5f),
        "glTF sun: type %d colour %g dir %g %g %g", li.type, li.color[0], li.direction[0], li.direction[1],
        li.direction[2]);
  /* the file's lights are the frame's: a point light 8 cd at distance √14 ... lights the triangle, no rig */
  rr_scene_release(s);
}

/* A glTF metallic–roughness plane under a directional light against the model
 * of shading.md evaluated in double: Lambert (1 - F) c (1 - m)/π plus GGX D,
 * height-correlated Smith and Schlick's F, per pixel with its own view direction. */
static void check_ggx(void) {
  static const float q[18] = {-1, 0, -1, -1, 0, 1, 1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0, -1};
  const double base[3] = {0.8, 0.5, 0.2}, m = 0.5, r = 0.4, E = 2, L[3] = {0.3, -1, 0.2};
  char b64[128], text[2048];
  base64((const unsigned char *)q, sizeof q, b64);
  snprintf(text, sizeof text,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
           "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[%g,%g,%g,1],\"metallicFactor\":%g,"
           "\"roughnessFactor\":%g}}],\"buffers\":[{\"byteLength\":72,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":72}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
           "\"count\":6,\"type\":\"VEC3\",\"min\":[-1,0,-1],\"max\":[1,0,1]}]}",
           base[0], base[1], base[2], m, r, b64);
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_file("ggx.gltf", text), &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  rr_light_info sun = {.type = RR_LIGHT_DIRECTIONAL, .direction = {(float)L[0], (float)L[1], (float)L[2]},
                       .color = {(float)E, (float)E, (float)E}};
  add_light(s, sun);
  const float eye[3] = {0.6f, 2.0f, 0.4f}; /* the light's mirror direction from the centre: the highlight in view */
  rr_camera cam = view(eye[0], eye[1], eye[2], 0, 0, 0, 0, 0, -1);
  enum { W = 64 };
  rr_frame *f = NULL;
  float *img = lit(s, &cam, W, W, NULL, &f, NULL);
  int hits = 0, bad = 0;
  double top = 0, low = INFINITY;
  double ll = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]), l[3] = {-L[0] / ll, -L[1] / ll, -L[2] / ll};
  for (int k = 0; img && f && k < W * W; k++) {
    uint32_t id = rr_frame_ids(f)[k];
    if (id == RR_MISS) continue;
    double p[3], v[3], vl = 0, l1 = rr_frame_bary1(f)[k], l2 = rr_frame_bary2(f)[k];
    for (int a = 0; a < 3; a++)
      p[a] = (1 - l1 - l2) * q[9 * id + a] + l1 * q[9 * id + 3 + a] + l2 * q[9 * id + 6 + a], v[a] = eye[a] - p[a],
      vl += v[a] * v[a];
    double h[3], hl = 0;
    for (int a = 0; a < 3; a++) v[a] /= sqrt(vl), h[a] = v[a] + l[a], hl += h[a] * h[a];
    double nl = l[1], nv = v[1], nh = h[1] / sqrt(hl), vh = (v[0] * h[0] + v[1] * h[1] + v[2] * h[2]) / sqrt(hl);
    double a2 = r * r * r * r, D = a2 / (RR_PI * pow(nh * nh * (a2 - 1) + 1, 2));
    double V = 0.5 / (nl * sqrt(nv * nv * (1 - a2) + a2) + nv * sqrt(nl * nl * (1 - a2) + a2));
    hits++;
    for (int c = 0; c < 3; c++) {
      double F0 = 0.04 * (1 - m) + base[c] * m, F = F0 + (1 - F0) * pow(1 - vh, 5);
      double want = ((1 - F) * base[c] * (1 - m) / RR_PI + F * D * V) * E * nl;
      bad += fabs(img[3 * k + c] - want) > 1e-4 * want;
      if (c == 0) top = fmax(top, want), low = fmin(low, want);
    }
  }
  CHECK(hits > W * W / 4 && top > 1.5 * low && bad == 0, "GGX: %d of %d pixel channels off (radiance %g..%g)", bad,
        3 * hits, low, top);
  free(img);
  rr_frame_release(f);
  rr_scene_release(s);
}

static void check_collada(void) {
  const char *dae =
      "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
      "<asset><up_axis>Y_UP</up_axis></asset>"
      "<library_lights><light id=\"lamp\" name=\"lamp\"><technique_common><point><color>2 1 0.5</color>"
      "<constant_attenuation>1</constant_attenuation><linear_attenuation>0</linear_attenuation>"
      "<quadratic_attenuation>0</quadratic_attenuation></point></technique_common></light>"
      "<light id=\"sun\" name=\"sun\"><technique_common><directional><color>1 1 1</color></directional>"
      "</technique_common></light></library_lights>"
      "<library_effects><effect id=\"fx\"><profile_COMMON><technique sid=\"t\"><phong>"
      "<emission><color>0 0.1 0 1</color></emission><diffuse><color>0.5 0.4 0.3 1</color></diffuse>"
      "<specular><color>0.2 0.2 0.2 1</color></specular><shininess><float>30</float></shininess>"
      "</phong></technique></profile_COMMON></effect></library_effects>"
      "<library_materials><material id=\"mat\" name=\"mat\"><instance_effect url=\"#fx\"/></material></library_materials>"
      "<library_geometries><geometry id=\"g\"><mesh><source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0"
      "</float_array><technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
      "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
      "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices><triangles material=\"m\" count=\"1\">"
      "<input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles></mesh></geometry>"
      "</library_geometries><library_visual_scenes><visual_scene id=\"s\"><node id=\"tri\" name=\"tri\">"
      "<instance_geometry url=\"#g\"><bind_material><technique_common><instance_material symbol=\"m\" target=\"#mat\"/>"
      "</technique_common></bind_material></instance_geometry></node>"
      "<node id=\"lampnode\" name=\"lamp\"><translate>1 2 3</translate><instance_light url=\"#lamp\"/></node>"
      "<node id=\"sunnode\" name=\"sun\"><rotate>1 0 0 -90</rotate><instance_light url=\"#sun\"/></node>"
      "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>\n";
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_file("l.dae", dae), &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  rr_material_info mi;
  if (material_named(s, "mat", &mi))
    CHECK(mi.params.model == RR_MATERIAL_PHONG && near3(mi.color, 0.5f, 0.4f, 0.3f, 1e-6f) &&
              near3(mi.params.specular, 0.2f, 0.2f, 0.2f, 1e-6f) && mi.params.shininess == 30 &&
              near3(mi.params.emission, 0, 0.1f, 0, 1e-6f),
          "COLLADA material: Ks %g Ns %g Ke %g", mi.params.specular[0], mi.params.shininess, mi.params.emission[1]);
  else CHECK(0, "no COLLADA material 'mat'");
  rr_light_info li;
  /* assimp names a COLLADA light after its node's id */
  CHECK(light_named(s, "lampnode", &li) && li.type == RR_LIGHT_POINT && near3(li.color, 2, 1, 0.5f, 1e-6f) &&
            near3(li.position, 1, 2, 3, 1e-5f),
        "COLLADA lamp: type %d colour %g at %g %g %g", li.type, li.color[0], li.position[0], li.position[1],
        li.position[2]);
  CHECK(light_named(s, "sunnode", &li) && li.type == RR_LIGHT_DIRECTIONAL && near3(li.direction, 0, -1, 0, 1e-5f),
        "COLLADA sun: type %d dir %g %g %g", li.type, li.direction[0], li.direction[1], li.direction[2]);
  rr_scene_release(s);
}

/* rr_scene_add_light refuses what it cannot shade; MSAA shades once per pixel and primitive in lit too. */
static void check_api(void) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, "plane:1", &s) != RR_OK) return;
  const rr_light_info bad[] = {
      {.type = RR_LIGHT_AREA, .color = {1, 1, 1}},
      {.type = RR_LIGHT_POINT, .color = {1, NAN, 1}},
      {.type = RR_LIGHT_POINT, .color = {1, -1, 1}},
      {.type = RR_LIGHT_DIRECTIONAL, .color = {1, 1, 1}},
      {.type = RR_LIGHT_SPOT, .direction = {0, -1, 0}, .color = {1, 1, 1}, .inner_cone_deg = 50, .outer_cone_deg = 40},
      {.type = RR_LIGHT_AMBIENT, .color = {1, 1, 1}, .ground = {-1, 0, 0}},
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
    CHECK(rr_scene_add_light(s, &bad[k]) == RR_ERROR_ARGUMENT && !strchr(rr_device_message(dev), '\n'),
          "bad light %zu accepted", k);
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.lights == 0, "%u lights after refusals", in.lights);
  /* a material made a mirror through the API reflects; bad values are refused */
  rr_material_info mi;
  CHECK(rr_scene_get_material_info(s, 0, &mi) == RR_OK, "%s", rr_device_message(dev));
  rr_material_params mirror = mi.params, bad_params = mi.params;
  mirror.illum = 3, mirror.specular[0] = mirror.specular[1] = mirror.specular[2] = 0.5f;
  const float grey[3] = {0.25f, 0.25f, 0.25f};
  CHECK(rr_scene_set_material(s, 0, grey, &mirror) == RR_OK && rr_scene_get_material_info(s, 0, &mi) == RR_OK &&
            mi.params.illum == 3 && mi.color[0] == 0.25f,
        "rr_scene_set_material: %s", rr_device_message(dev));
  bad_params.roughness = 2;
  CHECK(rr_scene_set_material(s, 0, NULL, &bad_params) == RR_ERROR_ARGUMENT &&
            rr_scene_set_material(s, 0, (const float[3]){0, NAN, 0}, NULL) == RR_ERROR_ARGUMENT &&
            rr_scene_set_material(s, 99, grey, NULL) == RR_ERROR_ARGUMENT,
        "bad materials accepted");
  rr_shade_stats mst;
  rr_camera top = view(0.5f, 0.5f, 0.5f, 0.5f, 0, 0.5f, 0, 0, -1);
  free(lit(s, &top, 16, 16, NULL, NULL, &mst));
  CHECK(mst.reflection_rays == 16 * 16, "a mirror set through the API: %llu reflection rays",
        (unsigned long long)mst.reflection_rays);
  mirror.illum = 2;
  rr_scene_set_material(s, 0, NULL, &mirror);
  rr_camera cam = view(0.5f, 0.5f, 0.5f, 0.5f, 0, 0.5f, 0, 0, -1);
  rr_shade_options so;
  rr_shade_options_init(&so);
  for (int mode = 0; mode < 2; mode++) { /* default rig, then a spot light */
    uint64_t shades[2];
    for (int m = 0; m < 2; m++) {
      rr_render_options o;
      rr_render_options_init(&o);
      o.width = o.height = 32, o.threads = 2, o.method = RR_METHOD_3DR_BB;
      rr_render_options_set_aa(dev, &o, RR_AA_MSAA, 4, 0, RR_AA_STANDARD, 0);
      rr_frame *f = test_render_opt(dev, s, &cam, &o);
      rr_image img = {0};
      rr_shade_stats st = {0};
      so.mode = m ? RR_SHADE_LIT : RR_SHADE_LAMBERT;
      CHECK(f && rr_shade_frame(dev, s, &cam, f, &so, &img, &st) == RR_OK, "%s", rr_device_message(dev));
      float lo = INFINITY;
      for (int k = 0; img.data && k < 32 * 32 * 3; k++) lo = fminf(lo, ((float *)img.data)[k]);
      CHECK(!m || lo > 0.05f, "lit with %s: a pixel as dark as %g", mode ? "a spot" : "the rig", lo);
      shades[m] = st.shades;
      rr_image_free(&img);
      rr_frame_release(f);
    }
    CHECK(shades[0] == shades[1], "msaa:4 shades %llu lambert, %llu lit", (unsigned long long)shades[0],
          (unsigned long long)shades[1]);
    rr_light_info spot = {.type = RR_LIGHT_SPOT, .position = {0.5f, 1, 0.5f}, .direction = {0, -1, 0},
                          .color = {5, 5, 5}, .outer_cone_deg = 80};
    add_light(s, spot);
  }
  rr_scene_release(s);
}

/* Lit images are the same bits for any method and thread count: shading reads only
 * the visibility, and each run of pixels is shaded alone. */
static void check_same_bits(void) {
  rr_scene *s = NULL;
  if (rr_scene_load(dev, "demo", &s) != RR_OK) {
    CHECK(0, "demo: %s", rr_device_message(dev));
    return;
  }
  enum { W = 96, H = 72 };
  rr_camera cam;
  rr_camera_init(&cam);
  CHECK(rr_camera_frame(dev, s, W, H, &cam) == RR_OK, "%s", rr_device_message(dev));
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT;
  float *ref = NULL;
  const struct {
    rr_method m;
    int threads;
  } runs[] = {{RR_METHOD_3DR_BB, 1}, {RR_METHOD_RC_BVH, 2}, {RR_METHOD_3DR_FULL, 8}};
  for (int r = 0; r < 3; r++) {
    rr_frame *f = test_render(dev, s, &cam, runs[r].m, runs[r].threads, W, H, 0);
    rr_image img = {0};
    CHECK(f && rr_shade_frame(dev, s, &cam, f, &so, &img, NULL) == RR_OK, "%s", rr_device_message(dev));
    if (r == 0) ref = img.data;
    else CHECK(ref && img.data && memcmp(ref, img.data, sizeof(float) * 3 * W * H) == 0, "%s on %d threads: other bits",
               rr_method_name(runs[r].m), runs[r].threads);
    if (r) rr_image_free(&img);
    rr_frame_release(f);
  }
  free(ref);
  rr_scene_release(s);
}

/* --light's and --shadows' refusals: exit 2, one line naming the problem, no image. */
static void check_cli(void) {
  write_file("tri.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
  const struct {
    const char *args, *says;
  } bad[] = {
      {"--light area:0,0,0:1,1,1", "area:0,0,0"},
      {"--light point:1,2,3", "point:1,2,3"},
      {"--light point:1,2:1,1,1", "1,2"},
      {"--light point:1,2,3:1,1,1:-2", "negative"},
      {"--light point:1,2,3:1,1,1:2:3", "point:1,2,3"},
      {"--light dir:0,0,0:1,1,1", "zero direction"},
      {"--light spot:0,1,0:0,-1,0:1,1,1:1:50:40", "cone"},
      {"--light sky:1,-1,1", "negative"},
      {"--light sky:1,1,1:0,0,nan", "nan"},
      {"--shadows soft", "soft"},
      {"--max-depth 17", "17"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    char args[256], out[2048];
    snprintf(args, sizeof args, "render tri.obj %s -o bad.png", bad[k].args);
    int rc = test_run_cli(dir, args, true, out, sizeof out);
    char png[600];
    snprintf(png, sizeof png, "%s/bad.png", dir);
    size_t n = strlen(out);
    CHECK(rc == 2 && n > 0 && strchr(out, '\n') == out + n - 1 && strstr(out, bad[k].says) && access(png, F_OK) != 0,
          "%s: exit %d, said '%s'", bad[k].args, rc, out);
  }
  char out[4096];
  int rc = test_run_cli(dir,
                        "render tri.obj --size 32x32 --light point:0,0,2:1,1,1:5 --light spot:0,0,2:0,0,-1:1,1,1:3:10:30 "
                        "--light dir:0,0,-1:1,1,1 --light sky:0.1,0.1,0.1:0,0,0 --shadows none --max-depth 0 "
                        "-o good.png --stats",
                        true, out, sizeof out);
  CHECK(rc == 0 && strstr(out, "shadow_rays=0"), "good lights: exit %d: %s", rc, out);
  /* the flags' numbers land where they belong: a directional light of 3 lux, then a
   * point light of 4 cd 2 units in front, on the OBJ's default grey 0.6 facing them */
  const struct {
    const char *light;
    double most; /* the brightest pixel's radiance */
  } good[] = {{"dir:0,0,-1:1,0.5,0.25:3", 0.6 * 3 / RR_PI}, {"point:0,0,2:1,0.5,0.25:4", 0.6 * 4 / (RR_PI * 4)}};
  for (int k = 0; k < 2; k++) {
    char args[256], path[600];
    snprintf(args, sizeof args, "render tri.obj --size 65x65 --light %s -o c.pfm", good[k].light);
    snprintf(path, sizeof path, "%s/c.pfm", dir);
    rr_image img = {0};
    CHECK(test_run_cli(dir, args, true, out, sizeof out) == 0 && rr_image_read(dev, path, &img) == RR_OK,
          "%s: %s", args, out);
    float top[3] = {0, 0, 0}; /* the reddest pixel (the background is bluish) */
    for (int i = 0; img.data && i < 65 * 65; i++)
      if (((float *)img.data)[3 * i] > top[0]) memcpy(top, (float *)img.data + 3 * i, sizeof top);
    CHECK(fabs(top[0] - good[k].most) < 0.01 * good[k].most && fabs(top[1] - 0.5 * good[k].most) < 0.01 * good[k].most &&
              fabs(top[2] - 0.25 * good[k].most) < 0.01 * good[k].most,
          "--light %s: brightest (%g, %g, %g), expected %g at most in red", good[k].light, top[0], top[1], top[2],
          good[k].most);
    rr_image_free(&img);
  }
}

/* A textured plane seen in a mirror plane looks as its mirror image seen directly: the
 * reflection rays carry the camera's differentials (reflected), so the texture
 * filters read the same footprints. The texture (8 texels a unit, one per square)
 * is minified well below a texel a pixel, where a lookup without a footprint
 * aliases; the sky lights both sides alike. */
static void check_mirror_texture(void) {
  uint8_t texels[8 * 8 * 3];
  for (int k = 0; k < 64; k++) memset(texels + 3 * k, ((k % 8) + (k / 8)) % 2 ? 230 : 20, 3);
  rr_image tex = {.width = 8, .height = 8, .channels = 3, .type = RR_PIXEL_U8, .data = texels};
  char png[700];
  snprintf(png, sizeof png, "%s/fine.png", dir);
  CHECK(rr_image_write(dev, &tex, png) == RR_OK, "texture: %s", rr_device_message(dev));
  const char *textured = "{\"point\": [0, %d, 0], \"normal\": [0, 1, 0], \"material\": {\"texture\": \"fine.png\"}}";
  char plane_a[256], plane_b[256], a[1024], b[1024];
  snprintf(plane_a, sizeof plane_a, textured, 3), snprintf(plane_b, sizeof plane_b, textured, -3);
  const char *sky = "\"lights\": [{\"type\": \"sky\", \"color\": [1, 1, 1], \"ground\": [1, 1, 1]}]";
  snprintf(a, sizeof a, "{\"planes\": [{\"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": {\"color\": [0, 0, 0], "
           "\"specular\": [1, 1, 1], \"mirror\": true}}, %s], %s}", plane_a, sky);
  snprintf(b, sizeof b, "{\"planes\": [%s], %s}", plane_b, sky);
  rr_scene *sa = NULL, *sb = NULL;
  CHECK(rr_scene_load_file(dev, write_file("ma.json", a), NULL, &sa, NULL) == RR_OK &&
            rr_scene_load_file(dev, write_file("mb.json", b), NULL, &sb, NULL) == RR_OK,
        "mirror texture scenes: %s", rr_device_message(dev));
  rr_camera cam = view(0, 0.5f, 0, 0.3f, 0, 3, 0, 1, 0);
  enum { W = 96 };
  for (int f = 0; sa && sb && f < 2; f++) {
    rr_shade_options so;
    rr_shade_options_init(&so);
    so.mode = RR_SHADE_LIT, so.texture_filter = f ? RR_TEXTURE_ANISO : RR_TEXTURE_TRILINEAR;
    rr_shade_stats st;
    rr_frame *fa = NULL;
    float *ia = lit(sa, &cam, W, W, &so, &fa, &st), *ib = lit(sb, &cam, W, W, &so, NULL, NULL);
    int off = 0, compared = 0;
    double worst = 0;
    for (int k = 0; ia && ib && fa && k < W * W; k++) {
      uint32_t g = RR_MISS;
      rr_scene_get_geometry(sa, rr_frame_ids(fa)[k], &g, NULL);
      if (g != 0) continue; /* the mirror's pixels (above the horizon A sees the plane itself) */
      compared++;
      for (int c = 0; c < 3; c++) {
        double e = fabs(ia[3 * k + c] - ib[3 * k + c]);
        worst = fmax(worst, e);
        off += e > 0.01 + 0.01 * ib[3 * k + c];
      }
    }
    CHECK(compared > W * W / 3 && st.reflection_rays >= (uint64_t)compared && off <= compared / 100,
          "%s: %d of %d mirror pixels' channels differ from the mirrored plane seen directly (worst %g)",
          rr_texture_filter_name(so.texture_filter), off, compared, worst);
    rr_frame_release(fa);
    free(ia), free(ib);
  }
  rr_scene_release(sa), rr_scene_release(sb);
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  dev = rr_device_new();
  check_radiance_identity();
  check_inverse_square();
  check_spot();
  check_shadows();
  check_shadow_lights();
  check_mirror();
  check_mirror_texture();
  check_mtl();
  check_gltf();
  check_ggx();
  check_collada();
  check_api();
  check_same_bits();
  check_cli();
  rr_device_release(dev);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
  return test_done();
}
