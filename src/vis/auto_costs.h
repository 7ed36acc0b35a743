
/* auto's costs: written by `bench_auto --calibrate --keep-gains` (132 views, median of 3);
 * see vis/auto.c and docs/auto.md. The thread gains are those of the calibration before. Figures: T, S, A, R, UP, P, PlogT, S/D, F, 1. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {5.944, 137.2, 2.447, 0, 0.3017, 0.1548, 0, 0, 0, 0},
    [RR_METHOD_3DR_BIN] = {6.193, 104, 1.174, 23.04, 0, 0.4186, 0, 0, 0, 0},
    [RR_METHOD_3DR_FC] = {30.22, 101.4, 2.595, 0, 0, 2.171, 0, 757.8, 0, 0},
    [RR_METHOD_3DR_FULL] = {24.65, 0, 2.418, 0, 0, 4.897, 0, 0, 517.6, 3.227e+05},
    [RR_METHOD_RC_PACKET] = {38.78, 275.3, 2.754, 0, 0, 0, 0.8117, 0, 0, 0},
    [RR_METHOD_RC_BVH] = {39.03, 329.3, 13.86, 0, 0, 0, 0.481, 0, 0, 0},
};
static const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_CAMERA_PARABOLIC] = {
        [RR_METHOD_3DR_BIN] = {50.62, 0, 0, 0, 0, 39.2, 0, 0, 0, 8.846e+05},
        [RR_METHOD_3DR_FC] = {103, 0, 0, 0, 0, 64.15, 0, 0, 0, 9.135e+04},
        [RR_METHOD_3DR_FULL] = {156.1, 0, 0, 0, 0, 78.67, 0, 0, 0, 3.818e+06},
        [RR_METHOD_RC_PACKET] = {110, 0, 0, 0, 0, 59.28, 0, 0, 0, 2.397e+06},
        [RR_METHOD_RC_BVH] = {110.6, 0, 0, 0, 0, 59.14, 0, 0, 0, 2.257e+06},
    },
    [RR_CAMERA_LATLONG] = {
        [RR_METHOD_3DR_BIN] = {47.27, 0, 0, 0, 0, 51.98, 0, 0, 0, 5.096e+05},
        [RR_METHOD_3DR_FC] = {81.35, 0, 0, 0, 0, 62.18, 0, 0, 0, 6.353e+05},
        [RR_METHOD_3DR_FULL] = {219, 0, 0, 0, 0, 47.78, 0, 0, 0, 9.902e+05},
        [RR_METHOD_RC_PACKET] = {110.9, 0, 0, 0, 0, 67.33, 0, 0, 0, 1.434e+06},
        [RR_METHOD_RC_BVH] = {112.2, 0, 0, 0, 0, 68.26, 0, 0, 0, 1.462e+06},
    },
    [RR_CAMERA_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {96.34, 0, 0, 0, 0, 42.31, 0, 0, 0, 2.024e+06},
        [RR_METHOD_3DR_FC] = {162.5, 0, 0, 0, 0, 67.97, 0, 0, 0, 1.291e+06},
        [RR_METHOD_3DR_FULL] = {173.6, 0, 0, 0, 0, 38.28, 0, 0, 0, 5.886e+06},
        [RR_METHOD_RC_PACKET] = {114.7, 0, 0, 0, 0, 57.23, 0, 0, 0, 2.949e+06},
        [RR_METHOD_RC_BVH] = {114.9, 0, 0, 0, 0, 60.26, 0, 0, 0, 2.647e+06},
    },
    [RR_CAMERA_CUBE] = {
        [RR_METHOD_3DR_BIN] = {42.55, 0, 0, 0, 0, 4.485, 0, 0, 0, 1.84e+06},
        [RR_METHOD_3DR_FC] = {72.37, 0, 0, 0, 0, 11.32, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {41.02, 0, 0, 0, 0, 4.33, 0, 0, 0, 2.6e+05},
        [RR_METHOD_RC_PACKET] = {208.3, 0, 0, 0, 0, 0, 0.5901, 0, 0, 1.403e+06},
        [RR_METHOD_RC_BVH] = {186.2, 0, 0, 0, 0, 28.28, 0, 0, 0, 1.435e+06},
    },
    [RR_CAMERA_OPENCV] = {
        [RR_METHOD_3DR_BIN] = {3849, 0, 0, 0, 0, 76.21, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {3047, 0, 0, 0, 0, 186.3, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1199, 0, 0, 0, 0, 374.8, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {220.9, 0, 0, 0, 0, 156.8, 3.491, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {213.5, 0, 0, 0, 0, 130.7, 5.671, 0, 0, 0},
    },
    [RR_CAMERA_OPENCV_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {3652, 0, 0, 0, 0, 73.98, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {3020, 0, 0, 0, 0, 165.1, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1223, 0, 0, 0, 0, 389.3, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {196.7, 0, 0, 0, 0, 199.3, 0, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {196, 0, 0, 0, 0, 192.7, 0, 0, 0, 0},
    },
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.357,
    [RR_METHOD_3DR_BIN] = 0.387,
    [RR_METHOD_3DR_FC] = 0.54,
    [RR_METHOD_3DR_FULL] = 0.52,
    [RR_METHOD_RC_PACKET] = 0.52,
    [RR_METHOD_RC_BVH] = 0.589,
};
