/* input_file.h — opening a file the library reads (a scene, its buffers
 * and images, a sky, a checkpoint): regular files only (input_file.c). */
#ifndef AJAR_INPUT_FILE_H
#define AJAR_INPUT_FILE_H
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Opens `path` read-only into *fd and gives its size. Anything but a
 * regular file is refused before it is opened: a FIFO blocks its reader,
 * a device can be endless or have side effects. AJAR_ERROR_IO when it is
 * missing, unreadable or a directory; AJAR_ERROR_BAD_INPUT for a FIFO,
 * device or socket. Messages name `path`. */
ajar_status input_open(const char *path, int *fd, uint64_t *size);

/* Whether `path` names a regular file (after symbolic links), without
 * opening it. */
int input_is_regular(const char *path);

#ifdef __cplusplus
}
#endif
#endif
