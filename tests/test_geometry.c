/* Geometries: the table of meshes over the global primitive ids (rr_scene_add_mesh
 * calls with dropped triangles, a multi-object OBJ, every built-in), the lookup of a
 * primitive's geometry, ray hits, the mesh and material AOVs of every method, and
 * the CLI writing them. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <sys/wait.h>

static char dir[] = "/tmp/rr_geometry_XXXXXX";
static const char *multi_obj; /* written by main */

/* The table's promises on any scene: geometries tile [0, triangles) in order, every
 * id maps to the geometry holding it with its local index, and every triangle
 * carries its geometry's material. */
static void check_table(const rr_scene *s, const char *what) {
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.geometries == s->ngeoms && (in.triangles == 0 || in.geometries > 0), "%s: %u geometries for %llu triangles",
        what, in.geometries, (unsigned long long)in.triangles);
  uint32_t next = 0, bad_range = 0, bad_lookup = 0, bad_material = 0;
  for (uint32_t g = 0; g < in.geometries; g++) {
    rr_geometry_info gi;
    if (rr_scene_get_geometry_info(s, g, &gi) != RR_OK) {
      CHECK(0, "%s: geometry %u: %s", what, g, rr_device_message(s->dev));
      return;
    }
    bad_range += gi.first != next || gi.kind != RR_GEOMETRY_TRIANGLE || (in.materials && gi.material >= in.materials);
    next = gi.first + gi.count;
    for (uint32_t i = gi.first; i < next && i < in.triangles; i++) {
      uint32_t geom, local;
      bad_lookup += rr_scene_get_geometry(s, i, &geom, &local) != RR_OK || geom != g || local != i - gi.first;
      bad_material += s->material[i] != gi.material;
    }
  }
  CHECK(bad_range == 0 && next == in.triangles, "%s: %u geometries out of order, they end at %u of %llu", what,
        bad_range, next, (unsigned long long)in.triangles);
  CHECK(bad_lookup == 0, "%s: %u ids map to the wrong geometry", what, bad_lookup);
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

/* Meshes added through the API, with degenerate and non-finite triangles: the ids
 * stay those of the kept triangles in order, a mesh that keeps nothing is an empty
 * geometry. */
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
  const uint32_t first[4] = {0, 2, 2, 3}, count[4] = {2, 0, 1, 1};
  for (uint32_t g = 0; g < 4 && g < in.geometries; g++) {
    rr_geometry_info gi = geometry(s, g);
    CHECK(gi.first == first[g] && gi.count == count[g] && gi.material == g && named(&gi, NULL),
          "geometry %u: first %u count %u material %u name %s", g, gi.first, gi.count, gi.material,
          gi.name ? gi.name : "(none)");
  }
  CHECK(scene_vertex(s, 1, 1).y == 1 && scene_vertex(s, 1, 2).x == 5 && scene_vertex(s, 0, 3).x == 8,
        "ids are the kept triangles in order");
  const uint32_t want_geom[4] = {0, 0, 2, 3}, want_local[4] = {0, 1, 0, 0};
  for (uint32_t i = 0; i < 4; i++) {
    uint32_t g = 99, l = 99;
    CHECK(rr_scene_get_geometry(s, i, &g, &l) == RR_OK && g == want_geom[i] && l == want_local[i],
          "triangle %u: geometry %u local %u", i, g, l);
  }
  uint32_t g = 0, l = 0;
  CHECK(rr_scene_get_geometry(s, RR_MISS, &g, &l) == RR_OK && g == RR_MISS && l == RR_MISS, "a miss maps to a miss");
  CHECK(rr_scene_get_geometry(s, 4, &g, NULL) == RR_ERROR_ARGUMENT && g == RR_MISS &&
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
    CHECK(rr_intersect(dev, s, &ray, &hit) == RR_OK && hit.prim == i && hit.geom == want_geom[i],
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
  const uint32_t first[4] = {0, 1, 2, 4}, count[4] = {1, 1, 2, 1};
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
      /* copy c of the file's geometry j is geometry 4c + j, ids shifted by c·5 */
      bool same = s->ngeoms == 9 * 4;
      for (uint32_t g = 0; same && g < s->ngeoms; g++) {
        rr_geometry_info gi = geometry(s, g), gj = geometry(s, g % 4);
        same = gi.first == gj.first + g / 4 * 5 && gi.count == gj.count && gi.material == gj.material &&
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
  test_cli(dev);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  rr_device_release(dev);
  return test_done();
}
