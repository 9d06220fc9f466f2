/* pane_planes.h — the planes of the panes whose mirror image of the sky
 * next-event estimation samples (kernels/integrator/pane_mirror.h). */
#ifndef AJAR_PANE_PLANES_H
#define AJAR_PANE_PLANES_H
#include <stdint.h>

#include "base/types.h"

/* Fills p->num_pane_planes, pane_n and pane_d from the flat triangles
 * tris[0..n) marked TRI_PANE: their planes by area, at most
 * PANE_PLANES_MAX, each facing the sky side of the portal nearest to it
 * (a plane with no portal of a known sky side near it is left out).
 * Deterministic: the same triangles give the same planes. */
void pane_planes_build(const Tri *tris, uint32_t n, const PortalTri *portals, uint32_t n_portals, float radius,
		       Params *p);

#endif
