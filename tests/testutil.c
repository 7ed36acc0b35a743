#include "testutil.h"

#include "rr.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int test_passed, test_failed;
static int skipped;

int test_done(void) {
  if (skipped && test_passed == 0 && test_failed == 0) {
    printf("0 passed, 0 failed, 1 skipped\n");
    return 77;
  }
  printf("%d passed, %d failed\n", test_passed, test_failed);
  return test_failed ? 1 : 0;
}

void test_skip(const char *why) {
  fprintf(stderr, "skipped: %s\n", why);
  skipped = 1;
}

const char *test_model(const char *name) {
  static char path[4][1024];
  static int slot;
  char *p = path[slot++ & 3];
  snprintf(p, sizeof path[0], "%s/%s", RR_MODELS_DIR, name);
  if (access(p, R_OK) != 0) {
    fprintf(stderr, "note: %s absent, its checks are skipped\n", p);
    skipped = 1;
    return NULL;
  }
  return p;
}

bool test_quick(void) {
  const char *q = getenv("RR_TEST_QUICK");
  return q && *q && strcmp(q, "0") != 0;
}

static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
unsigned test_rand(void) {
  rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
  return (unsigned)(rng_state >> 33);
}
float test_randf(float lo, float hi) { return lo + (hi - lo) * (test_rand() / 2147483648.0f); }

int test_frames_differ(const rr_frame *a, const rr_frame *b) {
  size_t n = (size_t)a->vb.width * a->vb.height;
  int d = 0;
  for (size_t k = 0; k < n; k++)
    d += a->vb.id[k] != b->vb.id[k] || memcmp(&a->vb.t[k], &b->vb.t[k], 4) || memcmp(&a->vb.l1[k], &b->vb.l1[k], 4) ||
         memcmp(&a->vb.l2[k], &b->vb.l2[k], 4);
  return d;
}
