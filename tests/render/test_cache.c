/* test_cache.c — the kernel binary cache of src/device/device_build.c: a first build
 * compiles and writes exactly one cache file, the next build of the same
 * source and options loads it and the program runs; other options get
 * their own file; a corrupted file is detected, rebuilt and replaced by a
 * good binary; AJAR_CACHE_DIR=off neither reads nor writes; the directory
 * falls back to $XDG_CACHE_HOME/ajar, then ~/.cache/ajar; and the build
 * options each kind of device gets.
 *
 * Every test gets a fresh cache directory under the group's temporary
 * directory (test_dir). PoCL keeps a cache of its own, so POCL_CACHE_DIR
 * points into test_dir too
 * (set before the first OpenCL call): the first build of the process is
 * cold in both caches, and the cold and cached build times printed are
 * measured, never asserted. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "device/device_build.h"
#include "device/device_plan.h"
#include "device/kernel_source.h"
#include "prepare/prepare.h"
#include "testutil.h"

#define BASE_OPTIONS KERNEL_OPTIONS "0"

extern const unsigned ajar_layout_host[];
extern const unsigned ajar_layout_count;

static unsigned next_dir;

/* A fresh, not yet existing cache directory that AJAR_CACHE_DIR names
 * (device_build.c creates it on the first write). */
static char *fresh_cache_dir(void)
{
	char name[32];
	snprintf(name, sizeof name, "cache%u", next_dir++);
	char *dir = test_tmp(name);
	assert_int_equal(setenv("AJAR_CACHE_DIR", dir, 1), 0);
	return dir;
}

/* Names of the entries of `dir` (none if it does not exist), at most `cap`;
 * returns how many there are. */
static int list_dir(const char *dir, char names[][256], int cap)
{
	DIR *d = opendir(dir);
	int n = 0;
	if (!d)
		return 0;
	struct dirent *e;
	while ((e = readdir(d))) {
		if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
			continue;
		if (n < cap)
			snprintf(names[n], 256, "%s", e->d_name);
		n++;
	}
	closedir(d);
	return n;
}

/* The one entry of `dir`, checked to be a cache file; returns its path. */
static char *only_cache_file(const char *dir)
{
	char names[8][256];
	int n = list_dir(dir, names, 8);
	if (n != 1)
		fail_msg("%s: %d entries (first '%s'), expected one cache file", dir, n, n ? names[0] : "");
	size_t len = strlen(names[0]);
	if (strncmp(names[0], "kernel-", 7) != 0 || len < 4 || strcmp(names[0] + len - 4, ".bin") != 0)
		fail_msg("%s: unexpected entry '%s'", dir, names[0]);
	return test_path(dir, names[0]);
}

static unsigned char *read_all(const char *path, long *size)
{
	size_t n;
	unsigned char *b = (unsigned char *)test_read_file(path, &n);
	*size = (long)n;
	assert_true(*size > 0);
	return b;
}

static void write_all(const char *path, const void *data, size_t size)
{
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, size, f), size);
	assert_int_equal(fclose(f), 0);
}

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Opens the default device and builds the embedded kernels with `options`,
 * as the renderer does; returns the wall-clock seconds of device_build. */
static double build(Device *d, const char *options)
{
	cl_platform_id plat;
	cl_device_id id;
	uint32_t n;
	if (device_select(NULL, &plat, &id, 1, &n) != AJAR_OK || device_open(d, plat, id) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	double t0 = now();
	if (device_build(d, ajar_kernel_source, options) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	return now() - t0;
}

/* Runs the layout probe kernel of the built program and compares what it
 * reports with the host's layout: the program really works. Returns the
 * seconds from kernel creation to the result (the first launch includes
 * any compilation the device defers to it). */
static double run_probe(Device *d)
{
	cl_kernel k;
	cl_mem buf;
	size_t one = 1, bytes = sizeof(cl_uint) * ajar_layout_count;
	cl_uint *dev = calloc(ajar_layout_count, sizeof *dev);
	assert_non_null(dev);
	double t0 = now();
	assert_int_equal(device_kernel(d, "layout_probe", &k), AJAR_OK);
	assert_int_equal(device_buffer(d, CL_MEM_WRITE_ONLY, bytes, NULL, &buf), AJAR_OK);
	assert_int_equal(clSetKernelArg(k, 0, sizeof buf, &buf), CL_SUCCESS);
	assert_int_equal(clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &one, &one, 0, NULL, NULL), CL_SUCCESS);
	assert_int_equal(clEnqueueReadBuffer(d->queue, buf, CL_TRUE, 0, bytes, dev, 0, NULL, NULL), CL_SUCCESS);
	double t = now() - t0;
	for (unsigned i = 0; i < ajar_layout_count; i++)
		if (dev[i] != ajar_layout_host[i])
			fail_msg("layout entry %u: device %u, host %u", i, dev[i], ajar_layout_host[i]);
	clReleaseMemObject(buf);
	clReleaseKernel(k);
	free(dev);
	return t;
}

/* Cold build, then a second device loads the cached binary. Runs first:
 * its cold build is the first in the process, so PoCL's cache is empty. */
static void test_second_build_loads_the_cache(void **state)
{
	char *dir = fresh_cache_dir();
	Device a, b;
	/* device_build's own build_seconds leaves out writing the cache file
	 * (where PoCL compiles the kernels it puts in the binary). */
	double cold = build(&a, BASE_OPTIONS), cold_reported = a.build_seconds;
	assert_int_equal(a.from_cache, 0);
	double cold_launch = run_probe(&a);
	free(only_cache_file(dir));
	device_close(&a);

	double cached = build(&b, BASE_OPTIONS), cached_reported = b.build_seconds;
	assert_int_equal(b.from_cache, 1);
	double cached_launch = run_probe(&b);
	free(only_cache_file(dir)); /* loading wrote nothing new */
	device_close(&b);
	print_message("kernel build, cold (Ajar's and PoCL's caches empty): %.3f s (build_seconds %.3f), "
		      "first launch %.3f s\n", cold, cold_reported, cold_launch);
	print_message("kernel build, from Ajar's cache:                    %.3f s (build_seconds %.3f), "
		      "first launch %.3f s\n", cached, cached_reported, cached_launch);
	free(dir);
}

static void test_other_options_get_another_file(void **state)
{
	char *dir = fresh_cache_dir();
	Device a, b, c;
	char names[4][256];
	build(&a, BASE_OPTIONS);
	char *first = only_cache_file(dir);
	device_close(&a);

	build(&b, BASE_OPTIONS " -DAJAR_TEST_CACHE_KEY=1");
	assert_int_equal(b.from_cache, 0);
	run_probe(&b);
	device_close(&b);
	assert_int_equal(list_dir(dir, names, 4), 2);
	const char *base = strrchr(first, '/') + 1;
	assert_true(strcmp(names[0], base) != 0 || strcmp(names[1], base) != 0);
	assert_true(strcmp(names[0], names[1]) != 0);

	/* Each options string finds its own file again. */
	build(&c, BASE_OPTIONS " -DAJAR_TEST_CACHE_KEY=1");
	assert_int_equal(c.from_cache, 1);
	device_close(&c);
	assert_int_equal(list_dir(dir, names, 4), 2);
	free(first);
	free(dir);
}

/* A cache file overwritten by `bad` (of `size` bytes) is rejected, the
 * program rebuilt from source and the file replaced by a loadable binary. */
static void check_rebuilt(const char *dir, const void *bad, size_t size)
{
	Device b, c;
	char *file = only_cache_file(dir);
	write_all(file, bad, size);

	build(&b, BASE_OPTIONS);
	assert_int_equal(b.from_cache, 0);
	run_probe(&b);
	device_close(&b);
	free(only_cache_file(dir));
	long now_size;
	unsigned char *now_data = read_all(file, &now_size);
	assert_false((size_t)now_size == size && memcmp(now_data, bad, size) == 0);

	build(&c, BASE_OPTIONS);
	assert_int_equal(c.from_cache, 1);
	run_probe(&c);
	device_close(&c);
	free(now_data);
	free(file);
}

static void test_corrupt_file_is_rebuilt(void **state)
{
	char *dir = fresh_cache_dir();
	Device a;
	build(&a, BASE_OPTIONS);
	device_close(&a);
	char *file = only_cache_file(dir);
	long size;
	unsigned char *good = read_all(file, &size);

	/* Garbage of the same size. */
	unsigned char *junk = malloc((size_t)size);
	assert_non_null(junk);
	uint32_t x = 12345u;
	for (long i = 0; i < size; i++) {
		x = x * 1664525u + 1013904223u;
		junk[i] = (unsigned char)(x >> 24);
	}
	check_rebuilt(dir, junk, (size_t)size);
	/* A good binary cut in half (what a crash mid-write would leave if
	 * the cache did not write to a temporary name first). */
	check_rebuilt(dir, good, (size_t)size / 2);
	free(junk);
	free(good);
	free(file);
	free(dir);
}

static void test_off_disables_the_cache(void **state)
{
	char *dir = fresh_cache_dir();
	char *xdg = test_tmp("xdg"), *home = test_tmp("home");
	char names[4][256];
	Device a, b;
	build(&a, BASE_OPTIONS);
	device_close(&a);
	free(only_cache_file(dir));

	/* With the cache off nothing is read (this build is cached above) and
	 * nothing is written, neither there nor in the fallback directories. */
	assert_int_equal(setenv("XDG_CACHE_HOME", xdg, 1), 0);
	assert_int_equal(setenv("HOME", home, 1), 0);
	assert_int_equal(setenv("AJAR_CACHE_DIR", "off", 1), 0);
	double t = build(&b, BASE_OPTIONS);
	assert_int_equal(b.from_cache, 0);
	run_probe(&b);
	print_message("kernel build, Ajar's cache off (PoCL's cache warm): %.3f s\n", t);
	device_close(&b);
	free(only_cache_file(dir));
	assert_int_equal(list_dir(xdg, names, 4), 0);
	assert_int_equal(list_dir(home, names, 4), 0);
	free(xdg);
	free(home);
	free(dir);
}

/* The options each kind of device builds each integrator with (0 pt,
 * 1 bdpt, 2 portal): calls for the bidirectional ones off CPUs, NVIDIA's
 * register cap where the device takes it, AJAR_CL_OPTIONS last. */
static void test_build_options(void **state)
{
	(void)state;
	char buf[512];
	Device cpu = {.is_cpu = 1}, gpu = {.is_cpu = 0}, nvidia = {.is_cpu = 0, .nv_options = 1};
	device_build_options(&cpu, 0, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 ");
	device_build_options(&cpu, 2, "-cl-opt-disable", buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "2 -cl-opt-disable");
	device_build_options(&gpu, 0, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 ");
	device_build_options(&gpu, 1, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "1 -DAJAR_CALLS ");
	device_build_options(&nvidia, 0, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 -cl-nv-maxrregcount=40 ");
	device_build_options(&nvidia, 2, "-UAJAR_CALLS -cl-nv-maxrregcount=255", buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "2 -DAJAR_CALLS -cl-nv-maxrregcount=32 -UAJAR_CALLS -cl-nv-maxrregcount=255");
}

/* render_pass's options: the plan's scratch, then one -DAJAR_NO_* for each
 * feature the scene lacks (none where `general`), AJAR_CL_OPTIONS last. */
static void test_render_options(void **state)
{
	(void)state;
	char buf[512];
	Device cpu = {.is_cpu = 1}, gpu = {.is_cpu = 0};
	DevicePlan p = {0};
	device_render_options(&cpu, 0, &p, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 ");
	p.omit = KERNEL_OMIT_ALPHA | KERNEL_OMIT_TEXTURES;
	device_render_options(&cpu, 0, &p, "-cl-opt-disable", buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 -DAJAR_NO_ALPHA -DAJAR_NO_TEXTURES -cl-opt-disable");
	p.omit = KERNEL_OMIT_ALPHA | KERNEL_OMIT_BENT_NORMALS | KERNEL_OMIT_TEXTURES | KERNEL_OMIT_TRI_EXTRA |
		 KERNEL_OMIT_LAYERS | KERNEL_OMIT_ANISOTROPY;
	p.soa = 1;
	p.capacity = 128;
	device_render_options(&gpu, 1, &p, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "1 -DAJAR_CALLS -DAJAR_SUBPATH_SOA=128 -DAJAR_SUBPATH_WORDS=116 "
					  "-DAJAR_NO_ALPHA -DAJAR_NO_BENT_NORMALS -DAJAR_NO_TEXTURES -DAJAR_NO_TRI_EXTRA "
					  "-DAJAR_NO_LAYERS -DAJAR_NO_ANISOTROPY ");
	p.general = 1;
	device_render_options(&gpu, 1, &p, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "1 -DAJAR_CALLS -DAJAR_SUBPATH_SOA=128 -DAJAR_SUBPATH_WORDS=116 ");
	/* The planes' sky tables: an option only where they are not the kernels' default size. */
	DevicePlan q = {.sky_res = 128};
	device_render_options(&cpu, 0, &q, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 ");
	q.sky_res = 512;
	device_render_options(&cpu, 0, &q, NULL, buf, sizeof buf);
	assert_string_equal(buf, KERNEL_OPTIONS "0 -DPORTAL_SKY_RES=512 ");
}

static void test_directory_fallbacks(void **state)
{
	char buf[512];
	assert_int_equal(setenv("AJAR_CACHE_DIR", "/some/where", 1), 0);
	assert_int_equal(setenv("XDG_CACHE_HOME", "/xdg", 1), 0);
	assert_int_equal(setenv("HOME", "/home/u", 1), 0);
	assert_string_equal(device_cache_dir(buf, sizeof buf), "/some/where");
	assert_int_equal(setenv("AJAR_CACHE_DIR", "", 1), 0);
	assert_string_equal(device_cache_dir(buf, sizeof buf), "/xdg/ajar");
	assert_int_equal(unsetenv("AJAR_CACHE_DIR"), 0);
	assert_string_equal(device_cache_dir(buf, sizeof buf), "/xdg/ajar");
	assert_int_equal(unsetenv("XDG_CACHE_HOME"), 0);
	assert_string_equal(device_cache_dir(buf, sizeof buf), "/home/u/.cache/ajar");
	assert_int_equal(unsetenv("HOME"), 0);
	assert_null(device_cache_dir(buf, sizeof buf));
	assert_int_equal(setenv("AJAR_CACHE_DIR", "off", 1), 0);
	assert_int_equal(setenv("HOME", "/home/u", 1), 0);
	assert_null(device_cache_dir(buf, sizeof buf));
}

/* The group's temporary directory, and the caches pointed into it. */
static int setup(void **state)
{
	if (test_group_setup(state))
		return -1;
	/* Before any OpenCL call: PoCL reads it when the platform starts. */
	char *pocl = test_tmp("pocl");
	setenv("POCL_CACHE_DIR", pocl, 1);
	free(pocl);
	/* Every test names its own directory; until then nothing may touch
	 * the user's cache. */
	setenv("AJAR_CACHE_DIR", test_dir, 1);
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_second_build_loads_the_cache),
		cmocka_unit_test(test_other_options_get_another_file),
		cmocka_unit_test(test_corrupt_file_is_rebuilt),
		cmocka_unit_test(test_off_disables_the_cache),
		cmocka_unit_test(test_directory_fallbacks),
		cmocka_unit_test(test_build_options),
		cmocka_unit_test(test_render_options),
	};
	return cmocka_run_group_tests_name("cache", tests, setup, test_group_teardown);
}
