/* Instances (scene/instance.h, rr_scene_add_instances, grid:PATH:N):
 * - an instanced scene renders bit for bit like the same scene flattened with the
 *   instances' own inst_point, in every method (the 2D pipeline too), at random views
 *   and views from inside, for every camera, on 1 and 2 threads; and every 3D method
 *   gives rc's bits on it;
 * - grid:PATH:N (instances) equals grid-flat:PATH:N (copies written out) bit for bit,
 *   ids and geometries included, and stores the mesh once;
 * - the two-level BVH as its readers see it (accel/bvh_levels.h): in each form
 *   (binary, 4- and 8-wide) every triangle in exactly one leaf, whose corners are its
 *   world corners and lie in the leaf's world box;
 * - instance ids: rr_hit.inst, rr_scene_get_instance;
 * - rr_intersect / rr_occluded agree with brute force (test_brute_ray);
 * - bad transforms (NaN, singular, mirroring) refused naming the instance, in the
 *   API and in scene files. */
#include "accel/bvh_levels.h"
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { NTRI = 60, NINST = 7 };

/* A small random mesh (a cluster of triangles about the origin, some sharing edges). */
static void random_mesh(float *pos, uint32_t *idx) {
  for (int t = 0; t < NTRI; t++) {
    float cx = test_randf(-1, 1), cy = test_randf(-1, 1), cz = test_randf(-1, 1), sz = test_randf(0.2f, 0.8f);
    for (int k = 0; k < 3; k++) {
      pos[9 * t + 3 * k] = cx + sz * test_randf(-1, 1), pos[9 * t + 3 * k + 1] = cy + sz * test_randf(-1, 1);
      pos[9 * t + 3 * k + 2] = cz + sz * test_randf(-1, 1);
      idx[3 * t + k] = (uint32_t)(3 * t + k);
    }
  }
  /* pairs sharing an edge: watertightness across instances' copies */
  for (int t = 1; t < NTRI; t += 4)
    for (int a = 0; a < 6; a++) pos[9 * t + a] = pos[9 * (t - 1) + a];
}

/* Transforms: translations, a rotation with scale, a shear. */
static void random_xf(float (*xf)[12]) {
  for (int k = 0; k < NINST; k++) {
    float m[12] = {1, 0, 0, test_randf(-5, 5), 0, 1, 0, test_randf(-1, 2), 0, 0, 1, test_randf(-5, 5)};
    if (k % 3 == 1) { /* rotate about y, scale */
      float a = test_randf(0, 6.28f), c = cosf(a), s = sinf(a), sc = test_randf(0.5f, 1.5f);
      m[0] = c * sc, m[2] = s * sc, m[8] = -s * sc, m[10] = c * sc, m[5] = sc;
    } else if (k % 3 == 2) { /* a general (sheared) affine map */
      m[1] = test_randf(-0.3f, 0.3f), m[6] = test_randf(-0.3f, 0.3f), m[5] = test_randf(0.7f, 1.3f);
    }
    memcpy(xf[k], m, sizeof m);
  }
}

/* The scene with ninst instances of the first ntri triangles of the mesh (flat =
 * false) or with the instances written out as meshes through inst_point (flat =
 * true); with `others`, a mesh before, and spheres, a tilted plane, an oriented box and
 * a mesh after. */
static rr_scene *build_n(rr_device *dev, const float *pos, const uint32_t *idx, const float (*xf)[12], bool flat,
                         int ntri, int ninst, bool others) {
  rr_scene *s = NULL;
  if (rr_scene_new(dev, &s) != RR_OK) return NULL;
  float before[9] = {-6, 0, -6, 6, 0, -6, 0, 0, 6}; /* a floor */
  uint32_t i3[3] = {0, 2, 1};
  if (others) CHECK(rr_scene_add_mesh(s, before, 3, i3, 1, NULL) == RR_OK, "floor");
  if (!flat) {
    CHECK(rr_scene_add_instances(s, pos, 3 * (uint32_t)ntri, idx, (uint32_t)ntri, NULL, &xf[0][0], (uint32_t)ninst) ==
              RR_OK,
          "instances: %s", rr_device_message(dev));
  } else {
    float *p = malloc(sizeof(float) * 9 * NTRI);
    for (int k = 0; k < ninst; k++) {
      for (int v = 0; v < 3 * ntri; v++) {
        bool shift = xf[k][0] == 1 && xf[k][1] == 0 && xf[k][2] == 0 && xf[k][4] == 0 && xf[k][5] == 1 &&
                     xf[k][6] == 0 && xf[k][8] == 0 && xf[k][9] == 0 && xf[k][10] == 1;
        v3_store(p + 3 * v, inst_point(xf[k], shift, v3_load(pos + 3 * v)));
      }
      CHECK(rr_scene_add_mesh(s, p, 3 * (uint32_t)ntri, idx, (uint32_t)ntri, NULL) == RR_OK, "copy %d", k);
    }
    free(p);
  }
  if (others) {
    const float sp[8] = {0, 1, 0, 0.7f, 3, 0.5f, 2, 0.5f};
    CHECK(rr_scene_add_spheres(s, sp, 2, NULL) == RR_OK, "spheres");
    const float pl[6] = {0, -4, 0, 0.1f, 1, 0.05f}, bx[12] = {-2, 0.5f, 1, 0.4f, 0.3f, 0.6f, 1, 0.2f, 0, 0, 1, 0.3f};
    CHECK(rr_scene_add_planes(s, pl, 1, NULL) == RR_OK, "plane");
    CHECK(rr_scene_add_boxes(s, bx, 1, NULL) == RR_OK, "box");
    CHECK(rr_scene_add_mesh(s, pos, 3 * NTRI, idx, NTRI, NULL) == RR_OK, "a mesh after");
  }
  CHECK(rr_scene_commit(s) == RR_OK, "commit: %s", rr_device_message(dev));
  return s;
}

static rr_scene *build(rr_device *dev, const float *pos, const uint32_t *idx, const float (*xf)[12], bool flat) {
  return build_n(dev, pos, idx, xf, flat, NTRI, NINST, true);
}

static const rr_method all[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_2DR_BB, RR_METHOD_2DR_BIN,
                                RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,  RR_METHOD_3DR_FC, RR_METHOD_3DR_FS,
                                RR_METHOD_3DR_FULL};

static void check_methods(rr_device *dev, const rr_scene *inst, const rr_scene *flat, int views, int min_hits) {
  int inst_hits = 0, frames = 0;
  for (int v = 0; v < views; v++)
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      rr_camera cam = test_random_camera(inst, (rr_camera_type)type, v % 2);
      int w = type == RR_CAMERA_CUBE ? 64 : 40, h = type == RR_CAMERA_CUBE ? 48 : 32, cull = (v + type) % 2;
      rr_frame *ref = test_render(dev, inst, &cam, RR_METHOD_RC, 2, w, h, cull);
      rr_frame *fref = test_render(dev, flat, &cam, RR_METHOD_RC, 1, w, h, cull);
      if (!ref || !fref) {
        rr_frame_release(ref), rr_frame_release(fref);
        continue;
      }
      CHECK(test_frames_differ(ref, fref) == 0, "view %d %s: rc on instances differs from the flattened scene", v,
            rr_camera_name(type));
      for (size_t k = 0; k < (size_t)w * h; k++) inst_hits += scene_instance_of(inst, ref->vb.id[k]) != RR_MISS;
      for (size_t m = 0; m < sizeof all / sizeof all[0]; m++) {
        bool planar2d = all[m] == RR_METHOD_2DR_BB || all[m] == RR_METHOD_2DR_BIN;
        if (planar2d && type != RR_CAMERA_PERSPECTIVE && type != RR_CAMERA_ORTHOGRAPHIC) continue;
        int threads = 1 + (int)((v + type + m) % 2);
        rr_frame *a = test_render(dev, inst, &cam, all[m], threads, w, h, cull);
        rr_frame *b = test_render(dev, flat, &cam, all[m], 3 - threads, w, h, cull);
        if (a && b) {
          int d = test_frames_differ(a, b);
          CHECK(d == 0, "view %d %s: %s on instances differs from the flattened scene at %d samples", v,
                rr_camera_name(type), rr_method_name(all[m]), d);
          if (!planar2d) { /* the 2D pipeline interpolates depth: its own bits, the same on both scenes */
            d = test_frames_differ(a, ref);
            CHECK(d == 0, "view %d %s: %s differs from rc at %d samples", v, rr_camera_name(type),
                  rr_method_name(all[m]), d);
          }
          frames++;
        }
        rr_frame_release(a), rr_frame_release(b);
      }
      rr_frame_release(ref), rr_frame_release(fref);
    }
  printf("methods: %d frame pairs, %d samples on instances\n", frames, inst_hits);
  CHECK(inst_hits > min_hits, "instances are seen (%d samples)", inst_hits);
}

/* A hit's instance ids: rr_scene_get_instance's, and for a triangle of an instance its
 * local index (the first instance's first id is `first`). */
typedef struct inst_check {
  const rr_scene *s;
  uint32_t first;
  int on_inst;
} inst_check;

static void check_hit_instance(const rr_hit *a, void *arg) {
  inst_check *ic = arg;
  uint32_t k = 0, l = 0;
  CHECK(rr_scene_get_instance(ic->s, a->prim, &k, &l) == RR_OK && k == a->inst, "instance of %u: %u, hit says %u",
        a->prim, k, a->inst);
  if (a->inst != RR_MISS) {
    ic->on_inst++;
    CHECK(a->inst < NINST && l == a->prim - ic->first - a->inst * NTRI, "hit %u: instance %u local %u", a->prim,
          a->inst, l);
  }
}

/* rr_intersect / rr_occluded against brute force, and the instance ids of hits. */
static void check_rays(rr_device *dev, const rr_scene *s) {
  inst_check ic = {s, RR_MISS, 0};
  for (uint32_t i = 0; i < s->ntris && ic.first == RR_MISS; i++)
    if (scene_instance_of(s, i) == 0) ic.first = scene_face_id(s, i);
  int hits, n = test_check_rays(dev, s, check_hit_instance, &ic, &hits);
  CHECK(ic.on_inst > 50, "rays on instances: %d", ic.on_inst);
  printf("rays: %d, %d on instances\n", n, ic.on_inst);
}

/* ---- the two-level BVH through its readers' accessors ---------------------------- */

typedef struct tree_walk {
  const rr_scene *s;
  uint32_t *cover; /* per triangle: the leaves holding it */
  uint32_t bad;
} tree_walk;

/* A leaf's ids and corners (leaf_v's layout, v8: leaf_v8's) against the scene's
 * world corners and the leaf's box lo..hi. */
static void walk_leaf(tree_walk *w, bool v8, uint32_t first, uint32_t count, const float lo[3], const float hi[3]) {
  float vbuf[9 * BVH_MAX_LEAF + BVH_LEAF_PAD];
  uint32_t ibuf[BVH_MAX_LEAF];
  const uint32_t *ids;
  if (count > BVH_MAX_LEAF) {
    w->bad++;
    return;
  }
  const float *v = bvh_leaf_at(w->s->bvh, v8, first, count, vbuf, ibuf, &ids);
  for (uint32_t t = 0; t < count; t++) {
    uint32_t id = ids[t];
    w->bad += id != bvh_prim_at(w->s->bvh, first + t);
    if (id >= w->s->ntris) {
      w->bad++;
      continue;
    }
    w->cover[id]++;
    if (scene_kind(w->s, id) != RR_GEOMETRY_TRIANGLE) continue;
    vec3 c[3];
    scene_corners(w->s, id, c);
    for (int m = 0; m < 9; m++) {
      float want = m % 3 == 0 ? c[m / 3].x : m % 3 == 1 ? c[m / 3].y : c[m / 3].z, got = v[m * count + t];
      w->bad += got != want || !(lo[m % 3] <= got && got <= hi[m % 3]);
    }
  }
}

static void walk_node(tree_walk *w, uint32_t r, int depth) {
  bvh_node buf;
  const bvh_node *n = bvh_node_at(w->s->bvh, r, &buf);
  if (depth > BVH_STACK) w->bad++;
  else if (n->count) walk_leaf(w, false, n->first, n->count, n->lo, n->hi);
  else walk_node(w, n->first, depth + 1), walk_node(w, n->first + 1, depth + 1);
}

/* The 4-wide (W 4) or 8-wide form from node r. */
static void walk_wide(tree_walk *w, int W, uint32_t r, int depth) {
  BVH_NODE_ALIGN bvh_wide b4;
  BVH_NODE_ALIGN bvh_wide8 b8;
  const bvh_wide *n4 = W == 4 ? bvh_wide_at(w->s->bvh, r, &b4) : NULL;
  const bvh_wide8 *n8 = W == 8 ? bvh_wide8_at(w->s->bvh, r, &b8) : NULL;
  if (n4) { /* the references alone, as rc-bvh's walks read them */
    uint32_t ref[4], count[4];
    bvh_wide_refs(w->s->bvh, r, ref, count);
    w->bad += memcmp(ref, n4->ref, sizeof ref) != 0 || memcmp(count, n4->count, sizeof count) != 0;
  }
  for (int i = 0; i < W && depth <= BVH_STACK; i++) {
    uint32_t ref = n4 ? n4->ref[i] : n8->ref[i], count = n4 ? n4->count[i] : n8->count[i];
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++)
      lo[a] = n4 ? n4->lo[a][i] : n8->lo[a][i], hi[a] = n4 ? n4->hi[a][i] : n8->hi[a][i];
    if (ref == UINT32_MAX) w->bad += lo[0] <= hi[0] || count;
    else if (count) walk_leaf(w, W == 8, ref, count, lo, hi);
    else walk_wide(w, W, ref, depth + 1);
  }
  w->bad += depth > BVH_STACK;
}

static void check_levels(const rr_scene *s, const char *name) {
  const rr_bvh *b = s->bvh;
  CHECK(b && b->obj && b->inst == s->inst && b->nprims == s->ntris, "%s: two levels", name);
  if (!b || !b->obj) return;
  CHECK(b->vpos == b->ntop + s->inst->n * s->inst->T && b->vwide == b->nwide + s->inst->n * b->obj->nwide,
        "%s: references", name);
  for (int form = 0; form < 3; form++) {
    tree_walk w = {s, calloc(s->ntris, sizeof(uint32_t)), 0};
    if (form == 0) walk_node(&w, 0, 0);
    else walk_wide(&w, form == 1 ? 4 : 8, 0, 0);
    uint32_t missing = 0;
    for (uint32_t i = 0; i < s->ntris; i++) missing += w.cover[i] != 1;
    CHECK(w.bad == 0 && missing == 0, "%s: the %s form has %u faults, %u triangles not in exactly one leaf", name,
          form == 0 ? "binary" : form == 1 ? "4-wide" : "8-wide", w.bad, missing);
    free(w.cover);
  }
}

/* Trees of odd shapes, every method against the flattened scene and the ray queries
 * against brute force: instances alone (the top tree's root an instance: one
 * instance, and many); a mesh of one triangle (the object tree one leaf); leaves of
 * up to 16 triangles (an instance's leaves are made in the traversals' buffers). */
static void check_shapes(rr_device *dev, const float *pos, const uint32_t *idx, const float (*xf)[12]) {
  const struct {
    int ntri, ninst, leaf;
    bool others;
  } c[] = {{NTRI, 1, 0, false}, {NTRI, NINST, 0, false}, {1, NINST, 0, false}, {1, 1, 0, true}, {NTRI, NINST, 16, true}};
  for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
    rr_build_options opt;
    rr_build_options_init(&opt);
    if (c[i].leaf) opt.leaf_size = c[i].leaf;
    CHECK(rr_device_set_build_options(dev, &opt) == RR_OK, "build options");
    printf("shape %zu: %d triangles, %d instances%s, leaves of %d\n", i, c[i].ntri, c[i].ninst,
           c[i].others ? " and more" : "", opt.leaf_size);
    rr_scene *inst = build_n(dev, pos, idx, xf, false, c[i].ntri, c[i].ninst, c[i].others);
    rr_scene *flat = build_n(dev, pos, idx, xf, true, c[i].ntri, c[i].ninst, c[i].others);
    if (inst && flat) {
      check_levels(inst, "shape");
      check_methods(dev, inst, flat, 2, c[i].ntri > 1 ? 20 : 0);
      int hits;
      test_check_rays(dev, inst, NULL, NULL, &hits);
    }
    rr_scene_release(inst), rr_scene_release(flat);
  }
  rr_build_options opt;
  rr_build_options_init(&opt);
  rr_device_set_build_options(dev, &opt);
}

/* grid:PATH:N against grid-flat:PATH:N. */
static void check_grid(rr_device *dev) {
  const char *model = test_model("teapot.obj");
  if (!model) return;
  char a[512], b[512];
  int n = test_quick() ? 2 : 3;
  snprintf(a, sizeof a, "grid:%s:%d", model, n);
  snprintf(b, sizeof b, "grid-flat:%s:%d", model, n);
  rr_scene *si = NULL, *sf = NULL;
  CHECK(rr_scene_load(dev, a, &si) == RR_OK, "load %s: %s", a, rr_device_message(dev));
  CHECK(rr_scene_load(dev, b, &sf) == RR_OK, "load %s: %s", b, rr_device_message(dev));
  if (!si || !sf) {
    rr_scene_release(si), rr_scene_release(sf);
    return;
  }
  rr_scene_info ii, fi;
  rr_scene_get_info(si, &ii), rr_scene_get_info(sf, &fi);
  CHECK(ii.triangles == fi.triangles && ii.skipped == fi.skipped && ii.geometries == fi.geometries,
        "counts: %llu/%llu triangles, %u/%u geometries", (unsigned long long)ii.triangles,
        (unsigned long long)fi.triangles, ii.geometries, fi.geometries);
  CHECK(ii.instances == (uint32_t)(n * n) && fi.instances == 0, "instances %u", ii.instances);
  CHECK(ii.stored_triangles * n * n == fi.stored_triangles, "stored %llu vs %llu",
        (unsigned long long)ii.stored_triangles, (unsigned long long)fi.stored_triangles);
  check_levels(si, a);
  /* two levels: the mesh's tree once, not one per instance */
  CHECK(ii.bvh_bytes * (uint64_t)(n * n) < 2 * fi.bvh_bytes && ii.scene_bytes * (uint64_t)(n * n) < 2 * fi.scene_bytes,
        "memory: BVH %llu against %llu flat, scene %llu against %llu", (unsigned long long)ii.bvh_bytes,
        (unsigned long long)fi.bvh_bytes, (unsigned long long)ii.scene_bytes, (unsigned long long)fi.scene_bytes);
  CHECK(memcmp(ii.bounds_min, fi.bounds_min, 12) == 0 && memcmp(ii.bounds_max, fi.bounds_max, 12) == 0, "bounds");
  for (uint32_t g = 0; g < ii.geometries; g++) {
    rr_geometry_info gi, gf;
    rr_scene_get_geometry_info(si, g, &gi), rr_scene_get_geometry_info(sf, g, &gf);
    CHECK(gi.first == gf.first && gi.count == gf.count && gi.material == gf.material, "geometry %u", g);
  }
  const rr_method ms[] = {RR_METHOD_RC_BVH, RR_METHOD_RC_PACKET, RR_METHOD_2DR_BIN, RR_METHOD_3DR_BB,
                          RR_METHOD_3DR_FC, RR_METHOD_3DR_FULL};
  for (int v = 0; v < 3; v++) {
    rr_camera cam = test_random_view(si, v == 1 ? 0.2f : 0.9f, v == 1 ? 0.5f : 1.5f, 0.2f, 60, 60);
    cam.type = v == 2 ? RR_CAMERA_LATLONG : RR_CAMERA_PERSPECTIVE;
    for (size_t m = 0; m < sizeof ms / sizeof ms[0]; m++) {
      if (cam.type != RR_CAMERA_PERSPECTIVE && ms[m] == RR_METHOD_2DR_BIN) continue;
      rr_frame *fa = test_render(dev, si, &cam, ms[m], 2, 64, 48, 0);
      rr_frame *fb = test_render(dev, sf, &cam, ms[m], 1, 64, 48, 0);
      if (fa && fb) {
        int d = test_frames_differ(fa, fb);
        CHECK(d == 0, "grid view %d, %s: instances differ from copies at %d samples", v, rr_method_name(ms[m]), d);
        CHECK(test_frame_hits(fa) > 20, "grid view %d: %d hits", v, test_frame_hits(fa));
        rr_image ia = {0}, ma = {0};
        if (rr_frame_aov(dev, si, &cam, fa, RR_AOV_INSTANCE, &ia) == RR_OK &&
            rr_frame_aov(dev, si, &cam, fa, RR_AOV_MESH, &ma) == RR_OK) {
          const uint32_t *inst = ia.data, *mesh = ma.data;
          int wrong = 0, seen = 0;
          for (int k = 0; k < 64 * 48; k++) { /* one geometry per instance: the mesh id is the instance */
            wrong += fa->vb.id[k] == RR_MISS ? inst[k] != RR_MISS : inst[k] != mesh[k] || inst[k] >= (uint32_t)(n * n);
            seen += inst[k] != RR_MISS && inst[k] != 0;
          }
          CHECK(wrong == 0 && (v == 1 || seen > 0), "grid view %d: instance AOV wrong at %d samples (%d seen)", v, wrong, seen);
        } else {
          CHECK(0, "instance AOV: %s", rr_device_message(dev));
        }
        rr_image_free(&ia), rr_image_free(&ma);
        for (int k = 0; k < 64 * 48; k++) { /* ids as the flattened grid's */
          if (fa->vb.id[k] == RR_MISS) continue;
          CHECK(scene_face_id(si, fa->vb.id[k]) == scene_face_id(sf, fb->vb.id[k]), "id at %d", k);
          break;
        }
      }
      rr_frame_release(fa), rr_frame_release(fb);
    }
  }
  rr_scene_release(si), rr_scene_release(sf);
}

static void check_errors(rr_device *dev, const float *pos, const uint32_t *idx) {
  rr_scene *s = NULL;
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  float xf[2][12] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}};
  xf[1][5] = NAN;
  CHECK(rr_scene_add_instances(s, pos, 3 * NTRI, idx, NTRI, NULL, &xf[0][0], 2) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "instance 1") && strstr(rr_device_message(dev), "not finite"),
        "NaN refused: %s", rr_device_message(dev));
  xf[1][5] = 1, xf[1][0] = 0;
  CHECK(rr_scene_add_instances(s, pos, 3 * NTRI, idx, NTRI, NULL, &xf[0][0], 2) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "singular"),
        "singular refused: %s", rr_device_message(dev));
  xf[1][0] = -1;
  CHECK(rr_scene_add_instances(s, pos, 3 * NTRI, idx, NTRI, NULL, &xf[0][0], 2) == RR_ERROR_ARGUMENT &&
            strstr(rr_device_message(dev), "mirror"),
        "mirror refused: %s", rr_device_message(dev));
  rr_scene_info info;
  rr_scene_get_info(s, &info);
  CHECK(info.triangles == 0 && info.geometries == 0 && info.materials == 0, "nothing added");
  xf[1][0] = 1;
  CHECK(rr_scene_add_instances(s, pos, 3 * NTRI, idx, NTRI, NULL, &xf[0][0], 2) == RR_OK, "ok");
  CHECK(rr_scene_add_instances(s, pos, 3 * NTRI, idx, NTRI, NULL, &xf[0][0], 2) == RR_ERROR_ARGUMENT,
        "a second instanced mesh refused");
  rr_scene_release(s);
}

/* Scene files: "instances" places a mesh by a list of transforms; bad ones are refused
 * with one line naming the transform. */
static void check_scene_file(rr_device *dev) {
  char dir[] = "/tmp/rr_inst_XXXXXX";
  if (!mkdtemp(dir)) {
    CHECK(0, "mkdtemp");
    return;
  }
  const char *good = test_write_file(dir, "good.json",
      "{\"instances\": {\"builtin\": \"box\", \"name\": \"crate\", \"transforms\": [{\"translate\": [3, 0, 0]},"
      " {\"rotate\": [0, 45, 0], \"scale\": [1, 2, 1]}, {\"matrix\": [[1, 0, 0, 0], [0, 1, 0, -3], [0, 0, 1, 0], [0, 0, 0, 1]]}]},"
      " \"spheres\": [{\"center\": [0, 5, 0], \"radius\": 1}]}");
  rr_scene *s = NULL;
  CHECK(rr_scene_load(dev, good, &s) == RR_OK, "good file: %s", rr_device_message(dev));
  if (s) {
    rr_scene_info in;
    rr_scene_get_info(s, &in);
    CHECK(in.instances == 3 && in.triangles == 3 * in.stored_triangles - 0 && in.spheres == 1, "%u instances, %llu triangles",
          in.instances, (unsigned long long)in.triangles);
    rr_camera cam = test_random_view(s, 1.5f, 2.0f, 0.1f, 60, 60);
    rr_frame *a = test_render(dev, s, &cam, RR_METHOD_RC, 1, 32, 24, 0);
    rr_frame *b = test_render(dev, s, &cam, RR_METHOD_3DR_FULL, 2, 32, 24, 0);
    if (a && b) CHECK(test_frames_differ(a, b) == 0 && test_frame_hits(a) > 0, "scene file: 3dr-full equals rc");
    rr_frame_release(a), rr_frame_release(b);
    rr_scene_release(s);
  }
  static const struct {
    const char *body, *want;
  } bad[] = {
      {"{\"instances\": {\"builtin\": \"box\", \"transforms\": [{}, {\"scale\": [1, 0, 1]}]}}",
       "'instances.transforms[1]': the transform is singular"},
      {"{\"instances\": {\"builtin\": \"box\", \"transforms\": [{\"scale\": [-1, 1, 1]}]}}",
       "'instances.transforms[0]': a mirroring transform"},
      {"{\"instances\": {\"builtin\": \"box\", \"transforms\": [{\"translate\": [1, \"x\", 0]}]}}",
       "'instances.transforms[0].translate'"},
      {"{\"instances\": {\"builtin\": \"box\", \"transforms\": [{\"translate\": [1e30, 0, 0], \"scale\": 1e30}]}}",
       "'instances.transforms[0]'"},
      {"{\"instances\": {\"builtin\": \"box\", \"translate\": [1, 0, 0], \"transforms\": [{}]}}",
       "unknown key 'translate'"},
      {"{\"instances\": {\"builtin\": \"box\"}}", "missing 'transforms'"},
      {"{\"instances\": {\"builtin\": \"sphere\", \"transforms\": [{}]}}", "triangle meshes only"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    const char *path = test_write_file(dir, "bad.json", bad[k].body);
    rr_scene *t = NULL;
    rr_error e = rr_scene_load(dev, path, &t);
    const char *msg = rr_device_message(dev);
    CHECK(e != RR_OK && !t && strstr(msg, bad[k].want) && !strchr(msg, '\n'), "bad file %zu: %s", k, msg);
    rr_scene_release(t);
  }
  char cmd[64];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "rm");
}

int main(void) {
  rr_device *dev = rr_device_new();
  float *pos = malloc(sizeof(float) * 9 * NTRI);
  uint32_t *idx = malloc(sizeof(uint32_t) * 3 * NTRI);
  float xf[NINST][12];
  random_mesh(pos, idx);
  random_xf(xf);
  rr_scene *inst = build(dev, pos, idx, (const float (*)[12])xf, false);
  rr_scene *flat = build(dev, pos, idx, (const float (*)[12])xf, true);
  if (inst && flat) {
    CHECK(inst->ntris == flat->ntris && inst->inst && inst->inst->n == NINST, "index space");
    check_levels(inst, "instances");
    check_methods(dev, inst, flat, test_quick() ? 2 : 4, 100);
    check_rays(dev, inst);
  }
  rr_scene_release(inst), rr_scene_release(flat);
  check_shapes(dev, pos, idx, (const float (*)[12])xf);
  check_grid(dev);
  check_errors(dev, pos, idx);
  check_scene_file(dev);
  free(pos), free(idx);
  rr_device_release(dev);
  return test_done();
}
