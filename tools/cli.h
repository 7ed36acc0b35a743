/* What the command line's files share; tools/rastray.c defines what camera_file.c
 * and progress.c do not. Exit codes: 0 success, 1 bad input (files, scenes),
 * 2 bad usage (flags, values). */
#ifndef RASTRAY_TOOLS_CLI_H
#define RASTRAY_TOOLS_CLI_H

#include "rastray.h"

#include <stdbool.h>

enum { EXIT_INPUT = 1, EXIT_USAGE = 2 };

/* Prints "rastray: MESSAGE" on its own line on stderr and exits with `code`. */
void die(int code, const char *fmt, ...) __attribute__((noreturn, format(printf, 2, 3)));
/* A message on stderr when the verbosity is at least `level` (-1 --quiet, 0, 1 --verbose). */
void note(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Milliseconds on a monotonic clock. */
double now_ms(void);

struct cJSON;
/* Adds a JSON value as the file `path` to the run's output set, written with the
 * images, all or nothing ("-": stdout; a device such as /dev/null directly), and
 * frees it; exits when it cannot. */
void json_add(rr_device *dev, rr_output *set, struct cJSON *root, const char *path);

/* The fields of an rr_camera that a flag or a camera file gives (rastray.h's RR_CAMERA_FIELD_*). */
enum {
  CAM_TYPE = RR_CAMERA_FIELD_TYPE, CAM_EYE = RR_CAMERA_FIELD_EYE, CAM_TARGET = RR_CAMERA_FIELD_TARGET,
  CAM_UP = RR_CAMERA_FIELD_UP, CAM_FOV = RR_CAMERA_FIELD_FOV, CAM_ORTHO = RR_CAMERA_FIELD_ORTHO,
  CAM_LENS = RR_CAMERA_FIELD_LENS
};
/* Reads a camera file (rr_camera_load), or a COLMAP model's or NeRF file's camera as
 * PATH[:IMAGE] (rr_camera_import), into *cam and returns the fields it gave; the
 * others keep their values. *width, *height: the imported camera's image, else 0.
 * A bad file ends the program (exit 1). */
unsigned camera_file_read(rr_device *dev, const char *arg, rr_camera *cam, int *width, int *height);
/* Adds a camera file for an image of width × height to the output set. */
void camera_file_add(rr_device *dev, rr_output *set, const char *path, const rr_camera *cam, int width, int height);

#endif
