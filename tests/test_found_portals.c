/* test_found_portals.c — portals found without markup, through the library
 * on the OpenCL device and through the `ajar` program.
 *
 * - The integrators agree on shipped scenes rendered with found portals
 *   (ajar_options.portals = AJAR_PORTALS_FOUND, the marked ones ignored):
 *   window-room (a constant sky through a window), window-room-forest (a
 *   sky image: the found window's sky table), atrium-forest (a roof
 *   opening) and door-ajar (a door's gap, an emitter behind). Statistic as
 *   test_integrators: image means of 16 batches, within 5 combined
 *   standard errors.
 * - A renderer's found portals are ajar_scene_find_portals's, bit for bit,
 *   on each of two devices (POCL_DEVICES="pthread pthread"): the search
 *   runs on the host, before any device.
 * - The command line: --portals, --portals-out, --sky, --sky-color,
 *   --sky-strength, --sky-rotation, --sun through `ajar info` and `ajar
 *   render`, their usage errors (exit 1) and a sky file that is missing
 *   (exit 2, named). */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ajar.h"
#include "testutil.h"

#define BATCHES 16

typedef struct {
	double mean[3], se[3];
} Estimate;

static void estimate(ajar_scene *s, ajar_integrator integ, uint32_t w, uint32_t h, uint32_t spp, Estimate *e)
{
	ajar_options o;
	ajar_renderer *r;
	ajar_options_default(&o);
	o.width = w;
	o.height = h;
	o.spp = spp;
	o.integrator = integ;
	o.max_depth = 12;
	o.portals = AJAR_PORTALS_FOUND;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	uint32_t n = 0;
	assert_int_equal(ajar_renderer_found_portals(r, NULL, 0, &n, NULL), AJAR_OK);
	assert_true(n > 0);
	float *img = malloc(sizeof(float) * 4 * w * h);
	double s1[3] = {0}, s2[3] = {0};
	for (int b = 0; b < BATCHES; b++) {
		assert_int_equal(ajar_renderer_restart(r, 200 + b), AJAR_OK);
		if (ajar_renderer_render(r, NULL, NULL) != AJAR_OK)
			fail_msg("%s", ajar_last_error());
		assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
		for (int c = 0; c < 3; c++) {
			double m = 0;
			for (uint32_t i = 0; i < w * h; i++)
				m += img[4 * i + c];
			m /= w * h;
			s1[c] += m;
			s2[c] += m * m;
		}
	}
	for (int c = 0; c < 3; c++) {
		e->mean[c] = s1[c] / BATCHES;
		e->se[c] = sqrt(fmax(0, (s2[c] - s1[c] * s1[c] / BATCHES) / (BATCHES - 1)) / BATCHES);
	}
	free(img);
	ajar_renderer_destroy(&r);
}

static void agree(const char *what, const Estimate *a, const Estimate *b)
{
	for (int c = 0; c < 3; c++) {
		double se = sqrt(a->se[c] * a->se[c] + b->se[c] * b->se[c]);
		double z = se > 0 ? (a->mean[c] - b->mean[c]) / se : 0;
		print_message("%s, channel %d: %.5f +- %.5f vs %.5f +- %.5f (%+.1f se)\n", what, c, a->mean[c], a->se[c],
			      b->mean[c], b->se[c], z);
		if (fabs(z) > 5)
			fail_msg("%s, channel %d: the integrators differ by %.1f standard errors", what, c, z);
	}
}

static void compare(const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	Estimate pt, bdpt, portal;
	char what[256];
	estimate(s, AJAR_INTEGRATOR_PT, w, h, spp_pt, &pt);
	estimate(s, AJAR_INTEGRATOR_BDPT, w, h, spp_bdpt, &bdpt);
	estimate(s, AJAR_INTEGRATOR_PORTAL, w, h, spp_bdpt, &portal);
	snprintf(what, sizeof what, "%s (found portals) bdpt vs pt", path);
	agree(what, &bdpt, &pt);
	snprintf(what, sizeof what, "%s (found portals) portal vs pt", path);
	agree(what, &portal, &pt);
	snprintf(what, sizeof what, "%s (found portals) portal vs bdpt", path);
	agree(what, &portal, &bdpt);
	ajar_scene_destroy(&s);
}

static void test_integrators_window_room(void **state)
{
	(void)state;
	compare(SCENE("window-room/window-room.gltf"), 32, 32, 64, 16);
	compare(SCENE("window-room-forest/window-room-forest.gltf"), 32, 32, 64, 16);
}

static void test_integrators_atrium(void **state)
{
	(void)state;
	compare(SCENE("atrium-forest/atrium-forest.gltf"), 24, 24, 64, 16);
}

static void test_integrators_door_ajar(void **state)
{
	(void)state;
	compare(SCENE("door-ajar/door-ajar.gltf"), 24, 24, 512, 128);
}

/* The same portals from the scene and from a renderer on each device. */
static void test_same_portals_on_devices(void **state)
{
	(void)state;
	ajar_device_info dev[8];
	uint32_t ndev = 0;
	assert_int_equal(ajar_devices(dev, 8, &ndev), AJAR_OK);
	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("living-room-forest/living-room-forest.gltf"), &s), AJAR_OK);
	ajar_portal want[16], got[16];
	uint32_t n = 0;
	assert_int_equal(ajar_scene_find_portals(s, want, 16, &n, NULL), AJAR_OK);
	assert_true(n >= 4);
	uint32_t tried = 0;
	for (uint32_t d = 0; d < ndev && d < 2; d++) {
		ajar_options o;
		ajar_options_default(&o);
		o.width = o.height = 8;
		o.spp = 1;
		o.portals = AJAR_PORTALS_FOUND;
		o.device = dev[d].selector;
		ajar_renderer *r;
		if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
			fail_msg("%s", ajar_last_error());
		assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
		uint32_t m = 0;
		double seconds = -1;
		assert_int_equal(ajar_renderer_found_portals(r, got, 16, &m, &seconds), AJAR_OK);
		assert_int_equal(m, n);
		assert_true(seconds >= 0.0);
		assert_memory_equal(got, want, sizeof *got * n);
		print_message("device %s: the same %u portals\n", dev[d].selector, m);
		ajar_renderer_destroy(&r);
		tried++;
	}
	assert_true(tried >= 1);
	/* Marked portals in use: none found. */
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = 8;
	o.spp = 1;
	ajar_renderer *r;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	uint32_t m = 9;
	assert_int_equal(ajar_renderer_found_portals(r, got, 16, &m, NULL), AJAR_OK);
	assert_int_equal(m, 0);
	ajar_renderer_destroy(&r);
	o.portals = (ajar_portals)7;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);
}

/* ---- The command line ------------------------------------------------------ */

static char *tmpdir;

typedef struct {
	int code;
	char *out, *err;
} Result;

static char *slurp(const char *path)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return calloc(1, 1);
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	char *s = malloc((size_t)n + 1);
	assert_non_null(s);
	s[fread(s, 1, (size_t)n, f)] = '\0';
	fclose(f);
	return s;
}

static Result run(const char *const *args)
{
	const char *argv[40];
	int n = 0;
	argv[n++] = test_ajar_bin();
	while (args[n - 1] && n < 39) {
		argv[n] = args[n - 1];
		n++;
	}
	argv[n] = NULL;
	char *out = test_path(tmpdir, "stdout.txt"), *err = test_path(tmpdir, "stderr.txt");
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		int fo = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644), fe = open(err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
		if (fo < 0 || fe < 0 || dup2(fo, 1) < 0 || dup2(fe, 2) < 0)
			_exit(127);
		execv(argv[0], (char *const *)argv);
		_exit(127);
	}
	int status;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status));
	Result r = {WEXITSTATUS(status), slurp(out), slurp(err)};
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
	char *gltf = test_path(tmpdir, "found.gltf");
	Result r = run((const char *[]){"info", lr, "--portals", "auto", "--portals-out", gltf, NULL});
	assert_int_equal(r.code, 0);
	assert_non_null(strstr(r.out, "found:        4 portals over openings"));
	assert_int_equal(count(r.out, "  ["), 4);
	free(r.out);
	free(r.err);
	/* The file: four nodes marked as portals, an embedded buffer. */
	char *text = slurp(gltf);
	assert_int_equal(count(text, "\"portal\": true"), 4);
	assert_non_null(strstr(text, "data:application/octet-stream;base64,"));
	free(text);
	/* render: found, said so, written; none: nothing found. */
	char *exr = test_path(tmpdir, "o.exr");
	unlink(gltf);
	expect((const char *[]){"render", da, "-o", exr, "--size", "8x8", "--spp", "1", "--portals", "auto",
				"--portals-out", gltf, NULL},
	       0, NULL, "found 1 portal over openings");
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
	char *exr = test_path(tmpdir, "sky.exr");
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

static int setup(void **state)
{
	(void)state;
	return test_tmpdir_setup(&tmpdir);
}

static int teardown(void **state)
{
	(void)state;
	return test_tmpdir_teardown(&tmpdir);
}

int main(void)
{
	/* Two PoCL devices, for the same portals on each. */
	setenv("POCL_DEVICES", "pthread pthread", 0);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cli_portals),
		cmocka_unit_test(test_cli_sky),
		cmocka_unit_test(test_same_portals_on_devices),
		cmocka_unit_test(test_integrators_window_room),
		cmocka_unit_test(test_integrators_atrium),
		cmocka_unit_test(test_integrators_door_ajar),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
