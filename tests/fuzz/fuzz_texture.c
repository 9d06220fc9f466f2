/* fuzz_texture.c — libFuzzer harness: the input is a texture image (PNG,
 * JPEG, anything stb_image reads) decoded by texture_decode, as the glTF
 * loader decodes every image a scene names. */
#include <stdint.h>

#include "image/texture_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
	unsigned char *px = NULL;
	int w, h, bits;
	char why[256];
	if (texture_decode(data, n, &px, &w, &h, &bits, why, sizeof why))
		texture_free(px);
	return 0;
}
