/* The lit shade mode (docs/shading.md): direct light from point, spot, directional
 * and sky lights, emission and mirror reflections over a material's diffuse and
 * specular lobes. Points are shaded in passes over a wave (the frame's shaded
 * points, or as many as fit LIT_WAVE): per light one occlusion pass over all the
 * wave's shadow rays (rasterized from the light or one ray stream), then one pass
 * of reflection rays per bounce whose hits are the next level's points. Shading of
 * one point never knows which method saw it. */
#ifndef RR_LIGHT_H
#define RR_LIGHT_H

#include "scene/scene.h"

/* A point to shade: where it is, how it faces, where it is seen from, what it is made of. */
typedef struct surface {
  vec3 p;               /* position */
  vec3 ng;              /* unit geometric normal, on the viewer's side */
  vec3 n;               /* unit shading normal, on the viewer's side */
  vec3 v;               /* unit direction towards the viewer */
  float base[3];        /* base colour: the material's times its texture and vertex colours */
  const rr_material *m; /* NULL: the default grey, Lambert alone */
  bool diff;             /* a mirror seen by a ray with differentials: how p, v and n move per */
  vec3 dp[2], dv[2], dn[2]; /* pixel step in x ([0]) and y ([1]), for its reflection's differentials */
} surface;

/* Whether material m is a mirror (phong: illum 3 with a specular colour; pbr: a
 * roughness below MIRROR_ROUGHNESS). */
bool rr_material_mirror(const rr_material *m);

/* A punctual light as shading uses it. */
typedef struct light {
  rr_light_type type;           /* directional, point or spot (area lights shade as points) */
  vec3 pos, dir;                /* dir: unit, where the light shines */
  float rgb[3];                 /* intensity (cd) or, directional, irradiance (lux) */
  float cos_inner, cos_outer;   /* spot: cosines of the cone's half-angles */
} light;

/* What a frame is lit by, and how. */
typedef struct lighting {
  light *lights; /* the punctual lights */
  int nlights;
  float sky[3], ground[3]; /* the ambient lights' sum: radiance from straight above and below */
  vec3 up;                 /* the scene's up, the sky's axis */
  rr_shadow_mode shadows;
  int max_depth;           /* mirror bounces */
  float eps;               /* the scene-wide part of a ray's offset (shading.md) */
} lighting;

/* The lights of a frame: the scene's, or the default rig placed from cam when the
 * scene has none and opt->default_lights is set. */
rr_error rr_lighting_make(rr_device *dev, const rr_scene *s, const rr_camera *cam, const rr_shade_options *opt,
                       lighting *out);
void rr_lighting_release(lighting *l);

/* Fills out with the surface a reflection ray (org, dir) hit: triangle index, its
 * barycentrics and t along dir, and the ray's differentials (diff[0..1]: origin,
 * diff[2..3]: direction, per pixel step in x and y; NULL: none), which give its
 * texture footprint (shade.c gives it; ctx is its own). */
typedef void (*surface_fn)(void *ctx, uint32_t index, float l1, float l2, float t, vec3 org, vec3 dir,
                           const vec3 diff[4], surface *out);

/* What a wave's passes traced and the wall time they took. */
typedef struct lit_stats {
  uint64_t shadow_rays, reflection_rays;
  uint64_t shadow_rays_raster; /* of shadow_rays, those rasterized from their light */
  double direct_ms;            /* the light passes: making the shadow rays, testing them, adding the light */
  double shadow_ms;            /* of which the occlusion tests */
  double reflection_ms;        /* the bounces: reflection rays and their hits' surfaces */
} lit_stats;

/* A point's colour in parts (the lit AOVs, named as Blender Cycles' passes): offsets
 * into an array of LIT_PARTS floats. The colour is direct + reflection + emission. */
enum {
  LIT_ALBEDO = 0,      /* rgb: the diffuse lobe's colour */
  LIT_DIRECT = 3,      /* rgb: light from the lights and the sky on the point itself */
  LIT_REFLECTION = 6,  /* rgb: what its mirror reflects (all bounces) */
  LIT_EMISSION = 9,    /* rgb: what it emits */
  LIT_SHADOW = 12,     /* the fraction of the punctual lights that reach it (1 when there is none) */
  LIT_PARTS = 13
};

/* The points of a wave, queued by up to RR_MAX_THREADS threads at once (each
 * through its own sink), then shaded together in passes. */
typedef struct lit_wave lit_wave;

/* An empty wave (NULL when out of memory). */
lit_wave *rr_lit_wave_new(void);
void rr_lit_wave_free(lit_wave *w);
/* Queues a point through sink `thread` (one thread per sink at a time); its linear
 * colour goes to out[0..2], its parts to parts[0 .. LIT_PARTS - 1] unless parts is
 * NULL, and whether each light reaches it (1 or 0, the terms of LIT_SHADOW) to
 * vis[0 .. nlights - 1] unless vis is NULL, when the wave is shaded. False when out
 * of memory. */
bool rr_lit_wave_add(lit_wave *w, int thread, const surface *sf, float *out, float *parts, float *vis);
/* Shades the queued points under L in passes on `threads` threads (rays through
 * s's tree; reflected hits made by fn(ctx), which may run on any of them), writes
 * their colours and empties the wave; adds to st. False when out of memory (the
 * colours are then incomplete). */
bool rr_lit_wave_shade(lit_wave *w, const rr_scene *s, const lighting *L, surface_fn fn, void *ctx, int threads,
                       lit_stats *st);

#endif
