/* Deferred shading: reads only the visibility buffer (id, t, λ1, λ2) and the
 * scene, so it never knows which method made the frame. */
#include "vis/vis.h"
#include "core/color.h"
#include "shade/resolve.h"

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
} hit;

static vec3 geometric_normal(const rr_scene *s, uint32_t i) {
  if (scene_inf(s, i)) return v3_norm(rr_scene_tri_normal(s, i)); /* corners at infinity */
  vec3 p0 = scene_vertex(s, 0, i);
  return v3_norm(v3_cross(v3_sub(scene_vertex(s, 1, i), p0), v3_sub(scene_vertex(s, 2, i), p0)));
}

static hit hit_at(const rr_scene *s, const camera *c, const visbuf *vb, int x, int y) {
  hit h = {0};
  size_t k = (size_t)y * vb->width + x;
  vec3 o, d;
  h.has_ray = rr_cam_ray(c, x, y, &o, &d);
  h.id = vb->id[k];
  if (h.id == RR_MISS || h.id >= s->ntris) return h;
  h.valid = true;
  if (!h.has_ray) {
    h.valid = false;
    return h;
  }
  float len = v3_len(d);
  h.dir = v3_scale(d, 1.0f / len);
  h.dist = vb->t[k] * len;
  h.l1 = vb->l1[k], h.l2 = vb->l2[k], h.l0 = 1.0f - h.l1 - h.l2;
  vec3 n = geometric_normal(s, h.id);
  if (s->n[0][0]) {
    vec3 sn = v3(0, 0, 0);
    float w[3] = {h.l0, h.l1, h.l2};
    for (int v = 0; v < 3; v++)
      sn = v3_add(sn, v3_scale(v3(s->n[v][0][h.id], s->n[v][1][h.id], s->n[v][2][h.id]), w[v]));
    if (v3_dot(sn, sn) > 1e-12f) {
      sn = v3_norm(sn);
      /* keep interpolated normals on the geometric normal's side */
      n = v3_dot(sn, n) < 0 ? v3_neg(sn) : sn;
    }
  }
  h.normal = v3_dot(n, h.dir) > 0 ? v3_neg(n) : n;
  return h;
}

static void texel(const rr_texture *t, float u, float v, float rgb[3]) {
  /* Wrap, bilinear; v points up in the file's convention, rows run down. */
  u -= floorf(u), v -= floorf(v);
  float fx = u * t->width - 0.5f, fy = (1.0f - v) * t->height - 0.5f;
  int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
  float ax = fx - x0, ay = fy - y0;
  for (int c = 0; c < 3; c++) rgb[c] = 0;
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 2; i++) {
      int xx = ((x0 + i) % t->width + t->width) % t->width, yy = ((y0 + j) % t->height + t->height) % t->height;
      float w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
      const uint8_t *p = t->rgb + 3 * ((size_t)yy * t->width + xx);
      for (int c = 0; c < 3; c++) rgb[c] += w * p[c] / 255.0f;
    }
  /* textures are sRGB-encoded; shading works in linear light */
  for (int c = 0; c < 3; c++) rgb[c] = srgb_decode(rgb[c]);
}

static void base_color(const rr_scene *s, const hit *h, float rgb[3]) {
  const rr_material *m = s->nmaterials ? &s->materials[s->material[h->id] % s->nmaterials] : NULL;
  rgb[0] = rgb[1] = rgb[2] = SCENE_GREY;
  if (!m) return;
  memcpy(rgb, m->color, sizeof m->color);
  if (m->texture.width > 0 && s->uv[0][0]) {
    uint32_t i = h->id;
    float u = h->l0 * s->uv[0][0][i] + h->l1 * s->uv[1][0][i] + h->l2 * s->uv[2][0][i];
    float v = h->l0 * s->uv[0][1][i] + h->l1 * s->uv[1][1][i] + h->l2 * s->uv[2][1][i];
    float t[3];
    texel(&m->texture, u, v, t);
    for (int c = 0; c < 3; c++) rgb[c] *= t[c];
  }
  if (s->col[0][0]) /* vertex colours (linear) multiply in, like glTF's COLOR_0 */
    for (int c = 0; c < 3; c++)
      rgb[c] *= h->l0 * s->col[0][c][h->id] + h->l1 * s->col[1][c][h->id] + h->l2 * s->col[2][c][h->id];
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

/* The eye distances of a layer's hits widen [*dmin, *dmax]. */
static void depth_range(const rr_scene *s, const camera *c, const visbuf *vb, float *dmin, float *dmax) {
  for (int y = 0; y < vb->height; y++)
    for (int x = 0; x < vb->width; x++) {
      hit h = hit_at(s, c, vb, x, y);
      if (h.valid) *dmin = fminf(*dmin, h.dist), *dmax = fmaxf(*dmax, h.dist);
    }
}

/* Shades one layer of samples (one sample per pixel, camera c at its position) into
 * px, 3 floats per pixel, left alone where the camera has no ray; depth shades
 * [dmin, dmax] from bright to dark. */
static void shade_layer(const rr_scene *s, const camera *cp, const visbuf *vb, rr_shade_mode mode, float dmin,
                        float dmax, float *px) {
  const camera c = *cp;
  for (int y = 0; y < vb->height; y++)
    for (int x = 0; x < vb->width; x++) {
      float *o = px + 3 * ((size_t)y * vb->width + x);
      hit h = hit_at(s, &c, vb, x, y);
      if (!h.has_ray) continue; /* black where the camera has no ray */
      if (h.valid && mode == RR_SHADE_LAMBERT) {
        float rgb[3];
        base_color(s, &h, rgb);
        float lit = 0.12f + 0.88f * fmaxf(0.0f, -v3_dot(h.normal, h.dir));
        for (int ch = 0; ch < 3; ch++) o[ch] = rgb[ch] * lit;
        continue;
      }
      /* everything else is designed in display colours, decoded to linear light below */
      if (!h.valid) {
        /* a quiet vertical gradient behind the scene */
        float g = 0.16f + 0.10f * (1.0f - (float)y / vb->height);
        o[0] = g * 0.9f, o[1] = g, o[2] = g * 1.15f;
      } else switch (mode) {
      case RR_SHADE_ID: {
        uint32_t hsh = hash32(scene_face_id(s, h.id) + 1); /* by id: the colour of a face whatever was dropped */
        for (int ch = 0; ch < 3; ch++) o[ch] = 0.2f + 0.8f * (float)((hsh >> (8 * ch)) & 255) / 255.0f;
        break;
      }
      case RR_SHADE_NORMAL:
        o[0] = 0.5f + 0.5f * h.normal.x, o[1] = 0.5f + 0.5f * h.normal.y, o[2] = 0.5f + 0.5f * h.normal.z;
        break;
      case RR_SHADE_DEPTH: {
        float g = dmax > dmin ? 1.0f - 0.85f * (h.dist - dmin) / (dmax - dmin) : 1.0f;
        o[0] = o[1] = o[2] = g;
        break;
      }
      default:
        break;
      }
      for (int ch = 0; ch < 3; ch++) o[ch] = srgb_decode(o[ch]);
    }
}

/* Heat maps: per pixel, drawn in display colours and stored in linear light. */
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
  float *px = out->data;
  for (size_t i = 0; i < (size_t)f->vb.width * f->vb.height * 3; i++) px[i] = srgb_decode(px[i]);
  return rr_ok(dev);
}

/* Layer s of a frame's visibility buffer: sample s of every pixel. */
static visbuf frame_layer(const rr_frame *f, int s) {
  size_t off = (size_t)s * f->vb.width * f->vb.height;
  return (visbuf){f->vb.width, f->vb.height, f->vb.id + off, f->vb.t + off, f->vb.l1 + off, f->vb.l2 + off};
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

/* Shades every sample of the frame (layer by layer, each at its own position) and
 * resolves them with the filter. */
static rr_error shade_frame(rr_device *dev, const rr_scene *s, const camera *cams, const rr_frame *f,
                            rr_shade_mode mode, const rr_resolve_options *ropt, rr_image *out) {
  size_t npix = (size_t)f->vb.width * f->vb.height, n = npix * f->samples;
  bool alpha = ropt && ropt->alpha;
  float *rgb = calloc(n * 3, sizeof *rgb), *cover = alpha ? malloc(n * sizeof *cover) : NULL;
  if (!rgb || (alpha && !cover)) {
    free(rgb), free(cover);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %d samples of a %dx%d image", f->samples, f->vb.width,
                   f->vb.height);
  }
  float dmin = INFINITY, dmax = 0;
  if (mode == RR_SHADE_DEPTH)
    for (int k = 0; k < f->samples; k++) {
      visbuf layer = frame_layer(f, k);
      depth_range(s, &cams[k], &layer, &dmin, &dmax);
    }
  for (int k = 0; k < f->samples; k++) {
    visbuf layer = frame_layer(f, k);
    shade_layer(s, &cams[k], &layer, mode, dmin, dmax, rgb + 3 * npix * k);
  }
  for (size_t i = 0; cover && i < n; i++) cover[i] = f->vb.id[i] < s->ntris ? 1.0f : 0.0f;
  resolve_input in = {f->vb.width, f->vb.height, f->samples, (const float(*)[2])f->sample_pos, rgb, NULL, cover};
  rr_error e = rr_resolve_image(dev, &in, ropt, f->stats.threads, out);
  free(rgb), free(cover);
  return e ? e : rr_ok(dev);
}

/* The value of an integer AOV (id, mesh, material) at a sample that saw primitive id. */
static uint32_t id_aov(const rr_scene *s, rr_aov aov, uint32_t id) {
  if (aov == RR_AOV_ID) return scene_face_id(s, id);
  if (id >= s->ntris) return RR_MISS;
  return aov == RR_AOV_MESH ? rr_scene_geometry_of(s, id) : s->material[id];
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

/* Fills an AOV from the frame's layers, by the rules of several samples per pixel
 * (rastray.h): a per-sample AOV takes every layer as a channel; coverage counts the
 * layers' hits; depth keeps the nearest; the others read the centre's layer. */
static rr_error frame_aov(rr_device *dev, const rr_scene *s, const camera *cams, const rr_frame *f, rr_aov aov,
                          rr_image *out) {
  const visbuf *vb = &f->vb;
  rr_error e;
  static const int channels[RR_AOV_COUNT] = {1, 1, 3, 2, 1, 1, 1, 1, 1};
  if (aov == RR_AOV_EVALS || aov == RR_AOV_NODES) {
    const float *counts = aov == RR_AOV_EVALS ? f->heat_e : f->heat_n;
    if (!counts) return rr_fail(dev, RR_ERROR_ARGUMENT, "AOVs evals and nodes need options.heat set when rendering");
    e = image_alloc(dev, out, vb->width, vb->height, 1, RR_PIXEL_F32, RR_IMAGE_AOV + (int)aov);
    if (e) return e;
    memcpy(out->data, counts, (size_t)vb->width * vb->height * sizeof(float));
    return rr_ok(dev);
  }
  rr_aov base = per_sample_base(aov);
  bool per_sample = base != aov, ints = base == RR_AOV_ID || base == RR_AOV_MESH || base == RR_AOV_MATERIAL;
  int ch = per_sample ? f->samples : channels[aov], centre = centre_sample(f);
  e = image_alloc(dev, out, vb->width, vb->height, ch, ints ? RR_PIXEL_U32 : RR_PIXEL_F32, RR_IMAGE_AOV + (int)aov);
  if (e) return e;
  size_t npix = (size_t)vb->width * vb->height;
  float *o = out->data;
  if (base == RR_AOV_DEPTH) /* a miss everywhere, until a sample sees nearer */
    for (size_t k = 0; k < npix * ch; k++) o[k] = INFINITY;
  for (int smp = 0; smp < f->samples; smp++) {
    if (!per_sample && base != RR_AOV_DEPTH && aov != RR_AOV_COVERAGE && smp != centre) continue;
    visbuf layer = frame_layer(f, smp);
    int c0 = per_sample ? smp : 0; /* this layer's channel */
    for (int y = 0; y < vb->height; y++)
      for (int x = 0; x < vb->width; x++) {
        size_t k = (size_t)y * vb->width + x;
        if (ints) {
          ((uint32_t *)out->data)[k * ch + c0] = id_aov(s, base, layer.id[k]);
          continue;
        }
        if (aov == RR_AOV_COVERAGE) {
          o[k] += layer.id[k] < s->ntris ? 1.0f / f->samples : 0.0f;
          continue;
        }
        hit h = hit_at(s, &cams[smp], &layer, x, y);
        float *p = o + k * ch + c0;
        if (base == RR_AOV_DEPTH) *p = fminf(*p, h.valid ? h.dist : INFINITY);
        else if (base == RR_AOV_NORMAL && h.valid) p[0] = h.normal.x, p[1] = h.normal.y, p[2] = h.normal.z;
        else if (base == RR_AOV_BARY && h.valid) p[0] = h.l1, p[1] = h.l2;
      }
  }
  return rr_ok(dev);
}

/* The public entry points resolve the frame's cameras, one per sample position, around the work. */
rr_error rr_shade_resolved(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f,
                           rr_shade_mode mode, const rr_resolve_options *resolve, rr_image *out) {
  if (!s || !cam || !f || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_shade: NULL argument");
  if ((int)mode < 0 || mode >= RR_SHADE_COUNT) return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown shade mode %d", (int)mode);
  if (mode == RR_SHADE_HEAT_EVALS || mode == RR_SHADE_HEAT_NODES) return shade_heat_frame(dev, f, mode, out);
  camera cams[RR_MAX_SAMPLES];
  rr_error e = frame_cameras(dev, cam, f, cams);
  if (e) return e;
  e = shade_frame(dev, s, cams, f, mode, resolve, out);
  for (int k = 0; k < f->samples; k++) rr_cam_release(&cams[k]);
  return e;
}

rr_error rr_shade(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_shade_mode mode,
                  rr_image *out) {
  return rr_shade_resolved(dev, s, cam, f, mode, NULL, out);
}

rr_error rr_frame_aov(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_frame *f, rr_aov aov,
                      rr_image *out) {
  if (!s || !cam || !f || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_frame_aov: NULL argument");
  if ((int)aov < 0 || aov >= RR_AOV_COUNT) return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown AOV %d", (int)aov);
  camera cams[RR_MAX_SAMPLES];
  rr_error e = frame_cameras(dev, cam, f, cams);
  if (e) return e;
  e = frame_aov(dev, s, cams, f, aov, out);
  for (int k = 0; k < f->samples; k++) rr_cam_release(&cams[k]);
  return e;
}
