
/* auto's costs: written by `bench_auto --calibrate --threads 2` (132 views, median of 5);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT, S/D, F, 1. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {6.837, 110.7, 1.647, 0, 0.2106, 0.2713, 0, 0, 0, 0},
    [RR_METHOD_3DR_BIN] = {7.546, 92.09, 0.6322, 18.62, 0, 1.06, 0, 0, 0, 0},
    [RR_METHOD_3DR_FC] = {20.45, 114, 1.906, 0, 0, 2.397, 0, 753.5, 0, 0},
    [RR_METHOD_3DR_FULL] = {15.2, 0, 1.751, 0, 0, 5.029, 0, 0, 544.1, 1.923e+05},
    [RR_METHOD_RC_PACKET] = {22.73, 300.2, 1.852, 0, 0, 0, 0.5058, 0, 0, 0},
    [RR_METHOD_RC_BVH] = {20.57, 344.5, 11.86, 0, 0, 0, 0.04525, 0, 0, 0},
};
static const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_CAMERA_PARABOLIC] = {
        [RR_METHOD_3DR_BIN] = {22.04, 0, 0, 0, 0, 35.87, 0, 0, 0, 1.043e+06},
        [RR_METHOD_3DR_FC] = {72.88, 0, 0, 0, 0, 57.58, 0, 0, 0, 4.866e+05},
        [RR_METHOD_3DR_FULL] = {115.6, 0, 0, 0, 0, 71.31, 0, 0, 0, 4.137e+06},
        [RR_METHOD_RC_PACKET] = {89.5, 0, 0, 0, 0, 56.53, 0, 0, 0, 2.486e+06},
        [RR_METHOD_RC_BVH] = {87.48, 0, 0, 0, 0, 59.11, 0, 0, 0, 2.191e+06},
    },
    [RR_CAMERA_LATLONG] = {
        [RR_METHOD_3DR_BIN] = {18.44, 0, 0, 0, 0, 39.6, 0, 0, 0, 7.648e+05},
        [RR_METHOD_3DR_FC] = {60.04, 0, 0, 0, 0, 51.09, 0, 0, 0, 8.335e+05},
        [RR_METHOD_3DR_FULL] = {167.2, 0, 0, 0, 0, 36.18, 0, 0, 0, 1.723e+06},
        [RR_METHOD_RC_PACKET] = {91.78, 0, 0, 0, 0, 61.88, 0, 0, 0, 1.738e+06},
        [RR_METHOD_RC_BVH] = {87.96, 0, 0, 0, 0, 65.51, 0, 0, 0, 1.526e+06},
    },
    [RR_CAMERA_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {67.38, 0, 0, 0, 0, 35.42, 0, 0, 0, 1.179e+06},
        [RR_METHOD_3DR_FC] = {163.4, 0, 0, 0, 0, 59.49, 0, 0, 0, 4.504e+05},
        [RR_METHOD_3DR_FULL] = {129.9, 0, 0, 0, 0, 35.94, 0, 0, 0, 5.788e+06},
        [RR_METHOD_RC_PACKET] = {103.6, 0, 0, 0, 0, 62.16, 0, 0, 0, 1.924e+06},
        [RR_METHOD_RC_BVH] = {103.7, 0, 0, 0, 0, 60.36, 0, 0, 0, 2.126e+06},
    },
    [RR_CAMERA_CUBE] = {
        [RR_METHOD_3DR_BIN] = {22.25, 0, 79.23, 0, 0, 0, 0, 0, 401.4, 5.786e+05},
        [RR_METHOD_3DR_FC] = {65.74, 0, 0, 0, 0, 14.64, 0, 0, 0, 6.196e+04},
        [RR_METHOD_3DR_FULL] = {45.71, 0, 10, 0, 0, 0, 0, 0, 1.32, 0},
        [RR_METHOD_RC_PACKET] = {170, 0, 0, 0, 0, 0, 1.638, 0, 0, 1.06e+06},
        [RR_METHOD_RC_BVH] = {151.6, 0, 0, 0, 0, 59.6, 0, 0, 0, 1.237e+06},
    },
    [RR_CAMERA_OPENCV] = {
        [RR_METHOD_3DR_BIN] = {3432, 0, 0, 0, 0, 78.23, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2789, 0, 0, 0, 0, 177.7, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1136, 0, 0, 0, 0, 359.1, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {162.5, 0, 0, 0, 0, 112, 6.07, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {159.3, 0, 0, 0, 0, 76.68, 8.79, 0, 0, 0},
    },
    [RR_CAMERA_OPENCV_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {3468, 0, 0, 0, 0, 66.71, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2736, 0, 0, 0, 0, 164.7, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1123, 0, 0, 0, 0, 375.3, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {176.1, 0, 0, 0, 0, 78.44, 7.977, 0, 0, 1.655e+05},
        [RR_METHOD_RC_BVH] = {172.3, 0, 0, 0, 0, 78.99, 7.986, 0, 0, 0},
    },
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.687,
    [RR_METHOD_3DR_BIN] = 0.655,
    [RR_METHOD_3DR_FC] = 0.485,
    [RR_METHOD_3DR_FULL] = 0.357,
    [RR_METHOD_RC_PACKET] = 0.746,
    [RR_METHOD_RC_BVH] = 0.804,
};
