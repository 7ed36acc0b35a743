/* Cameras beyond the pinhole: each camera's rays against an independent
 * double-precision reference; every 3D method bit-identical to rc for every
 * camera, on 1, 2 or 8 threads (curved binning and culling are conservative);
 * the cube's faces are six 90° perspective renders, and its one-pass drawing sets
 * each triangle up once (its shared setups, bit for bit the faces' own); 2D methods refuse
 * curved cameras. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <string.h>


/* The definitions, in double precision, with the basis of an eye on -z
 * looking at the origin (right = +x, up = +y, fwd = +z... computed here). */
static void reference_dir(const rr_camera *rc, int W, int H, int x, int y, double out[3], bool *has) {
  double f[3], r[3], u[3], up[3] = {rc->up[0], rc->up[1], rc->up[2]};
  for (int a = 0; a < 3; a++) f[a] = (double)rc->target[a] - rc->eye[a];
  double lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (int a = 0; a < 3; a++) f[a] /= lf;
  r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2], r[2] = f[0] * up[1] - f[1] * up[0];
  double lr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int a = 0; a < 3; a++) r[a] /= lr;
  u[0] = r[1] * f[2] - r[2] * f[1], u[1] = r[2] * f[0] - r[0] * f[2], u[2] = r[0] * f[1] - r[1] * f[0];
  double uu = 2 * (x + 0.5) / W - 1, vv = 1 - 2 * (y + 0.5) / H, cr = 0, cu = 0, cf = 0;
  *has = true;
  if (rc->type == RR_CAMERA_PARABOLIC) {
    if (uu * uu + vv * vv > 1) *has = false;
    cr = uu, cu = vv, cf = 0.5 - 0.5 * (uu * uu + vv * vv);
  } else if (rc->type == RR_CAMERA_LATLONG) {
    double phi = 2 * M_PI * (x + 0.5) / W - M_PI, th = M_PI * (y + 0.5) / H;
    cr = sin(th) * sin(phi), cf = sin(th) * cos(phi), cu = cos(th);
  } else if (rc->type == RR_CAMERA_FISHEYE) {
    double rad = sqrt(uu * uu + vv * vv), ang = rad * rc->fov_deg * M_PI / 360;
    if (rad > 1) *has = false;
    cr = rad > 0 ? sin(ang) * uu / rad : 0, cu = rad > 0 ? sin(ang) * vv / rad : 0, cf = cos(ang);
  } else if (rc->type == RR_CAMERA_PERSPECTIVE) {
    double th = tan(rc->fov_deg * M_PI / 360);
    cr = uu * th * W / H, cu = vv * th, cf = 1;
  }
  for (int a = 0; a < 3; a++) out[a] = cr * r[a] + cu * u[a] + cf * f[a];
}

static void check_directions(rr_device *dev) {
  const rr_camera_type types[] = {RR_CAMERA_PERSPECTIVE, RR_CAMERA_PARABOLIC, RR_CAMERA_LATLONG, RR_CAMERA_FISHEYE};
  const int W = 64, H = 48;
  /* centre, corners, poles (top and bottom rows), rims (edges of the disk) */
  const int pts[][2] = {{31, 23}, {32, 24}, {0, 0},  {63, 0},  {0, 47}, {63, 47},
                        {31, 0},  {31, 47}, {0, 23}, {63, 23}, {8, 8},  {56, 40}};
  for (size_t t = 0; t < sizeof types / sizeof types[0]; t++) {
    rr_camera rc = test_camera(types[t], v3(1, 2, 3), v3(-1, 0.5f, -2), types[t] == RR_CAMERA_FISHEYE ? 230 : 60);
    camera c;
    if (rr_cam_setup(dev, &rc, W, H, &c) != RR_OK) {
      CHECK(0, "camera %s: %s", rr_camera_name(types[t]), rr_device_message(dev));
      continue;
    }
    for (size_t p = 0; p < sizeof pts / sizeof pts[0]; p++) {
      int x = pts[p][0], y = pts[p][1];
      double ref[3];
      bool has_ref;
      reference_dir(&rc, W, H, x, y, ref, &has_ref);
      vec3 o, d;
      bool has = rr_cam_ray(&c, x, y, &o, &d);
      CHECK(has == has_ref, "%s (%d,%d): ray %d, reference %d", rr_camera_name(types[t]), x, y, has, has_ref);
      if (!has || !has_ref) continue;
      double ld = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
      double lr = sqrt(ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2]);
      double cosang = (d.x * ref[0] + d.y * ref[1] + d.z * ref[2]) / (ld * lr);
      CHECK(cosang > 1 - 1e-10 || acos(fmin(cosang, 1)) < 2e-6, "%s (%d,%d): direction off by %g rad",
            rr_camera_name(types[t]), x, y, acos(fmin(cosang, 1)));
    }
    rr_cam_release(&c);
  }
  /* Orthographic: parallel rays along fwd from the image plane through the eye. */
  rr_camera rc = test_camera(RR_CAMERA_ORTHOGRAPHIC, v3(0, 0, 5), v3(0, 0, 0), 45);
  rc.ortho_height = 4;
  camera c;
  CHECK(rr_cam_setup(dev, &rc, 40, 20, &c) == RR_OK, "ortho");
  vec3 o, d;
  rr_cam_ray(&c, 0, 0, &o, &d);
  CHECK(fabsf(o.x - (-4 + 0.1f)) < 1e-5f && fabsf(o.y - (2 - 0.1f)) < 1e-5f && o.z == 5 && d.z == -1,
        "ortho corner ray from (%g,%g,%g) along (%g,%g,%g)", o.x, o.y, o.z, d.x, d.y, d.z);
}

static const rr_method methods3d[] = {RR_METHOD_RC_BVH,  RR_METHOD_RC_PACKET, RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN,
                                      RR_METHOD_3DR_FC,  RR_METHOD_3DR_FS,    RR_METHOD_3DR_FULL};

/* Every camera, every 3D method, bit-identical to rc; random views, some inside.
 * The thread count goes round 1, 2 and 8 with the camera and the method, so each
 * method meets each count on every scene. (test_homogeneous renders every camera
 * and method on all three counts and compares S, E and N too; curved
 * rasterization of these meshes is slow enough to render each view once here.) */
static void check_methods(rr_device *dev, const char *name, int views) {
  rr_scene *s;
  if (rr_scene_load(dev, name, &s) != RR_OK) {
    CHECK(0, "load %s", name);
    return;
  }
  uint64_t bins = 0, empty = 0;
  /* views: 0 from outside, 1 inside; the sanitizers' run skips the outside one */
  for (int v = test_quick() ? 1 : 0; v < views; v++) {
    for (int type = 0; type < RR_CAMERA_COUNT; type++) {
      float fov = type == RR_CAMERA_FISHEYE ? 200 : 70;
      rr_camera cam = test_random_view(s, v % 2 ? 0.05f : 1.2f, v % 2 ? 0.5f : 2.5f, 0.3f, fov, fov);
      cam.type = (rr_camera_type)type;
      int w = type == RR_CAMERA_CUBE ? 64 : 56, h = 48;
      rr_frame *ref = test_render(dev, s, &cam, RR_METHOD_RC, 2, w, h, 0);
      if (!ref) continue;
      char what[256];
      snprintf(what, sizeof what, "%s view %d, %s camera", name, v, rr_camera_name(type));
      for (size_t m = 0; m < sizeof methods3d / sizeof methods3d[0]; m++) {
        int threads = test_threads[(v + type + m) % TEST_NTHREADS];
        rr_frame *f = test_render(dev, s, &cam, methods3d[m], threads, w, h, 0);
        if (!f) continue;
        int d = test_frames_differ(ref, f);
        CHECK(d == 0, "%s: %s on %d threads differs from rc at %d samples", what, rr_method_name(methods3d[m]),
              threads, d);
        if (type == RR_CAMERA_PARABOLIC || type == RR_CAMERA_LATLONG || type == RR_CAMERA_FISHEYE)
          bins += f->stats.bins, empty += f->stats.bins_empty;
        rr_frame_release(f);
      }
      rr_frame_release(ref);
    }
  }
  printf("%s: binning of the polar views refined %llu bins, %llu (%.1f%%) without the triangle\n", name,
         (unsigned long long)bins, (unsigned long long)empty, bins ? 100.0 * empty / bins : 0.0);
  rr_scene_release(s);
}

/* The cube's faces against six perspective renders of 90° at the same samples. */
static void check_cube(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "rooms:2", &s) != RR_OK) return;
  vec3 eye = v3(3.3f, 1.4f, 4.1f), f = v3(1, 0, 0), u = v3(0, 1, 0);
  rr_camera cube = test_camera(RR_CAMERA_CUBE, eye, v3_add(eye, f), 90);
  const int F = 48;
  rr_frame *cf = test_render(dev, s, &cube, RR_METHOD_3DR_FULL, 2, 4 * F, 3 * F, 0);
  /* faces of the cross: (col, row, forward, up) in the camera basis right = f × u */
  vec3 r = v3_cross(f, u);
  struct {
    int col, row;
    vec3 fwd, up;
  } faces[6] = {{1, 1, f, u}, {2, 1, r, u}, {3, 1, v3_neg(f), u}, {0, 1, v3_neg(r), u},
                {1, 0, u, v3_neg(f)}, {1, 2, v3_neg(u), f}};
  int same = 0, total = 0, depth_ok = 0, both = 0;
  for (int k = 0; k < 6 && cf; k++) {
    rr_camera p = test_camera(RR_CAMERA_PERSPECTIVE, eye, v3_add(eye, faces[k].fwd), 90);
    memcpy(p.up, &faces[k].up, 12);
    rr_frame *pf = test_render(dev, s, &p, RR_METHOD_3DR_BB, 1, F, F, 0);
    if (!pf) continue;
    for (int y = 0; y < F; y++)
      for (int x = 0; x < F; x++) {
        size_t kc = (size_t)(faces[k].row * F + y) * 4 * F + faces[k].col * F + x, kp = (size_t)y * F + x;
        total++;
        same += cf->vb.id[kc] == pf->vb.id[kp];
        if (cf->vb.id[kc] != RR_MISS && cf->vb.id[kc] == pf->vb.id[kp]) {
          both++;
          /* both cubes' face rays are fwd + a·right + b·up with the same length */
          depth_ok += fabsf(cf->vb.t[kc] - pf->vb.t[kp]) <= 1e-4f * pf->vb.t[kp];
        }
      }
    rr_frame_release(pf);
  }
  printf("cube faces vs six perspective renders: %d of %d ids agree, %d of %d depths within 1e-4\n", same, total,
         depth_ok, both);
  CHECK(total == 6 * F * F && same >= total * 0.998, "cube faces: %d of %d ids agree", same, total);
  CHECK(depth_ok >= both * 0.999, "cube faces: %d of %d depths agree", depth_ok, both);
  rr_frame_release(cf);
  rr_scene_release(s);
}

/* The cube in one pass: from the root (3dr-bb, 3dr-bin), S is once per triangle
 * whose corner rectangle meets a face (the union over the faces, fewer than the
 * sum when triangles straddle an edge of the cube); by frusta (3dr-fc, 3dr-fs,
 * 3dr-full), which cull some, at most that, the faces sharing each triangle's eye
 * part (tri_eyes); face by face they set up 429 and 965 here. The frame is
 * rc-bvh's, byte for byte, on 1, 2 and 8 threads, with one sample position and
 * with four. */
static void check_cube_setups(rr_device *dev) {
  rr_scene *s;
  if (rr_scene_load(dev, "rooms:2", &s) != RR_OK) return;
  const int F = 40;
  rr_camera cube = test_camera(RR_CAMERA_CUBE, v3(3.3f, 1.4f, 4.1f), v3(4.1f, 1.1f, 3.3f), 90);
  camera c;
  CHECK(rr_cam_setup(dev, &cube, 4 * F, 3 * F, &c) == RR_OK, "cube camera");
  uint8_t *met = malloc(s->ntris);
  tri_bound *b = malloc(s->ntris * sizeof *b);
  const float pos[4][2] = {{0.5f, 0.5f}, {0.125f, 0.375f}, {0.875f, 0.625f}, {0.375f, 0.875f}};
  uint64_t sum = 0, unis[5] = {0};
  for (int ns = 1; ns <= 4; ns += 3) { /* the triangles whose rectangle at some position meets a face */
    memset(met, 0, s->ntris);
    for (int f = 0; f < 6; f++) {
      camera fc;
      rr_cam_cube_face(&c, f, &fc);
      uint32_t n = rr_tri_corner_bounds_at(s, 0, NULL, s->ntris, &fc, ns, pos, false, b);
      for (uint32_t k = 0; k < n; k++) unis[ns] += !met[b[k].id], met[b[k].id] = 1;
      sum += ns == 1 ? n : 0;
    }
  }
  const uint64_t uni = unis[1];
  rr_cam_release(&c);
  free(met), free(b);
  for (int ns = 1; ns <= 4; ns += 3) {
    rr_render_options o = test_pattern(RR_METHOD_RC_BVH, 4 * F, 3 * F, 2, ns, pos);
    rr_frame *ref = test_render_opt(dev, s, &cube, &o);
    const rr_method cms[] = {RR_METHOD_3DR_BB, RR_METHOD_3DR_BIN, RR_METHOD_3DR_FC, RR_METHOD_3DR_FS, RR_METHOD_3DR_FULL};
    for (int m = 0; m < 5 && ref; m++) {
      char what[64];
      o.method = cms[m];
      snprintf(what, sizeof what, "cube, %s, %d position(s)", rr_method_name(o.method), ns);
      rr_frame *f = test_render_threads(dev, s, &cube, &o, ref, what);
      if (!f) continue;
      printf("%s: S = %llu; %llu triangles meet a face\n", what, (unsigned long long)f->stats.setups,
             (unsigned long long)unis[ns]);
      CHECK(m < 2 ? f->stats.setups == unis[ns] : f->stats.setups <= unis[ns],
            "%s: S = %llu, triangles that meet a face %llu", what, (unsigned long long)f->stats.setups,
            (unsigned long long)unis[ns]);
      /* walls cross the eye plane of the faces: clipped to their edge lines, they
       * leave few bins refined for nothing (62.7% of 1845 before, 9.1% of 758) */
      if (m == 1 && ns == 1)
        CHECK(f->stats.bins && f->stats.bins_empty * 4 < f->stats.bins, "%s: %llu of %llu bins refined empty", what,
              (unsigned long long)f->stats.bins_empty, (unsigned long long)f->stats.bins);
      rr_frame_release(f);
    }
    rr_frame_release(ref);
  }
  printf("cube: S = %llu once per triangle, against %llu over the faces one by one\n", (unsigned long long)uni,
         (unsigned long long)sum);
  CHECK(uni < sum, "no triangle straddles a face (%llu, %llu): the view proves nothing", (unsigned long long)uni,
        (unsigned long long)sum);
  rr_scene_release(s);
}

/* The cube's shared setup (rr_tri_setup_shared): each face's setups, bit for bit,
 * those of the face alone (rr_tri_setup_planes), with and without a table of
 * eye parts (which counts those it lacked), for random selections of random
 * triangles about the eye, with corners at infinity, and of translated and turned
 * instances, in lanes and in plain code; and the cube's rays (rr_cam_ray) the
 * faces' own, bit for bit. */
static void check_shared_setup(rr_device *dev) {
  enum { NT = 96 };
  const vec3 eye = v3(0.3f, -0.2f, 0.4f);
  rr_camera cube = test_camera(RR_CAMERA_CUBE, eye, v3(1.1f, 0.1f, -0.3f), 90);
  camera c, fc[6];
  const float pos[2] = {0.25f, 0.625f};
  CHECK(rr_cam_setup_at(dev, &cube, 4 * 24, 3 * 24, pos, &c) == RR_OK, "cube camera");
  for (int f = 0; f < 6; f++) rr_cam_cube_face(&c, f, &fc[f]);
  long rays = 0, ray_bad = 0;
  for (int y = 0; y < c.height; y++)
    for (int x = 0; x < c.width; x++) {
      vec3 o, d;
      const int f = rr_cam_cube_face_at(&c, x, y);
      const bool has = rr_cam_ray(&c, x, y, &o, &d);
      if (f < 0) {
        ray_bad += has;
        continue;
      }
      const vec3 e = camera_dir(&fc[f], (float)(x % c.face) + c.sx0, (float)(y % c.face) + c.sy0);
      rays++, ray_bad += !has || memcmp(&d, &e, sizeof d) != 0 || memcmp(&o, &eye, sizeof o) != 0;
    }
  CHECK(ray_bad == 0, "cube: %ld of %ld rays differ from their face's", ray_bad, rays);
  float v4[NT * 3][4], v3s[NT * 3][3], xf[3][12];
  uint32_t idx[NT * 3];
  for (int k = 0; k < NT * 3; k++) {
    const vec3 d = v3(test_randf(-1, 1), test_randf(-1, 1), test_randf(-1, 1));
    const float r = test_randf(0.2f, 4.0f), w = test_rand() % 9 == 0 && k % 3 != 0 ? 0.0f : 1.0f;
    v4[k][0] = w ? eye.x + r * d.x : d.x, v4[k][1] = w ? eye.y + r * d.y : d.y, v4[k][2] = w ? eye.z + r * d.z : d.z;
    v4[k][3] = w;
    v3s[k][0] = eye.x + r * d.x, v3s[k][1] = eye.y + r * d.y, v3s[k][2] = eye.z + r * d.z;
    idx[k] = (uint32_t)k;
  }
  for (int i = 0; i < 3; i++) /* two translations and a turn about z */
    for (int a = 0; a < 12; a++)
      xf[i][a] = a % 5 == 0 ? 1.0f : a == 3 ? 0.5f * (float)i : a == 7 ? -0.25f * (float)i : 0;
  xf[2][0] = xf[2][5] = 0.8f, xf[2][1] = -0.6f, xf[2][4] = 0.6f;
  long compared = 0, bad = 0, eyes_bad = 0;
  for (int sc = 0; sc < 2; sc++) {
    rr_scene *s = NULL;
    CHECK(rr_scene_new(dev, &s) == RR_OK, "scene");
    rr_error e = sc == 0 ? rr_scene_add_mesh4(s, &v4[0][0], NT * 3, idx, NT, NULL)
                         : rr_scene_add_instances(s, &v3s[0][0], NT * 3, idx, NT, NULL, &xf[0][0], 3);
    CHECK(e == RR_OK && rr_scene_commit(s) == RR_OK, "scene %d: %s", sc, rr_device_message(dev));
    const int n = (int)s->ntris < TRI_SHARED_MAX ? (int)s->ntris : TRI_SHARED_MAX;
    static float rec[TRI_SHARED_MAX][TRI_EYE_REC];
    static _Atomic uint32_t slot[TRI_SHARED_MAX];
    tri_eyes keep = {rec, slot, 0}; /* filled over the trials */
    memset((void *)slot, TRI_EYE_NONE, sizeof slot);
    uint32_t ids[TRI_SHARED_MAX];
    for (int i = 0; i < n; i++) ids[i] = (uint32_t)i;
    for (int trial = 0; trial < 8; trial++) {
      int32_t sel[6 * TRI_SHARED_MAX];
      int nsel[6], a = 0;
      for (int f = 0; f < 6; f++) { /* a random subset, in order (trial 0: every triangle) */
        nsel[f] = 0;
        for (int i = 0; i < n; i++)
          if (trial == 0 || test_rand() % 3 == 0) sel[a++] = i, nsel[f]++;
      }
      const bool simd = trial & 1, cull = trial & 2;
      static tri_setup got[6 * TRI_SHARED_MAX], want;
      static tri_plane gpl[6 * TRI_SHARED_MAX], wpl;
      static int face[6 * TRI_SHARED_MAX];
      rr_tri_setup_shared(s, ids, n, fc, 6, sel, nsel, cull, simd, got, sizeof *got, face, gpl, sizeof *gpl);
      /* from trial 4 on, the faces one by one through a table of eye parts
       * (rr_tri_setup_kept), in its order; each call makes those it lacks */
      for (int f = 0, k = 0; f < 6 && trial >= 4; k += nsel[f++]) {
        uint32_t fid[TRI_SHARED_MAX];
        int order[TRI_SHARED_MAX], absent = 0;
        for (int j = 0; j < nsel[f]; j++) fid[j] = ids[sel[k + j]], absent += slot[sel[k + j]] < TRI_EYE_AT;
        static tri_setup kts[TRI_SHARED_MAX];
        static tri_plane kpl[TRI_SHARED_MAX];
        int kface[TRI_SHARED_MAX];
        eyes_bad += rr_tri_setup_kept(s, &keep, fid, nsel[f], &fc[f], cull, simd, kts, kface, kpl, order) != absent;
        for (int j = 0; j < nsel[f]; j++) { /* back in the order asked */
          const int o = k + order[j];
          eyes_bad += order[j] < 0 || order[j] >= nsel[f] || kface[j] != face[o] ||
                      (face[o] != SETUP_CULLED && (memcmp(&kts[j], &got[o], sizeof *got) || memcmp(&kpl[j], &gpl[o], sizeof *gpl)));
        }
      }
      for (int f = 0, k = 0; f < 6; f++)
        for (int j = 0; j < nsel[f]; j++, k++) {
          int wface;
          memset(&want, 0, sizeof want), memset(&wpl, 0, sizeof wpl);
          rr_tri_setup_planes(s, &ids[sel[k]], 1, &fc[f], cull, !simd, &want, &wface, &wpl);
          compared++;
          bad += face[k] != wface ||
                 (wface != SETUP_CULLED && (memcmp(&got[k], &want, sizeof want) || memcmp(&gpl[k], &wpl, sizeof wpl)));
        }
    }
    rr_scene_release(s);
  }
  printf("cube: shared setups of %ld (triangle, face) pairs, %ld differ from the faces' own\n", compared, bad);
  CHECK(compared > 1000 && bad == 0, "cube: %ld of %ld shared setups differ from the faces' own", bad, compared);
  CHECK(eyes_bad == 0, "cube: %ld setups through a table of eye parts differ from the faces' own, or made another "
        "number of eye parts than it lacked", eyes_bad);
  rr_cam_release(&c);
}

int main(void) {
  rr_device *dev = rr_device_new();
  check_directions(dev);
  check_cube(dev);
  check_shared_setup(dev);
  check_cube_setups(dev);
  check_methods(dev, "demo", 2);
  check_methods(dev, "rooms:3", 2);
  const char *p = test_quick() ? NULL : test_model("stanford-bunny.obj");
  if (p) check_methods(dev, p, 1);

  /* 2D rasterization cannot draw curved views, and says which methods can. */
  rr_scene *s;
  rr_scene_load(dev, "sphere", &s);
  rr_camera cam = test_camera(RR_CAMERA_LATLONG, v3(0, 0, 0.2f), v3(0, 0, -1), 60);
  rr_render_options opt;
  rr_render_options_init(&opt);
  opt.method = RR_METHOD_2DR_BB, opt.width = 32, opt.height = 16;
  rr_frame *f = NULL;
  CHECK(rr_render(dev, s, &cam, &opt, &f) == RR_ERROR_UNSUPPORTED && strstr(rr_device_message(dev), "3dr-full"),
        "2dr-bb with a lat-long camera: %s", rr_device_message(dev));
  rr_frame_release(f);
  rr_scene_release(s);
  rr_device_release(dev);
  return test_done();
}
