/* A setup's values in lanes, as both loops below read them. */
typedef struct {
  VF a[3], b[3], cc[3];
  VI tie[3], tie2[3]; /* -1 and -2 where edge e's tie bit is set, else 0 */
  VF w0, w1, w2, vol, vol_x, vol_y, pb, pc, num_x, num_y;
} RR_CAT(tri_lanes, W);

TARGET static inline __attribute__((always_inline)) RR_CAT(tri_lanes, W) RR_CAT(lanes_of, W)(const tri_setup *ts) {
  RR_CAT(tri_lanes, W) L;
#pragma GCC unroll 3
  for (int e = 0; e < 3; e++) {
    L.a[e] = VF_(splat)(ts->a[e]), L.b[e] = VF_(splat)(ts->b[e]), L.cc[e] = VF_(splat)(ts->c[e]);
    L.tie[e] = VI_(splat)(ts->tie >> e & 1u ? -1 : 0), L.tie2[e] = L.tie[e] + L.tie[e];
  }
  L.w0 = VF_(splat)(ts->w[0]), L.w1 = VF_(splat)(ts->w[1]), L.w2 = VF_(splat)(ts->w[2]);
  L.vol = VF_(splat)(ts->vol), L.vol_x = VF_(splat)(ts->vol_x), L.vol_y = VF_(splat)(ts->vol_y);
  L.pb = VF_(splat)(ts->pb), L.pc = VF_(splat)(ts->pc);
  L.num_x = VF_(splat)(ts->num_x), L.num_y = VF_(splat)(ts->num_y);
  return L;
}

typedef uint32_t RR_CAT(vu, W) __attribute__((vector_size(sizeof(VI))));

/* TRI_EDGE_INSIDE(e, tie, 0) in two integer operations on e's bits, where it takes
 * four: e > 0 is bits > 0 (-0 is INT32_MIN); with the tie, e >= 0 is bits - 1 > -2
 * (wrapping: -0 becomes INT32_MAX, +0 -1, every negative float below -2). A NaN may
 * land either side, but then the weighted sum is NaN too and TRI_HIT_AHEAD rejects
 * the lane, so the hits are TRI_EDGE_INSIDE's. */
TARGET static inline __attribute__((always_inline)) VI RR_CAT(edge_inside, W)(VF e, VI tie, VI tie2) {
  return (VI)((RR_CAT(vu, W))e + (RR_CAT(vu, W))tie) > tie2;
}

/* The 3D rasterizer's sample loop for W lanes: a kernel template (core/simd.h)
 * that raster3d.c instantiates per width through core/simd_widths.h.
 *
 * Every sample of rectangle r against one set-up triangle, W samples of a row at
 * a time, columns then rows (the terms in sx are the same on every row), for each
 * of ns sample positions in turn: the triangle's constants are loaded once. One
 * position (mv NULL): ts's own over r. Several: the k-th is position s = act[k]
 * (cams[s], sample s of each pixel of vb: a gather, and the winners written one at
 * a time, as the lanes' samples lie vb->ns apart) over its own rectangle rs[k]
 * (inside r), with mv's four setup values that move with it. A lane is
 * the sample test of prim/triangle.h (sample_test_w) and the depth test of
 * vis/vis.h (depth_wins), with the depth of TRI_DEPTH: the same operations in the same order on IEEE single
 * floats (no FMA, a true division), so every width gives their bits. Lanes past
 * r[2] are masked off and touch no memory. */

TARGET KERNEL uint64_t RR_CAT(raster_loop, W)(const tri_setup *ts, const tri_moves *mv, const uint8_t *act,
                                                     const int (*rs)[4], uint32_t id, const int r0[4],
                                                     const camera *cams, int ns, visbuf *vb, const bool planar,
                                                     const bool dense) {
  const RR_CAT(tri_lanes, W) L = RR_CAT(lanes_of, W)(ts);
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f);
  /* depth_wins compares ids unsigned: flip the sign bits for a signed compare */
  const VI idv = VI_(splat)((int32_t)id), bias = VI_(splat)(INT32_MIN), id_biased = idv ^ bias;
  const size_t width = (size_t)vb->width, stride = dense ? 1 : (size_t)vb->ns;
  /* not dense (several samples a pixel): a row's samples of one position lie
   * stride apart, read by gathers of 32-bit indices where they fit */
  const bool gathered = (uint64_t)stride * width * (size_t)vb->height <= INT32_MAX;
  const VI strides = VI_(splat)((int32_t)stride) * VI_(lanes)();
  uint64_t covered = 0;
  for (int k = 0; k < ns; k++) {
  const int s = mv ? act[k] : 0, *r = mv ? rs[k] : r0;
  const camera *c = &cams[s];
  const struct { float pa, num0, cx, cy; } p = {mv ? mv->pa[s] : ts->pa, mv ? mv->num0[s] : ts->num0,
                                               mv ? mv->cx[s] : ts->cx, mv ? mv->cy[s] : ts->cy};
  const VI end = VI_(splat)(r[2] + 1);
  const VF pa = VF_(splat)(p.pa), num0 = VF_(splat)(p.num0), cx = VF_(splat)(p.cx), cy = VF_(splat)(p.cy);
  /* curved: the rays' directions by gathers of 32-bit float offsets where they fit */
  const bool dirs_gathered = !planar && (uint64_t)3 * width * (size_t)vb->height <= INT32_MAX;
  float *best_t = vb->t + s, *l1 = vb->l1 + s, *l2 = vb->l2 + s; /* sample s of each pixel */
  int32_t *best_id = (int32_t *)vb->id + s;
  for (int x = r[0]; x <= r[2]; x += W) {
    const VI xi = VI_(splat)(x) + VI_(lanes)(), valid = end > xi;
    const VF sx = VF_(from_int)(xi) + VF_(splat)(c->sx0);
    VF ax[3]; /* planar: a·1 + b·sx, the part of each edge function that rows share */
#pragma GCC unroll 3
    for (int e = 0; e < 3; e++) ax[e] = L.a[e] * one + L.b[e] * sx;
    const VF vx = L.vol + sx * L.vol_x, px = pa * one + L.pb * (sx - cx), nx = num0 + (sx - cx) * L.num_x;
    for (int y = r[1]; y <= r[3]; y++) {
      const VF sy = VF_(splat)((float)y + c->sy0);
      const size_t k = (size_t)y * width + (size_t)x;
      VF wx = zero, wy = zero, wz = zero; /* curved: the camera's ray direction per sample */
      if (!planar && dirs_gathered) { /* (lanes past r[2] read the first one's) */
        const VI at = (VI_(splat)((int32_t)k) + VI_(select)(valid, VI_(lanes)(), VI_(splat)(0))) * VI_(splat)(3);
        wx = VF_(gather)(&c->dirs->x, at), wy = VF_(gather)(&c->dirs->y, at), wz = VF_(gather)(&c->dirs->z, at);
      } else if (!planar) {
        for (int l = 0; l < W; l++) {
          vec3 d = c->dirs[k + (size_t)(x + l <= r[2] ? l : 0)];
          wx[l] = d.x, wy[l] = d.y, wz[l] = d.z;
        }
      }
      VF ev[3];
      VI in = valid;
#pragma GCC unroll 3
      for (int e = 0; e < 3; e++) {
        ev[e] = planar ? ax[e] + L.cc[e] * sy : L.a[e] * wx + L.b[e] * wy + L.cc[e] * wz;
        in &= RR_CAT(edge_inside, W)(ev[e], L.tie[e], L.tie2[e]);
      }
      if (!VI_(bits)(in)) continue;
      const VF sum = ev[0] * L.w0 + ev[1] * L.w1 + ev[2] * L.w2, v = vx + sy * L.vol_y;
      in &= TRI_HIT_AHEAD(sum, v, zero);
      int hit = VI_(bits)(in);
      if (!hit) continue;
      covered += W == 1 ? (uint64_t)hit : (uint64_t)__builtin_popcount((unsigned)hit);
      const VF den = planar ? px + L.pc * (sy - cy) : pa * wx + L.pb * (wy - cx) + L.pc * (wz - cy);
      const VF inv = one / sum, t = TRI_DEPTH(nx + (sy - cy) * L.num_y, den, v, inv, zero, VF_(select));
      if (dense) {
        const VF bt = VF_(load_masked)(best_t + k, in);
        const VI bid = VI_(load_masked)(best_id + k, in);
        const VI wins = in & ((t < bt) | ((t == bt) & ((bid ^ bias) > id_biased)));
        if (!VI_(bits)(wins)) continue;
        VF_(store_masked)(best_t + k, wins, t);
        VI_(store_masked)(best_id + k, wins, idv);
        VF_(store_masked)(l1 + k, wins, ev[1] * inv);
        VF_(store_masked)(l2 + k, wins, ev[2] * inv);
      } else {
        const VF b1 = ev[1] * inv, b2 = ev[2] * inv;
        if (gathered) {
          const VI kv = VI_(splat)((int32_t)(k * stride)) + strides;
          const VF bt = VF_(gather_masked)(best_t, kv, in);
          const VI bid = VI_(gather_masked)(best_id, kv, in);
          hit = VI_(bits)(in & ((t < bt) | ((t == bt) & ((bid ^ bias) > id_biased))));
        }
        for (; hit; hit &= hit - 1) { /* the winners' writes, one lane at a time */
          const int l = __builtin_ctz((unsigned)hit);
          const size_t q = (k + (size_t)l) * stride;
          if (gathered || t[l] < best_t[q] || (t[l] == best_t[q] && (uint32_t)best_id[q] > id))
            best_t[q] = t[l], best_id[q] = (int32_t)id, l1[q] = b1[l], l2[q] = b2[l];
        }
      }
    }
  }
  }
  return covered;
}

/* One position (the usual frame) and several: the loop above inlined into each,
 * so the one-position frame pays nothing for the loop over positions. */
TARGET static uint64_t RR_CAT(raster_one, W)(const tri_setup *ts, uint32_t id, const int r[4], const camera *c,
                                             visbuf *vb, const bool planar) {
  return planar ? RR_CAT(raster_loop, W)(ts, NULL, NULL, NULL, id, r, c, 1, vb, true, true)
                : RR_CAT(raster_loop, W)(ts, NULL, NULL, NULL, id, r, c, 1, vb, false, true);
}
TARGET static uint64_t RR_CAT(raster_many, W)(const tri_setup *ts, const tri_moves *mv, const uint8_t *act,
                                              const int (*rs)[4], uint32_t id, const camera *cams, int n,
                                              visbuf *vb, const bool planar) {
  return planar ? RR_CAT(raster_loop, W)(ts, mv, act, rs, id, rs[0], cams, n, vb, true, false)
                : RR_CAT(raster_loop, W)(ts, mv, act, rs, id, rs[0], cams, n, vb, false, false);
}

#include "prim/triangle_moved_tmp.h"

/* A triangle at several positions (planar cameras), within r: set up once for all
 * of them, lanes over (position, pixel) pairs. A step takes P positions (ns rounded
 * up to a power of two, at most W) at W / P pixels each. Each position's rectangle
 * comes in the lanes from the bounds' bits (tri_pos_rect), its moved setup values
 * (tri_moved) at the first hit: a draw costs nothing per position beyond its lanes.
 * The same operations in the same order as the loop above, lane by lane, so the
 * same bits. Two walks:
 * - each lane over its own rectangle (within r) in row order, so a triangle of a
 *   pixel or two costs one step per P positions. The lanes that pass take the depth
 *   test together (their samples are distinct: a lane's position or pixel
 *   differs), reading their samples by a gather of 32-bit indices (frames of fewer
 *   than 2^31 samples; larger ones test one lane at a time), and the winners are
 *   written one at a time.
 * - together (ns a power of two; larger draws): every lane at the same W / P pixels
 *   of the union of the rectangles, off where its own rectangle is not: the lanes'
 *   samples lie side by side in the buffer (vis.h), so one masked load and store an
 *   array. A few steps more than the largest rectangle (positions' rectangles
 *   differ by a row or column), no gathers and no one-at-a-time writes.
 * Adds the samples tested (those of the lanes' own rectangles) to *tested. */

/* One step's tests at the lanes' pixels (x, y) (*in: the lanes to test, then those
 * that hit): the edges, the hit ahead, then the depth and barycentrics. */
TARGET static inline __attribute__((always_inline)) int RR_CAT(pixel_hits, W)(
    const RR_CAT(tri_lanes, W) * L, const tri_setup *ts, const tri_moves *mv, const camera *c, VF ox, VF oy, VF m[4],
    bool *moved, VI x, VI y, VI *in, VF *t, VF *l1, VF *l2) {
  const VF zero = VF_(splat)(0.0f), one = VF_(splat)(1.0f);
  const VF sx = VF_(from_int)(x) + ox, sy = VF_(from_int)(y) + oy;
  VF ev[3];
  VI inside = *in;
#pragma GCC unroll 3
  for (int e = 0; e < 3; e++) {
    ev[e] = (L->a[e] * one + L->b[e] * sx) + L->cc[e] * sy;
    inside &= RR_CAT(edge_inside, W)(ev[e], L->tie[e], L->tie2[e]);
  }
  if (!VI_(bits)(inside)) return 0;
  const VF sum = ev[0] * L->w0 + ev[1] * L->w1 + ev[2] * L->w2, v = (L->vol + sx * L->vol_x) + sy * L->vol_y;
  inside &= TRI_HIT_AHEAD(sum, v, zero);
  const int hit = VI_(bits)(inside);
  if (!hit) return 0;
  if (!*moved) RR_CAT(tri_moved_lanes, W)(ts, mv->pl, c, ox, oy, m), *moved = true;
  const VF pa = m[0], num0 = m[1], cx = m[2], cy = m[3];
  const VF den = (pa * one + L->pb * (sx - cx)) + L->pc * (sy - cy);
  const VF inv = one / sum;
  *t = TRI_DEPTH((num0 + (sx - cx) * L->num_x) + (sy - cy) * L->num_y, den, v, inv, zero, VF_(select));
  *l1 = ev[1] * inv, *l2 = ev[2] * inv, *in = inside;
  return hit;
}

TARGET static inline __attribute__((always_inline)) uint64_t RR_CAT(pixels_at, W)(
    const tri_setup *ts, const tri_moves *mv, uint32_t id, const int r[4], const camera *c, int ns, visbuf *vb,
    uint64_t *tested, const int lg, const bool together) {
  const RR_CAT(tri_lanes, W) L = RR_CAT(lanes_of, W)(ts);
  const VF one = VF_(splat)(1.0f);
  const size_t width = (size_t)vb->width, nsv = (size_t)vb->ns, layer = width * (size_t)vb->height;
  const int P = 1 << lg, G = W / P;
  /* one pixel a lane (P = W): the next pixel is the one to the right, or the row's
   * first on the next row, without the division by the width */
  const bool stepwise = G == 1;
  const VI lane = VI_(lanes)(), one_i = VI_(splat)(1), zero_i = VI_(splat)(0);
  const VF half = VF_(splat)(0.5f);
  const tri_pos_bits *b = mv->pos;
  const bool gathered = (uint64_t)nsv * layer <= INT32_MAX;
  const VI nsv_i = VI_(splat)((int32_t)nsv);
  /* the buffer's arrays in locals: the compiler cannot tell that the writes leave vb alone */
  float *const buf_t = vb->t, *const buf_l1 = vb->l1, *const buf_l2 = vb->l2;
  uint32_t *const buf_id = vb->id;
  /* depth_wins compares ids unsigned: flip the sign bits for a signed compare */
  const VI bias = VI_(splat)(INT32_MIN), id_biased = VI_(splat)((int32_t)id) ^ bias, idv = VI_(splat)((int32_t)id);
  uint64_t covered = 0, evals = 0;
  for (int p0 = 0; p0 < ns; p0 += P) {
    const VI p = VI_(splat)(p0) + (lane & (P - 1)), bit = one_i << p;
    /* tri_pos_rect in the lanes, clipped to r */
    VI x0 = VI_(splat)(mv->bb[0]) - ((VI_(splat)(b->x0) & bit) != 0);
    VI y0 = VI_(splat)(mv->bb[1]) - ((VI_(splat)(b->y0) & bit) != 0);
    VI x1 = VI_(splat)(mv->bb[2]) + ((VI_(splat)(b->x1) & bit) != 0);
    VI y1 = VI_(splat)(mv->bb[3]) + ((VI_(splat)(b->y1) & bit) != 0);
    const VI r0 = VI_(splat)(r[0]), r1 = VI_(splat)(r[1]), r2 = VI_(splat)(r[2]), r3 = VI_(splat)(r[3]);
    x0 = VI_(select)(x0 < r0, r0, x0), y0 = VI_(select)(y0 < r1, r1, y0);
    x1 = VI_(select)(x1 > r2, r2, x1), y1 = VI_(select)(y1 > r3, r3, y1);
    const VI live = ((VI_(splat)(b->none) & bit) == 0) & (p < ns) & (x0 <= x1) & (y0 <= y1);
    if (!VI_(bits)(live)) continue;
    /* a lane without samples has none to run */
    const VI wv = VI_(select)(live, x1 - x0 + one_i, one_i), n = VI_(select)(live, wv * (y1 - y0 + one_i), zero_i);
    const VF ox = VF_(gather)(mv->ox, p), oy = VF_(gather)(mv->oy, p);
    VF m[4], t, l1, l2;
    bool moved = false;
    if (together) {
      /* the union of the live lanes' rectangles; lane l at pixel (ux + l / P, uy) */
      int ux0 = INT32_MAX, uy0 = INT32_MAX, ux1 = INT32_MIN, uy1 = INT32_MIN;
      for (int l = 0; l < P; l++) /* (lanes l and l + P hold the same position) */
        if (live[l]) {
          ux0 = x0[l] < ux0 ? x0[l] : ux0, uy0 = y0[l] < uy0 ? y0[l] : uy0;
          ux1 = x1[l] > ux1 ? x1[l] : ux1, uy1 = y1[l] > uy1 ? y1[l] : uy1;
          evals += (uint64_t)n[l];
        }
      const VI g = lane >> lg;
      for (int uy = uy0; uy <= uy1; uy++) {
        const VI y = VI_(splat)(uy), in_row = live & (y >= y0) & (y <= y1);
        if (!VI_(bits)(in_row)) continue;
        for (int ux = ux0; ux <= ux1; ux += G) {
          const VI x = VI_(splat)(ux) + g;
          VI in = in_row & (x >= x0) & (x <= x1);
          if (!VI_(bits)(in)) continue;
          const int hit = RR_CAT(pixel_hits, W)(&L, ts, mv, c, ox, oy, m, &moved, x, y, &in, &t, &l1, &l2);
          if (!hit) continue;
          covered += W == 1 ? (uint64_t)hit : (uint64_t)__builtin_popcount((unsigned)hit);
          const size_t k = ((size_t)uy * width + (size_t)ux) * nsv + (size_t)p0; /* lane 0's sample */
          const VF bt = VF_(load_masked)(buf_t + k, in);
          const VI bid = VI_(load_masked)((const int32_t *)buf_id + k, in);
          const VI wins = in & ((t < bt) | ((t == bt) & ((bid ^ bias) > id_biased)));
          if (!VI_(bits)(wins)) continue;
          VF_(store_masked)(buf_t + k, wins, t);
          VI_(store_masked)((int32_t *)buf_id + k, wins, idv);
          VF_(store_masked)(buf_l1 + k, wins, l1);
          VF_(store_masked)(buf_l2 + k, wins, l2);
        }
      }
      continue;
    }
    const VF inv_w = one / VF_(from_int)(wv);
    /* each lane's pixels: the q-th of every G of its rectangle's in row order; pixel
     * i is in row (i + 1/2) / wv, rounded down (exact while i < 2^22: the quotient
     * lies 1/(2·wv) or more from an integer, far above two roundings) */
    int most = 0; /* stepwise: the steps left, from the lanes' largest pixel count */
    if (stepwise)
      for (int l = 0; l < W; l++) most = n[l] > most ? n[l] : most, evals += (uint64_t)n[l];
    VI x = x0, y = y0, wrap;
    for (VI i = lane >> lg, in; !stepwise || most > 0; most--, i += VI_(splat)(G), /* to the next pixel */
         stepwise ? (x += one_i, wrap = x > x1, x = VI_(select)(wrap, x0, x), y -= wrap) : x) {
      in = i < n;
      if (!stepwise) {
        const int tried = VI_(bits)(in);
        if (!tried) break;
        evals += (uint64_t)__builtin_popcount((unsigned)tried);
        const VI row = VI_(trunc)((VF_(from_int)(i) + half) * inv_w);
        x = x0 + (i - row * wv), y = y0 + row;
      }
      int hit = RR_CAT(pixel_hits, W)(&L, ts, mv, c, ox, oy, m, &moved, x, y, &in, &t, &l1, &l2);
      if (!hit) continue;
      covered += W == 1 ? (uint64_t)hit : (uint64_t)__builtin_popcount((unsigned)hit);
      if (gathered) {
        const VI kv = (y * VI_(splat)((int32_t)width) + x) * nsv_i + p;
        const VF bt = VF_(gather_masked)(buf_t, kv, in);
        const VI bid = VI_(gather_masked)((const int32_t *)buf_id, kv, in);
        /* the winners' writes, one lane at a time (no scatter in AVX2) */
        for (hit = VI_(bits)(in & ((t < bt) | ((t == bt) & ((bid ^ bias) > id_biased)))); hit; hit &= hit - 1) {
          const int l = __builtin_ctz((unsigned)hit);
          const size_t k = (uint32_t)kv[l];
          buf_t[k] = t[l], buf_id[k] = id, buf_l1[k] = l1[l], buf_l2[k] = l2[l];
        }
      } else
        for (; hit; hit &= hit - 1) {
          const int l = __builtin_ctz((unsigned)hit);
          const size_t k = ((size_t)y[l] * width + (size_t)x[l]) * nsv + (size_t)p[l];
          if (t[l] < buf_t[k] || (t[l] == buf_t[k] && buf_id[k] > id))
            buf_t[k] = t[l], buf_id[k] = id, buf_l1[k] = l1[l], buf_l2[k] = l2[l];
        }
    }
  }
  *tested += evals;
  return covered;
}
TARGET static uint64_t RR_CAT(raster_pixels, W)(const tri_setup *ts, const tri_moves *mv, uint32_t id,
                                                const int r[4], const camera *c, int ns, visbuf *vb,
                                                uint64_t *tested) {
  const int lg_w = __builtin_ctz(W), lg_ns = ns > 1 ? 32 - __builtin_clz((unsigned)ns - 1) : 0;
  return lg_ns >= lg_w ? RR_CAT(pixels_at, W)(ts, mv, id, r, c, ns, vb, tested, lg_w, false)
                       : RR_CAT(pixels_at, W)(ts, mv, id, r, c, ns, vb, tested, lg_ns, false);
}
/* The same by the walk together (ns a power of two: a step's lanes are side by side). */
TARGET static uint64_t RR_CAT(raster_together, W)(const tri_setup *ts, const tri_moves *mv, uint32_t id,
                                                  const int r[4], const camera *c, int ns, visbuf *vb,
                                                  uint64_t *tested) {
  const int lg_w = __builtin_ctz(W), lg_ns = ns > 1 ? 32 - __builtin_clz((unsigned)ns - 1) : 0;
  return RR_CAT(pixels_at, W)(ts, mv, id, r, c, ns, vb, tested, lg_ns >= lg_w ? lg_w : lg_ns, true);
}
