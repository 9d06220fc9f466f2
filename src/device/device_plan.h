/* device_plan.h — how a pass spreads over a device (device_plan.c): where
 * bdpt's and portal's subpaths live, work-items per pixel, and the options
 * render_pass is built with for that plan and the scene's features
 * (kernels/gpu.md, "On GPUs: subpaths in global memory"). */
#ifndef AJAR_DEVICE_PLAN_H
#define AJAR_DEVICE_PLAN_H
#include <stddef.h>

#include "device/device.h"

/* PathVertex, as the host reserves room for it: at most
 * DEVICE_VERTEX_WORDS 32-bit words (kernels/integrator/vertex.h refuses to build
 * otherwise), SUBPATH_MAX vertices a subpath. */
#define DEVICE_VERTEX_WORDS 72
#define DEVICE_SUBPATH_MAX 33
typedef struct {
	int soa;           /* subpaths in a global scratch buffer (-DAJAR_SUBPATH_SOA), else private arrays */
	size_t capacity;   /* work-items the scratch holds (its stride), the most one launch covers */
	unsigned lanes;    /* work-items per pixel: a pass's samples of a pixel are split between them */
	size_t scratch_bytes; /* 0 without scratch */
	unsigned omit;        /* DEVICE_OMIT_*: scene features the program leaves out (the caller sets it) */
	int general;          /* AJAR_KERNEL_FEATURES=all: omit nothing, whatever `omit` says */
	int sky_res;          /* cells a side of the planes' sky tables (-DPORTAL_SKY_RES unless 128; the caller sets it) */
} DevicePlan;
/* Scene features render_pass can be built without (kernel specialisation,
 * kernels/materials.md "Feature-specialised programs"): prepare_scene says
 * which a scene lacks; each becomes a -D option, and the cache keys on it. */
#define DEVICE_OMIT_ALPHA 1u        /* -DAJAR_NO_ALPHA: no TRI_ALPHA triangle */
#define DEVICE_OMIT_BENT_NORMALS 2u /* -DAJAR_NO_BENT_NORMALS: no shading normal tilted from ng, no normal map */
#define DEVICE_OMIT_TEXTURES 4u     /* -DAJAR_NO_TEXTURES: no material reads a texture */
#define DEVICE_OMIT_TRI_EXTRA 8u    /* -DAJAR_NO_TRI_EXTRA: no TRI_EXTRA triangle (TEXCOORD_1, COLOR_0, tangents) */
#define DEVICE_OMIT_PANES 16u       /* -DAJAR_NO_PANES: no TRI_PANE triangle (thin glass that rays cross) */
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
