/* scene_bvh.c — a scene's BVH, built once for its share of triangles
 * (scene/scene_share.h): the build hands over the leaf order before its
 * collapse, and the scene's triangles, shading data and extra attributes
 * are put in that order where they lie, so no second copy of them is ever
 * made. Renderers of the unchanged scene reuse the share and its BVH.
 *
 * Peak memory of a build over n triangles of 112 bytes (Tri and
 * TriShade): the triangles, 28 n of references, 4 n of order and the
 * binary tree (some 26 n) while binning; then the references are freed,
 * the triangles reordered, the order freed, and the binary tree and the
 * wide nodes (about 44 n) held during the collapse: about 182 n. */
#include "prepare/scene_bvh.h"

#include <pthread.h>
#include <time.h>

#include "core/error.h"
#include "prepare/bvh_build.h"

/* One build at a time per process: two renderers made at once from one
 * scene take the same share, and the second waits for the first's BVH. */
static pthread_mutex_t scene_bvh_lock = PTHREAD_MUTEX_INITIALIZER;

static double seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* new[i] = old[order[i]] for the three arrays at once, cycle by cycle;
 * the top bit of order marks the entries done (indices are below 2^29). */
#define DONE 0x80000000u
static void reorder_in_place(uint32_t *order, uint32_t n, void *ctx)
{
	SceneShare *sh = ctx;
	Tri *tris = sh->tris;
	TriShade *shade = sh->shade;
	TriExtra *extra = sh->extra;
	for (uint32_t i = 0; i < n; i++) {
		if (order[i] & DONE)
			continue;
		Tri t0 = tris[i];
		TriShade s0 = shade[i];
		TriExtra e0;
		if (extra)
			e0 = extra[i];
		uint32_t j = i;
		for (;;) {
			uint32_t k = order[j];
			order[j] |= DONE;
			if (k == i) {
				tris[j] = t0;
				shade[j] = s0;
				if (extra)
					extra[j] = e0;
				break;
			}
			tris[j] = tris[k];
			shade[j] = shade[k];
			if (extra)
				extra[j] = extra[k];
			j = k;
		}
	}
}

ajar_status scene_bvh(Scene *s, SceneShare **out)
{
	*out = NULL;
	pthread_mutex_lock(&scene_bvh_lock);
	SceneShare *sh = scene_share(s);
	ajar_status st = sh ? AJAR_OK : AJAR_ERROR_OUT_OF_MEMORY;
	if (sh && !sh->nodes) {
		double t0 = seconds();
		Bvh bvh;
		st = bvh_build_reorder(sh->tris, (uint32_t)sh->ntris, bvh_threads(), reorder_in_place, sh, &bvh);
		if (st == AJAR_OK) {
			sh->nodes = bvh.nodes;
			sh->nnodes = bvh.nnodes;
			sh->bvh_depth = bvh.depth;
			sh->bvh_wide_depth = bvh.wide_depth;
			sh->bvh_seconds = seconds() - t0;
		}
	}
	pthread_mutex_unlock(&scene_bvh_lock);
	if (st != AJAR_OK) {
		scene_share_release(sh);
		return st;
	}
	*out = sh;
	return AJAR_OK;
}

ajar_status ajar_scene_build_bvh(ajar_scene *s)
{
	if (!s)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_build_bvh: scene is NULL");
	if (s->ntris == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: the scene has no triangles", s->source);
	SceneShare *sh;
	ajar_status st = scene_bvh(s, &sh);
	scene_share_release(sh); /* the scene keeps the share, and the BVH with it */
	return st;
}
