/* exr_read.cpp — the pixels of an OpenEXR file through OpenEXR's C++
 * library (Imf), which decodes every compression the format has: DWAA and
 * DWAB (Blender's and Poly Haven's skies), B44, PIZ, PXR24, ZIP, RLE, in
 * scanline or tiled files. OpenEXR's C Core (3.1, Debian 12) cannot
 * decompress DWA; Imf can, and it is the reference every other decoder is
 * measured against. exr.c checks the header with Core first (sizes,
 * channels, limits) and calls this for the pixels alone.
 *
 * Imf reports errors by exception; none leaves this file. */
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <Iex.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "image/exr.h"

namespace {

/* An Imf input stream on the descriptor exr.c opened: reads with pread at
 * the stream's own offset, and keeps the errno of a failed read, so a
 * failing disk is reported as an I/O error and not as a bad file. */
class FdStream : public Imf::IStream {
public:
	FdStream(const char *path, int fd) : Imf::IStream(path), fd_(fd)
	{
		struct stat st;
		size_ = fstat(fd, &st) == 0 ? (uint64_t)st.st_size : 0;
	}

	/* Imf's contract: all n bytes or an exception; false once the last
	 * byte of the file has been read. */
	bool read(char c[], int n) override
	{
		/* A corrupt offset can point anywhere, even past what pread
		 * accepts: that is the file's fault, not the disk's. */
		if (n < 0 || pos_ > size_ || (uint64_t)n > size_ - pos_)
			throw Iex::InputExc("unexpected end of file");
		int done = 0;
		while (done < n) {
			ssize_t k = pread(fd_, c + done, (size_t)(n - done), (off_t)(pos_ + (uint64_t)done));
			if (k < 0 && errno == EINTR)
				continue;
			if (k < 0) {
				io_errno = errno;
				throw Iex::IoExc(strerror(errno));
			}
			if (k == 0)
				throw Iex::InputExc("unexpected end of file");
			done += (int)k;
		}
		pos_ += (uint64_t)n;
		return pos_ < size_;
	}

	uint64_t tellg() override { return pos_; }
	void seekg(uint64_t pos) override { pos_ = pos; }

	int io_errno = 0;

private:
	int fd_;
	uint64_t pos_ = 0, size_;
};

/* Imf's message without the "... image file "path". " it starts with
 * when it names the file: ours names it already. */
const char *imf_why(const char *what, const char *path)
{
	std::string named = std::string("\"") + path + "\". ";
	const char *at = strstr(what, named.c_str());
	return at ? at + named.size() : what;
}

} // namespace

extern "C" ajar_status exr_decode_rgba(const char *path, int fd, const char *const channel[4], float *rgba,
				       uint32_t width, uint32_t height)
{
	FdStream stream(path, fd);
	try {
		/* No thread pool: the caller's thread decodes, as with any
		 * other file the library reads. */
		Imf::InputFile file(stream, 0);
		const Imath::Box2i &dw = file.header().dataWindow();
		if ((int64_t)dw.max.x - dw.min.x + 1 != (int64_t)width ||
		    (int64_t)dw.max.y - dw.min.y + 1 != (int64_t)height)
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: OpenEXR header read two ways gives two data windows",
				       path);
		Imf::FrameBuffer fb;
		for (int k = 0; k < 4; k++)
			if (channel[k])
				fb.insert(channel[k], Imf::Slice::Make(Imf::FLOAT, rgba + k, dw, 4 * sizeof(float),
								      (size_t)width * 4 * sizeof(float)));
		file.setFrameBuffer(fb);
		file.readPixels(dw.min.y, dw.max.y);
		return AJAR_OK;
	} catch (const std::bad_alloc &) {
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory decoding pixels", path);
	} catch (const std::exception &e) {
		if (stream.io_errno)
			return err_set(AJAR_ERROR_IO, "%s: cannot read: %s", path, strerror(stream.io_errno));
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: truncated or corrupt pixel data: %s", path,
			       imf_why(e.what(), path));
	} catch (...) {
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: truncated or corrupt pixel data", path);
	}
}
