/* gltf_files.c — reading a file the scene names (the scene file, its
 * buffers and images): a regular file only (input_open: a FIFO blocked the
 * loader, a URI "." was read as a folder of absurd size), at most 4 GiB,
 * the most a .glb can hold, so a buffer's size is never what a huge file
 * says. Whether it may be read at all is gltf_confine.c's. */
#include "scene/gltf_parts.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "core/input_file.h"

ajar_status gltf_file_open(const char *path, int *fd, size_t *size)
{
	uint64_t bytes = 0;
	ajar_status st = input_open(path, fd, &bytes);
	if (st)
		return st;
	if (bytes > 0xffffffffu) {
		close(*fd);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: file larger than 4 GiB", path);
	}
	*size = (size_t)bytes;
	return AJAR_OK;
}

ajar_status gltf_file_read(const char *path, int fd, unsigned char *data, size_t size)
{
	size_t got = 0;
	while (got < size) {
		ssize_t k = read(fd, data + got, size - got);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0) {
			int e = errno;
			close(fd);
			return err_set(AJAR_ERROR_IO, "%s: cannot read: %s", path, k < 0 ? strerror(e) : "the file shrank");
		}
		got += (size_t)k;
	}
	close(fd);
	return AJAR_OK;
}
