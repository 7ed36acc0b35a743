/* Built-in scenes: exact plane coordinates, closed and consistently wound sphere and
 * box, grid copies that are exact translations, and the name errors. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>

static rr_device *dev;

/* Loads a built-in name into a new scene; NULL (and *err set) on failure. */
static rr_scene *load(const char *name, rr_error *err) {
  rr_scene *s = NULL;
  rr_error e = rr_scene_new(dev, &s);
  if (!e) e = rr_scene_load_builtin(s, name);
  if (err) *err = e;
  if (e) {
    rr_scene_release(s);
    return NULL;
  }
  return s;
}

static vec3 face_normal(const rr_scene *s, uint32_t i) {
  vec3 a = scene_vertex(s, 0, i), b = scene_vertex(s, 1, i), c = scene_vertex(s, 2, i);
  return v3_cross(v3_sub(b, a), v3_sub(c, a));
}

/* Sum of the signed volumes of the tetrahedra origin-triangle: the enclosed volume,
 * positive when the triangles face outward. */
static double signed_volume(const rr_scene *s) {
  double v = 0;
  for (uint32_t i = 0; i < s->ntris; i++) {
    vec3 a = scene_vertex(s, 0, i), b = scene_vertex(s, 1, i), c = scene_vertex(s, 2, i);
    v += (a.x * ((double)b.y * c.z - (double)b.z * c.y) - a.y * ((double)b.x * c.z - (double)b.z * c.x) +
          a.z * ((double)b.x * c.y - (double)b.y * c.x)) / 6.0;
  }
  return v;
}

/* ---- closedness: directed edges keyed by exact coordinates ---------------------- */

typedef struct edge { float v[6]; } edge; /* from xyz, to xyz */

static int edge_cmp(const void *pa, const void *pb) {
  const edge *a = pa, *b = pb;
  for (int i = 0; i < 6; i++)
    if (a->v[i] != b->v[i]) return a->v[i] < b->v[i] ? -1 : 1;
  return 0;
}

/* Every undirected edge must appear exactly twice, once in each direction: no
 * directed edge twice, and each one's reverse present. */
static void check_closed(const rr_scene *s, const char *name) {
  size_t ne = 3 * (size_t)s->ntris;
  edge *e = malloc(ne * sizeof *e);
  CHECK(e != NULL, "out of memory");
  if (!e) return;
  for (uint32_t i = 0; i < s->ntris; i++)
    for (int k = 0; k < 3; k++) {
      vec3 a = scene_vertex(s, k, i), b = scene_vertex(s, (k + 1) % 3, i);
      edge *d = &e[3 * (size_t)i + k];
      d->v[0] = a.x, d->v[1] = a.y, d->v[2] = a.z, d->v[3] = b.x, d->v[4] = b.y, d->v[5] = b.z;
    }
  qsort(e, ne, sizeof *e, edge_cmp);
  size_t twice = 0, open = 0;
  for (size_t j = 0; j < ne; j++) {
    if (j + 1 < ne && edge_cmp(&e[j], &e[j + 1]) == 0) twice++;
    edge r = {{e[j].v[3], e[j].v[4], e[j].v[5], e[j].v[0], e[j].v[1], e[j].v[2]}};
    if (!bsearch(&r, e, ne, sizeof *e, edge_cmp)) open++;
  }
  CHECK(twice == 0, "%s: %zu directed edges used twice (inconsistent winding)", name, twice);
  CHECK(open == 0, "%s: %zu edges without their reverse (not closed)", name, open);
  free(e);
}

/* ---- plane ------------------------------------------------------------------------ */

static void test_plane(const char *name, int n) {
  rr_error err;
  rr_scene *s = load(name, &err);
  CHECK(s != NULL, "%s: error %d: %s", name, err, rr_device_message(dev));
  if (!s) return;
  CHECK(s->ntris == 2u * n * n, "%s: %u triangles, expected %d", name, s->ntris, 2 * n * n);
  uint32_t bad_coord = 0, bad_normal = 0;
  double area = 0;
  float lo = (float)-(n / 2), hi = lo + (float)n;
  for (uint32_t i = 0; i < s->ntris; i++) {
    for (int k = 0; k < 3; k++) {
      vec3 p = scene_vertex(s, k, i);
      if (p.y != 0 || p.x != floorf(p.x) || p.z != floorf(p.z) || p.x < lo || p.x > hi ||
          p.z < lo || p.z > hi)
        bad_coord++;
    }
    vec3 f = face_normal(s, i);
    if (!(f.y > 0) || f.x != 0 || f.z != 0) bad_normal++;
    area += 0.5 * f.y;
  }
  CHECK(bad_coord == 0, "%s: %u corners off the integer grid", name, bad_coord);
  CHECK(bad_normal == 0, "%s: %u triangles not facing +y", name, bad_normal);
  CHECK(area == (double)n * n, "%s: area %g, expected %d", name, area, n * n);
  if (n % 2 == 0)
    CHECK(s->bmin.x == -n / 2 && s->bmax.x == n / 2 && s->bmin.z == -n / 2 && s->bmax.z == n / 2,
          "%s: bounds x %g..%g z %g..%g", name, s->bmin.x, s->bmax.x, s->bmin.z, s->bmax.z);
  rr_scene_release(s);
}

/* ---- sphere and box ---------------------------------------------------------------- */

static void test_sphere(const char *name, int n) {
  rr_error err;
  rr_scene *s = load(name, &err);
  CHECK(s != NULL, "%s: error %d: %s", name, err, rr_device_message(dev));
  if (!s) return;
  uint32_t expect = 2u * n * (n / 2 - 1);
  CHECK(s->ntris == expect, "%s: %u triangles, expected %u", name, s->ntris, expect);
  check_closed(s, name);
  double vol = signed_volume(s), ball = 4.0 / 3.0 * 3.14159265358979;
  /* inscribed in the unit ball; close to it once the tessellation is fine */
  CHECK(vol > (n >= 32 ? 0.97 * ball : 0) && vol < ball, "%s: signed volume %g (ball %g)", name,
        vol, ball);
  CHECK(s->n[0][0] != NULL, "%s: no normals", name);
  uint32_t bad_n = 0, bad_r = 0;
  for (uint32_t i = 0; s->n[0][0] && i < s->ntris; i++)
    for (int k = 0; k < 3; k++) {
      vec3 p = scene_vertex(s, k, i), nk = v3(s->n[k][0][i], s->n[k][1][i], s->n[k][2][i]);
      if (nk.x != p.x || nk.y != p.y || nk.z != p.z) bad_n++;
      if (fabsf(v3_len(p) - 1) > 1e-6f) bad_r++;
    }
  CHECK(bad_n == 0, "%s: %u corner normals differ from the position", name, bad_n);
  CHECK(bad_r == 0, "%s: %u corners off the unit sphere", name, bad_r);
  rr_scene_release(s);
}

static void test_box(const char *name, int n) {
  rr_error err;
  rr_scene *s = load(name, &err);
  CHECK(s != NULL, "%s: error %d: %s", name, err, rr_device_message(dev));
  if (!s) return;
  CHECK(s->ntris == 12u * n * n, "%s: %u triangles, expected %d", name, s->ntris, 12 * n * n);
  check_closed(s, name);
  double vol = signed_volume(s);
  CHECK(fabs(vol - 8) < 1e-4, "%s: signed volume %g, expected 8", name, vol);
  uint32_t off = 0;
  for (uint32_t i = 0; i < s->ntris; i++) {
    /* each triangle lies on one face, facing out along that face's axis */
    vec3 f = face_normal(s, i), a = scene_vertex(s, 0, i);
    int axis = fabsf(f.x) > 0 ? 0 : fabsf(f.y) > 0 ? 1 : 2;
    float side = v3_get(a, axis);
    bool on = fabsf(side) == 1 && v3_get(f, axis) * side > 0;
    for (int k = 0; k < 3; k++) on = on && v3_get(scene_vertex(s, k, i), axis) == side;
    if (!on) off++;
  }
  CHECK(off == 0, "%s: %u triangles off the faces or facing in", name, off);
  CHECK(s->bmin.x == -1 && s->bmax.x == 1 && s->bmin.y == -1 && s->bmax.y == 1, "%s: bounds", name);
  rr_scene_release(s);
}

/* ---- grid ---------------------------------------------------------------------------- */

static void test_grid(int n) {
  const char *path = RR_DATA_DIR "/teapot.obj";
  rr_scene *ref = NULL;
  rr_error e = rr_scene_new(dev, &ref);
  if (!e) e = rr_scene_import_file(ref, path);
  CHECK(e == RR_OK, "loading %s: %s", path, rr_device_message(dev));
  char name[512];
  snprintf(name, sizeof name, "grid:%s:%d", path, n);
  rr_scene *s = e ? NULL : load(name, &e);
  CHECK(s != NULL, "%s: error %d: %s", name, e, rr_device_message(dev));
  if (!s) {
    rr_scene_release(ref);
    return;
  }
  uint32_t T = ref->ntris;
  CHECK(T > 0 && s->ntris == (uint32_t)(n * n) * T, "%s: %u triangles, expected %d x %u", name,
        s->ntris, n * n, T);
  float xlo = INFINITY, xhi = -INFINITY, zlo = INFINITY, zhi = -INFINITY;
  for (uint32_t m = 0; m < T; m++)
    for (int k = 0; k < 3; k++) {
      vec3 p = scene_vertex(ref, k, m);
      xlo = fminf(xlo, p.x), xhi = fmaxf(xhi, p.x), zlo = fminf(zlo, p.z), zhi = fmaxf(zhi, p.z);
    }
  float sx = xhi - xlo, sz = zhi - zlo;
  uint32_t bad_p = 0, bad_attr = 0;
  for (int j = 0; j < n && s->ntris == (uint32_t)(n * n) * T; j++)
    for (int i = 0; i < n; i++) {
      uint32_t base = (uint32_t)(j * n + i) * T;
      float ox = (float)i * 1.25f * sx, oz = (float)j * 1.25f * sz;
      for (uint32_t m = 0; m < T; m++) {
        for (int k = 0; k < 3; k++) {
          vec3 p = scene_vertex(ref, k, m), q = scene_vertex(s, k, base + m);
          if (q.x != p.x + ox || q.y != p.y || q.z != p.z + oz) bad_p++;
          /* (through the accessors: grid: stores the mesh once, instance.h) */
          uint32_t st = scene_st(s, base + m);
          vec3 na = ref->n[0][0] ? scene_normal(s, k, base + m) : v3(0, 0, 0), nb = ref->n[0][0] ? scene_normal(ref, k, m) : na;
          bad_attr += na.x != nb.x || na.y != nb.y || na.z != nb.z;
          for (int c = 0; c < 2 && ref->uv[0][0]; c++)
            if (s->uv[k][c][st] != ref->uv[k][c][m]) bad_attr++;
        }
        if (scene_material(s, base + m) != ref->material[m]) bad_attr++;
      }
    }
  CHECK(bad_p == 0, "%s: %u corners are not exact translations", name, bad_p);
  CHECK(bad_attr == 0, "%s: %u normals/uvs/materials differ from the original", name, bad_attr);
  CHECK(s->nmaterials == ref->nmaterials, "%s: %u materials, file has %u", name, s->nmaterials,
        ref->nmaterials);
  CHECK((s->n[0][0] != NULL) == (ref->n[0][0] != NULL) && (s->uv[0][0] != NULL) == (ref->uv[0][0] != NULL),
        "%s: attribute arrays differ from the file's", name);
  rr_scene_release(s);
  rr_scene_release(ref);
}

/* ---- names --------------------------------------------------------------------------- */

static void expect_error(const char *name, rr_error want, const char *in_message) {
  rr_error e;
  rr_scene *s = load(name, &e);
  CHECK(s == NULL && e == want, "'%s': got %d, expected %d", name, e, want);
  const char *msg = rr_device_message(dev);
  if (in_message)
    CHECK(strstr(msg, in_message) != NULL, "'%s': message '%s' does not name '%s'", name, msg, in_message);
  CHECK(strchr(msg, '\n') == NULL, "'%s': message has a newline", name);
  rr_scene_release(s);
}

static void test_names(void) {
  expect_error("grid:x.obj:0", RR_ERROR_ARGUMENT, "'0'");
  expect_error("grid:x.obj:1001", RR_ERROR_ARGUMENT, "'1001'");
  expect_error("grid:x.obj:-2", RR_ERROR_ARGUMENT, "'-2'");
  expect_error("grid:x.obj:2x", RR_ERROR_ARGUMENT, "'2x'");
  expect_error("grid:x.obj: 2", RR_ERROR_ARGUMENT, "' 2'");
  expect_error("grid:x.obj:", RR_ERROR_ARGUMENT, "''");
  expect_error("grid:x.obj", RR_ERROR_ARGUMENT, "grid:x.obj");
  expect_error("grid:", RR_ERROR_ARGUMENT, NULL);
  expect_error("grid::3", RR_ERROR_ARGUMENT, NULL);
  expect_error("grid:x.obj:99999999999999999999", RR_ERROR_ARGUMENT, "99999999999999999999");
  /* N·N·T beyond 32-bit ids: 1000² teapots */
  expect_error("grid:" RR_DATA_DIR "/teapot.obj:1000", RR_ERROR_ARGUMENT, "grid:");
  /* the count follows the last ':', so the path keeps its own ':' */
  expect_error("grid:/nonexistent:dir/x.obj:2", RR_ERROR_IO, "/nonexistent:dir/x.obj");
  expect_error("plane:0", RR_ERROR_ARGUMENT, "'0'");
  expect_error("plane:", RR_ERROR_ARGUMENT, "''");
  expect_error("plane:abc", RR_ERROR_ARGUMENT, "'abc'");
  expect_error("sphere:3", RR_ERROR_ARGUMENT, "'3'");
  expect_error("box:0", RR_ERROR_ARGUMENT, "'0'");
  expect_error("rooms:0", RR_ERROR_ARGUMENT, "'0'");
  expect_error("spheres:0", RR_ERROR_ARGUMENT, "'0'");
  expect_error("spheres:1000001", RR_ERROR_ARGUMENT, "'1000001'");
  const char *unknown[] = {"", "teapot.obj", RR_DATA_DIR "/teapot.obj", "planet", "spheres2",
                           "box.obj", "demo2", "grid", "Plane"};
  for (size_t i = 0; i < sizeof unknown / sizeof *unknown; i++) {
    rr_error e;
    rr_scene *s = load(unknown[i], &e);
    CHECK(s == NULL && e == RR_ERROR_UNSUPPORTED, "'%s': got %d, expected RR_ERROR_UNSUPPORTED",
          unknown[i], e);
    rr_scene_release(s);
  }
}

/* ---- spheres:N ----------------------------------------------------------------------- */

/* N analytic spheres, radii 0.15 .. 0.45, centres inside the cube of side 2.2·∛N, in
 * min(N, 8) geometries, the same scene at every load. */
static void test_spheres(const char *name, long n) {
  rr_error e;
  rr_scene *s = load(name, &e), *again = load(name, &e);
  CHECK(s && again, "'%s': %s", name, rr_device_message(dev));
  if (!s || !again) {
    rr_scene_release(s), rr_scene_release(again);
    return;
  }
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  CHECK(s->ntris == (uint32_t)n && info.triangles == 0 && s->ngeoms == (uint32_t)(n < 8 ? n : 8),
        "'%s': %u primitives (%llu triangles) in %u geometries", name, s->ntris, (unsigned long long)info.triangles,
        s->ngeoms);
  float half = 1.1f * cbrtf((float)n);
  uint32_t bad = 0;
  for (uint32_t i = 0; i < s->ntris; i++) {
    const float *a = s->ana + (size_t)ANA_FLOATS * i;
    bad += scene_kind(s, i) != RR_GEOMETRY_SPHERE || !(a[3] >= 0.15f && a[3] <= 0.45f) || !(fabsf(a[0]) <= half) ||
           !(fabsf(a[1]) <= half) || !(fabsf(a[2]) <= half);
  }
  CHECK(bad == 0, "'%s': %u spheres out of range", name, bad);
  CHECK(again->ntris == s->ntris && !memcmp(again->ana, s->ana, (size_t)ANA_FLOATS * s->ntris * sizeof(float)),
        "'%s': two loads differ", name);
  rr_scene_release(s), rr_scene_release(again);
}

/* ---- rooms and demo ------------------------------------------------------------------ */

/* Every triangle with corner normals faces the way its normals point. */
static uint32_t normals_against_winding(const rr_scene *s) {
  uint32_t bad = 0;
  for (uint32_t i = 0; s->n[0][0] && i < s->ntris; i++) {
    vec3 sum = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) sum = v3_add(sum, v3(s->n[k][0][i], s->n[k][1][i], s->n[k][2][i]));
    if (!(v3_dot(sum, face_normal(s, i)) > 0)) bad++;
  }
  return bad;
}

static void test_rooms(void) {
  rr_error e1, e2;
  rr_scene *a = load("rooms", &e1), *b = load("rooms:4", &e2);
  CHECK(a && b, "rooms: errors %d %d: %s", e1, e2, rr_device_message(dev));
  if (a && b) {
    CHECK(a->ntris > 16 * 28 && a->ntris == b->ntris, "rooms: %u and %u triangles", a->ntris, b->ntris);
    bool same = a->ntris == b->ntris;
    for (int k = 0; k < 3 && same; k++)
      for (int c = 0; c < 3; c++)
        same = same && memcmp(a->p[k][c], b->p[k][c], a->ntris * sizeof(float)) == 0;
    CHECK(same, "rooms is not deterministic");
    CHECK(a->skipped == 0, "rooms: %llu degenerate triangles", (unsigned long long)a->skipped);
  }
  rr_scene_release(a);
  rr_scene_release(b);
  rr_scene *one = load("rooms:1", &e1);
  CHECK(one && one->ntris >= 28 + 3 * 16 && one->ntris <= 28 + 3 * 24, "rooms:1: %u triangles",
        one ? one->ntris : 0);
  rr_scene_release(one);
}

static void test_demo(void) {
  rr_error e;
  rr_scene *s = load("demo", &e);
  CHECK(s != NULL, "demo: error %d: %s", e, rr_device_message(dev));
  if (!s) return;
  CHECK(s->ntris > 6320 + 5856, "demo: only %u triangles", s->ntris);
  CHECK(s->n[0][0] != NULL && s->uv[0][0] != NULL, "demo: normals or uvs missing");
  CHECK(normals_against_winding(s) == 0, "demo: %u triangles face against their normals",
        normals_against_winding(s));
  bool textured = false;
  for (uint32_t m = 0; m < s->nmaterials; m++)
    textured = textured || (s->materials[m].texture_path &&
                            strstr(s->materials[m].texture_path, "spot_texture.png"));
  CHECK(textured, "demo: Spot's texture is not named by any material");
  /* The floor (triangles 0 and 1) is not much wider than the objects on it. */
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  for (uint32_t i = 2; i < s->ntris; i++)
    for (int k = 0; k < 3; k++) lo = v3_min(lo, scene_vertex(s, k, i)), hi = v3_max(hi, scene_vertex(s, k, i));
  CHECK(lo.y >= s->bmin.y && s->bmax.x - s->bmin.x <= 3 * (hi.x - lo.x) &&
            s->bmax.z - s->bmin.z <= 3 * (hi.z - lo.z),
        "demo: floor %g x %g around objects %g x %g", s->bmax.x - s->bmin.x, s->bmax.z - s->bmin.z,
        hi.x - lo.x, hi.z - lo.z);
  rr_scene_release(s);
}

int main(void) {
  dev = rr_device_new();
  CHECK(dev != NULL, "rr_device_new");
  if (!dev) return test_done();
  test_plane("plane", 64);
  test_plane("plane:1", 1);
  test_plane("plane:5", 5);
  test_plane("plane:10", 10);
  test_sphere("sphere:32", 32);
  test_sphere("sphere:4", 4);
  test_sphere("sphere:7", 7);
  test_sphere("sphere:100", 100);
  test_box("box", 8);
  test_box("box:1", 1);
  test_box("box:3", 3);
  test_box("box:7", 7);
  test_grid(1);
  test_grid(3);
  test_spheres("spheres", 1000);
  test_spheres("spheres:5", 5);
  test_spheres("spheres:10000", 10000);
  test_names();
  test_rooms();
  test_demo();
  rr_device_release(dev);
  return test_done();
}
