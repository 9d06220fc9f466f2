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

/* stb_image reads past the end of a file as zeros, so a cut-short file
 * would decode to a black band: the reader counts reads that found nothing
 * (a whole file never needs one, as stb asks only for bytes it decodes). */
typedef struct {
	FILE *f;
	int short_reads;
} HdrStream;

static int hdr_cb_read(void *user, char *data, int size)
{
	HdrStream *h = user;
	size_t n = fread(data, 1, (size_t)size, h->f);
	if (n == 0 && size > 0)
		h->short_reads++;
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
	return feof(h->f) || ferror(h->f);
}

ajar_status hdr_read(const char *path, float **rgb, uint32_t *width, uint32_t *height)
{
	*rgb = NULL;
	int fd;
	ajar_status st = input_open(path, &fd, NULL);
	if (st != AJAR_OK)
		return st;
	HdrStream hs = {fdopen(fd, "rb"), 0};
	if (!hs.f) {
		close(fd);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	}
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
