/* test_confine.c — scene files stay in their folder: a buffer, image or
 * environment image that resolves (after "..", an absolute path or a
 * symbolic link) outside the scene file's folder is refused with a message
 * naming the URI, and read when ajar_load_options.allow_outside_files is
 * set; names that stay inside (a subfolder, "sub/../x", a link that points
 * inside) load either way.
 *
 * Layout in a fresh temporary directory T:
 *   T/outside.bin, T/outside.png, T/sky.exr     files outside the scene folder
 *   T/scene/tri.bin, T/scene/sub/inner.bin      inside
 *   T/scene/link-out.bin -> ../outside.bin, T/scene/link-in.bin -> tri.bin */
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ajar.h"

static char *scene_dir; /* test_dir/scene */

static void write_bytes(const char *path, const void *data, size_t n)
{
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
}

/* One triangle, (0,0,0) (1,0,0) (0,1,0), u16 indices: 42 bytes. */
static void write_tri(const char *path)
{
	uint8_t b[42];
	const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	const uint16_t idx[3] = {0, 1, 2};
	memcpy(b, pos, 36);
	memcpy(b + 36, idx, 6);
	write_bytes(path, b, sizeof b);
}

/* scene/<name>.gltf: the triangle from buffer `uri`, plus `more` at the top
 * level (images) and `extras` on the scene (environment). */
static char *write_scene(const char *name, const char *uri, const char *more, const char *extras)
{
	char json[4096];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]%s}],"
		 "\"nodes\":[{\"mesh\":0}],\"buffers\":[{\"uri\":\"%s\",\"byteLength\":42}],"
		 "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
		 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
		 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
		 "\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":3,"
		 "\"type\":\"SCALAR\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
		 "\"indices\":1}]}]%s}",
		 extras ? extras : "", uri, more ? more : "");
	char file[64];
	snprintf(file, sizeof file, "%s.gltf", name);
	char *path = test_path(scene_dir, file);
	write_bytes(path, json, strlen(json));
	return path;
}

static ajar_status load(const char *path, int allow)
{
	ajar_load_options o;
	ajar_load_options_default(&o);
	o.allow_outside_files = allow;
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load_with(path, &o, &s);
	assert_true((st == AJAR_OK) == (s != NULL));
	ajar_scene_destroy(&s);
	return st;
}

/* Refused by default with a message naming the scene file, the URI and the
 * option; loads with allow_outside_files. */
static void refused_then_allowed(const char *path, const char *uri)
{
	ajar_status st = load(path, 0);
	const char *msg = ajar_last_error();
	char quoted[512];
	snprintf(quoted, sizeof quoted, "'%s'", uri);
	if (st != AJAR_ERROR_BAD_INPUT || !strstr(msg, path) || !strstr(msg, quoted) ||
	    !strstr(msg, "outside the scene's folder") || !strstr(msg, "--allow-outside-files"))
		fail_msg("%s: got %s \"%s\"", path, ajar_status_name(st), msg);
	/* ajar_scene_load is the confined default too. */
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_load(path, &s), AJAR_ERROR_BAD_INPUT);
	assert_null(s);
	st = load(path, 1);
	if (st != AJAR_OK)
		fail_msg("%s with allow_outside_files: %s", path, ajar_last_error());
}

static void inside_loads(const char *path)
{
	if (load(path, 0) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
}

static void test_buffer_dotdot(void **state)
{
	(void)state;
	char *p = write_scene("dotdot", "../outside.bin", NULL, NULL);
	refused_then_allowed(p, "../outside.bin");
	free(p);
	/* Through a subfolder and back out: still outside. */
	p = write_scene("subdotdot", "sub/../../outside.bin", NULL, NULL);
	refused_then_allowed(p, "sub/../../outside.bin");
	free(p);
}

static void test_buffer_absolute(void **state)
{
	(void)state;
	char *abs = test_tmp("outside.bin");
	char *p = write_scene("absolute", abs, NULL, NULL);
	refused_then_allowed(p, abs);
	free(p);
	free(abs);
}

static void test_buffer_symlink_out(void **state)
{
	(void)state;
	char *p = write_scene("linkout", "link-out.bin", NULL, NULL);
	refused_then_allowed(p, "link-out.bin");
	free(p);
}

static void test_inside(void **state)
{
	(void)state;
	const char *uris[] = {"tri.bin", "sub/inner.bin", "sub/../tri.bin", "./sub/inner.bin", "link-in.bin"};
	for (size_t i = 0; i < sizeof uris / sizeof uris[0]; i++) {
		char name[16];
		snprintf(name, sizeof name, "in%zu", i);
		char *p = write_scene(name, uris[i], NULL, NULL);
		inside_loads(p);
		free(p);
	}
	/* The inside rule does not hide a plain missing file. */
	char *p = write_scene("missing", "nothere.bin", NULL, NULL);
	assert_int_equal(load(p, 0), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), "nothere.bin"));
	assert_null(strstr(ajar_last_error(), "outside the scene's folder"));
	free(p);
}

static void test_image(void **state)
{
	(void)state;
	/* The image need not be used by a material: tinygltf reads every image. */
	char *p = write_scene("image", "tri.bin", ",\"images\":[{\"uri\":\"../outside.png\"}]", NULL);
	refused_then_allowed(p, "../outside.png");
	free(p);
	/* The server's file the issue names: refused before it is read at all. */
	p = write_scene("passwd", "tri.bin", ",\"images\":[{\"uri\":\"../../../../../../../../etc/passwd\"}]", NULL);
	assert_int_equal(load(p, 0), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), "resolves to /etc/passwd, outside the scene's folder"));
	free(p);
}

static void test_environment_image(void **state)
{
	(void)state;
	char *p = write_scene("envout", "tri.bin", NULL, ",\"extras\":{\"environment\":{\"image\":\"../sky.exr\"}}");
	refused_then_allowed(p, "../sky.exr");
	free(p);
	char *abs = test_tmp("sky.exr");
	char extras[512];
	snprintf(extras, sizeof extras, ",\"extras\":{\"environment\":{\"image\":\"%s\"}}", abs);
	p = write_scene("envabs", "tri.bin", NULL, extras);
	refused_then_allowed(p, abs);
	free(p);
	free(abs);
	p = write_scene("envin", "tri.bin", NULL, ",\"extras\":{\"environment\":{\"image\":\"sub/sky.exr\"}}");
	inside_loads(p);
	free(p);
}

static int setup(void **state)
{
	if (test_group_setup(state))
		return -1;
	scene_dir = test_tmp("scene");
	char *sub = test_path(scene_dir, "sub");
	if (mkdir(scene_dir, 0755) || mkdir(sub, 0755))
		return -1;
	char *f;
	write_tri(f = test_tmp("outside.bin"));
	free(f);
	write_tri(f = test_path(scene_dir, "tri.bin"));
	free(f);
	write_tri(f = test_path(sub, "inner.bin"));
	free(f);
	const float px[4 * 4] = {1, 1, 1, 1, 0.5f, 0.5f, 0.5f, 1, 0.25f, 0.25f, 0.25f, 1, 1, 0, 0, 1};
	if (ajar_write_png(f = test_tmp("outside.png"), px, 2, 2) != AJAR_OK)
		return -1;
	free(f);
	if (ajar_write_exr(f = test_tmp("sky.exr"), px, 2, 2, NULL, 0) != AJAR_OK)
		return -1;
	free(f);
	if (ajar_write_exr(f = test_path(sub, "sky.exr"), px, 2, 2, NULL, 0) != AJAR_OK)
		return -1;
	free(f);
	char *l = test_path(scene_dir, "link-out.bin");
	char *l2 = test_path(scene_dir, "link-in.bin");
	int bad = symlink("../outside.bin", l) || symlink("tri.bin", l2);
	free(l);
	free(l2);
	free(sub);
	return bad ? -1 : 0;
}

static int teardown(void **state)
{
	free(scene_dir);
	return test_group_teardown(state);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_buffer_dotdot),
		cmocka_unit_test(test_buffer_absolute),
		cmocka_unit_test(test_buffer_symlink_out),
		cmocka_unit_test(test_inside),
		cmocka_unit_test(test_image),
		cmocka_unit_test(test_environment_image),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
