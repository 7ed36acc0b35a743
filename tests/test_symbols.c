/* The library's symbols, as nm lists them in librastray.a: every global one starts
 * with rr_ (the public API's prefix, and the internal functions shared between
 * files), and no object lives in writable memory (.data, .bss) but the thread pool's,
 * which is shared on purpose (core/threads.c says how it is kept safe). Writable
 * statics would be global mutable state, which rastray.h promises there is none of. */
#include "testutil.h"

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

int main(void) {
  /* System V format: name|value|class|type|size|line|section, one symbol a line. */
  FILE *nm = popen(RR_NM " --format=sysv --defined-only " RR_LIB " 2>&1", "r");
  CHECK(nm != NULL, "cannot run %s", RR_NM);
  if (!nm) return test_done();
  char line[1024];
  int symbols = 0, globals = 0;
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
    /* upper-case classes are global (U, undefined, is left out by --defined-only) */
    if (*cls >= 'A' && *cls <= 'Z') {
      globals++;
      CHECK(strncmp(name, "rr_", 3) == 0, "global symbol '%s' (class %s) does not start with rr_", name, cls);
    }
    bool writable = strcmp(section, ".data") == 0 || strcmp(section, ".bss") == 0 ||
                    strncmp(section, ".data.", 6) == 0 || strncmp(section, ".bss.", 5) == 0 ||
                    strcmp(section, ".tbss") == 0 || strcmp(section, ".tdata") == 0;
    bool read_only = strncmp(section, ".data.rel.ro", 12) == 0; /* const tables of pointers */
    CHECK(!writable || read_only || allowed_writable(name), "'%s' is writable static data (%s)", name, section);
  }
  int status = pclose(nm);
  CHECK(status == 0, "%s exited with status %d", RR_NM, status);
  CHECK(globals > 0, "nm listed no global symbol in %s", RR_LIB);
  printf("%d symbols, %d global\n", symbols, globals);
  return test_done();
}
