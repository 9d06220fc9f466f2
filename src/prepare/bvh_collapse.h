/* bvh_collapse.h — the binary tree of the SAH build made into the eight-wide
 * BvhNode array the kernels traverse (bvh_collapse.c). */
#ifndef AJAR_BVH_COLLAPSE_H
#define AJAR_BVH_COLLAPSE_H
#include "prepare/bvh_build.h"
#include "prepare/bvh_parts.h"

/* Collapses the binary tree rooted at bn[0] (ninterior interior nodes) into
 * out->nodes, out->nnodes and out->wide_depth. */
ajar_status bvh_collapse(const BinNode *bn, uint32_t ninterior, Bvh *out);
#endif
