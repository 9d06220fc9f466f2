/* test_render.c — whole renders through the public API, checked against
 * answers known independently of Ajar:
 *   - furnaces with analytic radiance (a convex Lambertian box under a
 *     constant sky; a closed emissive Lambertian box with a depth limit);
 *   - a turned sky seen directly: the column the device shows against one
 *     worked out here from the rotation convention;
 *   - the Cornell box against Mitsuba 3's converged 8192-spp reference;
 *   - determinism (same seed, same bits) and cancellation.
 *
 * Tolerances come from the renders' own noise: an independent second
 * render estimates each pixel's variance, so a threshold in units of the
 * predicted standard error stays meaningful whatever the sample count.
 * Furnace means must lie within 4 standard errors (a false alarm once in
 * ~16000 runs per check); the standard error comes from the spread of the
 * pixels, which share one expected value. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "image/exr.h"
#include "prepare/prepare.h"
#include "render/render_overrides.h"
#include "testutil.h"

#include <unistd.h>

static float *render(ajar_scene *s, uint32_t w, uint32_t h, uint32_t spp, uint32_t seed, uint32_t depth)
{
	ajar_options o;
	ajar_renderer *r = NULL;
	ajar_options_default(&o);
	o.width = w;
	o.height = h;
	o.spp = spp;
	o.seed = seed;
	o.max_depth = depth;
	ajar_status st = ajar_renderer_create(s, &o, &r);
	if (st != AJAR_OK)
		fail_msg("renderer: %s", ajar_last_error());
	st = ajar_renderer_render(r, NULL, NULL);
	if (st != AJAR_OK)
		fail_msg("render: %s", ajar_last_error());
	assert_int_equal(ajar_renderer_spp(r), spp);
	float *img = malloc(sizeof(float) * 4 * w * h);
	assert_non_null(img);
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	ajar_renderer_destroy(&r);
	assert_null(r);
	return img;
}

/* A unit cube [c-h, c+h]^3; `inward` winds the faces so their front (CCW)
 * faces the inside. */
static void add_cube(ajar_scene *s, uint32_t mat, float c, float hs, int inward)
{
	float p[8 * 3];
	for (int i = 0; i < 8; i++) {
		p[3 * i + 0] = c + ((i & 1) ? hs : -hs);
		p[3 * i + 1] = c + ((i & 2) ? hs : -hs);
		p[3 * i + 2] = c + ((i & 4) ? hs : -hs);
	}
	/* Outward-facing CCW quads. */
	static const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
					     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
	uint32_t idx[36];
	for (int f = 0; f < 6; f++) {
		const uint32_t *q = quads[f];
		uint32_t t[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
		for (int k = 0; k < 6; k++)
			idx[6 * f + k] = inward ? t[(k / 3) * 3 + 2 - k % 3] : t[k];
	}
	ajar_mesh m = {p, NULL, NULL, 8, idx, 12, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &m), AJAR_OK);
}

static void set_camera(ajar_scene *s, float px, float py, float pz, float yfov)
{
	ajar_camera cam = {{px, py, pz}, {0, 0, 0}, {0, 1, 0}, yfov, 0};
	assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
}

/* Mean and standard error of the mean over a block of pixels (channel c). */
static void block_stats(const float *img, uint32_t w, uint32_t x0, uint32_t y0, uint32_t n, int c, double *mean,
			double *sem)
{
	double s = 0, s2 = 0;
	for (uint32_t y = y0; y < y0 + n; y++)
		for (uint32_t x = x0; x < x0 + n; x++) {
			double v = img[4 * (y * w + x) + c];
			s += v;
			s2 += v * v;
		}
	double m = (double)n * n;
	*mean = s / m;
	*sem = sqrt(fmax(s2 / m - *mean * *mean, 0) / (m - 1));
}

/* Under a constant sky E, every point of a convex Lambertian object with
 * albedo rho has radiance rho * E (it sees only sky). Exercises env NEE,
 * BSDF sampling of the sky and their MIS. */
static void test_furnace_convex(void **state)
{
	ajar_scene *s;
	ajar_material m;
	uint32_t mat;
	const float sky[3] = {1.0f, 0.5f, 0.25f};
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material_default(&m);
	m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.6f;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	add_cube(s, mat, 0.0f, 1.0f, 0);
	assert_int_equal(ajar_scene_set_environment_color(s, sky), AJAR_OK);
	set_camera(s, 0.3f, 0.4f, 5.0f, 0.9f);
	float *img = render(s, 48, 48, 512, 1, 64);
	for (int c = 0; c < 3; c++) {
		double mean, sem;
		block_stats(img, 48, 16, 16, 16, c, &mean, &sem);
		double want = 0.6 * sky[c];
		print_message("furnace convex, channel %d: %.5f +- %.5f, want %.5f\n", c, mean, sem, want);
		if (fabs(mean - want) > 4 * sem + 1e-5)
			fail_msg("channel %d: cube radiance %.5f +- %.5f, want %.5f", c, mean, sem, want);
		/* The corner sees the sky directly: exact. */
		assert_float_equal(img[c], sky[c], 1e-5);
	}
	free(img);
	ajar_scene_destroy(&s);
	assert_null(s);
}

/* A UV sphere of radius 1 at the origin, flat-faceted (no normals): a
 * convex object whose facets face every direction. */
static void add_sphere(ajar_scene *s, uint32_t mat)
{
	enum { NT = 24, NP = 48 };
	static float p[(NT + 1) * NP * 3];
	static uint32_t idx[NT * NP * 6];
	uint32_t n = 0;
	for (int i = 0; i <= NT; i++)
		for (int j = 0; j < NP; j++) {
			double th = M_PI * i / NT, ph = 2 * M_PI * j / NP;
			p[3 * (i * NP + j) + 0] = (float)(sin(th) * cos(ph));
			p[3 * (i * NP + j) + 1] = (float)cos(th);
			p[3 * (i * NP + j) + 2] = (float)(sin(th) * sin(ph));
		}
	for (int i = 0; i < NT; i++)
		for (int j = 0; j < NP; j++) {
			uint32_t a = (uint32_t)(i * NP + j), b = (uint32_t)(i * NP + (j + 1) % NP);
			uint32_t c = a + NP, d = b + NP;
			if (i > 0) { /* the poles' degenerate triangles are left out */
				idx[n++] = a;
				idx[n++] = b;
				idx[n++] = c;
			}
			if (i < NT - 1) {
				idx[n++] = b;
				idx[n++] = d;
				idx[n++] = c;
			}
		}
	ajar_mesh m = {p, NULL, NULL, (NT + 1) * NP, idx, n / 3, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &m), AJAR_OK);
}

/* White furnace: a white sphere (base colour 1) under a white sky (1)
 * vanishes: every facet reflects all the light at every angle, which the
 * energy compensation of kernels/material/bsdf.h (metal multiple scattering, the
 * base under the dielectric coat) makes true for every roughness. The
 * image must average 1 within 4 standard errors plus 3e-3, the
 * tables' interpolation error at grazing angles (test_bsdf measures it);
 * single scattering alone gave 0.33 for metal at roughness 1. */
static void test_furnace_white(void **state)
{
	const float rough[] = {0.05f, 0.25f, 0.5f, 1.0f};
	const float one[3] = {1, 1, 1};
	static const char *names[] = {"plastic", "metal", "glass"};
	for (int fam = 0; fam < 3; fam++)
		for (int ri = 0; ri < 4; ri++) {
			ajar_scene *s;
			ajar_material m;
			uint32_t mat;
			assert_int_equal(ajar_scene_create(&s), AJAR_OK);
			ajar_material_default(&m);
			m.metallic = fam == 1 ? 1.0f : 0.0f;
			m.transmission = fam == 2 ? 1.0f : 0.0f;
			m.roughness = rough[ri];
			m.specular = 1.0f;
			m.base_color[0] = m.base_color[1] = m.base_color[2] = 1.0f;
			assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
			add_sphere(s, mat);
			assert_int_equal(ajar_scene_set_environment_color(s, one), AJAR_OK);
			set_camera(s, 0.0f, 0.0f, 4.0f, 0.6f); /* the sphere: a disk 40 pixels across */
			float *img = render(s, 48, 48, 64, 11, fam == 2 ? 64 : 16); /* light crosses glass in >= 3 segments */
			double mean, sem;
			block_stats(img, 48, 0, 0, 48, 1, &mean, &sem); /* sky pixels are exactly 1 */
			print_message("white furnace %s r %.2f: %.5f +- %.5f\n", names[fam], rough[ri], mean, sem);
			if (fabs(mean - 1) > 4 * sem + 3e-3)
				fail_msg("%s r %g: white sphere %.5f +- %.5f, want 1", names[fam], rough[ri], mean, sem);
			free(img);
			ajar_scene_destroy(&s);
		}
}

/* The device turns the sky as the host code does (kernels/light/env.h): a 4 x 2
 * sky whose columns have red 1..4 and whose rows have green 1, 2; a narrow
 * camera at each column centre's horizontal direction sees, with the sky
 * turned by `deg`, the column found by turning the view back by -deg
 * (right-handed about +Y, x' = c x - s z, z' = s x + c z), worked out
 * here without env.h. A triangle far below keeps the scene non-empty. */
static void test_sky_rotation(void **state)
{
	char *dir = test_tmpdir(), *sky = test_path(dir, "sky.exr");
	float rgba[4 * 2 * 4];
	for (int y = 0; y < 2; y++)
		for (int x = 0; x < 4; x++) {
			float *p = rgba + 4 * (y * 4 + x);
			p[0] = (float)(x + 1);
			p[1] = (float)(y + 1);
			p[2] = 0.0f;
			p[3] = 1.0f;
		}
	assert_int_equal(ajar_write_exr(sky, rgba, 4, 2, NULL, 0), AJAR_OK);
	static const float degs[] = {0.0f, 90.0f, -90.0f, 30.0f};
	for (size_t k = 0; k < sizeof degs / sizeof degs[0]; k++)
		for (int view = 0; view < 4; view++) {
			ajar_scene *s;
			ajar_material m;
			uint32_t mat;
			assert_int_equal(ajar_scene_create(&s), AJAR_OK);
			ajar_material_default(&m);
			assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
			float tri[9] = {0, -100, 0, 1, -100, 0, 0, -100, 1};
			uint32_t idx[3] = {0, 1, 2};
			ajar_mesh mesh = {tri, NULL, NULL, 3, idx, 1, mat, NULL};
			assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
			assert_int_equal(ajar_scene_set_environment_image(s, sky, 1.0f), AJAR_OK);
			assert_int_equal(ajar_scene_set_environment_rotation(s, degs[k]), AJAR_OK);
			/* View a little above the horizon, at column `view`'s centre. */
			double phi = 2.0 * M_PI * ((view + 0.5) / 4.0 - 0.5);
			float dx = (float)sin(phi), dz = (float)-cos(phi);
			ajar_camera cam = {{0, 0, 0}, {dx, 0.3f, dz}, {0, 1, 0}, 0.02f, 0};
			assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
			float *img = render(s, 4, 4, 2, 1, 4);
			double a = degs[k] * M_PI / 180.0, c = cos(a), sn = sin(a);
			double ix = c * dx - sn * dz, iz = sn * dx + c * dz;
			double u = 0.5 + atan2(ix, -iz) / (2.0 * M_PI);
			int col = (int)floor(u * 4.0 + 1e-9) % 4;
			for (int i = 0; i < 16; i++) {
				if (fabsf(img[4 * i] - (float)(col + 1)) > 1e-5f || fabsf(img[4 * i + 1] - 1.0f) > 1e-5f)
					fail_msg("turned %g, view %d: pixel %d is (%g, %g), want column %d (%d, 1)", degs[k],
						 view, i, img[4 * i], img[4 * i + 1], col, col + 1);
			}
			free(img);
			ajar_scene_destroy(&s);
		}
	free(sky);
	test_remove_tree(dir);
	free(dir);
}

/* Inside a closed box whose walls emit Le and reflect with albedo rho, a
 * path of at most D segments gathers Le * (1 + rho + ... + rho^(D-1)). */
static void test_furnace_closed(void **state)
{
	ajar_scene *s;
	ajar_material m;
	uint32_t mat;
	const double rho = 0.5, Le = 0.8;
	const int depth = 5;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material_default(&m);
	m.base_color[0] = m.base_color[1] = m.base_color[2] = (float)rho;
	m.emission[0] = m.emission[1] = m.emission[2] = (float)Le;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	add_cube(s, mat, 0.0f, 1.0f, 1);
	set_camera(s, 0.2f, -0.1f, 0.5f, 1.2f);
	float *img = render(s, 32, 32, 512, 3, depth);
	double want = Le * (1 - pow(rho, depth)) / (1 - rho);
	for (int c = 0; c < 3; c++) {
		double mean, sem;
		block_stats(img, 32, 0, 0, 32, c, &mean, &sem);
		print_message("furnace closed, channel %d: %.5f +- %.5f, want %.5f\n", c, mean, sem, want);
		if (fabs(mean - want) > 4 * sem + 1e-5)
			fail_msg("channel %d: furnace %.5f +- %.5f, want %.5f", c, mean, sem, want);
	}
	free(img);
	ajar_scene_destroy(&s);
}

/* relMSE of a against b, normalised by the reference r: mean (a-b)^2/(r^2+eps). */
static double rel_mse(const float *a, const float *b, const float *r, size_t npix)
{
	double sum = 0;
	for (size_t i = 0; i < npix; i++)
		for (int c = 0; c < 3; c++) {
			double d = a[4 * i + c] - b[4 * i + c], ref = r[4 * i + c];
			sum += d * d / (ref * ref + 1e-2);
		}
	return sum / (3.0 * npix);
}

static double image_mean(const float *img, size_t npix)
{
	double s = 0;
	for (size_t i = 0; i < npix; i++)
		s += img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
	return s / (3.0 * npix);
}

/* The Cornell box against Mitsuba 3 at 8192 spp (tests/refs/README.md).
 * Two renders A and B with different seeds give the noise: E|A-B|^2 is
 * twice the per-pixel variance, so an unbiased A has
 *   E relMSE(A, ref) = relMSE(A, B) / 2 * (1 + n / 8192)
 * (the reference's own noise at 8192 spp adds the last term). A bias adds
 * its square on top; the test allows 15% over the prediction, far less
 * than a wrong BSDF, emitter or MIS weight adds at this sample count. The
 * image means must also agree within 4 standard errors plus 0.3%, the
 * spread among independent renderers on this scene (shared/peers.md). */
static void test_cornell_reference(void **state)
{
	ajar_scene *s;
	float *ref;
	uint32_t rw, rh;
	const uint32_t n = 32;
	assert_int_equal(ajar_read_exr("tests/refs/cornell-mitsuba-8192.exr", &ref, &rw, &rh), AJAR_OK);
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	float *a = render(s, rw, rh, n, 11, 64);
	float *b = render(s, rw, rh, n, 12, 64);
	size_t npix = (size_t)rw * rh;
	double noise = rel_mse(a, b, ref, npix) / 2;
	double predicted = noise * (1.0 + n / 8192.0);
	double err = rel_mse(a, ref, ref, npix);
	double ma = image_mean(a, npix), mb = image_mean(b, npix), mr = image_mean(ref, npix);
	double sem = fabs(ma - mb) / sqrt(2.0) + 1e-9; /* one-sample estimate of the mean's error */
	print_message("cornell %u spp: relMSE vs ref %.5f, predicted by noise %.5f (ratio %.3f); "
		      "mean %.5f / %.5f vs ref %.5f (%+.3f%%)\n",
		      n, err, predicted, err / predicted, ma, mb, mr, 100 * ((ma + mb) / 2 / mr - 1));
	assert_true(err < 1.15 * predicted);
	assert_true(fabs((ma + mb) / 2 - mr) < 4 * sem + 0.003 * mr);
	free(a);
	free(b);
	free(ref);
	ajar_scene_destroy(&s);
}

static void test_same_seed_same_bits(void **state)
{
	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	float *a = render(s, 40, 30, 6, 5, 16);
	float *b = render(s, 40, 30, 6, 5, 16);
	float *c = render(s, 40, 30, 6, 6, 16);
	assert_memory_equal(a, b, sizeof(float) * 4 * 40 * 30);
	assert_memory_not_equal(a, c, sizeof(float) * 4 * 40 * 30);
	free(a);
	free(b);
	free(c);
	ajar_scene_destroy(&s);
}

/* The features prepare_scene finds a scene without (KERNEL_OMIT_*). */
static unsigned scene_omit(const char *path)
{
	ajar_scene *s;
	SceneData d;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	ajar_options po;
	ajar_options_default(&po);
	po.max_depth = 8;
	po.mis = AJAR_MIS_POWER;
	if (prepare_scene(s, &po, 8, 8, NULL, &d) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	unsigned omit = d.kernel_omit;
	prepare_free(&d);
	ajar_scene_destroy(&s);
	return omit;
}

/* Feature-specialised programs (kernels/material/README.md): the Cornell box
 * has no alpha, no tilted normals, no textures, no TriExtra, no panes, no
 * instances, no layers and no anisotropy, so its program is built with all
 * eight -DAJAR_NO_* options, and renders the same bits as
 * the general program (AJAR_KERNEL_FEATURES=all); scenes that have a
 * feature keep its code; a malformed AJAR_KERNEL_FEATURES is refused. */
static void test_kernel_features(void **state)
{
	(void)state;
	const unsigned all = KERNEL_OMIT_ALPHA | KERNEL_OMIT_BENT_NORMALS | KERNEL_OMIT_TEXTURES | KERNEL_OMIT_TRI_EXTRA |
			     KERNEL_OMIT_PANES | KERNEL_OMIT_INSTANCES | KERNEL_OMIT_LAYERS | KERNEL_OMIT_ANISOTROPY;
	assert_int_equal(scene_omit(SCENE("cornell/cornell.gltf")), all);
	/* A glazed room has panes. */
	assert_int_equal(scene_omit(SCENE("window-room/window-room-glazed.gltf")) & KERNEL_OMIT_PANES, 0);
	unsigned alpha = scene_omit(SCENE("khronos/AlphaBlendModeTest/AlphaBlendModeTest.gltf"));
	assert_int_equal(alpha & (KERNEL_OMIT_ALPHA | KERNEL_OMIT_TEXTURES), 0);
	unsigned nmap = scene_omit(SCENE("khronos/NormalTangentTest/NormalTangentTest.gltf"));
	assert_int_equal(nmap & (KERNEL_OMIT_BENT_NORMALS | KERNEL_OMIT_TEXTURES | KERNEL_OMIT_TRI_EXTRA), 0);
	unsigned colour = scene_omit(SCENE("khronos/VertexColorTest/VertexColorTest.gltf"));
	assert_int_equal(colour & KERNEL_OMIT_TRI_EXTRA, 0);
	/* Layers and anisotropy keep their code where a material has them. */
	assert_int_equal(scene_omit(SCENE("sofa-room/sofa-room.gltf")) & (KERNEL_OMIT_LAYERS | KERNEL_OMIT_ANISOTROPY),
			 KERNEL_OMIT_ANISOTROPY);
	assert_int_equal(scene_omit(SCENE("sofa-room/sofa-room-table.gltf")) & (KERNEL_OMIT_LAYERS | KERNEL_OMIT_ANISOTROPY),
			 0);

	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	float *spec = render(s, 24, 16, 4, 3, 8);
	setenv("AJAR_KERNEL_FEATURES", "all", 1);
	float *general = render(s, 24, 16, 4, 3, 8);
	assert_memory_equal(spec, general, sizeof(float) * 4 * 24 * 16);
	setenv("AJAR_KERNEL_FEATURES", "some", 1);
	ajar_options o;
	ajar_renderer *r = NULL;
	ajar_options_default(&o);
	o.width = o.height = 8;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "AJAR_KERNEL_FEATURES"));
	unsetenv("AJAR_KERNEL_FEATURES");
	free(spec);
	free(general);
	ajar_scene_destroy(&s);
}

/* Without portals the portal integrator is bdpt, sample for sample. Where
 * light subpaths bring the light in through them (a sky image with a sun,
 * a sun lamp, a lamp in the room; src/prepare/policy.c) it is bdpt joining eye
 * vertices to the first POLICY_PORTAL_BDPT_CONN light vertices (bdpt with
 * that connection set forced); under a constant sky it is neither. */
static void test_portal_as_bdpt(void **state)
{
	static const char *scenes[] = {"cornell/cornell.gltf", "window-room-forest/window-room-forest.gltf",
				       "window-room-sun/window-room-sun.gltf", "window-room-lamp/window-room-lamp.gltf",
				       "window-room/window-room.gltf"};
	for (int i = 0; i < 5; i++) {
		ajar_scene *s;
		ajar_renderer *r;
		ajar_options o;
		float a[24 * 24 * 4], b[24 * 24 * 4];
		char path[256];
		snprintf(path, sizeof path, SCENE("%s"), scenes[i]);
		assert_int_equal(ajar_scene_load(path, &s), AJAR_OK);
		ajar_options_default(&o);
		o.width = o.height = 24;
		o.spp = 4;
		o.seed = 9;
		for (int k = 0; k < 2; k++) {
			o.integrator = k ? AJAR_INTEGRATOR_PORTAL : AJAR_INTEGRATOR_BDPT;
			PolicyOverrides over = {0};
			if (k == 0 && i >= 1 && i <= 3) {
				over.bdpt_conn_given = 1;
				over.bdpt_conn = POLICY_PORTAL_BDPT_CONN;
			}
			assert_int_equal(renderer_create_overridden(s, &o, &over, &r), AJAR_OK);
			assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
			assert_int_equal(ajar_renderer_image(r, k ? b : a, NULL, NULL), AJAR_OK);
			ajar_renderer_destroy(&r);
		}
		if (i < 4)
			assert_memory_equal(a, b, sizeof a);
		else
			assert_memory_not_equal(a, b, sizeof a);
		ajar_scene_destroy(&s);
	}
}

/* AJAR_MIS_AUTO, the default: the balance heuristic under a sky image whose
 * sun shines in through the portals and is the only light (bdpt and portal
 * alike), the power heuristic elsewhere: under a constant sky, a sun lamp,
 * and the same sunny sky with a lamp added. Compared bit for bit with the
 * heuristic named. */
static void render_with(ajar_scene *s, ajar_integrator integ, ajar_mis mis, const PolicyOverrides *over, float *img)
{
	ajar_renderer *r;
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = 16;
	o.spp = 2;
	o.seed = 5;
	o.integrator = integ;
	o.mis = mis;
	assert_int_equal(renderer_create_overridden(s, &o, over, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	ajar_renderer_destroy(&r);
}

static void render_mis(ajar_scene *s, ajar_integrator integ, ajar_mis mis, float *img)
{
	render_with(s, integ, mis, NULL, img);
}

static void test_mis_auto(void **state)
{
	static const struct {
		const char *scene;
		int lamp;
		ajar_mis want;
	} cases[] = {
		{"window-room-forest/window-room-forest.gltf", 0, AJAR_MIS_BALANCE},
		{"window-room-sunset/window-room-sunset.gltf", 0, AJAR_MIS_BALANCE},
		{"window-room-forest/window-room-forest.gltf", 1, AJAR_MIS_POWER},
		{"window-room-sun/window-room-sun.gltf", 0, AJAR_MIS_POWER},
		{"window-room/window-room.gltf", 0, AJAR_MIS_POWER},
	};
	static float a[16 * 16 * 4], b[16 * 16 * 4], c[16 * 16 * 4];
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		ajar_scene *s;
		char path[256];
		snprintf(path, sizeof path, SCENE("%s"), cases[i].scene);
		assert_int_equal(ajar_scene_load(path, &s), AJAR_OK);
		if (cases[i].lamp) {
			ajar_light l;
			ajar_light_default(&l);
			l.position[1] = 1.5f;
			l.intensity = 50.0f;
			assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
		}
		for (int k = 0; k < 2; k++) {
			ajar_integrator integ = k ? AJAR_INTEGRATOR_PORTAL : AJAR_INTEGRATOR_BDPT;
			render_mis(s, integ, AJAR_MIS_AUTO, a);
			render_mis(s, integ, cases[i].want, b);
			render_mis(s, integ, cases[i].want == AJAR_MIS_BALANCE ? AJAR_MIS_POWER : AJAR_MIS_BALANCE, c);
			print_message("%s%s, %s: auto is %s\n", cases[i].scene, cases[i].lamp ? " with a lamp" : "",
				      k ? "portal" : "bdpt", cases[i].want == AJAR_MIS_BALANCE ? "balance" : "power");
			assert_memory_equal(a, b, sizeof a);
			assert_memory_not_equal(a, c, sizeof a);
		}
		ajar_scene_destroy(&s);
	}
}

/* The planes' sky tables: 512 cells a side for pt under a sky of 2048
 * columns, 256 under a shipped 1k sky (src/prepare/policy.c, sky_res), 128
 * for bdpt; each default compared bit for bit with the resolution forced,
 * and pt's with 128. */
static void render_sky_res(ajar_scene *s, ajar_integrator integ, int res, float *img)
{
	const PolicyOverrides over = {.sky_res = res};
	render_with(s, integ, AJAR_MIS_AUTO, &over, img);
}

static void test_sky_table_res(void **state)
{
	static float a[16 * 16 * 4], b[16 * 16 * 4];
	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("window-room/window-room.gltf"), &s), AJAR_OK);
	float *sky = test_sun_sky(2048, 1024, 0.1f, 0.74f, -0.67f, 0.01f, 4800.0f);
	assert_int_equal(scene_set_env_image(s, 2048, 1024, sky, 1.0f), AJAR_OK);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 0, a);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 512, b);
	assert_memory_equal(a, b, sizeof a);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 128, b);
	assert_memory_not_equal(a, b, sizeof a);
	render_sky_res(s, AJAR_INTEGRATOR_BDPT, 0, a);
	render_sky_res(s, AJAR_INTEGRATOR_BDPT, 128, b);
	assert_memory_equal(a, b, sizeof a);
	ajar_scene_destroy(&s);
	assert_int_equal(ajar_scene_load(SCENE("window-room-forest/window-room-forest.gltf"), &s), AJAR_OK);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 0, a);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 256, b);
	assert_memory_equal(a, b, sizeof a);
	render_sky_res(s, AJAR_INTEGRATOR_PT, 128, b);
	assert_memory_not_equal(a, b, sizeof a);
	ajar_scene_destroy(&s);
}

/* Strategy images: written with their header, refused when not kept. */
static void test_strategy_file(void **state)
{
	ajar_scene *s;
	ajar_renderer *r;
	ajar_options o;
	char *dir = test_tmpdir(), path[256], value[128];
	assert_non_null(dir);
	snprintf(path, sizeof path, "%s/strategies.exr", dir);
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	ajar_options_default(&o);
	o.width = o.height = 16;
	o.spp = 2;
	o.integrator = AJAR_INTEGRATOR_BDPT;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_strategies(r, path), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_renderer_destroy(&r);
	o.strategy_len = 2;
	o.strategy_unweighted = 1;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_strategies(r, path), AJAR_OK);
	assert_int_equal(exr_read_attr(path, "ajar:strategies", value, sizeof value), AJAR_OK);
	assert_string_equal(value, "unweighted");
	assert_int_equal(exr_read_attr(path, "ajar:spp", value, sizeof value), AJAR_OK);
	assert_string_equal(value, "2");
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	remove(path);
	rmdir(dir);
	free(dir);
}

static int stop_after_first(const ajar_progress *p, void *user)
{
	int *calls = user;
	(*calls)++;
	return 1;
}

static void test_cancel_keeps_image(void **state)
{
	ajar_scene *s;
	ajar_renderer *r;
	ajar_options o;
	int calls = 0;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	ajar_options_default(&o);
	o.width = o.height = 32;
	o.spp = 100000;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, stop_after_first, &calls), AJAR_ERROR_CANCELLED);
	assert_int_equal(calls, 1);
	uint32_t spp = ajar_renderer_spp(r);
	assert_true(spp >= 1 && spp < 100000);
	float img[32 * 32 * 4];
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	assert_true(image_mean(img, 32 * 32) > 0.01);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
}

static void test_bad_options(void **state)
{
	ajar_scene *s;
	ajar_renderer *r = (ajar_renderer *)1;
	ajar_options o;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	ajar_options_default(&o);
	o.max_depth = 2000;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	assert_null(r);
	assert_non_null(strstr(ajar_last_error(), "depth"));
	ajar_options_default(&o);
	o.integrator = AJAR_INTEGRATOR_BDPT;
	o.max_depth = AJAR_BIDIR_MAX_DEPTH + 1;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "at most"));
	ajar_options_default(&o);
	o.strategy_len = 3; /* strategy images need a bidirectional integrator */
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_options_default(&o);
	o.device = "no-such-device-anywhere";
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_DEVICE);
	assert_non_null(strstr(ajar_last_error(), "no-such-device-anywhere"));
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_furnace_convex),
		cmocka_unit_test(test_furnace_closed),
		cmocka_unit_test(test_sky_rotation),
		cmocka_unit_test(test_furnace_white),
		cmocka_unit_test(test_cornell_reference),
		cmocka_unit_test(test_same_seed_same_bits),
		cmocka_unit_test(test_portal_as_bdpt),
		cmocka_unit_test(test_mis_auto),
		cmocka_unit_test(test_sky_table_res),
		cmocka_unit_test(test_strategy_file),
		cmocka_unit_test(test_cancel_keeps_image),
		cmocka_unit_test(test_bad_options),
		cmocka_unit_test(test_kernel_features),
	};
	return cmocka_run_group_tests_name("render", tests, NULL, NULL);
}
