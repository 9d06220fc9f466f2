/* test_limits.c — the limits a render keeps, stated in include/ajar.h and
 * enforced before anything overflows or is allocated:
 *
 * - image size: at most AJAR_MAX_SIDE a side, and memory for the films
 *   found missing before the device touches them: under an address-space
 *   limit PoCL aborted the process (exit 134) when a film it allocates on
 *   first use did not fit.
 *
 * About 8 s on the 2-core machine, most of it the capped render. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ajar.h"
#include "testutil.h"

#define CORNELL SCENE("cornell/cornell.gltf")

/* A triangle far behind the camera and a sky of radiance `sky`: every
 * camera ray sees the sky. */
static ajar_scene *sky_scene(float sky)
{
	ajar_scene *s = NULL;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material m;
	ajar_material_default(&m);
	uint32_t mat;
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	const float pos[9] = {0, 0, 5, 1, 0, 5, 0, 1, 5};
	const uint32_t idx[3] = {0, 1, 2};
	ajar_mesh mesh = {pos, NULL, NULL, 3, idx, 1, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	ajar_camera c = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.5f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &c), AJAR_OK);
	const float rgb[3] = {sky, sky, sky};
	assert_int_equal(ajar_scene_set_environment_color(s, rgb), AJAR_OK);
	return s;
}

static ajar_options tiny(uint32_t spp)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = 1;
	o.spp = spp;
	return o;
}

/* Current virtual memory of this process, in bytes. */
static size_t vm_bytes(void)
{
	FILE *f = fopen("/proc/self/statm", "r");
	unsigned long pages = 0;
	if (f) {
		if (fscanf(f, "%lu", &pages) != 1)
			pages = 0;
		fclose(f);
	}
	return pages * (size_t)sysconf(_SC_PAGESIZE);
}

/* The child of test_memory_before_device (this binary run again: a fork
 * of a process whose PoCL threads run would wait for them forever): under
 * an address-space limit with room for `room` times F, renderer_create of
 * a 4096 x 4096 image, whose films take F = 805 MB on the host and F on
 * the device. Exit 0 if that is out of memory. */
#define MEM_SIDE 4096
static int memory_child(double room)
{
	ajar_scene *s = NULL;
	if (ajar_scene_load(CORNELL, &s) != AJAR_OK)
		return 3;
	/* PoCL and the program loaded first, at a tiny size. */
	ajar_options o = tiny(1);
	ajar_renderer *r = NULL;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		return 3;
	ajar_renderer_destroy(&r);
	struct rlimit lim;
	lim.rlim_cur = lim.rlim_max = (rlim_t)((double)vm_bytes() + room * 48.0 * MEM_SIDE * MEM_SIDE);
	if (setrlimit(RLIMIT_AS, &lim) != 0)
		return 4;
	o.width = o.height = MEM_SIDE;
	ajar_status st = ajar_renderer_create(s, &o, &r);
	fprintf(stderr, "  room %.2f F: %s\n", room, st == AJAR_OK ? "created" : ajar_last_error());
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	return st == AJAR_OK ? 1 : st == AJAR_ERROR_OUT_OF_MEMORY ? 0 : 2;
}

static char self[4096];

/* Room for 0.75 F: the device's film does not fit (PoCL asserted
 * `p->mem_ptr != NULL` and aborted, exit 134); 1.5 F: the host's films fit,
 * the device's do not. Either is out of memory (the CLI's exit 6), never a
 * crash. */
static void test_memory_before_device(void **state)
{
	const char *room[2] = {"0.75", "1.5"};
	for (int k = 0; k < 2; k++) {
		pid_t pid = fork();
		assert_true(pid >= 0);
		if (pid == 0) {
			execl(self, self, "--memory-child", room[k], (char *)NULL);
			_exit(127);
		}
		int status;
		assert_int_equal(waitpid(pid, &status, 0), pid);
		if (!WIFEXITED(status))
			fail_msg("room %s F: killed by signal %d", room[k], WTERMSIG(status));
		assert_int_equal(WEXITSTATUS(status), 0);
	}
}

/* Sizes beyond AJAR_MAX_SIDE: refused from the options (invalid argument)
 * and from a scene's suggested resolution (bad input naming the file). */
static void test_size_limit(void **state)
{
	ajar_scene *s = sky_scene(1.0f);
	ajar_options o = tiny(1);
	o.width = AJAR_MAX_SIDE + 1;
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);
	char *path = test_tmp("big.gltf");
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fprintf(f, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0],\"extras\":{\"resolution\":[%u,"
		   "8]}}],\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
		   "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
		   "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}",
		AJAR_MAX_SIDE + 1);
	fclose(f);
	assert_int_equal(ajar_scene_load(path, &s), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), path));
	assert_non_null(strstr(ajar_last_error(), "resolution"));
	unlink(path);
	free(path);
}

int main(int argc, char **argv)
{
	if (argc == 3 && !strcmp(argv[1], "--memory-child"))
		return memory_child(atof(argv[2]));
	ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
	if (n <= 0)
		return 1;
	self[n] = '\0';
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_memory_before_device),
		cmocka_unit_test(test_size_limit),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
