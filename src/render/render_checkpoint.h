/* render_checkpoint.h — the renderer's side of checkpoints
 * (render_checkpoint.c); the public calls are in include/ajar.h
 * (ajar_renderer_write_checkpoint, _set_checkpoint, ajar_checkpoint_options). */
#ifndef AJAR_RENDER_CHECKPOINT_H
#define AJAR_RENDER_CHECKPOINT_H
#include "render/checkpoint_file.h"
#include "render/render_state.h"

/* For ajar_renderer_resume: the checkpoint at `path` and the options to
 * continue it with, the checkpoint's with the budget and devices of o if o
 * is not NULL (anything else in o must agree). In a job only rank 0 reads
 * the file. *have: *c holds the checkpoint (free it, whatever the status). */
ajar_status render_checkpoint_read(const char *path, const ajar_options *o, ajar_options *want, Checkpoint *c,
				   int *have);
/* While creating the resumed renderer: its scene and parameters must hash
 * as the checkpoint's (checked before any kernel is built)... */
ajar_status render_checkpoint_check(ajar_renderer *r, const Checkpoint *c, const char *path);
/* ...and once the films exist, the checkpoint's films become the salvage,
 * its ranges the base, the gaps holes (c's films are taken). */
ajar_status render_checkpoint_apply(ajar_renderer *r, Checkpoint *c, const char *path);
/* From the render loop, under the lock: a checkpoint to r->ckpt_path
 * with the devices paused; a failed write keeps the previous file. */
void render_checkpoint_during(ajar_renderer *r);
#endif
