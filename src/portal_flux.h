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

#endif
