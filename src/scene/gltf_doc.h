/* gltf_doc.h — a glTF document in plain C: what gltf.cpp copies out of
 * tinygltf's Model, so that the loader's C files read glTF without a C++
 * type. Nothing here is checked yet (indices as the file wrote them, -1
 * where absent): the readers check what they use and name the element.
 *
 * Arrays of numbers, strings, buffers' bytes and decoded images point into
 * the Model, which lives until gltf_doc_free: a 10M-triangle scene holds
 * its buffers once. Extras and extensions are key-value trees (GltfValue). */
#ifndef AJAR_GLTF_DOC_H
#define AJAR_GLTF_DOC_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* NUL-terminated; len counts bytes up to the end, a NUL inside included
 * (names compare as tinygltf's std::string compared them). */
typedef struct {
	const char *s;
	size_t len;
} GltfString;

typedef struct {
	const double *v;
	size_t n;
} GltfNumbers;

typedef struct {
	const int *v;
	size_t n;
} GltfInts;

enum {
	GLTF_VALUE_NULL, /* also a binary value: nothing reads one */
	GLTF_VALUE_BOOL,
	GLTF_VALUE_NUMBER,
	GLTF_VALUE_STRING,
	GLTF_VALUE_ARRAY,
	GLTF_VALUE_OBJECT,
};

/* A JSON value of extras or extensions. */
typedef struct GltfValue GltfValue;
struct GltfValue {
	int type; /* GLTF_VALUE_* */
	int boolean;
	double number;
	GltfString string;
	size_t count;           /* an array's items, an object's members */
	const GltfValue *items; /* count values */
	const GltfString *keys; /* an object's count keys, sorted */
};

typedef struct {
	const unsigned char *data;
	size_t size;
} GltfBuffer;

typedef struct {
	int buffer;
	size_t byte_offset, byte_length, byte_stride;
} GltfBufferView;

typedef struct {
	int buffer_view;
	size_t byte_offset;
	int component_type; /* GLTF_FLOAT, ... (gltf_parts.h) */
	int normalized;
	size_t count;
	int type; /* GLTF_SCALAR, ... (gltf_parts.h) */
	int is_sparse;
	int sparse_count;
	int sparse_indices_view, sparse_indices_offset, sparse_indices_type;
	int sparse_values_view, sparse_values_offset;
} GltfAccessor;

/* Decoded by gltf.cpp's image loader: width x height texels of component
 * channels of bits each, or width -1 where nothing was decoded. */
typedef struct {
	int width, height, component, bits;
	const unsigned char *pixels;
	size_t size;
} GltfImage;

typedef struct {
	int wrap_s, wrap_t, mag_filter; /* OpenGL's codes, mag_filter -1 if absent */
} GltfSampler;

typedef struct {
	int source, sampler;
} GltfTexture;

/* A textureInfo (scale only on normalTexture); extensions is an object. */
typedef struct {
	int index, texcoord;
	double scale;
	GltfValue extensions;
} GltfTextureInfo;

typedef struct {
	GltfString name;
	GltfNumbers base_color; /* tinygltf's default [1, 1, 1, 1] where absent */
	GltfNumbers emissive;   /* empty where absent */
	double metallic, roughness, alpha_cutoff;
	int double_sided;
	GltfString alpha_mode;
	GltfTextureInfo base_color_texture, metallic_roughness_texture, emissive_texture, normal_texture;
	GltfValue extensions; /* an object */
} GltfMaterial;

typedef struct {
	GltfString name;
	int accessor;
} GltfAttribute;

typedef struct {
	int mode, indices, material;
	size_t nattributes;
	const GltfAttribute *attributes; /* sorted by name */
} GltfPrimitive;

typedef struct {
	size_t nprimitives;
	const GltfPrimitive *primitives;
} GltfMesh;

typedef struct {
	int mesh, camera;
	GltfInts children;
	GltfNumbers matrix, translation, rotation, scale; /* empty where absent */
	GltfValue extras;
	GltfValue extensions; /* an object */
} GltfNode;

typedef struct {
	GltfString type;
	double yfov, aspect_ratio;
	GltfValue extras;
} GltfCamera;

/* A KHR_lights_punctual light; range 0 where absent (infinite). */
typedef struct {
	GltfString type;
	GltfNumbers color;
	double intensity, range, inner_cone, outer_cone;
} GltfLight;

typedef struct {
	GltfInts nodes;
	GltfValue extras;
} GltfScene;

typedef struct {
	size_t nbuffers, nbuffer_views, naccessors, nimages, nsamplers, ntextures, nmaterials, nmeshes, nnodes,
		ncameras, nlights, nscenes;
	const GltfBuffer *buffers;
	const GltfBufferView *buffer_views;
	const GltfAccessor *accessors;
	const GltfImage *images;
	const GltfSampler *samplers;
	const GltfTexture *textures;
	const GltfMaterial *materials;
	const GltfMesh *meshes;
	const GltfNode *nodes;
	const GltfCamera *cameras;
	const GltfLight *lights;
	const GltfScene *scenes;
	int default_scene; /* -1 where absent */
	size_t nextensions_required, nextensions_used;
	const GltfString *extensions_required, *extensions_used;
} GltfDoc;

/* Reads and parses `file` (.gltf with its buffers and images, or .glb)
 * with tinygltf into *out. `dir` is the file's folder, against which URIs
 * resolve; unless allow_outside, a file a URI names must resolve inside
 * `root` (dir, symbolic links resolved), the first refusal being the error.
 * Errors name the file (AJAR_ERROR_BAD_INPUT, _IO, _OUT_OF_MEMORY). */
ajar_status gltf_doc_load(const char *file, const char *dir, const char *root, int allow_outside, GltfDoc **out);
void gltf_doc_free(GltfDoc *doc);

/* Readers of the trees (gltf_values.c). */
/* Member `key` of an object, or NULL (not an object, or no such member). */
const GltfValue *gltf_member(const GltfValue *v, const char *key);
/* The same for a key of len bytes, which may hold a NUL. */
const GltfValue *gltf_member_n(const GltfValue *v, const char *key, size_t len);
/* Item i of an array, or a null value past its end. */
const GltfValue *gltf_item(const GltfValue *v, size_t i);
/* Whether s is exactly the C string `text`. */
int gltf_string_is(GltfString s, const char *text);
/* The accessor of attribute `name` of a primitive; 0 where it has none. */
int gltf_attribute(const GltfPrimitive *pr, const char *name, int *accessor);

#ifdef __cplusplus
}
#endif
#endif
