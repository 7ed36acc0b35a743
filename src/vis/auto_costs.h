
/* auto's costs: written by `bench_auto --calibrate --threads 2` (112 views, median of 5);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {4.208, 85.06, 1.367, 0, 0.3261, 0.4095, 0},
    [RR_METHOD_3DR_BIN] = {4.299, 82.35, 0, 12.51, 0, 1.967, 0},
    [RR_METHOD_3DR_FC] = {19.38, 212, 0.5459, 0, 0, 3.029, 0},
    [RR_METHOD_3DR_FULL] = {0, 195.3, 0, 0, 0, 6.835, 0},
    [RR_METHOD_RC_PACKET] = {94.27, 0, 0, 0, 0, 0, 0.8084},
    [RR_METHOD_RC_BVH] = {107.1, 0, 0, 0, 0, 0, 1.211},
};
static const double cost_curved[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BIN] = {3541, 0, 0, 0, 0, 21.65, 0},
    [RR_METHOD_3DR_FC] = {3820, 0, 0, 0, 0, 23.35, 0},
    [RR_METHOD_3DR_FULL] = {3005, 0, 0, 0, 0, 18.37, 0},
    [RR_METHOD_RC_PACKET] = {83.13, 0, 0, 0, 0, 62.69, 0},
    [RR_METHOD_RC_BVH] = {83.39, 0, 0, 0, 0, 62.31, 0},
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.357,
    [RR_METHOD_3DR_BIN] = 0.387,
    [RR_METHOD_3DR_FC] = 0.54,
    [RR_METHOD_3DR_FULL] = 0.52,
    [RR_METHOD_RC_PACKET] = 0.52,
    [RR_METHOD_RC_BVH] = 0.589,
};
