/* fuzz_common.h — what the libFuzzer harnesses (tests/fuzz/fuzz_*.c)
 * share: a private folder in /dev/shm (else /tmp) where an input is
 * written as the file the library reads, and a silent log. */
#ifndef AJAR_FUZZ_COMMON_H
#define AJAR_FUZZ_COMMON_H
#include <stddef.h>
#include <stdint.h>

/* Creates the folder (once; removed at exit) and returns "folder/name",
 * which stays valid. */
const char *fuzz_path(const char *name);
/* Writes n bytes to fuzz_path(name); returns that path. */
const char *fuzz_write(const char *name, const uint8_t *data, size_t n);
#endif
