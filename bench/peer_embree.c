/* Embree 3 peer: see peer_embree.h. */
#include "peer_embree.h"

#include <embree3/rtcore.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

struct peer_embree {
  RTCDevice dev;
  RTCScene scene;
  uint32_t *sphere_ids; /* Embree's sphere primID k (geometry 1) is rastray's primitive sphere_ids[k] */
  uint32_t inst_T;      /* instanced: instance k's primID i is rastray's primitive k·inst_T + i */
  RTCScene mesh;        /* instanced: the one mesh, instanced by the top scene */
  atomic_llong bytes, peak; /* reported by Embree's memory monitor, from any of its threads */
  peer_embree_memory mem;
  double build_cpu_ms; /* processor time of the process during rtcCommitScene */
};

/* Embree calls this before each allocation (bytes > 0) and after each release (< 0). */
static bool embree_monitor(void *user, ssize_t bytes, bool post) {
  (void)post;
  peer_embree *e = user;
  long long now = atomic_fetch_add(&e->bytes, bytes) + bytes, peak = atomic_load(&e->peak);
  while (now > peak && !atomic_compare_exchange_weak(&e->peak, &peak, now)) {
  }
  return true; /* never refuse an allocation */
}

static void embree_error(void *user, enum RTCError code, const char *msg) {
  (void)user;
  fprintf(stderr, "embree: error %d: %s\n", (int)code, msg);
}

/* Commits e->scene, timing it (wall and processor) and taking Embree's account of
 * the memory. */
static void commit_measured(peer_embree *e, double *build_ms) {
  long long before = atomic_load(&e->bytes);
  atomic_store(&e->peak, before);
  double t0 = rr_now_ms(), c0 = rr_cpu_ms();
  rtcCommitScene(e->scene);
  *build_ms = rr_now_ms() - t0;
  e->build_cpu_ms = rr_cpu_ms() - c0;
  long long after = atomic_load(&e->bytes);
  e->mem = (peer_embree_memory){(double)after, (double)(after - before), (double)atomic_load(&e->peak)};
}

/* Triangles 0 .. n-1 of s as one committed Embree geometry, one vertex per corner so
 * that triangle i has primID i: their world corners, or (stored) their corners as
 * stored (an instanced mesh's own space). NULL when Embree has no memory. */
static RTCGeometry triangle_geometry(peer_embree *e, const rr_scene *s, uint32_t n, bool stored) {
  RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), (size_t)n * 3);
  unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n);
  if (!v || !ix) {
    rtcReleaseGeometry(g);
    return NULL;
  }
  for (uint32_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      vec3 p = stored ? scene_stored_vertex(s, k, i) : scene_vertex(s, k, i);
      float *o = v + (3 * (size_t)i + k) * 3;
      o[0] = p.x, o[1] = p.y, o[2] = p.z;
      ix[3 * (size_t)i + k] = 3 * i + k;
    }
  rtcCommitGeometry(g);
  return g;
}

/* A scene that is one instanced mesh (a grid): Embree's own instancing, the mesh in
 * a scene of its own (its stored corners) and one RTC_GEOMETRY_TYPE_INSTANCE per
 * instance with its 3×4 transform; the build counts both commits, the memory the top's. */
static peer_embree *new_instanced(peer_embree *e, const rr_scene *s, int quality, double *build_ms) {
  const scene_instances *in = s->inst;
  enum RTCBuildQuality q = quality >= 2 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  e->inst_T = in->T;
  e->mesh = rtcNewScene(e->dev);
  rtcSetSceneBuildQuality(e->mesh, q);
  RTCGeometry g = triangle_geometry(e, s, in->T, true);
  if (!g) {
    peer_embree_release(e);
    return NULL;
  }
  rtcAttachGeometry(e->mesh, g);
  rtcReleaseGeometry(g);
  e->scene = rtcNewScene(e->dev);
  rtcSetSceneBuildQuality(e->scene, q);
  double t0 = rr_now_ms(), c0 = rr_cpu_ms(), top_ms;
  rtcCommitScene(e->mesh);
  double mesh_ms = rr_now_ms() - t0, mesh_cpu = rr_cpu_ms() - c0;
  for (uint32_t k = 0; k < in->n; k++) {
    RTCGeometry ig = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(ig, e->mesh);
    rtcSetGeometryTransform(ig, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, in->xf[k]);
    rtcCommitGeometry(ig);
    rtcAttachGeometryByID(e->scene, ig, k);
    rtcReleaseGeometry(ig);
  }
  commit_measured(e, &top_ms);
  *build_ms = mesh_ms + top_ms, e->build_cpu_ms += mesh_cpu;
  return e;
}

peer_embree *peer_embree_new(const rr_scene *s, int threads, int quality, double *build_ms) {
  char cfg[64];
  snprintf(cfg, sizeof cfg, "threads=%d", threads);
  peer_embree *e = calloc(1, sizeof *e);
  if (!e) return NULL;
  e->dev = rtcNewDevice(cfg);
  if (!e->dev) {
    fprintf(stderr, "embree: cannot create a device (%s)\n", cfg);
    free(e);
    return NULL;
  }
  rtcSetDeviceErrorFunction(e->dev, embree_error, NULL);
  rtcSetDeviceMemoryMonitorFunction(e->dev, embree_monitor, e);
  if (s->inst && s->inst->base == 0 && s->ntris == s->inst->n * s->inst->T) return new_instanced(e, s, quality, build_ms);
  RTCGeometry g = triangle_geometry(e, s, s->ntris, false);
  if (!g) {
    peer_embree_release(e);
    return NULL;
  }
  e->scene = rtcNewScene(e->dev);
  rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(e->scene, quality >= 2 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  /* geometry 0, left out when every primitive is analytic (their stand-ins never hit) */
  bool any_triangle = false;
  for (uint32_t i = 0; i < s->ntris && !any_triangle; i++) any_triangle = scene_kind(s, i) == RR_GEOMETRY_TRIANGLE;
  if (any_triangle) rtcAttachGeometryByID(e->scene, g, 0);
  rtcReleaseGeometry(g);
  /* Analytic spheres as Embree's own (RTC_GEOMETRY_TYPE_SPHERE_POINT: centre and
   * radius), geometry 1. */
  size_t nsph = 0;
  for (uint32_t i = 0; i < s->ntris; i++) nsph += scene_kind(s, i) == RR_GEOMETRY_SPHERE;
  if (nsph) {
    RTCGeometry sg = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float *sv = rtcSetNewGeometryBuffer(sg, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), nsph);
    e->sphere_ids = malloc(nsph * sizeof *e->sphere_ids);
    if (!sv || !e->sphere_ids) {
      rtcReleaseGeometry(sg);
      peer_embree_release(e);
      return NULL;
    }
    for (uint32_t i = 0, k = 0; i < s->ntris; i++)
      if (scene_kind(s, i) == RR_GEOMETRY_SPHERE) {
        memcpy(sv + 4 * (size_t)k, rr_ana_params(s, i), 4 * sizeof(float));
        e->sphere_ids[k++] = i;
      }
    rtcCommitGeometry(sg);
    rtcAttachGeometryByID(e->scene, sg, 1);
    rtcReleaseGeometry(sg);
  }
  commit_measured(e, build_ms);
  return e;
}

peer_embree_memory peer_embree_bytes(const peer_embree *e) { return e->mem; }

double peer_embree_build_cpu_ms(const peer_embree *e) { return e->build_cpu_ms; }

void peer_embree_release(peer_embree *e) {
  if (!e) return;
  if (e->scene) rtcReleaseScene(e->scene);
  if (e->mesh) rtcReleaseScene(e->mesh);
  if (e->dev) rtcReleaseDevice(e->dev);
  free(e->sphere_ids);
  free(e);
}

/* rastray's primitive index of Embree's hit (geometry 0: triangles by index, 1: spheres). */
static uint32_t hit_id(const peer_embree *e, unsigned geom, unsigned inst, unsigned prim) {
  if (geom == RTC_INVALID_GEOMETRY_ID) return RR_MISS;
  if (e->mesh) return inst * e->inst_T + prim; /* instanced: instance inst's triangle prim */
  return geom == 0 ? prim : e->sphere_ids[prim];
}

enum { EMB_TILE = 32 };

typedef struct {
  peer_embree *e;
  const camera *c;
  int width, tiles_x;
  uint32_t *ids;
  float *t;
} cast_job;

static void cast1_tile(int job, int thread, void *arg) {
  (void)thread;
  cast_job *j = arg;
  const camera *c = j->c;
  int x0 = job % j->tiles_x * EMB_TILE, y0 = job / j->tiles_x * EMB_TILE;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (int y = y0; y < y0 + EMB_TILE && y < c->height; y++)
    for (int x = x0; x < x0 + EMB_TILE && x < c->width; x++) {
      vec3 d = camera_dir(c, (float)x + 0.5f, (float)y + 0.5f);
      struct RTCRayHit rh;
      rh.ray.org_x = c->eye.x, rh.ray.org_y = c->eye.y, rh.ray.org_z = c->eye.z;
      rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
      rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.time = 0, rh.ray.mask = 0xFFFFFFFFu, rh.ray.id = 0,
      rh.ray.flags = 0;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID, rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(j->e->scene, &ctx, &rh);
      size_t k = (size_t)y * c->width + x;
      bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      j->ids[k] = hit_id(j->e, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID);
      j->t[k] = hit ? rh.ray.tfar : INFINITY;
    }
}

static void cast8_tile(int job, int thread, void *arg) {
  (void)thread;
  cast_job *j = arg;
  const camera *c = j->c;
  int x0 = job % j->tiles_x * EMB_TILE, y0 = job / j->tiles_x * EMB_TILE;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTC_ALIGN(32) struct RTCRayHit8 rh;
  RTC_ALIGN(32) int valid[8];
  for (int py = y0; py < y0 + EMB_TILE && py < c->height; py += 2)
    for (int px = x0; px < x0 + EMB_TILE && px < c->width; px += 4) {
      for (int l = 0; l < 8; l++) {
        int x = px + (l & 3), y = py + (l >> 2);
        valid[l] = x < c->width && y < c->height ? -1 : 0;
        vec3 d = camera_dir(c, (float)x + 0.5f, (float)y + 0.5f);
        rh.ray.org_x[l] = c->eye.x, rh.ray.org_y[l] = c->eye.y, rh.ray.org_z[l] = c->eye.z;
        rh.ray.dir_x[l] = d.x, rh.ray.dir_y[l] = d.y, rh.ray.dir_z[l] = d.z;
        rh.ray.tnear[l] = 0, rh.ray.tfar[l] = INFINITY, rh.ray.time[l] = 0, rh.ray.mask[l] = 0xFFFFFFFFu;
        rh.ray.id[l] = 0, rh.ray.flags[l] = 0;
        rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID, rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect8(valid, j->e->scene, &ctx, &rh);
      for (int l = 0; l < 8; l++) {
        if (!valid[l]) continue;
        size_t k = (size_t)(py + (l >> 2)) * c->width + px + (l & 3);
        bool hit = rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
        j->ids[k] = hit_id(j->e, rh.hit.geomID[l], rh.hit.instID[0][l], rh.hit.primID[l]);
        j->t[k] = hit ? rh.ray.tfar[l] : INFINITY;
      }
    }
}

double peer_embree_cast(peer_embree *e, const camera *c, int width, int threads, uint32_t *ids, float *t) {
  cast_job j = {e, c, width, (c->width + EMB_TILE - 1) / EMB_TILE, ids, t};
  int tiles = j.tiles_x * ((c->height + EMB_TILE - 1) / EMB_TILE);
  double t0 = rr_now_ms();
  rr_parallel_for(tiles, threads, width == 8 ? cast8_tile : cast1_tile, &j);
  return rr_now_ms() - t0;
}

enum { EMB_RAYS = 256 }; /* rays per job */

typedef struct {
  peer_embree *e;
  const rr_ray *rays;
  size_t n;
  bool any;
  uint32_t *ids;
  float *t;
} rays_job;

static void rays1_chunk(int job, int thread, void *arg) {
  (void)thread;
  rays_job *j = arg;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (size_t i = (size_t)job * EMB_RAYS; i < j->n && i < (size_t)(job + 1) * EMB_RAYS; i++) {
    const rr_ray *r = &j->rays[i];
    struct RTCRayHit rh = {.ray = {.org_x = r->org[0], .org_y = r->org[1], .org_z = r->org[2], .tnear = r->tmin,
                                   .dir_x = r->dir[0], .dir_y = r->dir[1], .dir_z = r->dir[2], .tfar = r->tmax,
                                   .mask = 0xFFFFFFFFu},
                           .hit = {.geomID = RTC_INVALID_GEOMETRY_ID, .primID = RTC_INVALID_GEOMETRY_ID,
                                   .instID = {RTC_INVALID_GEOMETRY_ID}}};
    if (j->any) {
      rtcOccluded1(j->e->scene, &ctx, &rh.ray);
      j->ids[i] = rh.ray.tfar == -INFINITY ? 0 : RR_MISS; /* Embree marks an occluded ray so */
      continue;
    }
    rtcIntersect1(j->e->scene, &ctx, &rh);
    bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    j->ids[i] = hit_id(j->e, rh.hit.geomID, rh.hit.instID[0], rh.hit.primID);
    j->t[i] = hit ? rh.ray.tfar : INFINITY;
  }
}

static void rays8_chunk(int job, int thread, void *arg) {
  (void)thread;
  rays_job *j = arg;
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTC_ALIGN(32) struct RTCRayHit8 rh;
  RTC_ALIGN(32) int valid[8];
  for (size_t i0 = (size_t)job * EMB_RAYS; i0 < j->n && i0 < (size_t)(job + 1) * EMB_RAYS; i0 += 8) {
    for (int l = 0; l < 8; l++) {
      size_t i = i0 + l < j->n ? i0 + l : i0;
      const rr_ray *r = &j->rays[i];
      valid[l] = i0 + l < j->n ? -1 : 0;
      rh.ray.org_x[l] = r->org[0], rh.ray.org_y[l] = r->org[1], rh.ray.org_z[l] = r->org[2];
      rh.ray.dir_x[l] = r->dir[0], rh.ray.dir_y[l] = r->dir[1], rh.ray.dir_z[l] = r->dir[2];
      rh.ray.tnear[l] = r->tmin, rh.ray.tfar[l] = r->tmax, rh.ray.time[l] = 0, rh.ray.mask[l] = 0xFFFFFFFFu;
      rh.ray.id[l] = 0, rh.ray.flags[l] = 0;
      rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID, rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    if (j->any)
      rtcOccluded8(valid, j->e->scene, &ctx, &rh.ray);
    else
      rtcIntersect8(valid, j->e->scene, &ctx, &rh);
    for (int l = 0; l < 8 && i0 + l < j->n; l++) {
      bool hit = j->any ? rh.ray.tfar[l] == -INFINITY : rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
      j->ids[i0 + l] = !hit ? RR_MISS : j->any ? 0 : hit_id(j->e, rh.hit.geomID[l], rh.hit.instID[0][l], rh.hit.primID[l]);
      if (!j->any) j->t[i0 + l] = hit ? rh.ray.tfar[l] : INFINITY;
    }
  }
}

double peer_embree_rays(peer_embree *e, const rr_ray *rays, size_t n, bool any, int width, int threads, uint32_t *ids,
                        float *t) {
  rays_job j = {e, rays, n, any, ids, t};
  double t0 = rr_now_ms();
  rr_parallel_for((int)((n + EMB_RAYS - 1) / EMB_RAYS), threads, width == 8 ? rays8_chunk : rays1_chunk, &j);
  return rr_now_ms() - t0;
}
