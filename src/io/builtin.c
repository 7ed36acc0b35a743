/* Built-in scenes generated in code: exact test meshes (plane, sphere, box), a grid
 * of copies of a mesh file, a many-layered benchmark (rooms) and the default demo.
 * Each object is one geometry, named after what it is ("sphere", "floor"...).
 *
 * Closed meshes compute each vertex position once and index it, so a vertex shared
 * by several triangles has bitwise identical coordinates in all of them: the shared
 * sample test then leaves no cracks and counts no pixel twice along shared edges. */
#include "io/io.h"
#include "shade/texture.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- name parsing -------------------------------------------------------------- */

/* When `name` is `key` or `key:ARG`, returns ARG ("" for the bare key); else NULL. */
static const char *builtin_arg(const char *name, const char *key) {
  size_t n = strlen(key);
  if (strncmp(name, key, n) != 0) return NULL;
  if (name[n] == 0) return "";
  return name[n] == ':' ? name + n + 1 : NULL;
}

/* Parses a decimal count in [lo, hi]: digits only, no sign or spaces. */
static bool parse_count(const char *text, long lo, long hi, long *out) {
  if (!*text || strlen(text) > 9) return false;
  long v = 0;
  for (const char *c = text; *c; c++) {
    if (*c < '0' || *c > '9') return false;
    v = v * 10 + (*c - '0');
  }
  if (v < lo || v > hi) return false;
  *out = v;
  return true;
}

/* The size argument of `name` (its default when absent), or an argument error. */
static rr_error size_arg(rr_scene *s, const char *name, const char *arg, long def, long lo,
                         long hi, long *out) {
  if (!*arg && !strchr(name, ':')) {
    *out = def;
    return RR_OK;
  }
  if (parse_count(arg, lo, hi, out)) return RR_OK;
  return rr_fail(s->dev, RR_ERROR_ARGUMENT, "bad size '%s' in '%s' (expected %ld..%ld)", arg, name,
                 lo, hi);
}

/* ---- small helpers --------------------------------------------------------------- */

static rr_error add_material(rr_scene *s, float r, float g, float b, uint32_t *out) {
  float rgb[3] = {r, g, b};
  *out = rr_scene_add_material(s, rgb, NULL);
  if (*out == UINT32_MAX) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding a material");
  return RR_OK;
}

/* Opens the geometry of one object of material mat. */
static rr_error open_object(rr_scene *s, const char *name, uint32_t mat) {
  return rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, name);
}

/* Reserves room first so that rr_scene_push can only refuse degenerate triangles. */
static rr_error reserve(rr_scene *s, uint64_t more, bool with_normals) {
  if (more > UINT32_MAX - 1 - (uint64_t)s->ntris)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "scene too large: %llu more triangles",
                   (unsigned long long)more);
  return rr_scene_reserve(s, (uint32_t)more, with_normals, false);
}

/* Pushes triangle (a, b, c) of an indexed vertex array; nrm may be NULL. */
static void push_idx(rr_scene *s, const vec3 *pos, const vec3 *nrm, uint32_t a, uint32_t b,
                     uint32_t c, uint32_t mat) {
  vec3 p[3] = {pos[a], pos[b], pos[c]};
  if (nrm) {
    vec3 n[3] = {nrm[a], nrm[b], nrm[c]};
    rr_scene_push(s, p, n, NULL, mat);
  } else {
    rr_scene_push(s, p, NULL, NULL, mat);
  }
}

/* Pushes quad a-b-c-d as (a, b, c) and (a, c, d) with one flat normal (may be NULL). */
static void push_quad(rr_scene *s, vec3 a, vec3 b, vec3 c, vec3 d, const vec3 *flat,
                      uint32_t mat) {
  vec3 t0[3] = {a, b, c}, t1[3] = {a, c, d};
  vec3 n[3];
  if (flat) n[0] = n[1] = n[2] = *flat;
  rr_scene_push(s, t0, flat ? n : NULL, NULL, mat);
  rr_scene_push(s, t1, flat ? n : NULL, NULL, mat);
}

/* ---- plane ------------------------------------------------------------------------ */

/* n×n unit cells on y = 0 with integer corners, centred on the origin (for odd n the
 * extra column/row is on the + side so corners stay integers). Each cell is split
 * along its (x0,z0)-(x1,z1) diagonal; both halves are counter-clockwise from +y. */
static rr_error gen_plane(rr_scene *s, int n) {
  uint32_t mat;
  rr_error e = add_material(s, SCENE_GREY, SCENE_GREY, SCENE_GREY, &mat);
  if (!e) e = reserve(s, 2 * (uint64_t)n * n, false);
  if (!e) e = open_object(s, "plane", mat);
  if (e) return e;
  int lo = -(n / 2);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      float x0 = (float)(lo + i), x1 = (float)(lo + i + 1);
      float z0 = (float)(lo + j), z1 = (float)(lo + j + 1);
      push_quad(s, v3(x0, 0, z0), v3(x0, 0, z1), v3(x1, 0, z1), v3(x1, 0, z0), NULL, mat);
    }
  return RR_OK;
}

/* ---- UV sphere ------------------------------------------------------------------- */

/* A closed UV sphere: `seg` segments in longitude, seg/2 rings, single pole vertices.
 * Vertex 0 is the north pole, then rings 1..rings-1 of `seg` vertices each from the
 * top, then the south pole. Longitude turns counter-clockwise seen from +y, so
 * (upper j, lower j+1, upper j+1)-style triangles face outward. Corner normals are
 * the unit directions. */
static rr_error gen_sphere(rr_scene *s, int seg, vec3 centre, float radius, uint32_t mat) {
  int rings = seg / 2;
  size_t nv = 2 + (size_t)(rings - 1) * seg;
  vec3 *dir = malloc(nv * sizeof *dir), *pos = malloc(nv * sizeof *pos);
  rr_error e = dir && pos ? reserve(s, 2 * (uint64_t)seg * (rings - 1), true)
                          : rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory generating a sphere");
  if (!e) e = open_object(s, "sphere", mat);
  if (e) {
    free(dir), free(pos);
    return e;
  }
  dir[0] = v3(0, 1, 0);
  dir[nv - 1] = v3(0, -1, 0);
  for (int r = 1; r < rings; r++) {
    double th = RR_PI * r / rings;
    for (int j = 0; j < seg; j++) {
      double ph = 2 * RR_PI * j / seg;
      dir[1 + (size_t)(r - 1) * seg + j] =
          v3((float)(sin(th) * cos(ph)), (float)cos(th), (float)(-sin(th) * sin(ph)));
    }
  }
  for (size_t k = 0; k < nv; k++) pos[k] = v3_add(centre, v3_scale(dir[k], radius));

  uint32_t south = (uint32_t)(nv - 1);
  for (int j = 0; j < seg; j++) {
    uint32_t j1 = (uint32_t)((j + 1) % seg);
    push_idx(s, pos, dir, 0, 1 + j, 1 + j1, mat); /* north cap */
    for (int r = 1; r + 1 < rings; r++) {
      uint32_t up = 1 + (uint32_t)(r - 1) * seg, lo = up + seg;
      push_idx(s, pos, dir, up + j, lo + j, lo + j1, mat);
      push_idx(s, pos, dir, up + j, lo + j1, up + j1, mat);
    }
    uint32_t last = 1 + (uint32_t)(rings - 2) * seg;
    push_idx(s, pos, dir, south, last + j1, last + j, mat); /* south cap */
  }
  free(dir), free(pos);
  return RR_OK;
}

/* ---- box --------------------------------------------------------------------------- */

/* The cube [-1,1]^3, each face n×n cells. Every face takes its coordinates from one
 * table g[t] = (2t - n)/n, so vertices along the cube's edges and corners come out
 * bitwise identical on the faces that share them (g[0] = -1 and g[n] = 1 exactly). */
static rr_error gen_box(rr_scene *s, int n) {
  uint32_t mat;
  float *g = malloc(((size_t)n + 1) * sizeof *g);
  rr_error e = g ? add_material(s, SCENE_GREY, SCENE_GREY, SCENE_GREY, &mat)
                 : rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory generating a box");
  if (!e) e = reserve(s, 12 * (uint64_t)n * n, true);
  if (!e) e = open_object(s, "box", mat);
  if (e) {
    free(g);
    return e;
  }
  for (int t = 0; t <= n; t++) g[t] = (float)(2 * t - n) / (float)n;
  for (int a = 0; a < 3; a++) {
    int u = (a + 1) % 3, v = (a + 2) % 3; /* e_u × e_v = e_a */
    for (int side = -1; side <= 1; side += 2) {
      float nrm[3] = {0, 0, 0};
      nrm[a] = (float)side;
      vec3 flat = v3(nrm[0], nrm[1], nrm[2]);
      for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
          vec3 q[4]; /* (i,j), (i+1,j), (i+1,j+1), (i,j+1): counter-clockwise about +e_a */
          for (int k = 0; k < 4; k++) {
            float c[3];
            c[a] = (float)side;
            c[u] = g[i + (k == 1 || k == 2)];
            c[v] = g[j + (k >= 2)];
            q[k] = v3(c[0], c[1], c[2]);
          }
          if (side > 0) push_quad(s, q[0], q[1], q[2], q[3], &flat, mat);
          else push_quad(s, q[0], q[3], q[2], q[1], &flat, mat);
        }
    }
  }
  free(g);
  return RR_OK;
}

/* ---- torus ------------------------------------------------------------------------- */

/* A torus around the vertical axis through `centre`: major radius R, tube radius r,
 * nu segments around the axis and nv around the tube, smooth normals. */
static rr_error gen_torus(rr_scene *s, int nu, int nv, float R, float r, vec3 centre,
                          uint32_t mat) {
  size_t count = (size_t)nu * nv;
  vec3 *pos = malloc(count * sizeof *pos), *nrm = malloc(count * sizeof *nrm);
  rr_error e = pos && nrm ? reserve(s, 2 * (uint64_t)count, true)
                          : rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory generating a torus");
  if (!e) e = open_object(s, "torus", mat);
  if (e) {
    free(pos), free(nrm);
    return e;
  }
  for (int i = 0; i < nu; i++) {
    double u = 2 * RR_PI * i / nu;
    for (int j = 0; j < nv; j++) {
      double w = 2 * RR_PI * j / nv;
      double cu = cos(u), su = -sin(u), cw = cos(w), sw = sin(w);
      nrm[(size_t)i * nv + j] = v3((float)(cw * cu), (float)sw, (float)(cw * su));
      pos[(size_t)i * nv + j] =
          v3_add(centre, v3((float)((R + r * cw) * cu), (float)(r * sw), (float)((R + r * cw) * su)));
    }
  }
  for (int i = 0; i < nu; i++)
    for (int j = 0; j < nv; j++) {
      uint32_t a = (uint32_t)(i * nv + j), b = (uint32_t)(((i + 1) % nu) * nv + j);
      uint32_t c = (uint32_t)(((i + 1) % nu) * nv + (j + 1) % nv), d = (uint32_t)(i * nv + (j + 1) % nv);
      /* a→b turns about the axis, b→c climbs the tube: a-b-c-d faces outward. */
      push_idx(s, pos, nrm, a, b, c, mat);
      push_idx(s, pos, nrm, a, c, d, mat);
    }
  free(pos), free(nrm);
  return RR_OK;
}

/* ---- analytic primitives ---------------------------------------------------------- */

/* Analytic spheres (4 floats each) or planes (6) as one geometry named `name`. */
static rr_error add_analytic(rr_scene *s, prim_kind kind, const float *v, size_t n, const char *name, float r,
                             float g, float b) {
  const float rgb[3] = {r, g, b};
  rr_error e = kind == RR_GEOMETRY_SPHERE ? rr_scene_add_spheres(s, v, n, rgb) : rr_scene_add_planes(s, v, n, rgb);
  return e ? e : rr_scene_name_geometry(s, s->ngeoms - 1, name);
}

/* spheres:N — N analytic spheres of radii 0.15 .. 0.45 scattered uniformly through a
 * cube whose side grows as ∛N (about one sphere per 11 unit cubes, so a view of the
 * cloud sees a few layers deep whatever N), in eight colours, each a geometry
 * ("spheres.0" .. "spheres.7"). A fixed generator: the same scene every time. */
static rr_error gen_spheres(rr_scene *s, long n) {
  static const float colors[8][3] = {{0.85f, 0.30f, 0.24f}, {0.20f, 0.45f, 0.85f}, {0.95f, 0.70f, 0.25f},
                                     {0.30f, 0.70f, 0.35f}, {0.60f, 0.35f, 0.75f}, {0.90f, 0.90f, 0.92f},
                                     {0.25f, 0.70f, 0.75f}, {0.85f, 0.50f, 0.60f}};
  float side = 2.2f * cbrtf((float)n), *v = malloc((size_t)n * 4 * sizeof *v);
  if (!v) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for %ld spheres", n);
  uint64_t x = 0x9e3779b97f4a7c15u; /* xorshift64*: uniform in [0, 1) */
  for (long i = 0; i < 4 * n; i++) {
    x ^= x >> 12, x ^= x << 25, x ^= x >> 27;
    float u = (float)((x * 0x2545f4914f6cdd1du) >> 40) / 16777216.0f;
    v[i] = i % 4 == 3 ? 0.15f + 0.3f * u : (u - 0.5f) * side;
  }
  rr_error e = RR_OK;
  for (int g = 0; g < 8 && !e; g++) {
    long a = n * g / 8, b = n * (g + 1) / 8;
    char name[16];
    snprintf(name, sizeof name, "spheres.%d", g);
    if (b > a) e = add_analytic(s, RR_GEOMETRY_SPHERE, v + 4 * a, (size_t)(b - a), name, colors[g][0], colors[g][1], colors[g][2]);
  }
  free(v);
  return e;
}

/* ---- infinite ground (homogeneous vertices) ------------------------------------- */

/* The plane y = 0 without end: four triangles fanning from the origin to the
 * points at infinity (w = 0) in the directions +x, -z, -x, +z, counter-clockwise
 * seen from +y, so triangle q holds quadrant q: 0 (x > 0, z < 0), 1 (x < 0,
 * z < 0), 2 (x < 0, z > 0), 3 (x > 0, z > 0). On it, clear of the plane so that
 * nothing is coplanar with it: a sphere and a box (the generators' meshes, moved). */
/* `ground`: the same objects with the plane y = 0 and the sphere analytic (the box
 * stays a mesh), so its silhouettes and its contact with the plane are exact;
 * `ground:inf` is the plane as homogeneous triangles. */
static rr_error gen_box_on_ground(rr_scene *s);
static rr_error gen_ground_analytic(rr_scene *s) {
  const float plane[6] = {0, 0, 0, 0, 1, 0}, ball[4] = {-1.5f, 1.05f, 0.5f, 1.0f};
  rr_error e = add_analytic(s, RR_GEOMETRY_PLANE, plane, 1, "ground", 0.55f, 0.62f, 0.45f);
  if (!e) e = add_analytic(s, RR_GEOMETRY_SPHERE, ball, 1, "sphere", 0.20f, 0.45f, 0.85f);
  return e ? e : gen_box_on_ground(s);
}

static rr_error gen_ground(rr_scene *s) {
  uint32_t ground_m, ball_m;
  rr_error e = add_material(s, 0.55f, 0.62f, 0.45f, &ground_m);
  if (!e) e = add_material(s, 0.20f, 0.45f, 0.85f, &ball_m);
  if (!e) e = reserve(s, 4, false);
  if (!e) e = open_object(s, "ground", ground_m);
  if (!e) e = rr_scene_reserve_inf(s);
  if (e) return e;
  const vec3 origin = v3(0, 0, 0), dir[4] = {v3(1, 0, 0), v3(0, 0, -1), v3(-1, 0, 0), v3(0, 0, 1)};
  for (int q = 0; q < 4; q++) {
    vec3 p[3] = {origin, dir[q], dir[(q + 1) % 4]};
    rr_scene_push_inf(s, p, 6u, NULL, NULL, NULL, ground_m); /* corners 1 and 2 at infinity */
  }
  e = gen_sphere(s, 24, v3(-1.5f, 1.05f, 0.5f), 1.0f, ball_m);
  return e ? e : gen_box_on_ground(s);
}

static rr_error gen_box_on_ground(rr_scene *s) {
  uint32_t t0 = scene_stored(s); /* (stored indices: after any instances) */
  rr_error e = gen_box(s, 1);
  if (e) return e;
  /* the unit box [-1,1]^3 to half size, standing 0.05 above the plane at (1.5, -0.5):
   * the same map for every corner keeps shared corners identical */
  for (uint32_t i = t0; i < scene_stored(s); i++)
    for (int k = 0; k < 3; k++) {
      s->p[k][0][i] = s->p[k][0][i] * 0.5f + 1.5f;
      s->p[k][1][i] = s->p[k][1][i] * 0.5f + 0.55f;
      s->p[k][2][i] = s->p[k][2][i] * 0.5f - 0.5f;
    }
  float *box_rgb = s->materials[s->nmaterials - 1].color;
  box_rgb[0] = 0.90f, box_rgb[1] = 0.55f, box_rgb[2] = 0.20f;
  rr_scene_update_bounds(s);
  return RR_OK;
}

/* ---- checkerboard to the horizon (textured, homogeneous vertices) ------------- */

/* The checker texture: CHECKER_SIZE² texels in checks of CHECKER_CELL texels, light
 * and dark sRGB bytes; repeated every CHECKER_REPEAT units on the ground. */
enum { CHECKER_SIZE = 512, CHECKER_CELL = 16 };
#define CHECKER_REPEAT 8.0f

/* The plane y = 0 as in `ground` with u = x/8, v = -z/8 (its corners at infinity
 * carry those rates) and a black-and-white checkerboard texture of 32×32 checks a
 * repeat: a check is a quarter unit, so that a grazing view minifies it thousands
 * of times towards the horizon. Its own view looks along -z from 1 unit above the
 * plane, 9.5° down: the horizon a third of the way down the image. */
static rr_error gen_checker(rr_scene *s) {
  float white[3] = {1, 1, 1};
  uint32_t mat = rr_scene_add_material(s, white, "checker");
  if (mat == UINT32_MAX) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding a material");
  rr_texture *t = &s->materials[mat].texture;
  t->rgb = malloc((size_t)3 * CHECKER_SIZE * CHECKER_SIZE);
  if (!t->rgb) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the checker texture");
  t->width = t->height = CHECKER_SIZE;
  for (int y = 0; y < CHECKER_SIZE; y++)
    for (int x = 0; x < CHECKER_SIZE; x++)
      memset(t->rgb + 3 * ((size_t)y * CHECKER_SIZE + x), ((x / CHECKER_CELL) ^ (y / CHECKER_CELL)) & 1 ? 20 : 235, 3);
  if (!rr_texture_prepare(t)) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the checker texture");
  s->materials[mat].texture_status = RR_TEXTURE_EMBEDDED;
  rr_error e = rr_scene_reserve(s, 4, false, true);
  if (!e) e = open_object(s, "checker", mat);
  if (!e) e = rr_scene_reserve_inf(s);
  if (e) return e;
  const vec3 origin = v3(0, 0, 0), dir[4] = {v3(1, 0, 0), v3(0, 0, -1), v3(-1, 0, 0), v3(0, 0, 1)};
  for (int q = 0; q < 4; q++) {
    vec3 p[3] = {origin, dir[q], dir[(q + 1) % 4]};
    float uv[3][2] = {{0, 0}};
    for (int k = 1; k < 3; k++) uv[k][0] = p[k].x / CHECKER_REPEAT, uv[k][1] = -p[k].z / CHECKER_REPEAT;
    rr_scene_push_inf(s, p, 6u, NULL, (const float(*)[2])uv, NULL, mat);
  }
  s->has_view = true, s->view_eye = v3(0, 1, 0), s->view_target = v3(0, 0, -6);
  rr_scene_update_bounds(s);
  return RR_OK;
}

/* ---- grid of copies ----------------------------------------------------------------- */

/* grid:PATH:N — N×N instances of a mesh file on the XZ plane (scene/instance.h),
 * instance k = j·N + i moved by (i·1.25·sx, 0, j·1.25·sz): the mesh is stored once.
 * Instance k's triangle m has index k·T + m and id k·F + (the file's id of m), F the
 * file's faces, dropped ones included (ids as if the file were loaded N² times), and
 * its own geometries, like the file's, named as in the file.
 *
 * grid-flat:PATH:N — the same scene with the copies written out (N²·T triangles
 * stored), every corner moved by inst_point as the instances' are: the reference the
 * instanced grid renders bit for bit like. The copies go straight into the arrays
 * rather than through rr_scene_push, which could drop a translated sliver. */
static rr_error load_grid(rr_scene *s, const char *name, bool flat) {
  const char *rest = name + strlen(flat ? "grid-flat:" : "grid:");
  const char *colon = strrchr(rest, ':'); /* PATH may itself contain ':' */
  if (!colon || colon == rest)
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "bad grid name '%s' (expected grid:PATH:N)", name);
  long n;
  if (!parse_count(colon + 1, 1, 1000, &n))
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "bad grid count '%s' in '%s' (expected 1..1000)",
                   colon + 1, name);
  if (s->inst) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "grid '%s': the scene holds instances already", name);
  size_t len = (size_t)(colon - rest);
  char *path = malloc(len + 1);
  if (!path) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory reading '%s'", name);
  memcpy(path, rest, len);
  path[len] = 0;
  uint32_t t0 = s->ntris, g0 = s->ngeoms;
  uint64_t skipped0 = s->skipped, f0 = scene_faces(s);
  rr_error e = rr_scene_import_guarded(s, path);
  free(path);
  if (e) return e;

  uint32_t T = s->ntris - t0;
  uint64_t F = scene_faces(s) - f0, copies = (uint64_t)n * (uint64_t)n, total = copies * T;
  if (T == 0 || n == 1) return RR_OK;
  if (copies * F > UINT32_MAX - 1 - f0) /* ids, dropped faces' too, stay below RR_MISS */
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "grid '%s' would hold %llu triangles (at most %llu)", name,
                   (unsigned long long)(copies * F), (unsigned long long)(UINT32_MAX - 1 - f0));

  float xlo = INFINITY, xhi = -INFINITY, zlo = INFINITY, zhi = -INFINITY;
  for (int k = 0; k < 3; k++)
    for (uint32_t m = t0; m < s->ntris; m++) {
      xlo = fminf(xlo, s->p[k][0][m]), xhi = fmaxf(xhi, s->p[k][0][m]);
      zlo = fminf(zlo, s->p[k][2][m]), zhi = fmaxf(zhi, s->p[k][2][m]);
    }
  float sx = xhi - xlo, sz = zhi - zlo;
  if (!isfinite((float)(n - 1) * 1.25f * sx) || !isfinite((float)(n - 1) * 1.25f * sz))
    return rr_fail(s->dev, RR_ERROR_ARGUMENT, "grid '%s': the mesh is too large to replicate", name);
  float (*xf)[12] = malloc(copies * sizeof *xf);
  if (!xf) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory for the grid's %llu instances", (unsigned long long)copies);
  for (uint64_t copy = 0; copy < copies; copy++) {
    float ox = (float)(copy % n) * 1.25f * sx, oz = (float)(copy / n) * 1.25f * sz;
    const float m[12] = {1, 0, 0, ox, 0, 1, 0, 0, 0, 0, 1, oz};
    memcpy(xf[copy], m, sizeof m);
  }
  if (!flat) {
    e = rr_scene_instance(s, t0, F, g0, (uint32_t)copies, (const float (*)[12])xf);
    free(xf);
    return e;
  }

  s->skipped += (s->skipped - skipped0) * (copies - 1); /* as loading the file N² times would */
  e = rr_scene_reserve(s, (uint32_t)(total - T), false, false);
  if (!e && F != T) e = rr_scene_reserve_ids(s); /* copies' ids differ from their indices */
  uint32_t g1 = s->ngeoms;
  for (uint64_t copy = 1; copy < copies && !e; copy++)
    for (uint32_t g = g0; g < g1 && !e; g++)
      e = rr_scene_repeat_geometry(s, g, s->geoms[g].first + (uint32_t)(copy * T),
                                   s->geoms[g].face + (uint32_t)(copy * F));
  /* backwards, so that copy 0 (written over the file's corners) comes last */
  for (uint64_t copy = copies; !e && copy-- > 0;) {
    size_t dst = t0 + copy * T;
    for (int k = 0; k < 3; k++) {
      for (uint32_t m = 0; m < T; m++) {
        vec3 p = inst_point(xf[copy], true, v3(s->p[k][0][t0 + m], s->p[k][1][t0 + m], s->p[k][2][t0 + m]));
        s->p[k][0][dst + m] = p.x, s->p[k][1][dst + m] = p.y, s->p[k][2][dst + m] = p.z;
      }
      for (int c = 0; c < 3 && copy; c++)
        if (s->n[k][c]) memcpy(s->n[k][c] + dst, s->n[k][c] + t0, T * sizeof(float));
      for (int c = 0; c < 2 && copy; c++)
        if (s->uv[k][c]) memcpy(s->uv[k][c] + dst, s->uv[k][c] + t0, T * sizeof(float));
      for (int c = 0; c < 3 && copy; c++)
        if (s->col[k][c]) memcpy(s->col[k][c] + dst, s->col[k][c] + t0, T * sizeof(float));
    }
    if (!copy) continue;
    if (s->inf) memcpy(s->inf + dst, s->inf + t0, T);
    memcpy(s->material + dst, s->material + t0, T * sizeof(uint32_t));
    for (uint32_t m = 0; s->file_id && m < T; m++) s->file_id[dst + m] = s->file_id[t0 + m] + (uint32_t)(copy * F);
  }
  free(xf);
  if (e) return e;
  s->ntris = (uint32_t)(t0 + total);
  rr_scene_update_bounds(s);
  return RR_OK;
}

/* ---- rooms -------------------------------------------------------------------------- */

/* A small deterministic generator (LCG) so the benchmark scene never changes. */
static float rng_next(uint32_t *state) {
  *state = *state * 1664525u + 1013904223u;
  return (float)(*state >> 8) / 16777216.0f;
}

enum { ROOM_SIZE = 8 };
static const float ROOM_H = 3.0f, ROOM_INSET = 0.1f, DOOR_W = 1.2f, DOOR_H = 2.2f;

/* A vertical wall from floor point a to b (y = 0..ROOM_H) with a door in its middle;
 * its front faces (b - a) × y, the room's inside when walls go round counter-clockwise
 * seen from +y. */
static void push_wall(rr_scene *s, vec3 a, vec3 b, uint32_t mat) {
  vec3 d = v3_sub(b, a);
  float len = v3_len(d);
  vec3 u = v3_scale(d, 1.0f / len), up = v3(0, ROOM_H, 0), door = v3(0, DOOR_H, 0);
  vec3 l = v3_add(a, v3_scale(u, 0.5f * (len - DOOR_W))); /* door jambs */
  vec3 r = v3_add(a, v3_scale(u, 0.5f * (len + DOOR_W)));
  push_quad(s, a, l, v3_add(l, up), v3_add(a, up), NULL, mat);
  push_quad(s, r, b, v3_add(b, up), v3_add(r, up), NULL, mat);
  push_quad(s, v3_add(l, door), v3_add(r, door), v3_add(r, up), v3_add(l, up), NULL, mat);
}

/* A prism column of `sides` sides standing from the floor to the ceiling, a geometry
 * of its own. It has no caps: they would lie in the floor and ceiling planes and
 * fight with them. */
static rr_error push_column(rr_scene *s, float cx, float cz, float radius, int sides, uint32_t mat) {
  rr_error e = open_object(s, "column", mat);
  if (e) return e;
  vec3 bot[12], top[12];
  for (int k = 0; k < sides; k++) {
    double ph = 2 * RR_PI * k / sides; /* counter-clockwise seen from +y */
    bot[k] = v3(cx + radius * (float)cos(ph), 0, cz - radius * (float)sin(ph));
    top[k] = v3(bot[k].x, ROOM_H, bot[k].z);
  }
  for (int k = 0; k < sides; k++) {
    int k1 = (k + 1) % sides;
    push_quad(s, bot[k], bot[k1], top[k1], top[k], NULL, mat); /* faces outward */
  }
  return RR_OK;
}

/* rooms:N — N×N rooms of ROOM_SIZE units, each with floor, ceiling, four walls with a
 * door in the middle of each (so the rooms open into each other), and three prism
 * columns: six geometries a room. Walls of neighbouring rooms stand a little apart,
 * so a view across the array crosses many large overlapping layers. */
static rr_error gen_rooms(rr_scene *s, int n) {
  uint32_t floor_m, wall_m, ceil_m, col_m[3];
  rr_error e = add_material(s, 0.55f, 0.45f, 0.35f, &floor_m);
  if (!e) e = add_material(s, 0.85f, 0.82f, 0.75f, &wall_m);
  if (!e) e = add_material(s, 0.95f, 0.95f, 0.95f, &ceil_m);
  if (!e) e = add_material(s, 0.75f, 0.30f, 0.25f, &col_m[0]);
  if (!e) e = add_material(s, 0.25f, 0.45f, 0.75f, &col_m[1]);
  if (!e) e = add_material(s, 0.30f, 0.65f, 0.35f, &col_m[2]);
  /* per room: 4 floor/ceiling + 24 wall + 3 columns of at most 2·12 */
  if (!e) e = reserve(s, (uint64_t)n * n * (4 + 24 + 3 * 24), false);
  if (e) return e;
  uint32_t rng = 12345u;
  for (int rj = 0; rj < n; rj++)
    for (int ri = 0; ri < n; ri++) {
      float x0 = (float)(ri * ROOM_SIZE) + ROOM_INSET, x1 = (float)((ri + 1) * ROOM_SIZE) - ROOM_INSET;
      float z0 = (float)(rj * ROOM_SIZE) + ROOM_INSET, z1 = (float)((rj + 1) * ROOM_SIZE) - ROOM_INSET;
      vec3 c00 = v3(x0, 0, z0), c10 = v3(x1, 0, z0), c11 = v3(x1, 0, z1), c01 = v3(x0, 0, z1);
      vec3 up = v3(0, ROOM_H, 0);
      if ((e = open_object(s, "floor", floor_m))) return e;
      push_quad(s, c00, c01, c11, c10, NULL, floor_m); /* faces +y */
      if ((e = open_object(s, "ceiling", ceil_m))) return e;
      push_quad(s, v3_add(c00, up), v3_add(c10, up), v3_add(c11, up), v3_add(c01, up), NULL,
                ceil_m); /* faces -y */
      if ((e = open_object(s, "walls", wall_m))) return e;
      push_wall(s, c00, c10, wall_m);
      push_wall(s, c10, c11, wall_m);
      push_wall(s, c11, c01, wall_m);
      push_wall(s, c01, c00, wall_m);
      /* Columns near three of the four quadrant centres, clear of the door paths. */
      int skip = (int)(rng_next(&rng) * 4.0f);
      for (int q = 0; q < 4; q++) {
        if (q == skip) continue;
        float cx = 0.5f * (x0 + x1) + ((q & 1) ? 2.0f : -2.0f) + rng_next(&rng) - 0.5f;
        float cz = 0.5f * (z0 + z1) + ((q & 2) ? 2.0f : -2.0f) + rng_next(&rng) - 0.5f;
        float radius = 0.3f + 0.3f * rng_next(&rng);
        int sides = 8 + (int)(rng_next(&rng) * 5.0f); /* 8..12 */
        e = push_column(s, cx, cz, radius, sides, col_m[(q + ri + rj) % 3]);
        if (e) return e;
      }
    }
  return RR_OK;
}

/* ---- demo ----------------------------------------------------------------------------- */

typedef struct corner_key {
  float x, y, z;
  uint32_t tri, k;
} corner_key;

static int corner_cmp(const void *pa, const void *pb) {
  const corner_key *a = pa, *b = pb;
  if (a->x != b->x) return a->x < b->x ? -1 : 1;
  if (a->y != b->y) return a->y < b->y ? -1 : 1;
  if (a->z != b->z) return a->z < b->z ? -1 : 1;
  return 0;
}

rr_error rr_scene_smooth_normals(rr_scene *s, uint32_t t0, uint32_t t1) {
  /* on the stored triangles (an instanced mesh's once, in its own space) */
  if (t1 > t0) t0 = scene_st(s, t0), t1 = scene_st(s, t1 - 1) + 1;
  size_t nt = t1 - t0, nc = 3 * nt;
  rr_error e = rr_scene_reserve(s, 0, true, false);
  if (e) return e;
  corner_key *c = malloc(nc * sizeof *c);
  vec3 *fn = malloc(nt * sizeof *fn);
  if (!c || !fn) {
    free(c), free(fn);
    return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory smoothing normals");
  }
  for (size_t t = 0; t < nt; t++) {
    uint32_t i = t0 + (uint32_t)t;
    vec3 p0 = scene_stored_vertex(s, 0, i), p1 = scene_stored_vertex(s, 1, i), p2 = scene_stored_vertex(s, 2, i);
    fn[t] = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
    for (uint32_t k = 0; k < 3; k++) {
      vec3 p = scene_stored_vertex(s, (int)k, i);
      c[3 * t + k] = (corner_key){p.x, p.y, p.z, (uint32_t)t, k};
    }
  }
  qsort(c, nc, sizeof *c, corner_cmp);
  const float crease = 0.5f; /* cos 60° */
  for (size_t g0 = 0, g1; g0 < nc; g0 = g1) {
    for (g1 = g0 + 1; g1 < nc && corner_cmp(&c[g0], &c[g1]) == 0; g1++) {
    }
    for (size_t a = g0; a < g1; a++) {
      vec3 own = v3_norm(fn[c[a].tri]), sum = v3(0, 0, 0);
      for (size_t b = g0; b < g1; b++)
        if (v3_dot(own, v3_norm(fn[c[b].tri])) >= crease) sum = v3_add(sum, fn[c[b].tri]);
      vec3 nrm = v3_len(sum) > 0 ? v3_norm(sum) : own;
      uint32_t i = t0 + c[a].tri, k = c[a].k;
      s->n[k][0][i] = nrm.x, s->n[k][1][i] = nrm.y, s->n[k][2][i] = nrm.z;
    }
  }
  free(c), free(fn);
  return RR_OK;
}

enum { DATA_PATH_MAX = 4096 };

/* Finds one of the demo's data files in the first directory holding it: the
 * environment's RASTRAY_DATA, then the installed share/rastray, then the source
 * tree's data/ (a build that was never installed). */
static rr_error find_data_file(rr_device *dev, const char *file, char path[static DATA_PATH_MAX]) {
  const char *dirs[] = {getenv("RASTRAY_DATA"), RR_DATA_INSTALL_DIR, RR_DATA_DIR};
  for (size_t i = 0; i < sizeof dirs / sizeof *dirs; i++) {
    if (!dirs[i] || !*dirs[i]) continue;
    int n = snprintf(path, DATA_PATH_MAX, "%s/%s", dirs[i], file);
    FILE *f = n > 0 && n < DATA_PATH_MAX ? fopen(path, "rb") : NULL;
    if (f) {
      fclose(f);
      return RR_OK;
    }
  }
  return rr_fail(dev, RR_ERROR_IO, "demo file '%s' is in none of $RASTRAY_DATA, %s, %s", file,
                 RR_DATA_INSTALL_DIR, RR_DATA_DIR);
}

/* Loads a data file's mesh into s, names its geometries `name`, gives it smooth
 * normals, scales it uniformly by `size` divided by its largest extent, turns it by
 * `yaw` degrees about +y and stands the bottom centre of its bounds at (x, 0, z).
 * Returns the first material it added. */
static rr_error place_file(rr_scene *s, const char *file, const char *name, float size, float yaw, float x,
                           float z, uint32_t *first_mat) {
  uint32_t t0 = s->ntris, g0 = s->ngeoms;
  *first_mat = s->nmaterials;
  char path[DATA_PATH_MAX];
  rr_error e = find_data_file(s->dev, file, path);
  if (!e) e = rr_scene_import_guarded(s, path);
  if (!e && s->ntris == t0) e = rr_fail(s->dev, RR_ERROR_EMPTY, "demo mesh '%s' has no triangles", path);
  for (uint32_t g = g0; !e && g < s->ngeoms; g++) e = rr_scene_name_geometry(s, g, name);
  if (!e) e = rr_scene_smooth_normals(s, t0, s->ntris);
  if (e) return e;
  float cy = cosf(yaw * (float)(RR_PI / 180)), sy = sinf(yaw * (float)(RR_PI / 180));
  vec3 lo = v3(INFINITY, INFINITY, INFINITY), hi = v3(-INFINITY, -INFINITY, -INFINITY);
  uint32_t j0 = scene_stored(s) - (s->ntris - t0); /* stored indices: after any instances */
  for (uint32_t i = j0; i < scene_stored(s); i++)
    for (int k = 0; k < 3; k++) {
      vec3 p = scene_stored_vertex(s, k, i);
      lo = v3_min(lo, p), hi = v3_max(hi, p);
    }
  vec3 ext = v3_sub(hi, lo);
  float scale = size / fmaxf(ext.x, fmaxf(ext.y, ext.z));
  vec3 mid = v3(0.5f * (lo.x + hi.x), lo.y, 0.5f * (lo.z + hi.z));
  for (uint32_t i = j0; i < scene_stored(s); i++)
    for (int k = 0; k < 3; k++) {
      vec3 p = v3_scale(v3_sub(scene_stored_vertex(s, k, i), mid), scale);
      s->p[k][0][i] = cy * p.x + sy * p.z + x;
      s->p[k][1][i] = p.y;
      s->p[k][2][i] = -sy * p.x + cy * p.z + z;
      float nx = s->n[k][0][i], nz = s->n[k][2][i];
      s->n[k][0][i] = cy * nx + sy * nz;
      s->n[k][2][i] = -sy * nx + cy * nz;
    }
  return RR_OK;
}

/* The default scene: teapot, Spot the cow, two spheres and a torus on a floor. The
 * floor stays within about twice the group's size because auto-framing fits the
 * whole bounding box. */
static rr_error gen_demo(rr_scene *s) {
  uint32_t floor_m, blue_m, gold_m, green_m, teapot_m, spot_m;
  rr_error e = add_material(s, 0.82f, 0.82f, 0.80f, &floor_m);
  if (!e) e = add_material(s, 0.20f, 0.45f, 0.85f, &blue_m);
  if (!e) e = add_material(s, 0.95f, 0.70f, 0.18f, &gold_m);
  if (!e) e = add_material(s, 0.30f, 0.72f, 0.42f, &green_m);
  if (!e) e = reserve(s, 2, true);
  if (!e) e = open_object(s, "floor", floor_m);
  if (e) return e;
  vec3 up = v3(0, 1, 0);
  const float fy = -0.01f; /* just below the objects resting on y = 0 */
  push_quad(s, v3(-5.0f, fy, -3.0f), v3(-5.0f, fy, 3.0f), v3(5.0f, fy, 3.0f), v3(5.0f, fy, -3.0f),
            &up, floor_m);

  e = place_file(s, "teapot.obj", "teapot", 3.2f, -20.0f, -0.6f, -0.3f, &teapot_m);
  if (e) return e;
  for (uint32_t m = teapot_m; m < s->nmaterials; m++) { /* the file has no colour of its own */
    s->materials[m].color[0] = 0.86f, s->materials[m].color[1] = 0.30f, s->materials[m].color[2] = 0.24f;
  }
  e = place_file(s, "spot.obj", "spot", 1.9f, 145.0f, 2.6f, 0.3f, &spot_m);
  if (!e) e = gen_sphere(s, 48, v3(-3.3f, 0.6f, 0.9f), 0.6f, blue_m);
  if (!e) e = gen_sphere(s, 32, v3(0.9f, 0.35f, 1.6f), 0.35f, gold_m);
  if (!e) e = gen_torus(s, 48, 24, 0.5f, 0.17f, v3(-1.6f, 0.17f, 1.7f), green_m);
  if (e) return e;
  rr_scene_update_bounds(s);
  return RR_OK;
}

/* ---- entry point ------------------------------------------------------------------- */

rr_error rr_scene_load_builtin(rr_scene *s, const char *name) {
  const char *arg;
  long n;
  rr_error e;
  if (strcmp(name, "demo") == 0) {
    e = gen_demo(s);
  } else if ((arg = builtin_arg(name, "plane"))) {
    e = size_arg(s, name, arg, 64, 1, 4096, &n);
    if (!e) e = gen_plane(s, (int)n);
  } else if (strcmp(name, "sphere") == 0) { /* the analytic unit sphere; sphere:N is a mesh */
    const float unit[4] = {0, 0, 0, 1};
    e = add_analytic(s, RR_GEOMETRY_SPHERE, unit, 1, "sphere", SCENE_GREY, SCENE_GREY, SCENE_GREY);
  } else if ((arg = builtin_arg(name, "spheres"))) {
    e = size_arg(s, name, arg, 1000, 1, 1000000, &n);
    if (!e) e = gen_spheres(s, n);
  } else if ((arg = builtin_arg(name, "sphere"))) {
    uint32_t mat;
    e = size_arg(s, name, arg, 32, 4, 4096, &n);
    if (!e) e = add_material(s, SCENE_GREY, SCENE_GREY, SCENE_GREY, &mat);
    if (!e) e = gen_sphere(s, (int)n, v3(0, 0, 0), 1.0f, mat);
  } else if ((arg = builtin_arg(name, "box"))) {
    e = size_arg(s, name, arg, 8, 1, 1024, &n);
    if (!e) e = gen_box(s, (int)n);
  } else if ((arg = builtin_arg(name, "torus"))) {
    uint32_t mat; /* a ring of radius 1 around +y, tube radius 0.35: curved and closed, for shading */
    e = size_arg(s, name, arg, 48, 4, 4096, &n);
    if (!e) e = add_material(s, SCENE_GREY, SCENE_GREY, SCENE_GREY, &mat);
    if (!e) e = gen_torus(s, (int)n, (int)(n + 1) / 2, 1.0f, 0.35f, v3(0, 0, 0), mat);
  } else if ((arg = builtin_arg(name, "rooms"))) {
    e = size_arg(s, name, arg, 4, 1, 100, &n);
    if (!e) e = gen_rooms(s, (int)n);
  } else if (strcmp(name, "ground") == 0) {
    e = gen_ground_analytic(s);
  } else if (strcmp(name, "ground:inf") == 0) {
    e = gen_ground(s);
  } else if (strcmp(name, "checker") == 0) {
    e = gen_checker(s);
  } else if (strncmp(name, "grid:", 5) == 0) {
    e = load_grid(s, name, false);
  } else if (strncmp(name, "grid-flat:", 10) == 0) {
    e = load_grid(s, name, true);
  } else {
    return RR_ERROR_UNSUPPORTED; /* not a built-in name: the caller reads it as a file */
  }
  return e ? e : rr_ok(s->dev);
}
