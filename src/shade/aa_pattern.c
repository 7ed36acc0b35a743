/* Sample patterns of anti-aliasing: where in the pixel the visibility samples
 * sit (the data rr_render's sample_pos reads), and the AA modes' names. */
#include "core/core.h"

#include <string.h>

/* Direct3D's and Vulkan's standard positions: offsets from the pixel centre in 1/16
 * pixel, y down, for 1, 2, 4, 8 and 16 samples (rastray.h lists them too). */
static const signed char standard_1[1][2] = {{0, 0}};
static const signed char standard_2[2][2] = {{4, 4}, {-4, -4}};
static const signed char standard_4[4][2] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
static const signed char standard_8[8][2] = {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
static const signed char standard_16[16][2] = {{1, 1},   {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},
                                               {5, 3},   {3, -5},  {-2, 6}, {0, -7}, {-4, -6}, {-6, 4},
                                               {-8, 0},  {7, -4},  {6, 7},  {-7, -8}};

/* log2 of a supported count (1, 2, 4, 8, 16), -1 for any other. */
static int count_log2(int n) {
  for (int l = 0; l <= 4; l++)
    if (n == 1 << l) return l;
  return -1;
}

static uint32_t mix32(uint32_t x) {
  x ^= x >> 16, x *= 0x7feb352dU, x ^= x >> 15, x *= 0x846ca68bU, x ^= x >> 16;
  return x;
}

rr_error rr_aa_positions(rr_aa_pattern pattern, int n, uint32_t seed, float pos[][2]) {
  int l = count_log2(n);
  if (l < 0 || !pos || (int)pattern < 0 || pattern >= RR_AA_PATTERN_COUNT) return RR_ERROR_ARGUMENT;
  static const signed char (*const standard[5])[2] = {standard_1, standard_2, standard_4, standard_8, standard_16};
  int cols = 1 << ((l + 1) / 2), rows = n / cols; /* the cells of rotated and jitter: 1×1, 2×1, 2×2, 4×2, 4×4 */
  for (int s = 0; s < n; s++) {
    float x, y;
    int i = s % cols, j = s / cols;
    if (pattern == RR_AA_STANDARD) {
      x = 0.5f + standard[l][s][0] / 16.0f, y = 0.5f + standard[l][s][1] / 16.0f;
    } else if (pattern == RR_AA_ROTATED) {
      /* the cell's centre relative to the pixel's, rotated and scaled: exact in 1/16ths */
      float u = (i + 0.5f) / cols - 0.5f, v = (j + 0.5f) / rows - 0.5f;
      x = 0.5f + u - 0.5f * v, y = 0.5f + 0.5f * u + v;
      x -= floorf(x), y -= floorf(y);
    } else {
      /* 16 random bits per axis: (cell·2^16 + bits) / (cells·2^16) is exact and below 1 */
      uint32_t h = mix32(mix32(seed) ^ (uint32_t)s * 0x9e3779b9U);
      x = (float)((uint32_t)i * 65536u + (h & 0xffffu)) / (float)(cols * 65536);
      y = (float)((uint32_t)j * 65536u + (h >> 16)) / (float)(rows * 65536);
    }
    pos[s][0] = x, pos[s][1] = y;
  }
  return RR_OK;
}

const char *rr_aa_mode_name(int mode) {
  static const char *const names[RR_AA_MODE_COUNT] = {"none", "ssaa", "msaa", "csaa"};
  return mode >= 0 && mode < RR_AA_MODE_COUNT ? names[mode] : NULL;
}

const char *rr_aa_pattern_name(int pattern) {
  static const char *const names[RR_AA_PATTERN_COUNT] = {"standard", "rotated", "jitter"};
  return pattern >= 0 && pattern < RR_AA_PATTERN_COUNT ? names[pattern] : NULL;
}

rr_error rr_render_options_set_aa(rr_device *dev, rr_render_options *opt, rr_aa_mode mode, int samples, int stored,
                                  rr_aa_pattern pattern, uint32_t seed) {
  if (!opt) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_render_options_set_aa: NULL options");
  if ((int)mode < 0 || mode >= RR_AA_MODE_COUNT) return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown AA mode %d", (int)mode);
  if ((int)pattern < 0 || pattern >= RR_AA_PATTERN_COUNT)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown sample pattern %d", (int)pattern);
  if (count_log2(samples) < 0 || (mode == RR_AA_NONE && samples != 1))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad sample count %d for %s (expected 1, 2, 4, 8 or 16; none: 1)", samples,
                   rr_aa_mode_name(mode));
  if (mode == RR_AA_CSAA && (count_log2(stored) < 0 || stored > samples))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad stored sample count %d for csaa:K/%d (K: 1, 2, 4, 8 or 16, at most %d)",
                   stored, samples, samples);
  float pos[RR_MAX_SAMPLES][2];
  if (mode == RR_AA_NONE) {
    pos[0][0] = pos[0][1] = 0.5f; /* today's one sample at the centre, whatever the pattern */
  } else if (mode != RR_AA_CSAA) {
    rr_aa_positions(pattern, samples, seed, pos);
  } else {
    /* the stored samples where msaa:K samples; the coverage samples the positions of
     * N's pattern left once each stored sample has taken its nearest */
    float all[RR_MAX_SAMPLES][2];
    bool taken[RR_MAX_SAMPLES] = {false};
    rr_aa_positions(pattern, stored, seed, pos);
    rr_aa_positions(pattern, samples, seed, all);
    for (int k = 0; k < stored; k++) {
      int best = -1;
      float best_d = INFINITY;
      for (int s = 0; s < samples; s++) {
        float dx = all[s][0] - pos[k][0], dy = all[s][1] - pos[k][1], d = dx * dx + dy * dy;
        if (!taken[s] && d < best_d) best = s, best_d = d;
      }
      taken[best] = true;
    }
    for (int s = 0, n = stored; s < samples; s++)
      if (!taken[s]) memcpy(pos[n++], all[s], sizeof all[s]);
  }
  opt->aa = mode;
  opt->samples = samples;
  opt->aa_stored = mode == RR_AA_CSAA ? stored : 0;
  memcpy(opt->sample_pos, pos, (size_t)samples * sizeof pos[0]);
  return rr_ok(dev);
}
