/* Everything in a file, on files the test writes: textures embedded in GLB and in
 * data URIs, texture paths in the wrong case or with '\', missing and unreadable
 * textures reported, vertex colours, normals under a non-uniform and a mirroring
 * node scale, the file's cameras (by name and index) and lights, and the up axis
 * of COLLADA and STL files in the automatic framing. */
#include "camera/camera.h"
#include "core/color.h"
#include "testutil.h"

#include <stb/stb_image_write.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_import_XXXXXX";

/* ---- a small glTF writer: one binary buffer, JSON assembled from pieces ---- */

typedef struct gltf {
  uint8_t bin[1 << 16];
  size_t len;
  char views[4096], accessors[4096], images[256];
} gltf;

static void append(char *dst, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void append(char *dst, size_t cap, const char *fmt, ...) {
  size_t n = strlen(dst);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(dst + n, cap - n, fmt, ap);
  va_end(ap);
}

/* Appends bytes as a buffer view (4-byte aligned); its index. */
static int add_view(gltf *g, const void *data, size_t n) {
  static int count;
  if (g->len == 0 && g->views[0] == 0) count = 0;
  memcpy(g->bin + g->len, data, n);
  append(g->views, sizeof g->views, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", count ? "," : "", g->len, n);
  g->len = (g->len + n + 3) & ~(size_t)3;
  return count++;
}

/* Appends floats (comps per element: 2, 3 or 4) or uint16 indices (comps 1) as an accessor; its index. */
static int add_accessor(gltf *g, const void *data, int count, int comps) {
  static int n;
  if (g->accessors[0] == 0) n = 0;
  static const char *type[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
  int view = add_view(g, data, (size_t)count * (comps == 1 ? 2 : 4 * comps));
  append(g->accessors, sizeof g->accessors, "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"%s\"",
         n ? "," : "", view, comps == 1 ? 5123 : 5126, count, type[comps]);
  if (comps == 3) { /* POSITION needs its bounds */
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (int i = 0; i < 3 * count; i++)
      lo[i % 3] = fminf(lo[i % 3], ((const float *)data)[i]), hi[i % 3] = fmaxf(hi[i % 3], ((const float *)data)[i]);
    append(g->accessors, sizeof g->accessors, ",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]", lo[0], lo[1], lo[2], hi[0],
           hi[1], hi[2]);
  }
  append(g->accessors, sizeof g->accessors, "}");
  return n++;
}

static char *base64(const uint8_t *p, size_t n) {
  static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  char *o = malloc(4 * (n / 3 + 1) + 1), *q = o;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
    for (int k = 0; k < 4; k++) *q++ = k <= (int)(n - i) ? al[v >> (18 - 6 * k) & 63] : '=';
  }
  *q = 0;
  return o;
}

/* A 2×2 PNG: top row red, green; bottom row blue, yellow. */
static uint8_t png[256];
static int png_len;
static void to_mem(void *ctx, void *data, int n) {
  (void)ctx;
  memcpy(png + png_len, data, (size_t)n);
  png_len += n;
}
static const uint8_t texels[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 0};

/* The image of the file: a buffer view (GLB) or a data URI. */
static void add_image(gltf *g, bool glb) {
  if (glb) {
    snprintf(g->images, sizeof g->images, "{\"bufferView\":%d,\"mimeType\":\"image/png\"}", add_view(g, png, png_len));
    return;
  }
  char *b = base64(png, png_len);
  snprintf(g->images, sizeof g->images, "{\"uri\":\"data:image/png;base64,%s\"}", b);
  free(b);
}

/* Writes the file: `body` holds nodes, meshes, materials... (a comma-led JSON tail). */
static const char *write_gltf(gltf *g, const char *name, bool glb, const char *body) {
  static char json[1 << 17], path[512];
  char *uri = glb ? NULL : base64(g->bin, g->len);
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0%s%s%s%s,\"buffers\":[{\"byteLength\":%zu%s%s%s}],"
           "\"bufferViews\":[%s],\"accessors\":[%s]}",
           body, g->images[0] ? ",\"images\":[" : "", g->images, g->images[0] ? "]" : "", g->len,
           uri ? ",\"uri\":\"data:application/octet-stream;base64," : "", uri ? uri : "", uri ? "\"" : "", g->views,
           g->accessors);
  free(uri);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) return path;
  if (!glb) {
    fputs(json, f);
  } else { /* header, JSON chunk padded with spaces, BIN chunk */
    uint32_t jl = (uint32_t)(strlen(json) + 3) & ~3u, bl = (uint32_t)g->len;
    while (strlen(json) < jl) strcat(json, " ");
    uint32_t head[5] = {0x46546C67, 2, 12 + 8 + jl + 8 + bl, jl, 0x4E4F534A}, bin[2] = {bl, 0x004E4942};
    fwrite(head, 4, 5, f), fwrite(json, 1, jl, f), fwrite(bin, 4, 2, f), fwrite(g->bin, 1, bl, f);
  }
  fclose(f);
  return path;
}

/* ---- looking at renders ---- */

/* The shaded colour of pixel (x, y) of a w×h render of s through cam. */
static void pixel(rr_device *dev, const rr_scene *s, const rr_camera *cam, int w, int h, int x, int y, float rgb[3]) {
  rr_frame *f = test_render(dev, s, cam, RR_METHOD_3DR_BB, 1, w, h, 0);
  rr_image img = {0};
  rgb[0] = rgb[1] = rgb[2] = -1;
  if (f && rr_shade(dev, s, cam, f, RR_SHADE_LAMBERT, &img) == RR_OK)
    memcpy(rgb, (float *)img.data + 3 * ((size_t)y * w + x), 3 * sizeof(float));
  rr_image_free(&img);
  rr_frame_release(f);
}

/* Whether colour c is mostly `want` (each channel within 0.25 of 0 or of the lit value). */
static bool looks(const float c[3], float r, float g, float b) {
  float want[3] = {r, g, b}, top = fmaxf(c[0], fmaxf(c[1], c[2]));
  for (int k = 0; k < 3; k++)
    if (fabsf(c[k] - want[k] * top) > 0.25f) return false;
  return top > 0.5f;
}

/* The quad [-1, 1]² at z = 0 facing +Z, uv (0, 0) at its top left (glTF's origin),
 * textured, with a camera 3 units in front that it fills vertically, a second one
 * on +X looking back along -X, and a spot light. */
static const char *textured_quad(const char *name, bool glb) {
  static gltf g;
  memset(&g, 0, sizeof g);
  float pos[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
  uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  int a_pos = add_accessor(&g, pos, 4, 3), a_uv = add_accessor(&g, uv, 4, 2), a_idx = add_accessor(&g, idx, 6, 1);
  add_image(&g, glb);
  char body[4096];
  snprintf(body, sizeof body,
           ",\"scenes\":[{\"nodes\":[0,1,2,3]}],\"nodes\":[{\"mesh\":0,\"name\":\"quad\"},"
           "{\"camera\":0,\"name\":\"front\",\"translation\":[0,0,3]},"
           "{\"camera\":1,\"name\":\"side\",\"translation\":[3,0,0],\"rotation\":[0,0.70710678,0,0.70710678]},"
           "{\"name\":\"Lamp\",\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
           "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":%.8f,\"aspectRatio\":2,\"znear\":0.1}},"
           "{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],"
           "\"extensionsUsed\":[\"KHR_lights_punctual\"],\"extensions\":{\"KHR_lights_punctual\":{\"lights\":"
           "[{\"type\":\"spot\",\"color\":[1,0.5,0.25],\"intensity\":2,\"spot\":{\"innerConeAngle\":0.2,"
           "\"outerConeAngle\":0.4}}]}},"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"TEXCOORD_0\":%d},\"indices\":%d,"
           "\"material\":0}]}],\"materials\":[{\"name\":\"checker\",\"pbrMetallicRoughness\":"
           "{\"baseColorTexture\":{\"index\":0}}}],\"textures\":[{\"source\":0}]",
           2 * atan(1.0 / 3.0), a_pos, a_uv, a_idx);
  return write_gltf(&g, name, glb, body);
}

static void check_textured(rr_device *dev, const char *path, rr_texture_status want) {
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, path, &s) == RR_OK, "%s: %s", path, rr_device_message(dev));
  if (!s) return;
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  rr_material_info mi = {0};
  CHECK(rr_scene_get_material_info(s, 0, &mi) == RR_OK && mi.texture_status == want && mi.texture_width == 2 &&
            mi.name && strcmp(mi.name, "checker") == 0,
        "%s: material '%s' texture '%s' %s %dx%d", path, mi.name, mi.texture, rr_texture_status_name(mi.texture_status),
        mi.texture_width, mi.texture_height);
  CHECK(in.textures >= 1 && in.textures_missing == 0 && in.cameras == 2 && in.lights == 1,
        "%s: %u textures, %u missing, %u cameras, %u lights", path, in.textures, in.textures_missing, in.cameras,
        in.lights);
  /* Through the file's camera "front" the quad fills the image's height (glTF keeps
   * yfov whatever the aspect); each quarter shows its texel. */
  uint32_t front = 9, side = 9;
  rr_camera cam;
  CHECK(rr_scene_find_camera(dev, s, "front", &front) == RR_OK && front == 0, "camera 'front' is %u", front);
  CHECK(rr_scene_find_camera(dev, s, "1", &side) == RR_OK && side == 1, "camera '1' is %u", side);
  CHECK(rr_scene_find_camera(dev, s, "nope", &side) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "'front', 'side'") && !strchr(rr_device_message(dev), '\n'),
        "unknown camera: '%s'", rr_device_message(dev));
  CHECK(rr_scene_get_camera(dev, s, front, 64, 32, &cam) == RR_OK, "%s", rr_device_message(dev));
  CHECK(fabsf(cam.eye[2] - 3) < 1e-5f && fabsf(cam.eye[0]) < 1e-5f && cam.target[2] < cam.eye[2] &&
            fabsf(cam.fov_deg - (float)(2 * atan(1.0 / 3.0) * 180 / RR_PI)) < 1e-3f,
        "front: eye (%g %g %g) fov %g", cam.eye[0], cam.eye[1], cam.eye[2], cam.fov_deg);
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, 64, 32, 0);
  if (f) {
    const uint32_t *ids = rr_frame_ids(f);
    CHECK(ids[32] != RR_MISS && ids[31 * 64 + 32] != RR_MISS && ids[16 * 64 + 10] == RR_MISS &&
              ids[16 * 64 + 20] != RR_MISS,
          "the quad fills the height and the middle half of the width");
    rr_frame_release(f);
  }
  float c[3];
  static const int at[4][2] = {{24, 8}, {40, 8}, {24, 24}, {40, 24}};
  for (int q = 0; q < 4; q++) {
    pixel(dev, s, &cam, 64, 32, at[q][0], at[q][1], c);
    CHECK(looks(c, texels[3 * q] / 255.0f, texels[3 * q + 1] / 255.0f, texels[3 * q + 2] / 255.0f),
          "%s: quarter %d shows (%g %g %g)", path, q, c[0], c[1], c[2]);
  }
  CHECK(rr_scene_get_camera(dev, s, side, 32, 32, &cam) == RR_OK && fabsf(cam.eye[0] - 3) < 1e-5f &&
            fabsf(cam.target[0] - 2) < 1e-4f && fabsf(cam.target[2]) < 1e-4f,
        "side: eye (%g %g %g) target (%g %g %g)", cam.eye[0], cam.eye[1], cam.eye[2], cam.target[0], cam.target[1],
        cam.target[2]);
  CHECK(rr_scene_get_camera(dev, s, 2, 32, 32, &cam) == RR_ERROR_ARGUMENT, "camera 2 does not exist");
  rr_light_info l = {0};
  CHECK(rr_scene_get_light(s, 0, &l) == RR_OK && l.type == RR_LIGHT_SPOT && l.name && strcmp(l.name, "Lamp") == 0 &&
            fabsf(l.position[0] - 1) < 1e-5f && fabsf(l.position[1] - 2) < 1e-5f && fabsf(l.position[2] - 3) < 1e-5f &&
            fabsf(l.direction[2] + 1) < 1e-5f && fabsf(l.color[0] - 2) < 1e-5f && fabsf(l.color[2] - 0.5f) < 1e-5f &&
            fabsf(l.outer_cone_deg - 0.4f * 180 / (float)RR_PI) < 1e-3f,
        "light: %s %s at (%g %g %g) towards (%g %g %g) colour (%g %g %g) cone %g", l.name, rr_light_type_name(l.type),
        l.position[0], l.position[1], l.position[2], l.direction[0], l.direction[1], l.direction[2], l.color[0],
        l.color[1], l.color[2], l.outer_cone_deg);
  rr_scene_release(s);
}

/* A UV sphere of radius 1 with exact normals under a node scaled by `scale`: the
 * normal AOV against the ellipsoid's normal (x/a², y/b², z/c²) at each hit. */
static void check_scaled_sphere(rr_device *dev, const char *name, const float scale[3]) {
  enum { SEG = 48, RINGS = 24, NV = (SEG + 1) * (RINGS + 1) };
  static float pos[3 * NV], nrm[3 * NV];
  static uint16_t idx[6 * SEG * RINGS];
  int ni = 0;
  for (int r = 0; r <= RINGS; r++)
    for (int k = 0; k <= SEG; k++) {
      double th = RR_PI * r / RINGS, ph = 2 * RR_PI * k / SEG;
      float *p = pos + 3 * (r * (SEG + 1) + k), *n = nrm + 3 * (r * (SEG + 1) + k);
      n[0] = p[0] = (float)(sin(th) * cos(ph)), n[1] = p[1] = (float)cos(th), n[2] = p[2] = (float)(-sin(th) * sin(ph));
      if (r < RINGS && k < SEG) {
        uint16_t a = (uint16_t)(r * (SEG + 1) + k), b = (uint16_t)(a + SEG + 1);
        uint16_t t[6] = {a, b, (uint16_t)(a + 1), (uint16_t)(a + 1), b, (uint16_t)(b + 1)};
        memcpy(idx + ni, t, sizeof t), ni += 6;
      }
    }
  static gltf g;
  memset(&g, 0, sizeof g);
  int a_pos = add_accessor(&g, pos, NV, 3), a_n = add_accessor(&g, nrm, NV, 3), a_idx = add_accessor(&g, idx, ni, 1);
  char body[1024];
  snprintf(body, sizeof body,
           ",\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"scale\":[%g,%g,%g]}],\"meshes\":[{\"primitives\":"
           "[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d},\"indices\":%d}]}]",
           scale[0], scale[1], scale[2], a_pos, a_n, a_idx);
  const char *path = write_gltf(&g, name, true, body);
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, path, &s) == RR_OK, "%s: %s", name, rr_device_message(dev));
  if (!s) return;
  rr_camera cam;
  rr_camera_init(&cam);
  cam.eye[0] = 1.5f, cam.eye[1] = 2.0f, cam.eye[2] = 4.0f; /* sees the flat top and the rim */
  enum { W = 64 };
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, W, W, 1); /* culled: front faces must face out */
  rr_image img = {0};
  camera c;
  if (f && rr_frame_aov(dev, s, &cam, f, RR_AOV_NORMAL, &img) == RR_OK && rr_cam_setup(dev, &cam, W, W, &c) == RR_OK) {
    static float err[W * W];
    int n = 0;
    for (int y = 0; y < W; y++)
      for (int x = 0; x < W; x++) {
        float t = rr_frame_t(f)[y * W + x];
        if (!isfinite(t)) continue;
        vec3 o, d;
        rr_cam_ray(&c, x, y, &o, &d);
        vec3 p = v3_add(o, v3_scale(d, t));
        vec3 want = v3_norm(v3(p.x / (scale[0] * scale[0]), p.y / (scale[1] * scale[1]), p.z / (scale[2] * scale[2])));
        const float *got = (const float *)img.data + 3 * (y * W + x);
        float cosang = fminf(1.0f, v3_dot(want, v3_load(got)));
        err[n++] = acosf(cosang) * 180.0f / (float)RR_PI;
      }
    /* the median by counting: how many are under the bound */
    int under = 0;
    for (int i = 0; i < n; i++) under += err[i] < 1.0f;
    CHECK(n > W * W / 16 && under > n / 2, "%s: %d of %d hits have normals within 1° of the ellipsoid's", name, under, n);
    rr_cam_release(&c);
  }
  rr_image_free(&img);
  rr_frame_release(f);
  rr_scene_release(s);
}

/* A triangle with red, green and blue corners (glTF COLOR_0, linear): the pixel
 * nearest each corner (largest barycentric) shows its colour. */
static void check_vertex_colors(rr_device *dev) {
  static gltf g;
  memset(&g, 0, sizeof g);
  float pos[] = {-1, -1, 0, 1, -1, 0, 0, 1, 0}, col[] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  uint16_t idx[] = {0, 1, 2};
  int a_pos = add_accessor(&g, pos, 3, 3), a_col = add_accessor(&g, col, 3, 3), a_idx = add_accessor(&g, idx, 3, 1);
  char body[1024];
  snprintf(body, sizeof body,
           ",\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
           "{\"POSITION\":%d,\"COLOR_0\":%d},\"indices\":%d,\"material\":0}]}],\"materials\":[{\"pbrMetallicRoughness\":"
           "{\"baseColorFactor\":[1,1,1,1]}}]",
           a_pos, a_col, a_idx);
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_gltf(&g, "colors.gltf", false, body), &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  enum { W = 48 };
  rr_camera cam;
  rr_camera_init(&cam);
  CHECK(rr_camera_frame(dev, s, W, W, &cam) == RR_OK, "%s", rr_device_message(dev));
  rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, W, W, 1); /* seen from its front, +Z */
  rr_image img = {0};
  if (f && rr_shade(dev, s, &cam, f, RR_SHADE_LAMBERT, &img) == RR_OK) {
    for (int k = 0; k < 3; k++) {
      int best = -1;
      float top = -1;
      for (int i = 0; i < W * W; i++) {
        if (rr_frame_ids(f)[i] == RR_MISS) continue;
        float l1 = rr_frame_bary1(f)[i], l2 = rr_frame_bary2(f)[i], w = k == 0 ? 1 - l1 - l2 : k == 1 ? l1 : l2;
        if (w > top) top = w, best = i;
      }
      const float *c = best < 0 ? (const float[3]){-1, -1, -1} : (const float *)img.data + 3 * best;
      CHECK(top > 0.8f && looks(c, k == 0, k == 1, k == 2), "corner %d (weight %g) shows (%g %g %g)", k, top, c[0], c[1],
            c[2]);
    }
  }
  rr_image_free(&img);
  rr_frame_release(f);
  rr_scene_release(s);

  /* OBJ colours (as PLY's) are display values: stored linear. */
  const char *obj = test_write_file(dir, "col.obj", "v 0 0 0 0.5 0.5 0.5\nv 1 0 0 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->col[0][0] && fabsf(s->col[0][1][0] - srgb_decode(0.5f)) < 1e-4f && s->col[1][0][0] == 1 &&
              s->col[1][1][0] == 0,
          "OBJ vertex colours decoded to linear: %g", s->col[0][0] ? s->col[0][1][0] : -1);
    rr_scene_release(s);
  }
  /* grid: copies (instances, read through scene_st) carry their corner colours too */
  char grid[600];
  snprintf(grid, sizeof grid, "grid:%s:2", obj);
  CHECK(rr_scene_load(dev, grid, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    bool same = s->ntris == 4 && s->col[0][0];
    for (uint32_t t = 1; same && t < s->ntris; t++)
      for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++) same = same && s->col[k][c][scene_st(s, t)] == s->col[k][c][0];
    CHECK(same, "grid copies keep the vertex colours (%u triangles)", s->ntris);
    rr_scene_release(s);
  }

  /* The API: per-vertex colours into a white material; a non-finite one is refused. */
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  uint32_t tri[] = {0, 1, 2};
  float nan_col[9] = {1, 0, 0, 0, 1, 0, 0, 0, NAN};
  CHECK(rr_scene_add_mesh_colors(s, pos, 3, tri, 1, NULL, nan_col) == RR_ERROR_ARGUMENT && s->ntris == 0,
        "a NaN colour is refused");
  CHECK(rr_scene_add_mesh_colors(s, pos, 3, tri, 1, NULL, col) == RR_OK && s->col[0][0] && s->col[2][2][0] == 1 &&
            s->col[0][0][0] == 1 && s->materials[s->material[0]].color[1] == 1,
        "add_mesh_colors: %s", rr_device_message(dev));
  rr_scene_release(s);
}

/* Texture files: a name in the wrong case, a Windows path, a missing file and an
 * unreadable one, each with its status. */
static void check_texture_files(rr_device *dev) {
  char path[600];
  snprintf(path, sizeof path, "%s/test.png", dir);
  stbi_write_png(path, 2, 2, 3, texels, 6);
  snprintf(path, sizeof path, "mkdir -p %s/maps && cp %s/test.png %s/maps/wood.png", dir, dir, dir);
  CHECK(system(path) == 0, "%s", path);
  test_write_file(dir, "bad.png", "not a PNG at all");
  test_write_file(dir, "m.mtl", "newmtl upper\nmap_Kd TEST.PNG\nnewmtl windows\nmap_Kd Maps\\WOOD.png\n"
                                "newmtl absent\nmap_Kd nothere.png\nnewmtl broken\nmap_Kd bad.png\n");
  const char *obj = test_write_file(dir, "tex.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                                  "usemtl upper\nf 1/1 2/2 3/3\nusemtl windows\nf 1/1 2/2 3/3\n"
                                                  "usemtl absent\nf 1/1 2/2 3/3\nusemtl broken\nf 1/1 2/2 3/3\n");
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  static const struct {
    const char *name;
    rr_texture_status status;
  } want[] = {{"upper", RR_TEXTURE_FILE}, {"windows", RR_TEXTURE_FILE}, {"absent", RR_TEXTURE_MISSING},
              {"broken", RR_TEXTURE_UNREADABLE}};
  for (size_t w = 0; w < 4; w++) {
    bool found = false;
    for (uint32_t m = 0; m < s->nmaterials; m++) {
      rr_material_info mi;
      rr_scene_get_material_info(s, m, &mi);
      if (!mi.name || strcmp(mi.name, want[w].name) != 0) continue;
      found = true;
      bool read = want[w].status == RR_TEXTURE_FILE;
      CHECK(mi.texture_status == want[w].status && (!read || (mi.texture_width == 2 && !memcmp(s->materials[m].texture.rgb,
                                                                                              texels, 12))),
            "%s: texture '%s' is %s", mi.name, mi.texture, rr_texture_status_name(mi.texture_status));
    }
    CHECK(found, "material %s", want[w].name);
  }
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.textures == 4 && in.textures_missing == 2, "%u textures, %u missing", in.textures, in.textures_missing);
  rr_scene_release(s);
}

/* Z-up files: COLLADA's <up_axis>Z_UP</up_axis> is turned Y-up by assimp, STL and
 * FBX (UpAxis 2) stay Z-up; either way the automatic camera sees a triangle standing on the ground and
 * facing the front (-Y in Z-up terms) from its front, with culling. */
static void check_up_axis(rr_device *dev) {
  const char *dae = test_write_file(dir, "z.dae",
      "<?xml version=\"1.0\"?><COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
      "<asset><up_axis>Z_UP</up_axis></asset><library_cameras><camera id=\"cam\" name=\"cam\"><optics><technique_common>"
      "<perspective><xfov>60</xfov><aspect_ratio>1</aspect_ratio><znear>0.1</znear><zfar>100</zfar></perspective>"
      "</technique_common></optics></camera></library_cameras><library_geometries><geometry id=\"tri\"><mesh>"
      "<source id=\"pos\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 0 1</float_array><technique_common>"
      "<accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" "
      "type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source><vertices id=\"v\">"
      "<input semantic=\"POSITION\" source=\"#pos\"/></vertices><triangles count=\"1\"><input semantic=\"VERTEX\" "
      "source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles></mesh></geometry></library_geometries>"
      "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><instance_geometry url=\"#tri\"/></node>"
      "<node id=\"eye\" name=\"eye\"><translate>0.3 -5 0.3</translate><rotate>1 0 0 90</rotate>"
      "<instance_camera url=\"#cam\"/></node></visual_scene></library_visual_scenes>"
      "<scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>");
  const char *stl = test_write_file(dir, "z.stl", "solid t\nfacet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                                   "vertex 0 0 1\nendloop\nendfacet\nendsolid t\n");
  /* FBX records its axes (3ds Max's Z up, front -Y), which assimp leaves as they are */
  const char *fbx = test_write_file(dir, "z.fbx",
      "; FBX 7.4.0 project file\nFBXHeaderExtension: {\n FBXHeaderVersion: 1003\n FBXVersion: 7400\n}\n"
      "GlobalSettings: {\n Version: 1000\n Properties70: {\n  P: \"UpAxis\", \"int\", \"Integer\", \"\",2\n"
      "  P: \"UpAxisSign\", \"int\", \"Integer\", \"\",1\n  P: \"FrontAxis\", \"int\", \"Integer\", \"\",1\n"
      "  P: \"FrontAxisSign\", \"int\", \"Integer\", \"\",-1\n }\n}\nObjects: {\n"
      " Geometry: 1000, \"Geometry::tri\", \"Mesh\" {\n  Vertices: *9 {\n   a: 0,0,0,1,0,0,0,0,1\n  }\n"
      "  PolygonVertexIndex: *3 {\n   a: 0,1,-3\n  }\n }\n Model: 2000, \"Model::tri\", \"Mesh\" {\n  Version: 232\n }\n}\n"
      "Connections: {\n C: \"OO\",1000,2000\n C: \"OO\",2000,0\n}\n");
  const char *files[3] = {dae, stl, fbx};
  for (int i = 0; i < 3; i++) {
    rr_scene *s = NULL;
    CHECK(rr_scene_load(dev, files[i], &s) == RR_OK, "%s: %s", files[i], rr_device_message(dev));
    if (!s) continue;
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    float up_z = i >= 1; /* STL, FBX: +Z up, front -Y; COLLADA after assimp: +Y up, front +Z */
    CHECK(in.up[2] == up_z && in.up[1] == 1 - up_z && in.front[1] == -up_z && in.front[2] == 1 - up_z,
          "%s: up (%g %g %g) front (%g %g %g)", files[i], in.up[0], in.up[1], in.up[2], in.front[0], in.front[1],
          in.front[2]);
    rr_camera cam;
    rr_camera_init(&cam);
    rr_error e = rr_camera_frame(dev, s, 32, 32, &cam);
    vec3 view = v3_sub(v3_load(cam.eye), v3_load(cam.target)); /* from the front, a little above */
    CHECK(e == RR_OK && cam.up[2] == up_z && v3_dot(view, v3_load(in.front)) > 0 && v3_dot(view, v3_load(in.up)) > 0,
          "%s: framed with up (%g %g %g) from (%g %g %g)", files[i], cam.up[0], cam.up[1], cam.up[2], cam.eye[0],
          cam.eye[1], cam.eye[2]);
    rr_frame *f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, 32, 32, 1);
    CHECK(f && test_frame_hits(f) > 32 * 32 / 8, "%s: the front face fills the view: %d hits", files[i],
          f ? test_frame_hits(f) : -1);
    rr_frame_release(f);
    if (i == 0) { /* the file's camera, 5 units in front of the triangle, converted with the scene */
      uint32_t c = 9;
      CHECK(in.cameras == 1 && rr_scene_find_camera(dev, s, "eye", &c) == RR_OK &&
                rr_scene_get_camera(dev, s, c, 32, 32, &cam) == RR_OK && fabsf(cam.eye[2] - 5) < 1e-4f &&
                fabsf(cam.target[2] - 4) < 1e-4f && fabsf(cam.fov_deg - 60) < 1e-3f,
            "COLLADA camera: %s eye (%g %g %g) target (%g %g %g) fov %g", rr_device_message(dev), cam.eye[0], cam.eye[1],
            cam.eye[2], cam.target[0], cam.target[1], cam.target[2], cam.fov_deg);
      f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 1, 32, 32, 1);
      CHECK(f && rr_frame_ids(f)[16 * 32 + 16] == 0, "the COLLADA camera looks at the triangle");
      rr_frame_release(f);
    }
    rr_scene_release(s);
  }
}

static int cli(const char *args, char *out, size_t cap) { return test_run_cli(dir, args, true, out, cap); }

/* `info` lists materials with their textures, the textures that are missing, the
 * cameras and lights; `render --camera-from-file` looks through a file's camera. */
static void check_cli(void) {
  static char out[1 << 14];
  int st = cli("info quad.glb", out, sizeof out);
  CHECK(st == 0 && strstr(out, "checker") && strstr(out, "'*0' (embedded, 2x2)") && strstr(out, "cameras      2") &&
            strstr(out, "front") && strstr(out, "side") && strstr(out, "Lamp") && strstr(out, "spot"),
        "info quad.glb (%d):\n%s", st, out);
  st = cli("info tex.obj", out, sizeof out);
  CHECK(st == 0 && strstr(out, "textures     4 (2 missing or unreadable)") && strstr(out, "missing    'nothere.png'") &&
            strstr(out, "unreadable 'bad.png'") && strstr(out, "'TEST.PNG' (file, 2x2)"),
        "info tex.obj (%d):\n%s", st, out);
  st = cli("render tex.obj --size 16x16 -o tex.png", out, sizeof out);
  CHECK(st == 0 && strstr(out, "warning: 2 of 4 textures missing or unreadable"), "render tex.obj warns (%d): %s", st,
        out);
  st = cli("render tex.obj --size 16x16 -o tex.png -q", out, sizeof out);
  CHECK(st == 0 && !*out, "render tex.obj -q is quiet (%d): %s", st, out);
  st = cli("render quad.glb --camera-from-file=side --size 16x16 -o side.png -q", out, sizeof out);
  CHECK(st == 0, "--camera-from-file side (%d): %s", st, out);
  st = cli("render quad.glb --camera-from-file 0 --camera orthographic --size 16x16 -o front.png -q", out, sizeof out);
  CHECK(st == 0, "--camera-from-file 0 (%d): %s", st, out);
  st = cli("render quad.glb --camera-from-file nope --size 16x16 -o x.png", out, sizeof out);
  CHECK(st == 1 && strstr(out, "'front', 'side'") && strchr(out, '\n') == out + strlen(out) - 1,
        "unknown camera (%d): %s", st, out);
  st = cli("render quad.glb --camera-from-file front --fov 30 --size 16x16 -o x.png", out, sizeof out);
  CHECK(st == 2, "--camera-from-file with --fov is refused (%d): %s", st, out);
}

/* ---- a ZAE: a stored (uncompressed) zip of a COLLADA file and its texture ---- */

static uint32_t crc32_of(const uint8_t *p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = c >> 1 ^ (0xEDB88320u & -(c & 1u));
  }
  return ~c;
}

static void put(FILE *f, uint32_t v, int bytes) {
  for (int i = 0; i < bytes; i++) fputc((int)(v >> 8 * i & 255), f);
}

/* Writes the entries (name, bytes, length) as a zip with no compression. */
static const char *write_zip(const char *name, int n, const char *const names[], const void *const data[],
                             const size_t len[]) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) return path;
  uint32_t offset[8], at = 0;
  for (int i = 0; i < n; i++) { /* local headers and data */
    offset[i] = at;
    uint32_t nl = (uint32_t)strlen(names[i]);
    put(f, 0x04034b50, 4), put(f, 20, 2), put(f, 0, 2), put(f, 0, 2), put(f, 0, 4);
    put(f, crc32_of(data[i], len[i]), 4), put(f, (uint32_t)len[i], 4), put(f, (uint32_t)len[i], 4), put(f, nl, 2);
    put(f, 0, 2), fputs(names[i], f), fwrite(data[i], 1, len[i], f);
    at += 30 + nl + (uint32_t)len[i];
  }
  uint32_t dir_at = at;
  for (int i = 0; i < n; i++) { /* the central directory */
    uint32_t nl = (uint32_t)strlen(names[i]);
    put(f, 0x02014b50, 4), put(f, 20, 2), put(f, 20, 2), put(f, 0, 2), put(f, 0, 2), put(f, 0, 4);
    put(f, crc32_of(data[i], len[i]), 4), put(f, (uint32_t)len[i], 4), put(f, (uint32_t)len[i], 4), put(f, nl, 2);
    put(f, 0, 2), put(f, 0, 2), put(f, 0, 2), put(f, 0, 2), put(f, 0, 4), put(f, offset[i], 4), fputs(names[i], f);
    at += 46 + nl;
  }
  put(f, 0x06054b50, 4), put(f, 0, 4), put(f, (uint32_t)n, 2), put(f, (uint32_t)n, 2), put(f, at - dir_at, 4);
  put(f, dir_at, 4), put(f, 0, 2);
  fclose(f);
  return path;
}

/* A ZAE whose material's texture is a file inside the archive: assimp hands it
 * over as an embedded texture named like the file. */
static void check_zae(rr_device *dev) {
  static const char dae[] =
      "<?xml version=\"1.0\"?><COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
      "<library_images><image id=\"img\"><init_from>maps/test.png</init_from></image></library_images>"
      "<library_effects><effect id=\"fx\"><profile_COMMON><newparam sid=\"surf\"><surface type=\"2D\"><init_from>img"
      "</init_from></surface></newparam><newparam sid=\"samp\"><sampler2D><source>surf</source></sampler2D></newparam>"
      "<technique sid=\"t\"><lambert><diffuse><texture texture=\"samp\" texcoord=\"UV\"/></diffuse></lambert>"
      "</technique></profile_COMMON></effect></library_effects><library_materials><material id=\"mat\" name=\"mat\">"
      "<instance_effect url=\"#fx\"/></material></library_materials><library_geometries><geometry id=\"tri\"><mesh>"
      "<source id=\"pos\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array><technique_common>"
      "<accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" "
      "type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source><vertices id=\"v\">"
      "<input semantic=\"POSITION\" source=\"#pos\"/></vertices><triangles count=\"1\" material=\"m\"><input "
      "semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 2</p></triangles></mesh></geometry></library_geometries>"
      "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><instance_geometry url=\"#tri\"><bind_material>"
      "<technique_common><instance_material symbol=\"m\" target=\"#mat\"/></technique_common></bind_material>"
      "</instance_geometry></node></visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/>"
      "</scene></COLLADA>";
  static const char manifest[] = "<?xml version=\"1.0\"?><dae_root>scene.dae</dae_root>";
  const char *names[] = {"manifest.xml", "scene.dae", "maps/test.png"};
  const void *data[] = {manifest, dae, png};
  size_t len[] = {strlen(manifest), strlen(dae), (size_t)png_len};
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, write_zip("scene.zae", 3, names, data, len), &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  bool embedded = false;
  for (uint32_t m = 0; m < s->nmaterials; m++) {
    rr_material_info mi;
    rr_scene_get_material_info(s, m, &mi);
    embedded |= mi.texture_status == RR_TEXTURE_EMBEDDED && mi.texture_width == 2 &&
                !memcmp(s->materials[m].texture.rgb, texels, 12);
  }
  CHECK(embedded, "the ZAE's texture is read from the archive");
  rr_scene_release(s);
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  rr_device *dev = rr_device_new();
  png_len = 0;
  stbi_write_png_to_func(to_mem, NULL, 2, 2, 3, texels, 6);
  CHECK(png_len > 8, "PNG written");

  /* Embedded textures, cameras and a light: GLB (image in a buffer view) and glTF
   * (buffer and image as data URIs). */
  check_textured(dev, textured_quad("quad.glb", true), RR_TEXTURE_EMBEDDED);
  check_textured(dev, textured_quad("quad.gltf", false), RR_TEXTURE_EMBEDDED);

  /* Normals under node transforms: the inverse transpose, also when mirrored. */
  check_scaled_sphere(dev, "ellipsoid.glb", (const float[3]){1, 0.25f, 1});
  check_scaled_sphere(dev, "mirrored.glb", (const float[3]){-1, 0.25f, 1});

  check_vertex_colors(dev);
  check_texture_files(dev);
  check_up_axis(dev);
  check_zae(dev);
  check_cli();

  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(getenv("RR_KEEP") || system(cmd) == 0, "cleanup");
  rr_device_release(dev);
  return test_done();
}
