
/* auto's costs: written by `bench_auto --calibrate --threads 2` (132 views, median of 5);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT, S/D, F, 1. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {7.16, 102.3, 1.639, 0, 0.2226, 0.5326, 0, 0, 0, 0},
    [RR_METHOD_3DR_BIN] = {7.682, 92.93, 0.8105, 15.92, 0, 1.492, 0, 0, 0, 0},
    [RR_METHOD_3DR_FC] = {24.64, 102.1, 1.895, 0, 0, 2.956, 0, 612.9, 0, 0},
    [RR_METHOD_3DR_FULL] = {18.52, 0, 1.928, 0, 0, 5.365, 0, 0, 454.3, 1.116e+05},
    [RR_METHOD_RC_PACKET] = {25.63, 241.1, 2.355, 0, 0, 0, 0.3259, 0, 0, 0},
    [RR_METHOD_RC_BVH] = {22.68, 271.3, 11.68, 0, 0, 0, 0.1489, 0, 0, 0},
};
static const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_CAMERA_PARABOLIC] = {
        [RR_METHOD_3DR_BIN] = {21.79, 0, 0, 0, 0, 33.12, 0, 0, 0, 1.31e+06},
        [RR_METHOD_3DR_FC] = {64.52, 0, 0, 0, 0, 58.14, 0, 0, 0, 4.88e+05},
        [RR_METHOD_3DR_FULL] = {110.9, 0, 0, 0, 0, 63.84, 0, 0, 0, 4.126e+06},
        [RR_METHOD_RC_PACKET] = {73.62, 0, 0, 0, 0, 44.67, 0, 0, 0, 2.689e+06},
        [RR_METHOD_RC_BVH] = {71.2, 0, 0, 0, 0, 45.91, 0, 0, 0, 2.22e+06},
    },
    [RR_CAMERA_LATLONG] = {
        [RR_METHOD_3DR_BIN] = {10.66, 0, 0, 0, 0, 50.56, 0, 0, 0, 6.298e+05},
        [RR_METHOD_3DR_FC] = {46.82, 0, 0, 0, 0, 69.45, 0, 0, 0, 4.795e+05},
        [RR_METHOD_3DR_FULL] = {149.1, 0, 0, 0, 0, 43.27, 0, 0, 0, 1.622e+06},
        [RR_METHOD_RC_PACKET] = {71.36, 0, 0, 0, 0, 61.37, 0, 0, 0, 1.627e+06},
        [RR_METHOD_RC_BVH] = {68.04, 0, 0, 0, 0, 67.13, 0, 0, 0, 1.3e+06},
    },
    [RR_CAMERA_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {46.34, 0, 0, 0, 0, 34.68, 0, 0, 0, 1.591e+06},
        [RR_METHOD_3DR_FC] = {126.7, 0, 0, 0, 0, 60.71, 0, 0, 0, 6.769e+05},
        [RR_METHOD_3DR_FULL] = {128.2, 0, 0, 0, 0, 32.17, 0, 0, 0, 6.293e+06},
        [RR_METHOD_RC_PACKET] = {80.41, 0, 0, 0, 0, 54.23, 0, 0, 0, 2.851e+06},
        [RR_METHOD_RC_BVH] = {79.28, 0, 0, 0, 0, 54.16, 0, 0, 0, 2.829e+06},
    },
    [RR_CAMERA_CUBE] = {
        [RR_METHOD_3DR_BIN] = {32.56, 0, 7.97, 0, 0, 0, 0, 0, 122, 0},
        [RR_METHOD_3DR_FC] = {51.11, 0, 0, 0, 0, 14.14, 0, 0, 0, 7.731e+04},
        [RR_METHOD_3DR_FULL] = {41.36, 0, 10.37, 0, 0, 0, 0, 0, 8.13, 0},
        [RR_METHOD_RC_PACKET] = {158.4, 0, 0, 0, 0, 15.18, 0, 0, 0, 1.271e+06},
        [RR_METHOD_RC_BVH] = {136.3, 0, 0, 0, 0, 44.01, 0, 0, 0, 1.756e+06},
    },
    [RR_CAMERA_OPENCV] = {
        [RR_METHOD_3DR_BIN] = {433, 0, 0, 0, 0, 74.82, 0, 0, 0, 7.296e+06},
        [RR_METHOD_3DR_FC] = {625.8, 0, 0, 0, 0, 142.1, 0, 0, 0, 1.402e+06},
        [RR_METHOD_3DR_FULL] = {405, 0, 0, 0, 0, 331.8, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {164.8, 0, 0, 0, 0, 193.9, 0, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {162.3, 0, 0, 0, 0, 194.6, 0, 0, 0, 0},
    },
    [RR_CAMERA_OPENCV_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {419.8, 0, 0, 0, 0, 75.41, 0, 0, 0, 7.429e+06},
        [RR_METHOD_3DR_FC] = {621.3, 0, 0, 0, 0, 134.7, 0, 0, 0, 1.914e+06},
        [RR_METHOD_3DR_FULL] = {393.6, 0, 0, 0, 0, 328.6, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {150.5, 0, 0, 0, 0, 174.8, 0.878, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {148.6, 0, 0, 0, 0, 166.9, 1.505, 0, 0, 0},
    },
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.614,
    [RR_METHOD_3DR_BIN] = 0.51,
    [RR_METHOD_3DR_FC] = 0.557,
    [RR_METHOD_3DR_FULL] = 0.445,
    [RR_METHOD_RC_PACKET] = 0.8,
    [RR_METHOD_RC_BVH] = 0.842,
};
