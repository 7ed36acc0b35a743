/* Geometries and ids: the table of meshes over the global primitive ids
 * (rr_scene_add_mesh calls with dropped triangles, a multi-object OBJ, every
 * built-in), the lookup of a primitive's geometry, ray hits, the mesh and material
 * AOVs of every method, and the CLI writing them; ids in file order whatever was
 * dropped, for every method, ray queries and a real mesh against a ray cast of the
 * file's own faces. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <sys/wait.h>

static char dir[] = "/tmp/rr_geometry_XXXXXX";
static const char *multi_obj; /* written by main */

/* The table's promises on any scene: geometries tile the ids [0, triangles +
 * skipped) in order, every id (a skipped one's too) maps to the geometry holding it
 * with its local index, the kept triangles' ids increase with their indices, and
 * every triangle carries its geometry's material. */
static void check_table(const rr_scene *s, const char *what) {
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.geometries == s->ngeoms && (in.triangles == 0 || in.geometries > 0), "%s: %u geometries for %llu triangles",
        what, in.geometries, (unsigned long long)in.triangles);
  uint64_t faces = in.triangles + in.skipped + in.spheres + in.planes; /* every primitive has an id */
  uint32_t next = 0, bad_range = 0, bad_lookup = 0, bad_material = 0, bad_order = 0;
  for (uint32_t g = 0; g < in.geometries; g++) {
    rr_geometry_info gi;
    if (rr_scene_get_geometry_info(s, g, &gi) != RR_OK) {
      CHECK(0, "%s: geometry %u: %s", what, g, rr_device_message(s->dev));
      return;
    }
    bad_range += gi.first != next || (unsigned)gi.kind >= RR_GEOMETRY_KIND_COUNT || (in.materials && gi.material >= in.materials);
    next = gi.first + gi.count;
    for (uint32_t i = gi.first; i < next && i < faces; i++) {
      uint32_t geom, local;
      bad_lookup += rr_scene_get_geometry(s, i, &geom, &local) != RR_OK || geom != g || local != i - gi.first;
    }
  }
  for (uint32_t i = 0; i < s->ntris; i++) {
    uint32_t id = scene_face_id(s, i), geom = RR_MISS;
    bad_order += id >= faces || (i > 0 && id <= scene_face_id(s, i - 1));
    rr_scene_get_geometry(s, id, &geom, NULL);
    bad_material += geom == RR_MISS || scene_material(s, i) != s->geoms[geom].material;
  }
  CHECK(bad_range == 0 && next == faces, "%s: %u geometries out of order, they end at %u of %llu", what, bad_range,
        next, (unsigned long long)faces);
  CHECK(bad_lookup == 0, "%s: %u ids map to the wrong geometry", what, bad_lookup);
  CHECK(bad_order == 0, "%s: %u triangles' ids out of order", what, bad_order);
  CHECK(bad_material == 0, "%s: %u triangles with another material than their geometry's", what, bad_material);
}

static rr_geometry_info geometry(const rr_scene *s, uint32_t g) {
  rr_geometry_info gi = {0};
  CHECK(rr_scene_get_geometry_info(s, g, &gi) == RR_OK, "geometry %u: %s", g, rr_device_message(s->dev));
  return gi;
}

static bool named(const rr_geometry_info *gi, const char *name) {
  return name ? gi->name && strcmp(gi->name, name) == 0 : gi->name == NULL;
}

/* Meshes added through the API, with degenerate and non-finite triangles: every
 * triangle keeps its id (its index over all the calls), dropped or not, and a
 * mesh that keeps nothing still holds its ids. */
static void test_add_mesh(rr_device *dev) {
  rr_scene *s;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  /* Side by side along x, so that a ray down the z axis at a centroid hits one. */
  const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 1, 1, 0};
  const uint32_t a[] = {0, 1, 2, 0, 1, 3, 1, 4, 2}; /* the middle one is a line: dropped */
  const uint32_t b[] = {0, 1, 3, 0, 0, 2};          /* both degenerate */
  const float xyzw[] = {4, 0, 0, 1, NAN, 0, 0, 1, 4, 1, 0, 1, 10, 0, 0, 2};
  const uint32_t c[] = {0, 1, 2, 0, 3, 2}; /* the first has a NaN corner */
  const float pos_d[] = {8, 0, 0, 9, 0, 0, 8, 1, 0};
  const uint32_t d[] = {0, 1, 2}, bad[] = {0, 1, 9};
  float rgb[3] = {0.5f, 0.5f, 0.5f};
  CHECK(rr_scene_add_mesh(s, pos, 5, a, 3, rgb) == RR_OK, "mesh a");
  CHECK(rr_scene_add_mesh(s, pos, 5, b, 2, rgb) == RR_OK, "mesh b");
  CHECK(rr_scene_add_mesh4(s, xyzw, 4, c, 2, NULL) == RR_OK, "mesh c");
  CHECK(rr_scene_add_mesh(s, pos_d, 3, d, 1, NULL) == RR_OK, "mesh d");
  CHECK(rr_scene_add_mesh(s, pos, 5, bad, 1, NULL) == RR_ERROR_ARGUMENT, "a rejected mesh adds no geometry");
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.triangles == 4 && in.skipped == 4 && in.geometries == 4, "%llu triangles, %llu skipped, %u geometries",
        (unsigned long long)in.triangles, (unsigned long long)in.skipped, in.geometries);
  const uint32_t first[4] = {0, 3, 5, 7}, count[4] = {3, 2, 2, 1};
  for (uint32_t g = 0; g < 4 && g < in.geometries; g++) {
    rr_geometry_info gi = geometry(s, g);
    CHECK(gi.first == first[g] && gi.count == count[g] && gi.material == g && named(&gi, NULL),
          "geometry %u: first %u count %u material %u name %s", g, gi.first, gi.count, gi.material,
          gi.name ? gi.name : "(none)");
  }
  CHECK(scene_vertex(s, 1, 1).y == 1 && scene_vertex(s, 1, 2).x == 5 && scene_vertex(s, 0, 3).x == 8,
        "indices are the kept triangles in order");
  /* ids of the kept triangles 0..3; every id 0..7 (dropped ones too) in its geometry */
  const uint32_t kept_id[4] = {0, 2, 6, 7}, want_geom[8] = {0, 0, 0, 1, 1, 2, 2, 3},
                 want_local[8] = {0, 1, 2, 0, 1, 0, 1, 0};
  for (uint32_t i = 0; i < 4; i++)
    CHECK(scene_face_id(s, i) == kept_id[i], "triangle %u: id %u", i, scene_face_id(s, i));
  for (uint32_t i = 0; i < 8; i++) {
    uint32_t g = 99, l = 99;
    CHECK(rr_scene_get_geometry(s, i, &g, &l) == RR_OK && g == want_geom[i] && l == want_local[i],
          "id %u: geometry %u local %u", i, g, l);
  }
  uint32_t g = 0, l = 0;
  CHECK(rr_scene_get_geometry(s, RR_MISS, &g, &l) == RR_OK && g == RR_MISS && l == RR_MISS, "a miss maps to a miss");
  CHECK(rr_scene_get_geometry(s, 8, &g, NULL) == RR_ERROR_ARGUMENT && g == RR_MISS &&
            strstr(rr_device_message(dev), "out of range"),
        "an id past the end: %s", rr_device_message(dev));
  rr_geometry_info gi;
  CHECK(rr_scene_get_geometry_info(s, 4, &gi) == RR_ERROR_ARGUMENT, "a geometry past the end");
  CHECK(rr_scene_get_geometry_info(s, 0, NULL) == RR_ERROR_ARGUMENT, "NULL info");
  check_table(s, "add_mesh");

  /* Ray queries report the geometry beside the triangle. */
  CHECK(rr_scene_commit(s) == RR_OK, "commit: %s", rr_device_message(dev));
  for (uint32_t i = 0; i < 4; i++) {
    vec3 p = v3_scale(v3_add(v3_add(scene_vertex(s, 0, i), scene_vertex(s, 1, i)), scene_vertex(s, 2, i)), 1 / 3.0f);
    rr_ray ray = {{p.x, p.y, 2}, {0, 0, -1}, 0, INFINITY};
    rr_hit hit;
    CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == kept_id[i] && hit.geom == want_geom[kept_id[i]],
          "ray at triangle %u: prim %u geom %u", i, hit.prim, hit.geom);
  }
  rr_ray away = {{0, 0, 2}, {0, 0, 1}, 0, INFINITY};
  rr_hit hit;
  CHECK(rr_intersect(dev, s, &away, &hit) == RR_OK && hit.prim == RR_MISS && hit.geom == RR_MISS, "a missing ray: geom %u",
        hit.geom);
  rr_scene_release(s);

  /* Triangles pushed into a scene without geometries form one unnamed geometry. */
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  vec3 p[3] = {v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
  rr_scene_push(s, p, NULL, NULL, 0);
  rr_scene_push(s, p, NULL, NULL, 0);
  rr_geometry_info only = geometry(s, 0);
  CHECK(s->ngeoms == 1 && only.count == 2 && named(&only, NULL), "one implicit geometry");
  check_table(s, "pushed");
  rr_scene_release(s);
}

/* An OBJ with objects, a group and two materials in one object: a geometry per
 * node/mesh pair, named after its object or group, in file order. */
static void test_obj(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, multi_obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (!s) return;
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.triangles == 5 && in.skipped == 1 && in.geometries == 4,
        "multi.obj: %llu triangles, %llu skipped, %u geometries", (unsigned long long)in.triangles, (unsigned long long)in.skipped, in.geometries);
  const char *names[4] = {"first", "first", "second", "grp"};
  const uint32_t first[4] = {0, 2, 3, 5}, count[4] = {2, 1, 2, 1}; /* face 1 (f 1 2 5) is dropped, keeps its id */
  const float blue[4] = {0, 1, 1, 1}; /* the last two objects keep the current material */
  for (uint32_t g = 0; g < 4 && g < in.geometries; g++) {
    rr_geometry_info gi = geometry(s, g);
    const float *rgb = s->materials[gi.material].color;
    CHECK(gi.first == first[g] && gi.count == count[g] && named(&gi, names[g]) && rgb[2] == blue[g] &&
              rgb[0] == 1 - blue[g],
          "geometry %u: first %u count %u name %s colour %g %g %g", g, gi.first, gi.count, gi.name ? gi.name : "(none)",
          rgb[0], rgb[1], rgb[2]);
  }
  check_table(s, "multi.obj");
  rr_scene_release(s);
}

/* Every built-in keeps the table's promises; the demo's objects are named. */
static void test_builtins(rr_device *dev) {
  char grid[600];
  snprintf(grid, sizeof grid, "grid:%s/multi.obj:3", dir);
  const char *scenes[] = {"demo", "plane:3", "sphere:8", "box:2", "rooms:2", "ground", grid};
  for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; k++) {
    rr_scene *s = NULL;
    CHECK(rr_scene_load(dev, scenes[k], &s) == RR_OK, "%s: %s", scenes[k], rr_device_message(dev));
    if (!s) continue;
    check_table(s, scenes[k]);
    if (k == 0) {
      const char *names[] = {"floor", "teapot", "spot", "sphere", "sphere", "torus"};
      CHECK(s->ngeoms == 6, "demo: %u geometries", s->ngeoms);
      for (uint32_t g = 0; g < 6 && g < s->ngeoms; g++) {
        rr_geometry_info gi = geometry(s, g);
        CHECK(named(&gi, names[g]) && gi.count > 0, "demo geometry %u: %s, %u triangles", g,
              gi.name ? gi.name : "(none)", gi.count);
      }
    }
    if (k == 4) CHECK(s->ngeoms == 4 * 6, "rooms:2: %u geometries (six a room)", s->ngeoms);
    if (k == 6) {
      /* copy c of the file's geometry j is geometry 4c + j, ids shifted by c·6 (the file's faces) */
      bool same = s->ngeoms == 9 * 4;
      for (uint32_t g = 0; same && g < s->ngeoms; g++) {
        rr_geometry_info gi = geometry(s, g), gj = geometry(s, g % 4);
        same = gi.first == gj.first + g / 4 * 6 && gi.count == gj.count && gi.material == gj.material &&
               gi.name && gj.name && strcmp(gi.name, gj.name) == 0;
      }
      CHECK(same, "grid: 9 copies of the file's 4 geometries (%u)", s->ngeoms);
    }
    rr_scene_release(s);
  }
}

/* The mesh and material AOVs of every method agree with the table at every pixel. */
static void test_aovs(rr_device *dev) {
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, "demo", &s) == RR_OK, "demo: %s", rr_device_message(dev));
  if (!s) return;
  int w = test_quick() ? 40 : 80, h = test_quick() ? 30 : 60;
  rr_camera cam;
  rr_camera_init(&cam);
  rr_camera_frame(dev, s, w, h, &cam);
  uint32_t *mesh0 = NULL;
  for (int m = 0; m < RR_METHOD_COUNT; m++) {
    rr_frame *f = test_render(dev, s, &cam, (rr_method)m, 1, w, h, 0);
    if (!f) continue;
    rr_image id, mesh, mat;
    bool ok = rr_frame_aov(dev, s, &cam, f, RR_AOV_ID, &id) == RR_OK &&
              rr_frame_aov(dev, s, &cam, f, RR_AOV_MESH, &mesh) == RR_OK &&
              rr_frame_aov(dev, s, &cam, f, RR_AOV_MATERIAL, &mat) == RR_OK;
    CHECK(ok && mesh.type == RR_PIXEL_U32 && mat.type == RR_PIXEL_U32 && mesh.channels == 1 && mat.channels == 1,
          "%s: AOVs: %s", rr_method_name(m), rr_device_message(dev));
    if (!ok) continue;
    const uint32_t *ids = id.data, *ms = mesh.data, *mt = mat.data;
    int bad = 0, hits = 0;
    uint32_t seen = 0;
    for (int k = 0; k < w * h; k++) {
      if (ids[k] == RR_MISS) {
        bad += ms[k] != RR_MISS || mt[k] != RR_MISS;
        continue;
      }
      hits++;
      uint32_t g = RR_MISS;
      rr_scene_get_geometry(s, ids[k], &g, NULL);
      rr_geometry_info gi = {0};
      rr_scene_get_geometry_info(s, ms[k], &gi);
      bad += ms[k] != g || mt[k] != gi.material || ids[k] < gi.first || ids[k] >= gi.first + gi.count;
      seen |= 1u << (ms[k] & 31);
    }
    CHECK(bad == 0 && hits > w * h / 10, "%s: %d of %d hits disagree with the geometry table", rr_method_name(m), bad,
          hits);
    CHECK(__builtin_popcount(seen) >= 4, "%s: only %d geometries in view", rr_method_name(m), __builtin_popcount(seen));
    size_t bytes = sizeof *ms * w * h;
    if (!mesh0 && (mesh0 = malloc(bytes))) memcpy(mesh0, ms, bytes);
    else if (mesh0) CHECK(memcmp(mesh0, ms, bytes) == 0, "%s: mesh AOV differs from rc's", rr_method_name(m));
    rr_image_free(&id), rr_image_free(&mesh), rr_image_free(&mat);
    rr_frame_release(f);
  }
  free(mesh0);
  rr_scene_release(s);
}

/* ---- ids in file order ----------------------------------------------------------- */

/* A strip of faces at known places in file order: good ones (A, B, C, D at x = 0, 2,
 * 4, 6.5), one of zero area, one with a repeated vertex, one with a non-finite
 * vertex (vertex 8, 0-based 7), and a quad whose fan gives a degenerate triangle
 * and a good one (C). Faces 0..7 after fan triangulation; the good ones are
 * KNOWN_IDS. */
static const float known_v[15][3] = {{0, 0, 0},   {1.5f, 0, 0}, {0, 1.5f, 0}, {3, 0, 0},    {2, 0, 0},
                                     {3.5f, 0, 0}, {2, 1.5f, 0}, {0, 0, 0},    {4, 0, 0},    {5, 0, 0},
                                     {6, 0, 0},    {4, 1.5f, 0}, {6.5f, 0, 0}, {8, 0, 0},    {6.5f, 1.5f, 0}};
#define KNOWN_BAD 7 /* the non-finite vertex */
static const char *const known_f = "f 1 2 3\nf 1 2 4\nf 1 1 2\nf 5 6 7\nf 1 2 8\nf 9 10 11 12\nf 13 14 15\n";
static const uint32_t known_idx[8][3] = {{0, 1, 2}, {0, 1, 3}, {0, 0, 1}, {4, 5, 6},
                                         {0, 1, 7}, {8, 9, 10}, {8, 10, 11}, {12, 13, 14}};
enum { KNOWN_FACES = 8, KNOWN_GOOD = 4 };
static const uint32_t known_ids[KNOWN_GOOD] = {0, 3, 6, 7};

/* Every method's id at the pixel of each good face's centroid, the id AOV, and a
 * ray down onto the centroid: all the face's index in the scene (copy k of the
 * strip moved up by 2k, its ids by 8k); the geometry's local index is the face's. */
static void check_known(rr_device *dev, rr_scene *s, int copies, const char *what) {
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.triangles == (uint64_t)KNOWN_GOOD * copies && in.skipped == (uint64_t)(KNOWN_FACES - KNOWN_GOOD) * copies,
        "%s: %llu kept, %llu skipped", what, (unsigned long long)in.triangles, (unsigned long long)in.skipped);
  check_table(s, what);
  int w = 96, h = 64;
  rr_camera cam;
  rr_camera_init(&cam);
  float eye[3] = {4, copies - 0.25f, 12}, target[3] = {4, copies - 0.25f, 0};
  memcpy(cam.eye, eye, sizeof eye), memcpy(cam.target, target, sizeof target);
  camera c;
  if (rr_cam_setup(dev, &cam, w, h, &c) != RR_OK) {
    CHECK(0, "%s: camera: %s", what, rr_device_message(dev));
    return;
  }
  for (int m = 0; m < RR_METHOD_COUNT; m++) {
    rr_frame *f = test_render(dev, s, &cam, (rr_method)m, 2, w, h, 0);
    rr_image aov = {0};
    if (!f || rr_frame_aov(dev, s, &cam, f, RR_AOV_ID, &aov) != RR_OK) {
      CHECK(0, "%s %s: no frame or id AOV", what, rr_method_name(m));
      rr_frame_release(f);
      continue;
    }
    const uint32_t *ids = rr_frame_ids(f);
    CHECK(memcmp(ids, aov.data, sizeof *ids * w * h) == 0, "%s %s: the id AOV differs from the frame's ids", what,
          rr_method_name(m));
    for (int k = 0; k < copies; k++)
      for (int g = 0; g < KNOWN_GOOD; g++) {
        const uint32_t *t = known_idx[known_ids[g]];
        vec3 p = v3(0, 0, 0);
        for (int v = 0; v < 3; v++) p = v3_add(p, v3_load(known_v[t[v]]));
        p = v3_add(v3_scale(p, 1 / 3.0f), v3(0, 2.0f * k, 0));
        double sx = -1, sy = -1;
        rr_raster2d_project(s, &c, p, &sx, &sy);
        int x = (int)sx, y = (int)sy;
        uint32_t want = known_ids[g] + KNOWN_FACES * (uint32_t)k;
        bool inside = x >= 0 && x < w && y >= 0 && y < h;
        CHECK(inside && ids[y * w + x] == want, "%s %s: pixel (%d, %d) of face %u: id %u", what, rr_method_name(m), x,
              y, want, inside ? ids[y * w + x] : RR_MISS);
        if (m > 0) continue;
        rr_ray ray = {{p.x, p.y, 3}, {0, 0, -1}, 0, INFINITY};
        rr_hit hit;
        uint32_t geom = RR_MISS, local = RR_MISS;
        CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == want && hit.geom == (uint32_t)k &&
                  rr_scene_get_geometry(s, hit.prim, &geom, &local) == RR_OK && geom == (uint32_t)k &&
                  local == known_ids[g],
              "%s: ray onto face %u: prim %u geom %u local %u", what, want, hit.prim, hit.geom, local);
      }
    rr_image_free(&aov);
    rr_frame_release(f);
  }
  rr_cam_release(&c);
}

static void test_known_ids(rr_device *dev) {
  /* the file: the non-finite vertex overflows float (1e39) */
  char obj[2048] = "";
  size_t n = 0;
  for (int v = 0; v < 15; v++)
    n += (size_t)snprintf(obj + n, sizeof obj - n, v == KNOWN_BAD ? "v 1e39 0 0\n" : "v %g %g %g\n",
                          (double)known_v[v][0], (double)known_v[v][1], (double)known_v[v][2]);
  snprintf(obj + n, sizeof obj - n, "%s", known_f);
  const char *path = test_write_file(dir, "known.obj", obj);
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, path, &s) == RR_OK, "known.obj: %s", rr_device_message(dev));
  if (s) check_known(dev, s, 1, "known.obj");
  rr_scene_release(s);

  /* the API: three copies, through each adding call, the bad vertex NaN (and w = 2
   * elsewhere in rr_scene_add_mesh4) */
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  float pos[3][15 * 3], xyzw[15 * 4], rgb[15 * 3];
  for (int k = 0; k < 3; k++)
    for (int v = 0; v < 15; v++)
      for (int i = 0; i < 3; i++) pos[k][3 * v + i] = v == KNOWN_BAD ? NAN : known_v[v][i] + (i == 1 ? 2.0f * k : 0);
  for (int v = 0; v < 15; v++) {
    for (int i = 0; i < 3; i++) xyzw[4 * v + i] = 2 * pos[2][3 * v + i], rgb[3 * v + i] = 0.5f;
    xyzw[4 * v + 3] = 2;
  }
  CHECK(rr_scene_add_mesh(s, pos[0], 15, &known_idx[0][0], KNOWN_FACES, NULL) == RR_OK &&
            rr_scene_add_mesh_colors(s, pos[1], 15, &known_idx[0][0], KNOWN_FACES, NULL, rgb) == RR_OK &&
            rr_scene_add_mesh4(s, xyzw, 15, &known_idx[0][0], KNOWN_FACES, NULL) == RR_OK &&
            rr_scene_commit(s) == RR_OK,
        "adding the strips: %s", rr_device_message(dev));
  check_known(dev, s, 3, "rr_scene_add_mesh*");
  rr_scene_release(s);
}

/* The faces of an OBJ file in file order after fan triangulation, read here from
 * its v and f lines (the loader's reference): vertices in *v (3 doubles each),
 * triangles in *t (3 0-based indices each). False when unreadable. */
static bool read_obj(const char *path, double **v, size_t *nv, uint32_t **t, size_t *nt) {
  FILE *f = fopen(path, "r");
  if (!f) return false;
  size_t cv = 1024, ct = 1024;
  *v = malloc(cv * 3 * sizeof **v), *t = malloc(ct * 3 * sizeof **t), *nv = *nt = 0;
  char line[4096];
  bool ok = *v && *t;
  while (ok && fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') {
      if (*nv == cv && !(*v = realloc(*v, (cv *= 2) * 3 * sizeof **v))) break;
      char *p = line + 2;
      for (int i = 0; i < 3; i++) (*v)[3 * *nv + i] = strtod(p, &p);
      ++*nv;
    } else if (line[0] == 'f' && line[1] == ' ') {
      long idx[64];
      int n = 0;
      for (char *p = line + 1, *end; n < 64; p = end) {
        while (*p && *p != '\n' && (*p == ' ' || *p == '\t')) p++;
        long i = strtol(p, &end, 10);
        if (end == p) break;
        idx[n++] = i < 0 ? (long)*nv + i : i - 1; /* OBJ: 1-based, negative from the end */
        while (*end && *end != ' ' && *end != '\t' && *end != '\n') end++; /* the /vt/vn part */
      }
      for (int j = 1; j + 1 < n; j++) {
        if (*nt == ct && !(*t = realloc(*t, (ct *= 2) * 3 * sizeof **t))) break;
        uint32_t *o = *t + 3 * *nt;
        o[0] = (uint32_t)idx[0], o[1] = (uint32_t)idx[j], o[2] = (uint32_t)idx[j + 1];
        ok = ok && o[0] < *nv && o[1] < *nv && o[2] < *nv;
        ++*nt;
      }
    }
  }
  fclose(f);
  return ok && *v && *t;
}

/* The ogre has degenerate faces: the ids of a 3dr-bb render against a double-precision
 * ray cast (Möller–Trumbore, ties to the lower id) of the file's own faces, each
 * tried on the pixels its projection covers. */
static void test_ogre_ids(rr_device *dev) {
  const char *path = test_model("ogre.obj");
  if (!path) return;
  double *v = NULL;
  uint32_t *tri = NULL;
  size_t nv = 0, nt = 0;
  rr_scene *s = NULL;
  bool read = read_obj(path, &v, &nv, &tri, &nt);
  CHECK(read && nt > 0, "ogre.obj: read %zu faces", read ? nt : 0);
  CHECK(rr_scene_load(dev, path, &s) == RR_OK, "ogre.obj: %s", rr_device_message(dev));
  rr_scene_info in = {0};
  if (s) rr_scene_get_info(s, &in);
  CHECK(in.skipped > 0 && in.triangles + in.skipped == nt, "ogre.obj: %llu kept + %llu skipped of %zu faces",
        (unsigned long long)in.triangles, (unsigned long long)in.skipped, nt);
  int w = test_quick() ? 96 : 192, h = test_quick() ? 72 : 144;
  rr_camera cam;
  rr_camera_init(&cam);
  camera c;
  rr_frame *f = NULL;
  if (!read || !s || rr_camera_frame(dev, s, w, h, &cam) != RR_OK || rr_cam_setup(dev, &cam, w, h, &c) != RR_OK) {
    CHECK(0, "ogre.obj: no view: %s", rr_device_message(dev));
    goto done;
  }
  if ((f = test_render(dev, s, &cam, RR_METHOD_3DR_BB, 2, w, h, 0))) {
    size_t np = (size_t)w * h;
    double *o = malloc(np * 3 * sizeof *o), *d = malloc(np * 3 * sizeof *d), *best = malloc(np * sizeof *best);
    uint32_t *ref = malloc(np * sizeof *ref);
    for (size_t k = 0; o && d && best && ref && k < np; k++) {
      vec3 of, df;
      rr_cam_ray(&c, (int)(k % w), (int)(k / w), &of, &df);
      o[3 * k] = of.x, o[3 * k + 1] = of.y, o[3 * k + 2] = of.z, d[3 * k] = df.x, d[3 * k + 1] = df.y,
      d[3 * k + 2] = df.z, best[k] = INFINITY, ref[k] = RR_MISS;
    }
    for (size_t i = 0; o && d && best && ref && i < nt; i++) {
      const double *p0 = v + 3 * tri[3 * i], *p1 = v + 3 * tri[3 * i + 1], *p2 = v + 3 * tri[3 * i + 2];
      double e1[3], e2[3], lo[2] = {w, h}, hi[2] = {-1, -1};
      for (int a = 0; a < 3; a++) e1[a] = p1[a] - p0[a], e2[a] = p2[a] - p0[a];
      for (int k = 0; k < 3; k++) { /* the pixels to try: the projected corners' box, a pixel wider */
        const double *p = k == 0 ? p0 : k == 1 ? p1 : p2;
        double sx, sy;
        if (!rr_raster2d_project(s, &c, v3((float)p[0], (float)p[1], (float)p[2]), &sx, &sy)) sx = sy = NAN;
        if (!(sx == sx && sy == sy)) lo[0] = lo[1] = 0, hi[0] = w, hi[1] = h; /* behind the eye: everywhere */
        lo[0] = fmin(lo[0], sx), lo[1] = fmin(lo[1], sy), hi[0] = fmax(hi[0], sx), hi[1] = fmax(hi[1], sy);
      }
      int x0 = (int)fmax(0, floor(lo[0]) - 1), x1 = (int)fmin(w - 1, floor(hi[0]) + 1);
      int y0 = (int)fmax(0, floor(lo[1]) - 1), y1 = (int)fmin(h - 1, floor(hi[1]) + 1);
      for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
          size_t k = (size_t)y * w + x;
          const double *ro = o + 3 * k, *rd = d + 3 * k;
          double pv[3] = {rd[1] * e2[2] - rd[2] * e2[1], rd[2] * e2[0] - rd[0] * e2[2], rd[0] * e2[1] - rd[1] * e2[0]};
          double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
          if (!(det != 0)) continue; /* zero area or not finite: never hit */
          double sv[3] = {ro[0] - p0[0], ro[1] - p0[1], ro[2] - p0[2]};
          double u = (sv[0] * pv[0] + sv[1] * pv[1] + sv[2] * pv[2]) / det;
          double q[3] = {sv[1] * e1[2] - sv[2] * e1[1], sv[2] * e1[0] - sv[0] * e1[2], sv[0] * e1[1] - sv[1] * e1[0]};
          double l2 = (rd[0] * q[0] + rd[1] * q[1] + rd[2] * q[2]) / det;
          double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
          if (u >= 0 && l2 >= 0 && u + l2 <= 1 && t > 0 && t < best[k]) best[k] = t, ref[k] = (uint32_t)i;
        }
    }
    const uint32_t *ids = rr_frame_ids(f);
    size_t hits = 0, agree = 0;
    for (size_t k = 0; ref && k < np; k++)
      if (ids[k] != RR_MISS || ref[k] != RR_MISS) hits++, agree += ids[k] == ref[k];
    printf("ogre.obj %dx%d: ids agree with the file's faces on %zu of %zu hit pixels\n", w, h, agree, hits);
    CHECK(ref && hits > np / 10 && agree >= 0.999 * hits, "ogre.obj: ids agree with the file's faces on %zu of %zu",
          agree, hits);
    free(o), free(d), free(best), free(ref);
  }
  rr_cam_release(&c);
done:
  rr_frame_release(f);
  rr_scene_release(s);
  free(v), free(tri);
}

static int run(const char *args, char *out, size_t size) { return test_run_cli(dir, args, false, out, size); }

static rr_image read_u32(rr_device *dev, const char *name) {
  char path[600];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  rr_image img = {0};
  CHECK(rr_image_read(dev, path, &img) == RR_OK && img.type == RR_PIXEL_U32 && img.channels == 1, "%s: %s", name,
        rr_device_message(dev));
  return img;
}

static void test_cli(rr_device *dev) {
  char out[8192];
  int rc = run("render multi.obj --size 48x32 --method 3dr-bb --aov id=i.npy --aov mesh=m.npy --aov material=t.npy",
               out, sizeof out);
  CHECK(rc == 0, "render exit %d", rc);
  rr_image id = read_u32(dev, "i.npy"), mesh = read_u32(dev, "m.npy"), mat = read_u32(dev, "t.npy");
  rr_scene *s = NULL;
  rr_scene_load(dev, multi_obj, &s);
  if (s && id.data && mesh.data && mat.data) {
    const uint32_t *ids = id.data, *ms = mesh.data, *mt = mat.data;
    int bad = 0, hits = 0;
    for (int k = 0; k < 48 * 32; k++) {
      uint32_t g = RR_MISS;
      rr_scene_get_geometry(s, ids[k], &g, NULL);
      hits += ids[k] != RR_MISS;
      bad += ms[k] != g || mt[k] != (g == RR_MISS ? RR_MISS : geometry(s, g).material);
    }
    CHECK(bad == 0 && hits > 0, "CLI: %d pixels of mesh or material disagree (%d hits)", bad, hits);
  }
  rr_image_free(&id), rr_image_free(&mesh), rr_image_free(&mat);
  rr_scene_release(s);

  rc = run("info multi.obj", out, sizeof out);
  CHECK(rc == 0 && strstr(out, "geometries   4") && strstr(out, "second") && strstr(out, "grp"), "info: %s", out);
  rc = run("render multi.obj --aov meshes=x.npy", out, sizeof out);
  CHECK(rc == 2, "an unknown AOV is a usage error (%d)", rc);
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  rr_device *dev = rr_device_new();
  test_write_file(dir, "m.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  multi_obj = test_write_file(dir, "multi.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 2 0 0\n"
                                      "o first\nusemtl red\nf 1 2 3\nf 1 2 5\nusemtl blue\nf 1 3 4\n"
                                      "o second\nf 1 2 3 4\ng grp\nf 2 3 4\n");
  CHECK(rr_aov_from_name("mesh") == RR_AOV_MESH && rr_aov_from_name("material") == RR_AOV_MATERIAL, "AOV names");
  CHECK(strcmp(rr_geometry_kind_name(RR_GEOMETRY_TRIANGLE), "triangle") == 0 &&
            rr_geometry_kind_name(RR_GEOMETRY_KIND_COUNT) == NULL && rr_geometry_kind_name(-1) == NULL,
        "kind names");
  test_add_mesh(dev);
  test_obj(dev);
  test_builtins(dev);
  test_aovs(dev);
  test_known_ids(dev);
  test_ogre_ids(dev);
  test_cli(dev);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  rr_device_release(dev);
  return test_done();
}
