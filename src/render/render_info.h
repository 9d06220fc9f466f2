/* render_info.h — what the output writers (output.c) need to know about
 * a renderer, without the scheduling state of render.c. */
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
#endif
