/* ajar.cl — the kernel entry points; everything else is in the headers,
 * which the host also compiles for its tests. */
#include "aov.h"
#include "film.h"
#include "layout.h"
#include "portal.h"
#include "pt.h"

#define AJAR_KERNEL_ARG(type, name) __global const type *name,
#define AJAR_VIEW_INIT(type, name) sc.name = name;

/* One work-item per pixel: samples [sample_first, sample_first + count) of
 * that pixel, added in fixed point to accum (3 longs per pixel; the pixel
 * is owned by this work-item, so no atomics). Light paths that reach the
 * camera (t = 1) land in other pixels: they go to `splat` with 64-bit
 * atomic adds. The host divides both by the samples per pixel. When
 * Params.strategy_len > 0, bdpt's per-strategy layers follow the splat
 * image in the same buffer. With aov_at > 0, every sample also adds its
 * first-hit outputs (AOV_CHANNELS longs per pixel, aov.h) to the AOV film
 * at splat + aov_at, after the layers; the pixel owns them, as in accum. */
__kernel void render_pass(AJAR_SCENE_BUFFERS(AJAR_KERNEL_ARG) __global long *accum,
			  __global long *splat, uint sample_first, uint sample_count, ulong aov_at)
{
	SceneView sc;
	AJAR_SCENE_BUFFERS(AJAR_VIEW_INIT)
	GLOBAL const Camera *cam = &params->camera;
	uint pixel = (uint)get_global_id(0);
	if (pixel >= (uint)(cam->width * cam->height))
		return;
	float x = (float)(pixel % (uint)cam->width), y = (float)(pixel / (uint)cam->width);
	long sum[3] = {0, 0, 0};
	long aov_sum[AOV_CHANNELS];
	for (int c = 0; c < AOV_CHANNELS; c++)
		aov_sum[c] = 0;
	PathVertex light[SUBPATH_MAX], eye[SUBPATH_MAX], back[SUBPATH_MAX], fwd[SUBPATH_MAX];
	for (uint i = 0; i < sample_count; i++) {
		Rng rng = rng_init_pixel(params->seed, pixel, sample_first + i);
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
