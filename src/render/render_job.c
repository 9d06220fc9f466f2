/* render_job.c — one render on several machines (Open MPI, through
 * cluster.c). Under mpirun every rank creates the same renderer on its own
 * devices (job_join checks they prepared the same scene and tells every
 * rank of a failure anywhere). Rank 0 adds one device per device of the
 * other ranks to its scheduler, each driven by a proxy thread
 * (job_proxy_thread) that takes ranges with scheduler_take_range like a
 * device thread, sends them to that rank and counts them done when the
 * answer comes: the dealing by measured speed, the time limit, cancels,
 * checkpoints and device failures are rank 0's, exactly as for its own
 * devices. The other ranks serve (job_serve): they render the ranges they
 * are sent, and on a gather (at a checkpoint and at the end) sum their
 * films into rank 0's `remote` films with an MPI reduction. Every sum is
 * of integers, so the image is the same bits as one process that rendered
 * the same sample indices. A device that fails on another rank is dropped
 * like a local one (that rank keeps its film when it can, as the salvage
 * does here). A rank that stops answering (killed; mpirun then stops the
 * whole job) cannot be summed: the render ends with an error and nothing
 * but the last checkpoint is kept. A resumed job reads its checkpoint in
 * render_checkpoint.c. */
#include "render/render_job.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/cluster.h"
#include "render/render_device.h"
#include "render/render_film.h"
#include "render/render_scheduler.h"

enum { JOB_PASS = 1, JOB_GATHER, JOB_END };
/* TAG_PASS, TAG_DONE and TAG_WHY + the device's index on its rank */
enum { TAG_CMD = 1, TAG_GATHERED = 2, TAG_GATHER_WHY = 3, TAG_PASS = 1000, TAG_DONE = 2000, TAG_WHY = 3000 };

typedef struct {
	uint32_t op, device, first, count; /* JOB_END: `first` is rank 0's status */
} JobCmd; /* TAG_CMD, and TAG_PASS + device straight to the device's thread */

/* Kept small: Open MPI's shared-memory transport delivers a message of a
 * few dozen bytes at once, while one of a KiB waited for the receiver's
 * next poll (measured: 6 ms of a device's idle time per range, 0.02 ms
 * with this size). A failure's message follows as a JobWhy. */
typedef struct {
	int32_t ok, kept; /* the pass rendered; else whether the rank kept the film */
	double idle;      /* seconds the device waited for this range since its previous one ended (-1: first) */
} JobDone;

typedef struct {
	char text[1024];
} JobWhy;

typedef struct {
	int32_t status;
	uint32_t ndev, width, height;
	uint64_t scene_hash, params_hash;
	char host[64];
	char error[1024];
	char name[MAX_RENDER_DEVICES][256];
	char selector[MAX_RENDER_DEVICES][16];
} JobHello;

/* Rank 0 deals to every device of every rank: the other ranks' devices
 * join r->devs, each driven by a proxy thread, and every name says its rank. */
static ajar_status add_remote_devices(ajar_renderer *r, const JobHello *all, int size)
{
	uint32_t total = r->ndev;
	for (int k = 1; k < size; k++)
		total += all[k].ndev;
	RenderDevice *devs = realloc(r->devs, sizeof *devs * total);
	if (!devs)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	r->devs = devs;
	memset(devs + r->ndev, 0, sizeof *devs * (total - r->ndev));
	size_t len = 0;
	for (uint32_t i = 0; i < r->ndev; i++) {
		snprintf(devs[i].dev.selector, sizeof devs[i].dev.selector, "rank 0, %s", all[0].selector[i]);
		len += (size_t)snprintf(r->device_names + len, sizeof r->device_names - len, "%s%s (%s)",
					i ? " + " : "", devs[i].dev.name, devs[i].dev.selector);
	}
	for (int k = 1; k < size; k++)
		for (uint32_t j = 0; j < all[k].ndev; j++) {
			RenderDevice *rd = &devs[r->ndev++];
			rd->r = r;
			rd->alive = 1;
			rd->rank = k;
			rd->remote = j;
			snprintf(rd->dev.name, sizeof rd->dev.name, "%s", all[k].name[j]);
			snprintf(rd->dev.selector, sizeof rd->dev.selector, "rank %d, %s", k % 100000, all[k].selector[j]);
			if (len < sizeof r->device_names)
				len += (size_t)snprintf(r->device_names + len, sizeof r->device_names - len, " + %s (%s)",
							rd->dev.name, rd->dev.selector);
		}
	return AJAR_OK;
}

ajar_status job_join(ajar_renderer *r, ajar_status st)
{
	int size = cluster_size(), me = cluster_rank();
	if (size <= 1)
		return st;
	JobHello *all = calloc((size_t)size + 1, sizeof *all), *mine = all + size;
	if (!all)
		return st != AJAR_OK ? st : err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory");
	mine->status = (int32_t)st;
	snprintf(mine->host, sizeof mine->host, "%s", cluster_host());
	if (st != AJAR_OK) {
		snprintf(mine->error, sizeof mine->error, "%s", ajar_last_error());
	} else {
		render_ensure_hashes(r);
		mine->scene_hash = r->scene_hash;
		mine->params_hash = r->params_hash;
		mine->width = r->width;
		mine->height = r->height;
		mine->ndev = r->ndev;
		for (uint32_t i = 0; i < r->ndev; i++) {
			snprintf(mine->name[i], sizeof mine->name[i], "%.255s", r->devs[i].dev.name);
			snprintf(mine->selector[i], sizeof mine->selector[i], "%.15s", r->devs[i].dev.selector);
		}
	}
	if (cluster_allgather(mine, all, sizeof *mine, NULL) != 1) {
		free(all);
		return st != AJAR_OK ? st : AJAR_ERROR_DEVICE;
	}
	for (int k = 0; k < size && st == AJAR_OK; k++)
		if (all[k].status != AJAR_OK)
			st = err_set((ajar_status)all[k].status, "rank %d (%s): %s", k, all[k].host, all[k].error);
	for (int k = 1; k < size && st == AJAR_OK; k++)
		if (all[k].scene_hash != all[0].scene_hash || all[k].params_hash != all[0].params_hash ||
		    all[k].width != all[0].width || all[k].height != all[0].height)
			st = err_set(AJAR_ERROR_BAD_INPUT,
				     "rank %d (%s) prepared another scene or other options than rank 0 (%s): every rank "
				     "must read the same scene files with the same options",
				     k, all[k].host, all[0].host);
	if (st == AJAR_OK && me == 0)
		st = add_remote_devices(r, all, size);
	free(all);
	return st;
}

/* Rank 0, under the lock (left while it receives): range g of rd came back
 * failed (rc 1, with the device's answer d) or not at all (rc from
 * cluster_recv: the rank stopped answering). rd is dropped, and the nq
 * ranges queued behind g there come back unrendered. */
static void proxy_drop(ajar_renderer *r, RenderDevice *rd, Range g, const Range *q, int nq, int rc, JobDone *d)
{
	int tag_done = TAG_DONE + (int)rd->remote, tag_why = TAG_WHY + (int)rd->remote;
	if (rc == 1) {
		JobWhy why = {"?"};
		pthread_mutex_unlock(&r->lock);
		rc = cluster_recv(rd->rank, tag_why, &why, sizeof why, NULL, NULL, &r->cancel);
		pthread_mutex_lock(&r->lock);
		why.text[sizeof why.text - 1] = '\0';
		snprintf(rd->error, sizeof rd->error, "%s", why.text);
	}
	if (rc != 1) {
		snprintf(rd->error, sizeof rd->error, "rank %d stopped answering%s%s", rd->rank,
			 rc < 0 ? ": " : " (killed, or its machine failed)", rc < 0 ? ajar_last_error() : "");
		if (!r->job_lost)
			r->job_lost = rd->rank;
	}
	scheduler_drop_device(r, rd, g, NULL, NULL, rc == 1 && d->kept);
	for (int k = 0; k < nq; k++) { /* queued there, never rendered */
		if (!range_list_push(&r->holes, q[k]))
			r->out_of_memory = 1;
		r->in_flight--;
	}
	if (rc == 1 && nq) { /* their answers, so no message is left behind */
		pthread_mutex_unlock(&r->lock);
		JobWhy why;
		for (int k = 0; k < nq; k++)
			if (cluster_recv(rd->rank, tag_done, d, sizeof *d, NULL, NULL, &r->cancel) == 1 && !d->ok)
				cluster_recv(rd->rank, tag_why, &why, sizeof why, NULL, NULL, &r->cancel);
		pthread_mutex_lock(&r->lock);
	}
	pthread_cond_broadcast(&r->cond);
}

/* Rank 0: the thread of a device of another rank. It keeps two ranges
 * there (PIPELINE): the device starts the next as soon as it ends one, so
 * the messages' latency is hidden. The speed is measured from one end of
 * a pass to the next (or from the send, when the device was idle). A
 * failure there comes back with whether the rank kept the device's film;
 * the range queued behind it comes back unrendered. */
#define PIPELINE 2

void *job_proxy_thread(void *arg)
{
	RenderDevice *rd = arg;
	ajar_renderer *r = rd->r;
	Range q[PIPELINE];
	double sent[PIPELINE], last = 0;
	int nq = 0, tag_pass = TAG_PASS + (int)rd->remote, tag_done = TAG_DONE + (int)rd->remote;
	pthread_mutex_lock(&r->lock);
	for (;;) {
		int lost = 0;
		while (nq < PIPELINE && !r->pausing && scheduler_take_range(r, rd, &q[nq])) {
			r->in_flight++;
			JobCmd c = {JOB_PASS, rd->remote, q[nq].first, q[nq].count};
			pthread_mutex_unlock(&r->lock);
			lost = cluster_send(rd->rank, tag_pass, &c, sizeof c) != 1;
			sent[nq++] = render_seconds();
			pthread_mutex_lock(&r->lock);
			if (lost)
				break;
		}
		if (nq == 0) {
			if (!r->pausing && (r->in_flight == 0 || scheduler_stopping(r)))
				break;
			pthread_cond_wait(&r->cond, &r->lock); /* a checkpoint, or a range may come back */
			continue;
		}
		pthread_mutex_unlock(&r->lock);
		JobDone d;
		int rc = lost ? -1 : cluster_recv(rd->rank, tag_done, &d, sizeof d, NULL, NULL, &r->cancel);
		double t = render_seconds(), start = fmax(sent[0], last);
		pthread_mutex_lock(&r->lock);
		Range g = q[0];
		for (int k = 1; k < nq; k++)
			q[k - 1] = q[k], sent[k - 1] = sent[k];
		nq--;
		r->in_flight--;
		r->events++;
		if (rc == 1 && d.ok) {
			scheduler_range_done(r, rd, g, t - start);
			if (d.idle >= 0) {
				rd->job_ranges++;
				rd->job_idle += d.idle;
			}
			last = t;
			pthread_cond_broadcast(&r->cond);
			continue;
		}
		proxy_drop(r, rd, g, q, nq, rc, &d);
		break;
	}
	r->running--;
	pthread_cond_broadcast(&r->cond);
	pthread_mutex_unlock(&r->lock);
	return NULL;
}

/* Rank 0: the other ranks' films summed into r->remote. */
ajar_status job_gather(ajar_renderer *r)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = film_splat_count(r);
	if (!r->remote) {
		r->remote = calloc(n ? n : 1, sizeof *r->remote);
		r->remote_splat = calloc(ns ? ns : 1, sizeof *r->remote_splat);
		if (!r->remote || !r->remote_splat)
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the other ranks' films");
	}
	memset(r->remote, 0, n * sizeof *r->remote);
	memset(r->remote_splat, 0, ns * sizeof *r->remote_splat);
	JobCmd c = {JOB_GATHER, 0, 0, 0};
	int rc = 1;
	for (int k = 1; k < cluster_size() && rc == 1; k++)
		rc = cluster_send(k, TAG_CMD, &c, sizeof c);
	if (rc == 1)
		rc = cluster_sum(r->remote, n, &r->cancel);
	if (rc == 1)
		rc = cluster_sum(r->remote_splat, ns, &r->cancel);
	/* Each rank says whether its films could be read. */
	for (int k = 1; k < cluster_size() && rc == 1; k++) {
		JobDone d;
		JobWhy why = {"?"};
		rc = cluster_recv(k, TAG_GATHERED, &d, sizeof d, NULL, NULL, &r->cancel);
		if (rc == 1 && !d.ok) {
			cluster_recv(k, TAG_GATHER_WHY, &why, sizeof why, NULL, NULL, &r->cancel);
			why.text[sizeof why.text - 1] = '\0';
			memset(r->remote, 0, n * sizeof *r->remote);
			return err_set(AJAR_ERROR_DEVICE, "rank %d: %s", k, why.text);
		}
	}
	if (rc == 1)
		return AJAR_OK;
	if (rc == 0)
		r->job_lost = -1;
	/* The films are incomplete: nothing may be written from them. */
	memset(r->remote, 0, n * sizeof *r->remote);
	return err_set(AJAR_ERROR_DEVICE, "summing the other ranks' films failed: %s",
		       rc < 0 ? ajar_last_error() : "a rank stopped answering (killed, or its machine failed)");
}

/* Rank 0, after its render loop: the last gather, and the other ranks
 * told to stop. */
ajar_status job_end(ajar_renderer *r, ajar_status st)
{
	if (r->job_lost) {
		/* No reduction can complete: mpirun ends the job. */
		char why[1024] = "";
		for (uint32_t i = 0; i < r->ndev; i++)
			if (r->devs[i].rank == r->job_lost)
				snprintf(why, sizeof why, "%s", r->devs[i].error);
		free(r->remote);
		free(r->remote_splat);
		r->remote = r->remote_splat = NULL;
		return err_set(AJAR_ERROR_DEVICE,
			       "%s; the job cannot be finished: no image is written%s", why[0] ? why : "a rank stopped answering",
			       r->ckpt_path ? " and the last checkpoint is kept" : "");
	}
	char msg[1024];
	snprintf(msg, sizeof msg, "%s", ajar_last_error());
	ajar_status g = job_gather(r);
	JobCmd c = {JOB_END, 0, (uint32_t)st, 0};
	for (int k = 1; k < cluster_size() && g == AJAR_OK; k++)
		if (cluster_send(k, TAG_CMD, &c, sizeof c) != 1)
			g = AJAR_ERROR_DEVICE;
	if (g != AJAR_OK) {
		free(r->remote);
		free(r->remote_splat);
		r->remote = r->remote_splat = NULL;
		r->job_lost = -1;
		return err_set(AJAR_ERROR_DEVICE, "%s; the job cannot be finished: no image is written%s",
			       ajar_last_error(), r->ckpt_path ? " and the last checkpoint is kept" : "");
	}
	if (st != AJAR_OK)
		err_set(st, "%s", msg);
	return st;
}

/* Other ranks: one thread per device renders the ranges rank 0 sends it
 * (straight to the thread: one wake-up less per range than through the
 * main thread). */
static void *job_device_thread(void *arg)
{
	RenderDevice *rd = arg;
	ajar_renderer *r = rd->r;
	int index = (int)(rd - r->devs);
	double ended = -1; /* when its previous pass ended */
	for (;;) {
		JobCmd c;
		if (cluster_recv(0, TAG_PASS + index, &c, sizeof c, NULL, &r->job_over, NULL) != 1)
			break; /* the render is over (or MPI failed: the job ends) */
		Range g = {c.first, c.count};
		JobDone d = {0, 0, -1.0};
		JobWhy why;
		memset(&why, 0, sizeof why);
		int film_ok = 0;
		double t0 = render_seconds();
		d.idle = ended < 0 ? -1.0 : t0 - ended;
		d.ok = rd->alive && render_device_pass(rd, g, &film_ok);
		ended = render_seconds();
		long *accum = NULL, *splat = NULL;
		if (!d.ok && rd->alive) {
			if (film_ok)
				film_read(rd, &accum, &splat);
			snprintf(why.text, sizeof why.text, "%s", rd->error);
		} else if (!d.ok) {
			snprintf(why.text, sizeof why.text, "device %d of rank %d was dropped before", index, cluster_rank());
		}
		if (!d.ok && rd->alive) {
			pthread_mutex_lock(&r->lock);
			d.kept = accum && film_salvage_add(r, accum, splat);
			rd->alive = 0; /* its film is in the salvage, or lost: rank 0 renders those ranges again */
			pthread_mutex_unlock(&r->lock);
		}
		free(accum);
		free(splat);
		if (cluster_send(0, TAG_DONE + index, &d, sizeof d) != 1 ||
		    (!d.ok && cluster_send(0, TAG_WHY + index, &why, sizeof why) != 1))
			break;
	}
	return NULL;
}

ajar_status job_serve(ajar_renderer *r)
{
	ajar_status st = AJAR_OK;
	atomic_store(&r->job_over, 0);
	for (uint32_t i = 0; i < r->ndev && st == AJAR_OK; i++) {
		RenderDevice *rd = &r->devs[i];
		rd->started = pthread_create(&rd->thread, NULL, job_device_thread, rd) == 0;
		if (!rd->started) {
			st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "rank %d: cannot start a render thread", cluster_rank());
			log_msg(AJAR_LOG_WARNING, "%s; the job stops", ajar_last_error());
		}
	}
	while (st == AJAR_OK) {
		JobCmd c;
		if (cluster_recv(0, TAG_CMD, &c, sizeof c, NULL, NULL, NULL) != 1) {
			st = AJAR_ERROR_DEVICE;
			break;
		}
		if (c.op == JOB_END) {
			st = (ajar_status)c.first;
			break;
		}
		if (c.op == JOB_GATHER) {
			/* Rank 0 gathers only while no pass is in flight anywhere. */
			size_t n = 3 * (size_t)r->width * r->height, ns = film_splat_count(r);
			JobDone d = {1, 0, -1.0};
			JobWhy why = {""};
			if (film_reduce(r) != AJAR_OK) {
				d.ok = 0;
				snprintf(why.text, sizeof why.text, "%s", ajar_last_error());
				memset(r->film, 0, n * sizeof *r->film);
				memset(r->film_splat, 0, ns * sizeof *r->film_splat);
			}
			if (cluster_sum(r->film, n, NULL) != 1 || cluster_sum(r->film_splat, ns, NULL) != 1 ||
			    cluster_send(0, TAG_GATHERED, &d, sizeof d) != 1 ||
			    (!d.ok && cluster_send(0, TAG_GATHER_WHY, &why, sizeof why) != 1)) {
				st = AJAR_ERROR_DEVICE;
				break;
			}
		}
	}
	atomic_store(&r->job_over, 1);
	for (uint32_t i = 0; i < r->ndev; i++)
		if (r->devs[i].started) {
			pthread_join(r->devs[i].thread, NULL);
			r->devs[i].started = 0;
		}
	return st;
}
