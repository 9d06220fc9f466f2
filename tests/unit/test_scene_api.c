/* test_scene_api.c — scenes built through the C API (ajar_scene_create and
 * the ajar_scene_add_* calls): meshes land where their transforms put them
 * (normals by the inverse transpose, mirrored winding reversed), portals,
 * the camera and its default, the environment colour, the lights with
 * their defaults; caller mistakes refused with the argument named. */
#include "scene_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void test_api_scene(void **state)
{
	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	Scene *s = as;

	ajar_material m;
	ajar_material_default(&m);
	assert_float_equal(m.base_color[1], 0.8f, 0.0);
	assert_float_equal(m.specular, 0.0f, 0.0);
	uint32_t white, lamp;
	assert_int_equal(ajar_scene_add_material(as, &m, &white), AJAR_OK);
	m.emission[0] = m.emission[1] = m.emission[2] = 5.0f;
	assert_int_equal(ajar_scene_add_material(as, &m, &lamp), AJAR_OK);
	assert_int_equal(lamp, 1);
	ajar_material bad = m;
	bad.roughness = NAN;
	assert_int_equal(ajar_scene_add_material(as, &bad, NULL), AJAR_ERROR_INVALID_ARGUMENT);
	bad = m;
	bad.base_color[2] = -0.1f;
	assert_int_equal(ajar_scene_add_material(as, &bad, NULL), AJAR_ERROR_INVALID_ARGUMENT);
	bad = m;
	bad.emission[0] = -1.0f;
	assert_int_equal(ajar_scene_add_material(as, &bad, NULL), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(s->nmaterials, 2);

	/* A unit quad in z = 0, scaled by 2 in x and moved by (1, 2, 3). */
	const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	const float r = 0.70710678f;
	const float nrm[12] = {r, 0, r, r, 0, r, r, 0, r, 0, 0, 0};
	const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
	const float xf[16] = {2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1};
	ajar_mesh mesh = {pos, nrm, uv, 4, idx, 2, white, xf};
	assert_int_equal(ajar_scene_add_mesh(as, &mesh), AJAR_OK);
	assert_int_equal(s->ntris, 2);
	assert_v3(s->tris[0].p0, 1, 2, 3);
	assert_v3(s->tris[0].p1, 3, 2, 3);
	assert_v3(s->tris[0].p2, 3, 3, 3);
	assert_v3(s->tris[1].p2, 1, 3, 3);
	/* Normals by the inverse transpose diag(1/2, 1, 1): (1, 0, 1) becomes
	 * (1/2, 0, 1), renormalized. */
	assert_int_equal(s->shade[0].has_normals, 1);
	assert_v3(s->shade[0].n0, 0.4472136f, 0.0f, 0.8944272f);
	/* The second triangle has a zero normal: geometric normal instead. */
	assert_int_equal(s->shade[1].has_normals, 0);
	assert_float_equal(s->shade[0].u2, 1.0f, 0.0);
	assert_float_equal(s->shade[0].v2, 1.0f, 0.0);
	assert_int_equal(s->tris[0].emitter, -1);

	/* Mirrored (det < 0), non-indexed, emissive: the winding is reversed
	 * so the front face stays counter-clockwise. */
	const float mirror[16] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
	ajar_mesh lamp_mesh = {pos, NULL, NULL, 3, NULL, 1, lamp, mirror};
	assert_int_equal(ajar_scene_add_mesh(as, &lamp_mesh), AJAR_OK);
	assert_v3(s->tris[2].p0, 0, 0, 0);
	assert_v3(s->tris[2].p1, -1, 1, 0);
	assert_v3(s->tris[2].p2, -1, 0, 0);
	assert_int_equal(s->shade[2].has_normals, 0);

	/* Caller mistakes. */
	ajar_mesh wrong = mesh;
	wrong.material = 7;
	assert_int_equal(ajar_scene_add_mesh(as, &wrong), AJAR_ERROR_INVALID_ARGUMENT);
	const uint32_t far_idx[3] = {0, 1, 9};
	wrong = mesh;
	wrong.indices = far_idx;
	wrong.triangle_count = 1;
	assert_int_equal(ajar_scene_add_mesh(as, &wrong), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "index 9"));
	const float singular[16] = {0};
	wrong = mesh;
	wrong.transform = singular;
	assert_int_equal(ajar_scene_add_mesh(as, &wrong), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(s->ntris, 3);

	/* A portal: the quad moved to z = 5, area 1; invisible, not a triangle. */
	const float up5[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1};
	ajar_mesh portal = {pos, NULL, NULL, 4, idx, 2, 0, up5};
	assert_int_equal(ajar_scene_add_portal(as, &portal), AJAR_OK);
	assert_int_equal(s->nportals, 1);
	assert_int_equal(s->nportal_tris, 2);
	assert_v3(s->portals[1].p2, 0, 1, 5);
	assert_float_equal(s->portals[0].area, 0.5f, 1e-6);
	assert_float_equal(s->portals[0].pdf_select, 0.0f, 0.0);

	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(as, &in), AJAR_OK);
	assert_int_equal(in.triangles, 3);
	assert_int_equal(in.emissive_triangles, 1);
	assert_int_equal(in.portals, 1);
	assert_int_equal(in.portal_triangles, 2);
	assert_int_equal(in.has_camera, 0);
	/* Bounds include the portal. */
	assert_v3(v3(in.bounds_min[0], in.bounds_min[1], in.bounds_min[2]), -1, 0, 0);
	assert_v3(v3(in.bounds_max[0], in.bounds_max[1], in.bounds_max[2]), 3, 3, 5);
	/* Default view: along -Z from outside the bounding sphere, 45 degrees. */
	assert_float_equal(in.camera.yfov, 45.0f * AJAR_PI / 180.0f, 1e-6);
	assert_float_equal(in.camera.position[0], 1.0f, 1e-6);
	assert_true(in.camera.position[2] > 5.0f);
	assert_float_equal(in.camera.target[2] - in.camera.position[2], -1.0f, 1e-6);
	assert_float_equal(in.camera.up[1], 1.0f, 0.0);

	ajar_camera cam = {{0, 1, 10}, {0, 1, 0}, {0, 2, 0}, 0.8f, 1.5f};
	assert_int_equal(ajar_scene_set_camera(as, &cam), AJAR_OK);
	assert_int_equal(ajar_scene_info_get(as, &in), AJAR_OK);
	assert_int_equal(in.has_camera, 1);
	assert_float_equal(in.camera.target[2], 9.0f, 1e-6);
	assert_float_equal(in.camera.up[1], 1.0f, 1e-6);
	assert_float_equal(in.camera.aspect, 1.5f, 0.0);
	ajar_camera flat = {{0, 0, 0}, {0, 1, 0}, {0, 1, 0}, 0.8f, 0.0f};
	assert_int_equal(ajar_scene_set_camera(as, &flat), AJAR_ERROR_INVALID_ARGUMENT);

	const float sky[3] = {0.1f, 0.2f, 0.3f}, neg[3] = {0.1f, -1.0f, 0.3f};
	assert_int_equal(ajar_scene_set_environment_color(as, neg), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(ajar_scene_set_environment_color(as, sky), AJAR_OK);
	assert_int_equal(ajar_scene_info_get(as, &in), AJAR_OK);
	assert_int_equal(in.environment, 1);
	ajar_scene_destroy(&as);
	assert_null(as);
}

/* The API's lights: defaults, validation, what comes back. */
static void test_api_lights(void **state)
{
	ajar_scene *s;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_light l, got;
	ajar_light_default(&l);
	assert_int_equal(l.type, AJAR_LIGHT_POINT);
	assert_float_equal(l.outer_cone, (float)(M_PI / 4), 1e-7f);
	l.type = AJAR_LIGHT_SPOT;
	l.direction[0] = 3.0f;
	l.direction[2] = 0.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	assert_int_equal(ajar_scene_light_get(s, 0, &got), AJAR_OK);
	assert_float_equal(got.direction[0], 1.0f, 0.0f); /* normalised */
	l.direction[0] = 0.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "zero direction"));
	l.type = AJAR_LIGHT_POINT; /* a point light needs none */
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	l.color[1] = NAN;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_ERROR_INVALID_ARGUMENT);
	l.color[1] = 1.0f;
	l.type = (ajar_light_type)5;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(ajar_scene_add_light(s, NULL), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(s, &in), AJAR_OK);
	assert_int_equal(in.lights, 2);
	ajar_scene_destroy(&s);
}

/* Coordinates beyond 1e18, finite but whose squares overflow a float (a
 * vertex at 3e38 gave NaN bins in the BVH: fuzz_gltf, UBSan), are refused
 * for vertices, the camera and lights; 1e17 is taken. */
static void test_api_huge_coordinates(void **state)
{
	ajar_scene *s;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material m;
	ajar_material_default(&m);
	uint32_t mat;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	ajar_mesh mesh = {pos, NULL, NULL, 3, NULL, 1, mat, NULL};
	pos[3] = 3e38f;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_ERROR_INVALID_ARGUMENT);
	assert_non_null(strstr(ajar_last_error(), "beyond 1e18"));
	pos[3] = 1e17f;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	ajar_camera c = {{0, 0, 1e30f}, {0, 0, 0}, {0, 1, 0}, 0.8f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &c), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_light l;
	ajar_light_default(&l);
	l.position[1] = -1e30f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_api_scene),
		cmocka_unit_test(test_api_lights),
		cmocka_unit_test(test_api_huge_coordinates),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
