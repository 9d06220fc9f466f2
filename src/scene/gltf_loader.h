/* gltf_loader.h — the glTF loader's state and its parts that read the
 * document (gltf_doc.h) into a Scene, one concept a file: accessors
 * (gltf_accessors.c), textures (gltf_textures.c), materials
 * (gltf_materials.c), primitives (gltf_primitives.c), a mesh node's copies
 * and instances (gltf_instances.c), cameras and the image size
 * (gltf_cameras.c), lights (gltf_lights.c), the environment
 * (gltf_environment.c), the node walk (gltf_nodes.c); gltf_load.c runs
 * them. Every message names the file and the element (gltf_fail). */
#ifndef AJAR_GLTF_LOADER_H
#define AJAR_GLTF_LOADER_H
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "scene/gltf_doc.h"
#include "scene/scene.h"

typedef struct {
	const char *file;
	const char *dir;  /* the scene file's folder */
	const char *root; /* the same, symbolic links resolved */
	int allow_outside; /* files outside the scene's folder may be read */
	int instancing;    /* GLTF_INSTANCING_* */
	const GltfDoc *doc;
	Scene *s;
	uint32_t *material_ids; /* glTF material -> scene material */
	int default_material;   /* scene material, -1 until a primitive needs it */
	int *image_textures;    /* glTF image -> scene texture or -1 */
	uint64_t *mesh_uses;    /* glTF mesh -> its copies (nodes x EXT_mesh_gpu_instancing), portals aside */
	int *mesh_id;           /* glTF mesh -> scene mesh; -1 not loaded yet, -2 nothing to instance */
	char *mesh_inst;        /* glTF mesh -> kept once, as instances */
} GltfLoader;

/* "file: message" as the load's error. */
ajar_status gltf_fail(const GltfLoader *L, ajar_status st, const char *fmt, ...) AJAR_PRINTF(3, 4);
ajar_status gltf_out_of_memory(const GltfLoader *L);

/* An accessor's elements, tightly packed, sparse substitution applied. */
typedef struct {
	uint8_t *bytes;
	size_t count;
	int ctype, ncomp, normalized;
} GltfPacked;

typedef struct {
	float *v;
	size_t n; /* floats; 0 where absent */
} GltfFloats;

/* accessors[idx] (`attr` of `ctx`, for messages), which must have ncomp
 * components, into p (gltf_packed_free frees it, also after an error). */
ajar_status gltf_accessor_read(const GltfLoader *L, const char *ctx, const char *attr, int idx, int ncomp,
			       GltfPacked *p);
void gltf_packed_free(GltfPacked *p);
/* p's components as floats (normalized integers mapped as glTF says). */
ajar_status gltf_packed_floats(const GltfLoader *L, const GltfPacked *p, GltfFloats *out);
/* p as indices: unsigned integers only; accessor `acc` named otherwise. */
ajar_status gltf_packed_indices(const GltfLoader *L, const char *ctx, int acc, const GltfPacked *p, uint32_t **out);

/* materials[mi]'s texture `slot` as a scene texture use; *id -1 where
 * index is -1. exts: the textureInfo's extensions (KHR_texture_transform). */
ajar_status gltf_texture_use(GltfLoader *L, int mi, const char *slot, int index, int texcoord, const GltfValue *exts,
			     int *id);
/* The texture named by extensions[ext][key] of materials[mi], or *id -1. */
ajar_status gltf_ext_texture(GltfLoader *L, int mi, const GltfValue *exts, const char *ext, const char *key, int *id);

/* Every material of the document, into L->material_ids. */
ajar_status gltf_load_materials(GltfLoader *L);
/* glTF's default material, added once. */
ajar_status gltf_default_material(GltfLoader *L, uint32_t *id);

/* Triangles of a portal node, gathered over its primitives so the node is
 * one portal. */
typedef struct {
	float *pos;
	size_t npos, pos_cap; /* floats */
	uint32_t *idx;
	size_t nidx, idx_cap;
} GltfPortalMesh;

/* Primitive pi of mesh mi under `world` (nm its normal matrix, flip where
 * it mirrors) into the scene, or into `portal`'s triangles. */
ajar_status gltf_load_primitive(GltfLoader *L, int mi, int pi, const double world[16], const double nm[3][3],
				int flip, GltfPortalMesh *portal);

/* How often each mesh is drawn from `roots`, and which are kept once. */
ajar_status gltf_count_mesh_uses(GltfLoader *L, const int *roots, size_t nroots);
/* Node ni's mesh under `world`: flattened, as instances, or a portal. */
ajar_status gltf_load_mesh_node(GltfLoader *L, int ni, const double world[16]);

/* T * R * S; `what` names the node where the quaternion is zero. */
ajar_status gltf_trs(const GltfLoader *L, const char *what, const double t[3], const double q[4], const double s[3],
		     double m[16]);
/* Depth-first from `roots` (roots_what names them), parents before
 * children, in file order: meshes, the first camera, lights. */
ajar_status gltf_walk_nodes(GltfLoader *L, const int *roots, size_t nroots, const char *roots_what);

ajar_status gltf_load_camera_node(GltfLoader *L, int ni, const double world[16]);
/* "resolution": [w, h] of an extras object (`where`'s), unless set. */
ajar_status gltf_read_resolution(GltfLoader *L, const GltfValue *extras, const char *where);
ajar_status gltf_load_light_node(GltfLoader *L, int ni, const double world[16]);
/* The scene extras' "environment": a colour or an image. */
ajar_status gltf_read_environment(GltfLoader *L, const GltfValue *extras, const char *where);

#endif
