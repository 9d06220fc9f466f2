/* render_film.h — the renderer's films (render_film.c): their sizes, a
 * device's films read back, the salvage of dropped devices, the integer
 * reduction, and the image and AOVs read out of it. */
#ifndef AJAR_RENDER_FILM_H
#define AJAR_RENDER_FILM_H
#include <stddef.h>

#include "render/render_state.h"

/* Bytes of the own-pixel film: 3 longs a pixel. */
size_t film_bytes(const ajar_renderer *r);
/* Longs before the AOV film in the splat buffer: the splats and layers. */
size_t film_aov_offset(const ajar_renderer *r);
/* Longs of the splat buffer: the splat film, the strategy layers, the AOVs. */
size_t film_splat_count(const ajar_renderer *r);
size_t film_splat_bytes(const ajar_renderer *r);

/* Reads a device's films into fresh host arrays; 0 if it cannot. */
int film_read(RenderDevice *rd, long **accum, long **splat);
/* Adds a dropped device's films to the salvage (under the lock); 0 if out of memory. */
int film_salvage_add(ajar_renderer *r, const long *accum, const long *splat);
/* Sums the salvage, the other ranks' films and every live device's films
 * into r->film and r->film_splat. */
ajar_status film_reduce(ajar_renderer *r);
/* The reduced image as RGBA (ajar_renderer_image), and the AOVs
 * (ajar_renderer_aovs, AOV_CHANNELS a pixel). */
ajar_status film_image(ajar_renderer *r, float *rgba);
ajar_status film_aovs(ajar_renderer *r, float *px);
#endif
