/* bvh_split.c — one node of the binned SAH build (Wald 2007, "On fast
 * construction of SAH-based bounding volume hierarchies"): its bounds, its
 * refs' centroids binned into at most BVH_BINS bins per axis, the cheapest
 * split by the surface-area heuristic, and the partition. Where SAH cannot
 * split (all centroids equal, or every centroid in one bin) or the tree is
 * getting deep, an object-median split halves the node instead.
 *
 * Bounds and bins are filled over a range of refs, so bvh_build.c can fill
 * them for a large node on several threads and merge them in range order:
 * the merged result is the bits of one pass (bvh_parts.h). The three axes
 * are binned together in four-float vectors: 3x faster than the scalar
 * loop it replaced, with the same bins. */
#include <float.h>

#include "prepare/bvh_build.h"
#include "prepare/bvh_parts.h"

/* From this depth on only median splits: each halves the node, so even
 * 2^32 triangles in leaves of BVH_MAX_LEAF need at most 30 more levels. */
#define BVH_MEDIAN_DEPTH (BVH_MAX_DEPTH - 32)

void bvh_bounds(const Ref *refs, uint32_t start, uint32_t end, NodeBounds *nb)
{
	Box4 box = nb->box, cbox = nb->cbox;
	for (uint32_t i = start; i < end; i++) {
		Box4 r = box4_of_ref(&refs[i]);
		F4 key = f4_add(r.lo, r.hi);
		box = box4_grow(box, r);
		cbox.lo = f4_min(key, cbox.lo);
		cbox.hi = f4_max(key, cbox.hi);
	}
	nb->box = box;
	nb->cbox = cbox;
}

void bvh_bounds_merge(NodeBounds *acc, const NodeBounds *later)
{
	acc->box = box4_grow(acc->box, later->box);
	acc->cbox = box4_grow(acc->cbox, later->cbox);
}

void bvh_split_plan(uint32_t n, const Box4 *cbox, uint32_t depth, uint32_t inst_from, int nan_free, SplitPlan *p)
{
	p->inst_from = inst_from;
	p->nan_free = nan_free;
	float lo[4], hi[4];
	f4_store(lo, cbox->lo);
	f4_store(hi, cbox->hi);
	p->axis = 0;
	for (int a = 0; a < 3; a++) {
		p->cmin[a] = lo[a];
		p->ext[a] = hi[a] - lo[a];
		if (p->ext[a] > p->ext[p->axis])
			p->axis = a;
	}
	p->nb = 0;
	if (n <= 1 || p->ext[p->axis] <= 0.0f || depth >= BVH_MEDIAN_DEPTH)
		return;
	/* Small nodes get fewer bins: the sweep costs per bin, and most nodes
	 * are small. */
	p->nb = n < BVH_BINS ? (int)n : BVH_BINS;
#if defined(__SSE2__)
	/* the three divisions in one vector division: the same quotients */
	__m128 ext = _mm_sub_ps(cbox->hi, cbox->lo);
	__m128 q = _mm_and_ps(_mm_cmpgt_ps(ext, _mm_setzero_ps()), _mm_div_ps(_mm_set1_ps((float)p->nb), ext));
	float sc[4];
	_mm_storeu_ps(sc, q);
	for (int a = 0; a < 3; a++)
		p->scale[a] = sc[a];
#else
	for (int a = 0; a < 3; a++)
		p->scale[a] = p->ext[a] > 0.0f ? (float)p->nb / p->ext[a] : 0.0f;
#endif
}

void bvh_bins_clear(Bins *b, int nb)
{
	Box4 e = box4_empty();
	e.hi = f4_set_lane3_bits(e.hi, 0);
	for (int a = 0; a < 3; a++)
		for (int k = 0; k < nb; k++)
			b->box[a][k] = e;
}

/* A bin grown by ref box r and counted. */
static inline void bin_grow(Box4 *bin, Box4 r)
{
	bin->lo = f4_min(r.lo, bin->lo);
	bin->hi = f4_count1(f4_max(r.hi, bin->hi));
}

#define BINS_AHEAD 64u
/* One ref's box and bins: (int)((key - cmin) * scale) clamped to
 * [0, nb - 1], as the float clamped before truncation: the same bin for
 * every value. Binning is split in two, finding a ref's bins and growing
 * them (ref_bins_grow), so a loop can find the next refs' bins before it
 * grows this one's: every store's address is then known before the bin
 * loads after it issue, which need not wait on it or guess. */
typedef struct {
	Box4 r;
	int k[3];
} RefBins;

static inline RefBins ref_bins(const Ref *ref, F4 cmin, F4 scale, F4 top)
{
	RefBins q;
	q.r = box4_of_ref(ref);
	F4 f = f4_mul(f4_sub(f4_add(q.r.lo, q.r.hi), cmin), scale);
	f4_trunc3(f4_min(f4_max(f, f4_zero()), top), &q.k[0], &q.k[1], &q.k[2]);
	return q;
}

static inline void ref_bins_grow(Bins *b, const RefBins *q)
{
	bin_grow(&b->box[0][q->k[0]], q->r);
	bin_grow(&b->box[1][q->k[1]], q->r);
	bin_grow(&b->box[2][q->k[2]], q->r);
}

void bvh_bins_add(Bins *b, const SplitPlan *p, const Ref *refs, uint32_t start, uint32_t end)
{
	F4 cmin = f4_set(p->cmin[0], p->cmin[1], p->cmin[2]), scale = f4_set(p->scale[0], p->scale[1], p->scale[2]);
	F4 top = f4_splat((float)(p->nb - 1));
	uint32_t i = start;
	/* Neighbouring refs often share a bin; dealing them out over four
	 * sets of bins (two below 4096 refs, one below 256) lets each update
	 * run while the others wait on their stores: against two sets from
	 * 256 refs on, unique-1m 0.86x and bathroom 0.92x the CPU of the
	 * whole build. The merged boxes may differ from one pass's only in
	 * the sign of a zero, which neither their areas nor the split see.
	 * Each loop finds the bins of the refs after the ones it grows
	 * (ref_bins): the binning 0.8x its cycles on unique-1m, the build
	 * 0.94x (bathroom 0.96x). Since then fewer sets pay below 4096 refs
	 * (clearing and merging them cost more than they save): nodes of
	 * 32-1023 refs bin in 0.9x the cycles they took with four sets from
	 * 256 and two from 64. A node of 4096 refs or more may lie beyond the
	 * caches (the top levels: the refs are 32 MB a million triangles), so
	 * its refs are asked for BINS_AHEAD ahead (as the partition does,
	 * PART_AHEAD): unique-10m's build 0.92x the CPU (least of 3 alternating
	 * runs, 3.23 s against 3.51 s). */
	if (end - start >= 4096) {
		Bins more[3];
		for (int k = 0; k < 3; k++)
			bvh_bins_clear(&more[k], p->nb);
		RefBins q0 = ref_bins(&refs[i], cmin, scale, top), q1 = ref_bins(&refs[i + 1], cmin, scale, top);
		RefBins q2 = ref_bins(&refs[i + 2], cmin, scale, top), q3 = ref_bins(&refs[i + 3], cmin, scale, top);
		for (; i + 7 < end; i += 4) {
			if (i + BINS_AHEAD + 4 <= end) { /* the two lines of four refs */
				__builtin_prefetch(&refs[i + BINS_AHEAD]);
				__builtin_prefetch(&refs[i + BINS_AHEAD + 2]);
			}
			RefBins n0 = ref_bins(&refs[i + 4], cmin, scale, top), n1 = ref_bins(&refs[i + 5], cmin, scale, top);
			RefBins n2 = ref_bins(&refs[i + 6], cmin, scale, top), n3 = ref_bins(&refs[i + 7], cmin, scale, top);
			ref_bins_grow(b, &q0);
			ref_bins_grow(&more[0], &q1);
			ref_bins_grow(&more[1], &q2);
			ref_bins_grow(&more[2], &q3);
			q0 = n0;
			q1 = n1;
			q2 = n2;
			q3 = n3;
		}
		ref_bins_grow(b, &q0);
		ref_bins_grow(&more[0], &q1);
		ref_bins_grow(&more[1], &q2);
		ref_bins_grow(&more[2], &q3);
		i += 4;
		for (int k = 0; k < 3; k++)
			bvh_bins_merge(b, &more[k], p->nb);
	} else if (end - start >= 256) {
		Bins odd;
		bvh_bins_clear(&odd, p->nb);
		RefBins q0 = ref_bins(&refs[i], cmin, scale, top), q1 = ref_bins(&refs[i + 1], cmin, scale, top);
		for (; i + 3 < end; i += 2) {
			RefBins n0 = ref_bins(&refs[i + 2], cmin, scale, top), n1 = ref_bins(&refs[i + 3], cmin, scale, top);
			ref_bins_grow(b, &q0);
			ref_bins_grow(&odd, &q1);
			q0 = n0;
			q1 = n1;
		}
		ref_bins_grow(b, &q0);
		ref_bins_grow(&odd, &q1);
		i += 2;
		bvh_bins_merge(b, &odd, p->nb);
	}
	if (i < end) {
		RefBins q0 = ref_bins(&refs[i], cmin, scale, top);
		for (; i + 1 < end; i++) {
			RefBins n0 = ref_bins(&refs[i + 1], cmin, scale, top);
			ref_bins_grow(b, &q0);
			q0 = n0;
		}
		ref_bins_grow(b, &q0);
	}
}

void bvh_bins_merge(Bins *acc, const Bins *later, int nb)
{
	for (int a = 0; a < 3; a++)
		for (int k = 0; k < nb; k++) {
			uint32_t count = bins_count(acc, a, k) + bins_count(later, a, k);
			acc->box[a][k] = box4_grow(acc->box[a][k], later->box[a][k]);
			acc->box[a][k].hi = f4_set_lane3_bits(acc->box[a][k].hi, count);
		}
}

/* Clamped before the cast: a NaN or huge position is a bad bin, never
 * undefined behaviour (found by fuzz_gltf). */
static int bin_of(float key, float cmin, float scale, int nbins)
{
	float f = (key - cmin) * scale;
	return !(f > 0.0f) ? 0 : (f >= (float)nbins ? nbins - 1 : (int)f);
}

static float ref_key(const Ref *r, int axis) { return r->lo[axis] + r->hi[axis]; }

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

/* box_area of a vector box: the same products and sums in the same order. */
static inline float box4_area(Box4 b) { return f4_half_area(f4_sub(b.hi, b.lo)); }

#if defined(__SSE2__)
/* Half the areas of three boxes' extents d0, d1, d2 in lanes 0-2: each
 * f4_half_area's products and sums in its order, lane by lane; with
 * zero_neg, 0 where an extent is negative, as f4_half_area gives. */
static inline __m128 half_area3(__m128 d0, __m128 d1, __m128 d2, int zero_neg)
{
	__m128 t0 = _mm_unpacklo_ps(d0, d1), t1 = _mm_unpackhi_ps(d0, d1);
	__m128 x = _mm_movelh_ps(t0, d2), y = _mm_shuffle_ps(t0, d2, _MM_SHUFFLE(3, 1, 3, 2));
	__m128 z = _mm_shuffle_ps(t1, d2, _MM_SHUFFLE(3, 2, 1, 0));
	__m128 a = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, y), _mm_mul_ps(y, z)), _mm_mul_ps(z, x));
	if (!zero_neg)
		return a;
	__m128 zero = _mm_setzero_ps();
	__m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(x, zero), _mm_cmplt_ps(y, zero)), _mm_cmplt_ps(z, zero));
	return _mm_andnot_ps(neg, a);
}

/* Bin k's three boxes (count lanes cleared) grown into acc, its three
 * counts (lanes 0-2) returned. */
static inline __m128i grow3(Box4 acc[3], const Bins *bins, int k)
{
	__m128 keep = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
	__m128 h0 = bins->box[0][k].hi, h1 = bins->box[1][k].hi, h2 = bins->box[2][k].hi;
	acc[0].lo = _mm_min_ps(bins->box[0][k].lo, acc[0].lo);
	acc[1].lo = _mm_min_ps(bins->box[1][k].lo, acc[1].lo);
	acc[2].lo = _mm_min_ps(bins->box[2][k].lo, acc[2].lo);
	acc[0].hi = _mm_max_ps(_mm_and_ps(h0, keep), acc[0].hi);
	acc[1].hi = _mm_max_ps(_mm_and_ps(h1, keep), acc[1].hi);
	acc[2].hi = _mm_max_ps(_mm_and_ps(h2, keep), acc[2].hi);
	__m128 c = _mm_shuffle_ps(_mm_unpackhi_ps(h0, h1), h2, _MM_SHUFFLE(3, 3, 3, 2));
	return _mm_castps_si128(c);
}

static inline __m128 area3(const Box4 acc[3], int zero_neg)
{
	return half_area3(_mm_sub_ps(acc[0].hi, acc[0].lo), _mm_sub_ps(acc[1].hi, acc[1].lo),
			  _mm_sub_ps(acc[2].hi, acc[2].lo), zero_neg);
}

/* The cheapest SAH split over the bins (the scalar sah_sweep below, for
 * builds without SSE2, says how), the three axes side by side (lane a:
 * axis a):
 * every lane's areas, counts and costs are the scalar sweep's operations
 * on the same values, each lane keeps its first cheapest bin (strict <),
 * and the axes are then compared in order with strict <, as the scalar
 * scan over axis after axis compares them. Empty bins are swept too:
 * they change nothing, and a split after one is never strictly cheaper. */
static inline __attribute__((always_inline)) int sah_sweep_lanes(const Bins *bins, const SplitPlan *p,
								  int *best_bin, float *best_cost, int zero_neg)
{
	int nb = p->nb;
	__m128 right_area[BVH_BINS];
	__m128i right_count[BVH_BINS];
	Box4 acc[3] = {box4_empty(), box4_empty(), box4_empty()};
	__m128i cnt = _mm_setzero_si128(), zero = _mm_setzero_si128();
	for (int k = nb - 1; k > 0; k--) {
		cnt = _mm_add_epi32(cnt, grow3(acc, bins, k));
		right_area[k] = area3(acc, zero_neg);
		right_count[k] = cnt;
	}
	__m128i axes = _mm_setr_epi32(p->ext[0] > 0.0f ? -1 : 0, p->ext[1] > 0.0f ? -1 : 0,
				      p->ext[2] > 0.0f ? -1 : 0, 0);
	__m128 best = _mm_set1_ps(FLT_MAX);
	__m128i best_k = zero;
	acc[0] = acc[1] = acc[2] = box4_empty();
	cnt = zero;
	for (int k = 0; k < nb - 1; k++) {
		cnt = _mm_add_epi32(cnt, grow3(acc, bins, k));
		__m128 cost = _mm_add_ps(_mm_mul_ps(area3(acc, zero_neg), _mm_cvtepi32_ps(cnt)),
					 _mm_mul_ps(right_area[k + 1], _mm_cvtepi32_ps(right_count[k + 1])));
		__m128i valid = _mm_and_si128(axes, _mm_and_si128(_mm_cmpgt_epi32(cnt, zero),
								   _mm_cmpgt_epi32(right_count[k + 1], zero)));
		__m128 better = _mm_and_ps(_mm_castsi128_ps(valid), _mm_cmplt_ps(cost, best));
		best = _mm_or_ps(_mm_and_ps(better, cost), _mm_andnot_ps(better, best));
		__m128i bi = _mm_castps_si128(better);
		best_k = _mm_or_si128(_mm_and_si128(bi, _mm_set1_epi32(k)), _mm_andnot_si128(bi, best_k));
	}
	float bc[4];
	int bk[4];
	_mm_storeu_ps(bc, best);
	_mm_storeu_si128((__m128i *)bk, best_k);
	int best_axis = -1;
	*best_cost = FLT_MAX;
	*best_bin = 0;
	for (int a = 0; a < 3; a++)
		if (bc[a] < *best_cost) {
			*best_cost = bc[a];
			*best_bin = bk[a];
			best_axis = a;
		}
	return best_axis;
}

/* A box of at least one triangle has lo <= hi in every lane where no
 * corner is NaN (a ref's bounds are its corners' min and max), so among
 * NaN-free triangles only an empty side has a negative extent, and its
 * cost is never taken (its count is 0): the areas need not zero them
 * (some 8% of the sweep). Instances' boxes are the caller's. */
static int sah_sweep(const Bins *bins, const SplitPlan *p, int *best_bin, float *best_cost)
{
	if (p->nan_free && p->inst_from == UINT32_MAX)
		return sah_sweep_lanes(bins, p, best_bin, best_cost, 0);
	return sah_sweep_lanes(bins, p, best_bin, best_cost, 1);
}

/* One comparator of a sorting network, lane by lane: a gets the smaller
 * key, b the larger. */
static inline void sort2(__m128i *a, __m128i *b)
{
	__m128i d = _mm_and_si128(_mm_cmpgt_epi32(*a, *b), _mm_xor_si128(*a, *b));
	*a = _mm_xor_si128(*a, d);
	*b = _mm_xor_si128(*b, d);
}

/* sweep_few below for NaN-free refs, the three axes side by side and
 * without a branch on a ref's bin (sweep_few's, mispredicted, cost some
 * 300 cycles a node of 3-4 refs, a quarter of all nodes): on each axis
 * the refs sorted by bin (then index), a split after the j-th wherever
 * its bin is below the next one's. Those are sweep_few's candidates, in
 * its order (bin by bin, axis after axis, the first cheapest kept), each
 * side the union of the same refs (grown in another order: min and max
 * of the same values, so only the sign of a zero may differ, which no
 * area sees), costed with sah_sweep_lanes' operations, which are
 * sweep_few's. */
static int sweep_few_lanes(const Ref *refs, uint32_t n, const SplitPlan *p, int *best_bin, float *best_cost)
{
	F4 cmin = f4_set(p->cmin[0], p->cmin[1], p->cmin[2]), scale = f4_set(p->scale[0], p->scale[1], p->scale[2]);
	F4 top = f4_splat((float)(p->nb - 1));
	int zero_neg = p->inst_from != UINT32_MAX;
	Box4 r[BVH_FEW];
	__m128i key[BVH_FEW]; /* bin * BVH_FEW + ref, by lane */
	for (uint32_t i = 0; i < BVH_FEW; i++) {
		if (i >= n) {
			key[i] = _mm_set1_epi32(INT32_MAX);
			continue;
		}
		r[i] = box4_of_ref(&refs[i]); /* ref_bins' bins */
		F4 f = f4_mul(f4_sub(f4_add(r[i].lo, r[i].hi), cmin), scale);
		__m128i k = _mm_cvttps_epi32(f4_min(f4_max(f, f4_zero()), top));
		key[i] = _mm_or_si128(_mm_slli_epi32(k, 2), _mm_set1_epi32((int)i));
	}
	_Static_assert(BVH_FEW == 4, "the network sorts four keys");
	sort2(&key[0], &key[1]);
	sort2(&key[2], &key[3]);
	sort2(&key[0], &key[2]);
	sort2(&key[1], &key[3]);
	sort2(&key[1], &key[2]);
	int32_t sk[BVH_FEW][4];
	for (uint32_t j = 0; j < BVH_FEW; j++)
		_mm_storeu_si128((__m128i *)sk[j], key[j]);
	__m128 right_area[BVH_FEW];
	Box4 acc[3] = {box4_empty(), box4_empty(), box4_empty()};
	for (uint32_t j = n - 1; j > 0; j--) {
		for (int a = 0; a < 3; a++)
			acc[a] = box4_grow(acc[a], r[sk[j][a] & (BVH_FEW - 1)]);
		right_area[j] = area3(acc, zero_neg);
	}
	__m128i axes = _mm_setr_epi32(p->ext[0] > 0.0f ? -1 : 0, p->ext[1] > 0.0f ? -1 : 0,
				      p->ext[2] > 0.0f ? -1 : 0, 0);
	__m128 best = _mm_set1_ps(FLT_MAX);
	__m128i best_j = _mm_setzero_si128();
	acc[0] = acc[1] = acc[2] = box4_empty();
	for (uint32_t j = 0; j + 1 < n; j++) {
		for (int a = 0; a < 3; a++)
			acc[a] = box4_grow(acc[a], r[sk[j][a] & (BVH_FEW - 1)]);
		__m128 cost = _mm_add_ps(_mm_mul_ps(area3(acc, zero_neg), _mm_set1_ps((float)(j + 1))),
					 _mm_mul_ps(right_area[j + 1], _mm_set1_ps((float)(n - j - 1))));
		__m128i valid = _mm_and_si128(axes, _mm_cmpgt_epi32(_mm_srai_epi32(key[j + 1], 2),
								    _mm_srai_epi32(key[j], 2)));
		__m128 better = _mm_and_ps(_mm_castsi128_ps(valid), _mm_cmplt_ps(cost, best));
		best = _mm_or_ps(_mm_and_ps(better, cost), _mm_andnot_ps(better, best));
		__m128i bi = _mm_castps_si128(better);
		best_j = _mm_or_si128(_mm_and_si128(bi, _mm_set1_epi32((int)j)), _mm_andnot_si128(bi, best_j));
	}
	float bc[4];
	int bj[4];
	_mm_storeu_ps(bc, best);
	_mm_storeu_si128((__m128i *)bj, best_j);
	int best_axis = -1;
	*best_cost = FLT_MAX;
	*best_bin = 0;
	for (int a = 0; a < 3; a++)
		if (bc[a] < *best_cost) {
			*best_cost = bc[a];
			*best_bin = sk[bj[a]][a] / BVH_FEW;
			best_axis = a;
		}
	return best_axis;
}
#else
/* The cheapest SAH split over the bins: its axis (-1 if none) and the
 * last bin on its left; costs in units of one triangle test times the
 * parent's area, so a zero-area node still compares splits consistently.
 * Only non-empty bins are swept: an empty bin changes neither side, so a
 * split after it costs the bits of the split before it, which the strict
 * < below has already taken (or both have an empty side). */
static int sah_sweep(const Bins *bins, const SplitPlan *p, int *best_bin, float *best_cost)
{
	int best_axis = -1, nb = p->nb, best = 0;
	float best_c = FLT_MAX;
	for (int a = 0; a < 3; a++) {
		if (p->ext[a] <= 0.0f)
			continue;
		Box4 box[BVH_BINS];
		uint32_t count[BVH_BINS];
		int bin[BVH_BINS], m = 0;
		for (int k = 0; k < nb; k++) { /* written always, kept if non-empty: no branch to mispredict */
			uint32_t c = bins_count(bins, a, k);
			box[m].lo = bins->box[a][k].lo;
			box[m].hi = f4_set_lane3_bits(bins->box[a][k].hi, 0); /* no count in the area's arithmetic */
			count[m] = c;
			bin[m] = k;
			m += c != 0;
		}
		float right_area[BVH_BINS];
		uint32_t right_count[BVH_BINS];
		Box4 acc = box4_empty();
		uint32_t cnt = 0;
		for (int i = m - 1; i > 0; i--) {
			acc = box4_grow(acc, box[i]);
			cnt += count[i];
			right_area[i] = box4_area(acc);
			right_count[i] = cnt;
		}
		acc = box4_empty();
		cnt = 0;
		for (int i = 0; i < m - 1; i++) {
			acc = box4_grow(acc, box[i]);
			cnt += count[i];
			float cost = box4_area(acc) * (float)cnt + right_area[i + 1] * (float)right_count[i + 1];
			if (cost < best_c) {
				best_c = cost;
				best_axis = a;
				best = bin[i];
			}
		}
	}
	*best_bin = best;
	*best_cost = best_c;
	return best_axis;
}
#endif

/* sah_sweep for a node of at most BVH_FEW refs, without bins: over half
 * of all nodes, where filling and sweeping bins cost more than the split.
 * Each candidate's sides are grown from the refs themselves: min and max
 * of the same values as the bins' (only the sign of a zero may differ,
 * which no area or comparison sees), counted and costed with the same
 * operations, candidates in the same order (a bin no ref falls in offers
 * none, as in sah_sweep). */
static int sweep_few(const Ref *refs, uint32_t n, const SplitPlan *p, int *best_bin, float *best_cost)
{
	F4 cmin = f4_set(p->cmin[0], p->cmin[1], p->cmin[2]), scale = f4_set(p->scale[0], p->scale[1], p->scale[2]);
	F4 top = f4_splat((float)(p->nb - 1));
	Box4 r[BVH_FEW];
	int k[BVH_FEW][3];
	for (uint32_t i = 0; i < n; i++) { /* ref_bins' bins */
		r[i] = box4_of_ref(&refs[i]);
		F4 f = f4_mul(f4_sub(f4_add(r[i].lo, r[i].hi), cmin), scale);
		f4_trunc3(f4_min(f4_max(f, f4_zero()), top), &k[i][0], &k[i][1], &k[i][2]);
	}
	int best_axis = -1, best = 0;
	float best_c = FLT_MAX;
	for (int a = 0; a < 3; a++) {
		if (p->ext[a] <= 0.0f)
			continue;
		for (int t = 0; t < p->nb - 1; t++) {
			Box4 left = box4_empty(), right = box4_empty();
			uint32_t nl = 0;
			int used = 0;
			for (uint32_t i = 0; i < n; i++) {
				if (k[i][a] <= t) {
					left = box4_grow(left, r[i]);
					nl++;
					used |= k[i][a] == t;
				} else {
					right = box4_grow(right, r[i]);
				}
			}
			if (!used || nl == n)
				continue;
			float cost = box4_area(left) * (float)nl + box4_area(right) * (float)(n - nl);
			if (cost < best_c) {
				best_c = cost;
				best_axis = a;
				best = t;
			}
		}
	}
	*best_bin = best;
	*best_cost = best_c;
	return best_axis;
}

/* Whether a node of at most BVH_MAX_LEAF refs may be a leaf: not if it
 * holds an instance beside anything else. */
static int may_be_leaf(const Ref *refs, uint32_t n, const SplitPlan *p)
{
	if (n > BVH_MAX_LEAF)
		return 0;
	if (p->inst_from != UINT32_MAX)
		for (uint32_t i = 0; i < n; i++)
			if (refs[i].idx >= p->inst_from)
				return 0;
	return 1;
}

/* The SAH partition: refs whose bin on `axis` is at most best_bin first.
 * A ref found on the right is swapped with the last unexamined one, which
 * is examined next: the order every tree was built with. */
static uint32_t partition(Ref *refs, uint32_t n, const SplitPlan *p, int axis, int best_bin)
{
	float cmin = p->cmin[axis], scale = p->scale[axis];
	uint32_t i = 0, j = n;
	while (i < j) {
		if (bin_of(ref_key(&refs[i], axis), cmin, scale, p->nb) <= best_bin) {
			i++;
		} else {
			Ref t = refs[i];
			refs[i] = refs[--j];
			refs[j] = t;
		}
	}
	return i;
}

/* partition, filling the two sides' bounds on the way (one pass less per
 * level). A bin is at most best_bin exactly where (key - cmin) * scale is
 * not >= best_bin + 1 (negative and NaN keys bin to 0). The left side's
 * refs are met in their final order, so its bounds grow as bvh_bounds
 * grows them; the right side's in the reverse of theirs, so a tie goes to
 * the later ref (f4_min_late), which is the earlier in the final order:
 * the same bits, given no NaN (p->nan_free). With `ahead` (a node of 4096
 * refs or more), the refs PART_AHEAD ahead of both ends are asked for. */
#define PART_AHEAD 32u
static inline __attribute__((always_inline)) uint32_t partition_run(Ref *refs, uint32_t n, const SplitPlan *p,
								  int axis, int best_bin, NodeBounds child[2],
								  int ahead)
{
	F4 cmin = f4_set(p->cmin[0], p->cmin[1], p->cmin[2]), scale = f4_set(p->scale[0], p->scale[1], p->scale[2]);
	F4 edge = f4_splat((float)(best_bin + 1));
	Box4 lbox = box4_empty(), lc = box4_empty(), rbox = box4_empty(), rc = box4_empty();
	uint32_t i = 0, j = n;
	while (i < j) {
		if (ahead && j - i > 2 * PART_AHEAD) {
			__builtin_prefetch(&refs[i + PART_AHEAD]);
			__builtin_prefetch(&refs[j - PART_AHEAD]);
		}
		Box4 r = box4_of_ref(&refs[i]);
		F4 key = f4_add(r.lo, r.hi);
		if (!f4_lane_ge(f4_mul(f4_sub(key, cmin), scale), edge, axis)) {
			lbox = box4_grow(lbox, r);
			lc.lo = f4_min(key, lc.lo);
			lc.hi = f4_max(key, lc.hi);
			i++;
		} else {
			rbox.lo = f4_min_late(rbox.lo, r.lo);
			rbox.hi = f4_max_late(rbox.hi, r.hi);
			rc.lo = f4_min_late(rc.lo, key);
			rc.hi = f4_max_late(rc.hi, key);
			Ref t = refs[i];
			refs[i] = refs[--j];
			refs[j] = t;
		}
	}
	child[0] = (NodeBounds){lbox, lc};
	child[1] = (NodeBounds){rbox, rc};
	return i;
}

static uint32_t partition_bounds(Ref *refs, uint32_t n, const SplitPlan *p, int axis, int best_bin,
				 NodeBounds child[2])
{
	if (n >= 4096)
		return partition_run(refs, n, p, axis, best_bin, child, 1);
	return partition_run(refs, n, p, axis, best_bin, child, 0);
}

/* A node of two refs, decided without a plan, bins or sweep: nodes of two
 * are the commonest (bathroom 190,000 of 542,000, unique-1m 395,000 of
 * 1,000,000), nearly all leaves. Taken where the general path's outcome is
 * plain: no NaN, finite keys, not past BVH_MEDIAN_DEPTH, no instance. With
 * two refs each axis of positive centroid extent bins the smaller key to 0
 * and the larger to 1 (its f is ext * (2 / ext), about 2), so sweep_few's
 * first candidate is the first such axis (every one costs the two areas'
 * sum, added in either order to the same bits), and the leaf test and the
 * partition follow as bvh_split_apply takes them. Returns 0 where the
 * general path must decide, else 1 with *nleft (0: a leaf) and, for a
 * split, the children's bounds as partition_bounds grows them. */
int bvh_split_two(Ref *refs, const Box *box, const Box4 *cbox, uint32_t depth, uint32_t inst_from, int nan_free,
		  uint32_t *nleft, NodeBounds child[2])
{
	if (!nan_free || depth >= BVH_MEDIAN_DEPTH || (inst_from != UINT32_MAX && (refs[0].idx >= inst_from ||
										 refs[1].idx >= inst_from)))
		return 0;
	float lo[4], hi[4], ext[3];
	f4_store(lo, cbox->lo);
	f4_store(hi, cbox->hi);
	int first = -1;
	for (int a = 0; a < 3; a++) {
		if (!(lo[a] >= -FLT_MAX && hi[a] <= FLT_MAX))
			return 0;
		ext[a] = hi[a] - lo[a];
		if (first < 0 && ext[a] > 0.0f)
			first = a;
	}
	*nleft = 0;
	if (first < 0) /* all centroids equal: a leaf */
		return 1;
	Box4 r0 = box4_of_ref(&refs[0]), r1 = box4_of_ref(&refs[1]);
	float cost = box4_area(r0) + box4_area(r1);
	if (!(cost < FLT_MAX)) /* no SAH split: the median's leaf */
		return 1;
	float area = box_area(box);
	if ((float)2 * area <= BVH_COST_TRAVERSE * area + cost)
		return 1;
	/* partition_bounds: which ref bins left, then each side grown from empty */
	F4 cmin = f4_set(lo[0], lo[1], lo[2]), edge = f4_splat(1.0f);
	F4 scale = f4_set(first == 0 ? 2.0f / ext[0] : 0.0f, first == 1 ? 2.0f / ext[1] : 0.0f,
			  first == 2 ? 2.0f / ext[2] : 0.0f);
	F4 k0 = f4_add(r0.lo, r0.hi);
	if (f4_lane_ge(f4_mul(f4_sub(k0, cmin), scale), edge, first)) {
		Ref t = refs[0];
		refs[0] = refs[1];
		refs[1] = t;
		Box4 tb = r0;
		r0 = r1;
		r1 = tb;
	}
	Box4 e = box4_empty();
	F4 kl = f4_add(r0.lo, r0.hi), kr = f4_add(r1.lo, r1.hi);
	child[0] = (NodeBounds){box4_grow(e, r0), {f4_min(kl, e.lo), f4_max(kl, e.hi)}};
	child[1] = (NodeBounds){{f4_min_late(e.lo, r1.lo), f4_max_late(e.hi, r1.hi)},
				{f4_min_late(e.lo, kr), f4_max_late(e.hi, kr)}};
	*nleft = 1;
	return 1;
}

/* Both sides' bounds after a split that did not fill them. */
static void sides_bounds(const Ref *refs, uint32_t n, uint32_t nleft, NodeBounds child[2])
{
	child[0] = child[1] = (NodeBounds){box4_empty(), box4_empty()};
	bvh_bounds(refs, 0, nleft, &child[0]);
	bvh_bounds(refs, nleft, n, &child[1]);
}

uint32_t bvh_split_apply(Ref *refs, uint32_t n, const Box *box, const SplitPlan *p, const Bins *bins,
			 NodeBounds child[2])
{
	if (n <= 1)
		return 0;
	int leaf_ok = may_be_leaf(refs, n, p);
	if (p->ext[p->axis] <= 0.0f) { /* all centroids equal: any halving will do */
		if (leaf_ok)
			return 0;
		sides_bounds(refs, n, n / 2, child);
		return n / 2;
	}
	if (p->nb) {
		int best_bin;
		float best_cost;
		int best_axis;
		if (n > BVH_FEW)
			best_axis = sah_sweep(bins, p, &best_bin, &best_cost);
#if defined(__SSE2__)
		else if (p->nan_free)
			best_axis = sweep_few_lanes(refs, n, p, &best_bin, &best_cost);
#endif
		else
			best_axis = sweep_few(refs, n, p, &best_bin, &best_cost);
		if (best_axis >= 0) {
			float area = box_area(box);
			if (leaf_ok && (float)n * area <= BVH_COST_TRAVERSE * area + best_cost)
				return 0;
			/* Both sides non-empty by construction of the bins. */
			if (p->nan_free)
				return partition_bounds(refs, n, p, best_axis, best_bin, child);
			uint32_t nleft = partition(refs, n, p, best_axis, best_bin);
			sides_bounds(refs, n, nleft, child);
			return nleft;
		}
		/* Every centroid fell into one bin (float rounding on a tiny
		 * extent): fall through to the median. */
	}
	if (leaf_ok)
		return 0;
	select_nth(refs, n, n / 2, p->axis);
	sides_bounds(refs, n, n / 2, child);
	return n / 2;
}
