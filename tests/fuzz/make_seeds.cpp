// make_seeds.cpp — the EXR and JPEG seeds of tests/fuzz/corpus, written by
// the libraries Ajar reads them with: OpenEXR's C++ library (every
// compression, scanline and tiled, half and float, RGBA and Y) and
// stb_image_write (baseline JPEGs). From the top of the tree:
//   c++ -o build/make_seeds tests/fuzz/make_seeds.cpp $(pkg-config --cflags --libs OpenEXR stb)
//   build/make_seeds tests/fuzz/corpus
// (the DWA seeds are tests/data/dwa's files, copied).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <ImfTiledOutputFile.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <stb_image_write.h>

using namespace Imf;

static void rgba(const std::string &path, int w, int h, Compression c)
{
	std::vector<Rgba> px((size_t)w * h);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			Rgba &p = px[(size_t)y * w + x];
			p.r = 0.5f + 0.4f * std::sin(x * 0.3f);
			p.g = (x + y) / 40.0f;
			p.b = (y % 8 < 4) ? 1.0f : 0.25f;
			p.a = (x % 3) ? 1.0f : 0.5f;
		}
	RgbaOutputFile f(path.c_str(), w, h, WRITE_RGBA, 1, Imath::V2f(0, 0), 1, INCREASING_Y, c);
	f.setFrameBuffer(px.data(), 1, w);
	f.writePixels(h);
}

static void y_float_tiled(const std::string &path, int w, int h)
{
	Header hd(w, h);
	hd.channels().insert("Y", Channel(FLOAT));
	hd.setTileDescription(TileDescription(8, 8, ONE_LEVEL));
	hd.compression() = ZIP_COMPRESSION;
	std::vector<float> y((size_t)w * h);
	for (size_t i = 0; i < y.size(); i++)
		y[i] = (float)(i % 17) * 0.125f;
	TiledOutputFile f(path.c_str(), hd);
	FrameBuffer fb;
	fb.insert("Y", Slice(FLOAT, (char *)y.data(), sizeof(float), sizeof(float) * w));
	f.setFrameBuffer(fb);
	f.writeTiles(0, f.numXTiles() - 1, 0, f.numYTiles() - 1);
}

static void spill(void *ctx, void *data, int n) { fwrite(data, 1, (size_t)n, (FILE *)ctx); }

static void jpeg(const std::string &path, int w, int h, int comp, int quality)
{
	std::vector<unsigned char> px((size_t)w * h * comp);
	for (size_t i = 0; i < px.size(); i++)
		px[i] = (unsigned char)(i * 37 + i / 7);
	FILE *f = fopen(path.c_str(), "wb");
	stbi_write_jpg_to_func(spill, f, w, h, comp, px.data(), quality);
	fclose(f);
}

int main(int argc, char **argv)
{
	std::string dir = argc > 1 ? argv[1] : "tests/fuzz/corpus";
	const struct {
		const char *name;
		Compression c;
	} kinds[] = {{"none", NO_COMPRESSION}, {"rle", RLE_COMPRESSION},   {"zips", ZIPS_COMPRESSION},
		     {"zip", ZIP_COMPRESSION},   {"piz", PIZ_COMPRESSION},   {"pxr24", PXR24_COMPRESSION},
		     {"b44", B44_COMPRESSION},   {"b44a", B44A_COMPRESSION}};
	for (const auto &k : kinds)
		rgba(dir + "/exr/" + k.name + ".exr", 13, 9, k.c);
	y_float_tiled(dir + "/exr/tiled-y.exr", 19, 11);
	jpeg(dir + "/texture/rgb.jpg", 8, 8, 3, 90);
	jpeg(dir + "/texture/odd.jpg", 19, 7, 3, 40);
	jpeg(dir + "/texture/grey.jpg", 9, 9, 1, 75);
	return 0;
}
