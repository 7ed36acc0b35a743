/* Material textures: the files named by materials, or images embedded in the scene
 * file, decoded to 8-bit RGB (and alpha), with their MIP chains (shade/texture.h).
 *
 * A texture that cannot be found or decoded is not an error: the material keeps an
 * empty texture (width 0), shades with its base colour, and its status says why
 * (rr_scene_get_material_info), so nothing is dropped silently. */
#define _POSIX_C_SOURCE 200809L

#include "io/io.h"
#include "shade/texture.h"

#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include <stb_image.h>

/* Takes stb's RGBA pixels (or NULL) of size w×h into tex when that size is
 * acceptable: RGB, alpha when any texel is not opaque, and the MIP chain. */
static bool take_rgb(rr_texture *tex, uint8_t *px, int w, int h) {
  if (!px) return false;
  bool ok = w >= 1 && h >= 1 && w <= RR_MAX_SIZE && h <= RR_MAX_SIZE;
  size_t n = ok ? (size_t)w * h : 0;
  bool opaque = true;
  for (size_t k = 0; k < n; k++) opaque &= px[4 * k + 3] == 255;
  /* copied so that the scene can release it with free() whatever allocator stb uses */
  uint8_t *rgb = ok ? malloc(3 * n) : NULL, *alpha = ok && !opaque ? malloc(n) : NULL;
  if (rgb && (opaque || alpha)) {
    for (size_t k = 0; k < n; k++) {
      memcpy(rgb + 3 * k, px + 4 * k, 3);
      if (alpha) alpha[k] = px[4 * k + 3];
    }
    tex->width = w, tex->height = h, tex->rgb = rgb, tex->alpha = alpha;
    ok = rr_texture_prepare(tex);
    if (!ok) rr_texture_clear(tex);
  } else {
    free(rgb), free(alpha);
    ok = false;
  }
  stbi_image_free(px);
  return ok;
}

bool rr_texture_decode(rr_texture *tex, const void *bytes, size_t len) {
  int w = 0, h = 0, n;
  if (len > INT32_MAX) return false;
  uint8_t *px = stbi_load_from_memory(bytes, (int)len, &w, &h, &n, 4);
  return take_rgb(tex, px, w, h);
}

static bool is_file(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* dir/name, malloc'd (NULL when out of memory); name alone when dir is NULL. */
static char *join(const char *dir, const char *name) {
  size_t len = (dir ? strlen(dir) + 1 : 0) + strlen(name) + 1;
  char *p = malloc(len);
  if (p) snprintf(p, len, "%s%s%s", dir ? dir : "", dir ? "/" : "", name);
  return p;
}

/* The entry of directory dir named like `name` but for letter case (an exact match
 * first); malloc'd dir/entry, or NULL. */
static char *find_nocase(const char *dir, const char *name) {
  char *exact = join(dir, name);
  if (!exact || is_file(exact)) return exact;
  struct stat st;
  if (stat(exact, &st) == 0 && S_ISDIR(st.st_mode)) return exact;
  free(exact);
  DIR *d = opendir(dir);
  if (!d) return NULL;
  char *found = NULL;
  for (struct dirent *e; !found && (e = readdir(d));)
    if (strcasecmp(e->d_name, name) == 0) found = join(dir, e->d_name);
  closedir(d);
  return found;
}

/* Follows path (components separated by '/') from dir, each component matched
 * regardless of case; malloc'd path of the file, or NULL. */
static char *walk_nocase(const char *dir, char *path) {
  char *cur = strdup(dir), *save = NULL;
  for (char *part = strtok_r(path, "/", &save); cur && part; part = strtok_r(NULL, "/", &save)) {
    if (strcmp(part, ".") == 0) continue;
    char *next = find_nocase(cur, part);
    free(cur);
    cur = next;
  }
  if (cur && !is_file(cur)) free(cur), cur = NULL;
  return cur;
}

/* Where the texture named `name` is, trying in turn: the name as given (relative to
 * base_dir), with '\' read as '/' (material files written on Windows), letter case
 * ignored (a file naming TEST.PNG beside test.png), and the bare file name beside
 * the scene (absolute paths of the machine that wrote the file). Malloc'd, or NULL. */
static char *find_texture(const char *base_dir, const char *name) {
  bool absolute = name[0] == '/';
  const char *dir = absolute || !base_dir || !base_dir[0] ? NULL : base_dir;
  char *path = join(dir, name);
  if (!path || is_file(path)) return path;
  free(path);
  char *rel = strdup(name);
  if (!rel) return NULL;
  for (char *p = rel; *p; p++)
    if (*p == '\\') *p = '/';
  char *base = strrchr(rel, '/'); /* before the walk cuts rel into components */
  char *found = walk_nocase(absolute ? "/" : dir ? dir : ".", rel + absolute);
  if (!found && base) found = walk_nocase(dir ? dir : ".", base + 1);
  free(rel);
  return found;
}

void rr_scene_load_textures(rr_scene *s, const char *base_dir) {
  if (!s) return;
  for (uint32_t i = 0; i < s->nmaterials; i++) {
    rr_material *m = &s->materials[i];
    if (!m->texture_path || !m->texture_path[0] || m->texture_status != RR_TEXTURE_NONE) continue;
    m->texture.width = m->texture.height = 0;
    char *file = find_texture(base_dir, m->texture_path);
    int w = 0, h = 0, n;
    uint8_t *px = file ? stbi_load(file, &w, &h, &n, 4) : NULL;
    m->texture_status = !file ? RR_TEXTURE_MISSING : take_rgb(&m->texture, px, w, h) ? RR_TEXTURE_FILE
                                                                                       : RR_TEXTURE_UNREADABLE;
    free(file);
  }
}

bool rr_material_texture_file(rr_material *m, const char *path, const char *name) {
  int w = 0, h = 0, n;
  rr_texture tex = {0};
  char *copy = malloc(strlen(name) + 1);
  uint8_t *px = stbi_load(path, &w, &h, &n, 4); /* before take_rgb reads w, h */
  if (!copy || !take_rgb(&tex, px, w, h)) { /* take_rgb frees px */
    if (!copy) stbi_image_free(px);
    free(copy);
    return false;
  }
  rr_texture_clear(&m->texture);
  free(m->texture_path);
  m->texture = tex, m->texture_path = strcpy(copy, name), m->texture_status = RR_TEXTURE_FILE;
  return true;
}
