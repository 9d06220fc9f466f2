/* commands.c — the `ajar` command: the dispatch to `render`, `devices` and
 * `info` (cmd_render.c, cmd_devices.c, cmd_info.c), help and version;
 * on top of the public API (include/ajar.h) and nothing else; what the
 * commands share is in cli_common.c.
 *
 * Rules it keeps: no file is created before a render has succeeded (the
 * library writes images atomically, so a failed or bad-input run leaves
 * nothing behind); SIGINT/SIGTERM stop a render after the current pass and
 * the samples so far are still written, a second signal kills as usual;
 * every failure ends with one `ajar: error: ...` line and a documented exit
 * code (see usage_main). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "cli/commands_shared.h"

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
