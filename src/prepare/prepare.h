/* prepare.h — turns a Scene into the flat arrays the kernels read: the BVH,
 * triangles in BVH order, light and portal tables, and Params. */
#ifndef AJAR_PREPARE_H
#define AJAR_PREPARE_H
#include "prepare/bvh_build.h"
#include "prepare/light_tables.h"
#include "scene/scene.h"

typedef struct {
#define AJAR_DATA_FIELD(type, name) type *name; size_t n_##name;
	AJAR_SCENE_BUFFERS(AJAR_DATA_FIELD)
#undef AJAR_DATA_FIELD
	Bvh bvh;
	LightTables lights;
	float sun_share_portals; /* portal with a sky image: its sun's share of the sky light through the portals (portal_flux.c) */
	int sky_res;             /* cells a side of the planes' sky tables: the program's PORTAL_SKY_RES (kernels/light/portal_sky.h) */
	double bvh_seconds;
	V3 bmin, bmax;
	unsigned kernel_omit; /* DEVICE_OMIT_* (device.h): features no triangle or material uses */
} SceneData;

typedef struct {
	uint32_t width, height;
	int integrator;
	uint32_t max_depth;
	uint32_t seed;
	int mis;
	uint32_t min_depth;
	uint32_t strategy_len;
	int strategy_unweighted;
	int sky_res; /* cells a side of the planes' sky tables; 0: prepare_scene's choice (tests set their kernels' PORTAL_SKY_RES) */
} PrepareOptions;

/* The portal integrator's default rates of intermediate subpaths, in
 * scenes lit only by the sky and with emitters (kernels/README.md, "portal");
 * AJAR_PORTAL_RATE overrides them. */
#define PORTAL_RATE_SKY 0.1f
#define PORTAL_RATE_EMITTERS 1.0f
/* Scenes lit only by a sky image, sampled through planar portals. */
#define PORTAL_RATE_SKY_IMAGE 0.3f
/* The sun's share of the sky light through the portals
 * (src/prepare/portal_flux.c, portal_sun_share) from which portal traces the
 * sky's light subpaths (through the portals), and so renders as bdpt:
 * between an overcast sky's 0.020, where bdpt and portal without them were
 * even, and window-room-sunset's 0.066, where bdpt won by 1.3-1.4x once
 * its weights read the subpaths' MIS tails (kernels/sky_measurements.md,
 * "Weights from tails", "The sun through the openings"). The whole sky's
 * share, 0.02 until session 27, sat between the same skies' 0.01 and
 * 0.03 but saw a sun behind the wall. */
#define SKY_SUN_SHARE 0.04f
/* Where portal renders as bdpt (light subpaths bring the light in), its
 * strategies other than light tracing use at most this many light
 * vertices (Params.bdpt_conn): 2, measured against 1 and all
 * (kernels/sky_measurements.md, "Connections to the first light
 * vertices"). */
#define PORTAL_BDPT_CONN 2

ajar_status prepare_scene(const Scene *s, const PrepareOptions *o, SceneData *out);
void prepare_free(SceneData *d);
#endif
