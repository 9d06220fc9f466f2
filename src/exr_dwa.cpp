/* exr_dwa.cpp — reading OpenEXR files whose compression OpenEXR's C Core
 * (3.1, Debian 12) cannot decode, DWAA and DWAB, through the C++ library
 * of the same package. Blender's and Poly Haven's skies are DWAB, so an
 * environment reader without this refuses the images people have.
 *
 * ajar_read_exr (exr.c) reads everything else and calls this only for
 * those compressions, after its own header checks (size, channels); the
 * result is the same float RGBA, A = 1 where the file has none, a Y-only
 * image as grey. No exception leaves this file. */
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImathBox.h>

#include <cstdlib>
#include <exception>
#include <new>

#include "error.h"
#include "exr.h"

ajar_status exr_read_dwa(const char *path, float **rgba, uint32_t *width, uint32_t *height)
{
	*rgba = nullptr;
	float *px = nullptr;
	try {
		Imf::InputFile file(path);
		const Imath::Box2i dw = file.header().dataWindow();
		const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
		if (w <= 0 || h <= 0 || w > (1 << 20) || h > (1 << 20))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: data window [%d,%d]-[%d,%d] is empty or too large", path,
				       dw.min.x, dw.min.y, dw.max.x, dw.max.y);
		const Imf::ChannelList &cl = file.header().channels();
		const bool rgb = cl.findChannel("R") || cl.findChannel("G") || cl.findChannel("B");
		if (!rgb && !cl.findChannel("Y"))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: no R, G, B or Y channel", path);
		px = static_cast<float *>(calloc((size_t)w * (size_t)h * 4, sizeof(float)));
		if (!px)
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for a %lldx%lld image", path, w, h);
		/* Slices address pixel (x, y) of the data window at px[4 (y w + x)]. */
		char *base = reinterpret_cast<char *>(px) -
			     ((long long)dw.min.y * w + dw.min.x) * (long long)(4 * sizeof(float));
		const size_t xs = 4 * sizeof(float), ys = xs * (size_t)w;
		Imf::FrameBuffer fb;
		static const char *const names[3] = {"R", "G", "B"};
		for (int c = 0; c < (rgb ? 3 : 1); c++)
			fb.insert(rgb ? names[c] : "Y", Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys, 1, 1, 0.0));
		fb.insert("A", Imf::Slice(Imf::FLOAT, base + 3 * sizeof(float), xs, ys, 1, 1, 1.0));
		file.setFrameBuffer(fb);
		file.readPixels(dw.min.y, dw.max.y);
		if (!rgb)
			for (size_t i = 0, n = (size_t)w * (size_t)h; i < n; i++)
				px[4 * i + 1] = px[4 * i + 2] = px[4 * i];
		*rgba = px;
		*width = (uint32_t)w;
		*height = (uint32_t)h;
		return AJAR_OK;
	} catch (const std::bad_alloc &) {
		free(px);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory decoding pixels", path);
	} catch (const std::exception &e) {
		free(px);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: truncated or corrupt pixel data: %s", path, e.what());
	} catch (...) {
		free(px);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: truncated or corrupt pixel data", path);
	}
}
