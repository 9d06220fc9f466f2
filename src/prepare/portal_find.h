/* portal_find.h — openings found without markup: the host looks for the
 * windows, doors ajar and roof openings through which light from outside
 * the camera's space reaches it, and places a rectangular portal over each
 * (portal_find.c has the method; src/prepare/README.md its record). */
#ifndef AJAR_PORTAL_FIND_H
#define AJAR_PORTAL_FIND_H
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

/* A found portal: the rectangle c +- u +- v (u, v its half sides, u x v
 * along n), n unit, facing into the camera's space. */
typedef struct {
	V3 c, u, v, n;
	float share; /* its share of the light-carrying rays the search found through openings */
} FoundPortal;

/* What the search reads besides the geometry. */
typedef struct {
	V3 camera;                /* the camera's position */
	int env_type;             /* ENV_*: a sky behind every opening to the open */
	const ajar_light *lights; /* the punctual lights, glTF units (directions unit) */
	uint32_t nlights;
} PortalFindInput;

/* The search's result: portals by decreasing share, its cost. */
typedef struct {
	FoundPortal *portals;
	uint32_t count;
	uint64_t rays;   /* rays traced */
	double seconds;  /* wall time of the search */
} PortalSearch;

/* Finds the openings of the scene v (nodes, tris, shade, extra,
 * materials, textures and texels set; the other arrays unused) from the
 * camera's space. Deterministic: the same scene gives the same portals. */
ajar_status portal_find(const SceneView *v, uint32_t ntris, const PortalFindInput *in, PortalSearch *out);
void portal_search_free(PortalSearch *s);

/* The two triangles of found portal f as portal triangles (their normal
 * along f->n), as scene_add_portal makes them. */
void portal_found_tris(const FoundPortal *f, PortalTri out[2]);
#endif
