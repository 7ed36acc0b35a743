
/* auto's costs: written by `bench_auto --calibrate --threads 2` (132 views, median of 5);
 * see vis/auto.c and docs/auto.md. Figures: T, S, A, R, UP, P, PlogT, S/D, F, 1. */
static const double cost_planar[RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_METHOD_3DR_BB] = {6.991, 104.2, 1.694, 0, 0.2169, 0.271, 0, 0, 0, 0},
    [RR_METHOD_3DR_BIN] = {7.616, 89.22, 0.6867, 18.28, 0, 1.145, 0, 0, 0, 0},
    [RR_METHOD_3DR_FC] = {23.2, 116, 1.939, 0, 0, 2.404, 0, 627.7, 0, 0},
    [RR_METHOD_3DR_FULL] = {18.11, 0, 1.853, 0, 0, 5.368, 0, 0, 473.8, 1.231e+05},
    [RR_METHOD_RC_PACKET] = {23.71, 267.1, 1.96, 0, 0, 0, 0.5658, 0, 0, 0},
    [RR_METHOD_RC_BVH] = {20.55, 306.8, 12.19, 0, 0, 0, 0.149, 0, 0, 0},
};
static const double cost_curved[RR_CAMERA_COUNT][RR_METHOD_COUNT][AUTO_NFIG] = {
    [RR_CAMERA_PARABOLIC] = {
        [RR_METHOD_3DR_BIN] = {18.76, 0, 0, 0, 0, 34.2, 0, 0, 0, 1.376e+06},
        [RR_METHOD_3DR_FC] = {59.55, 0, 0, 0, 0, 60.14, 0, 0, 0, 5.665e+05},
        [RR_METHOD_3DR_FULL] = {108.5, 0, 0, 0, 0, 67.2, 0, 0, 0, 4.901e+06},
        [RR_METHOD_RC_PACKET] = {90.28, 0, 0, 0, 0, 51.33, 0, 0, 0, 3.181e+06},
        [RR_METHOD_RC_BVH] = {85.2, 0, 0, 0, 0, 58.84, 0, 0, 0, 2.507e+06},
    },
    [RR_CAMERA_LATLONG] = {
        [RR_METHOD_3DR_BIN] = {17.14, 0, 0, 0, 0, 41.08, 0, 0, 0, 7.77e+05},
        [RR_METHOD_3DR_FC] = {62, 0, 0, 0, 0, 50.2, 0, 0, 0, 9.738e+05},
        [RR_METHOD_3DR_FULL] = {159.3, 0, 0, 0, 0, 40.27, 0, 0, 0, 1.723e+06},
        [RR_METHOD_RC_PACKET] = {91.77, 0, 0, 0, 0, 67.07, 0, 0, 0, 1.677e+06},
        [RR_METHOD_RC_BVH] = {91.13, 0, 0, 0, 0, 71.77, 0, 0, 0, 1.334e+06},
    },
    [RR_CAMERA_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {48.51, 0, 0, 0, 0, 34.19, 0, 0, 0, 1.547e+06},
        [RR_METHOD_3DR_FC] = {132.7, 0, 0, 0, 0, 59.93, 0, 0, 0, 6.226e+05},
        [RR_METHOD_3DR_FULL] = {131.5, 0, 0, 0, 0, 34.22, 0, 0, 0, 6e+06},
        [RR_METHOD_RC_PACKET] = {97.15, 0, 0, 0, 0, 59.23, 0, 0, 0, 2.339e+06},
        [RR_METHOD_RC_BVH] = {99.24, 0, 0, 0, 0, 58.63, 0, 0, 0, 2.336e+06},
    },
    [RR_CAMERA_CUBE] = {
        [RR_METHOD_3DR_BIN] = {31.14, 0, 3.353, 0, 0, 0, 0, 0, 193.6, 0},
        [RR_METHOD_3DR_FC] = {65.68, 0, 0, 0, 0, 14.51, 0, 0, 0, 7.769e+04},
        [RR_METHOD_3DR_FULL] = {47.63, 0, 10.69, 0, 0, 0, 0, 0, 1.576, 0},
        [RR_METHOD_RC_PACKET] = {168.1, 0, 0, 0, 0, 0, 1.373, 0, 0, 1.286e+06},
        [RR_METHOD_RC_BVH] = {153.4, 0, 0, 0, 0, 50.39, 0, 0, 0, 1.454e+06},
    },
    [RR_CAMERA_OPENCV] = {
        [RR_METHOD_3DR_BIN] = {3505, 0, 0, 0, 0, 74.63, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2841, 0, 0, 0, 0, 173.3, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1145, 0, 0, 0, 0, 360.4, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {181.7, 0, 0, 0, 0, 164.2, 2.028, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {181.2, 0, 0, 0, 0, 162.3, 2.154, 0, 0, 0},
    },
    [RR_CAMERA_OPENCV_FISHEYE] = {
        [RR_METHOD_3DR_BIN] = {3378, 0, 0, 0, 0, 69.91, 0, 0, 0, 0},
        [RR_METHOD_3DR_FC] = {2753, 0, 0, 0, 0, 162.3, 0, 0, 0, 0},
        [RR_METHOD_3DR_FULL] = {1144, 0, 0, 0, 0, 378.6, 0, 0, 0, 0},
        [RR_METHOD_RC_PACKET] = {168.7, 0, 0, 0, 0, 146.9, 2.897, 0, 0, 0},
        [RR_METHOD_RC_BVH] = {167, 0, 0, 0, 0, 140.3, 3.407, 0, 0, 0},
    },
};
static const double thread_gain[RR_METHOD_COUNT] = {
    [RR_METHOD_3DR_BB] = 0.717,
    [RR_METHOD_3DR_BIN] = 0.737,
    [RR_METHOD_3DR_FC] = 0.509,
    [RR_METHOD_3DR_FULL] = 0.401,
    [RR_METHOD_RC_PACKET] = 0.808,
    [RR_METHOD_RC_BVH] = 0.866,
};
