/* scene_bvh.c — a scene's BVH, built once for its share of triangles
 * (scene/scene_share.h): the build hands over the leaf order before its
 * collapse, and the scene's triangles, shading data and extra attributes
 * are put in that order where they lie, so no second copy of them is ever
 * made. Renderers of the unchanged scene reuse the share and its BVH.
 *
 * Peak memory of a build over n triangles of 112 bytes (Tri and
 * TriShade): the triangles, 32 n of references, 4 n of order and the
 * binary tree (some 26 n) while binning; then the triangles are reordered
 * through the references' memory (bvh_permute), the references and the
 * order freed, and the binary tree and the wide nodes (about 44 n) held
 * during the collapse: about 182 n. */
#include "prepare/scene_bvh.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/big_array.h"
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

/* new[i] = old[order[i]] for the three arrays at once, cycle by cycle,
 * over the whole arrays (scene_bvh_two_level, where the order is its own);
 * the top bit of order marks the entries done (indices are below 2^29). */
#define DONE 0x80000000u
static void reorder_all(SceneShare *sh, uint32_t *order, uint32_t n)
{
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

/* The one-level build's leaf order, on its threads (bvh_permute). */
static void reorder_leaves(BvhPermute *p, void *ctx)
{
	SceneShare *sh = ctx;
	bvh_permute(p, sh->tris, sizeof *sh->tris);
	bvh_permute(p, sh->shade, sizeof *sh->shade);
	if (sh->extra)
		bvh_permute(p, sh->extra, sizeof *sh->extra);
}

/* With instanced meshes (scene.h, SceneMesh): a top-level tree over the
 * flat triangles and the instances' world boxes, then one tree per mesh
 * over its object-space triangles, appended; the arrays end up as the flat
 * triangles in the top-level tree's order, then each mesh's in its own. */
static ajar_status scene_bvh_two_level(Scene *s, SceneShare *sh)
{
	uint32_t n = s->ntris, nflat = scene_flat_triangles(s), ninst = s->ninstances, nm = s->nmeshes;
	int threads = bvh_threads();
	ajar_status st = AJAR_OK;
	uint32_t *flat = malloc(sizeof *flat * (nflat ? nflat : 1));
	uint32_t *order = malloc(sizeof *order * n);
	V3 *mb = malloc(sizeof *mb * 2 * nm), *ib = malloc(sizeof *ib * 2 * (ninst ? ninst : 1));
	int32_t *root = malloc(sizeof *root * nm);
	if (!flat || !order || !mb || !ib || !root) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for the BVH of %u triangles", s->source, n);
		goto done;
	}
	for (uint32_t i = 0, k = 0, f = 0; k <= nm; k++) { /* the flat triangles before mesh k */
		uint32_t end = k < nm ? s->meshes[k].first : n;
		for (; i < end; i++)
			flat[f++] = i;
		if (k < nm)
			i = s->meshes[k].first + s->meshes[k].count;
	}
	for (uint32_t k = 0; k < nm; k++) {
		scene_mesh_bounds(s, k, &mb[2 * k], &mb[2 * k + 1]);
		root[k] = -1;
	}
	for (uint32_t j = 0; j < ninst; j++) {
		const SceneInstance *in = &s->instances[j];
		scene_instance_bounds(in, mb[2 * in->mesh], mb[2 * in->mesh + 1], &ib[j], &ib[ninst + j]);
		root[in->mesh] = 0; /* has instances: gets a tree */
	}
	Bvh bvh;
	memset(&bvh, 0, sizeof bvh);
	BvhInput top = {sh->tris, flat, nflat, ib, ib + ninst, nflat + ninst, 0};
	if ((st = bvh_build_input(&top, threads, NULL, NULL, &bvh)) != AJAR_OK)
		goto done;
	sh->bvh_depth = bvh.depth;
	sh->bvh_wide_depth = bvh.wide_depth;
	for (uint32_t k = 0; k < nflat; k++)
		order[k] = flat[bvh.order[k]];
	free(bvh.order);
	bvh.order = NULL;
	uint32_t pos = nflat;
	for (uint32_t k = 0; k < nm && st == AJAR_OK; k++) {
		SceneMesh *m = &s->meshes[k];
		if (root[k] == 0) {
			root[k] = (int32_t)bvh.nnodes;
			BvhInput mesh = {sh->tris + m->first, NULL, m->count, NULL, NULL, m->count, pos};
			if ((st = bvh_build_input(&mesh, threads, NULL, NULL, &bvh)) != AJAR_OK)
				break;
			for (uint32_t i = 0; i < m->count; i++)
				order[pos + i] = m->first + bvh.order[i];
			free(bvh.order);
			bvh.order = NULL;
		} else {
			for (uint32_t i = 0; i < m->count; i++)
				order[pos + i] = m->first + i;
		}
		m->first = pos; /* where reorder_all moves it */
		pos += m->count;
	}
	if (st != AJAR_OK) {
		big_free(bvh.nodes, sizeof(BvhNode) * (size_t)bvh.nnodes);
		goto done;
	}
	reorder_all(sh, order, n);
	sh->nodes = bvh.nodes;
	sh->nnodes = bvh.nnodes;
	sh->mesh_root = root;
	root = NULL;
done:
	free(flat);
	free(order);
	free(mb);
	free(ib);
	free(root);
	return st;
}

ajar_status scene_bvh(Scene *s, SceneShare **out)
{
	*out = NULL;
	pthread_mutex_lock(&scene_bvh_lock);
	SceneShare *sh = scene_share(s);
	ajar_status st = sh ? AJAR_OK : AJAR_ERROR_OUT_OF_MEMORY;
	if (sh && s->ntris > BVH_MAX_TRIS)
		st = err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %u triangles, at most %u supported", s->source, s->ntris,
			     (unsigned)BVH_MAX_TRIS);
	if (sh && !sh->nodes && st == AJAR_OK) {
		double t0 = seconds();
		if (s->nmeshes) {
			st = scene_bvh_two_level(s, sh);
		} else {
			Bvh bvh;
			st = bvh_build_reorder(sh->tris, (uint32_t)sh->ntris, bvh_threads(), reorder_leaves, sh, &bvh);
			if (st == AJAR_OK) {
				sh->nodes = bvh.nodes;
				sh->nnodes = bvh.nnodes;
				sh->bvh_depth = bvh.depth;
				sh->bvh_wide_depth = bvh.wide_depth;
			}
		}
		if (st == AJAR_OK)
			sh->bvh_seconds = seconds() - t0;
	}
	pthread_mutex_unlock(&scene_bvh_lock);
	if (st != AJAR_OK) {
		scene_share_release(sh);
		return st;
	}
	*out = sh;
	return AJAR_OK;
}

ajar_status scene_bvh_instances(const Scene *s, const SceneShare *sh, Instance **out, size_t *n)
{
	*out = calloc(s->ninstances ? s->ninstances : 1, sizeof **out);
	*n = 0;
	if (!*out)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for %u instances", s->source, s->ninstances);
	*n = s->ninstances;
	for (uint32_t j = 0; j < s->ninstances; j++) {
		const SceneInstance *si = &s->instances[j];
		Instance *in = &(*out)[j];
		const double *m = si->m;
		/* The inverse of the 3x3 part by cofactors, then the translation. */
		double c[9] = {m[5] * m[10] - m[6] * m[9], m[2] * m[9] - m[1] * m[10], m[1] * m[6] - m[2] * m[5],
			       m[6] * m[8] - m[4] * m[10], m[0] * m[10] - m[2] * m[8], m[2] * m[4] - m[0] * m[6],
			       m[4] * m[9] - m[5] * m[8], m[1] * m[8] - m[0] * m[9], m[0] * m[5] - m[1] * m[4]};
		double det = m[0] * c[0] + m[1] * c[3] + m[2] * c[6];
		for (int r = 0; r < 3; r++) {
			double t = 0.0;
			for (int k = 0; k < 3; k++) {
				double v = c[3 * r + k] / det;
				in->inv[4 * r + k] = (float)v;
				t -= v * m[4 * k + 3];
			}
			in->inv[4 * r + 3] = (float)t;
		}
		for (int k = 0; k < 12; k++)
			in->xf[k] = (float)m[k];
		in->root = sh->mesh_root[si->mesh];
		in->flags = det < 0.0 ? INSTANCE_MIRROR : 0;
		in->mesh = (int)si->mesh;
	}
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
