/* hdr.c — Radiance RGBE (.hdr) images for the environment, decoded by
 * stb_image: Debian's libstb, the build tinygltf itself links, which has
 * stb_image's HDR reader (flat and run-length-encoded RGBE, the "-Y W +X
 * H" layout that nearly every .hdr uses). RGBE cannot hold negative or
 * non-finite values, so these images need no clamping. */
#include "image/hdr.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image.h>

#include "core/error.h"
#include "core/input_file.h"

int hdr_file(const char *path)
{
	/* Not a regular file, or not readable: the caller's other reader reports it. */
	int fd = input_is_regular(path) ? open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY) : -1;
	if (fd < 0)
		return 0;
	char head[10] = {0};
	ssize_t n = pread(fd, head, sizeof head, 0);
	close(fd);
	return (n >= 10 && !memcmp(head, "#?RADIANCE", 10)) || (n >= 6 && !memcmp(head, "#?RGBE", 6));
}

/* What a header may declare, checked before stb allocates: 65536 pixels a
 * side and 2^27 pixels, 1.5 GiB of float RGB (a 16384 x 8192 sky; stb's
 * own ceiling is 2 GiB of floats). */
#define HDR_MAX_SIDE 65536
#define HDR_MAX_PIXELS ((uint64_t)1 << 27)

/* One header line as stb reads it: up to '\n', at most cap - 1 kept. */
static void hdr_line(FILE *f, char *buf, size_t cap)
{
	size_t n = 0;
	int c;
	while ((c = getc(f)) != EOF && c != '\n')
		if (n + 1 < cap)
			buf[n++] = (char)c;
	buf[n] = '\0';
}

/* The header as stb parses it: the magic line, lines up to an empty one
 * (or the end), then "-Y H +X W". Sets the size and where the pixels
 * start; 0 if it is not that. */
static int hdr_header(FILE *f, long *w, long *h, long *data_at)
{
	char line[1024];
	hdr_line(f, line, sizeof line);
	if (strcmp(line, "#?RADIANCE") != 0 && strcmp(line, "#?RGBE") != 0)
		return 0;
	do
		hdr_line(f, line, sizeof line);
	while (line[0]);
	hdr_line(f, line, sizeof line);
	char *end;
	if (strncmp(line, "-Y ", 3) != 0)
		return 0;
	*h = strtol(line + 3, &end, 10);
	while (*end == ' ')
		end++;
	if (strncmp(end, "+X ", 3) != 0)
		return 0;
	*w = strtol(end + 3, NULL, 10);
	*data_at = ftell(f);
	return 1;
}

/* The fewest bytes of pixel data a w x h image can have: 4 a pixel flat
 * (stb reads widths below 8 or from 32768 so), else a scanline's 4-byte
 * header and, per channel, a 2-byte run for each 127 pixels. */
static uint64_t hdr_min_bytes(uint64_t w, uint64_t h)
{
	if (w < 8 || w >= 32768)
		return 4 * w * h;
	return h * (4 + 8 * ((w + 126) / 127));
}

/* stb_image reads past the end of a file as zeros, so a cut-short file
 * would decode to a black band, and its run-length reader takes a zero
 * count at the end of the file as a run of nothing, forever (a known stb
 * bug): past the end, the reader counts the read and hands stb runs of one
 * texel (0x81 0x81), which end every scanline; the file is then refused. */
typedef struct {
	FILE *f;
	int short_reads;
} HdrStream;

static int hdr_cb_read(void *user, char *data, int size)
{
	HdrStream *h = user;
	size_t n = fread(data, 1, (size_t)size, h->f);
	if (n == 0 && size > 0) {
		h->short_reads++;
		memset(data, 0x81, (size_t)size);
		return ferror(h->f) ? 0 : size;
	}
	return (int)n;
}

static void hdr_cb_skip(void *user, int n)
{
	HdrStream *h = user;
	if (fseek(h->f, n, SEEK_CUR) != 0)
		h->short_reads++;
}

static int hdr_cb_eof(void *user)
{
	HdrStream *h = user;
	return ferror(h->f) != 0;
}

ajar_status hdr_read(const char *path, float **rgb, uint32_t *width, uint32_t *height)
{
	*rgb = NULL;
	int fd;
	uint64_t size = 0;
	ajar_status st = input_open(path, &fd, &size);
	if (st != AJAR_OK)
		return st;
	HdrStream hs = {fdopen(fd, "rb"), 0};
	if (!hs.f) {
		close(fd);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	}
	long hw = 0, hh = 0, at = 0;
	if (!hdr_header(hs.f, &hw, &hh, &at)) {
		fclose(hs.f);
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: not a readable Radiance HDR image: no \"-Y height +X width\" line after the header",
			       path);
	}
	const char *why = NULL;
	char msg[160];
	if (hw < 1 || hh < 1 || hw > HDR_MAX_SIDE || hh > HDR_MAX_SIDE || (uint64_t)hw * (uint64_t)hh > HDR_MAX_PIXELS) {
		snprintf(msg, sizeof msg, "%ldx%ld pixels: at most %d a side and %llu in all", hw, hh, HDR_MAX_SIDE,
			 (unsigned long long)HDR_MAX_PIXELS);
		why = msg;
	} else if (at < 0 || size < (uint64_t)at || size - (uint64_t)at < hdr_min_bytes((uint64_t)hw, (uint64_t)hh)) {
		snprintf(msg, sizeof msg, "the pixel data is cut short (%llu bytes cannot hold %ldx%ld pixels)",
			 (unsigned long long)(at < 0 || size < (uint64_t)at ? 0 : size - (uint64_t)at), hw, hh);
		why = msg;
	}
	if (why) {
		fclose(hs.f);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: not a readable Radiance HDR image: %s", path, why);
	}
	rewind(hs.f);
	const stbi_io_callbacks cb = {hdr_cb_read, hdr_cb_skip, hdr_cb_eof};
	int w = 0, h = 0, n = 0;
	float *px = stbi_loadf_from_callbacks(&cb, &hs, &w, &h, &n, 3);
	int io = ferror(hs.f);
	fclose(hs.f);
	if (px && (io || hs.short_reads)) {
		stbi_image_free(px);
		px = NULL;
	}
	if (!px) {
		if (io)
			return err_set(AJAR_ERROR_IO, "%s: cannot read", path);
		if (hs.short_reads)
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: not a readable Radiance HDR image: the pixel data is cut short",
				       path);
		const char *why = stbi_failure_reason();
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: not a readable Radiance HDR image: %s", path,
			       why ? why : "not an RGBE file");
	}
	size_t count = (size_t)w * (size_t)h * 3;
	float *out = malloc(sizeof(float) * count);
	if (!out) {
		stbi_image_free(px);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for a %dx%d image", path, w, h);
	}
	memcpy(out, px, sizeof(float) * count);
	stbi_image_free(px);
	*rgb = out;
	*width = (uint32_t)w;
	*height = (uint32_t)h;
	return AJAR_OK;
}
