/* render_scheduler.c — which device renders which sample range: every
 * idle device takes the next range (the holes first), sized so a pass
 * takes about PASS_SECONDS at that device's measured speed, and near the
 * end of a fixed-count render the rest is split by the devices' speeds.
 * Device threads (render.c) and the other ranks' proxies (render_job.c)
 * call it alike, all under r->lock. */
#include <math.h>
#include <stdatomic.h>

#include "render/render_internal.h"
#include "render/render_overrides.h"

#define PASS_SECONDS 0.25

double scheduler_time_left(const ajar_renderer *r)
{
	return r->time_limit > 0 ? r->time_limit - (render_seconds() - r->t0) : 1e30;
}

/* Sample indices not yet handed out (UINT64_MAX: no sample target). */
uint64_t scheduler_work_left(const ajar_renderer *r)
{
	uint64_t n = r->spp_target ? r->spp_target - r->next_first : UINT64_MAX;
	for (size_t i = 0; i < r->holes.n && n != UINT64_MAX; i++)
		n += r->holes.r[i].count;
	return n;
}

/* The stop conditions other than running out of work. */
int scheduler_stopping(const ajar_renderer *r)
{
	return atomic_load(&r->cancel) || r->out_of_memory || r->job_lost || scheduler_time_left(r) <= 0;
}

/* The next range for device rd, or 0 if there is none now. */
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
