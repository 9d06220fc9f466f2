/* test_cli.c — the `ajar` program as a user runs it: help and version,
 * usage errors naming the option (exit 1), missing and broken scenes
 * (exit 2, the file named, no output created), `info`, a tiny render with
 * its EXR header and PNG, and SIGINT during a long render (exit 5 with the
 * samples so far written). Runs build/ajar (or $AJAR_BIN) from the top of
 * the source tree. */
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "image/exr.h"
#include "testutil.h"

#define CORNELL SCENE("cornell/cornell.gltf")
#define DOOR_AJAR SCENE("door-ajar/door-ajar.gltf")

static int file_exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

typedef struct {
	int code;
	char *out, *err;
} Result;

static Result run(const char *const *args)
{
	Result r;
	char *o = test_tmp("stdout.txt"), *e = test_tmp("stderr.txt");
	r.code = test_wait_exit(test_spawn(test_ajar_bin(), args, o, e));
	r.out = test_read_file(o, NULL);
	r.err = test_read_file(e, NULL);
	unlink(o);
	unlink(e);
	free(o);
	free(e);
	return r;
}

static void result_free(Result *r)
{
	free(r->out);
	free(r->err);
}

/* Runs and checks the exit code and that stderr contains `needle`. */
static void expect(const char *const *args, int code, const char *needle)
{
	Result r = run(args);
	if (r.code != code || (needle && !strstr(r.err, needle)))
		print_error("ajar %s ...: exit %d, stderr:\n%s\n", args[0] ? args[0] : "", r.code, r.err);
	assert_int_equal(r.code, code);
	if (needle)
		assert_non_null(strstr(r.err, needle));
	result_free(&r);
}

/* Number of entries in test_dir (outputs that should not exist show up). */
static int count_tmp_entries(void)
{
	char cmd[512];
	snprintf(cmd, sizeof cmd, "ls -A '%s' | wc -l", test_dir);
	FILE *p = popen(cmd, "r");
	assert_non_null(p);
	int n = -1;
	assert_int_equal(fscanf(p, "%d", &n), 1);
	pclose(p);
	return n;
}

static void test_help_version(void **state)
{
	Result r = run((const char *[]){"--version", NULL});
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, ajar_version()));
	result_free(&r);

	r = run((const char *[]){"--help", NULL});
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, "render"));
	assert_non_null(strstr(r.out, "exit codes"));
	result_free(&r);

	r = run((const char *[]){"render", "--help", NULL});
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, "--spp"));
	assert_non_null(strstr(r.out, "--device"));
	result_free(&r);

	r = run((const char *[]){"help", NULL});
	assert_int_equal(r.code, 0);
	result_free(&r);
}

static void test_usage_errors(void **state)
{
	char *out = test_tmp("never.exr");
	expect((const char *[]){NULL}, 1, "usage");
	expect((const char *[]){"frobnicate", NULL}, 1, "frobnicate");
	expect((const char *[]){"--frobnicate", NULL}, 1, "--frobnicate");
	expect((const char *[]){"render", CORNELL, "-o", out, "--bogus", NULL}, 1, "--bogus");
	expect((const char *[]){"render", CORNELL, "-o", out, "--spp", "-3", NULL}, 1, "--spp");
	expect((const char *[]){"render", CORNELL, "-o", out, "--spp", "12abc", NULL}, 1, "--spp");
	expect((const char *[]){"render", CORNELL, "-o", out, "--spp", NULL}, 1, "--spp");
	expect((const char *[]){"render", CORNELL, "-o", out, "--size", "0x5", NULL}, 1, "--size");
	expect((const char *[]){"render", CORNELL, "-o", out, "--size", "abc", NULL}, 1, "--size");
	expect((const char *[]){"render", CORNELL, "-o", out, "--size=64x", NULL}, 1, "--size");
	/* The real limits, stated: 16384 a side (not 65536), 2^21 spp (not 2^32 - 1). */
	expect((const char *[]){"render", CORNELL, "-o", out, "--size", "16385x8", NULL}, 1, "(1 to 16384)");
	expect((const char *[]){"render", CORNELL, "-o", out, "--spp", "2097153", NULL}, 1, "(1 to 2097152)");
	expect((const char *[]){"render", CORNELL, "-o", out, "--time", "-1", NULL}, 1, "--time");
	expect((const char *[]){"render", CORNELL, "-o", out, "--integrator", "magic", NULL}, 1, "--integrator");
	expect((const char *[]){"render", CORNELL, "-o", out, "--mis", "heavy", NULL}, 1, "not auto, power or balance");
	expect((const char *[]){"render", CORNELL, "-o", out, "--max-depth", "0", NULL}, 1, "--max-depth");
	expect((const char *[]){"render", CORNELL, NULL}, 1, "-o");
	expect((const char *[]){"render", "-o", out, NULL}, 1, "scene");
	expect((const char *[]){"info", NULL}, 1, "info");
	assert_false(file_exists(out));
	assert_int_equal(count_tmp_entries(), 0);
	free(out);
}

static void test_bad_scenes(void **state)
{
	char *missing = test_tmp("missing.gltf"), *broken = test_tmp("broken.gltf"), *out = test_tmp("out.exr");
	char *png = test_tmp("out.png");
	expect((const char *[]){"render", missing, "-o", out, "--png", png, NULL}, 2, missing);
	expect((const char *[]){"info", missing, NULL}, 2, missing);

	FILE *f = fopen(broken, "w");
	assert_non_null(f);
	fputs("{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0", f);
	fclose(f);
	expect((const char *[]){"render", broken, "-o", out, "--png", png, "--spp", "1", NULL}, 2, broken);
	expect((const char *[]){"info", broken, NULL}, 2, broken);
	assert_false(file_exists(out));
	assert_false(file_exists(png));
	assert_int_equal(count_tmp_entries(), 1); /* broken.gltf */
	unlink(broken);

	/* An output directory that does not exist is an I/O error, found
	 * before rendering. */
	char *nodir = test_tmp("no/such/dir/out.exr");
	expect((const char *[]){"render", CORNELL, "-o", nodir, NULL}, 4, nodir);
	free(nodir);
	free(missing);
	free(broken);
	free(out);
	free(png);
}

static void test_info(void **state)
{
	Result r = run((const char *[]){"info", CORNELL, NULL});
	if (r.code != 0)
		print_error("%s", r.err);
	assert_int_equal(r.code, 0);
	const char *t = strstr(r.out, "triangles:");
	assert_non_null(t);
	unsigned long long n = 0;
	assert_int_equal(sscanf(t, "triangles: %llu", &n), 1);
	assert_true(n > 0);
	assert_non_null(strstr(r.out, "camera:"));
	result_free(&r);
}

/* A glTF with KHR_lights_punctual (required): info lists each light in
 * glTF's units. */
static void test_info_lights(void **state)
{
	char *gltf = test_tmp("lights.gltf");
	FILE *f = fopen(gltf, "w");
	assert_non_null(f);
	fputs("{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
	      "\"extensionsRequired\":[\"KHR_lights_punctual\"],"
	      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"intensity\":3},"
	      "{\"type\":\"spot\",\"color\":[1,0.5,0.25],\"intensity\":100,\"range\":7,"
	      "\"spot\":{\"innerConeAngle\":0.25,\"outerConeAngle\":0.5}}]}},"
	      "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],\"nodes\":[{\"mesh\":0},"
	      "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
	      "{\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}}],"
	      "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
	      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
	      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
	      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
	      "\"min\":[0,0,0],\"max\":[1,1,0]}],"
	      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
	      f);
	assert_int_equal(fclose(f), 0);
	Result r = run((const char *[]){"info", gltf, NULL});
	if (r.code != 0)
		print_error("%s", r.err);
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, "lights:       2 (KHR_lights_punctual)"));
	assert_non_null(strstr(r.out, "[0] directional toward (0.000, 0.000, -1.000), colour (1, 1, 1), 3 lx"));
	assert_non_null(strstr(r.out, "[1] spot        at (1, 2, 3) toward (0.000, 0.000, -1.000), colour (1, 0.5, 0.25), "
				      "100 cd, cone 14.3..28.6 deg, range 7"));
	result_free(&r);
	unlink(gltf);
	free(gltf);
}

static void test_tiny_render(void **state)
{
	char *exr = test_tmp("tiny.exr"), *png = test_tmp("tiny.png");
	Result r = run((const char *[]){"render", CORNELL, "-o", exr, "--png", png, "--size", "32x32", "--spp", "2",
					"--seed", "7", NULL});
	if (r.code != 0)
		print_error("%s", r.err);
	assert_int_equal(r.code, 0);
	result_free(&r);

	char spp[32];
	assert_int_equal(exr_read_attr(exr, "ajar:spp", spp, sizeof spp), AJAR_OK);
	assert_string_equal(spp, "2");
	float *px;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(exr, &px, &w, &h), AJAR_OK);
	assert_int_equal(w, 32);
	assert_int_equal(h, 32);
	free(px);

	char *bytes = test_read_file(png, NULL);
	assert_memory_equal(bytes, "\x89PNG\r\n\x1a\n", 8);
	free(bytes);
	/* --quiet prints nothing on success. */
	r = run((const char *[]){"render", CORNELL, "-o", exr, "--size", "8x8", "--spp", "1", "--quiet", NULL});
	assert_int_equal(r.code, 0);
	assert_string_equal(r.err, "");
	result_free(&r);
	unlink(exr);
	unlink(png);
	free(exr);
	free(png);
}

/* Renders `scene` with `integrator` with and without AJAR_CL_OPTIONS =
 * `options`, which must not change a bit of the image. */
static void same_image_with(const char *options, const char *scene, const char *integrator)
{
	char *out[2] = {test_tmp("plain.exr"), test_tmp("options.exr")};
	float *px[2];
	uint32_t w[2], h[2];
	for (int i = 0; i < 2; i++) {
		const char *const args[] = {"render", scene, "-o", out[i], "--size", "16x16", "--spp", "2",
					    "--integrator", integrator, "-q", NULL};
		if (i == 1)
			assert_int_equal(setenv("AJAR_CL_OPTIONS", options, 1), 0);
		expect(args, 0, NULL);
		assert_int_equal(ajar_read_exr(out[i], &px[i], &w[i], &h[i]), AJAR_OK);
		unlink(out[i]);
		free(out[i]);
	}
	assert_int_equal(unsetenv("AJAR_CL_OPTIONS"), 0);
	assert_true(w[0] == w[1] && h[0] == h[1]);
	assert_memory_equal(px[0], px[1], sizeof(float) * 4 * w[0] * h[0]);
	free(px[0]);
	free(px[1]);
}

/* AJAR_CL_OPTIONS reaches the kernel build: -cl-opt-disable and
 * -DAJAR_CALLS render the same image bit for bit (on PoCL), and an option
 * the driver refuses fails with exit 3, naming the variable, and writes
 * nothing. */
static void test_cl_options(void **state)
{
	(void)state;
	same_image_with("-cl-opt-disable", CORNELL, "pt");
	/* What the host adds for GPUs (kernels/base/compat.h): the same image. */
	same_image_with("-DAJAR_CALLS", DOOR_AJAR, "portal");

	char *bad = test_tmp("bad.exr");
	const char *const args_bad[] = {"render", CORNELL, "-o", bad, "--size", "16x16", "--spp", "2", NULL};
	assert_int_equal(setenv("AJAR_CL_OPTIONS", "-cl-ajar-no-such-option", 1), 0);
	int entries = count_tmp_entries();
	expect(args_bad, 3, "AJAR_CL_OPTIONS='-cl-ajar-no-such-option'");
	assert_int_equal(count_tmp_entries(), entries);
	assert_int_equal(unsetenv("AJAR_CL_OPTIONS"), 0);
	free(bad);
}

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static void test_sigint(void **state)
{
	char *exr = test_tmp("long.exr"), *err = test_tmp("stderr.txt");
	const uint32_t full_spp = 1000000;
	char full[16];
	snprintf(full, sizeof full, "%u", full_spp);
	pid_t pid = test_spawn(test_ajar_bin(),
			       (const char *[]){"render", CORNELL, "-o", exr, "--size", "16x16", "--time", "60", "--spp", full,
						NULL},
			       NULL, err);
	/* Wait for the render to start (after kernels are built, which may
	 * take long on a cold cache), then for a pass or two. */
	int started = 0;
	for (double t0 = now(); !started && now() - t0 < 300;) {
		char *s = test_read_file(err, NULL);
		started = strstr(s, "rendering") != NULL;
		free(s);
		if (waitpid(pid, NULL, WNOHANG) == pid)
			fail_msg("ajar ended before rendering");
		usleep(50000);
	}
	assert_true(started);
	usleep(1500000);
	assert_int_equal(kill(pid, SIGINT), 0);
	/* A hang guard, not a timing check: stopping takes one short pass. */
	int status = 0;
	pid_t done = 0;
	for (double t0 = now(); done == 0 && now() - t0 < 60; usleep(20000))
		done = waitpid(pid, &status, WNOHANG);
	if (done == 0) {
		kill(pid, SIGKILL);
		waitpid(pid, &status, 0);
		fail_msg("ajar did not stop after SIGINT");
	}
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), 5);

	char spp[32];
	assert_int_equal(exr_read_attr(exr, "ajar:spp", spp, sizeof spp), AJAR_OK);
	unsigned long n = strtoul(spp, NULL, 10);
	assert_true(n >= 1);
	assert_true(n < full_spp);
	unlink(exr);
	unlink(err);
	free(exr);
	free(err);
}

/* ---- Outputs that are not new regular files --------------------------------
 * Outputs are written to a new file renamed onto their name, which
 * replaced whatever had the name: a device node (as root, -o /dev/full
 * replaced the device), a FIFO, a symbolic link (the link, not its
 * target); -o naming the scene overwrote the scene with exit 0. Each is
 * refused before rendering, and the name is left as it was. */
static mode_t kind_of(const char *path)
{
	struct stat sb;
	return lstat(path, &sb) == 0 ? sb.st_mode & S_IFMT : 0;
}

static void test_special_outputs(void **state)
{
	char *fifo = test_tmp("out-fifo.exr"), *link = test_tmp("out-link.exr"), *dev = test_tmp("out-null.exr");
	char *target = test_tmp("target.exr");
	assert_int_equal(mkfifo(fifo, 0644), 0);
	assert_int_equal(symlink("target.exr", link), 0);
	/* A character device like /dev/null, where the system lets us make
	 * one (root in most containers); the test never names /dev itself. */
	int have_dev = mknod(dev, S_IFCHR | 0666, makedev(1, 3)) == 0;
	const char *names[3] = {fifo, link, dev};
	const char *why[3] = {"is a FIFO", "is a symbolic link", "is a device"};
	for (int k = 0; k < 2 + have_dev; k++) {
		mode_t before = kind_of(names[k]);
		expect((const char *[]){"render", CORNELL, "-o", names[k], "--size", "8x8", "--spp", "1", NULL}, 4, why[k]);
		expect((const char *[]){"render", CORNELL, "-o", target, "--png", names[k], "--size", "8x8", "--spp", "1", NULL},
		       4, why[k]);
		assert_int_equal(kind_of(names[k]), before);
		/* The library refuses too (ajar_write_exr, the PNG, checkpoints). */
		float px[4] = {1, 1, 1, 1};
		assert_int_equal(ajar_write_exr(names[k], px, 1, 1, NULL, 0), AJAR_ERROR_IO);
		assert_non_null(strstr(ajar_last_error(), why[k]));
		assert_int_equal(kind_of(names[k]), before);
	}
	assert_false(file_exists(target));
	if (!have_dev)
		printf("  (no device node: mknod not permitted here)\n");

	/* An output that is the scene, or another output. */
	char *scene = test_tmp("scene.gltf");
	char *text = test_read_file(CORNELL, NULL);
	FILE *f = fopen(scene, "wb");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
	char *bin = test_tmp("cornell.bin"), cmd[1024];
	snprintf(cmd, sizeof cmd, "cp scenes/cornell/*.bin '%s/' 2>/dev/null; true", test_dir);
	assert_int_equal(system(cmd), 0);
	expect((const char *[]){"render", scene, "-o", scene, "--size", "8x8", "--spp", "1", NULL}, 1,
	       "is also the scene");
	char *again = test_read_file(scene, NULL);
	assert_string_equal(again, text);
	char *out = test_tmp("same.exr"), *dotted = test_tmp("./same.exr");
	expect((const char *[]){"render", scene, "-o", out, "--png", dotted, "--size", "8x8", "--spp", "1", NULL}, 1,
	       "is also -o");
	expect((const char *[]){"render", scene, "-o", out, "--checkpoint", dotted, "--size", "8x8", "--spp", "1", NULL}, 1,
	       "is also");
	assert_false(file_exists(out));
	free(again);
	free(text);
	free(bin);
	free(out);
	free(dotted);
	snprintf(cmd, sizeof cmd, "rm -f '%s'/*.bin", test_dir);
	assert_int_equal(system(cmd), 0);
	unlink(scene);
	free(scene);
	unlink(fifo);
	unlink(link);
	unlink(dev);
	free(fifo);
	free(link);
	free(dev);
	free(target);
}

/* A second SIGINT while the image is being written waited for nothing:
 * the program ended with OUT.exr.tmpPID.N left behind, against "a failed
 * run leaves no partial file". The command with faults
 * (tests/support/ajar_faults.c) raises two SIGINTs when the EXR's
 * temporary file is complete but not yet renamed: the program ends by the
 * second (as a second Ctrl-C does) once that file is whole, writes no
 * other output, and leaves no temporary file. */
static void test_second_sigint_in_write(void **state)
{
	char *exr = test_tmp("sig.exr"), *png = test_tmp("sig.png");
	assert_int_equal(setenv("AJAR_TEST_SIGNALS_IN_WRITE", "2", 1), 0);
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		int null = open("/dev/null", O_WRONLY);
		if (null >= 0)
			dup2(null, 2);
		execl(test_ajar_faults_bin(), "ajar", "render", CORNELL, "-o", exr, "--png", png, "--size", "8x8", "--spp",
		      "1", "-q", (char *)NULL);
		_exit(127);
	}
	assert_int_equal(unsetenv("AJAR_TEST_SIGNALS_IN_WRITE"), 0);
	int status;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
	assert_int_equal(count_tmp_entries(), 1); /* the EXR, whole; no PNG, no temporary */
	float *px;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(exr, &px, &w, &h), AJAR_OK);
	assert_int_equal(w, 8);
	free(px);
	assert_false(file_exists(png));
	unlink(exr);
	free(exr);
	free(png);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_help_version),
		cmocka_unit_test(test_usage_errors),
		cmocka_unit_test(test_bad_scenes),
		cmocka_unit_test(test_info),
		cmocka_unit_test(test_info_lights),
		cmocka_unit_test(test_tiny_render),
		cmocka_unit_test(test_cl_options),
		cmocka_unit_test(test_sigint),
		cmocka_unit_test(test_special_outputs),
		cmocka_unit_test(test_second_sigint_in_write),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
