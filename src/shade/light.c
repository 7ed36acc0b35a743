/* The lit shade mode: lights, the material model and the passes over a wave of
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

bool rr_material_mirror(const rr_material *m) {
  if (!m) return false;
  const float *ks = m->params.specular;
  if (m->params.model == RR_MATERIAL_PHONG) return m->params.illum == 3 && (ks[0] > 0 || ks[1] > 0 || ks[2] > 0);
  return m->params.roughness < MIRROR_ROUGHNESS;
}

/* The mirror reflectance of the surface seen along v (0: not a mirror). */
static bool mirror_of(const surface *sf, float R[3]) {
  const rr_material *m = sf->m;
  R[0] = R[1] = R[2] = 0;
  if (!rr_material_mirror(m)) return false;
  if (m->params.model == RR_MATERIAL_PHONG) {
    memcpy(R, m->params.specular, 3 * sizeof(float));
  } else {
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

/* ---- waves: the passes ------------------------------------------------------ */

/* A point of one bounce: its surface, what it passes on to the pixel (throughput
 * w), and where its colour goes: out, and the parts of a first bounce's point
 * (parts) or the reflection part of the point it is seen in (refl). out NULL: no
 * point (a reflection ray that left the scene). */
typedef struct lit_point {
  surface sf;
  float w[3];
  uint32_t reach; /* bit l < REACH_BITS: light l reaches it (facing, in its cone); bit MIRROR_BIT: a mirror */
  float *out, *parts, *refl;
  float *vis; /* NULL, or per light 1 where it reaches the point (a first bounce's) */
} lit_point;

/* A bit per point and light, set by the ambient pass, spares each light pass a
 * sweep to count its rays; lights past the first REACH_BITS count theirs. */
enum { REACH_BITS = 31, MIRROR_BIT = 31 };

/* CHUNK points are a block of a segment and a job of a pass; a chunk's rays lie
 * together in the pass's arrays, from `first` on (its points in order). */
enum { CHUNK = 4096 };

/* Points in blocks of CHUNK (kept from wave to wave; never moved, so growing
 * copies nothing): a sink of the first bounce, or a later bounce's points (point
 * k for reflection ray k of the bounce before). */
typedef struct seg {
  lit_point **block;
  size_t n, nblocks, cap; /* points; blocks made; room for block pointers */
} seg;
typedef struct chunk {
  lit_point *p;
  size_t n, first, rays;
  uint32_t reached[32]; /* the ambient pass's count of points with bit b of reach set */
} chunk;

struct lit_wave {
  seg sink[RR_MAX_THREADS]; /* the first bounce's points, by the thread that queued them */
  seg bounce[2];            /* the later bounces' points, alternately */
  chunk *ch;                /* the current pass's chunks */
  size_t nch, chcap;
  rr_ray *ray; /* the current pass's rays, ray k leaving point who[k] and bringing add[k] (shadows: */
  lit_point **who; /* its light unless blocked; mirrors: its throughput) */
  float (*add)[3];
  int *occluded;
  rr_hit *hit;
  vec3 (*diff)[4]; /* reflections: ray k's differentials (when who[k]->sf.diff) */
  size_t raycap;
};

lit_wave *rr_lit_wave_new(void) { return calloc(1, sizeof(lit_wave)); }

static void seg_free(seg *g) {
  for (size_t b = 0; b < g->nblocks; b++) free(g->block[b]);
  free(g->block);
}

void rr_lit_wave_free(lit_wave *w) {
  if (!w) return;
  for (int t = 0; t < RR_MAX_THREADS; t++) seg_free(&w->sink[t]);
  seg_free(&w->bounce[0]), seg_free(&w->bounce[1]), free(w->ch);
  free(w->ray), free(w->who), free(w->add), free(w->occluded), free(w->hit), free(w->diff);
  free(w);
}

/* Room for n points in g. */
static bool seg_reserve(seg *g, size_t n) {
  size_t need = (n + CHUNK - 1) / CHUNK;
  if (need > g->cap) {
    size_t cap = g->cap ? 2 * g->cap : 16;
    cap = cap < need ? need : cap;
    lit_point **b = realloc(g->block, cap * sizeof *b);
    if (!b) return false;
    g->block = b, g->cap = cap;
  }
  for (; g->nblocks < need; g->nblocks++)
    if (!(g->block[g->nblocks] = malloc(CHUNK * sizeof(lit_point)))) return false;
  return true;
}

static lit_point *seg_at(const seg *g, size_t i) { return &g->block[i / CHUNK][i % CHUNK]; }

bool rr_lit_wave_add(lit_wave *w, int thread, const surface *sf, float *out, float *parts, float *vis) {
  seg *g = &w->sink[thread];
  if (g->n == g->nblocks * CHUNK && !seg_reserve(g, g->n + 1)) return false;
  lit_point *q = seg_at(g, g->n++);
  q->sf = *sf, q->out = out, q->parts = parts, q->refl = NULL, q->vis = vis;
  q->w[0] = q->w[1] = q->w[2] = 1;
  out[0] = out[1] = out[2] = 0;
  if (parts) {
    memset(parts, 0, LIT_PARTS * sizeof *parts);
    albedo_of(sf, parts + LIT_ALBEDO);
  }
  return true;
}

/* Room for n rays in the pass arrays. */
static bool rays_reserve(lit_wave *w, size_t n) {
  if (n <= w->raycap) return true;
  free(w->ray), free(w->who), free(w->add), free(w->occluded), free(w->hit), free(w->diff);
  w->ray = malloc(n * sizeof *w->ray), w->who = malloc(n * sizeof *w->who), w->add = malloc(n * sizeof *w->add);
  w->occluded = malloc(n * sizeof *w->occluded), w->hit = malloc(n * sizeof *w->hit);
  w->diff = malloc(n * sizeof *w->diff);
  w->raycap = w->ray && w->who && w->add && w->occluded && w->hit && w->diff ? n : 0;
  return w->raycap != 0;
}

/* The chunks of the segments g[0..n-1]. */
static bool chunks_of(lit_wave *w, const seg *g, int n) {
  size_t nch = 0;
  for (int k = 0; k < n; k++) nch += (g[k].n + CHUNK - 1) / CHUNK;
  if (nch > w->chcap) {
    chunk *c = realloc(w->ch, nch * sizeof *c);
    if (!c) return false;
    w->ch = c, w->chcap = nch;
  }
  w->nch = 0;
  for (int k = 0; k < n; k++)
    for (size_t i = 0; i < g[k].n; i += CHUNK)
      w->ch[w->nch++] = (chunk){g[k].block[i / CHUNK], g[k].n - i < CHUNK ? g[k].n - i : CHUNK, 0, 0, {0}};
  return true;
}

/* Numbers the chunks' rays one after the other; their total. */
static size_t rays_place(lit_wave *w) {
  size_t total = 0;
  for (size_t c = 0; c < w->nch; c++) w->ch[c].first = total, total += w->ch[c].rays;
  return total;
}

/* A ray leaving p on the side of the geometric normal ng that dir goes to: its
 * origin is offset along ng by 1e-5 · (|p|∞ + the scene's diagonal) (shading.md). */
static rr_ray leave(const lighting *L, vec3 p, vec3 ng, vec3 dir, float tmax) {
  float big = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
  float eps = 1e-5f * big + L->eps;
  vec3 o = v3_add(p, v3_scale(ng, v3_dot(ng, dir) >= 0 ? eps : -eps));
  return (rr_ray){{o.x, o.y, o.z}, {dir.x, dir.y, dir.z}, 0, tmax};
}

/* Adds w·v to point q's colour and to the part it belongs to: `part` for a point
 * of the first bounce, the reflection of the point it is seen in for the others. */
static void credit(const lit_point *q, int part, const float w[3], const float v[3]) {
  float *p = q->parts ? q->parts + part : q->refl;
  for (int c = 0; c < 3; c++) {
    q->out[c] += w[c] * v[c];
    if (p) p[c] += w[c] * v[c];
  }
}

/* What a pass's jobs share. */
typedef struct pass {
  lit_wave *w;
  const rr_scene *s;
  const lighting *L;
  const light *lt; /* the light of a light pass */
  int li;          /* its index */
  int bit;         /* its bit of reach (REACH_BITS: none, with shadows none or past the first lights) */
  float share;     /* of the shadow part, per light */
  bool last;       /* reflection: the last bounce (the sky instead of rays) */
  seg *next;       /* reflection: the next bounce's points, one per ray */
  surface_fn fn;
  void *ctx;
} pass;

static bool light_on(const light *lt, const lit_point *q, vec3 *l, float c3[3]);
static bool mirror_dir(const lit_point *q, float R[3], vec3 *r, vec3 diff[4]);

/* The light that needs no ray: the sky, emission; and with no punctual light,
 * nothing to block. Marks which lights reach each point and which are mirrors,
 * and counts them. */
static void job_ambient(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  const lighting *L = ps->L;
  chunk *c = &ps->w->ch[job];
  int bits = L->shadows == RR_SHADOWS_NONE ? 0 : L->nlights < REACH_BITS ? L->nlights : REACH_BITS;
  memset(c->reached, 0, sizeof c->reached);
  for (size_t i = 0; i < c->n; i++) {
    lit_point *q = &c->p[i];
    q->reach = 0;
    if (!q->out) continue;
    float sky[3], R[3];
    sky_light(&q->sf, L, sky);
    credit(q, LIT_DIRECT, q->w, sky);
    if (q->sf.m) credit(q, LIT_EMISSION, q->w, q->sf.m->params.emission);
    if (q->parts && !L->nlights) q->parts[LIT_SHADOW] = 1;
    if (q->vis) memset(q->vis, 0, L->nlights * sizeof *q->vis);
    vec3 l;
    for (int b = 0; b < bits; b++)
      if (light_on(&L->lights[b], q, &l, NULL)) q->reach |= 1u << b, c->reached[b]++;
    if (mirror_dir(q, R, &l, NULL)) q->reach |= 1u << MIRROR_BIT, c->reached[MIRROR_BIT]++;
  }
}

/* The light's direction l and what it brings, c3 = f·E·cos, at point q; false
 * when none arrives or q faces away. */
static bool light_on(const light *lt, const lit_point *q, vec3 *l, float c3[3]) {
  float E[3], f[3];
  if (!q->out || !light_at(lt, q->sf.p, l, E)) return false;
  float cos = v3_dot(q->sf.n, *l);
  if (!(cos > 0)) return false;
  if (c3) {
    brdf(&q->sf, *l, f);
    for (int c = 0; c < 3; c++) c3[c] = f[c] * E[c] * cos;
  }
  return true;
}

static void job_light_count(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  chunk *c = &ps->w->ch[job];
  vec3 l;
  c->rays = 0;
  for (size_t i = 0; i < c->n; i++) c->rays += light_on(ps->lt, &c->p[i], &l, NULL);
}

/* The chunk's shadow rays: from a point or spot light to the point offset towards
 * it (rays from one light share their origin: the light is a camera), from the
 * point along a directional light's direction; without shadows, the light itself. */
static void job_light_rays(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  lit_wave *w = ps->w;
  const chunk *c = &w->ch[job];
  bool far = ps->lt->type == RR_LIGHT_DIRECTIONAL, marked = ps->bit < REACH_BITS;
  size_t k = c->first;
  for (size_t i = 0; i < c->n; i++) {
    const lit_point *q = &c->p[i];
    vec3 l;
    float c3[3];
    if (marked && !(q->reach >> ps->bit & 1)) continue;
    if (!light_on(ps->lt, q, &l, c3)) continue;
    if (ps->L->shadows == RR_SHADOWS_NONE) {
      credit(q, LIT_DIRECT, q->w, c3);
      if (q->parts) q->parts[LIT_SHADOW] += ps->share;
      if (q->vis) q->vis[ps->li] = 1;
      continue;
    }
    w->ray[k] = leave(ps->L, q->sf.p, q->sf.ng, l, far ? INFINITY : 1.0f);
    if (!far) { /* from the light to the ray's origin, reached at t = 1 */
      vec3 d = v3_sub(v3_load(w->ray[k].org), ps->lt->pos);
      v3_store(w->ray[k].org, ps->lt->pos), v3_store(w->ray[k].dir, d);
    }
    w->who[k] = (lit_point *)q;
    memcpy(w->add[k], c3, sizeof c3);
    k++;
  }
}

static void job_light_add(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  const lit_wave *w = ps->w;
  const chunk *c = &w->ch[job];
  for (size_t k = c->first; k < c->first + c->rays; k++) {
    if (w->occluded[k]) continue;
    const lit_point *q = w->who[k];
    credit(q, LIT_DIRECT, q->w, w->add[k]);
    if (q->parts) q->parts[LIT_SHADOW] += ps->share;
    if (q->vis) q->vis[ps->li] = 1;
  }
}

/* --shadows auto rasterizes a point or spot light's shadow rays when its pass
 * holds at least this many. bench/bench_shading's sweep (callgrind, one thread,
 * 1024²; docs/shading.md): rasterizing runs of N rays costs, against the streams,
 * 0.99x (N = 1024), 0.94x (4096) and 0.94x from 16384 on (the gain has saturated)
 * on the demo, 1.12x, 1.10x and 1.08x on the bunny over a mirror. A directional
 * light's parallel rays keep each its own edge setup: rasterized they cost 1.4x
 * to 2.1x the streams at every N, so auto traces them. */
#define SHADOW_RASTER_MIN 16384

/* One pass per light: its shadow rays made in parallel, tested together (one
 * rasterization from the light, or one stream: the same bits), then added. */
static bool direct(lit_wave *w, pass *ps, int threads, lit_stats *st) {
  const lighting *L = ps->L;
  rr_parallel_for((int)w->nch, threads, job_ambient, ps);
  ps->share = L->nlights ? 1.0f / (float)L->nlights : 0;
  bool empty;
  const rr_bvh *bvh = rr_bvh_of(NULL, ps->s, &empty); /* (checked current by rr_shade_frame) */
  for (int li = 0; li < L->nlights; li++) {
    ps->lt = &L->lights[li], ps->li = li;
    bool far = ps->lt->type == RR_LIGHT_DIRECTIONAL;
    ps->bit = L->shadows != RR_SHADOWS_NONE && li < REACH_BITS ? li : REACH_BITS;
    if (L->shadows == RR_SHADOWS_NONE)
      for (size_t c = 0; c < w->nch; c++) w->ch[c].rays = 0;
    else if (ps->bit < REACH_BITS) /* counted by the ambient pass */
      for (size_t c = 0; c < w->nch; c++) w->ch[c].rays = w->ch[c].reached[li];
    else rr_parallel_for((int)w->nch, threads, job_light_count, ps);
    size_t nr = rays_place(w);
    if (!rays_reserve(w, nr)) return false;
    rr_parallel_for((int)w->nch, threads, job_light_rays, ps);
    if (!nr) continue;
    double t0 = rr_now_ms();
    bool raster = L->shadows == RR_SHADOWS_RASTER || (L->shadows == RR_SHADOWS_AUTO && !far && nr >= SHADOW_RASTER_MIN);
    if (raster && rr_occluded_raster(ps->s, bvh, w->ray, nr, threads, w->occluded, NULL)) {
      st->shadow_rays_raster += nr;
    } else {
      rr_ray_stream rs = rr_ray_stream_aos(w->ray, nr);
      rr_occluded_stream(NULL, ps->s, &rs, threads, w->occluded); /* a refused ray (zero length) counts as lit */
    }
    st->shadow_ms += rr_now_ms() - t0, st->shadow_rays += nr;
    rr_parallel_for((int)w->nch, threads, job_light_add, ps);
  }
  return true;
}

/* The mirror bounce of point q: its reflectance R (false: not a mirror) and the
 * view mirrored about the shading normal, or about the geometric one when that
 * would leave through the surface; with diff (NULL: not wanted), the reflected ray's
 * differentials when q has its own (sf.diff): the origin moves with the point, the
 * direction r = 2 (n·v) n − v by ∂r = 2 ((∂n·v + n·∂v) n + (n·v) ∂n) − ∂v (Igehy;
 * the geometric normal does not turn). */
static bool mirror_dir(const lit_point *q, float R[3], vec3 *r, vec3 diff[4]) {
  const surface *sf = &q->sf;
  if (!q->out || !mirror_of(sf, R)) return false;
  bool shading = true;
  *r = v3_sub(v3_scale(sf->n, 2 * v3_dot(sf->n, sf->v)), sf->v);
  if (!(v3_dot(*r, sf->ng) > 0)) {
    *r = v3_sub(v3_scale(sf->ng, 2 * v3_dot(sf->ng, sf->v)), sf->v);
    shading = false;
  }
  if (!diff || !sf->diff) return true;
  vec3 n = shading ? sf->n : sf->ng;
  float nv = v3_dot(n, sf->v);
  for (int k = 0; k < 2; k++) {
    vec3 dn = shading ? sf->dn[k] : v3(0, 0, 0);
    float dnv = v3_dot(dn, sf->v) + v3_dot(n, sf->dv[k]);
    diff[k] = sf->dp[k];
    diff[2 + k] = v3_sub(v3_scale(v3_add(v3_scale(n, dnv), v3_scale(dn, nv)), 2), sf->dv[k]);
  }
  return true;
}

/* The chunk's reflection rays; at the last bounce, the sky they would see. */
static void job_mirror_rays(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  lit_wave *w = ps->w;
  const chunk *c = &w->ch[job];
  size_t k = c->first;
  for (size_t i = 0; i < c->n; i++) {
    const lit_point *q = &c->p[i];
    float R[3];
    vec3 r;
    if (!(q->reach >> MIRROR_BIT & 1) || !mirror_dir(q, R, &r, ps->last ? NULL : w->diff[k])) continue;
    float t[3] = {q->w[0] * R[0], q->w[1] * R[1], q->w[2] * R[2]};
    if (ps->last) {
      float sky[3];
      sky_along(ps->L, r, sky);
      credit(q, LIT_REFLECTION, t, sky);
      continue;
    }
    w->ray[k] = leave(ps->L, q->sf.p, q->sf.ng, r, INFINITY);
    w->who[k] = (lit_point *)q;
    memcpy(w->add[k], t, sizeof t);
    k++;
  }
}

/* The chunk's reflected hits: the next bounce's points (the sky where they miss). */
static void job_mirror_hits(int job, int thread, void *arg) {
  (void)thread;
  const pass *ps = arg;
  const lit_wave *w = ps->w;
  const chunk *c = &w->ch[job];
  for (size_t k = c->first; k < c->first + c->rays; k++) {
    uint32_t idx = rr_scene_index_of(ps->s, w->hit[k].prim);
    vec3 org = v3_load(w->ray[k].org), dir = v3_load(w->ray[k].dir);
    const lit_point *q = w->who[k];
    lit_point *nq = seg_at(ps->next, k);
    if (idx == RR_MISS) {
      float sky[3];
      sky_along(ps->L, dir, sky);
      credit(q, LIT_REFLECTION, w->add[k], sky);
      nq->out = NULL;
      continue;
    }
    ps->fn(ps->ctx, idx, w->hit[k].l1, w->hit[k].l2, w->hit[k].t, org, dir, q->sf.diff ? w->diff[k] : NULL, &nq->sf);
    memcpy(nq->w, w->add[k], sizeof nq->w);
    nq->out = q->out, nq->parts = NULL, nq->vis = NULL;
    nq->refl = q->parts ? q->parts + LIT_REFLECTION : q->refl;
  }
}

/* The bounce's reflection rays in one stream; their hits become the next bounce's
 * points (ps->next). */
static bool reflect(lit_wave *w, pass *ps, int threads, lit_stats *st) {
  double t0 = rr_now_ms();
  for (size_t c = 0; c < w->nch; c++) w->ch[c].rays = ps->last ? 0 : w->ch[c].reached[MIRROR_BIT];
  size_t nr = rays_place(w);
  ps->next->n = 0;
  if (!rays_reserve(w, nr) || !seg_reserve(ps->next, nr)) return false;
  rr_parallel_for((int)w->nch, threads, job_mirror_rays, ps);
  if (!nr) return true;
  rr_ray_stream rs = rr_ray_stream_aos(w->ray, nr);
  rr_intersect_stream(NULL, ps->s, &rs, threads, w->hit);
  ps->next->n = nr;
  rr_parallel_for((int)w->nch, threads, job_mirror_hits, ps);
  st->reflection_ms += rr_now_ms() - t0, st->reflection_rays += nr;
  return true;
}

bool rr_lit_wave_shade(lit_wave *w, const rr_scene *s, const lighting *L, surface_fn fn, void *ctx, int threads,
                       lit_stats *st) {
  pass ps = {.w = w, .s = s, .L = L, .fn = fn, .ctx = ctx};
  bool ok = chunks_of(w, w->sink, RR_MAX_THREADS);
  for (int depth = 0; ok && w->nch; depth++) {
    double t0 = rr_now_ms();
    ok = direct(w, &ps, threads, st);
    st->direct_ms += rr_now_ms() - t0;
    ps.last = depth >= L->max_depth, ps.next = &w->bounce[depth & 1];
    ok = ok && reflect(w, &ps, threads, st) && chunks_of(w, ps.next, 1);
  }
  for (int t = 0; t < RR_MAX_THREADS; t++) w->sink[t].n = 0;
  w->bounce[0].n = w->bounce[1].n = 0;
  return ok;
}
