/* exr.c — OpenEXR files through OpenEXR's C API (Core): writing the
 * renderer's float RGBA with string header attributes, reading header
 * attributes, the header half of reading RGB(A) or Y images for
 * environment maps and tests (its pixels are decoded by OpenEXR's C++
 * library, exr_read.cpp, as Core 3.1 cannot decompress DWA), and the atomic
 * write (temporary file next to the target, renamed on success) that PNG
 * output shares.
 *
 * Both directions use our own stream callbacks on a file descriptor: the
 * read side can then tell "cannot open" (an I/O error) from "not an EXR"
 * (bad input), and the write side creates the temporary file itself with
 * O_EXCL so two writers never share one. Core reads the header first
 * because it checks every size in it against the file's: the limits below
 * are applied before the C++ library, which trusts them, allocates. */
#include "image/exr.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <openexr.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/input_file.h"
#include "image/image_overrides.h"

/* The last message the OpenEXR library gave on this thread; it is more
 * specific than its error code (e.g. which attribute is malformed). */
static _Thread_local char exr_msg[512];

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
	snprintf(exr_msg, sizeof exr_msg, "%s", msg ? msg : exr_get_default_error_message(code));
}

/* "what went wrong" for a failed OpenEXR call: the library's own message if
 * it sent one during this call, else the code's default text. */
static const char *exr_why(exr_result_t rv)
{
	return exr_msg[0] ? exr_msg : exr_get_default_error_message(rv);
}

/* ---- Atomic output files ------------------------------------------------ */

/* What an existing `path` is, if the rename would replace something that
 * is not a plain file: a device node (as root, -o /dev/full replaced the
 * device), a FIFO, a socket, a symbolic link (the link, not its target,
 * would become the file) or a directory. NULL for a regular file or none. */
static const char *not_replaceable(const char *path)
{
	struct stat sb;
	if (lstat(path, &sb) != 0 || S_ISREG(sb.st_mode))
		return NULL;
	return S_ISDIR(sb.st_mode)			   ? "a directory"
	       : S_ISLNK(sb.st_mode)			   ? "a symbolic link"
	       : S_ISFIFO(sb.st_mode)			   ? "a FIFO"
	       : S_ISCHR(sb.st_mode) || S_ISBLK(sb.st_mode) ? "a device"
							   : "not a regular file";
}

ajar_status image_tmp_open(const char *path, char **tmp_path, int *fd)
{
	static atomic_uint counter;
	const char *what = not_replaceable(path);
	if (what)
		return err_set(AJAR_ERROR_IO,
			       "%s: is %s; outputs are written to a new file renamed onto their name, which would "
			       "replace it (name a regular file)",
			       path, what);
	size_t n = strlen(path) + 48;
	char *tmp = malloc(n);
	if (!tmp)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	/* A name unique in this process and, with the pid, among processes;
	 * O_EXCL makes a clash with a stranger's file a retry, never a share. */
	for (int attempt = 0; attempt < 100; attempt++) {
		snprintf(tmp, n, "%s.tmp%ld.%u", path, (long)getpid(), atomic_fetch_add(&counter, 1));
		int f = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
		if (f >= 0) {
			*tmp_path = tmp;
			*fd = f;
			return AJAR_OK;
		}
		if (errno != EEXIST) {
			int e = errno;
			free(tmp);
			return err_set(AJAR_ERROR_IO, "%s: cannot create file: %s", path, strerror(e));
		}
	}
	free(tmp);
	return err_set(AJAR_ERROR_IO, "%s: cannot create a temporary file next to it", path);
}

void (*image_tmp_hook)(const char *tmp_path);

ajar_status image_tmp_finish(const char *path, char *tmp_path, int fd, ajar_status status)
{
	if (close(fd) != 0 && status == AJAR_OK)
		status = err_set(AJAR_ERROR_IO, "%s: cannot write file: %s", path, strerror(errno));
	if (image_tmp_hook)
		image_tmp_hook(tmp_path);
	if (status == AJAR_OK && rename(tmp_path, path) != 0)
		status = err_set(AJAR_ERROR_IO, "%s: cannot rename %s to it: %s", path, tmp_path,
				 strerror(errno));
	if (status != AJAR_OK)
		unlink(tmp_path);
	free(tmp_path);
	return status;
}

ajar_status image_write_all(const char *path, int fd, const void *data, size_t size)
{
	const unsigned char *p = data;
	while (size > 0) {
		ssize_t k = write(fd, p, size);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0)
			return err_set(AJAR_ERROR_IO, "%s: cannot write file: %s", path,
				       k < 0 ? strerror(errno) : "no space written");
		p += k;
		size -= (size_t)k;
	}
	return AJAR_OK;
}

/* ---- Stream callbacks ---------------------------------------------------- */

typedef struct {
	int fd;
	int io_errno; /* errno of the first failed read or write, 0 if none */
} ExrStream;

static int64_t exr_stream_read(exr_const_context_t ctxt, void *user, void *buffer, uint64_t sz,
			       uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
	ExrStream *s = user;
	uint64_t done = 0;
	while (done < sz) {
		ssize_t k = pread(s->fd, (char *)buffer + done, sz - done, (off_t)(offset + done));
		if (k < 0 && errno == EINTR)
			continue;
		if (k < 0) {
			s->io_errno = errno;
			return -1;
		}
		if (k == 0)
			break; /* end of file: the library reports the short read */
		done += (uint64_t)k;
	}
	return (int64_t)done;
}

static int64_t exr_stream_size(exr_const_context_t ctxt, void *user)
{
	ExrStream *s = user;
	struct stat st;
	return fstat(s->fd, &st) == 0 ? (int64_t)st.st_size : -1;
}

static int64_t exr_stream_write(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t sz,
				uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
	ExrStream *s = user;
	uint64_t done = 0;
	while (done < sz) {
		ssize_t k = pwrite(s->fd, (const char *)buffer + done, sz - done, (off_t)(offset + done));
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0) {
			s->io_errno = k < 0 ? errno : ENOSPC;
			return -1;
		}
		done += (uint64_t)k;
	}
	return (int64_t)done;
}

/* ---- Writing ------------------------------------------------------------- */

static const char *const rgba_names[4] = {"R", "G", "B", "A"};

/* Encodes every scanline chunk of part 0 from interleaved float pixels of
 * nch channels named `names`. */
static exr_result_t exr_write_pixels(exr_context_t ctxt, const float *px, int nch, const char *const *names,
				     uint32_t width, uint32_t height)
{
	int32_t lines;
	exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
	exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
	int have_enc = 0;
	for (uint32_t y = 0; rv == EXR_ERR_SUCCESS && y < height; y += (uint32_t)lines) {
		exr_chunk_info_t cinfo;
		rv = exr_write_scanline_chunk_info(ctxt, 0, (int)y, &cinfo);
		if (rv != EXR_ERR_SUCCESS)
			break;
		rv = have_enc ? exr_encoding_update(ctxt, 0, &cinfo, &enc)
			      : exr_encoding_initialize(ctxt, 0, &cinfo, &enc);
		if (rv != EXR_ERR_SUCCESS)
			break;
		have_enc = 1;
		/* The library lists channels alphabetically; match by name. */
		for (int c = 0; c < enc.channel_count; c++) {
			exr_coding_channel_info_t *ch = &enc.channels[c];
			int k = 0;
			while (k < nch - 1 && strcmp(ch->channel_name, names[k]) != 0)
				k++;
			ch->user_pixel_stride = nch * (int32_t)sizeof(float);
			ch->user_line_stride = (int32_t)(width * nch * sizeof(float));
			ch->user_bytes_per_element = sizeof(float);
			ch->user_data_type = EXR_PIXEL_FLOAT;
			ch->encode_from_ptr = (const uint8_t *)(px + (size_t)y * width * nch + k);
		}
		rv = exr_encoding_choose_default_routines(ctxt, 0, &enc);
		if (rv == EXR_ERR_SUCCESS)
			rv = exr_encoding_run(ctxt, 0, &enc);
	}
	if (have_enc)
		exr_encoding_destroy(ctxt, &enc);
	return rv;
}

ajar_status ajar_write_exr(const char *path, const float *rgba, uint32_t width, uint32_t height,
			   const char *const *attrs, uint32_t nattrs)
{
	return exr_write_channels(path, rgba, 4, rgba_names, width, height, attrs, nattrs);
}

ajar_status exr_write_channels(const char *path, const float *px, int nch, const char *const *names, uint32_t width,
			       uint32_t height, const char *const *attrs, uint32_t nattrs)
{
	const float *rgba = px;
	if (!path || !rgba || width == 0 || height == 0 || (nattrs > 0 && !attrs) || nch < 1)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_write_exr: %s: no path, pixels or size",
			       path ? path : "(null)");
	if (width > INT_MAX / 16 || height > INT_MAX)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: image %ux%u too large for OpenEXR", path,
			       width, height);
	for (uint32_t i = 0; i < nattrs; i++)
		if (!attrs[2 * i] || !attrs[2 * i + 1] || !attrs[2 * i][0])
			return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: header attribute %u has no name or value",
				       path, i);

	char *tmp;
	ExrStream stream = {-1, 0};
	ajar_status st = image_tmp_open(path, &tmp, &stream.fd);
	if (st != AJAR_OK)
		return st;

	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.error_handler_fn = exr_on_error;
	init.user_data = &stream;
	init.write_fn = exr_stream_write;
	exr_context_t ctxt = NULL;
	int part;
	const char *step = "create";
	exr_msg[0] = '\0';
	exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
	if (rv == EXR_ERR_SUCCESS) {
		step = "define header";
		rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part);
	}
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_initialize_required_attr_simple(ctxt, 0, (int32_t)width, (int32_t)height,
							 EXR_COMPRESSION_ZIP);
	for (int k = 0; k < nch && rv == EXR_ERR_SUCCESS; k++)
		rv = exr_add_channel(ctxt, 0, names[k], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
	for (uint32_t i = 0; i < nattrs && rv == EXR_ERR_SUCCESS; i++) {
		step = "set attribute";
		rv = exr_attr_set_string(ctxt, 0, attrs[2 * i], attrs[2 * i + 1]);
	}
	if (rv == EXR_ERR_SUCCESS) {
		step = "write header";
		rv = exr_write_header(ctxt);
	}
	if (rv == EXR_ERR_SUCCESS) {
		step = "write pixels";
		rv = exr_write_pixels(ctxt, rgba, nch, names, width, height);
	}
	/* finish writes the chunk offset table; it can fail too. */
	if (ctxt) {
		exr_result_t frv = exr_finish(&ctxt);
		if (rv == EXR_ERR_SUCCESS && frv != EXR_ERR_SUCCESS) {
			step = "finish";
			rv = frv;
		}
	}
	if (stream.io_errno)
		st = err_set(AJAR_ERROR_IO, "%s: cannot write file: %s", path, strerror(stream.io_errno));
	else if (rv == EXR_ERR_OUT_OF_MEMORY)
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory writing OpenEXR", path);
	else if (rv != EXR_ERR_SUCCESS)
		st = err_set(rv == EXR_ERR_WRITE_IO ? AJAR_ERROR_IO : AJAR_ERROR_INVALID_ARGUMENT,
			     "%s: OpenEXR %s: %s", path, step, exr_why(rv));
	return image_tmp_finish(path, tmp, stream.fd, st);
}

/* ---- Reading ------------------------------------------------------------- */

typedef struct {
	exr_context_t ctxt;
	ExrStream stream;
} ExrReader;

/* Opens `path` for reading: I/O errors for a file that cannot be opened,
 * bad input for one that OpenEXR does not accept. */
static ajar_status exr_open(const char *path, ExrReader *r)
{
	r->ctxt = NULL;
	r->stream.io_errno = 0;
	ajar_status ost = input_open(path, &r->stream.fd, NULL);
	if (ost != AJAR_OK)
		return ost;
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	init.error_handler_fn = exr_on_error;
	init.user_data = &r->stream;
	init.read_fn = exr_stream_read;
	init.size_fn = exr_stream_size;
	exr_msg[0] = '\0';
	exr_result_t rv = exr_start_read(&r->ctxt, path, &init);
	if (rv == EXR_ERR_SUCCESS)
		return AJAR_OK;
	ajar_status st;
	if (r->stream.io_errno)
		st = err_set(AJAR_ERROR_IO, "%s: cannot read: %s", path, strerror(r->stream.io_errno));
	else if (rv == EXR_ERR_OUT_OF_MEMORY)
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory reading the OpenEXR header", path);
	else
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: not a valid (or a truncated) OpenEXR file: %s", path, exr_why(rv));
	exr_finish(&r->ctxt);
	close(r->stream.fd);
	return st;
}

static void exr_close(ExrReader *r)
{
	exr_finish(&r->ctxt);
	close(r->stream.fd);
}

/* Limits on what a header may declare, checked before anything is
 * allocated for it: a file of a few hundred bytes can declare any size, and
 * its allocation failing would report "out of memory" for a bad file.
 * 2^28 pixels is 4 GiB of float RGBA, a 16384 x 16384 image: the largest
 * Ajar renders (skies are held to less, src/scene/scene.c). */
#define EXR_MAX_SIDE 65536
#define EXR_MAX_PIXELS ((int64_t)1 << 28)
/* A tile may exceed the image (a 7 x 5 image in 64 x 64 tiles), not both
 * this and the image's side: the C++ library allocates whole tiles. */
#define EXR_MAX_TILE_SIDE 1024

/* Which of the file's channels fill R, G, B, A: NULL leaves the slot to
 * ajar_read_exr (0 for a missing colour, 1 for a missing alpha, Y's grey). */
typedef struct {
	const char *name[4];
	int have_rgb, have_a;
} ChannelMap;

static ajar_status exr_map_channels(const char *path, const exr_attr_chlist_t *cl, ChannelMap *m)
{
	static const char *const names[5] = {"R", "G", "B", "A", "Y"};
	memset(m, 0, sizeof *m);
	/* Each channel costs the C++ decoder a line buffer; 64 keeps those
	 * within a small multiple of the image. */
	if (cl->num_channels > 64)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %d channels; at most 64 are supported", path,
			       cl->num_channels);
	const char *y = NULL;
	for (int c = 0; c < cl->num_channels; c++) {
		const exr_attr_chlist_entry_t *e = &cl->entries[c];
		int k = 0;
		while (k < 5 && strcmp(e->name.str, names[k]) != 0)
			k++;
		if (k == 5)
			continue;
		if (e->x_sampling != 1 || e->y_sampling != 1)
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: channel %s is subsampled (%dx%d); not supported",
				       path, e->name.str, e->x_sampling, e->y_sampling);
		if (k < 4)
			m->name[k] = names[k];
		else
			y = names[4];
		m->have_rgb |= k < 3;
		m->have_a |= k == 3;
	}
	/* Y only matters when there is no colour: it becomes grey. */
	if (!m->have_rgb)
		m->name[0] = y;
	if (!m->name[0] && !m->have_rgb)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: no R, G, B or Y channel", path);
	return AJAR_OK;
}

/* The size checks: data window, tiles, and an offset table that the file
 * is long enough to hold. */
static ajar_status exr_check_size(const char *path, const ExrReader *r, exr_storage_t storage,
				  const exr_attr_box2i_t *dw)
{
	int64_t w = (int64_t)dw->max.x - dw->min.x + 1, h = (int64_t)dw->max.y - dw->min.y + 1;
	if (w <= 0 || h <= 0 || w > EXR_MAX_SIDE || h > EXR_MAX_SIDE || w * h > EXR_MAX_PIXELS)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: data window [%d,%d]-[%d,%d] is empty or too large (at most %d pixels a side, "
			       "%lld in all)",
			       path, dw->min.x, dw->min.y, dw->max.x, dw->max.y, EXR_MAX_SIDE,
			       (long long)EXR_MAX_PIXELS);
	exr_result_t rv = EXR_ERR_SUCCESS;
	if (storage == EXR_STORAGE_TILED) {
		uint32_t tw, th;
		rv = exr_get_tile_descriptor(r->ctxt, 0, &tw, &th, NULL, NULL);
		if (rv == EXR_ERR_SUCCESS && ((int64_t)tw > w && tw > EXR_MAX_TILE_SIDE))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: tiles %u pixels wide for an image %lld wide", path,
				       tw, (long long)w);
		if (rv == EXR_ERR_SUCCESS && ((int64_t)th > h && th > EXR_MAX_TILE_SIDE))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: tiles %u pixels high for an image %lld high", path,
				       th, (long long)h);
	}
	int32_t chunks = 0;
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_chunk_count(r->ctxt, 0, &chunks);
	if (rv != EXR_ERR_SUCCESS)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: OpenEXR header: %s", path, exr_why(rv));
	struct stat sb;
	if (fstat(r->stream.fd, &sb) == 0 && (int64_t)chunks * 8 > (int64_t)sb.st_size)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: truncated: %lld bytes cannot hold the offsets of its %d chunks", path,
			       (long long)sb.st_size, chunks);
	return AJAR_OK;
}

ajar_status exr_read_size(const char *path, uint32_t *width, uint32_t *height)
{
	ExrReader r;
	ajar_status st = exr_open(path, &r);
	if (st != AJAR_OK)
		return st;
	exr_storage_t storage;
	exr_attr_box2i_t dw;
	exr_result_t rv = exr_get_storage(r.ctxt, 0, &storage);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_data_window(r.ctxt, 0, &dw);
	if (rv != EXR_ERR_SUCCESS)
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: OpenEXR header: %s", path, exr_why(rv));
	else
		st = exr_check_size(path, &r, storage, &dw);
	if (st == AJAR_OK) {
		*width = (uint32_t)((int64_t)dw.max.x - dw.min.x + 1);
		*height = (uint32_t)((int64_t)dw.max.y - dw.min.y + 1);
	}
	exr_close(&r);
	return st;
}

ajar_status ajar_read_exr(const char *path, float **rgba, uint32_t *width, uint32_t *height)
{
	if (!path || !rgba || !width || !height)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_read_exr: null argument");
	*rgba = NULL;
	ExrReader r;
	ajar_status st = exr_open(path, &r);
	if (st != AJAR_OK)
		return st;

	exr_storage_t storage;
	exr_attr_box2i_t dw;
	const exr_attr_chlist_t *cl;
	exr_result_t rv = exr_get_storage(r.ctxt, 0, &storage);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_data_window(r.ctxt, 0, &dw);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_channels(r.ctxt, 0, &cl);
	if (rv != EXR_ERR_SUCCESS) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: OpenEXR header: %s", path, exr_why(rv));
		goto done;
	}
	if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: deep OpenEXR images are not supported", path);
		goto done;
	}
	st = exr_check_size(path, &r, storage, &dw);
	if (st != AJAR_OK)
		goto done;
	ChannelMap map;
	st = exr_map_channels(path, cl, &map);
	if (st != AJAR_OK)
		goto done;
	uint32_t w = (uint32_t)((int64_t)dw.max.x - dw.min.x + 1), h = (uint32_t)((int64_t)dw.max.y - dw.min.y + 1);
	size_t n = (size_t)w * h;
	float *px = calloc(n * 4, sizeof(float));
	if (!px) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for a %ux%u image", path, w, h);
		goto done;
	}
	st = exr_decode_rgba(path, r.stream.fd, map.name, px, w, h);
	if (st != AJAR_OK) {
		free(px);
		goto done;
	}
	for (size_t i = 0; i < n; i++) {
		if (!map.have_rgb)
			px[4 * i + 1] = px[4 * i + 2] = px[4 * i];
		if (!map.have_a)
			px[4 * i + 3] = 1.0f;
	}
	*rgba = px;
	*width = w;
	*height = h;
done:
	exr_close(&r);
	return st;
}

ajar_status exr_read_attr(const char *path, const char *name, char *value, size_t cap)
{
	if (!path || !name || !value || cap == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "exr_read_attr: null argument");
	ExrReader r;
	ajar_status st = exr_open(path, &r);
	if (st != AJAR_OK)
		return st;
	int32_t len;
	const char *s;
	exr_msg[0] = '\0';
	exr_result_t rv = exr_attr_get_string(r.ctxt, 0, name, &len, &s);
	if (rv == EXR_ERR_NO_ATTR_BY_NAME)
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: no header attribute \"%s\"", path, name);
	else if (rv != EXR_ERR_SUCCESS)
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: header attribute \"%s\": %s", path, name, exr_why(rv));
	else if (len < 0 || (size_t)len >= cap)
		st = err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: header attribute \"%s\" is %d bytes, buffer %zu",
			     path, name, len, cap);
	else {
		memcpy(value, s, (size_t)len);
		value[len] = '\0';
	}
	exr_close(&r);
	return st;
}
