/* test_cli_scene.c — what the `ajar` program changes in a scene from the
 * command line: --portals (marked, auto, none) and --portals-out through
 * `ajar info` and `ajar render`, a sky (--sky FILE, --sky-color,
 * --sky-strength, --sky-rotation) and a sun (--sun) in place of what an
 * exporter leaves out; their usage errors (exit 1, the option named) and a
 * sky file that is missing (exit 2, the file named). */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ajar.h"
#include "testutil.h"

typedef struct {
	int code;
	char *out, *err;
} Result;

static Result run(const char *const *args)
{
	char *out = test_tmp("stdout.txt"), *err = test_tmp("stderr.txt");
	int code = test_wait_exit(test_spawn(test_ajar_bin(), args, out, err));
	Result r = {code, test_read_file(out, NULL), test_read_file(err, NULL)};
	unlink(out);
	unlink(err);
	free(out);
	free(err);
	return r;
}

static void expect(const char *const *args, int code, const char *in_out, const char *in_err)
{
	Result r = run(args);
	if (r.code != code || (in_out && !strstr(r.out, in_out)) || (in_err && !strstr(r.err, in_err)))
		print_error("ajar %s %s ...: exit %d\nstdout:\n%s\nstderr:\n%s\n", args[0], args[1] ? args[1] : "", r.code,
			    r.out, r.err);
	assert_int_equal(r.code, code);
	if (in_out)
		assert_non_null(strstr(r.out, in_out));
	if (in_err)
		assert_non_null(strstr(r.err, in_err));
	free(r.out);
	free(r.err);
}

static int count(const char *hay, const char *needle)
{
	int n = 0;
	for (const char *p = hay; (p = strstr(p, needle)); p += strlen(needle))
		n++;
	return n;
}

static void test_cli_portals(void **state)
{
	(void)state;
	const char *da = SCENE("door-ajar/door-ajar.gltf"), *lr = SCENE("living-room/living-room.gltf");
	/* info: a scene that marks portals is not searched unless asked. */
	expect((const char *[]){"info", lr, NULL}, 0, "found:        not searched", NULL);
	char *gltf = test_tmp("found.gltf");
	Result r = run((const char *[]){"info", lr, "--portals", "auto", "--portals-out", gltf, NULL});
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, "found:        4 portals over openings"));
	assert_int_equal(count(r.out, "  ["), 4);
	free(r.out);
	free(r.err);
	/* The file: four nodes marked as portals, an embedded buffer. */
	char *text = test_read_file(gltf, NULL);
	assert_int_equal(count(text, "\"portal\": true"), 4);
	assert_non_null(strstr(text, "data:application/octet-stream;base64,"));
	free(text);
	/* render: found, said so, written; none: nothing found. */
	char *exr = test_tmp("o.exr");
	unlink(gltf);
	expect((const char *[]){"render", da, "-o", exr, "--size", "8x8", "--spp", "1", "--portals", "auto",
				"--portals-out", gltf, NULL},
	       0, NULL, "found 2 portals over openings"); /* the gap and the slit over the leaf */
	struct stat st;
	assert_int_equal(stat(gltf, &st), 0);
	Result q = run((const char *[]){"render", da, "-o", exr, "--size", "8x8", "--spp", "1", "--portals", "none", NULL});
	assert_int_equal(q.code, 0);
	assert_null(strstr(q.err, "found"));
	free(q.out);
	free(q.err);
	expect((const char *[]){"render", da, "-o", exr, "--portals", "some", NULL}, 1, NULL,
	       "--portals: 'some' is not one of marked, auto, none");
	expect((const char *[]){"info", da, "--portals", NULL}, 1, NULL, "--portals needs a value");
	free(gltf);
	free(exr);
}

static void test_cli_sky(void **state)
{
	(void)state;
	const char *da = SCENE("door-ajar/door-ajar.gltf"), *sky = SCENE("skies/forest.exr");
	expect((const char *[]){"info", da, NULL}, 0, "environment:  none", NULL);
	expect((const char *[]){"info", da, "--sky-color", "0.2,0.3,0.4", "--sky-strength", "2", NULL}, 0,
	       "environment:  colour", NULL);
	expect((const char *[]){"info", da, "--sky", sky, "--sky-rotation", "45", NULL}, 0, "environment:  image", NULL);
	/* A sun: a directional light toward elevation 30, azimuth 90 (+X). */
	expect((const char *[]){"info", da, "--sun", "30,90,100000", NULL}, 0,
	       "[0] directional toward (-0.866, -0.500, ", NULL);
	/* Usage errors and bad input. */
	expect((const char *[]){"info", da, "--sky-strength", "2", NULL}, 1, NULL,
	       "--sky-strength needs --sky FILE or --sky-color R,G,B");
	expect((const char *[]){"info", da, "--sky", sky, "--sky-color", "1,1,1", NULL}, 1, NULL, "give one sky");
	expect((const char *[]){"info", da, "--sky-color", "1,1", NULL}, 1, NULL, "is not R,G,B");
	expect((const char *[]){"info", da, "--sky-color", "1,-1,1", NULL}, 1, NULL, "out of range");
	expect((const char *[]){"info", da, "--sun", "95,0,1000", NULL}, 1, NULL, "--sun: 95 is out of range");
	expect((const char *[]){"info", da, "--sky", "no-such-sky.exr", NULL}, 2, NULL, "no-such-sky.exr");
	/* A render under a command-line sky: the window room's own colour sky
	 * replaced by a black one gives a black image. */
	char *exr = test_tmp("sky.exr");
	expect((const char *[]){"render", SCENE("window-room/window-room.gltf"), "-o", exr, "--size", "8x8", "--spp",
				"4", "--sky-color", "0,0,0", NULL},
	       0, NULL, NULL);
	float *px;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(exr, &px, &w, &h), AJAR_OK);
	double sum = 0;
	for (uint32_t i = 0; i < 4 * w * h; i++)
		sum += i % 4 == 3 ? 0.0 : px[i];
	assert_true(sum == 0.0);
	free(px);
	expect((const char *[]){"render", SCENE("window-room/window-room.gltf"), "-o", exr, "--size", "8x8", "--spp",
				"4", "--sky-color", "1,1,1", "--sky-strength", "0.5", NULL},
	       0, NULL, NULL);
	assert_int_equal(ajar_read_exr(exr, &px, &w, &h), AJAR_OK);
	sum = 0;
	for (uint32_t i = 0; i < 4 * w * h; i++)
		sum += i % 4 == 3 ? 0.0 : px[i];
	assert_true(sum > 0.0);
	free(px);
	free(exr);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cli_portals),
		cmocka_unit_test(test_cli_sky),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
