/* gltf_values.c — reading the glTF document's key-value trees (extras,
 * extensions) and a primitive's attributes, as tinygltf's Value and maps
 * answered: keys compare byte for byte, an item past an array's end is
 * null. */
#include "scene/gltf_doc.h"

#include <string.h>

static int same(GltfString s, const char *text, size_t len)
{
	return s.len == len && memcmp(s.s, text, len) == 0;
}

const GltfValue *gltf_member_n(const GltfValue *v, const char *key, size_t len)
{
	if (!v || v->type != GLTF_VALUE_OBJECT)
		return NULL;
	for (size_t i = 0; i < v->count; i++)
		if (same(v->keys[i], key, len))
			return &v->items[i];
	return NULL;
}

const GltfValue *gltf_member(const GltfValue *v, const char *key)
{
	return gltf_member_n(v, key, strlen(key));
}

const GltfValue *gltf_item(const GltfValue *v, size_t i)
{
	static const GltfValue null_value = {GLTF_VALUE_NULL, 0, 0.0, {"", 0}, 0, NULL, NULL};
	return v->type == GLTF_VALUE_ARRAY && i < v->count ? &v->items[i] : &null_value;
}

int gltf_string_is(GltfString s, const char *text)
{
	return same(s, text, strlen(text));
}

int gltf_attribute(const GltfPrimitive *pr, const char *name, int *accessor)
{
	for (size_t i = 0; i < pr->nattributes; i++)
		if (gltf_string_is(pr->attributes[i].name, name)) {
			*accessor = pr->attributes[i].accessor;
			return 1;
		}
	return 0;
}
