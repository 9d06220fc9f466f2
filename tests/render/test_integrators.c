/* test_integrators.c — the integrators agree on every shipped scene when
 * run through the library on the OpenCL device (PoCL by default).
 *
 * Statistic: the image mean per channel from B = 16 independent batches
 * (ajar_renderer_restart with a new seed); the batch spread gives the
 * standard error of each integrator's mean, and two integrators must agree
 * within 5 combined standard errors. With 15 degrees of freedom a false
 * alarm is ~2e-4 per comparison. A bias of 1% is caught where the
 * combined standard error is below 0.2% of the mean (window-room; the
 * printout shows it); elsewhere the sample counts below, kept small for
 * CI, give 0.3% (cornell), 0.5-0.6% (living-room, bathroom: the portal
 * integrator's noise) and 1% (door-ajar: all light comes through the gap
 * and pt is very noisy), so biases of 1.5-5% are caught there. The
 * Cornell box's absolute level is checked more closely by test_render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "render/render_overrides.h"
#include "scene/scene.h"
#include "batch_means.h"
#include "testutil.h"

#define BATCHES 16

/* The policy's choices a test forces on every render (none by default). */
static PolicyOverrides g_over;
/* The sky's intermediate strategy set with light subpaths: portal keeps its
 * intermediate strategies where it would render as bdpt. */
static const PolicyOverrides SKY_SET = {.portal_set_given = 1, .portal_set = {1, 2, 1, 3, 1}};

static void estimate(ajar_scene *s, ajar_integrator integ, uint32_t w, uint32_t h, uint32_t spp, uint32_t depth,
		     Estimate *e)
{
	ajar_options o;
	ajar_renderer *r;
	ajar_options_default(&o);
	o.width = w;
	o.height = h;
	o.spp = spp;
	o.integrator = integ;
	o.max_depth = depth;
	if (renderer_create_overridden(s, &o, &g_over, &r) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	batch_means(r, w, h, BATCHES, 100, e);
	ajar_renderer_destroy(&r);
}

static void compare_scene(ajar_scene *s, const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	Estimate pt, bdpt, portal;
	const uint32_t depth = 12;
	estimate(s, AJAR_INTEGRATOR_PT, w, h, spp_pt, depth, &pt);
	estimate(s, AJAR_INTEGRATOR_BDPT, w, h, spp_bdpt, depth, &bdpt);
	estimates_agree(path, "bdpt", &bdpt, "pt", &pt);
	estimate(s, AJAR_INTEGRATOR_PORTAL, w, h, spp_bdpt, depth, &portal);
	estimates_agree(path, "portal", &portal, "pt", &pt);
	estimates_agree(path, "portal", &portal, "bdpt", &bdpt);
	ajar_scene_destroy(&s);
}

static void compare(const char *path, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	compare_scene(s, path, w, h, spp_pt, spp_bdpt);
}

/* `path` with a directional light along `dir` (intensity in lux), and a
 * point light at p and a spot at q pointing down (candela), all in
 * glTF's units (KHR_lights_punctual). */
static void compare_punctual(const char *path, const char *what, const float dir[3], float lux, const float p[3],
			     const float q[3], float cd, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	for (int k = 0; k < 3; k++)
		l.direction[k] = dir[k];
	l.intensity = lux;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	for (int k = 0; k < 3; k++)
		l.position[k] = p[k];
	l.color[2] = 0.5f;
	l.intensity = cd;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_SPOT;
	for (int k = 0; k < 3; k++)
		l.position[k] = q[k];
	l.direction[0] = 0.1f;
	l.direction[1] = -1.0f;
	l.direction[2] = 0.2f;
	l.inner_cone = 0.3f;
	l.outer_cone = 0.6f;
	l.intensity = 2 * cd;
	l.range = 4.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	compare_scene(s, what, w, h, spp_pt, spp_bdpt);
}

/* path under a sky of sw x sh texels with a sun disc of angular radius
 * `radius` (radians) at elevation `sun` toward -z, its radiance so that it
 * carries what a disc of 0.04 rad at 300 does. */
static void compare_sky_image(const char *path, uint32_t sw, uint32_t sh, float sun, float radius, uint32_t w,
			      uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float L = 300.0f * (0.04f / radius) * (0.04f / radius);
	float *sky = test_sun_sky(sw, sh, 0.1f, sinf(sun), -cosf(sun), radius, L);
	assert_int_equal(scene_set_env_image(s, sw, sh, sky, 1.0f), AJAR_OK);
	compare_scene(s, path, w, h, spp_pt, spp_bdpt);
}

static void compare_sky(const char *path, float sun, uint32_t w, uint32_t h, uint32_t spp_pt, uint32_t spp_bdpt)
{
	compare_sky_image(path, 256, 128, sun, 0.04f, w, h, spp_pt, spp_bdpt);
}

static void test_cornell(void **state) { compare(SCENE("cornell/cornell.gltf"), 32, 32, 32, 8); }
static void test_window_room(void **state) { compare(SCENE("window-room/window-room.gltf"), 32, 32, 64, 16); }
static void test_living_room(void **state) { compare(SCENE("living-room/living-room.gltf"), 32, 18, 64, 16); }
static void test_bathroom(void **state) { compare(SCENE("bathroom/bathroom.gltf"), 24, 24, 32, 8); }
/* Under a sky with a sun through the window, high (the patch on the
 * floor) and low (on the far wall): next-event estimation through the
 * portal by the sky's radiance (kernels/light/portal_sky.h). */
/* portal renders as bdpt there by default (src/prepare/policy.c; test_render
 * checks the bits): the sky's set named keeps its intermediate strategies,
 * which are compared here. */
static void test_window_room_sun(void **state)
{
	g_over = SKY_SET;
	compare_sky(SCENE("window-room/window-room.gltf"), 0.84f, 32, 32, 64, 16);
	compare_sky(SCENE("window-room/window-room.gltf"), 0.14f, 32, 32, 64, 16);
	g_over = (PolicyOverrides){0};
}
/* A sun of 0.57 degrees sampled through the planes' tables of 512 cells a
 * side, as pt takes them under skies of 2048 columns or more (src/prepare/policy.c,
 * sky_res; test_render checks that choice), here for all three on a
 * smaller image. */
static void test_window_room_small_sun(void **state)
{
	g_over = SKY_SET;
	g_over.sky_res = 512;
	compare_sky_image(SCENE("window-room/window-room.gltf"), 1024, 512, 0.84f, 0.01f, 32, 32, 64, 16);
	g_over = (PolicyOverrides){0};
}
static void test_door_ajar(void **state) { compare(SCENE("door-ajar/door-ajar.gltf"), 24, 24, 512, 128); }

/* The materials of issue 44 (kernels/material/bsdf.h, "Layers"): a sheen
 * sofa, a clear-coated floor and an anisotropic steel table under a sky. */
static void test_sofa_room(void **state) { compare(SCENE("sofa-room/sofa-room-table.gltf"), 32, 18, 64, 16); }
/* Glazed windows (scenes/skies/make_glazed.py): a thin pane 2 cm inside
 * each window, crossed by every strategy (kernels/geom/visibility.h). */
static void test_window_room_glazed(void **state)
{
	compare(SCENE("window-room/window-room-glazed.gltf"), 32, 32, 64, 16);
}
static void test_living_room_forest_glazed(void **state)
{
	compare(SCENE("living-room-forest/living-room-forest-glazed.gltf"), 32, 18, 64, 16);
}
/* The shipped atrium: the forest sky's sun down through a portal in the
 * roof (horizontal, where the other sky scenes' are in walls); portal
 * renders as bdpt there (light subpaths on the portal's lines). */
static void test_atrium_forest(void **state)
{
	compare(SCENE("atrium-forest/atrium-forest.gltf"), 24, 24, 64, 16);
}
/* door-ajar with a point lamp for its emitter: portal's long halves at
 * rate 1 (a lamp behind a portal counts as an emitter, src/prepare/policy.c). */
static void test_door_ajar_lamp(void **state)
{
	compare(SCENE("door-ajar-lamp/door-ajar-lamp.gltf"), 24, 24, 512, 128);
}

/* The Cornell box lit by its emitter, the sun through its open side, a
 * point light and a spot (no portals: the sun's light subpaths start on
 * the scene's disk). */
static void test_cornell_punctual(void **state)
{
	const float sun[3] = {0.2f, -0.5f, 0.8f}, p[3] = {0.15f, 0.45f, 0.3f}, q[3] = {0.4f, 0.5f, 0.25f};
	compare_punctual(SCENE("cornell/cornell.gltf"), "cornell + punctual lights", sun, 683.0f, p, q, 0.1f * 683.0f,
			 32, 32, 32, 8);
}

/* The window room lit by the sun through its window (light subpaths start
 * on the portal), a point light and a spot, besides its sky; portal with
 * the sky's set named, as above. */
static void test_window_room_punctual(void **state)
{
	const float sun[3] = {0.3f, -0.5f, 0.8f}, p[3] = {1.0f, 2.2f, 2.0f}, q[3] = {3.0f, 2.5f, 1.5f};
	g_over = SKY_SET;
	compare_punctual(SCENE("window-room/window-room.gltf"), "window-room + sun + punctual lights", sun,
			 683.0f * 10.0f, p, q, 683.0f, 32, 32, 64, 16);
	g_over = (PolicyOverrides){0};
}

/* A quad (corners a, a + e1, a + e1 + e2, a + e2; uv (0,0) (1,0) (1,1) (0,1);
 * normal e1 x e2 normalised, tangent e1 with w = -1 as glTF generates
 * for v along e2, i.e. up the image) with material `mat`. */
static void add_quad(Scene *s, const char *what, V3 a, V3 e1, V3 e2, uint32_t mat)
{
	V3 p[4] = {a, v3_add(a, e1), v3_add(v3_add(a, e1), e2), v3_add(a, e2)};
	V3 n = v3_norm(v3_cross(e1, e2)), t = v3_norm(e1);
	float pos[12], nrm[12], tan[16], uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
	for (int k = 0; k < 4; k++) {
		pos[3 * k] = p[k].x, pos[3 * k + 1] = p[k].y, pos[3 * k + 2] = p[k].z;
		nrm[3 * k] = n.x, nrm[3 * k + 1] = n.y, nrm[3 * k + 2] = n.z;
		tan[4 * k] = t.x, tan[4 * k + 1] = t.y, tan[4 * k + 2] = t.z, tan[4 * k + 3] = -1;
	}
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles_ex(s, what, pos, nrm, uv, NULL, NULL, tan, 4, idx, 2, mat), AJAR_OK);
}

static uint32_t add_material(Scene *s, V3 base, float metallic, float roughness, int flags, float alpha,
			     int base_tex, int normal_tex, V3 emission)
{
	Material m;
	memset(&m, 0, sizeof m);
	m.base_color = base;
	m.base_tex = base_tex;
	m.metallic = metallic;
	m.roughness = roughness;
	m.ior = 1.5f;
	m.specular = 1.0f;
	m.flags = flags | MATERIAL_DOUBLE_SIDED;
	m.alpha_cutoff = 0.5f;
	m.base_alpha = alpha;
	m.normal_tex = normal_tex;
	m.normal_scale = 1.0f;
	m.emission = emission;
	uint32_t id;
	assert_int_equal(scene_add_material(s, &m, &id), AJAR_OK);
	return id;
}

/* Normal maps and alpha: a floor of glTF plastic and a wall of rough
 * metal, both with a strongly tilted 4 x 4 normal map (tilts up to 50
 * degrees in every direction, so grazing views bend the shading normal,
 * bsdf.h), an alpha-masked card (a 4 x 4 checker of alpha 0 and 1, cutoff
 * 0.5) and a half-transparent BLEND card (alpha 0.5) between them and the
 * camera, lit by a white sky and a small emitter over the floor. Every
 * ray kind meets the alpha (camera rays, shadow rays, connections, light
 * subpaths) and every vertex kind the bent normals. */
static void test_normal_alpha(void **state)
{
	(void)state;
	Scene *s;
	assert_int_equal(scene_new("<normal maps and alpha>", &s), AJAR_OK);
	uint8_t nm[4 * 16], checker[4 * 16];
	for (int i = 0; i < 16; i++) {
		float a = 0.4f * (float)i, tilt = 0.87f * (float)((i * 7) % 5) / 4.0f; /* sin(60 deg) at most */
		float x = tilt * cosf(a), y = tilt * sinf(a), z = sqrtf(fmaxf(1 - x * x - y * y, 0));
		nm[4 * i] = (uint8_t)lrintf((x + 1) * 127.5f);
		nm[4 * i + 1] = (uint8_t)lrintf((y + 1) * 127.5f);
		nm[4 * i + 2] = (uint8_t)lrintf((z + 1) * 127.5f);
		nm[4 * i + 3] = 255;
		int on = ((i & 3) + (i >> 2)) & 1;
		checker[4 * i] = on ? 230 : 40;
		checker[4 * i + 1] = 200;
		checker[4 * i + 2] = 120;
		checker[4 * i + 3] = on ? 255 : 0;
	}
	uint32_t nmi, chi;
	assert_int_equal(scene_add_texture(s, 4, 4, nm, &nmi), AJAR_OK);
	assert_int_equal(scene_add_texture(s, 4, 4, checker, &chi), AJAR_OK);
	V3 none = v3(0, 0, 0);
	uint32_t floor = add_material(s, v3(0.7f, 0.7f, 0.7f), 0, 0.4f, 0, 1, -1, (int)nmi + 1, none);
	uint32_t wall = add_material(s, v3(0.9f, 0.7f, 0.5f), 1, 0.3f, 0, 1, -1, (int)nmi + 1, none);
	uint32_t mask = add_material(s, v3(1, 1, 1), 0, 0.6f, MATERIAL_ALPHA_MASK, 1, (int)chi, 0, none);
	uint32_t blend = add_material(s, v3(0.3f, 0.8f, 0.4f), 0, 0.5f, MATERIAL_ALPHA_BLEND, 0.5f, -1, 0, none);
	uint32_t lamp = add_material(s, v3(0, 0, 0), 0, 1, 0, 1, -1, 0, v3(6, 6, 6));
	add_quad(s, "floor", v3(-1, 0, 1), v3(2, 0, 0), v3(0, 0, -2), floor);
	add_quad(s, "wall", v3(-1, 0, -1), v3(2, 0, 0), v3(0, 1.5f, 0), wall);
	add_quad(s, "mask card", v3(-0.7f, 0, 0), v3(0.9f, 0, 0), v3(0, 0.9f, 0), mask);
	add_quad(s, "blend card", v3(-0.2f, 0.1f, 0.4f), v3(0.8f, 0, 0), v3(0, 0.6f, 0), blend);
	add_quad(s, "lamp", v3(0.2f, 1.3f, 0.6f), v3(0, 0, -0.4f), v3(0.4f, 0, 0), lamp);
	scene_set_env_color(s, v3(0.5f, 0.5f, 0.5f));
	assert_int_equal(scene_set_camera(s, v3(0.3f, 0.5f, 2.2f), v3_norm(v3(-0.1f, -0.15f, -1)), v3(0, 1, 0), 0.8f, 1),
			 AJAR_OK);
	int alpha = 0, tangent = 0;
	for (uint32_t i = 0; i < s->ntris; i++) {
		alpha += (s->tris[i].flags & TRI_ALPHA) != 0;
		tangent += (s->tris[i].flags & TRI_TANGENT) != 0;
	}
	assert_int_equal(alpha, 4);
	assert_int_equal(tangent, 4);
	compare_scene(s, "normal maps and alpha", 24, 24, 64, 16);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cornell),
		cmocka_unit_test(test_window_room),
		cmocka_unit_test(test_window_room_sun),
		cmocka_unit_test(test_window_room_small_sun),
		cmocka_unit_test(test_living_room),
		cmocka_unit_test(test_bathroom),
		cmocka_unit_test(test_window_room_glazed), cmocka_unit_test(test_living_room_forest_glazed), cmocka_unit_test(test_door_ajar),
		cmocka_unit_test(test_door_ajar_lamp),
		cmocka_unit_test(test_atrium_forest),
		cmocka_unit_test(test_sofa_room),
		cmocka_unit_test(test_cornell_punctual),
		cmocka_unit_test(test_window_room_punctual),
		cmocka_unit_test(test_normal_alpha),
	};
	return cmocka_run_group_tests_name("integrators", tests, NULL, NULL);
}
