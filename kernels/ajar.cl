/* ajar.cl — the kernel entry points; everything else is in the headers,
 * which the host also compiles for its tests. */
#include "film/aov.h"
#include "film/film.h"
#include "base/layout.h"
#include "integrator/portal.h"
#include "integrator/pt.h"

#define AJAR_KERNEL_ARG(type, name) __global const type *name,
#define AJAR_VIEW_INIT(type, name) sc.name = name;

/* Work unit u = unit_first + global id is pixel u % npix, lane u / npix
 * of `lanes`: it renders the samples sample_first + lane + i lanes of
 * [sample_first, sample_first + count) of that pixel, added in fixed point
 * to accum (3 longs per pixel; with one lane the pixel is owned by this
 * work-item, so no atomics; with more, 64-bit atomic adds, which give the
 * same integers in any order). Light paths that reach the
 * camera (t = 1) land in other pixels: they go to `splat` with 64-bit
 * atomic adds. The host divides both by the samples per pixel. When
 * Params.strategy_len > 0, bdpt's per-strategy layers follow the splat
 * image in the same buffer. With aov_at > 0, every sample also adds its
 * first-hit outputs (AOV_CHANNELS longs per pixel, aov.h) to the AOV film
 * at splat + aov_at, after the layers; the pixel owns them, as in accum. */
__kernel void render_pass(AJAR_SCENE_BUFFERS(AJAR_KERNEL_ARG) __global long *accum,
			  __global long *splat, uint sample_first, uint sample_count, ulong aov_at,
			  __global uint *scratch, uint lanes, uint unit_first)
{
	SceneView sc;
	AJAR_SCENE_BUFFERS(AJAR_VIEW_INIT)
	GLOBAL const Camera *cam = &params->camera;
	uint npix = (uint)(cam->width * cam->height);
	uint unit = unit_first + (uint)get_global_id(0);
	if (unit >= npix * lanes)
		return;
	uint pixel = unit % npix, lane = unit / npix;
	float x = (float)(pixel % (uint)cam->width), y = (float)(pixel / (uint)cam->width);
	long sum[3] = {0, 0, 0};
	long aov_sum[AOV_CHANNELS];
	for (int c = 0; c < AOV_CHANNELS; c++)
		aov_sum[c] = 0;
#ifdef AJAR_SUBPATH_SOA
	/* This work-item's column of the scratch buffer (vertex.h): the eye
	 * subpath has one slot more, for the next-event vertex (VNEE). */
	VRef light = scratch + get_global_id(0), eye = VAT(light, SUBPATH_MAX), back = VAT(eye, SUBPATH_MAX + 1),
	     fwd = VAT(back, SUBPATH_MAX);
#else
	PathVertex light[SUBPATH_MAX], eye[SUBPATH_MAX], back[SUBPATH_MAX], fwd[SUBPATH_MAX];
#endif
	for (uint i = lane; i < sample_count; i += lanes) {
		float qmc[RNG_QMC_FLOATS];
		rng_qmc_table(params->seed, pixel, sample_first + i, qmc);
		Rng rng = rng_init_pixel(params->seed, pixel, sample_first + i, qmc);
		float jx, jy;
		rng_pixel(&rng, &jx, &jy);
		V3 L;
		if (PARAMS_INTEGRATOR(params) != INTEGRATOR_PT) {
			BdptFilm out = {splat, splat + 3 * (ulong)cam->width * cam->height, pixel,
					v3(0.0f, 0.0f, 0.0f)};
			if (PARAMS_INTEGRATOR(params) == INTEGRATOR_PORTAL)
				portal_sample_pixel(&sc, x + jx, y + jy, light, eye, back, fwd, &out, &rng);
			else
				bdpt_sample(&sc, x + jx, y + jy, light, eye, &out, &rng);
			L = out.L;
		} else {
			L = pt_radiance(&sc, cam->pos, camera_ray_dir(cam, x + jx, y + jy), &rng);
		}
		sum[0] += film_fixed(L.x, rng_pcg_f(&rng));
		sum[1] += film_fixed(L.y, rng_pcg_f(&rng));
		sum[2] += film_fixed(L.z, rng_pcg_f(&rng));
		if (aov_at)
			aov_sample(&sc, cam->pos, camera_ray_dir(cam, x + jx, y + jy), L, pixel, sample_first + i,
				   aov_sum);
	}
	if (lanes > 1) {
		for (int c = 0; c < 3; c++)
			atom_add(&accum[3 * pixel + c], sum[c]);
		if (aov_at)
			for (int c = 0; c < AOV_CHANNELS; c++)
				atom_add(&splat[aov_at + AOV_CHANNELS * (ulong)pixel + c], aov_sum[c]);
		return;
	}
	accum[3 * pixel + 0] += sum[0];
	accum[3 * pixel + 1] += sum[1];
	accum[3 * pixel + 2] += sum[2];
	if (aov_at)
		for (int c = 0; c < AOV_CHANNELS; c++)
			splat[aov_at + AOV_CHANNELS * (ulong)pixel + c] += aov_sum[c];
}

/* Sizes and offsets of the shared structs as this compiler lays them out. */
#define AJAR_PROBE_SIZE(type, size) out[n++] = (uint)sizeof(type);
#define AJAR_PROBE_FIELD(type, field) out[n++] = (uint)__builtin_offsetof(type, field);
__kernel void layout_probe(__global uint *out)
{
	uint n = 0;
	AJAR_LAYOUT_TYPES(AJAR_PROBE_SIZE)
	AJAR_LAYOUT_FIELDS(AJAR_PROBE_FIELD)
}

/* sample_cdf as this device compiles it (on a CPU with AVX its vector
 * count, sampling.h), for tests/render/test_device_cdf.c: draw i takes u[i]
 * and writes its bucket, probability and remapped u to out[3i .. 3i+2]. */
__kernel void cdf_probe(__global const float *cdf, int n, __global const float *u, __global float *out, uint count)
{
	uint i = (uint)get_global_id(0);
	if (i >= count)
		return;
	float pdf, ur;
	int k = sample_cdf(cdf, n, u[i], &pdf, &ur);
	out[3 * i] = (float)k;
	out[3 * i + 1] = pdf;
	out[3 * i + 2] = ur;
}

/* Closest-hit traversal alone, for the throughput benchmark: ray i is
 * rays[6i .. 6i+5] (origin, direction); hits[i] gets the triangle or -1. */
__kernel void trace_closest(AJAR_SCENE_BUFFERS(AJAR_KERNEL_ARG) __global const float *rays,
			    __global int *hits, uint count)
{
	SceneView sc;
	AJAR_SCENE_BUFFERS(AJAR_VIEW_INIT)
	uint i = (uint)get_global_id(0);
	if (i >= count)
		return;
	GLOBAL const float *r = rays + 6 * i;
	Hit h;
	hits[i] = bvh_intersect(&sc, v3(r[0], r[1], r[2]), v3(r[3], r[4], r[5]), AJAR_INF, &h) ? h.tri : -1;
}
