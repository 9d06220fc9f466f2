/* cli_common.c — what the commands share (commands_shared.h): the message
 * prefix, exit codes from statuses, error reports, loading a scene,
 * checking an output, the command line's sky and sun, the found portals'
 * lines. */
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
#include "cli/commands_shared.h"

/* Under mpirun (ajar_mpi_init): "ajar: " on rank 0, "ajar: rank N (host): "
 * elsewhere, so a message from another machine says where it came from. */
char g_prefix[128] = "ajar: ";

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

void print_found(const ajar_portal *p, uint32_t n)
{
	for (uint32_t i = 0; i < n && i < FOUND_MAX; i++)
		printf("  [%u] centre (%.3f, %.3f, %.3f), %.3f x %.3f, normal (%.3f, %.3f, %.3f), share %.1f%%\n", i,
		       p[i].center[0], p[i].center[1], p[i].center[2], p[i].width, p[i].height, p[i].normal[0],
		       p[i].normal[1], p[i].normal[2], 100.0 * p[i].share);
}
