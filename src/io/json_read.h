/* Typed reading of JSON objects (cJSON) for the scene and camera files: every
 * getter checks the value's type and range and, when it is wrong, fails with one
 * line naming the file and the key's path ("scene file 'a.json': 'meshes[1].scale':
 * expected a number > 0"). A key that is absent leaves the output untouched. */
#ifndef RR_IO_JSON_READ_H
#define RR_IO_JSON_READ_H

#include "core/core.h"

#include <cJSON.h>
#include <stdbool.h>

typedef struct json_reader {
  rr_device *dev;
  const char *what; /* the file, as messages name it: "scene file 'a.json'" */
  char at[192];     /* the path of the value being read ("meshes[1].material"); "" at the top */
} json_reader;

/* Reads a whole text file of at most max_bytes and parses it; *root is an object.
 * On failure (the file, its size, bad JSON with its line, not an object) returns
 * the error, *root NULL. */
rr_error rr_json_parse_file(json_reader *r, const char *path, size_t max_bytes, cJSON **root);

/* Steps into a member: appends ".key" (or "key" at the top) or "[index]" (key NULL)
 * to r->at and returns the previous length, for rr_json_leave. */
size_t rr_json_enter(json_reader *r, const char *key, int index);
static inline void rr_json_leave(json_reader *r, size_t len) { r->at[len] = 0; }

/* Fails with RR_ERROR_PARSE: "<what>: <at>.<key>: <message>" (key may be NULL). */
rr_error rr_json_fail(json_reader *r, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Checks that obj is an object whose keys are all among `keys` (a NULL-ended list),
 * each once. */
rr_error rr_json_keys(json_reader *r, const cJSON *obj, const char *const *keys);

/* The member `key` of obj, NULL when absent. */
static inline const cJSON *rr_json_get(const cJSON *obj, const char *key) {
  return cJSON_GetObjectItemCaseSensitive(obj, key);
}

/* A finite number in [lo, hi]. */
rr_error rr_json_float(json_reader *r, const cJSON *obj, const char *key, double lo, double hi, float *out);
/* The same, kept as a double. */
rr_error rr_json_double(json_reader *r, const cJSON *obj, const char *key, double lo, double hi, double *out);
/* An integer in [lo, hi]. */
rr_error rr_json_int(json_reader *r, const cJSON *obj, const char *key, int lo, int hi, int *out);
/* true or false. */
rr_error rr_json_bool(json_reader *r, const cJSON *obj, const char *key, int *out);
/* A string (owned by the parse). */
rr_error rr_json_string(json_reader *r, const cJSON *obj, const char *key, const char **out);
/* An array (the item itself) of exactly n <= 16 finite numbers, each in [lo, hi]. */
rr_error rr_json_array_doubles(json_reader *r, const cJSON *item, int n, double lo, double hi, double *out);
/* The member key: an array of exactly n <= 16 finite numbers, each in [lo, hi]. */
rr_error rr_json_doubles(json_reader *r, const cJSON *obj, const char *key, int n, double lo, double hi, double *out);
/* The same, rounded to floats. */
rr_error rr_json_floats(json_reader *r, const cJSON *obj, const char *key, int n, double lo, double hi, float *out);
/* A name that from_name knows (an rr_*_from_name: -1 when unknown); `expected`
 * lists the names for the message. */
rr_error rr_json_named(json_reader *r, const cJSON *obj, const char *key, int (*from_name)(const char *),
                    const char *expected, int *out);

#endif
