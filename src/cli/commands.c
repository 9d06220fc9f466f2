/* commands.c — the `ajar` command: the dispatch to `render`, `devices` and
 * `info` (cmd_render.c, cmd_devices.c, cmd_info.c), help and version, and
 * what the commands share (commands_shared.h); on top of the public API
 * (include/ajar.h) and nothing else.
 *
 * Rules it keeps: no file is created before a render has succeeded (the
 * library writes images atomically, so a failed or bad-input run leaves
 * nothing behind); SIGINT/SIGTERM stop a render after the current pass and
 * the samples so far are still written, a second signal kills as usual;
 * every failure ends with one `ajar: error: ...` line and a documented exit
 * code (see usage_main). */
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "cli/commands_shared.h"

/* Under mpirun (ajar_mpi_init): "ajar: " on rank 0, "ajar: rank N (host): "
 * elsewhere, so a message from another machine says where it came from. */
char g_prefix[128] = "ajar: ";

static const char usage_main[] =
	"usage: ajar <command> [options]\n"
	"\n"
	"Ajar renders glTF 2.0 scenes with unbiased path tracing, bidirectional path\n"
	"tracing, or portal-based BDPT for scenes lit through openings, on OpenCL devices.\n"
	"\n"
	"commands:\n"
	"  render SCENE -o OUT.exr [options]  render a .gltf/.glb scene to OpenEXR (see 'ajar render --help')\n"
	"  info SCENE [options]               what the scene holds: triangles, instances, lights, portals\n"
	"                                     (marked and found), camera, memory of geometry, BVH and\n"
	"                                     textures (see 'ajar info --help')\n"	"  devices                            list OpenCL devices and how to select one\n"
	"  help [render]                      this text, or the render options\n"
	"  --version                          print the version\n"
	"\n"
	"exit codes:\n"
	"  0  success\n"
	"  1  usage error (unknown command or option, missing or bad value)\n"
	"  2  bad input: the scene or an image it uses is missing or malformed\n"
	"  3  device error: no OpenCL device, kernel build or run failure\n"
	"  4  I/O error: cannot write the output\n"
	"  5  interrupted (SIGINT/SIGTERM): the image of the samples done so far is\n"
	"     written, unless the render had not started\n"
	"  6  out of memory\n";

/* ---- Errors ---------------------------------------------------------------- */

int exit_code(ajar_status st)
{
	switch (st) {
	case AJAR_OK: return EXIT_OK;
	case AJAR_ERROR_INVALID_ARGUMENT: return EXIT_USAGE;
	case AJAR_ERROR_BAD_INPUT: return EXIT_BAD_INPUT;
	case AJAR_ERROR_IO: return EXIT_IO;
	case AJAR_ERROR_DEVICE: return EXIT_DEVICE;
	case AJAR_ERROR_OUT_OF_MEMORY: return EXIT_NO_MEMORY;
	case AJAR_ERROR_CANCELLED: return EXIT_INTERRUPTED;
	}
	return EXIT_DEVICE;
}

/* Prints the library's message for a failure about `file` (prefixing the
 * file name when the message does not already name it). */
void report(ajar_status st, const char *file)
{
	const char *msg = ajar_last_error();
	if (!msg[0])
		msg = ajar_status_name(st);
	if (file && !strstr(msg, file))
		fprintf(stderr, "%serror: %s: %s\n", g_prefix, file, msg);
	else
		fprintf(stderr, "%serror: %s\n", g_prefix, msg);
}

/* Loads a scene; a scene that cannot be read is bad input (exit 2) even
 * when the library calls it an I/O error: exit 4 is for outputs. */
int load_scene(const char *path, int allow_outside_files, ajar_scene **scene)
{
	ajar_load_options lo;
	ajar_load_options_default(&lo);
	lo.allow_outside_files = allow_outside_files;
	ajar_status st = ajar_scene_load_with(path, &lo, scene);
	if (st == AJAR_OK)
		return EXIT_OK;
	report(st, path);
	return st == AJAR_ERROR_IO ? EXIT_BAD_INPUT : exit_code(st);
}

/* Before spending minutes on a render: can `path` be created? Checks the
 * directory only, and creates nothing. */
int check_output(const char *opt, const char *path)
{
	struct stat sb;
	/* The library renames a new file onto the name: only a regular file
	 * may be replaced, never a device (as root, -o /dev/full replaced
	 * the device node), a FIFO or a symbolic link. */
	if (lstat(path, &sb) == 0 && !S_ISREG(sb.st_mode)) {
		const char *what = S_ISDIR(sb.st_mode)			? "is a directory"
				   : S_ISLNK(sb.st_mode)		? "is a symbolic link (name its target)"
				   : S_ISFIFO(sb.st_mode)		? "is a FIFO"
				   : S_ISCHR(sb.st_mode) || S_ISBLK(sb.st_mode) ? "is a device"
									: "is not a regular file";
		fprintf(stderr, "ajar: error: %s %s: %s; outputs are written to a new file and renamed onto their name\n",
			opt, path, what);
		return EXIT_IO;
	}
	char *copy = strdup(path);
	if (!copy) {
		fprintf(stderr, "ajar: error: out of memory\n");
		return EXIT_NO_MEMORY;
	}
	const char *dir = dirname(copy);
	int rc = EXIT_OK;
	if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
		fprintf(stderr, "ajar: error: %s %s: directory '%s' does not exist\n", opt, path, dir);
		rc = EXIT_IO;
	} else if (access(dir, W_OK | X_OK) != 0) {
		fprintf(stderr, "ajar: error: %s %s: cannot write to directory '%s': %s\n", opt, path, dir,
			strerror(errno));
		rc = EXIT_IO;
	}
	free(copy);
	return rc;
}

/* ---- Scene options ---------------------------------------------------------- */

/* The command line's sky and sun (SceneArgs) into the loaded scene. A
 * file named there is the user's choice: not confined to the scene's
 * folder. */
int apply_scene_args(ajar_scene *scene, const SceneArgs *sc)
{
	ajar_status st = AJAR_OK;
	float k = sc->sky_strength_given ? sc->sky_strength : 1.0f;
	if (sc->sky) {
		st = ajar_scene_set_environment_image(scene, sc->sky, k);
		if (st != AJAR_OK) {
			report(st, sc->sky);
			return st == AJAR_ERROR_IO ? EXIT_BAD_INPUT : exit_code(st);
		}
	} else if (sc->sky_color_given) {
		float c[3] = {k * sc->sky_color[0], k * sc->sky_color[1], k * sc->sky_color[2]};
		st = ajar_scene_set_environment_color(scene, c);
	}
	if (st == AJAR_OK && sc->sky_rotation_given)
		st = ajar_scene_set_environment_rotation(scene, sc->sky_rotation);
	if (st == AJAR_OK && sc->sun_given) {
		/* Toward the sun: elevation above the horizon, azimuth from -Z
		 * toward +X (as a sky image's, README "Environment"); the light
		 * travels the other way. */
		double e = sc->sun[0] * M_PI / 180.0, az = sc->sun[1] * M_PI / 180.0;
		ajar_light l;
		ajar_light_default(&l);
		l.type = AJAR_LIGHT_DIRECTIONAL;
		l.direction[0] = (float)(-cos(e) * sin(az));
		l.direction[1] = (float)-sin(e);
		l.direction[2] = (float)(cos(e) * cos(az));
		l.intensity = sc->sun[2];
		st = ajar_scene_add_light(scene, &l);
	}
	if (st != AJAR_OK) {
		report(st, NULL);
		return EXIT_BAD_INPUT;
	}
	return EXIT_OK;
}

/* The portals found, up to FOUND_MAX of them. */
#define FOUND_MAX 64

void print_found(const ajar_portal *p, uint32_t n)
{
	for (uint32_t i = 0; i < n && i < FOUND_MAX; i++)
		printf("  [%u] centre (%.3f, %.3f, %.3f), %.3f x %.3f, normal (%.3f, %.3f, %.3f), share %.1f%%\n", i,
		       p[i].center[0], p[i].center[1], p[i].center[2], p[i].width, p[i].height, p[i].normal[0],
		       p[i].normal[1], p[i].normal[2], 100.0 * p[i].share);
}

static void on_start_log(ajar_log_level level, const char *message, void *user)
{
	(void)user;
	if (level == AJAR_LOG_WARNING)
		fprintf(stderr, "ajar: warning: %s\n", message);
}

/* ---- main ------------------------------------------------------------------ */

int cli_main(int argc, char **argv)
{
	if (argc < 2) {
		fputs(usage_main, stderr);
		return EXIT_USAGE;
	}
	const char *cmd = argv[1];
	if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
		if (argc > 2 && !strcmp(cmd, "help") && !strcmp(argv[2], "render"))
			fputs(usage_render, stdout);
		else
			fputs(usage_main, stdout);
		return EXIT_OK;
	}
	if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
		printf("ajar %s\n", ajar_version());
		return EXIT_OK;
	}
	if (!strcmp(cmd, "render")) {
		/* Started by mpirun: one rank of a job (else nothing happens).
		 * Its warnings (a build without Open MPI under mpirun) come
		 * before the render's own log callback is set. */
		ajar_set_log_callback(on_start_log, NULL);
		ajar_status st = ajar_mpi_init(&argc, &argv);
		ajar_set_log_callback(NULL, NULL);
		if (st != AJAR_OK) {
			fprintf(stderr, "ajar: error: %s\n", ajar_last_error());
			return EXIT_DEVICE;
		}
		int rc = cmd_render(argc - 2, argv + 2);
		ajar_mpi_finalize();
		return rc;
	}
	if (!strcmp(cmd, "devices"))
		return cmd_devices(argc - 2, argv + 2);
	if (!strcmp(cmd, "info"))
		return cmd_info(argc - 2, argv + 2);
	if (cmd[0] == '-')
		fprintf(stderr, "ajar: error: unknown option '%s' (see 'ajar --help')\n", cmd);
	else
		fprintf(stderr, "ajar: error: unknown command '%s' (see 'ajar --help')\n", cmd);
	return EXIT_USAGE;
}
