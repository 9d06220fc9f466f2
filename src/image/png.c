/* png.c — PNG previews: linear RGB is tone-mapped (exposure, clamp to
 * [0,1], sRGB transfer function) to 8-bit RGB here, and encoded by
 * stb_image_write from Debian's libstb (the library tinygltf and hdr.c
 * already link, which exports it: no implementation is compiled in here).
 * The file is written as the EXR is, under a temporary name renamed on
 * success. Alpha is not written: the preview is opaque. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include <stb_image_write.h>

#include "core/error.h"
#include "image/exr.h"

/* Scale applied to radiance before clamping: 1 shows the values as they are. */
#define PNG_EXPOSURE 1.0f
/* stb_image_write counts bytes in int and grows its output by doubling:
 * the filtered rows (3 bytes a pixel and a filter byte a row) must stay
 * well below INT_MAX, a quarter of it, 512 MiB (13,000 pixels square). */
#define PNG_MAX_ROW_BYTES ((uint64_t)INT_MAX / 4)

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

/* stb_image_write hands the whole encoded file to this callback at once. */
typedef struct {
	const char *path;
	int fd;
	ajar_status st;
} PngSink;

static void png_sink_write(void *user, void *data, int size)
{
	PngSink *sink = user;
	sink->st = image_write_all(sink->path, sink->fd, data, (size_t)size);
}

ajar_status ajar_write_png(const char *path, const float *rgba, uint32_t width, uint32_t height)
{
	if (!path || !rgba || width == 0 || height == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_write_png: %s: no path, pixels or size",
			       path ? path : "(null)");
	if (width > PNG_MAX_ROW_BYTES / 3 || ((uint64_t)width * 3 + 1) * height > PNG_MAX_ROW_BYTES)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: image %ux%u too large for a PNG preview", path, width,
			       height);

	size_t n = (size_t)width * height;
	unsigned char *rgb = malloc(n * 3);
	if (!rgb)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for PNG rows", path);
	for (size_t i = 0; i < n; i++)
		for (int c = 0; c < 3; c++)
			rgb[3 * i + c] = png_tonemap(rgba[4 * i + c]);

	char *tmp;
	PngSink sink = {path, -1, AJAR_OK};
	ajar_status st = image_tmp_open(path, &tmp, &sink.fd);
	if (st == AJAR_OK) {
		/* 0 without calling the sink when an allocation failed. */
		if (!stbi_write_png_to_func(png_sink_write, &sink, (int)width, (int)height, 3, rgb, (int)width * 3))
			st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory encoding PNG", path);
		else
			st = sink.st;
		st = image_tmp_finish(path, tmp, sink.fd, st);
	}
	free(rgb);
	return st;
}
