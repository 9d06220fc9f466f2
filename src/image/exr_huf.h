/* exr_huf.h — OpenEXR's Huffman decoder (exr_huf.c), used by exr_dwa.c. */
#ifndef AJAR_EXR_HUF_H
#define AJAR_EXR_HUF_H

#include <openexr.h>
#include <stddef.h>
#include <stdint.h>

#include "image/exr.h"

/* Decodes the `n`-byte Huffman section `in` into exactly `nout` 16-bit
 * values. On failure returns EXR_ERR_CORRUPT_CHUNK or EXR_ERR_OUT_OF_MEMORY
 * and, if `why` is not NULL, writes the reason into it (EXR_DWA_MSG bytes). */
exr_result_t exr_huf_decode(const uint8_t *in, size_t n, uint16_t *out, size_t nout, char *why);

#endif
