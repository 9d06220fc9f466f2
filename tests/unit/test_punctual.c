/* test_punctual.c — KHR_lights_punctual lights, checked on the host with
 * the kernels' own code (tests/support/kernel_host.h):
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
 *     light and the sky at once has the sum of their images (within its
 *     noise), the lights sharing the emitters' table and the sky's share;
 *   - light subpaths' sampling against the densities MIS reads
 *     (chi-square): directions from point and spot lights, the lines of a
 *     directional light on the scene's disk and through two overlapping
 *     portals;
 *   - every integrator prepares a scene with punctual lights, with and
 *     without portals. */
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

/* ---- Light-subpath sampling against its densities (chi-square) ---------- */

#define N_EMIT 200000
#define N_CHI2 4 /* tests below, for the Sidak correction */

static void check_chi2(const char *what, const double *obs, const double *expct, int n)
{
	double alpha = 1.0 - pow(1.0 - 1e-3, 1.0 / N_CHI2);
	double p = chi2_test(obs, expct, n, 5.0);
	print_message("%s: chi-square p = %.3g\n", what, p);
	if (p < alpha)
		fail_msg("%s: chi-square p-value %g below %g", what, p, alpha);
	for (int i = 0; i < n; i++)
		if (expct[i] == 0.0 && obs[i] > 0.0)
			fail_msg("%s: %g samples in cell %d of zero probability", what, obs[i], i);
}

/* Directions from a point or spot light in (cos to its axis, phi) cells
 * of the sphere, against punctual_dir_pdf integrated over each cell. */
#define DZ 20
#define DPHI 24
static void check_directions(const char *what, GLOBAL const PunctualLight *l)
{
	static double obs[DZ * DPHI], expct[DZ * DPHI];
	memset(obs, 0, sizeof obs);
	V3 t, b;
	v3_basis(l->dir, &t, &b);
	Rng rng = rng_init(3, 4, 5, 6);
	for (int i = 0; i < N_EMIT; i++) {
		V3 w = punctual_dir_sample(l, rng_f(&rng), rng_f(&rng));
		double z = v3_dot(w, l->dir), phi = atan2(v3_dot(w, b), v3_dot(w, t)) + M_PI;
		int iz = (int)((z + 1) / 2 * DZ), ip = (int)(phi / (2 * M_PI) * DPHI);
		iz = iz < 0 ? 0 : iz >= DZ ? DZ - 1 : iz;
		ip = ip < 0 ? 0 : ip >= DPHI ? DPHI - 1 : ip;
		obs[iz * DPHI + ip]++;
	}
	const int sub = 8;
	for (int iz = 0; iz < DZ; iz++)
		for (int ip = 0; ip < DPHI; ip++) {
			double sum = 0;
			for (int a = 0; a < sub; a++)
				for (int c = 0; c < sub; c++) {
					double z = -1 + 2.0 * (iz + (a + 0.5) / sub) / DZ;
					double phi = 2 * M_PI * (ip + (c + 0.5) / sub) / DPHI - M_PI, r = sqrt(fmax(0, 1 - z * z));
					V3 w = v3_add(v3_scale(l->dir, (float)z),
						      v3_add(v3_scale(t, (float)(r * cos(phi))), v3_scale(b, (float)(r * sin(phi)))));
					sum += punctual_dir_pdf(l, w);
				}
			/* Each cell spans dz dphi = (2 / DZ)(2 pi / DPHI) sr. */
			expct[iz * DPHI + ip] = N_EMIT * sum / (sub * sub) * (2.0 / DZ) * (2 * M_PI / DPHI);
		}
	check_chi2(what, obs, expct, DZ * DPHI);
}

static void test_emission_directions(void **state)
{
	PunctualLight l;
	memset(&l, 0, sizeof l);
	l.type = LIGHT_POINT;
	l.dir = v3_norm(v3(0.2f, -1.0f, 0.4f));
	l.cos_outer = -1.0f;
	check_directions("point light directions", &l);
	/* The outer cone at 60 degrees: cos 0.5, a cell edge. */
	l.type = LIGHT_SPOT;
	l.cos_outer = 0.5f;
	l.cone_scale = 1.0f / (float)(cos(0.3) - 0.5);
	check_directions("spot light directions", &l);
}

/* The lines along w of disk radius R (line_sample: a directional light's,
 * or the environment's for a sampled direction) where they cross the plane
 * through the scene's centre perpendicular to w, in cells of a grid over
 * [lo, hi]^2 (basis t, b of w), against line_pdf_perp integrated over each
 * cell. */
#define GN 12
static void check_lines(const char *what, const SceneView *sc, V3 w, float R, double lo, double hi)
{
	static double obs[GN * GN], expct[GN * GN];
	memset(obs, 0, sizeof obs);
	V3 t, b, c = sc->params->scene_center;
	v3_basis(w, &t, &b);
	Rng rng = rng_init(7, 8, 9, 10);
	double cell = (hi - lo) / GN;
	int outside = 0;
	for (int i = 0; i < N_EMIT; i++) {
		V3 o;
		float pdf;
		if (!line_sample(sc, w, R, rng_f(&rng), rng_f(&rng), rng_f(&rng), &o, &pdf))
			fail_msg("%s: no line sampled", what);
		V3 q = v3_sub(o, c);
		double x = v3_dot(q, t), y = v3_dot(q, b);
		/* The line starts behind the scene's bounding sphere. */
		if (!(v3_dot(q, w) < -sc->params->scene_radius))
			fail_msg("%s: a line starts inside the scene", what);
		int ix = (int)floor((x - lo) / cell), iy = (int)floor((y - lo) / cell);
		if (ix < 0 || ix >= GN || iy < 0 || iy >= GN) {
			outside++;
			continue;
		}
		obs[iy * GN + ix]++;
	}
	assert_int_equal(outside, 0);
	const int sub = 32;
	double total = 0;
	for (int iy = 0; iy < GN; iy++)
		for (int ix = 0; ix < GN; ix++) {
			double sum = 0;
			for (int a = 0; a < sub; a++)
				for (int k = 0; k < sub; k++) {
					double x = lo + cell * (ix + (k + 0.5) / sub), y = lo + cell * (iy + (a + 0.5) / sub);
					V3 p = v3_add(c, v3_add(v3_scale(t, (float)x), v3_scale(b, (float)y)));
					sum += line_pdf_perp(sc, w, R, p);
				}
			expct[iy * GN + ix] = N_EMIT * sum / (sub * sub) * cell * cell;
			total += expct[iy * GN + ix];
		}
	/* The density integrates to one over the lines it samples. */
	print_message("%s: integral of the line density %.4f\n", what, total / N_EMIT);
	assert_true(fabs(total / N_EMIT - 1) < 0.01);
	check_chi2(what, obs, expct, GN * GN);
}

/* A directional light's lines: on the disk of the scene's radius without
 * portals (the disk's edge cuts cells, so cells are integrated finely and
 * only those wholly inside or outside it count exactly); through two
 * overlapping portals, whose shared lines have the sum of both
 * densities. */
static void test_sun_lines(void **state)
{
	ajar_scene *s = plane_scene_sized(1.0f);
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	l.direction[0] = 0.3f;
	l.direction[1] = -0.8f;
	l.direction[2] = 0.4f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	HostScene h;
	look_at(s, 0, 0);
	host_scene_open(&h, NULL, s, 1, 1, INTEGRATOR_PT, 8);
	/* The disk: its density is 1 / (pi R^2) inside, so integrating it
	 * over the square would count the corners; compare on the square
	 * inscribed in the disk's circle instead, where every cell is inside. */
	{
		GLOBAL const PunctualLight *pl = &h.view.punctual[0];
		double r = pl->disk_radius, half = r / sqrt(2.0);
		static double obs[GN * GN], expct[GN * GN];
		memset(obs, 0, sizeof obs);
		V3 t, b, c = h.view.params->scene_center;
		v3_basis(pl->dir, &t, &b);
		Rng rng = rng_init(11, 12, 13, 14);
		double cell = 2 * half / GN;
		for (int i = 0; i < N_EMIT; i++) {
			V3 o;
			float pdf;
			assert_true(line_sample(&h.view, pl->dir, pl->disk_radius, rng_f(&rng), rng_f(&rng), rng_f(&rng), &o, &pdf));
			V3 q = v3_sub(o, c);
			double x = v3_dot(q, t), y = v3_dot(q, b);
			assert_true(x * x + y * y <= r * r * (1 + 1e-5));
			int ix = (int)floor((x + half) / cell), iy = (int)floor((y + half) / cell);
			if (ix >= 0 && ix < GN && iy >= 0 && iy < GN)
				obs[iy * GN + ix]++;
		}
		for (int i = 0; i < GN * GN; i++)
			expct[i] = N_EMIT * line_pdf_perp(&h.view, pl->dir, pl->disk_radius, c) * cell * cell;
		check_chi2("directional light, disk", obs, expct, GN * GN);
	}
	h.scene = NULL;
	host_scene_close(&h);
	ajar_scene_destroy(&s);

	/* Two unit-square windows, one 0.5 above the other and shifted, so
	 * that some lines cross both. */
	s = plane_scene_sized(1.0f);
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	const float w1[12] = {-0.5f, 1, -0.5f, -0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f};
	const float w2[12] = {-0.2f, 1.5f, -0.6f, -0.2f, 1.5f, 0.4f, 0.8f, 1.5f, 0.4f, 0.8f, 1.5f, -0.6f};
	const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
	ajar_mesh m1 = {w1, NULL, NULL, 4, quad, 2, 0, NULL}, m2 = {w2, NULL, NULL, 4, quad, 2, 0, NULL};
	assert_int_equal(ajar_scene_add_portal(s, &m1), AJAR_OK);
	assert_int_equal(ajar_scene_add_portal(s, &m2), AJAR_OK);
	host_scene_open(&h, NULL, s, 1, 1, INTEGRATOR_PT, 8);
	assert_int_equal(h.view.params->num_portals, 4);
	float R = h.view.punctual[0].disk_radius * 1.01f;
	check_lines("directional light through two portals", &h.view, h.view.punctual[0].dir,
		    h.view.punctual[0].disk_radius, -R, R);
	h.scene = NULL;
	host_scene_close(&h);
	ajar_scene_destroy(&s);

	/* The environment's lines (bdpt_light_subpath: along -dir, on the
	 * scene's radius) through a horizontal and a vertical window, for two
	 * directions: the first has lines through both (down through the
	 * roof window, then out of the wall one), the second meets the wall
	 * window from its back at a slant. */
	s = plane_scene_sized(1.0f);
	const float w3[12] = {0.9f, 0.1f, -0.5f, 0.9f, 1.1f, -0.5f, 0.9f, 1.1f, 0.5f, 0.9f, 0.1f, 0.5f};
	ajar_mesh m3 = {w3, NULL, NULL, 4, quad, 2, 0, NULL};
	assert_int_equal(ajar_scene_add_portal(s, &m1), AJAR_OK);
	assert_int_equal(ajar_scene_add_portal(s, &m3), AJAR_OK);
	host_scene_open(&h, NULL, s, 1, 1, INTEGRATOR_BDPT, 8);
	assert_int_equal(h.view.params->num_portals, 4);
	float r = h.view.params->scene_radius;
	const V3 dirs[2] = {v3_norm(v3(0.6f, -0.8f, 0.1f)), v3_norm(v3(-0.3f, -0.9f, -0.3f))};
	for (int i = 0; i < 2; i++) {
		/* A line through both windows has twice the portal share. */
		V3 x = v3(0.4f, 1.0f, 0.05f);
		double both = 0.9 * 2 / (double)line_portal_area(&h.view, dirs[i]) + 0.1 / (M_PI * r * r);
		if (i == 0)
			assert_true(fabs(line_pdf_perp(&h.view, dirs[i], r, x) / both - 1) < 1e-4);
		check_lines(i ? "environment lines, slanted through the wall window" : "environment lines, two windows",
			    &h.view, dirs[i], r, -1.01 * r, 1.01 * r);
	}
	h.scene = NULL;
	host_scene_close(&h);
	ajar_scene_destroy(&s);
}

/* Every integrator takes punctual lights, with portals in the scene or
 * without (portal without portals is bdpt), and the portal integrator
 * then traces light subpaths. */
static void test_every_integrator_prepares(void **state)
{
	ajar_scene *s = plane_scene();
	ajar_light l;
	ajar_light_default(&l);
	l.position[1] = 1.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	SceneData d;
	const float w[12] = {-0.5f, 1, -0.5f, -0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f};
	const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
	ajar_mesh m = {w, NULL, NULL, 4, quad, 2, 0, NULL};
	for (int portals = 0; portals < 2; portals++) {
		if (portals)
			assert_int_equal(ajar_scene_add_portal(s, &m), AJAR_OK);
		for (int integ = INTEGRATOR_PT; integ <= INTEGRATOR_PORTAL; integ++) {
			ajar_options po;
			ajar_options_default(&po);
			po.integrator = (ajar_integrator)integ;
			po.max_depth = 8;
			po.mis = AJAR_MIS_POWER;
			if (prepare_scene(s, &po, 8, 8, NULL, &d) != AJAR_OK)
				fail_msg("integrator %d, portals %d: %s", integ, portals, ajar_last_error());
			assert_int_equal(d.params->num_lights, 1);
			assert_true(d.params->light_paths);
			prepare_free(&d);
		}
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
		cmocka_unit_test(test_emission_directions),
		cmocka_unit_test(test_sun_lines),
		cmocka_unit_test(test_every_integrator_prepares),
	};
	return cmocka_run_group_tests_name("punctual", tests, NULL, NULL);
}
