/* input_file.c — input files are regular files, checked before they are
 * opened (input_file.h). The check is repeated on the descriptor, so a
 * file swapped for a FIFO between the two is still refused; O_NONBLOCK
 * keeps even that open from waiting for a writer. */
#include "core/input_file.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

static const char *kind(mode_t m)
{
	return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) || S_ISBLK(m) ? "a device" : S_ISSOCK(m) ? "a socket" : "not a file";
}

static ajar_status refuse(const char *path, mode_t m)
{
	if (S_ISDIR(m))
		return err_set(AJAR_ERROR_IO, "%s: cannot read: is a directory", path);
	return err_set(AJAR_ERROR_BAD_INPUT, "%s: not a regular file (%s)", path, kind(m));
}

int input_is_regular(const char *path)
{
	struct stat sb;
	return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

ajar_status input_open(const char *path, int *fd, uint64_t *size)
{
	*fd = -1;
	struct stat sb;
	if (stat(path, &sb) != 0)
		return err_set(AJAR_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
	if (!S_ISREG(sb.st_mode))
		return refuse(path, sb.st_mode);
	int f = open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
	if (f < 0)
		return err_set(AJAR_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
	if (fstat(f, &sb) != 0 || !S_ISREG(sb.st_mode)) {
		int e = errno;
		close(f);
		return S_ISREG(sb.st_mode) ? err_set(AJAR_ERROR_IO, "%s: cannot read: %s", path, strerror(e))
					   : refuse(path, sb.st_mode);
	}
	/* Regular files never block; clear the flag all the same. */
	int fl = fcntl(f, F_GETFL);
	if (fl >= 0)
		fcntl(f, F_SETFL, fl & ~O_NONBLOCK);
	*fd = f;
	if (size)
		*size = (uint64_t)sb.st_size;
	return AJAR_OK;
}
