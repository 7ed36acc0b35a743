/* bench_texture: texture filtering on the built-in checker scene's grazing view
 * (issue 15). Quality: the RMSE in linear light of each filter against a reference
 * of 16×16 stratified bilinear level-0 lookups per pixel, over the pixels wholly on
 * the plane, split into the near and far halves (by distance: equal pixel counts),
 * beside Mesa llvmpipe's GL_LINEAR_MIPMAP_LINEAR with 16× anisotropy (and without)
 * on the same view and texture. The filters are read as shading reads them: the
 * camera's ray differentials, rr_texcoord and rr_texture_sample at each pixel's
 * centre. Cost: the shading pass (rr_shade_frame, Lambert) per filter on a frame of
 * method auto, the median of --runs rounds in which the filters take turns, and its
 * ratio to bilinear's.
 *
 * --scene MODEL (e.g. spot.obj, the textured cow) measures a textured mesh instead,
 * from a moderately grazing view: each pixel's reference averages the bilinear
 * level-0 texture values at the hits of SUB×SUB stratified sub-pixel rays
 * (rr_intersect, the hit's UVs from its barycentrics as shading takes them), over
 * the pixels whose sub-rays all hit one textured material (edges would dominate
 * otherwise); each filter reads at the pixel centre's hit with its exact
 * derivatives; the RMSE is over the three channels. No llvmpipe peer there.
 *
 * --cost-only skips the quality part; --filter NAME times that filter alone (for
 * callgrind: valgrind --tool=callgrind --toggle-collect=rr_shade_frame); --ref-sub N
 * takes N×N lookups a pixel for the reference (16 by default; the reference's own
 * noise is a floor under every filter's RMSE, docs/textures.md).
 *
 *   bench_texture [--size WxH] [--threads N] [--runs N] [--cost-only] [--filter NAME] [--ref-sub N]
 *                 [--scene checker|MODEL] */
#include "benchutil.h"
#include "camera/camera.h"
#include "shade/texcoord.h"
#include "shade/texture.h"
#ifdef RR_HAVE_OSMESA
#include "peer_osmesa.h"
#endif

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_RUNS = 64 };
static int SUB = 16; /* SUB × SUB lookups a pixel for the reference */

static const struct {
  const char *label;
  tex_filter f;
} filters[] = {{"nearest", {RR_TEXTURE_NEAREST, 16, 0}},  {"bilinear", {RR_TEXTURE_BILINEAR, 16, 0}},
               {"trilinear", {RR_TEXTURE_TRILINEAR, 16, 0}}, {"aniso:4", {RR_TEXTURE_ANISO, 4, 0}},
               {"aniso:16", {RR_TEXTURE_ANISO, 16, 0}},   {"ewa", {RR_TEXTURE_EWA, 16, 0}}};
enum { NF = sizeof filters / sizeof *filters };

typedef struct job {
  const rr_scene *s;
  const camera *c;
  int w, h, y0, y1;
  float *ref;  /* reference, NaN where a pixel is not wholly on the plane */
  float *dist; /* distance of the pixel centre's hit */
} job;

/* The textured material of triangle id, or NULL. */
static const rr_material *textured(const rr_scene *s, uint32_t id) {
  if (id == RR_MISS || !s->nmaterials || !s->uv[0][0]) return NULL;
  const rr_material *m = &s->materials[scene_material(s, id) % s->nmaterials];
  return m->texture.width > 0 ? m : NULL;
}

/* The closest hit of the ray (o, d); its textured material or NULL. */
static const rr_material *mesh_hit(const rr_scene *s, vec3 o, vec3 d, rr_hit *hit) {
  rr_ray r = {{o.x, o.y, o.z}, {d.x, d.y, d.z}, 0, INFINITY};
  if (rr_intersect(NULL, s, &r, hit) != RR_OK) return NULL;
  return textured(s, hit->prim);
}

/* The mesh's reference, rows y0 .. y1, 3 channels a pixel: SUB² sub-pixel rays,
 * each hit's UVs from its barycentrics (as shading), one bilinear level-0 lookup. */
static void *mesh_reference_rows(void *arg) {
  job *j = arg;
  tex_filter bil = {RR_TEXTURE_BILINEAR, 1, 0};
  uint32_t rng = 0x9e3779b9u * (uint32_t)(j->y0 + 1);
  vec3 eye = j->c->eye;
  for (int y = j->y0; y < j->y1; y++)
    for (int x = 0; x < j->w; x++) {
      size_t k = (size_t)y * j->w + x;
      float *ref = j->ref + 3 * k;
      ref[0] = ref[1] = ref[2] = NAN;
      rr_hit hc;
      vec3 centre = camera_dir(j->c, x + 0.5f, y + 0.5f);
      if (!mesh_hit(j->s, eye, centre, &hc)) continue;
      j->dist[k] = hc.t * v3_len(centre);
      const rr_material *m0 = NULL;
      double sum[3] = {0};
      for (int b = 0; b < SUB; b++)
        for (int a = 0; a < SUB; a++) {
          rng ^= rng << 13, rng ^= rng >> 17, rng ^= rng << 5;
          float jx = (a + (rng & 0xffff) / 65536.0f) / SUB, jy = (b + (rng >> 16) / 65536.0f) / SUB;
          vec3 d = camera_dir(j->c, x + jx, y + jy);
          rr_hit hit;
          const rr_material *m = mesh_hit(j->s, eye, d, &hit);
          if (!m || (m0 && m != m0)) goto skip; /* an edge or another material */
          m0 = m;
          tex_coord tc = rr_texcoord(j->s, hit.prim, hit.l1, hit.l2, hit.t, eye, d, NULL, NULL);
          float col[4];
          rr_texture_sample(&m->texture, &tc, &bil, col);
          for (int ch = 0; ch < 3; ch++) sum[ch] += col[ch];
        }
      for (int ch = 0; ch < 3; ch++) ref[ch] = (float)(sum[ch] / (SUB * SUB));
    skip:;
    }
  return NULL;
}

/* A filter's image of the mesh at the pixel centres' hits, 3 channels a pixel. */
static void mesh_filter_image(const rr_scene *s, const camera *c, int w, int h, const tex_filter *f, float *out) {
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      vec3 o, d, dO[2], dD[2];
      float *px = out + 3 * ((size_t)y * w + x);
      px[0] = px[1] = px[2] = NAN;
      rr_hit hit;
      const rr_material *m;
      if (!rr_cam_ray_diff(c, x, y, &o, &d, dO, dD) || !(m = mesh_hit(s, o, d, &hit))) continue;
      tex_coord tc = rr_texcoord(s, hit.prim, hit.l1, hit.l2, hit.t, o, d, dO, dD);
      float col[4];
      rr_texture_sample(&m->texture, &tc, f, col);
      memcpy(px, col, 3 * sizeof *px);
    }
}

/* The reference rows y0 .. y1: SUB² bilinear level-0 lookups at stratified
 * positions, their rays from the planar camera's d(x, y) = d0 + x dx + y dy. */
static void *reference_rows(void *arg) {
  job *j = arg;
  const rr_texture *t = &j->s->materials[0].texture;
  tex_filter bil = {RR_TEXTURE_BILINEAR, 1, 0};
  uint32_t rng = 0x9e3779b9u * (uint32_t)(j->y0 + 1);
  vec3 eye = j->c->eye;
  for (int y = j->y0; y < j->y1; y++)
    for (int x = 0; x < j->w; x++) {
      size_t k = (size_t)y * j->w + x;
      j->ref[k] = NAN;
      vec3 top = camera_dir(j->c, x + 0.5f, (float)y), centre = camera_dir(j->c, x + 0.5f, y + 0.5f);
      if (!(top.y < 0)) continue; /* the pixel's top edge above the horizon */
      j->dist[k] = -eye.y / centre.y * v3_len(centre);
      double sum = 0;
      for (int b = 0; b < SUB; b++)
        for (int a = 0; a < SUB; a++) {
          rng ^= rng << 13, rng ^= rng >> 17, rng ^= rng << 5;
          float jx = (a + (rng & 0xffff) / 65536.0f) / SUB, jy = (b + (rng >> 16) / 65536.0f) / SUB;
          vec3 d = camera_dir(j->c, x + jx, y + jy);
          float tt = -eye.y / d.y;
          tex_coord tc = {(eye.x + tt * d.x) / 8.0f, -(eye.z + tt * d.z) / 8.0f, 0, 0, 0, 0};
          float col[4];
          rr_texture_sample(t, &tc, &bil, col);
          sum += col[0];
        }
      j->ref[k] = (float)(sum / (SUB * SUB));
    }
  return NULL;
}

/* A filter's image at the pixel centres, as shading reads the texture. */
static void filter_image(const rr_scene *s, const camera *c, int w, int h, const tex_filter *f, float *out) {
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      vec3 o, d, dO[2], dD[2];
      out[(size_t)y * w + x] = NAN;
      if (!rr_cam_ray_diff(c, x, y, &o, &d, dO, dD) || !(d.y < 0)) continue;
      float tt = -o.y / d.y;
      vec3 p = v3_add(o, v3_scale(d, tt));
      uint32_t tri = p.z < 0 ? (p.x >= 0 ? 0 : 1) : (p.x < 0 ? 2 : 3); /* the fan's quadrant */
      tex_coord tc = rr_texcoord(s, tri, 0, 0, tt, o, d, dO, dD);
      float col[4];
      rr_texture_sample(&s->materials[0].texture, &tc, f, col);
      out[(size_t)y * w + x] = col[0];
    }
}

/* RMSE of img against ref (nc channels a pixel) over all, near and far pixels
 * (dist below or above split). */
static void rmse3(const float *img, const float *ref, const float *dist, size_t n, int nc, float split, double e[3]) {
  double se[3] = {0}, cnt[3] = {0};
  for (size_t k = 0; k < n * nc; k++) {
    if (ref[k] != ref[k] || !(img[k] >= 0)) continue;
    double d = (double)img[k] - ref[k];
    int half = dist[k / nc] < split ? 1 : 2;
    se[0] += d * d, cnt[0]++, se[half] += d * d, cnt[half]++;
  }
  for (int i = 0; i < 3; i++) e[i] = cnt[i] ? sqrt(se[i] / cnt[i]) : NAN;
}

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  int w = 1024, h = 1024, threads = 2, runs = 5, cost_only = 0, only = -1;
  const char *scene = "checker";
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
      if (!bench_arg_size("bench_texture", argv[++i], 8, &w, &h)) return 2;
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_texture", "--threads", argv[++i], 1, RR_MAX_THREADS, &threads)) return 2;
    } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      if (!bench_arg_int("bench_texture", "--runs", argv[++i], 1, MAX_RUNS, &runs)) return 2;
    } else if (strcmp(argv[i], "--cost-only") == 0) {
      cost_only = 1;
    } else if (strcmp(argv[i], "--filter") == 0 && i + 1 < argc) {
      for (int f = 0; f < NF; f++)
        if (strcmp(argv[i + 1], filters[f].label) == 0) only = f;
      if (only < 0) {
        fprintf(stderr, "bench_texture: unknown --filter '%s' (nearest, bilinear, trilinear, aniso:4, aniso:16, ewa)\n",
                argv[i + 1]);
        return 2;
      }
      i++;
    } else if (strcmp(argv[i], "--ref-sub") == 0 && i + 1 < argc) {
      SUB = atoi(argv[++i]);
      if (SUB < 1 || SUB > 256) {
        fprintf(stderr, "bench_texture: bad --ref-sub '%s' (1..256)\n", argv[i]);
        return 2;
      }
    } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc) {
      scene = argv[++i];
    } else {
      fprintf(stderr, "usage: bench_texture [--size WxH] [--threads N] [--runs N] [--cost-only] [--filter NAME] "
                      "[--ref-sub N] [--scene checker|MODEL]\n");
      return 2;
    }
  }
  rr_device *dev = rr_device_new();
  double load_ms;
  bool mesh = strcmp(scene, "checker") != 0;
  int nc = mesh ? 3 : 1; /* channels compared: the checker is grey */
  rr_scene *s = bench_load(dev, scene, &load_ms);
  bool any = false;
  for (uint32_t m = 0; m < s->nmaterials; m++) any |= s->materials[m].texture.width > 0;
  if (!any || !s->uv[0][0]) return fprintf(stderr, "bench_texture: scene '%s' has no texture\n", scene), 2;
  rr_camera cam;
  rr_camera_init(&cam);
  if (rr_camera_frame(dev, s, w, h, &cam) != RR_OK) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
  if (mesh) { /* a moderately grazing view: from behind and a little above, the right side (+x) at
               * about 50° to the view and rounding off to grazing, the back and the rump foreshortened */
    float dx = cam.eye[0] - cam.target[0], dy = cam.eye[1] - cam.target[1], dz = cam.eye[2] - cam.target[2];
    float r = sqrtf(dx * dx + dy * dy + dz * dz) * 0.9f / sqrtf(0.62f * 0.62f + 0.22f * 0.22f + 0.75f * 0.75f);
    const float dir[3] = {0.62f, 0.22f, 0.75f};
    for (int a = 0; a < 3; a++) cam.eye[a] = cam.target[a] + r * dir[a];
  }
  camera c;
  const float centre[2] = {0.5f, 0.5f};
  if (rr_cam_setup_at(dev, &cam, w, h, centre, &c) != RR_OK) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
  size_t n = (size_t)w * h;
  float *ref = malloc(n * nc * sizeof *ref), *dist = malloc(n * sizeof *dist), *img = malloc(n * nc * sizeof *img);
  if (!ref || !dist || !img) return fprintf(stderr, "bench_texture: out of memory\n"), 1;

  if (cost_only) goto cost;
  /* the reference, on the bench's threads */
  double t0 = bench_now_ms();
  job jobs[RR_MAX_THREADS];
  pthread_t tid[RR_MAX_THREADS];
  for (int k = 0; k < threads; k++) {
    jobs[k] = (job){s, &c, w, h, h * k / threads, h * (k + 1) / threads, ref, dist};
    pthread_create(&tid[k], NULL, mesh ? mesh_reference_rows : reference_rows, &jobs[k]);
  }
  for (int k = 0; k < threads; k++) pthread_join(tid[k], NULL);
  /* near and far: split at the median distance of the compared pixels */
  size_t m = 0;
  for (size_t k = 0; k < n; k++)
    if (ref[k * nc] == ref[k * nc]) img[m++] = dist[k];
  qsort(img, m, sizeof *img, cmp_float);
  float split = m ? img[m / 2] : 0;
  printf("%s %dx%d, eye (%g, %g, %g) -> (%g, %g, %g), fov %g; %zu pixels wholly on %s, near/far split "
         "at distance %.2f; reference (%dx%d bilinear lookups a pixel) in %.0f ms\n\n",
         scene, w, h, cam.eye[0], cam.eye[1], cam.eye[2], cam.target[0], cam.target[1], cam.target[2], cam.fov_deg, m, mesh ? "one textured material" : "the plane", split, SUB,
         SUB, bench_now_ms() - t0);

  printf("| filter | RMSE | near half | far half | RMSE / trilinear's |\n|---|---|---|---|---|\n");
  double e[NF][3];
  for (int f = 0; f < NF; f++) {
    if (mesh) mesh_filter_image(s, &c, w, h, &filters[f].f, img);
    else filter_image(s, &c, w, h, &filters[f].f, img);
    rmse3(img, ref, dist, n, nc, split, e[f]);
  }
  for (int f = 0; f < NF; f++)
    printf("| %s | %.4f | %.4f | %.4f | %.2f |\n", filters[f].label, e[f][0], e[f][1], e[f][2], e[f][0] / e[2][0]);
#ifdef RR_HAVE_OSMESA
  osmesa_peer *gl = mesh ? NULL : osmesa_new(w, h, threads);
  const rr_texture *tx = &s->materials[0].texture;
  double gl_ms[2] = {-1, -1};
  for (int a = 0; gl && a < 2; a++) {
    float aniso = a ? 16.0f : 1.0f;
    gl_ms[a] = osmesa_render_textured_plane(gl, &cam, tx->rgb, tx->width, tx->height, 8.0f, aniso, 1, img);
    if (gl_ms[a] < 0) break;
    double ge[3];
    rmse3(img, ref, dist, n, 1, split, ge);
    printf("| llvmpipe %s | %.4f | %.4f | %.4f | %.2f |\n", a ? "trilinear + 16x aniso" : "trilinear", ge[0], ge[1],
           ge[2], ge[0] / e[2][0]);
  }
  if (gl) printf("\nllvmpipe (%s): the textured plane drawn once in %.1f ms (trilinear), %.1f ms (16x aniso), %d threads\n",
                 osmesa_renderer(gl), gl_ms[0], gl_ms[1], threads);
  osmesa_release(gl);
#else
  if (!mesh) printf("| llvmpipe | (OSMesa not found) | | | |\n");
#endif
  fflush(stdout);

cost: /* the cost of shading, per filter */
  ;
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_AUTO, opt.width = w, opt.height = h, opt.threads = threads;
  rr_frame *frame;
  if (rr_render(dev, s, &cam, &opt, &frame) != RR_OK) return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
  static double ms[NF][MAX_RUNS];
  for (int r = 0; r < runs; r++)
    for (int f = 0; f < NF; f++) {
      if (only >= 0 && f != only) continue;
      rr_shade_options so;
      rr_shade_options_init(&so);
      so.texture_filter = filters[f].f.filter, so.aniso = filters[f].f.aniso;
      rr_image out;
      rr_shade_stats st;
      if (rr_shade_frame(dev, s, &cam, frame, &so, &out, &st) != RR_OK)
        return fprintf(stderr, "%s\n", rr_device_message(dev)), 1;
      ms[f][r] = st.shade_ms;
      rr_image_free(&out);
    }
  printf("\nshading (Lambert, %dx%d, %d threads, median of %d runs)\n\n| filter | shade ms | / bilinear |\n|---|---|---|\n",
         w, h, threads, runs);
  double med[NF];
  for (int f = 0; f < NF; f++) med[f] = bench_median(ms[f], runs);
  for (int f = 0; f < NF; f++)
    if (only < 0) printf("| %s | %.1f | %.2fx |\n", filters[f].label, med[f], med[f] / med[1]);
    else if (f == only) printf("| %s | %.1f | |\n", filters[f].label, med[f]);
  rr_frame_release(frame);
  rr_cam_release(&c);
  rr_scene_release(s);
  rr_device_release(dev);
  free(ref), free(dist), free(img);
  return 0;
}
