/* test_lights.c — the light tables (src/prepare/light_tables.c) and light sampling
 * (kernels/light/lights.h): environment orientation, env_sample against
 * env_pdf_w, emitter selection by power and uniform points on emitters,
 * portal selection by area, and light_sample's solid-angle density against
 * light_pdf_w with environment and emitters mixed, all by chi-square
 * against densities integrated numerically. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prepare/light_tables.h"
#include "prepare/portal_flux.h"
#include "prepare/sky_tables.h"
#include "scene/scene.h"
#include "light/lights.h"

static uint64_t rng_state;

static uint32_t rnd_u32(void)
{
	/* PCG32 (O'Neill), fixed seed per test. */
	uint64_t old = rng_state;
	rng_state = old * 6364136223846793005ULL + 1442695040888963407ULL;
	uint32_t xs = (uint32_t)(((old >> 18) ^ old) >> 27), rot = (uint32_t)(old >> 59);
	return (xs >> rot) | (xs << ((-rot) & 31));
}

/* Uniform in the open interval (0, 1): a 0 would put a portal sample
 * exactly on a triangle's corner or edge (sph_tri_sample), which the
 * neighbouring triangles share, so that one direction would count as
 * crossing several (measure zero, but the density checks compare each
 * sample's density exactly). */
static float rnd(void) { return ((float)(rnd_u32() >> 8) + 0.5f) * (1.0f / 16777216.0f); }

#define ALPHA 1e-3 /* chi-square significance; fixed seeds make it reproducible */

/* A scene, its light tables and the SceneView the kernels read. */
typedef struct {
	Scene *s;
	Tri *tris;
	LightTables lt;
	Params prm;
	SceneView sc;
	PortalPlane *planes; /* lit_planes */
	float *sky;
} Lit;

static uint32_t add_material(Scene *s, V3 emission)
{
	Material m;
	memset(&m, 0, sizeof(m));
	m.base_color = v3(0.5f, 0.5f, 0.5f);
	m.base_tex = -1;
	m.emission = emission;
	m.roughness = 1.0f;
	m.ior = 1.5f;
	uint32_t id;
	assert_int_equal(scene_add_material(s, &m, &id), AJAR_OK);
	return id;
}

static void add_tri(Scene *s, V3 a, V3 b, V3 c, uint32_t mat)
{
	float pos[9] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
	uint32_t idx[3] = {0, 1, 2};
	assert_int_equal(scene_add_triangles(s, "test", pos, NULL, NULL, 3, idx, 1, mat), AJAR_OK);
}

static void lit_build(Lit *l)
{
	Scene *s = l->s;
	l->tris = malloc(sizeof(Tri) * (s->ntris ? s->ntris : 1));
	assert_non_null(l->tris);
	if (s->ntris)
		memcpy(l->tris, s->tris, sizeof(Tri) * s->ntris);
	assert_int_equal(lights_build(s, l->tris, s->shade, s->extra, s->ntris, s->materials, s->portals, s->nportal_tris,
				      v3(0, 0, 0), 10.0f, &l->lt),
			 AJAR_OK);
	memset(&l->prm, 0, sizeof(l->prm));
	l->prm.num_tris = (int)s->ntris;
	l->prm.num_emitters = (int)l->lt.nemitters;
	l->prm.num_portals = (int)s->nportal_tris;
	l->prm.env_type = s->env_type;
	l->prm.env_width = (int)s->env_width;
	l->prm.env_height = (int)s->env_height;
	l->prm.env_strength = s->env_strength;
	lights_set_env_rotation(&l->prm, s->env_rotation);
	l->prm.env_color = s->env_color;
	l->prm.env_pdf_select = l->lt.env_pdf_select;
	memset(&l->sc, 0, sizeof(l->sc));
	l->sc.tris = l->tris;
	l->sc.shade = s->shade;
	l->sc.textures = s->textures;
	l->sc.texels = s->texels;
	l->sc.materials = s->materials;
	l->sc.emitters = l->lt.emitters;
	l->sc.emitter_cdf = l->lt.emitter_cdf;
	l->sc.env = l->lt.env;
	l->sc.portals = s->portals;
	l->sc.portal_cdf = l->lt.portal_cdf;
	l->sc.params = &l->prm;
	l->planes = NULL;
	l->sky = NULL;
}

/* Planar portals with sky tables (src/prepare/sky_tables.c) from the portal
 * triangles' sky sides as they are now; returns how many. */
static int lit_planes(Lit *l)
{
	size_t np, ns;
	free(l->planes);
	free(l->sky);
	np = ns = 0;
	l->planes = NULL;
	l->sky = NULL;
	if (l->prm.env_type == ENV_IMAGE) { /* prepare_scene builds planes under a sky image only */
		assert_int_equal(portal_sky_planes(l->s->portals, l->s->nportal_tris, &l->planes, &np), AJAR_OK);
		assert_int_equal(portal_sky_tables(&l->sc, l->planes, np, PORTAL_SKY_RES, &l->sky, &ns), AJAR_OK);
	}
	l->sc.portal_planes = l->planes;
	l->sc.portal_sky = l->sky;
	l->prm.num_portal_planes = (int)np;
	return (int)np;
}

static void lit_free(Lit *l)
{
	free(l->planes);
	free(l->sky);
	lights_free(&l->lt);
	free(l->tris);
	scene_free(l->s);
}

/* A w x h sky: a bright blob near the top, a dimmer one below the
 * horizon, a black row and a black column, colour varying along u. */
static float *synthetic_sky(uint32_t w, uint32_t h)
{
	float *rgb = malloc(sizeof(float) * 3 * w * h);
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
			float blob = 20.0f * expf(-((u - 0.3f) * (u - 0.3f) + (v - 0.2f) * (v - 0.2f)) * 40.0f);
			float low = 3.0f * expf(-((u - 0.7f) * (u - 0.7f) + (v - 0.7f) * (v - 0.7f)) * 20.0f);
			float base = 0.2f + 0.1f * u;
			float *p = rgb + 3 * (y * w + x);
			p[0] = blob + low + base;
			p[1] = blob + 0.5f * low + base;
			p[2] = 0.5f * blob + base * 2.0f;
			if (y == h / 2 + 1 || x == 3)
				p[0] = p[1] = p[2] = 0.0f;
		}
	return rgb;
}

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

/* Emissive triangles of different areas and emissions, one black, one
 * with zero area: selection by power, uniform points, front normals. */
static void test_emitter_sampling(void **state)
{
	rng_state = 12;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t black = add_material(l.s, v3(0, 0, 0));
	V3 em[4] = {v3(1, 1, 1), v3(10, 0, 0), v3(0, 0, 3), v3(0.5f, 2, 0.5f)};
	uint32_t mats[4];
	for (int i = 0; i < 4; i++)
		mats[i] = add_material(l.s, em[i]);
	add_tri(l.s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), black);
	add_tri(l.s, v3(0, 0, 1), v3(2, 0, 1), v3(0, 3, 1), mats[0]);      /* area 3 */
	add_tri(l.s, v3(5, 0, 0), v3(5, 0.5f, 0), v3(5, 0, 0.5f), mats[1]); /* 0.125 */
	add_tri(l.s, v3(1, 1, 1), v3(2, 2, 2), v3(3, 3, 3), mats[2]);      /* area 0 */
	add_tri(l.s, v3(-1, 2, 0), v3(-1, 2, 4), v3(3, 2, 0), mats[2]);    /* 8 */
	add_tri(l.s, v3(0, -1, 0), v3(0, -1, 1), v3(1, -1, 0), mats[3]);   /* 0.5 */
	lit_build(&l);
	assert_int_equal(l.lt.nemitters, 4);
	int expect_emitter[6] = {-1, 0, 1, -1, 2, 3};
	double power[4];
	double total = 0.0;
	for (int i = 0; i < 6; i++) {
		assert_int_equal(l.tris[i].emitter, expect_emitter[i]);
		if (expect_emitter[i] < 0)
			continue;
		const Emitter *e = &l.lt.emitters[expect_emitter[i]];
		assert_int_equal(e->tri, i);
		const Tri *t = &l.tris[i];
		double area = 0.5 * v3_len(v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0)));
		assert_float_equal(e->area, area, 1e-6 * area);
		V3 L = l.s->materials[t->material].emission;
		power[expect_emitter[i]] = area * M_PI * (0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z);
		total += power[expect_emitter[i]];
	}
	assert_float_equal(l.lt.emitter_power, total, 1e-5 * total);
	assert_float_equal(l.lt.emitter_cdf[0], 0.0f, 0.0f);
	assert_float_equal(l.lt.emitter_cdf[4], 1.0f, 0.0f);

	enum { N = 100000, SUBD = 4, NCELL = SUBD * SUBD };
	double obs[4] = {0}, expct[4];
	for (int k = 0; k < 4; k++) {
		expct[k] = N * power[k] / total;
		assert_float_equal(l.lt.emitters[k].pdf_select, power[k] / total, 1e-6);
	}
	/* Points on the big emitter, binned into its 16 congruent
	 * sub-triangles (equal areas, so equal expected counts). */
	double pobs[NCELL] = {0}, pexp[NCELL];
	int big = 4;
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(tri >= 0 && tri < 6 && l.tris[tri].emitter >= 0);
		const Tri *t = &l.tris[tri];
		obs[t->emitter] += 1.0;
		assert_float_equal(pdf_a, emitter_pdf_a(&l.sc, tri, p), 0.0f);
		assert_float_equal(pdf_a, power[t->emitter] / total / l.lt.emitters[t->emitter].area,
				   1e-5 * pdf_a);
		V3 ng = tri_normal(t);
		assert_float_equal(v3_len(n), 1.0f, 1e-5f);
		assert_float_equal(v3_dot(n, ng), v3_len(ng), 1e-4f * v3_len(ng));
		/* Barycentrics of p by least squares on the edges. */
		V3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0), q = v3_sub(p, t->p0);
		float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
		float det = d11 * d22 - d12 * d12;
		float b1 = (d22 * v3_dot(q, e1) - d12 * v3_dot(q, e2)) / det;
		float b2 = (d11 * v3_dot(q, e2) - d12 * v3_dot(q, e1)) / det;
		assert_true(b1 >= -1e-5f && b2 >= -1e-5f && b1 + b2 <= 1.0f + 1e-5f);
		if (tri == big) {
			float x = fminf(fmaxf(b1 * SUBD, 0.0f), SUBD - 1e-3f);
			float y = fminf(fmaxf(b2 * SUBD, 0.0f), SUBD - 1e-3f);
			int i = (int)x, j = (int)y;
			if (i + j >= SUBD) /* rounding at the hypotenuse */
				j = SUBD - 1 - i;
			int upper = i + j < SUBD - 1 && (x - i) + (y - j) > 1.0f;
			/* Row j holds 2 (SUBD - j) - 1 sub-triangles. */
			int cell = 0;
			for (int r = 0; r < j; r++)
				cell += 2 * (SUBD - r) - 1;
			cell += 2 * i + upper;
			pobs[cell] += 1.0;
		}
	}
	double p = chi2_test(obs, expct, 4, 5.0);
	printf("  emitter selection: p = %.3f\n", p);
	assert_true(p > ALPHA);
	for (int c = 0; c < NCELL; c++)
		pexp[c] = expct[2] / NCELL;
	p = chi2_test(pobs, pexp, NCELL, 5.0);
	printf("  emitter points: p = %.3f\n", p);
	assert_true(p > ALPHA);

	/* Radiance leaves the front face only; non-emitters give none. */
	V3 front = tri_normal(&l.tris[1]);
	assert_float_equal(emitter_radiance(&l.sc, 1, l.tris[1].p0, front).x, 1.0f, 0.0f);
	assert_true(v3_is_zero(emitter_radiance(&l.sc, 1, l.tris[1].p0, v3_neg(front))));
	assert_true(v3_is_zero(emitter_radiance(&l.sc, 0, l.tris[0].p0, tri_normal(&l.tris[0]))));
	assert_float_equal(emitter_pdf_a(&l.sc, 0, l.tris[0].p0), 0.0f, 0.0f);
	lit_free(&l);
}

/* A unit quad in z = 0 (UVs = xy) with an 8 x 8 emissive texture whose
 * left half (x < 0.5) is black, nearest filtering, and a triangle whose
 * UVs lie in the black half: the quad emits half the power of an
 * untextured one, its points are sampled only where it emits and
 * uniformly there (chi-square over 8 x 8 cells of the lit half), and the
 * black triangle is no emitter at all. */
static void test_emissive_texture(void **state)
{
	(void)state;
	rng_state = 17;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint8_t rgba[8 * 8 * 4];
	for (int i = 0; i < 64; i++) {
		uint8_t c = (i % 8) < 4 ? 0 : 255;
		rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = c;
		rgba[4 * i + 3] = 255;
	}
	uint32_t img, tex;
	assert_int_equal(scene_add_texture(l.s, 8, 8, rgba, &img), AJAR_OK);
	const float xf[6] = {1, 0, 0, 0, 1, 0};
	assert_int_equal(scene_add_texture_use(l.s, img, TEX_NEAREST, xf, &tex), AJAR_OK);
	uint32_t m = add_material(l.s, v3(2, 2, 2));
	l.s->materials[m].emissive_tex = (int)tex + 1;
	float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles(l.s, "quad", pos, NULL, uv, 4, idx, 2, m), AJAR_OK);
	float pos2[] = {3, 0, 0, 4, 0, 0, 3, 1, 0};
	float uv2[] = {0.1f, 0, 0.4f, 0, 0.1f, 1};
	assert_int_equal(scene_add_triangles(l.s, "dark", pos2, NULL, uv2, 3, NULL, 1, m), AJAR_OK);
	lit_build(&l);
	assert_true(l.tris[0].emitter >= 0 && l.tris[1].emitter >= 0);
	assert_int_equal(l.tris[2].emitter, -1);
	/* Area 1, half of it at radiance 2 (luminance 2): pi W. */
	assert_float_equal(l.lt.emitter_power, AJAR_PI, 1e-5 * AJAR_PI);
	enum { N = 64000, G = 8 };
	double obs[G * G] = {0}, expct[G * G];
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(tri == 0 || tri == 1);
		assert_true(p.x >= 0.5f - 1e-6f);
		/* Uniform over the lit half: density 2 per unit area. */
		assert_float_equal(pdf_a, 2.0f, 1e-4f);
		assert_float_equal(emitter_pdf_a(&l.sc, tri, p), pdf_a, 1e-4f);
		assert_float_equal(emitter_radiance(&l.sc, tri, p, v3(0, 0, 1)).x, 2.0f, 0.0f);
		int i = (int)fminf((p.x - 0.5f) * 2 * G, G - 1), j = (int)fminf(p.y * G, G - 1);
		obs[j * G + i] += 1.0;
	}
	for (int c = 0; c < G * G; c++)
		expct[c] = (double)N / (G * G);
	double p = chi2_test(obs, expct, G * G, 5.0);
	printf("  points on the lit half: p = %.3f\n", p);
	assert_true(p > ALPHA);
	/* The black half: no emission and zero density. */
	V3 dark = v3(0.25f, 0.6f, 0.0f);
	int t = 1; /* (0,0) (1,1) (0,1) holds x < y */
	assert_true(v3_is_zero(emitter_radiance(&l.sc, t, dark, v3(0, 0, 1))));
	assert_float_equal(emitter_pdf_a(&l.sc, t, dark), 0.0f, 0.0f);

	/* An alpha-masked emitter (checker of 4 x 4 texels, clear where
	 * x + y is even): half the power, sampled only where it is. */
	lit_free(&l);
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint8_t chk[4 * 4 * 4];
	for (int i = 0; i < 16; i++) {
		chk[4 * i] = chk[4 * i + 1] = chk[4 * i + 2] = 255;
		chk[4 * i + 3] = ((i % 4) + (i / 4)) % 2 ? 255 : 0;
	}
	assert_int_equal(scene_add_texture(l.s, 4, 4, chk, &img), AJAR_OK);
	assert_int_equal(scene_add_texture_use(l.s, img, TEX_NEAREST, xf, &tex), AJAR_OK);
	m = add_material(l.s, v3(2, 2, 2));
	l.s->materials[m].base_tex = (int)tex;
	l.s->materials[m].base_alpha = 1.0f;
	l.s->materials[m].alpha_cutoff = 0.5f;
	l.s->materials[m].flags = MATERIAL_ALPHA_MASK;
	assert_int_equal(scene_add_triangles(l.s, "quad", pos, NULL, uv, 4, idx, 2, m), AJAR_OK);
	lit_build(&l);
	assert_float_equal(l.lt.emitter_power, AJAR_PI, 1e-5 * AJAR_PI);
	for (int k = 0; k < 2000; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		int ix = (int)fminf(p.x * 4, 3), iy = (int)fminf(p.y * 4, 3);
		assert_true((ix + iy) % 2 == 1);
		assert_float_equal(pdf_a, 2.0f, 1e-4f);
		assert_float_equal(emitter_radiance(&l.sc, tri, p, v3(0, 0, 1)).x, 2.0f, 0.0f);
	}

	/* The metallic-roughness texture (linear, B metallic, G roughness)
	 * times the factors, sRGB decoding only for colour. */
	uint8_t mr[4] = {0, 128, 64, 255};
	uint32_t mimg;
	assert_int_equal(scene_add_texture(l.s, 1, 1, mr, &mimg), AJAR_OK);
	l.sc.textures = l.s->textures;
	l.sc.texels = l.s->texels;
	Material *mm = &l.s->materials[m];
	mm->metallic = 1.0f;
	mm->roughness = 0.5f;
	mm->mr_tex = (int)mimg + 1;
	mm->base_tex = (int)mimg;
	Surface s;
	memset(&s, 0, sizeof s);
	s.material = (int)m;
	s.ng = s.ns = v3(0, 0, 1);
	s.tu = s.tv = 0.3f;
	s.color = v3(1, 1, 1);
	s.alpha = 1.0f;
	Bsdf bs;
	surface_bsdf(&l.sc, &s, surface_base_color(&l.sc, &s), &bs);
	assert_float_equal(bs.metallic, 64.0f / 255.0f, 1e-6f);
	assert_float_equal(bs.alpha, powf(0.5f * 128.0f / 255.0f, 2.0f), 1e-6f);
	assert_float_equal(bs.base_color.y, 0.5f * srgb_to_linear(128.0f / 255.0f), 1e-6f);
	lit_free(&l);
}

static void test_portal_sampling(void **state)
{
	rng_state = 13;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	add_material(l.s, v3(0, 0, 0));
	/* A 2 x 1 window (two triangles) and a small 0.5 x 0.5 one. */
	float pos[] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0, 5, 0, 0, 5.5f, 0, 0, 5, 0.5f, 0};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3, 4, 5, 6};
	assert_int_equal(scene_add_portal(l.s, "window", pos, 7, idx, 3), AJAR_OK);
	lit_build(&l);
	assert_int_equal(l.lt.nportals, 3);
	double area[3] = {1.0, 1.0, 0.125}, total = 2.125;
	enum { N = 50000 };
	double obs[3] = {0}, expct[3];
	for (int k = 0; k < 3; k++) {
		expct[k] = N * area[k] / total;
		assert_float_equal(l.s->portals[k].pdf_select, area[k] / total, 1e-6);
		assert_float_equal(l.s->portals[k].area, area[k], 1e-6);
	}
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int i = portal_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(i >= 0 && i < 3);
		obs[i] += 1.0;
		assert_float_equal(pdf_a, 1.0 / total, 1e-5);
		assert_float_equal(n.z, 1.0f, 1e-6f);
		assert_float_equal(p.z, 0.0f, 0.0f);
		assert_true(i == 2 ? p.x >= 5.0f && p.x <= 5.5f : p.x >= 0.0f && p.x <= 2.0f);
	}
	double p = chi2_test(obs, expct, 3, 5.0);
	printf("  portal selection: p = %.3f\n", p);
	assert_true(p > ALPHA);
	lit_free(&l);

	/* No portals: nothing to sample. */
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	add_material(l.s, v3(0, 0, 0));
	lit_build(&l);
	V3 pp, nn;
	float pdf_a;
	assert_int_equal(portal_sample(&l.sc, 0.5f, 0.5f, 0.5f, &pp, &nn, &pdf_a), -1);
	lit_free(&l);
}

/* Total solid-angle density of light_sample at x in direction wi: the
 * environment's share plus every emitter the ray crosses (light sampling
 * ignores occlusion, so overlapping emitters add up). */
static double light_density(const Lit *l, V3 x, V3 n, V3 wi)
{
	double pdf = light_pdf_w(&l->sc, x, n, wi, -1, AJAR_INF, 1.0f);
	RayPre r = ray_pre(x, wi);
	for (uint32_t k = 0; k < l->lt.nemitters; k++) {
		int tri = l->lt.emitters[k].tri;
		float t, u, v;
		if (!tri_intersect(&r, &l->tris[tri], AJAR_INF, &t, &u, &v))
			continue;
		pdf += light_pdf_w(&l->sc, x, n, wi, tri, t, -v3_dot(v3_norm(tri_normal(&l->tris[tri])), wi));
	}
	return pdf;
}

/* Directions from x (receiver normal n) binned into equal-area cells
 * (cos theta about +Y, phi), expected counts from light_pdf_w integrated
 * over each cell; one more cell for samples light_sample refused
 * (back-facing emitters). */
static void check_light_sample(Lit *l, V3 x, V3 n, const char *name)
{
	enum { CT = 24, CP = 48, SUB = 24, N = 300000, NC = CT * CP + 1 };
	static double obs[NC], expct[NC];
	memset(obs, 0, sizeof(obs));
	double total = 0.0;
	for (int ct = 0; ct < CT; ct++)
		for (int cp = 0; cp < CP; cp++) {
			double sum = 0.0;
			for (int j = 0; j < SUB; j++)
				for (int i = 0; i < SUB; i++) {
					float c = 1.0f - 2.0f * (ct + (j + 0.5f) / SUB) / CT;
					float phi = 2.0f * AJAR_PI * (cp + (i + 0.5f) / SUB) / CP;
					float s = sqrtf(fmaxf(0.0f, 1.0f - c * c));
					sum += light_density(l, x, n, v3(s * cosf(phi), c, s * sinf(phi)));
				}
			double cell = sum * (4.0 * M_PI / (CT * CP)) / (SUB * SUB);
			expct[ct * CP + cp] = cell * N;
			total += cell;
		}
	expct[NC - 1] = N * (1.0 - total);
	int env_count = 0;
	for (int k = 0; k < N; k++) {
		LightSample ls;
		if (!light_sample(&l->sc, x, n, rnd(), rnd(), rnd(), &ls)) {
			obs[NC - 1] += 1.0;
			continue;
		}
		env_count += ls.is_env;
		assert_true(ls.pdf_w > 0.0f);
		assert_float_equal(v3_len(ls.wi), 1.0f, 1e-5f);
		/* light_pdf_w reproduces the sample's own density. */
		if (ls.is_env) {
			/* Through portals the sample adds its own triangle's term
			 * first, so the sum may round differently. */
			assert_true(ls.dist == AJAR_INF);
			assert_float_equal(light_pdf_w(&l->sc, x, n, ls.wi, -1, ls.dist, 1.0f), ls.pdf_w, 1e-5f * ls.pdf_w);
		} else {
			assert_float_equal(ls.dist, v3_len(v3_sub(ls.p, x)), 1e-5f * ls.dist);
			float cos_light = -v3_dot(ls.n, ls.wi);
			RayPre r = ray_pre(x, ls.wi);
			float t, u, v;
			int tri = -1;
			for (uint32_t e = 0; e < l->lt.nemitters && tri < 0; e++) {
				int ti = l->lt.emitters[e].tri;
				if (tri_intersect(&r, &l->tris[ti], ls.dist * 1.0001f, &t, &u, &v) &&
				    fabsf(t - ls.dist) < 1e-4f * ls.dist)
					tri = ti;
			}
			assert_true(tri >= 0);
			assert_float_equal(light_pdf_w(&l->sc, x, n, ls.wi, tri, ls.dist, cos_light), ls.pdf_w,
					   1e-4f * ls.pdf_w);
			V3 Le = emitter_radiance(&l->sc, tri, ls.p, v3_neg(ls.wi));
			assert_true(Le.x == ls.Le.x && Le.y == ls.Le.y && Le.z == ls.Le.z);
		}
		float c = fminf(fmaxf(ls.wi.y, -1.0f), 1.0f);
		float phi = atan2f(ls.wi.z, ls.wi.x);
		if (phi < 0.0f)
			phi += 2.0f * AJAR_PI;
		int ct = (int)((1.0f - c) * 0.5f * CT), cp = (int)(phi / (2.0f * AJAR_PI) * CP);
		ct = ct < 0 ? 0 : (ct >= CT ? CT - 1 : ct);
		cp = cp < 0 ? 0 : (cp >= CP ? CP - 1 : cp);
		obs[ct * CP + cp] += 1.0;
	}
	double expected_env = N * l->lt.env_pdf_select;
	assert_true(fabs(env_count - expected_env) <= 5.0 * sqrt(expected_env + 1.0));
	double p = chi2_test(obs, expct, NC, 5.0);
	printf("  light_sample %-14s p = %.3f (env picked %.3f, refused %.3f)\n", name, p,
	       (double)env_count / N, obs[NC - 1] / N);
	assert_true(p > ALPHA);
}

/* Emitters around x = (0, 0, 0): a square above, a triangle in front with
 * another behind it (overlapping as seen from x), one facing away, and a
 * non-emissive occluder (light sampling ignores it). */
static void build_light_scene(Lit *l)
{
	assert_int_equal(scene_new("<test>", &l->s), AJAR_OK);
	Scene *s = l->s;
	uint32_t grey = add_material(s, v3(0, 0, 0));
	uint32_t white = add_material(s, v3(1, 1, 1));
	uint32_t red = add_material(s, v3(4, 0.5f, 0.5f));
	uint32_t blue = add_material(s, v3(0.2f, 0.2f, 3));
	/* Square at y = 1.5 facing down (CCW seen from below). */
	add_tri(s, v3(-1, 1.5f, -1), v3(1, 1.5f, -1), v3(1, 1.5f, 1), white);
	add_tri(s, v3(-1, 1.5f, -1), v3(1, 1.5f, 1), v3(-1, 1.5f, 1), white);
	/* Tilted triangle at z ~ -2 facing +z, and a larger one behind it. */
	add_tri(s, v3(-0.5f, -0.5f, -2), v3(1, -0.5f, -2.5f), v3(0, 1, -2), red);
	add_tri(s, v3(-2, -1, -4), v3(2, -1, -4), v3(0, 2, -4), blue);
	/* At x = 2, facing +x: x sees its back. */
	add_tri(s, v3(2, -1, -1), v3(2, 1, -1), v3(2, 0, 1), white);
	/* Occluder below. */
	add_tri(s, v3(-1, -1, -1), v3(1, -1, -1), v3(0, -1, 1), grey);
}

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

/* Portals around x = (0.1, 0.2, 0.05): a window in front, a triangle
 * behind it, a tiny far one, one with x on its sky side and one with no
 * sky behind it (the last two get their sides from the callers). */
static void add_window_portals(Lit *l)
{
	float pos[] = {-0.8f, -0.4f, 1, 0.8f, -0.4f, 1, 0.8f, 0.8f, 1, -0.8f, 0.8f, 1, /* window, z = 1 */
		       0.0f, 0.0f, 2, 1.5f, 0.0f, 2, 1.5f, 1.5f, 2,                /* behind it, z = 2 */
		       3.0f, 0.2f, 2, 3.05f, 0.2f, 2, 3.0f, 0.25f, 2,              /* tiny and far */
		       -1.5f, -1, -1, -1.5f, 1, -1, -1.5f, 0, 1,                   /* x on its sky side */
		       0, -2, -1, 1, -2, 1, -1, -2, 1};                            /* no sky behind it */
	uint32_t idx[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
	assert_int_equal(scene_add_portal(l->s, "windows", pos, 16, idx, 6), AJAR_OK);
	lit_build(l);
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

/* The window [-1, 1] x [-0.6, 0.9] at z = 1 as a 4 x 3 grid of quads. */
enum { GRID_NX = 4, GRID_NY = 3, GRID_NV = (GRID_NX + 1) * (GRID_NY + 1), GRID_NT = 2 * GRID_NX * GRID_NY };
static void grid_window(float *pos, uint32_t *idx)
{
	for (int j = 0; j <= GRID_NY; j++)
		for (int i = 0; i <= GRID_NX; i++) {
			float *v = &pos[3 * (j * (GRID_NX + 1) + i)];
			v[0] = -1.0f + 2.0f * (float)i / GRID_NX;
			v[1] = -0.6f + 1.5f * (float)j / GRID_NY;
			v[2] = 1.0f;
		}
	int t = 0;
	for (int j = 0; j < GRID_NY; j++)
		for (int i = 0; i < GRID_NX; i++) {
			uint32_t a = (uint32_t)(j * (GRID_NX + 1) + i), b = a + 1, c = a + GRID_NX + 2, d = a + GRID_NX + 1;
			uint32_t q[6] = {a, b, c, a, c, d};
			for (int k = 0; k < 6; k++)
				idx[3 * t + k] = q[k];
			t += 2;
		}
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

/* ---- Sky images through planar portals (kernels/light/portal_sky.h) ---------- */

/* Plane k's (U, V) sampler from x against its density, exactly: the
 * density is constant on each table cell within x's rectangle, so a bin
 * of whole cells expects the sum of density times area. Also the
 * directions: (U, V) -> w -> (U, V) round trips, and w lies in the plane's
 * sky half. */
static void check_sky_uv(Lit *l, int k, V3 x, const char *name)
{
	enum { B = PORTAL_SKY_RES / 32, NB = (PORTAL_SKY_RES / B) * (PORTAL_SKY_RES / B), N = 200000 };
	static double obs[NB], expct[NB];
	const PortalPlane *P = &l->planes[k];
	const float *S = l->sky + P->table;
	SkyRect r;
	assert_true(sky_rect(P, x, &r));
	float total = sky_rect_integral(S, &r);
	assert_true(total > 0.0f);
	memset(obs, 0, sizeof obs);
	memset(expct, 0, sizeof expct);
	double sum = 0.0;
	for (int j = (int)r.V0; j < PORTAL_SKY_RES && j < r.V1; j++)
		for (int i = (int)r.U0; i < PORTAL_SKY_RES && i < r.U1; i++) {
			float ulo = fmaxf((float)i, r.U0), uhi = fminf((float)(i + 1), r.U1);
			float vlo = fmaxf((float)j, r.V0), vhi = fminf((float)(j + 1), r.V1);
			double area = (double)(uhi - ulo) * (vhi - vlo);
			if (!(area > 0.0))
				continue;
			double pc = sky_pdf_uv(S, &r, total, 0.5f * (ulo + uhi), 0.5f * (vlo + vhi));
			assert_true(pc > 0.0); /* the floor: no cell within the rectangle is left out */
			expct[(j / B) * (PORTAL_SKY_RES / B) + i / B] += pc * area * N;
			sum += pc * area;
		}
	assert_float_equal(sum, 1.0, 1e-3);
	for (int n = 0; n < N; n++) {
		float U, V, jac, U2, V2, jac2;
		assert_true(sky_sample_uv(S, &r, total, rnd(), rnd(), &U, &V));
		assert_true(U >= r.U0 && U <= r.U1 && V >= r.V0 && V <= r.V1);
		int i = (int)U, j = (int)V;
		i = i >= PORTAL_SKY_RES ? PORTAL_SKY_RES - 1 : i;
		j = j >= PORTAL_SKY_RES ? PORTAL_SKY_RES - 1 : j;
		obs[(j / B) * (PORTAL_SKY_RES / B) + i / B] += 1.0;
		if (n % 16 == 0) {
			V3 w = sky_dir(P, U, V, &jac);
			assert_float_equal(v3_len(w), 1.0f, 1e-5f);
			assert_true(v3_dot(w, P->n) > 0.0f);
			sky_coords(P, w, &U2, &V2, &jac2);
			assert_float_equal(U2, U, 2e-3f);
			assert_float_equal(V2, V, 2e-3f);
			assert_float_equal(jac2, jac, 1e-3f * jac);
		}
	}
	double p = chi2_test(obs, expct, NB, 5.0);
	printf("  sky through plane %d %-12s p = %.3f (rectangle %.1f..%.1f x %.1f..%.1f cells)\n", k, name, p, r.U0,
	       r.U1, r.V0, r.V1);
	assert_true(p > ALPHA);
}

/* The light scene under a sky with a sun seen from x through the window
 * (add_window_portals), its portals' sky sides set as seen from x (the
 * fifth faces the other way, the sixth has no sky): 4 planes. Returns the
 * sun's direction. */
static V3 window_sun_scene(Lit *l, V3 x)
{
	build_light_scene(l);
	V3 sun = v3_norm(v3(0.15f, 0.5f, 1.0f));
	assert_int_equal(scene_set_env_image(l->s, 128, 64, test_sun_sky(128, 64, sun.x, sun.y, sun.z, 0.06f, 300.0f), 0.05f), AJAR_OK);
	add_window_portals(l);
	for (int j = 0; j < 5; j++) {
		PortalTri *pt = &l->s->portals[j];
		float dn = v3_dot(v3_sub(x, pt->p0), pt->n);
		pt->env_side = j == 4 ? (dn > 0 ? 1 : -1) : (dn > 0 ? -1 : 1);
	}
	l->s->portals[5].env_side = 0;
	assert_int_equal(lit_planes(l), 4);
	return sun;
}

/* The portals of test_light_sample_env_portals (a window quad in front of
 * x, an overlapping triangle behind it, a tiny far one in the same plane
 * but apart, one x sees from its sky side, one without sky) and a sky
 * with a sun: they group into four planes, each plane's sampler follows
 * its density, and the whole next-event sample (sky through the planes by
 * radiance, the environment's own sampling as defence, the emitters)
 * follows light_pdf_w, with the sun inside the window's view and outside
 * every portal's. */
static void test_light_sample_sky_portals(void **state)
{
	rng_state = 31;
	Lit l;
	V3 x = v3(0.1f, 0.2f, 0.05f);
	V3 sun = window_sun_scene(&l, x);
	SkyRect r;
	int seen = 0;
	for (int k = 0; k < 4; k++)
		if (sky_rect(&l.planes[k], x, &r)) {
			seen++;
			check_sky_uv(&l, k, x, "");
		}
	assert_int_equal(seen, 3); /* not the one x sees from its sky side */
	check_light_sample(&l, x, v3_norm(v3(0.3f, -0.2f, 0.9f)), "+ sky, planes");
	check_light_sample(&l, x, v3(1, 0, 0), "+ sky sideways");
	check_light_sample(&l, x, v3(0, 0, 0), "+ sky, no n");
	/* From a point that sees the sun through no portal (above the window,
	 * beside the triangle behind it; within that triangle's bounding
	 * rectangle, which its frame along the hypotenuse makes larger). */
	V3 x2 = v3(-0.6f, 0.5f, 0.2f), nx = v3_norm(v3(0.3f, -0.2f, 0.9f));
	SkyWeights sw;
	sky_weights(&l.sc, x, nx, &sw);
	assert_true(sky_portal_pdf_w(&l.sc, &sw, x, nx, sun) > 0.0f);
	assert_int_equal(portal_crossings(&l.sc, x2, sun, 1), 0);
	for (int k = 0; k < 4; k++)
		if (sky_rect(&l.planes[k], x2, &r))
			check_sky_uv(&l, k, x2, "");
	check_light_sample(&l, x2, v3(0, 0, 1), "+ sun outside");
	lit_free(&l);
}

/* The portal part of the sky's next-event density as env_portal.h
 * computed it before the views and the tangent test (session 22): every plane's rectangle, integral and weight again, and sky_coords
 * and sky_pdf_uv for every plane that faces wi. */
static float sky_portal_pdf_ref(const Lit *l, V3 x, V3 n, V3 wi)
{
	int np = l->prm.num_portal_planes;
	SkyRect r[8];
	float mass[8], w[8], W = 0.0f, p = 0.0f;
	assert_true(np <= 8);
	for (int k = 0; k < np; k++) {
		const PortalPlane *P = &l->planes[k];
		w[k] = 0.0f;
		if (!sky_rect(P, x, &r[k]))
			continue;
		mass[k] = sky_rect_integral(l->sky + P->table, &r[k]);
		if (!(mass[k] > 0.0f))
			continue;
		V3 d = v3_sub(sky_plane_centre(P), x);
		float cr = fmaxf(PORTAL_COS_MIN, v3_dot(d, n) / sqrtf(v3_len2(d)));
		w[k] = mass[k] * cr;
		W += w[k];
	}
	if (!(W > 0.0f))
		return -1.0f;
	for (int k = 0; k < np; k++) {
		const PortalPlane *P = &l->planes[k];
		float U, V, jac;
		if (!(v3_dot(wi, P->n) > 0.0f) || !(w[k] > 0.0f))
			continue;
		sky_coords(P, wi, &U, &V, &jac);
		float puv = sky_pdf_uv(l->sky + P->table, &r[k], mass[k], U, V);
		if (puv > 0.0f && jac > 0.0f)
			p += w[k] / W * puv / jac;
	}
	return p;
}

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* The sky's next-event density is the same bits with the planes' views
 * and their tangent test (env_portal.h) as computed from scratch
 * (sky_portal_pdf_ref): from points all about the window, toward
 * directions at random and just inside and outside every rectangle's
 * edges (where the tangent test must keep what sky_pdf_uv keeps), with
 * both sides' normals at one point; and a next-event sample's density,
 * which reuses its drawn cell's knots, is the one computed afresh. */
static void test_sky_pdf_views(void **state)
{
	rng_state = 41;
	Lit l;
	window_sun_scene(&l, v3(0.1f, 0.2f, 0.05f));
	enum { NX = 7 };
	V3 xs[NX];
	for (int i = 0; i < NX; i++)
		xs[i] = v3(4.0f * rnd() - 2.0f, 4.0f * rnd() - 2.0f, 2.5f * rnd() - 1.5f);
	int checked = 0, edge = 0, nonzero = 0, sampled = 0;
	for (int it = 0; it < 4000; it++) {
		V3 x = xs[(it * 5 + it / 7) % NX];
		V3 n = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		if (it % 3 == 1)
			n = v3_neg(n);
		V3 wi;
		int k = (int)(rnd() * 4.0f) & 3;
		SkyRect r;
		if (it % 2 == 0 && sky_rect(&l.planes[k], x, &r)) {
			/* just inside or outside an edge of plane k's rectangle */
			float e = (rnd() - 0.5f) * 2e-3f, U = r.U0 + (r.U1 - r.U0) * rnd(), V = r.V0 + (r.V1 - r.V0) * rnd();
			int side = (int)(rnd() * 4.0f) & 3;
			if (side == 0)
				U = r.U0 + e;
			else if (side == 1)
				U = r.U1 + e;
			else if (side == 2)
				V = r.V0 + e;
			else
				V = r.V1 + e;
			float jac;
			wi = sky_dir(&l.planes[k], fminf(fmaxf(U, 1e-3f), PORTAL_SKY_RES - 1e-3f),
				     fminf(fmaxf(V, 1e-3f), PORTAL_SKY_RES - 1e-3f), &jac);
			edge++;
		} else {
			wi = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		}
		float ref = sky_portal_pdf_ref(&l, x, n, wi);
		SkyWeights a;
		sky_weights(&l.sc, x, n, &a);
		if (ref < 0.0f) {
			assert_false(a.W > 0.0f);
			continue;
		}
		assert_true(same_bits(sky_portal_pdf_w(&l.sc, &a, x, n, wi), ref));
		checked++;
		nonzero += ref > 0.0f;
	}
	/* next-event samples */
	for (int it = 0; it < 2000; it++) {
		V3 x = xs[(it * 3 + it / 5) % NX], n = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		float um = rnd(), u1 = rnd(), u2 = rnd(), pa;
		V3 wa = v3(0, 0, 0);
		sky_nee_sample(&l.sc, x, n, um, u1, u2, &wa, &pa);
		/* through a plane: the density with the drawn cell's knots is the
		 * one computed afresh from the direction */
		if (um < PORTAL_SKY_NEE_MIX && pa > 0.0f) {
			assert_true(same_bits(pa, sky_nee_pdf_w(&l.sc, x, n, wa, env_pdf_w(&l.sc, wa))));
			sampled++;
		}
	}
	printf("  %d densities (%d nonzero, %d toward rectangle edges) and %d samples' the same bits\n", checked,
	       nonzero, edge, sampled);
	assert_true(checked > 1000 && nonzero > 300 && edge > 1000 && sampled > 500);
	lit_free(&l);
}

/* A window in a grid of 24 triangles (one plane), seen from close by and
 * off its centre, and single-triangle portals (directions in their
 * bounding rectangles but outside them are valid samples of the plane). */
static void test_light_sample_sky_grid(void **state)
{
	rng_state = 37;
	Lit l;
	build_light_scene(&l);
	V3 sun = v3_norm(v3(-0.2f, 0.3f, 1.0f));
	assert_int_equal(scene_set_env_image(l.s, 128, 64, test_sun_sky(128, 64, sun.x, sun.y, sun.z, 0.05f, 500.0f), 0.05f), AJAR_OK);
	enum { NV = GRID_NV, NT = GRID_NT };
	float pos[3 * NV + 36];
	uint32_t idx[3 * NT + 12];
	grid_window(pos, idx);
	/* A triangle in the plane x = 1.2, tilted against the grid, and three
	 * apart in the plane z = 1.6 behind it: more planes than the sampler
	 * keeps weights for (SKY_KEPT), so the rest are weighed again. */
	const float tri[4][9] = {{1.2f, -0.5f, -0.5f, 1.2f, 0.9f, 0.2f, 1.2f, 0.0f, 0.8f},
				 {-0.6f, 0.2f, 1.6f, -0.3f, 0.2f, 1.6f, -0.4f, 0.5f, 1.6f},
				 {0.1f, -0.3f, 1.6f, 0.4f, -0.3f, 1.6f, 0.3f, 0.0f, 1.6f},
				 {0.5f, 0.4f, 1.6f, 0.8f, 0.4f, 1.6f, 0.7f, 0.7f, 1.6f}};
	for (int k = 0; k < 4; k++) {
		memcpy(&pos[3 * (NV + 3 * k)], tri[k], sizeof tri[k]);
		for (int c = 0; c < 3; c++)
			idx[3 * (NT + k) + c] = (uint32_t)(NV + 3 * k + c);
	}
	assert_int_equal(scene_add_portal(l.s, "grid", pos, NV + 12, idx, NT + 4), AJAR_OK);
	lit_build(&l);
	V3 x = v3(0.3f, 0.1f, 0.75f);
	for (int j = 0; j < NT + 4; j++)
		l.s->portals[j].env_side = v3_dot(v3_sub(x, l.s->portals[j].p0), l.s->portals[j].n) > 0 ? -1 : 1;
	assert_int_equal(lit_planes(&l), 5);
	assert_true(5 > SKY_KEPT);
	check_sky_uv(&l, 0, x, "near");
	check_sky_uv(&l, 1, x, "triangle");
	check_light_sample(&l, x, v3_norm(v3(0.2f, -0.3f, 0.9f)), "+ sky grid");
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
		cmocka_unit_test(test_emissive_texture),
		cmocka_unit_test(test_env_black_and_color),
		cmocka_unit_test(test_emitter_sampling),
		cmocka_unit_test(test_portal_sampling),
		cmocka_unit_test(test_light_sample_emitters),
		cmocka_unit_test(test_light_sample_env_color),
		cmocka_unit_test(test_light_sample_env_image),
		cmocka_unit_test(test_light_sample_env_portals),
		cmocka_unit_test(test_light_sample_env_portal_near),
		cmocka_unit_test(test_light_sample_env_portal_grid),
		cmocka_unit_test(test_light_sample_sky_portals),
		cmocka_unit_test(test_light_sample_sky_grid),
		cmocka_unit_test(test_sky_pdf_views),
	};
	/* test_lights_fine (Makefile): the planes' tables at PORTAL_SKY_RES
	 * cells a side, as pt takes them under large skies (src/prepare/prepare.c,
	 * sky_table_res): the sky-through-planes tests alone, the last three. */
	enum { NT = sizeof tests / sizeof tests[0], FINE = 3 };
	if (PORTAL_SKY_RES != 128)
		return _cmocka_run_group_tests("lights, fine sky tables", tests + NT - FINE, FINE, NULL, NULL);
	return cmocka_run_group_tests(tests, NULL, NULL);
}
