/* Input and output: scene import (assimp, built-ins), textures and image files. */
#ifndef RR_IO_H
#define RR_IO_H

#include "scene/scene.h"

/* Loaders: assimp files and the built-in scenes. rr_scene_import_guarded is the one
 * for files a user names: structural checks, then assimp in a child process under
 * the device's import limits (import_guard.c); rr_scene_import_file is assimp itself. */
rr_error rr_scene_import_guarded(rr_scene *s, const char *path);
rr_error rr_scene_import_file(rr_scene *s, const char *path);
/* Returns RR_OK when `name` named a built-in scene (and fills s), RR_ERROR_UNSUPPORTED
 * when it is not a built-in name; other codes are real failures. */
rr_error rr_scene_load_builtin(rr_scene *s, const char *name);
/* Smooth corner normals for triangles [t0, t1) (src/io/builtin.c): each corner
 * averages the area-weighted normals of the triangles meeting at the same position
 * whose faces turn by less than 60° from its own, so creases (the teapot's rim) stay sharp. */
rr_error rr_scene_smooth_normals(rr_scene *s, uint32_t t0, uint32_t t1);
/* Loads the textures named by the materials that have none yet, from files found
 * from base_dir; the materials' texture_status says what became of each. */
void rr_scene_load_textures(rr_scene *s, const char *base_dir);
/* Decodes a compressed image in memory (PNG, JPEG, ... as stb_image reads) into tex;
 * false (tex untouched) when it cannot. */
bool rr_texture_decode(rr_texture *tex, const void *bytes, size_t len);
/* Gives material m the texture in image file `path` (named `name`), in place of any
 * it had; false (m untouched) when the file cannot be read or decoded, or memory
 * runs out. */
bool rr_material_texture_file(rr_material *m, const char *path, const char *name);

#endif
