/* render.c — the renderer behind ajar_renderer_*, its public face: a
 * renderer created (the scene prepared, the devices opened, a checkpoint
 * resumed, the ranks of a job joined), rendered, restarted, cancelled,
 * read and destroyed. Each step is another room's, called downward:
 * render_loop.c renders, render_job.c serves the other ranks of a job,
 * render_checkpoint.c reads and applies checkpoints, render_device.c opens
 * the devices, render_film.c reads the image out, render_info.c tells the
 * device figures. How a render runs: README.md beside this file. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/compat.h"
#include "core/error.h"
#include "device/device_select.h"
#include "mis/strategies.h"
#include "prepare/prepare.h"
#include "render/cluster.h"
#include "render/render_checkpoint.h"
#include "render/render_device.h"
#include "render/render_film.h"
#include "render/render_info.h"
#include "render/render_job.h"
#include "render/render_loop.h"
#include "render/render_noise.h"
#include "render/render_options.h"
#include "render/render_overrides.h"
#include "render/render_state.h"
#include "scene/scene.h"

#define DEFAULT_WIDTH 512

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

/* ajar_renderer_create, and ajar_renderer_resume with the checkpoint c read
 * from `path`: refused after the scene is prepared (its hash), before any
 * kernel is built; applied once the films exist. */
static ajar_status renderer_new(const ajar_scene *scene, const ajar_options *opt, const PolicyOverrides *over,
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
	noise_reset(r);
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
	if ((st = render_devices_open(r, opt->device)) != AJAR_OK)
		goto fail;
	r->film = calloc(3 * (size_t)r->width * r->height, sizeof *r->film);
	r->film_splat = calloc(film_splat_count(r), sizeof *r->film_splat);
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

ajar_status ajar_renderer_resume(const ajar_scene *scene, const char *path, const ajar_options *o,
				 ajar_renderer **out)
{
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_resume: out is NULL");
	*out = NULL;
	if (!scene || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_resume: NULL argument");
	Checkpoint c;
	ajar_options want;
	int have;
	ajar_status st = render_checkpoint_read(path, o, &want, &c, &have);
	if (st == AJAR_OK)
		st = renderer_new(scene, &want, NULL, have ? &c : NULL, have ? path : NULL, out);
	if (have)
		checkpoint_free(&c);
	return st;
}

void ajar_renderer_destroy(ajar_renderer **rp)
{
	ajar_renderer *r = rp ? *rp : NULL;
	if (!r)
		return;
	for (uint32_t i = 0; i < r->ndev; i++)
		render_device_close(&r->devs[i]);
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
	noise_reset(r);
	pthread_cond_destroy(&r->cond);
	pthread_mutex_destroy(&r->lock);
	free(r);
	*rp = NULL;
}

ajar_status ajar_renderer_render(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_render: renderer is NULL");
	if (cluster_size() > 1 && cluster_rank() > 0)
		return job_serve(r); /* rank 0 deals, this rank's devices render */
	ajar_status st = render_loop(r, fn, user);
	return cluster_size() > 1 ? job_end(r, st) : st;
}

ajar_status ajar_renderer_restart(ajar_renderer *r, uint32_t seed)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_restart: renderer is NULL");
	ajar_status st;
	r->data.params->seed = seed;
	for (uint32_t k = 0; k < r->ndev; k++) {
		RenderDevice *rd = &r->devs[k];
		rd->done.n = 0;
		rd->spp_kept = 0;
		if (rd->alive && !rd->rank && (st = render_device_reset(rd)) != AJAR_OK)
			return st;
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
	noise_reset(r);
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

ajar_status ajar_renderer_image(ajar_renderer *r, float *rgba, uint32_t *width, uint32_t *height)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_image: renderer is NULL");
	if (width)
		*width = r->width;
	if (height)
		*height = r->height;
	return rgba ? film_image(r, rgba) : AJAR_OK;
}

ajar_status ajar_renderer_aovs(ajar_renderer *r, float *px)
{
	if (!r || !px)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_aovs: NULL argument");
	if (!r->opt.aov)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "the renderer keeps no AOVs (set ajar_options.aov)");
	return film_aovs(r, px);
}

const char *ajar_renderer_device_name(const ajar_renderer *r) { return r ? r->device_names : ""; }

uint32_t ajar_renderer_device_count(const ajar_renderer *r) { return r ? r->ndev : 0; }

ajar_status ajar_renderer_device_stats(const ajar_renderer *r, uint32_t index, ajar_device_stats *out)
{
	if (!r || !out || index >= r->ndev)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_device_stats: device %u of %u", index,
			       r ? r->ndev : 0);
	render_info_device(r, index, out);
	return AJAR_OK;
}

ajar_status ajar_devices(ajar_device_info *out, uint32_t capacity, uint32_t *count)
{
	return device_list(out, capacity, count);
}
