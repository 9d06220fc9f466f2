/* found_portals.h — the portal search on a loaded scene, outside a render
 * (ajar_scene_find_portals, `ajar info`). */
#ifndef AJAR_FOUND_PORTALS_H
#define AJAR_FOUND_PORTALS_H
#include "prepare/portal_find.h"
#include "scene/scene.h"

/* What the search reads of a scene besides its geometry. */
void portal_find_input(const Scene *s, PortalFindInput *in);
/* Builds a BVH for s and runs the search (portal_find). */
ajar_status portal_find_scene(const Scene *s, PortalSearch *out);
/* ps's portals as the API gives them (up to capacity into out). */
void portals_to_api(const PortalSearch *ps, ajar_portal *out, uint32_t capacity, uint32_t *count, double *seconds);
#endif
