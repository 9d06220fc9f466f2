/* render_scheduler.h — which device renders which sample range, and which
 * ranges each device's film holds (render_scheduler.c). Every call is
 * made under r->lock. */
#ifndef AJAR_RENDER_SCHEDULER_H
#define AJAR_RENDER_SCHEDULER_H
#include "render/render_state.h"

/* Seconds left of the time limit (1e30 without one). */
double scheduler_time_left(const ajar_renderer *r);
/* Sample indices not yet handed out (UINT64_MAX: no sample target). */
uint64_t scheduler_work_left(const ajar_renderer *r);
/* The stop conditions other than running out of work. */
int scheduler_stopping(const ajar_renderer *r);
/* The next range for device rd, or 0 if there is none now. */
int scheduler_take_range(ajar_renderer *r, RenderDevice *rd, Range *g);
/* rd rendered g in `seconds`: its film holds g, and its speed is measured. */
void scheduler_range_done(ajar_renderer *r, RenderDevice *rd, Range g, double seconds);
/* Drops rd after its pass g failed: g goes back to the pool, and so do
 * its completed ranges unless its film was kept: read back (accum and
 * splat, added to the salvage) or, for a device of another rank, kept
 * there (kept_there). */
void scheduler_drop_device(ajar_renderer *r, RenderDevice *rd, Range g, const long *accum, const long *splat,
			   int kept_there);
#endif
