/* gltf_cameras.c — the scene's camera (the first perspective camera of the
 * node walk: at the node's world position, looking down its -Z) and the
 * image size a scene suggests ("resolution": [w, h] in camera, camera
 * node or scene extras). */
#include "scene/gltf_loader.h"

#include <stdio.h>
#include <string.h>

ajar_status gltf_read_resolution(GltfLoader *L, const GltfValue *extras, const char *where)
{
	const GltfValue *r = gltf_member(extras, "resolution");
	if (!r || L->s->width)
		return AJAR_OK;
	const GltfValue *w = gltf_item(r, 0), *h = gltf_item(r, 1);
	if (r->type != GLTF_VALUE_ARRAY || r->count != 2 || w->type != GLTF_VALUE_NUMBER ||
	    h->type != GLTF_VALUE_NUMBER || !(w->number >= 1 && w->number <= AJAR_MAX_SIDE) ||
	    !(h->number >= 1 && h->number <= AJAR_MAX_SIDE))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.resolution must be [width, height] in 1..%u", where,
				 AJAR_MAX_SIDE);
	L->s->width = (uint32_t)w->number;
	L->s->height = (uint32_t)h->number;
	return AJAR_OK;
}

ajar_status gltf_load_camera_node(GltfLoader *L, int ni, const double world[16])
{
	const GltfNode *n = &L->doc->nodes[ni];
	if ((size_t)n->camera >= L->doc->ncameras)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: cameras[%d] does not exist (%zu cameras)", ni,
				 n->camera, L->doc->ncameras);
	const GltfCamera *c = &L->doc->cameras[n->camera];
	if (!gltf_string_is(c->type, "perspective")) {
		log_msg(AJAR_LOG_INFO, "%s: cameras[%d]: %s camera skipped (only perspective is supported)", L->file,
			n->camera, c->type.s);
		return AJAR_OK;
	}
	double yfov = c->yfov, aspect = c->aspect_ratio;
	if (!(yfov > 0.0 && yfov < 3.14159265358979323846) || !(aspect >= 0.0))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "cameras[%d]: yfov %g must be in (0, pi), aspectRatio %g positive",
				 n->camera, yfov, aspect);
	V3 pos = v3((float)world[12], (float)world[13], (float)world[14]);
	V3 fwd = v3((float)-world[8], (float)-world[9], (float)-world[10]);
	V3 up = v3((float)world[4], (float)world[5], (float)world[6]);
	if (scene_set_camera(L->s, pos, fwd, up, (float)yfov, (float)aspect)) {
		char msg[2048];
		snprintf(msg, sizeof msg, "%s", ajar_last_error());
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: unusable camera transform (%s)", ni, msg);
	}
	char where[64];
	snprintf(where, sizeof where, "cameras[%d]", n->camera);
	ajar_status st = gltf_read_resolution(L, &c->extras, where);
	snprintf(where, sizeof where, "nodes[%d]", ni);
	return st ? st : gltf_read_resolution(L, &n->extras, where);
}
