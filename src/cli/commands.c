/* commands.c — the `ajar` command: `render`, `devices`, `info`, help and
 * version, on top of the public API (include/ajar.h) and nothing else.
 *
 * Rules it keeps: no file is created before a render has succeeded (the
 * library writes images atomically, so a failed or bad-input run leaves
 * nothing behind); SIGINT/SIGTERM stop a render after the current pass and
 * the samples so far are still written, a second signal kills as usual;
 * every failure ends with one `ajar: error: ...` line and a documented exit
 * code (see usage_main). */
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "cli/portals_gltf.h"
#include "cli/progress.h"

/* Under mpirun (ajar_mpi_init): "ajar: " on rank 0, "ajar: rank N (host): "
 * elsewhere, so a message from another machine says where it came from. */
static char g_prefix[128] = "ajar: ";

/* More OpenCL devices than any machine we know of has. */
#define MAX_DEVICES 256

static const char usage_main[] =
	"usage: ajar <command> [options]\n"
	"\n"
	"Ajar renders glTF 2.0 scenes with unbiased path tracing, bidirectional path\n"
	"tracing, or portal-based BDPT for scenes lit through openings, on OpenCL devices.\n"
	"\n"
	"commands:\n"
	"  render SCENE -o OUT.exr [options]  render a .gltf/.glb scene to OpenEXR (see 'ajar render --help')\n"
	"  info SCENE [options]               what the scene holds: triangles, lights, portals (marked\n"
	"                                     and found), camera (see 'ajar info --help')\n"
	"  devices                            list OpenCL devices and how to select one\n"
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

static const char usage_render[] =
	"usage: ajar render SCENE.gltf|SCENE.glb -o OUT.exr [options]\n"
	"\n"
	"  -o, --output OUT.exr   linear HDR result (float RGBA, ZIP); the header records\n"
	"                         the samples per pixel done as \"ajar:spp\"\n"
	"  --spp N                samples per pixel (default 64 unless --time or --noise\n"
	"                         is given)\n"
	"  --time SECONDS         render until this time has passed (with --spp: whichever\n"
	"                         comes first)\n"
	"  --noise PCT            render until the image's estimated relative error is\n"
	"                         below PCT percent (--spp and --time bound it); the\n"
	"                         estimate, from two halves of the samples, shows in\n"
	"                         the progress\n"
	"  --size WxH             image size (default: the scene's suggestion, else 512 wide)\n"
	"  --integrator NAME      pt (default): path tracing; bdpt: bidirectional path\n"
	"                         tracing; portal: bdpt plus intermediate subpaths\n"
	"                         through the scene's portals\n"
	"  --max-depth N          maximum path segments, camera segment included\n"
	"                         (default 64 for pt, 32 for bdpt and portal, their limit)\n"
	"  --min-depth N          leave out paths of fewer segments\n"
	"  --mis NAME             bdpt, portal: auto (default: balance if a sky image's\n"
	"                         sun through portals is the only light, else power),\n"
	"                         power or balance heuristic\n"
	"  --strategies OUT.exr   bdpt, portal: also write one RGB layer per strategy of\n"
	"                         paths of up to --strategy-len N segments (default 4):\n"
	"                         len<n>.s<s>t<t>.R/G/B for bdpt's (s, t), and for\n"
	"                         portal len<n>.portal.s<s>t<t>.* for its intermediate\n"
	"                         strategies by light and eye vertices; weighted, they\n"
	"                         sum to the image of paths of up to N segments\n"
	"  --unweighted           the strategy layers without MIS weights\n"
	"  --seed N               random seed (same seed, device and options: same image)\n"
	"  --aov LIST             add channels a denoiser takes to the EXR, any of\n"
	"                         albedo (albedo.R/G/B), normal (normal.X/Y/Z), depth\n"
	"                         (depth.Z) and variance (variance.R/G/B), comma-separated;\n"
	"                         albedo and normal of the first non-specular hit\n"
	"                         (through mirrors and glass), depth of the first hit\n"
	"  --checkpoint FILE      keep the render resumable: write its state to FILE every\n"
	"                         --checkpoint-every SECONDS (default 60), when a device\n"
	"                         fails and when the render stops (also on Ctrl-C)\n"
	"  --resume FILE          continue the render FILE holds (with its options; only\n"
	"                         --spp, --time, --noise and --device may change); the\n"
	"                         result equals an uninterrupted render bit for bit. FILE\n"
	"                         is updated as the render goes on unless --checkpoint\n"
	"                         names another\n"
	"  --portals WHICH        the portals to sample through: marked (the scene's),\n"
	"                         auto (found over the openings from the camera, the\n"
	"                         marked ones ignored) or none; default: the marked\n"
	"                         ones if the scene marks any, else found ones\n"
	"  --portals-out FILE.gltf  write the found portals as translucent red quads\n"
	"                         (extras \"portal\": true) to view over the scene\n"
	"  --sky FILE.exr|.hdr    an equirectangular sky in place of the scene's\n"
	"                         environment (+Y up, the centre looking down -Z)\n"
	"  --sky-color R,G,B      a constant sky (radiance) in its place\n"
	"  --sky-strength S       scale --sky or --sky-color (default 1)\n"
	"  --sky-rotation DEG     turn the sky about +Y, counter-clockwise from above\n"
	"  --sun ELEV,AZIM,LUX    add a sun: elevation and azimuth in degrees (azimuth\n"
	"                         from -Z toward +X, as a sky image's), illuminance\n"
	"                         in lux (clear noon about 100000)\n"
	"  --allow-outside-files  let the scene read files outside its folder (by default\n"
	"                         every URI and the environment image must resolve, after\n"
	"                         '..' and symbolic links, inside the scene file's folder)\n"
	"  --device SELECTOR      platform:device index (e.g. 0:1), cpu, gpu, a part of the\n"
	"                         device name, a comma-separated list of these, or all:\n"
	"                         several devices render at once; see 'ajar devices'\n"
	"  --png OUT.png          also write a tone-mapped 8-bit sRGB preview\n"
	"  --exposure EV          brighten (EV > 0) or darken the preview by 2^EV (default 0)\n"
	"  -q, --quiet            print nothing but errors\n"
	"  -h, --help             this text\n"
	"\n"
	"Ctrl-C (SIGINT) or SIGTERM stops after the current pass and writes the image so\n"
	"far (exit code 5), and the checkpoint with --checkpoint; a second one ends the\n"
	"program at once.\n"
	"\n"
	"Under mpirun (Open MPI), every rank renders the same image on its own devices\n"
	"(--device applies per rank); rank 0 deals the samples, prints the progress and\n"
	"alone writes the files; the image is the same bits as one process.\n";

static const char usage_info[] =
	"usage: ajar info SCENE.gltf|SCENE.glb [options]\n"
	"\n"
	"Prints what the scene holds: triangles, materials, lights, marked portals,\n"
	"the portals a render finds over its openings where it marks none, the\n"
	"environment, bounds and camera.\n"
	"\n"
	"  --portals WHICH          auto: search the openings even where portals are\n"
	"                           marked; marked or none: no search\n"
	"  --portals-out FILE.gltf  write the found portals as a glTF file\n"
	"  --sky, --sky-color, --sky-strength, --sky-rotation, --sun\n"
	"                           as for 'ajar render' (the search looks for light\n"
	"                           from them)\n"
	"  --allow-outside-files    let the scene read files outside its folder\n"
	"  -h, --help               this text\n";

/* ---- Errors ---------------------------------------------------------------- */

static int exit_code(ajar_status st)
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
static void report(ajar_status st, const char *file)
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
static int load_scene(const char *path, int allow_outside_files, ajar_scene **scene)
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
static int check_output(const char *opt, const char *path)
{
	struct stat sb;
	if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) {
		fprintf(stderr, "ajar: error: %s %s: is a directory\n", opt, path);
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
static int apply_scene_args(ajar_scene *scene, const SceneArgs *sc)
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

static void print_found(const ajar_portal *p, uint32_t n)
{
	for (uint32_t i = 0; i < n && i < FOUND_MAX; i++)
		printf("  [%u] centre (%.3f, %.3f, %.3f), %.3f x %.3f, normal (%.3f, %.3f, %.3f), share %.1f%%\n", i,
		       p[i].center[0], p[i].center[1], p[i].center[2], p[i].width, p[i].height, p[i].normal[0],
		       p[i].normal[1], p[i].normal[2], 100.0 * p[i].share);
}

/* ---- Signals --------------------------------------------------------------- */

static ajar_renderer *_Atomic g_renderer;
static volatile sig_atomic_t g_interrupted;

static void on_signal(int sig)
{
	g_interrupted = 1;
	/* The next SIGINT/SIGTERM takes the default action (ends the process). */
	struct sigaction dfl;
	memset(&dfl, 0, sizeof dfl);
	dfl.sa_handler = SIG_DFL;
	sigemptyset(&dfl.sa_mask);
	sigaction(SIGINT, &dfl, NULL);
	sigaction(SIGTERM, &dfl, NULL);
	/* The library documents ajar_renderer_cancel as signal-safe. */
	ajar_renderer *r = atomic_load(&g_renderer);
	if (r)
		ajar_renderer_cancel(r);
}

static void install_signals(void)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sa.sa_flags = SA_RESTART;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
}

/* ---- render ---------------------------------------------------------------- */

static void on_log(ajar_log_level level, const char *message, void *user)
{
	Progress *progress = user;
	/* Errors come back through statuses and are printed once, by report(). */
	if (level != AJAR_LOG_WARNING || progress->quiet)
		return;
	progress_break_line(progress);
	fprintf(stderr, "%swarning: %s\n", g_prefix, message);
}

static void on_start_log(ajar_log_level level, const char *message, void *user)
{
	(void)user;
	if (level == AJAR_LOG_WARNING)
		fprintf(stderr, "ajar: warning: %s\n", message);
}

static int on_progress(const ajar_progress *p, void *user)
{
	progress_update(user, p);
	/* Also stops a render when the signal came before the renderer was
	 * registered with the handler. */
	return g_interrupted;
}

static int interrupted_early(void)
{
	fprintf(stderr, "ajar: interrupted before rendering started; no image written\n");
	return EXIT_INTERRUPTED;
}

/* The PNG preview at 2^exposure: the image scaled before tone mapping. */
static ajar_status write_png(ajar_renderer *r, const char *path, double exposure)
{
	uint32_t w, h;
	ajar_status st = ajar_renderer_image(r, NULL, &w, &h);
	if (st != AJAR_OK)
		return st;
	float *rgba = malloc(sizeof(float) * 4 * (size_t)w * h);
	if (!rgba)
		return AJAR_ERROR_OUT_OF_MEMORY;
	if ((st = ajar_renderer_image(r, rgba, &w, &h)) == AJAR_OK) {
		float k = (float)pow(2.0, exposure);
		for (size_t i = 0; i < 4 * (size_t)w * h; i++)
			if (i % 4 != 3)
				rgba[i] *= k;
		st = ajar_write_png(path, rgba, w, h);
	}
	free(rgba);
	return st;
}

static int write_outputs(ajar_renderer *r, const RenderArgs *a)
{
	ajar_status st = ajar_renderer_write_exr(r, a->exr);
	if (st != AJAR_OK) {
		report(st, a->exr);
		return exit_code(st) == EXIT_BAD_INPUT ? EXIT_IO : exit_code(st);
	}
	if (a->strategies) {
		st = ajar_renderer_write_strategies(r, a->strategies);
		if (st != AJAR_OK) {
			report(st, a->strategies);
			return exit_code(st) == EXIT_BAD_INPUT ? EXIT_IO : exit_code(st);
		}
	}
	if (a->png) {
		st = write_png(r, a->png, a->exposure);
		if (st != AJAR_OK) {
			report(st, a->png);
			return exit_code(st) == EXIT_BAD_INPUT ? EXIT_IO : exit_code(st);
		}
	}
	return EXIT_OK;
}

static const char *mis_name(ajar_mis m)
{
	return m == AJAR_MIS_BALANCE ? "balance" : m == AJAR_MIS_AUTO ? "auto" : "power";
}

/* --resume: the options come from the checkpoint; an option given on the
 * command line must agree with it, except --spp, --time and --device,
 * which extend the budget or move the render. */
static int resume_options(RenderArgs *a)
{
	ajar_options ck;
	ajar_status st = ajar_checkpoint_options(a->resume, &ck, NULL);
	if (st != AJAR_OK) {
		report(st, a->resume);
		return st == AJAR_ERROR_IO ? EXIT_BAD_INPUT : exit_code(st);
	}
	const ajar_options *o = &a->opt;
	char mine[64] = "", theirs[64] = "";
	const char *opt = NULL;
#define CONFLICT(bit, name, cond, fmt, mv, cv)                               \
	if (!opt && (a->given & (bit)) && (cond)) {                          \
		opt = name;                                                  \
		snprintf(mine, sizeof mine, fmt, mv);                        \
		snprintf(theirs, sizeof theirs, fmt, cv);                    \
	}
	if ((a->given & GIVEN_SIZE) && (o->width != ck.width || o->height != ck.height)) {
		opt = "--size";
		snprintf(mine, sizeof mine, "%ux%u", o->width, o->height);
		snprintf(theirs, sizeof theirs, "%ux%u", ck.width, ck.height);
	}
	CONFLICT(GIVEN_INTEGRATOR, "--integrator", o->integrator != ck.integrator, "%s",
		 args_integrator_name(o->integrator), args_integrator_name(ck.integrator));
	CONFLICT(GIVEN_MAX_DEPTH, "--max-depth", o->max_depth != ck.max_depth, "%u", o->max_depth, ck.max_depth);
	CONFLICT(GIVEN_MIN_DEPTH, "--min-depth", o->min_depth != ck.min_depth, "%u", o->min_depth, ck.min_depth);
	CONFLICT(GIVEN_SEED, "--seed", o->seed != ck.seed, "%u", o->seed, ck.seed);
	CONFLICT(GIVEN_MIS, "--mis", o->mis != ck.mis, "%s", mis_name(o->mis), mis_name(ck.mis));
	CONFLICT(GIVEN_AOV, "--aov", o->aov != ck.aov, "(0x%x)", o->aov, ck.aov);
	CONFLICT(GIVEN_PORTALS, "--portals", o->portals != ck.portals, "%s", args_portals_name(o->portals),
		 args_portals_name(ck.portals));
	CONFLICT(GIVEN_STRATEGY_LEN, "--strategy-len", o->strategy_len != ck.strategy_len, "%u", o->strategy_len,
		 ck.strategy_len);
#undef CONFLICT
	if (!opt && (a->given & GIVEN_UNWEIGHTED) && !ck.strategy_unweighted)
		return args_usage_error("--unweighted: the checkpoint %s keeps weighted strategy layers", a->resume);
	if (opt)
		return args_usage_error("%s %s: the checkpoint %s was rendered with %s %s; a resumed render keeps "
					"its options (only --spp, --time and --device may change)",
					opt, mine, a->resume, opt, theirs);
	if (a->strategies && ck.strategy_len == 0)
		return args_usage_error("--strategies: the checkpoint %s keeps no strategy layers", a->resume);
	const char *device = o->device;
	uint32_t spp = o->spp;
	double time_limit = o->time_limit, noise = o->noise;
	a->opt = ck;
	a->opt.device = device;
	if (a->given & GIVEN_NOISE)
		a->opt.noise = noise;
	if (a->given & GIVEN_SPP)
		a->opt.spp = spp;
	if (a->given & GIVEN_TIME)
		a->opt.time_limit = time_limit;
	return EXIT_OK;
}

/* The last checkpoint of a render that has samples; 0 or EXIT_IO. */
static int final_checkpoint(ajar_renderer *r, const RenderArgs *a, const char *path)
{
	ajar_status st = ajar_renderer_write_checkpoint(r, path);
	if (st != AJAR_OK) {
		report(st, path);
		return EXIT_IO;
	}
	if (!a->quiet)
		fprintf(stderr, "ajar: checkpoint %s holds %u spp\n", path, ajar_renderer_spp(r));
	return EXIT_OK;
}

/* One line per device when several rendered: who did which share. */
static void print_device_shares(const ajar_renderer *r)
{
	uint32_t n = ajar_renderer_device_count(r);
	for (uint32_t i = 0; n > 1 && i < n; i++) {
		ajar_device_stats ds;
		if (ajar_renderer_device_stats(r, i, &ds) == AJAR_OK)
			fprintf(stderr, "ajar:   %s (%s): %.1f%% of the samples, %.3g Msamples/s%s\n", ds.name,
				ds.selector, 100.0 * ds.share, ds.samples_per_second * 1e-6,
				ds.failed ? ", dropped after a failure" : "");
	}
}

/* A render that found its portals says how many and how long the search
 * took, and writes them with --portals-out. */
static int found_portals(ajar_renderer *r, const RenderArgs *a)
{
	ajar_portal found[FOUND_MAX];
	uint32_t n = 0;
	double seconds = 0.0;
	if (ajar_renderer_found_portals(r, found, FOUND_MAX, &n, &seconds) != AJAR_OK)
		return EXIT_OK;
	if (n > FOUND_MAX)
		n = FOUND_MAX;
	if (!a->quiet && (n || seconds > 0.0))
		fprintf(stderr, "ajar: found %u portal%s over openings in %.2f s%s\n", n, n == 1 ? "" : "s", seconds,
			n ? " ('ajar info' lists them)" : "");
	return a->sc.portals_out ? portals_write_gltf(a->sc.portals_out, found, n) : EXIT_OK;
}

/* Under mpirun every rank runs this with the same arguments: rank 0 checks
 * the outputs, reads a checkpoint, prints and writes; every rank loads the
 * scene and renders on its own devices (ajar.h, "Several machines"); a
 * failure on any rank before the render is agreed on (ajar_mpi_agree), so
 * every rank stops with the same exit code. */
static int cmd_render(int argc, char **argv)
{
	RenderArgs a;
	int rank = ajar_mpi_rank(), size = ajar_mpi_size();
	if (size > 1 && rank > 0)
		snprintf(g_prefix, sizeof g_prefix, "ajar: rank %d: ", rank);
	/* Rank 0 alone prints usage errors and help (every rank parses the same). */
	int saved[2] = {-1, -1};
	if (rank > 0) {
		fflush(NULL);
		int null = open("/dev/null", O_WRONLY);
		for (int f = 0; f < 2 && null >= 0; f++)
			if ((saved[f] = dup(f + 1)) >= 0)
				dup2(null, f + 1);
		if (null >= 0)
			close(null);
	}
	int rc = args_parse_render(argc, argv, &a);
	if (rank > 0) {
		fflush(NULL);
		for (int f = 0; f < 2; f++)
			if (saved[f] >= 0) {
				dup2(saved[f], f + 1);
				close(saved[f]);
			}
	}
	if (rc != EXIT_OK)
		return rc;
	if (a.help) {
		if (rank == 0)
			fputs(usage_render, stdout);
		return EXIT_OK;
	}
	const char *ckpt = a.checkpoint ? a.checkpoint : a.resume;
	if (rank > 0)
		ckpt = NULL; /* rank 0 writes the checkpoints, and reads the one resumed */
	if (rank == 0) {
		if ((rc = check_output("-o", a.exr)) == EXIT_OK && a.png)
			rc = check_output("--png", a.png);
		if (rc == EXIT_OK && a.strategies)
			rc = check_output("--strategies", a.strategies);
		if (rc == EXIT_OK && a.sc.portals_out)
			rc = check_output("--portals-out", a.sc.portals_out);
		if (rc == EXIT_OK && ckpt)
			rc = check_output(a.checkpoint ? "--checkpoint" : "--resume", ckpt);
		if (rc == EXIT_OK && a.resume)
			rc = resume_options(&a);
	}
	if (size == 1 && rc != EXIT_OK)
		return rc;

	Progress progress;
	progress_init(&progress, stderr, a.quiet, a.opt.noise > 0.0);
	ajar_set_log_callback(on_log, &progress);
	install_signals();

	ajar_scene *scene = NULL;
	ajar_renderer *r = NULL;
	if (rc == EXIT_OK)
		rc = load_scene(a.scene, a.allow_outside_files, &scene);
	if (rc == EXIT_OK)
		rc = apply_scene_args(scene, &a.sc);
	if (rc == EXIT_OK && g_interrupted)
		rc = interrupted_early();
	if (size > 1)
		rc = ajar_mpi_agree(rc);
	if (rc != EXIT_OK)
		goto done;
	ajar_status st = a.resume ? ajar_renderer_resume(scene, a.resume, &a.opt, &r)
				  : ajar_renderer_create(scene, &a.opt, &r);
	if (st == AJAR_OK && ckpt)
		st = ajar_renderer_set_checkpoint(r, ckpt, a.checkpoint_every);
	if (st != AJAR_OK) {
		if (rank == 0) /* its message names the rank that failed */
			report(st, NULL);
		rc = exit_code(st);
		goto done;
	}
	atomic_store(&g_renderer, r);
	if (g_interrupted) {
		if (size == 1) {
			rc = interrupted_early();
			goto done;
		}
		ajar_renderer_cancel(r); /* the other ranks wait for rank 0's render: end it at once */
	}
	if (rank > 0) {
		/* Renders what rank 0 deals until it ends the job. */
		st = ajar_renderer_render(r, NULL, NULL);
		rc = exit_code(st);
		goto done;
	}
	if (!a.quiet) {
		char budget[64] = "";
		if (a.opt.spp)
			snprintf(budget, sizeof budget, "%u spp", a.opt.spp);
		if (a.opt.time_limit > 0)
			snprintf(budget + strlen(budget), sizeof budget - strlen(budget), "%s%g s",
				 a.opt.spp ? ", at most " : "", a.opt.time_limit);
		if (a.opt.noise > 0)
			snprintf(budget + strlen(budget), sizeof budget - strlen(budget), "%suntil noise %g%%",
				 budget[0] ? ", " : "", 100.0 * a.opt.noise);
		const char *device = ajar_renderer_device_name(r);
		char from[64] = "";
		if (a.resume)
			snprintf(from, sizeof from, " from %u spp", ajar_renderer_spp(r));
		char ranks[32] = "";
		if (size > 1)
			snprintf(ranks, sizeof ranks, "%d ranks: ", size);
		fprintf(stderr, "ajar: %s %s with %s (%s%s) on %s%s\n", a.resume ? "resuming" : "rendering", a.scene,
			args_integrator_name(a.opt.integrator), budget, from, ranks, device ? device : "?");
	}
	if ((rc = found_portals(r, &a)) != EXIT_OK)
		goto done;

	st = ajar_renderer_render(r, on_progress, &progress);
	progress_break_line(&progress);
	uint32_t spp = ajar_renderer_spp(r);
	if (st != AJAR_OK && st != AJAR_ERROR_CANCELLED) {
		/* A device failure keeps what the others rendered. */
		if (ckpt && spp > 0 && st == AJAR_ERROR_DEVICE) {
			char *msg = strdup(ajar_last_error());
			/* Under mpirun a rank lost leaves films that cannot be summed:
			 * then the checkpoint written during the render stays. */
			if (size == 1)
				final_checkpoint(r, &a, ckpt);
			else if (ajar_renderer_write_checkpoint(r, ckpt) == AJAR_OK && !a.quiet)
				fprintf(stderr, "ajar: checkpoint %s holds %u spp\n", ckpt, spp);
			if (msg)
				fprintf(stderr, "ajar: error: %s\n", msg);
			free(msg);
		} else {
			report(st, NULL);
		}
		rc = exit_code(st);
		goto done;
	}
	if (spp == 0) {
		rc = interrupted_early();
		goto done;
	}
	if ((rc = write_outputs(r, &a)) != EXIT_OK)
		goto done;
	if (ckpt && (rc = final_checkpoint(r, &a, ckpt)) != EXIT_OK)
		goto done;
	const ajar_progress *last = &progress.last;
	char elapsed[24];
	progress_format_time(last->elapsed, elapsed, sizeof elapsed);
	if (st == AJAR_ERROR_CANCELLED || g_interrupted) {
		fprintf(stderr, "ajar: interrupted after %u spp (%s); wrote %s%s%s%s%s\n", spp, elapsed, a.exr,
			a.png ? " and " : "", a.png ? a.png : "", ckpt ? "; continue with --resume " : "",
			ckpt ? ckpt : "");
		rc = EXIT_INTERRUPTED;
	} else if (!a.quiet) {
		char noise[64] = "";
		if (a.opt.noise > 0 && ajar_renderer_noise(r) >= 0)
			snprintf(noise, sizeof noise, ", estimated error %.2g%%", 100.0 * ajar_renderer_noise(r));
		fprintf(stderr, "ajar: done: %u spp in %s (%.3g Msamples/s%s); wrote %s%s%s\n", spp, elapsed,
			last->samples_per_second * 1e-6, noise, a.exr, a.png ? " and " : "", a.png ? a.png : "");
		print_device_shares(r);
	}
done:
	atomic_store(&g_renderer, NULL);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&scene);
	ajar_set_log_callback(NULL, NULL);
	return rc;
}

/* ---- devices --------------------------------------------------------------- */

static void format_bytes(uint64_t b, char *buf, size_t cap)
{
	if (b >= (1ull << 30))
		snprintf(buf, cap, "%.1f GiB", (double)b / (double)(1ull << 30));
	else
		snprintf(buf, cap, "%.0f MiB", (double)b / (double)(1ull << 20));
}

static int cmd_devices(int argc, char **argv)
{
	if (argc > 0)
		return args_usage_error("devices: unexpected argument '%s'", argv[0]);
	ajar_device_info *dev = calloc(MAX_DEVICES, sizeof *dev);
	if (!dev) {
		fprintf(stderr, "ajar: error: out of memory\n");
		return EXIT_NO_MEMORY;
	}
	uint32_t n = 0;
	ajar_status st = ajar_devices(dev, MAX_DEVICES, &n);
	if (st != AJAR_OK) {
		report(st, NULL);
		free(dev);
		return exit_code(st);
	}
	if (n == 0) {
		fprintf(stderr, "ajar: error: no OpenCL device found; install an OpenCL driver "
				"(for the CPU: PoCL, Debian package pocl-opencl-icd)\n");
		free(dev);
		return EXIT_DEVICE;
	}
	if (n > MAX_DEVICES)
		n = MAX_DEVICES;
	printf("%-8s %-6s %-40s %s\n", "SELECTOR", "TYPE", "NAME", "COMPUTE UNITS, MEMORY, PLATFORM");
	for (uint32_t i = 0; i < n; i++) {
		char mem[32];
		format_bytes(dev[i].global_memory, mem, sizeof mem);
		printf("%-8s %-6s %-40s %u CU, %s, %s\n", dev[i].selector, dev[i].type, dev[i].name,
		       dev[i].compute_units, mem, dev[i].platform);
	}
	printf("\nSelect one with --device %s (platform:device), --device cpu, --device gpu,\n"
	       "or --device NAME where NAME is any part of a device's name; several at once\n"
	       "with a comma-separated list of these, or --device all.\n",
	       dev[0].selector);
	free(dev);
	return EXIT_OK;
}

/* ---- info ------------------------------------------------------------------ */

static int cmd_info(int argc, char **argv)
{
	InfoArgs ia;
	int rc = args_parse_info(argc, argv, &ia);
	if (rc != EXIT_OK)
		return rc;
	if (ia.help) {
		fputs(usage_info, stdout);
		return EXIT_OK;
	}
	if (ia.sc.portals_out && (rc = check_output("--portals-out", ia.sc.portals_out)) != EXIT_OK)
		return rc;
	ajar_scene *scene = NULL;
	rc = load_scene(ia.scene, ia.allow_outside_files, &scene);
	if (rc == EXIT_OK)
		rc = apply_scene_args(scene, &ia.sc);
	if (rc != EXIT_OK) {
		ajar_scene_destroy(&scene);
		return rc;
	}
	ajar_scene_info in;
	ajar_status st = ajar_scene_info_get(scene, &in);
	if (st != AJAR_OK) {
		report(st, ia.scene);
		ajar_scene_destroy(&scene);
		return exit_code(st);
	}
	static const char *const env[] = {"none", "colour", "image"};
	printf("scene:        %s\n", ia.scene);
	printf("triangles:    %llu\n", (unsigned long long)in.triangles);
	printf("materials:    %u\n", in.materials);
	printf("emissive:     %u triangles\n", in.emissive_triangles);
	printf("portals:      %u objects, %u triangles (marked)\n", in.portals, in.portal_triangles);
	/* The portals a render would find: where none is marked, or asked for. */
	ajar_portal found[FOUND_MAX];
	uint32_t nfound = 0;
	double seconds = 0.0;
	int search = (in.portal_triangles == 0 && ia.sc.portals == AJAR_PORTALS_DEFAULT) || ia.search ||
		     ia.sc.portals_out;
	if (search && ia.sc.portals != AJAR_PORTALS_NONE && ia.sc.portals != AJAR_PORTALS_MARKED) {
		st = ajar_scene_find_portals(scene, found, FOUND_MAX, &nfound, &seconds);
		if (st != AJAR_OK) {
			report(st, ia.scene);
			ajar_scene_destroy(&scene);
			return exit_code(st);
		}
		printf("found:        %u portal%s over openings (search %.2f s)%s\n", nfound, nfound == 1 ? "" : "s",
		       seconds, in.portal_triangles && !ia.search ? "; a render uses the marked ones" : "");
		print_found(found, nfound);
	} else if (in.portal_triangles) {
		printf("found:        not searched (the scene marks portals; --portals auto searches)\n");
	}
	printf("lights:       %u (KHR_lights_punctual)\n", in.lights);
	for (uint32_t i = 0; i < in.lights; i++) {
		ajar_light l;
		if (ajar_scene_light_get(scene, i, &l) != AJAR_OK)
			break;
		static const char *const kind[] = {"directional", "point", "spot"};
		printf("  [%u] %-11s", i, kind[l.type]);
		if (l.type != AJAR_LIGHT_DIRECTIONAL)
			printf(" at (%g, %g, %g)", l.position[0], l.position[1], l.position[2]);
		if (l.type != AJAR_LIGHT_POINT)
			printf(" toward (%.3f, %.3f, %.3f)", l.direction[0], l.direction[1], l.direction[2]);
		printf(", colour (%g, %g, %g), %g %s", l.color[0], l.color[1], l.color[2], l.intensity,
		       l.type == AJAR_LIGHT_DIRECTIONAL ? "lx" : "cd");
		if (l.type == AJAR_LIGHT_SPOT)
			printf(", cone %.1f..%.1f deg", l.inner_cone * 180.0 / M_PI, l.outer_cone * 180.0 / M_PI);
		if (l.type != AJAR_LIGHT_DIRECTIONAL && l.range > 0.0f)
			printf(", range %g", l.range);
		printf("\n");
	}
	printf("textures:     %u (%u base colour, %u metallic-roughness, %u emissive, %u normal; %.1f MiB)\n",
	       in.textures, in.base_color_textures, in.metallic_roughness_textures, in.emissive_textures,
	       in.normal_textures,
	       (double)in.texture_bytes / (1024.0 * 1024.0));
	printf("alpha-tested: %llu triangles\n", (unsigned long long)in.alpha_triangles);
	printf("environment:  %s\n", in.environment >= 0 && in.environment <= 2 ? env[in.environment] : "?");
	printf("bounds:       (%g, %g, %g) .. (%g, %g, %g)\n", in.bounds_min[0], in.bounds_min[1],
	       in.bounds_min[2], in.bounds_max[0], in.bounds_max[1], in.bounds_max[2]);
	const ajar_camera *c = &in.camera;
	float d[3] = {c->target[0] - c->position[0], c->target[1] - c->position[1], c->target[2] - c->position[2]};
	float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	if (len > 0)
		for (int k = 0; k < 3; k++)
			d[k] /= len;
	printf("camera:       %sposition (%g, %g, %g), direction (%.3f, %.3f, %.3f), yfov %.1f deg\n",
	       in.has_camera ? "" : "none in the file; default view framing the bounds: ", c->position[0],
	       c->position[1], c->position[2], d[0], d[1], d[2], c->yfov * 180.0 / M_PI);
	if (in.width && in.height)
		printf("resolution:   %ux%u (suggested by the scene)\n", in.width, in.height);
	else
		printf("resolution:   none suggested (renders 512 wide at the camera's aspect)\n");
	ajar_scene_destroy(&scene);
	if (ia.sc.portals_out)
		return portals_write_gltf(ia.sc.portals_out, found, nfound > FOUND_MAX ? FOUND_MAX : nfound);
	return EXIT_OK;
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
