
/* auto's costs: written by `bench_auto --calibrate` (112 views, median of 3);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {5.33, 91.57, 1.883, 0, 0.3219, 0.1969, 0},
    [RR_METHOD_3DR_BIN] = {4.387, 93.93, 0, 14.19, 0, 1.362, 0},
    [RR_METHOD_3DR_FC] = {21.6, 248.3, 0.641, 0, 0, 2.781, 0},
    [RR_METHOD_3DR_FULL] = {0, 250.6, 0, 0, 0, 7.331, 0},
    [RR_METHOD_RC_PACKET] = {163.1, 0, 0, 0, 0, 0, 0.9623},
    [RR_METHOD_RC_BVH] = {185.7, 0, 0, 0, 0, 0, 2.437},
};
static const double cost_curved[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BIN] = {3845, 0, 0, 0, 0, 15.16, 0},
    [RR_METHOD_3DR_FC] = {4455, 0, 0, 0, 0, 17.56, 0},
    [RR_METHOD_3DR_FULL] = {2844, 0, 0, 0, 0, 11.21, 0},
    [RR_METHOD_RC_PACKET] = {101.9, 0, 0, 0, 0, 71.37, 0},
    [RR_METHOD_RC_BVH] = {97.25, 0, 0, 0, 0, 69.3, 0},
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.75,
    [RR_METHOD_3DR_BIN] = 0.75,
    [RR_METHOD_3DR_FC] = 0.75,
    [RR_METHOD_3DR_FULL] = 0.75,
    [RR_METHOD_RC_PACKET] = 0.75,
    [RR_METHOD_RC_BVH] = 0.75,
};
