/* bench.c — `make bench`: the figures the design asks for, per scene:
 * BVH build time and memory, closest-hit traversal throughput on incoherent
 * rays (dedicated kernel), path-tracing samples per second, and the cold and
 * warm start-up time of the CLI (a cold start has neither Ajar's nor PoCL's
 * kernel cache). Speeds vary between runs on shared machines; compare
 * figures from one run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ajar.h"
#include "device.h"
#include "prepare.h"
#include "scene.h"
#include "upload.h"

extern const char ajar_kernel_source[];

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
static double traversal_mrays(const SceneData *sd, Device *d)
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
	double best = 1e30;
	for (int rep = 0; rep < 3; rep++) { /* the first run includes PoCL's work-group compile */
		double t0 = now();
		clEnqueueNDRangeKernel(d->queue, k, 1, NULL, &global, NULL, 0, NULL, NULL);
		clFinish(d->queue);
		double t = now() - t0;
		if (rep > 0 && t < best)
			best = t;
	}
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
	PrepareOptions po = {64, 64, 0, 64, 1, 0, 0, 0, 0};
	check(prepare_scene(s, &po, &sd));
	check(device_select(NULL, &plat, &id, 1, &ndev));
	check(device_open(&d, plat, id));
	check(device_build(&d, ajar_kernel_source, "-cl-std=CL1.2"));
	double mrays = traversal_mrays(&sd, &d);
	double msps = pt_msamples(s, 256, spp);
	printf("%-34s %9u tris  load %6.2f s  BVH build %6.3f s  %7.1f MiB  %5u nodes/k-tri  "
	       "traversal %6.2f Mrays/s  pt %6.3f Msamples/s\n",
	       path, s->ntris, load, sd.bvh_seconds, bvh_memory(&sd.bvh) / 1048576.0,
	       (unsigned)(1000.0 * sd.bvh.nnodes / s->ntris), mrays, msps);
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

int main(int argc, char **argv)
{
	char dir[] = "/tmp/ajar-bench-XXXXXX";
	if (!mkdtemp(dir))
		return 1;
	printf("Ajar %s bench (device: first CPU device; one run, compare figures within it)\n", ajar_version());
	bench_devices();
	double cold = startup(dir, 1);
	startup(dir, 0); /* fills PoCL's cache */
	double warm = startup(dir, 0);
	printf("start-up (load + compile + 1 spp at 16x16): cold %.2f s, warm %.2f s (%.1fx)\n", cold, warm,
	       cold / warm);
	bench_scene("scenes/cornell/cornell.gltf", 16);
	bench_scene("scenes/bathroom/bathroom.gltf", 4);
	char rm[128];
	snprintf(rm, sizeof rm, "rm -rf %s", dir);
	return system(rm) != 0;
}
