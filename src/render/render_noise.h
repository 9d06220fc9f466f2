/* render_noise.h — the image's estimated relative error and stopping at a
 * noise level (render_noise.c; ajar_options.noise, ajar_renderer_noise). */
#ifndef AJAR_RENDER_NOISE_H
#define AJAR_RENDER_NOISE_H
#include "render/render_state.h"

/* No estimate yet, nothing kept (a new renderer, a restart). */
void noise_reset(ajar_renderer *r);
/* A new estimate into r->noise from the films as they are (the devices
 * idle), the sums kept for later ones. */
void noise_update(ajar_renderer *r);
/* From the render loop, under the lock, once r->spp_done reaches
 * r->noise_next: with the devices paused, a new estimate into r->noise;
 * at or below the target, r->noise_reached and no further ranges. */
void noise_during(ajar_renderer *r);
#endif
