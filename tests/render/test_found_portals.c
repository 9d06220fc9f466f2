/* test_found_portals.c — portals found without markup, through the library
 * on the OpenCL device (the command line's options: tests/api/test_cli_scene.c).
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
 *   runs on the host, before any device. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "batch_means.h"
#include "testutil.h"

#define BATCHES 16

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
	batch_means(r, w, h, BATCHES, 200, e);
	ajar_renderer_destroy(&r);
}

static void compare(const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	Estimate pt, bdpt, portal;
	char what[256];
	snprintf(what, sizeof what, "%s (found portals)", path);
	estimate(s, AJAR_INTEGRATOR_PT, w, h, spp_pt, &pt);
	estimate(s, AJAR_INTEGRATOR_BDPT, w, h, spp_bdpt, &bdpt);
	estimate(s, AJAR_INTEGRATOR_PORTAL, w, h, spp_bdpt, &portal);
	estimates_agree(what, "bdpt", &bdpt, "pt", &pt);
	estimates_agree(what, "portal", &portal, "pt", &pt);
	estimates_agree(what, "portal", &portal, "bdpt", &bdpt);
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

int main(void)
{
	/* Two PoCL devices, for the same portals on each. */
	setenv("POCL_DEVICES", "pthread pthread", 0);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_same_portals_on_devices),
		cmocka_unit_test(test_integrators_window_room),
		cmocka_unit_test(test_integrators_atrium),
		cmocka_unit_test(test_integrators_door_ajar),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
