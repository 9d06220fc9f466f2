/* sky_tables.h — planar portals and the tables of the sky behind them
 * (kernels/light/portal_sky.h), built at load time where the environment is an
 * image. */
#ifndef AJAR_SKY_TABLES_H
#define AJAR_SKY_TABLES_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

/* Groups the portal triangles that show the sky (env_side != 0, set by
 * portal_flux_build) into planar portals: coplanar, sharing corners, the
 * same sky side. *planes is malloc'd (NULL, 0 when there is no such
 * triangle); the caller builds them only under a sky image. */
ajar_status portal_sky_planes(const PortalTri *portals, uint32_t n, PortalPlane **planes, size_t *nplanes);
/* Tabulates the environment of `sc` behind each plane with the kernels' own
 * lookup, in tables of res cells a side (the program's PORTAL_SKY_RES), and
 * sets each plane's table offset. *sky is malloc'd (NULL, 0 without planes). */
ajar_status portal_sky_tables(const SceneView *sc, PortalPlane *planes, size_t nplanes, int res, float **sky,
			      size_t *nsky);
#endif
