/* test_portal_policy.c — what the policy (src/prepare/policy.c) chooses
 * for the portal integrator, through prepare_scene: the default strategy
 * sets and a forced set taken whole; where portal renders as bdpt (light
 * subpaths bring the light in) and where it keeps its intermediate
 * strategies; the rate of intermediate subpaths, default and forced; a
 * sky image's sun share, of the whole sky and through the portals, and
 * light subpaths only with a sun that shines in. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "portal_scenes.h"
#include "testutil.h"

/* The default strategy sets, and a forced set taken whole. */
static void test_portal_set(void **state)
{
	HostScene h;
	const int M = AJAR_BIDIR_MAX_DEPTH;
	const struct {
		const char *scene;
		int forced, set[5];
		int expect[5]; /* s, s', t', t, light paths */
	} cases[] = {
		{"window-room/window-room.gltf", 0, {0}, {1, 2, 1, 3, 0}},
		{"window-room-forest/window-room-forest.gltf", 0, {0}, {1, 2, 1, 3, 1}}, /* a sky image: light subpaths */
		{"window-room-forest/window-room-forest.gltf", 1, {1, 2, 1, 3, 0}, {1, 2, 1, 3, 0}},
		{"door-ajar/door-ajar.gltf", 0, {0}, {1, M, M, 1 << 20, 1}},
		{"door-ajar/door-ajar.gltf", 1, {2, 4, 5, 1 << 20, 1}, {2, 4, 5, 1 << 20, 1}},
		{"door-ajar/door-ajar.gltf", 1, {1, 2, 2, 4, 0}, {1, 2, 2, 4, 0}},
		{"window-room/window-room.gltf", 1, {3, 2, 1, 3, 0}, {1, 2, 1, 3, 0}}, /* s > 1 needs light subpaths */
	};
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		PolicyOverrides over = {.portal_set_given = cases[i].forced};
		memcpy(over.portal_set, cases[i].set, sizeof over.portal_set);
		char path[256];
		snprintf(path, sizeof path, SCENE("%s"), cases[i].scene);
		host_scene_open_with(&h, path, NULL, 8, 8, INTEGRATOR_PORTAL, 8, &over);
		const Params *p = h.data.params;
		int got[5] = {p->portal_s_max, p->portal_sp_max, p->portal_tp_max, p->portal_t_max, p->light_paths};
		for (int j = 0; j < 5; j++)
			if (got[j] != cases[i].expect[j])
				fail_msg("%s, case %u: field %d is %d, expected %d", cases[i].scene, i, j, got[j],
					 cases[i].expect[j]);
		host_scene_close(&h);
	}
}

/* A lamp at `pos` (range 0: unlimited) with window-room's constant sky. */
static Scene *window_room_lamp_at(float x, float y, float z, float range)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.position[0] = x;
	l.position[1] = y;
	l.position[2] = z;
	l.intensity = 683.0f;
	l.range = range;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	return s;
}

/* Where light subpaths bring the light in through the portals (a sky
 * image with a sun, punctual lights none of which lies behind a portal),
 * portal renders as bdpt; a point light behind a portal counts as an
 * emitter (the long set at rate 1); constant skies, a sky without a sun
 * (no light subpaths, test_sky_sun_share) and emitters keep their intermediate subpaths,
 * and so does a forced strategy set (src/prepare/policy.c). */
static void test_portal_as_bdpt(void **state)
{
	(void)state;
	const struct {
		const char *scene;
		Scene *built;
		int integrator, long_set;
	} cases[] = {
		{"window-room/window-room.gltf", NULL, INTEGRATOR_PORTAL, 0},
		{"window-room-sunset/window-room-sunset.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"door-ajar/door-ajar.gltf", NULL, INTEGRATOR_PORTAL, 1},
		{"window-room-forest/window-room-forest.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"window-room-sun/window-room-sun.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"window-room-lamp/window-room-lamp.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"atrium-forest/atrium-forest.gltf", NULL, INTEGRATOR_BDPT, 0}, /* the sun through the roof */
		{NULL, sun_window_room(1, 1), INTEGRATOR_BDPT, 0},     /* sun, lamp and spot in the room */
		{NULL, door_ajar_lamps(), INTEGRATOR_PORTAL, 1},      /* a point light behind the door */
		{NULL, window_room_lamp_at(2.0f, 1.4f, -1.0f, 0.0f), INTEGRATOR_PORTAL, 1}, /* outside the window */
		{NULL, window_room_lamp_at(2.0f, 1.4f, -1.0f, 0.5f), INTEGRATOR_BDPT, 0},   /* its range ends short of it */
		{NULL, window_room_lamp_at(2.0f, 1.4f, 2.0f, 0.0f), INTEGRATOR_BDPT, 0},    /* inside */
	};
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char path[256];
		if (cases[i].scene)
			snprintf(path, sizeof path, SCENE("%s"), cases[i].scene);
		HostScene h;
		host_scene_open(&h, cases[i].scene ? path : NULL, cases[i].built, 8, 8, INTEGRATOR_PORTAL, 8);
		const Params *p = h.data.params;
		if (p->integrator != cases[i].integrator || (p->portal_sp_max == AJAR_BIDIR_MAX_DEPTH) != cases[i].long_set)
			fail_msg("case %u (%s): integrator %d, s' <= %d, expected %d and %s", i,
				 cases[i].scene ? cases[i].scene : "built", p->integrator, p->portal_sp_max,
				 cases[i].integrator, cases[i].long_set ? "the long set" : "the sky's");
		if (cases[i].long_set)
			assert_float_equal(p->portal_rate, 1.0f, 0.0f);
		/* as bdpt, eye vertices join the first light vertices only */
		assert_int_equal(p->bdpt_conn, p->integrator == INTEGRATOR_BDPT ? POLICY_PORTAL_BDPT_CONN : 0);
		host_scene_close(&h);
	}
	HostScene h;
	host_scene_open_with(&h, SCENE("window-room-forest/window-room-forest.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8,
			     &SKY_SET);
	assert_int_equal(h.data.params->integrator, INTEGRATOR_PORTAL);
	host_scene_close(&h);
}

/* The whole sky's share of a sky image's power in its brightest texels. */
static float whole_sky_share(const HostScene *h)
{
	GLOBAL const Params *p = h->data.params;
	uint32_t w = (uint32_t)p->env_width, hh = (uint32_t)p->env_height;
	return env_sun_share_weighted(h->data.env + ENV_PIXELS(w, hh), w, hh, NULL, NULL);
}

/* The sun's share of a sky image's power (src/prepare/light_tables.c, env_sun_share_weighted),
 * of the sky light through the portals (src/prepare/portal_flux.c,
 * portal_sun_share) and what portal makes of it (src/prepare/prepare.c,
 * SKY_SUN_SHARE): a uniform sky with a disc 5000 times as bright covering
 * 0.008% of the sphere gets the share the texels' solid angles give
 * exactly; behind the wall, the disc brings no light subpaths, and turned
 * by 180 degrees into the window it does, with the whole sky's share
 * unchanged; the shipped skies their measured shares; light subpaths from
 * the sky only with a sun through the window: window-room-forest,
 * window-room-sunset and a strong synthetic sun yes, that sun turned
 * behind the window's wall or a sky without a sun no (the sky set's rate
 * 0.3). */
static void test_sky_sun_share(void **state)
{
	(void)state;
	enum { W = 256, H = 128 };
	float *rgb = malloc(sizeof(float) * 3 * W * H);
	assert_non_null(rgb);
	double cos_r = cos(0.02), disc = 0.0, all = 0.0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			double phi = 2.0 * M_PI * ((x + 0.5) / W - 0.5), theta = M_PI * (y + 0.5) / H;
			double dy = cos(theta), dz = -sin(theta) * cos(phi), sa = sin(theta);
			int in = dy * 0.6 + dz * 0.8 > cos_r; /* the sun toward (0, 0.6, 0.8) */
			for (int c = 0; c < 3; c++)
				rgb[3 * (y * W + x) + c] = in ? 5000.0f : 1.0f;
			disc += in ? sa : 0.0;
			all += sa;
		}
	assert_true(disc > 0.0 && disc < 1e-3 * all);
	float *turned = malloc(sizeof(float) * 3 * W * H); /* scene_set_env_image takes each */
	assert_non_null(turned);
	memcpy(turned, rgb, sizeof(float) * 3 * W * H);
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(scene_set_env_image(s, W, H, rgb, 1.0f), AJAR_OK);
	HostScene h;
	host_scene_open(&h, NULL, s, 8, 8, INTEGRATOR_PORTAL, 8);
	double want = (5000.0 * disc + (1e-3 * all - disc)) / (all + 4999.0 * disc);
	printf("  disc of %.3g%% of the sphere: share %.5f, expected %.5f\n", 100.0 * disc / all,
	       whole_sky_share(&h), want);
	assert_float_equal(whole_sky_share(&h), want, 1e-4 * want);
	printf("  behind the wall: share through the portals %.5f\n", h.data.sun_share_portals);
	assert_true(h.data.sun_share_portals < 0.01f);
	assert_false(h.data.params->light_paths);
	host_scene_close(&h);
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(scene_set_env_image(s, W, H, turned, 1.0f), AJAR_OK);
	assert_int_equal(scene_set_env_rotation(s, 180.0f), AJAR_OK);
	host_scene_open(&h, NULL, s, 8, 8, INTEGRATOR_PORTAL, 8);
	printf("  turned into the window: share %.5f, through the portals %.5f\n", whole_sky_share(&h),
	       h.data.sun_share_portals);
	assert_float_equal(whole_sky_share(&h), want, 1e-3 * want);
	/* Each texel's power times the portals' area projected toward its
	 * turned direction from their sky side: the disc's, and of the rest
	 * the part of solid angle that fills the brightest 0.1%. */
	double in_disc = 0.0, in_rest = 0.0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			double phi = 2.0 * M_PI * ((x + 0.5) / W - 0.5), theta = M_PI * (y + 0.5) / H;
			double dx = sin(theta) * sin(phi), dy = cos(theta), dz = -sin(theta) * cos(phi);
			double a = 0.0;
			for (size_t k = 0; k < h.data.n_portals; k++) {
				const PortalTri *pt = &h.data.portals[k];
				double c = (-dx * pt->n.x + dy * pt->n.y - dz * pt->n.z) * pt->env_side;
				a += c > 0.0 ? pt->area * c : 0.0;
			}
			if (dy * 0.6 + dz * 0.8 > cos_r)
				in_disc += 5000.0 * sin(theta) * a;
			else
				in_rest += sin(theta) * a;
		}
	double want_in = (in_disc + in_rest * (1e-3 * all - disc) / (all - disc)) / (in_disc + in_rest);
	printf("  expected through the portals %.5f\n", want_in);
	assert_float_equal(h.data.sun_share_portals, want_in, 2e-3 * want_in);
	assert_true(h.data.params->light_paths);
	host_scene_close(&h);

	struct {
		const char *scene;
		Scene *sky;
		float lo, hi;
		int light_paths;
	} cases[] = {
		{SCENE("window-room-forest/window-room-forest.gltf"), NULL, 0.18f, 0.30f, 1},
		{SCENE("window-room-sunset/window-room-sunset.gltf"), NULL, 0.05f, 0.09f, 1},
		{NULL, sun_room(0, 3000.0f), 0.25f, 1.0f, 1},
		{NULL, sun_room(0, 3000.0f), 0.0f, 0.01f, 0}, /* turned by 120 degrees, behind the wall's plane */
		{NULL, sun_room(0, 0.5f), 0.0f, 0.02f, 0},    /* the "sun" no brighter than the sky */
	};
	assert_int_equal(scene_set_env_rotation(cases[3].sky, 120.0f), AJAR_OK);
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		host_scene_open(&h, cases[i].scene, cases[i].sky, 8, 8, INTEGRATOR_PORTAL, 8);
		float share = h.data.sun_share_portals;
		printf("  case %u: sun share %.4f, through the portals %.4f, light subpaths %d, rate %g\n", i,
		       whole_sky_share(&h), share, h.data.params->light_paths, h.data.params->portal_rate);
		if (!(share >= cases[i].lo && share <= cases[i].hi))
			fail_msg("case %u: sun share through the portals %g outside [%g, %g]", i, share, cases[i].lo,
				 cases[i].hi);
		assert_int_equal(h.data.params->light_paths, cases[i].light_paths);
		assert_float_equal(h.data.params->portal_rate, cases[i].light_paths ? 0.1f : 0.3f, 0.0f);
		host_scene_close(&h);
	}
}

/* The rate of intermediate subpaths: 0.1 where a constant sky is the only
 * light and where a sky image is (with its light subpaths), 0.3 under a
 * sky image (sampled through planar portals) without light subpaths, 1
 * with emitters; a forced rate replaces it, and strategy layers without
 * MIS weights take every intermediate subpath. */
static void test_portal_rate(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	assert_float_equal(h.data.params->portal_rate, 0.1f, 0.0f);
	host_scene_close(&h);
	host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	assert_float_equal(h.data.params->portal_rate, 1.0f, 0.0f);
	host_scene_close(&h);
	host_scene_open(&h, NULL, sun_room(0, 300.0f), 8, 8, INTEGRATOR_PORTAL, 8); /* a sky image */
	assert_float_equal(h.data.params->portal_rate, 0.1f, 0.0f);
	host_scene_close(&h);
	const PolicyOverrides no_lines = {.portal_set_given = 1, .portal_set = {1, 2, 1, 3, 0}};
	host_scene_open_with(&h, NULL, sun_room(0, 300.0f), 8, 8, INTEGRATOR_PORTAL, 8, &no_lines);
	assert_float_equal(h.data.params->portal_rate, 0.3f, 0.0f);
	host_scene_close(&h);
	const float rates[] = {0.25f, 1.0f};
	for (int i = 0; i < 2; i++) {
		const PolicyOverrides over = {.portal_rate = rates[i]};
		host_scene_open_with(&h, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8, &over);
		assert_float_equal(h.data.params->portal_rate, rates[i], 0.0f);
		host_scene_close(&h);
	}
	/* Unweighted strategy layers (the strategy tests) take every intermediate subpath. */
	const PolicyOverrides over = {.portal_rate = 0.25f};
	Scene *s;
	assert_int_equal(ajar_scene_load(SCENE("window-room/window-room.gltf"), &s), AJAR_OK);
	ajar_options o;
	ajar_options_default(&o);
	o.integrator = AJAR_INTEGRATOR_PORTAL;
	o.max_depth = 8;
	o.strategy_len = 4;
	o.strategy_unweighted = 1;
	SceneData d;
	assert_int_equal(prepare_scene(s, &o, 8, 8, &over, &d), AJAR_OK);
	assert_float_equal(d.params->portal_rate, 1.0f, 0.0f);
	prepare_free(&d);
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_portal_set),
		cmocka_unit_test(test_portal_as_bdpt),
		cmocka_unit_test(test_portal_rate),
		cmocka_unit_test(test_sky_sun_share),
	};
	return cmocka_run_group_tests_name("portal policy", tests, NULL, NULL);
}
