/* test_punctual.c — KHR_lights_punctual lights, checked on the host with
 * the kernels' own code (tests/kernel_host.h):
 *   - analytic radiance of a Lambertian plane (albedo rho) lit by each
 *     light type, seen by a camera whose pixel covers a tiny patch: a
 *     directional light of illuminance E gives rho E cos(theta) / pi; a
 *     point light of intensity I at distance d gives rho I cos / (pi d^2);
 *     a spot the same times the spec's cone falloff t^2; `range` the
 *     spec's window clamp(1 - (d / range)^4, 0, 1); all in glTF's units at
 *     683 lm/W. Next-event estimation of a delta light is deterministic and
 *     a lone plane has no other light path, so these are exact up to
 *     float rounding;
 *   - the light choice: the plane lit by a point light, a directional
 *     light, an emissive triangle's absence notwithstanding, and the sky,
 *     all at once, has the sum of their images (within its noise);
 *   - bdpt and portal refuse scenes with punctual lights (not built yet)
 *     with a message that says so. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel_host.h"
#include "testutil.h"

#define RHO 0.5f

/* A 2a x 2a plane at y = 0 facing +Y, albedo RHO, Lambertian. */
static ajar_scene *plane_scene_sized(float a)
{
	ajar_scene *s;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material m;
	ajar_material_default(&m);
	m.base_color[0] = m.base_color[1] = m.base_color[2] = RHO;
	uint32_t mat;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	const float pos[12] = {-a, 0, -a, -a, 0, a, a, 0, a, a, 0, -a};
	const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	ajar_mesh mesh = {pos, NULL, NULL, 4, idx, 2, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	return s;
}

static ajar_scene *plane_scene(void) { return plane_scene_sized(100.0f); }

/* A camera 1 above (x, 0, z) looking straight down, 1e-3 rad wide. */
static void look_at(ajar_scene *s, float x, float z)
{
	ajar_camera c = {{x, 1, z}, {x, 0, z}, {0, 0, -1}, 1e-3f, 1.0f};
	assert_int_equal(ajar_scene_set_camera(s, &c), AJAR_OK);
}

/* The pt image (1 x 1, 16 samples) of the plane at (x, 0, z) with `l`. */
static void render_at(ajar_scene *s, float x, float z, double rgb[3])
{
	look_at(s, x, z);
	HostScene h;
	host_scene_open(&h, NULL, s, 1, 1, INTEGRATOR_PT, 8);
	host_render(&h, 16, 1, rgb, NULL);
	h.scene = NULL; /* the caller keeps the scene */
	host_scene_close(&h);
}

static void expect(const char *what, const double got[3], const double want[3])
{
	for (int c = 0; c < 3; c++) {
		double tol = 2e-4 * fabs(want[c]) + 1e-9;
		if (fabs(got[c] - want[c]) > tol)
			fail_msg("%s, channel %d: %.7g, expected %.7g", what, c, got[c], want[c]);
	}
}

static const float colour[3] = {1.0f, 0.5f, 0.25f};

/* rho / pi x colour x intensity / 683 x k. */
static void lambert(double k, float intensity, double out[3])
{
	for (int c = 0; c < 3; c++)
		out[c] = RHO / M_PI * colour[c] * intensity / 683.0 * k;
}

static void test_directional(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	const float d[3] = {0.3f, -0.8f, 0.2f};
	memcpy(l.direction, d, sizeof d);
	memcpy(l.color, colour, sizeof colour);
	l.intensity = 1000.0f; /* lux */
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	double got[3], want[3];
	double cos_t = 0.8 / sqrt(0.09 + 0.64 + 0.04);
	lambert(cos_t, l.intensity, want);
	render_at(s, 0.0f, 0.0f, got);
	expect("directional at the origin", got, want);
	render_at(s, 40.0f, -30.0f, got); /* the same everywhere */
	expect("directional at (40, -30)", got, want);
	ajar_scene_destroy(&s);

	/* From below the plane it lights nothing the camera sees. */
	s = plane_scene();
	l.direction[1] = 0.8f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	render_at(s, 0.0f, 0.0f, got);
	const double zero[3] = {0, 0, 0};
	expect("directional from below", got, zero);
	ajar_scene_destroy(&s);
}

static void test_point(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.position[1] = 2.0f;
	memcpy(l.color, colour, sizeof colour);
	l.intensity = 683.0f; /* candela: 1 W/sr in white */
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	const float xs[3] = {0.0f, 1.5f, 6.0f};
	for (int i = 0; i < 3; i++) {
		double got[3], want[3], d2 = xs[i] * xs[i] + 4.0, cos_t = 2.0 / sqrt(d2);
		lambert(cos_t / d2, l.intensity, want);
		render_at(s, xs[i], 0.0f, got);
		char what[64];
		snprintf(what, sizeof what, "point light, x = %g", xs[i]);
		expect(what, got, want);
	}
	ajar_scene_destroy(&s);
}

/* The spec's falloff: t = clamp((cos - cos outer) / (cos inner - cos
 * outer), 0, 1), squared. */
static double spot_falloff(double cos_a, double inner, double outer)
{
	double t = (cos_a - cos(outer)) / fmax(0.001, cos(inner) - cos(outer));
	t = fmin(fmax(t, 0.0), 1.0);
	return t * t;
}

static void test_spot(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_SPOT;
	l.position[1] = 2.0f;
	l.direction[0] = 0.0f;
	l.direction[1] = -1.0f;
	l.direction[2] = 0.0f;
	l.inner_cone = 0.2f;
	l.outer_cone = 0.5f;
	memcpy(l.color, colour, sizeof colour);
	l.intensity = 683.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	/* Inside the inner cone, in the falloff (twice), outside. */
	const double angle[4] = {0.1, 0.3, 0.42, 0.6};
	for (int i = 0; i < 4; i++) {
		float x = (float)(2.0 * tan(angle[i]));
		double got[3], want[3], d2 = x * x + 4.0, cos_t = 2.0 / sqrt(d2);
		double f = spot_falloff(cos_t, l.inner_cone, l.outer_cone);
		if (i == 0)
			assert_float_equal(f, 1.0, 0.0);
		if (i == 1 || i == 2)
			assert_true(f > 0.05 && f < 0.95);
		if (i == 3)
			assert_float_equal(f, 0.0, 0.0);
		lambert(cos_t / d2 * f, l.intensity, want);
		render_at(s, x, 0.0f, got);
		char what[64];
		snprintf(what, sizeof what, "spot, %g rad off its axis", angle[i]);
		expect(what, got, want);
	}
	ajar_scene_destroy(&s);
}

static void test_range(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.position[1] = 2.0f;
	l.range = 3.0f;
	memcpy(l.color, colour, sizeof colour);
	l.intensity = 683.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	const float xs[3] = {0.0f, 2.0f, 2.5f}; /* d = 2, 2.83, 3.2 */
	for (int i = 0; i < 3; i++) {
		double got[3], want[3], d2 = xs[i] * xs[i] + 4.0, cos_t = 2.0 / sqrt(d2);
		double r = sqrt(d2) / 3.0, win = fmin(fmax(1.0 - r * r * r * r, 0.0), 1.0);
		if (i == 2)
			assert_float_equal(win, 0.0, 0.0);
		lambert(cos_t / d2 * win, l.intensity, want);
		render_at(s, xs[i], 0.0f, got);
		char what[64];
		snprintf(what, sizeof what, "range 3, distance %g", sqrt(d2));
		expect(what, got, want);
	}
	ajar_scene_destroy(&s);
}

/* Every light at once, with a grey sky: the light choice (the sky, the
 * emitter table with the lights after it) must give the sum. */
static void test_light_choice(void **state)
{
	/* Small, so that the sky's share (its power through the scene's
	 * cross-section) does not starve the lights. */
	ajar_scene *s = plane_scene_sized(5.0f);
	ajar_light p, d;
	ajar_light_default(&p);
	p.position[1] = 2.0f;
	p.intensity = 683.0f * 3.0f;
	ajar_light_default(&d);
	d.type = AJAR_LIGHT_DIRECTIONAL;
	d.direction[0] = 0.6f;
	d.direction[1] = -0.8f;
	d.direction[2] = 0.0f;
	d.intensity = 683.0f * 0.5f;
	assert_int_equal(ajar_scene_add_light(s, &p), AJAR_OK);
	assert_int_equal(ajar_scene_add_light(s, &d), AJAR_OK);
	const float sky[3] = {0.2f, 0.2f, 0.2f};
	assert_int_equal(ajar_scene_set_environment_color(s, sky), AJAR_OK);
	look_at(s, 1.0f, 0.0f);
	HostScene h;
	host_scene_open(&h, NULL, s, 1, 1, INTEGRATOR_PT, 8);
	assert_true(h.data.params->env_pdf_select > 0.0f && h.data.params->env_pdf_select < 1.0f);
	Estimate e;
	host_batch_estimate(&h, 256, -1, 16, 5, &e);
	/* The sky over a plane: irradiance pi L, radiance rho L. */
	double want = RHO * 0.2 + RHO / M_PI * (3.0 * (2.0 / sqrt(5.0)) / 5.0 + 0.5 * 0.8);
	for (int c = 0; c < 3; c++) {
		print_message("channel %d: %.5f +- %.5f, expected %.5f\n", c, e.mean[c], e.se[c], want);
		if (fabs(e.mean[c] - want) > 5 * e.se[c] + 1e-6)
			fail_msg("channel %d: %.6f +- %.6f, expected %.6f", c, e.mean[c], e.se[c], want);
	}
	host_scene_close(&h);
}

static void test_bidirectional_refuse(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.position[1] = 1.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	for (int integ = INTEGRATOR_BDPT; integ <= INTEGRATOR_PORTAL; integ++) {
		PrepareOptions po = {8, 8, integ, 8, 1, MIS_POWER, 0, 0, 0};
		SceneData d;
		assert_int_equal(prepare_scene(s, &po, &d), AJAR_ERROR_INVALID_ARGUMENT);
		assert_non_null(strstr(ajar_last_error(), "only the pt integrator renders them"));
	}
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_directional),
		cmocka_unit_test(test_point),
		cmocka_unit_test(test_spot),
		cmocka_unit_test(test_range),
		cmocka_unit_test(test_light_choice),
		cmocka_unit_test(test_bidirectional_refuse),
	};
	return cmocka_run_group_tests_name("punctual", tests, NULL, NULL);
}
