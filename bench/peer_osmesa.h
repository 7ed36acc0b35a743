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
/* Renders the loaded scene from cam `reps` times (depth test GL_LESS, flat colour,
 * back faces culled when `cull`) and returns the median milliseconds of the draw
 * and glFinish; the clear is finished before the clock starts. */
double osmesa_render(osmesa_peer *p, const rr_camera *cam, int cull, int reps);
/* The ids of the last rendering, row 0 at the top (RR_MISS where nothing was
 * drawn); owned by the peer. */
const uint32_t *osmesa_ids(osmesa_peer *p);
#endif
