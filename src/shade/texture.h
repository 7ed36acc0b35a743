/* Texture lookups for shading: a texture is read over a sample's footprint, the
 * pixel's extent in texture space, which the derivatives of (u, v) give. */
#ifndef RR_TEXTURE_H
#define RR_TEXTURE_H

#include "scene/scene.h"

/* How lookups read textures (from rr_shade_options). */
typedef struct tex_filter {
  rr_texture_filter filter;
  int aniso;      /* most probes along the footprint's major axis (RR_TEXTURE_ANISO) */
  float lod_bias; /* added to the level of detail, in levels */
} tex_filter;

/* A sample's texture coordinates (v up, as files give them) and their
 * derivatives per pixel step in x and in y. */
typedef struct tex_coord {
  float u, v;
  float dudx, dvdx, dudy, dvdy;
} tex_coord;

/* Prepares texture t for filtered lookups after its level 0 is read (false: out of memory). */
bool rr_texture_prepare(rr_texture *t);
/* The linear RGBA of texture t filtered over the footprint tc, with t's wrap modes. */
void rr_texture_sample(const rr_texture *t, const tex_coord *tc, const tex_filter *f, float rgba[4]);

#endif
