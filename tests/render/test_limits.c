/* test_limits.c — the limits a render keeps, stated in include/ajar.h and
 * enforced before anything overflows or is allocated:
 *
 * - samples per pixel: at most AJAR_MAX_SPP (2^21), where the 64-bit
 *   fixed-point films of a pixel's own samples and of the AOVs cannot
 *   overflow; a render with a time limit alone stops there. A 1x1 render
 *   of a sky of radiance 1e7 (clamped to 1e6 a sample) gave -954,687 at
 *   9M spp with exit 0;
 * - films whose sums pass 2^63 anyway (light paths' splats have no count
 *   bound; a checkpoint can say anything) are refused, never wrapped, and
 *   a checkpoint's films must hold what its samples can add, and its
 *   options be ones a render can have (bad input naming the file);
 * - image size: at most AJAR_MAX_SIDE a side, and memory for the films
 *   found missing before the device touches them: under an address-space
 *   limit PoCL aborted the process (exit 134) when a film it allocates on
 *   first use did not fit.
 *
 * About 8 s on the 2-core machine, most of it the capped render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include "ajar.h"
#include "testutil.h"

#define CORNELL SCENE("cornell/cornell.gltf")

static ajar_scene *load(const char *path)
{
	ajar_scene *s = NULL;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	return s;
}

/* A triangle far behind the camera and a sky of radiance `sky`: every
 * camera ray sees the sky. */
static ajar_scene *sky_scene(float sky)
{
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material m;
	ajar_material_default(&m);
	uint32_t mat;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	const float pos[9] = {0, 0, 5, 1, 0, 5, 0, 1, 5};
	const uint32_t idx[3] = {0, 1, 2};
	ajar_mesh mesh = {pos, NULL, NULL, 3, idx, 1, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	ajar_camera c = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.5f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &c), AJAR_OK);
	const float rgb[3] = {sky, sky, sky};
	assert_int_equal(ajar_scene_set_environment_color(s, rgb), AJAR_OK);
	return s;
}

static ajar_options tiny(uint32_t spp)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = 1;
	o.spp = spp;
	return o;
}

/* The cap: more is refused, and a time limit alone stops at it with the
 * clamped value, 1e6 (before: the render ran on to the time limit, past
 * 8.8M spp, where the film wrapped). */
static void test_spp_cap(void **state)
{
	ajar_scene *s = sky_scene(1e7f);
	ajar_renderer *r = NULL;
	ajar_options o = tiny(AJAR_MAX_SPP + 1);
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "2097152"));
	o = tiny(0);
	o.time_limit = 40; /* far more than the ~3 s the cap takes; the render stops at the cap */
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), AJAR_MAX_SPP);
	float px[4];
	uint32_t w, h;
	assert_int_equal(ajar_renderer_image(r, px, &w, &h), AJAR_OK);
	assert_float_equal(px[0], 1e6f, 1.0f);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
}

/* The checkpoint of a 1x1 render of `scene` with `integrator` at `spp`,
 * its bytes in *buf (malloc'ed). */
static size_t checkpoint_bytes(ajar_scene *s, ajar_integrator integrator, uint32_t spp, const char *path,
			       unsigned char **buf)
{
	ajar_options o = tiny(spp);
	o.integrator = integrator;
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, path), AJAR_OK);
	ajar_renderer_destroy(&r);
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	*buf = malloc(1 << 16);
	size_t n = fread(*buf, 1, 1 << 16, f);
	fclose(f);
	return n;
}

/* Sets film value k of a 1x1 checkpoint without AOVs (3 own, then 3
 * splat values, then the CRC-32) and writes it back with a valid CRC. */
static void patch_film(const char *path, unsigned char *buf, size_t n, int k, long v)
{
	memcpy(buf + n - 4 - 48 + 8 * (size_t)k, &v, 8);
	uint32_t crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), buf, (uInt)(n - 4));
	memcpy(buf + n - 4, &crc, 4);
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(buf, 1, n, f), n);
	fclose(f);
}

/* A checkpoint's own-pixel sum near 2^63 (the crafted file made
 * the next sum overflow, UBSan: signed overflow) is refused naming the
 * file; a splat sum that a resumed render's splats push past 2^63 is an
 * error, not a wrapped image. */
static void test_checkpoint_films(void **state)
{
	char *ck = test_tmp("limits.ckpt");
	ajar_scene *s = sky_scene(1.0f);
	unsigned char *buf;
	size_t n = checkpoint_bytes(s, AJAR_INTEGRATOR_PT, 4, ck, &buf);
	patch_film(ck, buf, n, 0, 0x7ffffffffffff000L);
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_resume(s, ck, NULL, &r), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), ck));
	assert_non_null(strstr(ajar_last_error(), "the pixels' own sums"));
	patch_film(ck, buf, n, 1, -5);
	assert_int_equal(ajar_renderer_resume(s, ck, NULL, &r), AJAR_ERROR_BAD_INPUT);
	free(buf);
	ajar_scene_destroy(&s);

	/* bdpt's light paths splat into the one pixel of the Cornell box. */
	s = load(CORNELL);
	n = checkpoint_bytes(s, AJAR_INTEGRATOR_BDPT, 4, ck, &buf);
	for (int c = 0; c < 3; c++)
		patch_film(ck, buf, n, 3 + c, 0x7fffffffffffffffL - 1000);
	ajar_options o;
	assert_int_equal(ajar_checkpoint_options(ck, &o, NULL), AJAR_OK);
	o.spp = 64;
	assert_int_equal(ajar_renderer_resume(s, ck, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float px[4];
	uint32_t w, h;
	assert_int_equal(ajar_renderer_image(r, px, &w, &h), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), "passes the 64-bit film"));
	assert_int_equal(ajar_renderer_write_exr(r, test_tmp("never.exr")), AJAR_ERROR_BAD_INPUT);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	free(buf);
	unlink(ck);
	free(ck);
}

/* A checkpoint whose options no render can have (each field of the
 * header in turn, the CRC made valid): bad input naming the file, from
 * ajar_checkpoint_options and ajar_renderer_resume (a crafted file gave
 * exit 1, and 22 of 41 such messages did not name it). The header
 * (src/render/checkpoint_file.c): magic, format, version[16], two hashes,
 * scene[256] (300 bytes), then 12 u32 options from width to aov and
 * portals, and the f64 time_limit, noise and elapsed. */
static void test_checkpoint_options(void **state)
{
	char *ck = test_tmp("options.ckpt");
	ajar_scene *s = sky_scene(1.0f);
	unsigned char *buf;
	size_t n = checkpoint_bytes(s, AJAR_INTEGRATOR_PT, 2, ck, &buf);
	static const struct {
		size_t at;
		uint32_t v;
	} u32s[] = {{308, 7}, {312, 5000}, {316, 100}, {324, 9}, {328, 9},
		    {332, 2}, {336, 3000000}, {340, 0x40}, {344, 9}, {312, 0}};
	static const struct {
		size_t at;
		double v;
	} f64s[] = {{348, -1.0}, {348, NAN}, {356, -0.5}, {356, 2.0}, {364, NAN}, {364, -5.0}};
	size_t cases = sizeof u32s / sizeof u32s[0] + sizeof f64s / sizeof f64s[0];
	unsigned char *bad = malloc(n);
	for (size_t k = 0; k < cases; k++) {
		memcpy(bad, buf, n);
		if (k < sizeof u32s / sizeof u32s[0])
			memcpy(bad + u32s[k].at, &u32s[k].v, 4);
		else
			memcpy(bad + f64s[k - sizeof u32s / sizeof u32s[0]].at, &f64s[k - sizeof u32s / sizeof u32s[0]].v, 8);
		patch_film(ck, bad, n, 0, 0);
		ajar_options o;
		ajar_status st = ajar_checkpoint_options(ck, &o, NULL);
		if (st != AJAR_ERROR_BAD_INPUT || !strstr(ajar_last_error(), ck))
			fail_msg("case %zu: %s \"%s\"", k, ajar_status_name(st), ajar_last_error());
		ajar_renderer *r = NULL;
		st = ajar_renderer_resume(s, ck, NULL, &r);
		if (st != AJAR_ERROR_BAD_INPUT || !strstr(ajar_last_error(), ck))
			fail_msg("case %zu, resume: %s \"%s\"", k, ajar_status_name(st), ajar_last_error());
	}
	free(bad);
	free(buf);
	ajar_scene_destroy(&s);
	unlink(ck);
	free(ck);
}

/* Current virtual memory of this process, in bytes. */
static size_t vm_bytes(void)
{
	FILE *f = fopen("/proc/self/statm", "r");
	unsigned long pages = 0;
	if (f) {
		if (fscanf(f, "%lu", &pages) != 1)
			pages = 0;
		fclose(f);
	}
	return pages * (size_t)sysconf(_SC_PAGESIZE);
}

/* The child of test_memory_before_device (this binary run again: a fork
 * of a process whose PoCL threads run would wait for them forever): under
 * an address-space limit with room for `room` times F, renderer_create of
 * a 4096 x 4096 image, whose films take F = 805 MB on the host and F on
 * the device. Exit 0 if that is out of memory. */
#define MEM_SIDE 4096
static int memory_child(double room)
{
	ajar_scene *s = NULL;
	if (ajar_scene_load(CORNELL, &s) != AJAR_OK)
		return 3;
	/* PoCL and the program loaded first, at a tiny size. */
	ajar_options o = tiny(1);
	ajar_renderer *r = NULL;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		return 3;
	ajar_renderer_destroy(&r);
	struct rlimit lim;
	lim.rlim_cur = lim.rlim_max = (rlim_t)((double)vm_bytes() + room * 48.0 * MEM_SIDE * MEM_SIDE);
	if (setrlimit(RLIMIT_AS, &lim) != 0)
		return 4;
	o.width = o.height = MEM_SIDE;
	ajar_status st = ajar_renderer_create(s, &o, &r);
	fprintf(stderr, "  room %.2f F: %s\n", room, st == AJAR_OK ? "created" : ajar_last_error());
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	return st == AJAR_OK ? 1 : st == AJAR_ERROR_OUT_OF_MEMORY ? 0 : 2;
}

static char self[4096];

/* Room for 0.75 F: the device's film does not fit (PoCL asserted
 * `p->mem_ptr != NULL` and aborted, exit 134); 1.5 F: the host's films fit,
 * the device's do not. Either is out of memory (the CLI's exit 6), never a
 * crash. */
static void test_memory_before_device(void **state)
{
	const char *room[2] = {"0.75", "1.5"};
	for (int k = 0; k < 2; k++) {
		pid_t pid = fork();
		assert_true(pid >= 0);
		if (pid == 0) {
			execl(self, self, "--memory-child", room[k], (char *)NULL);
			_exit(127);
		}
		int status;
		assert_int_equal(waitpid(pid, &status, 0), pid);
		if (!WIFEXITED(status))
			fail_msg("room %s F: killed by signal %d", room[k], WTERMSIG(status));
		assert_int_equal(WEXITSTATUS(status), 0);
	}
}

/* Sizes beyond AJAR_MAX_SIDE: refused from the options (invalid argument)
 * and from a scene's suggested resolution (bad input naming the file). */
static void test_size_limit(void **state)
{
	ajar_scene *s = sky_scene(1.0f);
	ajar_options o = tiny(1);
	o.width = AJAR_MAX_SIDE + 1;
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);
	char *path = test_tmp("big.gltf");
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fprintf(f, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0],\"extras\":{\"resolution\":[%u,"
		   "8]}}],\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
		   "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
		   "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
		AJAR_MAX_SIDE + 1);
	fclose(f);
	assert_int_equal(ajar_scene_load(path, &s), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), path));
	assert_non_null(strstr(ajar_last_error(), "resolution"));
	unlink(path);
	free(path);
}

int main(int argc, char **argv)
{
	if (argc == 3 && !strcmp(argv[1], "--memory-child"))
		return memory_child(atof(argv[2]));
	ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
	if (n <= 0)
		return 1;
	self[n] = '\0';
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_spp_cap),
		cmocka_unit_test(test_checkpoint_films),
		cmocka_unit_test(test_checkpoint_options),
		cmocka_unit_test(test_memory_before_device),
		cmocka_unit_test(test_size_limit),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
