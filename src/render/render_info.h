/* render_info.h — what a renderer tells about itself (render_info.c): the
 * figures of each device, the line of their shares, and what the output
 * writers (output.c) put in a file's header; without the renderer's
 * state, which stays in render_state.h. */
#ifndef AJAR_RENDER_INFO_H
#define AJAR_RENDER_INFO_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

typedef struct {
	uint32_t width, height, spp, seed, max_depth;
	double seconds;
	const char *integrator, *devices, *scene;
	char shares[2048]; /* per-device share and throughput */
	int nlayers, strategy_len, strategy_unweighted;
	/* The strategy layers, fixed point, 3 * width * height each; current
	 * after ajar_renderer_image. */
	const long *layers;
	uint32_t aov; /* AJAR_AOV_* bits the EXR adds (ajar_renderer_aovs) */
} RenderInfo;

void render_info(const ajar_renderer *r, RenderInfo *info);
/* The figures of device `index` (below ajar_renderer_device_count). */
void render_info_device(const ajar_renderer *r, uint32_t index, ajar_device_stats *out);
/* "name (P:D): 52.1% 0.71 Msamples/s; ..." for the log and the EXR header. */
void render_info_shares(const ajar_renderer *r, char *buf, size_t cap);
#endif
