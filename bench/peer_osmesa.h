/* Mesa's llvmpipe through OSMesa: the same scene and camera rasterized by OpenGL
 * on the CPU, with the triangle id as a flat colour, for timing and id agreement.
 * Compiled into the benchmark programs when OSMesa is found (RR_HAVE_OSMESA). */
#ifndef RR_PEER_OSMESA_H
#define RR_PEER_OSMESA_H
#include "rastray.h"

#include <stdint.h>

typedef struct osmesa_peer osmesa_peer;

/* Creates an RGBA context of w×h with a depth buffer, rasterizing on `threads`
 * llvmpipe threads (LP_NUM_THREADS is set before the first context of the process
 * is made, so only the first call's count takes effect). NULL, with a message on
 * stderr, when that fails. */
osmesa_peer *osmesa_new(int w, int h, int threads);
/* Releases the context and its buffers. */
void osmesa_release(osmesa_peer *p);
/* The GL_RENDERER string of the context (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"). */
const char *osmesa_renderer(const osmesa_peer *p);
/* Uploads a scene's triangles to a vertex buffer, each triangle coloured by its id.
 * Returns 0 on success. */
int osmesa_load(osmesa_peer *p, const rr_scene *scene);
/* Where the following renderings go: 1, OSMesa's own buffer (the default); more, a
 * framebuffer object of that many samples per pixel (colour and depth renderbuffers
 * from glRenderbufferStorageMultisample), resolved into OSMesa's buffer by
 * glBlitFramebuffer after each frame. Returns the samples GL granted (it may round
 * up), or 0, with a message on stderr, when it cannot (llvmpipe offers 4). */
int osmesa_set_samples(osmesa_peer *p, int samples);
/* Renders the loaded scene from cam `reps` times (depth test GL_LESS, flat colour,
 * back faces culled when `cull`) and returns the median milliseconds of the draw
 * and glFinish; the clear is finished before the clock starts. */
double osmesa_render(osmesa_peer *p, const rr_camera *cam, int cull, int reps);
/* The median milliseconds of the last osmesa_render's resolves (glBlitFramebuffer
 * and glFinish, after each timed draw); 0 with one sample. */
double osmesa_resolve_ms(const osmesa_peer *p);
/* The ids of the last rendering, row 0 at the top (RR_MISS where nothing was
 * drawn); owned by the peer. */
const uint32_t *osmesa_ids(osmesa_peer *p);
/* Draws the plane y = 0 (a square of side 8192 around the origin: the rest is within
 * a pixel of the horizon at 1024 rows and 45°, from 1 unit above it) seen by cam with
 * texture coordinates (x/scale, -z/scale), textured by the w×h sRGB texels rgb
 * (3 bytes each, row 0 at the top: v = 1) as an sRGB texture (so filtering is in
 * linear light) with its mipmaps (glGenerateMipmap), GL_LINEAR_MIPMAP_LINEAR,
 * GL_REPEAT and `aniso`× anisotropic filtering (EXT_texture_filter_anisotropic), into
 * a float framebuffer, `reps` times. Writes the linear red channel per pixel (row 0
 * at the top; -1 where the plane is not drawn) to out and returns the median
 * milliseconds of the draw and glFinish; -1, with a message, when it cannot. */
double osmesa_render_textured_plane(osmesa_peer *p, const rr_camera *cam, const uint8_t *rgb, int w, int h,
                                    float scale, float aniso, int reps, float *out);
#endif
