/* fuzz_gltf.c — libFuzzer harness: the input is a .gltf or .glb file, loaded
 * as a scene (ajar_scene_load_with: tinygltf, our accessors, materials,
 * textures through image/texture_file.c, lights, the sky), described
 * (ajar_scene_info_get: which triangles emit) and prepared for an 8 x 8
 * render (prepare_scene: BVH, light tables, portals, sky tables). Beside it
 * lie files its URIs may name: tri.bin (a triangle's positions, normals and
 * indices), tex.png, sky.hdr and sky.exr. Any crash, leak, sanitizer report
 * or allocation past libFuzzer's limit is a finding. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

#include "ajar.h"
#include "fuzz_common.h"
#include "prepare/prepare.h"
#include "scene/scene.h"

static void write_png(void *ctx, void *data, int n) { fuzz_write((const char *)ctx, data, (size_t)n); }

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	/* tri.bin: (0,0,0) (1,0,0) (0,1,0), normals +Z, u16 indices 0 1 2. */
	uint8_t bin[80] = {0};
	const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	const uint16_t idx[3] = {0, 1, 2};
	memcpy(bin, pos, 36);
	memcpy(bin + 36, nrm, 36);
	memcpy(bin + 72, idx, 6);
	fuzz_write("tri.bin", bin, 78);
	uint8_t rgba[4 * 4 * 4];
	for (int i = 0; i < 64; i++)
		rgba[i] = (uint8_t)(i * 29);
	stbi_write_png_to_func(write_png, "tex.png", 4, 4, 4, rgba, 16);
	static const char hdr[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n";
	uint8_t sky[sizeof hdr - 1 + 32];
	memcpy(sky, hdr, sizeof hdr - 1);
	for (int i = 0; i < 32; i++)
		sky[sizeof hdr - 1 + (size_t)i] = (uint8_t)(i % 4 == 3 ? 128 : 100 + i);
	fuzz_write("sky.hdr", sky, sizeof sky);
	float px[4 * 2 * 4];
	for (int i = 0; i < 32; i++)
		px[i] = 0.25f * (float)(i % 5);
	if (ajar_write_exr(fuzz_path("sky.exr"), px, 4, 2, NULL, 0) != AJAR_OK)
		abort();
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
	const char *path = fuzz_write("scene.gltf", data, n);
	ajar_load_options lo;
	ajar_load_options_default(&lo);
	ajar_scene *s = NULL;
	if (ajar_scene_load_with(path, &lo, &s) != AJAR_OK)
		return 0;
	ajar_scene_info info;
	ajar_scene_info_get(s, &info);
	ajar_options o;
	ajar_options_default(&o);
	SceneData d;
	if (prepare_scene(s, &o, 8, 8, NULL, &d) == AJAR_OK)
		prepare_free(&d);
	ajar_scene_destroy(&s);
	return 0;
}
