/* test_instances_render.c — an instanced scene renders the image of its
 * flattened copy on the OpenCL device, with every integrator:
 * tests/support/instance_scenes.c's room (balls under non-uniform and
 * mirroring scales, nested nodes, EXT_mesh_gpu_instancing; lamps whose
 * emitting quads are flattened copies beside instanced shades; a window
 * portal under a white sky), loaded with every mesh kept as instances and
 * with every copy flattened.
 *
 * Statistic: B = 8 batches, each both scenes at the same seed; the
 * batches' differences of image means, per channel, must average to zero
 * within 5 of their standard errors (paired: both renders follow nearly
 * the same paths, so the test is far tighter than two independent
 * renders' noise), and each image mean within 5 standard errors of the
 * other's by the batches' own spread. The general program renders both
 * (AJAR_KERNEL_FEATURES=all), with its instance code either way. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "instance_scenes.h"
#include "scene/gltf.h"
#include "testutil.h"

#define BATCHES 8
#define SIZE 32

/* Image means per batch of `s` rendered by `integ` at spp (seeds 100 + b). */
static void batch_means(ajar_scene *s, ajar_integrator integ, uint32_t spp, double mean[BATCHES][3])
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = SIZE;
	o.spp = spp;
	o.integrator = integ;
	o.max_depth = 8;
	ajar_renderer *r;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float *img = malloc(sizeof *img * 4 * SIZE * SIZE);
	for (int b = 0; b < BATCHES; b++) {
		assert_int_equal(ajar_renderer_restart(r, 100 + (uint32_t)b), AJAR_OK);
		if (ajar_renderer_render(r, NULL, NULL) != AJAR_OK)
			fail_msg("%s", ajar_last_error());
		assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
		for (int c = 0; c < 3; c++) {
			double sum = 0;
			for (int i = 0; i < SIZE * SIZE; i++)
				sum += img[4 * i + c];
			mean[b][c] = sum / (SIZE * SIZE);
		}
	}
	free(img);
	ajar_renderer_destroy(&r);
}

static void compare(ajar_integrator integ, const char *name, uint32_t spp)
{
	write_instance_scene(test_dir, "room");
	char *path = test_path(test_dir, "room.gltf");
	Scene *si = NULL, *sf = NULL;
	assert_int_equal(gltf_load_instancing(path, 0, GLTF_INSTANCING_ALL, &si), AJAR_OK);
	assert_int_equal(gltf_load_instancing(path, 0, GLTF_INSTANCING_NONE, &sf), AJAR_OK);
	assert_int_equal(si->ninstances, 11);
	double mi[BATCHES][3], mf[BATCHES][3];
	batch_means(si, integ, spp, mi);
	batch_means(sf, integ, spp, mf);
	for (int c = 0; c < 3; c++) {
		double d = 0, d2 = 0, a = 0, a2 = 0, f = 0, f2 = 0;
		for (int b = 0; b < BATCHES; b++) {
			double x = mi[b][c] - mf[b][c];
			d += x / BATCHES;
			d2 += x * x / BATCHES;
			a += mi[b][c] / BATCHES;
			a2 += mi[b][c] * mi[b][c] / BATCHES;
			f += mf[b][c] / BATCHES;
			f2 += mf[b][c] * mf[b][c] / BATCHES;
		}
		double se_d = sqrt(fmax(d2 - d * d, 0.0) / (BATCHES - 1));
		double se = sqrt((fmax(a2 - a * a, 0.0) + fmax(f2 - f * f, 0.0)) / (BATCHES - 1));
		printf("  %-6s channel %d: instanced %.5f, flattened %.5f; paired difference %+.2e (se %.1e), "
		       "independent se %.1e\n",
		       name, c, a, f, d, se_d, se);
		assert_true(a > 0.0);
		assert_true(fabs(d) <= 5.0 * se_d + 1e-7 * f);
		assert_true(fabs(a - f) <= 5.0 * se);
	}
	scene_free(si);
	scene_free(sf);
	free(path);
}

static void test_pt(void **state) { compare(AJAR_INTEGRATOR_PT, "pt", 16); }
static void test_bdpt(void **state) { compare(AJAR_INTEGRATOR_BDPT, "bdpt", 8); }
static void test_portal(void **state) { compare(AJAR_INTEGRATOR_PORTAL, "portal", 8); }

int main(void)
{
	/* Both scenes through the general program, one per integrator: half
	 * the cold compiles (the image is the same, src/device/README.md). */
	setenv("AJAR_KERNEL_FEATURES", "all", 1);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_pt),
		cmocka_unit_test(test_bdpt),
		cmocka_unit_test(test_portal),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
