/* scene_bvh.h — a scene's BVH, built once for the triangles it shares with
 * its renderers, which it puts in the BVH's leaf order (scene_bvh.c). */
#ifndef AJAR_SCENE_BVH_H
#define AJAR_SCENE_BVH_H
#include "scene/scene_share.h"

/* s's share (with a reference for the caller, released with
 * scene_share_release) with its BVH, built now if the share has none. */
ajar_status scene_bvh(Scene *s, SceneShare **out);
/* The device's Instance entries (kernels/base/types.h) of s with its
 * share's BVH: the transform and its inverse, computed in double and
 * rounded once, and the mesh's BVH root. *n is 0 without instances, *out
 * then one unused entry, so a device buffer exists. */
ajar_status scene_bvh_instances(const Scene *s, const SceneShare *sh, Instance **out, size_t *n);
#endif
