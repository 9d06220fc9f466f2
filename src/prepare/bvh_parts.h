/* bvh_parts.h — what the BVH build's files share (bvh_build.c drives the
 * build and its threads, bvh_split.c bins and splits a node, bvh_collapse.c
 * makes the eight-wide tree): boxes as four-float vectors, references,
 * binary nodes, bins.
 *
 * Every operation here gives the bits of the scalar build it replaced:
 * min and max keep the earlier value on ties (so -0 and +0 come out as
 * before), sums and products are the same IEEE single operations in the
 * same order, and bins merged in the order of their ranges equal bins
 * filled in one pass. That is why any number of threads builds the same
 * tree. */
#ifndef AJAR_BVH_PARTS_H
#define AJAR_BVH_PARTS_H
#include <stdint.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
typedef __m128 F4;
static inline F4 f4_zero(void) { return _mm_setzero_ps(); }
static inline F4 f4_set(float x, float y, float z) { return _mm_setr_ps(x, y, z, 0.0f); }
static inline F4 f4_splat(float v) { return _mm_set1_ps(v); }
/* Three floats at p (a fourth readable after them), the fourth lane 0. */
static inline F4 f4_load3(const float *p)
{
	return _mm_and_ps(_mm_loadu_ps(p), _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}
/* Four floats at p, 16-byte aligned. */
static inline F4 f4_load(const float *p) { return _mm_load_ps(p); }
static inline F4 f4_add(F4 a, F4 b) { return _mm_add_ps(a, b); }
static inline F4 f4_sub(F4 a, F4 b) { return _mm_sub_ps(a, b); }
static inline F4 f4_mul(F4 a, F4 b) { return _mm_mul_ps(a, b); }
/* o < b ? o : b and o > b ? o : b, lane by lane: b stays on ties. */
static inline F4 f4_min(F4 o, F4 b) { return _mm_min_ps(o, b); }
static inline F4 f4_max(F4 o, F4 b) { return _mm_max_ps(o, b); }
/* acc < o ? acc : o and acc > o ? acc : o: o replaces acc on ties too
 * (and would on a NaN o: for NaN-free values only). */
static inline F4 f4_min_late(F4 acc, F4 o) { return _mm_min_ps(acc, o); }
static inline F4 f4_max_late(F4 acc, F4 o) { return _mm_max_ps(acc, o); }
/* a with 1 added to lane 3's bits as an integer. */
static inline F4 f4_count1(F4 a)
{
	return _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(a), _mm_setr_epi32(0, 0, 0, 1)));
}
/* Lane 3's bits as an integer. */
static inline uint32_t f4_lane3_bits(F4 a)
{
	return (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(_mm_castps_si128(a), 3));
}
static inline F4 f4_set_lane3_bits(F4 a, uint32_t v)
{
	__m128i keep = _mm_setr_epi32(-1, -1, -1, 0);
	return _mm_or_ps(_mm_and_ps(a, _mm_castsi128_ps(keep)), _mm_castsi128_ps(_mm_setr_epi32(0, 0, 0, (int)v)));
}
/* Whether a lane of 0-2 is NaN. */
static inline int f4_any_nan3(F4 a) { return _mm_movemask_ps(_mm_cmpunord_ps(a, a)) & 7; }
/* seen with a NaN in every lane where a has one. */
static inline F4 f4_mark_nan(F4 seen, F4 a) { return _mm_or_ps(seen, _mm_cmpunord_ps(a, a)); }
/* Whether lane `axis` of a is >= t. */
static inline int f4_lane_ge(F4 a, F4 t, int axis) { return (_mm_movemask_ps(_mm_cmpge_ps(a, t)) >> axis) & 1; }
static inline void f4_store(float out[4], F4 a) { _mm_storeu_ps(out, a); }
/* Lanes truncated toward zero (the values fit an int). */
static inline void f4_trunc(int out[4], F4 a) { _mm_storeu_si128((__m128i *)out, _mm_cvttps_epi32(a)); }
/* Lanes 0-2 truncated toward zero, without a trip through memory. */
static inline void f4_trunc3(F4 a, int *k0, int *k1, int *k2)
{
	__m128i k = _mm_cvttps_epi32(a);
	*k0 = _mm_cvtsi128_si32(k);
	*k1 = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 1));
	*k2 = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 2));
}
/* d0 d1 + d1 d2 + d2 d0 of lanes 0-2 (summed in that order), 0 where a
 * lane is negative: half the area of a box of extents d. */
static inline float f4_half_area(F4 d)
{
	if (_mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps())) & 7)
		return 0.0f;
	F4 t = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));
	F4 s = _mm_add_ss(t, _mm_shuffle_ps(t, t, _MM_SHUFFLE(1, 1, 1, 1)));
	return _mm_cvtss_f32(_mm_add_ss(s, _mm_shuffle_ps(t, t, _MM_SHUFFLE(2, 2, 2, 2))));
}
#else
typedef struct {
	float v[4];
} F4;
static inline F4 f4_zero(void) { return (F4){{0.0f, 0.0f, 0.0f, 0.0f}}; }
static inline F4 f4_set(float x, float y, float z) { return (F4){{x, y, z, 0.0f}}; }
static inline F4 f4_splat(float v) { return (F4){{v, v, v, v}}; }
static inline F4 f4_load3(const float *p) { return (F4){{p[0], p[1], p[2], 0.0f}}; }
static inline F4 f4_load(const float *p) { return (F4){{p[0], p[1], p[2], p[3]}}; }
static inline F4 f4_add(F4 a, F4 b)
{
	for (int i = 0; i < 4; i++)
		a.v[i] += b.v[i];
	return a;
}
static inline F4 f4_sub(F4 a, F4 b)
{
	for (int i = 0; i < 4; i++)
		a.v[i] -= b.v[i];
	return a;
}
static inline F4 f4_mul(F4 a, F4 b)
{
	for (int i = 0; i < 4; i++)
		a.v[i] *= b.v[i];
	return a;
}
static inline F4 f4_min(F4 o, F4 b)
{
	for (int i = 0; i < 4; i++)
		b.v[i] = o.v[i] < b.v[i] ? o.v[i] : b.v[i];
	return b;
}
static inline F4 f4_max(F4 o, F4 b)
{
	for (int i = 0; i < 4; i++)
		b.v[i] = o.v[i] > b.v[i] ? o.v[i] : b.v[i];
	return b;
}
static inline F4 f4_min_late(F4 acc, F4 o)
{
	for (int i = 0; i < 4; i++)
		acc.v[i] = acc.v[i] < o.v[i] ? acc.v[i] : o.v[i];
	return acc;
}
static inline F4 f4_max_late(F4 acc, F4 o)
{
	for (int i = 0; i < 4; i++)
		acc.v[i] = acc.v[i] > o.v[i] ? acc.v[i] : o.v[i];
	return acc;
}
static inline uint32_t f4_lane3_bits(F4 a)
{
	uint32_t v;
	memcpy(&v, &a.v[3], sizeof v);
	return v;
}
static inline F4 f4_set_lane3_bits(F4 a, uint32_t v)
{
	memcpy(&a.v[3], &v, sizeof v);
	return a;
}
static inline F4 f4_count1(F4 a) { return f4_set_lane3_bits(a, f4_lane3_bits(a) + 1); }
static inline int f4_any_nan3(F4 a) { return a.v[0] != a.v[0] || a.v[1] != a.v[1] || a.v[2] != a.v[2]; }
static inline F4 f4_mark_nan(F4 seen, F4 a)
{
	for (int i = 0; i < 4; i++)
		if (a.v[i] != a.v[i])
			seen.v[i] = a.v[i];
	return seen;
}
static inline int f4_lane_ge(F4 a, F4 t, int axis) { return a.v[axis] >= t.v[axis]; }
static inline void f4_store(float out[4], F4 a)
{
	for (int i = 0; i < 4; i++)
		out[i] = a.v[i];
}
static inline void f4_trunc(int out[4], F4 a)
{
	for (int i = 0; i < 4; i++)
		out[i] = (int)a.v[i];
}
static inline void f4_trunc3(F4 a, int *k0, int *k1, int *k2)
{
	*k0 = (int)a.v[0];
	*k1 = (int)a.v[1];
	*k2 = (int)a.v[2];
}
static inline float f4_half_area(F4 d)
{
	if (d.v[0] < 0.0f || d.v[1] < 0.0f || d.v[2] < 0.0f)
		return 0.0f;
	return d.v[0] * d.v[1] + d.v[1] * d.v[2] + d.v[2] * d.v[0];
}
#endif

/* Leaves hold at most this many triangles (the leaf slot encodes 1-4). */
#define BVH_MAX_LEAF 4
/* SAH bins per axis at most; a node of fewer refs gets one per ref. */
#define BVH_BINS 32
/* Nodes of at most this many refs are swept without bins (bvh_split.c). */
#define BVH_FEW 4
/* Traversal cost relative to one triangle test. */
#define BVH_COST_TRAVERSE 1.0f

typedef struct {
	float lo[3], hi[3];
} Box;

/* A box as vectors: lanes 0-2 the axes. */
typedef struct {
	F4 lo, hi;
} Box4;

/* A triangle's bounds and where it came from; the build permutes these.
 * 32 bytes, aligned: each bound is one aligned vector load (28-byte refs
 * split a cache line every other ref) and a swap two vector moves. */
typedef struct {
	_Alignas(16) float lo[3];
	uint32_t idx; /* lane 3 of lo's load: masked off */
	float hi[3];
	float zero; /* lane 3 of hi's load: 0 */
} Ref;

/* Node of the binary tree: an interior node's left child is the next
 * node, its right child node `index`; a leaf (count > 0) covers refs
 * [index, index + count) (after a build with instances, bvh_build.c
 * renumbers leaves: triangles by their place among the triangles, and an
 * instance leaf index -1 - instance). A subtree over n refs rooted at node p uses
 * nodes within [p, p + 2n - 1), so a node's children can be placed before
 * either is built: left p + 1, right p + 2 n_left. */
typedef struct {
	Box b;
	int index;
	int count;
} BinNode;

static inline Box4 box4_empty(void)
{
	Box4 b = {f4_splat(3.402823466e+38f), f4_splat(-3.402823466e+38f)};
	return b;
}

/* Grows b by o: a lane of o replaces b's only where strictly outside. */
static inline Box4 box4_grow(Box4 b, Box4 o)
{
	b.lo = f4_min(o.lo, b.lo);
	b.hi = f4_max(o.hi, b.hi);
	return b;
}

static inline Box4 box4_of_ref(const Ref *r)
{
	Box4 b = {f4_load3(r->lo), f4_load(r->hi)};
	return b;
}

/* A ref of box b (lane 3 of b.lo and b.hi +0) and index idx, stored as
 * two vectors. */
static inline void ref_store(Ref *r, Box4 b, uint32_t idx)
{
#if defined(__SSE2__)
	_mm_store_ps((float *)r, f4_set_lane3_bits(b.lo, idx));
	_mm_store_ps((float *)r + 4, b.hi);
#else
	*r = (Ref){{b.lo.v[0], b.lo.v[1], b.lo.v[2]}, idx, {b.hi.v[0], b.hi.v[1], b.hi.v[2]}, 0.0f};
#endif
}

static inline void box4_store(Box *out, Box4 b)
{
	float lo[4], hi[4];
	f4_store(lo, b.lo);
	f4_store(hi, b.hi);
	for (int a = 0; a < 3; a++) {
		out->lo[a] = lo[a];
		out->hi[a] = hi[a];
	}
}

/* Half the surface area; 0 for an empty box. */
static inline float box_area(const Box *b)
{
	float d[3];
	for (int a = 0; a < 3; a++) {
		d[a] = b->hi[a] - b->lo[a];
		if (d[a] < 0.0f)
			return 0.0f;
	}
	return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

/* A node's bounds and its refs' centroid (key) bounds. A lane that equals
 * several refs' (-0 and +0 compare equal) holds the first one's bits in
 * the refs' order: that is the bits of one pass in order, which is what
 * the trees were measured with. */
typedef struct {
	Box4 box, cbox;
} NodeBounds;

/* Bounds of refs [start, end), grown into *nb (box4_empty to start). */
void bvh_bounds(const Ref *refs, uint32_t start, uint32_t end, NodeBounds *nb);
/* *acc grown by `later`, the bounds of refs after acc's. */
void bvh_bounds_merge(NodeBounds *acc, const NodeBounds *later);

/* A node's SAH bins: one box per bin and axis, its count in the bits of
 * lane 3 of hi (a ref's hi has +0 there, never larger as a float, so the
 * max keeps the count and one integer add counts the ref: no second
 * read-modify-write per bin). */
typedef struct {
	Box4 box[3][BVH_BINS];
} Bins;

static inline uint32_t bins_count(const Bins *b, int a, int k) { return f4_lane3_bits(b->box[a][k].hi); }

/* How a node of n refs with centroid bounds cbox is split: the axis of
 * largest centroid extent, and whether SAH bins are needed (else a leaf,
 * a halving of equal centroids, or a median split). */
typedef struct {
	int axis;         /* of largest centroid extent (the median split's) */
	int nb;           /* bins per axis; 0: no SAH for this node */
	float cmin[3];    /* centroid bounds' low corner */
	float scale[3];   /* nb / extent, 0 for a flat axis */
	float ext[3];
	uint32_t inst_from; /* refs with idx >= this are instances, leaves of one (UINT32_MAX: none) */
	int nan_free;       /* no ref's bounds or key has a NaN lane */
} SplitPlan;

void bvh_split_plan(uint32_t n, const Box4 *cbox, uint32_t depth, uint32_t inst_from, int nan_free, SplitPlan *p);
void bvh_bins_clear(Bins *b, int nb);
/* bvh_split_plan and bvh_split_apply on a node of two refs where their
 * outcome is plain (bvh_split.c); 0 where they must decide. */
int bvh_split_two(Ref *refs, const Box *box, const Box4 *cbox, uint32_t depth, uint32_t inst_from, int nan_free,
		  uint32_t *nleft, NodeBounds child[2]);
/* Bins refs [start, end) into b. */
void bvh_bins_add(Bins *b, const SplitPlan *p, const Ref *refs, uint32_t start, uint32_t end);
/* acc += later, the bins of refs after acc's. */
void bvh_bins_merge(Bins *acc, const Bins *later, int nb);
/* Chooses the split of refs[0, n) (node box `box`) with the plan and, when
 * p->nb, its bins; reorders refs. Returns the count on the left, or 0 for
 * a leaf; with a split, child[0] and child[1] are the bounds of the two
 * sides (as bvh_bounds over each). */
uint32_t bvh_split_apply(Ref *refs, uint32_t n, const Box *box, const SplitPlan *p, const Bins *bins,
			 NodeBounds child[2]);
#endif
