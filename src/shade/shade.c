/* Deferred shading: reads only the visibility buffer (id, t, λ1, λ2) and the
 * scene, so it never knows which method made the frame. */
#include "vis/vis.h"
#include "core/color.h"
#include "shade/light.h"
#include "shade/resolve.h"
#include "shade/texcoord.h"

#include <stdio.h>
#include <string.h>

/* stb_easy_font is header-only with static functions; only some are used. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

typedef struct hit {
  bool valid, has_ray;
  uint32_t id;
  vec3 dir;    /* unit ray direction */
  float dist;  /* eye-to-hit distance */
  vec3 normal; /* unit shading normal facing the eye */
  float l0, l1, l2;
  float t;           /* along the ray org + t·ray (ray unnormalised) */
  vec3 org, ray;
  const camera *cam; /* the ray is camera cam's at pixel (x, y), whose differentials give the */
  int x, y;          /* texture footprint; NULL for other rays (reflections): */
  const vec3 *diff;  /* their differentials (origin x, y, direction x, y), NULL: none */
  float footprint; /* the pixel steps the sample's texture footprint spans (ssaa: 1/√N) */
} hit;

/* (l1, l2: the hit's coordinates, which give an analytic primitive's normal) */
static vec3 geometric_normal(const rr_scene *s, uint32_t i, float l1, float l2) {
  if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) return rr_ana_normal(s, i, l1, l2);
  if (scene_inf(s, i)) return v3_norm(rr_scene_tri_normal(s, i)); /* corners at infinity */
  vec3 c[3];
  scene_corners(s, i, c);
  return v3_norm(v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0])));
}

/* The shading inputs of triangle `id` at barycentrics (l1, l2), seen along the ray
 * o + t·d (d unnormalised) at parameter t, camera c's at pixel (x, y) (c NULL:
 * another ray); not valid on a miss. */
static hit hit_make(const rr_scene *s, uint32_t id, float l1, float l2, float t, vec3 o, vec3 d, const camera *c,
                    int x, int y) {
  hit h = {.has_ray = true, .id = id, .t = t, .org = o, .ray = d, .cam = c, .x = x, .y = y, .footprint = 1.0f};
  if (id == RR_MISS || id >= s->ntris) return h;
  h.valid = true;
  float len = v3_len(d);
  h.dir = v3_scale(d, 1.0f / len);
  h.dist = t * len;
  h.l1 = l1, h.l2 = l2, h.l0 = 1.0f - l1 - l2;
  vec3 n = geometric_normal(s, id, l1, l2);
  if (s->n[0][0] && scene_kind(s, id) == RR_GEOMETRY_TRIANGLE) {
    vec3 sn = v3(0, 0, 0), c[3];
    float w[3] = {h.l0, h.l1, h.l2};
    scene_normals(s, id, c);
    for (int v = 0; v < 3; v++) sn = v3_add(sn, v3_scale(c[v], w[v]));
    if (v3_dot(sn, sn) > 1e-12f) {
      sn = v3_norm(sn);
      /* keep interpolated normals on the geometric normal's side */
      n = v3_dot(sn, n) < 0 ? v3_neg(sn) : sn;
    }
  }
  h.normal = v3_dot(n, h.dir) > 0 ? v3_neg(n) : n;
  return h;
}

/* The hit of entry i of the visibility buffer (a sample of pixel (x, y)) seen by c. */
static hit sample_hit(const rr_scene *s, const camera *c, const visbuf *vb, size_t i, int x, int y) {
  vec3 o, d;
  if (!rr_cam_ray(c, x, y, &o, &d)) return (hit){.id = vb->id[i]};
  return hit_make(s, vb->id[i], vb->l1[i], vb->l2[i], vb->t[i], o, d, c, x, y);
}

/* Sample 0 of pixel (x, y). */
static hit hit_at(const rr_scene *s, const camera *c, const visbuf *vb, int x, int y) {
  return sample_hit(s, c, vb, ((size_t)y * vb->width + x) * vb->ns, x, y); /* vb: one layer */
}

/* The hit's ray's differentials over the sample's footprint (a camera's, scaled to
 * it, or a reflection's as carried); false when it has none. */
static bool hit_diffs(const hit *h, vec3 do_dxy[2], vec3 dd_dxy[2]) {
  vec3 o, d;
  if (h->diff) {
    do_dxy[0] = h->diff[0], do_dxy[1] = h->diff[1], dd_dxy[0] = h->diff[2], dd_dxy[1] = h->diff[3];
    return true;
  }
  if (!h->cam) return false;
  rr_cam_ray_diff(h->cam, h->x, h->y, &o, &d, do_dxy, dd_dxy);
  for (int k = 0; k < 2; k++)
    do_dxy[k] = v3_scale(do_dxy[k], h->footprint), dd_dxy[k] = v3_scale(dd_dxy[k], h->footprint);
  return true;
}

/* The texture coordinates of a valid hit on a triangle with UVs; with derivs, their
 * derivatives over the sample's footprint too (else 0). */
static tex_coord hit_texcoord(const rr_scene *s, const hit *h, bool derivs) {
  vec3 do_dxy[2], dd_dxy[2];
  derivs = derivs && hit_diffs(h, do_dxy, dd_dxy);
  return rr_texcoord(s, h->id, h->l1, h->l2, h->t, h->org, h->ray, derivs ? do_dxy : NULL, derivs ? dd_dxy : NULL);
}

/* How a mirror's point, view direction and shading normal move per pixel step
 * (Igehy's ray differentials), for its reflection ray's: the hit slides on the
 * tangent plane, ∂p = w − d (n_g·w)/(n_g·d) with w = ∂o + t ∂d; the unit view
 * v = −d/|d| turns by ∂v = −(∂d − d̂ (d̂·∂d))/|d|; the normal turns with the surface:
 * a sphere's by ∂p/r, an interpolated one by its corners' normals weighed by the
 * barycentrics' change along ∂p; flat faces (planes, boxes, triangles without
 * corner normals) not at all. */
static void mirror_diffs(const rr_scene *s, const hit *h, surface *sf) {
  vec3 do_dxy[2], dd_dxy[2], d = h->ray;
  sf->diff = rr_material_mirror(sf->m) && hit_diffs(h, do_dxy, dd_dxy);
  float nd = v3_dot(sf->ng, d), len = v3_len(d);
  if (!sf->diff || !(nd != 0)) {
    sf->diff = false;
    return;
  }
  uint32_t i = h->id;
  bool smooth = scene_kind(s, i) == RR_GEOMETRY_TRIANGLE && s->n[0][0] && !scene_inf(s, i);
  vec3 ga, gb, e1n, e2n, big_n;
  if (smooth) { /* the barycentrics' gradients in the plane (texcoord.c's dual basis) */
    vec3 p0 = scene_vertex(s, 0, i), e1 = v3_sub(scene_vertex(s, 1, i), p0), e2 = v3_sub(scene_vertex(s, 2, i), p0);
    vec3 n = v3_cross(e1, e2);
    float nn = v3_dot(n, n);
    ga = v3_scale(v3_cross(e2, n), 1.0f / nn), gb = v3_scale(v3_cross(n, e1), 1.0f / nn);
    vec3 c[3];
    for (int v = 0; v < 3; v++) c[v] = scene_normal(s, v, i);
    e1n = v3_sub(c[1], c[0]), e2n = v3_sub(c[2], c[0]);
    big_n = v3_add(v3_add(v3_scale(c[0], h->l0), v3_scale(c[1], h->l1)), v3_scale(c[2], h->l2));
  }
  for (int k = 0; k < 2; k++) {
    vec3 w = v3_add(do_dxy[k], v3_scale(dd_dxy[k], h->t));
    sf->dp[k] = v3_sub(w, v3_scale(d, v3_dot(sf->ng, w) / nd));
    vec3 dd = v3_scale(dd_dxy[k], 1.0f / len);
    sf->dv[k] = v3_neg(v3_sub(dd, v3_scale(h->dir, v3_dot(h->dir, dd))));
    sf->dn[k] = v3(0, 0, 0);
    if (scene_kind(s, i) == RR_GEOMETRY_SPHERE) {
      const float *a = rr_ana_params(s, i);
      float side = v3_dot(sf->n, v3_sub(sf->p, v3(a[0], a[1], a[2]))) >= 0 ? 1.0f : -1.0f;
      sf->dn[k] = v3_scale(sf->dp[k], side / a[3]);
    } else if (smooth) {
      float len_n = v3_len(big_n);
      vec3 dN = v3_add(v3_scale(e1n, v3_dot(ga, sf->dp[k])), v3_scale(e2n, v3_dot(gb, sf->dp[k])));
      vec3 nh = v3_scale(big_n, 1.0f / len_n);
      float side = v3_dot(sf->n, nh) >= 0 ? 1.0f : -1.0f;
      sf->dn[k] = v3_scale(v3_sub(dN, v3_scale(nh, v3_dot(nh, dN))), side / len_n);
    }
  }
}

static void base_color(const rr_scene *s, const hit *h, const tex_filter *tf, float rgb[3]) {
  const rr_material *m = s->nmaterials ? &s->materials[scene_material(s, h->id) % s->nmaterials] : NULL;
  rgb[0] = rgb[1] = rgb[2] = SCENE_GREY;
  if (!m) return;
  memcpy(rgb, m->color, sizeof m->color);
  if (m->texture.width > 0 && rr_has_texcoord(s, h->id)) {
    /* only textured materials pay for derivatives, and only filters with a footprint */
    bool footprint = tf->filter != RR_TEXTURE_NEAREST && tf->filter != RR_TEXTURE_BILINEAR;
    tex_coord tc = hit_texcoord(s, h, footprint);
    float t[4];
    rr_texture_sample(&m->texture, &tc, tf, t);
    for (int c = 0; c < 3; c++) rgb[c] *= t[c];
  }
  if (s->col[0][0]) { /* vertex colours (linear) multiply in, like glTF's COLOR_0 */
    uint32_t j = scene_st(s, h->id);
    for (int c = 0; c < 3; c++) rgb[c] *= h->l0 * s->col[0][c][j] + h->l1 * s->col[1][c][j] + h->l2 * s->col[2][c][j];
  }
}

static uint32_t hash32(uint32_t x) {
  x ^= x >> 16, x *= 0x7feb352dU, x ^= x >> 15, x *= 0x846ca68bU, x ^= x >> 16;
  return x;
}

static rr_error image_alloc(rr_device *dev, rr_image *img, int w, int h, int ch, rr_pixel_type type, int kind) {
  size_t size = type == RR_PIXEL_U8 ? 1 : 4;
  img->width = w, img->height = h, img->channels = ch, img->type = type, img->kind = kind;
  img->data = calloc((size_t)w * h * ch, size);
  return img->data ? RR_OK : rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d image", w, h);
}

/* A perceptually ordered ramp: dark blue, cyan, green, yellow, red, white. */
static void heat_color(float v, float *o) {
  static const float stops[6][3] = {{0.05f, 0.05f, 0.35f}, {0.0f, 0.6f, 0.9f}, {0.1f, 0.8f, 0.2f},
                                    {1.0f, 0.9f, 0.1f},    {0.9f, 0.1f, 0.05f}, {1.0f, 1.0f, 1.0f}};
  v = fminf(fmaxf(v, 0.0f), 1.0f) * 5.0f;
  int i = v >= 5.0f ? 4 : (int)v;
  float f = v - (float)i;
  for (int c = 0; c < 3; c++) o[c] = stops[i][c] * (1 - f) + stops[i + 1][c] * f;
}

/* Room for stb_easy_font's quads (64 bytes each) of one line of up to 127 characters. */
enum { TEXT_BUF = 64 * 1024 };

/* Draws text with stb_easy_font's quads, scaled by `scale`, into an RGB float
 * image; buf (TEXT_BUF bytes) receives the quads. */
static void draw_text(rr_image *img, char *buf, float x, float y, float scale, const char *text) {
  char t[128];
  snprintf(t, sizeof t, "%s", text);
  int quads = stb_easy_font_print(0, 0, t, NULL, buf, TEXT_BUF);
  float *px = img->data;
  for (int q = 0; q < quads; q++) {
    const float *v0 = (const float *)(buf + q * 64), *v2 = (const float *)(buf + q * 64 + 32);
    int x0 = (int)(x + v0[0] * scale), y0 = (int)(y + v0[1] * scale);
    int x1 = (int)(x + v2[0] * scale), y1 = (int)(y + v2[1] * scale);
    for (int yy = y0 < 0 ? 0 : y0; yy < y1 && yy < img->height; yy++)
      for (int xx = x0 < 0 ? 0 : x0; xx < x1 && xx < img->width; xx++) {
        float *o = px + 3 * ((size_t)yy * img->width + xx);
        o[0] = o[1] = o[2] = 1.0f;
      }
  }
}

/* Per-pixel counts as a heat map on a log scale up to the largest value, with a
 * legend: the ramp along the bottom, its range and the mean. */
static rr_error shade_heat(rr_device *dev, const float *heat, rr_image *img, const char *what) {
  size_t n = (size_t)img->width * img->height;
  float top = 0;
  double sum = 0;
  for (size_t k = 0; k < n; k++) top = fmaxf(top, heat[k]), sum += heat[k];
  float *px = img->data, norm = top > 0 ? 1.0f / log1pf(top) : 0;
  for (size_t k = 0; k < n; k++) heat_color(log1pf(heat[k]) * norm, px + 3 * k);
  int bar = img->height / 40 > 5 ? img->height / 40 : 5;
  float scale = bar / 7.0f > 1 ? bar / 7.0f : 1, line = 11 * scale;
  int y0 = img->height - bar - 3, ytext = (int)(y0 - line - 2);
  if (ytext < 0 || img->width < 64) return RR_OK;
  char *buf = malloc(TEXT_BUF); /* each call its own: two threads may draw legends at once */
  if (!buf) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a heat map's legend");
  int x0 = img->width * 3 / 5, x1 = img->width - 8;
  for (int y = ytext - 2; y < img->height; y++)
    for (int x = 0; x < img->width; x++) {
      float *o = px + 3 * ((size_t)y * img->width + x);
      o[0] = o[1] = o[2] = 0.0f;
      if (y >= y0 && y < y0 + bar && x >= x0 && x < x1) heat_color((float)(x - x0) / (x1 - x0 - 1), o);
    }
  char label[128];
  snprintf(label, sizeof label, "%s per pixel (log), mean %.1f", what, sum / n);
  draw_text(img, buf, 4, (float)ytext, scale, label);
  draw_text(img, buf, (float)x0 - 8 * scale, (float)y0 - 2 * scale, scale, "0");
  snprintf(label, sizeof label, "%.0f", top);
  draw_text(img, buf, (float)x1 - stb_easy_font_width(label) * scale, (float)ytext, scale, label);
  free(buf);
  return RR_OK;
}

/* The linear colour of a valid hit under a shade mode other than the heat maps;
 * [dmin, dmax]: the frame's range of distances (depth). */
static void shade_hit(const rr_scene *s, const hit *h, rr_shade_mode mode, const tex_filter *tf, float dmin,
                      float dmax, float o[3]) {
  if (mode == RR_SHADE_LAMBERT) {
    float rgb[3];
    base_color(s, h, tf, rgb);
    float lit = 0.12f + 0.88f * fmaxf(0.0f, -v3_dot(h->normal, h->dir));
    for (int ch = 0; ch < 3; ch++) o[ch] = rgb[ch] * lit;
    return;
  }
  /* the visualisations are designed in display colours, decoded to linear light */
  switch (mode) {
  case RR_SHADE_ID: {
    uint32_t hsh = hash32(scene_face_id(s, h->id) + 1); /* by id: the colour of a face whatever was dropped */
    for (int ch = 0; ch < 3; ch++) o[ch] = 0.2f + 0.8f * (float)((hsh >> (8 * ch)) & 255) / 255.0f;
    break;
  }
  case RR_SHADE_NORMAL:
    o[0] = 0.5f + 0.5f * h->normal.x, o[1] = 0.5f + 0.5f * h->normal.y, o[2] = 0.5f + 0.5f * h->normal.z;
    break;
  default: { /* depth */
    float g = dmax > dmin ? 1.0f - 0.85f * (h->dist - dmin) / (dmax - dmin) : 1.0f;
    o[0] = o[1] = o[2] = g;
    break;
  }
  }
  for (int ch = 0; ch < 3; ch++) o[ch] = srgb_decode(o[ch]);
}

/* The surface the lit mode shades at a valid hit h. */
static void hit_surface(const rr_scene *s, const hit *h, const tex_filter *tf, surface *sf) {
  uint32_t i = h->id;
  vec3 ng = geometric_normal(s, i, h->l1, h->l2);
  sf->ng = v3_dot(ng, h->dir) > 0 ? v3_neg(ng) : ng;
  sf->n = h->normal, sf->v = v3_neg(h->dir);
  if (scene_kind(s, i) != RR_GEOMETRY_TRIANGLE) { /* analytic: from its coordinates */
    sf->p = rr_ana_point(s, i, h->l1, h->l2);
  } else if (scene_inf(s, i)) { /* corners at infinity: along the ray */
    sf->p = v3_add(h->org, v3_scale(h->dir, h->dist));
  } else { /* from the corners: as exact as the triangle, wherever the ray came from */
    sf->p = v3_add(v3_add(v3_scale(scene_vertex(s, 0, i), h->l0), v3_scale(scene_vertex(s, 1, i), h->l1)),
                   v3_scale(scene_vertex(s, 2, i), h->l2));
  }
  sf->m = s->nmaterials ? &s->materials[scene_material(s, i) % s->nmaterials] : NULL;
  base_color(s, h, tf, sf->base);
  mirror_diffs(s, h, sf);
}

/* One shading pass over the samples of a frame (rows dealt out in jobs). */
typedef struct shade_pass {
  const rr_scene *s;
  const camera *cams; /* cams[s] resolved at sample s's position */
  const visbuf *vb;
  rr_shade_mode mode;
  tex_filter tex;
  float footprint; /* hit.footprint */
  rr_aa_mode aa;
  int samples, stored; /* samples shaded and those carrying colour (csaa: K; else all) */
  float dmin, dmax;
  const float *background; /* the caller's colour behind misses, NULL: the gradient */
  signed char nearest[RR_MAX_SAMPLES][RR_MAX_SAMPLES]; /* csaa: coverage sample c's stored samples, nearest first */
  float *rgb, *weight, *alpha; /* the resolve's input (resolve.h); weight NULL: all 1; alpha NULL: opaque */
  bool has_alpha;
  float *out; /* a filter of each pixel's own samples: the image, resolved as shading goes (no rgb kept) */
  uint64_t shades[RR_MAX_THREADS];
  bool failed; /* a job found no memory */
  /* RR_SHADE_LIT: the points of a wave of rows (light.h) are made first, their
   * colours going to the wave's per-sample arrays, then shaded together in passes,
   * then copied to the samples that share them and resolved */
  bool lit;
  lighting lights;
  lit_wave *wave;
  lit_stats lit_st;
  int y0, rows;     /* the wave's rows */
  float *wave_rgb;  /* sample i of the wave's pixel q at 3(i·wave_pix + q) */
  float *wave_w;    /* and its weight at i·wave_pix + q */
  signed char *wave_lead; /* and the sample whose colour it shares */
  size_t wave_pix;  /* the wave's room in pixels */
  float *parts;     /* NULL, or the lit parts of each pixel's centre sample (LIT_PARTS floats a pixel) */
  float *vis;       /* NULL, or which lights reach it (lights.nlights floats a pixel) */
  int centre;       /* the sample nearest the pixel's centre */
} shade_pass;

/* A reflection ray's hit as the lit mode's surface (light.h's surface_fn): its
 * differentials, when it has them, give its texture footprint. */
static void reflected_surface(void *ctx, uint32_t index, float l1, float l2, float t, vec3 org, vec3 dir,
                              const vec3 diff[4], surface *out) {
  const shade_pass *p = ctx;
  hit h = hit_make(p->s, index, l1, l2, t, org, dir, NULL, 0, 0);
  h.diff = diff;
  hit_surface(p->s, &h, &p->tex, out);
}

enum { SHADE_ROWS = 8 }; /* rows per job */

/* Behind misses: a quiet vertical gradient in display colours, as linear light;
 * black where the camera has no ray. */
static void background(int y, int height, float o[3]) {
  float g = 0.16f + 0.10f * (1.0f - (float)y / height);
  o[0] = srgb_decode(g * 0.9f), o[1] = srgb_decode(g), o[2] = srgb_decode(g * 1.15f);
}

/* The samples of one pixel, side by side in the visibility buffer (vis.h). */
typedef struct pixel_samples {
  const uint32_t *id;
  const float *l1, *l2, *t;
} pixel_samples;

static inline pixel_samples pixel_at(const visbuf *vb, int x, int y) {
  const size_t e = ((size_t)y * vb->width + x) * vb->ns;
  return (pixel_samples){vb->id + e, vb->l1 + e, vb->l2 + e, vb->t + e};
}

/* A run of pixels of one row: the colours of their samples, each sample's row of
 * them apart (as the resolve and the lit wave take them). */
enum { RUN = 64 };
typedef struct sample_run {
  float rgb[RR_MAX_SAMPLES][3 * RUN], w[RR_MAX_SAMPLES][RUN], a[RR_MAX_SAMPLES][RUN];
  signed char lead[RR_MAX_SAMPLES][RUN]; /* lit: the sample whose colour this one shares */
  bool one[RUN]; /* the pixel is in the image already: one colour for all its samples */
} sample_run;

/* Whether samples a and b of a pixel saw the same surface: the same primitive, and
 * of a box the same face (l1's integer part), so msaa shades each face it covers. */
static inline bool same_surface(const rr_scene *s, const pixel_samples *px, int a, int b) {
  uint32_t id = px->id[a];
  if (px->id[b] != id) return false;
  return id >= s->ntris || scene_kind(s, id) != RR_GEOMETRY_BOX || (int)px->l1[a] == (int)px->l1[b];
}

/* Whether all n samples of a pixel saw one surface (most pixels under msaa, csaa). */
static inline bool one_surface(const rr_scene *s, const pixel_samples *px, int n) {
  typedef uint32_t v4u __attribute__((vector_size(16)));
  const uint32_t id0 = px->id[0];
  uint32_t diff = 0;
  int m = 1;
  if (n >= 4) { /* four ids a step (n is 4, 8 or 16) */
    v4u acc = {0, 0, 0, 0}, v;
    for (m = 0; m < n; m += 4) memcpy(&v, px->id + m, sizeof v), acc |= v ^ id0;
    diff = acc[0] | acc[1] | acc[2] | acc[3];
  }
  for (; m < n; m++) diff |= px->id[m] ^ id0;
  if (diff) return false;
  for (int m = 1; m < n && s->kind && px->id[0] < s->ntris; m++)
    if (!same_surface(s, px, m, 0)) return false;
  return true;
}

/* The colour of the group of samples of pixel (x, y) that starts at stored sample i
 * and ends before `last` (those of them that saw its surface; all: every one of
 * them, as one_surface found): shaded once at the
 * group's mean barycentrics and ray parameter along sample i's ray (a triangle's),
 * or at sample i's hit (an analytic primitive's); the background on a miss, black
 * where the camera has no ray. Lit, the point is queued in the wave instead and col
 * stays black. Returns the shading invocations (0 or 1). */
static uint64_t shade_group(shade_pass *p, const pixel_samples *px, int i, int last, bool all, int thread, int x,
                            int y, const float bg[3], float col[3]) {
  const rr_scene *s = p->s;
  uint32_t id = px->id[i];
  vec3 o, d;
  col[0] = col[1] = col[2] = 0;
  if (id >= s->ntris) {
    if (p->cams[i].planar || rr_cam_ray(&p->cams[i], x, y, &o, &d)) memcpy(col, bg, 3 * sizeof *col);
    return 0;
  }
  float l1 = 0, l2 = 0, t = 0;
  int members = 0;
  /* An analytic primitive's coordinates are not linear over it (a box's face in
   * l1's integer part, a sphere's u wrapping at its seam): its first sample's hit. */
  int upto = scene_kind(s, id) == RR_GEOMETRY_TRIANGLE ? last : i + 1;
  if (all) /* every sample is the group's (one_surface): the same sums, without the tests */
    for (int m = i; m < upto; m++) l1 += px->l1[m], l2 += px->l2[m], t += px->t[m], members++;
  else
    for (int m = i; m < upto; m++)
      if (same_surface(s, px, m, i)) l1 += px->l1[m], l2 += px->l2[m], t += px->t[m], members++;
  if (!rr_cam_ray(&p->cams[i], x, y, &o, &d)) return 0;
  float inv = 1.0f / (float)members;
  hit h = hit_make(s, id, l1 * inv, l2 * inv, t * inv, o, d, &p->cams[i], x, y);
  h.footprint = p->footprint;
  if (p->lit) { /* shaded with the wave's other points; the colour arrives in the wave's arrays */
    surface sf;
    hit_surface(s, &h, &p->tex, &sf);
    size_t q = (size_t)(y - p->y0) * p->vb->width + x;
    /* the lit AOVs: the point of the centre sample (of its group in msaa, csaa) */
    bool grouped = p->aa == RR_AA_MSAA || p->aa == RR_AA_CSAA;
    bool centre = grouped ? same_surface(s, px, p->centre, i) : i == p->centre;
    size_t pix = (size_t)y * p->vb->width + x;
    float *parts = p->parts && centre ? p->parts + LIT_PARTS * pix : NULL;
    float *vis = p->vis && centre ? p->vis + (size_t)p->lights.nlights * pix : NULL;
    if (!rr_lit_wave_add(p->wave, thread, &sf, p->wave_rgb + 3 * (i * p->wave_pix + q), parts, vis))
      p->failed = true;
  } else {
    shade_hit(s, &h, p->mode, &p->tex, p->dmin, p->dmax, col);
  }
  return 1;
}

/* Shades pixel (x, y), run entry j: see rr_aa_mode for what each mode does. */
static uint64_t shade_pixel(shade_pass *p, sample_run *r, const pixel_samples *px, int thread, int j, int x, int y,
                            const float bg[3]) {
  const rr_scene *s = p->s;
  int n = p->samples, K = p->stored;
  bool grouped = p->aa == RR_AA_MSAA || p->aa == RR_AA_CSAA;
  bool done[RR_MAX_SAMPLES] = {false};
  uint64_t shades = 0;
  /* Each stored sample not yet coloured starts a group: the samples that saw its
   * primitive. ssaa and none: every sample its own group. msaa, csaa: shade_group. */
  for (int i = 0; i < K; i++) {
    if (done[i]) continue;
    int last = grouped ? n : i + 1;
    float col[3];
    shades += shade_group(p, px, i, last, false, thread, x, y, bg, col);
    for (int m = i; m < (last < K ? last : K); m++)
      if (same_surface(s, px, m, i)) {
        memcpy(&r->rgb[m][3 * j], col, sizeof col); /* (queued: 0 until the wave is shaded) */
        done[m] = true, r->w[m][j] = 1.0f, r->lead[m][j] = (signed char)i;
      }
  }
  /* csaa: a coverage sample votes for the nearest stored sample of its primitive;
   * its own colour counts for nothing */
  for (int c = K; c < n; c++) {
    for (int v = 0; v < K; v++)
      if (same_surface(s, px, p->nearest[c][v], c)) {
        r->w[p->nearest[c][v]][j] += 1.0f;
        break;
      }
    r->w[c][j] = 0.0f;
    memset(&r->rgb[c][3 * j], 0, 3 * sizeof(float));
  }
  return shades;
}

/* The run's coloured samples, but for the pixels already in the image (r->one):
 * resolved into the image (the box of each pixel's own samples), or kept for the
 * resolve. */
static void run_store(shade_pass *p, sample_run *r, int y, int x0, int len) {
  const visbuf *vb = p->vb;
  size_t npix = (size_t)vb->width * vb->height, k0 = (size_t)y * vb->width + x0;
  int n = p->samples;
  for (int j = 0; p->has_alpha && j < len; j++) {
    const uint32_t *id = pixel_at(vb, x0 + j, y).id;
    for (int i = 0; i < n; i++) r->a[i][j] = id[i] < p->s->ntris ? 1.0f : 0.0f;
  }
  const float *w = p->aa == RR_AA_CSAA ? r->w[0] : NULL, *a = p->has_alpha ? r->a[0] : NULL;
  if (p->out) {
    int ch = p->has_alpha ? 4 : 3;
    for (int j = 0; j < len; j++)
      if (!r->one[j])
        resolve_own(n, &r->rgb[0][3 * j], 3 * RUN, w ? w + j : NULL, a ? a + j : NULL, RUN, ch, p->out + ch * (k0 + j));
    return;
  }
  for (int i = 0; i < n; i++) {
    memcpy(p->rgb + 3 * (i * npix + k0), r->rgb[i], 3 * len * sizeof(float));
    if (w) memcpy(p->weight + i * npix + k0, r->w[i], len * sizeof(float));
    if (a) memcpy(p->alpha + i * npix + k0, r->a[i], len * sizeof(float));
  }
}

/* The background of row y. */
static void row_background(const shade_pass *p, int y, float bg[3]) {
  if (p->background) memcpy(bg, p->background, 3 * sizeof *bg);
  else background(y, p->vb->height, bg);
}

/* Rows y0 + job·SHADE_ROWS on, at most to row `end`, run by run through fn. */
typedef void (*run_fn)(shade_pass *p, sample_run *r, int thread, int y, int x0, int len);
static void rows_by_runs(shade_pass *p, int y0, int end, int job, int thread, run_fn fn) {
  sample_run *r = malloc(sizeof *r);
  if (!r) { /* a job without room leaves its rows for shade_frame to report */
    p->failed = true;
    return;
  }
  for (int y = y0 + job * SHADE_ROWS; y < end && y < y0 + (job + 1) * SHADE_ROWS; y++)
    for (int x0 = 0; x0 < p->vb->width; x0 += RUN) fn(p, r, thread, y, x0, p->vb->width - x0 < RUN ? p->vb->width - x0 : RUN);
  free(r);
}

/* The modes other than lit: each run shaded and stored. A pixel whose samples all
 * share one colour (one sample; msaa and csaa where one surface covers the pixel)
 * goes straight into the image under the box, as its resolve would give it. */
static void shade_run(shade_pass *p, sample_run *r, int thread, int y, int x0, int len) {
  float bg[3];
  row_background(p, y, bg);
  const int n = p->samples, ch = p->has_alpha ? 4 : 3;
  const bool grouped = p->aa == RR_AA_MSAA || p->aa == RR_AA_CSAA;
  uint64_t shades = 0;
  for (int j = 0; j < len; j++) {
    const int x = x0 + j;
    const pixel_samples px = pixel_at(p->vb, x, y);
    r->one[j] = p->out && (n == 1 || (grouped && one_surface(p->s, &px, n)));
    if (r->one[j]) {
      float col[3];
      const bool hit = px.id[0] < p->s->ntris;
      if (!hit && p->cams[0].planar) memcpy(col, bg, sizeof col); /* shade_group's miss, inline */
      else shades += shade_group(p, &px, 0, n, true, thread, x, y, bg, col);
      resolve_one(col, hit || !p->has_alpha, ch, p->out + ch * ((size_t)y * p->vb->width + x));
    } else {
      shades += shade_pixel(p, r, &px, thread, j, x, y, bg);
    }
  }
  p->shades[thread] += shades;
  run_store(p, r, y, x0, len);
}
static void shade_rows(int job, int thread, void *arg) {
  shade_pass *p = arg;
  rows_by_runs(p, 0, p->vb->height, job, thread, shade_run);
}

/* Lit, first: the run's points queued in the wave, its samples' weights and leads kept. */
static void lit_gather_run(shade_pass *p, sample_run *r, int thread, int y, int x0, int len) {
  float bg[3];
  row_background(p, y, bg);
  for (int j = 0; j < len; j++) {
    const pixel_samples px = pixel_at(p->vb, x0 + j, y);
    p->shades[thread] += shade_pixel(p, r, &px, thread, j, x0 + j, y, bg);
  }
  size_t q0 = (size_t)(y - p->y0) * p->vb->width + x0;
  for (int i = 0; i < p->samples; i++) {
    size_t e = i * p->wave_pix + q0;
    memcpy(p->wave_rgb + 3 * e, r->rgb[i], 3 * len * sizeof(float));
    memcpy(p->wave_w + e, r->w[i], len * sizeof(float));
    memcpy(p->wave_lead + e, r->lead[i], len);
  }
}
static void lit_gather_rows(int job, int thread, void *arg) {
  shade_pass *p = arg;
  rows_by_runs(p, p->y0, p->y0 + p->rows, job, thread, lit_gather_run);
}

/* Lit, last: the shaded colours given to the samples that share them, then stored. */
static void lit_finish_run(shade_pass *p, sample_run *r, int thread, int y, int x0, int len) {
  (void)thread;
  memset(r->one, 0, sizeof r->one);
  size_t q0 = (size_t)(y - p->y0) * p->vb->width + x0;
  for (int i = 0; i < p->samples; i++) {
    size_t e = i * p->wave_pix + q0;
    memcpy(r->rgb[i], p->wave_rgb + 3 * e, 3 * len * sizeof(float));
    memcpy(r->w[i], p->wave_w + e, len * sizeof(float));
    memcpy(r->lead[i], p->wave_lead + e, len);
  }
  for (int i = 0; i < p->stored; i++)
    for (int j = 0; j < len; j++)
      if (r->lead[i][j] != i) memcpy(&r->rgb[i][3 * j], &r->rgb[r->lead[i][j]][3 * j], 3 * sizeof(float));
  run_store(p, r, y, x0, len);
}
static void lit_finish_rows(int job, int thread, void *arg) {
  shade_pass *p = arg;
  rows_by_runs(p, p->y0, p->y0 + p->rows, job, thread, lit_finish_run);
}

/* The lit mode's frame, a wave of rows at a time: every shaded point of the wave
 * made (per sample in ssaa, per pixel and primitive in msaa and csaa), then the
 * passes over all of them (light.h), then the samples coloured and stored. */
static void lit_frame(shade_pass *p, int wave_points, int threads) {
  const visbuf *vb = p->vb;
  bool grouped = p->aa == RR_AA_MSAA || p->aa == RR_AA_CSAA; /* about one point a pixel */
  size_t row = (size_t)vb->width * (grouped ? 1 : p->samples), want = wave_points > 0 ? (size_t)wave_points : RR_LIT_WAVE;
  int rows = want / row < 1 ? 1 : want / row >= (size_t)vb->height ? vb->height : (int)(want / row);
  p->wave_pix = (size_t)rows * vb->width;
  size_t n = p->wave_pix * p->samples;
  p->wave = rr_lit_wave_new();
  p->wave_rgb = rr_alloc_large(3 * n * sizeof(float));
  p->wave_w = rr_alloc_large(n * sizeof(float));
  p->wave_lead = rr_alloc_large(n);
  if (!p->wave || !p->wave_rgb || !p->wave_w || !p->wave_lead) p->failed = true;
  for (p->y0 = 0; !p->failed && p->y0 < vb->height; p->y0 += rows) {
    p->rows = vb->height - p->y0 < rows ? vb->height - p->y0 : rows;
    int jobs = (p->rows + SHADE_ROWS - 1) / SHADE_ROWS;
    rr_parallel_for(jobs, threads, lit_gather_rows, p);
    if (p->failed) break;
    if (!rr_lit_wave_shade(p->wave, p->s, &p->lights, reflected_surface, p, threads, &p->lit_st)) p->failed = true;
    rr_parallel_for(jobs, threads, lit_finish_rows, p);
  }
  rr_lit_wave_free(p->wave);
  free(p->wave_rgb), free(p->wave_w), free(p->wave_lead);
}

/* The frame's range of eye distances over every shaded sample (the depth mode's scale). */
static void depth_range(const shade_pass *p, float *dmin, float *dmax) {
  const visbuf *vb = p->vb;
  *dmin = INFINITY, *dmax = 0;
  for (int i = 0; i < p->samples; i++)
    for (int y = 0; y < vb->height; y++)
      for (int x = 0; x < vb->width; x++) {
        hit h = sample_hit(p->s, &p->cams[i], vb, ((size_t)y * vb->width + x) * vb->ns + i, x, y);
        if (h.valid) *dmin = fminf(*dmin, h.dist), *dmax = fmaxf(*dmax, h.dist);
      }
}

static rr_error shade_heat_frame(rr_device *dev, const rr_frame *f, rr_shade_mode mode, rr_image *out) {
  const float *counts = mode == RR_SHADE_HEAT_EVALS ? f->heat_e : f->heat_n;
  if (!counts)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "heat maps need per-pixel statistics (render with options.heat set)");
  rr_error e = image_alloc(dev, out, f->vb.width, f->vb.height, 3, RR_PIXEL_F32, RR_IMAGE_COLOR);
  if (!e) e = shade_heat(dev, counts, out, mode == RR_SHADE_HEAT_EVALS ? "edge evaluations" : "BVH nodes");
  if (e) {
    free(out->data);
    out->data = NULL;
    return e;
  }
  /* drawn in display colours; the image holds linear light */
  float *px = out->data;
  for (size_t i = 0; i < (size_t)f->vb.width * f->vb.height * 3; i++) px[i] = srgb_decode(px[i]);
  return rr_ok(dev);
}

static int centre_sample(const rr_frame *f);

/* Shades the samples as the frame's AA mode says (cams: one per sample position),
 * then resolves them into out with the options' filter; lit, the parts of each
 * pixel's centre sample go to parts (LIT_PARTS floats a pixel) unless it is NULL,
 * and which lights reach it to vis (lights->nlights floats a pixel) unless it is NULL. */
static rr_error shade_samples(rr_device *dev, const rr_scene *s, const camera *cams, const rr_frame *f,
                              const rr_shade_options *opt, const lighting *lights, float *parts, float *vis,
                              rr_image *out, rr_shade_stats *st) {
  const visbuf *vb = &f->vb;
  size_t npix = (size_t)vb->width * vb->height;
  shade_pass *p = calloc(1, sizeof *p);
  if (!p) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for shading");
  *p = (shade_pass){.s = s, .cams = cams, .vb = vb, .mode = opt->mode, .aa = f->aa, .samples = f->samples,
                      .tex = {opt->texture_filter, opt->aniso, opt->lod_bias}, .lit = lights != NULL};
  if (lights) p->lights = *lights;
  p->parts = parts, p->vis = vis, p->centre = centre_sample(f);
  p->background = opt->has_background ? opt->background : NULL;
  p->stored = f->aa == RR_AA_CSAA ? f->aa_stored : p->samples;
  /* Derivatives are per pixel step. A sample shaded for the whole pixel (one per
   * pixel, msaa, csaa) filters over all of it; ssaa's N samples each over their
   * share, a pixel step of 1/√N, so that their mean is not filtered twice. */
  p->footprint = f->aa == RR_AA_SSAA ? 1.0f / sqrtf((float)p->samples) : 1.0f;
  const float(*pos)[2] = (const float(*)[2])f->sample_pos;
  /* coverage samples' stored samples by distance (ties: the lower index) */
  for (int c = p->stored; c < p->samples; c++) {
    for (int j = 0; j < p->stored; j++) p->nearest[c][j] = (signed char)j;
    for (int a = 1; a < p->stored; a++) /* insertion sort: stable */
      for (int b = a; b > 0; b--) {
        int u = p->nearest[c][b - 1], v = p->nearest[c][b];
        float du = hypotf(pos[u][0] - pos[c][0], pos[u][1] - pos[c][1]);
        float dv = hypotf(pos[v][0] - pos[c][0], pos[v][1] - pos[c][1]);
        if (dv >= du) break;
        p->nearest[c][b - 1] = (signed char)v, p->nearest[c][b] = (signed char)u;
      }
  }
  bool own;
  rr_error e = rr_resolve_check(dev, opt, &own);
  size_t nsamp = own ? 0 : (size_t)p->samples * npix;
  p->has_alpha = opt->alpha != 0;
  if (!e && own) { /* resolved as shading goes: no per-sample colours */
    int ch = opt->alpha ? 4 : 3;
    /* in huge pages where the system gives them: the image is written whole, and in
     * small pages each 4 KiB of it is a fault in the shading loop (3072 at 1024²) */
    *out = (rr_image){vb->width, vb->height, ch, RR_PIXEL_F32, rr_alloc_large(sizeof(float) * ch * npix), RR_IMAGE_COLOR};
    if (!(p->out = out->data)) e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d image", vb->width, vb->height);
  } else if (!e) {
    p->rgb = rr_alloc_large(nsamp * 3 * sizeof(float));
    p->weight = f->aa == RR_AA_CSAA ? rr_alloc_large(nsamp * sizeof(float)) : NULL;
    p->alpha = opt->alpha ? rr_alloc_large(nsamp * sizeof(float)) : NULL;
    if (!p->rgb || (f->aa == RR_AA_CSAA && !p->weight) || (opt->alpha && !p->alpha))
      e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %dx%d pixels of %d samples", vb->width, vb->height,
                  p->samples);
  }
  if (!e) {
    double t0 = rr_now_ms();
    if (opt->mode == RR_SHADE_DEPTH) depth_range(p, &p->dmin, &p->dmax);
    int threads = f->stats.threads > 0 ? f->stats.threads : 1;
    if (p->lit) lit_frame(p, opt->wave_points, threads);
    else rr_parallel_for((vb->height + SHADE_ROWS - 1) / SHADE_ROWS, threads, shade_rows, p);
    double t1 = rr_now_ms();
    resolve_input in = {vb->width, vb->height, p->samples, pos, p->rgb, p->weight, p->alpha};
    e = p->failed ? rr_fail(dev, RR_ERROR_MEMORY, "out of memory for shading")
        : own     ? RR_OK
                  : rr_resolve_image(dev, &in, opt, threads, out);
    if (e && own) free(out->data), out->data = NULL;
    if (st) {
      *st = (rr_shade_stats){.shade_ms = t1 - t0, .resolve_ms = rr_now_ms() - t1};
      for (int t = 0; t < RR_MAX_THREADS; t++) st->shades += p->shades[t];
      const lit_stats *l = &p->lit_st;
      st->shadow_rays = l->shadow_rays, st->shadow_rays_raster = l->shadow_rays_raster;
      st->reflection_rays = l->reflection_rays, st->direct_ms = l->direct_ms, st->shadow_ms = l->shadow_ms;
      st->reflection_ms = l->reflection_ms;
    }
  }
  free(p->rgb), free(p->weight), free(p->alpha), free(p);
  return e ? e : rr_ok(dev);
}

/* Resolves the frame's cameras, one per sample position; on failure none is left. */
static rr_error frame_cameras(rr_device *dev, const rr_camera *cam, const rr_frame *f, camera *cams) {
  for (int s = 0; s < f->samples; s++) {
    rr_error e = rr_cam_setup_at(dev, cam, f->vb.width, f->vb.height, f->sample_pos[s], &cams[s]);
    if (e) {
      while (s > 0) rr_cam_release(&cams[--s]);
      return e;
    }
  }
  return RR_OK;
}

/* The value of an integer AOV (id, mesh, material, instance) at a sample that saw primitive id. */
static uint32_t id_aov(const rr_scene *s, rr_aov aov, uint32_t id) {
  if (aov == RR_AOV_ID) return scene_face_id(s, id);
  if (id >= s->ntris) return RR_MISS;
  if (aov == RR_AOV_INSTANCE) return scene_instance_of(s, id);
  return aov == RR_AOV_MESH ? rr_scene_geometry_of(s, id) : scene_material(s, id);
}

/* The sample nearest the pixel's centre (the lowest index on a tie): the same in
 * every pixel, as every pixel has the frame's pattern. */
static int centre_sample(const rr_frame *f) {
  int best = 0;
  float best_d = INFINITY;
  for (int s = 0; s < f->samples; s++) {
    float dx = f->sample_pos[s][0] - 0.5f, dy = f->sample_pos[s][1] - 0.5f, d = dx * dx + dy * dy;
    if (d < best_d) best = s, best_d = d;
  }
  return best;
}

/* The AOV a per-sample AOV gives for each sample; the AOV itself otherwise. */
static rr_aov per_sample_base(rr_aov aov) {
  switch (aov) {
  case RR_AOV_SAMPLE_ID: return RR_AOV_ID;
  case RR_AOV_SAMPLE_DEPTH: return RR_AOV_DEPTH;
  case RR_AOV_SAMPLE_MESH: return RR_AOV_MESH;
  default: return aov;
  }
}

/* Fills an AOV from the frame's layers (a layer: one sample of every pixel), by the
 * rules of several samples per pixel (rastray.h): a per-sample AOV takes every layer
 * as a channel (the H × W × N order of the buffer itself); coverage counts the
 * layers' hits; depth keeps the nearest; the others read the centre's layer. */
static rr_error frame_aov(rr_device *dev, const rr_scene *s, const camera *cams, const rr_frame *f, rr_aov aov,
                          rr_image *out) {
  const visbuf *vb = &f->vb;
  rr_error e;
  static const int channels[RR_AOV_COUNT] = {[RR_AOV_DEPTH] = 1, [RR_AOV_ID] = 1,       [RR_AOV_NORMAL] = 3,
                                             [RR_AOV_BARY] = 2,  [RR_AOV_EVALS] = 1,    [RR_AOV_NODES] = 1,
                                             [RR_AOV_MESH] = 1,  [RR_AOV_MATERIAL] = 1, [RR_AOV_COVERAGE] = 1,
                                             [RR_AOV_UV] = 2,    [RR_AOV_UV_DERIV] = 4,
                                             [RR_AOV_ZDEPTH] = 1,   [RR_AOV_INSTANCE] = 1}; /* the lit parts: lit_aov */
  if (aov == RR_AOV_EVALS || aov == RR_AOV_NODES) {
    const float *counts = aov == RR_AOV_EVALS ? f->heat_e : f->heat_n;
    if (!counts) return rr_fail(dev, RR_ERROR_ARGUMENT, "AOVs evals and nodes need options.heat set when rendering");
    e = image_alloc(dev, out, vb->width, vb->height, 1, RR_PIXEL_F32, RR_IMAGE_AOV + (int)aov);
    if (e) return e;
    memcpy(out->data, counts, (size_t)vb->width * vb->height * sizeof(float));
    return rr_ok(dev);
  }
  rr_aov base = per_sample_base(aov);
  bool per_sample = base != aov, ints = base == RR_AOV_ID || base == RR_AOV_MESH || base == RR_AOV_MATERIAL ||
                                  base == RR_AOV_INSTANCE;
  int ch = per_sample ? f->samples : channels[aov], centre = centre_sample(f);
  e = image_alloc(dev, out, vb->width, vb->height, ch, ints ? RR_PIXEL_U32 : RR_PIXEL_F32, RR_IMAGE_AOV + (int)aov);
  if (e) return e;
  size_t npix = (size_t)vb->width * vb->height;
  float *o = out->data;
  bool depth = base == RR_AOV_DEPTH || base == RR_AOV_ZDEPTH;
  if (depth) /* a miss everywhere, until a sample sees nearer */
    for (size_t k = 0; k < npix * ch; k++) o[k] = INFINITY;
  for (int smp = 0; smp < f->samples; smp++) {
    if (!per_sample && !depth && aov != RR_AOV_COVERAGE && smp != centre) continue;
    visbuf layer = visbuf_layer(&f->vb, smp);
    int c0 = per_sample ? smp : 0; /* this layer's channel */
    for (int y = 0; y < vb->height; y++)
      for (int x = 0; x < vb->width; x++) {
        size_t k = (size_t)y * vb->width + x;
        if (ints) {
          ((uint32_t *)out->data)[k * ch + c0] = id_aov(s, base, layer.id[k * layer.ns]);
          continue;
        }
        if (aov == RR_AOV_COVERAGE) {
          o[k] += layer.id[k * layer.ns] < s->ntris ? 1.0f / f->samples : 0.0f;
          continue;
        }
        hit h = hit_at(s, &cams[smp], &layer, x, y);
        float *p = o + k * ch + c0;
        if (base == RR_AOV_DEPTH) *p = fminf(*p, h.valid ? h.dist : INFINITY);
        else if (base == RR_AOV_ZDEPTH) *p = fminf(*p, h.valid ? h.dist * v3_dot(h.dir, cams[smp].fwd) : INFINITY);
        else if (base == RR_AOV_NORMAL && h.valid) p[0] = h.normal.x, p[1] = h.normal.y, p[2] = h.normal.z;
        else if (base == RR_AOV_BARY && h.valid) p[0] = h.l1, p[1] = h.l2;
        else if ((base == RR_AOV_UV || base == RR_AOV_UV_DERIV) && h.valid && rr_has_texcoord(s, h.id)) {
          tex_coord tc = hit_texcoord(s, &h, base == RR_AOV_UV_DERIV);
          if (base == RR_AOV_UV) p[0] = tc.u, p[1] = tc.v;
          else p[0] = tc.dudx, p[1] = tc.dvdx, p[2] = tc.dudy, p[3] = tc.dvdy;
        }
      }
  }
  return rr_ok(dev);
}

static const char *const texture_filter_names[RR_TEXTURE_FILTER_COUNT] = {"nearest", "bilinear", "trilinear",
                                                                          "aniso", "ewa"};

int rr_texture_filter_from_name(const char *name) {
  for (int i = 0; name && i < RR_TEXTURE_FILTER_COUNT; i++)
    if (!strcmp(name, texture_filter_names[i])) return i;
  return -1;
}

const char *rr_texture_filter_name(int filter) {
  return filter >= 0 && filter < RR_TEXTURE_FILTER_COUNT ? texture_filter_names[filter] : NULL;
}

static bool is_lit_aov(int a) { return (a >= RR_AOV_ALBEDO && a <= RR_AOV_EMISSION) || a == RR_AOV_SHADOW_LIGHTS; }

/* The image of lit AOV a, from the parts (LIT_PARTS floats a pixel) or, shadow-lights,
 * from vis (nlights floats a pixel); fails for shadow-lights without punctual lights
 * or with more than an image holds. */
static rr_error lit_image(rr_device *dev, int a, int width, int height, const float *parts, const float *vis,
                          int nlights, rr_image *out) {
  static const int part[] = {LIT_ALBEDO, LIT_DIRECT, LIT_REFLECTION, LIT_SHADOW, LIT_EMISSION};
  bool per_light = a == RR_AOV_SHADOW_LIGHTS;
  if (per_light && (nlights < 1 || nlights > RR_MAX_SHADOW_LIGHTS))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "the shadow-lights AOV needs 1 to %d punctual lights, the frame has %d",
                   RR_MAX_SHADOW_LIGHTS, nlights);
  int ch = per_light ? nlights : a == RR_AOV_SHADOW ? 1 : 3, first = per_light ? 0 : part[a - RR_AOV_ALBEDO];
  int stride = per_light ? nlights : LIT_PARTS;
  const float *from = per_light ? vis : parts;
  rr_error e = image_alloc(dev, out, width, height, ch, RR_PIXEL_F32, RR_IMAGE_AOV + a);
  size_t npix = (size_t)width * height;
  for (size_t k = 0; !e && k < npix; k++)
    memcpy((float *)out->data + k * ch, from + k * stride + first, ch * sizeof(float));
  return e;
}

/* The lit mode's parts (AOVs albedo .. emission, shadow-lights) at the sample nearest
 * each pixel's centre, under the lights of the default lit shading. */
static rr_error lit_aov(rr_device *dev, const rr_scene *s, const rr_camera *cam, const camera *cams,
                        const rr_frame *f, rr_aov aov, rr_image *out) {
  int centre = centre_sample(f);
  rr_shade_options opt;
  rr_shade_options_init(&opt);
  opt.mode = RR_SHADE_LIT;
  bool empty;
  if (!rr_bvh_of(dev, s, &empty) && !empty) return RR_ERROR_ARGUMENT; /* rays need the current BVH */
  const visbuf vb = visbuf_layer(&f->vb, centre);
  size_t npix = (size_t)vb.width * vb.height;
  shade_pass *p = calloc(1, sizeof *p); /* what reflected_surface reads */
  float *parts = calloc(npix, LIT_PARTS * sizeof(float)), *colour = malloc(npix * 3 * sizeof(float));
  lit_wave *wave = rr_lit_wave_new();
  float *vis = NULL;
  rr_error e = p && parts && colour && wave ? RR_OK : rr_fail(dev, RR_ERROR_MEMORY, "out of memory for AOV %d", (int)aov);
  if (!e) e = rr_lighting_make(dev, s, cam, &opt, &p->lights);
  int nl = e ? 0 : p->lights.nlights;
  if (!e && aov == RR_AOV_SHADOW_LIGHTS && nl > 0 && !(vis = calloc(npix * nl, sizeof *vis))) {
    rr_lighting_release(&p->lights);
    e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for AOV %d", (int)aov);
  }
  if (!e) {
    p->s = s, p->tex = (tex_filter){opt.texture_filter, opt.aniso, opt.lod_bias};
    lit_stats st = {0};
    bool ok = true;
    for (size_t k = 0; ok && k < npix; k++) {
      int x = (int)(k % vb.width), y = (int)(k / vb.width);
      vec3 o, d;
      const size_t q = k * vb.ns; /* the centre's sample of pixel k */
      if (vb.id[q] >= s->ntris || !rr_cam_ray(&cams[centre], x, y, &o, &d)) continue; /* 0 */
      hit h = hit_make(s, vb.id[q], vb.l1[q], vb.l2[q], vb.t[q], o, d, &cams[centre], x, y);
      surface sf;
      hit_surface(s, &h, &p->tex, &sf);
      ok = rr_lit_wave_add(wave, 0, &sf, colour + 3 * k, parts + k * LIT_PARTS, vis ? vis + k * nl : NULL);
    }
    ok = ok && rr_lit_wave_shade(wave, s, &p->lights, reflected_surface, p, 1, &st);
    rr_lighting_release(&p->lights);
    e = ok ? lit_image(dev, aov, vb.width, vb.height, parts, vis, nl, out)
           : rr_fail(dev, RR_ERROR_MEMORY, "out of memory for AOV %d", (int)aov);
  }
  free(p), free(parts), free(vis), free(colour), rr_lit_wave_free(wave);
  return e ? e : rr_ok(dev);
}

/* The public entry points resolve the frame's cameras, one per sample position, around the work. */
void rr_shade_options_init(rr_shade_options *opt) {
  *opt = (rr_shade_options){.mode = RR_SHADE_LAMBERT, .filter = RR_FILTER_BOX, .radius = 0, .alpha = 0,
                              .texture_filter = RR_TEXTURE_ANISO, .aniso = 16, .lod_bias = 0,
                              .shadows = RR_SHADOWS_RAYS, .max_depth = 2, .default_lights = 1};
}

static rr_error shade_frame(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                            const rr_shade_options *opt, unsigned aovs, rr_image *aov_images, rr_image *out,
                            rr_shade_stats *stats) {
  rr_shade_options def;
  if (!opt) rr_shade_options_init(&def), opt = &def;
  if (!s || !cam || !f || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_shade: NULL argument");
  if ((int)opt->mode < 0 || opt->mode >= RR_SHADE_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown shade mode %d", (int)opt->mode);
  if ((int)opt->texture_filter < 0 || opt->texture_filter >= RR_TEXTURE_FILTER_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown texture filter %d", (int)opt->texture_filter);
  if (opt->aniso < 1 || opt->aniso > 16)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad anisotropy %d (expected 1..16 probes)", opt->aniso);
  if (!isfinite(opt->lod_bias)) return rr_fail(dev, RR_ERROR_ARGUMENT, "the texture LOD bias must be finite");
  for (int c = 0; opt->has_background && c < 3; c++)
    if (!(opt->background[c] >= 0 && opt->background[c] <= 1e30f))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "the background colour must be finite and at least 0");
  if (stats) *stats = (rr_shade_stats){0};
  if (opt->mode == RR_SHADE_HEAT_EVALS || opt->mode == RR_SHADE_HEAT_NODES) {
    double t0 = rr_now_ms();
    rr_error e = shade_heat_frame(dev, f, opt->mode, out);
    if (stats) stats->shade_ms = rr_now_ms() - t0;
    return e;
  }
  bool lit = opt->mode == RR_SHADE_LIT;
  if (lit && ((int)opt->shadows < 0 || opt->shadows >= RR_SHADOWS_COUNT))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown shadow mode %d", (int)opt->shadows);
  if (lit && opt->wave_points < 0) return rr_fail(dev, RR_ERROR_ARGUMENT, "negative wave size %d", opt->wave_points);
  if (lit && (opt->max_depth < 0 || opt->max_depth > RR_MAX_DEPTH))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "max depth %d out of range (0 .. %d)", opt->max_depth, RR_MAX_DEPTH);
  bool empty;
  if (lit && !rr_bvh_of(dev, s, &empty) && !empty) return RR_ERROR_ARGUMENT; /* rays need the current BVH */
  lighting lights;
  rr_error e = lit ? rr_lighting_make(dev, s, cam, opt, &lights) : RR_OK;
  if (e) return e;
  camera cams[RR_MAX_SAMPLES];
  e = frame_cameras(dev, cam, f, cams);
  bool have_cams = !e, shaded = false;
  size_t npix = (size_t)f->vb.width * f->vb.height;
  float *parts = !e && aovs ? calloc(npix, LIT_PARTS * sizeof(float)) : NULL;
  if (!e && aovs && !parts) e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the lit AOVs");
  /* which lights reach each pixel's point: checked for a size before any shading */
  int nl = lit ? lights.nlights : 0;
  float *vis = NULL;
  if (!e && (aovs & 1u << RR_AOV_SHADOW_LIGHTS)) {
    if (nl < 1 || nl > RR_MAX_SHADOW_LIGHTS)
      e = rr_fail(dev, RR_ERROR_ARGUMENT, "the shadow-lights AOV needs 1 to %d punctual lights, the frame has %d",
                  RR_MAX_SHADOW_LIGHTS, nl);
    else if (!(vis = calloc(npix * nl, sizeof *vis))) e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the lit AOVs");
  }
  if (!e) e = shade_samples(dev, s, cams, f, opt, lit ? &lights : NULL, parts, vis, out, stats), shaded = !e;
  for (int k = 0; have_cams && k < f->samples; k++) rr_cam_release(&cams[k]);
  /* the AOVs asked for, from the parts */
  rr_image made[RR_AOV_COUNT] = {{0}};
  for (int a = 0; !e && a < RR_AOV_COUNT; a++)
    if (aovs & 1u << a) e = lit_image(dev, a, f->vb.width, f->vb.height, parts, vis, nl, &made[a]);
  for (int a = 0; a < RR_AOV_COUNT; a++)
    if (aovs & 1u << a) {
      if (e) free(made[a].data); /* (rr_image_free is io's: shading does not call io) */
      else aov_images[a] = made[a];
    }
  if (e && shaded) free(out->data), *out = (rr_image){0};
  free(parts), free(vis);
  if (lit) rr_lighting_release(&lights);
  return e ? e : rr_ok(dev);
}

rr_error rr_shade_frame(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                        const rr_shade_options *opt, rr_image *out, rr_shade_stats *stats) {
  return shade_frame(dev, s, cam, f, opt, 0, NULL, out, stats);
}

rr_error rr_shade_frame_aovs(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                             const rr_shade_options *opt, unsigned aovs, rr_image aov_images[RR_AOV_COUNT],
                             rr_image *out, rr_shade_stats *stats) {
  if (!opt || opt->mode != RR_SHADE_LIT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_shade_frame_aovs: the lit AOVs need options with the lit mode");
  unsigned lit_bits = 0;
  for (int a = 0; a < RR_AOV_COUNT; a++) lit_bits |= is_lit_aov(a) ? 1u << a : 0;
  if (aovs & ~lit_bits) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_shade_frame_aovs: AOVs other than the lit parts asked for");
  if (aovs && !aov_images) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_shade_frame_aovs: NULL argument");
  return shade_frame(dev, s, cam, f, opt, aovs, aov_images, out, stats);
}

rr_error rr_shade(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_shade_mode mode,
                  rr_image *out) {
  rr_shade_options opt;
  rr_shade_options_init(&opt);
  opt.mode = mode;
  return rr_shade_frame(dev, s, cam, f, &opt, out, NULL);
}

rr_error rr_frame_aov(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_aov aov,
                      rr_image *out) {
  if (!s || !cam || !f || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_frame_aov: NULL argument");
  if ((int)aov < 0 || aov >= RR_AOV_COUNT) return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown AOV %d", (int)aov);
  camera cams[RR_MAX_SAMPLES];
  rr_error e = frame_cameras(dev, cam, f, cams);
  if (e) return e;
  e = is_lit_aov(aov) ? lit_aov(dev, s, cam, cams, f, aov, out) : frame_aov(dev, s, cams, f, aov, out);
  for (int k = 0; k < f->samples; k++) rr_cam_release(&cams[k]);
  return e;
}
