/* render_options.c — ajar_options: the defaults, and the check every
 * renderer makes of what it is given. */
#include "render/render_options.h"

#include <string.h>

#include "core/error.h"

void ajar_options_default(ajar_options *o)
{
	memset(o, 0, sizeof *o);
	o->spp = 64;
	o->integrator = AJAR_INTEGRATOR_PT;
	o->max_depth = 0; /* the integrator's default */
	o->seed = 1;
	o->mis = AJAR_MIS_AUTO;
}

ajar_status options_resolve(const ajar_options *in, ajar_options *out)
{
	*out = *in;
	ajar_options *o = out;
	if (o->max_depth == 0)
		o->max_depth = o->integrator == AJAR_INTEGRATOR_PT ? 64 : AJAR_BIDIR_MAX_DEPTH;
	if (o->width > 16384 || o->height > 16384 || (o->width == 0) != (o->height == 0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "image size %ux%u: both must be in 1..16384",
			       o->width, o->height);
	if (o->integrator != AJAR_INTEGRATOR_PT && o->integrator != AJAR_INTEGRATOR_BDPT &&
	    o->integrator != AJAR_INTEGRATOR_PORTAL)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "unknown integrator %d", (int)o->integrator);
	if (o->max_depth < 1 || o->max_depth > 1024)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "max depth %u: must be in 1..1024", o->max_depth);
	/* Bidirectional subpaths live in fixed-size private arrays (kernels/integrator/vertex.h). */
	if (o->integrator != AJAR_INTEGRATOR_PT && o->max_depth > AJAR_BIDIR_MAX_DEPTH)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "max depth %u: bdpt and portal allow at most %d",
			       o->max_depth, AJAR_BIDIR_MAX_DEPTH);
	if (o->mis != AJAR_MIS_POWER && o->mis != AJAR_MIS_BALANCE && o->mis != AJAR_MIS_AUTO)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "unknown MIS heuristic %d", (int)o->mis);
	if (o->min_depth > o->max_depth)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "min depth %u exceeds max depth %u", o->min_depth,
			       o->max_depth);
	if (o->strategy_len && (o->integrator == AJAR_INTEGRATOR_PT || o->strategy_len > 8))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT,
			       "strategy images need a bidirectional integrator and a length of 1..8");
	if (!(o->noise >= 0.0 && o->noise < 1.0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "noise target %g: must be in [0, 1)", o->noise);
	if (o->spp == 0 && !(o->time_limit > 0) && !(o->noise > 0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "set a sample count, a time limit or a noise target");
	if (o->time_limit < 0 || o->time_limit != o->time_limit)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "time limit must be positive");
	if (o->portals != AJAR_PORTALS_DEFAULT && o->portals != AJAR_PORTALS_MARKED && o->portals != AJAR_PORTALS_FOUND &&
	    o->portals != AJAR_PORTALS_NONE)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "unknown portals choice %d", (int)o->portals);
	if (o->aov & ~AJAR_AOV_ALL)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "aov: unknown bits 0x%x", o->aov & ~AJAR_AOV_ALL);
	return AJAR_OK;
}
