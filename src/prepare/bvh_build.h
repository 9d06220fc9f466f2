/* bvh_build.h — the bounding volume hierarchy over the scene's triangles, built
 * on the host with binned SAH, collapsed to eight-wide nodes and flattened
 * into the BvhNode array that kernels/geom/bvh.h traverses (layout in
 * kernels/base/types.h).
 *
 * The build reorders triangles so every leaf covers a contiguous range;
 * `order` says where each reordered triangle came from, so the caller can
 * permute Tri and TriShade the same way before upload. The tree is at most
 * BVH_MAX_DEPTH levels deep, which the device's fixed traversal stack
 * relies on. */
#ifndef AJAR_BVH_H
#define AJAR_BVH_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

/* Deepest root-to-leaf path of the binary tree, counted in nodes. The
 * eight-wide tree is at most half as deep, and its traversal pushes at most
 * seven entries per level (BVH_STACK_SIZE in kernels/geom/bvh.h). */
#define BVH_MAX_DEPTH 64
/* Leaf slots encode 4 first + count - 1 in an int. */
#define BVH_MAX_TRIS (1u << 29)

typedef struct {
	BvhNode *nodes;      /* BVH_WIDTH-wide */
	uint32_t nnodes;
	uint32_t *order;     /* order[i] = original index of reordered triangle i (NULL after a reorder) */
	uint32_t ntris;
	uint32_t depth;      /* binary tree: nodes on the longest root-to-leaf path */
	uint32_t wide_depth; /* the wide tree: the same */
} Bvh;

/* What a tree is built over: primitives 0 .. ntris - 1 are triangles
 * (tris[i], or tris[index[i]] with an index list), ntris .. n - 1 are
 * instances with world-space boxes inst_lo/inst_hi[i - ntris], each a leaf
 * of its own, BVH_INSTANCE(i - ntris) (kernels/geom/bvh.h). Leaves name
 * triangles tri_base + their place in the leaf order. */
typedef struct {
	const Tri *tris;
	const uint32_t *index; /* NULL: primitive i is tris[i] */
	uint32_t ntris;
	const V3 *inst_lo, *inst_hi;
	uint32_t n;            /* ntris + instances, >= 1 */
	uint32_t tri_base;
} BvhInput;

/* ntris >= 1, on bvh_threads() threads. On failure *out is left empty
 * (safe to bvh_free). out->nodes is a big array (core/big_array.h). */
ajar_status bvh_build(const Tri *tris, uint32_t ntris, Bvh *out);
/* The same tree, bit for bit, on `threads` threads (1: the caller's alone). */
ajar_status bvh_build_threads(const Tri *tris, uint32_t ntris, int threads, Bvh *out);
/* The leaf order as the build hands it over: bvh_permute puts an array of
 * one element per triangle in that order, on the build's threads. */
typedef struct BvhPermute BvhPermute;
/* array[i] = the old array[order[i]] for every triangle i: gathered a
 * 32-byte slice of each element at a time into the build's reference
 * array (freed after), so no second copy of the array is made and the
 * reads run in parallel rather than one cycle's miss after another. */
void bvh_permute(BvhPermute *p, void *array, size_t stride);
/* Puts the caller's triangle arrays in the leaf order (bvh_permute). */
typedef void (*BvhReorder)(BvhPermute *p, void *ctx);
/* bvh_build_threads that hands the order to `reorder` between building
 * the binary tree and collapsing it, when the build holds the least
 * memory, and frees it (out->order NULL). */
ajar_status bvh_build_reorder(const Tri *tris, uint32_t ntris, int threads, BvhReorder reorder, void *ctx,
			      Bvh *out);
/* The general build: out->order has in->ntris entries (primitive
 * numbers); with out->nodes already holding a tree (out->nnodes nodes), the
 * new tree is appended after it, its root node out->nnodes, and
 * out->nnodes grows. */
ajar_status bvh_build_input(const BvhInput *in, int threads, BvhReorder reorder, void *ctx, Bvh *out);
/* The threads a build uses: the processors the process may run on. */
int bvh_threads(void);
void bvh_free(Bvh *b);
/* Bytes of nodes + order. */
size_t bvh_memory(const Bvh *b);

#endif
