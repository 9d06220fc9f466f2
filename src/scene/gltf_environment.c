/* gltf_environment.c — the scene extras' "environment": a colour times
 * its strength, or an image (scene_load_env_image: EXR or .hdr) named
 * relative to the scene's folder, inside it unless allowed; "rotation" in
 * degrees (src/scene/README.md, "The environment"). */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/gltf_parts.h"

/* The environment image, named `name` by the scene. */
static ajar_status read_image(GltfLoader *L, const char *name, double strength, const char *where)
{
	size_t need = name[0] == '/' ? strlen(name) + 1 : strlen(L->dir) + strlen(name) + 2;
	char *path = malloc(need);
	if (!path)
		return gltf_out_of_memory(L);
	snprintf(path, need, "%s%s%s", name[0] == '/' ? "" : L->dir, name[0] == '/' ? "" : "/", name);
	char why[GLTF_WHY_SIZE];
	ajar_status st;
	if (access(path, F_OK) == 0 && !gltf_confined(L->root, L->allow_outside, path, name, why, sizeof why)) {
		st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.image: %s", where, why);
	} else if ((st = scene_load_env_image(L->s, path, (float)strength))) {
		char msg[GLTF_WHY_SIZE];
		snprintf(msg, sizeof msg, "%s", ajar_last_error());
		st = gltf_fail(L, st, "%s.extras.environment.image: %s", where, msg);
	}
	free(path);
	return st;
}

ajar_status gltf_read_environment(GltfLoader *L, const GltfValue *extras, const char *where)
{
	const GltfValue *env = gltf_member(extras, "environment");
	if (!env)
		return AJAR_OK;
	if (env->type != GLTF_VALUE_OBJECT)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment is not an object", where);
	double strength = 1.0;
	const GltfValue *v = gltf_member(env, "strength");
	if (v) {
		if (v->type != GLTF_VALUE_NUMBER || !(v->number >= 0.0) || !isfinite(v->number))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.strength must be a number >= 0",
					 where);
		strength = v->number;
	}
	if ((v = gltf_member(env, "rotation"))) {
		if (v->type != GLTF_VALUE_NUMBER || !isfinite(v->number))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
					 "%s.extras.environment.rotation must be a number (degrees)", where);
		ajar_status st = scene_set_env_rotation(L->s, v->number);
		if (st)
			return st;
	}
	const GltfValue *img = gltf_member(env, "image");
	if (img) {
		if (img->type != GLTF_VALUE_STRING || !img->string.len)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.image is not a file name", where);
		return read_image(L, img->string.s, strength, where);
	}
	const GltfValue *col = gltf_member(env, "color");
	float rgb[3];
	if (!col || col->type != GLTF_VALUE_ARRAY || col->count != 3)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment needs \"color\": [r, g, b] or \"image\"",
				 where);
	for (int c = 0; c < 3; c++) {
		const GltfValue *x = gltf_item(col, (size_t)c);
		if (x->type != GLTF_VALUE_NUMBER || !(x->number >= 0.0) || !isfinite(x->number))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.color must be 3 numbers >= 0", where);
		rgb[c] = (float)(x->number * strength);
	}
	scene_set_env_color(L->s, v3(rgb[0], rgb[1], rgb[2]));
	return AJAR_OK;
}
