/* bench.c — `make bench`: the figures the design asks for, per scene:
 * BVH build time and memory, closest-hit traversal throughput on incoherent
 * rays (dedicated kernel), path-tracing samples per second, and the cold and
 * warm start-up time of the CLI (a cold start has neither Ajar's nor PoCL's
 * kernel cache). Speeds vary between runs on shared machines; compare
 * figures from one run. AJAR_BENCH_SCENES (equal-time part only) and
 * AJAR_BENCH_FILES (per-scene figures only) pick what runs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ajar.h"
#include "device/device_build.h"
#include "device/kernel_source.h"
#include "prepare/prepare.h"
#include "scene/gltf.h"
#include "scene/scene.h"
#include "device/upload.h"
#include "testutil.h"

/* CPU seconds of the whole process (every thread): on a machine shared
 * with other jobs a steadier measure of work than the wall clock. */
static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* The last traversal's rays per CPU second, in millions. */
static double g_trace_cpu;

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static float frand(unsigned *s)
{
	*s = *s * 1664525u + 1013904223u;
	return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

static int check(ajar_status st)
{
	if (st != AJAR_OK) {
		fprintf(stderr, "bench: %s\n", ajar_last_error());
		exit(1);
	}
	return 0;
}

/* Million closest-hit rays per second: rays from random points in the
 * scene's bounds in random directions (incoherent by construction). */
static double traversal_mrays_local(const SceneData *sd, Device *d, size_t *local);

static double traversal_mrays(const SceneData *sd, Device *d)
{
	/* PoCL picks its own groups for a one-level tree, as the figures
	 * before instances were measured; with instances groups of 64 (the
	 * two-level stack, held for a whole group, is twice as deep). */
	size_t local = 64;
	return traversal_mrays_local(sd, d, sd->n_instances ? &local : NULL);
}

static double traversal_mrays_local(const SceneData *sd, Device *d, size_t *local)
{
	const uint32_t n = 1u << 20;
	float *rays = malloc(sizeof(float) * 6 * n);
	unsigned seed = 7;
	V3 lo = sd->bmin, ext = v3_sub(sd->bmax, sd->bmin);
	for (uint32_t i = 0; i < n; i++) {
		float *r = rays + 6 * i;
		r[0] = lo.x + ext.x * frand(&seed);
		r[1] = lo.y + ext.y * frand(&seed);
		r[2] = lo.z + ext.z * frand(&seed);
		float z = 1 - 2 * frand(&seed), phi = 6.2831853f * frand(&seed), s = sqrtf(fmaxf(0, 1 - z * z));
		r[3] = s * cosf(phi);
		r[4] = s * sinf(phi);
		r[5] = z;
	}
	SceneBuffers b;
	cl_kernel k;
	cl_mem mrays, mhits;
	cl_uint arg, count = n;
	check(upload_scene(d, sd, &b));
	check(device_kernel(d, "trace_closest", &k));
	check(upload_bind(d, k, &b, &arg));
	check(device_buffer(d, CL_MEM_READ_ONLY, sizeof(float) * 6 * n, rays, &mrays));
	check(device_buffer(d, CL_MEM_WRITE_ONLY, sizeof(int) * n, NULL, &mhits));
	clSetKernelArg(k, arg, sizeof mrays, &mrays);
	clSetKernelArg(k, arg + 1, sizeof mhits, &mhits);
	clSetKernelArg(k, arg + 2, sizeof count, &count);
	size_t global = n;
	double best = 1e30, best_cpu = 1e30;
	for (int rep = 0; rep < 3; rep++) { /* the first run includes PoCL's work-group compile */
		double t0 = now(), c0 = cpu_now();
		clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, local, 0, NULL, NULL);
		clFinish(d->queue);
		double t = now() - t0, c = cpu_now() - c0;
		if (rep > 0 && t < best)
			best = t;
		if (rep > 0 && c < best_cpu)
			best_cpu = c;
	}
	g_trace_cpu = n / best_cpu * 1e-6;
	clReleaseMemObject(mrays);
	clReleaseMemObject(mhits);
	clReleaseKernel(k);
	upload_free(&b);
	free(rays);
	return n / best * 1e-6;
}

static double pt_msamples(ajar_scene *s, uint32_t size, uint32_t spp)
{
	ajar_options o;
	ajar_renderer *r;
	ajar_options_default(&o);
	o.width = o.height = size;
	o.spp = 1;
	check(ajar_renderer_create(s, &o, &r));
	check(ajar_renderer_render(r, NULL, NULL)); /* warm-up pass */
	ajar_renderer_destroy(&r);
	o.spp = spp;
	check(ajar_renderer_create(s, &o, &r));
	double t0 = now();
	check(ajar_renderer_render(r, NULL, NULL));
	double t = now() - t0;
	ajar_renderer_destroy(&r);
	return (double)size * size * spp / t * 1e-6;
}

static void bench_scene(const char *path, uint32_t spp)
{
	ajar_scene *s;
	SceneData sd;
	Device d;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t ndev;
	double t0 = now();
	check(ajar_scene_load(path, &s));
	double load = now() - t0;
	/* The BVH first, alone: its process CPU time too (on a shared machine
	 * the wall time counts other jobs' turns on the cores). */
	double c0 = cpu_now();
	check(ajar_scene_build_bvh(s));
	double bvh_cpu = cpu_now() - c0;
	ajar_options po;
	ajar_options_default(&po);
	po.max_depth = 64;
	po.mis = AJAR_MIS_POWER;
	check(prepare_scene(s, &po, 64, 64, NULL, &sd));
	check(device_select(NULL, &plat, &id, 1, &ndev));
	check(device_open(&d, plat, id));
	/* The general program, as before instances, but without their code
	 * where the scene has none (its renders' program leaves it out too). */
	check(device_build(&d, ajar_kernel_source,
			   sd.n_instances ? KERNEL_OPTIONS "0" : KERNEL_OPTIONS "0 -DAJAR_NO_INSTANCES"));
	double mrays = traversal_mrays(&sd, &d);
	double msps = pt_msamples(s, 256, spp);
	/* Textures as the device holds them: RGBA8 texels (4 bytes each). */
	printf("%-34s %9u tris  load %6.2f s  BVH build %6.3f s (cpu %.3f s)  %7.1f MiB  %5u nodes/k-tri  "
	       "traversal %6.2f Mrays/s (%.2f a CPU second)  pt %6.3f Msamples/s  textures %u, %.1f MiB\n",
	       path, s->ntris, load, sd.bvh_seconds, bvh_cpu, (double)sd.n_nodes * sizeof(BvhNode) / 1048576.0,
	       (unsigned)(1000.0 * sd.n_nodes / s->ntris), mrays, g_trace_cpu, msps, s->nimages,
	       (double)(sd.n_texels * sizeof *sd.texels) / 1048576.0);
	device_close(&d);
	prepare_free(&sd);
	ajar_scene_destroy(&s);
}

/* Path-tracing samples per second on one device and on all devices at
 * once, with each device's share. Without other devices PoCL's pthread
 * device is exposed twice; those two share the machine's cores, so the
 * figure shows the scheduler's overhead and balance, not a speed-up. Runs
 * before anything else starts OpenCL (PoCL reads POCL_DEVICES then). */
static void bench_devices(void)
{
	int set = !getenv("POCL_DEVICES");
	ajar_scene *s;
	uint32_t ndev = 0;
	if (set)
		setenv("POCL_DEVICES", "pthread pthread", 1);
	check(ajar_devices(NULL, 0, &ndev));
	check(ajar_scene_load("scenes/cornell/cornell.gltf", &s));
	const char *sel[] = {"0:0", "all"};
	for (int k = 0; k < (ndev > 1 ? 2 : 1); k++) {
		ajar_options o;
		ajar_renderer *r;
		ajar_options_default(&o);
		o.width = o.height = 256;
		o.device = sel[k];
		o.spp = 2; /* warm-up: PoCL's work-group compile */
		check(ajar_renderer_create(s, &o, &r));
		check(ajar_renderer_render(r, NULL, NULL));
		ajar_renderer_destroy(&r);
		o.spp = 32;
		check(ajar_renderer_create(s, &o, &r));
		double t0 = now();
		check(ajar_renderer_render(r, NULL, NULL));
		double t = now() - t0;
		printf("cornell 256x256 32 spp on %-3s: %6.3f Msamples/s", sel[k], 256.0 * 256 * 32 / t * 1e-6);
		for (uint32_t i = 0; i < ajar_renderer_device_count(r); i++) {
			ajar_device_stats st;
			check(ajar_renderer_device_stats(r, i, &st));
			printf("%s %s %.1f%% %.3g Msamples/s", i ? ";" : " ", st.selector, 100 * st.share,
			       st.samples_per_second * 1e-6);
		}
		printf("\n");
		ajar_renderer_destroy(&r);
	}
	ajar_scene_destroy(&s);
	if (set)
		unsetenv("POCL_DEVICES");
}

/* Wall time of a tiny CLI render; `cold` empties both kernel caches. */
static double startup(const char *cache, int cold)
{
	char cmd[1024];
	snprintf(cmd, sizeof cmd,
		 "%s AJAR_CACHE_DIR=%s POCL_CACHE_DIR=%s/pocl build/ajar render scenes/cornell/cornell.gltf "
		 "-o %s/s.exr --spp 1 --size 16x16 --quiet",
		 cold ? "POCL_KERNEL_CACHE=0" : "", cache, cache, cache);
	double t0 = now();
	if (system(cmd) != 0) {
		fprintf(stderr, "bench: start-up run failed: %s\n", cmd);
		exit(1);
	}
	return now() - t0;
}

/* ---- Scale: the big scenes of issue 42 ---------------------------------- */

/* One `ajar render SCENE --spp 1` in a child process: its wall time (start
 * to the end of the first pass, the EXR of 64x48 pixels written), peak RSS
 * (getrusage of the child: every page it ever held) and the load and BVH
 * times its log names. Kernel caches warm (the caller runs it once before). */
static void scale_row(const char *dir, const char *name, int quiet)
{
	char scene[512], log[512], cmd[2048];
	snprintf(scene, sizeof scene, "build/scale/%s.gltf", name);
	snprintf(log, sizeof log, "%s/scale.log", dir);
	snprintf(cmd, sizeof cmd, "exec build/ajar render %s -o %s/scale.exr --spp 1 --size 64x48 2> %s", scene, dir,
		 log);
	double t0 = now();
	pid_t pid = fork();
	if (pid == 0) {
		execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
		_exit(127);
	}
	int status = 0;
	struct rusage ru;
	if (pid < 0 || wait4(pid, &status, 0, &ru) < 0) {
		fprintf(stderr, "bench: cannot run %s\n", cmd);
		exit(1);
	}
	double wall = now() - t0;
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		printf("%-14s exit %d (%s)\n", name, WIFEXITED(status) ? WEXITSTATUS(status) : -1,
		       WEXITSTATUS(status) == 6 ? "out of memory" : "failed");
		return;
	}
	/* The render log's counts and times (src/cli/cmd_render.c). */
	double load = -1, bvh = -1;
	unsigned long long tris = 0, unique = 0, inst = 0;
	FILE *f = fopen(log, "r");
	char line[1024];
	while (f && fgets(line, sizeof line, f)) {
		const char *p;
		if ((p = strstr(line, "loaded in ")))
			load = atof(p + 10);
		if ((p = strstr(line, "BVH built in ")))
			bvh = atof(p + 13);
		if ((p = strstr(line, "ajar: scene: ")))
			sscanf(p, "ajar: scene: %llu triangles (%llu unique, %llu instances", &tris, &unique, &inst);
	}
	if (f)
		fclose(f);
	if (quiet)
		return;
	double peak = (double)ru.ru_maxrss * 1024.0; /* kilobytes on Linux */
	printf("%-14s %11llu tris %10llu unique %5llu inst  peak %7.0f MiB  %6.1f B/tri (unique)  "
	       "to first pass %6.2f s (cpu %6.2f s)  load %6.2f s  BVH %6.2f s\n",
	       name, tris, unique, inst, peak / 1048576.0, unique ? peak / (double)unique : 0.0, wall,
	       (double)ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec +
		       ru.ru_stime.tv_usec * 1e-6,
	       load, bvh);
}

/* Whether the comma-separated `list` names `name` exactly (NULL: all). */
static int in_list(const char *list, const char *name)
{
	size_t n = strlen(name);
	for (const char *p = list; p; p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL)
		if (!strncmp(p, name, n) && (p[n] == ',' || p[n] == '\0'))
			return 1;
	return list == NULL;
}

/* The scale rows: scenes written by tests/bench/make_scale_scenes.py into
 * build/scale (once; 30 s and 0.6 GB of files for all). AJAR_BENCH_SCALE: a
 * comma-separated list of the scenes (default all of them), or 0 for none.
 * One at a time: the largest holds gigabytes. */
static void bench_scale(const char *dir)
{
	const char *want = getenv("AJAR_BENCH_SCALE");
	static const char *const names[] = {"unique-1m", "unique-10m", "inst-100", "inst-1000", "inst-1000-gpu"};
	if (want && !strcmp(want, "0"))
		return;
	char cmd[1024] = "python3 tests/bench/make_scale_scenes.py build/scale";
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (in_list(want, names[i]))
			snprintf(cmd + strlen(cmd), sizeof cmd - strlen(cmd), " %s", names[i]);
	if (system(cmd) != 0) { /* no python3, or no room in build/ */
		printf("scale rows skipped: %s failed\n", cmd);
		return;
	}
	int first = 1;
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		if (!in_list(want, names[i]))
			continue;
		if (first) /* warms the kernel caches */
			scale_row(dir, names[i], 1);
		first = 0;
		scale_row(dir, names[i], 0);
	}
}

/* ---- The flattening rule ---------------------------------------------- */

/* One rule scene (make_scale_scenes.py rule-T-U) flattened and as
 * instances: closest-hit rays per CPU second of each (groups of 64 for both),
 * and the memory of its triangles and BVH. */
static void rule_row(const char *name, Device *flat, Device *inst)
{
	char path[256];
	snprintf(path, sizeof path, "build/scale/%s.gltf", name);
	double mrays[2];
	size_t bytes[2];
	for (int m = 0; m < 2; m++) {
		Scene *s;
		SceneData sd;
		check(gltf_load_instancing(path, 0, m ? GLTF_INSTANCING_ALL : GLTF_INSTANCING_NONE, &s));
		ajar_options po;
		ajar_options_default(&po);
		po.max_depth = 8;
		check(prepare_scene(s, &po, 64, 64, NULL, &sd));
		size_t local = 64;
		traversal_mrays_local(&sd, m ? inst : flat, &local);
		mrays[m] = g_trace_cpu; /* per CPU second: steadier on a shared machine */
		bytes[m] = sd.n_tris * (sizeof(Tri) + sizeof(TriShade)) + sd.n_nodes * sizeof(BvhNode);
		prepare_free(&sd);
		scene_free(s);
	}
	printf("%-16s flattened %6.2f Mrays/CPU s %7.1f MiB   instances %6.2f Mrays/CPU s %7.1f MiB   speed inst/flat %.2f\n",
	       name, mrays[0], bytes[0] / 1048576.0, mrays[1], bytes[1] / 1048576.0, mrays[1] / mrays[0]);
}

/* AJAR_BENCH_RULE=1: every rule scene, both ways. */
static void bench_rule(void)
{
	static const unsigned tris[] = {64, 1024, 16384}, copies[] = {4, 16, 64, 256};
	char cmd[2048] = "python3 tests/bench/make_scale_scenes.py build/scale";
	for (int t = 0; t < 3; t++)
		for (int u = 0; u < 4; u++)
			snprintf(cmd + strlen(cmd), sizeof cmd - strlen(cmd), " rule-%u-%u", tris[t], copies[u]);
	if (system(cmd) != 0) {
		fprintf(stderr, "bench: %s failed\n", cmd);
		exit(1);
	}
	Device flat, inst;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t ndev;
	check(device_select(NULL, &plat, &id, 1, &ndev));
	check(device_open(&flat, plat, id));
	check(device_build(&flat, ajar_kernel_source, KERNEL_OPTIONS "0 -DAJAR_NO_INSTANCES"));
	check(device_open(&inst, plat, id));
	check(device_build(&inst, ajar_kernel_source, KERNEL_OPTIONS "0"));
	for (int t = 0; t < 3; t++)
		for (int u = 0; u < 4; u++) {
			char name[64];
			snprintf(name, sizeof name, "rule-%u-%u", tris[t], copies[u]);
			rule_row(name, &flat, &inst);
		}
	device_close(&flat);
	device_close(&inst);
}

/* ---- Efficiency at equal time ------------------------------------------- */

/* Renders for `seconds` (or spp samples if seconds is 0); returns the
 * image (malloc'ed) and the samples per pixel done. */
static float *render_for(ajar_scene *s, ajar_integrator integ, uint32_t size, double seconds, uint32_t seed,
			 uint32_t *spp)
{
	ajar_options o;
	ajar_renderer *r;
	ajar_options_default(&o);
	o.width = o.height = size;
	o.integrator = integ;
	o.max_depth = 32;
	o.seed = seed;
	o.spp = 0;
	o.time_limit = seconds;
	check(ajar_renderer_create(s, &o, &r));
	check(ajar_renderer_render(r, NULL, NULL));
	float *img = malloc(sizeof(float) * 4 * size * size);
	check(ajar_renderer_image(r, img, NULL, NULL));
	*spp = ajar_renderer_spp(r);
	ajar_renderer_destroy(&r);
	return img;
}

/* Relative MSE of a against b: mean over pixels and channels of
 * (a - b)^2 / (b^2 + eps), eps = (0.1 mean(b))^2 so dark scenes are not
 * judged by absolute error. */
static double rel_mse(const float *a, const float *b, size_t npix, double mean_b)
{
	double sum = 0, eps = 0.01 * mean_b * mean_b;
	for (size_t i = 0; i < npix; i++)
		for (int c = 0; c < 3; c++) {
			double d = a[4 * i + c] - b[4 * i + c];
			sum += d * d / ((double)b[4 * i + c] * b[4 * i + c] + eps);
		}
	return sum / (3.0 * npix);
}

/* pt, bdpt and portal for `seconds` each against a reference of two
 * independent portal renders of ref_seconds; the reference's own noise,
 * estimated from its two halves, is subtracted. */
static void bench_equal_time(const char *path, uint32_t size, double seconds, double ref_seconds)
{
	ajar_scene *s;
	uint32_t spp1, spp2, spp;
	size_t npix = (size_t)size * size;
	check(ajar_scene_load(path, &s));
	float *r1 = render_for(s, AJAR_INTEGRATOR_PORTAL, size, ref_seconds, 1001, &spp1);
	float *r2 = render_for(s, AJAR_INTEGRATOR_PORTAL, size, ref_seconds, 1002, &spp2);
	double mean = 0;
	for (size_t i = 0; i < 4 * npix; i++) {
		r1[i] = 0.5f * (r1[i] + r2[i]);
		if (i % 4 != 3)
			mean += r1[i] / (3.0 * npix);
	}
	/* For R = (R1 + R2) / 2, E|R1 - R2|^2 / 4 is the variance of R. */
	double ref_noise = 0;
	for (size_t i = 0; i < npix; i++)
		for (int c = 0; c < 3; c++) {
			double d = 2.0 * (r2[4 * i + c] - r1[4 * i + c]); /* = R2 - R1 */
			ref_noise += d * d / 4 / ((double)r1[4 * i + c] * r1[4 * i + c] + 0.01 * mean * mean);
		}
	ref_noise /= 3.0 * npix;
	printf("%s, %ux%u, %.0f s each; reference: portal %u + %u spp, mean %.5f, its relMSE %.2e\n", path, size, size,
	       seconds, spp1, spp2, mean, ref_noise);
	static const ajar_integrator integ[] = {AJAR_INTEGRATOR_PT, AJAR_INTEGRATOR_BDPT, AJAR_INTEGRATOR_PORTAL};
	static const char *const names[] = {"pt", "bdpt", "portal"};
	double e[3];
	for (int k = 0; k < 3; k++) {
		float *img = render_for(s, integ[k], size, seconds, 7, &spp);
		e[k] = rel_mse(img, r1, npix, mean) - ref_noise;
		double m = 0;
		for (size_t i = 0; i < npix; i++)
			m += (img[4 * i] + img[4 * i + 1] + img[4 * i + 2]) / (3.0 * npix);
		printf("  %-7s %6u spp  relMSE %.3e  mean %.5f  (%+.2f%% vs reference)\n", names[k], spp, e[k], m,
		       100 * (m / mean - 1));
		free(img);
	}
	printf("  relMSE ratios at equal time: bdpt/portal %.2f, pt/portal %.2f, pt/bdpt %.2f\n", e[1] / e[2],
	       e[0] / e[2], e[0] / e[1]);
	free(r1);
	free(r2);
	ajar_scene_destroy(&s);
}

int main(int argc, char **argv)
{
	printf("Ajar %s bench (device: first CPU device; one run, compare figures within it)\n", ajar_version());
	/* AJAR_BENCH_FILES="a.gltf b.gltf": only the BVH, traversal and pt
	 * figures, for those files (tests/peers/rays.py sets it). */
	const char *files = getenv("AJAR_BENCH_FILES");
	if (files) {
		char list[4096];
		snprintf(list, sizeof list, "%s", files);
		for (char *save, *f = strtok_r(list, " ", &save); f; f = strtok_r(NULL, " ", &save))
			bench_scene(f, 1);
		return 0;
	}
	char *dir = test_tmpdir();
	if (!dir)
		return 1;
	if (getenv("AJAR_BENCH_SCENES"))
		goto equal_time;
	if (getenv("AJAR_BENCH_RULE")) {
		bench_rule(); /* the flattening rule's rows alone */
		goto done;
	}
	if (getenv("AJAR_BENCH_SCALE") && strcmp(getenv("AJAR_BENCH_SCALE"), "0")) {
		bench_scale(dir); /* AJAR_BENCH_SCALE=list: those rows alone */
		goto done;
	}
	bench_devices();
	double cold = startup(dir, 1);
	startup(dir, 0); /* fills PoCL's cache */
	double warm = startup(dir, 0);
	printf("start-up (load + compile + 1 spp at 16x16): cold %.2f s, warm %.2f s (%.1fx)\n", cold, warm,
	       cold / warm);
	bench_scene("scenes/cornell/cornell.gltf", 16);
	bench_scene("scenes/bathroom/bathroom.gltf", 4);
	bench_scale(dir);
equal_time:;
	/* Equal time: AJAR_BENCH_SECONDS per integrator (default 10), the
	 * reference 2 x 4 times as long; AJAR_BENCH_SCENES picks scenes and
	 * skips the other figures. */
	double secs = getenv("AJAR_BENCH_SECONDS") ? atof(getenv("AJAR_BENCH_SECONDS")) : 10.0;
	static const char *const scenes[] = {"scenes/window-room/window-room.gltf", "scenes/door-ajar/door-ajar.gltf",
					     "scenes/living-room/living-room.gltf", "scenes/bathroom/bathroom.gltf",
					     "scenes/cornell/cornell.gltf"};
	const char *only = getenv("AJAR_BENCH_SCENES"); /* e.g. "door-ajar,window-room" */
	for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
		const char *name = strrchr(scenes[i], '/') + 1;
		char stem[64];
		snprintf(stem, sizeof stem, "%.*s", (int)(strchr(name, '.') - name), name);
		if (!only || strstr(only, stem))
			bench_equal_time(scenes[i], 128, secs, 4 * secs);
	}
done:
	test_remove_tree(dir);
	free(dir);
	return 0;
}
