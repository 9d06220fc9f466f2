/* render_checkpoint.c — the renderer's side of checkpoints
 * (checkpoint_file.c holds the file format): writing one, also during a
 * render, and resuming one, also as a job of several ranks. A checkpoint
 * holds the reduced integer films and the sample ranges they hold, with
 * the hashes of the prepared scene and of the render parameters
 * (render_state.c). Resumed, the films become the salvage (the host part
 * every image adds), the ranges the base, and the gaps below the highest
 * range go back to the pool, so the continued render hands out exactly the
 * sample indices an uninterrupted one would have: the sums, and so the
 * image, are the same bits. */
#include "render/render_checkpoint.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/cluster.h"
#include "render/render_film.h"
#include "render/render_job.h"

static int range_before(const void *a, const void *b)
{
	const Range *x = a, *y = b;
	return x->first < y->first ? -1 : x->first > y->first;
}

/* The checkpoint of r now (films reduced; c->ranges malloc'ed, the films
 * borrowed from r). Devices must be idle. */
static ajar_status checkpoint_gather(ajar_renderer *r, Checkpoint *c)
{
	memset(c, 0, sizeof *c);
	ajar_status st = film_reduce(r);
	if (st != AJAR_OK)
		return st;
	render_ensure_hashes(r);
	snprintf(c->version, sizeof c->version, "%s", AJAR_VERSION_STRING);
	snprintf(c->scene, sizeof c->scene, "%s", r->scene_name);
	c->scene_hash = r->scene_hash;
	c->params_hash = r->params_hash;
	const ajar_options *o = &r->opt;
	c->width = r->width;
	c->height = r->height;
	c->integrator = (uint32_t)o->integrator;
	c->max_depth = o->max_depth;
	c->min_depth = o->min_depth;
	c->seed = r->seed;
	c->mis = (uint32_t)o->mis;
	c->strategy_len = o->strategy_len;
	c->strategy_unweighted = (uint32_t)o->strategy_unweighted;
	c->spp = r->spp_target;
	c->aov = o->aov;
	c->portals = (uint32_t)o->portals;
	c->time_limit = r->time_limit;
	c->noise = r->opt.noise;
	c->elapsed = r->elapsed;
	size_t n = r->base.n;
	for (uint32_t i = 0; i < r->ndev; i++)
		n += r->devs[i].done.n;
	c->ranges = malloc(sizeof *c->ranges * (n ? n : 1));
	if (!c->ranges)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for a checkpoint");
	if (r->base.n) /* memcpy from NULL is undefined even for 0 bytes (UBSan) */
		memcpy(c->ranges, r->base.r, sizeof *c->ranges * r->base.n);
	n = r->base.n;
	for (uint32_t i = 0; i < r->ndev; i++) {
		if (r->devs[i].done.n)
			memcpy(c->ranges + n, r->devs[i].done.r, sizeof *c->ranges * r->devs[i].done.n);
		n += r->devs[i].done.n;
	}
	qsort(c->ranges, n, sizeof *c->ranges, range_before);
	uint64_t total = 0;
	c->nranges = 0;
	for (size_t i = 0; i < n; i++) {
		Range *last = c->nranges ? &c->ranges[c->nranges - 1] : NULL;
		total += c->ranges[i].count;
		if (last && last->first + last->count == c->ranges[i].first)
			last->count += c->ranges[i].count;
		else
			c->ranges[c->nranges++] = c->ranges[i];
	}
	if (total != r->spp_done) { /* every sample index in the films is in exactly one range */
		free(c->ranges);
		c->ranges = NULL;
		return err_set(AJAR_ERROR_DEVICE, "checkpoint: the films hold %u samples per pixel, the ranges %llu",
			       r->spp_done, (unsigned long long)total);
	}
	c->film[CKPT_ACCUM] = r->film;
	c->nfilm[CKPT_ACCUM] = 3 * (size_t)r->width * r->height;
	c->film[CKPT_SPLAT] = r->film_splat;
	c->nfilm[CKPT_SPLAT] = film_aov_offset(r);
	c->film[CKPT_AOV] = r->film_splat + film_aov_offset(r);
	c->nfilm[CKPT_AOV] = film_splat_count(r) - film_aov_offset(r);
	return AJAR_OK;
}

static ajar_status write_checkpoint(ajar_renderer *r, const char *path)
{
	Checkpoint c;
	ajar_status st = checkpoint_gather(r, &c);
	if (st == AJAR_OK)
		st = checkpoint_write(path, &c);
	free(c.ranges);
	return st;
}

ajar_status ajar_renderer_write_checkpoint(ajar_renderer *r, const char *path)
{
	if (!r || !path || !path[0])
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_checkpoint: NULL argument");
	return write_checkpoint(r, path);
}

/* From the render loop, under the lock: waits until no pass is in flight,
 * sums the films, lets the devices go on and writes the file meanwhile
 * (the sums are the main thread's own arrays). A failed write keeps the
 * previous file. */
void render_checkpoint_during(ajar_renderer *r)
{
	r->pausing = 1;
	while (r->in_flight > 0)
		pthread_cond_wait(&r->cond, &r->lock);
	pthread_mutex_unlock(&r->lock);
	r->elapsed = render_seconds() - r->t0;
	Checkpoint c;
	memset(&c, 0, sizeof c);
	ajar_status st = cluster_size() > 1 ? job_gather(r) : AJAR_OK;
	if (st == AJAR_OK)
		st = checkpoint_gather(r, &c);
	pthread_mutex_lock(&r->lock);
	r->pausing = 0;
	pthread_cond_broadcast(&r->cond);
	pthread_mutex_unlock(&r->lock);
	if (st == AJAR_OK)
		st = checkpoint_write(r->ckpt_path, &c);
	free(c.ranges);
	if (st != AJAR_OK)
		log_msg(AJAR_LOG_WARNING, "checkpoint not written (the previous one is kept): %s", ajar_last_error());
	r->ckpt_last = render_seconds();
	pthread_mutex_lock(&r->lock);
}

ajar_status ajar_renderer_set_checkpoint(ajar_renderer *r, const char *path, double every)
{
	if (!r)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_set_checkpoint: renderer is NULL");
	if (!(every >= 0) || every > 1e9)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "checkpoint interval %g s: must be 0 or more", every);
	char *p = path && path[0] ? strdup(path) : NULL;
	if (path && path[0] && !p)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	free(r->ckpt_path);
	r->ckpt_path = p;
	r->ckpt_every = every > 0 ? every : 1e30;
	return AJAR_OK;
}

static void options_from_checkpoint(const Checkpoint *c, ajar_options *o)
{
	ajar_options_default(o);
	o->width = c->width;
	o->height = c->height;
	o->spp = c->spp;
	o->time_limit = c->time_limit;
	o->noise = c->noise;
	o->integrator = (ajar_integrator)c->integrator;
	o->max_depth = c->max_depth;
	o->min_depth = c->min_depth;
	o->seed = c->seed;
	o->mis = (ajar_mis)c->mis;
	o->strategy_len = c->strategy_len;
	o->strategy_unweighted = (int)c->strategy_unweighted;
	o->aov = c->aov;
	o->portals = (ajar_portals)c->portals;
}

ajar_status ajar_checkpoint_options(const char *path, ajar_options *o, uint32_t *spp_done)
{
	if (!path || !o)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_checkpoint_options: NULL argument");
	Checkpoint c;
	ajar_status st = checkpoint_read(path, &c, spp_done == NULL);
	if (st != AJAR_OK)
		return st;
	options_from_checkpoint(&c, o);
	if (spp_done) {
		uint64_t n = 0;
		for (uint32_t i = 0; i < c.nranges; i++)
			n += c.ranges[i].count;
		*spp_done = (uint32_t)n;
	}
	checkpoint_free(&c);
	return AJAR_OK;
}

ajar_status render_checkpoint_check(ajar_renderer *r, const Checkpoint *c, const char *path)
{
	render_ensure_hashes(r);
	if (c->scene_hash != r->scene_hash)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: checkpoint is of another scene (it was made from %s, and this scene differs from it); "
			       "it cannot be resumed here",
			       path, c->scene[0] ? c->scene : "?");
	if (c->params_hash != r->params_hash)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: checkpoint was made with other render parameters (the options agree, so the "
			       "program that made it chose other strategies); it cannot be resumed here",
			       path);
	return AJAR_OK;
}

ajar_status render_checkpoint_apply(ajar_renderer *r, Checkpoint *c, const char *path)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = film_aov_offset(r);
	if (c->nfilm[CKPT_ACCUM] != n || c->nfilm[CKPT_SPLAT] != ns || c->nfilm[CKPT_AOV] != film_splat_count(r) - ns)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is corrupted (film sizes)", path);
	long *splat = realloc(c->film[CKPT_SPLAT], sizeof *splat * (film_splat_count(r) ? film_splat_count(r) : 1));
	if (!splat)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	memcpy(splat + ns, c->film[CKPT_AOV], sizeof *splat * (film_splat_count(r) - ns));
	c->film[CKPT_SPLAT] = splat;
	uint32_t end = 0;
	uint64_t done = 0;
	for (uint32_t i = 0; i < c->nranges; i++) {
		Range g = c->ranges[i];
		if (g.first > end && !range_list_push(&r->holes, (Range){end, g.first - end}))
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
		if (!range_list_push(&r->base, g))
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
		end = g.first + g.count;
		done += g.count;
	}
	if (r->spp_target && r->spp_target < end)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT,
			       "%s: the checkpoint holds %llu samples per pixel (indices up to %u); a sample count of %u "
			       "is too few to continue it",
			       path, (unsigned long long)done, end, r->spp_target);
	r->salvage = c->film[CKPT_ACCUM];
	r->salvage_splat = c->film[CKPT_SPLAT];
	c->film[CKPT_ACCUM] = c->film[CKPT_SPLAT] = NULL;
	r->spp_done = (uint32_t)done;
	r->next_first = end;
	r->elapsed = c->elapsed;
	return AJAR_OK;
}

/* The options of a resumed render: the checkpoint's (want), with the
 * budget and the devices of o if o is not NULL; anything else in o must
 * agree with the checkpoint. */
static ajar_status resume_options(ajar_options *want, const ajar_options *o, const char *path)
{
	if (o) {
		/* Only the budget and the devices may change. */
		const char *differs = o->width != want->width || o->height != want->height ? "width/height"
				      : o->integrator != want->integrator			 ? "integrator"
				      : o->max_depth != want->max_depth			 ? "max_depth"
				      : o->min_depth != want->min_depth			 ? "min_depth"
				      : o->seed != want->seed				 ? "seed"
				      : o->mis != want->mis				 ? "mis"
				      : o->strategy_len != want->strategy_len		 ? "strategy_len"
				      : o->strategy_unweighted != want->strategy_unweighted ? "strategy_unweighted"
				      : o->aov != want->aov				 ? "aov"
				      : o->portals != want->portals			 ? "portals"
											   : NULL;
		if (differs)
			return err_set(AJAR_ERROR_INVALID_ARGUMENT,
				       "%s: options.%s differs from the checkpoint's (only spp, time_limit, noise and device "
				       "may change when resuming)",
				       path, differs);
		want->spp = o->spp;
		want->time_limit = o->time_limit;
		want->noise = o->noise;
		want->device = o->device;
	}
	return AJAR_OK;
}

ajar_status render_checkpoint_read(const char *path, const ajar_options *o, ajar_options *want, Checkpoint *c,
				   int *have)
{
	ajar_status st = AJAR_OK;
	*have = 0;
	if (cluster_size() <= 1) {
		if ((st = checkpoint_read(path, c, 0)) != AJAR_OK)
			return st;
		*have = 1;
		options_from_checkpoint(c, want);
		return resume_options(want, o, path);
	}
	/* A job: rank 0 reads the file, the other ranks receive its options
	 * (they need no copy of the file). */
	struct {
		int32_t status;
		char error[1024];
		ajar_options want;
	} msg;
	memset(&msg, 0, sizeof msg);
	if (cluster_rank() == 0) {
		st = checkpoint_read(path, c, 0);
		*have = st == AJAR_OK;
		if (*have) {
			options_from_checkpoint(c, &msg.want);
			st = resume_options(&msg.want, o, path);
		}
		msg.status = (int32_t)st;
		if (st != AJAR_OK)
			snprintf(msg.error, sizeof msg.error, "%s", ajar_last_error());
		msg.want.device = NULL;
	}
	if (cluster_bcast(&msg, sizeof msg, NULL) != 1)
		return AJAR_ERROR_DEVICE;
	msg.want.device = o ? o->device : NULL;
	*want = msg.want;
	if (msg.status != AJAR_OK)
		return cluster_rank() == 0 ? st : err_set((ajar_status)msg.status, "rank 0: %s", msg.error);
	return AJAR_OK;
}
