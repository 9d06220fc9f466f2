/* device_plan.h — how a pass spreads over a device (device_plan.c): where
 * bdpt's and portal's subpaths live, work-items per pixel, and the options
 * render_pass is built with for that plan and the scene's features
 * (kernels/integrator/README.md, "Where subpaths live"). */
#ifndef AJAR_DEVICE_PLAN_H
#define AJAR_DEVICE_PLAN_H
#include <stddef.h>

#include "device/device.h"

/* PathVertex, as the host reserves room for it: at most
 * DEVICE_VERTEX_WORDS 32-bit words (kernels/integrator/vertex.h refuses to build
 * otherwise), SUBPATH_MAX vertices a subpath. */
#define DEVICE_VERTEX_WORDS 116
#define DEVICE_SUBPATH_MAX 33
typedef struct {
	int soa;           /* subpaths in a global scratch buffer (-DAJAR_SUBPATH_SOA), else private arrays */
	size_t capacity;   /* work-items the scratch holds (its stride), the most one launch covers */
	unsigned lanes;    /* work-items per pixel: a pass's samples of a pixel are split between them */
	size_t scratch_bytes; /* 0 without scratch */
	unsigned omit;        /* KERNEL_OMIT_* (prepare.h): scene features the program leaves out (the caller sets it) */
	int general;          /* AJAR_KERNEL_FEATURES=all: omit nothing, whatever `omit` says */
	int sky_res;          /* cells a side of the planes' sky tables (-DPORTAL_SKY_RES unless 128; the caller sets it) */
} DevicePlan;
/* The plan of integrator `integrator` for an image of npix pixels on d:
 * private arrays on CPUs and for pt, the scratch on other devices; one lane
 * per pixel on CPUs, on other devices enough for compute units x
 * max work-group size x 2 work-items in flight (at most 64); a scratch of
 * that many work-items, within half the device's memory and its largest
 * buffer. AJAR_SUBPATHS=private|global, AJAR_SUBPATH_CAPACITY=N and
 * AJAR_PASS_LANES=N override (tests, measurements); AJAR_KERNEL_FEATURES=all
 * sets `general` (empty or "scene": specialise); a malformed value or a
 * scratch that does not fit is an error. */
ajar_status device_plan(const Device *d, int integrator, size_t npix, DevicePlan *p);
/* The options render_pass is built with: device_build_options', the
 * plan's (-DAJAR_SUBPATH_SOA=capacity -DAJAR_SUBPATH_WORDS=n for the
 * scratch, -DAJAR_NO_* for p->omit unless p->general), then `extra`
 * (AJAR_CL_OPTIONS, NULL for none). */
void device_render_options(const Device *d, int integrator, const DevicePlan *p, const char *extra, char *buf,
			   size_t cap);
#endif
