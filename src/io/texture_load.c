/* Material textures: the files named by materials, decoded to 8-bit RGB.
 *
 * A texture that cannot be read is not an error: the material keeps an empty
 * texture (width 0) and shades with its base colour. */
#define _POSIX_C_SOURCE 200809L

#include "io/io.h"

#include <stdio.h>
#include <string.h>

#include <stb_image.h>

/* path itself when absolute or when there is no base directory, else base_dir/path;
 * malloc'd, NULL when out of memory. */
static char *resolve(const char *base_dir, const char *path) {
  bool relative = path[0] != '/' && base_dir && base_dir[0];
  size_t len = strlen(path) + (relative ? strlen(base_dir) + 1 : 0) + 1;
  char *full = malloc(len);
  if (!full) return NULL;
  if (relative) snprintf(full, len, "%s/%s", base_dir, path);
  else snprintf(full, len, "%s", path);
  return full;
}

/* Loads one file as RGB into tex; false (tex left empty) when it cannot. */
static bool load_rgb(rr_texture *tex, const char *file) {
  int w, h, n;
  uint8_t *px = stbi_load(file, &w, &h, &n, 3);
  if (!px) return false;
  bool ok = w >= 1 && h >= 1 && w <= RR_MAX_SIZE && h <= RR_MAX_SIZE;
  size_t bytes = ok ? (size_t)w * h * 3 : 0;
  /* copied so that the scene can release it with free() whatever allocator stb uses */
  uint8_t *rgb = ok ? malloc(bytes) : NULL;
  if (rgb) {
    memcpy(rgb, px, bytes);
    tex->width = w;
    tex->height = h;
    tex->rgb = rgb;
  }
  stbi_image_free(px);
  return rgb != NULL;
}

void rr_scene_load_textures(rr_scene *s, const char *base_dir) {
  if (!s) return;
  for (uint32_t i = 0; i < s->nmaterials; i++) {
    rr_material *m = &s->materials[i];
    if (!m->texture_path || !m->texture_path[0] || m->texture.rgb) continue;
    m->texture.width = m->texture.height = 0;
    char *file = resolve(base_dir, m->texture_path);
    if (!file) continue;
    if (!load_rgb(&m->texture, file) && strchr(file, '\\')) {
      /* material files written on Windows often separate directories with '\' */
      for (char *p = file; *p; p++)
        if (*p == '\\') *p = '/';
      load_rgb(&m->texture, file);
    }
    free(file);
  }
}
