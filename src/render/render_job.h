/* render_job.h — one render on several machines under Open MPI
 * (render_job.c). Without mpirun there is one rank, and only job_join is
 * called (it returns st). */
#ifndef AJAR_RENDER_JOB_H
#define AJAR_RENDER_JOB_H
#include "render/render_state.h"

/* Every rank, at the end of creating its renderer with status st: the
 * ranks' statuses, devices and hashes exchanged; a failure anywhere is
 * every rank's, and rank 0 adds the other ranks' devices to r->devs. */
ajar_status job_join(ajar_renderer *r, ajar_status st);
/* Rank 0: the thread that drives a device of another rank (a RenderDevice
 * with rank > 0), as a device thread drives a local one. */
void *job_proxy_thread(void *arg);
/* Rank 0, while no pass is in flight: the other ranks' films summed into
 * r->remote. */
ajar_status job_gather(ajar_renderer *r);
/* Rank 0, after its render loop ended with st: the last gather, and the
 * other ranks told to stop with st. */
ajar_status job_end(ajar_renderer *r, ajar_status st);
/* The other ranks' ajar_renderer_render: render what rank 0 sends until it
 * ends the render; returns rank 0's status. */
ajar_status job_serve(ajar_renderer *r);
#endif
