/* scene_share.c — see scene_share.h. */
#include "scene/scene_share.h"

#include <stdlib.h>
#include <string.h>

#include "core/big_array.h"
#include "core/error.h"

SceneShare *scene_share(Scene *s)
{
	if (!s->share) {
		SceneShare *sh = calloc(1, sizeof *sh);
		if (!sh) {
			err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->source);
			return NULL;
		}
		atomic_init(&sh->refs, 1);
		sh->tris = s->tris;
		sh->shade = s->shade;
		sh->ntris = s->ntris;
		sh->cap_tris = s->cap_tris;
		sh->extra = s->extra;
		sh->cap_extra = s->cap_extra;
		sh->texels = s->texels;
		sh->ntexels = s->ntexels;
		sh->cap_texels = s->cap_texels;
		s->share = sh;
	}
	atomic_fetch_add(&s->share->refs, 1);
	return s->share;
}

static void share_free(SceneShare *sh, int arrays)
{
	if (arrays) {
		big_free(sh->tris, sh->cap_tris * sizeof *sh->tris);
		big_free(sh->shade, sh->cap_tris * sizeof *sh->shade);
		big_free(sh->extra, sh->cap_extra * sizeof *sh->extra);
		big_free(sh->texels, sh->cap_texels * sizeof *sh->texels);
	}
	big_free(sh->nodes, (size_t)sh->nnodes * sizeof *sh->nodes);
	free(sh->mesh_root);
	free(sh);
}

void scene_share_release(SceneShare *sh)
{
	if (sh && atomic_fetch_sub(&sh->refs, 1) == 1)
		share_free(sh, 1);
}

/* A copy of n items of `size` in a big array of capacity cap (>= n). */
static void *copy_of(const void *p, size_t n, size_t cap, size_t size)
{
	if (!p)
		return NULL;
	void *q = big_alloc(cap * size);
	if (q)
		memcpy(q, p, n * size);
	return q;
}

ajar_status scene_private(Scene *s)
{
	SceneShare *sh = s->share;
	if (!sh)
		return AJAR_OK;
	if (atomic_load(&sh->refs) == 1) {
		/* No renderer holds it: the arrays are the scene's again, in the
		 * BVH's order; the BVH goes, since the scene is about to change. */
		s->share = NULL;
		share_free(sh, 0);
		return AJAR_OK;
	}
	Tri *tris = copy_of(s->tris, s->ntris, s->cap_tris, sizeof *tris);
	TriShade *shade = copy_of(s->shade, s->ntris, s->cap_tris, sizeof *shade);
	TriExtra *extra = copy_of(s->extra, s->extra ? s->ntris : 0, s->cap_extra, sizeof *extra);
	uint32_t *texels = copy_of(s->texels, s->ntexels, s->cap_texels, sizeof *texels);
	if ((s->tris && !tris) || (s->shade && !shade) || (s->extra && !extra) || (s->texels && !texels)) {
		big_free(tris, s->cap_tris * sizeof *tris);
		big_free(shade, s->cap_tris * sizeof *shade);
		big_free(extra, s->cap_extra * sizeof *extra);
		big_free(texels, s->cap_texels * sizeof *texels);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for a copy of the scene's triangles", s->source);
	}
	s->tris = tris;
	s->shade = shade;
	s->extra = extra;
	s->texels = texels;
	s->share = NULL;
	scene_share_release(sh);
	return AJAR_OK;
}
