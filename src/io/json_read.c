/* Typed getters over cJSON with messages that name the key's path. */
#include "io/json_read.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rr_error rr_json_parse_file(json_reader *r, const char *path, size_t max_bytes, cJSON **root) {
  *root = NULL;
  FILE *f = fopen(path, "rb");
  if (!f) return rr_fail(r->dev, RR_ERROR_IO, "cannot open %s: %s", r->what, strerror(errno));
  char *text = malloc(max_bytes + 1);
  size_t n = text ? fread(text, 1, max_bytes + 1, f) : 0;
  int failed = ferror(f);
  fclose(f);
  rr_error e = RR_OK;
  if (!text) e = rr_fail(r->dev, RR_ERROR_MEMORY, "out of memory reading %s", r->what);
  else if (failed) e = rr_fail(r->dev, RR_ERROR_IO, "cannot read %s", r->what);
  else if (n > max_bytes) e = rr_fail(r->dev, RR_ERROR_PARSE, "%s: larger than %zu bytes", r->what, max_bytes);
  if (e) {
    free(text);
    return e;
  }
  text[n] = 0;
  const char *end = NULL;
  cJSON *doc = cJSON_ParseWithOpts(text, &end, 1);
  if (!doc) {
    int line = 1;
    for (const char *p = text; end && p < end; p++) line += *p == '\n';
    if (memchr(text, 0, n)) e = rr_fail(r->dev, RR_ERROR_PARSE, "%s: not valid JSON (a NUL byte)", r->what);
    else e = rr_fail(r->dev, RR_ERROR_PARSE, "%s: not valid JSON (line %d)", r->what, line);
  } else if (!cJSON_IsObject(doc)) {
    e = rr_fail(r->dev, RR_ERROR_PARSE, "%s: not a JSON object", r->what);
  }
  free(text);
  if (e) {
    cJSON_Delete(doc);
    return e;
  }
  *root = doc;
  return RR_OK;
}

size_t rr_json_enter(json_reader *r, const char *key, int index) {
  size_t len = strlen(r->at);
  if (key) snprintf(r->at + len, sizeof r->at - len, "%s%s", len ? "." : "", key);
  else snprintf(r->at + len, sizeof r->at - len, "[%d]", index);
  return len;
}

rr_error rr_json_fail(json_reader *r, const char *key, const char *fmt, ...) {
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  size_t len = key ? rr_json_enter(r, key, 0) : strlen(r->at);
  for (char *c = msg; *c; c++) /* the file's strings quoted in it (names, paths) stay on one line */
    if ((unsigned char)*c < 32) *c = '?';
  rr_error e = r->at[0] ? rr_fail(r->dev, RR_ERROR_PARSE, "%s: '%s': %s", r->what, r->at, msg)
                        : rr_fail(r->dev, RR_ERROR_PARSE, "%s: %s", r->what, msg);
  rr_json_leave(r, len);
  return e;
}

rr_error rr_json_keys(json_reader *r, const cJSON *obj, const char *const *keys) {
  if (!cJSON_IsObject(obj)) return rr_json_fail(r, NULL, "expected an object");
  for (const cJSON *k = obj->child; k; k = k->next) {
    size_t i = 0;
    while (keys[i] && strcmp(k->string, keys[i]) != 0) i++;
    if (!keys[i]) {
      char list[256] = "";
      for (size_t j = 0; keys[j]; j++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", j ? ", " : "", keys[j]);
      /* a key is the file's text: shown in part, never a line break */
      char shown[48];
      snprintf(shown, sizeof shown, "%s", k->string);
      for (char *c = shown; *c; c++)
        if ((unsigned char)*c < 32) *c = '?';
      return rr_json_fail(r, NULL, "unknown key '%s' (expected %s)", shown, list);
    }
    for (const cJSON *o = obj->child; o != k; o = o->next)
      if (strcmp(o->string, k->string) == 0) return rr_json_fail(r, k->string, "given twice");
  }
  return RR_OK;
}

/* A finite number in [lo, hi], for the key's message. */
static rr_error number(json_reader *r, const cJSON *item, const char *key, double lo, double hi, double *out) {
  if (!cJSON_IsNumber(item)) return rr_json_fail(r, key, "expected a number");
  double v = item->valuedouble;
  if (!isfinite(v)) return rr_json_fail(r, key, "expected a finite number");
  if (!(v >= lo && v <= hi)) return rr_json_fail(r, key, "%g is outside [%g, %g]", v, lo, hi);
  *out = v;
  return RR_OK;
}

rr_error rr_json_double(json_reader *r, const cJSON *obj, const char *key, double lo, double hi, double *out) {
  const cJSON *item = rr_json_get(obj, key);
  return item ? number(r, item, key, lo, hi, out) : RR_OK;
}

rr_error rr_json_float(json_reader *r, const cJSON *obj, const char *key, double lo, double hi, float *out) {
  double v;
  const cJSON *item = rr_json_get(obj, key);
  rr_error e = item ? number(r, item, key, lo, hi, &v) : RR_OK;
  if (item && !e) *out = (float)v;
  return e;
}

rr_error rr_json_int(json_reader *r, const cJSON *obj, const char *key, int lo, int hi, int *out) {
  double v;
  const cJSON *item = rr_json_get(obj, key);
  if (!item) return RR_OK;
  rr_error e = number(r, item, key, lo, hi, &v);
  if (!e && v != floor(v)) e = rr_json_fail(r, key, "expected an integer");
  if (!e) *out = (int)v;
  return e;
}

rr_error rr_json_bool(json_reader *r, const cJSON *obj, const char *key, int *out) {
  const cJSON *item = rr_json_get(obj, key);
  if (!item) return RR_OK;
  if (!cJSON_IsBool(item)) return rr_json_fail(r, key, "expected true or false");
  *out = cJSON_IsTrue(item);
  return RR_OK;
}

rr_error rr_json_string(json_reader *r, const cJSON *obj, const char *key, const char **out) {
  const cJSON *item = rr_json_get(obj, key);
  if (!item) return RR_OK;
  if (!cJSON_IsString(item) || !item->valuestring) return rr_json_fail(r, key, "expected a string");
  *out = item->valuestring;
  return RR_OK;
}

rr_error rr_json_array_doubles(json_reader *r, const cJSON *item, int n, double lo, double hi, double *out) {
  if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n) return rr_json_fail(r, NULL, "expected an array of %d numbers", n);
  double v[16];
  int i = 0;
  for (const cJSON *x = item->child; x && i < 16; x = x->next, i++) {
    rr_error e = number(r, x, NULL, lo, hi, &v[i]);
    if (e) return e;
  }
  memcpy(out, v, sizeof *v * (size_t)n);
  return RR_OK;
}

rr_error rr_json_doubles(json_reader *r, const cJSON *obj, const char *key, int n, double lo, double hi, double *out) {
  const cJSON *item = rr_json_get(obj, key);
  if (!item) return RR_OK;
  size_t len = rr_json_enter(r, key, 0);
  rr_error e = rr_json_array_doubles(r, item, n, lo, hi, out);
  rr_json_leave(r, len);
  return e;
}

rr_error rr_json_floats(json_reader *r, const cJSON *obj, const char *key, int n, double lo, double hi, float *out) {
  double v[16];
  if (!rr_json_get(obj, key)) return RR_OK;
  rr_error e = rr_json_doubles(r, obj, key, n, lo, hi, v);
  for (int i = 0; !e && i < n; i++) out[i] = (float)v[i];
  return e;
}

rr_error rr_json_named(json_reader *r, const cJSON *obj, const char *key, int (*from_name)(const char *),
                    const char *expected, int *out) {
  const cJSON *item = rr_json_get(obj, key);
  if (!item) return RR_OK;
  int v = cJSON_IsString(item) && item->valuestring ? from_name(item->valuestring) : -1;
  if (v < 0) return rr_json_fail(r, key, "expected %s", expected);
  *out = v;
  return RR_OK;
}
