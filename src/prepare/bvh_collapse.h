/* bvh_collapse.h — the binary tree of the SAH build made into the eight-wide
 * BvhNode array the kernels traverse (bvh_collapse.c). */
#ifndef AJAR_BVH_COLLAPSE_H
#define AJAR_BVH_COLLAPSE_H
#include "prepare/bvh_build.h"
#include "prepare/bvh_parts.h"

/* Collapses the binary tree rooted at bn[0] (ninterior interior nodes) into
 * out->nodes after the out->nnodes already there (none if out->nodes is
 * NULL), leaves naming triangles from tri_base on; sets out->nnodes and
 * out->wide_depth. */
ajar_status bvh_collapse(const BinNode *bn, uint32_t ninterior, uint32_t tri_base, Bvh *out);
#endif
