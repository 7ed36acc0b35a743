/* Devices and their errors: the one place a failure is recorded. */
#include "core/core.h"

#include <stdio.h>
#include <stdlib.h>

rr_device *rr_device_new(void) {
  rr_device *dev = calloc(1, sizeof(rr_device));
  for (int u = 0; dev && u < SCRATCH_COUNT; u++) atomic_init(&dev->scratch[u].busy, false);
  return dev;
}

void rr_device_release(rr_device *dev) {
  if (dev) rr_scratch_free(dev);
  free(dev);
}

rr_error rr_device_error(const rr_device *dev) { return dev ? dev->error : RR_ERROR_ARGUMENT; }

const char *rr_device_message(const rr_device *dev) { return dev ? dev->message : "no device"; }

rr_error rr_fail(rr_device *dev, rr_error code, const char *fmt, ...) {
  if (dev) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dev->message, sizeof dev->message, fmt, ap);
    va_end(ap);
    dev->error = code;
  }
  return code;
}

rr_error rr_ok(rr_device *dev) {
  if (dev) {
    dev->error = RR_OK;
    dev->message[0] = 0;
  }
  return RR_OK;
}

rr_error rr_device_set_progress(rr_device *dev, rr_progress_fn fn, void *user) {
  if (!dev) return RR_ERROR_ARGUMENT;
  dev->progress = fn, dev->progress_user = user, dev->progress_ms = 0;
  return rr_ok(dev);
}
