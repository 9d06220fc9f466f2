/* portal_flux.h — what lies behind each side of every portal triangle,
 * measured once per scene on the host (see portal_flux.c). */
#ifndef AJAR_PORTAL_FLUX_H
#define AJAR_PORTAL_FLUX_H
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

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

/* The share of a sky image's light subpaths whose directions follow the
 * light that comes in through the portals (the rest follow the image
 * alone, a defensive part for openings without portals and for what the
 * geometric weight misses). */
#define SKY_LINES_PORTAL_MIX 0.9

/* Appends to a sky image's float array (*env, *nenv floats; grown to
 * ENV_LINE_FLOATS) the table its light subpaths take their directions
 * from when they start on lines through the portals (kernels/light/env.h,
 * env_line_sample): each texel's lum sin(theta), weighted by the portals'
 * area projected toward it from their sky side, mixed with the image's
 * own weight (SKY_LINES_PORTAL_MIX). Call after portal_flux_build. */
ajar_status portal_sky_lines_build(GLOBAL const Params *prm, const PortalTri *portals, uint32_t n, float **env,
				   size_t *nenv);

#endif
