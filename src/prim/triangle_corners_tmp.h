/* The world corners of W triangles at once, for the kernel templates of corner
 * bounds and setup (core/simd.h): included inside their instantiation for width W.
 * Lane l holds triangle lane_id[l]; consecutive says the lanes are lane_id[0],
 * lane_id[0] + 1, ... Corner k's axis a goes to p[k][a]. Without instances the
 * stored corners (loaded when consecutive, else gathered); with instances, a run
 * inside one translated instance (the common case) loads its stored corners and
 * adds the translation, translated lanes gather theirs and add it, and other maps
 * move each lane's corners with scene_vertex: inst_point's operations, so the
 * flattened scene's bits. flat (a constant where it is inlined) says the scene has
 * no instances: that copy is only the first case, whose corners stay in registers. */
TARGET static inline __attribute__((always_inline)) void RR_CAT(lane_corners, W)(const rr_scene *s,
                                                                               const int32_t lane_id[W],
                                                                               bool consecutive, VF p[3][3],
                                                                               bool flat) {
  if (flat || !s->inst) {
    const VI idx = VI_(load)(lane_id);
    if (consecutive) {
#pragma GCC unroll 3
      for (int k = 0; k < 3; k++)
#pragma GCC unroll 3
        for (int a = 0; a < 3; a++) p[k][a] = VF_(load)(s->p[k][a] + lane_id[0]);
    } else {
#pragma GCC unroll 3
      for (int k = 0; k < 3; k++)
#pragma GCC unroll 3
        for (int a = 0; a < 3; a++) p[k][a] = VF_(gather)(s->p[k][a], idx);
    }
    return;
  }
  uint32_t run_k = RR_MISS, run_st = consecutive ? scene_locate(s, (uint32_t)lane_id[0], &run_k) : 0;
  if (run_k != RR_MISS && s->inst->shift[run_k] && run_st - s->inst->base + W <= s->inst->T) {
    const float *m = s->inst->xf[run_k];
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) p[k][a] = VF_(load)(s->p[k][a] + run_st) + VF_(splat)(m[4 * a + 3]);
    return;
  }
  float lane_tr[3 * W];
  int32_t lane_st[W], lane_moved[W];
  if (scene_lanes(s, lane_id, W, lane_st, lane_tr, lane_moved)) {
    const VI st_idx = VI_(load)(lane_st), moved = VI_(load)(lane_moved);
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) {
        VF g = VF_(gather)(s->p[k][a], st_idx);
        p[k][a] = VF_(select)(moved, g + VF_(load)(lane_tr + a * W), g);
      }
    return;
  }
  float lane_p[3][3][W];
  for (int l = 0; l < W; l++)
    for (int k = 0; k < 3; k++) {
      vec3 v = scene_vertex(s, k, (uint32_t)lane_id[l]);
      lane_p[k][0][l] = v.x, lane_p[k][1][l] = v.y, lane_p[k][2][l] = v.z;
    }
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < 3; a++) p[k][a] = VF_(load)(lane_p[k][a]);
}
