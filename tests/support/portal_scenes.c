/* portal_scenes.c — see portal_scenes.h. */
#include "portal_scenes.h"

#include <math.h>
#include <string.h>

#include "testutil.h"

Scene *punctual_scene(const char *path, const float dir[3], int inside, const float p[3], const float q[3], int sky)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	memcpy(l.direction, dir, sizeof l.direction);
	l.color[2] = 0.8f;
	l.intensity = 683.0f * 4.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	if (inside) {
		ajar_light_default(&l);
		memcpy(l.position, p, sizeof l.position);
		l.intensity = 683.0f * 0.5f;
		l.range = 6.0f;
		assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
		ajar_light_default(&l);
		l.type = AJAR_LIGHT_SPOT;
		memcpy(l.position, q, sizeof l.position);
		l.direction[0] = 0.2f;
		l.direction[1] = -1.0f;
		l.direction[2] = 0.1f;
		l.inner_cone = 0.2f;
		l.outer_cone = 0.6f;
		l.intensity = 683.0f;
		assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	}
	if (!sky)
		s->env_type = ENV_NONE;
	return s;
}

static const float sun_in[3] = {0.3f, -0.5f, 0.8f}; /* through window-room's window */
static const float wr_p[3] = {1.0f, 2.2f, 2.0f}, wr_q[3] = {3.0f, 2.5f, 1.5f};

const PolicyOverrides SKY_SET = {.portal_set_given = 1, .portal_set = {1, 2, 1, 3, 1}};

void open_portal_kept(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int depth)
{
	host_scene_open_with(h, path, built, w, hgt, INTEGRATOR_PORTAL, depth, &SKY_SET);
	assert_int_equal(h->data.params->integrator, INTEGRATOR_PORTAL);
}

Scene *sun_window_room(int inside, int sky)
{
	return punctual_scene(SCENE("window-room/window-room.gltf"), sun_in, inside, wr_p, wr_q, sky);
}

Scene *door_ajar_lamps(void)
{
	const float sun[3] = {-0.4f, -0.6f, 0.5f}, lp[3] = {2.0f, 2.0f, 6.0f}, lq[3] = {1.0f, 2.4f, 2.0f};
	Scene *s = punctual_scene(SCENE("door-ajar/door-ajar.gltf"), sun, 1, lp, lq, 0);
	for (uint32_t i = 0; i < s->nmaterials; i++)
		s->materials[i].emission = v3(0.0f, 0.0f, 0.0f);
	return s;
}

Scene *round_trip_scene(void)
{
	ajar_scene *s;
	ajar_material m;
	uint32_t white, light, mirror;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material_default(&m);
	assert_int_equal(ajar_scene_add_material(s, &m, &white), AJAR_OK);
	m.emission[0] = m.emission[1] = m.emission[2] = 10;
	assert_int_equal(ajar_scene_add_material(s, &m, &light), AJAR_OK);
	ajar_material_default(&m);
	m.metallic = 1;
	m.roughness = 0;
	assert_int_equal(ajar_scene_add_material(s, &m, &mirror), AJAR_OK);
	/* The room [0,2]^3 without its x = 2 wall, which has a window. */
	static const float room[] = {0, 0, 0, 2, 0, 0, 2, 0, 2, 0, 0, 2,  0, 2, 0, 0, 2, 2, 2, 2, 2, 2, 2, 0,
				     0, 0, 0, 0, 0, 2, 0, 2, 2, 0, 2, 0,  0, 0, 0, 0, 2, 0, 2, 2, 0, 2, 0, 0,
				     0, 0, 2, 2, 0, 2, 2, 2, 2, 0, 2, 2};
	static const uint32_t quads[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10, 8, 10, 11,
					 12, 13, 14, 12, 14, 15, 16, 17, 18, 16, 18, 19};
	ajar_mesh mesh = {room, NULL, NULL, 20, quads, 10, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	/* x = 2 wall around a window y, z in [0.7, 1.3] */
	static const float wall[] = {2, 0, 0, 2, 0.7f, 0, 2, 0.7f, 2, 2, 0, 2,  2, 1.3f, 0, 2, 2, 0, 2, 2, 2, 2, 1.3f, 2,
				     2, 0.7f, 0, 2, 1.3f, 0, 2, 1.3f, 0.7f, 2, 0.7f, 0.7f,
				     2, 0.7f, 1.3f, 2, 1.3f, 1.3f, 2, 1.3f, 2, 2, 0.7f, 2};
	static const uint32_t wq[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10, 8, 10, 11, 12, 13, 14, 12, 14, 15};
	ajar_mesh wm = {wall, NULL, NULL, 16, wq, 8, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &wm), AJAR_OK);
	/* Outside: a white wall at x = 3 and a mirror at x = 2.6 below the window. */
	static const float out[] = {3, -1, -1, 3, 3, -1, 3, 3, 3, 3, -1, 3};
	static const float mir[] = {2.6f, 0, 0.6f, 2.6f, 0.6f, 0.6f, 2.6f, 0.6f, 1.4f, 2.6f, 0, 1.4f};
	static const uint32_t q[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh om = {out, NULL, NULL, 4, q, 2, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &om), AJAR_OK);
	om.positions = mir;
	om.material = mirror;
	assert_int_equal(ajar_scene_add_mesh(s, &om), AJAR_OK);
	/* A light on the ceiling, facing down. */
	static const float lp[] = {0.7f, 1.99f, 0.7f, 1.3f, 1.99f, 0.7f, 1.3f, 1.99f, 1.3f, 0.7f, 1.99f, 1.3f};
	static const uint32_t lq[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh lm = {lp, NULL, NULL, 4, lq, 2, light, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &lm), AJAR_OK);
	static const float portal[] = {2, 0.7f, 0.7f, 2, 1.3f, 0.7f, 2, 1.3f, 1.3f, 2, 0.7f, 1.3f};
	ajar_mesh pm = {portal, NULL, NULL, 4, q, 2, 0, NULL};
	assert_int_equal(ajar_scene_add_portal(s, &pm), AJAR_OK);
	ajar_camera cam = {{0.3f, 1.2f, 1.0f}, {2, 0.8f, 1.0f}, {0, 1, 0}, 1.2f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
	return s;
}

Scene *sun_room(int low, float sun_l)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float e = low ? 0.14f : 0.84f; /* elevation: 8 and 48 degrees */
	float *sky = test_sun_sky(256, 128, 0.1f, sinf(e), -cosf(e), 0.03f, sun_l);
	assert_int_equal(scene_set_env_image(s, 256, 128, sky, 1.0f), AJAR_OK);
	return s;
}

Scene *without_portals(const char *path)
{
	Scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	s->nportal_tris = 0;
	s->nportals = 0;
	return s;
}
