/* test_checkpoint.c — checkpoint and resume.
 *
 * A render stopped at random passes (the points drawn from a fixed seed),
 * checkpointed, and resumed, twice, ends with the same films (own-pixel
 * sums, splats, strategy layers) and the same image bits as the straight
 * render, for every integrator; so does the `ajar` program stopped by
 * SIGINT at random times. Checkpoints that are corrupted, truncated, of
 * another scene, version or option set are refused with the right message
 * and left untouched; a write that fails keeps the previous file; a device
 * lost mid-render leaves a checkpoint the render resumes from.
 *
 * Passes of one sample per pixel (render_faults.pass_spp, set in main) give
 * the renders through the API many points to stop at; PoCL exposes two CPU
 * devices (POCL_DEVICES, set in main) for the device-loss test. */
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ajar.h"
#include "render/checkpoint_file.h"
#include "render/render_overrides.h"
#include "testutil.h"

#define W 16
#define H 12
#define SPP 16

static uint32_t lcg = 12345; /* the stop points: fixed seed */

static uint32_t draw(uint32_t n)
{
	lcg = lcg * 1664525u + 1013904223u;
	return (lcg >> 8) % n;
}

static ajar_scene *load(const char *path)
{
	ajar_scene *s = NULL;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	return s;
}

static ajar_options options(ajar_integrator integrator, uint32_t strategy_len, uint32_t aov)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = SPP;
	o.seed = 11;
	o.integrator = integrator;
	o.strategy_len = strategy_len;
	o.max_depth = 6;
	o.aov = aov;
	return o;
}

static float *image(ajar_renderer *r)
{
	float *img = malloc(sizeof(float) * 4 * W * H);
	assert_non_null(img);
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	return img;
}

/* Passes may end faster than the callback runs: stop by samples done. */
static uint32_t stop_at;
static int stop_at_spp(const ajar_progress *p, void *user)
{
	(void)user;
	return p->spp_done >= stop_at;
}

/* Every film of two checkpoints is the same, bit for bit. */
static void same_films(const char *a, const char *b)
{
	Checkpoint x, y;
	assert_int_equal(checkpoint_read(a, &x, 0), AJAR_OK);
	assert_int_equal(checkpoint_read(b, &y, 0), AJAR_OK);
	assert_int_equal(x.nranges, y.nranges);
	assert_memory_equal(x.ranges, y.ranges, sizeof *x.ranges * x.nranges);
	for (int s = 0; s < CKPT_SECTIONS; s++) {
		assert_int_equal(x.nfilm[s], y.nfilm[s]);
		if (memcmp(x.film[s], y.film[s], 8 * x.nfilm[s]) != 0)
			fail_msg("film section %d differs between %s and %s", s, a, b);
	}
	checkpoint_free(&x);
	checkpoint_free(&y);
}

/* Stops once on an earlier budget, resumed with the full one, then once
 * by cancelling from the progress callback at a random pass, resumed
 * again. The first stop is certain; the second can be overtaken on a
 * loaded machine (devices may finish passes faster than the callback
 * runs, so the render ends before it is cancelled), which is no failure:
 * the cancelled case is also covered by the CLI's SIGINT test. */
static void resume_equals_straight(const char *scene_path, ajar_integrator integrator, uint32_t strategy_len,
				   uint32_t aov)
{
	ajar_scene *s = load(scene_path);
	ajar_options o = options(integrator, strategy_len, aov);
	ajar_renderer *r = NULL;
	char *straight = test_tmp("straight.ck"), *ck = test_tmp("resumed.ck");
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *want = image(r);
	assert_int_equal(ajar_renderer_write_checkpoint(r, straight), AJAR_OK);
	ajar_renderer_destroy(&r);

	ajar_options early = o;
	early.spp = 1 + draw(SPP / 2);
	assert_int_equal(ajar_renderer_create(s, &early, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_OK);
	ajar_renderer_destroy(&r);
	if (ajar_renderer_resume(s, ck, &o, &r) != AJAR_OK)
		fail_msg("resume: %s", ajar_last_error());
	uint32_t done = ajar_renderer_spp(r);
	assert_int_equal(done, early.spp);

	stop_at = done + 1 + draw(SPP - done - 1);
	ajar_status st = ajar_renderer_render(r, stop_at_spp, NULL);
	if (st != AJAR_OK) {
		assert_int_equal(st, AJAR_ERROR_CANCELLED);
		assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_OK);
		ajar_renderer_destroy(&r);
		if (ajar_renderer_resume(s, ck, NULL, &r) != AJAR_OK)
			fail_msg("resume: %s", ajar_last_error());
		done = ajar_renderer_spp(r);
		assert_true(done >= stop_at && done < SPP);
		assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	}
	assert_int_equal(ajar_renderer_spp(r), SPP);
	float *got = image(r);
	assert_memory_equal(got, want, sizeof(float) * 4 * W * H);
	assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_OK);
	same_films(straight, ck);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	free(want);
	free(got);
	unlink(straight);
	unlink(ck);
	free(straight);
	free(ck);
}

static void test_resume_pt(void **state)
{
	(void)state;
	resume_equals_straight(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, 0, 0);
}

static void test_resume_bdpt_layers(void **state)
{
	(void)state;
	resume_equals_straight(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_BDPT, 3, AJAR_AOV_ALL);
}

static void test_resume_portal_layers(void **state)
{
	(void)state;
	resume_equals_straight(SCENE("door-ajar/door-ajar.gltf"), AJAR_INTEGRATOR_PORTAL, 3, AJAR_AOV_ALL);
}

/* ---- Refusals -------------------------------------------------------------- */

static unsigned char *slurp(const char *path, size_t *n) { return (unsigned char *)test_read_file(path, n); }

static void spit(const char *path, const void *b, size_t n)
{
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(b, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
}

/* Resuming `path` with scene s fails with `status` and a message holding
 * `needle`, and the file is byte for byte as before. */
static void refused(ajar_scene *s, const char *path, const ajar_options *o, ajar_status status, const char *needle)
{
	size_t n0, n1;
	unsigned char *before = slurp(path, &n0);
	ajar_renderer *r = (ajar_renderer *)(void *)&n0;
	ajar_status st = ajar_renderer_resume(s, path, o, &r);
	const char *msg = ajar_last_error();
	if (st != status || !strstr(msg, needle) || !strstr(msg, path))
		fail_msg("%s: got %s \"%s\", want %s with \"%s\"", path, ajar_status_name(st), msg,
			 ajar_status_name(status), needle);
	assert_null(r);
	unsigned char *after = slurp(path, &n1);
	assert_int_equal(n0, n1);
	assert_memory_equal(before, after, n0);
	free(before);
	free(after);
}

static void test_refused(void **state)
{
	(void)state;
	ajar_scene *s = load(SCENE("cornell/cornell.gltf")), *other = load(SCENE("door-ajar/door-ajar.gltf"));
	ajar_options o = options(AJAR_INTEGRATOR_PT, 0, 0);
	o.spp = 2;
	ajar_renderer *r = NULL;
	char *good = test_tmp("good.ck"), *bad = test_tmp("bad.ck");
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, good), AJAR_OK);
	ajar_renderer_destroy(&r);
	size_t n;
	unsigned char *b = slurp(good, &n);

	/* One flipped bit in the film. */
	b[n - 100] ^= 4;
	spit(bad, b, n);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "corrupted (checksum mismatch)");
	b[n - 100] ^= 4;
	/* Cut short, in the films and in the header. */
	spit(bad, b, n - 1000);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "truncated");
	spit(bad, b, 100);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "truncated");
	spit(bad, b, 0);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "not an Ajar checkpoint");
	/* Another version: the version string after magic and format. */
	unsigned char v = b[12];
	b[12] = '9';
	spit(bad, b, n);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "made by Ajar 9");
	b[12] = v;
	/* A header that disagrees with itself (the width). */
	uint32_t w;
	memcpy(&w, b + 8 + 4 + 16 + 16 + 256, 4);
	assert_int_equal(w, W);
	w++;
	memcpy(b + 8 + 4 + 16 + 16 + 256, &w, 4);
	spit(bad, b, n);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "corrupted");
	free(b);
	/* Not a checkpoint at all. */
	spit(bad, "glTF and other things, but no checkpoint", 40);
	refused(s, bad, NULL, AJAR_ERROR_BAD_INPUT, "not an Ajar checkpoint");
	/* Another scene. */
	refused(other, good, NULL, AJAR_ERROR_BAD_INPUT, "of another scene (it was made from scenes/cornell/cornell.gltf");
	/* Another option set: only spp, time_limit and device may change. */
	ajar_options ck;
	uint32_t done = 0;
	assert_int_equal(ajar_checkpoint_options(good, &ck, &done), AJAR_OK);
	assert_int_equal(done, 2);
	assert_int_equal(ck.width, W);
	assert_int_equal(ck.seed, o.seed);
	ck.seed++;
	refused(s, good, &ck, AJAR_ERROR_INVALID_ARGUMENT, "options.seed differs");
	ck.seed--;
	ck.integrator = AJAR_INTEGRATOR_BDPT;
	refused(s, good, &ck, AJAR_ERROR_INVALID_ARGUMENT, "options.integrator differs");
	ck.integrator = AJAR_INTEGRATOR_PT;
	ck.spp = 1; /* fewer than it holds */
	refused(s, good, &ck, AJAR_ERROR_INVALID_ARGUMENT, "too few to continue it");
	/* Another parameter set with the same options (a forced policy choice). */
	o.integrator = AJAR_INTEGRATOR_PORTAL;
	const PolicyOverrides rate = {.portal_rate = 0.5f};
	assert_int_equal(renderer_create_overridden(other, &o, &rate, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, bad), AJAR_OK);
	ajar_renderer_destroy(&r);
	refused(other, bad, NULL, AJAR_ERROR_BAD_INPUT, "other render parameters");
	assert_int_equal(ajar_renderer_create(other, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, good), AJAR_OK);
	ajar_renderer_destroy(&r);
	assert_int_equal(ajar_checkpoint_options(good, &ck, NULL), AJAR_OK);
	ck.spp = 4;
	assert_int_equal(ajar_renderer_resume(other, good, &ck, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), 2);
	ajar_renderer_destroy(&r);
	unlink(good);
	unlink(bad);
	free(good);
	free(bad);
	ajar_scene_destroy(&s);
	ajar_scene_destroy(&other);
}

/* ---- A write that fails keeps the previous file -------------------------- */

static int files_in(const char *dir)
{
	char cmd[512];
	snprintf(cmd, sizeof cmd, "ls -A '%s' | wc -l", dir);
	FILE *p = popen(cmd, "r");
	int n = -1;
	assert_non_null(p);
	assert_int_equal(fscanf(p, "%d", &n), 1);
	pclose(p);
	return n;
}

static void test_failed_write_keeps_old(void **state)
{
	(void)state;
	ajar_scene *s = load(SCENE("cornell/cornell.gltf"));
	ajar_options o = options(AJAR_INTEGRATOR_PT, 0, 0);
	o.spp = 2;
	ajar_renderer *r = NULL;
	char *dir = test_tmp("keep"), *ck = test_path(dir, "render.ck");
	assert_int_equal(mkdir(dir, 0755), 0);
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_OK);
	size_t n0, n1;
	unsigned char *before = slurp(ck, &n0);
	o.spp = 3;
	ajar_renderer_destroy(&r);
	assert_int_equal(ajar_renderer_resume(s, ck, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	/* A read-only directory (root may write anyway: then only the next case). */
	assert_int_equal(chmod(dir, 0555), 0);
	if (geteuid() != 0) {
		assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_ERROR_IO);
		assert_non_null(strstr(ajar_last_error(), "render.ck"));
	}
	assert_int_equal(chmod(dir, 0755), 0);
	/* A full disk, as a file size limit (it binds root too): lowered for
	 * this write only (OpenCL does not survive a fork, so no child). */
	struct rlimit old, rl;
	assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
	rl = old;
	rl.rlim_cur = 4096;
	void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &rl), 0);
	ajar_status st = ajar_renderer_write_checkpoint(r, ck);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, was);
	assert_int_equal(st, AJAR_ERROR_IO);
	assert_non_null(strstr(ajar_last_error(), "render.ck"));
	unsigned char *after = slurp(ck, &n1);
	assert_int_equal(n0, n1);
	assert_memory_equal(before, after, n0);
	assert_int_equal(files_in(dir), 1); /* no temporary file left */
	/* The old checkpoint still resumes. */
	ajar_renderer_destroy(&r);
	assert_int_equal(ajar_renderer_resume(s, ck, NULL, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_spp(r), 2);
	ajar_renderer_destroy(&r);
	free(before);
	free(after);
	test_remove_tree(dir);
	free(dir);
	free(ck);
	ajar_scene_destroy(&s);
}

/* ---- A device lost mid-render --------------------------------------------- */

static void test_device_lost(void **state)
{
	(void)state;
	ajar_scene *s = load(SCENE("cornell/cornell.gltf"));
	ajar_options o = options(AJAR_INTEGRATOR_PT, 0, 0);
	ajar_renderer *r = NULL;
	char *ck = test_tmp("lost.ck");
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *want = image(r);
	ajar_renderer_destroy(&r);
	/* The device fails to launch its 3rd pass, passes of at most 4 samples
	 * (1, 4, then the failed one): it is dropped with its film intact, the
	 * render fails, and the checkpoint written on the loss (checkpoints
	 * only on losses) holds exactly the first 5 samples, whatever the
	 * machine's speed. (Two devices with one lost raced: the other could
	 * take every remaining sample first, and no checkpoint was written.) */
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_set_checkpoint(r, ck, 0), AJAR_OK);
	RenderFaults before = render_faults;
	render_faults = (RenderFaults){.device = 0, .pass = 3, .pass_spp = 4};
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_ERROR_DEVICE);
	render_faults = before;
	ajar_renderer_destroy(&r);
	/* The checkpoint written when the device was dropped resumes to the same bits. */
	ajar_options ckopt;
	uint32_t done = 0;
	assert_int_equal(ajar_checkpoint_options(ck, &ckopt, &done), AJAR_OK);
	assert_int_equal(done, 5);
	assert_int_equal(ajar_renderer_resume(s, ck, NULL, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *got = image(r);
	assert_memory_equal(got, want, sizeof(float) * 4 * W * H);
	ajar_renderer_destroy(&r);
	free(want);
	free(got);
	unlink(ck);
	free(ck);
	ajar_scene_destroy(&s);
}

/* ---- The program, stopped by SIGINT ------------------------------------------ */

/* Runs ajar with args; with delay_ms > 0 sends SIGINT after that long.
 * Returns the exit code; stderr goes to test_dir/stderr.txt. */
static int run_ajar(const char *const *args, int delay_ms)
{
	char *err = test_tmp("stderr.txt");
	pid_t pid = test_spawn(test_ajar_bin(), args, NULL, err);
	free(err);
	if (delay_ms > 0) {
		struct timespec ts = {delay_ms / 1000, (long)(delay_ms % 1000) * 1000000L};
		nanosleep(&ts, NULL);
		kill(pid, SIGINT);
	}
	return test_wait_exit(pid);
}

static char *stderr_text(void)
{
	char *p = test_tmp("stderr.txt"), *s = test_read_file(p, NULL);
	free(p);
	return s;
}

static void test_cli_sigint(void **state)
{
	(void)state;
	/* The straight render through the API: the EXR holds the same floats. */
	ajar_scene *s = load(SCENE("cornell/cornell.gltf"));
	ajar_options o = options(AJAR_INTEGRATOR_BDPT, 2, AJAR_AOV_ALL);
	o.width = 24;
	o.height = 24;
	o.spp = 1000;
	ajar_renderer *r = NULL;
	assert_int_equal(ajar_renderer_create(s, &o, &r), AJAR_OK);
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *want = malloc(sizeof(float) * 4 * 24 * 24);
	assert_non_null(want);
	assert_int_equal(ajar_renderer_image(r, want, NULL, NULL), AJAR_OK);
	char *straight = test_tmp("cli-straight.ck");
	assert_int_equal(ajar_renderer_write_checkpoint(r, straight), AJAR_OK);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);

	char *exr = test_tmp("cli.exr"), *strat = test_tmp("cli-strategies.exr"), *ck = test_tmp("cli.ck");
	const char *first[] = {"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "24x24", "--spp", "1000",
			       "--seed", "11", "--integrator", "bdpt", "--max-depth", "6", "--strategies", strat,
			       "--strategy-len", "2", "--aov", "albedo,normal,depth,variance", "--checkpoint", ck, "-q", NULL};
	const char *again[] = {"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--resume", ck, "--strategies",
			       strat, "-q", NULL};
	int interrupted = 0, runs = 0, base = 300, span = 1200;
	struct stat sb;
	while (runs < 12) {
		int resuming = stat(ck, &sb) == 0;
		/* Two SIGINTs at random times (0.3 .. 1.5 s), then to the end. */
		int delay = interrupted < 2 ? base + (int)draw((uint32_t)span) : 0;
		int rc = run_ajar(resuming ? again : first, delay);
		runs++;
		if (rc == 0 && interrupted < 2) {
			/* A fast machine finished before the second signal: start
			 * over with signals twice as early. */
			unlink(ck);
			unlink(exr);
			interrupted = 0;
			base /= 2;
			span = span > 1 ? span / 2 : 1;
			continue;
		}
		if (rc == 0)
			break;
		char *e = stderr_text();
		if (rc != 5)
			fail_msg("exit %d: %s", rc, e);
		free(e);
		interrupted += stat(ck, &sb) == 0; /* a SIGINT before the first pass writes nothing */
	}
	assert_int_equal(interrupted, 2);
	float *got;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(exr, &got, &w, &h), AJAR_OK);
	assert_int_equal(w, 24);
	assert_memory_equal(got, want, sizeof(float) * 4 * 24 * 24);
	free(got);

	/* The films, AOVs and layers too: the program's last checkpoint against
	 * the straight render's. */
	same_films(ck, straight);
	unlink(straight);
	free(straight);

	/* A conflicting option names itself; a corrupted file is refused and kept. */
	const char *conflict[] = {"render", SCENE("cornell/cornell.gltf"), "-o", exr, "--resume", ck, "--seed", "12",
				  NULL};
	assert_int_equal(run_ajar(conflict, 0), 1);
	char *e = stderr_text();
	assert_non_null(strstr(e, "--seed 12: the checkpoint"));
	assert_non_null(strstr(e, "--seed 11"));
	free(e);
	size_t n;
	unsigned char *b = slurp(ck, &n);
	b[n / 2] ^= 1;
	spit(ck, b, n);
	assert_int_equal(run_ajar(again, 0), 2);
	e = stderr_text();
	assert_non_null(strstr(e, "corrupted"));
	free(e);
	size_t n2;
	unsigned char *b2 = slurp(ck, &n2);
	assert_int_equal(n, n2);
	assert_memory_equal(b, b2, n);
	free(b);
	free(b2);
	free(want);
	unlink(exr);
	unlink(strat);
	unlink(ck);
	free(exr);
	free(strat);
	free(ck);
}

int main(void)
{
	/* Before the OpenCL platform is first initialised. */
	setenv("POCL_DEVICES", "pthread pthread", 1);
	render_faults.pass_spp = 1; /* many passes: a render can stop at many points */
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_resume_pt),
		cmocka_unit_test(test_resume_bdpt_layers),
		cmocka_unit_test(test_resume_portal_layers),
		cmocka_unit_test(test_refused),
		cmocka_unit_test(test_failed_write_keeps_old),
		cmocka_unit_test(test_device_lost),
		cmocka_unit_test(test_cli_sigint),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
