/* test_subpaths.c — where bdpt's and portal's subpaths live (kernels/integrator/vertex.h,
 * src/device/device_plan.c; kernels/integrator/README.md, "Where subpaths live"): private arrays or the global scratch laid out by work-item, and
 * a pass spread over several work-items a pixel, must render the same image
 * bit for bit on the same device. On PoCL the GPU's layout is forced with
 * AJAR_SUBPATHS=global; a small AJAR_SUBPATH_CAPACITY makes every pass take
 * several launches, and AJAR_PASS_LANES splits each pixel's samples between
 * work-items (atomic adds into the pixel's film and AOVs). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "device/device_plan.h"
#include "testutil.h"
#include "integrator/vertex.h"

/* The host's room for a vertex (device/device_plan.h) holds the kernels' PathVertex. */
_Static_assert(sizeof(PathVertex) <= 4 * DEVICE_VERTEX_WORDS, "PathVertex outgrew DEVICE_VERTEX_WORDS");
_Static_assert(SUBPATH_MAX == DEVICE_SUBPATH_MAX, "SUBPATH_MAX and DEVICE_SUBPATH_MAX differ");

#define W 32
#define H 20

static void setenv_or_unset(const char *name, const char *value)
{
	if (value)
		assert_int_equal(setenv(name, value, 1), 0);
	else
		assert_int_equal(unsetenv(name), 0);
}

/* The image and the AOVs of a render with the storage environment given. */
static void render(const ajar_scene *s, ajar_integrator integ, const char *mode, const char *cap, const char *lanes,
		   float *img, float *aov)
{
	ajar_options o;
	ajar_renderer *r = NULL;
	setenv_or_unset("AJAR_SUBPATHS", mode);
	setenv_or_unset("AJAR_SUBPATH_CAPACITY", cap);
	setenv_or_unset("AJAR_PASS_LANES", lanes);
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = 5;
	o.seed = 11;
	o.integrator = integ;
	o.aov = AJAR_AOV_ALL;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("renderer: %s", ajar_last_error());
	if (ajar_renderer_render(r, NULL, NULL) != AJAR_OK)
		fail_msg("render: %s", ajar_last_error());
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_aovs(r, aov), AJAR_OK);
	ajar_renderer_destroy(&r);
	setenv_or_unset("AJAR_SUBPATHS", NULL);
	setenv_or_unset("AJAR_SUBPATH_CAPACITY", NULL);
	setenv_or_unset("AJAR_PASS_LANES", NULL);
}

/* bdpt and portal on a scene with emitters and a door (door-ajar), one with
 * a sky, a sun and a window (window-room-sun: environment, punctual light,
 * sky-only strategy set) and one with glass and mirrors (bathroom: delta
 * vertices): the same bits from both storage modes, with one lane and
 * with three, in one launch a pass and in several. */
static void test_same_bits_both_layouts(void **state)
{
	(void)state;
	static const char *const scenes[] = {"door-ajar/door-ajar.gltf", "window-room-sun/window-room-sun.gltf",
					     "bathroom/bathroom.gltf"};
	size_t n = 4 * (size_t)W * H, na = (size_t)10 * W * H; /* ajar_renderer_aovs: 10 floats a pixel */
	float *a = calloc(n, sizeof *a), *b = calloc(n, sizeof *b), *aa = calloc(na, sizeof *aa),
	      *ab = calloc(na, sizeof *ab);
	assert_true(a && b && aa && ab);
	for (int i = 0; i < 3; i++) {
		char path[256];
		ajar_scene *s;
		snprintf(path, sizeof path, SCENE("%s"), scenes[i]);
		assert_int_equal(ajar_scene_load(path, &s), AJAR_OK);
		for (int k = 0; k < 2; k++) {
			ajar_integrator integ = k ? AJAR_INTEGRATOR_PORTAL : AJAR_INTEGRATOR_BDPT;
			render(s, integ, NULL, NULL, NULL, a, aa);
			/* 640 pixels: three launches of at most 256 work-items */
			render(s, integ, "global", "256", NULL, b, ab);
			assert_memory_equal(a, b, n * sizeof *a);
			assert_memory_equal(aa, ab, na * sizeof *aa);
			/* three lanes: 1920 work units, eight launches */
			render(s, integ, "global", "256", "3", b, ab);
			assert_memory_equal(a, b, n * sizeof *a);
			assert_memory_equal(aa, ab, na * sizeof *aa);
			/* private arrays, three lanes in one launch */
			render(s, integ, "private", NULL, "3", b, ab);
			assert_memory_equal(a, b, n * sizeof *a);
			assert_memory_equal(aa, ab, na * sizeof *aa);
		}
		ajar_scene_destroy(&s);
	}
	free(a);
	free(b);
	free(aa);
	free(ab);
}

/* Malformed overrides are refused when the renderer is made, naming the
 * variable. */
static void test_bad_overrides(void **state)
{
	(void)state;
	static const char *const vars[][2] = {{"AJAR_SUBPATHS", "shared"}, {"AJAR_PASS_LANES", "0"},
					      {"AJAR_PASS_LANES", "4x"}, {"AJAR_SUBPATH_CAPACITY", "-5"}};
	ajar_scene *s;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	for (int i = 0; i < 4; i++) {
		ajar_options o;
		ajar_renderer *r = NULL;
		ajar_options_default(&o);
		o.width = o.height = 8;
		o.integrator = AJAR_INTEGRATOR_BDPT;
		setenv_or_unset(vars[i][0], vars[i][1]);
		assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
		assert_null(r);
		assert_non_null(strstr(ajar_last_error(), vars[i][0]));
		setenv_or_unset(vars[i][0], NULL);
	}
	ajar_scene_destroy(&s);
}

/* device_plan's choices on the first CPU device, and as it would choose
 * for a device of the same size that is not a CPU. */
static void test_plan(void **state)
{
	(void)state;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t n = 0;
	Device d;
	DevicePlan p;
	cl_uint cu = 0;
	size_t wg = 0;
	if (device_select("cpu", &plat, &id, 1, &n) != AJAR_OK) {
		skip(); /* a GPU machine without PoCL (tests/gpu/run.sh) */
		return;
	}
	assert_int_equal(device_open(&d, plat, id), AJAR_OK);
	clGetDeviceInfo(id, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
	clGetDeviceInfo(id, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof wg, &wg, NULL);
	/* CPU: private arrays, one work-item a pixel */
	for (int integ = 0; integ < 3; integ++) {
		assert_int_equal(device_plan(&d, integ, 640, &p), AJAR_OK);
		assert_int_equal(p.soa, 0);
		assert_int_equal(p.lanes, 1);
		assert_int_equal(p.scratch_bytes, 0);
	}
	/* forced: a scratch of 256 work-items a compute unit */
	assert_int_equal(setenv("AJAR_SUBPATHS", "global", 1), 0);
	assert_int_equal(device_plan(&d, 2, 640, &p), AJAR_OK);
	assert_int_equal(p.soa, 1);
	assert_int_equal(p.capacity, (256 * cu + 63) / 64 * 64);
	assert_int_equal(p.scratch_bytes, p.capacity * (size_t)(4 * SUBPATH_MAX + 1) * DEVICE_VERTEX_WORDS * 4);
	assert_int_equal(device_plan(&d, 1, 640, &p), AJAR_OK);
	assert_int_equal(p.scratch_bytes, p.capacity * (size_t)(2 * SUBPATH_MAX + 1) * DEVICE_VERTEX_WORDS * 4);
	assert_int_equal(device_plan(&d, 0, 640, &p), AJAR_OK); /* pt keeps no subpaths */
	assert_int_equal(p.soa, 0);
	/* more than the device holds: an error, not a failed allocation later */
	assert_int_equal(setenv("AJAR_SUBPATH_CAPACITY", "2000000000", 1), 0);
	assert_int_equal(device_plan(&d, 2, 640, &p), AJAR_ERROR_OUT_OF_MEMORY);
	assert_int_equal(unsetenv("AJAR_SUBPATH_CAPACITY"), 0);
	assert_int_equal(unsetenv("AJAR_SUBPATHS"), 0);
	/* a device that is not a CPU: the scratch by default, and lanes that
	 * fill 2 x compute units x work-group size (at most 64 a pixel) */
	d.is_cpu = 0;
	size_t flight = 2 * (size_t)cu * wg;
	assert_int_equal(device_plan(&d, 1, 640, &p), AJAR_OK);
	assert_int_equal(p.soa, 1);
	assert_int_equal(p.lanes, (flight + 639) / 640 > 64 ? 64 : (flight + 639) / 640);
	assert_true(p.capacity > 0 && p.capacity % 64 == 0 && p.capacity <= (flight + 63) / 64 * 64);
	assert_int_equal(device_plan(&d, 1, 4 * flight, &p), AJAR_OK); /* a large image: one lane */
	assert_int_equal(p.lanes, 1);
	assert_int_equal(device_plan(&d, 0, 640, &p), AJAR_OK);
	assert_int_equal(p.soa, 0);
	d.is_cpu = 1;
	device_close(&d);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_plan),
		cmocka_unit_test(test_bad_overrides),
		cmocka_unit_test(test_same_bits_both_layouts),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
