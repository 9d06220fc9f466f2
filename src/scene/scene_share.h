/* scene_share.h — the scene's large arrays held once, by the scene and by
 * every renderer prepared from it (issue 42: one copy of the geometry).
 *
 * The first prepare_scene of a scene takes a share of its triangles,
 * shading data, extra attributes and texels, builds the BVH once, puts the
 * triangles in its leaf order in place and keeps the BVH here; later
 * renderers of the unchanged scene take the same share and its BVH.
 * Devices on the CPU read these arrays where they are. The scene writes
 * to them only through scene_private(), which first gives the scene arrays
 * of its own when a renderer still holds the share (or takes the arrays
 * back when none does). */
#ifndef AJAR_SCENE_SHARE_H
#define AJAR_SCENE_SHARE_H
#include <stdatomic.h>

#include "scene/scene.h"

struct SceneShare {
	atomic_int refs;        /* the scene's, while it holds the share, and each holder's */
	/* The scene's arrays (big_array.h) and their capacities in items. */
	Tri *tris;
	TriShade *shade;
	size_t ntris, cap_tris;
	TriExtra *extra;        /* NULL, or one per triangle */
	size_t cap_extra;
	uint32_t *texels;
	size_t ntexels, cap_texels;
	/* What src/prepare/ builds once for these triangles: the BVH, with
	 * the triangles above in its leaf order. */
	BvhNode *nodes;         /* a big array of nnodes: the top-level tree first */
	uint32_t nnodes;
	int32_t *mesh_root;     /* with meshes: each one's BVH root node, -1 for one without instances */
	uint32_t bvh_depth, bvh_wide_depth;
	double bvh_seconds;
};

/* The scene's share, made on first use, with one more reference for the
 * caller; NULL when out of memory (error set). */
SceneShare *scene_share(Scene *s);
/* Drops a reference; the last one frees the arrays. NULL is ignored. */
void scene_share_release(SceneShare *sh);
#endif
