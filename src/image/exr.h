/* exr.h — internal helpers of the image-file modules (exr.c, exr_read.cpp, png.c)
 * beyond the public ajar_write_exr / ajar_read_exr / ajar_write_png. */
#ifndef AJAR_EXR_H
#define AJAR_EXR_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Copies the string attribute `name` of the first part of `path` into
 * `value` (NUL-terminated, at most cap - 1 bytes). A missing attribute or
 * one of another type is AJAR_ERROR_BAD_INPUT; a value longer than the
 * buffer is AJAR_ERROR_INVALID_ARGUMENT. */
ajar_status exr_read_attr(const char *path, const char *name, char *value, size_t cap);
/* The size of part 0 from the header alone, after the checks
 * ajar_read_exr makes before it allocates: errors as it gives them. */
ajar_status exr_read_size(const char *path, uint32_t *width, uint32_t *height);

/* Writes nch float channels named names[0..nch-1], interleaved per pixel
 * in `px` (top row first), with string attributes as in ajar_write_exr. */
ajar_status exr_write_channels(const char *path, const float *px, int nch, const char *const *names, uint32_t width,
			       uint32_t height, const char *const *attrs, uint32_t nattrs);

/* Decodes the pixels of part 0 of the OpenEXR file open on `fd` with
 * OpenEXR's C++ library (exr_read.cpp) into `rgba`, width x height float
 * RGBA, top row first: channel[k] names the file's channel for R, G, B, A,
 * or is NULL to leave that component as it is. The caller checked the
 * header (sizes, channels); the file's data window must be width x height.
 * Errors name `path`: bad input for a corrupt or truncated file, I/O for a
 * failed read. */
ajar_status exr_decode_rgba(const char *path, int fd, const char *const channel[4], float *rgba, uint32_t width,
			    uint32_t height);

/* Atomic output, shared by the EXR and PNG writers: image_tmp_open creates
 * a new file next to `path` (*tmp_path is malloc'd); image_tmp_finish
 * closes it and, if `status` is AJAR_OK, renames it to `path`, else removes
 * it, frees tmp_path and returns the final status. So a failed write never
 * leaves a partial file, nor replaces an existing one. A `path` that is
 * anything but a regular file (a device, FIFO, symbolic link, directory)
 * is refused (I/O error): the rename would replace it. */
ajar_status image_tmp_open(const char *path, char **tmp_path, int *fd);
ajar_status image_tmp_finish(const char *path, char *tmp_path, int fd, ajar_status status);
/* write() all of `data`, retrying short writes; errors name `path`. */
ajar_status image_write_all(const char *path, int fd, const void *data, size_t size);

#ifdef __cplusplus
}
#endif
#endif
