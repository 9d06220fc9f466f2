/* test_mpi.c — one image rendered by the ranks of an Open MPI job.
 *
 * Runs `mpirun --oversubscribe -n 2 build/ajar render ...` (as root, with
 * Open MPI's OMPI_ALLOW_RUN_AS_ROOT pair set for mpirun alone: CI runs as
 * root) and compares the job's last checkpoint, which holds the integer
 * films and the sample ranges, and its EXR with one process rendering the
 * same sample indices through the API: bit for bit, for pt and for portal
 * with strategy layers and AOVs; with --time (rank 0 stops the job) and
 * resumed by a job; with a device failing in rank 1 (dropped, its samples
 * rendered again); with rank 1 killed (the job stops with a message,
 * writes no image, and its checkpoint resumes in one process to the same
 * bits); with rank 1 unable to start. Each rank gets one PoCL thread.
 * Skipped when the library was built without MPI. (That the MPI-built
 * program run alone is one process as before is what every other test of
 * the program checks.) */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ajar.h"
#include "render/checkpoint_file.h"
#include "testutil.h"

/* The image size: 32x32, 64x64 for the test that must render long enough. */
static uint32_t W = 32, H = 32;

static ajar_scene *load(const char *path)
{
	ajar_scene *s = NULL;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	return s;
}

/* The reference: one process, through the API; its checkpoint at `ck`,
 * its image returned. */
static float *one_process(const char *scene, ajar_integrator integrator, uint32_t spp, uint32_t strategy_len,
			  uint32_t aov, const char *ck)
{
	ajar_scene *s = load(scene);
	ajar_options o;
	ajar_options_default(&o);
	o.width = W;
	o.height = H;
	o.spp = spp;
	o.seed = 5;
	o.integrator = integrator;
	o.max_depth = 6;
	o.strategy_len = strategy_len;
	o.aov = aov;
	ajar_renderer *r = NULL;
	if (ajar_renderer_create(s, &o, &r) != AJAR_OK)
		fail_msg("renderer: %s", ajar_last_error());
	assert_int_equal(ajar_renderer_render(r, NULL, NULL), AJAR_OK);
	float *img = malloc(sizeof(float) * 4 * W * H);
	assert_non_null(img);
	assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
	assert_int_equal(ajar_renderer_write_checkpoint(r, ck), AJAR_OK);
	ajar_renderer_destroy(&r);
	ajar_scene_destroy(&s);
	return img;
}

/* Every film and range of two checkpoints, bit for bit. */
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

/* The samples per pixel a checkpoint holds, which must be [0, n). */
static uint32_t ckpt_spp(const char *path)
{
	Checkpoint c;
	assert_int_equal(checkpoint_read(path, &c, 0), AJAR_OK);
	assert_int_equal(c.nranges, 1);
	assert_int_equal(c.ranges[0].first, 0);
	uint32_t n = c.ranges[0].count;
	checkpoint_free(&c);
	return n;
}

static void same_image(const char *exr, const float *want)
{
	float *got;
	uint32_t w, h;
	assert_int_equal(ajar_read_exr(exr, &got, &w, &h), AJAR_OK);
	assert_int_equal(w, W);
	assert_int_equal(h, H);
	assert_memory_equal(got, want, sizeof(float) * 4 * W * H);
	free(got);
}

/* Runs argv (NULL-terminated; "ajar" is replaced by the ajar command with
 * faults injected from its environment, test_ajar_faults_bin) with
 * stderr to test_dir/stderr.txt. With kill_after set, waits until that file
 * exists and `pidfile` names a process, then sends SIGKILL to it. Returns
 * the exit status as the shell shows it (128 + signal when killed). */
static int run(const char *const *args, const char *kill_after, const char *pidfile)
{
	const char *argv[64];
	int n = 0;
	for (; args[n] && n < 63; n++)
		argv[n] = strcmp(args[n], "ajar") ? args[n] : test_ajar_faults_bin();
	argv[n] = NULL;
	char *err = test_tmp("stderr.txt");
	fflush(NULL);
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		int fe = open(err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
		if (fe < 0 || dup2(fe, 2) < 0)
			_exit(127);
		/* Open MPI refuses root unless told twice; CI runs as root. */
		if (geteuid() == 0) {
			setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
			setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
		}
		/* Containers often forbid the cross-memory attach that Open MPI's
		 * shared-memory transport uses for large messages. */
		setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
		setenv("POCL_MAX_PTHREAD_COUNT", "1", 1);
		execvp(argv[0], (char *const *)argv);
		_exit(127);
	}
	free(err);
	int status, ended = 0;
	if (kill_after) {
		struct stat sb;
		pid_t victim = 0;
		for (int i = 0; i < 6000 && victim == 0 && !ended; i++) {
			struct timespec ts = {0, 10 * 1000000L};
			nanosleep(&ts, NULL);
			FILE *f = stat(kill_after, &sb) == 0 ? fopen(pidfile, "r") : NULL;
			if (f && fscanf(f, "%d", &victim) != 1)
				victim = 0;
			if (f)
				fclose(f);
			ended = waitpid(pid, &status, WNOHANG) == pid; /* done before (a fast machine) */
		}
		assert_true(victim > 0 || ended);
		struct timespec ts = {0, 100 * 1000000L}; /* a little past the checkpoint */
		nanosleep(&ts, NULL);
		if (!ended)
			kill(victim, SIGKILL);
	}
	if (!ended)
		assert_int_equal(waitpid(pid, &status, 0), pid);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static char *stderr_text(void)
{
	char *p = test_tmp("stderr.txt");
	FILE *f = fopen(p, "rb");
	assert_non_null(f);
	char *s = calloc(1, 65536);
	assert_non_null(s);
	size_t n = fread(s, 1, 65535, f);
	s[n] = '\0';
	fclose(f);
	free(p);
	return s;
}

/* The share rank 1's device did, from the "done" lines (percent). */
static double rank1_share(const char *text)
{
	const char *p = strstr(text, "(rank 1, ");
	p = p ? strstr(p, "): ") : NULL;
	return p ? atof(p + 3) : -1.0;
}

static int exists(const char *path)
{
	struct stat sb;
	return stat(path, &sb) == 0;
}

#define MPIRUN "mpirun", "--oversubscribe"

static void skip_without_mpi(void)
{
	if (!ajar_mpi_available()) {
		print_message("built without Open MPI: skipped\n");
		skip();
	}
}

/* pt and portal (strategy layers, AOVs): the job's films and image are the
 * one process's, and rank 1 rendered a part of them. */
static void test_two_ranks_equal_one(void **state)
{
	(void)state;
	skip_without_mpi();
	char *ck1 = test_tmp("one.ck"), *ck2 = test_tmp("two.ck"), *exr = test_tmp("two.exr");
	char *strat = test_tmp("two-strat.exr");
	float *want = one_process(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, 40, 0, 0, ck1);
	/* Small passes (the test hook), so both ranks get many ranges. */
	const char *pt[] = {MPIRUN, "-n", "2", "env", "AJAR_TEST_PASS_SPP=2", "ajar", "render",
			    SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "32x32", "--spp", "40", "--seed", "5",
			    "--max-depth", "6", "--checkpoint", ck2, NULL};
	int rc = run(pt, NULL, NULL);
	char *e = stderr_text();
	if (rc != 0)
		fail_msg("mpirun exit %d: %s", rc, e);
	assert_non_null(strstr(e, "2 ranks: "));
	if (!(rank1_share(e) > 0.0))
		fail_msg("rank 1 rendered nothing: %s", e);
	free(e);
	same_films(ck1, ck2);
	same_image(exr, want);
	free(want);

	want = one_process(SCENE("door-ajar/door-ajar.gltf"), AJAR_INTEGRATOR_PORTAL, 8, 2, AJAR_AOV_ALL, ck1);
	const char *portal[] = {MPIRUN, "-n", "2", "env", "AJAR_TEST_PASS_SPP=1", "ajar", "render",
				SCENE("door-ajar/door-ajar.gltf"), "-o", exr, "--size", "32x32", "--spp", "8", "--seed",
				"5", "--max-depth", "6", "--integrator", "portal", "--strategies", strat,
				"--strategy-len", "2", "--aov", "albedo,normal,depth,variance", "--checkpoint", ck2, "-q",
				NULL};
	rc = run(portal, NULL, NULL);
	if (rc != 0)
		fail_msg("mpirun exit %d: %s", rc, stderr_text());
	same_films(ck1, ck2);
	same_image(exr, want);
	assert_true(exists(strat));
	free(want);
	unlink(ck1), unlink(ck2), unlink(exr), unlink(strat);
	free(ck1), free(ck2), free(exr), free(strat);
}

/* --time: rank 0 stops the job; the samples are [0, n) and the films
 * those of one process rendering n; resumed by a job, n + 8. */
static void test_time_limit(void **state)
{
	(void)state;
	skip_without_mpi();
	W = H = 16; /* a second at 16x16 is already some 1500 spp */
	char *ck1 = test_tmp("one.ck"), *ck2 = test_tmp("two.ck"), *exr = test_tmp("two.exr");
	const char *args[] = {MPIRUN, "-n", "2", "env", "AJAR_TEST_PASS_SPP=2", "ajar", "render",
			      SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "16x16", "--time", "1", "--seed",
			      "5", "--max-depth", "6", "--checkpoint", ck2, "-q", NULL};
	int rc = run(args, NULL, NULL);
	if (rc != 0)
		fail_msg("mpirun exit %d: %s", rc, stderr_text());
	uint32_t spp = ckpt_spp(ck2);
	assert_true(spp >= 1);
	float *want = one_process(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, spp, 0, 0, ck1);
	same_films(ck1, ck2);
	same_image(exr, want);
	free(want);

	/* Resumed by a job of two ranks (rank 0 reads the checkpoint, rank 1
	 * gets the options from it), 8 samples further (--time is the total
	 * budget: the first second is spent). */
	char more[16];
	snprintf(more, sizeof more, "%u", spp + 8);
	const char *resume[] = {MPIRUN, "-n", "2", "env", "AJAR_TEST_PASS_SPP=2", "ajar", "render",
				SCENE("cornell/cornell.gltf"), "-o", exr, "--resume", ck2, "--spp", more, "--time", "600", "-q", NULL};
	rc = run(resume, NULL, NULL);
	if (rc != 0)
		fail_msg("resume: mpirun exit %d: %s", rc, stderr_text());
	assert_int_equal(ckpt_spp(ck2), spp + 8);
	want = one_process(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, spp + 8, 0, 0, ck1);
	same_films(ck1, ck2);
	same_image(exr, want);
	free(want);
	W = H = 32;
	unlink(ck1), unlink(ck2), unlink(exr);
	free(ck1), free(ck2), free(exr);
}

/* A device of rank 1 fails (the library's test hook, set for rank 1 only),
 * at launch (its film kept by rank 1) and after its kernel ran (its film
 * untrusted: its ranges are rendered again): dropped with a warning naming
 * it, and the image is still the one process's. */
static void test_device_fails_in_rank1(void **state)
{
	(void)state;
	skip_without_mpi();
	char *ck1 = test_tmp("one.ck"), *ck2 = test_tmp("two.ck"), *exr = test_tmp("two.exr");
	float *want = one_process(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, 40, 0, 0, ck1);
	static const char *const modes[] = {"AJAR_TEST_FAIL_DEVICE=0:4", "AJAR_TEST_FAIL_DEVICE=0:4:lost"};
	for (int m = 0; m < 2; m++) {
		unlink(ck2);
		unlink(exr);
		const char *args[] = {MPIRUN, "-n", "1", "env", "AJAR_TEST_PASS_SPP=2", "ajar", "render",
				      SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "32x32", "--spp", "40",
				      "--seed", "5", "--max-depth", "6", "--checkpoint", ck2, ":", "-n", "1", "env",
				      "AJAR_TEST_PASS_SPP=2", modes[m], "ajar", "render", SCENE("cornell/cornell.gltf"),
				      "-o", exr, "--size", "32x32", "--spp", "40", "--seed", "5", "--max-depth", "6",
				      "--checkpoint", ck2, NULL};
		int rc = run(args, NULL, NULL);
		char *e = stderr_text();
		if (rc != 0)
			fail_msg("%s: mpirun exit %d: %s", modes[m], rc, e);
		if (!strstr(e, "(rank 1, 0:0) dropped: ") || !strstr(e, "an injected fault"))
			fail_msg("%s: no warning naming rank 1's device: %s", modes[m], e);
		free(e);
		same_films(ck1, ck2);
		same_image(exr, want);
	}
	free(want);
	unlink(ck1), unlink(ck2), unlink(exr);
	free(ck1), free(ck2), free(exr);
}

/* Rank 1 killed mid-render: the job stops with a non-zero status and a
 * message naming rank 1, no image is written, and the checkpoint written
 * before resumes in one process (no mpirun) to the straight render. */
static void test_rank_killed(void **state)
{
	(void)state;
	skip_without_mpi();
	W = H = 64;
	char *ck1 = test_tmp("one.ck"), *ck2 = test_tmp("two.ck"), *exr = test_tmp("two.exr");
	char *pid = test_tmp("rank1.pid");
	char script[512], spp[16];
	snprintf(script, sizeof script, "echo $$ > %s; exec \"$0\" \"$@\"", pid);
	/* On a machine fast enough to finish before the kill, again with 4x the samples. */
	int rc = 0;
	uint32_t n = 400;
	for (int attempt = 0; attempt < 3; attempt++, n *= 4) {
		unlink(ck2);
		unlink(pid);
		snprintf(spp, sizeof spp, "%u", n);
		const char *args[] = {MPIRUN, "-n", "1", "env", "AJAR_TEST_PASS_SPP=1", "ajar", "render",
				      SCENE("cornell/cornell.gltf"), "-o", exr, "--size", "64x64", "--spp", spp, "--seed",
				      "5", "--max-depth", "6", "--checkpoint", ck2, "--checkpoint-every", "0.1", ":", "-n",
				      "1", "sh", "-c", script, "ajar", "render", SCENE("cornell/cornell.gltf"), "-o", exr,
				      "--size", "64x64", "--spp", spp, "--seed", "5", "--max-depth", "6", "--checkpoint",
				      ck2, "--checkpoint-every", "0.1", NULL};
		/* "ajar" after "sh -c script" is $0: replaced by the binary as well. */
		if ((rc = run(args, ck2, pid)) != 0)
			break;
		unlink(exr);
	}
	char *e = stderr_text();
	if (rc == 0)
		fail_msg("the job ended well with rank 1 killed: %s", e);
	if (!strstr(e, "rank 1"))
		fail_msg("exit %d, no message naming rank 1: %s", rc, e);
	free(e);
	assert_false(exists(exr));
	uint32_t held = ckpt_spp(ck2);
	assert_true(held >= 1 && held < n);

	const char *resume[] = {"ajar", "render", SCENE("cornell/cornell.gltf"), "-o", exr, "--resume", ck2, "-q",
				NULL};
	rc = run(resume, NULL, NULL);
	if (rc != 0)
		fail_msg("resume: exit %d: %s", rc, stderr_text());
	float *want = one_process(SCENE("cornell/cornell.gltf"), AJAR_INTEGRATOR_PT, n, 0, 0, ck1);
	same_films(ck1, ck2);
	same_image(exr, want);
	free(want);
	W = H = 32;
	unlink(ck1), unlink(ck2), unlink(exr), unlink(pid);
	free(ck1), free(ck2), free(exr), free(pid);
}

/* A rank that cannot start stops every rank before anything renders, with
 * a message naming it: no device matching its --device (exit 3), another
 * scene than rank 0's (exit 2), a scene it cannot read (exit 2). */
static void test_rank_cannot_start(void **state)
{
	(void)state;
	skip_without_mpi();
	char *exr = test_tmp("never.exr");
	static const struct {
		const char *scene, *device;
		int rc;
		const char *says;
	} cases[] = {
		{SCENE("cornell/cornell.gltf"), "no-such-device", 3, "rank 1 ("},
		{SCENE("window-room/window-room.gltf"), "cpu", 2, "rank 1 ("},
		{SCENE("no-such-scene.gltf"), "cpu", 2, "ajar: rank 1: error: "},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		const char *args[] = {MPIRUN, "-n", "1", "ajar", "render", SCENE("cornell/cornell.gltf"), "-o", exr,
				      "--size", "16x16", "--spp", "4", ":", "-n", "1", "ajar", "render", cases[k].scene,
				      "-o", exr, "--size", "16x16", "--spp", "4", "--device", cases[k].device, NULL};
		int rc = run(args, NULL, NULL);
		char *e = stderr_text();
		if (rc != cases[k].rc || !strstr(e, cases[k].says))
			fail_msg("case %zu: exit %d (want %d), no '%s': %s", k, rc, cases[k].rc, cases[k].says, e);
		free(e);
		assert_false(exists(exr));
	}
	free(exr);
}

int main(void)
{
	/* The in-process reference renders with one PoCL thread too (the same
	 * floats either way; it only keeps the machine's two cores for mpirun). */
	setenv("POCL_MAX_PTHREAD_COUNT", "1", 0);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_two_ranks_equal_one),
		cmocka_unit_test(test_time_limit),
		cmocka_unit_test(test_device_fails_in_rank1),
		cmocka_unit_test(test_rank_killed),
		cmocka_unit_test(test_rank_cannot_start),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
