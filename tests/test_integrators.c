/* test_integrators.c — the integrators agree on every shipped scene when
 * run through the library on the OpenCL device (PoCL by default).
 *
 * Statistic: the image mean per channel from B = 16 independent batches
 * (ajar_renderer_restart with a new seed); the batch spread gives the
 * standard error of each integrator's mean, and two integrators must agree
 * within 5 combined standard errors. With 15 degrees of freedom a false
 * alarm is ~2e-4 per comparison. A bias of 1% is caught where the
 * combined standard error is below 0.2% of the mean (window-room; the
 * printout shows it); elsewhere the sample counts below, kept small for
 * CI, give 0.3% (cornell), 0.5-0.6% (living-room, bathroom: the portal
 * integrator's noise) and 1% (door-ajar: all light comes through the gap
 * and pt is very noisy), so biases of 1.5-5% are caught there. The
 * Cornell box's absolute level is checked more closely by test_render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ajar.h"
#include "testutil.h"

#define BATCHES 16

typedef struct {
	double mean[3], se[3];
} Estimate;

static void estimate(ajar_scene *s, ajar_integrator integ, uint32_t w, uint32_t h, uint32_t spp, uint32_t depth,
		     Estimate *e)
{
	ajar_options o;
	ajar_renderer *r;
	ajar_options_default(&o);
	o.width = w;
	o.height = h;
	o.spp = spp;
	o.integrator = integ;
	o.max_depth = depth;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float *img = malloc(sizeof(float) * 4 * w * h);
	double s1[3] = {0}, s2[3] = {0};
	for (int b = 0; b < BATCHES; b++) {
		assert_int_equal(ajar_renderer_restart(r, 100 + b), AJAR_OK);
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
		print_message("%s, channel %d: %.5f +- %.5f vs %.5f +- %.5f (%+.1f se, se %.2f%% of the mean)\n",
			      what, c, a->mean[c], a->se[c], b->mean[c], b->se[c], z,
			      100 * se / fmax(fabs(b->mean[c]), 1e-12));
		if (fabs(z) > 5)
			fail_msg("%s, channel %d: the integrators differ by %.1f standard errors", what, c, z);
	}
}

static void compare_scene(ajar_scene *s, const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	Estimate pt, bdpt, portal;
	char what[256];
	const uint32_t depth = 12;
	estimate(s, AJAR_INTEGRATOR_PT, w, h, spp_pt, depth, &pt);
	estimate(s, AJAR_INTEGRATOR_BDPT, w, h, spp_bdpt, depth, &bdpt);
	snprintf(what, sizeof what, "%s bdpt vs pt", path);
	agree(what, &bdpt, &pt);
	estimate(s, AJAR_INTEGRATOR_PORTAL, w, h, spp_bdpt, depth, &portal);
	snprintf(what, sizeof what, "%s portal vs pt", path);
	agree(what, &portal, &pt);
	snprintf(what, sizeof what, "%s portal vs bdpt", path);
	agree(what, &portal, &bdpt);
	ajar_scene_destroy(&s);
}

static void compare(const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	compare_scene(s, path, w, h, spp_pt, spp_bdpt);
}

/* `path` with a directional light along `dir` (intensity in lux), and a
 * point light at p and a spot at q pointing down (candela), all in
 * glTF's units (KHR_lights_punctual). */
static void compare_punctual(const char *path, const char *what, const float dir[3], float lux, const float p[3],
			     const float q[3], float cd, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	for (int k = 0; k < 3; k++)
		l.direction[k] = dir[k];
	l.intensity = lux;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	for (int k = 0; k < 3; k++)
		l.position[k] = p[k];
	l.color[2] = 0.5f;
	l.intensity = cd;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_SPOT;
	for (int k = 0; k < 3; k++)
		l.position[k] = q[k];
	l.direction[0] = 0.1f;
	l.direction[1] = -1.0f;
	l.direction[2] = 0.2f;
	l.inner_cone = 0.3f;
	l.outer_cone = 0.6f;
	l.intensity = 2 * cd;
	l.range = 4.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	compare_scene(s, what, w, h, spp_pt, spp_bdpt);
}

static void test_cornell(void **state) { compare(SCENE("cornell/cornell.gltf"), 32, 32, 32, 8); }
static void test_window_room(void **state) { compare(SCENE("window-room/window-room.gltf"), 32, 32, 64, 16); }
static void test_living_room(void **state) { compare(SCENE("living-room/living-room.gltf"), 32, 18, 64, 16); }
static void test_bathroom(void **state) { compare(SCENE("bathroom/bathroom.gltf"), 24, 24, 32, 8); }
static void test_door_ajar(void **state) { compare(SCENE("door-ajar/door-ajar.gltf"), 24, 24, 512, 128); }

/* The Cornell box lit by its emitter, the sun through its open side, a
 * point light and a spot (no portals: the sun's light subpaths start on
 * the scene's disk). */
static void test_cornell_punctual(void **state)
{
	const float sun[3] = {0.2f, -0.5f, 0.8f}, p[3] = {0.15f, 0.45f, 0.3f}, q[3] = {0.4f, 0.5f, 0.25f};
	compare_punctual(SCENE("cornell/cornell.gltf"), "cornell + punctual lights", sun, 683.0f, p, q, 0.1f * 683.0f,
			 32, 32, 32, 8);
}

/* The window room lit by the sun through its window (light subpaths start
 * on the portal), a point light and a spot, besides its sky. */
static void test_window_room_punctual(void **state)
{
	const float sun[3] = {0.3f, -0.5f, 0.8f}, p[3] = {1.0f, 2.2f, 2.0f}, q[3] = {3.0f, 2.5f, 1.5f};
	compare_punctual(SCENE("window-room/window-room.gltf"), "window-room + sun + punctual lights", sun,
			 683.0f * 10.0f, p, q, 683.0f, 32, 32, 64, 16);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cornell),
		cmocka_unit_test(test_window_room),
		cmocka_unit_test(test_living_room),
		cmocka_unit_test(test_bathroom),
		cmocka_unit_test(test_door_ajar),
		cmocka_unit_test(test_cornell_punctual),
		cmocka_unit_test(test_window_room_punctual),
	};
	return cmocka_run_group_tests_name("integrators", tests, NULL, NULL);
}
