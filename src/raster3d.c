/* 3D rasterization kernels shared by the traversal's configurations: a triangle's
 * screen bounds and the test of every sample of a rectangle (paper sect. 3.2, 5).
 * A triangle that crosses the eye plane has no bounded projection and is tested
 * over the whole screen; 3D edge functions need no clipping for that. */
#include "rr.h"

/* Samples a set-up triangle may cover, as an inclusive pixel rectangle. Returns
 * false when it covers none. Projected bounds get a one-pixel margin so rounding
 * in the edge functions can never put a hit outside the box. */
bool tri_screen_bounds(const rr_scene *s, uint32_t i, const camera *c, int r[4]) {
  float x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  int behind = 0, projected = 0;
  for (int k = 0; k < 3; k++) {
    vec3 q = v3_sub(scene_vertex(s, k, i), c->eye);
    float sx, sy;
    if (!(v3_dot(q, c->fwd) > 0)) behind++;
    else if (camera_project(c, q, &sx, &sy) && isfinite(sx) && isfinite(sy)) {
      projected++;
      x0 = fminf(x0, sx), x1 = fmaxf(x1, sx), y0 = fminf(y0, sy), y1 = fmaxf(y1, sy);
    }
  }
  if (!c->planar) {
    /* Curved views have no straight-edged projection: the whole image (the
     * traversal's binning and frusta narrow it down). Hemispheres see nothing
     * wholly behind the eye plane. */
    if (behind == 3 && c->type == RR_CAMERA_PARABOLIC) return false;
    r[0] = 0, r[1] = 0, r[2] = c->width - 1, r[3] = c->height - 1;
    return true;
  }
  if (behind == 3) return false; /* every camera ray has d·fwd > 0: unreachable */
  if (projected == 3) {
    /* Sample (x + 0.5) lies in [x0, x1] for x in [ceil(x0 - 0.5), floor(x1 - 0.5)]. */
    float m = 1.0f;
    float lx = fmaxf(ceilf(x0 - 0.5f - m), 0.0f), hx = fminf(floorf(x1 - 0.5f + m), (float)(c->width - 1));
    float ly = fmaxf(ceilf(y0 - 0.5f - m), 0.0f), hy = fminf(floorf(y1 - 0.5f + m), (float)(c->height - 1));
    if (lx > hx || ly > hy) return false;
    r[0] = (int)lx, r[1] = (int)ly, r[2] = (int)hx, r[3] = (int)hy;
    return true;
  }
  r[0] = 0, r[1] = 0, r[2] = c->width - 1, r[3] = c->height - 1;
  return true;
}

/* The sample loop, written once and specialised for planar and curved cameras. */
static inline void raster_loop(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb,
                               const bool planar) {
  for (int y = r[1]; y <= r[3]; y++) {
    float sy = (float)y + 0.5f;
    size_t row = (size_t)y * vb->width;
    for (int x = r[0]; x <= r[2]; x++) {
      float sx = (float)x + 0.5f;
      vec3 w = planar ? v3(1.0f, sx, sy) : c->dirs[row + x];
      shade_sample_w(ts, id, w, sx, sy, vb, row + x);
    }
  }
}

/* Tests every sample of rectangle r against one triangle; returns the evaluations. */
uint64_t raster_rect(const tri_setup *ts, uint32_t id, const int r[4], const camera *c, visbuf *vb) {
  if (c->planar) raster_loop(ts, id, r, c, vb, true);
  else raster_loop(ts, id, r, c, vb, false);
  return (uint64_t)(r[2] - r[0] + 1) * (uint64_t)(r[3] - r[1] + 1);
}
