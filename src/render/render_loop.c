/* render_loop.c — one render: a host thread per device takes ranges from
 * the scheduler and renders them, one pass at a time, until the sample
 * count, the time limit or a cancel; a device whose pass fails is dropped
 * (its film read back into the salvage when its kernel never ran) and the
 * others take over its ranges. The calling thread waits for pass events:
 * after each it calls the progress callback, warns of dropped devices and
 * writes the checkpoint when it is due. On rank 0 of a job a device of
 * another rank is driven by render_job.c's proxy thread instead. */
#include "render/render_loop.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/cluster.h"
#include "render/render_checkpoint.h"
#include "render/render_device.h"
#include "render/render_film.h"
#include "render/render_info.h"
#include "render/render_job.h"
#include "render/render_noise.h"
#include "render/render_scheduler.h"

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
		int ok = render_device_pass(rd, g, &film_ok);
		double dt = render_seconds() - tp;
		long *accum = NULL, *splat = NULL;
		if (!ok && film_ok)
			film_read(rd, &accum, &splat);
		pthread_mutex_lock(&r->lock);
		r->in_flight--;
		r->events++;
		if (ok)
			scheduler_range_done(r, rd, g, dt);
		else
			scheduler_drop_device(r, rd, g, accum, splat, 0);
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
	p->noise = r->opt.noise > 0.0 ? r->noise : -1.0;
	if (!r->spp_target && !(r->time_limit > 0)) {
		/* Only a noise target: the error falls as 1/sqrt(samples). */
		double q = r->noise > 0 ? r->opt.noise / r->noise : 0.0;
		p->fraction = fmin(1.0, q * q);
		p->eta = q > 0 && rate > 0 ? fmax(0.0, r->spp_done * (1.0 / (q * q) - 1.0) / rate) : -1.0;
	} else if (r->spp_target) {
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

/* The calling thread, under the lock, until every device thread ended:
 * after each pass event the progress callback, warnings of dropped
 * devices, and a checkpoint when one is due. */
static void wait_passes(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
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
			atomic_store(&r->cancel, 1);
		pthread_mutex_lock(&r->lock);
		/* After a cancel the caller writes the last checkpoint itself. */
		if (r->ckpt_path && !scheduler_stopping(r) && scheduler_work_left(r) > 0 &&
		    (dropped || render_seconds() - r->ckpt_last >= r->ckpt_every))
			render_checkpoint_during(r);
		/* A noise target: an estimate as the samples grow. */
		if (r->opt.noise > 0.0 && !scheduler_stopping(r) && scheduler_work_left(r) > 0 &&
		    r->spp_done >= r->noise_next)
			noise_during(r);
		pthread_cond_broadcast(&r->cond); /* wakes idle devices after a cancel */
	}
}

/* After the device threads ended: why the render stopped short, if it did. */
static ajar_status outcome(ajar_renderer *r)
{
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
	if (r->noise_reached)
		return AJAR_OK; /* stopped at the noise target */
	if (left > 0 && scheduler_time_left(r) > 0 && atomic_load(&r->cancel))
		return err_set(AJAR_ERROR_CANCELLED, "render cancelled after %u samples per pixel", r->spp_done);
	return AJAR_OK;
}

ajar_status render_loop(ajar_renderer *r, ajar_progress_fn fn, void *user)
{
	pthread_mutex_lock(&r->lock);
	r->t0 = render_seconds() - r->elapsed;
	r->ckpt_last = render_seconds();
	r->running = 0;
	for (uint32_t i = 0; i < r->ndev; i++) {
		RenderDevice *rd = &r->devs[i];
		/* A device of another rank is driven by a proxy thread (render_job.c). */
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
	wait_passes(r, fn, user);
	pthread_mutex_unlock(&r->lock);
	for (uint32_t i = 0; i < r->ndev; i++)
		if (r->devs[i].started) {
			pthread_join(r->devs[i].thread, NULL);
			r->devs[i].started = 0;
		}
	r->elapsed = render_seconds() - r->t0;
	/* Under a noise target, the estimate of the image as it ends (a job's
	 * other ranks' films are summed later, in job_end: there the last
	 * estimate of the render stands). */
	if (r->opt.noise > 0.0 && cluster_size() == 1 && r->spp_done > r->noise_snap_spp[0] &&
	    r->spp_done > r->noise_snap_spp[1])
		noise_update(r);
	report_drops(r);
	if (r->ndev > 1) {
		char shares[2048];
		render_info_shares(r, shares, sizeof shares);
		log_msg(AJAR_LOG_INFO, "devices: %s", shares);
	}
	return outcome(r);
}
