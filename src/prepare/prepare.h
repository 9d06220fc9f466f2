/* prepare.h — turns a Scene into the flat arrays the kernels read: the BVH,
 * triangles in BVH order, light and portal tables, and Params. */
#ifndef AJAR_PREPARE_H
#define AJAR_PREPARE_H
#include "prepare/bvh_build.h"
#include "prepare/light_tables.h"
#include "prepare/policy.h"
#include "prepare/portal_find.h"
#include "scene/scene_share.h"

/* Scene features render_pass can be built without (kernel specialisation,
 * kernels/material/README.md, "Feature-specialised programs"): prepare_scene says
 * which a scene lacks (kernel_omit); device_render_options makes each a -D
 * option, and the cache keys on it. */
#define KERNEL_OMIT_ALPHA 1u        /* -DAJAR_NO_ALPHA: no TRI_ALPHA triangle */
#define KERNEL_OMIT_BENT_NORMALS 2u /* -DAJAR_NO_BENT_NORMALS: no shading normal tilted from ng, no normal map */
#define KERNEL_OMIT_TEXTURES 4u     /* -DAJAR_NO_TEXTURES: no material reads a texture */
#define KERNEL_OMIT_TRI_EXTRA 8u    /* -DAJAR_NO_TRI_EXTRA: no TRI_EXTRA triangle (TEXCOORD_1, COLOR_0, tangents) */
#define KERNEL_OMIT_PANES 16u       /* -DAJAR_NO_PANES: no TRI_PANE triangle (thin glass that rays cross) */
#define KERNEL_OMIT_INSTANCES 32u   /* -DAJAR_NO_INSTANCES: no instance (a one-level BVH, kernels/geom/bvh.h) */
#define KERNEL_OMIT_LAYERS 64u      /* -DAJAR_NO_LAYERS: no sheen, clear coat or specular colour */
#define KERNEL_OMIT_ANISOTROPY 128u /* -DAJAR_NO_ANISOTROPY: no anisotropic material */

/* nodes, tris, shade, extra and texels are the scene's share's (one copy
 * of the geometry, scene_share.h), the rest this SceneData's own. */
typedef struct {
#define AJAR_DATA_FIELD(type, name) type *name; size_t n_##name;
	AJAR_SCENE_BUFFERS(AJAR_DATA_FIELD)
#undef AJAR_DATA_FIELD
	SceneShare *share;
	int own_tris;            /* tris is a copy (a test's panes_opaque) */
	uint32_t bvh_depth, bvh_wide_depth;
	LightTables lights;
	float sun_share_portals; /* a sky image's sun's share of the sky light through the portals (portal_flux.c) */
	int sky_res;             /* cells a side of the planes' sky tables: the program's PORTAL_SKY_RES (kernels/light/portal_sky.h) */
	double bvh_seconds;
	int portal_source;       /* POLICY_PORTALS_*: where the portals came from */
	PortalSearch found;      /* the search's portals and cost, where they were found */
	V3 bmin, bmax;
	unsigned kernel_omit; /* KERNEL_OMIT_*: features no triangle or material uses */
} SceneData;

/* Prepares s for a width x height image rendered with the options o
 * (resolved: max_depth set); the policy (policy.h) decides the rest, with
 * over (NULL in the product) forcing some of its choices. The scene's
 * triangles are shared, put in its BVH's order the first time
 * (scene_bvh.h). */
ajar_status prepare_scene(Scene *s, const ajar_options *o, uint32_t width, uint32_t height,
			  const PolicyOverrides *over, SceneData *out);
void prepare_free(SceneData *d);
#endif
