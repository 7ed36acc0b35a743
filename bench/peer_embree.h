/* Embree 3 as a peer of the ray-casting methods (bench only): the same triangles,
 * the same rays (origin = eye, direction = camera_dir of each sample), the same
 * thread pool (rr_parallel_for). Compiled when the build finds Embree 3. */
#ifndef RR_PEER_EMBREE_H
#define RR_PEER_EMBREE_H
#include "vis/vis.h"

typedef struct peer_embree peer_embree;

/* Builds an Embree scene of s's triangles (RTC_SCENE_FLAG_NONE; quality 1 = MEDIUM,
 * 2 = HIGH) on a device with "threads=N". *build_ms: the time of rtcCommitScene.
 * NULL (and a message on stderr) on failure. */
peer_embree *peer_embree_new(const rr_scene *s, int threads, int quality, double *build_ms);
void peer_embree_release(peer_embree *e);
/* Embree's own account of its memory (its memory monitor callback), in bytes:
 * what the scene holds after rtcCommitScene (geometry buffers and BVH), the part
 * the commit added (the BVH), and the most it held during the commit. */
typedef struct {
  double scene, bvh, build_peak;
} peer_embree_memory;
peer_embree_memory peer_embree_bytes(const peer_embree *e);
/* Processor time of the whole process during the build (all threads; on a loaded
 * machine steadier than the wall time, at one thread the same work). */
double peer_embree_build_cpu_ms(const peer_embree *e);
/* Casts one primary ray per pixel of camera c: width = 1 uses rtcIntersect1,
 * width = 8 rtcIntersect8 on 2x4-pixel packets; tiles dealt to `threads` threads.
 * Writes ids (RR_MISS on a miss) and t (+inf on a miss) in rastray's layout and
 * returns the wall time in milliseconds. */
double peer_embree_cast(peer_embree *e, const camera *c, int width, int threads, uint32_t *ids, float *t);
/* Traces rays[0..n-1] (rastray's rr_ray: t along the unnormalised direction, as
 * Embree's) in chunks dealt to `threads` threads: width 1 with rtcIntersect1 /
 * rtcOccluded1 (any), width 8 with rtcIntersect8 / rtcOccluded8 on 8 consecutive
 * rays. Writes ids (RR_MISS on a miss; any: 0 when occluded) and t (+inf on a
 * miss; any: unused, may be NULL) and returns the wall time in milliseconds. */
double peer_embree_rays(peer_embree *e, const rr_ray *rays, size_t n, bool any, int width, int threads, uint32_t *ids,
                        float *t);
#endif
