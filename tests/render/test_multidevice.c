/* test_multidevice.c — rendering on several OpenCL devices at once.
 *
 * PoCL exposes two CPU devices when POCL_DEVICES="pthread pthread" is set
 * before the platform is first initialised (main() does so). Every sample
 * index has its own random stream and the film is 64-bit fixed point, so
 * integer sums do not depend on which device rendered which range: on two
 * identical devices the image must equal the one-device image bit for bit,
 * also after a device fails mid-render (its range, and its completed ones
 * when its film is untrusted, are rendered again by the other). Failures
 * are injected through render_faults (src/render/render_overrides.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "render/render_overrides.h"
#include "testutil.h"

#define W 64
#define H 64
#define SPP 32
#define SEED 7

static struct {
	int warnings;
	char last[2048];
} logged;

static void on_log(ajar_log_level level, const char *message, void *user)
{
	if (level != AJAR_LOG_WARNING)
		return;
	logged.warnings++;
	snprintf(logged.last, sizeof logged.last, "%s", message);
}

static ajar_scene *cornell(void)
{
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	return s;
}

static ajar_renderer *renderer(ajar_scene *s, const char *device, uint32_t spp)
{
	ajar_options o;
	ajar_renderer *r = NULL;
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = spp;
	o.seed = SEED;
	o.device = device;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("renderer on %s: %s", device, ajar_last_error());
	return r;
}

static float *image(ajar_renderer *r)
{
	float *img = malloc(sizeof(float) * 4 * W * H);
	assert_non_null(img);
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	return img;
}

/* A complete render of `spp` samples on `device`. */
static float *render(ajar_scene *s, const char *device, uint32_t spp)
{
	ajar_renderer *r = renderer(s, device, spp);
	if (ajar_renderer_render(r, NULL, NULL) != AJAR_OK)
		fail_msg("render on %s: %s", device, ajar_last_error());
	assert_int_equal(ajar_renderer_spp(r), spp);
	float *img = image(r);
	ajar_renderer_destroy(&r);
	return img;
}

static void test_two_devices_listed(void **state)
{
	ajar_device_info info[8];
	uint32_t n = 0;
	assert_int_equal(ajar_devices(info, 8, &n), AJAR_OK);
	assert_true(n >= 2);
	assert_string_equal(info[0].selector, "0:0");
	assert_string_equal(info[1].selector, "0:1");
}

/* Comma lists and "all" open several devices; a device listed twice or a
 * list item that matches nothing is an error naming it. */
static void test_selectors(void **state)
{
	ajar_scene *s = cornell();
	ajar_renderer *r = renderer(s, " 0:1 , 0:0", 1);
	assert_int_equal(ajar_renderer_device_count(r), 2);
	ajar_device_stats st;
	assert_int_equal(ajar_renderer_device_stats(r, 0, &st), AJAR_OK);
	assert_string_equal(st.selector, "0:1");
	assert_int_equal(ajar_renderer_device_stats(r, 2, &st), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_renderer_device_name(r), " + "));
	ajar_renderer_destroy(&r);
	r = renderer(s, "cpu,cpu", 1);
	assert_int_equal(ajar_renderer_device_count(r), 2);
	ajar_renderer_destroy(&r);
	ajar_options o;
	ajar_options_default(&o);
	o.device = "0:0,0:0";
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_DEVICE);
	assert_non_null(strstr(ajar_last_error(), "'0:0' is listed twice"));
	o.device = "0:0,no-such-device";
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_DEVICE);
	assert_non_null(strstr(ajar_last_error(), "no-such-device"));
	assert_null(r);
	ajar_scene_destroy(&s);
}

/* Two devices give the one-device image bit for bit; every sample is
 * accounted to exactly one device. */
static void test_two_equal_one(void **state)
{
	ajar_scene *s = cornell();
	float *one = render(s, "0:0", SPP);
	ajar_renderer *r = renderer(s, "all", SPP);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), SPP);
	float *two = image(r);
	assert_memory_equal(one, two, sizeof(float) * 4 * W * H);
	assert_int_equal(ajar_renderer_device_count(r), 2);
	uint64_t samples = 0;
	double share = 0;
	for (uint32_t i = 0; i < 2; i++) {
		ajar_device_stats st;
		assert_int_equal(ajar_renderer_device_stats(r, i, &st), AJAR_OK);
		assert_false(st.failed);
		print_message("device %s (%s): %.1f%% of samples, %.3g Msamples/s\n", st.name, st.selector,
			      100 * st.share, st.samples_per_second * 1e-6);
		samples += st.samples;
		share += st.share;
	}
	assert_int_equal(samples, (uint64_t)SPP * W * H);
	assert_float_equal(share, 1.0, 1e-12);
	ajar_renderer_destroy(&r);
	free(one);
	free(two);
	ajar_scene_destroy(&s);
}

/* Device 1 fails at its second pass; device 0 finishes the same image. */
static void fail_second_device(int lost)
{
	ajar_scene *s = cornell();
	float *one = render(s, "0:0", SPP);
	ajar_renderer *r = renderer(s, "0:0,0:1", SPP);
	logged.warnings = 0;
	ajar_set_log_callback(on_log, NULL);
	render_faults = (RenderFaults){.device = 1, .pass = 2, .lost = lost};
	ajar_status st = ajar_renderer_render(r, NULL, NULL);
	render_faults = (RenderFaults){0};
	ajar_set_log_callback(NULL, NULL);
	if (st != AJAR_OK)
		fail_msg("render with device 1 %s at its second pass: %s", lost ? "lost" : "failing", ajar_last_error());
	assert_int_equal(ajar_renderer_spp(r), SPP);
	assert_int_equal(logged.warnings, 1);
	print_message("warning: %s\n", logged.last);
	assert_non_null(strstr(logged.last, "(0:1) dropped"));
	assert_non_null(strstr(logged.last, "an injected fault"));
	ajar_device_stats ds;
	assert_int_equal(ajar_renderer_device_stats(r, 1, &ds), AJAR_OK);
	assert_true(ds.failed);
	float *two = image(r);
	assert_memory_equal(one, two, sizeof(float) * 4 * W * H);
	ajar_renderer_destroy(&r);
	free(one);
	free(two);
	ajar_scene_destroy(&s);
}

/* The launch fails: device 1's film still holds its first pass. */
static void test_failed_launch_keeps_film(void **state) { fail_second_device(0); }

/* The device is lost after its kernel ran: its film is untrusted and its
 * completed ranges are rendered again on device 0. */
static void test_lost_device_rerendered(void **state) { fail_second_device(1); }

/* The only device fails: a device error, and the image of what was done
 * (the first pass is one sample per pixel) equals a 1-spp render. */
static void test_only_device_fails(void **state)
{
	ajar_scene *s = cornell();
	float *first = render(s, "0:0", 1);
	ajar_renderer *r = renderer(s, "0:0", SPP);
	render_faults = (RenderFaults){.device = 0, .pass = 2};
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_ERROR_DEVICE);
	render_faults = (RenderFaults){0};
	assert_non_null(strstr(ajar_last_error(), "no device left"));
	assert_int_equal(ajar_renderer_spp(r), 1);
	float *partial = image(r);
	assert_memory_equal(first, partial, sizeof(float) * 4 * W * H);
	/* A later render call has nothing to render with. */
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_ERROR_DEVICE);
	ajar_renderer_destroy(&r);
	free(first);
	free(partial);
	ajar_scene_destroy(&s);
}

int main(void)
{
	/* Before any ajar call: PoCL reads it when the platform starts. */
	setenv("POCL_DEVICES", "pthread pthread", 1);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_two_devices_listed),
		cmocka_unit_test(test_selectors),
		cmocka_unit_test(test_two_equal_one),
		cmocka_unit_test(test_failed_launch_keeps_film),
		cmocka_unit_test(test_lost_device_rerendered),
		cmocka_unit_test(test_only_device_fails),
	};
	return cmocka_run_group_tests_name("multidevice", tests, NULL, NULL);
}
