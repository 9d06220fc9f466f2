/* fuzz_hdr.c — libFuzzer harness: the input is a Radiance .hdr sky read
 * by hdr_read (our header checks, then stb_image). */
#include <stdint.h>
#include <stdlib.h>

#include "fuzz_common.h"
#include "image/hdr.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
	float *rgb = NULL;
	uint32_t w, h;
	if (hdr_read(fuzz_write("in.hdr", data, n), &rgb, &w, &h) == AJAR_OK)
		free(rgb);
	return 0;
}
