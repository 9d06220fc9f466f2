/* exr_huf.c — OpenEXR's Huffman coder, decoding only: the AC values of a
 * DWA chunk (exr_dwa.c) when its header says they are Huffman coded. The
 * stream layout is OpenEXR's (HufCompressor, C++ 3.1); every length and
 * count read from it is checked against the bytes it describes. */
#include "image/exr_huf.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static exr_result_t huf_fail(char *why, exr_result_t rv, const char *fmt, ...)
{
	if (why) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(why, EXR_DWA_MSG, fmt, ap);
		va_end(ap);
	}
	return rv;
}

#define CORRUPT(...) huf_fail(why, EXR_ERR_CORRUPT_CHUNK, __VA_ARGS__)

static uint32_t rd_u32(const uint8_t *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}


/* The section starts with five little-endian u32: the lowest and highest
 * symbol with a code (the highest is the run-length symbol: it is followed
 * by 8 bits, how many more times to repeat the previous value), the table
 * length, the data length in bits, and zero. Then code lengths, 6 bits
 * each, MSB first, where 59..62 are runs of 2..5 zero lengths and 63 is
 * followed by 8 bits of a longer run (6..261); then the canonical code
 * (longer codes are numerically lower) bits, MSB first. */
enum {
	HUF_SYMS = 65537,
	HUF_MAXLEN = 58,
	HUF_FASTBITS = 14,
	HUF_SHORT_RUN = 59,
	HUF_LONG_RUN = 63,
};

typedef struct {
	const uint8_t *data;
	size_t nbytes;
	uint64_t nbits;
} BitReader;

/* The next `n` (1..57) bits from bit `pos`, zero past the end. */
static inline uint64_t bits_peek(const BitReader *br, uint64_t pos, int n)
{
	size_t byte = (size_t)(pos >> 3);
	uint64_t w = 0;
	if (byte + 8 <= br->nbytes) {
		memcpy(&w, br->data + byte, sizeof w);
		w = __builtin_bswap64(w); /* the stream is MSB first */
	} else {
		for (int i = 0; i < 8; i++)
			w = (w << 8) | (byte + i < br->nbytes ? br->data[byte + i] : 0);
	}
	return (w << (pos & 7)) >> (64 - n);
}

typedef struct {
	uint8_t len[HUF_SYMS];
	uint64_t code[HUF_SYMS];
	/* fast[prefix]: a code of at most HUF_FASTBITS bits (its length in
	 * bits 24..29, its symbol in bits 0..16), or (length 0) the head + 1
	 * of a list of longer codes sharing that prefix, 0 for none, linked
	 * through `next`. 4 bytes each, so the table stays in cache. */
	uint32_t fast[1 << HUF_FASTBITS];
	uint32_t next[HUF_SYMS];
} HufTable;

exr_result_t exr_huf_decode(const uint8_t *in, size_t n, uint16_t *out, size_t nout, char *why)
{
	if (n < 20)
		return nout == 0 ? EXR_ERR_SUCCESS : CORRUPT("Huffman section of %zu bytes", n);
	uint32_t im = rd_u32(in), iM = rd_u32(in + 4), nbits = rd_u32(in + 12);
	if (im >= HUF_SYMS || iM >= HUF_SYMS || im > iM)
		return CORRUPT("Huffman symbol range %u..%u", im, iM);
	HufTable *t = calloc(1, sizeof *t);
	if (!t)
		return huf_fail(why, EXR_ERR_OUT_OF_MEMORY, "out of memory for a Huffman table");
	exr_result_t rv = EXR_ERR_SUCCESS;
	BitReader br = {in + 20, n - 20, (uint64_t)(n - 20) * 8};
	uint64_t pos = 0;
	/* Code lengths. */
	for (uint32_t s = im; s <= iM; s++) {
		if (pos + 6 > br.nbits) {
			rv = CORRUPT("Huffman code table cut short");
			goto done;
		}
		uint32_t l = (uint32_t)bits_peek(&br, pos, 6);
		pos += 6;
		uint32_t zeros = 0;
		if (l == HUF_LONG_RUN) {
			if (pos + 8 > br.nbits) {
				rv = CORRUPT("Huffman code table cut short");
				goto done;
			}
			zeros = (uint32_t)bits_peek(&br, pos, 8) + 6;
			pos += 8;
		} else if (l >= HUF_SHORT_RUN) {
			zeros = l - HUF_SHORT_RUN + 2;
		} else {
			t->len[s] = (uint8_t)l;
			continue;
		}
		if ((uint64_t)s + zeros > (uint64_t)iM + 1) {
			rv = CORRUPT("Huffman code table runs past its last symbol");
			goto done;
		}
		s += zeros - 1; /* those lengths stay 0 */
	}
	/* The data starts at the next whole byte. */
	size_t table_bytes = (size_t)((pos + 7) / 8);
	if ((uint64_t)nbits > (uint64_t)(br.nbytes - table_bytes) * 8) {
		rv = CORRUPT("Huffman data of %u bits in %zu bytes", nbits, br.nbytes - table_bytes);
		goto done;
	}
	/* Canonical codes: count per length, then the first code of each
	 * length from the longest up, then assign in symbol order. */
	uint64_t first[HUF_MAXLEN + 1] = {0}, c = 0;
	for (uint32_t s = im; s <= iM; s++)
		first[t->len[s]]++;
	for (int l = HUF_MAXLEN; l > 0; l--) {
		uint64_t nc = (c + first[l]) >> 1;
		first[l] = c;
		c = nc;
	}
	for (uint32_t s = im; s <= iM; s++) {
		int l = t->len[s];
		if (!l)
			continue;
		uint64_t code = first[l]++;
		if (code >> l || l > 57) {
			rv = CORRUPT("Huffman code table is not a prefix code");
			goto done;
		}
		t->code[s] = code;
		if (l <= HUF_FASTBITS) {
			uint32_t lo = (uint32_t)(code << (HUF_FASTBITS - l)), cnt = 1u << (HUF_FASTBITS - l);
			for (uint32_t k = lo; k < lo + cnt; k++) {
				if (t->fast[k]) {
					rv = CORRUPT("Huffman code table is not a prefix code");
					goto done;
				}
				t->fast[k] = (uint32_t)l << 24 | s;
			}
		} else {
			uint32_t k = (uint32_t)(code >> (l - HUF_FASTBITS));
			if (t->fast[k] >> 24) {
				rv = CORRUPT("Huffman code table is not a prefix code");
				goto done;
			}
			t->next[s] = t->fast[k];
			t->fast[k] = s + 1;
		}
	}
	/* Symbols. */
	br.data += table_bytes;
	br.nbytes -= table_bytes;
	br.nbits = nbits;
	size_t o = 0;
	for (pos = 0; pos < br.nbits;) {
		uint32_t k = (uint32_t)bits_peek(&br, pos, HUF_FASTBITS), s;
		int l = (int)(t->fast[k] >> 24);
		if (l) {
			s = t->fast[k] & 0x1ffffu;
		} else {
			for (s = t->fast[k]; s; s = t->next[s - 1]) {
				l = t->len[s - 1];
				if (bits_peek(&br, pos, l) == t->code[s - 1])
					break;
			}
			if (!s) {
				rv = CORRUPT("invalid Huffman code");
				goto done;
			}
			s--;
		}
		if (pos + (uint64_t)l > br.nbits) {
			rv = CORRUPT("Huffman code past the end of its data");
			goto done;
		}
		pos += (uint64_t)l;
		if (s == iM) { /* run: repeat the previous value */
			if (pos + 8 > br.nbits || o == 0) {
				rv = CORRUPT("Huffman run without a value or a count");
				goto done;
			}
			size_t run = (size_t)bits_peek(&br, pos, 8);
			pos += 8;
			if (run > nout - o) {
				rv = CORRUPT("Huffman data decodes to more than %zu values", nout);
				goto done;
			}
			for (uint16_t v = out[o - 1]; run > 0; run--)
				out[o++] = v;
		} else {
			if (o == nout) {
				rv = CORRUPT("Huffman data decodes to more than %zu values", nout);
				goto done;
			}
			out[o++] = (uint16_t)s;
		}
	}
	if (o != nout)
		rv = CORRUPT("Huffman data decodes to %zu values, not %zu", o, nout);
done:
	free(t);
	return rv;
}
