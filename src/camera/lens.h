/* OpenCV's lens models (rr_camera's fx, fy, cx, cy, dist) forwards and inverted. */
#ifndef RR_LENS_H
#define RR_LENS_H

#include <stdbool.h>

#include "rastray.h"

/* Where the camera's radial map folds back (Brown–Conrady: the undistorted radius
 * where r·q(r²) stops growing, at most 1e4; fisheye: the angle where θd(θ) does, at
 * most π): the edge of the field a camera renders. */
double rr_lens_fold(const rr_camera *cam);
/* The unit ray, in camera axes (x right, y down, z forward), of OpenCV image point
 * (u, v) (pixel centres at integers), and when ddir is not NULL its derivatives by
 * u (ddir[0]) and v (ddir[1]); false where the point has no ray (beyond the fold,
 * or where the inversion does not converge). */
bool rr_lens_unproject(const rr_camera *cam, double fold, double u, double v, double dir[3], double ddir[2][3]);
/* OpenCV's projection of camera-axes point p (cv::projectPoints without pose, or
 * cv::fisheye::projectPoints): false when p is not in front (z <= 0). */
bool rr_lens_project(const rr_camera *cam, const double p[3], double *u, double *v);

/* The largest angle from the axis of the rays of a width × height image (at most
 * atan(fold), or the fisheye's fold; the Brown–Conrady's with tangential terms is that). */
double rr_lens_field(const rr_camera *cam, double fold, int width, int height);
/* The sample-coordinate extents x0, x1, y0, y1 of every pixel whose ray lies
 * within angle rho of the unit axis (camera axes), the cap wholly in front: the
 * cap's box in the undistorted plane, mapped through the distortion in interval
 * arithmetic. 1 with e, 0 when no pixel's ray can lie there (beyond the field,
 * rr_lens_field), -1 when unknown. */
int rr_lens_cap_extent(const rr_camera *cam, double fold, double field, const double axis[3], double rho,
                       double e[4]);

#endif
