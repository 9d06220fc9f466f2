/* png.c — a small PNG encoder for previews: linear RGB is tone-mapped
 * (exposure, clamp to [0,1], sRGB transfer function) to 8-bit RGB and
 * written as signature, IHDR, sRGB, IDAT chunks and IEND, deflated with zlib.
 * Every row uses the Paeth filter, which suits smooth rendered images and
 * keeps the encoder short. Alpha is not written: the preview is opaque. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "core/error.h"
#include "image/exr.h"

/* Scale applied to radiance before clamping: 1 shows the values as they are. */
#define PNG_EXPOSURE 1.0f
/* Largest IDAT chunk we write; PNG allows 2^31 - 1, smaller keeps readers' buffers small. */
#define PNG_IDAT_MAX (1u << 20)

static unsigned char png_tonemap(float v)
{
	v *= PNG_EXPOSURE;
	if (!(v > 0.0f)) /* also NaN */
		return 0;
	if (v >= 1.0f)
		return 255;
	float s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
	return (unsigned char)(s * 255.0f + 0.5f);
}

static int png_paeth(int a, int b, int c)
{
	int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
	if (pa <= pb && pa <= pc)
		return a;
	return pb <= pc ? b : c;
}

static void put_be32(unsigned char *p, uint32_t v)
{
	p[0] = (unsigned char)(v >> 24);
	p[1] = (unsigned char)(v >> 16);
	p[2] = (unsigned char)(v >> 8);
	p[3] = (unsigned char)v;
}

/* Appends one chunk (length, type, data, CRC over type and data) at *pos. */
static void png_chunk(unsigned char *out, size_t *pos, const char type[4], const unsigned char *data, uint32_t n)
{
	unsigned char *p = out + *pos;
	put_be32(p, n);
	memcpy(p + 4, type, 4);
	if (n)
		memcpy(p + 8, data, n);
	uLong crc = crc32(0L, Z_NULL, 0);
	crc = crc32(crc, p + 4, 4 + n);
	put_be32(p + 8 + n, (uint32_t)crc);
	*pos += 12 + (size_t)n;
}

/* The filtered scanlines (a filter byte and width * 3 bytes per row). */
static unsigned char *png_filtered_rows(const float *rgba, uint32_t width, uint32_t height, size_t *size)
{
	size_t stride = (size_t)width * 3;
	unsigned char *raw = malloc(stride * 2);
	unsigned char *out = malloc((stride + 1) * height);
	if (!raw || !out) {
		free(raw);
		free(out);
		return NULL;
	}
	unsigned char *cur = raw, *prev = raw + stride;
	memset(prev, 0, stride); /* the row above the first is zero */
	for (uint32_t y = 0; y < height; y++) {
		const float *src = rgba + (size_t)y * width * 4;
		for (uint32_t x = 0; x < width; x++)
			for (int c = 0; c < 3; c++)
				cur[3 * x + c] = png_tonemap(src[4 * x + c]);
		unsigned char *dst = out + y * (stride + 1);
		dst[0] = 4; /* Paeth */
		for (size_t i = 0; i < stride; i++) {
			int a = i >= 3 ? cur[i - 3] : 0, b = prev[i], c = i >= 3 ? prev[i - 3] : 0;
			dst[1 + i] = (unsigned char)(cur[i] - png_paeth(a, b, c));
		}
		unsigned char *t = prev;
		prev = cur;
		cur = t;
	}
	free(raw);
	*size = (stride + 1) * height;
	return out;
}

ajar_status ajar_write_png(const char *path, const float *rgba, uint32_t width, uint32_t height)
{
	if (!path || !rgba || width == 0 || height == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_write_png: %s: no path, pixels or size",
			       path ? path : "(null)");
	/* PNG limits dimensions to 2^31 - 1; the row buffer must also fit. */
	if (width > 0x7fffffffu / 4 || height > 0x7fffffffu ||
	    (uint64_t)width * 3 * height > (uint64_t)(SIZE_MAX / 2))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: image %ux%u too large for PNG", path, width,
			       height);

	size_t raw_size;
	unsigned char *raw = png_filtered_rows(rgba, width, height, &raw_size);
	if (!raw)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for PNG rows", path);
	uLong zcap = compressBound((uLong)raw_size);
	unsigned char *z = malloc(zcap);
	size_t nidat = zcap / PNG_IDAT_MAX + 1;
	size_t file_cap = 8 + (12 + 13) + (12 + 1) + zcap + 12 * nidat + 12;
	unsigned char *file = malloc(file_cap);
	if (!z || !file) {
		free(raw);
		free(z);
		free(file);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for PNG data", path);
	}
	uLongf zsize = zcap;
	int zrv = compress2(z, &zsize, raw, (uLong)raw_size, Z_DEFAULT_COMPRESSION);
	free(raw);
	if (zrv != Z_OK) {
		free(z);
		free(file);
		return err_set(zrv == Z_MEM_ERROR ? AJAR_ERROR_OUT_OF_MEMORY : AJAR_ERROR_IO,
			       "%s: zlib compress failed (%d)", path, zrv);
	}

	static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	size_t pos = 0;
	memcpy(file, signature, 8);
	pos = 8;
	unsigned char ihdr[13];
	put_be32(ihdr, width);
	put_be32(ihdr + 4, height);
	ihdr[8] = 8;  /* bit depth */
	ihdr[9] = 2;  /* colour type: RGB */
	ihdr[10] = 0; /* deflate */
	ihdr[11] = 0; /* adaptive filtering */
	ihdr[12] = 0; /* no interlace */
	png_chunk(file, &pos, "IHDR", ihdr, 13);
	const unsigned char intent = 0; /* perceptual: the pixels are sRGB-encoded */
	png_chunk(file, &pos, "sRGB", &intent, 1);
	for (size_t off = 0; off < zsize; off += PNG_IDAT_MAX) {
		size_t n = zsize - off < PNG_IDAT_MAX ? zsize - off : PNG_IDAT_MAX;
		png_chunk(file, &pos, "IDAT", z + off, (uint32_t)n);
	}
	png_chunk(file, &pos, "IEND", NULL, 0);
	free(z);

	char *tmp;
	int fd;
	ajar_status st = image_tmp_open(path, &tmp, &fd);
	if (st == AJAR_OK)
		st = image_tmp_finish(path, tmp, fd, image_write_all(path, fd, file, pos));
	free(file);
	return st;
}
