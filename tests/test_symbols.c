/* The library's symbols, as nm lists them in librastray.a: every global one starts
 * with rr_ (the public API's prefix, and the internal functions shared between
 * files), and no object lives in writable memory (.data, .bss) but the thread pool's,
 * which is shared on purpose (core/threads.c says how it is kept safe). Writable
 * statics would be global mutable state, which rastray.h promises there is none of.
 * librastray.so exports exactly the functions rastray.h declares (RR_API), no
 * internal one: its objects are compiled with hidden visibility. */
#include "testutil.h"

#include <ctype.h>
#include <string.h>

/* Writable objects allowed, by name as nm prints it (function-scope statics get a
 * numeric suffix: "buf.1"). */
static const char *const writable_ok[] = {
    "P",           /* core/threads.c: the thread pool */
    "atfork_once", /* core/threads.c: registers the pool's fork handler once */
    /* stb_easy_font.h declares its font tables without const; nothing writes them */
    "stb_easy_font_hseg", "stb_easy_font_vseg", "stb_easy_font_charinfo",
};

/* Names the compiler's instrumentation adds in the sanitizer builds. */
static bool instrumentation(const char *name) {
  return strncmp(name, "__asan", 6) == 0 || strncmp(name, "__ubsan", 7) == 0 || strncmp(name, "__tsan", 6) == 0 ||
         strncmp(name, "__odr_asan", 10) == 0 || strncmp(name, "___asan", 7) == 0 || name[0] == '.';
}

static bool allowed_writable(const char *name) {
  for (size_t i = 0; i < sizeof writable_ok / sizeof *writable_ok; i++)
    if (strcmp(name, writable_ok[i]) == 0) return true;
  return false;
}

/* Trims the spaces around a field of nm's System V format. */
static char *field(char *s) {
  while (*s == ' ') s++;
  for (size_t n = strlen(s); n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\n'); n--) s[n - 1] = 0;
  return s;
}

/* Runs nm (System V format: name|value|class|type|size|line|section, one symbol a
 * line) on the defined symbols of `args` and calls fn on each but the
 * instrumentation's; returns how many, or -1 when nm fails. */
static int for_each_symbol(const char *args, void (*fn)(const char *name, const char *cls, const char *section)) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "%s --format=sysv --defined-only %s 2>&1", RR_NM, args);
  FILE *nm = popen(cmd, "r");
  CHECK(nm != NULL, "cannot run %s", cmd);
  if (!nm) return -1;
  char line[1024];
  int symbols = 0;
  while (fgets(line, sizeof line, nm)) {
    char *f[7];
    int n = 0;
    for (char *p = line; n < 7; n++) {
      f[n] = p;
      char *bar = strchr(p, '|');
      if (!bar) break;
      *bar = 0, p = bar + 1;
    }
    if (n < 6) continue; /* headers and blank lines */
    const char *name = field(f[0]), *cls = field(f[2]), *section = field(f[6]);
    if (!*cls || instrumentation(name)) continue;
    symbols++;
    fn(name, cls, section);
  }
  int status = pclose(nm);
  CHECK(status == 0, "%s exited with status %d", cmd, status);
  return status == 0 ? symbols : -1;
}

static int archive_globals;

static void check_archive_symbol(const char *name, const char *cls, const char *section) {
  /* upper-case classes are global (U, undefined, is left out by --defined-only) */
  if (*cls >= 'A' && *cls <= 'Z') {
    archive_globals++;
    CHECK(strncmp(name, "rr_", 3) == 0, "global symbol '%s' (class %s) does not start with rr_", name, cls);
  }
  bool writable = strcmp(section, ".data") == 0 || strcmp(section, ".bss") == 0 ||
                  strncmp(section, ".data.", 6) == 0 || strncmp(section, ".bss.", 5) == 0 ||
                  strcmp(section, ".tbss") == 0 || strcmp(section, ".tdata") == 0;
  bool read_only = strncmp(section, ".data.rel.ro", 12) == 0; /* const tables of pointers */
  CHECK(!writable || read_only || allowed_writable(name), "'%s' is writable static data (%s)", name, section);
}

/* The functions rastray.h declares: every rr_ name followed by "(" outside comments. */
enum { MAX_API = 256 };
static char api[MAX_API][64];
static int napi;
static bool api_found[MAX_API];

static void read_api(void) {
  FILE *f = fopen(RR_HEADER, "rb");
  CHECK(f != NULL, "cannot open %s", RR_HEADER);
  if (!f) return;
  static char text[1 << 16];
  size_t len = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  CHECK(len < sizeof text - 1, "%s is larger than this test reads", RR_HEADER);
  text[len] = 0;
  for (char *p = text; *p;) {
    if (p[0] == '/' && p[1] == '*') {
      char *end = strstr(p + 2, "*/");
      p = end ? end + 2 : p + strlen(p);
    } else if (p[0] == '/' && p[1] == '/') {
      p += strcspn(p, "\n");
    } else if (strncmp(p, "rr_", 3) == 0 && (p == text || !(p[-1] == '_' || isalnum((unsigned char)p[-1])))) {
      size_t n = 3;
      while (p[n] == '_' || isalnum((unsigned char)p[n])) n++;
      size_t after = n;
      while (p[after] == ' ') after++;
      if (p[after] == '(' && napi < MAX_API && n < sizeof api[0]) memcpy(api[napi++], p, n);
      p += n;
    } else {
      p++;
    }
  }
}

static int shared_exports;

static void check_shared_symbol(const char *name, const char *cls, const char *section) {
  (void)section;
  if (!(*cls >= 'A' && *cls <= 'Z')) return;
  shared_exports++;
  int i = 0;
  while (i < napi && strcmp(api[i], name) != 0) i++;
  CHECK(i < napi, "librastray.so exports '%s' (class %s), which rastray.h does not declare", name, cls);
  if (i < napi) api_found[i] = true;
}

int main(void) {
  int symbols = for_each_symbol(RR_LIB, check_archive_symbol);
  CHECK(archive_globals > 0, "nm listed no global symbol in %s", RR_LIB);
  printf("librastray.a: %d symbols, %d global\n", symbols, archive_globals);

  read_api();
  CHECK(napi > 20, "found only %d function declarations in %s", napi, RR_HEADER);
  for_each_symbol("-D " RR_SHARED_LIB, check_shared_symbol);
  for (int i = 0; i < napi; i++)
    CHECK(api_found[i], "librastray.so does not export %s, which rastray.h declares (RR_API missing?)", api[i]);
  printf("librastray.so: %d exported symbols, rastray.h declares %d functions\n", shared_exports, napi);
  return test_done();
}
