/* Cameras: the ray direction of every sample, and bounds for rasterization. */
#include "rr.h"

void rr_camera_init(rr_camera *cam) {
  if (!cam) return;
  *cam = (rr_camera){.type = RR_CAMERA_PERSPECTIVE,
                     .eye = {0, 0, 3},
                     .target = {0, 0, 0},
                     .up = {0, 1, 0},
                     .fov_deg = 45};
}

static bool finite_v(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

rr_error rr_camera_check(rr_device *dev, const rr_camera *c) {
  if (!c) return rr_fail(dev, RR_ERROR_ARGUMENT, "camera is NULL");
  if (c->type != RR_CAMERA_PERSPECTIVE) return rr_fail(dev, RR_ERROR_ARGUMENT, "unknown camera type %d", (int)c->type);
  if (!finite_v(c->eye) || !finite_v(c->target) || !finite_v(c->up))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "camera vectors must be finite");
  if (!(c->fov_deg > 0 && c->fov_deg < 180))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad field of view %g (expected 0 < fov < 180 degrees)", c->fov_deg);
  vec3 f = v3_sub(v3_load(c->target), v3_load(c->eye));
  if (f.x == 0 && f.y == 0 && f.z == 0)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "eye equals target (%g,%g,%g)", c->eye[0], c->eye[1], c->eye[2]);
  vec3 up = v3_load(c->up);
  float lf = v3_len(f), lu = v3_len(up);
  if (!(lu > 0) || !(v3_len(v3_cross(f, up)) > 1e-6f * lf * lu))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "up (%g,%g,%g) is parallel to the view direction", c->up[0], c->up[1],
                   c->up[2]);
  return rr_ok(dev);
}

rr_error camera_setup(rr_device *dev, const rr_camera *in, int width, int height, camera *c) {
  rr_error e = rr_camera_check(dev, in);
  if (e) return e;
  if (width < 1 || height < 1 || width > RR_MAX_SIZE || height > RR_MAX_SIZE)
    return rr_fail(dev, RR_ERROR_ARGUMENT, "bad image size %dx%d (1..%d per side)", width, height, RR_MAX_SIZE);
  c->type = in->type;
  c->width = width;
  c->height = height;
  c->eye = v3_load(in->eye);
  c->fwd = v3_norm(v3_sub(v3_load(in->target), c->eye));
  c->right = v3_norm(v3_cross(c->fwd, v3_load(in->up)));
  c->up = v3_cross(c->right, c->fwd);
  c->tan_half_h = tanf(in->fov_deg * (float)M_PI / 360.0f);
  c->tan_half_w = c->tan_half_h * (float)width / (float)height;
  /* d(sx, sy) = fwd + (2 sx / W - 1) tw right + (1 - 2 sy / H) th up */
  c->d0 = v3_add(c->fwd, v3_sub(v3_scale(c->up, c->tan_half_h), v3_scale(c->right, c->tan_half_w)));
  c->dx = v3_scale(c->right, 2.0f * c->tan_half_w / (float)width);
  c->dy = v3_scale(c->up, -2.0f * c->tan_half_h / (float)height);
  return rr_ok(dev);
}

bool camera_project(const camera *c, vec3 p, float *sx, float *sy) {
  float z = v3_dot(p, c->fwd);
  if (!(z > 0)) return false;
  float u = v3_dot(p, c->right) / (z * c->tan_half_w), v = v3_dot(p, c->up) / (z * c->tan_half_h);
  *sx = (u + 1.0f) * 0.5f * (float)c->width;
  *sy = (1.0f - v) * 0.5f * (float)c->height;
  return true;
}

rr_error rr_camera_frame(rr_device *dev, const rr_scene *s, int width, int height, rr_camera *cam) {
  if (!s || !cam) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_camera_frame: NULL argument");
  if (s->ntris == 0) return rr_fail(dev, RR_ERROR_EMPTY, "cannot frame an empty scene");
  if (width < 1 || height < 1) return rr_fail(dev, RR_ERROR_ARGUMENT, "bad image size %dx%d", width, height);
  vec3 centre = v3_scale(v3_add(s->bmin, s->bmax), 0.5f);
  float th = cam->fov_deg > 0 && cam->fov_deg < 180 ? tanf(cam->fov_deg * (float)M_PI / 360.0f) : 0.41f;
  float tw = th * (float)width / (float)height, fill = 0.94f;
  /* Look from the front and a little above; back off until every corner of the
   * bounding box is inside the view: for a corner at offset o from the centre, at
   * depth D - o·dir, |o·right| <= depth·tw and |o·up| <= depth·th. */
  vec3 dir = v3_norm(v3(0.0f, 0.5f, 1.0f));
  vec3 right = v3_norm(v3_cross(v3_neg(dir), v3(0, 1, 0))), up = v3_cross(right, v3_neg(dir));
  float dist = 0;
  for (int k = 0; k < 8; k++) {
    vec3 o = v3_sub(v3(k & 1 ? s->bmax.x : s->bmin.x, k & 2 ? s->bmax.y : s->bmin.y, k & 4 ? s->bmax.z : s->bmin.z),
                    centre);
    float along = v3_dot(o, dir);
    dist = fmaxf(dist, along + fabsf(v3_dot(o, right)) / (tw * fill));
    dist = fmaxf(dist, along + fabsf(v3_dot(o, up)) / (th * fill));
    dist = fmaxf(dist, along * 1.01f);
  }
  if (!(dist > 0)) dist = 1;
  vec3 eye = v3_add(centre, v3_scale(dir, dist));
  cam->eye[0] = eye.x, cam->eye[1] = eye.y, cam->eye[2] = eye.z;
  cam->target[0] = centre.x, cam->target[1] = centre.y, cam->target[2] = centre.z;
  cam->up[0] = 0, cam->up[1] = 1, cam->up[2] = 0;
  return rr_ok(dev);
}
