/* test_lights_env.c — the environment's light tables (src/prepare/light_tables.c)
 * and sampling (kernels/light/env.h): orientation and rotation sense,
 * env_sample against env_pdf_w (the sky turned or not), the table of a sky
 * image's light subpaths through a window (src/prepare/portal_flux.c)
 * against its density and that density against the one it is made to be,
 * env_uv against the exact map, black and constant skies; chi-square
 * against densities integrated numerically. */
#include "lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prepare/portal_flux.h"

static void test_env_orientation(void **state)
{
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t w = 8, h = 4;
	float *rgb = calloc(3 * w * h, sizeof(float));
	/* Pixel (x, y) has red = x, green = y. */
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			rgb[3 * (y * w + x)] = (float)x;
			rgb[3 * (y * w + x) + 1] = (float)y;
			rgb[3 * (y * w + x) + 2] = 1.0f;
		}
	assert_int_equal(scene_set_env_image(l.s, w, h, rgb, 2.0f), AJAR_OK);
	lit_build(&l);
	assert_int_equal(l.lt.nenv, ENV_FLOATS(w, h));
	/* +Y is row 0, -Y the last row; strength applied once. */
	V3 up = env_radiance(&l.sc, v3(0, 1, 0));
	assert_float_equal(up.y, 0.0f, 0.0f);
	assert_float_equal(up.z, 2.0f, 0.0f);
	V3 down = env_radiance(&l.sc, v3(0, -1, 0));
	assert_float_equal(down.y, 2.0f * (h - 1), 0.0f);
	/* Image centre looks down -Z; +X is at u = 0.75, -X at 0.25. */
	V3 fwd = env_radiance(&l.sc, v3_norm(v3(0, 0.1f, -1)));
	assert_float_equal(fwd.x, 2.0f * (w / 2), 0.0f);
	assert_float_equal(fwd.y, 2.0f * (h / 2 - 1), 0.0f);
	assert_float_equal(env_radiance(&l.sc, v3(1, 0.01f, 0)).x, 2.0f * (3 * w / 4), 0.0f);
	assert_float_equal(env_radiance(&l.sc, v3(-1, 0.01f, 0)).x, 2.0f * (w / 4), 0.0f);
	/* env_dir is the inverse of the lookup at texel centres. */
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			V3 d = env_dir(&l.prm, (x + 0.5f) / w, (y + 0.5f) / h);
			assert_float_equal(v3_len(d), 1.0f, 1e-5f);
			V3 L = env_radiance(&l.sc, d);
			assert_float_equal(L.x, 2.0f * x, 0.0f);
			assert_float_equal(L.y, 2.0f * y, 0.0f);
		}
	lit_free(&l);
}

/* The unturned equirect direction of (u, v) (env.h's image frame). */
static V3 uv_dir(float u, float v)
{
	float phi = 2.0f * AJAR_PI * (u - 0.5f), theta = AJAR_PI * v;
	return v3(sinf(theta) * sinf(phi), cosf(theta), -sinf(theta) * cosf(phi));
}

/* A window quad at z = 1 (1.6 x 1.2) whose sky lies on its -z side, seen
 * through it from z > 1, and the table of light subpaths' directions
 * through it (src/prepare/portal_flux.c, portal_sky_lines_build). */
static void add_line_window(Lit *l)
{
	float pos[] = {-0.8f, -0.4f, 1, 0.8f, -0.4f, 1, 0.8f, 0.8f, 1, -0.8f, 0.8f, 1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_portal(l->s, "window", pos, 4, idx, 2), AJAR_OK);
	lights_free(&l->lt);
	free(l->tris);
	lit_build(l);
	for (int j = 0; j < 2; j++)
		l->s->portals[j].env_side = l->s->portals[j].n.z > 0.0f ? -1 : 1;
	assert_int_equal(portal_sky_lines_build(&l->prm, l->s->portals, 2, &l->lt.env, &l->lt.nenv), AJAR_OK);
	assert_int_equal(l->lt.nenv, ENV_LINE_FLOATS(l->s->env_width, l->s->env_height));
	l->sc.env = l->lt.env;
	l->prm.env_lines = 1;
}

/* Histogram of env_light_sample (env_sample, or with `line` the table of
 * light subpaths through a window) over 16 x 8 cells in the scene's (u, v)
 * (those of an unturned sky), expected counts from env_light_pdf_w
 * integrated over each cell in solid angle; the sky turned by `degrees`. */
static void env_sample_chi2(double degrees, int line)
{
	rng_state = 11;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t w = 40, h = 20;
	assert_int_equal(scene_set_env_image(l.s, w, h, synthetic_sky(w, h), 1.5f), AJAR_OK);
	assert_int_equal(scene_set_env_rotation(l.s, degrees), AJAR_OK);
	lit_build(&l);
	if (line)
		add_line_window(&l);
	assert_true(l.lt.env_power > 0.0f);
	assert_float_equal(l.lt.env_pdf_select, 1.0f, 0.0f); /* no emitters */

	enum { CU = 16, CV = 8, SUB = 20, N = 200000 };
	static double obs[CU * CV], expct[CU * CV];
	memset(obs, 0, sizeof(obs));
	double total = 0.0;
	for (int cv = 0; cv < CV; cv++)
		for (int cu = 0; cu < CU; cu++) {
			double sum = 0.0;
			/* Midpoints of a sub-grid aligned with the texels (2.5 texels
			 * per cell, 20 sub-steps): exact for a per-texel constant. */
			for (int j = 0; j < SUB; j++)
				for (int i = 0; i < SUB; i++) {
					float u = (cu + (i + 0.5f) / SUB) / CU, v = (cv + (j + 0.5f) / SUB) / CV;
					float st = sinf(AJAR_PI * v);
					sum += env_light_pdf_w(&l.sc, uv_dir(u, v)) * st;
				}
			double cell = sum * (2.0 * M_PI / (CU * SUB)) * (M_PI / (CV * SUB));
			expct[cv * CU + cu] = cell * N;
			total += cell;
		}
	assert_float_equal(total, 1.0, 1e-4); /* the density integrates to 1 */

	int refused = 0;
	for (int k = 0; k < N; k++) {
		V3 d;
		float pdf_w;
		V3 L = env_light_sample(&l.sc, rnd(), rnd(), &d, &pdf_w);
		if (!(pdf_w > 0.0f)) {
			/* Rounded across a texel edge into a black texel (or onto
			 * a pole): a refused sample, which must stay rare. */
			refused++;
			assert_true(v3_is_zero(L));
			continue;
		}
		assert_float_equal(v3_len(d), 1.0f, 1e-5f);
		/* The returned density and radiance are exactly those of d. */
		V3 Le = env_radiance(&l.sc, d);
		assert_true(env_light_pdf_w(&l.sc, d) == pdf_w);
		assert_true(Le.x == L.x && Le.y == L.y && Le.z == L.z);
		float u = 0.5f + atan2f(d.x, -d.z) / (2.0f * AJAR_PI);
		float v = acosf(fminf(fmaxf(d.y, -1.0f), 1.0f)) / AJAR_PI;
		int cu = (int)(u * CU), cv = (int)(v * CV);
		cu = cu < 0 ? 0 : (cu >= CU ? CU - 1 : cu);
		cv = cv < 0 ? 0 : (cv >= CV ? CV - 1 : cv);
		obs[cv * CU + cu] += 1.0;
	}
	assert_true(refused < N / 10000);
	double p = chi2_test(obs, expct, CU * CV, 5.0);
	printf("  env_%s, turned %g degrees: p = %.3f (%d refused)\n", line ? "light_sample through a window" : "sample",
	       degrees, p, refused);
	assert_true(p > ALPHA);

	/* Densities follow luminance: bright texel centres are denser. */
	float bright = env_pdf_w(&l.sc, env_dir(&l.prm, 0.3f, 0.2f)), dim = env_pdf_w(&l.sc, env_dir(&l.prm, 0.9f, 0.5f));
	assert_true(bright > 10.0f * dim);
	/* The black column and row are never sampled. */
	assert_float_equal(env_pdf_w(&l.sc, env_dir(&l.prm, 3.5f / w, 0.3f)), 0.0f, 0.0f);
	assert_float_equal(env_pdf_w(&l.sc, env_dir(&l.prm, 0.5f, (h / 2 + 1.5f) / h)), 0.0f, 0.0f);
	lit_free(&l);
}

static void test_env_sample_chi2(void **state) { env_sample_chi2(0.0, 0); }

/* The light subpaths' table through a window, sampled against its density
 * (the sky turned, as the table's directions turn with it), and that
 * density against the one it is made to be, in double: per texel, the
 * image's own density times (1 - mix) + mix A S / S_A, A the window's area
 * projected toward the texel's centre from its sky side (0 behind it), S
 * the sum of lum sin(theta) over the texels, S_A the same weighted by A. */
static void test_env_line_table(void **state)
{
	env_sample_chi2(37.0, 1);
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t w = 40, h = 20;
	assert_int_equal(scene_set_env_image(l.s, w, h, synthetic_sky(w, h), 1.5f), AJAR_OK);
	assert_int_equal(scene_set_env_rotation(l.s, 37.0), AJAR_OK);
	lit_build(&l);
	add_line_window(&l);
	static double A[40 * 20], e[40 * 20];
	double S = 0.0, SA = 0.0;
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			V3 d = env_dir(&l.prm, (x + 0.5f) / w, (y + 0.5f) / h);
			double a = 0.0;
			for (int k = 0; k < 2; k++) {
				const PortalTri *pt = &l.s->portals[k];
				double c = ((double)d.x * pt->n.x + (double)d.y * pt->n.y + (double)d.z * pt->n.z) * pt->env_side;
				a += c > 0.0 ? pt->area * c : 0.0;
			}
			const float *p = l.lt.env + 3 * (y * w + x);
			double lum = v3_lum(v3(p[0], p[1], p[2]));
			A[y * w + x] = a;
			e[y * w + x] = lum > 0.0 ? lum * sin(M_PI * (y + 0.5) / h) : 0.0;
			S += e[y * w + x];
			SA += e[y * w + x] * a;
		}
	assert_true(SA > 0.0);
	int behind = 0, through = 0;
	double worst = 0.0;
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			if (!(e[y * w + x] > 0.0))
				continue;
			V3 d = env_dir(&l.prm, (x + 0.5f) / w, (y + 0.5f) / h);
			double want = env_pdf_w(&l.sc, d) *
				      ((1.0 - SKY_LINES_PORTAL_MIX) + SKY_LINES_PORTAL_MIX * A[y * w + x] * S / SA);
			double got = env_light_pdf_w(&l.sc, d), diff = fabs(got - want) / want;
			worst = fmax(worst, diff);
			behind += A[y * w + x] == 0.0;
			through += A[y * w + x] > 0.5;
			if (diff > 1e-3) /* both from float CDFs: their differences round */
				fail_msg("texel (%u, %u): density %.7g, want %.7g (projected area %.4f)", x, y, got, want,
					 A[y * w + x]);
		}
	printf("  line table: %d texels behind the window, %d through it, worst %.2e\n", behind, through, worst);
	assert_true(behind > 100 && through > 50);
	lit_free(&l);
}

/* env_uv (fastmath.h's atan2, the host's cos and sin of the turn) against
 * the exact map in double, turned by the same float angle: within 2e-7 in
 * u (where sin(theta) > 0.01: at the poles u is ill-posed) and in v, and
 * back through env_dir (fast_sincos) within 1e-6 of the direction. Near
 * the poles, the seam (u = 0 and 1) and the axes as well as uniformly. */
static void test_env_uv_exact(void **state)
{
	(void)state;
	static const double turns[] = {0.0, 55.6836, -120.0, 179.99, 359.0};
	double worst_u = 0.0, worst_v = 0.0, worst_st = 0.0, worst_back = 0.0;
	rng_state = 5;
	for (size_t k = 0; k < sizeof turns / sizeof turns[0]; k++) {
		Params prm;
		memset(&prm, 0, sizeof prm);
		lights_set_env_rotation(&prm, (float)(turns[k] * M_PI / 180.0));
		double a = prm.env_rotation, c = cos(a), s = -sin(a); /* R(-a) */
		for (int i = 0; i < 100000; i++) {
			V3 d;
			float e = ldexpf(rnd(), -(int)(rnd() * 24.0f)); /* small offsets down to 2^-24 */
			switch (i % 8) {
			case 0: d = v3_norm(v3(e * (rnd() - 0.5f), rnd() < 0.5f ? 1.0f : -1.0f, e * (rnd() - 0.5f))); break;
			case 1: d = v3_norm(v3(e * (rnd() - 0.5f), 2.0f * rnd() - 1.0f, rnd())); break; /* the seam, unturned */
			case 2: d = v3_norm(v3(rnd() < 0.5f ? 1.0f : -1.0f, e * (rnd() - 0.5f), e * (rnd() - 0.5f))); break;
			default: d = sample_uniform_sphere(rnd(), rnd()); break;
			}
			float u, v, st = env_uv(&prm, d, &u, &v);
			double x = c * d.x + s * d.z, y = d.y, z = c * d.z - s * d.x, r = sqrt(x * x + z * z);
			double ue = 0.5 + atan2(x, -z) / (2.0 * M_PI), ve = atan2(r, y) / M_PI;
			double du = fabs(u - ue);
			du = fmin(du, 1.0 - du);
			worst_v = fmax(worst_v, fabs(v - ve));
			worst_st = fmax(worst_st, fabs(st - r));
			assert_true(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f);
			if (r > 0.01) {
				worst_u = fmax(worst_u, du);
				V3 back = env_dir(&prm, u, v);
				worst_back = fmax(worst_back, v3_len(v3_sub(back, d)));
			}
		}
	}
	print_message("env_uv: |du| %.3g, |dv| %.3g, |d sin theta| %.3g, |env_dir(env_uv(d)) - d| %.3g\n", worst_u,
		      worst_v, worst_st, worst_back);
	assert_true(worst_u < 2e-7);
	assert_true(worst_v < 2e-7);
	assert_true(worst_st < 2e-7);
	assert_true(worst_back < 1e-6);
}

/* Turned by 11 texels (99 degrees): the sub-grid above still meets the
 * texel edges (1/8 texel steps), so the expected counts stay exact. */
static void test_env_sample_chi2_turned(void **state) { env_sample_chi2(99.0, 0); }

/* A 6 x 3 sky black but for texel (4, 1), centred on +X at the horizon.
 * Turned by +90 degrees (counter-clockwise seen from above) it is found
 * toward -Z, by -90 toward +Z, by every lookup and by sampling; 450 is 90. */
static void test_env_rotation_sense(void **state)
{
	static const struct {
		double degrees;
		V3 want, away;
	} cases[] = {{0.0, {1, 0, 0}, {0, 0, -1}},
		     {90.0, {0, 0, -1}, {1, 0, 0}},
		     {-90.0, {0, 0, 1}, {0, 0, -1}},
		     {450.0, {0, 0, -1}, {-1, 0, 0}},
		     {180.0, {-1, 0, 0}, {1, 0, 0}}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		Lit l;
		assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
		uint32_t w = 6, h = 3;
		float *rgb = calloc(3 * w * h, sizeof(float));
		assert_non_null(rgb);
		rgb[3 * (1 * w + 4)] = rgb[3 * (1 * w + 4) + 1] = rgb[3 * (1 * w + 4) + 2] = 5.0f;
		assert_int_equal(scene_set_env_image(l.s, w, h, rgb, 1.0f), AJAR_OK);
		assert_int_equal(scene_set_env_rotation(l.s, cases[k].degrees), AJAR_OK);
		lit_build(&l);
		V3 want = cases[k].want, away = cases[k].away;
		assert_float_equal(env_radiance(&l.sc, want).x, 5.0f, 0.0f);
		assert_float_equal(env_radiance(&l.sc, away).x, 0.0f, 0.0f);
		assert_true(env_pdf_w(&l.sc, want) > 0.0f);
		assert_float_equal(env_pdf_w(&l.sc, away), 0.0f, 0.0f);
		/* The texel centre maps to the turned direction. */
		V3 c = env_dir(&l.prm, 4.5f / w, 0.5f);
		assert_true(v3_len(v3_sub(c, want)) < 1e-5f);
		/* Every sample lies within the texel (60 x 60 degrees) around it. */
		for (int i = 0; i < 1000; i++) {
			V3 d;
			float pdf_w;
			V3 L = env_sample(&l.sc, rnd(), rnd(), &d, &pdf_w);
			if (!(pdf_w > 0.0f))
				continue;
			assert_float_equal(L.x, 5.0f, 0.0f);
			assert_true(v3_dot(d, want) > cosf(AJAR_PI / 6.0f * 1.4143f));
		}
		lit_free(&l);
	}
	/* A turn must be a finite angle. */
	Scene *s;
	assert_int_equal(scene_new("<test>", &s), AJAR_OK);
	assert_int_equal(scene_set_env_rotation(s, NAN), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(scene_set_env_rotation(s, INFINITY), AJAR_ERROR_INVALID_ARGUMENT);
	scene_free(s);
}

static void test_env_black_and_color(void **state)
{
	/* An all-black image: no power, never picked, tables still sane. */
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t mat = add_material(l.s, v3(1, 1, 1));
	add_tri(l.s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), mat);
	assert_int_equal(scene_set_env_image(l.s, 8, 4, calloc(3 * 8 * 4, sizeof(float)), 1.0f), AJAR_OK);
	lit_build(&l);
	assert_float_equal(l.lt.env_power, 0.0f, 0.0f);
	assert_float_equal(l.lt.env_pdf_select, 0.0f, 0.0f);
	for (size_t i = 0; i < l.lt.nenv; i++)
		assert_true(isfinite(l.lt.env[i]));
	V3 d;
	float pdf_w;
	env_sample(&l.sc, 0.3f, 0.6f, &d, &pdf_w);
	assert_true(isfinite(pdf_w) && pdf_w > 0.0f);
	assert_true(pdf_w == env_pdf_w(&l.sc, d));
	lit_free(&l);

	/* A constant colour: power pi R^2 pi L, uniform sphere sampling, and
	 * a selection probability by power against the emitters. */
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	mat = add_material(l.s, v3(2, 2, 2));
	add_tri(l.s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), mat);
	scene_set_env_color(l.s, v3(0.5f, 0.5f, 0.5f));
	lit_build(&l);
	double env_power = M_PI * 100.0 * M_PI * 0.5, em_power = 0.5 * M_PI * 2.0;
	assert_float_equal(l.lt.env_power, env_power, 1e-3 * env_power);
	assert_float_equal(l.lt.emitter_power, em_power, 1e-5 * em_power);
	assert_float_equal(l.lt.env_pdf_select, env_power / (env_power + em_power), 1e-5);
	assert_int_equal(l.lt.nenv, 0);
	V3 L = env_sample(&l.sc, 0.2f, 0.7f, &d, &pdf_w);
	assert_float_equal(pdf_w, 0.25 / M_PI, 1e-7);
	assert_float_equal(env_pdf_w(&l.sc, v3(0, 0, 1)), 0.25 / M_PI, 1e-7);
	assert_float_equal(L.x, 0.5f, 0.0f);
	assert_float_equal(env_radiance(&l.sc, v3(1, 0, 0)).y, 0.5f, 0.0f);
	lit_free(&l);

	/* No environment at all. */
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	mat = add_material(l.s, v3(1, 0, 0));
	add_tri(l.s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), mat);
	lit_build(&l);
	assert_float_equal(l.lt.env_pdf_select, 0.0f, 0.0f);
	assert_float_equal(env_pdf_w(&l.sc, v3(0, 1, 0)), 0.0f, 0.0f);
	assert_true(v3_is_zero(env_radiance(&l.sc, v3(0, 1, 0))));
	lit_free(&l);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_env_orientation),
		cmocka_unit_test(test_env_sample_chi2),
		cmocka_unit_test(test_env_line_table),
		cmocka_unit_test(test_env_sample_chi2_turned),
		cmocka_unit_test(test_env_rotation_sense),
		cmocka_unit_test(test_env_uv_exact),
		cmocka_unit_test(test_env_black_and_color),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
