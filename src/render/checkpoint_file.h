/* checkpoint_file.h — the file a render can be continued from: its films as
 * integer sums, the sample ranges they hold, the options and hashes of the
 * prepared scene and of the render parameters (checkpoint_file.c).
 *
 * render_checkpoint.c gathers and applies the state; this module only writes the file
 * atomically (temporary name, fsync, rename: a failed write keeps the
 * previous file) and reads it back, refusing a file that is not a
 * checkpoint, comes from another version, is truncated or corrupted. */
#ifndef AJAR_CHECKPOINT_H
#define AJAR_CHECKPOINT_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

/* Sample indices [first, first + count) of every pixel. */
typedef struct {
	uint32_t first, count;
} SampleRange;

/* The films, in this order: own-pixel sums (3 per pixel), splats followed by
 * the strategy layers, first-hit AOVs. */
enum { CKPT_ACCUM, CKPT_SPLAT, CKPT_AOV, CKPT_SECTIONS };

typedef struct {
	char version[16];        /* AJAR_VERSION_STRING of the writer */
	uint64_t scene_hash;     /* of the prepared scene arrays (BVH, triangles, ...) */
	uint64_t params_hash;    /* of the kernels' Params (options, derived rates) */
	char scene[256];         /* the scene's file name, for messages */
	uint32_t width, height, integrator, max_depth, min_depth, seed, mis, strategy_len, strategy_unweighted;
	uint32_t spp;            /* the sample target, 0 = until the time limit */
	uint32_t aov;            /* AJAR_AOV_* bits */
	uint32_t portals;        /* ajar_portals */
	double time_limit, noise, elapsed; /* the budget: seconds, a noise target (ajar_options.noise) */
	SampleRange *ranges;     /* sorted, merged */
	uint32_t nranges;
	long *film[CKPT_SECTIONS];
	uint64_t nfilm[CKPT_SECTIONS];
} Checkpoint;

ajar_status checkpoint_write(const char *path, const Checkpoint *c);
/* Reads `path` into *c (zeroed first). header_only: everything but the
 * ranges and films, and only the header's own checks. Messages name the
 * file and what is wrong ("truncated", "corrupted", "made by Ajar x"). */
ajar_status checkpoint_read(const char *path, Checkpoint *c, int header_only);
void checkpoint_free(Checkpoint *c);

/* 64-bit hash (CRC-32 and Adler-32 side by side) of n bytes, continued from h. */
uint64_t checkpoint_hash(uint64_t h, const void *data, size_t n);
#endif
