/* render.c — the renderer behind ajar_renderer_*: prepares the scene,
 * compiles the kernels on the chosen device, runs passes until the sample
 * count, the time limit or a cancel, and reduces the fixed-point film into
 * the image.
 *
 * A pass renders samples [first, first + count) of every pixel. Its size
 * adapts so a pass takes about PASS_SECONDS: progress stays smooth and a
 * stop loses at most one pass. Because samples have their own random
 * streams and the film is fixed point (kernels/film.h), the image does not
 * depend on how the samples were split into passes. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "device.h"
#include "error.h"
#include "prepare.h"
#include "scene.h"
#include "upload.h"
#include "../kernels/film.h"

#define PASS_SECONDS 0.25
#define DEFAULT_WIDTH 512

extern const char ajar_kernel_source[];

struct ajar_renderer {
	SceneData data;
	Device dev;
	cl_kernel k_render;
	SceneBuffers bufs;
	cl_uint arg_first; /* index of the render kernel's first non-scene argument */
	cl_mem accum, splat; /* fixed-point films: own pixel, and atomic splats */
	uint32_t width, height;
	uint32_t spp_done, spp_target;
	double time_limit, elapsed;
	ajar_integrator integrator;
	uint32_t seed, max_depth;
	char scene_name[256];
	atomic_int cancel;
	long *film, *film_splat; /* host copies */
};

static double seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

void ajar_options_default(ajar_options *o)
{
	memset(o, 0, sizeof *o);
	o->spp = 64;
	o->integrator = AJAR_INTEGRATOR_PT;
	o->max_depth = 64;
	o->seed = 1;
}

static ajar_status check_options(const ajar_options *o)
{
	if (o->width > 16384 || o->height > 16384 || (o->width == 0) != (o->height == 0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "image size %ux%u: both must be in 1..16384",
			       o->width, o->height);
	if (o->integrator != AJAR_INTEGRATOR_PT)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT,
			       "integrator %d is not available in this version (only pt)", (int)o->integrator);
	if (o->max_depth < 1 || o->max_depth > 1024)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "max depth %u: must be in 1..1024", o->max_depth);
	if (o->spp == 0 && !(o->time_limit > 0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "set a sample count or a time limit");
	if (o->time_limit < 0 || o->time_limit != o->time_limit)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "time limit must be positive");
	return AJAR_OK;
}

static void image_size(const Scene *s, const ajar_options *o, uint32_t *w, uint32_t *h)
{
	if (o->width) {
		*w = o->width;
		*h = o->height;
	} else if (s->width && s->height) {
		*w = s->width;
		*h = s->height;
	} else {
		float aspect = s->has_camera && s->cam_aspect > 0 ? s->cam_aspect : 1.0f;
		*w = DEFAULT_WIDTH;
		*h = (uint32_t)fmaxf(1.0f, roundf(DEFAULT_WIDTH / aspect));
	}
}

static ajar_status upload(ajar_renderer *r)
{
	Device *d = &r->dev;
	ajar_status st;
	if ((st = upload_scene(d, &r->data, &r->bufs)) != AJAR_OK ||
	    (st = upload_bind(d, r->k_render, &r->bufs, &r->arg_first)) != AJAR_OK)
		return st;
	size_t film_bytes = sizeof(cl_long) * 3 * (size_t)r->width * r->height;
	cl_long zero = 0;
	if ((st = device_buffer(d, CL_MEM_READ_WRITE, film_bytes, NULL, &r->accum)) != AJAR_OK ||
	    (st = device_buffer(d, CL_MEM_READ_WRITE, film_bytes, NULL, &r->splat)) != AJAR_OK)
		return st;
	CL_TRY(d, clEnqueueFillBuffer(d->queue, r->accum, &zero, sizeof zero, 0, film_bytes, 0, NULL, NULL));
	CL_TRY(d, clEnqueueFillBuffer(d->queue, r->splat, &zero, sizeof zero, 0, film_bytes, 0, NULL, NULL));
	CL_TRY(d, clSetKernelArg(r->k_render, r->arg_first, sizeof(cl_mem), &r->accum));
	CL_TRY(d, clSetKernelArg(r->k_render, r->arg_first + 1, sizeof(cl_mem), &r->splat));
	CL_TRY(d, clFinish(d->queue));
	return AJAR_OK;
}

ajar_status ajar_renderer_create(const ajar_scene *scene, const ajar_options *opt, ajar_renderer **out)
{
	ajar_status st;
	ajar_options defaults;
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_create: out is NULL");
	*out = NULL;
	if (!scene)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_create: scene is NULL");
	if (!opt) {
		ajar_options_default(&defaults);
		opt = &defaults;
	}
	if ((st = check_options(opt)) != AJAR_OK)
		return st;
	ajar_renderer *r = calloc(1, sizeof *r);
	if (!r)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	image_size(scene, opt, &r->width, &r->height);
	r->spp_target = opt->spp;
	r->time_limit = opt->time_limit;
	r->integrator = opt->integrator;
	r->seed = opt->seed;
	r->max_depth = opt->max_depth;
	snprintf(r->scene_name, sizeof r->scene_name, "%s", scene->source ? scene->source : "");
	PrepareOptions po = {r->width, r->height, (int)opt->integrator, opt->max_depth, opt->seed};
	if ((st = prepare_scene(scene, &po, &r->data)) != AJAR_OK)
		goto fail;

	cl_platform_id plat;
	cl_device_id id;
	uint32_t ndev;
	if ((st = device_select(opt->device, &plat, &id, 1, &ndev)) != AJAR_OK)
		goto fail;
	if ((st = device_open(&r->dev, plat, id)) != AJAR_OK)
		goto fail;
	if ((st = device_build(&r->dev, ajar_kernel_source, "-cl-std=CL1.2")) != AJAR_OK)
		goto fail;
	if ((st = device_kernel(&r->dev, "render_pass", &r->k_render)) != AJAR_OK)
		goto fail;
	if ((st = upload(r)) != AJAR_OK)
		goto fail;
	r->film = calloc(3 * (size_t)r->width * r->height, sizeof *r->film);
	r->film_splat = calloc(3 * (size_t)r->width * r->height, sizeof *r->film_splat);
	if (!r->film || !r->film_splat) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for a %ux%u image", r->width, r->height);
		goto fail;
	}
	log_msg(AJAR_LOG_INFO, "device %s: kernels %s in %.2f s", r->dev.name,
		r->dev.from_cache ? "loaded from cache" : "compiled", r->dev.build_seconds);
	*out = r;
	return AJAR_OK;
fail:
	ajar_renderer_destroy(&r);
	return st;
}

void ajar_renderer_destroy(ajar_renderer **rp)
{
	ajar_renderer *r = rp ? *rp : NULL;
	if (!r)
		return;
	upload_free(&r->bufs);
	if (r->accum)
		clReleaseMemObject(r->accum);
	if (r->splat)
		clReleaseMemObject(r->splat);
	if (r->k_render)
		clReleaseKernel(r->k_render);
	device_close(&r->dev);
	prepare_free(&r->data);
	free(r->film);
	free(r->film_splat);
	free(r);
	*rp = NULL;
}

void ajar_renderer_cancel(ajar_renderer *r)
{
	if (r)
		atomic_store(&r->cancel, 1);
}

uint32_t ajar_renderer_spp(const ajar_renderer *r) { return r ? r->spp_done : 0; }

const char *ajar_renderer_device_name(const ajar_renderer *r) { return r ? r->dev.name : ""; }

static ajar_status run_pass(ajar_renderer *r, uint32_t count)
{
	Device *d = &r->dev;
	cl_uint first = r->spp_done, n = count;
	CL_TRY(d, clSetKernelArg(r->k_render, r->arg_first + 2, sizeof first, &first));
	CL_TRY(d, clSetKernelArg(r->k_render, r->arg_first + 3, sizeof n, &n));
	size_t global = (size_t)r->width * r->height;
	CL_TRY(d, clEnqueueNDRangeKernel(d->queue, r->k_render, 1, NULL, &global, NULL, 0, NULL, NULL));
	CL_TRY(d, clFinish(d->queue));
	r->spp_done += count;
	return AJAR_OK;
}

ajar_status ajar_renderer_render(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
	ajar_status st;
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_render: renderer is NULL");
	double t0 = seconds() - r->elapsed, per_spp = 0.0;
	uint32_t count = 1;
	for (;;) {
		uint32_t left = r->spp_target ? r->spp_target - r->spp_done : UINT32_MAX;
		double time_left = r->time_limit > 0 ? r->time_limit - (seconds() - t0) : 1e30;
		if (left == 0 || time_left <= 0)
			break;
		if (atomic_load(&r->cancel))
			return err_set(AJAR_ERROR_CANCELLED, "render cancelled after %u samples per pixel",
				       r->spp_done);
		if (per_spp > 0) {
			double want = fmin(PASS_SECONDS, time_left) / per_spp;
			count = (uint32_t)fmax(1.0, fmin(want, 1e6));
		}
		if (count > left)
			count = left;
		double tp = seconds();
		if ((st = run_pass(r, count)) != AJAR_OK)
			return st;
		per_spp = (seconds() - tp) / count;
		r->elapsed = seconds() - t0;
		if (fn) {
			ajar_progress p;
			memset(&p, 0, sizeof p);
			p.spp_done = r->spp_done;
			p.spp_target = r->spp_target;
			p.samples_done = (uint64_t)r->spp_done * r->width * r->height;
			p.elapsed = r->elapsed;
			p.samples_per_second = r->elapsed > 0 ? p.samples_done / r->elapsed : 0;
			if (r->spp_target) {
				p.fraction = (double)r->spp_done / r->spp_target;
				p.eta = per_spp * (r->spp_target - r->spp_done);
			} else {
				p.fraction = fmin(1.0, r->elapsed / r->time_limit);
				p.eta = fmax(0.0, r->time_limit - r->elapsed);
			}
			if (r->time_limit > 0 && r->spp_target)
				p.eta = fmin(p.eta, fmax(0.0, r->time_limit - r->elapsed));
			if (fn(&p, user))
				ajar_renderer_cancel(r);
		}
	}
	return AJAR_OK;
}

ajar_status ajar_renderer_image(ajar_renderer *r, float *rgba, uint32_t *width, uint32_t *height)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_image: renderer is NULL");
	if (width)
		*width = r->width;
	if (height)
		*height = r->height;
	if (!rgba)
		return AJAR_OK;
	size_t npix = (size_t)r->width * r->height;
	CL_TRY(&r->dev, clEnqueueReadBuffer(r->dev.queue, r->accum, CL_TRUE, 0, sizeof(cl_long) * 3 * npix,
					    r->film, 0, NULL, NULL));
	CL_TRY(&r->dev, clEnqueueReadBuffer(r->dev.queue, r->splat, CL_TRUE, 0, sizeof(cl_long) * 3 * npix,
					    r->film_splat, 0, NULL, NULL));
	double scale = r->spp_done ? 1.0 / ((double)FILM_SCALE * r->spp_done) : 0.0;
	for (size_t i = 0; i < npix; i++) {
		for (int c = 0; c < 3; c++)
			rgba[4 * i + c] = (float)((double)(r->film[3 * i + c] + r->film_splat[3 * i + c]) * scale);
		rgba[4 * i + 3] = 1.0f;
	}
	return AJAR_OK;
}

static const char *integrator_name(ajar_integrator i)
{
	return i == AJAR_INTEGRATOR_BDPT ? "bdpt" : i == AJAR_INTEGRATOR_PORTAL ? "portal" : "pt";
}

static ajar_status read_image(ajar_renderer *r, float **rgba)
{
	*rgba = malloc(sizeof(float) * 4 * (size_t)r->width * r->height);
	if (!*rgba)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the image");
	ajar_status st = ajar_renderer_image(r, *rgba, NULL, NULL);
	if (st != AJAR_OK)
		free(*rgba);
	return st;
}

ajar_status ajar_renderer_write_exr(ajar_renderer *r, const char *path)
{
	float *rgba;
	ajar_status st;
	char spp[32], seed[32], depth[32], secs[32];
	if (!r || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_exr: NULL argument");
	if ((st = read_image(r, &rgba)) != AJAR_OK)
		return st;
	snprintf(spp, sizeof spp, "%u", r->spp_done);
	snprintf(seed, sizeof seed, "%u", r->seed);
	snprintf(depth, sizeof depth, "%u", r->max_depth);
	snprintf(secs, sizeof secs, "%.3f", r->elapsed);
	const char *attrs[] = {"ajar:spp", spp, "ajar:integrator", integrator_name(r->integrator),
			       "ajar:seed", seed, "ajar:max_depth", depth, "ajar:render_seconds", secs,
			       "ajar:device", r->dev.name, "ajar:scene", r->scene_name,
			       "ajar:version", AJAR_VERSION_STRING};
	st = ajar_write_exr(path, rgba, r->width, r->height, attrs, sizeof attrs / sizeof attrs[0] / 2);
	free(rgba);
	return st;
}

ajar_status ajar_renderer_write_png(ajar_renderer *r, const char *path)
{
	float *rgba;
	ajar_status st;
	if (!r || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_png: NULL argument");
	if ((st = read_image(r, &rgba)) != AJAR_OK)
		return st;
	st = ajar_write_png(path, rgba, r->width, r->height);
	free(rgba);
	return st;
}

ajar_status ajar_devices(ajar_device_info *out, uint32_t capacity, uint32_t *count)
{
	return device_list(out, capacity, count);
}
