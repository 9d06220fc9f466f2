/* render_scheduler.c — which device renders which sample range: every
 * idle device takes the next range (the holes first), sized so a pass
 * takes about PASS_SECONDS at that device's measured speed (the first pass
 * is one sample: it also pays PoCL's work-group compile), and near the end
 * of a fixed-count render the rest is split by the devices' speeds, so no
 * device holds the render back by more than one pass. It keeps the ledger
 * of which ranges each device's film holds: a dropped device's range goes
 * back to the pool, and so do its completed ranges unless its film was
 * kept; every range covers all pixels, so the image is always the exact
 * mean of the sample indices it holds. Device threads (render_loop.c) and
 * the other ranks' proxies (render_job.c) call it alike, all under
 * r->lock. */
#include "render/render_scheduler.h"

#include <math.h>
#include <stdatomic.h>

#include "render/render_film.h"
#include "render/render_overrides.h"

#define PASS_SECONDS 0.25

double scheduler_time_left(const ajar_renderer *r)
{
	return r->time_limit > 0 ? r->time_limit - (render_seconds() - r->t0) : 1e30;
}

uint64_t scheduler_work_left(const ajar_renderer *r)
{
	uint64_t n = r->spp_target ? r->spp_target - r->next_first : UINT64_MAX;
	for (size_t i = 0; i < r->holes.n && n != UINT64_MAX; i++)
		n += r->holes.r[i].count;
	return n;
}

int scheduler_stopping(const ajar_renderer *r)
{
	return atomic_load(&r->cancel) || r->out_of_memory || r->job_lost || scheduler_time_left(r) <= 0;
}

int scheduler_take_range(ajar_renderer *r, RenderDevice *rd, Range *g)
{
	uint64_t left = scheduler_work_left(r);
	if (left == 0 || scheduler_stopping(r))
		return 0;
	uint32_t count = 1;
	if (rd->per_spp > 0) {
		count = (uint32_t)fmax(1.0, fmin(fmin(PASS_SECONDS, scheduler_time_left(r)) / rd->per_spp, 1e6));
		if (left != UINT64_MAX) {
			/* Near the end, split the rest by speed; a device not
			 * measured yet counts as fast as this one. */
			double rates = 0;
			for (uint32_t i = 0; i < r->ndev; i++)
				if (r->devs[i].alive)
					rates += 1.0 / (r->devs[i].per_spp > 0 ? r->devs[i].per_spp : rd->per_spp);
			double share = ceil((double)left / (rd->per_spp * rates));
			if (share < count)
				count = (uint32_t)share;
		}
	}
	/* Under a noise target a pass ends by the next estimate, so the render
	 * stops within a few percent of the samples the target needs. */
	if (r->opt.noise > 0.0) {
		uint32_t room = r->noise_next > r->next_first ? r->noise_next - r->next_first : 1;
		if (count > room)
			count = room;
	}
	if (render_faults.pass_spp && count > render_faults.pass_spp)
		count = render_faults.pass_spp;
	if (r->holes.n) {
		Range *h = &r->holes.r[r->holes.n - 1];
		g->first = h->first;
		g->count = count < h->count ? count : h->count;
		h->first += g->count;
		h->count -= g->count;
		if (h->count == 0)
			r->holes.n--;
		return 1;
	}
	if (left < count)
		count = (uint32_t)left;
	if (count > UINT32_MAX - r->next_first)
		return 0; /* the sample index space is exhausted */
	g->first = r->next_first;
	g->count = count;
	r->next_first += count;
	return 1;
}

void scheduler_range_done(ajar_renderer *r, RenderDevice *rd, Range g, double seconds)
{
	if (!range_list_push(&rd->done, g))
		r->out_of_memory = 1;
	rd->spp_kept += g.count;
	rd->busy_seconds += seconds;
	rd->per_spp = seconds / g.count;
	r->spp_done += g.count;
}

void scheduler_drop_device(ajar_renderer *r, RenderDevice *rd, Range g, const long *accum, const long *splat,
			   int kept_there)
{
	int kept = kept_there || (accum && film_salvage_add(r, accum, splat));
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
