/* gltf_lights.c — KHR_lights_punctual: a node's light at the node's world
 * position, pointing down its world -Z (scale affects neither the light's
 * range nor its intensity), kept in glTF's units (ajar_light). */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

ajar_status gltf_load_light_node(GltfLoader *L, int ni, const double world[16])
{
	const GltfValue *ext = gltf_member(&L->doc->nodes[ni].extensions, "KHR_lights_punctual");
	if (!ext)
		return AJAR_OK;
	const GltfValue *v = gltf_member(ext, "light");
	if (!v || v->type != GLTF_VALUE_NUMBER)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: KHR_lights_punctual has no light index", ni);
	double li = v->number;
	if (!(li >= 0.0 && li < (double)L->doc->nlights) || li != floor(li))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: KHR_lights_punctual light %g does not exist (%zu lights)",
				 ni, li, L->doc->nlights);
	const GltfLight *gl = &L->doc->lights[(size_t)li];
	ajar_light l;
	memset(&l, 0, sizeof l);
	l.color[0] = l.color[1] = l.color[2] = 1.0f; /* the spec's default */
	if (gltf_string_is(gl->type, "directional"))
		l.type = AJAR_LIGHT_DIRECTIONAL;
	else if (gltf_string_is(gl->type, "point"))
		l.type = AJAR_LIGHT_POINT;
	else if (gltf_string_is(gl->type, "spot"))
		l.type = AJAR_LIGHT_SPOT;
	else
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[%g]: unknown type '%s'", li,
				 gl->type.s);
	if (gl->color.n && gl->color.n != 3)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[%g]: color has %zu numbers, expected 3",
				 li, gl->color.n);
	for (size_t k = 0; k < gl->color.n; k++)
		l.color[k] = (float)gl->color.v[k];
	l.intensity = (float)gl->intensity;
	l.range = (float)gl->range; /* 0 when absent (infinite) */
	l.inner_cone = (float)gl->inner_cone;
	l.outer_cone = (float)gl->outer_cone;
	for (int k = 0; k < 3; k++) {
		l.position[k] = (float)world[12 + k];
		l.direction[k] = (float)-world[8 + k];
	}
	char what[96];
	snprintf(what, sizeof what, "nodes[%d]: KHR_lights_punctual.lights[%g]", ni, li);
	return scene_add_light(L->s, what, &l);
}
