/* portal_groups.h — portal triangles grouped into openings. */
#ifndef AJAR_PORTAL_GROUPS_H
#define AJAR_PORTAL_GROUPS_H
#include <stdint.h>

#include "base/types.h"

/* root[k]: the smallest index of triangle k's group, the triangles in one
 * plane that share a corner, transitively (a window's two triangles, a row
 * of panes marked as one mesh). With sky, only triangles that show the sky
 * (env_side != 0, portal_flux_build) join, and only those facing it alike;
 * the others are groups of their own. Without, any two coplanar ones,
 * whichever way they face (before the sky's side is known). */
void portal_groups(const PortalTri *p, uint32_t n, int sky, uint32_t *root);

/* The smallest rectangle around group g (the triangles k with root[k] ==
 * g) in the plane of normal n through o, with a side along one of their
 * edges: a window's own sides, not its diagonal, whose frame would bound
 * twice a square's area. Its sides *t and *b = n x *t, its extents
 * [*a0, *a1] x [*b0, *b1] from o; returns its area, 0 if none. */
float portal_group_rect(const PortalTri *p, const uint32_t *root, uint32_t n, uint32_t g, V3 nrm, V3 o, V3 *t,
			V3 *b, float ext[4]);
#endif
