/* test_lights_sample.c — next-event sampling (kernels/light/lights.h,
 * kernels/light/env_portal.h): light_sample's solid-angle density against
 * light_pdf_w with emitters, a constant sky and a sky image mixed, and the
 * sky sampled through portals (overlapping, tiny, facing the wrong way,
 * without sky behind, a point so close that a triangle covers more than
 * pi sr, a window of more triangles than the sampler keeps weights for);
 * chi-square against densities integrated numerically. Sky images through
 * planar portals: test_lights_sky_planes. */
#include "lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_light_sample_emitters(void **state)
{
	rng_state = 14;
	Lit l;
	build_light_scene(&l);
	lit_build(&l);
	assert_int_equal(l.lt.nemitters, 5);
	assert_float_equal(l.lt.env_pdf_select, 0.0f, 0.0f);
	check_light_sample(&l, v3(0, 0, 0), v3(0, 1, 0), "emitters");
	lit_free(&l);
}

static void test_light_sample_env_color(void **state)
{
	rng_state = 15;
	Lit l;
	build_light_scene(&l);
	scene_set_env_color(l.s, v3(0.02f, 0.03f, 0.05f));
	lit_build(&l);
	assert_true(l.lt.env_pdf_select > 0.2f && l.lt.env_pdf_select < 0.8f);
	check_light_sample(&l, v3(0, 0, 0), v3(0, 1, 0), "+ env colour");
	lit_free(&l);
}

static void test_light_sample_env_image(void **state)
{
	rng_state = 16;
	Lit l;
	build_light_scene(&l);
	assert_int_equal(scene_set_env_image(l.s, 40, 20, synthetic_sky(40, 20), 0.02f), AJAR_OK);
	lit_build(&l);
	assert_true(l.lt.env_pdf_select > 0.1f && l.lt.env_pdf_select < 0.9f);
	check_light_sample(&l, v3(0.1f, 0.2f, 0.05f), v3(0, 1, 0), "+ env image");
	lit_free(&l);
}

/* Environment sampling through portals (kernels/light/env_portal.h) from x =
 * (0.1, 0.2, 0.05) among the emitters above and an environment image:
 * a window in front of x, a second one behind it that overlaps it as seen
 * from x, a triangle so far away that it is sampled by area, one that
 * shows x no sky (x is on its sky side) and one with no sky behind it.
 * The sky sides are set by hand here; src/prepare/portal_flux.c finds them in real
 * scenes (test_portal.c). */
static void test_light_sample_env_portals(void **state)
{
	rng_state = 17;
	Lit l;
	build_light_scene(&l);
	assert_int_equal(scene_set_env_image(l.s, 40, 20, synthetic_sky(40, 20), 0.02f), AJAR_OK);
	add_window_portals(&l);
	V3 x = v3(0.1f, 0.2f, 0.05f);
	int side[6] = {0, 0, 0, 0, 0, 0};
	for (int j = 0; j < 5; j++) { /* the sky beyond each from x, but for the fourth */
		PortalTri *pt = &l.s->portals[j];
		float dn = v3_dot(v3_sub(x, pt->p0), pt->n);
		side[j] = j == 4 ? (dn > 0 ? 1 : -1) : (dn > 0 ? -1 : 1);
		pt->env_side = side[j];
	}
	l.s->portals[5].env_side = 0;
	/* What x sees of them: the far one below PORTAL_SA_MIN, the last two
	 * nothing. */
	float om[6];
	for (int j = 0; j < 6; j++)
		om[j] = portal_env_solid_angle(&l.s->portals[j], x);
	assert_true(om[0] > 0.1f && om[1] > 0.1f && om[2] > 0.05f && om[3] > 0.0f);
	assert_true(om[3] < PORTAL_SA_MIN && om[4] == 0.0f && om[5] == 0.0f);
	/* The solid angle of the window quad agrees with a direct count. */
	double hits = 0;
	for (int k = 0; k < 200000; k++) {
		V3 d = sample_uniform_sphere(rnd(), rnd());
		hits += portal_tri_crossed(x, d, AJAR_INF, l.s->portals[0].p0, l.s->portals[0].p1, l.s->portals[0].p2) +
			portal_tri_crossed(x, d, AJAR_INF, l.s->portals[1].p0, l.s->portals[1].p1, l.s->portals[1].p2);
	}
	double quad = 4 * M_PI * hits / 200000;
	printf("  window solid angle %.4f sr, counted %.4f sr\n", om[0] + om[1], quad);
	assert_true(fabs(om[0] + om[1] - quad) < 5 * sqrt(quad * 4 * M_PI / 200000));
	/* The receiver's normal weighs the portal triangles: sideways (one
	 * window triangle behind x's horizon, at the floor weight, the others
	 * at their cosines); tilted toward the window; and none. */
	check_light_sample(&l, x, v3(1, 0, 0), "+ portals sideways");
	check_light_sample(&l, x, v3_norm(v3(0.3f, -0.2f, 0.9f)), "+ portals");
	check_light_sample(&l, x, v3(0, 0, 0), "+ portals, no n");
	lit_free(&l);
}

/* A shading point close to a window, off its centre: one portal triangle
 * covers more than pi sr, where the half-angle tangent of the sampler's
 * sub-triangle area passes infinity (a bug that darkened the living room,
 * whose window frames are near its portals, by 0.5%). */
static void test_light_sample_env_portal_near(void **state)
{
	rng_state = 23;
	Lit l;
	build_light_scene(&l);
	assert_int_equal(scene_set_env_image(l.s, 40, 20, synthetic_sky(40, 20), 0.02f), AJAR_OK);
	float pos[] = {-0.8f, -0.4f, 1, 0.8f, -0.4f, 1, 0.8f, 0.8f, 1, -0.8f, 0.8f, 1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_portal(l.s, "window", pos, 4, idx, 2), AJAR_OK);
	lit_build(&l);
	V3 x = v3(0.35f, -0.1f, 0.93f);
	for (int j = 0; j < 2; j++)
		l.s->portals[j].env_side = v3_dot(v3_sub(x, l.s->portals[j].p0), l.s->portals[j].n) > 0 ? -1 : 1;
	float om0 = portal_env_solid_angle(&l.s->portals[0], x), om1 = portal_env_solid_angle(&l.s->portals[1], x);
	printf("  solid angles from x: %.3f and %.3f sr\n", om0, om1);
	assert_true(fmaxf(om0, om1) > 1.2f * AJAR_PI);
	check_light_sample(&l, x, v3_norm(v3(-0.5f, 0.3f, 0.8f)), "+ near portal");
	lit_free(&l);
}

/* A window cut into 24 triangles (a 4 x 3 grid of quads), more than
 * env_nee_sample keeps weights for between its sum and its pick
 * (PORTAL_W_KEPT): the rest are weighed again, and the pick must still
 * follow the weights. */
static void test_light_sample_env_portal_grid(void **state)
{
	rng_state = 29;
	Lit l;
	build_light_scene(&l);
	assert_int_equal(scene_set_env_image(l.s, 40, 20, synthetic_sky(40, 20), 0.02f), AJAR_OK);
	enum { NV = GRID_NV, NT = GRID_NT };
	float pos[3 * NV];
	uint32_t idx[3 * NT];
	grid_window(pos, idx);
	assert_true(NT > PORTAL_W_KEPT);
	assert_int_equal(scene_add_portal(l.s, "grid", pos, NV, idx, NT), AJAR_OK);
	lit_build(&l);
	V3 x = v3(0.3f, 0.1f, 0.2f);
	for (int j = 0; j < NT; j++)
		l.s->portals[j].env_side = v3_dot(v3_sub(x, l.s->portals[j].p0), l.s->portals[j].n) > 0 ? -1 : 1;
	check_light_sample(&l, x, v3_norm(v3(0.2f, -0.3f, 0.9f)), "+ portal grid");
	lit_free(&l);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_light_sample_emitters),
		cmocka_unit_test(test_light_sample_env_color),
		cmocka_unit_test(test_light_sample_env_image),
		cmocka_unit_test(test_light_sample_env_portals),
		cmocka_unit_test(test_light_sample_env_portal_near),
		cmocka_unit_test(test_light_sample_env_portal_grid),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
