/* render_overrides.h — what only tests may choose, never the product:
 * a renderer whose policy choices are forced (PolicyOverrides), and faults
 * injected into the device passes. Not installed; include/ajar.h is the
 * API. Tests link the static library and include this header. */
#ifndef AJAR_RENDER_OVERRIDES_H
#define AJAR_RENDER_OVERRIDES_H
#include <stdint.h>

#include "ajar.h"
#include "prepare/policy.h"

/* ajar_renderer_create with some of the policy's choices forced. */
ajar_status renderer_create_overridden(const ajar_scene *scene, const ajar_options *o,
				       const PolicyOverrides *over, ajar_renderer **out);

/* Faults every renderer injects while they are set (all zero: none). Pass
 * number `pass` (from 1) of device `device` (from 0, in selection order)
 * fails: as if its kernel launch returned an error (the film stays
 * readable), or with `lost` after the kernel ran, as if the device was lost
 * mid-pass (the film is untrusted). pass_spp caps every pass at that many
 * samples per pixel, so a test can stop a render at many points. Set them
 * between renders, from one thread. */
typedef struct {
	uint32_t device, pass;
	int lost;
	uint32_t pass_spp;
} RenderFaults;
extern RenderFaults render_faults;
#endif
