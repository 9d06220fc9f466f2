/* render_device.c — a renderer's devices. Each has its own context, queue,
 * program, scene buffers and films (render_film.h); a pass renders samples
 * [first, first + count) of every pixel into them. The faults that tests
 * inject (render_overrides.h) fail a chosen pass here, at launch or after
 * the kernel ran. */
#include "render/render_device.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/env_vars.h"
#include "core/error.h"
#include "device/device_build.h"
#include "device/kernel_source.h"
#include "render/render_film.h"
#include "render/render_overrides.h"

/* An explicit work-group size, measured on PoCL 3.1's CPU device (2
 * cores, 128x128 path tracing, first pass = PoCL's cold work-group
 * compile + 1 spp; Msamples/s over 16 spp; two runs each):
 *   local    cornell: first pass, speed    bathroom: first pass, speed
 *   1        0.63/0.61 s, 1.69/1.77        0.71/0.74 s, 0.35/0.25
 *   8        0.61/0.68 s, 1.74/1.57        0.73/0.70 s, 0.34/0.38
 *   64       0.63/0.68 s, 1.69/1.56        0.81/0.69 s, 0.33/0.38
 *   NULL     crashes (SIGSEGV in PoCL's work-group function) at 128x128
 *            and 256x256: PoCL picks 4096 work-items per group.
 * On the CPU the choice is within noise; 64 is a multiple of every GPU's
 * SIMD width, capped by what the compiled kernel allows. */
static ajar_status work_group_size(RenderDevice *rd)
{
	Device *d = &rd->dev;
	size_t max_local = 0;
	CL_TRY(d, clGetKernelWorkGroupInfo(rd->k_render, d->id, CL_KERNEL_WORK_GROUP_SIZE, sizeof max_local,
					   &max_local, NULL));
	for (rd->local = 64; rd->local > 1 && rd->local > max_local; rd->local /= 2)
		;
	if (rd->plan.soa && rd->plan.capacity % rd->local)
		rd->plan.capacity -= rd->plan.capacity % rd->local; /* whole groups; the stride is the built one */
	if (rd->plan.soa && rd->plan.capacity == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "device %s: subpath capacity below the work-group size %zu",
			       d->name, rd->local);
	return AJAR_OK;
}

/* Context, program, scene and films on one device. */
static ajar_status device_setup(ajar_renderer *r, RenderDevice *rd, cl_platform_id plat, cl_device_id id)
{
	Device *d = &rd->dev;
	ajar_status st;
	cl_long zero = 0;
	size_t bytes = film_bytes(r), sbytes = film_splat_bytes(r);
	/* One program per integrator (see PARAMS_INTEGRATOR), built with
	 * device_build_options and what AJAR_CL_OPTIONS adds (src/device/README.md, "Build options"). */
	const char *extra = env_var(ENV_VAR_CL_OPTIONS);
	char options[768]; /* KERNEL_OPTIONS, the plan's, the -DAJAR_NO_* and 400 of AJAR_CL_OPTIONS */
	if (extra && strlen(extra) > 400)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "AJAR_CL_OPTIONS is %zu characters long; at most 400",
			       strlen(extra));
	if ((st = device_open(d, plat, id)) != AJAR_OK)
		return st;
	if ((st = device_plan(d, r->data.params->integrator, (size_t)r->width * r->height, &rd->plan)) != AJAR_OK)
		return st;
	rd->plan.omit = r->data.kernel_omit; /* features the scene lacks: a specialised program */
	rd->plan.sky_res = r->data.sky_res;
	device_render_options(d, r->data.params->integrator, &rd->plan, extra, options, sizeof options);
	if ((st = device_build(d, ajar_kernel_source, options)) != AJAR_OK) {
		char *why = extra && extra[0] ? strdup(ajar_last_error()) : NULL;
		if (why) {
			for (size_t n = strlen(why); n > 0 && (why[n - 1] == '\n' || why[n - 1] == ' '); n--)
				why[n - 1] = '\0';
			err_set(st, "%s\n(the build options included AJAR_CL_OPTIONS='%s')", why, extra);
		}
		free(why);
		return st;
	}
	/* The scene's arrays, the films and the scratch, all known before one is made. */
	size_t sizes[AJAR_MAX_BUFFERS + 3];
	int nsizes = 0;
#define AJAR_SIZE(type, name) sizes[nsizes++] = sizeof(type) * r->data.n_##name;
	AJAR_SCENE_BUFFERS(AJAR_SIZE)
#undef AJAR_SIZE
	sizes[nsizes++] = bytes;
	sizes[nsizes++] = sbytes;
	sizes[nsizes++] = rd->plan.soa ? rd->plan.scratch_bytes : 4;
	char what[96];
	snprintf(what, sizeof what, "the scene and the films of a %ux%u image", r->width, r->height);
	if ((st = device_reserve(d, sizes, nsizes, what)) != AJAR_OK)
		return st;
	if ((st = device_kernel(d, "render_pass", &rd->k_render)) != AJAR_OK ||
	    (st = upload_scene(d, &r->data, &rd->bufs)) != AJAR_OK ||
	    (st = upload_bind(d, rd->k_render, &rd->bufs, &rd->arg_first)) != AJAR_OK ||
	    (st = device_buffer(d, CL_MEM_READ_WRITE, bytes, NULL, &rd->accum)) != AJAR_OK ||
	    (st = device_buffer(d, CL_MEM_READ_WRITE, sbytes, NULL, &rd->splat)) != AJAR_OK ||
	    (st = device_buffer(d, CL_MEM_READ_WRITE, rd->plan.soa ? rd->plan.scratch_bytes : 4, NULL, &rd->scratch)) !=
		    AJAR_OK)
		return st;
	CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->accum, &zero, sizeof zero, 0, bytes, 0, NULL, NULL));
	CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->splat, &zero, sizeof zero, 0, sbytes, 0, NULL, NULL));
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first, sizeof(cl_mem), &rd->accum));
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first + 1, sizeof(cl_mem), &rd->splat));
	/* The AOV film: the same buffer, after the layers (the kernel adds aov_at). */
	cl_ulong aov_at = r->opt.aov ? film_aov_offset(r) : 0;
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first + 4, sizeof aov_at, &aov_at));
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first + 5, sizeof(cl_mem), &rd->scratch));
	CL_TRY(d, clFinish(d->queue));
	if ((st = work_group_size(rd)) != AJAR_OK)
		return st;
	if (rd->plan.soa || rd->plan.lanes > 1)
		log_msg(AJAR_LOG_INFO, "device %s: subpaths %s, %u work-items a pixel, at most %zu a launch", d->name,
			rd->plan.soa ? "in global memory" : "private", rd->plan.lanes,
			rd->plan.soa ? rd->plan.capacity : (size_t)r->width * r->height * rd->plan.lanes);
	log_msg(AJAR_LOG_INFO, "device %s (%s): kernels %s in %.2f s", d->name, d->selector,
		d->from_cache ? "loaded from cache" : "compiled", d->build_seconds);
	return AJAR_OK;
}

void render_device_close(RenderDevice *rd)
{
	upload_free(&rd->bufs);
	if (rd->accum)
		clReleaseMemObject(rd->accum);
	if (rd->splat)
		clReleaseMemObject(rd->splat);
	if (rd->scratch)
		clReleaseMemObject(rd->scratch);
	if (rd->k_render)
		clReleaseKernel(rd->k_render);
	device_close(&rd->dev);
	free(rd->done.r);
	memset(rd, 0, sizeof *rd);
}

ajar_status render_devices_open(ajar_renderer *r, const char *selector)
{
	cl_platform_id plats[MAX_RENDER_DEVICES];
	cl_device_id ids[MAX_RENDER_DEVICES];
	uint32_t n;
	ajar_status st;
	if ((st = device_select(selector, plats, ids, MAX_RENDER_DEVICES, &n)) != AJAR_OK)
		return st;
	r->devs = calloc(n, sizeof *r->devs);
	if (!r->devs)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	for (uint32_t i = 0; i < n; i++) {
		RenderDevice *rd = &r->devs[r->ndev];
		if ((st = device_setup(r, rd, plats[i], ids[i])) != AJAR_OK) {
			if (n > 1)
				log_msg(AJAR_LOG_WARNING, "device %s left out: %s", rd->dev.name[0] ? rd->dev.name : "?",
					ajar_last_error());
			render_device_close(rd);
			continue;
		}
		rd->r = r;
		rd->alive = 1;
		size_t len = strlen(r->device_names);
		if (n == 1)
			snprintf(r->device_names, sizeof r->device_names, "%s", rd->dev.name);
		else
			snprintf(r->device_names + len, sizeof r->device_names - len, "%s%s (%s)",
				 r->ndev ? " + " : "", rd->dev.name, rd->dev.selector);
		r->ndev++;
	}
	if (r->ndev == 0)
		return st; /* the last device's error, already set */
	return AJAR_OK;
}

ajar_status render_device_reset(RenderDevice *rd)
{
	ajar_renderer *r = rd->r;
	Device *d = &rd->dev;
	cl_long zero = 0;
	cl_mem params = rd->bufs.mem[rd->bufs.count - 1]; /* last in AJAR_SCENE_BUFFERS */
	CL_TRY(d, clEnqueueWriteBuffer(d->queue, params, CL_TRUE, 0, sizeof(Params), r->data.params, 0, NULL, NULL));
	CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->accum, &zero, sizeof zero, 0, film_bytes(r), 0, NULL, NULL));
	CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->splat, &zero, sizeof zero, 0, film_splat_bytes(r), 0, NULL, NULL));
	CL_TRY(d, clFinish(d->queue));
	return AJAR_OK;
}

/* The message of a failed call, kept on the device (not err_set: that is
 * per thread and would log an error for what may only be a warning). */
static int pass_failed(RenderDevice *rd, const char *what, cl_int err)
{
	snprintf(rd->error, sizeof rd->error, "%s failed: %s (%d)", what, cl_error_name(err), (int)err);
	return 0;
}

int render_device_pass(RenderDevice *rd, Range g, int *film_ok)
{
	ajar_renderer *r = rd->r;
	Device *d = &rd->dev;
	cl_uint first = g.first, n = g.count;
	cl_int err;
	uint32_t index = (uint32_t)(rd - r->devs);
	int inject = ++rd->passes == render_faults.pass && index == render_faults.device;
	*film_ok = 1;
	if ((err = clSetKernelArg(rd->k_render, rd->arg_first + 2, sizeof first, &first)) != CL_SUCCESS ||
	    (err = clSetKernelArg(rd->k_render, rd->arg_first + 3, sizeof n, &n)) != CL_SUCCESS)
		return pass_failed(rd, "clSetKernelArg", err);
	size_t npix = (size_t)r->width * r->height;
	/* Work units: pixel x lane (no more lanes than samples); with the
	 * scratch, launches of at most its capacity (device_plan). */
	cl_uint lanes = rd->plan.lanes < n ? rd->plan.lanes : n;
	size_t units = npix * lanes, step = rd->plan.soa ? rd->plan.capacity : units;
	if (inject && !render_faults.lost)
		return pass_failed(rd, "clEnqueueNDRangeKernel (an injected fault)", CL_OUT_OF_RESOURCES);
	if ((err = clSetKernelArg(rd->k_render, rd->arg_first + 6, sizeof lanes, &lanes)) != CL_SUCCESS)
		return pass_failed(rd, "clSetKernelArg", err);
	for (size_t u0 = 0; u0 < units; u0 += step) {
		cl_uint unit_first = (cl_uint)u0;
		size_t todo = units - u0 < step ? units - u0 : step;
		size_t global = (todo + rd->local - 1) / rd->local * rd->local; /* the kernel skips the excess */
		if ((err = clSetKernelArg(rd->k_render, rd->arg_first + 7, sizeof unit_first, &unit_first)) !=
			    CL_SUCCESS ||
		    (err = clEnqueueNDRangeKernel(d->queue, rd->k_render, 1, NULL, &global, &rd->local, 0, NULL, NULL)) !=
			    CL_SUCCESS)
			return pass_failed(rd, "clEnqueueNDRangeKernel", err);
	}
	err = clFinish(d->queue);
	if (err == CL_SUCCESS && inject)
		err = CL_DEVICE_NOT_AVAILABLE;
	if (err != CL_SUCCESS) {
		*film_ok = 0;
		return pass_failed(rd, inject ? "clFinish (an injected fault)" : "clFinish", err);
	}
	return 1;
}
