/* gltf.h — the glTF 2.0 loader (gltf_load.c): tinygltf parses the file in
 * the one C++ file (gltf.cpp), C files fill a Scene (scene.h) from it.
 *
 * Conventions the loader adds to glTF (see design.md): mesh nodes with
 * extras {"portal": true} (or 1) are portals; scene extras "environment"
 * give a colour or an equirectangular EXR; camera, camera-node or scene
 * extras "resolution": [w, h] suggest an image size. */
#ifndef AJAR_GLTF_H
#define AJAR_GLTF_H
#include "ajar.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Loads .gltf (with .bin, images, data URIs) or .glb into a new Scene.
 * A file that cannot be read is AJAR_ERROR_IO; anything malformed is
 * AJAR_ERROR_BAD_INPUT with a message naming the file and the element. */
ajar_status gltf_load(const char *path, Scene **out);
/* The same; files the scene names (buffers, images, the environment image)
 * must resolve inside the scene file's folder unless allow_outside_files
 * (AJAR_ERROR_BAD_INPUT naming the URI otherwise). gltf_load confines. */
ajar_status gltf_load_with(const char *path, int allow_outside_files, Scene **out);

/* Which meshes used by several nodes (or EXT_mesh_gpu_instancing copies)
 * are kept once, as instances: by the rule of gltf_instancing.c
 * (gltf_mesh_instanced), none (every copy flattened into world space), or
 * every mesh used at all (tests: instanced against flattened). */
enum { GLTF_INSTANCING_AUTO = 0, GLTF_INSTANCING_NONE = 1, GLTF_INSTANCING_ALL = 2 };
ajar_status gltf_load_instancing(const char *path, int allow_outside_files, int instancing, Scene **out);

#ifdef __cplusplus
}
#endif
#endif
