/* portal_slide.h — portals, marked or found, moved out through the tunnel
 * they lie in (a window marked on a thick wall's room face, a skylight at
 * the ceiling under a roof slab). */
#ifndef AJAR_PORTAL_SLIDE_H
#define AJAR_PORTAL_SLIDE_H
#include "base/types.h"

/* Moves each opening's portal triangles p[0..n) (groups that share
 * corners) away from the camera's side through the tunnel they lie in, to
 * its far end; returns how many triangles moved. v: the scene's geometry. */
uint32_t portal_slide(const SceneView *v, PortalTri *p, uint32_t n, V3 camera);
#endif
