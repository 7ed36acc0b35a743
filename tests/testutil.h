/* A tiny test harness: CHECK counts and reports, test_done prints the summary
 * line and returns the exit code (77 tells ctest the test was skipped). */
#ifndef RR_TESTUTIL_H
#define RR_TESTUTIL_H
#include <stdbool.h>
#include <stdio.h>

extern int test_passed, test_failed;

#define CHECK(cond, ...)                                                   \
  do {                                                                     \
    if (cond) {                                                            \
      test_passed++;                                                       \
    } else {                                                               \
      test_failed++;                                                       \
      fprintf(stderr, "%s:%d: FAILED: %s: ", __FILE__, __LINE__, #cond);   \
      fprintf(stderr, __VA_ARGS__);                                        \
      fputc('\n', stderr);                                                 \
    }                                                                      \
  } while (0)

/* Prints "N passed, N failed" and returns the process exit code. */
int test_done(void);
/* Marks the run skipped (printed by test_done) with a reason. */
void test_skip(const char *why);
/* Path of a shared model, or NULL (and a note) when it is absent. */
const char *test_model(const char *name);
/* True when RR_TEST_QUICK is set (the sanitizer run): property tests then visit
 * fewer views and smaller meshes, the same code paths. */
bool test_quick(void);
struct rr_frame;
/* Samples where two visibility buffers differ in any byte of id, t, λ1 or λ2. */
int test_frames_differ(const struct rr_frame *a, const struct rr_frame *b);
/* Deterministic random numbers for property tests. */
unsigned test_rand(void);
float test_randf(float lo, float hi);
#endif
