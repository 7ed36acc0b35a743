/* Mesa llvmpipe through OSMesa (see peer_osmesa.h). Legacy OpenGL is enough: the
 * camera's world → clip matrix goes into GL_PROJECTION, triangles into a vertex
 * buffer object once (so a timed frame is the draw and glFinish, not the upload),
 * and every triangle carries its id + 1 as an RGB colour, flat shaded. */
#define GL_GLEXT_PROTOTYPES 1
#include "peer_osmesa.h"

#include "vis/vis.h"

#include <GL/osmesa.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct osmesa_peer {
  OSMesaContext ctx;
  int w, h;
  uint8_t *rgba; /* the colour buffer, row 0 at the bottom */
  uint32_t *ids; /* row 0 at the top */
  GLuint vbo[2]; /* positions, colours */
  GLuint fbo, rb[2]; /* the multisample target (colour, depth) when samples > 1 */
  int samples;
  double resolve_ms;
  GLsizei nverts;
  vec3 bmin, bmax;
};

static double now(void) { return rr_now_ms(); }

#define PLANE_HALF 4096.0f /* half the side of the textured plane's square */


static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *t, int n) {
  qsort(t, n, sizeof *t, cmp_double);
  return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

osmesa_peer *osmesa_new(int w, int h, int threads) {
  char n[16];
  snprintf(n, sizeof n, "%d", threads < 1 ? 1 : threads);
  setenv("LP_NUM_THREADS", n, 1);      /* read when llvmpipe's screen is made */
  setenv("GALLIUM_DRIVER", "llvmpipe", 0); /* not softpipe */
  osmesa_peer *p = calloc(1, sizeof *p);
  if (!p) return NULL;
  p->w = w, p->h = h;
  p->rgba = malloc((size_t)w * h * 4);
  p->ids = malloc((size_t)w * h * sizeof *p->ids);
  /* The deepest depth buffer llvmpipe offers, so z-fighting does not blur the ids. */
  static const int depths[] = {32, 24, 16};
  for (int i = 0; i < 3 && !p->ctx; i++) p->ctx = OSMesaCreateContextExt(OSMESA_RGBA, depths[i], 0, 0, NULL);
  if (!p->rgba || !p->ids || !p->ctx || !OSMesaMakeCurrent(p->ctx, p->rgba, GL_UNSIGNED_BYTE, w, h)) {
    fprintf(stderr, "osmesa: cannot create a %dx%d context\n", w, h);
    osmesa_release(p);
    return NULL;
  }
  glViewport(0, 0, w, h);
  glDisable(GL_LIGHTING);
  glDisable(GL_DITHER);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glShadeModel(GL_FLAT);
  glClearColor(0, 0, 0, 0);
  glClearDepth(1.0);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glGenBuffers(2, p->vbo);
  p->samples = 1;
  return p;
}

void osmesa_release(osmesa_peer *p) {
  if (!p) return;
  if (p->ctx) {
    osmesa_set_samples(p, 1);
    glDeleteBuffers(2, p->vbo);
    OSMesaDestroyContext(p->ctx);
  }
  free(p->rgba), free(p->ids), free(p);
}

const char *osmesa_renderer(const osmesa_peer *p) {
  (void)p;
  const GLubyte *s = glGetString(GL_RENDERER);
  return s ? (const char *)s : "unknown";
}

int osmesa_set_samples(osmesa_peer *p, int samples) {
  if (p->fbo) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &p->fbo);
    glDeleteRenderbuffers(2, p->rb);
    p->fbo = 0;
  }
  p->samples = 1;
  if (samples <= 1) return 1;
  GLint max = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max);
  if (samples > max) {
    fprintf(stderr, "osmesa: %d samples asked, GL_MAX_SAMPLES is %d\n", samples, max);
    return 0;
  }
  glGenFramebuffers(1, &p->fbo);
  glGenRenderbuffers(2, p->rb);
  glBindRenderbuffer(GL_RENDERBUFFER, p->rb[0]);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, p->w, p->h);
  glBindRenderbuffer(GL_RENDERBUFFER, p->rb[1]);
  /* as deep as OSMesa's own depth buffer is at best, so both targets test alike */
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT32F, p->w, p->h);
  GLint got = 0;
  glGetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_SAMPLES, &got);
  glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, p->rb[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, p->rb[1]);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE || glGetError() != GL_NO_ERROR) {
    fprintf(stderr, "osmesa: no framebuffer of %d samples\n", samples);
    osmesa_set_samples(p, 1);
    return 0;
  }
  p->samples = got > 1 ? got : samples;
  return p->samples;
}

double osmesa_resolve_ms(const osmesa_peer *p) { return p->resolve_ms; }

int osmesa_load(osmesa_peer *p, const rr_scene *s) {
  if (s->ntris >= 0xFFFFFFu) {
    fprintf(stderr, "osmesa: %u triangles do not fit 24-bit colour ids\n", s->ntris);
    return 1;
  }
  size_t nv = (size_t)s->ntris * 3;
  float *pos = malloc(nv * 3 * sizeof *pos);
  uint8_t *col = malloc(nv * 4);
  if (!pos || !col) {
    free(pos), free(col);
    fprintf(stderr, "osmesa: out of memory for %u triangles\n", s->ntris);
    return 1;
  }
  for (uint32_t i = 0; i < s->ntris; i++) {
    uint32_t c = i + 1;
    for (int k = 0; k < 3; k++) {
      size_t v = (size_t)i * 3 + k;
      for (int a = 0; a < 3; a++) pos[v * 3 + a] = scene_coord(s, k, a, i);
      col[v * 4 + 0] = (uint8_t)c, col[v * 4 + 1] = (uint8_t)(c >> 8), col[v * 4 + 2] = (uint8_t)(c >> 16);
      col[v * 4 + 3] = 255;
    }
  }
  glBindBuffer(GL_ARRAY_BUFFER, p->vbo[0]);
  glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof *pos), pos, GL_STATIC_DRAW);
  glVertexPointer(3, GL_FLOAT, 0, (const void *)0);
  glBindBuffer(GL_ARRAY_BUFFER, p->vbo[1]);
  glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 4), col, GL_STATIC_DRAW);
  glColorPointer(4, GL_UNSIGNED_BYTE, 0, (const void *)0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  free(pos), free(col);
  p->nverts = (GLsizei)nv;
  p->bmin = s->bmin, p->bmax = s->bmax;
  glFinish();
  return glGetError() != GL_NO_ERROR;
}

/* World → clip for GL, from rastray's camera: (sx·w, sy·w, w) = [dx dy d0]⁻¹·(p − eye)
 * (the ray parameterization inverted, as the 2D pipeline does); GL's window y runs
 * up, so y_ndc = 1 − sy/hh; z maps w ∈ [near, far] to [−1, 1]. */
static void clip_matrix(const camera *c, const osmesa_peer *p, double m[16]) {
  double col[3][3] = {{c->dx.x, c->dx.y, c->dx.z}, {c->dy.x, c->dy.y, c->dy.z}, {c->d0.x, c->d0.y, c->d0.z}}, inv[3][3];
  for (int i = 0; i < 3; i++) {
    const double *u = col[(i + 1) % 3], *v = col[(i + 2) % 3];
    inv[i][0] = u[1] * v[2] - u[2] * v[1], inv[i][1] = u[2] * v[0] - u[0] * v[2], inv[i][2] = u[0] * v[1] - u[1] * v[0];
  }
  double det = col[0][0] * inv[0][0] + col[0][1] * inv[0][1] + col[0][2] * inv[0][2];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) inv[i][j] /= det;
  /* near and far around the scene's bounds, in ray parameter (w) units */
  double lo = INFINITY, hi = -INFINITY;
  for (int k = 0; k < 8; k++) {
    double q[3] = {(k & 1 ? p->bmax.x : p->bmin.x) - (double)c->eye.x, (k & 2 ? p->bmax.y : p->bmin.y) - (double)c->eye.y,
                   (k & 4 ? p->bmax.z : p->bmin.z) - (double)c->eye.z};
    double w = inv[2][0] * q[0] + inv[2][1] * q[1] + inv[2][2] * q[2];
    lo = w < lo ? w : lo, hi = w > hi ? w : hi;
  }
  double far = hi > 0 ? hi * 1.01 : 1, near = lo * 0.99 > far * 1e-5 ? lo * 0.99 : far * 1e-5;
  double hw = 0.5 * p->w, hh = 0.5 * p->h, a = (far + near) / (far - near), b = -2 * far * near / (far - near);
  double rows[4][4];
  for (int j = 0; j < 3; j++) {
    rows[0][j] = inv[0][j] / hw - inv[2][j];
    rows[1][j] = inv[2][j] - inv[1][j] / hh;
    rows[2][j] = a * inv[2][j];
    rows[3][j] = inv[2][j];
  }
  double eye[3] = {c->eye.x, c->eye.y, c->eye.z};
  for (int r = 0; r < 4; r++) rows[r][3] = -(rows[r][0] * eye[0] + rows[r][1] * eye[1] + rows[r][2] * eye[2]);
  rows[2][3] += b;
  for (int r = 0; r < 4; r++)
    for (int j = 0; j < 4; j++) m[j * 4 + r] = rows[r][j]; /* column-major */
}

double osmesa_render(osmesa_peer *p, const rr_camera *cam, int cull, int reps) {
  camera c;
  if (rr_cam_setup(NULL, cam, p->w, p->h, &c) != RR_OK || cam->type != RR_CAMERA_PERSPECTIVE) {
    fprintf(stderr, "osmesa: needs a valid perspective camera\n");
    return -1;
  }
  double m[16];
  clip_matrix(&c, p, m);
  rr_cam_release(&c);
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixd(m);
  if (cull) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
  } else {
    glDisable(GL_CULL_FACE);
  }
  double t[64], res[64] = {0};
  if (reps < 1) reps = 1;
  if (reps > 64) reps = 64;
  for (int r = 0; r < reps; r++) {
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glFinish();
    double t0 = now();
    glDrawArrays(GL_TRIANGLES, 0, p->nverts);
    glFinish();
    t[r] = now() - t0;
    if (p->fbo) { /* the resolve into OSMesa's buffer, timed apart */
      t0 = now();
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
      glBlitFramebuffer(0, 0, p->w, p->h, 0, 0, p->w, p->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      glFinish();
      res[r] = now() - t0;
      glBindFramebuffer(GL_FRAMEBUFFER, p->fbo);
    }
  }
  p->resolve_ms = median(res, reps);
  return median(t, reps);
}

const uint32_t *osmesa_ids(osmesa_peer *p) {
  for (int y = 0; y < p->h; y++) {
    const uint8_t *row = p->rgba + (size_t)(p->h - 1 - y) * p->w * 4;
    for (int x = 0; x < p->w; x++) {
      uint32_t c = row[4 * x] | (uint32_t)row[4 * x + 1] << 8 | (uint32_t)row[4 * x + 2] << 16;
      p->ids[(size_t)y * p->w + x] = c ? c - 1 : RR_MISS;
    }
  }
  return p->ids;
}

double osmesa_render_textured_plane(osmesa_peer *p, const rr_camera *cam, const uint8_t *rgb, int w, int h,
                                    float scale, float aniso, int reps, float *out) {
  camera c;
  if (rr_cam_setup(NULL, cam, p->w, p->h, &c) != RR_OK || cam->type != RR_CAMERA_PERSPECTIVE) {
    fprintf(stderr, "osmesa: needs a valid perspective camera\n");
    return -1;
  }
  /* a square of side 2·PLANE_HALF: beyond it the plane is less than a pixel from
   * the horizon (GL cannot clip points at infinity through its far plane) */
  const float R = PLANE_HALF;
  vec3 bmin = p->bmin, bmax = p->bmax;
  p->bmin = v3(-R, 0, -R), p->bmax = v3(R, 0, R);
  double m[16];
  clip_matrix(&c, p, m);
  p->bmin = bmin, p->bmax = bmax;
  rr_cam_release(&c);
  /* a float target, so that the filtered linear values come back unquantized */
  GLuint fbo, rb, tex;
  glGenFramebuffers(1, &fbo);
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, p->w, p->h);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
  /* texels: GL's rows run up from t = 0, ours down from v = 1, so rows are flipped */
  uint8_t *flip = malloc((size_t)3 * w * h);
  for (int y = 0; flip && y < h; y++) memcpy(flip + (size_t)3 * y * w, rgb + (size_t)3 * (h - 1 - y) * w, (size_t)3 * w);
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, flip);
  free(flip);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, aniso);
  glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
  glEnable(GL_TEXTURE_2D);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glShadeModel(GL_SMOOTH);
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixd(m);
  glClearColor(-1, -1, -1, -1);
  bool ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE && glGetError() == GL_NO_ERROR;
  double t[64];
  if (reps < 1) reps = 1;
  if (reps > 64) reps = 64;
  /* the square's corners and their texture coordinates (x/scale, -z/scale) */
  static const float corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int r = 0; ok && r < reps; r++) {
    glClear(GL_COLOR_BUFFER_BIT);
    glFinish();
    double t0 = now();
    glBegin(GL_QUADS);
    for (int k = 0; k < 4; k++) {
      float x = corner[k][0] * R, z = corner[k][1] * R;
      glTexCoord2f(x / scale, -z / scale), glVertex3f(x, 0, z);
    }
    glEnd();
    glFinish();
    t[r] = now() - t0;
  }
  float *px = ok ? malloc((size_t)p->w * p->h * 4 * sizeof *px) : NULL;
  if (px) {
    glReadPixels(0, 0, p->w, p->h, GL_RGBA, GL_FLOAT, px);
    for (int y = 0; y < p->h; y++)
      for (int x = 0; x < p->w; x++) out[(size_t)y * p->w + x] = px[4 * ((size_t)(p->h - 1 - y) * p->w + x)];
  }
  ok = ok && px && glGetError() == GL_NO_ERROR;
  free(px);
  glDisable(GL_TEXTURE_2D);
  glEnable(GL_DEPTH_TEST);
  glShadeModel(GL_FLAT);
  glClearColor(0, 0, 0, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteTextures(1, &tex);
  glDeleteRenderbuffers(1, &rb);
  glDeleteFramebuffers(1, &fbo);
  if (!ok) {
    fprintf(stderr, "osmesa: the textured plane failed (GL error or incomplete float framebuffer)\n");
    return -1;
  }
  return median(t, reps);
}
