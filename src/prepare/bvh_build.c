/* bvh_build.c — binned SAH build of the flattened BVH (see bvh_build.h).
 *
 * Top-down, one node at a time from an explicit stack (no recursion, so a
 * million triangles or a pathological input cannot overflow the C stack).
 * Each node bins its triangles' centroids into BVH_BINS bins on each axis
 * and takes the cheapest surface-area-heuristic split (Wald 2007, "On fast
 * construction of SAH-based bounding volume hierarchies"). Where SAH cannot
 * split (all centroids equal, or every centroid in one bin) or the tree is
 * getting deep, an object-median split halves the node instead, which keeps
 * the depth within BVH_MAX_DEPTH whatever the input.
 *
 * The binary tree is then collapsed into eight-wide nodes (Dammertz et al.
 * 2008, "Shallow bounding volume hierarchies for fast SIMD ray tracing of
 * incoherent rays"; Embree's BVH8 on AVX machines): a node takes its binary
 * node's children, opens every interior one into its two children, and
 * fills a slot still free by opening its largest interior child again.
 * Every interior slot thus lies at least two binary levels down, which
 * halves the depth the traversal stack must hold; the kernel tests a
 * node's eight boxes side by side. Against four-wide nodes, a ray visits
 * fewer of them for the same box-test instructions: living-room pt 1.11x,
 * bathroom 1.07x, door-ajar portal 1.09x faster at one thread. */
#include "prepare/bvh_build.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "geom/bvh.h"

/* Traversal pushes at most BVH_WIDTH - 1 entries per wide level, and the
 * wide tree has at most BVH_MAX_DEPTH / 2 interior levels (bvh.h). */
_Static_assert((BVH_WIDTH - 1) * (BVH_MAX_DEPTH / 2) <= BVH_STACK_SIZE, "kernels/geom/bvh.h: traversal stack too small");

#define BVH_BINS 32
#define BVH_MAX_LEAF 4
_Static_assert(BVH_MAX_LEAF <= 4, "leaf slots encode at most 4 triangles");
/* Traversal cost relative to one triangle test. */
#define BVH_COST_TRAVERSE 1.0f
/* From this depth on only median splits: each halves the node, so even
 * 2^32 triangles in leaves of BVH_MAX_LEAF need at most 30 more levels. */
#define BVH_MEDIAN_DEPTH (BVH_MAX_DEPTH - 32)

typedef struct {
	float lo[3], hi[3];
} Box;

/* Node of the binary tree, depth-first: an interior node's left child is
 * the next node, its right child node `index`; a leaf (count > 0) covers
 * triangles [index, index + count). */
typedef struct {
	Box b;
	int index;
	int count;
} BinNode;

/* A triangle's bounds and where it came from; the build permutes these. */
typedef struct {
	Box b;
	uint32_t idx;
} Ref;

typedef struct {
	uint32_t start, end;
	uint32_t parent; /* node whose right child this is, or NO_PARENT */
	uint32_t depth;
} Task;

#define NO_PARENT UINT32_MAX

static void box_empty(Box *b)
{
	for (int a = 0; a < 3; a++) {
		b->lo[a] = FLT_MAX;
		b->hi[a] = -FLT_MAX;
	}
}

static void box_grow(Box *b, const Box *o)
{
	for (int a = 0; a < 3; a++) {
		if (o->lo[a] < b->lo[a])
			b->lo[a] = o->lo[a];
		if (o->hi[a] > b->hi[a])
			b->hi[a] = o->hi[a];
	}
}

/* Half the surface area; 0 for an empty box. */
static float box_area(const Box *b)
{
	float d[3];
	for (int a = 0; a < 3; a++) {
		d[a] = b->hi[a] - b->lo[a];
		if (d[a] < 0.0f)
			return 0.0f;
	}
	return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

/* Centroid times two: only compared, never used as a position. */
static float ref_key(const Ref *r, int axis) { return r->b.lo[axis] + r->b.hi[axis]; }

/* Clamped before the cast: a NaN or huge position (e.g. the builder API's
 * sums near FLT_MAX) is a bad bin, never undefined behaviour. */
static int bin_of(float key, float cmin, float scale, int nbins)
{
	float f = (key - cmin) * scale;
	return !(f > 0.0f) ? 0 : (f >= (float)nbins ? nbins - 1 : (int)f);
}

/* Reorders r[0, n) so that r[k] has the k-th smallest key on `axis` and
 * nothing before it is larger (Hoare partition, median-of-three pivot;
 * stops on equal keys, so all-equal input stays linear). */
static void select_nth(Ref *r, uint32_t n, uint32_t k, int axis)
{
	uint32_t lo = 0, hi = n - 1;
	while (hi > lo) {
		float a = ref_key(&r[lo], axis), b = ref_key(&r[lo + (hi - lo) / 2], axis);
		float c = ref_key(&r[hi], axis);
		float pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
		uint32_t i = lo, j = hi;
		while (i <= j) {
			while (ref_key(&r[i], axis) < pivot)
				i++;
			while (ref_key(&r[j], axis) > pivot)
				j--;
			if (i <= j) {
				Ref t = r[i];
				r[i] = r[j];
				r[j] = t;
				i++;
				if (j == 0)
					break;
				j--;
			}
		}
		if (k <= j)
			hi = j;
		else if (k >= i)
			lo = i;
		else
			break;
	}
}

/* Chooses a split of refs[0, n) with bounds `box` and centroid bounds
 * `cbox`. Returns the number of refs put on the left (refs reordered), or
 * 0 to make a leaf. */
static uint32_t split_node(Ref *refs, uint32_t n, const Box *box, const Box *cbox, uint32_t depth)
{
	int axis = 0;
	float ext[3];
	for (int a = 0; a < 3; a++) {
		ext[a] = cbox->hi[a] - cbox->lo[a];
		if (ext[a] > ext[axis])
			axis = a;
	}
	if (n <= 1)
		return 0;
	if (ext[axis] <= 0.0f) /* all centroids equal: any halving will do */
		return n <= BVH_MAX_LEAF ? 0 : n / 2;

	if (depth < BVH_MEDIAN_DEPTH) {
		/* Small nodes get fewer bins: the sweep below costs per bin, and
		 * most nodes are small. */
		int nb = n < BVH_BINS ? (int)n : BVH_BINS;
		uint32_t count[3][BVH_BINS] = {{0}};
		Box bins[3][BVH_BINS];
		float scale[3];
		for (int a = 0; a < 3; a++) {
			scale[a] = ext[a] > 0.0f ? (float)nb / ext[a] : 0.0f;
			for (int k = 0; k < nb; k++)
				box_empty(&bins[a][k]);
		}
		for (uint32_t i = 0; i < n; i++) {
			for (int a = 0; a < 3; a++) {
				int k = bin_of(ref_key(&refs[i], a), cbox->lo[a], scale[a], nb);
				count[a][k]++;
				box_grow(&bins[a][k], &refs[i].b);
			}
		}
		/* Costs in units of one triangle test times the parent's area, so
		 * a zero-area node still compares splits consistently. */
		float best_cost = FLT_MAX;
		int best_axis = -1, best_bin = 0;
		for (int a = 0; a < 3; a++) {
			if (ext[a] <= 0.0f)
				continue;
			float right_area[BVH_BINS];
			uint32_t right_count[BVH_BINS];
			Box acc;
			box_empty(&acc);
			uint32_t cnt = 0;
			for (int k = nb - 1; k > 0; k--) {
				box_grow(&acc, &bins[a][k]);
				cnt += count[a][k];
				right_area[k] = box_area(&acc);
				right_count[k] = cnt;
			}
			box_empty(&acc);
			cnt = 0;
			for (int k = 0; k < nb - 1; k++) {
				box_grow(&acc, &bins[a][k]);
				cnt += count[a][k];
				if (cnt == 0 || right_count[k + 1] == 0)
					continue;
				float cost = box_area(&acc) * (float)cnt +
					     right_area[k + 1] * (float)right_count[k + 1];
				if (cost < best_cost) {
					best_cost = cost;
					best_axis = a;
					best_bin = k;
				}
			}
		}
		if (best_axis >= 0) {
			float area = box_area(box);
			if (n <= BVH_MAX_LEAF && (float)n * area <= BVH_COST_TRAVERSE * area + best_cost)
				return 0;
			uint32_t i = 0, j = n;
			while (i < j) {
				if (bin_of(ref_key(&refs[i], best_axis), cbox->lo[best_axis],
					   scale[best_axis], nb) <= best_bin) {
					i++;
				} else {
					Ref t = refs[i];
					refs[i] = refs[--j];
					refs[j] = t;
				}
			}
			return i; /* both sides non-empty by construction of the bins */
		}
		/* Every centroid fell into one bin (float rounding on a tiny
		 * extent): fall through to the median. */
	}
	if (n <= BVH_MAX_LEAF)
		return 0;
	select_nth(refs, n, n / 2, axis);
	return n / 2;
}

/* Slots of a wide node under construction: binary node ids. */
typedef struct {
	uint32_t bin[BVH_WIDTH];
	int n;
} Slots;

static int bin_is_leaf(const BinNode *bn, uint32_t i) { return bn[i].count > 0; }

/* Opens slot k (an interior binary node) into its two children. */
static void slots_open(const BinNode *bn, Slots *s, int k)
{
	uint32_t i = s->bin[k];
	s->bin[k] = i + 1;
	s->bin[s->n++] = (uint32_t)bn[i].index;
}

/* The binary children of interior node i, each interior one opened, then
 * while a slot is free the interior slot of largest box area opened. */
static void slots_fill(const BinNode *bn, uint32_t i, Slots *s)
{
	s->n = 0;
	s->bin[s->n++] = i + 1;
	s->bin[s->n++] = (uint32_t)bn[i].index;
	for (int k = 0, n0 = s->n; k < n0; k++)
		if (!bin_is_leaf(bn, s->bin[k]))
			slots_open(bn, s, k);
	while (s->n < BVH_WIDTH) {
		int best = -1;
		float best_area = -1.0f;
		for (int k = 0; k < s->n; k++)
			if (!bin_is_leaf(bn, s->bin[k]) && box_area(&bn[s->bin[k]].b) > best_area) {
				best_area = box_area(&bn[s->bin[k]].b);
				best = k;
			}
		if (best < 0)
			break;
		slots_open(bn, s, best);
	}
}

static void wide_set_slot(BvhNode *w, int k, const Box *b, int child)
{
	w->lo_x[k] = b->lo[0];
	w->lo_y[k] = b->lo[1];
	w->lo_z[k] = b->lo[2];
	w->hi_x[k] = b->hi[0];
	w->hi_y[k] = b->hi[1];
	w->hi_z[k] = b->hi[2];
	w->child[k] = child;
}

/* Collapses the binary tree bn[0, nbin) into out->nodes. Children of a
 * node get consecutive ids, handed out as the node is written. */
static ajar_status collapse(const BinNode *bn, uint32_t nbin, Bvh *out)
{
	/* At most one per interior binary node, of which a full binary tree of
	 * nbin nodes has (nbin - 1) / 2; one for a root that is a leaf. */
	uint32_t cap = nbin / 2 + 1;
	out->nodes = malloc(sizeof(BvhNode) * cap);
	if (!out->nodes)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for %u nodes", cap);
	memset(out->nodes, 0, sizeof(BvhNode) * cap);
	/* Pending (binary node, wide id) pairs: at most BVH_WIDTH - 1 per wide
	 * level plus one; BVH_MAX_DEPTH bounds the levels. */
	struct {
		uint32_t bin, wide, depth;
	} stack[(BVH_WIDTH - 1) * BVH_MAX_DEPTH + BVH_WIDTH];
	int sp = 0;
	uint32_t nwide = 1;
	out->wide_depth = 1;
	stack[sp].bin = 0;
	stack[sp].wide = 0;
	stack[sp++].depth = 1;
	while (sp > 0) {
		sp--;
		uint32_t i = stack[sp].bin, id = stack[sp].wide, depth = stack[sp].depth;
		if (depth > out->wide_depth)
			out->wide_depth = depth;
		Slots s;
		if (bin_is_leaf(bn, i)) { /* only the root: a scene of at most 4 triangles */
			s.n = 1;
			s.bin[0] = i;
		} else {
			slots_fill(bn, i, &s);
		}
		BvhNode *w = &out->nodes[id];
		for (int k = 0; k < BVH_WIDTH; k++) {
			if (k >= s.n) {
				const Box none = {{INFINITY, INFINITY, INFINITY}, {INFINITY, INFINITY, INFINITY}};
				wide_set_slot(w, k, &none, BVH_EMPTY);
				continue;
			}
			const BinNode *c = &bn[s.bin[k]];
			if (c->count > 0) {
				wide_set_slot(w, k, &c->b, BVH_LEAF(c->index, c->count));
			} else {
				wide_set_slot(w, k, &c->b, (int)nwide);
				stack[sp].bin = s.bin[k];
				stack[sp].wide = nwide++;
				stack[sp++].depth = depth + 1;
			}
		}
	}
	BvhNode *shrunk = realloc(out->nodes, sizeof(BvhNode) * nwide);
	if (shrunk)
		out->nodes = shrunk;
	out->nnodes = nwide;
	return AJAR_OK;
}

ajar_status bvh_build(const Tri *tris, uint32_t ntris, Bvh *out)
{
	memset(out, 0, sizeof(*out));
	if (ntris == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "bvh_build: no triangles");
	if (ntris > BVH_MAX_TRIS)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "bvh_build: %u triangles, at most %u supported",
			       ntris, (unsigned)BVH_MAX_TRIS);

	size_t max_nodes = 2 * (size_t)ntris - 1;
	Ref *refs = malloc(sizeof(Ref) * ntris);
	BinNode *bn = malloc(sizeof(BinNode) * max_nodes);
	out->order = malloc(sizeof(uint32_t) * ntris);
	if (!refs || !bn || !out->order) {
		free(refs);
		free(bn);
		bvh_free(out);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for %u triangles",
			       ntris);
	}
	for (uint32_t i = 0; i < ntris; i++) {
		const Tri *t = &tris[i];
		Box *b = &refs[i].b;
		b->lo[0] = fmin(t->p0.x, fmin(t->p1.x, t->p2.x));
		b->lo[1] = fmin(t->p0.y, fmin(t->p1.y, t->p2.y));
		b->lo[2] = fmin(t->p0.z, fmin(t->p1.z, t->p2.z));
		b->hi[0] = fmax(t->p0.x, fmax(t->p1.x, t->p2.x));
		b->hi[1] = fmax(t->p0.y, fmax(t->p1.y, t->p2.y));
		b->hi[2] = fmax(t->p0.z, fmax(t->p1.z, t->p2.z));
		refs[i].idx = i;
	}

	/* LIFO: a split pushes the right task, then the left, so the left
	 * subtree is written completely before the right one starts. At most
	 * one pending right sibling per level plus the current task. */
	Task stack[BVH_MAX_DEPTH + 2];
	int sp = 0;
	uint32_t nnodes = 0, max_depth = 0;
	stack[sp++] = (Task){0, ntris, NO_PARENT, 0};
	while (sp > 0) {
		Task task = stack[--sp];
		uint32_t id = nnodes++;
		if (task.parent != NO_PARENT)
			bn[task.parent].index = (int)id;
		if (task.depth + 1 > max_depth)
			max_depth = task.depth + 1;

		Box box, cbox;
		box_empty(&box);
		box_empty(&cbox);
		for (uint32_t i = task.start; i < task.end; i++) {
			const Ref *r = &refs[i];
			box_grow(&box, &r->b);
			for (int a = 0; a < 3; a++) {
				float k = ref_key(r, a);
				if (k < cbox.lo[a])
					cbox.lo[a] = k;
				if (k > cbox.hi[a])
					cbox.hi[a] = k;
			}
		}
		BinNode *node = &bn[id];
		node->b = box;
		uint32_t n = task.end - task.start;
		uint32_t nleft = split_node(refs + task.start, n, &box, &cbox, task.depth);
		if (nleft == 0) {
			node->index = (int)task.start;
			node->count = (int)n;
			continue;
		}
		node->index = -1; /* patched when the right child is written */
		node->count = 0;
		uint32_t mid = task.start + nleft;
		stack[sp++] = (Task){mid, task.end, id, task.depth + 1};
		stack[sp++] = (Task){task.start, mid, NO_PARENT, task.depth + 1};
	}
	for (uint32_t i = 0; i < ntris; i++)
		out->order[i] = refs[i].idx;
	free(refs);
	out->ntris = ntris;
	out->depth = max_depth;
	ajar_status st = collapse(bn, nnodes, out);
	free(bn);
	if (st != AJAR_OK)
		bvh_free(out);
	return st;
}

void bvh_free(Bvh *b)
{
	free(b->nodes);
	free(b->order);
	memset(b, 0, sizeof(*b));
}

size_t bvh_memory(const Bvh *b)
{
	return sizeof(BvhNode) * (size_t)b->nnodes + sizeof(uint32_t) * (size_t)b->ntris;
}
