/* Texture filtering over a sample's footprint (docs/textures.md).
 *
 * At load every texture gets a MIP chain: level 0 holds the file's texels decoded
 * from sRGB to linear light and premultiplied by alpha (so that transparent texels
 * add no colour when averaged), 16 bits a channel; each next level is the exact box
 * average of the one before, at half the size rounded down, whatever the size (an
 * odd side weighs its input texels by their fractional overlap).
 *
 * A lookup reads the footprint, the parallelogram spanned by the derivatives of
 * (u, v) per pixel step, as the filter says: nearest and bilinear at level 0;
 * trilinear at the level where a texel is as wide as the footprint; aniso as up to
 * N trilinear probes along the footprint's long side, each the size of its short
 * side (as EXT_texture_filter_anisotropic); ewa as an elliptical weighted average
 * over the footprint's ellipse (Heckbert's EWA), its radial weight the one whose
 * profile along every direction is the pixel's box. */
#include "shade/texture.h"
#include "core/color.h"
#include "core/simd.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TEXEL_ONE 65535.0f

/* ---- the MIP chain ------------------------------------------------------------------ */

/* How output texel j of a downsampling axis reads its input: the input texels
 * first .. first + 3 with weights w (their overlap with [j r, (j + 1) r), r = N / n,
 * over r). r <= 3 (N = 3, n = 1), so four taps always suffice. */
typedef struct box_taps {
  int first;
  float w[4];
} box_taps;

static void box_weights(int N, int n, box_taps *t) {
  double r = (double)N / n;
  for (int j = 0; j < n; j++) {
    double a = j * r, b = (j + 1) * r;
    int i0 = (int)floor(a);
    t[j].first = i0;
    for (int k = 0; k < 4; k++) {
      double lo = fmax(a, i0 + k), hi = fmin(b, i0 + k + 1.0);
      t[j].w[k] = i0 + k < N && hi > lo ? (float)((hi - lo) / r) : 0.0f;
    }
  }
}

/* Level `out` as the box average of level `in`: rows first into tmp (floats, out's
 * width × in's height), then columns, rounded to 16 bits. */
static void downsample(const tex_level *in, tex_level *out, float *tmp, box_taps *tx, box_taps *ty) {
  box_weights(in->width, out->width, tx);
  box_weights(in->height, out->height, ty);
  for (int y = 0; y < in->height; y++) {
    const uint16_t *row = in->texels + (size_t)4 * y * in->width;
    for (int x = 0; x < out->width; x++) {
      float acc[4] = {0, 0, 0, 0};
      for (int k = 0; k < 4; k++)
        if (tx[x].w[k] > 0)
          for (int c = 0; c < 4; c++) acc[c] += tx[x].w[k] * row[4 * (tx[x].first + k) + c];
      memcpy(tmp + 4 * ((size_t)y * out->width + x), acc, sizeof acc);
    }
  }
  for (int y = 0; y < out->height; y++)
    for (int x = 0; x < out->width; x++) {
      float acc[4] = {0, 0, 0, 0};
      for (int k = 0; k < 4; k++)
        if (ty[y].w[k] > 0)
          for (int c = 0; c < 4; c++) acc[c] += ty[y].w[k] * tmp[4 * ((size_t)(ty[y].first + k) * out->width + x) + c];
      uint16_t *o = out->texels + 4 * ((size_t)y * out->width + x);
      for (int c = 0; c < 4; c++) o[c] = (uint16_t)fminf(acc[c] + 0.5f, TEXEL_ONE);
    }
}

bool rr_texture_prepare(rr_texture *t) {
  if (t->nlevels || t->width < 1 || t->height < 1 || !t->rgb) return true;
  int n = 1;
  for (int w = t->width, h = t->height; w > 1 || h > 1; n++) w = w > 1 ? w / 2 : 1, h = h > 1 ? h / 2 : 1;
  tex_level *lv = calloc(n, sizeof *lv);
  float *tmp = malloc((size_t)4 * (t->width / 2 + 1) * t->height * sizeof *tmp);
  box_taps *taps = malloc(((size_t)t->width + t->height) * sizeof *taps); /* a level's rows', then columns' */
  bool ok = lv && tmp && taps;
  for (int l = 0; ok && l < n; l++) {
    lv[l].width = l ? (lv[l - 1].width > 1 ? lv[l - 1].width / 2 : 1) : t->width;
    lv[l].height = l ? (lv[l - 1].height > 1 ? lv[l - 1].height / 2 : 1) : t->height;
    lv[l].sx = (float)lv[l].width / (float)t->width, lv[l].sy = (float)lv[l].height / (float)t->height;
    lv[l].texels = malloc((size_t)lv[l].width * lv[l].height * 4 * sizeof(uint16_t));
    ok = lv[l].texels != NULL;
  }
  if (ok) {
    float lin[256]; /* the sRGB curve once per byte value */
    for (int i = 0; i < 256; i++) lin[i] = srgb_decode(i / 255.0f);
    size_t texels = (size_t)t->width * t->height;
    for (size_t k = 0; k < texels; k++) {
      float a = t->alpha ? t->alpha[k] / 255.0f : 1.0f;
      uint16_t *o = lv[0].texels + 4 * k;
      for (int c = 0; c < 3; c++) o[c] = (uint16_t)(lin[t->rgb[3 * k + c]] * a * TEXEL_ONE + 0.5f);
      o[3] = (uint16_t)(a * TEXEL_ONE + 0.5f);
    }
    for (int l = 1; l < n; l++) downsample(&lv[l - 1], &lv[l], tmp, taps, taps + t->width);
  }
  free(tmp), free(taps);
  if (!ok) {
    for (int l = 0; lv && l < n; l++) free(lv[l].texels);
    free(lv);
    return false;
  }
  t->levels = lv, t->nlevels = n;
  return true;
}

/* ---- lookups ------------------------------------------------------------------------ */

/* floor(x) as an int, kept within ±2^30 so that footprints far outside [0, 1] wrap
 * without overflow. */
KERNEL int ifloor(float x) {
  x = x > 1073741824.0f ? 1073741824.0f : x < -1073741824.0f ? -1073741824.0f : x == x ? x : 0.0f;
  int i = (int)x; /* truncation, then down for negatives: no floorf call without SSE4.1 */
  return i - (x < (float)i);
}

/* Texel index i of a side of n texels, wrapped as mode says. */
static inline int wrap_index(int i, int n, rr_texture_wrap mode) {
  if ((unsigned)i < (unsigned)n) return i;
  if (mode == RR_WRAP_CLAMP) return i < 0 ? 0 : n - 1;
  if (mode == RR_WRAP_MIRROR) {
    int p = 2 * n;
    i %= p;
    if (i < 0) i += p;
    return i < n ? i : p - 1 - i;
  }
  i += i < 0 ? n : -n; /* a probe line crosses the seam by a period at most, mostly */
  if ((unsigned)i < (unsigned)n) return i;
  i %= n; /* (no division otherwise) */
  return i < 0 ? i + n : i;
}

/* Four 16-bit channels of a texel as floats. On x86 each 16-bit x goes under the
 * high half 0x4b00, the float 2^23 + x exactly, less 2^23: two instructions where
 * SSE2 has no conversion from 16 bits. */
typedef uint16_t texel_u16 __attribute__((vector_size(8)));
KERNEL rr_vf4 texel(const uint16_t *p) {
#ifdef RR_SIMD_X86
  __m128i v = _mm_loadl_epi64((const __m128i *)(const void *)p);
  return (rr_vf4)_mm_unpacklo_epi16(v, _mm_set1_epi16(0x4b00)) - rr_vf4_splat(8388608.0f);
#else
  texel_u16 v;
  memcpy(&v, p, sizeof v);
  return __builtin_convertvector(__builtin_convertvector(v, rr_vi4), rr_vf4);
#endif
}

/* Two texels side by side (one load). */
typedef uint16_t texel2_u16 __attribute__((vector_size(16)));
typedef int32_t texel2_i32 __attribute__((vector_size(32)));
KERNEL void texel2(const uint16_t *p, rr_vf4 *a, rr_vf4 *b) {
#ifdef RR_SIMD_X86
  __m128i v = _mm_loadu_si128((const __m128i *)(const void *)p), hi = _mm_set1_epi16(0x4b00);
  *a = (rr_vf4)_mm_unpacklo_epi16(v, hi) - rr_vf4_splat(8388608.0f);
  *b = (rr_vf4)_mm_unpackhi_epi16(v, hi) - rr_vf4_splat(8388608.0f);
#else
  texel2_u16 v;
  memcpy(&v, p, sizeof v);
  texel2_i32 i = __builtin_convertvector(v, texel2_i32);
  rr_vi4 lo, hi;
  memcpy(&lo, &i, sizeof lo), memcpy(&hi, (char *)&i + sizeof lo, sizeof hi);
  *a = __builtin_convertvector(lo, rr_vf4), *b = __builtin_convertvector(hi, rr_vf4);
#endif
}

/* Adds weight w times the bilinear lookup of level lv to acc: the texels (x0, y0) to
 * (x0 + 1, y0 + 1), (ax, ay) the position between them. Hot: up to 32 a pixel with
 * aniso:16. Edges false: the texels are known to be inside the level, no wrapping. */
KERNEL void bilerp_at(const rr_texture *t, const tex_level *lv, int x0, int y0, float ax, float ay, float w,
                      bool edges, rr_vf4 *acc) {
  int x1 = x0 + 1, y1 = y0 + 1, W = lv->width, H = lv->height;
  rr_vf4 t00, t10, t01, t11;
  if (edges) {
    if ((unsigned)x0 >= (unsigned)(W - 1)) /* wrap only at the edges */
      x1 = wrap_index(x1, W, t->wrap[0]), x0 = wrap_index(x0, W, t->wrap[0]);
    if ((unsigned)y0 >= (unsigned)(H - 1)) y1 = wrap_index(y1, H, t->wrap[1]), y0 = wrap_index(y0, H, t->wrap[1]);
    const uint16_t *r0 = lv->texels + (size_t)4 * y0 * W, *r1 = lv->texels + (size_t)4 * y1 * W;
    t00 = texel(r0 + 4 * x0), t10 = texel(r0 + 4 * x1), t01 = texel(r1 + 4 * x0), t11 = texel(r1 + 4 * x1);
  } else {
    const uint16_t *r0 = lv->texels + 4 * ((size_t)y0 * W + x0);
    texel2(r0, &t00, &t10), texel2(r0 + 4 * W, &t01, &t11);
  }
  rr_vf4 vx = rr_vf4_splat(ax), top = t00 + vx * (t10 - t00), bottom = t01 + vx * (t11 - t01);
  *acc += rr_vf4_splat(w) * (top + rr_vf4_splat(ay) * (bottom - top));
}

/* Two bilinear lookups whose texel addressing is shared: weight wa times level la's
 * at (p[0], p[1]) added to acc_a and wb times level lb's at (p[2], p[3]) to acc_b
 * (which may be one), texel coordinates with the texel centres at integers, floored
 * in one vector, within ±2^30 so that footprints far outside [0, 1] wrap without
 * overflow (NaN: -2^30). Edges false: both lookups' texels are known to be inside
 * their levels. */
KERNEL void bilerp2(const rr_texture *t, const tex_level *la, const tex_level *lb, rr_vf4 p, float wa, float wb,
                    bool edges, rr_vf4 *acc_a, rr_vf4 *acc_b) {
  if (edges) p = rr_vf4_min(rr_vf4_max(p, rr_vf4_splat(-1073741824.0f)), rr_vf4_splat(1073741824.0f));
  rr_vi4 i = rr_vi4_trunc(p);
  i += p < __builtin_convertvector(i, rr_vf4); /* truncation, then down for negatives (-1 where true) */
  rr_vf4 a = p - __builtin_convertvector(i, rr_vf4);
  bilerp_at(t, la, i[0], i[1], a[0], a[1], wa, edges, acc_a);
  bilerp_at(t, lb, i[2], i[3], a[2], a[3], wb, edges, acc_b);
}

/* Adds weight w times the bilinear lookup of level lv at texel coordinates (x, y). */
KERNEL void bilerp(const rr_texture *t, const tex_level *lv, float x, float y, float w, rr_vf4 *acc) {
  x -= 0.5f, y -= 0.5f;
  int x0 = ifloor(x), y0 = ifloor(y);
  bilerp_at(t, lv, x0, y0, x - (float)x0, y - (float)y0, w, true, acc);
}

/* log2(x) for a level of detail without libm's call: the exponent plus a polynomial
 * in the mantissa fitted to log2 (within 3e-5 of a level, exact at powers of two, so
 * continuous across octaves); libm's where x is not a normal positive float. */
static inline float lod_log2(float x) {
  if (!(x >= 1.17549435e-38f && x <= 3.4e38f)) return log2f(x);
  uint32_t b;
  memcpy(&b, &x, sizeof b);
  float e = (float)((int)(b >> 23) - 127), m;
  b = (b & 0x7fffffu) | 0x3f800000u; /* the mantissa 1 + m in [1, 2) */
  memcpy(&m, &b, sizeof m);
  m -= 1.0f;
  return e + m + m * (1.0f - m) * (0.44174030f + m * (-0.26602988f + m * (0.14631434f - 0.04400469f * m)));
}

/* Two levels and their weights, the trilinear blend at a level of detail. */
typedef struct lod_pair {
  const tex_level *lv[2];
  float w[2];
  int n; /* levels used: 1 or 2 */
} lod_pair;

static inline lod_pair lod_levels(const rr_texture *t, float lod) {
  int top = t->nlevels - 1, l = !(lod > 0) ? 0 : lod >= (float)top ? top : (int)lod; /* NaN: level 0 */
  float f = l == top || !(lod > 0) ? 0.0f : lod - (float)l;
  return (lod_pair){{&t->levels[l], &t->levels[l < top ? l + 1 : l]}, {1 - f, f}, f > 0 ? 2 : 1};
}

/* Adds weight w times the trilinear lookup at (s, r) (level-0 texel units) to acc. */
KERNEL void trilerp(const rr_texture *t, const lod_pair *p, float s, float r, float w, rr_vf4 *acc) {
  const tex_level *a = p->lv[0], *b = p->lv[1];
  if (p->n == 1) bilerp(t, a, s * a->sx, r * a->sy, w, acc);
  else
    bilerp2(t, a, b, (rr_vf4){s * a->sx - 0.5f, r * a->sy - 0.5f, s * b->sx - 0.5f, r * b->sy - 0.5f}, w * p->w[0],
            w * p->w[1], true, acc, acc);
}

/* The footprint in level-0 texels: the derivative vectors per pixel step in x (a)
 * and y (b), texel rows running down as v runs up. */
typedef struct footprint {
  float ax, ay, bx, by;
} footprint;

/* The probes j = 0 .. n - 1 of a line at base + j d, texel coordinates with the
 * centres at integers: with two levels, the finer one's in lanes 0, 1 (summed into
 * s0) and the coarser one's in lanes 2, 3 (into s1), one probe of each at a time;
 * with one level, lanes 2, 3 repeat 0, 1 and the probes go two at a time. Edges
 * false: the line is known to be inside its levels. */
KERNEL void probe_line(const rr_texture *t, const lod_pair *p, rr_vf4 base, rr_vf4 d, int n, bool edges, rr_vf4 *s0,
                       rr_vf4 *s1) {
  if (p->n == 2) {
    rr_vf4 j = rr_vf4_splat(0), one = rr_vf4_splat(1);
    for (int k = 0; k < n; k++, j += one) bilerp2(t, p->lv[0], p->lv[1], base + j * d, 1, 1, edges, s0, s1);
    return;
  }
  rr_vf4 j = {0, 0, 1, 1}, two = rr_vf4_splat(2);
  for (int k = 0; k + 1 < n; k += 2, j += two) bilerp2(t, p->lv[0], p->lv[0], base + j * d, 1, 1, edges, s0, s0);
  if (n & 1) {
    rr_vf4 last = base + rr_vf4_splat((float)(n - 1)) * d; /* (as j would reach it) */
    bilerp(t, p->lv[0], last[0] + 0.5f, last[1] + 0.5f, 1, s0);
  }
}

/* Up to f->aniso trilinear probes spread along the long side of the parallelogram
 * spanned by a and b, each as wide as the parallelogram across. */
static void filter_aniso(const rr_texture *t, float s, float r, const footprint *fp, const tex_filter *f,
                         rr_vf4 *acc) {
  float la = fp->ax * fp->ax + fp->ay * fp->ay, lb = fp->bx * fp->bx + fp->by * fp->by;
  float mx = la >= lb ? fp->ax : fp->bx, my = la >= lb ? fp->ay : fp->by; /* the longer vector */
  float nx = la >= lb ? fp->bx : fp->ax, ny = la >= lb ? fp->by : fp->ay;
  float lmaj = sqrtf(la >= lb ? la : lb);
  if (!(lmaj > 0)) { /* no footprint: magnified */
    lod_pair p = lod_levels(t, f->lod_bias);
    trilerp(t, &p, s, r, 1, acc);
    return;
  }
  /* the parallelogram's extent along the longer vector and its width across it */
  float along = lmaj + fabsf(mx * nx + my * ny) / lmaj, across = fabsf(mx * ny - my * nx) / lmaj;
  int n = f->filter == RR_TEXTURE_ANISO ? f->aniso : 1;
  if (along < (float)n * across) { /* n = ceil(along / across), across > 0 here */
    float q = along / across;
    n = (int)q, n += (float)n < q;
  }
  if (n < 1) n = 1;
  float size = along / (float)n > across ? along / (float)n : across;
  float lod = lod_log2(size) + f->lod_bias;
  if (lod >= (float)(t->nlevels - 1)) n = 1; /* the top level is one texel's mean everywhere */
  lod_pair p = lod_levels(t, lod);
  if (n == 1) {
    trilerp(t, &p, s, r, 1, acc);
    return;
  }
  /* probe j at (j + 1/2 - n/2)·along/n along the unit longer vector, in each level:
   * the line's first probe (base) and step (d) in both levels' texels, with the
   * texel centres at integers, so that the first and last bound all in float too */
  const tex_level *a = p.lv[0], *b = p.n == 2 ? p.lv[1] : a;
  float step = along / ((float)n * lmaj), o = 0.5f - 0.5f * (float)n;
  rr_vf4 scale = {a->sx, a->sy, b->sx, b->sy};
  rr_vf4 d = (rr_vf4){mx, my, mx, my} * rr_vf4_splat(step) * scale;
  rr_vf4 base = (rr_vf4){s, r, s, r} * scale + rr_vf4_splat(o) * d - rr_vf4_splat(0.5f);
  rr_vf4 end = base + rr_vf4_splat((float)(n - 1)) * d;
  rr_vf4 lim = {(float)(a->width - 1), (float)(a->height - 1), (float)(b->width - 1), (float)(b->height - 1)};
  rr_vf4 zero = rr_vf4_splat(0), s0 = zero, s1 = zero;
  if (rr_vi4_bits((base >= zero) & (base < lim) & (end >= zero) & (end < lim)) == 15) /* (NaN: not inside) */
    probe_line(t, &p, base, d, n, false, &s0, &s1);
  else
    probe_line(t, &p, base, d, n, true, &s0, &s1);
  /* the levels' probes summed, then weighed */
  *acc += rr_vf4_splat(p.w[0] / (float)n) * s0 + rr_vf4_splat(p.w[1] / (float)n) * s1;
}

/* EWA (docs/textures.md). The weight over the ellipse x^T M^-1 x < EWA_R², M = J Jᵀ
 * (J the footprint: r = |J^-1 x| is the distance in pixels), is the radially
 * symmetric w(r) ∝ 1/sqrt(EWA_R² - r²), EWA_R half a pixel: the surface of a sphere
 * seen from afar, whose profile along every line is a box (Archimedes' hat-box
 * theorem), a pixel wide, as the pixel's square has along its axes (a Gaussian's
 * is a Gaussian). The ellipse is read on a grid fine
 * enough that its short axis spans EWA_STEPS steps or more: a MIP level's texels,
 * or, finer than level 0, level 0's bilinear reconstruction sampled every 2^l
 * texels (l < 0); each grid point weighs w's mean over its cell (the rim's infinite
 * but integrable weight spread over the cells that cross it; q = r² taken as linear
 * across a cell). Under EWA_MIN_AXIS texels of level 0 across, the footprint is
 * nearly a point: aniso's probes. The eccentricity is limited to
 * EWA_MAX_ECCENTRICITY (the short axis grown), a bound on the points read. */
#define EWA_R 0.5f
#define EWA_STEPS 8.0f
#define EWA_MIN_AXIS 0.5f
#define EWA_MAX_ECCENTRICITY 64.0f

/* Weight w times the EWA of grid l (above) over the ellipse M (m11, m12, m22, in
 * level-0 texels) around (s, r). */
static void ewa_grid(const rr_texture *t, int l, float s, float r, const float m[3], float w, rr_vf4 *acc) {
  const tex_level *lv = &t->levels[l > 0 ? l : 0];
  bool fine = l < 0; /* level 0's reconstruction, every step texels */
  float step = fine ? exp2f((float)l) : 1.0f;
  float sx = fine ? 1.0f / step : lv->sx, sy = fine ? sx : lv->sy;
  float m11 = m[0] * sx * sx, m12 = m[1] * sx * sy, m22 = m[2] * sy * sy; /* in grid steps */
  float det = m11 * m22 - m12 * m12;
  /* the centre in grid steps, grid points (and texel centres) at integers */
  float cx = fine ? (s - 0.5f) * sx : s * sx - 0.5f, cy = fine ? (r - 0.5f) * sy : r * sy - 0.5f;
  if (!(det > 0)) { /* (the caller's short axis spans steps: a guard) */
    bilerp(t, lv, fine ? s : s * sx, fine ? r : r * sy, w, acc);
    return;
  }
  float q11 = m22 / det, q12 = -m12 / det, q22 = m11 / det; /* M^-1 */
  const float R2 = EWA_R * EWA_R, A = 0.5f;                 /* A: a cell's half-width */
  /* the rows within the ellipse grown by a cell, at most a period of the texture
   * each way (a thin texture's levels stop halving across: the rest would revisit
   * the same texels); in a row, the ellipse's span over the rows within a cell,
   * grown by a cell (the span of row ty is slope·ty ± sqrt((R² - ty²/m22) det/m22)) */
  float wp = (float)lv->width * sx + 1, hp = (float)lv->height * sy + 1;
  float ey = fminf(sqrtf(m22 * R2) + A, hp), slope = -q12 / q11, hh = det / m22;
  int y0 = ifloor(cy - ey) + 1, y1 = ifloor(cy + ey);
  rr_vf4 sum = rr_vf4_splat(0);
  float wsum = 0;
  for (int y = y0; y <= y1; y++) {
    float ty = (float)y - cy, tn = fabsf(ty) > A ? fabsf(ty) - A : 0.0f; /* the row within a cell nearest the centre */
    float h = sqrtf(fmaxf(R2 - tn * tn / m22, 0.0f) * hh), c0 = slope * (ty - A), c1 = slope * (ty + A);
    float xl = fmaxf(fminf(c0, c1) - h - A, -wp), xr = fminf(fmaxf(c0, c1) + h + A, wp);
    int x0 = ifloor(cx + xl) + 1, x1 = ifloor(cx + xr);
    const uint16_t *row = lv->texels + (fine ? 0 : (size_t)4 * wrap_index(y, lv->height, t->wrap[1]) * lv->width);
    float gy1 = q12 * ty, gy2 = q22 * ty, py = (float)y * step;
    int iy = ifloor(py);
    for (int x = x0; x <= x1; x++) {
      float tx = (float)x - cx, g1 = q11 * tx + gy1, g2 = q12 * tx + gy2;
      float q = tx * g1 + ty * g2, dq = A * (fabsf(g1) + fabsf(g2)); /* q = r², and its spread over the cell */
      if (!(q - dq < R2)) continue;                                    /* (NaN too) */
      /* w's mean over [q - dq, q + dq], 0 beyond R², times 2 (the scale cancels);
       * dq = 0 only at the ellipse's centre */
      float g = dq > 0 ? (sqrtf(R2 - (q - dq)) - sqrtf(R2 - fminf(q + dq, R2))) / dq : 2.0f / sqrtf(R2 - q);
      if (fine) {
        float px = (float)x * step;
        int ix = ifloor(px);
        bilerp_at(t, lv, ix, iy, px - (float)ix, py - (float)iy, g, true, &sum);
      } else {
        sum += rr_vf4_splat(g) * texel(row + 4 * wrap_index(x, lv->width, t->wrap[0]));
      }
      wsum += g;
    }
  }
  if (wsum > 0)
    *acc += rr_vf4_splat(w / wsum) * sum;
  else /* (the centre's cell is always read; a guard all the same) */
    bilerp(t, lv, fine ? s : s * sx, fine ? r : r * sy, w, acc);
}

/* EWA at the two grids around the one on which the ellipse's short axis spans
 * EWA_STEPS steps, the footprint scaled by 2^lod_bias. */
static void filter_ewa(const rr_texture *t, float s, float r, const footprint *fp, const tex_filter *f, rr_vf4 *acc) {
  float k = exp2f(2.0f * f->lod_bias); /* the footprint's area scale */
  float m[3] = {k * (fp->ax * fp->ax + fp->bx * fp->bx), k * (fp->ax * fp->ay + fp->bx * fp->by),
                k * (fp->ay * fp->ay + fp->by * fp->by)};
  /* M's eigenvalues: the ellipse's semi-axes squared at r = 1 */
  float half = 0.5f * (m[0] + m[2]), root = sqrtf(0.25f * (m[0] - m[2]) * (m[0] - m[2]) + m[1] * m[1]);
  float l1 = half + root, l2 = fmaxf(half - root, 0.0f);
  const float E2 = EWA_MAX_ECCENTRICITY * EWA_MAX_ECCENTRICITY;
  if (l2 * E2 < l1) { /* the short axis grown: M + d P, P = (M - l1 I) / (l2 - l1) the projector onto it */
    float c = (l1 / E2 - l2) / (l2 - l1);
    m[0] += c * (m[0] - l1), m[1] += c * m[1], m[2] += c * (m[2] - l1);
    l2 = l1 / E2;
  }
  float lmin = 2.0f * EWA_R * sqrtf(l2); /* the short axis, in level-0 texels */
  if (!(lmin >= EWA_MIN_AXIS)) {         /* nearly a point (none, NaN) */
    tex_filter probes = {RR_TEXTURE_ANISO, f->aniso, f->lod_bias};
    filter_aniso(t, s, r, fp, &probes, acc);
    return;
  }
  float lod = lod_log2(lmin / EWA_STEPS); /* at least log2(EWA_MIN_AXIS / EWA_STEPS) */
  int top = t->nlevels - 1;
  if (lod >= (float)top) { /* the ellipse covers the texture: its mean (and a bounded loop) */
    bilerp(t, &t->levels[top], s / (float)t->width, r / (float)t->height, 1, acc);
    return;
  }
  int l = ifloor(lod);
  float w = lod - (float)l;
  ewa_grid(t, l, s, r, m, 1 - w, acc);
  if (w > 0) ewa_grid(t, l + 1, s, r, m, w, acc);
}

/* A coordinate brought near [0, 1] (repeat) or [0, 2] (mirror) so that texel
 * coordinates stay exact far from the origin; clamp keeps it (ifloor bounds it). */
static inline float wrap_coord(float u, rr_texture_wrap mode) {
  if (mode == RR_WRAP_REPEAT) return u - floorf(u);
  if (mode == RR_WRAP_MIRROR) return u - 2.0f * floorf(0.5f * u);
  return u;
}

void rr_texture_sample(const rr_texture *t, const tex_coord *tc, const tex_filter *f, float rgba[4]) {
  if (t->nlevels < 1) { /* no texels: white, so that the base colour shows */
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 1.0f;
    return;
  }
  float W = (float)t->width, H = (float)t->height;
  /* level-0 texel coordinates (s, r), rows running down from v = 1 */
  float s = wrap_coord(tc->u, t->wrap[0]) * W, r = (1.0f - wrap_coord(tc->v, t->wrap[1])) * H;
  rr_vf4 acc = rr_vf4_splat(0);
  switch (f->filter) {
  case RR_TEXTURE_NEAREST: {
    const tex_level *lv = &t->levels[0];
    int x = wrap_index(ifloor(s), lv->width, t->wrap[0]), y = wrap_index(ifloor(r), lv->height, t->wrap[1]);
    acc = texel(lv->texels + 4 * ((size_t)y * lv->width + x));
    break;
  }
  case RR_TEXTURE_BILINEAR:
    bilerp(t, &t->levels[0], s, r, 1, &acc);
    break;
  default: {
    footprint fp = {tc->dudx * W, -tc->dvdx * H, tc->dudy * W, -tc->dvdy * H};
    if (f->filter == RR_TEXTURE_EWA) filter_ewa(t, s, r, &fp, f, &acc);
    else filter_aniso(t, s, r, &fp, f, &acc); /* trilinear: one probe */
    break;
  }
  }
  /* premultiplied to straight colour: the colour of what is there */
  float a = acc[3] / TEXEL_ONE, inv = a > 0 ? 1.0f / acc[3] : 0.0f;
  for (int c = 0; c < 3; c++) rgba[c] = fminf(acc[c] * inv, 1.0f);
  rgba[3] = a;
}
