/* What the fuzz targets share: the input written to a temporary file with a chosen
 * extension (rastray reads scenes and images by path), one device for the run. */
#ifndef RR_FUZZ_UTIL_H
#define RR_FUZZ_UTIL_H
#define _GNU_SOURCE /* mkstemps */
#include "rastray.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Writes data to a new file /tmp/rr_fuzz_XXXXXX.ext; its path in path (cap bytes), false on failure. */
static inline int fuzz_write_file(const uint8_t *data, size_t size, const char *ext, char *path, size_t cap) {
  snprintf(path, cap, "/tmp/rr_fuzz_XXXXXX.%s", ext);
  int fd = mkstemps(path, (int)strlen(ext) + 1);
  if (fd < 0) return 0;
  size_t done = 0;
  while (done < size) {
    ssize_t w = write(fd, data + done, size - done);
    if (w <= 0) break;
    done += (size_t)w;
  }
  close(fd);
  if (done == size) return 1;
  unlink(path);
  return 0;
}

/* The run's device (libFuzzer never returns from its loop, so it is not released). */
static inline rr_device *fuzz_device(void) {
  static rr_device *dev;
  if (!dev) {
    dev = rr_device_new();
    if (!dev) abort();
    /* Files are imported as a user's are: structural checks, then assimp in a child
     * process, whose crashes, hangs and runaway allocations must come back as one-line
     * errors. assimp itself corrupts its heap on some files (a PLY without elements
     * did, caught in process by ASan), which would fail every run that meets one;
     * RR_FUZZ_IN_PROCESS=1 imports in this process instead, where libFuzzer sees
     * assimp's coverage and crashes (for fuzzing the importer by hand). */
    rr_import_limits lim;
    rr_import_limits_init(&lim);
    const char *in_process = getenv("RR_FUZZ_IN_PROCESS");
    lim.in_process = in_process && in_process[0] == '1';
    lim.timeout_s = 10;
    lim.max_memory = 1ull << 30;
    rr_device_set_import_limits(dev, &lim);
  }
  return dev;
}

/* A failed call must leave a one-line message naming something. */
static inline void fuzz_check_message(rr_device *dev) {
  const char *m = rr_device_message(dev);
  if (!m || !m[0] || strchr(m, '\n')) abort();
}

#endif
