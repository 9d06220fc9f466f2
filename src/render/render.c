/* render.c — the renderer behind ajar_renderer_*: prepares the scene,
 * compiles the kernels on every chosen device, deals sample ranges to the
 * devices until the sample count, the time limit or a cancel, and reduces
 * their fixed-point films into the image.
 *
 * A pass renders samples [first, first + count) of every pixel on one
 * device. Each device has its own context, queue, buffers, program and host
 * thread; a scheduler under one lock hands each idle device the next range,
 * sized so the pass takes about PASS_SECONDS at that device's measured speed
 * (the first pass is one sample: it also pays PoCL's work-group compile).
 * Near the end of a fixed-count render the rest is split in proportion to
 * the devices' speeds, so no device holds the render back by more than one
 * pass. Because every sample index has its own random stream and the film
 * is 64-bit fixed point (kernels/film/film.h), integer sums do not depend on
 * which device rendered a sample nor on how the ranges were split: on
 * identical devices the image is bit-identical to a one-device render.
 *
 * A device whose pass fails is dropped; its range goes back to the pool. If
 * the failure came before its kernel could run (argument or launch error),
 * its film still holds exactly its completed ranges and is read back into
 * `salvage`; otherwise the film is untrusted and its completed ranges are
 * re-rendered by the others. Every range covers all pixels, so the image is
 * always the exact mean of the sample indices it holds.
 *
 * The scheduler is in render_scheduler.c, checkpoints in
 * render_checkpoint.c, several machines in render_job.c; the state they
 * share is in render_internal.h. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/checkpoint_file.h"
#include "render/cluster.h"
#include "device/device_build.h"
#include "device/device_plan.h"
#include "core/env_vars.h"
#include "core/error.h"
#include "image/exr.h"
#include "device/kernel_source.h"
#include "prepare/prepare.h"
#include "scene/scene.h"
#include "render/render_info.h"
#include "render/render_internal.h"
#include "render/render_options.h"
#include "render/render_overrides.h"
#include "device/upload.h"
#include "film/aov_layout.h"
#include "base/compat.h"
#include "film/film.h"
#include "mis/strategies.h"

#define DEFAULT_WIDTH 512

/* Faults tests inject (render_overrides.h); none in the product. */
RenderFaults render_faults;

double render_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Appends g, merging with the last range when they touch; 0 if out of memory. */
int range_list_push(RangeList *l, Range g)
{
	if (l->n && l->r[l->n - 1].first + l->r[l->n - 1].count == g.first) {
		l->r[l->n - 1].count += g.count;
		return 1;
	}
	if (l->n == l->cap) {
		size_t cap = l->cap ? 2 * l->cap : 16;
		Range *p = realloc(l->r, cap * sizeof *p);
		if (!p)
			return 0;
		l->r = p;
		l->cap = cap;
	}
	l->r[l->n++] = g;
	return 1;
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

static size_t film_bytes(const ajar_renderer *r)
{
	return sizeof(cl_long) * 3 * (size_t)r->width * r->height;
}

/* Longs before the AOV film in the splat buffer: the splats and layers. */
size_t render_aov_offset(const ajar_renderer *r) { return 3 * (size_t)r->width * r->height * (1 + (size_t)r->nlayers); }

/* The splat film, followed by bdpt's per-strategy layers if asked for and
 * the first-hit AOVs (aov.h) if asked for: own-pixel sums, but kept here
 * so every path that reads, salvages, sums and checkpoints films has them. */
size_t render_splat_count(const ajar_renderer *r)
{
	return render_aov_offset(r) + (r->opt.aov ? (size_t)AOV_CHANNELS * r->width * r->height : 0);
}

static size_t splat_bytes(const ajar_renderer *r) { return sizeof(cl_long) * render_splat_count(r); }

/* Context, program, scene and films on one device. */
static ajar_status device_setup(ajar_renderer *r, RenderDevice *rd, cl_platform_id plat, cl_device_id id)
{
	Device *d = &rd->dev;
	ajar_status st;
	cl_long zero = 0;
	size_t bytes = film_bytes(r), sbytes = splat_bytes(r);
	/* One program per integrator (see PARAMS_INTEGRATOR), built with
	 * device_build_options and what AJAR_CL_OPTIONS adds (kernels/gpu.md, "On GPUs"). */
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
	cl_ulong aov_at = r->opt.aov ? render_aov_offset(r) : 0;
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first + 4, sizeof aov_at, &aov_at));
	CL_TRY(d, clSetKernelArg(rd->k_render, rd->arg_first + 5, sizeof(cl_mem), &rd->scratch));
	CL_TRY(d, clFinish(d->queue));
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
	if (rd->plan.soa || rd->plan.lanes > 1)
		log_msg(AJAR_LOG_INFO, "device %s: subpaths %s, %u work-items a pixel, at most %zu a launch", d->name,
			rd->plan.soa ? "in global memory" : "private", rd->plan.lanes,
			rd->plan.soa ? rd->plan.capacity : (size_t)r->width * r->height * rd->plan.lanes);
	log_msg(AJAR_LOG_INFO, "device %s (%s): kernels %s in %.2f s", d->name, d->selector,
		d->from_cache ? "loaded from cache" : "compiled", d->build_seconds);
	return AJAR_OK;
}

static void device_teardown(RenderDevice *rd)
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

/* Opens every selected device. With several, one that cannot be set up is
 * dropped with a warning; with none left, the last error stands. */
static ajar_status open_devices(ajar_renderer *r, const char *selector)
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
			device_teardown(rd);
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

/* ajar_renderer_create, and ajar_renderer_resume with the checkpoint c read
 * from `path`: refused after the scene is prepared (its hash), before any
 * kernel is built; applied once the films exist. */
ajar_status renderer_new(const ajar_scene *scene, const ajar_options *opt, const PolicyOverrides *over,
			 Checkpoint *ck, const char *ck_path, ajar_renderer **out)
{
	ajar_status st;
	ajar_options defaults, resolved;
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_create: out is NULL");
	*out = NULL;
	if (!scene)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_create: scene is NULL");
	if (!opt) {
		ajar_options_default(&defaults);
		opt = &defaults;
	}
	if ((st = options_resolve(opt, &resolved)) != AJAR_OK)
		return st;
	opt = &resolved;
	ajar_renderer *r = calloc(1, sizeof *r);
	if (!r)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	pthread_mutex_init(&r->lock, NULL);
	pthread_cond_init(&r->cond, NULL);
	image_size(scene, opt, &r->width, &r->height);
	r->spp_target = opt->spp;
	r->time_limit = opt->time_limit;
	r->integrator = opt->integrator;
	r->seed = opt->seed;
	r->max_depth = opt->max_depth;
	r->nlayers = opt->strategy_len ? bdpt_layer_count((int)opt->strategy_len) : 0;
	if (opt->strategy_len && opt->integrator == AJAR_INTEGRATOR_PORTAL)
		r->nlayers += portal_layer_count((int)opt->strategy_len);
	r->strategy_unweighted = opt->strategy_unweighted;
	r->strategy_len = (int)opt->strategy_len;
	r->opt = *opt;
	r->opt.device = NULL;
	r->opt.width = r->width;
	r->opt.height = r->height;
	snprintf(r->scene_name, sizeof r->scene_name, "%s", scene->source ? scene->source : "");
	if ((st = prepare_scene(scene, opt, r->width, r->height, over, &r->data)) != AJAR_OK)
		goto fail;
	if (ck && (st = render_checkpoint_check(r, ck, ck_path)) != AJAR_OK)
		goto fail;
	if ((st = open_devices(r, opt->device)) != AJAR_OK)
		goto fail;
	r->film = calloc(3 * (size_t)r->width * r->height, sizeof *r->film);
	r->film_splat = calloc(render_splat_count(r), sizeof *r->film_splat);
	if (!r->film || !r->film_splat) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for a %ux%u image", r->width, r->height);
		goto fail;
	}
	if (ck && (st = render_checkpoint_apply(r, ck, ck_path)) != AJAR_OK)
		goto fail;
	if ((st = job_join(r, AJAR_OK)) != AJAR_OK)
		goto joined;
	*out = r;
	return AJAR_OK;
fail:
	st = job_join(r, st); /* the other ranks learn of it, and this rank of theirs */
joined:
	ajar_renderer_destroy(&r);
	return st;
}

ajar_status ajar_renderer_create(const ajar_scene *scene, const ajar_options *opt, ajar_renderer **out)
{
	return renderer_new(scene, opt, NULL, NULL, NULL, out);
}

ajar_status renderer_create_overridden(const ajar_scene *scene, const ajar_options *opt,
				       const PolicyOverrides *over, ajar_renderer **out)
{
	return renderer_new(scene, opt, over, NULL, NULL, out);
}

void ajar_renderer_destroy(ajar_renderer **rp)
{
	ajar_renderer *r = rp ? *rp : NULL;
	if (!r)
		return;
	for (uint32_t i = 0; i < r->ndev; i++)
		device_teardown(&r->devs[i]);
	free(r->devs);
	prepare_free(&r->data);
	free(r->film);
	free(r->film_splat);
	free(r->salvage);
	free(r->salvage_splat);
	free(r->remote);
	free(r->remote_splat);
	free(r->holes.r);
	free(r->base.r);
	free(r->ckpt_path);
	pthread_cond_destroy(&r->cond);
	pthread_mutex_destroy(&r->lock);
	free(r);
	*rp = NULL;
}

ajar_status ajar_renderer_restart(ajar_renderer *r, uint32_t seed)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_restart: renderer is NULL");
	cl_long zero = 0;
	r->data.params->seed = seed;
	for (uint32_t k = 0; k < r->ndev; k++) {
		RenderDevice *rd = &r->devs[k];
		Device *d = &rd->dev;
		rd->done.n = 0;
		rd->spp_kept = 0;
		if (!rd->alive || rd->rank)
			continue;
		cl_mem params = rd->bufs.mem[rd->bufs.count - 1]; /* last in AJAR_SCENE_BUFFERS */
		CL_TRY(d, clEnqueueWriteBuffer(d->queue, params, CL_TRUE, 0, sizeof(Params), r->data.params, 0, NULL,
					       NULL));
		CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->accum, &zero, sizeof zero, 0, film_bytes(r), 0, NULL, NULL));
		CL_TRY(d, clEnqueueFillBuffer(d->queue, rd->splat, &zero, sizeof zero, 0, splat_bytes(r), 0, NULL, NULL));
		CL_TRY(d, clFinish(d->queue));
	}
	free(r->salvage);
	free(r->salvage_splat);
	free(r->remote);
	free(r->remote_splat);
	r->salvage = r->salvage_splat = r->remote = r->remote_splat = NULL;
	r->holes.n = 0;
	r->base.n = 0;
	r->seed = seed;
	r->opt.seed = seed;
	r->hashed = 0;
	r->spp_done = r->next_first = 0;
	r->elapsed = 0;
	atomic_store(&r->cancel, 0);
	return AJAR_OK;
}

void ajar_renderer_cancel(ajar_renderer *r)
{
	if (r)
		atomic_store(&r->cancel, 1);
}

uint32_t ajar_renderer_spp(const ajar_renderer *r)
{
	if (!r)
		return 0;
	pthread_mutex_lock((pthread_mutex_t *)&r->lock);
	uint32_t spp = r->spp_done;
	pthread_mutex_unlock((pthread_mutex_t *)&r->lock);
	return spp;
}

const char *ajar_renderer_device_name(const ajar_renderer *r) { return r ? r->device_names : ""; }

uint32_t ajar_renderer_device_count(const ajar_renderer *r) { return r ? r->ndev : 0; }

ajar_status ajar_renderer_device_stats(const ajar_renderer *r, uint32_t index, ajar_device_stats *out)
{
	if (!r || !out || index >= r->ndev)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_device_stats: device %u of %u", index,
			       r ? r->ndev : 0);
	const RenderDevice *rd = &r->devs[index];
	memset(out, 0, sizeof *out);
	snprintf(out->name, sizeof out->name, "%.127s", rd->dev.name);
	snprintf(out->selector, sizeof out->selector, "%.31s", rd->dev.selector);
	pthread_mutex_lock((pthread_mutex_t *)&r->lock);
	out->samples = rd->spp_kept * r->width * r->height;
	out->samples_per_second = rd->busy_seconds > 0 ? out->samples / rd->busy_seconds : 0.0;
	out->share = r->spp_done ? (double)rd->spp_kept / r->spp_done : 0.0;
	out->failed = !rd->alive;
	pthread_mutex_unlock((pthread_mutex_t *)&r->lock);
	return AJAR_OK;
}

/* ---- Device threads ------------------------------------------------------- */

/* The message of a failed call, kept on the device (not err_set: that is
 * per thread and would log an error for what may only be a warning). */
static int pass_failed(RenderDevice *rd, const char *what, cl_int err)
{
	snprintf(rd->error, sizeof rd->error, "%s failed: %s (%d)", what, cl_error_name(err), (int)err);
	return 0;
}

/* Renders range g on rd; on failure sets *film_ok to whether the film
 * still holds exactly the completed ranges (the kernel never started). */
int render_run_pass(RenderDevice *rd, Range g, int *film_ok)
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

/* Reads a device's films into fresh host arrays; 0 if it cannot. */
int render_read_films(RenderDevice *rd, long **accum, long **splat)
{
	size_t bytes = film_bytes(rd->r), sbytes = splat_bytes(rd->r);
	*accum = malloc(bytes);
	*splat = malloc(sbytes);
	if (*accum && *splat &&
	    clEnqueueReadBuffer(rd->dev.queue, rd->accum, CL_TRUE, 0, bytes, *accum, 0, NULL, NULL) == CL_SUCCESS &&
	    clEnqueueReadBuffer(rd->dev.queue, rd->splat, CL_TRUE, 0, sbytes, *splat, 0, NULL, NULL) == CL_SUCCESS)
		return 1;
	free(*accum);
	free(*splat);
	*accum = *splat = NULL;
	return 0;
}

/* Adds a dropped device's films to the salvage (under the lock); 0 if out of memory. */
int render_salvage_add(ajar_renderer *r, const long *accum, const long *splat)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = render_splat_count(r);
	if (!r->salvage) {
		r->salvage = calloc(n, sizeof *r->salvage);
		r->salvage_splat = calloc(ns, sizeof *r->salvage_splat);
		if (!r->salvage || !r->salvage_splat) {
			free(r->salvage);
			free(r->salvage_splat);
			r->salvage = r->salvage_splat = NULL;
			return 0;
		}
	}
	for (size_t i = 0; i < n; i++)
		r->salvage[i] += accum[i];
	for (size_t i = 0; i < ns; i++)
		r->salvage_splat[i] += splat[i];
	return 1;
}

/* Drops rd after its pass g failed (under the lock): g goes back to the
 * pool, and so do its completed ranges unless its film was read back. */
void render_drop_device(ajar_renderer *r, RenderDevice *rd, Range g, const long *accum, const long *splat,
			int kept_there)
{
	/* kept_there: a device of another rank whose film that rank kept. */
	int kept = kept_there || (accum && render_salvage_add(r, accum, splat));
	rd->alive = 0;
	r->last_dropped = rd;
	if (!range_list_push(&r->holes, g))
		r->out_of_memory = 1;
	if (!kept) {
		for (size_t i = 0; i < rd->done.n; i++)
			if (!range_list_push(&r->holes, rd->done.r[i]))
				r->out_of_memory = 1;
		r->spp_done -= (uint32_t)rd->spp_kept;
		rd->spp_kept = 0;
		rd->done.n = 0;
	}
}

static void *device_thread(void *arg)
{
	RenderDevice *rd = arg;
	ajar_renderer *r = rd->r;
	pthread_mutex_lock(&r->lock);
	for (;;) {
		Range g;
		if (r->pausing) { /* a checkpoint is being written */
			pthread_cond_wait(&r->cond, &r->lock);
			continue;
		}
		if (!scheduler_take_range(r, rd, &g)) {
			/* A pass in flight elsewhere may still fail and return its range. */
			if (r->in_flight == 0 || scheduler_stopping(r))
				break;
			pthread_cond_wait(&r->cond, &r->lock);
			continue;
		}
		r->in_flight++;
		pthread_mutex_unlock(&r->lock);
		double tp = render_seconds();
		int film_ok;
		int ok = render_run_pass(rd, g, &film_ok);
		double dt = render_seconds() - tp;
		long *accum = NULL, *splat = NULL;
		if (!ok && film_ok)
			render_read_films(rd, &accum, &splat);
		pthread_mutex_lock(&r->lock);
		r->in_flight--;
		r->events++;
		if (ok) {
			if (!range_list_push(&rd->done, g))
				r->out_of_memory = 1;
			rd->spp_kept += g.count;
			rd->busy_seconds += dt;
			rd->per_spp = dt / g.count;
			r->spp_done += g.count;
		} else {
			render_drop_device(r, rd, g, accum, splat, 0);
		}
		free(accum);
		free(splat);
		pthread_cond_broadcast(&r->cond);
		if (!ok)
			break;
	}
	r->running--;
	pthread_cond_broadcast(&r->cond);
	pthread_mutex_unlock(&r->lock);
	return NULL;
}

/* "name (P:D): 52.1% 0.71 Msamples/s; ..." for the EXR header. */
static void device_shares(const ajar_renderer *r, char *buf, size_t cap)
{
	size_t len = 0;
	buf[0] = '\0';
	for (uint32_t i = 0; i < r->ndev && len < cap; i++) {
		ajar_device_stats s;
		ajar_renderer_device_stats(r, i, &s);
		len += (size_t)snprintf(buf + len, cap - len, "%s%s (%s): %.1f%% %.3g Msamples/s%s", i ? "; " : "",
					s.name, s.selector, 100 * s.share, s.samples_per_second * 1e-6,
					s.failed ? " (failed)" : "");
		/* Another rank's device: how long it waited there between its ranges. */
		const RenderDevice *rd = &r->devs[i];
		if (rd->job_ranges && len < cap)
			len += (size_t)snprintf(buf + len, cap - len, ", idle %.2f ms between ranges (mean of %u)",
						1e3 * rd->job_idle / rd->job_ranges, rd->job_ranges);
	}
}

/* ---- The render loop (main thread) ---------------------------------------- */

static void fill_progress(const ajar_renderer *r, ajar_progress *p)
{
	double elapsed = render_seconds() - r->t0, rate = 0; /* sample indices per second */
	memset(p, 0, sizeof *p);
	for (uint32_t i = 0; i < r->ndev; i++)
		if (r->devs[i].alive && r->devs[i].per_spp > 0)
			rate += 1.0 / r->devs[i].per_spp;
	p->spp_done = r->spp_done;
	p->spp_target = r->spp_target;
	p->samples_done = (uint64_t)r->spp_done * r->width * r->height;
	p->elapsed = elapsed;
	p->samples_per_second = elapsed > 0 ? p->samples_done / elapsed : 0;
	if (r->spp_target) {
		p->fraction = (double)r->spp_done / r->spp_target;
		p->eta = rate > 0 ? (r->spp_target - r->spp_done) / rate : -1.0;
	} else {
		p->fraction = fmin(1.0, elapsed / r->time_limit);
		p->eta = fmax(0.0, r->time_limit - elapsed);
	}
	if (r->time_limit > 0 && r->spp_target)
		p->eta = p->eta < 0 ? fmax(0.0, r->time_limit - elapsed) : fmin(p->eta, fmax(0.0, r->time_limit - elapsed));
}

/* Logs a warning for every device dropped since the last call (unlocked);
 * returns how many. */
static int report_drops(ajar_renderer *r)
{
	int drops = 0;
	for (uint32_t i = 0; i < r->ndev; i++) {
		RenderDevice *rd = &r->devs[i];
		pthread_mutex_lock(&r->lock);
		int fresh = !rd->alive && !rd->reported;
		uint32_t left = 0;
		for (uint32_t j = 0; j < r->ndev; j++)
			left += r->devs[j].alive;
		rd->reported |= fresh;
		drops += fresh;
		pthread_mutex_unlock(&r->lock);
		if (fresh && left)
			log_msg(AJAR_LOG_WARNING,
				"device %s (%s) dropped: %s; its unfinished samples go to the %u other device%s",
				rd->dev.name, rd->dev.selector, rd->error, left, left == 1 ? "" : "s");
	}
	return drops;
}

static ajar_status render_run(ajar_renderer *r, ajar_progress_fn fn, void *user);

ajar_status ajar_renderer_render(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_render: renderer is NULL");
	if (cluster_size() > 1 && cluster_rank() > 0)
		return job_serve(r); /* rank 0 deals, this rank's devices render */
	ajar_status st = render_run(r, fn, user);
	return cluster_size() > 1 ? job_end(r, st) : st;
}

static ajar_status render_run(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
	pthread_mutex_lock(&r->lock);
	r->t0 = render_seconds() - r->elapsed;
	r->ckpt_last = render_seconds();
	r->running = 0;
	for (uint32_t i = 0; i < r->ndev; i++) {
		RenderDevice *rd = &r->devs[i];
		/* A device of another rank is driven by a proxy thread (see "Several machines"). */
		rd->started = rd->alive && pthread_create(&rd->thread, NULL, rd->rank ? job_proxy_thread : device_thread,
							  rd) == 0;
		r->running += (uint32_t)rd->started;
	}
	if (r->running == 0 && r->last_dropped != NULL) {
		pthread_mutex_unlock(&r->lock);
		return err_set(AJAR_ERROR_DEVICE, "no OpenCL device left (the last failed: %s)", r->last_dropped->error);
	}
	if (r->running == 0 && scheduler_work_left(r) > 0 && !atomic_load(&r->cancel)) {
		pthread_mutex_unlock(&r->lock);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "cannot start a render thread");
	}
	uint64_t seen = r->events;
	int callbacks = fn != NULL;
	while (r->running > 0) {
		while (r->events == seen && r->running > 0)
			pthread_cond_wait(&r->cond, &r->lock);
		if (r->events == seen)
			break; /* the devices stopped without another pass */
		seen = r->events;
		ajar_progress p;
		fill_progress(r, &p);
		pthread_mutex_unlock(&r->lock);
		int dropped = report_drops(r);
		if (callbacks && !atomic_load(&r->cancel) && fn(&p, user))
			ajar_renderer_cancel(r);
		pthread_mutex_lock(&r->lock);
		/* After a cancel the caller writes the last checkpoint itself. */
		if (r->ckpt_path && !scheduler_stopping(r) && scheduler_work_left(r) > 0 &&
		    (dropped || render_seconds() - r->ckpt_last >= r->ckpt_every))
			render_checkpoint_during(r);
		pthread_cond_broadcast(&r->cond); /* wakes idle devices after a cancel */
	}
	pthread_mutex_unlock(&r->lock);
	for (uint32_t i = 0; i < r->ndev; i++)
		if (r->devs[i].started) {
			pthread_join(r->devs[i].thread, NULL);
			r->devs[i].started = 0;
		}
	r->elapsed = render_seconds() - r->t0;
	report_drops(r);
	if (r->ndev > 1) {
		char shares[2048];
		device_shares(r, shares, sizeof shares);
		log_msg(AJAR_LOG_INFO, "devices: %s", shares);
	}

	uint32_t alive = 0;
	for (uint32_t i = 0; i < r->ndev; i++)
		alive += (uint32_t)r->devs[i].alive;
	uint64_t left = scheduler_work_left(r);
	if (r->out_of_memory)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory while scheduling passes");
	if (alive == 0 && left > 0) {
		const RenderDevice *rd = r->last_dropped;
		return err_set(AJAR_ERROR_DEVICE,
			       "OpenCL device %s (%s): %s; no device left: the image holds the %u samples per pixel "
			       "rendered before",
			       rd->dev.name, rd->dev.selector, rd->error, r->spp_done);
	}
	if (left > 0 && scheduler_time_left(r) > 0 && atomic_load(&r->cancel))
		return err_set(AJAR_ERROR_CANCELLED, "render cancelled after %u samples per pixel", r->spp_done);
	return AJAR_OK;
}

/* ---- Reduction and output --------------------------------------------------- */

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
	ajar_status st = render_reduce(r);
	if (st != AJAR_OK)
		return st;
	size_t n = 3 * (size_t)r->width * r->height;
	long *sum = r->film, *sum_splat = r->film_splat;
	double scale = r->spp_done ? 1.0 / ((double)FILM_SCALE * r->spp_done) : 0.0;
	for (size_t i = 0; i < n / 3; i++) {
		for (int c = 0; c < 3; c++)
			rgba[4 * i + c] = (float)((double)(sum[3 * i + c] + sum_splat[3 * i + c]) * scale);
		rgba[4 * i + 3] = 1.0f;
	}
	return AJAR_OK;
}

ajar_status ajar_renderer_aovs(ajar_renderer *r, float *px)
{
	if (!r || !px)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_aovs: NULL argument");
	if (!r->opt.aov)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "the renderer keeps no AOVs (set ajar_options.aov)");
	ajar_status st = render_reduce(r);
	if (st != AJAR_OK)
		return st;
	size_t npix = (size_t)r->width * r->height;
	const long *a = r->film_splat + render_aov_offset(r);
	double n = r->spp_done, inv = n > 0 ? 1.0 / ((double)FILM_SCALE * n) : 0.0;
	double inv_sq = n > 0 ? 1.0 / ((double)AOV_SQ_SCALE * n) : 0.0;
	static const uint32_t bit[AOV_CHANNELS] = {AJAR_AOV_ALBEDO, AJAR_AOV_ALBEDO, AJAR_AOV_ALBEDO,
						   AJAR_AOV_NORMAL, AJAR_AOV_NORMAL, AJAR_AOV_NORMAL,
						   AJAR_AOV_DEPTH,  AJAR_AOV_VARIANCE, AJAR_AOV_VARIANCE,
						   AJAR_AOV_VARIANCE};
	for (size_t i = 0; i < npix; i++) {
		const long *p = a + AOV_CHANNELS * i;
		float *o = px + AOV_CHANNELS * i;
		for (int c = 0; c < 7; c++)
			o[c] = (r->opt.aov & bit[c]) ? (float)((double)p[c] * inv) : 0.0f;
		/* Sample variance of the pixel's own estimates over n, from
		 * sum(x) (the own-pixel film) and sum(x^2). */
		for (int c = 0; c < 3; c++) {
			double m = (double)r->film[3 * i + c] * inv, m2 = (double)p[7 + c] * inv_sq;
			o[7 + c] = (r->opt.aov & AJAR_AOV_VARIANCE) && n > 1 ? (float)(fmax(0.0, m2 - m * m) / (n - 1))
									       : 0.0f;
		}
	}
	return AJAR_OK;
}

/* Sums the salvage and every live device's films into r->film and
 * r->film_splat: integer sums, the same bits whatever the device count. */
ajar_status render_reduce(ajar_renderer *r)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = render_splat_count(r);
	long *sum = r->film, *sum_splat = r->film_splat;
	if (r->job_lost)
		return err_set(AJAR_ERROR_DEVICE, "a rank of the job stopped answering: the films of the job cannot be "
						  "summed (a checkpoint written before is kept)");
	if (r->salvage) {
		memcpy(sum, r->salvage, n * sizeof *sum);
		memcpy(sum_splat, r->salvage_splat, ns * sizeof *sum_splat);
	} else {
		memset(sum, 0, n * sizeof *sum);
		memset(sum_splat, 0, ns * sizeof *sum_splat);
	}
	if (r->remote) { /* rank 0: what the other ranks rendered */
		for (size_t i = 0; i < n; i++)
			sum[i] += r->remote[i];
		for (size_t i = 0; i < ns; i++)
			sum_splat[i] += r->remote_splat[i];
	}
	/* Integer sums first, scaled once: the same bits whatever the device count. */
	for (uint32_t k = 0; k < r->ndev; k++) {
		RenderDevice *rd = &r->devs[k];
		long *a, *s;
		if (!rd->alive || rd->rank) /* another rank's films are in r->remote */
			continue;
		if (!render_read_films(rd, &a, &s))
			return err_set(AJAR_ERROR_DEVICE, "OpenCL device %s: reading the film back failed",
				       rd->dev.name);
		for (size_t i = 0; i < n; i++)
			sum[i] += a[i];
		for (size_t i = 0; i < ns; i++)
			sum_splat[i] += s[i];
		free(a);
		free(s);
	}
	return AJAR_OK;
}

static const char *integrator_name(ajar_integrator i)
{
	return i == AJAR_INTEGRATOR_BDPT ? "bdpt" : i == AJAR_INTEGRATOR_PORTAL ? "portal" : "pt";
}

void render_info(const ajar_renderer *r, RenderInfo *info)
{
	memset(info, 0, sizeof *info);
	info->width = r->width;
	info->height = r->height;
	info->spp = r->spp_done;
	info->seed = r->seed;
	info->max_depth = r->max_depth;
	info->seconds = r->elapsed;
	info->integrator = integrator_name(r->integrator);
	info->devices = r->device_names;
	device_shares(r, info->shares, sizeof info->shares);
	info->scene = r->scene_name;
	info->nlayers = r->nlayers;
	info->strategy_len = r->strategy_len;
	info->strategy_unweighted = r->strategy_unweighted;
	info->layers = r->film_splat + 3 * (size_t)r->width * r->height;
	info->aov = r->opt.aov;
}

ajar_status ajar_devices(ajar_device_info *out, uint32_t capacity, uint32_t *count)
{
	return device_list(out, capacity, count);
}
