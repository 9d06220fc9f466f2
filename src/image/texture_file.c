/* texture_file.c — texture images through stb_image, with the checks it
 * lacks (texture_file.h). stb decodes from the size a header declares and
 * reads past the end of the data as zeros: a 688-byte JPEG declaring
 * 20000 x 20000 texels made it allocate 4.7 GB and gave a garbage texture.
 * Here the declared size is checked first, and the decode goes through a
 * reader that notices a read past the end. Otherwise it decodes exactly as
 * tinygltf's own loader did (RGBA, 16 bits where the file has them), so
 * textures are the same bits. */
#include "image/texture_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

typedef struct {
	const unsigned char *p;
	size_t n, pos;
	int short_reads;
} Bytes;

static int cb_read(void *user, char *data, int size)
{
	Bytes *b = user;
	size_t k = b->n - b->pos < (size_t)size ? b->n - b->pos : (size_t)size;
	if (k == 0 && size > 0)
		b->short_reads++;
	memcpy(data, b->p + b->pos, k);
	b->pos += k;
	return (int)k;
}

static void cb_skip(void *user, int n)
{
	Bytes *b = user;
	if (n < 0)
		b->pos = (size_t)-(long)n > b->pos ? 0 : b->pos - (size_t)-(long)n;
	else if ((size_t)n > b->n - b->pos)
		b->pos = b->n, b->short_reads++;
	else
		b->pos += (size_t)n;
}

static int cb_eof(void *user)
{
	const Bytes *b = user;
	return b->pos >= b->n;
}

static const stbi_io_callbacks callbacks = {cb_read, cb_skip, cb_eof};

/* A JPEG's markers, checked before stb_image reads them, and the fewest
 * bytes its declared size can take. stb (Debian's 2022 build) trusts a
 * Huffman table's code counts: counts summing past 256 write past its
 * tables (fuzz_texture found it: UBSan, index 257 of size[257]), so every
 * table (DHT, also between the scans of a progressive file) must hold at
 * most 256 codes and fit its segment. stb also decodes with tables never
 * defined, whose memory it never set (its index of the symbol came out
 * 1,062,821,993: an out-of-bounds read, fuzz_texture after 3.4M runs), so
 * every scan's tables must be defined before it: DC and AC for sequential
 * files; for progressive ones DC on a first DC scan, AC on an AC scan. Every scan codes each 8 x 8 block of
 * a component with at least one bit (its DC coefficient, or an end-of-band
 * run covering it), so the first component's blocks at its sampling need
 * that many bits: *min_bytes. Returns a reason to refuse, or NULL (also for
 * what is not a JPEG: stb then says what is wrong). */
static const char *jpeg_check(const unsigned char *p, size_t n, size_t *min_bytes)
{
	*min_bytes = 0;
	/* A JPEG to stb: 0xff, any more fill bytes 0xff, then SOI. */
	size_t i = 1;
	while (i < n && p[i] == 0xff)
		i++;
	if (n < 4 || p[0] != 0xff || i >= n || p[i] != 0xd8)
		return NULL;
	i++;
	unsigned defined = 0; /* Huffman tables defined: bit id for DC, 4 + id for AC */
	int progressive = 0;
	while (i + 4 <= n) {
		if (p[i] != 0xff) { /* entropy-coded data up to the next marker */
			i++;
			continue;
		}
		unsigned m = p[i + 1];
		if (m == 0xff) { /* fill byte */
			i++;
			continue;
		}
		if (m == 0x00 || m == 0x01 || (m >= 0xd0 && m <= 0xd7)) { /* stuffed 0xff, TEM, RSTn */
			i += 2;
			continue;
		}
		if (m == 0xd9) /* EOI */
			break;
		size_t len = (size_t)p[i + 2] << 8 | p[i + 3], end = i + 2 + len;
		if (len < 2)
			return "a marker segment shorter than its length field";
		if (m == 0xc4) { /* DHT: tables of class/id, 16 counts, their values */
			for (size_t t = i + 4; t < end && t < n;) {
				defined |= 1u << ((p[t] >> 4 & 1) * 4 + (p[t] & 3));
				size_t codes = 0;
				for (size_t k = 0; k < 16 && t + 1 + k < n; k++)
					codes += p[t + 1 + k];
				if (codes > 256)
					return "a Huffman table of more than 256 codes";
				t += 17 + codes;
				if (t > end)
					return "a Huffman table longer than its segment";
			}
		}
		if (m == 0xda && i + 5 <= n) { /* SOS: components' table ids, then Ss, Se, Ah/Al */
			unsigned ns = p[i + 4], need = 0;
			size_t after = i + 5 + 2 * (size_t)ns;
			int dc_first = after + 2 < n && p[after] == 0 && p[after + 2] >> 4 == 0, ac = after < n && p[after] > 0;
			for (unsigned c = 0; c < ns && i + 6 + 2 * (size_t)c < n; c++) {
				unsigned td = p[i + 6 + 2 * c] >> 4 & 3, ta = p[i + 6 + 2 * c] & 3;
				if (!progressive || dc_first)
					need |= 1u << td;
				if (!progressive || ac)
					need |= 1u << (4 + ta);
			}
			if (need & ~defined)
				return "a scan uses a Huffman table never defined";
		}
		int sof = m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc;
		if (sof)
			progressive = m == 0xc2 || m == 0xc6 || m == 0xca || m == 0xce;
		if (sof && !*min_bytes && i + 4 + 6 + 3 <= n && len >= 8) {
			const unsigned char *f = p + i + 4; /* precision, height, width, components */
			size_t h = (size_t)f[1] << 8 | f[2], w = (size_t)f[3] << 8 | f[4];
			unsigned nc = f[5], hmax = 1, vmax = 1;
			for (unsigned c = 0; c < nc && i + 10 + 3 * c + 3 <= n; c++) {
				unsigned hv = f[7 + 3 * c];
				hmax = (hv >> 4) > hmax ? hv >> 4 : hmax;
				vmax = (hv & 15) > vmax ? hv & 15 : vmax;
			}
			unsigned h1 = f[7] >> 4, v1 = f[7] & 15;
			if (nc > 0 && h1 > 0 && v1 > 0) {
				size_t cw = (w * h1 + hmax - 1) / hmax, ch = (h * v1 + vmax - 1) / vmax;
				*min_bytes = ((cw + 7) / 8) * ((ch + 7) / 8) / 8;
			}
		}
		i = end;
	}
	return NULL;
}

int texture_decode(const unsigned char *bytes, size_t n, unsigned char **pixels, int *width, int *height, int *bits,
		   char *why, size_t cap)
{
	*pixels = NULL;
	Bytes b = {bytes, n, 0, 0};
	int w = 0, h = 0, comp = 0;
	if (n > 0x7fffffff) {
		snprintf(why, cap, "larger than 2 GiB");
		return 0;
	}
	/* glTF's texture formats, PNG and JPEG, and nothing else stb would
	 * try: a 99-byte file read as a TGA of 8224 x 8224 texels took 12 s
	 * under the sanitizers (fuzz_texture), reading zeros past its end. */
	static const unsigned char png_magic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	int is_png = n >= 8 && !memcmp(bytes, png_magic, 8);
	size_t lead = 0;
	while (lead < n && bytes[lead] == 0xff)
		lead++;
	if (!is_png && !(lead > 0 && lead < n && bytes[lead] == 0xd8)) {
		snprintf(why, cap, "not a PNG or JPEG image (the formats glTF textures have)");
		return 0;
	}
	/* Before any stb call: stbi_info builds the Huffman tables too. */
	size_t need = 0;
	const char *bad = jpeg_check(bytes, n, &need);
	if (bad) {
		snprintf(why, cap, "corrupt JPEG: %s", bad);
		return 0;
	}
	if (!stbi_info_from_callbacks(&callbacks, &b, &w, &h, &comp)) {
		const char *r = stbi_failure_reason();
		snprintf(why, cap, "not a PNG or JPEG image stb_image reads: %s", r ? r : "unknown format");
		return 0;
	}
	if (w < 1 || h < 1 || w > TEXTURE_MAX_SIDE || h > TEXTURE_MAX_SIDE) {
		snprintf(why, cap, "%dx%d texels: at most %d a side", w, h, TEXTURE_MAX_SIDE);
		return 0;
	}
	if (need > n) {
		snprintf(why, cap, "the image data is cut short (%zu bytes cannot code %dx%d texels)", n, w, h);
		return 0;
	}
	unsigned char *data = NULL;
	int depth = 8;
	b = (Bytes){bytes, n, 0, 0};
	int is16 = stbi_is_16_bit_from_callbacks(&callbacks, &b);
	b = (Bytes){bytes, n, 0, 0};
	if (is16 && (data = (unsigned char *)stbi_load_16_from_callbacks(&callbacks, &b, &w, &h, &comp, 4)))
		depth = 16;
	if (!data) {
		b = (Bytes){bytes, n, 0, 0};
		data = stbi_load_from_callbacks(&callbacks, &b, &w, &h, &comp, 4);
	}
	if (!data || b.short_reads) {
		const char *r = stbi_failure_reason();
		if (b.short_reads)
			snprintf(why, cap, "the image data is cut short");
		else
			snprintf(why, cap, "cannot decode: %s", r ? r : "unknown error");
		stbi_image_free(data);
		return 0;
	}
	*pixels = data;
	*width = w;
	*height = h;
	*bits = depth;
	return 1;
}

void texture_free(unsigned char *pixels) { stbi_image_free(pixels); }
