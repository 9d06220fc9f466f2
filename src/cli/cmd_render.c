/* cmd_render.c — `ajar render`: its usage, the outputs checked before a
 * render (writable, each a file of its own), the signals that stop it after
 * the current pass, the render under mpirun, the files it writes. */
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands_shared.h"
#include "cli/portals_gltf.h"
#include "cli/progress.h"

const char usage_render[] =
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

/* Whether two names are one file: the same inode where both exist, else
 * the same name once their folders are resolved. */
static int same_file(const char *a, const char *b)
{
	struct stat sa, sb;
	int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0;
	if (ea && eb)
		return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
	if (ea != eb)
		return 0;
	char *ca = strdup(a), *cb = strdup(b), *da = strdup(a), *db = strdup(b);
	char ra[PATH_MAX], rb[PATH_MAX];
	int same = ca && cb && da && db && realpath(dirname(da), ra) && realpath(dirname(db), rb) && !strcmp(ra, rb) &&
		   !strcmp(basename(ca), basename(cb));
	free(ca);
	free(cb);
	free(da);
	free(db);
	return same;
}

/* No output may be the scene, the checkpoint resumed (unless it is the one
 * kept up to date) or another output: -o naming the scene overwrote it. */
static int check_outputs_distinct(const RenderArgs *a)
{
	const struct {
		const char *opt, *path;
	} out[] = {{"-o", a->exr},
		   {"--png", a->png},
		   {"--strategies", a->strategies},
		   {"--portals-out", a->sc.portals_out},
		   {"--checkpoint", a->checkpoint}};
	enum { N = sizeof out / sizeof out[0] };
	for (int i = 0; i < N; i++) {
		if (!out[i].path)
			continue;
		const char *clash = same_file(out[i].path, a->scene) ? "the scene"
				    : i < 4 && a->resume && same_file(out[i].path, a->resume) ? "--resume"
												 : NULL;
		for (int j = 0; !clash && j < i; j++)
			if (out[j].path && same_file(out[i].path, out[j].path))
				clash = out[j].opt;
		if (clash)
			return args_usage_error("%s %s: is also %s; every output needs a file of its own", out[i].opt,
						out[i].path, clash);
	}
	return EXIT_OK;
}

/* ---- Signals --------------------------------------------------------------- */

static ajar_renderer *_Atomic g_renderer;
static volatile sig_atomic_t g_interrupted;
/* While a file is written, a second signal waits for it to be complete
 * (g_deferred): ending at once left OUT.exr.tmpPID.N behind. */
static volatile sig_atomic_t g_writing, g_deferred;

/* The signal's default action: the program ends as if never handled. */
static void end_by(int sig)
{
	struct sigaction dfl;
	memset(&dfl, 0, sizeof dfl);
	dfl.sa_handler = SIG_DFL;
	sigemptyset(&dfl.sa_mask);
	sigaction(SIGINT, &dfl, NULL);
	sigaction(SIGTERM, &dfl, NULL);
	raise(sig);
}

static void on_signal(int sig)
{
	if (g_interrupted) { /* the second one ends the program */
		if (g_writing)
			g_deferred = sig;
		else
			end_by(sig);
		return;
	}
	g_interrupted = 1;
	/* The library documents ajar_renderer_cancel as signal-safe. */
	ajar_renderer *r = atomic_load(&g_renderer);
	if (r)
		ajar_renderer_cancel(r);
}

/* Around every output the program writes (and the render, whose periodic
 * checkpoint may be in flight): a second signal that came meanwhile ends
 * the program once the file is complete. */
static void writing_begin(void) { g_writing = 1; }

static void writing_end(void)
{
	g_writing = 0;
	if (g_deferred)
		end_by(g_deferred);
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
	writing_begin();
	ajar_status st = ajar_renderer_write_exr(r, a->exr);
	writing_end();
	if (st != AJAR_OK) {
		report(st, a->exr);
		return exit_code(st) == EXIT_BAD_INPUT ? EXIT_IO : exit_code(st);
	}
	if (a->strategies) {
		writing_begin();
		st = ajar_renderer_write_strategies(r, a->strategies);
		writing_end();
		if (st != AJAR_OK) {
			report(st, a->strategies);
			return exit_code(st) == EXIT_BAD_INPUT ? EXIT_IO : exit_code(st);
		}
	}
	if (a->png) {
		writing_begin();
		st = write_png(r, a->png, a->exposure);
		writing_end();
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
	writing_begin();
	ajar_status st = ajar_renderer_write_checkpoint(r, path);
	writing_end();
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
int cmd_render(int argc, char **argv)
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
		if (rc == EXIT_OK)
			rc = check_outputs_distinct(&a);
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
		/* The scene as loaded and prepared: its size and the time it took. */
		ajar_scene_info si;
		if (ajar_scene_info_get(scene, &si) == AJAR_OK)
			fprintf(stderr,
				"ajar: scene: %llu triangles (%llu unique, %u instances), geometry %.1f MiB, BVH %.1f MiB, "
				"textures %.1f MiB; loaded in %.2f s, BVH built in %.2f s\n",
				(unsigned long long)si.triangles, (unsigned long long)si.unique_triangles, si.instances,
				si.geometry_bytes / 1048576.0, si.bvh_bytes / 1048576.0, si.texture_bytes / 1048576.0,
				si.load_seconds, si.bvh_seconds);
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
	writing_begin(); /* --portals-out */
	rc = found_portals(r, &a);
	writing_end();
	if (rc != EXIT_OK)
		goto done;

	if (ckpt) /* the render writes checkpoints as it goes */
		writing_begin();
	st = ajar_renderer_render(r, on_progress, &progress);
	if (ckpt)
		writing_end();
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
			else {
				writing_begin();
				st = ajar_renderer_write_checkpoint(r, ckpt);
				writing_end();
				if (st == AJAR_OK && !a.quiet)
					fprintf(stderr, "ajar: checkpoint %s holds %u spp\n", ckpt, spp);
				st = AJAR_ERROR_DEVICE;
			}
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
