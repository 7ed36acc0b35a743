/* Image files through rr_image_read: the first byte picks the format (PNG, PFM,
 * EXR, NPY), the rest is the file. A read gives an image of the size it says or a
 * one-line message. */
#include "fuzz_util.h"

static const char *const exts[] = {"png", "pfm", "exr", "npy"};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  char path[64];
  if (!fuzz_write_file(data + 1, size - 1, exts[data[0] % (sizeof exts / sizeof *exts)], path, sizeof path)) return 0;
  rr_device *dev = fuzz_device();
  rr_image img = {0};
  if (rr_image_read(dev, path, &img) == RR_OK) {
    if (img.width < 1 || img.height < 1 || img.channels < 1 || !img.data) abort();
    /* every byte of the image must be readable */
    size_t bytes = (size_t)img.width * img.height * img.channels * (img.type == RR_PIXEL_U8 ? 1 : 4);
    uint8_t sum = 0;
    for (size_t i = 0; i < bytes; i++) sum += ((const uint8_t *)img.data)[i];
    if (sum == 0 && bytes == 0) abort(); /* keeps the reads */
    rr_image_free(&img);
  } else {
    fuzz_check_message(dev);
  }
  unlink(path);
  return 0;
}
