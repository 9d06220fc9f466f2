/* test_api.c — the C API as a user meets it: the example program in
 * README.md (between <!-- example:begin --> and <!-- example:end -->) is
 * compiled against a `make install` into a temporary prefix with the
 * command lines the README gives (pkg-config, shared with an rpath, and
 * static), run on the Cornell box at a tiny size, and the EXR each writes
 * is read back: size, sample count, finite non-negative values whose
 * mean is near the reference image's (tests/refs, Mitsuba), and the same
 * bits from both (same seed, device and options).
 *
 * Runs from the top of the source tree. Installs with MODE=release
 * whatever mode this test was built in: the example is compiled without
 * sanitizers, so it must link the release library. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "ajar.h"
#include "image/exr.h"
#include "testutil.h"

#define CORNELL SCENE("cornell/cornell.gltf")
/* Square like the reference, so the image means are comparable. */
#define REFERENCE "tests/refs/cornell-mitsuba-8192.exr"
#define WIDTH 32
#define HEIGHT 32
#define SPP 4
/* Relative tolerance on each channel's image mean; at this size and
 * sample count the mean is within about 10% of the reference's. */
#define MEAN_TOLERANCE 0.25

/* Runs a shell command built printf-style; returns its exit status. */
static int shell(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int shell(const char *fmt, ...)
{
	char cmd[4096];
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(cmd, sizeof cmd, fmt, ap);
	va_end(ap);
	assert_true(n > 0 && (size_t)n < sizeof cmd);
	int rc = system(cmd);
	return rc == -1 ? -1 : WEXITSTATUS(rc);
}

/* Prints a log file of a failed step into the test output. */
static void show_log(const char *name)
{
	shell("sed 's/^/    /' '%s/%s' >&2", test_dir, name);
}

/* README.md's example program, written to test_dir/render.c. */
static void extract_example(void)
{
	FILE *in = fopen("README.md", "r");
	if (!in)
		fail_msg("README.md not found: run the test from the top of the source tree");
	char path[512];
	snprintf(path, sizeof path, "%s/render.c", test_dir);
	FILE *out = fopen(path, "w");
	assert_non_null(out);
	char line[1024];
	int state = 0; /* 0 before the begin marker, 1 before the fence, 2 in the code, 3 done */
	int lines = 0;
	while (state < 3 && fgets(line, sizeof line, in)) {
		if (state == 0 && !strcmp(line, "<!-- example:begin -->\n"))
			state = 1;
		else if (state == 1 && !strcmp(line, "```c\n"))
			state = 2;
		else if (state == 1 && strcmp(line, "\n") != 0)
			fail_msg("README.md: expected ```c after <!-- example:begin -->, found: %s", line);
		else if (state == 2 && !strcmp(line, "```\n"))
			state = 3;
		else if (state == 2 && !strcmp(line, "<!-- example:end -->\n"))
			fail_msg("README.md: the example has no closing ``` before <!-- example:end -->");
		else if (state == 2) {
			fputs(line, out);
			lines++;
		}
	}
	int end_found = 0;
	while (state == 3 && !end_found && fgets(line, sizeof line, in))
		end_found = !strcmp(line, "<!-- example:end -->\n");
	fclose(in);
	assert_int_equal(fclose(out), 0);
	if (state != 3 || !end_found)
		fail_msg("README.md: no complete ```c block between <!-- example:begin --> and <!-- example:end -->");
	assert_true(lines > 10);
}

static void image_mean(const float *rgba, uint32_t w, uint32_t h, double mean[3])
{
	double sum[3] = {0, 0, 0};
	for (size_t i = 0; i < (size_t)w * h; i++)
		for (int c = 0; c < 3; c++)
			sum[c] += rgba[4 * i + c];
	for (int c = 0; c < 3; c++)
		mean[c] = sum[c] / ((double)w * h);
}

/* Renders with the built example `exe` and checks the image it writes;
 * returns the pixels (caller frees). */
static float *render_and_check(const char *exe)
{
	char exr[512], log[64];
	snprintf(exr, sizeof exr, "%s/%s.exr", test_dir, exe);
	snprintf(log, sizeof log, "%s.log", exe);
	if (shell("'%s/%s' %s '%s' %d %d %d >'%s/%s' 2>&1", test_dir, exe, CORNELL, exr, WIDTH, HEIGHT, SPP, test_dir,
		  log) != 0) {
		show_log(log);
		fail_msg("the README example (%s) failed", exe);
	}
	float *rgba = NULL;
	uint32_t w = 0, h = 0;
	if (ajar_read_exr(exr, &rgba, &w, &h) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(w, WIDTH);
	assert_int_equal(h, HEIGHT);
	char spp[32];
	assert_int_equal(exr_read_attr(exr, "ajar:spp", spp, sizeof spp), AJAR_OK);
	assert_int_equal(atoi(spp), SPP);

	double mean[3], ref[3];
	image_mean(rgba, w, h, mean);
	for (uint32_t i = 0; i < w * h; i++)
		for (int c = 0; c < 4; c++)
			if (!(rgba[4 * i + c] >= 0.0f && isfinite(rgba[4 * i + c])) || (c == 3 && rgba[4 * i + c] != 1.0f))
				fail_msg("%s: pixel %u channel %d is %g", exr, i, c, rgba[4 * i + c]);
	float *r = NULL;
	if (ajar_read_exr(REFERENCE, &r, &w, &h) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	image_mean(r, w, h, ref);
	free(r);
	for (int c = 0; c < 3; c++) {
		print_message("%s: mean %c %.4f (reference %.4f)\n", exe, "RGB"[c], mean[c], ref[c]);
		if (!(fabs(mean[c] - ref[c]) <= MEAN_TOLERANCE * ref[c]))
			fail_msg("%s: channel %c mean %.4f, reference %.4f", exr, "RGB"[c], mean[c], ref[c]);
	}
	return rgba;
}

static void test_readme_example(void **state)
{
	if (shell("command -v cc >/dev/null 2>&1 && command -v pkg-config >/dev/null 2>&1") != 0) {
		print_message("cc or pkg-config is missing: cannot build the README example\n");
		skip();
	}
	extract_example();

	/* A make started by `make test` would inherit its MAKEFLAGS. */
	if (shell("env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory install PREFIX='%s' "
		  "MODE=release >'%s/install.log' 2>&1",
		  test_dir, test_dir) != 0) {
		show_log("install.log");
		fail_msg("make install PREFIX=%s MODE=release failed", test_dir);
	}

	/* The README's two link lines. */
	if (shell("cd '%s' && export PKG_CONFIG_PATH='%s/lib/pkgconfig' && "
		  "cc -std=c11 -Wall -Wextra -Werror -o render_shared render.c $(pkg-config --cflags --libs ajar) "
		  "-Wl,-rpath,'%s/lib' >cc_shared.log 2>&1",
		  test_dir, test_dir, test_dir) != 0) {
		show_log("cc_shared.log");
		fail_msg("cannot build the README example against libajar.so");
	}
	if (shell("cd '%s' && export PKG_CONFIG_PATH='%s/lib/pkgconfig' && "
		  "cc -std=c11 -Wall -Wextra -Werror -o render_static render.c $(pkg-config --cflags ajar) "
		  "$(pkg-config --static --libs ajar | sed 's/-lajar /-l:libajar.a /') >cc_static.log 2>&1",
		  test_dir, test_dir) != 0) {
		show_log("cc_static.log");
		fail_msg("cannot build the README example against libajar.a");
	}
	/* Linked as intended: one needs the installed libajar.so, the other not. */
	assert_int_equal(shell("readelf -d '%s/render_shared' | grep -q 'NEEDED.*libajar\\.so\\.0'", test_dir), 0);
	assert_int_not_equal(shell("readelf -d '%s/render_static' | grep -q 'libajar'", test_dir), 0);

	float *shared = render_and_check("render_shared");
	float *stat = render_and_check("render_static");
	assert_memory_equal(shared, stat, sizeof(float) * 4 * WIDTH * HEIGHT);
	free(shared);
	free(stat);
}

int main(void)
{
	const struct CMUnitTest tests[] = {cmocka_unit_test(test_readme_example)};
	return cmocka_run_group_tests_name("api", tests, test_group_setup, test_group_teardown);
}
