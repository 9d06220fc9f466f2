/* render_loop.h — one render on this process's devices (render_loop.c). */
#ifndef AJAR_RENDER_LOOP_H
#define AJAR_RENDER_LOOP_H
#include "render/render_state.h"

/* Runs a thread per device (and, on rank 0 of a job, per device of the
 * other ranks) until the sample count, the time limit or a cancel; the
 * calling thread reports progress and writes the checkpoints. */
ajar_status render_loop(ajar_renderer *r, ajar_progress_fn fn, void *user);
#endif
