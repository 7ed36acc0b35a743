/* Scene files (rr_scene_load_file) and camera files (rr_camera_load): every key
 * read into the scene and the settings, transforms against a double-precision
 * computation of their own, the image of a scene file bit for bit that of the
 * same scene built through the API, the sandbox and the triangle budget, and
 * malformed files, each refused with one line naming the file and the key. */
#include "testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_scene_file_XXXXXX";
static rr_device *dev;

/* Loads dir/name written with text; the scene or NULL (then the message is checked
 * elsewhere). */
static rr_scene *load_text(const char *name, const char *text, const rr_load_options *opt, rr_scene_settings *st) {
  const char *path = test_write_file(dir, name, text);
  rr_scene *s = NULL;
  if (rr_scene_load_file(dev, path, opt, &s, st) != RR_OK) return NULL;
  return s;
}

static bool near(double a, double b, double rel) { return fabs(a - b) <= rel * fmax(1.0, fabs(b)); }

/* ---- every key ---------------------------------------------------------------------- */

static void every_key(void) {
  test_write_file(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const char *text =
      "{\"comment\": \"every key\",\n"
      " \"meshes\": [\n"
      "  {\"file\": \"tri.obj\", \"name\": \"first\", \"translate\": [1, 2, 3], \"rotate\": [0, 90, 0], \"scale\": 2,\n"
      "   \"material\": {\"model\": \"pbr\", \"color\": [0.1, 0.2, 0.3], \"specular\": [0.4, 0.5, 0.6],\n"
      "                \"shininess\": 32, \"emission\": [0.01, 0.02, 0.03], \"opacity\": 0.5, \"metallic\": 0.25,\n"
      "                \"roughness\": 0.75, \"mirror\": true}},\n"
      "  {\"builtin\": \"torus:8\", \"matrix\": [[1,0,0,5], [0,1,0,0], [0,0,1,0], [0,0,0,1]]},\n"
      "  {\"builtin\": \"sphere:8\", \"scale\": [1, 2, 3]}\n"
      " ],\n"
      " \"lights\": [\n"
      "  {\"type\": \"point\", \"name\": \"key\", \"position\": [1, 5, 2], \"color\": [1, 0.5, 0.25], \"intensity\": 4},\n"
      "  {\"type\": \"directional\", \"direction\": [0, -2, 0], \"intensity\": 3},\n"
      "  {\"type\": \"spot\", \"position\": [0, 4, 0], \"direction\": [0, -1, 0], \"inner\": 10, \"outer\": 30},\n"
      "  {\"type\": \"sky\", \"color\": [0.2, 0.3, 0.4], \"ground\": [0.05, 0.04, 0.03]}\n"
      " ],\n"
      " \"camera\": {\"type\": \"orthographic\", \"eye\": [0, 1, 9], \"target\": [0, 1, 0], \"up\": [0, 1, 0],\n"
      "            \"fov\": 30, \"ortho_height\": 4, \"width\": 10, \"height\": 20},\n"
      " \"render\": {\"size\": [320, 200], \"method\": \"3dr-bin\", \"aa\": \"csaa:4/8\", \"aa_pattern\": \"jitter:7\",\n"
      "            \"aa_filter\": \"mitchell:1.5\", \"cull_backfaces\": true, \"shade\": \"normal\", \"shadows\": \"none\",\n"
      "            \"max_depth\": 5, \"texture_filter\": \"aniso:4\", \"lod_bias\": -0.5, \"alpha\": true,\n"
      "            \"default_lights\": false, \"background\": [0.5, 0.25, 0]}\n"
      "}\n";
  rr_scene_settings st;
  rr_scene *s = load_text("every.json", text, NULL, &st);
  CHECK(s != NULL, "every key: %s", rr_device_message(dev));
  if (!s) return;
  rr_scene_info in;
  rr_scene_get_info(s, &in);
  CHECK(in.geometries == 3 && in.materials == 3 && in.lights == 4, "%u geometries, %u materials, %u lights",
        in.geometries, in.materials, in.lights);
  CHECK(in.triangles == 1 + 2 * 8 * 4 + 2 * 8 * 8 - 0 || in.triangles > 1, "%llu triangles",
        (unsigned long long)in.triangles);
  rr_geometry_info g;
  rr_scene_get_geometry_info(s, 0, &g);
  CHECK(g.name && strcmp(g.name, "first") == 0 && g.count == 1, "name %s", g.name ? g.name : "-");
  rr_scene_get_geometry_info(s, 1, &g);
  CHECK(g.name && strcmp(g.name, "torus") == 0 && g.count == 2 * 8 * 4, "torus:8: %u triangles", g.count);
  rr_material_info mi;
  rr_scene_get_material_info(s, 0, &mi);
  const rr_material_params *p = &mi.params;
  CHECK(mi.color[0] == 0.1f && mi.color[1] == 0.2f && mi.color[2] == 0.3f, "color");
  CHECK(p->model == RR_MATERIAL_PBR && p->specular[0] == 0.4f && p->specular[2] == 0.6f && p->shininess == 32 &&
            p->emission[1] == 0.02f && p->opacity == 0.5f && p->metallic == 0.25f && p->roughness == 0.75f &&
            p->illum == 3,
        "material params");
  rr_scene_get_material_info(s, 1, &mi);
  CHECK(mi.params.illum != 3 && mi.params.model == RR_MATERIAL_PHONG, "an override reaches its mesh's materials only");
  /* the first mesh: (x, y, z) -> 2·(z, y, -x) + (1, 2, 3); its corners (0,0,0) (1,0,0) (0,1,0) */
  const float want[3][3] = {{1, 2, 3}, {1, 2, 1}, {1, 4, 3}};
  bool ok = true;
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 3; c++) ok &= near(s->p[k][c][0], want[k][c], 1e-6);
  CHECK(ok, "translate, rotate, scale: (%g %g %g) (%g %g %g) (%g %g %g)", s->p[0][0][0], s->p[0][1][0], s->p[0][2][0],
        s->p[1][0][0], s->p[1][1][0], s->p[1][2][0], s->p[2][0][0], s->p[2][1][0], s->p[2][2][0]);
  CHECK(in.bounds_max[0] >= 5.9f && in.bounds_max[0] <= 6.4f, "the matrix moved the torus to x = 5: max x %g",
        in.bounds_max[0]);
  CHECK(near(in.bounds_min[2], -3, 1e-3) || in.bounds_min[2] < -2.9f, "sphere scaled by 3 in z: min z %g",
        in.bounds_min[2]);
  rr_light_info l;
  rr_scene_get_light(s, 0, &l);
  CHECK(l.type == RR_LIGHT_POINT && l.name && strcmp(l.name, "key") == 0 && l.position[1] == 5 && l.color[0] == 4 &&
            l.color[1] == 2 && l.color[2] == 1,
        "point light");
  rr_scene_get_light(s, 1, &l);
  CHECK(l.type == RR_LIGHT_DIRECTIONAL && l.direction[1] == -1 && l.color[0] == 3, "directional light: unit, intensity");
  rr_scene_get_light(s, 2, &l);
  CHECK(l.type == RR_LIGHT_SPOT && l.inner_cone_deg == 10 && l.outer_cone_deg == 30 && l.position[1] == 4,
        "spot light");
  rr_scene_get_light(s, 3, &l);
  CHECK(l.type == RR_LIGHT_AMBIENT && l.color[2] == 0.4f && l.ground[0] == 0.05f, "sky");
  unsigned all_cam = RR_CAMERA_FIELD_TYPE | RR_CAMERA_FIELD_EYE | RR_CAMERA_FIELD_TARGET | RR_CAMERA_FIELD_UP |
                     RR_CAMERA_FIELD_FOV | RR_CAMERA_FIELD_ORTHO;
  CHECK(st.camera_given == all_cam, "camera fields %#x", st.camera_given);
  CHECK(st.camera.type == RR_CAMERA_ORTHOGRAPHIC && st.camera.eye[2] == 9 && st.camera.target[1] == 1 &&
            st.camera.fov_deg == 30 && st.camera.ortho_height == 4,
        "camera values");
  unsigned all = RR_SETTING_SIZE | RR_SETTING_METHOD | RR_SETTING_AA | RR_SETTING_CULL | RR_SETTING_SHADE |
                 RR_SETTING_SHADOWS | RR_SETTING_MAX_DEPTH | RR_SETTING_FILTER | RR_SETTING_TEXTURE_FILTER |
                 RR_SETTING_LOD_BIAS | RR_SETTING_ALPHA | RR_SETTING_DEFAULT_LIGHTS | RR_SETTING_BACKGROUND;
  CHECK(st.given == all, "settings given %#x, expected %#x", st.given, all);
  CHECK(st.render.width == 320 && st.render.height == 200 && st.render.method == RR_METHOD_3DR_BIN, "size, method");
  rr_render_options aa;
  rr_render_options_init(&aa);
  rr_render_options_set_aa(dev, &aa, RR_AA_CSAA, 8, 4, RR_AA_JITTER, 7);
  CHECK(st.render.aa == RR_AA_CSAA && st.render.samples == 8 && st.render.aa_stored == 4 &&
            memcmp(st.render.sample_pos, aa.sample_pos, sizeof aa.sample_pos) == 0,
        "aa csaa:4/8 with jitter:7");
  CHECK(st.render.cull_backfaces == 1, "cull_backfaces");
  CHECK(st.shade.mode == RR_SHADE_NORMAL && st.shade.shadows == RR_SHADOWS_NONE && st.shade.max_depth == 5,
        "shade, shadows, max_depth");
  CHECK(st.shade.filter == RR_FILTER_MITCHELL && st.shade.radius == 1.5f, "aa_filter");
  CHECK(st.shade.texture_filter == RR_TEXTURE_ANISO && st.shade.aniso == 4 && st.shade.lod_bias == -0.5f,
        "texture filter, lod bias");
  CHECK(st.shade.alpha == 1 && st.shade.default_lights == 0, "alpha, default_lights");
  CHECK(st.shade.has_background == 1 && st.shade.background[0] == 0.5f && st.shade.background[1] == 0.25f &&
            st.shade.background[2] == 0,
        "background");
  rr_scene_release(s);

  /* the least file: defaults everywhere */
  s = load_text("least.json", "{\"meshes\": [{\"builtin\": \"box:1\"}]}", NULL, &st);
  CHECK(s != NULL, "least file: %s", rr_device_message(dev));
  rr_render_options ro;
  rr_render_options_init(&ro);
  rr_shade_options so;
  rr_shade_options_init(&so);
  CHECK(st.given == 0 && st.camera_given == 0 && st.render.method == RR_METHOD_AUTO && st.shade.mode == RR_SHADE_LIT &&
            st.render.width == ro.width && st.render.samples == 1 && st.shade.max_depth == so.max_depth &&
            st.shade.shadows == so.shadows,
        "defaults: given %#x", st.given);
  rr_scene_release(s);
  /* rr_scene_load reads a .json path as a scene file */
  s = NULL;
  CHECK(rr_scene_load(dev, test_write_file(dir, "via_load.json", "{\"meshes\": [{\"builtin\": \"torus:6\"}]}"), &s) ==
            RR_OK && s,
        "rr_scene_load of a scene file: %s", rr_device_message(dev));
  if (s) rr_scene_get_info(s, &in);
  CHECK(s && in.triangles == 2 * 6 * 3, "torus:6 has 36 triangles");
  rr_scene_release(s);
}

/* ---- transforms against double precision ----------------------------------------- */

/* The test's own composition: x' = T + Rz Ry Rx (S x), angles in degrees. */
static void reference(const double s[3], const double deg[3], const double t[3], const double x[3], double out[3]) {
  double v[3] = {x[0] * s[0], x[1] * s[1], x[2] * s[2]};
  double a = deg[0] * M_PI / 180, b = deg[1] * M_PI / 180, c = deg[2] * M_PI / 180;
  double y1 = cos(a) * v[1] - sin(a) * v[2], z1 = sin(a) * v[1] + cos(a) * v[2]; /* about x */
  double x2 = cos(b) * v[0] + sin(b) * z1, z2 = -sin(b) * v[0] + cos(b) * z1;      /* about y */
  double x3 = cos(c) * x2 - sin(c) * y1, y3 = sin(c) * x2 + cos(c) * y1;           /* about z */
  out[0] = x3 + t[0], out[1] = y3 + t[1], out[2] = z2 + t[2];
}

static void transforms(void) {
  test_write_file(dir, "n.obj", "v 0.3 -0.7 1.1\nv 2.5 0.2 -0.4\nv -1.3 1.9 0.6\nvn 3.45 3.5 7.16\nf 1//1 2//1 3//1\n");
  static const double s[3] = {2, 3, 0.5}, deg[3] = {30, 45, 60}, t[3] = {1, -2, 3};
  static const double x[3][3] = {{0.3, -0.7, 1.1}, {2.5, 0.2, -0.4}, {-1.3, 1.9, 0.6}};
  rr_scene *sc = load_text("xf.json",
                           "{\"meshes\": [{\"file\": \"n.obj\", \"scale\": [2, 3, 0.5], \"rotate\": [30, 45, 60], "
                           "\"translate\": [1, -2, 3]}]}",
                           NULL, NULL);
  CHECK(sc != NULL, "transform: %s", rr_device_message(dev));
  if (!sc) return;
  double want[3][3];
  for (int k = 0; k < 3; k++) reference(s, deg, t, x[k], want[k]);
  int close = 0;
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 3; c++) close += near(sc->p[k][c][0], want[k][c], 2e-7);
  CHECK(close == 9, "%d of 9 coordinates within float rounding of the double-precision reference", close);
  /* normals through the inverse transpose: still perpendicular to the moved triangle */
  double e1[3], e2[3], n[3];
  for (int c = 0; c < 3; c++) e1[c] = want[1][c] - want[0][c], e2[c] = want[2][c] - want[0][c];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  bool normals = sc->n[0][0] != NULL;
  for (int k = 0; normals && k < 3; k++) {
    double d = (sc->n[k][0][0] * n[0] + sc->n[k][1][0] * n[1] + sc->n[k][2][0] * n[2]) / ln;
    normals &= fabs(d - 1) < 1e-5;
  }
  CHECK(normals, "the moved normals are the moved triangle's unit normal: (%g %g %g) vs (%g %g %g)",
        sc->n[0][0] ? sc->n[0][0][0] : -9, sc->n[0][0] ? sc->n[0][1][0] : -9, sc->n[0][0] ? sc->n[0][2][0] : -9,
        n[0] / ln, n[1] / ln, n[2] / ln);
  rr_scene_release(sc);

  /* the same map as a matrix, its entries from the reference */
  char text[1024];
  double m[3][4], o[3] = {0, 0, 0};
  reference(s, deg, t, o, o);
  for (int c = 0; c < 3; c++) {
    double e[3] = {c == 0, c == 1, c == 2}, col[3];
    reference(s, deg, t, e, col);
    for (int r = 0; r < 3; r++) m[r][c] = col[r] - o[r];
  }
  for (int r = 0; r < 3; r++) m[r][3] = o[r];
  snprintf(text, sizeof text,
           "{\"meshes\": [{\"file\": \"n.obj\", \"matrix\": [[%.17g, %.17g, %.17g, %.17g], [%.17g, %.17g, %.17g, %.17g],"
           " [%.17g, %.17g, %.17g, %.17g], [0, 0, 0, 1]]}]}",
           m[0][0], m[0][1], m[0][2], m[0][3], m[1][0], m[1][1], m[1][2], m[1][3], m[2][0], m[2][1], m[2][2], m[2][3]);
  sc = load_text("xm.json", text, NULL, NULL);
  CHECK(sc != NULL, "matrix: %s", rr_device_message(dev));
  if (!sc) return;
  close = 0;
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 3; c++) close += near(sc->p[k][c][0], want[k][c], 2e-7);
  CHECK(close == 9, "matrix: %d of 9 coordinates within float rounding", close);
  rr_scene_release(sc);

  /* no transform: the file's mesh as rr_scene_load reads it, normals' bits too */
  rr_scene *plain = load_text("plain.json", "{\"meshes\": [{\"file\": \"n.obj\"}]}", NULL, NULL), *direct = NULL;
  char obj[300];
  snprintf(obj, sizeof obj, "%s/n.obj", dir);
  CHECK(plain && rr_scene_load(dev, obj, &direct) == RR_OK, "%s", rr_device_message(dev));
  bool bits = plain && direct && plain->ntris == direct->ntris && plain->n[0][0] && direct->n[0][0];
  for (int k = 0; bits && k < 3; k++)
    for (int c = 0; c < 3; c++)
      bits &= memcmp(plain->p[k][c], direct->p[k][c], plain->ntris * sizeof(float)) == 0 &&
              memcmp(plain->n[k][c], direct->n[k][c], plain->ntris * sizeof(float)) == 0;
  CHECK(bits, "a mesh without a transform is its file's, bit for bit");
  rr_scene_release(plain), rr_scene_release(direct);

  /* a mirror keeps the front face in front: corners 1 and 2 trade places */
  sc = load_text("xmirror.json", "{\"meshes\": [{\"file\": \"tri.obj\", \"scale\": [-1, 1, 1]}]}", NULL, NULL);
  CHECK(sc != NULL, "mirror: %s", rr_device_message(dev));
  if (!sc) return;
  vec3 nn = rr_scene_tri_normal(sc, 0);
  CHECK(nn.z > 0 && sc->p[1][0][0] == 0 && sc->p[2][0][0] == -1, "mirrored triangle faces +z: %g", nn.z);
  rr_scene_release(sc);
}

/* ---- the same scene through the API, bit for bit ------------------------------------- */

static rr_image render(const rr_scene *s, const rr_camera *cam, const rr_render_options *ro, const rr_shade_options *so) {
  rr_image img = {0};
  rr_frame *f = test_render_opt(dev, s, cam, ro);
  if (f) CHECK(rr_shade_frame(dev, s, cam, f, so, &img, NULL) == RR_OK, "%s", rr_device_message(dev));
  rr_frame_release(f);
  return img;
}

static void same_as_api(void) {
  test_write_file(dir, "floor.obj", "v -4 0 -4\nv -4 0 4\nv 4 0 4\nv 4 0 -4\nf 1 2 3 4\n");
  test_write_file(dir, "tet.obj", "v 0 0 0\nv 1 0 0\nv 0 0 -1\nv 0.3 1 -0.3\nf 1 2 4\nf 2 3 4\nf 3 1 4\nf 1 3 2\n");
  const char *text =
      "{\"meshes\": [\n"
      "  {\"file\": \"floor.obj\", \"material\": {\"model\": \"phong\", \"color\": [0.5, 0.5, 0.5], \"specular\": "
      "[0.3, 0.3, 0.3], \"shininess\": 0, \"emission\": [0, 0, 0], \"opacity\": 1, \"mirror\": true}},\n"
      "  {\"file\": \"tet.obj\", \"scale\": 2, \"translate\": [-1, 0.5, 1], \"material\": {\"model\": \"phong\", "
      "\"color\": [0.9, 0.3, 0.1], \"specular\": [0, 0, 0], \"shininess\": 0, \"emission\": [0, 0, 0], \"opacity\": 1, "
      "\"mirror\": false}}],\n"
      " \"lights\": [{\"type\": \"point\", \"position\": [3, 6, 4], \"intensity\": 30},\n"
      "            {\"type\": \"sky\", \"color\": [0.1, 0.15, 0.2]}],\n"
      " \"camera\": {\"eye\": [1, 4, 8], \"target\": [0, 0.5, 0], \"fov\": 40},\n"
      " \"render\": {\"size\": [96, 64], \"method\": \"3dr-bb\", \"aa\": \"msaa:4\", \"shade\": \"lit\", "
      "\"max_depth\": 2}}\n";
  rr_scene_settings st;
  rr_scene *a = load_text("same.json", text, NULL, &st);
  CHECK(a != NULL, "same scene: %s", rr_device_message(dev));
  if (!a) return;
  /* the API's scene: the same triangles (exactly: the transform is exact here), materials, lights */
  rr_scene *b;
  rr_scene_new(dev, &b);
  const float floor_p[] = {-4, 0, -4, -4, 0, 4, 4, 0, 4, 4, 0, -4};
  const uint32_t floor_i[] = {0, 1, 2, 0, 2, 3};
  const float tet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0.3f, 1, -0.3f}};
  float tet_p[12];
  for (int v = 0; v < 4; v++)
    for (int c = 0; c < 3; c++) tet_p[3 * v + c] = (float)(2.0 * (double)tet[v][c] + (c == 0 ? -1 : c == 1 ? 0.5 : 1));
  const uint32_t tet_i[] = {0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 2, 1};
  const float grey[3] = {0.5f, 0.5f, 0.5f}, red[3] = {0.9f, 0.3f, 0.1f};
  CHECK(rr_scene_add_mesh(b, floor_p, 4, floor_i, 2, grey) == RR_OK && rr_scene_add_mesh(b, tet_p, 4, tet_i, 4, red) == RR_OK,
        "%s", rr_device_message(dev));
  rr_material_params mirror = {.model = RR_MATERIAL_PHONG, .specular = {0.3f, 0.3f, 0.3f}, .opacity = 1, .illum = 3,
                               .metallic = 1, .roughness = 1};
  rr_material_params plain = mirror;
  plain.specular[0] = plain.specular[1] = plain.specular[2] = 0, plain.illum = -1;
  rr_material_info ma;
  rr_scene_get_material_info(a, 0, &ma);
  mirror.metallic = ma.params.metallic, mirror.roughness = ma.params.roughness, mirror.ambient[0] = ma.params.ambient[0],
  mirror.ambient[1] = ma.params.ambient[1], mirror.ambient[2] = ma.params.ambient[2];
  rr_scene_get_material_info(a, 1, &ma);
  plain.metallic = ma.params.metallic, plain.roughness = ma.params.roughness, plain.ambient[0] = ma.params.ambient[0],
  plain.ambient[1] = ma.params.ambient[1], plain.ambient[2] = ma.params.ambient[2];
  CHECK(rr_scene_set_material(b, 0, NULL, &mirror) == RR_OK && rr_scene_set_material(b, 1, NULL, &plain) == RR_OK, "%s",
        rr_device_message(dev));
  rr_light_info key = {.type = RR_LIGHT_POINT, .position = {3, 6, 4}, .color = {30, 30, 30}};
  rr_light_info sky = {.type = RR_LIGHT_AMBIENT, .color = {0.1f, 0.15f, 0.2f}};
  CHECK(rr_scene_add_light(b, &key) == RR_OK && rr_scene_add_light(b, &sky) == RR_OK, "%s", rr_device_message(dev));
  CHECK(rr_scene_commit(b) == RR_OK, "%s", rr_device_message(dev));
  /* the same triangles, bit for bit */
  bool same = a->ntris == b->ntris;
  for (uint32_t i = 0; same && i < a->ntris; i++)
    for (int k = 0; k < 3; k++)
      for (int c = 0; c < 3; c++) same &= memcmp(&a->p[k][c][i], &b->p[k][c][i], sizeof(float)) == 0;
  CHECK(same, "the scene file's triangles are the API's, bit for bit");
  rr_camera cam;
  rr_camera_init(&cam);
  const float eye[3] = {1, 4, 8}, target[3] = {0, 0.5f, 0};
  memcpy(cam.eye, eye, sizeof eye), memcpy(cam.target, target, sizeof target), cam.fov_deg = 40;
  CHECK(memcmp(&cam, &st.camera, sizeof cam) == 0, "the file's camera is the API's");
  rr_render_options ro;
  rr_render_options_init(&ro);
  ro.width = 96, ro.height = 64, ro.method = RR_METHOD_3DR_BB, ro.threads = 2;
  rr_render_options_set_aa(dev, &ro, RR_AA_MSAA, 4, 0, RR_AA_STANDARD, 1);
  rr_shade_options so;
  rr_shade_options_init(&so);
  so.mode = RR_SHADE_LIT, so.max_depth = 2;
  st.render.threads = 2;
  rr_image ia = render(a, &st.camera, &st.render, &st.shade), ib = render(b, &cam, &ro, &so);
  size_t bytes = (size_t)ia.width * ia.height * ia.channels * sizeof(float);
  CHECK(ia.data && ib.data && ia.width == 96 && ib.width == 96 && ia.channels == ib.channels &&
            memcmp(ia.data, ib.data, bytes) == 0,
        "the scene file renders the API scene's image bit for bit");
  /* and the picture is not empty: the mirror floor reflects the red tetrahedron somewhere */
  int lit = 0;
  for (size_t i = 0; ia.data && i < (size_t)96 * 64; i++) lit += ((float *)ia.data)[3 * i] > 0.05f;
  CHECK(lit > 1000, "%d lit pixels", lit);
  rr_image_free(&ia), rr_image_free(&ib);
  rr_scene_release(a), rr_scene_release(b);
}

/* ---- sandbox, built-ins, budget --------------------------------------------------- */

static void options(void) {
  char sub[256], path[300], link[300];
  snprintf(sub, sizeof sub, "%s/sub", dir);
  CHECK(mkdir(sub, 0700) == 0, "mkdir");
  test_write_file(sub, "in.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  snprintf(path, sizeof path, "%s/tri.obj", dir);
  snprintf(link, sizeof link, "%s/out_link.obj", sub);
  CHECK(symlink(path, link) == 0, "symlink");
  rr_load_options box;
  rr_load_options_init(&box);
  box.sandbox = 1;
  struct {
    const char *text;
    bool sandboxed_ok;
    const char *needle;
  } cases[] = {
      {"{\"meshes\": [{\"file\": \"in.obj\"}]}", true, NULL},
      {"{\"meshes\": [{\"file\": \"../tri.obj\"}]}", false, "outside"},
      {"{\"meshes\": [{\"file\": \"out_link.obj\"}]}", false, "outside"},
      {"{\"meshes\": [{\"builtin\": \"sphere:8\"}]}", true, NULL},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    const char *p = test_write_file(sub, "box.json", cases[i].text);
    rr_scene *s = NULL;
    CHECK(rr_scene_load_file(dev, p, NULL, &s, NULL) == RR_OK, "no sandbox: %s: %s", cases[i].text,
          rr_device_message(dev));
    rr_scene_release(s);
    s = NULL;
    rr_error e = rr_scene_load_file(dev, p, &box, &s, NULL);
    CHECK((e == RR_OK) == cases[i].sandboxed_ok && (e == RR_OK) == (s != NULL), "sandbox: %s: %s", cases[i].text,
          rr_device_message(dev));
    if (cases[i].needle) CHECK(strstr(rr_device_message(dev), cases[i].needle), "%s", rr_device_message(dev));
    rr_scene_release(s);
  }
  char text[400];
  snprintf(text, sizeof text, "{\"meshes\": [{\"file\": \"%s\"}]}", path);
  rr_scene *s = NULL;
  CHECK(rr_scene_load_file(dev, test_write_file(sub, "abs.json", text), &box, &s, NULL) != RR_OK && !s &&
            strstr(rr_device_message(dev), "outside"),
        "an absolute path outside: %s", rr_device_message(dev));
  snprintf(text, sizeof text, "{\"meshes\": [{\"builtin\": \"grid:%s:2\"}]}", path);
  CHECK(rr_scene_load_file(dev, test_write_file(sub, "grid.json", text), &box, &s, NULL) != RR_OK && !s &&
            strstr(rr_device_message(dev), "sandbox"),
        "grid: under the sandbox: %s", rr_device_message(dev));
  snprintf(text, sizeof text, "{\"instances\": {\"builtin\": \"grid-flat:%s:2\", \"transforms\": [{}]}}", path);
  CHECK(rr_scene_load_file(dev, test_write_file(sub, "gridf.json", text), &box, &s, NULL) != RR_OK && !s &&
            strstr(rr_device_message(dev), "sandbox"),
        "grid-flat: under the sandbox: %s", rr_device_message(dev));
  /* base_dir: relative paths from elsewhere */
  rr_load_options base;
  rr_load_options_init(&base);
  base.base_dir = sub;
  CHECK(rr_scene_load_file(dev, test_write_file(dir, "base.json", "{\"meshes\": [{\"file\": \"in.obj\"}]}"), &base, &s,
                           NULL) == RR_OK,
        "base_dir: %s", rr_device_message(dev));
  rr_scene_release(s), s = NULL;
  rr_load_options nob;
  rr_load_options_init(&nob);
  nob.builtins = 0;
  CHECK(rr_scene_load_file(dev, test_write_file(dir, "nob.json", "{\"meshes\": [{\"builtin\": \"box:1\"}]}"), &nob, &s,
                           NULL) != RR_OK && !s && strstr(rr_device_message(dev), "not allowed"),
        "built-ins refused: %s", rr_device_message(dev));
  /* the budget: sphere:16 has 2·16·(16-1)-ish triangles, more than 100 */
  rr_load_options budget;
  rr_load_options_init(&budget);
  budget.max_tris = 100;
  const char *two = test_write_file(dir, "budget.json", "{\"meshes\": [{\"builtin\": \"box:1\"}, {\"builtin\": \"sphere:16\"}]}");
  CHECK(rr_scene_load_file(dev, two, &budget, &s, NULL) != RR_OK && !s && strstr(rr_device_message(dev), "limit") &&
            strstr(rr_device_message(dev), "meshes[1]"),
        "max_tris: %s", rr_device_message(dev));
  const char *file_budget = test_write_file(dir, "budget2.json", "{\"meshes\": [{\"file\": \"tet.obj\"}]}");
  budget.max_tris = 3;
  CHECK(rr_scene_load_file(dev, file_budget, &budget, &s, NULL) != RR_OK && !s && strstr(rr_device_message(dev), "limit"),
        "max_tris on a mesh file: %s", rr_device_message(dev));
  budget.max_tris = 100000;
  CHECK(rr_scene_load_file(dev, two, &budget, &s, NULL) == RR_OK, "within max_tris: %s", rr_device_message(dev));
  rr_scene_release(s), s = NULL;

  /* camera files */
  rr_camera cam;
  rr_camera_init(&cam);
  unsigned fields = 99;
  CHECK(rr_camera_load(dev, test_write_file(dir, "cam.json", "{\"eye\": [1, 2, 3], \"target\": [0, 0, 0], \"fov\": 20}"),
                       &cam, &fields) == RR_OK &&
            fields == (RR_CAMERA_FIELD_EYE | RR_CAMERA_FIELD_TARGET | RR_CAMERA_FIELD_FOV) && cam.eye[1] == 2 &&
            cam.fov_deg == 20 && cam.up[1] == 1,
        "camera file: %#x %s", fields, rr_device_message(dev));
  CHECK(rr_camera_load(dev, test_write_file(dir, "cam2.json", "{\"matrix\": [[1,0,0,0], [0,1,0,0], [0,0,1,5], [0,0,0,1]]}"),
                       &cam, &fields) == RR_OK &&
            cam.eye[2] == 5 && cam.target[2] == 4 && cam.up[1] == 1,
        "camera matrix: %s", rr_device_message(dev));
  rr_camera before = cam;
  CHECK(rr_camera_load(dev, test_write_file(dir, "cam3.json", "{\"eye\": [1, 2, 3]}"), &cam, &fields) != RR_OK &&
            memcmp(&before, &cam, sizeof cam) == 0 && strstr(rr_device_message(dev), "'target'"),
        "a camera file without target: %s", rr_device_message(dev));
}

/* ---- malformed files ------------------------------------------------------------------ */

/* ---- textures on analytic primitives ------------------------------------------------ */

/* A material's "texture" on a sphere and a box seen head-on: a 2×1 texture, red then
 * blue along u, shows red left of the centre and blue right of it (the sphere's
 * longitude and the +z face's u both grow with x there); the material info names
 * the file. */
static void textures(void) {
  uint8_t texels[6] = {255, 0, 0, 0, 0, 255};
  rr_image tex = {.width = 2, .height = 1, .channels = 3, .type = RR_PIXEL_U8, .data = texels};
  char png[300];
  snprintf(png, sizeof png, "%s/rb.png", dir);
  CHECK(rr_image_write(dev, &tex, png) == RR_OK, "write the texture: %s", rr_device_message(dev));
  const char *kinds[2] = {"{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, ",
                          "{\"boxes\": [{\"center\": [0, 0, 0], \"size\": [2, 2, 2], "};
  for (int k = 0; k < 2; k++) {
    char text[400];
    snprintf(text, sizeof text, "%s\"material\": {\"color\": [1, 1, 1], \"texture\": \"rb.png\"}}]}", kinds[k]);
    rr_scene *s = load_text("tex.json", text, NULL, NULL);
    CHECK(s != NULL, "textured %s: %s", k ? "box" : "sphere", rr_device_message(dev));
    if (!s) continue;
    rr_material_info mi;
    rr_scene_get_material_info(s, 0, &mi);
    CHECK(mi.texture && !strcmp(mi.texture, "rb.png") && mi.texture_status == RR_TEXTURE_FILE && mi.texture_width == 2,
          "the material's texture: %s, status %d", mi.texture ? mi.texture : "none", mi.texture_status);
    rr_camera cam;
    rr_camera_init(&cam);
    cam.eye[2] = 5, cam.fov_deg = 30;
    rr_render_options ro;
    rr_render_options_init(&ro);
    ro.width = 64, ro.height = 48, ro.method = RR_METHOD_3DR_BB;
    rr_shade_options so;
    rr_shade_options_init(&so);
    so.texture_filter = RR_TEXTURE_NEAREST;
    rr_image img = render(s, &cam, &ro, &so);
    const float *px = img.type == RR_PIXEL_F32 ? img.data : NULL; /* linear colour */
    int red = 0, blue = 0, wrong = 0;
    for (int y = 18; px && y < 30; y++)
      for (int x = 20; x < 44; x++) {
        if (x == 31 || x == 32) continue; /* the texel edge at the centre */
        const float *c = px + ((size_t)y * img.width + x) * img.channels;
        bool r = c[0] > 0.05f && c[2] < 0.01f, b = c[2] > 0.05f && c[0] < 0.01f;
        red += r, blue += b, wrong += (x < 32) != r || (x > 32) != b;
      }
    CHECK(red > 100 && blue > 100 && wrong == 0, "textured %s: %d red, %d blue, %d on the wrong side",
          k ? "box" : "sphere", red, blue, wrong);
    rr_image_free(&img);
    rr_scene_release(s);
  }
}

static bool one_line(const char *m) { return m && *m && !strchr(m, '\n'); }
/* The output of a command: one line, ending in its line break. */
static bool printed_one_line(const char *out) {
  const char *nl = strchr(out, '\n');
  return nl && nl > out && nl[1] == 0;
}

static void errors(void) {
  static const struct {
    const char *text, *needle;
  } bad[] = {
      {"", "not valid JSON"},
      {"{\"meshes\": [", "line 1"},
      {"{\n\"meshes\": [\n{\"builtin\": \"box\"},\n]\n}", "line 4"},
      {"[1, 2]", "not a JSON object"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": NaN}]}", "not valid JSON (line 1)"},
      {"{}", "missing 'meshes'"},
      {"{\"meshes\": {}}", "'meshes': expected an array"},
      {"{\"meshes\": [1]}", "'meshes[0]': expected an object"},
      {"{\"meshes\": []}", "no triangles"},
      {"{\"meshes\": [{}]}", "'meshes[0]': expected one of 'file'"},
      {"{\"meshes\": [{\"file\": \"tri.obj\", \"builtin\": \"box\"}]}", "expected one of"},
      {"{\"meshes\": [{\"file\": \"missing.obj\"}]}", "'meshes[0].file': cannot open"},
      {"{\"meshes\": [{\"file\": \"\"}]}", "empty path"},
      {"{\"meshes\": [{\"file\": 3}]}", "'meshes[0].file': expected a string"},
      {"{\"meshes\": [{\"file\": \"not_a_mesh.obj\"}]}", "'meshes[0].file'"},
      {"{\"meshes\": [{\"builtin\": \"teapot\"}]}", "unknown built-in 'teapot'"},
      {"{\"meshes\": [{\"builtin\": \"sphere:2\"}]}", "'meshes[0].builtin': bad size"},
      {"{\"meshes\": [{\"builtin\": \"a\\nb\"}]}", "unknown built-in 'a?b'"},
      {"{\"meshes\": [{\"file\": \"x\\n.obj\"}]}", "'meshes[0].file'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"colour\": 1}]}", "unknown key 'colour'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"meshs\": []}", "unknown key 'meshs'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"name\": \"a\", \"name\": \"b\"}]}", "'meshes[0].name': given twice"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": \"big\"}]}", "'meshes[0].scale': expected an array of 3"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": 0}]}", "singular"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": [1, 0, 1]}]}", "singular"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": 1e999}]}", "'meshes[0].scale': expected a finite number"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"scale\": 9e29, \"translate\": [9e29, 0, 0]}]}", "beyond 1e30"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"translate\": [0, 1e31, 0]}]}", "'meshes[0].translate'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"translate\": [0, 1]}]}", "'meshes[0].translate': expected an array of 3"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"rotate\": [0, \"x\", 0]}]}", "'meshes[0].rotate'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}]}", "'meshes[0].matrix'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]}]}", "bottom row"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], \"scale\": 2}]}",
       "not both"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": []}]}", "'meshes[0].material': expected an object"},
      {"{\"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": {\"texture\": \"nowhere.png\"}}]}",
       "'spheres[0].material.texture': cannot read the image 'nowhere.png'"},
      {"{\"boxes\": [{\"center\": [0, 0, 0], \"size\": [1, 1, 1], \"material\": {\"texture\": \"bad.json\"}}]}",
       "'boxes[0].material.texture': cannot read the image 'bad.json'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": {\"texture\": 7}}]}",
       "'meshes[0].material.texture': expected a string"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": {\"color\": [1, -1, 0]}}]}", "'meshes[0].material.color'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": {\"roughness\": 2}}]}", "'meshes[0].material.roughness'"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": {\"model\": \"glass\"}}]}", "phong or pbr"},
      {"{\"meshes\": [{\"builtin\": \"box\", \"material\": {\"mirror\": 1}}]}", "expected true or false"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"position\": [0, 1, 0]}]}", "'lights[0]': missing 'type'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"laser\"}]}", "'lights[0].type'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"point\"}]}", "needs 'position'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"sky\", \"direction\": [0, 1, 0]}]}",
       "'lights[0].direction': not used"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"directional\", \"direction\": [0, 0, 0]}]}",
       "'lights[0]'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"spot\", \"position\": [0, 1, 0], "
       "\"direction\": [0, -1, 0], \"inner\": 40, \"outer\": 20}]}",
       "inner <= outer"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"lights\": [{\"type\": \"point\", \"position\": [0, 1, 0], "
       "\"intensity\": -1}]}",
       "'lights[0].intensity'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"camera\": {\"eye\": [0, 0, 5]}}", "'camera': missing 'target'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"camera\": {\"eye\": [0, 0, 5], \"target\": [0, 0, 5]}}", "'camera'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"camera\": {\"fov\": 0}}", "'camera.fov'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"camera\": {\"type\": \"pinhole\"}}", "'camera.type'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"size\": [0, 10]}}", "'render.size'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"size\": [10.5, 10]}}", "'render.size'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"method\": \"fast\"}}", "'render.method'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"aa\": \"msaa:3\"}}", "'render.aa'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"aa\": \"csaa:8/4\"}}", "'render.aa'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"aa_pattern\": \"rotated\"}}", "needs an 'aa'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"aa_filter\": \"gauss\"}}", "'render.aa_filter'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"texture_filter\": \"aniso:32\"}}",
       "'render.texture_filter'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"shade\": \"toon\"}}", "'render.shade'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"shadows\": \"shadow-map\"}}", "none, rays, raster or auto"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"max_depth\": 1.5}}", "'render.max_depth': expected an integer"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"max_depth\": 99}}", "'render.max_depth'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"alpha\": \"yes\"}}", "'render.alpha'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"lod_bias\": 1e300}}", "'render.lod_bias'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": []}", "'render': expected an object"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"render\": {\"background\": [0, -1, 0]}}", "'render.background'"},
      {"{\"meshes\": [{\"builtin\": \"box\"}], \"comment\": 5}", "'comment'"},
  };
  test_write_file(dir, "not_a_mesh.obj", "this is not a mesh\n\x01\x02\n");
  int refused = 0;
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    const char *path = test_write_file(dir, "bad.json", bad[i].text);
    rr_scene *s = (rr_scene *)&refused; /* must come back NULL */
    rr_scene_settings st, before;
    memset(&st, 0xA5, sizeof st), memcpy(&before, &st, sizeof st);
    rr_error e = rr_scene_load_file(dev, path, NULL, &s, &st);
    const char *m = rr_device_message(dev);
    bool ok = e != RR_OK && !s && one_line(m) && strstr(m, "scene file '") && strstr(m, "bad.json") &&
              strstr(m, bad[i].needle) && memcmp(&st, &before, sizeof st) == 0;
    CHECK(ok, "'%s': expected a refusal naming the file and \"%s\", got %d: %s", bad[i].text, bad[i].needle, (int)e, m);
    refused += ok;
  }
  printf("%d malformed scene files refused, each with one line naming the key\n", refused);
  rr_scene *s = NULL;
  CHECK(rr_scene_load_file(dev, "/nonexistent/x.json", NULL, &s, NULL) == RR_ERROR_IO && !s &&
            strstr(rr_device_message(dev), "cannot open"),
        "a missing scene file: %s", rr_device_message(dev));
  CHECK(rr_scene_load_file(dev, NULL, NULL, &s, NULL) == RR_ERROR_ARGUMENT, "NULL path");

  /* the command line: exit 1, one line, no image; flags override the file */
  char out[4096];
  test_write_file(dir, "bad.json", "{\"meshes\": [{\"builtin\": \"box\", \"scale\": \"big\"}]}");
  int rc = test_run_cli(dir, "render bad.json -o bad.png", true, out, sizeof out);
  char png[300];
  snprintf(png, sizeof png, "%s/bad.png", dir);
  CHECK(rc == 1 && printed_one_line(out) && strstr(out, "'meshes[0].scale'") && access(png, F_OK) != 0,
        "CLI refusal: %d %s", rc, out);
  test_write_file(dir, "missing.json", "{\"meshes\": [{\"file\": \"nowhere.obj\"}]}");
  rc = test_run_cli(dir, "render missing.json -o bad.png", true, out, sizeof out);
  CHECK(rc == 1 && printed_one_line(out) && strstr(out, "'meshes[0].file'") && strstr(out, "nowhere.obj") &&
            access(png, F_OK) != 0,
        "CLI, a missing mesh: %d %s", rc, out);
  test_write_file(dir, "cli.json",
                  "{\"meshes\": [{\"builtin\": \"box:1\"}], \"render\": {\"size\": [40, 30], \"shade\": \"normal\"},"
                  " \"camera\": {\"eye\": [2, 2, 3], \"target\": [0, 0, 0]}}");
  rc = test_run_cli(dir, "render cli.json -o cli.png --stats", true, out, sizeof out);
  CHECK(rc == 0 && strstr(out, "width=40 height=30"), "CLI takes the file's size: %d %s", rc, out);
  rc = test_run_cli(dir, "render cli.json -o cli.png --size 20x10 --stats", true, out, sizeof out);
  CHECK(rc == 0 && strstr(out, "width=20 height=10"), "a flag overrides the file's size: %d %s", rc, out);
  test_write_file(dir, "bg.json",
                  "{\"meshes\": [{\"builtin\": \"box:1\", \"scale\": 0.2}], \"render\": {\"size\": [16, 12], "
                  "\"background\": [0.25, 0.5, 1]}}");
  rc = test_run_cli(dir, "render bg.json -o bg.exr", true, out, sizeof out);
  rr_image bg = {0};
  char exr[300];
  snprintf(exr, sizeof exr, "%s/bg.exr", dir);
  CHECK(rc == 0 && rr_image_read(dev, exr, &bg) == RR_OK && bg.type == RR_PIXEL_F32 && bg.channels >= 3 &&
            ((float *)bg.data)[0] == 0.25f && ((float *)bg.data)[1] == 0.5f && ((float *)bg.data)[2] == 1.0f,
        "the file's background behind misses: %d %s", rc, out);
  rr_image_free(&bg);
  rc = test_run_cli(dir, "info cli.json", false, out, sizeof out);
  CHECK(rc == 0 && strstr(out, "triangles    12"), "info of a scene file: %d %s", rc, out);
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  dev = rr_device_new();
  every_key();
  transforms();
  same_as_api();
  options();
  errors();
  textures();
  rr_device_release(dev);
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  return test_done();
}
