/* sky_tables.h — planar portals and the tables of the sky behind them
 * (kernels/light/portal_sky.h), built at load time where the environment is an
 * image. */
#ifndef AJAR_PORTAL_SKY_H
#define AJAR_PORTAL_SKY_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

/* Groups the portal triangles that show the sky (env_side != 0, set by
 * portal_flux_build) into planar portals — coplanar, sharing corners, the
 * same sky side — and tabulates the environment of `sc` behind each with
 * the kernels' own lookup, in tables of res cells a side (the program's
 * PORTAL_SKY_RES). *planes and *sky are malloc'd (NULL, 0 when there is no
 * image or no such triangle). */
ajar_status portal_sky_build(const SceneView *sc, const PortalTri *portals, uint32_t n, int res, PortalPlane **planes,
			     size_t *nplanes, float **sky, size_t *nsky);
#endif
