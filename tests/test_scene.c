/* test_scene.c — the host scene, the scene API and the glTF loader.
 *
 * The shipped scenes load with the counts their SOURCE.md files state;
 * scenes built through the API end up where their transforms put them;
 * small glTF files written here exercise one loader feature each (node
 * hierarchies, strips and fans, interleaved, sparse and normalized
 * accessors, data URIs, .glb, portals, environments); broken files fail
 * with the right status and a message naming the file and the element. */
#include "testutil.h"

#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ajar.h"
#include "scene/scene.h"
#include "geom/surface.h"

#define EPS 1e-5f

static char *tmpdir;

static void assert_v3(V3 a, float x, float y, float z)
{
	if (fabsf(a.x - x) > EPS || fabsf(a.y - y) > EPS || fabsf(a.z - z) > EPS)
		fail_msg("(%g, %g, %g) != (%g, %g, %g)", a.x, a.y, a.z, x, y, z);
}

static char *tmp_path(const char *name)
{
	char *p = malloc(strlen(tmpdir) + strlen(name) + 2);
	assert_non_null(p);
	sprintf(p, "%s/%s", tmpdir, name);
	return p;
}

static void write_bytes(const char *name, const void *data, size_t n)
{
	char *p = tmp_path(name);
	FILE *f = fopen(p, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
	free(p);
}

static void write_text(const char *name, const char *text) { write_bytes(name, text, strlen(text)); }

static Scene *load_ok(const char *name)
{
	char *p = tmp_path(name);
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load(p, &s);
	if (st)
		fail_msg("%s: %s", ajar_status_name(st), ajar_last_error());
	free(p);
	return s;
}

/* The load fails with `status`, and the message names the file and holds
 * `needle` (the element and what is wrong with it). */
static void load_fails(const char *name, ajar_status status, const char *needle)
{
	char *p = tmp_path(name);
	static char sentinel;
	ajar_scene *s = (ajar_scene *)(void *)&sentinel; /* must come back NULL */
	ajar_status st = ajar_scene_load(p, &s);
	const char *msg = ajar_last_error();
	if (st != status || !strstr(msg, name) || !strstr(msg, needle))
		fail_msg("%s: got %s \"%s\", want %s with \"%s\"", name, ajar_status_name(st), msg,
			 ajar_status_name(status), needle);
	assert_null(s);
	free(p);
}

/* ---- The standard one-triangle buffer ------------------------------------
 * (0,0,0) (1,0,0) (0,1,0), normals +Z, u16 indices 0 1 2: 78 bytes with
 * views at 0 (positions), 36 (normals), 72 (indices). */
static size_t tri_bin(uint8_t *b, const uint16_t idx[3], float bad)
{
	const float pos[9] = {0, 0, 0, bad, 0, 0, 0, 1, 0};
	const float nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	memcpy(b, pos, 36);
	memcpy(b + 36, nrm, 36);
	memcpy(b + 72, idx, 6);
	return 78;
}

static const uint16_t idx012[3] = {0, 1, 2};

#define TRI_BUFFERS(uri)                                                                                         \
	"\"buffers\":[{\"uri\":\"" uri "\",\"byteLength\":78}],"                                               \
	"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"                                  \
	"{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}]," \
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]"

#define TRI_ACCESSORS(npos)                                                                                   \
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" #npos ",\"type\":\"VEC3\"},"      \
	"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                            \
	"{\"bufferView\":2,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]"

static void write_tri_bin(void)
{
	uint8_t bin[80];
	write_bytes("tri.bin", bin, tri_bin(bin, idx012, 1.0f));
}

/* One triangle mesh in tri.bin, with the given scene nodes, nodes, and
 * `more` added to the scene object (its extras). */
static void write_tri_gltf(const char *name, const char *scene_nodes, const char *nodes, const char *more)
{
	write_tri_bin();
	char json[4096];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[%s]%s}],\"nodes\":[%s]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}",
		 scene_nodes, more, nodes);
	write_text(name, json);
}

/* ---- Shipped scenes --------------------------------------------------- */

static Scene *load_shipped(const char *path, ajar_scene_info *info)
{
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load(path, &s);
	if (st)
		fail_msg("%s: %s", path, ajar_last_error());
	assert_int_equal(ajar_scene_info_get(s, info), AJAR_OK);
	return s;
}

static void test_cornell(void **state)
{
	ajar_scene_info in;
	Scene *s = load_shipped(SCENE("cornell/cornell.gltf"), &in);
	/* Counted from cornell.gltf: 5 walls and the light are 2 triangles
	 * each, the two blocks 10 each. */
	assert_int_equal(in.triangles, 32);
	assert_int_equal(in.materials, 4);
	assert_int_equal(in.emissive_triangles, 2);
	assert_int_equal(in.portals, 0);
	assert_int_equal(in.portal_triangles, 0);
	assert_int_equal(in.textures, 0);
	assert_int_equal(in.environment, 0);
	assert_true(in.has_camera);
	assert_int_equal(in.width, 0);
	/* Camera node: translation (0.278, 0.273, -0.8), 180 degrees about Y. */
	assert_v3(s->cam_pos, 0.278f, 0.273f, -0.8f);
	assert_v3(s->cam_forward, 0.0f, 0.0f, 1.0f);
	assert_v3(s->cam_up, 0.0f, 1.0f, 0.0f);
	assert_float_equal(s->cam_yfov, 0.6860478808414068f, 1e-7);
	assert_float_equal(s->cam_aspect, 1.0f, 0.0);
	assert_v3(v3(in.bounds_min[0], in.bounds_min[1], in.bounds_min[2]), 0.0f, 0.0f, 0.0f);
	assert_v3(v3(in.bounds_max[0], in.bounds_max[1], in.bounds_max[2]), 0.556f, 0.5488f, 0.5592f);
	/* The light: emissiveFactor x strength 17, single-sided, Lambertian. */
	const Material *light = &s->materials[3];
	assert_v3(light->emission, 17.0f, 12.0f, 4.0f);
	assert_int_equal(light->flags & MATERIAL_DOUBLE_SIDED, 0);
	assert_float_equal(light->specular, 0.0f, 0.0);
	const Material *white = &s->materials[0];
	assert_v3(white->base_color, 0.725f, 0.71f, 0.68f);
	assert_int_equal(white->flags, MATERIAL_DOUBLE_SIDED);
	assert_int_equal(white->base_tex, -1);
	assert_float_equal(white->ior, 1.5f, 0.0);
	for (uint32_t i = 0; i < s->ntris; i++) {
		assert_int_equal(s->tris[i].emitter, -1);
		assert_int_equal(s->shade[i].has_normals, 1);
	}
	ajar_scene_destroy(&s);
	assert_null(s);
}

static void test_window_room(void **state)
{
	ajar_scene_info in;
	Scene *s = load_shipped(SCENE("window-room/window-room.gltf"), &in);
	assert_int_equal(in.triangles, 28);
	assert_int_equal(in.portals, 1);
	assert_int_equal(in.portal_triangles, 2);
	assert_int_equal(in.emissive_triangles, 0);
	assert_int_equal(in.environment, 1);
	assert_v3(s->env_color, 1.0f, 1.0f, 1.0f);
	assert_true(in.has_camera);
	/* The portal is a 0.8 x 0.8 m quad. */
	assert_float_equal(s->portals[0].area + s->portals[1].area, 0.64f, 1e-5);
	ajar_scene_destroy(&s);
}

static void test_living_room(void **state)
{
	ajar_scene_info in;
	Scene *s = load_shipped(SCENE("living-room/living-room.gltf"), &in);
	assert_int_equal(in.triangles, 143163);
	assert_int_equal(in.portals, 4);
	assert_int_equal(in.portal_triangles, 8);
	assert_int_equal(in.emissive_triangles, 0);
	assert_int_equal(in.materials, 20);
	assert_int_equal(in.environment, 1);
	assert_true(in.has_camera);
	assert_int_equal(in.width, 1280);
	assert_int_equal(in.height, 720);
	assert_float_equal(s->cam_aspect, 16.0f / 9.0f, 1e-6);
	/* SOURCE.md: camera at (5.105, 0.731, -2.318) looking (-0.962, 0.074, 0.263). */
	assert_float_equal(s->cam_pos.x, 5.105f, 1e-3);
	assert_float_equal(s->cam_forward.x, -0.962f, 1e-3);
	assert_float_equal(s->cam_forward.z, 0.263f, 1e-3);
	/* leaf.png 365x271 and picture8.png 1280x853, as RGBA8. */
	assert_int_equal(in.textures, 2);
	int found = 0;
	for (uint32_t i = 0; i < s->ntextures; i++)
		found |= (s->textures[i].width == 365 && s->textures[i].height == 271) ? 1
			 : (s->textures[i].width == 1280 && s->textures[i].height == 853) ? 2
											   : 4;
	assert_int_equal(found, 3);
	assert_int_equal(s->ntexels, 365 * 271 + 1280 * 853);
	ajar_scene_destroy(&s);
}

/* Warnings sent to the log callback while a test loads something. */
static int warnings;
static char last_warning[2048];

static void count_warnings(ajar_log_level level, const char *message, void *user)
{
	if (level != AJAR_LOG_WARNING)
		return;
	warnings++;
	snprintf(last_warning, sizeof last_warning, "%s", message);
}

/* The sky-lit variants (scenes/skies/make_sky_scenes.py) and the atrium
 * (make_atrium.py): the rooms' geometry, the sky image with its slightly
 * negative pixels clamped (one warning), and the sun where the scene's
 * notes put it: the ray from the sun's pixel, turned by the scene's
 * rotation (right-handed about +Y, worked out here again), through an
 * opening's centre lands on the surface named. */
static void sun_landing(const Scene *s, V3 from, V3 *hit, float plane, int axis)
{
	size_t best = 0;
	for (size_t i = 0; i < (size_t)s->env_width * s->env_height; i++)
		if (s->env_rgb[3 * i] + s->env_rgb[3 * i + 1] > s->env_rgb[3 * best] + s->env_rgb[3 * best + 1])
			best = i;
	double u = ((double)(best % s->env_width) + 0.5) / s->env_width;
	double v = ((double)(best / s->env_width) + 0.5) / s->env_height;
	double phi = 2.0 * M_PI * (u - 0.5), th = M_PI * v, a = s->env_rotation;
	double dx = sin(th) * sin(phi), dy = cos(th), dz = -sin(th) * cos(phi);
	/* Turned: x' = c x + s z, z' = c z - s x. */
	double tx = cos(a) * dx + sin(a) * dz, tz = cos(a) * dz - sin(a) * dx;
	double dir[3] = {-tx, -dy, -tz}, o[3] = {from.x, from.y, from.z};
	double t = (plane - o[axis]) / dir[axis];
	assert_true(t > 0.0);
	*hit = v3((float)(o[0] + t * dir[0]), (float)(o[1] + t * dir[1]), (float)(o[2] + t * dir[2]));
}

static void test_sky_scenes(void **state)
{
	static const struct {
		const char *path;
		uint64_t triangles;
		int negative;
		float rotation; /* degrees, as make_sky_scenes.py printed */
	} scenes[] = {
		{SCENE("window-room-sunset/window-room-sunset.gltf"), 28, 4, 45.5352f},
		{SCENE("window-room-forest/window-room-forest.gltf"), 28, 826, 55.6836f},
		{SCENE("living-room-forest/living-room-forest.gltf"), 143163, 826, 140.6836f},
		{SCENE("atrium-forest/atrium-forest.gltf"), 42, 826, 75.6836f},
	};
	for (int k = 0; k < 4; k++) {
		warnings = 0;
		last_warning[0] = '\0';
		ajar_set_log_callback(count_warnings, NULL);
		ajar_scene_info in;
		Scene *s = load_shipped(scenes[k].path, &in);
		ajar_set_log_callback(NULL, NULL);
		char want[64];
		snprintf(want, sizeof want, "%d negative pixel values", scenes[k].negative);
		assert_int_equal(warnings, 1);
		if (!strstr(last_warning, want))
			fail_msg("%s: warning \"%s\"", scenes[k].path, last_warning);
		assert_int_equal(in.triangles, scenes[k].triangles);
		assert_int_equal(in.environment, 2);
		assert_int_equal(s->env_width, 1024);
		assert_int_equal(s->env_height, 512);
		assert_float_equal(s->env_rotation, scenes[k].rotation * M_PI / 180.0, 1e-5);
		V3 p;
		if (k == 0) {
			/* Low sun: on the far wall z = 3, right of the window, high up. */
			sun_landing(s, v3(2.0f, 1.4f, 0.0f), &p, 3.0f, 2);
			assert_true(p.x > 2.3f && p.x < 2.7f && p.y > 1.1f && p.y < 1.3f);
		} else if (k == 1) {
			/* The forest's sun: beyond the far wall's foot (y < 0 at z = 3),
			 * so it lights the wall's bottom and the floor before it. */
			sun_landing(s, v3(2.0f, 1.4f, 0.0f), &p, 3.0f, 2);
			assert_true(p.y > -0.2f && p.y < 0.3f && p.x > 2.5f && p.x < 3.5f);
		} else if (k == 2) {
			/* Through the window at x = -0.436 (z in [-1.04, -0.15]) onto the
			 * floor, in front of the camera (x 1.5..5.1, z in the room). */
			sun_landing(s, v3(-0.436f, 1.58f, -0.595f), &p, 0.0f, 1);
			assert_true(p.x > 1.5f && p.x < 5.1f && p.z > -3.6f && p.z < 0.0f);
		} else {
			/* Down through the roof's opening (its centre, 3.05 m up) onto the
			 * far wall z = 4, near its corner with x = 4, 2 m up. */
			sun_landing(s, v3(2.0f, 3.05f, 2.0f), &p, 4.0f, 2);
			assert_true(p.x > 3.5f && p.x < 3.9f && p.y > 1.9f && p.y < 2.3f);
		}
		ajar_scene_destroy(&s);
	}
}

static void test_bathroom(void **state)
{
	ajar_scene_info in;
	Scene *s = load_shipped(SCENE("bathroom/bathroom.gltf"), &in);
	assert_int_equal(in.triangles, 592188);
	assert_int_equal(in.portals, 2);
	assert_int_equal(in.portal_triangles, 4);
	/* One emissive quad outside the window, radiance 30. */
	assert_int_equal(in.emissive_triangles, 2);
	for (uint32_t i = 0; i < s->ntris; i++)
		if (!v3_is_zero(s->materials[s->tris[i].material].emission)) {
			assert_v3(s->materials[s->tris[i].material].emission, 30.0f, 30.0f, 30.0f);
			assert_float_equal(s->tris[i].p0.x, -2.898f, 1e-3);
		}
	assert_int_equal(in.environment, 0);
	assert_int_equal(in.textures, 3);
	assert_true(in.has_camera);
	assert_int_equal(in.width, 1024);
	assert_int_equal(in.height, 1024);
	assert_float_equal(s->cam_forward.x, -0.752f, 1e-3);
	assert_float_equal(s->cam_forward.z, -0.659f, 1e-3);
	assert_float_equal(in.bounds_min[0], -2.898f, 1e-3);
	assert_float_equal(in.bounds_max[1], 2.792f, 1e-3);
	ajar_scene_destroy(&s);
}

/* ---- API-built scenes -------------------------------------------------- */

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

/* ---- Loader features --------------------------------------------------- */

static void test_hierarchy_trs(void **state)
{
	/* Parent: translate (1,2,3), scale 2; child 1: 90 degrees about +Y with
	 * the mesh; child 2: the camera, 1 unit along the parent's +Z. */
	char json[4096];
	write_tri_bin();
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":["
		 "{\"translation\":[1,2,3],\"scale\":[2,2,2],\"children\":[1,2]},"
		 "{\"rotation\":[0,0.7071067811865476,0,0.7071067811865476],\"mesh\":0},"
		 "{\"camera\":0,\"translation\":[0,0,1],\"extras\":{\"resolution\":[320,240]}}],"
		 "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}");
	write_text("trs.gltf", json);
	Scene *s = load_ok("trs.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p0, 1, 2, 3);
	assert_v3(s->tris[0].p1, 1, 2, 1);
	assert_v3(s->tris[0].p2, 1, 4, 3);
	assert_v3(s->shade[0].n0, 1, 0, 0);
	assert_true(s->has_camera);
	assert_v3(s->cam_pos, 1, 2, 5);
	assert_v3(s->cam_forward, 0, 0, -1);
	assert_v3(s->cam_up, 0, 1, 0);
	assert_float_equal(s->cam_yfov, 0.5f, 0.0);
	assert_float_equal(s->cam_aspect, 0.0f, 0.0);
	assert_int_equal(s->width, 320);
	assert_int_equal(s->height, 240);
	/* No material: glTF's default (white, metallic 1, roughness 1). */
	assert_int_equal(s->nmaterials, 1);
	assert_v3(s->materials[0].base_color, 1, 1, 1);
	assert_float_equal(s->materials[0].metallic, 1.0f, 0.0);
	assert_float_equal(s->materials[0].roughness, 1.0f, 0.0);
	assert_int_equal(s->materials[0].base_tex, -1);
	ajar_scene_destroy(&s);
}

static void test_hierarchy_matrix(void **state)
{
	/* Column-major matrix: mirror x, then move to z = 5. Mirroring keeps
	 * the normal (inverse transpose) and reverses the winding. */
	write_tri_gltf("matrix.gltf", "0", "{\"matrix\":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1],\"mesh\":0}", "");
	Scene *s = load_ok("matrix.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p0, 0, 0, 5);
	assert_v3(s->tris[0].p1, 0, 1, 5);
	assert_v3(s->tris[0].p2, -1, 0, 5);
	V3 ng = v3_cross(v3_sub(s->tris[0].p1, s->tris[0].p0), v3_sub(s->tris[0].p2, s->tris[0].p0));
	assert_v3(ng, 0, 0, 1);
	assert_v3(s->shade[0].n1, 0, 0, 1);
	assert_false(s->has_camera);
	ajar_scene_destroy(&s);
}

static void test_no_scenes_all_roots(void **state)
{
	/* No "scenes": every root node is shown; node 1 is node 0's child. */
	write_tri_bin();
	write_text("roots.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0,\"children\":[1]},"
				 "{\"mesh\":0,\"translation\":[0,0,1]},{\"mesh\":0,\"translation\":[0,0,2]}]," TRI_BUFFERS(
					 "tri.bin") "," TRI_ACCESSORS(3) "}");
	Scene *s = load_ok("roots.gltf");
	assert_int_equal(s->ntris, 3);
	assert_float_equal(s->tris[1].p0.z, 1.0f, 0.0);
	assert_float_equal(s->tris[2].p0.z, 2.0f, 0.0);
	ajar_scene_destroy(&s);
}

static void test_non_indexed_and_materials(void **state)
{
	/* Two non-indexed triangles, drawn twice: with a material using every
	 * extension we read, and without a material. */
	const float pos[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1};
	write_bytes("flat.bin", pos, sizeof pos);
	write_text("flat.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0},"
		   "{\"attributes\":{\"POSITION\":0}}]}],"
		   "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,0.125,1],"
		   "\"metallicFactor\":0.2,\"roughnessFactor\":0.3},\"emissiveFactor\":[1,0.5,0],"
		   "\"doubleSided\":true,\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25,\"extensions\":{"
		   "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4},"
		   "\"KHR_materials_transmission\":{\"transmissionFactor\":0.75},"
		   "\"KHR_materials_ior\":{\"ior\":1.33},\"KHR_materials_specular\":{\"specularFactor\":0.5}}}],"
		   "\"extensionsUsed\":[\"KHR_materials_emissive_strength\",\"KHR_materials_transmission\","
		   "\"KHR_materials_ior\",\"KHR_materials_specular\"],"
		   "\"extensionsRequired\":[\"KHR_materials_transmission\"],"
		   "\"buffers\":[{\"uri\":\"flat.bin\",\"byteLength\":72}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":72}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"}]}");
	Scene *s = load_ok("flat.gltf");
	assert_int_equal(s->ntris, 4);
	assert_v3(s->tris[1].p0, 0, 0, 1);
	assert_v3(s->tris[1].p2, 0, 1, 1);
	assert_int_equal(s->shade[0].has_normals, 0);
	assert_int_equal(s->nmaterials, 2);
	const Material *m = &s->materials[0];
	assert_v3(m->base_color, 0.5f, 0.25f, 0.125f);
	assert_v3(m->emission, 4.0f, 2.0f, 0.0f);
	assert_float_equal(m->metallic, 0.2f, 1e-7);
	assert_float_equal(m->roughness, 0.3f, 1e-7);
	assert_float_equal(m->transmission, 0.75f, 0.0);
	assert_float_equal(m->ior, 1.33f, 1e-7);
	assert_float_equal(m->specular, 0.5f, 0.0);
	assert_int_equal(m->flags, MATERIAL_DOUBLE_SIDED | MATERIAL_ALPHA_MASK);
	assert_float_equal(m->alpha_cutoff, 0.25f, 0.0);
	assert_int_equal(s->tris[0].material, 0);
	assert_int_equal(s->tris[2].material, 1);
	assert_float_equal(s->materials[1].metallic, 1.0f, 0.0);
	assert_int_equal(scene_count_emissive(s), 2);
	ajar_scene_destroy(&s);
}

static void test_unread_extension_members(void **state)
{
	(void)state;
	/* Members of the extensions we read that we do not use: one warning
	 * each, naming it; the factors still apply. */
	const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	write_bytes("unread.bin", pos, sizeof pos);
	const char *head = "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
			   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
			   "\"materials\":[{\"extensions\":{";
	const char *tail = "}}],\"buffers\":[{\"uri\":\"unread.bin\",\"byteLength\":36}],"
			   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
			   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
	const struct {
		const char *ext, *want;
		int warnings;
	} cases[] = {
		{"\"KHR_materials_transmission\":{\"transmissionFactor\":0.5},"
		 "\"KHR_materials_volume\":{\"thicknessFactor\":0.1,\"thicknessTexture\":{\"index\":0}}",
		 "KHR_materials_volume.thicknessTexture is not supported", 1},
		{"\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,0.5,1],"
		 "\"specularTexture\":{\"index\":0}}",
		 "specularColorFactor is not supported", 2},
		{"\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,1,1]}", "", 0},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		char json[2048];
		snprintf(json, sizeof json, "%s%s%s", head, cases[k].ext, tail);
		write_text("unread.gltf", json);
		warnings = 0;
		last_warning[0] = '\0';
		ajar_set_log_callback(count_warnings, NULL);
		Scene *s = load_ok("unread.gltf");
		ajar_set_log_callback(NULL, NULL);
		assert_int_equal(warnings, cases[k].warnings);
		if (!strstr(last_warning, cases[k].want) || (cases[k].warnings && !strstr(last_warning, "materials[0]")))
			fail_msg("case %zu: warning \"%s\"", k, last_warning);
		assert_float_equal(k == 0 ? s->materials[0].transmission : s->materials[0].specular, 0.5f, 0.0);
		ajar_scene_destroy(&s);
	}
}

static void test_interleaved_strip_fan(void **state)
{
	/* Four vertices interleaved (position, normal, normalized u16 uv;
	 * stride 28) and three primitives over u8 indices: a triangle list, a
	 * strip, a fan; plus a point primitive that is skipped. */
	struct {
		float p[3], n[3];
		uint16_t uv[2];
	} v[4] = {
		{{0, 0, 0}, {0, 0, 1}, {0, 0}},
		{{1, 0, 0}, {0, 0, 1}, {65535, 0}},
		{{0, 1, 0}, {0, 0, 1}, {0, 32768}},
		{{1, 1, 0}, {0, 0, 1}, {65535, 65535}},
	};
	_Static_assert(sizeof v == 112, "packed vertices");
	uint8_t bin[124];
	const uint8_t idx[11] = {0, 1, 2, 0, 1, 2, 3, 0, 1, 3, 2};
	memcpy(bin, v, 112);
	memcpy(bin + 112, idx, 11);
	write_bytes("inter.bin", bin, 123);
	write_text("inter.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":["
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3},"
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":4,\"mode\":5},"
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":5,\"mode\":6},"
		   "{\"attributes\":{\"POSITION\":0},\"mode\":0}]}],"
		   "\"buffers\":[{\"uri\":\"inter.bin\",\"byteLength\":123}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":112,\"byteStride\":28},"
		   "{\"buffer\":0,\"byteOffset\":112,\"byteLength\":11}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		   "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		   "{\"bufferView\":0,\"byteOffset\":24,\"componentType\":5123,\"normalized\":true,\"count\":4,"
		   "\"type\":\"VEC2\"},"
		   "{\"bufferView\":1,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"},"
		   "{\"bufferView\":1,\"byteOffset\":3,\"componentType\":5121,\"count\":4,\"type\":\"SCALAR\"},"
		   "{\"bufferView\":1,\"byteOffset\":7,\"componentType\":5121,\"count\":4,\"type\":\"SCALAR\"}]}");
	Scene *s = load_ok("inter.gltf");
	assert_int_equal(s->ntris, 5);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->shade[0].n2, 0, 0, 1);
	assert_float_equal(s->shade[0].u1, 1.0f, 0.0);
	assert_float_equal(s->shade[0].v2, 32768.0f / 65535.0f, 1e-7);
	/* Strip 0 1 2 3: (0 1 2), (1 3 2). Fan 0 1 3 2: (1 3 0), (3 2 0). */
	assert_v3(s->tris[2].p0, 1, 0, 0);
	assert_v3(s->tris[2].p1, 1, 1, 0);
	assert_v3(s->tris[2].p2, 0, 1, 0);
	assert_v3(s->tris[3].p0, 1, 0, 0);
	assert_v3(s->tris[3].p2, 0, 0, 0);
	assert_v3(s->tris[4].p0, 1, 1, 0);
	assert_v3(s->tris[4].p1, 0, 1, 0);
	for (uint32_t i = 0; i < s->ntris; i++) {
		V3 ng = v3_cross(v3_sub(s->tris[i].p1, s->tris[i].p0), v3_sub(s->tris[i].p2, s->tris[i].p0));
		assert_true(ng.z > 0.0f); /* all counter-clockwise seen from +Z */
	}
	ajar_scene_destroy(&s);
}

static void test_sparse(void **state)
{
	/* POSITION: the triangle with vertex 2 replaced by (5, 5, 5) through a
	 * sparse u8 index; NORMAL: no buffer view (zeros) with one sparse
	 * value at vertex 1, so the triangle falls back to its geometric normal. */
	uint8_t bin[128];
	tri_bin(bin, idx012, 1.0f); /* bytes 0..77 */
	const uint8_t sidx[4] = {2, 1, 0, 0};
	const float sval[6] = {5, 5, 5, 0, 0, 3};
	memcpy(bin + 80, sidx, 4);
	memcpy(bin + 84, sval, 24);
	write_bytes("sparse.bin", bin, 108);
	write_text("sparse.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
		   "\"buffers\":[{\"uri\":\"sparse.bin\",\"byteLength\":108}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6},"
		   "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":24}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
		   "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":2,\"componentType\":5121},"
		   "\"values\":{\"bufferView\":3}}},"
		   "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
		   "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":2,\"byteOffset\":1,\"componentType\":5121},"
		   "\"values\":{\"bufferView\":3,\"byteOffset\":12}}},"
		   "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}");
	Scene *s = load_ok("sparse.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->tris[0].p2, 5, 5, 5);
	assert_int_equal(s->shade[0].has_normals, 0);
	ajar_scene_destroy(&s);
}

static char *base64(const uint8_t *p, size_t n)
{
	static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
	assert_non_null(out);
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
		*o++ = tab[v >> 18];
		*o++ = tab[(v >> 12) & 63];
		*o++ = i + 1 < n ? tab[(v >> 6) & 63] : '=';
		*o++ = i + 2 < n ? tab[v & 63] : '=';
	}
	*o = '\0';
	return out;
}

static void test_data_uri(void **state)
{
	uint8_t bin[80];
	char *b64 = base64(bin, tri_bin(bin, idx012, 1.0f));
	char *json = malloc(8192);
	assert_non_null(json);
	snprintf(json, 8192,
		 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,"
		 "\"translation\":[0,0,-1]}],\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\","
		 "\"byteLength\":78}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},"
		 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]," TRI_ACCESSORS(
			 3) "}",
		 b64);
	write_text("datauri.gltf", json);
	free(json);
	free(b64);
	Scene *s = load_ok("datauri.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p2, 0, 1, -1);
	ajar_scene_destroy(&s);
}

static void put_u32(uint8_t *p, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static void test_glb(void **state)
{
	/* GLB: 12-byte header, a JSON chunk padded with spaces, a BIN chunk
	 * padded with zeros, all little-endian. The file has no extension
	 * hint (.glb) that the loader relies on; it checks the magic. */
	char json[2048];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		 "\"buffers\":[{\"byteLength\":78}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},"
		 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]," TRI_ACCESSORS(
			 3) "}");
	size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3, blen = 80;
	size_t total = 12 + 8 + jpad + 8 + blen;
	uint8_t *glb = calloc(1, total);
	assert_non_null(glb);
	memcpy(glb, "glTF", 4);
	put_u32(glb + 4, 2);
	put_u32(glb + 8, (uint32_t)total);
	put_u32(glb + 12, (uint32_t)jpad);
	put_u32(glb + 16, 0x4E4F534A); /* "JSON" */
	memcpy(glb + 20, json, jlen);
	memset(glb + 20 + jlen, ' ', jpad - jlen);
	uint8_t *b = glb + 20 + jpad;
	put_u32(b, (uint32_t)blen);
	put_u32(b + 4, 0x004E4942); /* "BIN" */
	tri_bin(b + 8, idx012, 1.0f);
	write_bytes("tri.glb", glb, total);
	free(glb);
	Scene *s = load_ok("tri.glb");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->shade[0].n0, 0, 0, 1);
	ajar_scene_destroy(&s);
}

static void test_portals_and_environment(void **state)
{
	/* Node 0 is a portal (marked 1, as Blender writes custom properties);
	 * its child is not; node 2 is a portal marked true at z = 3; the
	 * environment colour is scaled by its strength. */
	write_tri_gltf("portal.gltf", "0,2",
		       "{\"mesh\":0,\"extras\":{\"portal\":1},\"children\":[1]},"
		       "{\"mesh\":0,\"translation\":[0,0,1]},"
		       "{\"mesh\":0,\"translation\":[0,0,3],\"extras\":{\"portal\":true}}",
		       ",\"extras\":{\"environment\":{\"color\":[0.5,1,2],\"strength\":2},\"resolution\":[64,32]}");
	Scene *s = load_ok("portal.gltf");
	assert_int_equal(s->ntris, 1);
	assert_float_equal(s->tris[0].p0.z, 1.0f, 0.0);
	assert_int_equal(s->nportals, 2);
	assert_int_equal(s->nportal_tris, 2);
	assert_float_equal(s->portals[1].p0.z, 3.0f, 0.0);
	assert_float_equal(s->portals[0].area, 0.5f, 1e-7);
	assert_int_equal(s->env_type, ENV_COLOR);
	assert_v3(s->env_color, 1, 2, 4);
	assert_int_equal(s->width, 64);
	assert_int_equal(s->height, 32);
	ajar_scene_destroy(&s);
}

static void test_environment_image(void **state)
{
	/* An 8x4 EXR next to the glTF, named relative to it. */
	float rgba[8 * 4 * 4];
	for (int i = 0; i < 8 * 4; i++) {
		rgba[4 * i] = (float)i;
		rgba[4 * i + 1] = 0.5f;
		rgba[4 * i + 2] = 0.25f * (float)(i % 8);
		rgba[4 * i + 3] = 1.0f;
	}
	char *exr = tmp_path("sky.exr");
	assert_int_equal(ajar_write_exr(exr, rgba, 8, 4, NULL, 0), AJAR_OK);
	free(exr);
	write_tri_gltf("envimg.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"sky.exr\",\"strength\":0.5}}");
	Scene *s = load_ok("envimg.gltf");
	assert_int_equal(s->env_type, ENV_IMAGE);
	assert_int_equal(s->env_width, 8);
	assert_int_equal(s->env_height, 4);
	assert_float_equal(s->env_strength, 0.5f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13], 13.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13 + 1], 0.5f, 0.0);
	assert_float_equal(s->env_rgb[3 * 13 + 2], 1.25f, 0.0);
	ajar_scene_destroy(&s);

	write_tri_gltf("envmissing.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"nosky.exr\"}}");
	load_fails("envmissing.gltf", AJAR_ERROR_IO, "scenes[0].extras.environment.image");
}

/* An 8x4 EXR of 0.5 with `bad` at the pixels listed (x, y pairs). */
static void write_sky(const char *name, float bad, const int *xy, int n)
{
	float rgba[8 * 4 * 4];
	for (int i = 0; i < 8 * 4 * 4; i++)
		rgba[i] = 0.5f;
	for (int k = 0; k < n; k++)
		rgba[4 * (xy[2 * k + 1] * 8 + xy[2 * k]) + (k % 3)] = bad;
	char *exr = tmp_path(name);
	assert_int_equal(ajar_write_exr(exr, rgba, 8, 4, NULL, 0), AJAR_OK);
	free(exr);
}

static void test_environment_pixels(void **state)
{
	/* Tiny negatives (as filtering tools leave them) become 0 with one
	 * warning that counts them and names the file. */
	static const int neg[] = {1, 0, 5, 2, 7, 3};
	write_sky("negsky.exr", -1e-4f, neg, 3);
	write_tri_gltf("negsky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"negsky.exr\"}}");
	warnings = 0;
	ajar_set_log_callback(count_warnings, NULL);
	Scene *s = load_ok("negsky.gltf");
	ajar_set_log_callback(NULL, NULL);
	assert_int_equal(warnings, 1);
	if (!strstr(last_warning, "negsky.exr") || !strstr(last_warning, "3 negative pixel values"))
		fail_msg("warning \"%s\"", last_warning);
	assert_int_equal(s->env_type, ENV_IMAGE);
	assert_float_equal(s->env_rgb[3 * (0 * 8 + 1)], 0.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * (2 * 8 + 5) + 1], 0.0f, 0.0);
	assert_float_equal(s->env_rgb[3 * (3 * 8 + 7) + 2], 0.0f, 0.0);
	for (int i = 0; i < 8 * 4 * 3; i++)
		assert_true(s->env_rgb[i] == 0.0f || s->env_rgb[i] == 0.5f);
	ajar_scene_destroy(&s);

	/* A clean sky: no warning. */
	write_sky("cleansky.exr", 0.0f, neg, 0);
	write_tri_gltf("cleansky.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"cleansky.exr\"}}");
	warnings = 0;
	ajar_set_log_callback(count_warnings, NULL);
	s = load_ok("cleansky.gltf");
	ajar_set_log_callback(NULL, NULL);
	assert_int_equal(warnings, 0);
	ajar_scene_destroy(&s);

	/* NaN and Inf are refused, naming the file and the pixel; the glTF
	 * loader adds the scene file and the element. */
	static const int one[] = {6, 2};
	write_sky("nansky.exr", NAN, one, 1);
	write_tri_gltf("nansky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"nansky.exr\"}}");
	load_fails("nansky.gltf", AJAR_ERROR_BAD_INPUT, "nansky.exr: environment: pixel (6, 2) channel R is nan");
	write_sky("infsky.exr", -INFINITY, one, 1);
	write_tri_gltf("infsky.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"infsky.exr\"}}");
	load_fails("infsky.gltf", AJAR_ERROR_BAD_INPUT, "infsky.exr: environment: pixel (6, 2) channel R is -inf");

	/* Through the API: the same check, and the scene keeps no sky. */
	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	char *nan_exr = tmp_path("nansky.exr");
	assert_int_equal(ajar_scene_set_environment_image(as, nan_exr, 1.0f), AJAR_ERROR_BAD_INPUT);
	if (!strstr(ajar_last_error(), "nansky.exr: environment: pixel (6, 2)"))
		fail_msg("\"%s\"", ajar_last_error());
	free(nan_exr);
	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(as, &in), AJAR_OK);
	assert_int_equal(in.environment, 0);
	ajar_scene_destroy(&as);
}

static void test_environment_rotation(void **state)
{
	/* Degrees in the extras, radians about +Y in the scene, reduced
	 * modulo a turn; any number of degrees, of either sign. */
	write_sky("rotsky.exr", 0.0f, NULL, 0);
	write_tri_gltf("rot.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"rotsky.exr\",\"rotation\":-450}}");
	Scene *s = load_ok("rot.gltf");
	assert_float_equal(s->env_rotation, -0.5 * M_PI, 1e-6);
	ajar_scene_destroy(&s);
	write_tri_gltf("rotcol.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"color\":[1,1,1],\"rotation\":30}}");
	s = load_ok("rotcol.gltf");
	assert_float_equal(s->env_rotation, M_PI / 6.0, 1e-6);
	ajar_scene_destroy(&s);
	write_tri_gltf("rotbad.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"color\":[1,1,1],\"rotation\":\"east\"}}");
	load_fails("rotbad.gltf", AJAR_ERROR_BAD_INPUT, "scenes[0].extras.environment.rotation must be a number");

	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	assert_float_equal(as->env_rotation, 0.0f, 0.0);
	assert_int_equal(ajar_scene_set_environment_rotation(as, 90.0f), AJAR_OK);
	assert_float_equal(as->env_rotation, 0.5 * M_PI, 1e-6);
	assert_int_equal(ajar_scene_set_environment_rotation(as, NAN), AJAR_ERROR_INVALID_ARGUMENT);
	assert_int_equal(ajar_scene_set_environment_rotation(NULL, 1.0f), AJAR_ERROR_INVALID_ARGUMENT);
	assert_float_equal(as->env_rotation, 0.5 * M_PI, 1e-6);
	ajar_scene_destroy(&as);
}

/* A flat (not run-length) 8x4 Radiance file: pixel i has mantissas
 * (128 + i, 64, 0) and exponent byte 129, so RGB = (1 + i / 128, 0.5, 0). */
static void write_hdr(const char *name)
{
	static const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
	unsigned char data[sizeof head - 1 + 8 * 4 * 4];
	memcpy(data, head, sizeof head - 1);
	for (int i = 0; i < 8 * 4; i++) {
		unsigned char *p = data + sizeof head - 1 + 4 * i;
		p[0] = (unsigned char)(128 + i);
		p[1] = 64;
		p[2] = 0;
		p[3] = 129;
	}
	write_bytes(name, data, sizeof data);
}

static void test_environment_hdr(void **state)
{
	/* Told by its header, not its name. */
	write_hdr("sky.hdr");
	write_hdr("sky-hdr.exr");
	const char *names[2] = {"sky.hdr", "sky-hdr.exr"};
	for (int k = 0; k < 2; k++) {
		char extras[256];
		snprintf(extras, sizeof extras, ",\"extras\":{\"environment\":{\"image\":\"%s\",\"strength\":2}}",
			 names[k]);
		write_tri_gltf("hdr.gltf", "0", "{\"mesh\":0}", extras);
		Scene *s = load_ok("hdr.gltf");
		assert_int_equal(s->env_type, ENV_IMAGE);
		assert_int_equal(s->env_width, 8);
		assert_int_equal(s->env_height, 4);
		assert_float_equal(s->env_strength, 2.0f, 0.0);
		for (int i = 0; i < 8 * 4; i++) {
			assert_true(s->env_rgb[3 * i] == 1.0f + (float)i / 128.0f);
			assert_true(s->env_rgb[3 * i + 1] == 0.5f);
			assert_true(s->env_rgb[3 * i + 2] == 0.0f);
		}
		ajar_scene_destroy(&s);
	}
	ajar_scene *as = NULL;
	assert_int_equal(ajar_scene_create(&as), AJAR_OK);
	char *p = tmp_path("sky.hdr");
	assert_int_equal(ajar_scene_set_environment_image(as, p, 1.0f), AJAR_OK);
	free(p);
	assert_int_equal(as->env_width, 8);
	assert_true(as->env_rgb[3 * 9] == 1.0f + 9.0f / 128.0f);
	ajar_scene_destroy(&as);

	/* A Radiance header with a layout stb_image does not read, and one
	 * cut short: refused, naming the file. */
	write_text("sideways.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+X 8 -Y 4\n");
	write_tri_gltf("hdrbad.gltf", "0", "{\"mesh\":0}",
		       ",\"extras\":{\"environment\":{\"image\":\"sideways.hdr\"}}");
	load_fails("hdrbad.gltf", AJAR_ERROR_BAD_INPUT, "sideways.hdr: not a readable Radiance HDR image");
	write_text("cut.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n\x80\x40");
	write_tri_gltf("hdrcut.gltf", "0", "{\"mesh\":0}", ",\"extras\":{\"environment\":{\"image\":\"cut.hdr\"}}");
	load_fails("hdrcut.gltf", AJAR_ERROR_BAD_INPUT, "cut.hdr: not a readable Radiance HDR image");
}

/* ---- Broken files ------------------------------------------------------ */

/* ---- Texture coordinates, samplers, transforms, vertex colours ----------
 * One triangle (0,0,0) (1,0,0) (0,1,0) with TEXCOORD_0 = xy, TEXCOORD_1 =
 * (0.5 + x/2, 0.5 + y/2) and COLOR_0 red, green, blue (alpha 0.5) as
 * normalized bytes, and a 4 x 4 PNG whose texel (x, y) is
 * (60x + 10, 60y + 10, 0). Three materials: TEXCOORD_1 with a clamp (s) /
 * mirrored-repeat (t) nearest sampler; KHR_texture_transform offset
 * (0.25, 0), scale 0.5; rotation pi/2 and texCoord 1 (repeat, nearest). */
#define UV_BUFFER "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAPwAAAD8AAIA/AAAAPwAAAD8AAIA//wAA/wD/AP8AAP+A"
#define UV_PNG "iVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAYAAACp8Z5+AAAAK0lEQVR4nBXIMQEAMBACMWaEIQxhWGvvhyyRrRcUgxwCxXJRAsV6MQLF8AFZeRxxtxm5jwAAAABJRU5ErkJggg=="
static const char uv_gltf[] =
	"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_texture_transform\"],"
	"\"extensionsRequired\":[\"KHR_texture_transform\"],\"scenes\":[{\"nodes\":[0,1,2]}],"
	"\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"mesh\":2}],"
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"TEXCOORD_1\":2,\"COLOR_0\":3},\"material\":0}]},"
	"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1}]},"
	"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2}]}],"
	"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1}}},"
	"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":"
	"{\"offset\":[0.25,0],\"scale\":[0.5,0.5]}}}}},"
	"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":"
	"{\"rotation\":1.5707963267948966,\"texCoord\":1}}}}}],"
	"\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":0,\"sampler\":1}],"
	"\"samplers\":[{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33648},{\"magFilter\":9728}],"
	"\"images\":[{\"uri\":\"data:image/png;base64," UV_PNG "\"}],"
	"\"buffers\":[{\"byteLength\":96,\"uri\":\"data:application/octet-stream;base64," UV_BUFFER "\"}],"
	"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
	"{\"buffer\":0,\"byteOffset\":60,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":12}],"
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
	"{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
	"{\"bufferView\":3,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"}]}";

/* KHR_materials_volume and KHR_materials_transmission's texture: a
 * thickness above 0 makes a refracting solid (MATERIAL_VOLUME) absorbing
 * sigma = -ln(attenuationColor) / attenuationDistance; thickness 0 or no
 * volume is thin-walled, and smooth thin glass is a pane (TRI_PANE) that
 * shadow rays cross, rough or volume glass is not; the transmission
 * texture is kept (+1, as the other texture slots). Bad volume values are
 * bad input naming the member. */
static void test_volume_and_transmission(void **state)
{
	(void)state;
	static const char head[] =
		"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_transmission\",\"KHR_materials_volume\"],"
		"\"scenes\":[{\"nodes\":[0,1,2,3]}],\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"mesh\":2},{\"mesh\":3}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":3}]}],"
		"\"materials\":[";
	static const char tail[] =
		"],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64," UV_PNG "\"}],"
		"\"buffers\":[{\"byteLength\":96,\"uri\":\"data:application/octet-stream;base64," UV_BUFFER "\"}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
		"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}]}";
	static const char good[] =
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
		"\"KHR_materials_volume\":{\"thicknessFactor\":0.5,\"attenuationColor\":[0.5,0.25,1],\"attenuationDistance\":2}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
		"\"KHR_materials_volume\":{\"thicknessFactor\":0}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":0.8,"
		"\"transmissionTexture\":{\"index\":0}}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0.5},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1}}}";
	char json[8192];
	snprintf(json, sizeof json, "%s%s%s", head, good, tail);
	write_text("volume.gltf", json);
	Scene *s = load_ok("volume.gltf");
	const Material *m = s->materials;
	assert_true(m[0].flags & MATERIAL_VOLUME);
	assert_v3(m[0].sigma, (float)(log(2.0) / 2), (float)(log(4.0) / 2), 0.0f);
	assert_false(m[1].flags & MATERIAL_VOLUME);
	assert_false(m[2].flags & MATERIAL_VOLUME);
	assert_int_equal(m[2].transmission_tex, s->materials[2].transmission_tex);
	assert_true(m[2].transmission_tex >= 1 && m[2].transmission_tex <= (int)s->ntextures);
	assert_float_equal(m[2].transmission, 0.8f, 1e-7);
	assert_int_equal(m[1].transmission_tex, 0);
	/* One triangle a mesh, in node order: the volume is no pane, thin
	 * smooth glass is (textured or not), rough thin glass is not. */
	assert_int_equal(s->ntris, 4);
	assert_false(s->tris[0].flags & TRI_PANE);
	assert_true(s->tris[1].flags & TRI_PANE);
	assert_true(s->tris[2].flags & TRI_PANE);
	assert_false(s->tris[3].flags & TRI_PANE);
	ajar_scene_destroy(&s);
	const char *bad[][2] = {
		{"\"attenuationDistance\":0", "attenuationDistance"},
		{"\"attenuationColor\":[1,2,1]", "attenuationColor"},
		{"\"attenuationColor\":[1,1]", "attenuationColor"},
		{"\"thicknessFactor\":-1", "thicknessFactor"},
	};
	for (int k = 0; k < 4; k++) {
		char mat[512];
		snprintf(mat, sizeof mat,
			 "{\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
			 "\"KHR_materials_volume\":{\"thicknessFactor\":1,%s}}},{},{},{}",
			 bad[k][0]);
		if (k == 3)
			snprintf(mat, sizeof mat, "{\"extensions\":{\"KHR_materials_volume\":{%s}}},{},{},{}", bad[k][0]);
		snprintf(json, sizeof json, "%s%s%s", head, mat, tail);
		write_text("volume.gltf", json);
		load_fails("volume.gltf", AJAR_ERROR_BAD_INPUT, bad[k][1]);
	}
}

/* Texel (x, y)'s red and green, as texture_rgba reads them undecoded. */
static void assert_texel(Rgba c, int x, int y)
{
	if (fabsf(c.rgb.x - (60 * x + 10) / 255.0f) > EPS || fabsf(c.rgb.y - (60 * y + 10) / 255.0f) > EPS)
		fail_msg("read (%g, %g), want texel (%d, %d)", c.rgb.x * 255, c.rgb.y * 255, x, y);
}

static void test_texture_coordinates(void **state)
{
	(void)state;
	write_text("uv.gltf", uv_gltf);
	Scene *s = load_ok("uv.gltf");
	assert_int_equal(s->nimages, 1);
	SceneView sc = scene_surface_view(s);
	int t0 = s->materials[0].base_tex, t1 = s->materials[1].base_tex, t2 = s->materials[2].base_tex;
	/* Wrap modes at and past the edges: clamp in s, mirrored repeat in t. */
	assert_texel(texture_rgba(&sc, t0, 1.3f, 0.1f, 0), 3, 0);
	assert_texel(texture_rgba(&sc, t0, -0.2f, 0.1f, 0), 0, 0);
	assert_texel(texture_rgba(&sc, t0, 0.99f, 0.99f, 0), 3, 3);
	assert_texel(texture_rgba(&sc, t0, 0.1f, 1.2f, 0), 0, 3);   /* 2 - 1.2 = 0.8 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, -0.1f, 0), 0, 0);  /* 0.1 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, 2.3f, 0), 0, 1);   /* 0.3 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, -1.3f, 0), 0, 2);  /* 2 - 1.3 = 0.7 */
	/* Repeat (texture 1's sampler) and the transform: offset + scale x uv. */
	assert_texel(texture_rgba(&sc, t1, 0.1f, 0.1f, 0), 1, 0);   /* (0.3, 0.05) */
	assert_texel(texture_rgba(&sc, t1, 1.9f, 0.9f, 0), 0, 1);   /* (1.2, 0.45) -> 0.2 */
	/* Rotation pi/2: (u, v) -> (v, -u), as TextureTransformTest shows. */
	assert_true(s->textures[t2].flags & TEX_UV1);
	assert_texel(texture_rgba(&sc, t2, 0.1f, 0.6f, 0), 2, 3);   /* (0.6, -0.1) -> (0.6, 0.9) */
	/* Bilinear (a use with the default sampler): halfway between texel
	 * centres 0 and 1, blended before decoding (as Cycles: texture.h). */
	const float id[6] = {1, 0, 0, 0, 1, 0};
	uint32_t lin;
	assert_int_equal(scene_add_texture_use(s, 0, 0, id, &lin), AJAR_OK);
	sc.textures = s->textures;
	Rgba c = texture_rgba(&sc, (int)lin, 0.25f, 0.125f, 0);
	assert_float_equal(c.rgb.x, 40.0f / 255.0f, EPS);
	assert_float_equal(c.rgb.y, 10.0f / 255.0f, EPS);
	c = texture_rgba(&sc, (int)lin, 0.25f, 0.125f, 1);
	assert_float_equal(c.rgb.x, srgb_to_linear(40.0f / 255), EPS);
	assert_true(c.rgb.x < 0.5f * (srgb_to_linear(10.0f / 255) + srgb_to_linear(70.0f / 255)) - 0.005f);
	/* TEXCOORD_1 and COLOR_0 end to end: at barycentrics (0.2, 0.2) of
	 * triangle 0, TEXCOORD_1 is (0.6, 0.6) (texel (2, 2)) and the colour
	 * (0.6, 0.2, 0.2), alpha 0.6 + 0.2 + 0.2 x 128/255. */
	assert_true(s->tris[0].flags & TRI_EXTRA);
	assert_false(s->tris[1].flags & TRI_EXTRA);
	Hit h = {1.0f, 0.2f, 0.2f, 0};
	Surface sf;
	surface_from_hit(&sc, &h, &sf);
	assert_float_equal(sf.alpha, 0.8f + 0.2f * 128.0f / 255.0f, EPS);
	V3 base = surface_base_color(&sc, &sf);
	float t22 = srgb_to_linear(130.0f / 255.0f);
	assert_v3(base, 0.6f * t22, 0.2f * t22, 0.0f);
	h.tri = 1; /* no COLOR_0: white */
	surface_from_hit(&sc, &h, &sf);
	assert_v3(sf.color, 1, 1, 1);
	ajar_scene_destroy(&s);
}

/* ---- The Khronos sample assets (scenes/khronos) ---------------------------
 * Each loads without a warning, and what it exercises arrives: required
 * KHR_texture_transform, clamp and mirror samplers, TEXCOORD_1, COLOR_0,
 * MASK and BLEND. */
typedef struct {
	int warnings;
	char last[512];
} LogCount;

static void count_asset_warnings(ajar_log_level level, const char *msg, void *user)
{
	LogCount *c = user;
	if (level == AJAR_LOG_WARNING) {
		c->warnings++;
		snprintf(c->last, sizeof c->last, "%s", msg);
	}
}

static Scene *load_asset(const char *name, ajar_scene_info *in)
{
	char path[256];
	snprintf(path, sizeof path, SCENE("khronos/%s/%s.gltf"), name, name);
	LogCount c = {0, ""};
	ajar_set_log_callback(count_asset_warnings, &c);
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load(path, &s);
	ajar_set_log_callback(NULL, NULL);
	if (st)
		fail_msg("%s: %s", path, ajar_last_error());
	if (c.warnings)
		fail_msg("%s: %d warnings, the last: %s", path, c.warnings, c.last);
	assert_int_equal(ajar_scene_info_get(s, in), AJAR_OK);
	return s;
}

static void test_khronos_assets(void **state)
{
	(void)state;
	ajar_scene_info in;
	Scene *s = load_asset("TextureTransformTest", &in);
	int moved = 0, clamped = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		int t = s->materials[i].base_tex;
		if (t < 0)
			continue;
		moved += s->textures[t].xf[2] != 0.0f || s->textures[t].xf[5] != 0.0f || s->textures[t].xf[1] != 0.0f ||
			 s->textures[t].xf[0] != 1.0f;
		clamped += TEX_WRAP_S(s->textures[t].flags) == TEX_WRAP_CLAMP;
	}
	assert_true(moved >= 6);
	assert_true(clamped >= 1);
	ajar_scene_destroy(&s);

	s = load_asset("TextureSettingsTest", &in);
	int modes = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		int t = s->materials[i].base_tex;
		if (t >= 0)
			modes |= 1 << TEX_WRAP_S(s->textures[t].flags) | 8 << TEX_WRAP_T(s->textures[t].flags);
	}
	assert_int_equal(modes, 63); /* every mode on both axes */
	ajar_scene_destroy(&s);

	s = load_asset("MultiUVTest", &in);
	assert_int_equal(in.emissive_textures, 1);
	int uv1 = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++)
		if (s->materials[i].emissive_tex)
			uv1 += (s->textures[s->materials[i].emissive_tex - 1].flags & TEX_UV1) != 0;
	assert_int_equal(uv1, 1);
	assert_true(s->extra != NULL);
	ajar_scene_destroy(&s);

	s = load_asset("VertexColorTest", &in);
	uint32_t coloured = 0;
	for (uint32_t i = 0; i < s->ntris; i++)
		coloured += (s->tris[i].flags & TRI_EXTRA) != 0;
	assert_true(coloured > 0 && coloured < s->ntris);
	ajar_scene_destroy(&s);

	s = load_asset("AlphaBlendModeTest", &in);
	int mask = 0, blend = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		mask += (s->materials[i].flags & MATERIAL_ALPHA_MASK) != 0;
		blend += (s->materials[i].flags & MATERIAL_ALPHA_BLEND) != 0;
	}
	assert_int_equal(mask, 3);
	assert_int_equal(blend, 1);
	assert_int_equal(in.normal_textures, 1);
	assert_true(in.alpha_triangles > 0);
	ajar_scene_destroy(&s);

	s = load_asset("EmissiveStrengthTest", &in);
	assert_true(in.emissive_triangles > 0);
	ajar_scene_destroy(&s);
}

/* Tangents generated for NormalTangentMirrorTest (its TANGENT left out of
 * a copy of the file) match the ones it stores: per triangle corner the
 * same handedness and, in the normal's plane, nearly the same direction.
 * The copy and the files it reads go to the test's folder. */
static void test_generated_tangents(void **state)
{
	(void)state;
	static const char *const files[] = {"NormalTangentMirrorTest.bin", "NormalTangentTest_Normal.png",
					    "NormalTangentMirrorTest_BaseColor.png",
					    "NormalTangentMirrorTest_OcclusionRoughnessMetallic.png"};
	char src[PATH_MAX], *dir = realpath(SCENE("khronos/NormalTangentMirrorTest"), NULL);
	assert_non_null(dir);
	static char data[1 << 22];
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		snprintf(src, sizeof src, "%s/%s", dir, files[i]);
		FILE *in = fopen(src, "rb");
		assert_non_null(in);
		size_t got = fread(data, 1, sizeof data, in);
		assert_true(got < sizeof data && !ferror(in));
		fclose(in);
		write_bytes(files[i], data, got);
	}
	snprintf(src, sizeof src, "%s/NormalTangentMirrorTest.gltf", dir);
	free(dir);
	FILE *f = fopen(src, "rb");
	assert_non_null(f);
	static char text[1 << 16];
	size_t n = fread(text, 1, sizeof text - 1, f);
	fclose(f);
	text[n] = 0;
	char *t = strstr(text, "\"TANGENT\" : 3, ");
	assert_non_null(t);
	memmove(t, t + strlen("\"TANGENT\" : 3, "), strlen(t + strlen("\"TANGENT\" : 3, ")) + 1);
	write_text("notangent.gltf", text);
	ajar_scene *stored = NULL;
	assert_int_equal(ajar_scene_load(SCENE("khronos/NormalTangentMirrorTest/NormalTangentMirrorTest.gltf"), &stored),
			 AJAR_OK);
	Scene *gen = load_ok("notangent.gltf");
	assert_int_equal(gen->ntris, stored->ntris);
	double worst = 1.0;
	for (uint32_t i = 0; i < gen->ntris; i++) {
		assert_true(gen->tris[i].flags & TRI_TANGENT);
		assert_true(stored->tris[i].flags & TRI_TANGENT);
		const float *g[3] = {gen->extra[i].t0, gen->extra[i].t1, gen->extra[i].t2};
		const float *s[3] = {stored->extra[i].t0, stored->extra[i].t1, stored->extra[i].t2};
		V3 nv[3] = {gen->shade[i].n0, gen->shade[i].n1, gen->shade[i].n2};
		for (int k = 0; k < 3; k++) {
			assert_float_equal(g[k][3], s[k][3], 0.0f);
			V3 a = v3(g[k][0], g[k][1], g[k][2]), b = v3(s[k][0], s[k][1], s[k][2]);
			a = v3_norm(v3_madd(a, nv[k], -v3_dot(a, nv[k])));
			b = v3_norm(v3_madd(b, nv[k], -v3_dot(b, nv[k])));
			worst = fmin(worst, v3_dot(a, b));
		}
	}
	printf("  generated vs stored tangents: worst cosine %.5f\n", worst);
	assert_true(worst > 0.99);
	ajar_scene_destroy(&gen);
	ajar_scene_destroy(&stored);
}

/* A normal map of constant tilt on a quad in z = 0 (u along +x, v along
 * +y, tangent +x with w = -1 as generated for such UVs) turns the shading
 * normal as the tilted plane's: the texel (r, g, b) read linearly as
 * (2r - 1, 2g - 1, 2b - 1), x and y scaled, along (t, w (n x t), n),
 * and the BSDF is built on it: it shades like that plane (f and the
 * densities equal a tilted plane's). */
static void test_normal_map(void **state)
{
	(void)state;
	Scene *s;
	assert_int_equal(scene_new("<test>", &s), AJAR_OK);
	uint8_t texel[4] = {200, 100, 220, 255};
	uint32_t img;
	assert_int_equal(scene_add_texture(s, 1, 1, texel, &img), AJAR_OK);
	Material m;
	memset(&m, 0, sizeof m);
	m.base_color = v3(1, 1, 1);
	m.base_tex = -1;
	m.roughness = 1.0f;
	m.ior = 1.5f;
	m.normal_tex = (int)img + 1;
	m.normal_scale = 0.5f;
	uint32_t mid;
	assert_int_equal(scene_add_material(s, &m, &mid), AJAR_OK);
	float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	float uv[] = {0, 0, 1, 0, 1, 1, 0, 1}, tan[] = {1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles_ex(s, "quad", pos, nrm, uv, NULL, NULL, tan, 4, idx, 2, mid), AJAR_OK);
	assert_true(s->tris[0].flags & TRI_TANGENT);
	SceneView sc = scene_surface_view(s);
	float x = (2.0f * 200 / 255 - 1) * 0.5f, y = (2.0f * 100 / 255 - 1) * 0.5f, z = 2.0f * 220 / 255 - 1;
	/* b = w (n x t) = -(z x x) = -y */
	V3 want = v3_norm(v3(x, -y, z));
	for (int tri = 0; tri < 2; tri++) {
		Hit h = {1.0f, 0.3f, 0.2f, tri};
		Surface sf;
		surface_from_hit(&sc, &h, &sf);
		assert_v3(sf.ns, want.x, want.y, want.z);
		Bsdf bs;
		surface_bsdf(&sc, &sf, v3(0.5f, 0.5f, 0.5f), &bs);
		assert_v3(bs.n, want.x, want.y, want.z);
		/* It shades as that plane: f |wi . n| and the densities of the
		 * normal-mapped quad equal those of a plane whose geometric normal
		 * is `want`, for directions above both surfaces whose mirror
		 * images stay above the quad (no bend, bsdf.h). */
		Bsdf plane;
		bsdf_setup(&plane, &sc.materials[sf.material], v3(0.5f, 0.5f, 0.5f), want, want);
		const V3 wos[] = {v3_norm(v3(0.1f, 0.2f, 1)), v3_norm(v3(0.6f, -0.3f, 1)), v3_norm(v3(-0.3f, 0.5f, 1))};
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++) {
				V3 wi = v3_norm(v3(wos[b].y, -wos[b].x, wos[b].z));
				float p1, r1, p2, r2;
				V3 f1 = bsdf_eval(&bs, wos[a], wi, BSDF_RADIANCE, &p1, &r1);
				V3 f2 = bsdf_eval(&plane, wos[a], wi, BSDF_RADIANCE, &p2, &r2);
				assert_true(f2.x > 0);
				assert_float_equal(f1.x, f2.x, 1e-5f * f2.x);
				assert_float_equal(p1, p2, 1e-5f * p2);
				assert_float_equal(r1, r2, 1e-5f * r2);
			}
	}
	scene_free(s);
}

static void test_broken_files(void **state)
{
	/* Truncated JSON. */
	FILE *f = fopen(SCENE("cornell/cornell.gltf"), "rb");
	assert_non_null(f);
	char head[3000];
	assert_int_equal(fread(head, 1, sizeof head, f), sizeof head);
	fclose(f);
	write_bytes("trunc.gltf", head, sizeof head);
	load_fails("trunc.gltf", AJAR_ERROR_BAD_INPUT, "parse error");

	/* A buffer file that is not there. */
	write_text("nobin.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("missing.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("nobin.gltf", AJAR_ERROR_BAD_INPUT, "missing.bin");

	/* Index 7 with 3 vertices. */
	uint8_t bin[80];
	const uint16_t idx017[3] = {0, 1, 7};
	write_bytes("badidx.bin", bin, tri_bin(bin, idx017, 1.0f));
	write_text("badidx.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("badidx.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("badidx.gltf", AJAR_ERROR_BAD_INPUT, "meshes[0].primitives[0]: index 7 (at 2) out of range (3 vertices)");

	/* POSITION claims 4 vertices (48 bytes) of a 36-byte view. */
	write_tri_bin();
	write_text("pastend.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("tri.bin") "," TRI_ACCESSORS(4) "}");
	load_fails("pastend.gltf", AJAR_ERROR_BAD_INPUT,
		   "meshes[0].primitives[0]: accessors[0] (POSITION): needs 48 bytes at offset 0 but bufferViews[0] has 36");

	/* A buffer view past the end of its buffer. */
	write_text("viewpast.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":78}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":60,\"byteLength\":36},"
		   "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
		   TRI_ACCESSORS(3) "}");
	load_fails("viewpast.gltf", AJAR_ERROR_BAD_INPUT, "bufferViews[0]: needs 36 bytes at offset 60 but buffers[0] has 78");

	/* A NaN position. */
	write_bytes("nan.bin", bin, tri_bin(bin, idx012, NAN));
	write_text("nan.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("nan.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("nan.gltf", AJAR_ERROR_BAD_INPUT, "meshes[0].primitives[0]: vertex 1: position is not finite");

	/* Nothing to render: a portal alone. */
	write_tri_gltf("onlyportal.gltf", "0", "{\"mesh\":0,\"extras\":{\"portal\":true}}", "");
	load_fails("onlyportal.gltf", AJAR_ERROR_BAD_INPUT, "scenes[0]: no triangles to render (portals do not count)");

	/* A node that is its own grandchild. */
	write_tri_gltf("cycle.gltf", "0", "{\"mesh\":0,\"children\":[1]},{\"children\":[0]}", "");
	load_fails("cycle.gltf", AJAR_ERROR_BAD_INPUT, "nodes[0]: reached twice");

	/* An extension we cannot honour. */
	write_text("draco.gltf", "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
		   "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}");
	load_fails("draco.gltf", AJAR_ERROR_BAD_INPUT, "extensionsRequired: KHR_draco_mesh_compression");

	/* A missing file is an I/O error. */
	load_fails("nonexistent.gltf", AJAR_ERROR_IO, "cannot open");
}

/* ---- KHR_lights_punctual ------------------------------------------------ */

/* The one-triangle scene with `nodes` after the mesh node (nodes[0]) and
 * root lights `lights`, the extension required. */
static void write_lights_gltf(const char *name, const char *scene_nodes, const char *nodes, const char *lights)
{
	write_tri_bin();
	char json[4096];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
		 "\"extensionsRequired\":[\"KHR_lights_punctual\"],"
		 "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}},"
		 "\"scene\":0,\"scenes\":[{\"nodes\":[0,%s]}],\"nodes\":[{\"mesh\":0},%s]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}",
		 lights, scene_nodes, nodes);
	write_text(name, json);
}

#define LIGHT_NODE(i) "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":" #i "}}"

static void test_lights_punctual(void **state)
{
	/* nodes[1]: the directional light turned -90 degrees about X (-Z to
	 * -Y); nodes[2]: the point light at (1, 2, 3); nodes[3] (scaled, child
	 * of nodes[4] at (0, 1, 0)): the spot, pointing down -Z. */
	write_lights_gltf("lights.gltf", "1,2,4",
			  LIGHT_NODE(0) ",\"rotation\":[-0.70710678,0,0,0.70710678]}," LIGHT_NODE(
				  1) ",\"translation\":[1,2,3]}," LIGHT_NODE(2) ",\"scale\":[2,2,2]},"
				     "{\"translation\":[0,1,0],\"children\":[3]}",
			  "{\"type\":\"directional\",\"color\":[1,0.5,0.25],\"intensity\":3},"
			  "{\"type\":\"point\",\"range\":5},"
			  "{\"type\":\"spot\",\"intensity\":683,\"spot\":{\"innerConeAngle\":0.1,\"outerConeAngle\":0.3}}");
	Scene *s = load_ok("lights.gltf");
	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(s, &in), AJAR_OK);
	assert_int_equal(in.lights, 3);
	ajar_light l;
	assert_int_equal(ajar_scene_light_get(s, 0, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_DIRECTIONAL);
	assert_float_equal(l.direction[0], 0.0f, 1e-6f);
	assert_float_equal(l.direction[1], -1.0f, 1e-6f);
	assert_float_equal(l.direction[2], 0.0f, 1e-6f);
	assert_float_equal(l.color[1], 0.5f, 0.0f);
	assert_float_equal(l.intensity, 3.0f, 0.0f);
	assert_int_equal(ajar_scene_light_get(s, 1, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_POINT);
	assert_float_equal(l.position[0], 1.0f, 0.0f);
	assert_float_equal(l.position[1], 2.0f, 0.0f);
	assert_float_equal(l.position[2], 3.0f, 0.0f);
	assert_float_equal(l.color[0], 1.0f, 0.0f); /* the spec's defaults */
	assert_float_equal(l.intensity, 1.0f, 0.0f);
	assert_float_equal(l.range, 5.0f, 0.0f);
	/* The scene walks the root nodes in order: the spot (child of
	 * nodes[4]) comes last. */
	assert_int_equal(ajar_scene_light_get(s, 2, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_SPOT);
	assert_float_equal(l.position[1], 1.0f, 0.0f);
	assert_float_equal(l.direction[2], -1.0f, 1e-6f); /* scale leaves it unit */
	assert_float_equal(l.inner_cone, 0.1f, 1e-7f);
	assert_float_equal(l.outer_cone, 0.3f, 1e-7f);
	assert_float_equal(l.range, 0.0f, 0.0f); /* infinite */
	assert_int_equal(ajar_scene_light_get(s, 3, &l), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);

	/* A spot without blend, as Blender exports it: inner = outer. */
	write_lights_gltf("hard.gltf", "1", LIGHT_NODE(0) "}",
			  "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.5,\"outerConeAngle\":0.5}}");
	s = load_ok("hard.gltf");
	ajar_scene_destroy(&s);

	write_lights_gltf("nolight.gltf", "1", LIGHT_NODE(7) "}", "{\"type\":\"point\"}");
	load_fails("nolight.gltf", AJAR_ERROR_BAD_INPUT, "nodes[1]: KHR_lights_punctual light 7 does not exist (1 lights)");
	write_lights_gltf("area.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"area\"}");
	load_fails("area.gltf", AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[0]: unknown type 'area'");
	write_lights_gltf("colour.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"color\":[1,1]}");
	load_fails("colour.gltf", AJAR_ERROR_BAD_INPUT, "color has 2 numbers, expected 3");
	write_lights_gltf("negative.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"intensity\":-1}");
	load_fails("negative.gltf", AJAR_ERROR_BAD_INPUT, "nodes[1]: KHR_lights_punctual.lights[0]: intensity -1");
	write_lights_gltf("range.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"range\":-2}");
	load_fails("range.gltf", AJAR_ERROR_BAD_INPUT, "range -2 must be finite and > 0");
	write_lights_gltf("cone.gltf", "1", LIGHT_NODE(0) "}",
			  "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.6,\"outerConeAngle\":0.5}}");
	load_fails("cone.gltf", AJAR_ERROR_BAD_INPUT, "spot cone angles 0.6, 0.5");
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

static int setup(void **state)
{
	(void)state;
	return test_tmpdir_setup(&tmpdir);
}

static int teardown(void **state)
{
	(void)state;
	return test_tmpdir_teardown(&tmpdir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cornell),
		cmocka_unit_test(test_window_room),
		cmocka_unit_test(test_living_room),
		cmocka_unit_test(test_sky_scenes),
		cmocka_unit_test(test_bathroom),
		cmocka_unit_test(test_api_scene),
		cmocka_unit_test(test_hierarchy_trs),
		cmocka_unit_test(test_hierarchy_matrix),
		cmocka_unit_test(test_no_scenes_all_roots),
		cmocka_unit_test(test_non_indexed_and_materials),
		cmocka_unit_test(test_unread_extension_members),
		cmocka_unit_test(test_volume_and_transmission),
		cmocka_unit_test(test_interleaved_strip_fan),
		cmocka_unit_test(test_sparse),
		cmocka_unit_test(test_data_uri),
		cmocka_unit_test(test_glb),
		cmocka_unit_test(test_portals_and_environment),
		cmocka_unit_test(test_environment_image),
		cmocka_unit_test(test_environment_pixels),
		cmocka_unit_test(test_environment_rotation),
		cmocka_unit_test(test_environment_hdr),
		cmocka_unit_test(test_texture_coordinates),
		cmocka_unit_test(test_khronos_assets),
		cmocka_unit_test(test_generated_tangents),
		cmocka_unit_test(test_normal_map),
		cmocka_unit_test(test_broken_files),
		cmocka_unit_test(test_lights_punctual),
		cmocka_unit_test(test_api_lights),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
