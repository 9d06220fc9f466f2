/* texture_file.h — a scene's texture images (PNG and JPEG, glTF's
 * formats) decoded by stb_image with limits (texture_file.c). */
#ifndef AJAR_TEXTURE_FILE_H
#define AJAR_TEXTURE_FILE_H
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The largest texture side: what GPUs sample, 1 GiB of RGBA8. */
#define TEXTURE_MAX_SIDE 16384

/* The n bytes of a PNG or JPEG file as RGBA, 8 or 16 bits a channel (`bits`)
 * as the file has them; *pixels is malloc'ed. The declared size is
 * checked before anything is allocated for it (at most TEXTURE_MAX_SIDE a
 * side, and, for JPEG, a file long enough to code every block), and a
 * decode that reads past the end is refused. Returns 0 and says why in
 * `why` on failure. Free the pixels with texture_free. */
int texture_decode(const unsigned char *bytes, size_t n, unsigned char **pixels, int *width, int *height, int *bits,
		   char *why, size_t cap);
void texture_free(unsigned char *pixels);

#ifdef __cplusplus
}
#endif
#endif
