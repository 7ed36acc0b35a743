/* Guarded import: structural checks before assimp, and assimp in a child process
 * under a time and memory limit (import_check.c, import_guard.c). */
#ifndef RR_IMPORT_GUARD_H
#define RR_IMPORT_GUARD_H

#include "io/io.h"

/* Checks the declared counts and lengths of a PLY, OFF, binary STL or GLB file
 * against its size; false (and the cause in why, one line without the path) when
 * the file cannot be valid. Files of other formats, and files it cannot open, pass. */
bool rr_import_check(const char *path, char *why, size_t cap);

/* Test hooks for the guard's child (the device's; tests only). */
typedef enum import_test_hook {
  IMPORT_HOOK_NONE = 0,
  IMPORT_HOOK_CRASH,   /* the child dies of SIGSEGV before importing */
  IMPORT_HOOK_NO_CHECK /* the structural checks are skipped, so the limits meet the file */
} import_test_hook;
void rr_device_set_import_test_hook(rr_device *dev, import_test_hook hook);

#endif
