/* exr.h — internal helpers of the image-file modules (exr.c, png.c)
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

/* Writes nch float channels named names[0..nch-1], interleaved per pixel
 * in `px` (top row first), with string attributes as in ajar_write_exr. */
ajar_status exr_write_channels(const char *path, const float *px, int nch, const char *const *names, uint32_t width,
			       uint32_t height, const char *const *attrs, uint32_t nattrs);

/* The decompress step of OpenEXR Core's decode pipeline for DWAA and DWAB
 * chunks, which Core 3.1 cannot decompress (exr_dwa.c): set it as the
 * pipeline's decompress_fn. It turns dec->packed_buffer into the chunk's
 * uncompressed layout in dec->unpacked_buffer; if dec->decoding_user_data
 * is not NULL it is a char[EXR_DWA_MSG] that gets why a chunk is refused.
 * Returns an exr_result_t. */
#define EXR_DWA_MSG 192
struct _exr_decode_pipeline;
int32_t exr_dwa_decompress(struct _exr_decode_pipeline *dec);
/* DWA's table from stored (nonlinear) half values to linear half values. */
const uint16_t *exr_dwa_to_linear_table(void);

/* Atomic output, shared by the EXR and PNG writers: image_tmp_open creates
 * a new file next to `path` (*tmp_path is malloc'd); image_tmp_finish
 * closes it and, if `status` is AJAR_OK, renames it to `path`, else removes
 * it, frees tmp_path and returns the final status. So a failed write never
 * leaves a partial file, nor replaces an existing one. */
ajar_status image_tmp_open(const char *path, char **tmp_path, int *fd);
ajar_status image_tmp_finish(const char *path, char *tmp_path, int fd, ajar_status status);
/* write() all of `data`, retrying short writes; errors name `path`. */
ajar_status image_write_all(const char *path, int fd, const void *data, size_t size);

#ifdef __cplusplus
}
#endif
#endif
