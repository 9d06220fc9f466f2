/* gltf_extensions.c — the glTF extensions the loader implements: a file
 * that requires any other is refused; one that uses any other, on the file
 * or on a material, gets a warning naming it. */
#include "scene/gltf_parts.h"

#include <string.h>

/* Extensions whose meaning the loader implements; a file that requires any
 * other cannot be shown correctly and is refused. */
static const char *const supported_extensions[] = {
	"KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_specular",
	"KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_sheen", "KHR_materials_clearcoat",
	"KHR_materials_anisotropy", "KHR_mesh_quantization", "KHR_lights_punctual", "KHR_texture_transform",
	"EXT_mesh_gpu_instancing",
};

/* The material extensions load_material reads; any other on a material is
 * named in a warning (KHR_materials_dispersion and _iridescence among
 * them: Blender writes both). */
static const char *const material_extensions[] = {
	"KHR_materials_emissive_strength", "KHR_materials_ior",      "KHR_materials_specular",
	"KHR_materials_transmission",      "KHR_materials_volume",   "KHR_materials_sheen",
	"KHR_materials_clearcoat",         "KHR_materials_anisotropy",
};

/* Compared as std::string compares: a name with a NUL byte in it matches
 * nothing. */
static int listed(const char *const *list, size_t n, const char *name, size_t len)
{
	for (size_t i = 0; i < n; i++)
		if (strlen(list[i]) == len && memcmp(list[i], name, len) == 0)
			return 1;
	return 0;
}

int gltf_extension_supported(const char *name, size_t len)
{
	return listed(supported_extensions, sizeof supported_extensions / sizeof *supported_extensions, name, len);
}

int gltf_material_extension_read(const char *name, size_t len)
{
	return listed(material_extensions, sizeof material_extensions / sizeof *material_extensions, name, len);
}
