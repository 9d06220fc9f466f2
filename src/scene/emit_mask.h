/* emit_mask.h — which triangles an emissive texture lets emit, answered
 * in constant time per triangle (emit_mask.c). */
#ifndef AJAR_EMIT_MASK_H
#define AJAR_EMIT_MASK_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Per texture used as an emissive texture, a summed-area table of its
 * non-black texels; textures that share an image share a table. */
typedef struct {
	uint32_t ntextures;
	size_t *at;     /* per texture: its table's first entry in sat, or SIZE_MAX */
	uint32_t *sat;  /* (w + 1) x (h + 1) counts per table */
} EmitMask;

/* Tables for every texture some material uses as emissive; *m is zeroed
 * first and freed with emit_mask_free. Out of memory is an error (the
 * caller may go on with *m empty: emit_mask_can_emit then scans). */
ajar_status emit_mask_build(EmitMask *m, const Texture *textures, uint32_t ntextures, const uint32_t *texels,
			    const Material *materials, uint32_t nmaterials);
void emit_mask_free(EmitMask *m);

/* Whether triangle i of v can emit anywhere with emissive texture `tex`:
 * some texel that a lookup inside its texture coordinates' bounding box
 * reads (bilinear: the texels around x - 0.5, which include nearest's) is
 * not black. From m's table when it has one for `tex` (m may be NULL),
 * else by reading the texels. */
int emit_mask_can_emit(const EmitMask *m, const SceneView *v, uint32_t i, int tex);

#ifdef __cplusplus
}
#endif
/* Triangle i of v (tris, shade, extra and textures set): its texture
 * coordinates for texture `tex` (its set and transform) in texels. */
void scene_tri_texel_coords(const SceneView *v, uint32_t i, int tex, double x[3], double y[3]);

#endif
