/* args.h — the command line of `ajar`, parsed by hand into plain structs.
 * Parse errors print `ajar: error: <message naming the option>` and make
 * the caller exit with EXIT_USAGE. */
#ifndef AJAR_CLI_ARGS_H
#define AJAR_CLI_ARGS_H
#include <stdint.h>

#include "ajar.h"

/* Exit codes of `ajar`, listed in `ajar --help`. */
enum {
	EXIT_OK = 0,
	EXIT_USAGE = 1,
	EXIT_BAD_INPUT = 2,
	EXIT_DEVICE = 3,
	EXIT_IO = 4,
	EXIT_INTERRUPTED = 5,
	EXIT_NO_MEMORY = 6
};

/* What the command line changes in a scene before it renders or is
 * described: the sky and a sun (exporters write none), and which portals
 * (--portals; in RenderArgs.opt for a render). */
typedef struct {
	const char *sky;          /* --sky FILE.exr|.hdr, or NULL */
	int sky_color_given;      /* --sky-color R,G,B */
	float sky_color[3];
	int sky_strength_given;   /* --sky-strength S */
	float sky_strength;
	int sky_rotation_given;   /* --sky-rotation DEG */
	float sky_rotation;
	int sun_given;            /* --sun ELEVATION,AZIMUTH,LUX */
	float sun[3];
	ajar_portals portals;     /* --portals */
	const char *portals_out;  /* --portals-out FILE.gltf, or NULL */
} SceneArgs;

typedef struct {
	const char *scene;
	const char *exr;   /* -o */
	const char *png;   /* --png, or NULL */
	const char *strategies; /* --strategies, or NULL */
	double exposure;   /* --exposure, EV for the PNG preview */
	ajar_options opt;  /* spp, time_limit, size, integrator, depth, seed, device */
	int quiet;
	int help;          /* --help was given: print render help, nothing else */
	int allow_outside_files; /* --allow-outside-files */
	const char *checkpoint;  /* --checkpoint FILE, or NULL */
	double checkpoint_every; /* --checkpoint-every SECONDS (default 60) */
	const char *resume;      /* --resume FILE, or NULL */
	unsigned given;          /* GIVEN_* bits: options set on the command line */
	SceneArgs sc;            /* --sky, --sun, --portals, --portals-out (portals also in opt) */
} RenderArgs;

/* `ajar info`'s arguments. */
typedef struct {
	const char *scene;
	int allow_outside_files;
	int help;
	int search;              /* --portals auto: search even where portals are marked */
	SceneArgs sc;
} InfoArgs;

/* Options a resumed render takes from its checkpoint (RenderArgs.given). */
enum {
	GIVEN_SIZE = 1 << 0,
	GIVEN_INTEGRATOR = 1 << 1,
	GIVEN_MAX_DEPTH = 1 << 2,
	GIVEN_MIN_DEPTH = 1 << 3,
	GIVEN_SEED = 1 << 4,
	GIVEN_MIS = 1 << 5,
	GIVEN_STRATEGY_LEN = 1 << 6,
	GIVEN_UNWEIGHTED = 1 << 7,
	GIVEN_SPP = 1 << 8,
	GIVEN_TIME = 1 << 9,
	GIVEN_AOV = 1 << 10,
	GIVEN_PORTALS = 1 << 11,
	GIVEN_NOISE = 1 << 12
};

/* Parses the arguments after `render`. Returns EXIT_OK or EXIT_USAGE
 * (after printing the error). */
int args_parse_render(int argc, char **argv, RenderArgs *a);

/* Parses the arguments after `info`. Returns EXIT_OK or EXIT_USAGE. */
int args_parse_info(int argc, char **argv, InfoArgs *a);

/* --portals' names: marked, auto, none (and default). */
const char *args_portals_name(ajar_portals p);

/* Prints a usage error (printf-style) and returns EXIT_USAGE. */
int args_usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

const char *args_integrator_name(ajar_integrator i);
#endif
