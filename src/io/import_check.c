/* Structural checks before assimp: the formats that declare counts and lengths
 * (PLY, OFF, binary STL, GLB, glTF buffers) are held against the file's size, so
 * that a few hundred bytes declaring 10^8 vertices or a 4 GB chunk are refused in
 * microseconds instead of making the importer allocate gigabytes (or loop) first.
 * The checks only refuse what cannot be a valid file; anything they do not
 * understand goes on to assimp (which then runs under the guard's limits). They
 * read the file through a read-only mapping and allocate nothing. */
#define _DEFAULT_SOURCE /* MAP_PRIVATE and friends under -std=c11 */
#include "io/import_guard.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct span {
  const unsigned char *p;
  size_t n;
} span;

static bool refuse(char *why, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static bool refuse(char *why, size_t cap, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(why, cap, fmt, ap);
  va_end(ap);
  return false;
}

static bool has_prefix(span f, const char *s) {
  size_t n = strlen(s);
  return f.n >= n && memcmp(f.p, s, n) == 0;
}

static uint32_t le32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* ---- PLY ------------------------------------------------------------------------ */

enum { PLY_MAX_ELEMENTS = 64, PLY_MAX_PROPS = 256 };
typedef struct ply_prop {
  uint8_t size;       /* a scalar's bytes, or a list's items' */
  uint8_t count_size; /* a list's count's bytes; 0 for a scalar */
  bool count_signed;
} ply_prop;
typedef struct ply_element {
  char name[32];
  unsigned long long count;
  ply_prop props[PLY_MAX_PROPS];
  int nprops;
} ply_element;

/* The bytes of a PLY scalar type, 0 when unknown (signedness in *sign). */
static int ply_type_size(const char *t, bool *sign) {
  static const struct {
    const char *name;
    int size;
    bool sign;
  } types[] = {{"char", 1, 1},   {"int8", 1, 1},   {"uchar", 1, 0},  {"uint8", 1, 0},   {"short", 2, 1},
               {"int16", 2, 1},  {"ushort", 2, 0}, {"uint16", 2, 0}, {"int", 4, 1},     {"int32", 4, 1},
               {"uint", 4, 0},   {"uint32", 4, 0}, {"float", 4, 1},  {"float32", 4, 1}, {"double", 8, 1},
               {"float64", 8, 1}};
  for (size_t i = 0; i < sizeof types / sizeof *types; i++)
    if (strcmp(t, types[i].name) == 0) return *sign = types[i].sign, types[i].size;
  return 0;
}

/* A binary list count at p (size bytes, big or little endian); -1 for a negative one. */
static long long ply_count(const unsigned char *p, int size, bool sign, bool big) {
  uint64_t v = 0;
  for (int i = 0; i < size; i++) v |= (uint64_t)p[big ? i : size - 1 - i] << 8 * (size - 1 - i);
  if (sign && v >> (8 * size - 1)) return -1;
  return (long long)v;
}

/* Walks a binary body record by record: each list's count must fit in what remains. */
static bool ply_walk_binary(span body, const ply_element *el, int nel, bool big, char *why,
                            size_t cap) {
  size_t pos = 0;
  for (int e = 0; e < nel; e++) {
    size_t fixed = 0; /* a record's bytes */
    bool lists = false;
    for (int k = 0; k < el[e].nprops; k++) fixed += el[e].props[k].size, lists |= el[e].props[k].count_size != 0;
    if (!lists) { /* the size check bounded count × fixed by the file's size */
      if (el[e].count * fixed > body.n - pos) return true;
      pos += el[e].count * fixed;
      continue;
    }
    for (unsigned long long r = 0; r < el[e].count; r++)
      for (int k = 0; k < el[e].nprops; k++) {
        const ply_prop *pr = &el[e].props[k];
        size_t need = pr->count_size ? pr->count_size : pr->size;
        if (body.n - pos < need) return true; /* short: the size check above judged it */
        if (!pr->count_size) {
          pos += need;
          continue;
        }
        long long c = ply_count(body.p + pos, pr->count_size, pr->count_signed, big);
        pos += need;
        if (c < 0 || (unsigned long long)c > (body.n - pos) / pr->size)
          return refuse(why, cap, "PLY %s %llu declares a list of %lld items, more than the %zu bytes left can hold", el[e].name, r, c, body.n - pos);
        pos += (size_t)c * pr->size;
      }
  }
  return true;
}

/* The next whitespace-separated token of an ASCII body from *pos; false at the end. */
static bool next_token(span body, size_t *pos, size_t *start, size_t *len) {
  size_t i = *pos;
  while (i < body.n && isspace(body.p[i])) i++;
  if (i == body.n) return false;
  *start = i;
  while (i < body.n && !isspace(body.p[i])) i++;
  *len = i - *start, *pos = i;
  return true;
}

/* Walks an ASCII body token by token: each list's count must be one that the bytes
 * left could hold (an item takes at least two bytes, a digit and a separator). */
static bool ply_walk_ascii(span body, const ply_element *el, int nel, char *why, size_t cap) {
  size_t pos = 0, start, len;
  for (int e = 0; e < nel; e++)
    for (unsigned long long r = 0; r < el[e].count; r++)
      for (int k = 0; k < el[e].nprops; k++) {
        if (!next_token(body, &pos, &start, &len)) return true;
        if (!el[e].props[k].count_size) continue;
        char num[32];
        if (len >= sizeof num) len = sizeof num - 1;
        memcpy(num, body.p + start, len);
        num[len] = 0;
        char *end;
        double c = strtod(num, &end);
        if (*end || !(c >= 0) || c > (double)(body.n - pos) / 2)
          return refuse(why, cap, "PLY %s %llu declares a list of %s items, more than the %zu bytes left can hold", el[e].name, r, num, body.n - pos);
        for (long long i = 0; i < (long long)c; i++)
          if (!next_token(body, &pos, &start, &len)) return true;
      }
  return true;
}

static bool check_ply(span f, char *why, size_t cap) {
  /* the header: lines up to end_header */
  static const char end_mark[] = "end_header";
  size_t pos = 0, body_at = 0;
  int format = -1; /* 0 ascii, 1 little endian, 2 big endian */
  ply_element *el = calloc(PLY_MAX_ELEMENTS, sizeof *el);
  if (!el) return true; /* no room to check: assimp (under its limits) decides */
  int nel = 0;
  bool ok = true;
  while (pos < f.n && !body_at && ok) {
    const unsigned char *nl = memchr(f.p + pos, '\n', f.n - pos);
    size_t end = nl ? (size_t)(nl - f.p) : f.n;
    char line[512];
    size_t len = end - pos < sizeof line - 1 ? end - pos : sizeof line - 1;
    memcpy(line, f.p + pos, len);
    line[len] = 0;
    if (memchr(f.p + pos, 0, end - pos)) { /* the lines read here and the importer's would differ */
      ok = refuse(why, cap, "a NUL byte in the PLY header");
      break;
    }
    pos = nl ? end + 1 : f.n;
    char a[64] = "", b[64] = "", c[64] = "", d[64] = "", g[64] = "";
    int n = sscanf(line, "%63s %63s %63s %63s %63s", a, b, c, d, g);
    if (n <= 0) continue;
    if (strcmp(a, end_mark) == 0) {
      if (!nl) break; /* end_header with no line end: the body would start past the file */
      body_at = pos;
    } else if (strcmp(a, "format") == 0) {
      if (format != -1) {
        ok = refuse(why, cap, "two format lines in the PLY header");
        break;
      }
      format = !strcmp(b, "ascii") ? 0 : !strcmp(b, "binary_little_endian") ? 1 : !strcmp(b, "binary_big_endian") ? 2 : -2;
      if (format == -2) ok = refuse(why, cap, "unknown PLY format '%s'", b);
    } else if (strcmp(a, "element") == 0) {
      char *endp;
      errno = 0;
      unsigned long long count = strtoull(c, &endp, 10);
      if (n < 3 || *endp || c[0] == '-' || errno)
        ok = refuse(why, cap, "bad PLY count '%s' for element '%s'", c, b);
      else if (nel == PLY_MAX_ELEMENTS)
        ok = refuse(why, cap, "a PLY header of more than %d elements", PLY_MAX_ELEMENTS);
      else {
        snprintf(el[nel].name, sizeof el[nel].name, "%s", b);
        el[nel++].count = count;
      }
    } else if (strcmp(a, "property") == 0) {
      ply_element *e = nel ? &el[nel - 1] : NULL;
      bool list = strcmp(b, "list") == 0, sign = false, isign = false;
      int size = list ? ply_type_size(d, &isign) : ply_type_size(b, &sign);
      int csize = list ? ply_type_size(c, &sign) : 0;
      if (!e) ok = refuse(why, cap, "a PLY property before any element");
      else if (!size || (list && (!csize || n < 5)) || (!list && n < 3))
        ok = refuse(why, cap, "bad PLY property line '%s'", line);
      else if (e->nprops == PLY_MAX_PROPS)
        ok = refuse(why, cap, "PLY element '%s' has more than %d properties", e->name, PLY_MAX_PROPS);
      else
        e->props[e->nprops++] = (ply_prop){(uint8_t)size, (uint8_t)csize, sign};
    }
  }
  if (ok && !body_at) ok = refuse(why, cap, "truncated PLY header (no end_header line)");
  if (ok && format < 0) ok = refuse(why, cap, "no format line in the PLY header");
  bool vertices = false; /* without them the file holds nothing to load, and assimp has corrupted its heap on such files */
  for (int e = 0; e < nel; e++) vertices |= strcmp(el[e].name, "vertex") == 0;
  if (ok && !vertices) ok = refuse(why, cap, "no vertex element in the PLY header");
  /* the least each element's records take: binary, the scalars' bytes and the lists'
   * counts; ASCII, two bytes (a digit and a separator) per value */
  span body = {f.p + body_at, f.n - body_at};
  unsigned long long least = 0;
  for (int e = 0; ok && e < nel; e++) {
    unsigned long long rec = 0;
    for (int k = 0; k < el[e].nprops; k++)
      rec += format ? (el[e].props[k].count_size ? el[e].props[k].count_size : el[e].props[k].size) : 2;
    if (!rec) rec = 1; /* an element without properties still cannot be counted past the file's bytes */
    if (el[e].count > (unsigned long long)f.n / rec || least + el[e].count * rec > body.n)
      ok = refuse(why, cap, "PLY element '%s' declares %llu records (at least %.4g bytes) but %zu bytes follow the header",
                  el[e].name, el[e].count, (double)el[e].count * (double)rec, body.n);
    else least += el[e].count * rec;
  }
  if (ok) ok = format ? ply_walk_binary(body, el, nel, format == 2, why, cap) : ply_walk_ascii(body, el, nel, why, cap);
  free(el);
  return ok;
}

/* ---- OFF ------------------------------------------------------------------------ */

/* The next token of an OFF file, '#' comments skipped; false at the end. */
static bool off_token(span f, size_t *pos, char *tok, size_t cap) {
  size_t i = *pos;
  for (;;) {
    while (i < f.n && isspace(f.p[i])) i++;
    if (i < f.n && f.p[i] == '#') {
      while (i < f.n && f.p[i] != '\n') i++;
      continue;
    }
    break;
  }
  if (i == f.n) return false;
  size_t n = 0;
  while (i < f.n && !isspace(f.p[i]) && f.p[i] != '#') {
    if (n + 1 < cap) tok[n++] = (char)f.p[i];
    i++;
  }
  tok[n] = 0, *pos = i;
  return true;
}

static bool check_off(span f, char *why, size_t cap) {
  size_t pos = 0;
  char tok[64];
  if (!off_token(f, &pos, tok, sizeof tok)) return true;
  size_t len = strlen(tok);
  if (len >= 3 && strcmp(tok + len - 3, "OFF") == 0) {
    if (tok[0] == 'n') return true; /* nOFF: a dimension comes first; left to assimp */
    if (!off_token(f, &pos, tok, sizeof tok)) return true;
  }
  unsigned long long counts[2];
  for (int i = 0; i < 2; i++) {
    if (i && !off_token(f, &pos, tok, sizeof tok)) return true;
    char *end;
    errno = 0;
    counts[i] = strtoull(tok, &end, 10);
    if (*end || tok[0] == '-' || errno)
      return refuse(why, cap, "bad OFF %s count '%s'", i ? "face" : "vertex", tok);
  }
  /* a vertex is at least three numbers of two bytes (a digit and a separator), a face
   * at least its count */
  size_t left = f.n - pos;
  if (counts[0] > left / 6 || counts[1] > left / 2 || counts[0] * 6 + counts[1] * 2 > left)
    return refuse(why, cap, "OFF header declares %llu vertices and %llu faces but only %zu bytes follow",
                  counts[0], counts[1], left);
  return true;
}

/* ---- STL, GLB, glTF --------------------------------------------------------------- */

static bool check_stl(span f, char *why, size_t cap) {
  if (f.n < 84) return true; /* assimp says what is wrong with it */
  uint64_t n = le32(f.p + 80), need = 84 + 50 * n;
  /* an ASCII file starts with "solid"; so do some binary ones, whose size then matches */
  if (has_prefix(f, "solid") && need != f.n) return true;
  if (need > f.n)
    return refuse(why, cap, "binary STL declares %llu triangles (%llu bytes) but the file has %zu",
                  (unsigned long long)n, (unsigned long long)need, f.n);
  return true;
}

static bool check_gltf_json(const char *path, span text, uint64_t bin, char *why, size_t cap);

static bool check_glb(const char *path, span f, char *why, size_t cap) {
  if (f.n < 20) return refuse(why, cap, "GLB of %zu bytes, shorter than its header", f.n);
  uint32_t version = le32(f.p + 4), length = le32(f.p + 8);
  if (length > f.n)
    return refuse(why, cap, "GLB header declares %u bytes but the file has %zu", length, f.n);
  if (version == 1) { /* glTF 1.0's binary extension: one JSON content after a 20-byte header */
    uint32_t content = le32(f.p + 12);
    if (content > f.n - 20)
      return refuse(why, cap, "GLB JSON content of %u bytes but %zu follow the header", content, f.n - 20);
    return true;
  }
  size_t pos = 12;
  span text = {NULL, 0};
  uint64_t bin = 0;
  for (int k = 0; pos + 8 <= f.n; k++) {
    uint32_t clen = le32(f.p + pos);
    pos += 8;
    if (clen > f.n - pos)
      return refuse(why, cap, "GLB chunk %d declares %u bytes but %zu remain", k, clen, f.n - pos);
    if (k == 0 && !memcmp(f.p + pos - 4, "JSON", 4)) text = (span){f.p + pos, clen};
    if (k == 1 && !memcmp(f.p + pos - 4, "BIN", 4)) bin = clen;
    pos += clen;
  }
  return !text.p || check_gltf_json(path, text, bin, why, cap);
}

/* glTF's buffers: each byteLength must fit in the data it names: a data: URI's
 * decoded bytes, a file beside the glTF, or (no uri, in a GLB) the BIN chunk. A
 * small JSON walker finds "buffers" at the top level; anything it does not
 * understand passes to assimp, which runs under the guard's limits. */

typedef struct json {
  const unsigned char *p, *end;
  int depth;
  bool bad;
} json;

static void json_ws(json *j) {
  while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r')) j->p++;
}

static bool json_eat(json *j, char c) {
  json_ws(j);
  if (j->p < j->end && *j->p == (unsigned char)c) return j->p++, true;
  return false;
}

/* A string's raw bytes (escapes left as they are) in *s, *n. */
static bool json_string(json *j, const unsigned char **s, size_t *n) {
  if (!json_eat(j, '"')) return j->bad = true, false;
  const unsigned char *start = j->p;
  while (j->p < j->end && *j->p != '"') j->p += *j->p == '\\' ? 2 : 1;
  if (j->p >= j->end) return j->bad = true, false;
  *s = start, *n = (size_t)(j->p - start);
  j->p++;
  return true;
}

static void json_skip(json *j);

/* Calls member(j, key, key_len, user) for each member of an object; the callback
 * reads (or skips) the value. */
static void json_object(json *j, void (*member)(json *, const unsigned char *, size_t, void *), void *user) {
  if (!json_eat(j, '{')) return (void)(j->bad = true);
  if (json_eat(j, '}')) return;
  do {
    const unsigned char *k;
    size_t n;
    if (!json_string(j, &k, &n) || !json_eat(j, ':')) return (void)(j->bad = true);
    member(j, k, n, user);
  } while (!j->bad && json_eat(j, ','));
  if (!json_eat(j, '}')) j->bad = true;
}

static void skip_member(json *j, const unsigned char *k, size_t n, void *user) {
  (void)k, (void)n, (void)user;
  json_skip(j);
}

static void json_skip(json *j) {
  json_ws(j);
  if (j->p >= j->end || ++j->depth > 256) return (void)(j->bad = true);
  if (*j->p == '{') json_object(j, skip_member, NULL);
  else if (*j->p == '[') {
    j->p++;
    if (!json_eat(j, ']')) {
      do json_skip(j);
      while (!j->bad && json_eat(j, ','));
      if (!json_eat(j, ']')) j->bad = true;
    }
  } else if (*j->p == '"') {
    const unsigned char *s;
    size_t n;
    json_string(j, &s, &n);
  } else {
    while (j->p < j->end && (isalnum(*j->p) || *j->p == '-' || *j->p == '+' || *j->p == '.')) j->p++;
  }
  j->depth--;
}

typedef struct gltf_buffer {
  double byte_length; /* -1: none given */
  const unsigned char *uri;
  size_t uri_len;
} gltf_buffer;

static void buffer_member(json *j, const unsigned char *k, size_t n, void *user) {
  gltf_buffer *b = user;
  json_ws(j);
  if (n == 10 && !memcmp(k, "byteLength", 10) && j->p < j->end && (isdigit(*j->p) || *j->p == '-')) {
    char num[64];
    size_t len = 0;
    while (j->p < j->end && len + 1 < sizeof num && (isalnum(*j->p) || *j->p == '-' || *j->p == '+' || *j->p == '.'))
      num[len++] = (char)*j->p++;
    num[len] = 0;
    b->byte_length = strtod(num, NULL);
  } else if (n == 3 && !memcmp(k, "uri", 3) && j->p < j->end && *j->p == '"') {
    json_string(j, &b->uri, &b->uri_len);
  } else {
    json_skip(j);
  }
}

typedef struct gltf_check {
  const char *path;   /* the glTF's own path: files are found beside it */
  uint64_t bin;       /* the GLB's BIN chunk bytes (UINT64_MAX: not a GLB) */
  char *why;
  size_t cap;
  bool refused;
} gltf_check;

/* The bytes a buffer's data holds; UINT64_MAX when unknown (the check passes). */
static uint64_t buffer_bytes(const gltf_check *c, const gltf_buffer *b) {
  if (!b->uri) return c->bin;
  static const char b64[] = ";base64,";
  if (b->uri_len >= 5 && !memcmp(b->uri, "data:", 5)) {
    for (size_t i = 5; i + sizeof b64 - 1 <= b->uri_len; i++)
      if (!memcmp(b->uri + i, b64, sizeof b64 - 1)) {
        const unsigned char *data = b->uri + i + sizeof b64 - 1;
        size_t n = b->uri_len - i - (sizeof b64 - 1);
        while (n && data[n - 1] == '=') n--;
        return (uint64_t)n * 3 / 4;
      }
    return UINT64_MAX;
  }
  /* a file beside the glTF: its name percent-decoded, escapes and odd names left alone */
  char file[1024];
  const char *slash = strrchr(c->path, '/');
  size_t dir = slash ? (size_t)(slash - c->path) + 1 : 0, n = dir;
  if (dir >= sizeof file) return UINT64_MAX;
  memcpy(file, c->path, dir);
  for (size_t i = 0; i < b->uri_len; i++) {
    unsigned ch = b->uri[i];
    if (ch == '\\' || ch == 0) return UINT64_MAX;
    if (ch == '%' && i + 2 < b->uri_len && isxdigit(b->uri[i + 1]) && isxdigit(b->uri[i + 2])) {
      char hex[3] = {(char)b->uri[i + 1], (char)b->uri[i + 2], 0};
      ch = (unsigned)strtoul(hex, NULL, 16), i += 2;
    }
    if (n + 1 >= sizeof file) return UINT64_MAX;
    file[n++] = (char)ch;
  }
  file[n] = 0;
  struct stat st;
  if (b->uri_len == 0 || stat(file, &st) != 0 || !S_ISREG(st.st_mode)) return UINT64_MAX;
  return (uint64_t)st.st_size;
}

static void buffers_member(json *j, const unsigned char *k, size_t n, void *user) {
  gltf_check *c = user;
  json_ws(j);
  if (!(n == 7 && !memcmp(k, "buffers", 7) && j->p < j->end && *j->p == '[')) return json_skip(j);
  j->p++;
  if (json_eat(j, ']')) return;
  int index = 0;
  do {
    json_ws(j);
    if (j->p >= j->end || *j->p != '{') {
      json_skip(j);
      continue;
    }
    gltf_buffer b = {-1, NULL, 0};
    json_object(j, buffer_member, &b);
    uint64_t have = j->bad || b.byte_length < 0 ? UINT64_MAX : buffer_bytes(c, &b);
    if (!c->refused && have != UINT64_MAX && b.byte_length > (double)have) {
      c->refused = true;
      refuse(c->why, c->cap, "glTF buffer %d declares %.0f bytes but its %s holds %llu", index, b.byte_length,
             !b.uri ? "BIN chunk" : b.uri_len >= 5 && !memcmp(b.uri, "data:", 5) ? "data URI" : "file",
             (unsigned long long)have);
    }
    index++;
  } while (!j->bad && json_eat(j, ','));
  if (!json_eat(j, ']')) j->bad = true;
}

static bool check_gltf_json(const char *path, span text, uint64_t bin, char *why, size_t cap) {
  json j = {text.p, text.p + text.n, 0, false};
  gltf_check c = {path, bin, why, cap, false};
  json_ws(&j);
  if (j.p < j.end && *j.p == '{') json_object(&j, buffers_member, &c);
  return !c.refused;
}

/* ---- dispatch ---------------------------------------------------------------------- */

static bool ext_is(const char *path, const char *ext) {
  const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
  return dot && (!slash || dot > slash) && strcasecmp(dot + 1, ext) == 0;
}

bool rr_import_check(const char *path, char *why, size_t cap) {
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return true; /* the loader reports it */
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0 || (uint64_t)st.st_size > SIZE_MAX) {
    close(fd);
    return true;
  }
  span f = {NULL, (size_t)st.st_size};
  void *m = mmap(NULL, f.n, PROT_READ, MAP_PRIVATE, fd, 0);
  close(fd);
  if (m == MAP_FAILED) return true;
  f.p = m;
  bool ok = true;
  /* assimp takes any file starting with "ply" (or "PLY") for one */
  if (has_prefix(f, "ply") || has_prefix(f, "PLY")) ok = check_ply(f, why, cap);
  else if (has_prefix(f, "glTF")) ok = check_glb(path, f, why, cap);
  else if (ext_is(path, "stl")) ok = check_stl(f, why, cap);
  else if (ext_is(path, "off")) ok = check_off(f, why, cap);
  else if (ext_is(path, "gltf")) ok = check_gltf_json(path, f, UINT64_MAX, why, cap);
  munmap(m, f.n);
  return ok;
}
