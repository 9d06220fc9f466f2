/* render_device.h — a renderer's devices (render_device.c): each set up
 * with its program, scene and films, one pass of a sample range on one,
 * and torn down. */
#ifndef AJAR_RENDER_DEVICE_H
#define AJAR_RENDER_DEVICE_H
#include "render/render_state.h"

/* Opens every device `selector` chooses into r->devs. With several, one
 * that cannot be set up is left out with a warning; with none left, the
 * last error stands. */
ajar_status render_devices_open(ajar_renderer *r, const char *selector);
void render_device_close(RenderDevice *rd);
/* For a restart: the renderer's params again, and films of zeros. */
ajar_status render_device_reset(RenderDevice *rd);
/* Renders range g on rd, unlocked; 0 if it failed, with rd->error set and
 * *film_ok telling whether the film still holds exactly the completed
 * ranges (the kernel never started). */
int render_device_pass(RenderDevice *rd, Range g, int *film_ok);
#endif
