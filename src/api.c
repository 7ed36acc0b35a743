/* The public API's devices, errors, method table and the visibility pass. */
#include "rr.h"

#include <stdio.h>
#include <string.h>

rr_device *rr_device_new(void) { return calloc(1, sizeof(rr_device)); }

void rr_device_release(rr_device *dev) { free(dev); }

rr_error rr_device_error(const rr_device *dev) { return dev ? dev->error : RR_ERROR_ARGUMENT; }

const char *rr_device_message(const rr_device *dev) { return dev ? dev->message : "no device"; }

rr_error rr_fail(rr_device *dev, rr_error code, const char *fmt, ...) {
  if (dev) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dev->message, sizeof dev->message, fmt, ap);
    va_end(ap);
    dev->error = code;
  }
  return code;
}

rr_error rr_ok(rr_device *dev) {
  if (dev) {
    dev->error = RR_OK;
    dev->message[0] = 0;
  }
  return RR_OK;
}

/* ---- names ---------------------------------------------------------------- */

/* Every method is one traversal configuration; a NULL entry is a method this
 * build does not have yet. */
static const struct {
  const char *name;
  vis_method_fn fn;
} methods[RR_METHOD_COUNT] = {
    [RR_METHOD_RC] = {"rc", vis_rc},
    [RR_METHOD_RC_BVH] = {"rc-bvh", NULL},
    [RR_METHOD_RC_PACKET] = {"rc-packet", NULL},
    [RR_METHOD_2DR_BB] = {"2dr-bb", NULL},
    [RR_METHOD_2DR_BIN] = {"2dr-bin", NULL},
    [RR_METHOD_3DR_BB] = {"3dr-bb", vis_3dr_bb},
    [RR_METHOD_3DR_BIN] = {"3dr-bin", NULL},
    [RR_METHOD_3DR_FC] = {"3dr-fc", NULL},
    [RR_METHOD_3DR_FS] = {"3dr-fs", NULL},
    [RR_METHOD_3DR_FULL] = {"3dr-full", NULL},
};

int rr_method_from_name(const char *name) {
  for (int m = 0; name && m < RR_METHOD_COUNT; m++)
    if (strcmp(methods[m].name, name) == 0) return m;
  return -1;
}

const char *rr_method_name(int m) { return m >= 0 && m < RR_METHOD_COUNT ? methods[m].name : NULL; }

static int name_index(const char *const *names, int n, const char *name) {
  for (int i = 0; name && i < n; i++)
    if (strcmp(names[i], name) == 0) return i;
  return -1;
}

int rr_shade_from_name(const char *name) {
  static const char *const names[RR_SHADE_COUNT] = {"lambert", "id", "normal", "depth"};
  return name_index(names, RR_SHADE_COUNT, name);
}

int rr_aov_from_name(const char *name) {
  static const char *const names[RR_AOV_COUNT] = {"depth", "id", "normal", "bary"};
  return name_index(names, RR_AOV_COUNT, name);
}

/* ---- rendering ------------------------------------------------------------ */

void rr_render_options_init(rr_render_options *opt) {
  if (!opt) return;
  *opt = (rr_render_options){.method = RR_METHOD_3DR_BB, .width = 1024, .height = 768, .threads = 0};
}

static void visbuf_free(visbuf *vb) {
  free(vb->id), free(vb->t), free(vb->l1), free(vb->l2);
  memset(vb, 0, sizeof *vb);
}

static bool visbuf_alloc(visbuf *vb, int w, int h) {
  size_t n = (size_t)w * h;
  vb->width = w, vb->height = h;
  vb->id = malloc(n * sizeof *vb->id);
  vb->t = malloc(n * sizeof *vb->t);
  vb->l1 = malloc(n * sizeof *vb->l1);
  vb->l2 = malloc(n * sizeof *vb->l2);
  if (!vb->id || !vb->t || !vb->l1 || !vb->l2) {
    visbuf_free(vb);
    return false;
  }
  for (size_t k = 0; k < n; k++) vb->id[k] = RR_MISS, vb->t[k] = INFINITY, vb->l1[k] = vb->l2[k] = 0;
  return true;
}

rr_error rr_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                   const rr_render_options *opt, rr_frame **out) {
  if (!scene || !cam || !opt || !out) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_render: NULL argument");
  *out = NULL;
  if ((int)opt->method < 0 || opt->method >= RR_METHOD_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown method %d", (int)opt->method);
  if (opt->threads < 0 || opt->threads > 256)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad thread count %d (0 for all cores, at most 256)", opt->threads);
  if (!methods[opt->method].fn)
    return rr_fail(dev, RR_ERROR_UNSUPPORTED, "method '%s' is not available in this build", methods[opt->method].name);
  camera c;
  rr_error e = camera_setup(dev, cam, opt->width, opt->height, &c);
  if (e) return e;
  rr_frame *f = calloc(1, sizeof *f);
  if (!f || !visbuf_alloc(&f->vb, opt->width, opt->height)) {
    free(f);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for a %dx%d visibility buffer", opt->width, opt->height);
  }
  f->method = opt->method;
  render_ctx ctx = {.scene = scene,
                    .cam = &c,
                    .opt = opt,
                    .threads = opt->threads ? opt->threads : cpu_count(),
                    .vb = &f->vb,
                    .stats = &f->stats};
  f->stats.threads = ctx.threads;
  double t0 = now_ms();
  e = methods[opt->method].fn(dev, &ctx);
  f->stats.frame_ms = now_ms() - t0;
  if (e) {
    rr_frame_release(f);
    return e;
  }
  *out = f;
  return rr_ok(dev);
}

void rr_frame_release(rr_frame *f) {
  if (!f) return;
  visbuf_free(&f->vb);
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

const uint32_t *rr_frame_ids(const rr_frame *f) { return f ? f->vb.id : NULL; }
const float *rr_frame_t(const rr_frame *f) { return f ? f->vb.t : NULL; }
const float *rr_frame_bary1(const rr_frame *f) { return f ? f->vb.l1 : NULL; }
const float *rr_frame_bary2(const rr_frame *f) { return f ? f->vb.l2 : NULL; }
