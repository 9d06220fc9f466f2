/* test_noise.c — stopping at a noise level (ajar_options.noise, --noise),
 * through the library on the OpenCL device and through the `ajar` program.
 *
 * - On the Cornell box (32 x 32), whose converged image a long render
 *   gives: a render stopped at 5% by pt and by bdpt (splats counted) has,
 *   against that reference (its own noise subtracted), a relative error
 *   within 1.3 times the bound and not under 0.6 times it (it stopped near
 *   the target, not far past it); its own last estimate is at most the
 *   target; the progress callback saw estimates, unknown (< 0) at first.
 * - A sample budget that comes first ends the render as before, with an
 *   estimate above the target.
 * - Options out of range are refused; the command line's --noise renders,
 *   says the estimate, and refuses 0 and 100 (exit 1). */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ajar.h"
#include "testutil.h"

#define SIZE 32

static ajar_renderer *make(ajar_scene *s, ajar_integrator integ, uint32_t spp, double noise, uint32_t seed)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = SIZE;
	o.spp = spp;
	o.noise = noise;
	o.integrator = integ;
	o.seed = seed;
	ajar_renderer *r;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	return r;
}

typedef struct {
	int calls, unknown, known;
	double last;
} Seen;

static int on_progress(const ajar_progress *p, void *user)
{
	Seen *s = user;
	s->calls++;
	if (p->noise < 0)
		s->unknown++;
	else
		s->known++, s->last = p->noise;
	return 0;
}

/* mean over pixels and channels of (a - ref)^2 / (ref^2 + (0.1 mean ref)^2). */
static double rel_mse(const float *a, const float *ref)
{
	double mean = 0.0, e = 0.0;
	for (int i = 0; i < SIZE * SIZE; i++)
		for (int c = 0; c < 3; c++)
			mean += ref[4 * i + c];
	mean /= 3.0 * SIZE * SIZE;
	for (int i = 0; i < SIZE * SIZE; i++)
		for (int c = 0; c < 3; c++) {
			double d = (double)a[4 * i + c] - ref[4 * i + c], r = ref[4 * i + c];
			e += d * d / (r * r + 0.01 * mean * mean);
		}
	return e / (3.0 * SIZE * SIZE);
}

static void test_stops_within_bound(void **state)
{
	(void)state;
	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	/* The reference: 8192 spp of pt, its own error estimated as well. */
	float *ref = malloc(sizeof(float) * 4 * SIZE * SIZE), *img = malloc(sizeof(float) * 4 * SIZE * SIZE);
	ajar_renderer *r = make(s, AJAR_INTEGRATOR_PT, 8192, 1e-4, 99);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), 8192); /* the budget came first */
	double ref_noise = ajar_renderer_noise(r);
	assert_true(ref_noise > 1e-4 && ref_noise < 0.02);
	assert_int_equal(ajar_renderer_image(r, ref, NULL, NULL), AJAR_OK);
	ajar_renderer_destroy(&r);
	print_message("reference: 8192 spp, estimated error %.4f\n", ref_noise);

	static const ajar_integrator integ[] = {AJAR_INTEGRATOR_PT, AJAR_INTEGRATOR_BDPT};
	const double target = 0.05;
	for (int k = 0; k < 2; k++) {
		for (uint32_t seed = 1; seed <= 2; seed++) {
			r = make(s, integ[k], 0, target, seed);
			Seen seen = {0, 0, 0, -1};
			assert_int_equal(ajar_renderer_render(r, on_progress, &seen), AJAR_OK);
			double est = ajar_renderer_noise(r);
			assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
			double truth = sqrt(fmax(0.0, rel_mse(img, ref) - ref_noise * ref_noise));
			print_message("%s, seed %u: stopped at %u spp, estimate %.4f, against the reference %.4f "
				      "(progress: %d unknown, %d known)\n",
				      k ? "bdpt" : "pt", seed, ajar_renderer_spp(r), est, truth, seen.unknown, seen.known);
			assert_true(est > 0.0 && est <= target);
			assert_true(seen.unknown > 0 && seen.known > 0);
			if (truth > 1.3 * target)
				fail_msg("the error against the reference, %.4f, exceeds 1.3 x the bound %.2f", truth, target);
			if (truth < 0.6 * target)
				fail_msg("the error against the reference, %.4f, is far under the bound %.2f: stopped late",
					 truth, target);
			ajar_renderer_destroy(&r);
		}
	}
	/* A budget that comes first: 4 spp, far above 5% noise. */
	r = make(s, AJAR_INTEGRATOR_PT, 16, target, 3);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), 16);
	assert_true(ajar_renderer_noise(r) > target);
	ajar_renderer_destroy(&r);
	/* Out of range. */
	ajar_options o;
	ajar_options_default(&o);
	o.noise = 1.5;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	o.noise = -0.1;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	o.noise = 0.0;
	o.spp = 0;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	free(ref);
	free(img);
	ajar_scene_destroy(&s);
}

/* Runs ajar with args; returns the exit code, stderr in err (malloc'ed). */
static int run(const char *const *args, char **err)
{
	char *path = test_tmp("stderr.txt");
	int code = test_wait_exit(test_spawn(test_ajar_bin(), args, NULL, path));
	*err = test_read_file(path, NULL);
	free(path);
	return code;
}

static void test_cli_noise(void **state)
{
	(void)state;
	char *exr = test_tmp("n.exr"), *err;
	assert_int_equal(run((const char *[]){"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "16x16",
					      "--noise", "10", NULL},
			     &err),
			 0);
	assert_non_null(strstr(err, "until noise 10%"));
	assert_non_null(strstr(err, "estimated error"));
	free(err);
	assert_int_equal(run((const char *[]){"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--noise", "0", NULL},
			     &err),
			 1);
	assert_non_null(strstr(err, "--noise: 0 is not a percentage"));
	free(err);
	assert_int_equal(
		run((const char *[]){"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--noise", "100", NULL}, &err), 1);
	free(err);
	free(exr);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_stops_within_bound),
		cmocka_unit_test(test_cli_noise),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
