/* Cameras resolved for an image: a ray for every sample, planar bases, cones of curved views. */
#ifndef RR_CAMERA_H
#define RR_CAMERA_H

#include "scene/scene.h"

/* A camera resolved for an image and one position of the sample pattern: the
 * sample (sx, sy) of pixel (x, y) is (x + sx0, y + sy0), row 0 at the top, and
 * (sx0, sy0) is the only place a position inside the pixel is written (the centre,
 * 0.5, 0.5, for one sample per pixel). A pattern of N samples renders N such
 * cameras, one layer of the visibility buffer each. Planar cameras (perspective, orthographic)
 * have edge functions linear in (sx, sy): a perspective ray leaves the eye along
 * d0 + sx·dx + sy·dy; an orthographic ray leaves eye + o0 + sx·ox + sy·oy along fwd.
 * Curved cameras (parabolic, lat-long, fisheye, the OpenCV lenses) keep one direction per
 * sample in `dirs` (zero where the image has no ray), and bound the directions of
 * a rectangle of samples by a cone whose half-angle grows by `lipschitz` radians
 * per pixel of distance (the lenses: by the exact cones of small cells, `fine`).
 * The cube keeps neither: every method draws its faces, perspective cameras
 * (rr_cam_cube_face), and rr_cam_ray gives its rays. */
typedef struct camera {
  rr_camera_type type;
  int width, height;
  float sx0, sy0; /* the sample's position inside every pixel, in [0, 1) */
  bool planar;
  vec3 eye, right, up, fwd;
  vec3 d0, dx, dy;
  vec3 col_n0, col_n1, row_n0, row_n1; /* perspective: n0 + x·n1 is the plane of column x, */
                                      /* row y likewise, facing increasing x (y) */
  vec3 o0, ox, oy;
  float tan_half_h, tan_half_w;
  float fov_deg; /* as given: the fisheye's angle */
  vec3 *dirs;
  float lipschitz;
  float *fine;       /* measured maps (the OpenCV lenses): per CAMERA_FINE² cell of samples, the */
  int fine_x;        /* least cone about its centre's ray that holds its rays: unit axis, half-angle */
                     /* (< 0: no rays), 4 floats a cell, fine_x cells a row; NULL otherwise */
  double bend_x, bend_y; /* polar curved maps: bounds on |∂²d/∂sx²|, |∂²d/∂sy²| over the */
                         /* image (rr_cam_dir_at's d); 0 when none is known */
  float dir_len_max; /* longest |d| of the camera's rays */
  int face;          /* cube: side of a face in pixels */
  int cells_x, cells_y; /* curved: cones of CAMERA_CELL² cells of samples, 4 floats each: */
  float *cells;         /* unit axis and half-angle; no bound when >= CAMERA_NO_CONE, no rays when < 0 */
  rr_camera lens;       /* the OpenCV cameras: intrinsics and distortion as given */
  double lens_fold;     /* and the edge of their field (rr_lens_fold), */
  double lens_field;    /* the largest angle of the image's rays from fwd (rr_lens_field) */
} camera;

#define CAMERA_CELL 32
/* camera.fine's cells: as small as the traversal's frusta split (vis/traverse.c). */
#define CAMERA_FINE 8
/* Cones (and caps) of directions this wide or wider bound nothing: the cone tests
 * hold for half-angles under 90° only (a little more than 1.5 radians). A cell
 * without a useful cone stores this half-angle. */
#define CAMERA_NO_CONE 1.5f

/* The cube camera is six perspective cameras of 90°, one per face of F×F samples
 * (F = c->face) in the horizontal cross: a ray of face f is that face's planar
 * d0 + sx·dx + sy·dy with (sx, sy) the sample's position within the face, so every
 * method tests a face's samples as a perspective camera's (and may share the part of
 * a triangle's setup that depends on the eye alone between the faces).
 * rr_cam_cube_face: face f (0..5: front, right, back, left, top, bottom) of cube
 * camera c, at c's sample position; rr_cam_cube_face_origin: where its samples
 * start in the cross; rr_cam_cube_face_at: the face of pixel (x, y), -1 in a gap. */
void rr_cam_cube_face(const camera *c, int f, camera *out);
void rr_cam_cube_face_origin(const camera *c, int f, int *x0, int *y0);
int rr_cam_cube_face_at(const camera *c, int x, int y);

/* Resolves a public camera for an image size; rr_cam_release frees it. */
rr_error rr_cam_setup(rr_device *dev, const rr_camera *in, int width, int height, camera *out);
/* The same for the sample at `sample` (x, y in [0, 1)) inside every pixel. */
rr_error rr_cam_setup_at(rr_device *dev, const rr_camera *in, int width, int height, const float sample[2],
                         camera *out);
/* The same on `threads` threads (1..RR_MAX_THREADS): a curved camera's table of
 * rays in bands of rows, with the same bits. */
rr_error rr_cam_setup_threads(rr_device *dev, const rr_camera *in, int width, int height, const float sample[2],
                              int threads, camera *out);
void rr_cam_release(camera *c);
/* The ray of sample (sx, sy) of a planar perspective camera (unnormalised). */
static inline vec3 camera_dir(const camera *c, float sx, float sy) {
  return v3_add(c->d0, v3_add(v3_scale(c->dx, sx), v3_scale(c->dy, sy)));
}
/* The ray of pixel (x, y) for any camera: origin and (unnormalised) direction;
 * false when the pixel has no ray (outside a hemisphere's disk, a cube's cross). */
bool rr_cam_ray(const camera *c, int x, int y, vec3 *origin, vec3 *dir);
/* rr_cam_ray with the ray's differentials: the derivatives of its origin and of
 * its (unnormalised) direction with respect to the sample position, per pixel step
 * in x ([0]) and in y ([1]), exact for every camera (constant for the planar ones;
 * a cube's within the pixel's face). Zero where the pixel has no ray (false). */
bool rr_cam_ray_diff(const camera *c, int x, int y, vec3 *origin, vec3 *dir, vec3 do_dxy[2], vec3 dd_dxy[2]);
/* What a triangle's edge functions are evaluated against at pixel (x, y):
 * (1, sx, sy) for planar cameras, the ray direction for curved ones (not the
 * cube: its faces'). */
static inline vec3 camera_w(const camera *c, int x, int y) {
  return c->planar ? v3(1.0f, (float)x + c->sx0, (float)y + c->sy0) : c->dirs[(size_t)y * c->width + x];
}
/* The direction of a polar curved camera (parabolic, lat-long, fisheye) at any
 * sample position (sx, sy) in double, the map extended smoothly beyond the disk
 * where it has one: the rays of the samples with rays, without their float
 * rounding. False for the other cameras. */
bool rr_cam_dir_at(const camera *c, double sx, double sy, double d[3]);
/* Projects a point given relative to the eye to sample coordinates (planar
 * cameras); false when it is not strictly in front of the image plane. */
bool rr_cam_project(const camera *c, vec3 p, float *sx, float *sy);
/* A cone (unit axis, half-angle) holding the directions of the samples
 * [x0, x1) × [y0, y1) of a curved camera: 1 when found, 0 when none is known,
 * -1 when none of the samples has a ray (not for the cube, which has no rays of its own). */
int rr_cam_rect_cone(const camera *c, int x0, int y0, int x1, int y1, vec3 *axis, float *angle);
/* The angle a pixel of the samples [x0, x1) × [y0, y1) of a curved camera spans,
 * to judge sizes by (not a bound), from their rr_cam_rect_cone (cone, angle):
 * camera.lipschitz, or for the lenses, whose stretch varies, the cone's
 * half-angle over the rectangle's half-diagonal. */
float rr_cam_rect_pixel_angle(const camera *c, int x0, int y0, int x1, int y1, int cone, float angle);

/* A pseudo-camera for one arbitrary ray: eye = origin, d0 = direction and dx, dy
 * two fixed directions perpendicular to it, so rr_tri_setup() sets a triangle
 * up for the ray, and its edge functions at sample (0, 0) are the ray's. The tie
 * bits (top-left rule) then come from the derivatives along dx, then dy: a ray
 * through a shared edge or vertex hits exactly one triangle. */
void rr_cam_for_ray(const float org[3], const float dir[3], camera *out);

#endif
