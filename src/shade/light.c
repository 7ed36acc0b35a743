/* The lit shade mode: lights, the material model and the passes over a batch of
 * points (docs/shading.md is the reference for every formula here). */
#include "shade/light.h"
#include "vis/shadow_raster.h"

#include <string.h>

int rr_shadows_from_name(const char *name) {
  static const char *const names[RR_SHADOWS_COUNT] = {"none", "rays", "raster", "auto"};
  for (int k = 0; name && k < RR_SHADOWS_COUNT; k++)
    if (strcmp(name, names[k]) == 0) return k;
  return -1;
}

/* ---- lights of a frame ---------------------------------------------------- */

static bool push_light(lighting *L, const rr_light_info *li) {
  light *p = realloc(L->lights, (L->nlights + 1) * sizeof *p);
  if (!p) return false;
  L->lights = p;
  bool spot = li->type == RR_LIGHT_SPOT;
  float deg = (float)RR_PI / 180.0f;
  p[L->nlights++] = (light){.type = li->type == RR_LIGHT_AREA ? RR_LIGHT_POINT : li->type,
                            .pos = v3_load(li->position),
                            .dir = v3_norm(v3_load(li->direction)),
                            .rgb = {li->color[0], li->color[1], li->color[2]},
                            .cos_inner = spot ? cosf(li->inner_cone_deg * deg) : -1,
                            .cos_outer = spot ? cosf(li->outer_cone_deg * deg) : -1};
  return true;
}

static void add_sky(lighting *L, const rr_light_info *li) {
  bool constant = li->ground[0] == 0 && li->ground[1] == 0 && li->ground[2] == 0;
  for (int c = 0; c < 3; c++) L->sky[c] += li->color[c], L->ground[c] += constant ? li->color[c] : li->ground[c];
}

/* The default rig: a directional key light from above, to the left and behind the
 * camera (so its shadows fall visibly behind and beside what it lights), with an
 * irradiance that puts a white surface facing it near 0.8, and a gradient sky that
 * keeps the shadows readable. */
static bool default_rig(lighting *L, const rr_scene *s, const rr_camera *cam) {
  vec3 up = s->up, fwd = v3_norm(v3_sub(v3_load(cam->target), v3_load(cam->eye)));
  vec3 right = v3_cross(fwd, up);
  if (!(v3_dot(right, right) > 1e-8f)) right = v3_cross(fwd, v3(fwd.y, fwd.z, fwd.x)); /* looking along up */
  right = v3_norm(right);
  vec3 towards = v3_norm(v3_add(v3_add(v3_scale(up, 1.0f), v3_scale(fwd, -0.7f)), v3_scale(right, -0.6f)));
  rr_light_info key = {.type = RR_LIGHT_DIRECTIONAL, .color = {2.3f, 2.25f, 2.15f}};
  v3_store(key.direction, v3_neg(towards));
  rr_light_info sky = {.type = RR_LIGHT_AMBIENT, .color = {0.24f, 0.27f, 0.32f}, .ground = {0.075f, 0.07f, 0.065f}};
  add_sky(L, &sky);
  return push_light(L, &key);
}

/* Whether a file's light can be shaded: finite, colours not negative (a file may say anything). */
static bool usable(const rr_light_info *li) {
  const float *v[] = {li->position, li->direction, li->color, li->ground};
  for (int k = 0; k < 4; k++)
    for (int c = 0; c < 3; c++)
      if (!isfinite(v[k][c]) || (k >= 2 && v[k][c] < 0)) return false;
  return isfinite(li->inner_cone_deg) && isfinite(li->outer_cone_deg);
}

rr_error rr_lighting_make(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_shade_options *opt,
                       lighting *L) {
  *L = (lighting){.up = s->up, .shadows = opt->shadows, .max_depth = opt->max_depth};
  vec3 ext = v3_sub(s->bmax, s->bmin);
  L->eps = 1e-5f * (v3_dot(ext, ext) > 0 && isfinite(v3_dot(ext, ext)) ? v3_len(ext) : 1.0f);
  bool ok = true;
  for (uint32_t k = 0; k < s->nlights && ok; k++) {
    const rr_light_info *li = &s->lights[k];
    if (!usable(li)) continue;
    if (li->type == RR_LIGHT_AMBIENT) add_sky(L, li);
    else if (li->type != RR_LIGHT_UNDEFINED) ok = push_light(L, li);
  }
  if (ok && s->nlights == 0 && opt->default_lights) ok = default_rig(L, s, cam);
  if (!ok) {
    rr_lighting_release(L);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for the lights");
  }
  return RR_OK;
}

void rr_lighting_release(lighting *L) {
  free(L->lights);
  L->lights = NULL, L->nlights = 0;
}

/* ---- the material model --------------------------------------------------- */

/* Light arriving at p from light li: the unit direction l towards it and the
 * irradiance E (rgb) on a surface facing it; false when none arrives. */
static bool light_at(const light *li, vec3 p, vec3 *l, float E[3]) {
  float k = 1;
  if (li->type == RR_LIGHT_DIRECTIONAL) {
    *l = v3_neg(li->dir);
  } else {
    vec3 d = v3_sub(li->pos, p);
    float r2 = v3_dot(d, d);
    if (!(r2 > 0)) return false;
    *l = v3_scale(d, 1.0f / sqrtf(r2));
    k = 1.0f / r2; /* candela to lux: the inverse square law */
    if (li->type == RR_LIGHT_SPOT) { /* glTF's smooth cone: the square of a linear ramp in cos */
      float cd = -v3_dot(*l, li->dir), w = li->cos_inner - li->cos_outer;
      float t = w > 0 ? fminf(fmaxf((cd - li->cos_outer) / w, 0.0f), 1.0f) : cd >= li->cos_outer;
      k *= t * t;
    }
  }
  for (int c = 0; c < 3; c++) E[c] = li->rgb[c] * k;
  return k > 0;
}

static float sq(float x) { return x * x; }

/* glTF's F0: 4% for dielectrics, the base colour for metals. */
static float f0_of(const surface *sf, int c) {
  float mt = sf->m->params.metallic;
  return 0.04f * (1 - mt) + sf->base[c] * mt;
}

/* The BRDF f(l, v) of the surface (per colour channel, the diffuse 1/π included). */
static void brdf(const surface *sf, vec3 l, float f[3]) {
  const rr_material *m = sf->m;
  vec3 h = v3_norm(v3_add(l, sf->v));
  float nh = fmaxf(v3_dot(sf->n, h), 0.0f), inv_pi = (float)(1 / RR_PI);
  if (!m || m->params.model == RR_MATERIAL_PHONG) {
    const rr_material_params *p = m ? &m->params : NULL;
    /* normalised Blinn–Phong: (Ns + 8) / 8π keeps the lobe's energy about fixed as Ns changes */
    float spec = p && p->shininess > 0 ? (p->shininess + 8) / 8 * inv_pi * powf(nh, p->shininess) : 0;
    for (int c = 0; c < 3; c++) f[c] = sf->base[c] * inv_pi + (p ? p->specular[c] * spec : 0);
    return;
  }
  /* GGX with height-correlated Smith visibility, Schlick's Fresnel (glTF Appendix B) */
  float mt = m->params.metallic, a2 = fmaxf(sq(sq(m->params.roughness)), 1e-4f);
  float nl = fmaxf(v3_dot(sf->n, l), 0.0f), nv = fmaxf(v3_dot(sf->n, sf->v), 1e-4f);
  float vh = fmaxf(v3_dot(sf->v, h), 0.0f);
  float D = a2 * inv_pi / sq(nh * nh * (a2 - 1) + 1);
  float V = 0.5f / (nl * sqrtf(nv * nv * (1 - a2) + a2) + nv * sqrtf(nl * nl * (1 - a2) + a2));
  float fw = powf(1 - vh, 5);
  for (int c = 0; c < 3; c++) {
    float F = f0_of(sf, c) + (1 - f0_of(sf, c)) * fw;
    f[c] = (1 - F) * sf->base[c] * (1 - mt) * inv_pi + F * D * V;
  }
}

/* PBR surfaces this smooth are mirrors. */
#define MIRROR_ROUGHNESS 0.1f

/* The mirror reflectance of the surface seen along v (0: not a mirror). */
static bool mirror_of(const surface *sf, float R[3]) {
  const rr_material *m = sf->m;
  R[0] = R[1] = R[2] = 0;
  if (!m) return false;
  if (m->params.model == RR_MATERIAL_PHONG) {
    if (m->params.illum != 3) return false;
    memcpy(R, m->params.specular, 3 * sizeof(float));
  } else {
    if (!(m->params.roughness < MIRROR_ROUGHNESS)) return false;
    float fw = powf(1 - fminf(fmaxf(v3_dot(sf->n, sf->v), 0.0f), 1.0f), 5);
    for (int c = 0; c < 3; c++) R[c] = f0_of(sf, c) + (1 - f0_of(sf, c)) * fw;
  }
  return R[0] > 0 || R[1] > 0 || R[2] > 0;
}

/* The sky's radiance along unit direction w. */
static void sky_along(const lighting *L, vec3 w, float o[3]) {
  float a = 0.5f * (1 + v3_dot(w, L->up));
  for (int c = 0; c < 3; c++) o[c] = L->ground[c] + (L->sky[c] - L->ground[c]) * a;
}

/* The colour of the diffuse lobe. */
static void albedo_of(const surface *sf, float a[3]) {
  bool pbr = sf->m && sf->m->params.model == RR_MATERIAL_PBR;
  for (int c = 0; c < 3; c++) a[c] = sf->base[c] * (pbr ? 1 - sf->m->params.metallic : 1);
}

/* The sky's light, which needs no ray: on the diffuse lobe its irradiance over the
 * hemisphere of n, exactly, without occlusion; on rough PBR surfaces also on the
 * specular lobe, as F0 times the sky along n (an approximation). */
static void sky_light(const surface *sf, const lighting *L, float o[3]) {
  const rr_material *m = sf->m;
  float nu = v3_dot(sf->n, L->up), diffuse[3], spec_sky[3] = {0, 0, 0};
  albedo_of(sf, diffuse);
  if (m && m->params.model == RR_MATERIAL_PBR && !(m->params.roughness < MIRROR_ROUGHNESS)) {
    sky_along(L, sf->n, spec_sky);
    for (int c = 0; c < 3; c++) spec_sky[c] *= f0_of(sf, c);
  }
  for (int c = 0; c < 3; c++) {
    /* E/π of the sky L(w) = g + (s - g)(1 + w·up)/2 over the hemisphere of n */
    float e = 0.5f * (L->sky[c] + L->ground[c]) + (L->sky[c] - L->ground[c]) * nu / 3;
    o[c] = diffuse[c] * e + spec_sky[c];
  }
}

/* ---- batches --------------------------------------------------------------- */

/* The points of one bounce: their surfaces, what they pass on to the pixel
 * (throughput, rgb) and where their colour goes: out, and the parts of the first
 * bounce's points (parts) or the reflection part of the point they are seen in (refl). */
typedef struct level {
  int n;
  surface pt[LIT_BATCH];
  float w[LIT_BATCH][3];
  float *out[LIT_BATCH], *parts[LIT_BATCH], *refl[LIT_BATCH];
} level;

struct lit_batch {
  level lv[2]; /* this bounce's points and the next's */
  int cur;
  rr_ray ray[LIT_BATCH];
  int who[LIT_BATCH];           /* the point ray k belongs to */
  float add[LIT_BATCH][3];      /* what ray k brings when it is not blocked (shadows), its throughput (mirrors) */
  int occluded[LIT_BATCH];
  rr_hit hit[LIT_BATCH];
};

lit_batch *rr_lit_batch_new(void) {
  lit_batch *b = malloc(sizeof *b); /* not zeroed: ~300 KB, of which the counts say what is set */
  if (b) b->lv[0].n = b->lv[1].n = 0, b->cur = 0;
  return b;
}
void rr_lit_batch_free(lit_batch *b) { free(b); }

bool rr_lit_batch_add(lit_batch *b, const surface *sf, float *out, float *parts) {
  level *lv = &b->lv[b->cur];
  if (lv->n == LIT_BATCH) return false;
  lv->pt[lv->n] = *sf, lv->out[lv->n] = out, lv->parts[lv->n] = parts, lv->refl[lv->n] = NULL;
  lv->w[lv->n][0] = lv->w[lv->n][1] = lv->w[lv->n][2] = 1;
  out[0] = out[1] = out[2] = 0;
  if (parts) {
    memset(parts, 0, LIT_PARTS * sizeof *parts);
    albedo_of(sf, parts + LIT_ALBEDO);
  }
  lv->n++;
  return true;
}

/* A ray leaving p on the side of the geometric normal ng that dir goes to: its
 * origin is offset along ng by 1e-5 · (|p|∞ + the scene's diagonal) (shading.md). */
static rr_ray leave(const lighting *L, vec3 p, vec3 ng, vec3 dir, float tmax) {
  float big = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
  float eps = 1e-5f * big + L->eps;
  vec3 o = v3_add(p, v3_scale(ng, v3_dot(ng, dir) >= 0 ? eps : -eps));
  return (rr_ray){{o.x, o.y, o.z}, {dir.x, dir.y, dir.z}, 0, tmax};
}

/* Adds w·v to point i's colour and to the part it belongs to: `part` for a point
 * of the first bounce, the reflection of the point it is seen in for the others. */
static void credit(const level *lv, int i, int part, const float w[3], const float v[3]) {
  float *p = lv->parts[i] ? lv->parts[i] + part : lv->refl[i];
  for (int c = 0; c < 3; c++) {
    lv->out[i][c] += w[c] * v[c];
    if (p) p[c] += w[c] * v[c];
  }
}

/* --shadows auto rasterizes a point or spot light's shadow rays when a batch
 * holds at least this many of them. bench/bench_shading's sweep (instructions,
 * 1024²): in runs of 1024 rays raster costs 0.99x the streams on the demo and
 * 1.12x on the bunny over a plane (whole frames 0.94x and 1.09x); in the lit
 * mode's batches of 64 points (one sample per pixel) 1.20x, of 1024 (16 samples)
 * 0.94x on the demo. A directional light's parallel rays rasterized cost about
 * 2.0x and 1.6x (each ray keeps its own edge setup): auto traces them. */
#define SHADOW_RASTER_MIN 512

/* Direct light on a level's points: one pass per light, its shadow rays in one
 * stream, or rasterized from the light (vis/shadow_raster.c: the same bits). */
static void direct(lit_batch *b, const level *lv, const rr_scene *s, const lighting *L, lit_stats *st) {
  for (int i = 0; i < lv->n; i++) {
    float sky[3];
    sky_light(&lv->pt[i], L, sky);
    credit(lv, i, LIT_DIRECT, lv->w[i], sky);
    if (lv->pt[i].m) credit(lv, i, LIT_EMISSION, lv->w[i], lv->pt[i].m->params.emission);
    if (lv->parts[i] && !L->nlights) lv->parts[i][LIT_SHADOW] = 1; /* nothing to block */
  }
  float share = L->nlights ? 1.0f / (float)L->nlights : 0; /* of the shadow part, per light */
  bool empty;
  const rr_bvh *bvh = rr_bvh_of(NULL, s, &empty); /* (checked current by rr_shade_frame) */
  for (int li = 0; li < L->nlights; li++) {
    const light *lt = &L->lights[li];
    bool far = lt->type == RR_LIGHT_DIRECTIONAL;
    int nr = 0;
    for (int i = 0; i < lv->n; i++) {
      const surface *sf = &lv->pt[i];
      vec3 l;
      float E[3], f[3];
      if (!light_at(lt, sf->p, &l, E)) continue;
      float cos = v3_dot(sf->n, l);
      if (!(cos > 0)) continue;
      brdf(sf, l, f);
      float c3[3];
      for (int c = 0; c < 3; c++) c3[c] = f[c] * E[c] * cos;
      if (L->shadows == RR_SHADOWS_NONE) {
        credit(lv, i, LIT_DIRECT, lv->w[i], c3);
        if (lv->parts[i]) lv->parts[i][LIT_SHADOW] += share;
        continue;
      }
      b->ray[nr] = leave(L, sf->p, sf->ng, l, far ? INFINITY : 1.0f);
      if (!far) { /* from the light to the ray's origin, reached at t = 1: the light's rays share their origin */
        vec3 d = v3_sub(v3_load(b->ray[nr].org), lt->pos);
        v3_store(b->ray[nr].org, lt->pos), v3_store(b->ray[nr].dir, d);
      }
      b->who[nr] = i;
      memcpy(b->add[nr], c3, sizeof c3);
      nr++;
    }
    if (!nr) continue;
    double t0 = rr_now_ms();
    /* analytic primitives (prim/analytic.h) are not rasterized from the light yet: rays */
    bool raster = !s->kind && (L->shadows == RR_SHADOWS_RASTER ||
                               (L->shadows == RR_SHADOWS_AUTO && !far && nr >= SHADOW_RASTER_MIN));
    if (!raster || !rr_occluded_raster(s, bvh, b->ray, (size_t)nr, 1, b->occluded, NULL)) {
      rr_ray_stream rs = rr_ray_stream_aos(b->ray, (size_t)nr);
      rr_occluded_stream(NULL, s, &rs, 1, b->occluded); /* a refused ray (zero length) counts as lit */
    }
    st->shadow_ms += rr_now_ms() - t0, st->shadow_rays += (uint64_t)nr;
    for (int k = 0; k < nr; k++) {
      int i = b->who[k];
      if (b->occluded[k]) continue;
      credit(lv, i, LIT_DIRECT, lv->w[i], b->add[k]);
      if (lv->parts[i]) lv->parts[i][LIT_SHADOW] += share;
    }
  }
}

/* Mirror bounces: the reflected rays of a level's mirrors in one stream; the
 * surfaces they hit become the next level (the sky where they miss, and beyond
 * the last bounce). */
static void reflect(lit_batch *b, const level *lv, level *next, bool last, const rr_scene *s, const lighting *L,
                    surface_fn fn, void *ctx, lit_stats *st) {
  int nr = 0;
  next->n = 0;
  for (int i = 0; i < lv->n; i++) {
    const surface *sf = &lv->pt[i];
    float R[3];
    if (!mirror_of(sf, R)) continue;
    /* the view mirrored about the shading normal, or about the geometric one when
     * that would leave through the surface */
    vec3 r = v3_sub(v3_scale(sf->n, 2 * v3_dot(sf->n, sf->v)), sf->v);
    if (!(v3_dot(r, sf->ng) > 0)) r = v3_sub(v3_scale(sf->ng, 2 * v3_dot(sf->ng, sf->v)), sf->v);
    float w[3] = {lv->w[i][0] * R[0], lv->w[i][1] * R[1], lv->w[i][2] * R[2]};
    if (last) {
      float sky[3];
      sky_along(L, r, sky);
      credit(lv, i, LIT_REFLECTION, w, sky);
      continue;
    }
    b->ray[nr] = leave(L, sf->p, sf->ng, r, INFINITY);
    b->who[nr] = i;
    memcpy(b->add[nr], w, sizeof w);
    nr++;
  }
  if (!nr) return;
  double t0 = rr_now_ms();
  rr_ray_stream rs = rr_ray_stream_aos(b->ray, (size_t)nr);
  rr_intersect_stream(NULL, s, &rs, 1, b->hit);
  for (int k = 0; k < nr; k++) {
    uint32_t idx = rr_scene_index_of(s, b->hit[k].prim);
    vec3 org = v3_load(b->ray[k].org), dir = v3_load(b->ray[k].dir);
    int i = b->who[k];
    if (idx == RR_MISS) {
      float sky[3];
      sky_along(L, dir, sky);
      credit(lv, i, LIT_REFLECTION, b->add[k], sky);
      continue;
    }
    int j = next->n++;
    fn(ctx, idx, b->hit[k].l1, b->hit[k].l2, b->hit[k].t, org, dir, &next->pt[j]);
    memcpy(next->w[j], b->add[k], sizeof b->add[k]);
    next->out[j] = lv->out[i], next->parts[j] = NULL;
    next->refl[j] = lv->parts[i] ? lv->parts[i] + LIT_REFLECTION : lv->refl[i];
  }
  st->reflection_ms += rr_now_ms() - t0, st->reflection_rays += (uint64_t)nr;
}

void rr_lit_batch_shade(lit_batch *b, const rr_scene *s, const lighting *L, surface_fn fn, void *ctx, lit_stats *st) {
  for (int depth = 0;; depth++) {
    level *lv = &b->lv[b->cur], *next = &b->lv[1 - b->cur];
    if (!lv->n) break;
    direct(b, lv, s, L, st);
    reflect(b, lv, next, depth >= L->max_depth, s, L, fn, ctx, st);
    lv->n = 0;
    b->cur = 1 - b->cur;
  }
  b->lv[0].n = b->lv[1].n = 0, b->cur = 0;
}
