
/* auto's costs: written by `bench_auto --calibrate --threads 2` (132 views, median of 5; the cube's
 * re-fitted from the same times for its face figures);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT, S/D, F, 1. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {5.502, 115.9, 1.786, 0, 0.2119, 0.239, 0, 0, 0, 0},
    [RR_METHOD_3DR_BIN] = {6.035, 95.79, 0.7464, 18.56, 0, 1.01, 0, 0, 0, 0},
    [RR_METHOD_3DR_FC] = {25.33, 104.7, 1.997, 0, 0, 2.39, 0, 660.5, 0, 0},
    [RR_METHOD_3DR_FULL] = {18.29, 0, 2, 0, 0, 5.183, 0, 0, 492.1, 1.158e+05},
    [RR_METHOD_RC_PACKET] = {23.1, 266.3, 1.998, 0, 0, 0, 0.5464, 0, 0, 0},
    [RR_METHOD_RC_BVH] = {19.81, 332.6, 12.98, 0, 0, 0, 0.1767, 0, 0, 0},
};
static const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_CAMERA_PARABOLIC] = {
        [RR_METHOD_3DR_BIN] = {42.54, 0, 0, 0, 0, 34.15, 0, 0, 0, 1.392e+06},
        [RR_METHOD_3DR_FC] = {93.25, 0, 0, 0, 0, 59.69, 0, 0, 0, 5.991e+05},
        [RR_METHOD_3DR_FULL] = {135.2, 0, 0, 0, 0, 73.42, 0, 0, 0, 4.472e+06},
        [RR_METHOD_RC_PACKET] = {89.4, 0, 0, 0, 0, 56.42, 0, 0, 0, 2.564e+06},
        [RR_METHOD_RC_BVH] = {89.15, 0, 0, 0, 0, 62.66, 0, 0, 0, 2.266e+06},
    },
    [RR_CAMERA_LATLONG] = {
        [RR_METHOD_3DR_BIN] = {36.76, 0, 0, 0, 0, 41.21, 0, 0, 0, 8.419e+05},
        [RR_METHOD_3DR_FC] = {78.34, 0, 0, 0, 0, 52.21, 0, 0, 0, 9.831e+05},
        [RR_METHOD_3DR_FULL] = {178.8, 0, 0, 0, 0, 45.89, 0, 0, 0, 1.505e+06},
        [RR_METHOD_RC_PACKET] = {94.22, 0, 0, 0, 0, 66.4, 0, 0, 0, 1.674e+06},
        [RR_METHOD_RC_BVH] = {98.11, 0, 0, 0, 0, 66.51, 0, 0, 0, 1.577e+06},
    },
    [RR_CAMERA_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {69.64, 0, 0, 0, 0, 36.15, 0, 0, 0, 1.638e+06},
        [RR_METHOD_3DR_FC] = {159.4, 0, 0, 0, 0, 63.9, 0, 0, 0, 6.169e+05},
        [RR_METHOD_3DR_FULL] = {153.4, 0, 0, 0, 0, 39.47, 0, 0, 0, 6.206e+06},
        [RR_METHOD_RC_PACKET] = {96.73, 0, 0, 0, 0, 60.62, 0, 0, 0, 2.762e+06},
        [RR_METHOD_RC_BVH] = {97.07, 0, 0, 0, 0, 60.76, 0, 0, 0, 2.687e+06},
    },
    [RR_CAMERA_CUBE] = {
        [RR_METHOD_3DR_BIN] = {23.15, 0, 79.79, 0, 0, 0, 0, 0, 378.2, 6.424e+05},
        [RR_METHOD_3DR_FC] = {70.06, 0, 0, 0, 0, 15.15, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {47.86, 0, 10.47, 0, 0, 0, 0, 0, 1.382, 0},
        [RR_METHOD_RC_PACKET] = {181, 0, 0, 0, 0, 0, 1.559, 0, 0, 1.207e+06},
        [RR_METHOD_RC_BVH] = {158.4, 0, 0, 0, 0, 55.69, 0, 0, 0, 1.428e+06},
    },
    [RR_CAMERA_OPENCV] = {
        [RR_METHOD_3DR_BIN] = {3563, 0, 0, 0, 0, 73.87, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2872, 0, 0, 0, 0, 173.5, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1143, 0, 0, 0, 0, 364.9, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {163.9, 0, 0, 0, 0, 133.3, 4.854, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {167.1, 0, 0, 0, 0, 135.5, 4.61, 0, 0, 0},
    },
    [RR_CAMERA_OPENCV_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {3351, 0, 0, 0, 0, 72.99, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2772, 0, 0, 0, 0, 165.6, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1154, 0, 0, 0, 0, 384.4, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {154.6, 0, 0, 0, 0, 135.5, 4.006, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {153.1, 0, 0, 0, 0, 128.9, 4.457, 0, 0, 0},
    },
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.592,
    [RR_METHOD_3DR_BIN] = 0.597,
    [RR_METHOD_3DR_FC] = 0.469,
    [RR_METHOD_3DR_FULL] = 0.426,
    [RR_METHOD_RC_PACKET] = 0.752,
    [RR_METHOD_RC_BVH] = 0.824,
};
