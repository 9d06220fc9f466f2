/* test_portal_groups.c — the portal integrator converges, on the host with
 * the kernels' own code (tests/support/kernel_host.h): each group of
 * intermediate strategies (length n, light vertices s, eye vertices t),
 * unweighted, converges to the path tracer's image of paths of n segments
 * counted once per portal crossing on the edges those strategies can
 * cross (Params.cross_filter), under a constant sky, skies with a sun, a
 * light whose paths leave and come back, and punctual lights; and portal
 * agrees with pt under punctual lights. (That the portal integrator
 * without portals is bdpt to the bit is checked through the device in
 * test_render.c.) Statistics as in test_bdpt.c: batch means, 5 standard
 * errors. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "portal_scenes.h"
#include "testutil.h"

#define BATCHES 32

static void batch_layer(HostScene *h, uint32_t spp, int layer, Estimate *est)
{
	host_batch_estimate(h, spp, layer, BATCHES, 500, est);
}

/* Only channel 1 (the scenes are grey), 5 standard errors. Returns
 * whether the group carried light. */
static int agree1(const char *what, const Estimate *a, const Estimate *b)
{
	double se = sqrt(a->se[1] * a->se[1] + b->se[1] * b->se[1]);
	double z = se > 0 ? (a->mean[1] - b->mean[1]) / se : 0;
	print_message("%s: %.6f +- %.6f vs %.6f +- %.6f (%+.1f se)\n", what, a->mean[1], a->se[1], b->mean[1], b->se[1],
		      z);
	if (fabs(z) > 5)
		fail_msg("%s: differ by %.1f standard errors", what, z);
	if ((a->mean[1] > 0) != (b->mean[1] > 0))
		fail_msg("%s: only one of the two carried light", what);
	return a->mean[1] > 0;
}

/* Returns how many groups carried light (some cannot in a given scene:
 * with only a sky outside, no <- end outside gets a light sample). */
static int check_groups(HostScene *hp, HostScene *ht, int len, uint32_t spp_portal, uint32_t spp_pt)
{
	int lit = 0;
	Params *pp = hp->data.params, *pt = ht->data.params;
	pp->portal_s_max = pp->portal_sp_max = pp->portal_tp_max = SUBPATH_MAX; /* every group */
	pp->portal_t_max = SUBPATH_MAX + 1;
	pp->light_paths = 1;
	pp->strategy_len = len;
	pp->strategy_unweighted = 1;
	/* Every group's layer from one render per batch. */
	Estimate *groups = malloc(sizeof *groups * portal_layer_count(len));
	host_batch_estimates(hp, spp_portal, bdpt_layer_count(len), portal_layer_count(len), BATCHES, 500, groups);
	/* Lit by punctual lights alone, s = 0 groups carry nothing (their <-
	 * half would have to hit a delta light), while the crossing filter
	 * also counts paths that cross a portal on the light's own edge, which
	 * only bdpt's strategies sample: compare from s = 1. */
	int s0 = pp->num_emitters == 0 && pp->env_type == ENV_NONE;
	for (int n = 2; n <= len; n++)
		for (int t = 1; t < n; t++)
			for (int s = s0; s + t < n; s++) {
				Estimate a = groups[portal_layer(n, s, t)], b;
				char what[96];
				pt->min_depth = pt->max_depth = n;
				pt->cross_filter = 1;
				pt->cross_lo = t;
				pt->cross_hi = s;
				batch_layer(ht, spp_pt, -1, &b);
				snprintf(what, sizeof what, "length %d, intermediate strategies with s=%d, t=%d", n, s, t);
				lit += agree1(what, &a, &b);
			}
	free(groups);
	return lit;
}

/* Sky through the window: s = 0 groups carry the light. Unweighted, they
 * have heavy tails: at 8 spp per pixel (standard error 5% of the mean)
 * all three came out 2-4.5 standard errors low, and a bias below about 25%
 * went unseen. 256 spp make the standard error 1% of the mean, so 5
 * standard errors catch a bias of 5%. */
#define GROUP_SPP 256

static void test_groups_unbiased_window_room(void **state)
{
	HostScene hp, ht;
	host_scene_open(&hp, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 3);
	host_scene_open(&ht, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PT, 3);
	assert_true(check_groups(&hp, &ht, 3, GROUP_SPP, 64) >= 3);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* The same with a pane 2 cm inside the window: the intermediate subpaths'
 * -> halves and the next-event rays cross it by its null event and its
 * transmittance; each group must still equal the filtered path tracer. */
static void test_groups_unbiased_glazed(void **state)
{
	HostScene hp, ht;
	host_scene_open(&hp, SCENE("window-room/window-room-glazed.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 3);
	host_scene_open(&ht, SCENE("window-room/window-room-glazed.gltf"), NULL, 8, 8, INTEGRATOR_PT, 3);
	assert_true(check_groups(&hp, &ht, 3, GROUP_SPP, 64) >= 3);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* The same under skies with a sun, high and low: next-event samples
 * through the portal by the sky's radiance (kernels/light/portal_sky.h), <-
 * halves guided toward the sun. The sun's light is noisier: 1024 spp
 * (and 512 for pt) keep the combined standard error near 1% of the mean
 * (1.1% at most), so a bias of about 5.5% is caught. */
#ifdef __SANITIZE_ADDRESS__
#define SUN_ROOMS 1 /* sanitizers: the low sun alone, at the same samples (the suite's time) */
#else
#define SUN_ROOMS 2
#endif

static void test_groups_unbiased_window_room_sun(void **state)
{
	for (int low = 2 - SUN_ROOMS; low < 2; low++) {
		HostScene hp, ht;
		open_portal_kept(&hp, NULL, sun_room(low, 300.0f), 8, 8, 3);
		host_scene_open(&ht, NULL, sun_room(low, 300.0f), 8, 8, INTEGRATOR_PT, 3);
		assert_true(check_groups(&hp, &ht, 3, 4 * GROUP_SPP, 2 * GROUP_SPP) >= 3);
		host_scene_close(&hp);
		host_scene_close(&ht);
	}
}

/* A light inside, bouncing outside: s >= 1 groups carry the light. */
static void test_groups_unbiased_round_trip(void **state)
{
	HostScene hp, ht;
	host_scene_open(&hp, NULL, round_trip_scene(), 8, 8, INTEGRATOR_PORTAL, 4);
	host_scene_open(&ht, NULL, round_trip_scene(), 8, 8, INTEGRATOR_PT, 4);
	/* Lambertian only: the mirror outside would hide paths from connections. */
	Material *m = (Material *)&hp.data.materials[2], *m2 = (Material *)&ht.data.materials[2];
	m->metallic = m2->metallic = 0;
	m->specular = m2->specular = 0;
	assert_true(check_groups(&hp, &ht, 4, 8, 32) >= 5);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* door-ajar lit only by punctual lights: a sun outside its house (a
 * directional light's light subpaths start on the portals), a point light
 * and a spot where its emitter was (its emission set to 0), no sky. Only
 * the s >= 1 groups can carry their light through the gap (next-event
 * estimation of a delta light from <- vertices, light subpaths from them;
 * a <- half never hits a delta light). In the window rooms nothing lies
 * outside the window for a -> half to hit, so there only the sky's s = 0
 * groups carry light, as test_groups_unbiased_window_room checks. 64 and
 * 128 spp (about 15 s) give standard errors of 3-9% of each group's mean:
 * a bias above about a third is caught, not a small one. */
static void test_groups_unbiased_punctual(void **state)
{
	(void)state;
	HostScene hp, ht;
	host_scene_open(&hp, NULL, door_ajar_lamps(), 8, 8, INTEGRATOR_PORTAL, 4);
	host_scene_open(&ht, NULL, door_ajar_lamps(), 8, 8, INTEGRATOR_PT, 4);
	assert_true(hp.data.params->num_emitters == 0 && hp.data.params->num_lights == 3);
	assert_true(check_groups(&hp, &ht, 4, 64, 128) >= 3);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* portal against pt in the window room lit by the sun, a point light and
 * a spot (no sky, so they carry all the light). */
static void test_portal_matches_pt_punctual(void **state)
{
	HostScene hq, hp;
	Estimate q, p;
	open_portal_kept(&hq, NULL, sun_window_room(1, 0), 12, 12, 6);
	host_scene_open(&hp, NULL, sun_window_room(1, 0), 12, 12, INTEGRATOR_PT, 6);
	host_batch_estimate(&hq, 4, -1, 32, 2000, &q);
	host_batch_estimate(&hp, 16, -1, 32, 2000, &p);
	for (int c = 0; c < 3; c++) {
		double se = sqrt(q.se[c] * q.se[c] + p.se[c] * p.se[c]), z = (q.mean[c] - p.mean[c]) / se;
		print_message("window room with punctual lights, portal vs pt, channel %d: %.5f +- %.5f vs %.5f +- %.5f "
			      "(%.1f se)\n", c, q.mean[c], q.se[c], p.mean[c], p.se[c], z);
		if (fabs(z) > 5)
			fail_msg("channel %d: portal and pt differ by %.1f standard errors", c, z);
	}
	host_scene_close(&hq);
	host_scene_close(&hp);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_groups_unbiased_window_room),
		cmocka_unit_test(test_groups_unbiased_glazed),
		cmocka_unit_test(test_groups_unbiased_window_room_sun),
		cmocka_unit_test(test_groups_unbiased_round_trip),
		cmocka_unit_test(test_groups_unbiased_punctual),
		cmocka_unit_test(test_portal_matches_pt_punctual),
	};
	return cmocka_run_group_tests_name("portal groups", tests, NULL, NULL);
}
