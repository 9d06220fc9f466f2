/* fuzz_checkpoint.c — libFuzzer harness: the input is a checkpoint file,
 * read whole (header, ranges, films, CRC) and its options checked
 * (ajar_checkpoint_options). The films' bounds are checked when a renderer
 * resumes one (render_checkpoint_apply), which needs an OpenCL device: that
 * part is tests/render/test_limits.c's. */
#include <stdint.h>

#include "ajar.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
	ajar_options o;
	uint32_t spp = 0;
	ajar_checkpoint_options(fuzz_write("in.ckpt", data, n), &o, &spp);
	return 0;
}
