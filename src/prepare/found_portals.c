/* found_portals.c — the portal search (portal_find.c) on a loaded scene:
 * the BVH built for it alone, for `ajar info` and programs that want to
 * see the portals a render would find (ajar_scene_find_portals). A render
 * runs the same search inside prepare_scene, on the BVH it builds anyway. */
#include "prepare/found_portals.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "prepare/bvh_build.h"

ajar_status portal_find_scene(const Scene *s, PortalSearch *out)
{
	memset(out, 0, sizeof *out);
	if (s->ntris == 0)
		return AJAR_OK;
	Bvh bvh;
	ajar_status st = bvh_build(s->tris, s->ntris, &bvh);
	if (st != AJAR_OK)
		return st;
	Tri *tris = malloc(sizeof *tris * s->ntris);
	TriShade *shade = malloc(sizeof *shade * s->ntris);
	TriExtra *extra = calloc(s->extra ? s->ntris : 1, sizeof *extra);
	Params *params = calloc(1, sizeof *params);
	if (!tris || !shade || !extra || !params) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for the portal search", s->source);
		goto done;
	}
	for (uint32_t i = 0; i < s->ntris; i++) {
		tris[i] = s->tris[bvh.order[i]];
		shade[i] = s->shade[bvh.order[i]];
		if (s->extra)
			extra[i] = s->extra[bvh.order[i]];
	}
	SceneView v;
	memset(&v, 0, sizeof v);
	v.nodes = bvh.nodes;
	v.tris = tris;
	v.shade = shade;
	v.extra = extra;
	v.materials = s->materials;
	v.textures = s->textures;
	v.texels = s->texels;
	v.params = params;
	PortalFindInput in;
	portal_find_input(s, &in);
	st = portal_find(&v, s->ntris, &in, out);
done:
	free(tris);
	free(shade);
	free(extra);
	free(params);
	bvh_free(&bvh);
	return st;
}

void portal_find_input(const Scene *s, PortalFindInput *in)
{
	V3 fwd, up;
	float yfov;
	memset(in, 0, sizeof *in);
	scene_camera(s, &in->camera, &fwd, &up, &yfov);
	in->env_type = s->env_type;
	in->lights = s->lights;
	in->nlights = s->nlights;
}

ajar_status ajar_scene_find_portals(const ajar_scene *s, ajar_portal *out, uint32_t capacity, uint32_t *count,
				    double *seconds)
{
	if (!s || !count || (capacity && !out))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_find_portals: NULL scene, count or portals");
	PortalSearch ps;
	ajar_status st = portal_find_scene(s, &ps);
	if (st != AJAR_OK)
		return st;
	portals_to_api(&ps, out, capacity, count, seconds);
	portal_search_free(&ps);
	return AJAR_OK;
}

void portals_to_api(const PortalSearch *ps, ajar_portal *out, uint32_t capacity, uint32_t *count, double *seconds)
{
	for (uint32_t i = 0; i < ps->count && i < capacity; i++) {
		const FoundPortal *f = &ps->portals[i];
		ajar_portal *p = &out[i];
		const V3 *src[4] = {&f->c, &f->n, &f->u, &f->v};
		float *dst[4] = {p->center, p->normal, p->half_u, p->half_v};
		for (int k = 0; k < 4; k++) {
			dst[k][0] = src[k]->x;
			dst[k][1] = src[k]->y;
			dst[k][2] = src[k]->z;
		}
		p->width = 2.0f * v3_len(f->u);
		p->height = 2.0f * v3_len(f->v);
		p->share = f->share;
	}
	*count = ps->count;
	if (seconds)
		*seconds = ps->seconds;
}
