/* test_aov.c — the outputs a denoiser takes, on scenes with analytic
 * values: a camera at the centre of a closed box whose walls all have one
 * albedo (a furnace) sees that albedo in every pixel, the back wall's
 * normal turned toward it, and depths of 1 / |cos| of its rays; a mirror
 * on the back wall shows the front wall's albedo and normal at the
 * mirror's depth; a smooth glass pane in front shows the back wall behind
 * it at the pane's depth. The variance AOV of a pixel whose samples are 0
 * or Le (an emitter edge) is (m Le - m^2) / (n - 1). AOVs are the same bits
 * for every integrator, and the EXR carries the channels asked for. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ajar.h"
#include "image/exr.h"
#include "testutil.h"

#define W 24
#define H 24
#define SPP 16

static uint32_t material(ajar_scene *s, float r, float g, float b, float metallic, float transmission, float emit)
{
	ajar_material m;
	ajar_material_default(&m);
	m.base_color[0] = r;
	m.base_color[1] = g;
	m.base_color[2] = b;
	m.specular = metallic > 0 || transmission > 0 ? 1.0f : 0.0f;
	m.metallic = metallic;
	m.transmission = transmission;
	m.roughness = metallic > 0 || transmission > 0 ? 0.0f : 1.0f;
	m.ior = 1.5f;
	m.emission[0] = m.emission[1] = m.emission[2] = emit;
	m.double_sided = 1;
	uint32_t id;
	assert_int_equal(ajar_scene_add_material(s, &m, &id), AJAR_OK);
	return id;
}

/* A quad with corners a, b, c, d (counter-clockwise seen from its front). */
static void quad(ajar_scene *s, uint32_t mat, const float p[12])
{
	const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	ajar_mesh m = {p, NULL, NULL, 4, idx, 2, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &m), AJAR_OK);
}

/* The box [-1, 1]^3 seen from its centre looking down -Z (60 degrees: every
 * camera ray meets the back wall z = -1 first). back, front: materials of
 * the walls z = -1 and z = +1; the others get `side`. */
static void box_walls(ajar_scene *s, uint32_t back, uint32_t front, uint32_t side)
{
	const float zb[12] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1};
	const float zf[12] = {-1, -1, 1, -1, 1, 1, 1, 1, 1, 1, -1, 1};
	const float xl[12] = {-1, -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1};
	const float xr[12] = {1, -1, -1, 1, -1, 1, 1, 1, 1, 1, 1, -1};
	const float yb[12] = {-1, -1, -1, -1, -1, 1, 1, -1, 1, 1, -1, -1};
	const float yt[12] = {-1, 1, -1, 1, 1, -1, 1, 1, 1, -1, 1, 1};
	quad(s, back, zb);
	quad(s, front, zf);
	quad(s, side, xl);
	quad(s, side, xr);
	quad(s, side, yb);
	quad(s, side, yt);
	ajar_camera c = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, (float)(M_PI / 3), 0};
	assert_int_equal(ajar_scene_set_camera(s, &c), AJAR_OK);
}

static float *render_aovs(ajar_scene *s, ajar_integrator integrator, uint32_t max_depth, float **image)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = SPP;
	o.integrator = integrator;
	o.max_depth = max_depth;
	o.aov = AJAR_AOV_ALL;
	ajar_renderer *r = NULL;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *aov = malloc(sizeof(float) * 10 * W * H);
	assert_non_null(aov);
	assert_int_equal(ajar_renderer_aovs(r, aov), AJAR_OK);
	if (image) {
		*image = malloc(sizeof(float) * 4 * W * H);
		assert_int_equal(ajar_renderer_image(r, *image, NULL, NULL), AJAR_OK);
	}
	ajar_renderer_destroy(&r);
	return aov;
}

/* |cos| of the camera ray through the centre of pixel (x, y), 60 degrees. */
static double center_cos(int x, int y)
{
	double h = tan(M_PI / 6), sx = (2.0 * (x + 0.5) / W - 1) * h, sy = (1 - 2.0 * (y + 0.5) / H) * h;
	return 1.0 / sqrt(1 + sx * sx + sy * sy);
}

/* albedo, normal (nz: its z; x and y are 0) and depth = dist / |cos| in
 * pixels lo..hi-1 of both axes (depth: the pixel's mean over its
 * footprint, which is within 1e-3 of its centre's at this size). */
static void expect(const float *aov, int lo, int hi, const float albedo[3], float nz, double dist)
{
	for (int y = lo; y < hi; y++)
		for (int x = lo; x < hi; x++) {
			const float *a = aov + 10 * (y * W + x);
			for (int c = 0; c < 3; c++)
				if (fabsf(a[c] - albedo[c]) > 2e-6f)
					fail_msg("pixel (%d, %d): albedo[%d] %g, want %g", x, y, c, a[c], albedo[c]);
			if (fabsf(a[3]) > 2e-6f || fabsf(a[4]) > 2e-6f || fabsf(a[5] - nz) > 2e-6f)
				fail_msg("pixel (%d, %d): normal (%g, %g, %g), want (0, 0, %g)", x, y, a[3], a[4], a[5], nz);
			double d = dist / center_cos(x, y);
			if (fabs(a[6] - d) > 1e-3 * d)
				fail_msg("pixel (%d, %d): depth %g, want %g", x, y, a[6], d);
		}
}

static void test_furnace(void **state)
{
	(void)state;
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	uint32_t wall = material(s, 0.3f, 0.5f, 0.7f, 0, 0, 0);
	box_walls(s, wall, wall, wall);
	float *aov = render_aovs(s, AJAR_INTEGRATOR_PT, 0, NULL);
	const float albedo[3] = {0.3f, 0.5f, 0.7f};
	expect(aov, 0, W, albedo, 1.0f, 1.0);
	free(aov);
	ajar_scene_destroy(&s);
}

static void test_mirror(void **state)
{
	(void)state;
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	uint32_t side = material(s, 0.3f, 0.5f, 0.7f, 0, 0, 0);
	uint32_t mirror = material(s, 1, 1, 1, 1, 0, 0), front = material(s, 0.9f, 0.2f, 0.1f, 0, 0, 0);
	box_walls(s, mirror, front, side);
	float *aov = render_aovs(s, AJAR_INTEGRATOR_PT, 0, NULL);
	/* The front wall, seen in the mirror, its normal turned to the ray (-Z):
	 * in the pixels whose reflected rays reach z = +1 within the box (three
	 * times their offset at z = -1 stays under 1: pixels 6..17). */
	const float albedo[3] = {0.9f, 0.2f, 0.1f};
	expect(aov, 6, 18, albedo, -1.0f, 1.0);
	free(aov);
	ajar_scene_destroy(&s);
}

static void test_glass(void **state)
{
	(void)state;
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	uint32_t side = material(s, 0.3f, 0.5f, 0.7f, 0, 0, 0);
	uint32_t glass = material(s, 1, 1, 1, 0, 1, 0), back = material(s, 0.1f, 0.8f, 0.4f, 0, 0, 0);
	box_walls(s, back, side, side);
	const float pane[12] = {-1, -1, -0.5f, 1, -1, -0.5f, 1, 1, -0.5f, -1, 1, -0.5f};
	quad(s, glass, pane);
	float *aov = render_aovs(s, AJAR_INTEGRATOR_PT, 0, NULL);
	/* Refraction bends rays toward the pane's normal: they still meet the back wall. */
	const float albedo[3] = {0.1f, 0.8f, 0.4f};
	expect(aov, 0, W, albedo, 1.0f, 0.5);
	free(aov);
	ajar_scene_destroy(&s);
}

/* Emitter on the left half of the back wall, seen directly only: every
 * sample is 0 or Le, so var(mean) = (m Le - m^2) / (n - 1). */
static void test_variance(void **state)
{
	(void)state;
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	const float le = 2.0f;
	uint32_t black = material(s, 0, 0, 0, 0, 0, 0), light = material(s, 0, 0, 0, 0, 0, le);
	box_walls(s, black, black, black);
	/* Edges through the middle of pixel column 8 and row 12's centre line. */
	double h = tan(M_PI / 6);
	float xe = (float)((2.0 * 8.5 / W - 1) * h * 0.999), ye = (float)((1 - 2.0 * 12.5 / H) * h * 0.999);
	const float half[12] = {-1, -1, -0.999f, xe, -1, -0.999f, xe, ye, -0.999f, -1, ye, -0.999f};
	quad(s, light, half);
	float *img;
	float *aov = render_aovs(s, AJAR_INTEGRATOR_PT, 1, &img);
	int mixed = 0;
	for (int i = 0; i < W * H; i++) {
		double m = img[4 * i], want = (m * le - m * m) / (SPP - 1);
		mixed += m > 0.05 && m < le - 0.05;
		for (int c = 0; c < 3; c++)
			if (fabs(aov[10 * i + 7 + c] - want) > 1e-5 + 1e-4 * want)
				fail_msg("pixel %d: variance %g, want %g (mean %g)", i, aov[10 * i + 7 + c], want, m);
	}
	assert_true(mixed >= 10); /* the edge pixels really mix 0 and Le */
	free(aov);
	free(img);
	ajar_scene_destroy(&s);
}

/* The first-hit AOVs do not depend on the integrator; the EXR carries them. */
static void test_integrators_and_exr(void **state)
{
	(void)state;
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	float *pt = render_aovs(s, AJAR_INTEGRATOR_PT, 0, NULL);
	float *bdpt = render_aovs(s, AJAR_INTEGRATOR_BDPT, 0, NULL);
	for (int i = 0; i < W * H; i++)
		assert_memory_equal(pt + 10 * i, bdpt + 10 * i, 7 * sizeof(float));
	free(pt);
	free(bdpt);

	ajar_options o;
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = 2;
	o.aov = AJAR_AOV_ALBEDO | AJAR_AOV_DEPTH;
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *aov = malloc(sizeof(float) * 10 * W * H);
	assert_int_equal(ajar_renderer_aovs(r, aov), AJAR_OK);
	char *path = test_tmp("aov.exr");
	assert_int_equal(ajar_renderer_write_exr(r, path), AJAR_OK);
	ajar_renderer_destroy(&r);
	/* Channels asked for are in the header, the others not. */
	float *rgba;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(path, &rgba, &w, &h), AJAR_OK);
	free(rgba);
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	char head[4096];
	size_t n = fread(head, 1, sizeof head, f);
	fclose(f);
	int found[4] = {0};
	const char *names[4] = {"albedo.G", "depth.Z", "normal.X", "variance.R"};
	for (int k = 0; k < 4; k++)
		for (size_t i = 0; i + strlen(names[k]) < n; i++)
			found[k] |= memcmp(head + i, names[k], strlen(names[k])) == 0;
	assert_true(found[0] && found[1] && !found[2] && !found[3]);
	unlink(path);
	free(path);
	free(aov);
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_furnace),	  cmocka_unit_test(test_mirror),
		cmocka_unit_test(test_glass),	  cmocka_unit_test(test_variance),
		cmocka_unit_test(test_integrators_and_exr),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
