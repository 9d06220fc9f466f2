/* hdr.h — reading Radiance RGBE (.hdr) images (hdr.c). */
#ifndef AJAR_HDR_H
#define AJAR_HDR_H
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if `path` opens and starts with a Radiance header ("#?RADIANCE" or
 * "#?RGBE"), else 0 (a file that cannot be opened is left to the caller's
 * other reader to report). */
int hdr_file(const char *path);
/* Linear RGB, 3 floats per pixel, row 0 at the top; *rgb is malloc'ed.
 * I/O errors and undecodable files name `path`. */
ajar_status hdr_read(const char *path, float **rgb, uint32_t *width, uint32_t *height);

#ifdef __cplusplus
}
#endif
#endif
