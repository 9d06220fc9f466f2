/* fuzz_exr.c — libFuzzer harness: the input is an OpenEXR file read by
 * ajar_read_exr (OpenEXR Core for the header and our limits, the C++
 * library for the pixels: every compression, DWAA and DWAB included). */
#include <stdint.h>
#include <stdlib.h>

#include "ajar.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
	float *px = NULL;
	uint32_t w, h;
	if (ajar_read_exr(fuzz_write("in.exr", data, n), &px, &w, &h) == AJAR_OK)
		free(px);
	return 0;
}
