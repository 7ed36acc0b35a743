/* The method table and the visibility pass (rr_render): a frame from a scene, a camera and options. */
#define _POSIX_C_SOURCE 200809L /* strtok_r */

#include "vis/vis.h"
#include "core/simd.h"

#include <stdio.h>
#include <stdlib.h>
#include <stddef.h>
#include <string.h>

/* ---- names ---------------------------------------------------------------- */

/* The 3D rasterization methods are configurations of one traversal (paper
 * sect. 5); the others have loops of their own around the same sample test.
 * A method without either is one this build does not have yet. all_samples: it
 * draws every sample position of a pattern in one pass (render_ctx). */
static const struct {
  const char *name;
  vis_method_fn fn;
  oracles o;
  bool all_samples;
} methods[RR_METHOD_COUNT] = {
    [RR_METHOD_RC] = {"rc", rr_vis_rc, {0}, false},
    [RR_METHOD_RC_BVH] = {"rc-bvh", rr_vis_rc_bvh, {0}, false},
    [RR_METHOD_RC_PACKET] = {"rc-packet", rr_vis_rc_packet, {0}, false},
    [RR_METHOD_2DR_BB] = {"2dr-bb", rr_vis_2dr_bb, {0}, true},
    [RR_METHOD_2DR_BIN] = {"2dr-bin", rr_vis_2dr_bin, {0}, true},
    [RR_METHOD_3DR_BB] = {"3dr-bb", rr_vis_traverse, {.bin_size = 64, .bin_min = 4}, true},
    [RR_METHOD_3DR_BIN] = {"3dr-bin", rr_vis_traverse, {.binning = 1, .early_z = 1, .bin_size = 64, .bin_min = 4}, true},
    [RR_METHOD_3DR_FC] = {"3dr-fc", rr_vis_traverse,
                          {.frustum_size = 256, .leaves = 1, .cull_outside = 1, .binning = 1, .early_z = 1,
                           .bin_size = 64, .bin_min = 4},
                          true},
    [RR_METHOD_3DR_FS] = {"3dr-fs", rr_vis_traverse,
                          {.leaves = 1, .cull_outside = 1, .cull_occluded = 1, .split_min = 8, .split_ratio = 0.25f,
                           .bin_size = 64, .bin_min = 4},
                         true},
    [RR_METHOD_3DR_FULL] = {"3dr-full", rr_vis_traverse,
                            {.leaves = 1, .cull_outside = 1, .cull_occluded = 1, .split_min = 8, .split_ratio = 0.25f,
                             .binning = 1, .early_z = 1, .bin_size = 64, .bin_min = 4},
                            true},
};

/* Applies "key=value,..." to a method's oracles. */
static rr_error parse_oracles(rr_device *dev, const char *spec, oracles *o) {
  char buf[512];
  if (strlen(spec) >= sizeof buf) return rr_fail(dev, RR_ERROR_ARGUMENT, "oracle settings too long");
  strcpy(buf, spec);
  char *save = NULL;
  for (char *kv = strtok_r(buf, ",", &save); kv; kv = strtok_r(NULL, ",", &save)) {
    char *eq = strchr(kv, '=');
    if (!eq || eq == kv || !eq[1]) return rr_fail(dev, RR_ERROR_ARGUMENT, "bad oracle setting '%s' (expected key=value)", kv);
    *eq = 0;
    char *end;
    double v = strtod(eq + 1, &end);
    if (*end || !isfinite(v)) return rr_fail(dev, RR_ERROR_ARGUMENT, "bad value '%s' for oracle '%s'", eq + 1, kv);
    /* each key, where it goes and its range: 0|1 flags, whole counts, one ratio */
    static const struct {
      const char *key;
      size_t offset;
      char kind; /* 'b' bool flag, 'i' int, 'f' float */
      double lo, hi;
    } keys[] = {{"frustum", offsetof(oracles, frustum_size), 'i', 0, 65536},
                {"leaves", offsetof(oracles, leaves), 'b', 0, 1},
                {"outside", offsetof(oracles, cull_outside), 'b', 0, 1},
                {"occluded", offsetof(oracles, cull_occluded), 'b', 0, 1},
                {"split", offsetof(oracles, split_min), 'i', 0, 65536},
                {"split-ratio", offsetof(oracles, split_ratio), 'f', 0, 65536},
                {"binning", offsetof(oracles, binning), 'b', 0, 1},
                {"early-z", offsetof(oracles, early_z), 'b', 0, 1},
                {"bin", offsetof(oracles, bin_size), 'i', 1, 65536},
                {"bin-min", offsetof(oracles, bin_min), 'i', 1, 65536}};
    size_t k = 0;
    while (k < sizeof keys / sizeof *keys && strcmp(kv, keys[k].key) != 0) k++;
    if (k == sizeof keys / sizeof *keys)
      return rr_fail(dev, RR_ERROR_ARGUMENT,
                     "unknown oracle '%s' (expected frustum, leaves, outside, occluded, split, split-ratio, binning, "
                     "early-z, bin or bin-min)", kv);
    bool whole = keys[k].kind != 'f';
    if (!(v >= keys[k].lo && v <= keys[k].hi) || (whole && v != floor(v)))
      return keys[k].kind == 'b'
                 ? rr_fail(dev, RR_ERROR_ARGUMENT, "bad value '%s' for oracle '%s' (expected 0 or 1)", eq + 1, kv)
                 : rr_fail(dev, RR_ERROR_ARGUMENT, "bad value '%s' for oracle '%s' (expected %s %g..%g)", eq + 1, kv,
                           whole ? "a whole number" : "a number", keys[k].lo, keys[k].hi);
    char *field = (char *)o + keys[k].offset;
    if (keys[k].kind == 'b') *(bool *)field = v != 0;
    else if (whole) *(int *)field = (int)v;
    else *(float *)field = (float)v;
  }
  if (o->split_min && o->split_min < 8) o->split_min = 8; /* frusta split down to the z tiles */
  return RR_OK;
}

int rr_method_from_name(const char *name) {
  if (name && strcmp(name, "auto") == 0) return RR_METHOD_AUTO;
  for (int m = 0; name && m < RR_METHOD_COUNT; m++)
    if (strcmp(methods[m].name, name) == 0) return m;
  return -1;
}

const char *rr_method_name(int m) {
  return m == RR_METHOD_AUTO ? "auto" : m >= 0 && m < RR_METHOD_COUNT ? methods[m].name : NULL;
}

static int name_index(const char *const *names, int n, const char *name) {
  for (int i = 0; name && i < n; i++)
    if (strcmp(names[i], name) == 0) return i;
  return -1;
}

int rr_shade_from_name(const char *name) {
  static const char *const names[RR_SHADE_COUNT] = {"lambert", "id", "normal", "depth", "heat-evals", "heat-nodes", "lit"};
  return name_index(names, RR_SHADE_COUNT, name);
}

int rr_aov_from_name(const char *name) {
  static const char *const names[RR_AOV_COUNT] = {"depth", "id",       "normal",    "bary",         "evals",      "nodes",
                                                  "mesh",  "material", "coverage", "sample-id", "sample-depth", "sample-mesh",
                                                  "uv",    "uv-deriv", "albedo", "direct", "reflection", "shadow",
                                                  "emission", "z-depth", "shadow-lights", "instance"};
  return name_index(names, RR_AOV_COUNT, name);
}

/* ---- rendering ------------------------------------------------------------ */

void rr_render_options_init(rr_render_options *opt) {
  if (!opt) return;
  *opt = (rr_render_options){.method = RR_METHOD_3DR_BB, .width = 1024, .height = 768, .threads = 0, .samples = 1};
  opt->sample_pos[0][0] = opt->sample_pos[0][1] = 0.5f;
}

static void visbuf_free(visbuf *vb) {
  free(vb->id), free(vb->t), free(vb->l1), free(vb->l2);
  memset(vb, 0, sizeof *vb);
}

/* Clears n samples, sixteen a copy (16 samples at 1024² are 256 MB; glibc's memset
 * of that size is a rep stosb, which callgrind counts a byte at a time): with
 * AVX2, two stores an array. */
static inline __attribute__((always_inline)) void visbuf_clear(visbuf *vb, size_t n) {
  typedef uint32_t v8u __attribute__((vector_size(32)));
  typedef float v8f __attribute__((vector_size(32)));
  const v8u miss = (v8u){0} + RR_MISS;
  const v8f far = (v8f){0} + INFINITY, zero = {0};
  uint32_t *id = vb->id;
  float *t = vb->t, *l1 = vb->l1, *l2 = vb->l2;
  size_t k = 0;
  for (; k + 16 <= n; k += 16)
    for (int h = 0; h < 16; h += 8)
      memcpy(id + k + h, &miss, 32), memcpy(t + k + h, &far, 32), memcpy(l1 + k + h, &zero, 32),
          memcpy(l2 + k + h, &zero, 32);
  for (; k < n; k++) id[k] = RR_MISS, t[k] = INFINITY, l1[k] = l2[k] = 0;
}
#ifdef RR_SIMD_X86
RR_TARGET_AVX2 static void visbuf_clear_avx2(visbuf *vb, size_t n) { visbuf_clear(vb, n); }
#endif

/* visbuf_clear with AVX2 where the processor has it. */
static void visbuf_clear_any(visbuf *vb, size_t n) {
#ifdef RR_SIMD_X86
  if (__builtin_cpu_supports("avx2")) {
    visbuf_clear_avx2(vb, n);
    return;
  }
#endif
  visbuf_clear(vb, n);
}

/* A buffer of w × h pixels of `samples` samples each (vis.h: a pixel's side by side). */
static bool visbuf_alloc(visbuf *vb, int w, int h, int samples) {
  size_t n = (size_t)w * h * samples;
  vb->width = w, vb->height = h, vb->ns = samples;
  vb->id = rr_alloc_large(n * sizeof *vb->id);
  vb->t = rr_alloc_large(n * sizeof *vb->t);
  vb->l1 = rr_alloc_large(n * sizeof *vb->l1);
  vb->l2 = rr_alloc_large(n * sizeof *vb->l2);
  if (!vb->id || !vb->t || !vb->l1 || !vb->l2) {
    visbuf_free(vb);
    return false;
  }
  visbuf_clear_any(vb, n);
  return true;
}

/* auto: the method its model (vis/auto.c) predicts fastest; where the model is unsure
 * and the frames to come repay it, the fastest of the close candidates in a trial, a
 * verdict the device keeps for the same view. */
static bool same_view(const struct auto_choice *a, const struct auto_choice *b) {
  return a->scene == b->scene && a->bvh == b->bvh && a->ntris == b->ntris &&
         memcmp(&a->cam, &b->cam, sizeof a->cam) == 0 && a->width == b->width && a->height == b->height &&
         a->threads == b->threads && a->cull == b->cull && a->scalar == b->scalar;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Renders the view with cand[0..n-1] in AUTO_TRIAL_ROUNDS interleaved rounds (each round
 * renders every candidate once, in turn, so that a change of load hits them alike);
 * the lowest median decides. One thread is timed by the process's CPU time, which
 * another process's load does not inflate; more threads by the wall clock (CPU time
 * would hide a method's serial parts). Writes "trial: <median ms of each> ms at WxH;
 * " and then `model` to why. */
static rr_error trial(rr_device *dev, const rr_scene *scene, const rr_camera *cam, const rr_render_options *t,
                      const rr_method *cand, int n, const char *model, int *best, char why[AUTO_WHY]) {
  rr_render_options o = *t;
  double ms[AUTO_NCAND][AUTO_TRIAL_ROUNDS];
  for (int r = 0; r < AUTO_TRIAL_ROUNDS; r++)
    for (int i = 0; i < n; i++) {
      rr_frame *f;
      o.method = cand[i];
      rr_error e = rr_render(dev, scene, cam, &o, &f);
      if (e) return e;
      ms[i][r] = f->stats.threads == 1 ? f->stats.cpu_ms : f->stats.frame_ms;
      rr_frame_release(f);
    }
  double best_ms = INFINITY;
  char got[96] = "";
  for (int i = 0; i < n; i++) {
    qsort(ms[i], AUTO_TRIAL_ROUNDS, sizeof ms[i][0], cmp_double);
    double med = ms[i][AUTO_TRIAL_ROUNDS / 2];
    size_t len = strlen(got);
    snprintf(got + len, sizeof got - len, "%s%s %.3g", i ? ", " : "", rr_method_name(cand[i]), med);
    if (med < best_ms) best_ms = med, *best = cand[i];
  }
  snprintf(why, AUTO_WHY, "trial: %s ms at %dx%d; %.140s", got, t->width, t->height, model);
  return RR_OK;
}

static rr_error render_auto(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                            const rr_render_options *opt, rr_frame **out) {
  if (opt->oracles && *opt->oracles)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "oracles apply to the 3dr methods: choose one instead of auto");
  struct auto_choice key = {.scene = scene, .bvh = scene->bvh, .ntris = scene->ntris, .cam = *cam,
                            .width = opt->width, .height = opt->height, .threads = opt->threads,
                            .cull = opt->cull_backfaces != 0, .scalar = opt->scalar != 0};
  struct auto_choice *last = dev ? &dev->auto_choice : NULL;
  rr_render_options t = *opt;
  char why[AUTO_WHY];
  if (last && last->scene && same_view(last, &key)) { /* a trial's verdict for this view */
    t.method = (rr_method)last->method;
    snprintf(why, sizeof why, "%s", last->why);
  } else {
    rr_method near[AUTO_NCAND];
    int close;
    bool repays;
    auto_prediction p;
    rr_error e = rr_auto_choose(dev, scene, cam, opt, &p, near, &close, &repays);
    if (e) return e;
    int w = snprintf(why, sizeof why, "model:");
    for (int i = 0; i < AUTO_NCAND && w >= 0 && (size_t)w < sizeof why; i++)
      w += snprintf(why + w, sizeof why - w, "%s %s %.3g", i ? "," : "", rr_method_name(p.method[i]), p.ms[i]);
    if (w >= 0 && (size_t)w < sizeof why) snprintf(why + w, sizeof why - w, " ms predicted (%s)", p.figures);
    t.method = near[0];
    if (repays) {
      int best = near[0];
      char model[AUTO_WHY];
      memcpy(model, why, sizeof model);
      rr_render_options small = rr_auto_trial_options(cam, opt);
      if ((e = trial(dev, scene, cam, &small, near, close, model, &best, why))) return e;
      t.method = (rr_method)best;
      if (last) {
        key.method = best;
        snprintf(key.why, sizeof key.why, "%s", why);
        *last = key;
      }
    }
  }
  rr_error e = rr_render(dev, scene, cam, &t, out);
  if (!e) snprintf((*out)->stats.why, sizeof (*out)->stats.why, "%s", why);
  return e;
}

/* A method's passes over ctx: one for every position, or one per position, each
 * writing its own sample of every pixel (S grows with N). */
static rr_error run_passes(rr_device *dev, rr_method m, render_ctx ctx, progress_span whole) {
  const int ns = ctx.samples;
  if (methods[m].all_samples || ns == 1) {
    ctx.progress = whole;
    return methods[m].fn(dev, &ctx);
  }
  const camera *cams = ctx.cams;
  visbuf *vb = ctx.vb;
  /* each position into a buffer of one sample, then copied into that sample of
   * every pixel (the methods index a buffer of one sample per pixel) */
  visbuf one;
  if (!visbuf_alloc(&one, vb->width, vb->height, 1))
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d visibility buffer", vb->width, vb->height);
  const size_t npix = (size_t)vb->width * vb->height;
  rr_error e = RR_OK;
  for (int s = 0; s < ns && !e; s++) {
    ctx.progress = rr_progress_part(&whole, (double)s / ns, (double)(s + 1) / ns);
    ctx.cam = ctx.cams = &cams[s];
    ctx.samples = 1;
    ctx.vb = &one;
    if (s) visbuf_clear(&one, npix);
    if ((e = methods[m].fn(dev, &ctx))) break;
    for (size_t k = 0; k < npix; k++) {
      const size_t o = k * ns + s;
      vb->id[o] = one.id[k], vb->t[o] = one.t[k], vb->l1[o] = one.l1[k], vb->l2[o] = one.l2[k];
    }
  }
  visbuf_free(&one);
  return e;
}

/* The cube camera: its six faces are perspective cameras (camera/camera.h), each
 * drawn into a buffer of its own and copied into the cross. The 3D rasterizing
 * methods draw the six in one pass, which sets each triangle up once for the eye
 * (vis/traverse.c); the ray casters run once per face. */
static rr_error render_cube(rr_device *dev, rr_method m, render_ctx ctx, progress_span whole) {
  const camera *cube = ctx.cam;
  visbuf *cross = ctx.vb;
  const int ns = ctx.samples, F = cube->face, W = cross->width;
  const size_t FF = (size_t)F * F;
  camera fc[6 * RR_MAX_SAMPLES];
  for (int f = 0; f < 6; f++)
    for (int s = 0; s < ns; s++) rr_cam_cube_face(&ctx.cams[s], f, &fc[f * ns + s]);
  /* the faces' buffers from the device's scratch, kept from frame to frame: no
   * fresh pages to fault in and zero every frame (six separate renders' buffers
   * are small enough to come back from the heap) */
  const size_t nf = 6 * FF * ns, part = (nf * sizeof(float) + 63) / 64 * 64;
  rr_buf fbuf = rr_scratch_take(dev, SCRATCH_CUBE, 4 * part);
  float *heat = NULL;
  if (!fbuf.p || (ctx.heat_e && !(heat = calloc(12 * FF, sizeof *heat)))) {
    rr_scratch_give(dev, fbuf);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a cube camera's faces of %dx%d", F, F);
  }
  char *fp = fbuf.p;
  visbuf fvb = {F, 6 * F, (uint32_t *)fp, (float *)(fp + part), (float *)(fp + 2 * part), (float *)(fp + 3 * part), ns},
         faces[6];
  visbuf_clear_any(&fvb, nf);
  /* face f: F × F pixels of ns samples, after the f before it */
  for (int f = 0; f < 6; f++) {
    const size_t o = (size_t)f * FF * ns;
    faces[f] = (visbuf){F, F, fvb.id + o, fvb.t + o, fvb.l1 + o, fvb.l2 + o, ns};
  }
  rr_error e = RR_OK;
  if (methods[m].fn == rr_vis_traverse) {
    ctx.faces = 6, ctx.face_cams = fc, ctx.face_vb = faces;
    ctx.face_heat_e = heat, ctx.face_heat_n = heat ? heat + 6 * FF : NULL;
    ctx.cam = ctx.cams = fc, ctx.vb = &faces[0];
    e = run_passes(dev, m, ctx, whole);
  } else {
    for (int f = 0; f < 6 && !e; f++) {
      render_ctx sub = ctx;
      sub.cam = sub.cams = &fc[f * ns], sub.vb = &faces[f];
      sub.heat_e = heat ? heat + f * FF : NULL, sub.heat_n = heat ? heat + (6 + f) * FF : NULL;
      e = run_passes(dev, m, sub, rr_progress_part(&whole, f / 6.0, (f + 1) / 6.0));
    }
  }
  for (int f = 0; f < 6 && !e; f++) {
    int x0, y0;
    rr_cam_cube_face_origin(cube, f, &x0, &y0);
    const visbuf *from = &faces[f];
    for (int y = 0; y < F; y++) { /* a row's pixels with their samples */
      size_t k = ((size_t)(y0 + y) * W + x0) * ns, j = (size_t)y * F * ns, n = (size_t)F * ns;
      memcpy(cross->id + k, from->id + j, n * sizeof *cross->id), memcpy(cross->t + k, from->t + j, n * sizeof *cross->t);
      memcpy(cross->l1 + k, from->l1 + j, n * sizeof *cross->l1), memcpy(cross->l2 + k, from->l2 + j, n * sizeof *cross->l2);
    }
    for (int y = 0; heat && y < F; y++)
      for (int x = 0; x < F; x++) {
        size_t k = (size_t)(y0 + y) * W + x0 + x, j = f * FF + (size_t)y * F + x;
        ctx.heat_e[k] += heat[j], ctx.heat_n[k] += heat[6 * FF + j];
      }
  }
  rr_scratch_give(dev, fbuf);
  free(heat);
  return e;
}

rr_error rr_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                   const rr_render_options *opt, rr_frame **out) {
  if (!scene || !cam || !opt || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_render: NULL argument");
  *out = NULL;
  if (opt->method != RR_METHOD_AUTO && ((int)opt->method < 0 || opt->method >= RR_METHOD_COUNT))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown method %d", (int)opt->method);
  if (opt->threads < 0 || opt->threads > RR_MAX_THREADS)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad thread count %d (0 for all cores, at most %d)", opt->threads,
                   RR_MAX_THREADS);
  if (opt->samples < 1 || opt->samples > RR_MAX_SAMPLES)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad sample count %d (1..%d per pixel)", opt->samples, RR_MAX_SAMPLES);
  for (int s = 0; s < opt->samples; s++) { /* every position, before any work */
    const float *p = opt->sample_pos[s];
    if (!(p[0] >= 0.0f && p[0] < 1.0f && p[1] >= 0.0f && p[1] < 1.0f))
      return rr_fail(dev, RR_ERROR_ARGUMENT, "bad position (%g, %g) of sample %d (each in [0, 1))", (double)p[0],
                     (double)p[1], s);
  }
  if ((int)opt->aa < 0 || opt->aa >= RR_AA_MODE_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown AA mode %d", (int)opt->aa);
  if (opt->aa == RR_AA_CSAA && (opt->aa_stored < 1 || opt->aa_stored > opt->samples))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad stored sample count %d for csaa (1..%d, the samples)", opt->aa_stored,
                   opt->samples);
  if (opt->method == RR_METHOD_AUTO) return render_auto(dev, scene, cam, opt, out);
  oracles o = methods[opt->method].o;
  if (opt->oracles && *opt->oracles) {
    if (methods[opt->method].fn != rr_vis_traverse)
      return rr_fail(dev, RR_ERROR_ARGUMENT, "oracles apply to the 3dr methods, not to '%s'", methods[opt->method].name);
    rr_error e = parse_oracles(dev, opt->oracles, &o);
    if (e) return e;
  }
  if (!methods[opt->method].fn)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED, "method '%s' is not available in this build", methods[opt->method].name);
  if ((opt->method == RR_METHOD_2DR_BB || opt->method == RR_METHOD_2DR_BIN) && cam->type != RR_CAMERA_PERSPECTIVE &&
      cam->type != RR_CAMERA_ORTHOGRAPHIC)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED,
                   "method '%s' projects onto a plane and cannot render a %s camera; the 3D methods can (rc, rc-bvh, "
                   "rc-packet, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full)",
                   methods[opt->method].name, rr_camera_name(cam->type));
  /* One camera per sample position: a method that takes them all at once gets
   * them together, any other runs once per position (render_ctx in vis.h). */
  camera cams[RR_MAX_SAMPLES];
  int ncams = 0;
  rr_error e = RR_OK;
  const int threads = opt->threads ? opt->threads : rr_cpu_count();
  for (; ncams < opt->samples && !e; ncams++)
    e = rr_cam_setup_threads(dev, cam, opt->width, opt->height, opt->sample_pos[ncams], threads, &cams[ncams]);
  if (e) ncams--;
  rr_frame *f = e ? NULL : calloc(1, sizeof *f);
  size_t npix = (size_t)opt->width * opt->height;
  if (!e && (!f || !visbuf_alloc(&f->vb, opt->width, opt->height, opt->samples) ||
             (opt->heat && (!(f->heat_e = calloc(npix, sizeof(float))) || !(f->heat_n = calloc(npix, sizeof(float)))))))
    e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d visibility buffer", opt->width, opt->height);
  if (e) {
    rr_frame_release(f);
    while (ncams > 0) rr_cam_release(&cams[--ncams]);
    return e;
  }
  f->method = opt->method;
  f->samples = opt->samples;
  memcpy(f->sample_pos, opt->sample_pos, sizeof f->sample_pos);
  f->aa = opt->aa, f->aa_stored = opt->aa == RR_AA_CSAA ? opt->aa_stored : 0;
  render_ctx ctx = {.scene = scene,
                    .cam = &cams[0],
                    .cams = cams,
                    .samples = opt->samples,
                    .opt = opt,
                    .threads = threads,
                    .vb = &f->vb,
                    .stats = &f->stats,
                    .heat_e = f->heat_e,
                    .heat_n = f->heat_n,
                    .oracles = &o};
  f->stats.threads = ctx.threads;
  f->stats.method = opt->method;
  double t0 = rr_now_ms(), c0 = rr_cpu_ms();
  progress_span whole = {dev, RR_PROGRESS_RENDER, 0, 1};
  rr_progress(&whole, 0);
  e = cam->type == RR_CAMERA_CUBE ? render_cube(dev, opt->method, ctx, whole) : run_passes(dev, opt->method, ctx, whole);
  f->stats.frame_ms = rr_now_ms() - t0, f->stats.cpu_ms = rr_cpu_ms() - c0;
  while (ncams > 0) rr_cam_release(&cams[--ncams]);
  /* The methods write triangle indices; users see ids (scene.h), which differ after
   * a dropped face. Mapped once here, outside every method and the timed pass. */
  if (!e && scene->file_id) {
    size_t n = npix * opt->samples;
    if (!(f->ids = malloc(n * sizeof *f->ids)))
      e = rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d visibility buffer", opt->width, opt->height);
    for (size_t k = 0; !e && k < n; k++) f->ids[k] = scene_face_id(scene, f->vb.id[k]);
  }
  if (e) {
    rr_frame_release(f);
    return e;
  }
  rr_progress(&whole, 1);
  *out = f;
  return rr_ok(dev);
}

void rr_frame_release(rr_frame *f) {
  if (!f) return;
  visbuf_free(&f->vb);
  free(f->ids);
  free(f->heat_e), free(f->heat_n);
  free(f);
}

rr_error rr_frame_get_stats(const rr_frame *f, rr_stats *stats) {
  if (!f || !stats) return RR_ERROR_ARGUMENT;
  *stats = f->stats;
  return RR_OK;
}

rr_error rr_frame_get_size(const rr_frame *f, int *w, int *h) {
  if (!f || !w || !h) return RR_ERROR_ARGUMENT;
  *w = f->vb.width, *h = f->vb.height;
  return RR_OK;
}

rr_error rr_frame_get_sample_pos(const rr_frame *f, float pos[RR_MAX_SAMPLES][2]) {
  if (!f || !pos) return RR_ERROR_ARGUMENT;
  memcpy(pos, f->sample_pos, sizeof f->sample_pos);
  return RR_OK;
}

rr_error rr_frame_get_samples(const rr_frame *f, int *samples) {
  if (!f || !samples) return RR_ERROR_ARGUMENT;
  *samples = f->samples;
  return RR_OK;
}

const uint32_t *rr_frame_ids(const rr_frame *f) { return !f ? NULL : f->ids ? f->ids : f->vb.id; }
const float *rr_frame_t(const rr_frame *f) { return f ? f->vb.t : NULL; }
const float *rr_frame_bary1(const rr_frame *f) { return f ? f->vb.l1 : NULL; }
const float *rr_frame_bary2(const rr_frame *f) { return f ? f->vb.l2 : NULL; }
