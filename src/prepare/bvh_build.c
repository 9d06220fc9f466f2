/* bvh_build.c — the binned SAH build of the flattened BVH (see bvh_build.h),
 * on every core.
 *
 * Top-down: each node bins its triangles' centroids and takes the cheapest
 * SAH split (bvh_split.c); the binary tree is then collapsed into
 * eight-wide nodes (bvh_collapse.c). Two phases share the cores:
 *
 *  1. The nodes of at least 1/threads of the references (and PAR_MIN), one
 *     at a time: their bins are filled by every thread over a slice of the
 *     references each and merged in slice order (bvh_parts.h: the same
 *     bits as one pass); the partition is one thread's.
 *  2. The nodes below them from a shared stack, each thread taking the
 *     latest: a node of at least SPLIT_MIN references is split alone and
 *     its children pushed, a smaller one's whole subtree is built from an
 *     explicit stack (no recursion, so a pathological input cannot
 *     overflow the C stack), numbered depth-first. The cores stay busy
 *     down to the last small subtree (before, subtrees of up to 1/(4
 *     threads) of the references went one a thread, largest first, and
 *     a core could wait out the last of them).
 *
 * A node's split depends on its references alone, and a subtree over n
 * references rooted at binary node p fits in [p, p + 2n - 1): a node split
 * alone places its children at p + 1 and p + 2 n_left before they are
 * built, so the phases need no stitching, and the tree is the same, bit for
 * bit, whatever the number of threads (test_bvh's test_threads_same_tree,
 * test_instances).
 *
 * A top-level tree (scene_bvh.c) takes instances too: boxes given by the
 * caller, each a leaf of its own (bvh_split.c), its slot BVH_INSTANCE(i);
 * the leaves are then renumbered to the triangles' places among the
 * triangles alone (number_leaves).
 *
 * Times (src/prepare/README.md, "The BVH"): bathroom, 592,188 triangles,
 * 0.69 s of CPU before the vector bins, 0.23 s after; issue 42's second
 * round (the same tree) 0.74x that, Embree 1.3x faster where it was 1.8x;
 * its fourth (the same tree) 0.9x the second's, Embree 1.14x faster; its
 * fifth (the same tree) 0.9x the fourth's on bathroom and unique-10m. */
#include "prepare/bvh_build.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/big_array.h"
#include "core/error.h"
#include "core/workers.h"
#include "geom/bvh.h"
#include "prepare/bvh_collapse.h"
#include "prepare/bvh_parts.h"

/* Traversal pushes at most BVH_WIDTH - 1 entries per wide level, and the
 * wide tree has at most BVH_MAX_DEPTH / 2 interior levels (bvh.h). */
_Static_assert((BVH_WIDTH - 1) * (BVH_MAX_DEPTH / 2) <= BVH_STACK_SIZE, "kernels/geom/bvh.h: traversal stack too small");
_Static_assert(BVH_MAX_LEAF <= 4, "leaf slots encode at most 4 triangles");

/* Phase 1 takes nodes of at least this many references, and of at least
 * 1/threads of them all. */
#define PAR_MIN (1u << 15)
/* Phase 2 splits nodes of at least this many references one at a time;
 * a smaller subtree (a few hundred microseconds) is one thread's. */
#define SPLIT_MIN 4096u

typedef struct {
	uint32_t start, end; /* references */
	uint32_t node;       /* its binary node */
	uint32_t depth;
	NodeBounds nb;       /* of its references, from its parent's split */
} Task;

typedef struct {
	const BvhInput *in;
	uint32_t inst_from;      /* in->ntris with instances, else UINT32_MAX */
	Ref *refs;
	BinNode *bn;
	uint32_t *order;
	uint32_t nrefs;
	int nan_free;            /* no NaN in any ref's bounds or key (SplitPlan) */
	Workers workers;
	/* Phase 1: the node whose bins the threads fill. */
	Task node;
	const SplitPlan *plan;
	NodeBounds *part_bounds; /* one per thread: the root's, by slice */
	int *part_nan;           /* one per thread: a NaN in its slice */
	Bins *part_bins;         /* one per thread */
	/* Phase 2: the shared stack of nodes not yet taken. */
	pthread_mutex_t mu;
	pthread_cond_t cv;
	Task *tasks;
	size_t ntasks, cap;
	int busy; /* threads working on a node or subtree */
	atomic_uint ninterior, max_depth;
} Build;

static void slice(uint32_t start, uint32_t end, int part, int nparts, uint32_t *s, uint32_t *e)
{
	uint64_t n = end - start;
	*s = start + (uint32_t)(n * (uint64_t)part / (uint64_t)nparts);
	*e = start + (uint32_t)(n * (uint64_t)(part + 1) / (uint64_t)nparts);
}

/* A triangle's bounds: fmin/fmax of its corners, which keep the first
 * argument on ties (-0 and +0 as the scalar build had them); an
 * instance's as given. With them the root's bounds over the slice, and
 * whether a NaN is among them. */
static void refs_fill(void *ctx, int part, int nparts)
{
	Build *b = ctx;
	const BvhInput *in = b->in;
	uint32_t s, e;
	slice(0, b->nrefs, part, nparts, &s, &e);
	F4 nan = f4_zero(); /* NaN lanes seen: x != x */
	Box4 box = box4_empty(), cbox = box4_empty();
	for (uint32_t i = s; i < e; i++) {
		Ref *r = &b->refs[i];
		Box4 rb;
		if (i >= in->ntris) {
			V3 lo = in->inst_lo[i - in->ntris], hi = in->inst_hi[i - in->ntris];
			*r = (Ref){{lo.x, lo.y, lo.z}, i, {hi.x, hi.y, hi.z}, 0.0f};
			rb = box4_of_ref(r);
		} else {
			/* Each bound one vector store, the box kept in registers: stored
			 * in pieces and loaded whole, the ref waited on the stores
			 * (refs_fill 2x its cycles). Lane 3 of the corners is 0, so hi's
			 * is the ref's +0 and lo's its index. */
			const Tri *t = &in->tris[in->index ? in->index[i] : i];
			F4 p0 = f4_load3(&t->p0.x), p1 = f4_load3(&t->p1.x), p2 = f4_load3(&t->p2.x);
			rb.lo = f4_min(f4_min(p2, p1), p0);
			rb.hi = f4_max(f4_max(p2, p1), p0);
			ref_store(r, rb, i);
		}
		/* bvh_bounds' growth, ref by ref */
		F4 key = f4_add(rb.lo, rb.hi);
		box = box4_grow(box, rb);
		cbox.lo = f4_min(key, cbox.lo);
		cbox.hi = f4_max(key, cbox.hi);
		nan = f4_mark_nan(f4_mark_nan(f4_mark_nan(nan, rb.lo), rb.hi), key);
	}
	b->part_nan[part] = f4_any_nan3(nan);
	b->part_bounds[part] = (NodeBounds){box, cbox};
}

static void part_bins(void *ctx, int part, int nparts)
{
	Build *b = ctx;
	uint32_t s, e;
	slice(b->node.start, b->node.end, part, nparts, &s, &e);
	bvh_bins_clear(&b->part_bins[part], b->plan->nb);
	bvh_bins_add(&b->part_bins[part], b->plan, b->refs, s, e);
}

static void note_depth(Build *b, uint32_t depth)
{
	uint32_t d = atomic_load(&b->max_depth);
	while (depth > d && !atomic_compare_exchange_weak(&b->max_depth, &d, depth))
		;
}

/* Phase 2: the subtree of task `root`, numbered depth-first from
 * root.node. LIFO: a split pushes the right task, then the left, so the
 * left subtree is written completely before the right one starts; at
 * most one pending right sibling per level plus the current task. */
static void build_subtree(Build *b, Task root)
{
	Bins bins;
	struct {
		Task t;
		uint32_t parent; /* node whose right child this is, or UINT32_MAX */
	} stack[BVH_MAX_DEPTH + 2];
	int sp = 0;
	uint32_t next = root.node, ninterior = 0, max_depth = 0;
	stack[sp].t = root;
	stack[sp++].parent = UINT32_MAX;
	while (sp > 0) {
		sp--;
		Task task = stack[sp].t;
		uint32_t parent = stack[sp].parent, id = next++;
		if (parent != UINT32_MAX)
			b->bn[parent].index = (int)id;
		if (task.depth + 1 > max_depth)
			max_depth = task.depth + 1;
		BinNode *node = &b->bn[id];
		box4_store(&node->b, task.nb.box);
		uint32_t n = task.end - task.start, nleft;
		NodeBounds child[2];
		if (n != 2 || !bvh_split_two(b->refs + task.start, &node->b, &task.nb.cbox, task.depth, b->inst_from,
					     b->nan_free, &nleft, child)) {
			SplitPlan plan;
			bvh_split_plan(n, &task.nb.cbox, task.depth, b->inst_from, b->nan_free, &plan);
			if (plan.nb && n > BVH_FEW) { /* fewer are split without bins (bvh_split.c) */
				bvh_bins_clear(&bins, plan.nb);
				bvh_bins_add(&bins, &plan, b->refs, task.start, task.end);
			}
			nleft = bvh_split_apply(b->refs + task.start, n, &node->b, &plan, &bins, child);
		}
		if (nleft == 0) {
			node->index = (int)task.start;
			node->count = (int)n;
			continue;
		}
		node->index = -1; /* patched when the right child is written */
		node->count = 0;
		ninterior++;
		uint32_t mid = task.start + nleft;
		stack[sp].t = (Task){mid, task.end, 0, task.depth + 1, child[1]};
		stack[sp++].parent = id;
		stack[sp].t = (Task){task.start, mid, 0, task.depth + 1, child[0]};
		stack[sp++].parent = UINT32_MAX;
	}
	atomic_fetch_add(&b->ninterior, ninterior);
	note_depth(b, max_depth);
}

/* Splits node t alone with the bins given (filled when plan->nb), its
 * children placed at t.node + 1 and t.node + 2 n_left. Returns how many
 * children go to kids (0 for a leaf). */
static int split_alone(Build *b, Task t, const SplitPlan *plan, const Bins *bins, Task kids[2])
{
	uint32_t n = t.end - t.start;
	note_depth(b, t.depth + 1);
	BinNode *node = &b->bn[t.node];
	box4_store(&node->b, t.nb.box);
	NodeBounds child[2];
	uint32_t nleft = bvh_split_apply(b->refs + t.start, n, &node->b, plan, bins, child);
	if (nleft == 0) {
		node->index = (int)t.start;
		node->count = (int)n;
		return 0;
	}
	node->index = (int)(t.node + 2 * nleft);
	node->count = 0;
	atomic_fetch_add(&b->ninterior, 1);
	uint32_t mid = t.start + nleft;
	kids[0] = (Task){mid, t.end, t.node + 2 * nleft, t.depth + 1, child[1]};
	kids[1] = (Task){t.start, mid, t.node + 1, t.depth + 1, child[0]};
	return 2;
}

/* Pushes a task on the shared stack (b->mu held); 0 if out of memory. */
static int push_task(Build *b, Task t)
{
	if (b->ntasks == b->cap) {
		size_t cap = b->cap ? 2 * b->cap : 64;
		Task *q = realloc(b->tasks, sizeof *q * cap);
		if (!q)
			return 0;
		b->tasks = q;
		b->cap = cap;
	}
	b->tasks[b->ntasks++] = t;
	return 1;
}

/* Phase 2 on one thread: takes the latest node until none is left and no
 * thread can push more. */
static void part_nodes(void *ctx, int part, int nparts)
{
	(void)part;
	(void)nparts;
	Build *b = ctx;
	Bins bins;
	pthread_mutex_lock(&b->mu);
	for (;;) {
		while (b->ntasks == 0 && b->busy > 0)
			pthread_cond_wait(&b->cv, &b->mu);
		if (b->ntasks == 0)
			break;
		Task t = b->tasks[--b->ntasks];
		b->busy++;
		pthread_mutex_unlock(&b->mu);
		Task kids[2];
		int nk = 0;
		uint32_t n = t.end - t.start;
		if (n >= SPLIT_MIN) {
			SplitPlan plan;
			bvh_split_plan(n, &t.nb.cbox, t.depth, b->inst_from, b->nan_free, &plan);
			if (plan.nb) {
				bvh_bins_clear(&bins, plan.nb);
				bvh_bins_add(&bins, &plan, b->refs, t.start, t.end);
			}
			nk = split_alone(b, t, &plan, &bins, kids);
		} else {
			build_subtree(b, t);
		}
		pthread_mutex_lock(&b->mu);
		for (int k = 0; k < nk; k++)
			if (!push_task(b, kids[k])) { /* out of memory: built here, one thread's */
				pthread_mutex_unlock(&b->mu);
				build_subtree(b, kids[k]);
				pthread_mutex_lock(&b->mu);
			}
		b->busy--;
		if (nk || b->busy == 0)
			pthread_cond_broadcast(&b->cv);
	}
	pthread_mutex_unlock(&b->mu);
}

/* Phase 1 from the root, then phase 2 over the nodes it left. */
static ajar_status build_tree(Build *b)
{
	int nt = b->workers.n;
	Task root = {0, b->nrefs, 0, 0, b->part_bounds[0]};
	b->nan_free = !b->part_nan[0];
	for (int k = 1; k < nt; k++) {
		bvh_bounds_merge(&root.nb, &b->part_bounds[k]);
		b->nan_free &= !b->part_nan[k];
	}
	if (nt == 1) { /* one subtree, numbered depth-first from the root */
		build_subtree(b, root);
		return AJAR_OK;
	}
	uint32_t big = b->nrefs / (uint32_t)nt;
	if (big < PAR_MIN)
		big = PAR_MIN;
	b->part_bins = malloc(sizeof *b->part_bins * (size_t)nt);
	if (!b->part_bins || !push_task(b, root))
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for the build's tasks");
	/* Phase 1: while a node on the stack is big (a few at most). */
	for (;;) {
		size_t k = 0;
		while (k < b->ntasks && b->tasks[k].end - b->tasks[k].start < big)
			k++;
		if (k == b->ntasks)
			break;
		Task t = b->tasks[k], kids[2];
		b->tasks[k] = b->tasks[--b->ntasks];
		uint32_t n = t.end - t.start;
		b->node = t;
		SplitPlan plan;
		bvh_split_plan(n, &t.nb.cbox, t.depth, b->inst_from, b->nan_free, &plan);
		if (plan.nb) {
			b->plan = &plan;
			workers_run(&b->workers, part_bins, b);
			for (int k = 1; k < nt; k++)
				bvh_bins_merge(&b->part_bins[0], &b->part_bins[k], plan.nb);
		}
		int nk = split_alone(b, t, &plan, &b->part_bins[0], kids);
		for (int k = 0; k < nk; k++)
			if (!push_task(b, kids[k]))
				return err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for the build's tasks");
	}
	b->busy = 0;
	workers_run(&b->workers, part_nodes, b);
	return AJAR_OK;
}

/* With instances: leaves renumbered (bvh_parts.h, BinNode) and the order
 * of the triangles alone, walking the tree from its root. */
static ajar_status number_leaves(Build *b)
{
	uint32_t *place = malloc(sizeof *place * (size_t)b->nrefs);
	if (!place)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for %u references", b->nrefs);
	uint32_t k = 0;
	for (uint32_t i = 0; i < b->nrefs; i++)
		if (b->refs[i].idx < b->inst_from) {
			b->order[k] = b->refs[i].idx;
			place[i] = k++;
		}
	uint32_t stack[BVH_MAX_DEPTH + 2];
	int sp = 0;
	stack[sp++] = 0;
	while (sp > 0) {
		BinNode *node = &b->bn[stack[--sp]];
		if (node->count == 0) {
			stack[sp++] = (uint32_t)node->index;
			stack[sp++] = (uint32_t)(node - b->bn) + 1;
			continue;
		}
		uint32_t idx = b->refs[node->index].idx;
		node->index = idx >= b->inst_from ? -1 - (int)(idx - b->inst_from) : (int)place[node->index];
	}
	free(place);
	return AJAR_OK;
}

static void order_fill(void *ctx, int part, int nparts)
{
	Build *b = ctx;
	uint32_t s, e;
	slice(0, b->nrefs, part, nparts, &s, &e);
	for (uint32_t i = s; i < e; i++)
		b->order[i] = b->refs[i].idx;
}

struct BvhPermute {
	const uint32_t *order;
	uint32_t n;
	Ref *scratch; /* the references, done with: 32 bytes a triangle */
	Workers *workers;
	char *array;  /* the array being permuted, and its slice */
	size_t stride, off, len;
};

/* A slice of len bytes at off: fixed sizes compile to vector moves. */
static inline void move_slice(char *to, const char *from, size_t len)
{
	if (len == 32)
		memcpy(to, from, 32);
	else if (len == 16)
		memcpy(to, from, 16);
	else
		memcpy(to, from, len);
}

/* The slices read lie anywhere: each is asked for PERMUTE_AHEAD slices
 * before it is read, so many misses are under way at once (the whole
 * permute, gathers and copies back, 0.8x the cycles on unique-1m, 0.85x
 * on bathroom; 32 to 256 ahead about alike). */
#define PERMUTE_AHEAD 64u
static void permute_gather(void *ctx, int part, int nparts)
{
	BvhPermute *p = ctx;
	uint32_t s, e;
	slice(0, p->n, part, nparts, &s, &e);
	for (uint32_t i = s; i < e; i++) {
		if (i + PERMUTE_AHEAD < e)
			__builtin_prefetch(p->array + p->stride * p->order[i + PERMUTE_AHEAD] + p->off);
		move_slice((char *)&p->scratch[i], p->array + p->stride * p->order[i] + p->off, p->len);
	}
}

static void permute_back(void *ctx, int part, int nparts)
{
	BvhPermute *p = ctx;
	uint32_t s, e;
	slice(0, p->n, part, nparts, &s, &e);
	for (uint32_t i = s; i < e; i++)
		move_slice(p->array + p->stride * i + p->off, (const char *)&p->scratch[i], p->len);
}

void bvh_permute(BvhPermute *p, void *array, size_t stride)
{
	_Static_assert(sizeof(Ref) == 32, "bvh_permute moves 32 bytes a reference");
	p->array = array;
	p->stride = stride;
	for (p->off = 0; p->off < stride; p->off += p->len) {
		p->len = stride - p->off < 32 ? stride - p->off : 32;
		/* Every read before any write: a slice read may lie anywhere. */
		workers_run(p->workers, permute_gather, p);
		workers_run(p->workers, permute_back, p);
	}
}

int bvh_threads(void) { return workers_cores(); }

ajar_status bvh_build_input(const BvhInput *in, int threads, BvhReorder reorder, void *ctx, Bvh *out)
{
	BvhNode *base_nodes = out->nodes;
	uint32_t base = base_nodes ? out->nnodes : 0;
	memset(out, 0, sizeof(*out));
	out->nodes = base_nodes;
	out->nnodes = base;
	if (in->n == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "bvh_build: no triangles");
	if (in->n > BVH_MAX_TRIS || in->n - in->ntris >= BVH_INSTANCE_BASE)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "bvh_build: %u triangles and instances, at most %u supported",
			       in->n, (unsigned)BVH_MAX_TRIS);
	Build b;
	memset(&b, 0, sizeof b);
	b.in = in;
	b.inst_from = in->ntris < in->n ? in->ntris : UINT32_MAX;
	b.nrefs = in->n;
	/* The binary tree's array is as large as any tree could need; pages
	 * the build leaves untouched cost no memory. */
	size_t max_nodes = 2 * (size_t)in->n - 1;
	b.refs = big_alloc(sizeof(Ref) * in->n); /* page-aligned: the refs are aligned */
	big_advise_huge(b.refs, 0, sizeof(Ref) * in->n);
	b.bn = malloc(sizeof(BinNode) * max_nodes);
	out->order = malloc(sizeof(uint32_t) * (in->ntris ? in->ntris : 1));
	ajar_status st = AJAR_OK;
	if (!b.refs || !b.bn || !out->order)
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for %u triangles", in->n);
	if (st == AJAR_OK)
		st = workers_start(&b.workers, threads < 1 ? 1 : threads);
	if (st == AJAR_OK) {
		b.part_bounds = malloc(sizeof *b.part_bounds * (size_t)b.workers.n);
		b.part_nan = malloc(sizeof *b.part_nan * (size_t)b.workers.n);
		if (!b.part_bounds || !b.part_nan)
			st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "bvh_build: out of memory for the build's tasks");
	}
	if (st == AJAR_OK) {
		workers_run(&b.workers, refs_fill, &b);
		pthread_mutex_init(&b.mu, NULL);
		pthread_cond_init(&b.cv, NULL);
		st = build_tree(&b);
		pthread_cond_destroy(&b.cv);
		pthread_mutex_destroy(&b.mu);
	}
	if (st == AJAR_OK) {
		b.order = out->order;
		if (b.inst_from != UINT32_MAX)
			st = number_leaves(&b);
		else
			workers_run(&b.workers, order_fill, &b);
	}
	free(b.tasks);
	free(b.part_bounds);
	free(b.part_nan);
	free(b.part_bins);
	if (st == AJAR_OK && reorder) {
		BvhPermute p = {out->order, in->ntris, b.refs, &b.workers, NULL, 0, 0, 0};
		reorder(&p, ctx);
		free(out->order);
		out->order = NULL;
	}
	if (b.workers.threads || b.workers.n)
		workers_stop(&b.workers);
	big_free(b.refs, sizeof(Ref) * in->n);
	if (st == AJAR_OK) {
		out->ntris = in->ntris;
		out->depth = atomic_load(&b.max_depth);
		st = bvh_collapse(b.bn, atomic_load(&b.ninterior), in->tri_base, out);
	}
	free(b.bn);
	if (st != AJAR_OK) {
		free(out->order);
		out->order = NULL;
		if (!base_nodes)
			bvh_free(out);
	}
	return st;
}

ajar_status bvh_build_reorder(const Tri *tris, uint32_t ntris, int threads, BvhReorder reorder, void *ctx,
			      Bvh *out)
{
	BvhInput in = {tris, NULL, ntris, NULL, NULL, ntris, 0};
	memset(out, 0, sizeof *out);
	return bvh_build_input(&in, threads, reorder, ctx, out);
}

ajar_status bvh_build_threads(const Tri *tris, uint32_t ntris, int threads, Bvh *out)
{
	return bvh_build_reorder(tris, ntris, threads, NULL, NULL, out);
}

ajar_status bvh_build(const Tri *tris, uint32_t ntris, Bvh *out)
{
	return bvh_build_threads(tris, ntris, bvh_threads(), out);
}

void bvh_free(Bvh *b)
{
	big_free(b->nodes, sizeof(BvhNode) * (size_t)b->nnodes);
	free(b->order);
	memset(b, 0, sizeof(*b));
}

size_t bvh_memory(const Bvh *b)
{
	return sizeof(BvhNode) * (size_t)b->nnodes + sizeof(uint32_t) * (size_t)b->ntris;
}
