/* tri_moved (prim/triangle.h) for W positions at once: a part of kernel templates
 * (core/simd.h), included by the setup's and the 3D rasterizer's inside their
 * instantiation for width W. Planar camera c (any of the positions: only its size
 * and type are read), whose positions' sample offsets are lo_x, lo_y lane by lane:
 * ts's pa, num0, cx, cy there, in tri_moved's operations (minps and maxps are its
 * comparisons), so its bits. */
TARGET static inline __attribute__((always_inline)) void RR_CAT(tri_moved_lanes, W)(const tri_setup *ts,
                                                                                    const tri_plane *pl,
                                                                                    const camera *c, VF lo_x, VF lo_y,
                                                                                    VF m[4]) {
  typedef RR_CAT(rr_vd, W) vd;
  const VF hi_x = VF_(splat)((float)(c->width - 1)) + lo_x, hi_y = VF_(splat)((float)(c->height - 1)) + lo_y;
  VF x = VF_(max)(VF_(min)(VF_(splat)(pl->px), hi_x), lo_x), y = VF_(max)(VF_(min)(VF_(splat)(pl->py), hi_y), lo_y);
  x = VF_(floor)(x - lo_x) + lo_x, y = VF_(floor)(y - lo_y) + lo_y;
  const vd base = pl->base - RR_CAT(RR_CAT(rr_vf, W), _to_double)(VF_(splat)(0.0f)); /* (base - 0 keeps a -0) */
  const VF p = RR_CAT(RR_CAT(rr_vd, W), _to_float)(base + RR_CAT(RR_CAT(rr_vf, W), _to_double)(x) * pl->u +
                                                   RR_CAT(RR_CAT(rr_vf, W), _to_double)(y) * pl->v);
  const bool persp = c->type == RR_CAMERA_PERSPECTIVE;
  m[0] = persp ? p : VF_(splat)(ts->pa), m[1] = persp ? VF_(splat)(ts->num0) : p, m[2] = x, m[3] = y;
}
