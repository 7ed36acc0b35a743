/* Ray casting through the BVH: rc-bvh (one ray per sample) and rc-packet (8x8
 * packets of primary rays), both through the one traversal of vis/bvh_trace.h
 * (the public queries rr_intersect / rr_occluded use it too: vis/ray_query.c).
 *
 * Leaves run the project's one sample test, so the methods produce the same bits
 * as rc and 3dr-bb: a primary ray tests a triangle set up by rr_tri_setup()
 * for the camera (once per frame, kept in leaf order) with shade_sample_w() at
 * its sample. Traversal only decides which (sample, triangle) pairs are visited,
 * and for primary rays it never skips the winner, by construction:
 * - planar cameras test a triangle only at the samples of its corner rectangle
 *   (rr_tri_corner_bounds), exactly the samples 3dr-bb tests it at, so the two
 *   choose among the same candidates (where that rectangle is the whole image, only
 *   its part inside the polygon bounds of rr_tri_bounds, which hold every sample
 *   where the triangle can pass as well); triangles whose rectangle holds no sample
 *   (most of a detailed mesh's) are not set up;
 * - each triangle set up gets, per frame, a lower bound of the t that
 *   sample_test() can compute for it at those samples (rr_tri_rect_floor; curved
 *   cameras: rr_tri_bounds over the image), from the float error of the edge
 *   functions and of the plane; a rectangle of at most PROBE samples (most
 *   triangles of a detailed mesh) is tested at its samples instead, with the
 *   rays' own test, so its bound is the exact least t and its rectangle shrinks to
 *   the samples where it passes (probe_samples); nodes take the least bound and
 *   the union of rectangles;
 * - a ray skips a node whose rectangle does not hold its sample, or whose bound
 *   is greater than its best t (strictly: an equal t with a lower id still wins).
 * The price of exactness is that per-frame pass. Perspective views of scenes
 * with more triangles than samples walk down the tree to the boxes whose projection
 * may hold a sample (box_reach, reach_walk; below a box over a few samples with
 * a few triangles, their corner bounds are cheaper than more boxes), so the pass
 * follows what the view sees (a few cells of a 2M-triangle plane: 24 setups, the
 * frame 92% rays); the
 * others bound every triangle's corners (in id order, streaming the vertex arrays)
 * and every wide node. Either way setups, floors and their memory follow the
 * triangles a sample reaches (19² teapot grid, 1024²: 37% of them, which is what a
 * frame of the whole grid still costs: at 512², one thread, the rays take 73 M
 * instructions, fewer than Embree's 110 M for rtcIntersect1, the pass 490 M: the
 * walk and its box tests 190 M, corner bounds 100 M, setups 40 M, floors and
 * leaf bookkeeping 80 M, the unions up the tree 50 M). Triangles cutting the eye's plane are set
 * up to be bounded by their polygons: a tilted view of a large plane sets up a
 * line of them (√N). Box entry
 * distances would remove it but are no proven bound: a triangle seen at a grazing
 * angle computes t = num / den with a relative error of a few ulps over the cosine
 * to its plane, after edge tests that pass rays up to a few ulps outside it, which
 * puts the plane's hit a distance ~ ulps / sin² away along a plane of slope sin;
 * TRI_DEPTH's fallback has no bound at all; rc and 3dr-bb keep such hits. A proof
 * needs per node a floor on the sine between the eye's rays and its triangles'
 * planes (normal cones in the tree), with per-frame exact floors kept for the
 * nodes that fail it. Curved cameras use 3D box tests widened by RAY_MARGIN
 * relative to t (NaN slabs ignored) besides the exact bounds. */
#include "vis/bvh_trace.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

/* ---- per-frame triangle setups and exact pruning bounds ------------------------ */

/* A node's `tlo` is the least floor of its triangles (see the head comment): a
 * primary ray prunes a node only when it is greater than its best t. */
/* A triangle's setup with its id and the samples x0, y0, x1, y1 where it is
 * tested: what a leaf reads. Kept only for the triangles a sample can reach, side
 * by side (a batch of leaves takes its run of them), so the memory a frame
 * touches follows those rather than the scene: on a detailed scene most are not. */
typedef struct {
  tri_setup ts;
  uint32_t id;
  float rect[4];
} leaf_tri;

/* Per wide node and slot: the screen rectangle (planar cameras) and the bound;
 * an empty slot has an empty rectangle and an infinite bound. */
typedef struct {
  rr_vf4 x0, y0, x1, y1, tlo;
  uint32_t ref[4], count[4]; /* the node's (an instance's moved to its place): what the rays descend by */
  uint32_t slots; /* the node's non-empty slots, what N counts for its test: one load, not four compares */
} wide_bounds;

typedef struct {
  uint64_t evals, nodes, setups;
  char pad[40]; /* one cache line per thread */
} thread_stats;

typedef struct {
  const rr_scene *s;
  const rr_bvh *b;
  const camera *cam;
  bool cull, simd;
  leaf_tri *ts;      /* the live triangles, in runs of a batch */
  atomic_uint nts;   /* how many ts holds */
  uint32_t *slot;    /* by position in b->prims: its index in ts, or UINT32_MAX */
  uint8_t *seen;     /* by triangle id (eager planar frames): its corner rectangle holds a sample */
  uint8_t *reached;  /* by wide node (perspective frames): its box may hold a sample (reach_walk) */
  wide_bounds *wb;   /* by wide node */
  thread_stats *st;  /* per thread: S */
  rr_device *dev;    /* keeps ts, slot and wb for its next frame (rr_scratch_take) */
  rr_buf ts_buf, slot_buf, wb_buf;
} frame_setups;

enum { SETUP_CHUNK = 1024, SEEN_CHUNK = 1024, BATCH = 2 * BVH_MAX_LEAF };
enum { SETUP_ANALYTIC = -2 }; /* leaf_batch.setup of an analytic primitive */
/* reach_walk stops testing boxes below a slot over at most REACH_FEW samples whose
 * subtree holds at most REACH_CAP triangles; batch_finish tests a triangle whose
 * corner rectangle holds at most PROBE samples at them (probe_samples). Both
 * chosen by instruction counts on the bunny and teapot grids at 512² and 1024². */
enum { REACH_FEW = 4, REACH_CAP = 8, PROBE = 4 };

/* A batch of leaves (leaves[]: wide node · 4 + slot) and their triangles ids[k],
 * and of the ones set up (setup[k] >= 0: their index in ts/face) the pixel
 * rectangle bb[k] (planar). */
typedef struct {
  uint32_t ids[BATCH], sid[BATCH], leaves[BATCH], first[BATCH], count[BATCH]; /* per leaf: its positions */
  int n, nl, setup[BATCH];
  int nout; /* the setups and analytic primitives: batch_finish's run in ts */
  int bb[BATCH][4];
  tri_setup ts[BATCH];
  int face[BATCH];
  tri_bound found[BATCH];
} leaf_batch;

/* Adds leaf slot `leaf` (wide node · 4 + slot) holding positions [first, first + count). */
static void leaf_add(leaf_batch *lb, const rr_bvh *b, uint32_t leaf, uint32_t first, uint32_t count) {
  bvh_prims_at(b, first, count, lb->ids + lb->n);
  lb->first[lb->nl] = first, lb->count[lb->nl] = count;
  lb->n += (int)count, lb->leaves[lb->nl++] = leaf;
}

/* Sets up the batch's triangles that can be seen, eight lanes at a time where
 * there is AVX2 (lanes never mix: the same bits as one at a time). Planar cameras
 * first bound each triangle by its corners (rr_tri_corner_bounds, the rectangles
 * 3dr-bb tests it over): most triangles of a detailed mesh fall between samples
 * and cost no setup. */
static void batch_setup(frame_setups *fs, leaf_batch *lb, int thread) {
  int ns = 0, nana = 0;
  /* analytic primitives (SETUP_ANALYTIC) are bounded in batch_finish, not set up */
  const rr_scene *s = fs->s;
  if (fs->cam->planar) {
    uint32_t near[BATCH], nn = 0; /* seen_chunk's survivors, bounded again for their rectangles */
    for (int k = 0; k < lb->n; k++)
      if ((!fs->seen || fs->seen[lb->ids[k]]) && scene_kind(s, lb->ids[k]) == RR_GEOMETRY_TRIANGLE)
        near[nn++] = lb->ids[k];
    uint32_t nf = rr_tri_corner_bounds(fs->s, 0, near, nn, fs->cam, fs->simd, lb->found);
    for (int k = 0, q = 0; k < lb->n; k++) {
      bool kept = q < (int)nf && lb->found[q].id == lb->ids[k]; /* in order; ids in a tree are distinct */
      lb->setup[k] = scene_kind(s, lb->ids[k]) != RR_GEOMETRY_TRIANGLE ? SETUP_ANALYTIC : kept ? ns : -1;
      nana += lb->setup[k] == SETUP_ANALYTIC;
      if (kept) memcpy(lb->bb[k], lb->found[q++].bb, sizeof lb->bb[k]), lb->sid[ns++] = lb->ids[k];
    }
  } else {
    for (int k = 0; k < lb->n; k++)
      if (scene_kind(s, lb->ids[k]) != RR_GEOMETRY_TRIANGLE) lb->setup[k] = SETUP_ANALYTIC, nana++;
      else lb->setup[k] = ns, lb->sid[ns++] = lb->ids[k];
  }
  lb->nout = ns + nana;
  rr_tri_setup_run(fs->s, lb->sid, ns, fs->cam, fs->cull, fs->simd, lb->ts, lb->face);
  fs->st[thread].setups += (uint64_t)ns;
}

/* Marks the triangles [job·chunk, (job+1)·chunk) whose corner rectangle holds a
 * sample: in id order, the order of the vertex arrays, where leaf order would
 * gather nine scattered floats a triangle. */
static void seen_chunk(int job, int thread, void *arg) {
  (void)thread;
  frame_setups *fs = arg;
  uint32_t i0 = (uint32_t)job * SEEN_CHUNK, n = fs->s->ntris - i0 < SEEN_CHUNK ? fs->s->ntris - i0 : SEEN_CHUNK;
  tri_bound found[SEEN_CHUNK];
  memset(fs->seen + i0, 0, n);
  uint32_t nf = rr_tri_corner_bounds(fs->s, i0, NULL, n, fs->cam, fs->simd, found);
  for (uint32_t q = 0; q < nf; q++) fs->seen[found[q].id] = 1;
}

/* A triangle whose corner rectangle bb holds at most PROBE samples (most of a
 * detailed mesh's) is tested at them here, with the sample test its rays make
 * (the same w, sx, sy: the same bits): its floor is then the least t it gives
 * there, exact, and its rectangle tr only the samples where it passes (none: it
 * is dropped, +inf). Cheaper than a floor over the rectangle in double, and
 * tighter for the rays. A NaN t, which never wins, still floors by 0. */
static float probe_samples(const tri_setup *ts, const camera *c, const int bb[4], float tr[4]) {
  float lo = INFINITY, r[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (int y = bb[1]; y <= bb[3]; y++)
    for (int x = bb[0]; x <= bb[2]; x++) {
      float sx = (float)x + c->sx0, sy = (float)y + c->sy0, e[3], t, l1, l2;
      vec3 w = v3(1.0f, sx, sy);
      tri_edges_w(ts, w, e);
      if (!sample_test_w(e, ts->w, ts->tie, tri_vol(ts, sx, sy), tri_num(ts, sx, sy), tri_den_w(ts, w), &t, &l1, &l2))
        continue;
      t = t == t ? t : 0;
      lo = t < lo ? t : lo;
      r[0] = minf(r[0], sx), r[1] = minf(r[1], sy), r[2] = maxf(r[2], sx), r[3] = maxf(r[3], sy);
    }
  memcpy(tr, r, sizeof r);
  return lo;
}

/* Finishes the batch's leaves: each triangle's setup, id, rectangle and floor, each
 * leaf's least floor and rectangle into its wide node's slot. A planar camera's triangle is tested only at
 * the samples of its corner rectangle (as 3dr-bb tests it), so its floor holds over
 * that rectangle; a curved camera's over the whole image. */
static void batch_finish(frame_setups *fs, const leaf_batch *lb) {
  const camera *c = fs->cam;
  /* The batch's run: room for every triangle set up; those with a sample where
   * they can pass are packed at its start (the rest, culled or never passing,
   * leave its end unused and cost no copy). Where the run lands depends on the
   * threads' timing; what it holds does not. */
  uint32_t base = atomic_fetch_add_explicit(&fs->nts, (unsigned)lb->nout, memory_order_relaxed);
  leaf_tri *out = fs->ts + base;
  int nout = 0;
  for (int q = 0, k = 0; q < lb->nl; q++) {
    uint32_t w = lb->leaves[q] / 4, s = lb->leaves[q] % 4, first = lb->first[q];
    float tlo = INFINITY, r[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = first; i < first + lb->count[q]; i++, k++) {
      int j = lb->setup[k];
      fs->slot[i] = UINT32_MAX;
      if (j != SETUP_ANALYTIC && (j < 0 || lb->face[j] == SETUP_CULLED)) continue;
      /* the bounds into out[nout], kept only when some sample can pass */
      float t, *tr = out[nout].rect;
      const tri_setup *ts = j == SETUP_ANALYTIC ? NULL : &lb->ts[j];
      if (j == SETUP_ANALYTIC) {
        /* its samples (rr_ana_screen_bounds) and its floor over the image (rr_ana_t_floor) */
        int bb[4] = {0, 0, -1, -1};
        t = rr_ana_screen_bounds(fs->s, lb->ids[k], c, bb) ? rr_ana_t_floor(fs->s, lb->ids[k], c) : INFINITY;
        tr[0] = (float)bb[0] + c->sx0, tr[1] = (float)bb[1] + c->sy0;
        tr[2] = (float)bb[2] + c->sx0, tr[3] = (float)bb[3] + c->sy0;
      } else if (c->planar) {
        /* the extreme samples, as the rays compute their coordinates */
        tr[0] = (float)lb->bb[k][0] + c->sx0, tr[1] = (float)lb->bb[k][1] + c->sy0;
        tr[2] = (float)lb->bb[k][2] + c->sx0, tr[3] = (float)lb->bb[k][3] + c->sy0;
        const int *bb = lb->bb[k];
        if ((bb[2] - bb[0] + 1) * (bb[3] - bb[1] + 1) <= PROBE) {
          t = probe_samples(ts, c, bb, tr);
        } else if (bb[0] > 0 || bb[1] > 0 || bb[2] < c->width - 1 || bb[3] < c->height - 1) {
          t = rr_tri_rect_floor(ts, c, tr);
        } else {
          /* A corner rectangle of the whole image (mostly a triangle crossing the
           * eye's plane) would give every ancestor the whole image and a floor near
           * 0: inside a scene, every ray would test all such triangles. The
           * polygon's bounds hold every sample where it can pass too, so the
           * triangle is tested only where both rectangles meet, with their floor (a NaN
           * bound leaves the corner rectangle as it is). */
          float pr[4];
          t = rr_tri_bounds(ts, c, pr);
          tr[0] = maxf(pr[0], tr[0]), tr[1] = maxf(pr[1], tr[1]), tr[2] = minf(pr[2], tr[2]), tr[3] = minf(pr[3], tr[3]);
          if (!(tr[0] <= tr[2] && tr[1] <= tr[3])) t = INFINITY;
        }
      } else {
        t = rr_tri_bounds(ts, c, tr);
      }
      if (t == INFINITY) continue; /* no sample can pass */
      out[nout].id = lb->ids[k];
      if (ts) out[nout].ts = *ts;
      fs->slot[i] = base + (uint32_t)nout++;
      tlo = t < tlo ? t : tlo;
      r[0] = minf(r[0], tr[0]), r[1] = minf(r[1], tr[1]), r[2] = maxf(r[2], tr[2]), r[3] = maxf(r[3], tr[3]);
    }
    wide_bounds *wb = &fs->wb[w];
    wb->tlo[s] = tlo, wb->x0[s] = r[0], wb->y0[s] = r[1], wb->x1[s] = r[2], wb->y1[s] = r[3];
  }
}

/* Sets up the triangles of the leaf slots of wide nodes [job·chunk, (job+1)·chunk)
 * and gives their empty slots no samples. Leaves hold a few triangles each, so
 * those of several leaves are set up together. */
static void setup_leaves(int job, int thread, void *arg) {
  frame_setups *fs = arg;
  const rr_bvh *b = fs->b;
  uint32_t w0 = (uint32_t)job * SETUP_CHUNK, w1 = w0 + SETUP_CHUNK < b->vwide ? w0 + SETUP_CHUNK : b->vwide;
  leaf_batch lb;
  lb.n = lb.nl = 0;
  for (uint32_t w = w0; w < w1; w++) {
    BVH_NODE_ALIGN bvh_wide buf;
    const bvh_wide *n = bvh_wide_at(b, w, &buf);
    memcpy(fs->wb[w].ref, n->ref, sizeof n->ref), memcpy(fs->wb[w].count, n->count, sizeof n->count);
    for (uint32_t i = 0; i < 4; i++) {
      if (n->ref[i] == UINT32_MAX) {
        wide_bounds *wb = &fs->wb[w];
        wb->tlo[i] = wb->x0[i] = wb->y0[i] = INFINITY, wb->x1[i] = wb->y1[i] = -INFINITY;
      }
      if (!n->count[i]) continue; /* empty, or an inner slot: wide_union's */
      if (lb.n + (int)n->count[i] > BATCH) {
        batch_setup(fs, &lb, thread), batch_finish(fs, &lb);
        lb.n = lb.nl = 0;
      }
      leaf_add(&lb, b, 4 * w + i, n->ref[i], n->count[i]);
    }
  }
  batch_setup(fs, &lb, thread), batch_finish(fs, &lb);
}

/* Fills the inner slots of wide node w from their children, bottom up, and returns
 * the union of its slots: the least bound and the rectangle x0, y0, x1, y1. At
 * `depth` 0 the node's subtree is already filled (reach_subtree: the subtrees in
 * parallel), so only its union is taken; below 0 it never stops. */
static void wide_union(frame_setups *fs, uint32_t w, int depth, float u[5]) {
  wide_bounds *wb = &fs->wb[w];
  if (depth != 0) {
    const uint32_t *ref = wb->ref, *count = wb->count; /* setup_leaves' or reach_walk's copy */
    wb->slots = (uint32_t)refs_slots(ref);
    for (int i = 0; i < 4; i++) {
      if (count[i] || ref[i] == UINT32_MAX || (fs->reached && !fs->reached[ref[i]])) continue;
      float c[5];
      wide_union(fs, ref[i], depth - 1, c);
      wb->tlo[i] = c[0], wb->x0[i] = c[1], wb->y0[i] = c[2], wb->x1[i] = c[3], wb->y1[i] = c[4];
    }
  }
  u[0] = u[1] = u[2] = INFINITY, u[3] = u[4] = -INFINITY;
  for (int i = 0; i < 4; i++) {
    u[0] = minf(u[0], wb->tlo[i]), u[1] = minf(u[1], wb->x0[i]), u[2] = minf(u[2], wb->y0[i]);
    u[3] = maxf(u[3], wb->x1[i]), u[4] = maxf(u[4], wb->y1[i]);
  }
}

/* ---- perspective frames: only the nodes whose box may hold a sample ---------- */

/* A slot that no sample can reach: an empty rectangle and an infinite bound. */
static void slot_empty(wide_bounds *wb, int i) {
  wb->tlo[i] = wb->x0[i] = wb->y0[i] = INFINITY, wb->x1[i] = wb->y1[i] = -INFINITY;
}

/* The slots of wide node n (bit i) whose box may hold a triangle tested at some
 * sample, from the box alone (perspective cameras). A triangle is tested only at
 * the samples of its corner rectangle (rr_tri_corner_bounds: the float
 * projections of its corners, widened by 1/64 + 1e-5·|coordinate| pixels). When
 * every corner of the box is ahead of the eye (z > 0: convex, so the whole box
 * is), the box, and each triangle in it, projects inside the bounding box of its
 * corners' projections (a perspective map keeps convex sets convex). With R the
 * largest |q| / z of the box's corners (>= that of any point in it), a float
 * projection errs by less than 4u·R·(1 + R)·W / tan_w + 3u·|sx| (u = 2^-24: q, z
 * and the dot products err by 5u·|q|, and |qr| / (z·tan_w) <= R / tan_w), both the
 * box's here and the triangle corners' there, so the box's rectangle widened by
 * 1/32 + 2e-5·|coordinate| + 16u·R·(1 + R)·(W / tan_w + H / tan_h) holds every
 * sample any of its triangles is tested at. A box without a sample in that
 * rectangle holds no triangle that a frame would set up; a box reaching the eye's
 * plane may hold any. `few`: the slots kept whose rectangle holds at most
 * REACH_FEW samples. */
static int box_reach(const camera *c, const bvh_wide *n, int *few) {
  const rr_vf4 zero = rr_vf4_splat(0), one = rr_vf4_splat(1), half = rr_vf4_splat(0.5f);
  const rr_vf4 tw = rr_vf4_splat(c->tan_half_w), th = rr_vf4_splat(c->tan_half_h);
  const rr_vf4 W = rr_vf4_splat((float)c->width), H = rr_vf4_splat((float)c->height);
  const float eye[3] = {c->eye.x, c->eye.y, c->eye.z}, fwd[3] = {c->fwd.x, c->fwd.y, c->fwd.z};
  const float right[3] = {c->right.x, c->right.y, c->right.z}, up[3] = {c->up.x, c->up.y, c->up.z};
  /* Per axis and side (lo, hi) the terms a corner sums: a corner's z, qr, qu and
   * |q|² are the same sums of the same products, in the same order, as if each
   * corner computed them itself (the same bits), at a quarter of the products. */
  rr_vf4 pz[3][2], pr[3][2], pu[3][2], pl[3][2];
  for (int a = 0; a < 3; a++)
    for (int h = 0; h < 2; h++) {
      rr_vf4 q = rr_vf4_load_aligned(h ? n->hi[a] : n->lo[a]) - rr_vf4_splat(eye[a]);
      pz[a][h] = q * rr_vf4_splat(fwd[a]), pr[a][h] = q * rr_vf4_splat(right[a]), pu[a][h] = q * rr_vf4_splat(up[a]);
      pl[a][h] = q * q;
    }
  /* A corner projects to sx = (qr / (z·tw) + 1)·½·W, sy = (1 − qu / (z·th))·½·H;
   * each step after the quotient is monotonic in it under rounding (adding 1,
   * subtracting from 1, multiplying by positive constants), so the extreme corners'
   * samples are the extreme quotients' carried through once: the same bits as
   * each corner's own. (Starting a sum at +0, as 0 + a + b + c, changes no value
   * but the sign of a zero, which nothing below tells apart.) */
  rr_vf4 rx0 = rr_vf4_splat(INFINITY), ry0 = rx0, rx1 = -rx0, ry1 = -rx0;
  rr_vi4 front = (rr_vi4){-1, -1, -1, -1};
  rr_vf4 r2 = zero; /* the largest (|q| / z)² */
  for (int k = 0; k < 8; k++) {
    int h0 = k & 1, h1 = k >> 1 & 1, h2 = k >> 2 & 1;
    rr_vf4 z = pz[0][h0] + pz[1][h1] + pz[2][h2], qr = pr[0][h0] + pr[1][h1] + pr[2][h2];
    rr_vf4 qu = pu[0][h0] + pu[1][h1] + pu[2][h2], len2 = pl[0][h0] + pl[1][h1] + pl[2][h2];
    front &= z > zero;
    r2 = rr_vf4_max(r2, len2 / (z * z));
    rr_vf4 rx = qr / (z * tw), ry = qu / (z * th);
    rx0 = rr_vf4_min(rx0, rx), rx1 = rr_vf4_max(rx1, rx), ry0 = rr_vf4_min(ry0, ry), ry1 = rr_vf4_max(ry1, ry);
  }
  rr_vf4 x0 = (rx0 + one) * half * W, x1 = (rx1 + one) * half * W;
  rr_vf4 y0 = (one - ry1) * half * H, y1 = (one - ry0) * half * H;
  const float u = 0x1p-24f, wh = (float)c->width / c->tan_half_w + (float)c->height / c->tan_half_h;
  rr_vf4 big = rr_vf4_max(rr_vf4_max(rr_vf4_abs(x0), rr_vf4_abs(x1)), rr_vf4_max(rr_vf4_abs(y0), rr_vf4_abs(y1)));
  rr_vf4 R;
  for (int i = 0; i < 4; i++) R[i] = sqrtf(r2[i]);
  R = R * rr_vf4_splat(1.01f); /* rounded up past this computation's own error */
  rr_vf4 m = rr_vf4_splat(1.0f / 32) + rr_vf4_splat(2e-5f) * big +
             rr_vf4_splat(16 * u) * R * (one + R) * rr_vf4_splat(wh);
  /* The first and last pixel whose sample lies in the widened rectangle, clamped
   * to the image, as whole numbers: ceil and floor of values in [-1, width] (a
   * rectangle beyond the image stays empty), so truncation to int is exact. */
  const rr_vf4 sx0 = rr_vf4_splat(c->sx0), sy0 = rr_vf4_splat(c->sy0), m1 = rr_vf4_splat(-1);
  rr_vf4 a[4] = {x0 - m - sx0, y0 - m - sy0, x1 + m - sx0, y1 + m - sy0}, hi[2] = {W - one, H - one}, top[2] = {W, H};
  rr_vi4 idx[4];
  for (int k = 0; k < 4; k++) {
    rr_vf4 v = k < 2 ? rr_vf4_min(rr_vf4_max(a[k], zero), top[k]) : rr_vf4_max(rr_vf4_min(a[k], hi[k - 2]), m1);
    rr_vi4 t = rr_vi4_trunc(v);
    rr_vf4 tf = __builtin_convertvector(t, rr_vf4);
    idx[k] = k < 2 ? t - (tf < v) : t + (tf > v); /* ceil for the first, floor for the last */
  }
  /* A slot is out only when everything is a number and the rectangle holds no sample. */
  rr_vi4 sure = front & (m < rr_vf4_splat(INFINITY));
  for (int k = 0; k < 4; k++) sure &= a[k] == a[k];
  rr_vi4 nx = idx[2] - idx[0] + 1, ny = idx[3] - idx[1] + 1;
  rr_vi4 live = -(rr_vi4){n->ref[0] != UINT32_MAX, n->ref[1] != UINT32_MAX, n->ref[2] != UINT32_MAX,
                          n->ref[3] != UINT32_MAX};
  rr_vi4 out = sure & ((nx <= 0) | (ny <= 0));
  *few = rr_vi4_bits(live & sure & ~out & (nx * ny <= REACH_FEW));
  return rr_vi4_bits(live & ~out);
}

/* Whether the subtree of wide node w holds at most `cap` triangles. */
static bool subtree_small(const rr_bvh *b, uint32_t w, uint32_t cap) {
  return (w < b->nwide ? b->wide_tris[w] : b->obj->wide_tris[(w - b->nwide) % b->obj->nwide]) <= cap;
}

/* Perspective frames: walks down from wide node w through the slots box_reach
 * keeps (all of them when `all`), adding the leaves met to the batch (set up and
 * finished whenever it fills) and giving every other slot no samples. Above `depth` 0 it walks on;
 * at 0 it leaves the node to roots[] (walked in parallel) instead. */
typedef struct {
  uint32_t w[64];
  int n;
} reach_roots;

static void reach_walk(frame_setups *fs, uint32_t w, int depth, bool all, leaf_batch *lb, int thread,
                       reach_roots *roots) {
  if (roots && depth == 0) {
    roots->w[roots->n++] = w;
    return;
  }
  BVH_NODE_ALIGN bvh_wide buf;
  const bvh_wide *n = all ? bvh_wide_refs_at(fs->b, w, &buf) : bvh_wide_at(fs->b, w, &buf);
  wide_bounds *wb = &fs->wb[w];
  memcpy(wb->ref, n->ref, sizeof n->ref), memcpy(wb->count, n->count, sizeof n->count);
  int few = 0, reach = all ? 15 : box_reach(fs->cam, n, &few);
  fs->reached[w] = 1;
  for (int i = 0; i < 4; i++) {
    if (n->ref[i] == UINT32_MAX || !(reach >> i & 1)) {
      slot_empty(wb, i);
    } else if (!n->count[i]) {
      /* A box over a few samples with a few triangles below: their corner bounds
       * (in batch_setup) cost less than the boxes' tests and drop the same ones. */
      bool below = all || (few >> i & 1 && subtree_small(fs->b, n->ref[i], REACH_CAP));
      reach_walk(fs, n->ref[i], depth - 1, below, lb, thread, roots);
    } else {
      if (lb->n + (int)n->count[i] > BATCH) {
        batch_setup(fs, lb, thread), batch_finish(fs, lb);
        lb->n = lb->nl = 0;
      }
      leaf_add(lb, fs->b, 4 * w + (uint32_t)i, n->ref[i], n->count[i]);
    }
  }
}

typedef struct {
  frame_setups *fs;
  reach_roots roots;
} reach_job;

static void reach_subtree(int job, int thread, void *arg) {
  reach_job *rj = arg;
  leaf_batch lb;
  lb.n = lb.nl = 0;
  reach_walk(rj->fs, rj->roots.w[job], -1, false, &lb, thread, NULL);
  batch_setup(rj->fs, &lb, thread), batch_finish(rj->fs, &lb);
  float u[5];
  wide_union(rj->fs, rj->roots.w[job], -1, u); /* its leaves are all finished: the unions in parallel too */
}

enum { REACH_TOP = 3 }; /* levels walked in one thread above the parallel subtrees */

/* The top REACH_TOP levels in this thread, the subtrees below them in parallel
 * (their walks, setups and unions), then the unions of the top levels. */
static void reach_frame(frame_setups *fs, int threads) {
  reach_job rj = {.fs = fs};
  leaf_batch lb;
  lb.n = lb.nl = 0;
  reach_walk(fs, 0, REACH_TOP, false, &lb, 0, &rj.roots);
  batch_setup(fs, &lb, 0), batch_finish(fs, &lb);
  rr_parallel_for(rj.roots.n, threads, reach_subtree, &rj);
  float root[5];
  wide_union(fs, 0, REACH_TOP, root);
}

static void setups_free(frame_setups *fs) {
  rr_scratch_give(fs->dev, fs->ts_buf), rr_scratch_give(fs->dev, fs->slot_buf), rr_scratch_give(fs->dev, fs->wb_buf);
  free(fs->seen), free(fs->reached);
}

static rr_error setups_init(rr_device *dev, frame_setups *fs, const render_ctx *ctx, const rr_bvh *b,
                            thread_stats *st) {
  *fs = (frame_setups){.s = ctx->scene, .b = b, .cam = ctx->cam, .cull = ctx->opt->cull_backfaces != 0,
                        .simd = !ctx->opt->scalar, .st = st, .dev = dev};
  atomic_init(&fs->nts, 0);
  size_t n = b->vpos;
  /* The device's buffers: a frame writes what it reads, and on the teapot grid a
   * fresh 264 MB of setups would cost a page fault per 4 KiB touched each frame. */
  fs->ts_buf = rr_scratch_take(dev, SCRATCH_RC_SETUPS, n * sizeof *fs->ts + 1), fs->ts = fs->ts_buf.p;
  fs->slot_buf = rr_scratch_take(dev, SCRATCH_RC_SLOTS, n * sizeof *fs->slot + 1), fs->slot = fs->slot_buf.p;
  /* Perspective views of scenes with more triangles than samples walk down to the
   * boxes that may hold a sample (reach_walk): a frame touches what its samples can
   * reach, and most triangles fall between samples or outside the view. Where
   * samples outnumber triangles nearly every box holds one and the walk's box
   * tests only add (bunny, 512²: 10% more instructions); those, other cameras and
   * scenes with corners at infinity (boxes cut at PRIM_FAR) bound every triangle. */
  bool reach = fs->cam->type == RR_CAMERA_PERSPECTIVE && !ctx->scene->inf &&
               ctx->scene->ntris > (uint64_t)ctx->cam->width * (uint64_t)ctx->cam->height;
  if (reach) fs->reached = calloc(b->vwide, 1);
  else if (fs->cam->planar) fs->seen = malloc((size_t)ctx->scene->ntris + 1);
  fs->wb_buf = rr_scratch_take(dev, SCRATCH_RC_BOUNDS, (size_t)b->vwide * sizeof *fs->wb), fs->wb = fs->wb_buf.p;
  if (!fs->ts || !fs->slot || !fs->wb || (reach ? !fs->reached : fs->cam->planar && !fs->seen)) {
    setups_free(fs);
    return rr_fail(dev, RR_ERROR_MEMORY, "out of memory for %zu triangle setups", n);
  }
  if (reach) {
    reach_frame(fs, ctx->threads);
  } else {
    if (fs->cam->planar)
      rr_parallel_for((int)((ctx->scene->ntris + SEEN_CHUNK - 1) / SEEN_CHUNK), ctx->threads, seen_chunk, fs);
    rr_parallel_for((int)((b->vwide + SETUP_CHUNK - 1) / SETUP_CHUNK), ctx->threads, setup_leaves, fs);
    float root[5];
    wide_union(fs, 0, -1, root);
  }
  return RR_OK;
}

/* ---- primary rays: tiles of the image dealt to threads -------------------------- */

enum { TILE = 32, PK = 8, PN = PK * PK };

typedef struct {
  render_ctx *ctx;
  const rr_bvh *b;
  frame_setups fs;
  int tiles_x;
  thread_stats st[RR_MAX_THREADS];
} frame_job;

/* ---- one ray per sample: the traversal's policy ------------------------------ */

/* A primary ray: its best hit, its sample with the evaluation vector, and for
 * curved cameras its 3D ray for the box tests. */
typedef struct {
  float t, l1, l2; /* best hit so far */
  uint32_t id;
  float sx, sy;
  rr_vf4 sx4, sy4; /* the sample broadcast, for the rectangle tests */
  vec3 w;
  ray_q q;
  const frame_setups *fs;
  const wide_bounds *wb; /* fs->wb, one load nearer */
  uint64_t evals, nodes;
} primary_ray;

/* Planar cameras: the slots whose rectangle holds the sample and whose bound is
 * not above the best t, nearest bound first (rectangles only: no 3D test). */
KERNEL int ray_node_planar(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)w, (void)lanes;
  primary_ray *r = q;
  const wide_bounds *wb = &r->wb[ref];
  rr_vf4 x = r->sx4, y = r->sy4;
  rr_vi4 in = (wb->x0 <= x) & (x <= wb->x1) & (wb->y0 <= y) & (y <= wb->y1);
  r->nodes += wb->slots;
  s->order = s->key = wb->tlo;
  s->ref = wb->ref, s->count = wb->count;
  return rr_vi4_bits(in & (wb->tlo <= rr_vf4_splat(r->t)));
}

/* Curved cameras: the slots whose box the ray meets and whose bound is not above
 * the best t, nearest box entry first. */
KERNEL int ray_node_curved(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)lanes;
  primary_ray *r = q;
  r->nodes += r->wb[ref].slots;
  s->key = r->wb[ref].tlo;
  return wide_test(w, &r->q, 0, s->key, r->t, &s->order);
}

/* Tests the leaf's triangles, set up for the frame, at the ray's sample where it
 * lies in their rectangle (their floor holds there; curved cameras: everywhere). */
KERNEL bool ray_leaf(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  (void)lanes;
  primary_ray *r = q;
  visbuf one = {1, 1, &r->id, &r->t, &r->l1, &r->l2, 1};
  const uint32_t *slot = r->fs->slot; /* in locals: the hit's stores cannot change them */
  const leaf_tri *ts = r->fs->ts;
  for (uint32_t i = first; i < first + count; i++) {
    if (slot[i] == UINT32_MAX) continue;
    const leaf_tri *lt = &ts[slot[i]];
    const float *tr = lt->rect;
    if (!(tr[0] <= r->sx && r->sx <= tr[2] && tr[1] <= r->sy && r->sy <= tr[3])) continue;
    r->evals++;
    if (scene_kind(r->fs->s, lt->id) != RR_GEOMETRY_TRIANGLE)
      ana_shade_sample(r->fs->s, r->fs->cam, lt->id, r->w, r->sx, r->sy, &one, 0);
    else
      shade_sample_w(&lt->ts, lt->id, r->w, r->sx, r->sy, &one, 0);
  }
  return false;
}

KERNEL float ray_best(const void *q) { return ((const primary_ray *)q)->t; }

static void rc_bvh_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  const camera *c = j->ctx->cam;
  visbuf *vb = j->ctx->vb;
  int x0 = job % j->tiles_x * TILE, y0 = job / j->tiles_x * TILE;
  int x1 = x0 + TILE < vb->width ? x0 + TILE : vb->width, y1 = y0 + TILE < vb->height ? y0 + TILE : vb->height;
  primary_ray r = {.fs = &j->fs, .wb = j->fs.wb};
  /* in locals: the stores into the buffers cannot change them */
  uint32_t *vid = vb->id;
  float *vt = vb->t, *vl1 = vb->l1, *vl2 = vb->l2, *heat_e = j->ctx->heat_e, *heat_n = j->ctx->heat_n;
  const size_t stride = (size_t)vb->width;
  /* 4x4 blocks in the tile: neighbouring rays run one after the other and find
   * the nodes and setups their neighbour just loaded still in cache. */
  for (int by = y0; by < y1; by += 4)
    for (int bx = x0; bx < x1; bx += 4)
      for (int k = 0; k < 16; k++) {
        int x = bx + (k & 3), y = by + (k >> 2);
        if (x >= x1 || y >= y1) continue;
        r.sx = (float)x + c->sx0, r.sy = (float)y + c->sy0;
        r.sx4 = rr_vf4_splat(r.sx), r.sy4 = rr_vf4_splat(r.sy);
        r.t = INFINITY, r.id = RR_MISS, r.l1 = r.l2 = 0;
        r.w = camera_w(c, x, y);
        vec3 o, d;
        uint64_t e0 = r.evals, n0 = r.nodes;
        if (c->planar) bvh_trace_nodes(j->b, &r, 1, ray_node_planar, ray_leaf, ray_best, false); /* fs.wb alone */
        else if (rr_cam_ray(c, x, y, &o, &d)) { /* else a pixel without a ray: a miss */
          ray_q_init(&r.q, o, d);
          bvh_trace(j->b, &r, 1, ray_node_curved, ray_leaf, ray_best);
        }
        size_t i = (size_t)y * stride + x;
        if (heat_e) heat_e[i] += (float)(r.evals - e0), heat_n[i] += (float)(r.nodes - n0);
        vid[i] = r.id, vt[i] = r.t, vl1[i] = r.l1, vl2[i] = r.l2;
      }
  thread_stats *st = &j->st[thread];
  st->evals += r.evals, st->nodes += r.nodes;
}

/* ---- packets of 8x8 primary rays (planar cameras): the traversal's policy ------ */

/* A packet: its samples' best hits, which lanes are samples of the image, and the
 * sample coordinates of its columns and rows (4 lanes each, two halves). */
typedef struct {
  float t[PN], l1[PN], l2[PN];
  uint32_t id[PN];
  int x0, y0;
  uint64_t valid;
  rr_vf4 sx[2], sy[2];
  float maxbest; /* the largest best t of the lanes: no lane can use a node whose bound is above */
  bool heat; /* charge E and N to the lanes (a node test is shared by its lanes) */
  float heat_e[PN], heat_n[PN];
  const frame_setups *fs;
  uint64_t evals, nodes;
} packet;

/* The lanes whose sample lies in the rectangle [x0, x1] × [y0, y1]: a run of
 * columns times a run of rows, the same comparisons as a single ray makes. */
KERNEL uint64_t rect_lanes(const packet *p, float x0, float y0, float x1, float y1) {
  rr_vf4 a0 = rr_vf4_splat(x0), a1 = rr_vf4_splat(x1), b0 = rr_vf4_splat(y0), b1 = rr_vf4_splat(y1);
  int cols = rr_vi4_bits((a0 <= p->sx[0]) & (p->sx[0] <= a1)) | rr_vi4_bits((a0 <= p->sx[1]) & (p->sx[1] <= a1)) << 4;
  int rows = rr_vi4_bits((b0 <= p->sy[0]) & (p->sy[0] <= b1)) | rr_vi4_bits((b0 <= p->sy[1]) & (p->sy[1] <= b1)) << 4;
  if (!cols || !rows) return 0;
  int r0 = __builtin_ctz(rows), r1 = 31 - __builtin_clz(rows); /* a run: the rectangle is convex */
  uint64_t rowmask = (~0ull >> (8 * (7 - r1))) & (~0ull << (8 * r0));
  return (uint64_t)cols * 0x0101010101010101ull & rowmask;
}

/* The slots whose bound is not above every lane's best t, each with the lanes
 * whose samples lie in its rectangle, nearest bound first. */
KERNEL int packet_node(void *q, const bvh_wide *w, uint32_t ref, uint64_t lanes, trace_slots *s) {
  (void)w;
  packet *p = q;
  const wide_bounds *wb = &p->fs->wb[ref];
  int hits = 0;
  for (int i = 0; i < 4; i++) {
    s->lanes[i] = wb->tlo[i] > p->maxbest ? 0 : lanes & rect_lanes(p, wb->x0[i], wb->y0[i], wb->x1[i], wb->y1[i]);
    hits |= (s->lanes[i] != 0) << i;
  }
  s->order = s->key = wb->tlo;
  s->ref = wb->ref, s->count = wb->count;
  uint64_t tested = wb->slots;
  p->nodes += tested;
  if (p->heat) {
    float share = (float)tested / (float)__builtin_popcountll(lanes);
    for (uint64_t l = lanes; l; l &= l - 1) p->heat_n[__builtin_ctzll(l)] += share;
  }
  return hits;
}

/* Tests the lanes in each triangle's rectangle, then finds the largest best t again. */
KERNEL bool packet_leaf(void *q, uint32_t first, uint32_t count, uint64_t lanes) {
  packet *p = q;
  const frame_setups *fs = p->fs;
  visbuf pvb = {PK, PK, p->id, p->t, p->l1, p->l2, 1};
  for (uint32_t i = first; i < first + count; i++) {
    if (fs->slot[i] == UINT32_MAX) continue;
    const leaf_tri *lt = &fs->ts[fs->slot[i]];
    const float *tr = lt->rect;
    uint64_t in = lanes & rect_lanes(p, tr[0], tr[1], tr[2], tr[3]);
    bool ana = scene_kind(fs->s, lt->id) != RR_GEOMETRY_TRIANGLE;
    p->evals += (uint64_t)__builtin_popcountll(in);
    for (; in; in &= in - 1) {
      int k = __builtin_ctzll(in);
      p->heat_e[k] += 1;
      float sx = (float)(p->x0 + (k & 7)) + fs->cam->sx0, sy = (float)(p->y0 + (k >> 3)) + fs->cam->sy0;
      if (ana) ana_shade_sample(fs->s, fs->cam, lt->id, v3(1.0f, sx, sy), sx, sy, &pvb, k);
      else shade_sample_w(&lt->ts, lt->id, v3(1.0f, sx, sy), sx, sy, &pvb, k);
    }
  }
  rr_vf4 m = rr_vf4_load_aligned(p->t);
  for (int g = 1; g < PN / 4; g++) m = rr_vf4_max(m, rr_vf4_load_aligned(&p->t[4 * g]));
  p->maxbest = rr_vf4_hmax(m);
  return false;
}

KERNEL float packet_best(const void *q) { return ((const packet *)q)->maxbest; }

static void rc_packet_tile(int job, int thread, void *arg) {
  frame_job *j = arg;
  visbuf *vb = j->ctx->vb;
  int tx0 = job % j->tiles_x * TILE, ty0 = job / j->tiles_x * TILE;
  packet pk = {.fs = &j->fs, .heat = j->ctx->heat_e != NULL}, *p = &pk;
  for (int py = ty0; py < ty0 + TILE && py < vb->height; py += PK)
    for (int px = tx0; px < tx0 + TILE && px < vb->width; px += PK) {
      /* the lanes on the image: nx columns by ny rows */
      int nx = vb->width - px < PK ? vb->width - px : PK, ny = vb->height - py < PK ? vb->height - py : PK;
      uint64_t row = (1ull << nx) - 1, rows = ny == PK ? ~0ull : (1ull << 8 * ny) - 1;
      p->x0 = px, p->y0 = py, p->valid = row * 0x0101010101010101ull & rows, p->maxbest = INFINITY;
      float cx[PK], cy[PK];
      for (int k = 0; k < PK; k++) cx[k] = (float)(px + k) + j->ctx->cam->sx0, cy[k] = (float)(py + k) + j->ctx->cam->sy0;
      p->sx[0] = rr_vf4_load(cx), p->sx[1] = rr_vf4_load(cx + 4);
      p->sy[0] = rr_vf4_load(cy), p->sy[1] = rr_vf4_load(cy + 4);
      for (int k = 0; k < PN; k++)
        p->t[k] = INFINITY, p->id[k] = RR_MISS, p->l1[k] = p->l2[k] = 0, p->heat_e[k] = p->heat_n[k] = 0;
      bvh_trace_nodes(j->b, p, p->valid, packet_node, packet_leaf, packet_best, false); /* fs.wb alone */
      for (int y = 0; y < ny; y++) { /* a row of the packet: a run of the buffer */
        size_t i = (size_t)(py + y) * vb->width + px, n = (size_t)nx;
        memcpy(vb->id + i, p->id + PK * y, n * sizeof *vb->id), memcpy(vb->t + i, p->t + PK * y, n * sizeof *vb->t);
        memcpy(vb->l1 + i, p->l1 + PK * y, n * sizeof *vb->l1), memcpy(vb->l2 + i, p->l2 + PK * y, n * sizeof *vb->l2);
        if (j->ctx->heat_e)
          for (int x = 0; x < nx; x++)
            j->ctx->heat_e[i + x] += p->heat_e[PK * y + x], j->ctx->heat_n[i + x] += p->heat_n[PK * y + x];
      }
    }
  thread_stats *st = &j->st[thread];
  st->evals += p->evals, st->nodes += p->nodes;
}

static rr_error run_frame(rr_device *dev, render_ctx *ctx, rr_parallel_fn tile_fn) {
  /* Packets work on screen rectangles: curved cameras cast one ray per sample. */
  if (tile_fn == rc_packet_tile && !ctx->cam->planar) tile_fn = rc_bvh_tile;
  bool empty;
  const rr_bvh *b = rr_bvh_of(dev, ctx->scene, &empty);
  if (empty) return RR_OK; /* the visibility buffer is already all misses */
  if (!b) return dev ? dev->error : RR_ERROR_ARGUMENT;
  frame_job *j = calloc(1, sizeof *j);
  if (!j) return rr_fail(dev, RR_ERROR_MEMORY, "out of memory");
  j->ctx = ctx, j->b = b;
  rr_error e = setups_init(dev, &j->fs, ctx, b, j->st);
  if (e) {
    free(j);
    return e;
  }
  const visbuf *vb = ctx->vb;
  j->tiles_x = (vb->width + TILE - 1) / TILE;
  int tiles = j->tiles_x * ((vb->height + TILE - 1) / TILE);
  rr_parallel_for_progress(tiles, ctx->threads, tile_fn, j, &ctx->progress);
  for (int t = 0; t < RR_MAX_THREADS; t++) {
    ctx->stats->edge_evals += j->st[t].evals;
    ctx->stats->nodes += j->st[t].nodes;
    ctx->stats->setups += j->st[t].setups;
  }
  setups_free(&j->fs);
  free(j);
  return RR_OK;
}

rr_error rr_vis_rc_bvh(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_bvh_tile); }

rr_error rr_vis_rc_packet(rr_device *dev, render_ctx *ctx) { return run_frame(dev, ctx, rc_packet_tile); }
