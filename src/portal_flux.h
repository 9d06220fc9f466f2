/* portal_flux.h — what lies behind each side of every portal triangle,
 * measured once per scene on the host (see portal_flux.c). */
#ifndef AJAR_PORTAL_FLUX_H
#define AJAR_PORTAL_FLUX_H
#include <stdint.h>

#include "ajar.h"
#include "../kernels/types.h"

/* Fills env_side, side_plus and pdf_select of the scene's portal
 * triangles (sc->portals, writable as `portals`) and rebuilds their
 * selection CDF `portal_cdf` (n + 1 floats). sc must be complete: BVH,
 * triangles, emitter and environment tables, Params. */
ajar_status portal_flux_build(const SceneView *sc, PortalTri *portals, uint32_t n, float *portal_cdf);

/* The share of a sky image's power coming in through the portals (each
 * texel weighted by the portals' area projected toward it from their sky
 * side) that its brightest 0.1% of solid angle carries: a sun's, seen
 * through the openings. 0 without a sky image. Call after
 * portal_flux_build (it reads env_side). */
float portal_sun_share(const SceneView *sc, const PortalTri *portals, uint32_t n);

#endif
