/* test_scene_env.c — environment images named by a scene (and through the
 * API): an EXR next to the glTF, a missing one refused naming the element;
 * tiny negative pixels clamped with one warning, NaN and Inf refused naming
 * the file and the pixel; the rotation in degrees (any number, either
 * sign), refused if not a number; Radiance .hdr files told by their
 * header, unreadable layouts refused. */
#include "scene_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void test_environment_image(void **state)
{
	/* An 8x4 EXR next to the glTF, named relative to it. */
	float rgba[8 * 4 * 4];
	for (int i = 0; i < 8 * 4; i++) {
		rgba[4 * i] = (float)i;
		rgba[4 * i + 1] = 0.5f;
		rgba[4 * i + 2] = 0.25f * (float)(i % 8);
		rgba[4 * i + 3] = 1.0f;
	}
	char *exr = test_tmp("sky.exr");
	assert_int_equal(ajar_write_exr(exr, rgba, 8, 4, NULL, 0), AJAR_OK);
	free(exr);
	write_tri_gltf("envimg.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"sky.exr\",\"strength\":0.5}}");
	Scene *s = load_ok("envimg.gltf");
	assert_int_equal(s->env_type, ENV_IMAGE);
	assert_int_equal(s->env_width, 8);
	assert_int_equal(s->env_height, 4);
	assert_float_equal(s->env_strength, 0.5f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13], 13.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13 + 1], 0.5f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13 + 2], 1.25f, 0.0);
	ajar_scene_destroy(&s);

	write_tri_gltf("envmissing.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"nosky.exr\"}}");
	load_fails("envmissing.gltf", AJAR_ERROR_IO, "scenes[0].extras.environment.image");
}

/* An 8x4 EXR of 0.5 with `bad` at the pixels listed (x, y pairs). */
static void write_sky(const char *name, float bad, const int *xy, int n)
{
	float rgba[8 * 4 * 4];
	for (int i = 0; i < 8 * 4 * 4; i++)
		rgba[i] = 0.5f;
	for (int k = 0; k < n; k++)
		rgba[4 * (xy[2 * k + 1] * 8 + xy[2 * k]) + (k % 3)] = bad;
	char *exr = test_tmp(name);
	assert_int_equal(ajar_write_exr(exr, rgba, 8, 4, NULL, 0), AJAR_OK);
	free(exr);
}

static void test_environment_pixels(void **state)
{
	/* Tiny negatives (as filtering tools leave them) become 0 with one
	 * warning that counts them and names the file. */
	static const int neg[] = {1, 0, 5, 2, 7, 3};
	write_sky("negsky.exr", -1e-4f, neg, 3);
	write_tri_gltf("negsky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"negsky.exr\"}}");
	warnings = 0;
	ajar_set_log_callback(count_warnings, NULL);
	Scene *s = load_ok("negsky.gltf");
	ajar_set_log_callback(NULL, NULL);
	assert_int_equal(warnings, 1);
	if (!strstr(last_warning, "negsky.exr") || !strstr(last_warning, "3 negative pixel values"))
		fail_msg("warning \"%s\"", last_warning);
	assert_int_equal(s->env_type, ENV_IMAGE);
	assert_float_equal(s->env_rgb[3 * (0 * 8 + 1)], 0.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * (2 * 8 + 5) + 1], 0.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * (3 * 8 + 7) + 2], 0.0f, 0.0);
	for (int i = 0; i < 8 * 4 * 3; i++)
		assert_true(s->env_rgb[i] == 0.0f || s->env_rgb[i] == 0.5f);
	ajar_scene_destroy(&s);

	/* A clean sky: no warning. */
	write_sky("cleansky.exr", 0.0f, neg, 0);
	write_tri_gltf("cleansky.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"cleansky.exr\"}}");
	warnings = 0;
	ajar_set_log_callback(count_warnings, NULL);
	s = load_ok("cleansky.gltf");
	ajar_set_log_callback(NULL, NULL);
	assert_int_equal(warnings, 0);
	ajar_scene_destroy(&s);

	/* NaN and Inf are refused, naming the file and the pixel; the glTF
	 * loader adds the scene file and the element. */
	static const int one[] = {6, 2};
	write_sky("nansky.exr", NAN, one, 1);
	write_tri_gltf("nansky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"nansky.exr\"}}");
	load_fails("nansky.gltf", AJAR_ERROR_BAD_INPUT, "nansky.exr: environment: pixel (6, 2) channel R is nan");
	write_sky("infsky.exr", -INFINITY, one, 1);
	write_tri_gltf("infsky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"infsky.exr\"}}");
	load_fails("infsky.gltf", AJAR_ERROR_BAD_INPUT, "infsky.exr: environment: pixel (6, 2) channel R is -inf");

	/* Through the API: the same check, and the scene keeps no sky. */
	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	char *nan_exr = test_tmp("nansky.exr");
	assert_int_equal(ajar_scene_set_environment_image(as, nan_exr, 1.0f), AJAR_ERROR_BAD_INPUT);
	if (!strstr(ajar_last_error(), "nansky.exr: environment: pixel (6, 2)"))
		fail_msg("\"%s\"", ajar_last_error());
	free(nan_exr);
	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(as, &in), AJAR_OK);
	assert_int_equal(in.environment, 0);
	ajar_scene_destroy(&as);
}

static void test_environment_rotation(void **state)
{
	/* Degrees in the extras, radians about +Y in the scene, reduced
	 * modulo a turn; any number of degrees, of either sign. */
	write_sky("rotsky.exr", 0.0f, NULL, 0);
	write_tri_gltf("rot.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"rotsky.exr\",\"rotation\":-450}}");
	Scene *s = load_ok("rot.gltf");
	assert_float_equal(s->env_rotation, -0.5 * M_PI, 1e-6);
	ajar_scene_destroy(&s);
	write_tri_gltf("rotcol.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"color\":[1,1,1],\"rotation\":30}}");
	s = load_ok("rotcol.gltf");
	assert_float_equal(s->env_rotation, M_PI / 6.0, 1e-6);
	ajar_scene_destroy(&s);
	write_tri_gltf("rotbad.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"color\":[1,1,1],\"rotation\":\"east\"}}");
	load_fails("rotbad.gltf", AJAR_ERROR_BAD_INPUT, "scenes[0].extras.environment.rotation must be a number");

	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	assert_float_equal(as->env_rotation, 0.0f, 0.0);
	assert_int_equal(ajar_scene_set_environment_rotation(as, 90.0f), AJAR_OK);
	assert_float_equal(as->env_rotation, 0.5 * M_PI, 1e-6);
	assert_int_equal(ajar_scene_set_environment_rotation(as, NAN), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(ajar_scene_set_environment_rotation(NULL, 1.0f), AJAR_ERROR_INVALID_ARGUMENT);
	assert_float_equal(as->env_rotation, 0.5 * M_PI, 1e-6);
	ajar_scene_destroy(&as);
}

/* A flat (not run-length) 8x4 Radiance file: pixel i has mantissas
 * (128 + i, 64, 0) and exponent byte 129, so RGB = (1 + i / 128, 0.5, 0). */
static void write_hdr(const char *name)
{
	static const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
	unsigned char data[sizeof head - 1 + 8 * 4 * 4];
	memcpy(data, head, sizeof head - 1);
	for (int i = 0; i < 8 * 4; i++) {
		unsigned char *p = data + sizeof head - 1 + 4 * i;
		p[0] = (unsigned char)(128 + i);
		p[1] = 64;
		p[2] = 0;
		p[3] = 129;
	}
	write_bytes(name, data, sizeof data);
}

static void test_environment_hdr(void **state)
{
	/* Told by its header, not its name. */
	write_hdr("sky.hdr");
	write_hdr("sky-hdr.exr");
	const char *names[2] = {"sky.hdr", "sky-hdr.exr"};
	for (int k = 0; k < 2; k++) {
		char extras[256];
		snprintf(extras, sizeof extras, ",\"extras\":{\"environment\":{\"image\":\"%s\",\"strength\":2}}",
			 names[k]);
		write_tri_gltf("hdr.gltf", "0", "{\"mesh\":0}", extras);
		Scene *s = load_ok("hdr.gltf");
		assert_int_equal(s->env_type, ENV_IMAGE);
		assert_int_equal(s->env_width, 8);
		assert_int_equal(s->env_height, 4);
		assert_float_equal(s->env_strength, 2.0f, 0.0);
		for (int i = 0; i < 8 * 4; i++) {
			assert_true(s->env_rgb[3 * i] == 1.0f + (float)i / 128.0f);
			assert_true(s->env_rgb[3 * i + 1] == 0.5f);
			assert_true(s->env_rgb[3 * i + 2] == 0.0f);
		}
		ajar_scene_destroy(&s);
	}
	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	char *p = test_tmp("sky.hdr");
	assert_int_equal(ajar_scene_set_environment_image(as, p, 1.0f), AJAR_OK);
	free(p);
	assert_int_equal(as->env_width, 8);
	assert_true(as->env_rgb[3 * 9] == 1.0f + 9.0f / 128.0f);
	ajar_scene_destroy(&as);

	/* A Radiance header with a layout stb_image does not read, and one
	 * cut short: refused, naming the file. */
	write_text("sideways.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+X 8 -Y 4\n");
	write_tri_gltf("hdrbad.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"sideways.hdr\"}}");
	load_fails("hdrbad.gltf", AJAR_ERROR_BAD_INPUT, "sideways.hdr: not a readable Radiance HDR image");
	write_text("cut.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n\x80\x40");
	write_tri_gltf("hdrcut.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"cut.hdr\"}}");
	load_fails("hdrcut.gltf", AJAR_ERROR_BAD_INPUT, "cut.hdr: not a readable Radiance HDR image");
}

/* Cut-short and oversized .hdr files, which stb_image alone either reads
 * forever (its run-length reader takes the zeros past the end as empty
 * runs: both files below hung `ajar info`) or allocates for from the header
 * alone: refused as bad input, naming the file, before any pixel buffer. A
 * hang ends the binary by SIGALRM instead of the suite. RLE scanlines read
 * back; the resolution line may space its parts as stb allows. */
static void test_environment_hdr_hostile(void **state)
{
	static const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
	unsigned char data[sizeof head - 1 + 4 + 8];
	memcpy(data, head, sizeof head - 1);
	const unsigned char scan[4] = {2, 2, 0, 8};
	memcpy(data + sizeof head - 1, scan, 4);
	memset(data + sizeof head - 1 + 4, 0, 8);
	/* The 49 bytes: a scanline header and the end of the file. */
	write_bytes("eof.hdr", data, sizeof head - 1 + 4);
	/* Long enough for its size, but only zero counts: runs of nothing. */
	write_bytes("zeros.hdr", data, sizeof data);
	const char *cases[][2] = {{"eof.hdr", "cut short"},
				  {"zeros.hdr", "cut short"},
				  {"huge.hdr", "at most 65536 a side"},
				  {"many.hdr", "134217728 in all"},
				  {"tall.hdr", "cut short (12 bytes cannot hold 8x60000"}};
	write_text("huge.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 70000\n\x02\x02\x01\x11");
	write_text("many.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 16384 +X 16384\n\x02\x02\x40\x00");
	write_text("tall.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 8\n012345678901");
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		char extras[256];
		snprintf(extras, sizeof extras, ",\"extras\":{\"environment\":{\"image\":\"%s\"}}", cases[k][0]);
		write_tri_gltf("hostile.gltf", "0", "{\"mesh\":0}", extras);
		alarm(30);
		load_fails("hostile.gltf", AJAR_ERROR_BAD_INPUT, cases[k][0]);
		alarm(0);
		if (!strstr(ajar_last_error(), cases[k][1]))
			fail_msg("%s: \"%s\"", cases[k][0], ajar_last_error());
	}
	/* A whole RLE scanline of 8 texels (each channel one run), with the
	 * resolution line spaced as stb accepts it. */
	static const char head2[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1   +X 8\n";
	unsigned char ok[sizeof head2 - 1 + 4 + 8];
	memcpy(ok, head2, sizeof head2 - 1);
	const unsigned char rle[12] = {2, 2, 0, 8, 0x88, 128, 0x88, 64, 0x88, 0, 0x88, 129};
	memcpy(ok + sizeof head2 - 1, rle, sizeof rle);
	write_bytes("rle.hdr", ok, sizeof ok);
	write_tri_gltf("rle.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"rle.hdr\"}}");
	Scene *s = load_ok("rle.gltf");
	assert_int_equal(s->env_width, 8);
	assert_int_equal(s->env_height, 1);
	for (int i = 0; i < 8; i++)
		assert_true(s->env_rgb[3 * i] == 1.0f && s->env_rgb[3 * i + 1] == 0.5f && s->env_rgb[3 * i + 2] == 0.0f);
	ajar_scene_destroy(&s);
}

/* An EXR sky whose header declares 16384 x 16384 pixels (as many as the EXR
 * reader takes, twice what a sky may have): refused from its header, before
 * 4 GiB are allocated for pixels it does not have. */
static void test_environment_exr_too_large(void **state)
{
	char *p = test_tmp("huge.exr");
	const float px[4] = {1, 1, 1, 1};
	assert_int_equal(ajar_write_exr(p, px, 1, 1, NULL, 0), AJAR_OK);
	FILE *f = fopen(p, "rb");
	unsigned char buf[16384] = {0};
	size_t n = fread(buf, 1, sizeof buf, f);
	fclose(f);
	static const char key[] = "dataWindow\0box2i";
	unsigned char *at = memmem(buf, n, key, sizeof key);
	assert_non_null(at);
	const int32_t box[4] = {0, 0, 16383, 16383};
	memcpy(at + sizeof key + 4, box, sizeof box);
	write_bytes("huge.exr", buf, sizeof buf); /* long enough for its 1024 chunk offsets */
	write_tri_gltf("huge.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"huge.exr\"}}");
	load_fails("huge.gltf", AJAR_ERROR_BAD_INPUT, "huge.exr: environment: 16384x16384 pixels; a sky has at most 134217728");
	free(p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_environment_image),
		cmocka_unit_test(test_environment_pixels),
		cmocka_unit_test(test_environment_rotation),
		cmocka_unit_test(test_environment_hdr),
		cmocka_unit_test(test_environment_hdr_hostile),
		cmocka_unit_test(test_environment_exr_too_large),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
