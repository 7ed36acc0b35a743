/* rr_scene_load: a built-in scene by name, a scene file (.json), else a file through assimp. */
#include "io/io.h"

#include <string.h>

rr_error rr_scene_load(rr_device *dev, const char *path, rr_scene **out) {
  if (!out || !path) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_scene_load: NULL argument");
  *out = NULL;
  size_t len = strlen(path);
  if (len > 5 && strcmp(path + len - 5, ".json") == 0) return rr_scene_load_file(dev, path, NULL, out, NULL);
  rr_scene *s;
  rr_error e = rr_scene_new(dev, &s);
  if (e) return e;
  progress_span progress = {dev, RR_PROGRESS_LOAD, 0, 1}; /* files give no fraction to report */
  rr_progress(&progress, 0);
  e = rr_scene_load_builtin(s, path);
  if (e == RR_ERROR_UNSUPPORTED) e = rr_scene_import_guarded(s, path);
  if (!e) rr_progress(&progress, 1);
  if (!e && s->ntris == 0)
    e = rr_fail(dev, RR_ERROR_EMPTY, "scene '%s' has no triangles%s", path,
                s->skipped ? " (all were degenerate or non-finite)" : "");
  if (!e) e = rr_scene_commit(s);
  if (e) {
    rr_scene_release(s);
    return e;
  }
  *out = s;
  return rr_ok(dev);
}
