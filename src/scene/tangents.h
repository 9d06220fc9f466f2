/* tangents.h — tangents for normal maps where a glTF mesh has none
 * (tangents.c), used by the loader (gltf_primitives.c). */
#ifndef AJAR_TANGENTS_H
#define AJAR_TANGENTS_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Tangents of the nv vertices pos (3 floats each, world space), nrm (3
 * each, or NULL: face normals) and uv (2 each) of the ntri triangles tri.
 * A vertex used by triangles of both handednesses is split in two: twin[v]
 * (nv entries) is its copy's index (nv, nv + 1, ... in order of v), or
 * UINT32_MAX, and tri is renumbered to the copies; the caller appends the
 * copies to its per-vertex arrays. *tan gets 4 floats (xyz, handedness w)
 * for each of the *total vertices, malloc'd. AJAR_ERROR_OUT_OF_MEMORY or
 * AJAR_OK. */
ajar_status tangents_generate(const float *pos, const float *nrm, const float *uv, size_t nv, uint32_t *tri,
			      size_t ntri, uint32_t *twin, float **tan, size_t *total);

#ifdef __cplusplus
}
#endif
#endif
