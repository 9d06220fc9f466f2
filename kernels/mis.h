/* mis.h — multiple importance sampling (Veach 1997, ch. 9 and 10).
 *
 * Two-strategy heuristics for the path tracer, and the weight of one
 * bidirectional strategy over a whole path (design.md, "Path sampling and
 * MIS"). A path x_0 .. x_{k-1} runs from the light (x_0) to the camera
 * (x_{k-1}); each vertex keeps pf, its density when sampled from the light
 * side, and pr, its density when sampled from the eye side, in area measure
 * (solid angle for a vertex at infinity). Strategy s takes x_0..x_{s-1} from
 * the light subpath and x_s..x_{k-1} from the eye subpath, so
 *     p_s = prod_{i<s} pf_i * prod_{i>=s} pr_i,
 *     p_{s+1} / p_s = pf_s / pr_s.
 * Weights are computed from these ratios, never from raw products, which
 * overflow float. A density that involves a delta lobe is stored as 0 and
 * counts as 1 in the ratios: the same delta appears in every strategy that
 * can sample the path, and strategies that would connect at a delta vertex
 * are left out of the sum. */
#ifndef AJAR_MIS_H
#define AJAR_MIS_H
#include "compat.h"

#define MIS_BALANCE 1
#define MIS_POWER 0

/* Power heuristic (beta = 2) weight of a strategy with density a against
 * one with density b, both in the same measure. */
INLINE float mis_power(float a, float b)
{
	if (!(a > 0.0f))
		return 0.0f;
	float r = b / a; /* a ratio: squares of raw densities overflow */
	return 1.0f / (1.0f + r * r);
}

INLINE float mis_balance(float a, float b)
{
	if (!(a > 0.0f))
		return 0.0f;
	return 1.0f / (1.0f + b / a);
}

typedef struct {
	float pf, pr;
	int delta;    /* scattered by a delta lobe: never a connection end */
	int infinite; /* the environment: cannot connect to the camera */
} MisVertex;

INLINE float mis_remap0(float p) { return p > 0.0f ? p : 1.0f; }

INLINE float mis_term(float r, int heuristic) { return heuristic == MIS_BALANCE ? r : r * r; }

/* Weight of strategy s (light vertices x_0..x_{s-1}) for the k-vertex path
 * v[0..k-1] among all strategies s' in [0, k-1] that can produce it (t' = 0
 * is impossible with a pinhole camera). The connection of s' joins
 * x_{s'-1} and x_{s'}; s' = 0 means the eye subpath hit the light. */
INLINE float mis_path_weight(const MisVertex *v, int k, int s, int heuristic)
{
	float sum = 1.0f, r = 1.0f;
	for (int i = s; i < k - 1; i++) { /* s' = i + 1: x_i moves to the light side */
		r *= mis_remap0(v[i].pf) / mis_remap0(v[i].pr);
		if (!v[i].delta && !v[i + 1].delta && !(v[i].infinite && i + 1 == k - 1))
			sum += mis_term(r, heuristic);
	}
	r = 1.0f;
	for (int i = s - 1; i >= 0; i--) { /* s' = i: x_i moves to the eye side */
		r *= mis_remap0(v[i].pr) / mis_remap0(v[i].pf);
		if (!v[i].delta && (i == 0 || !v[i - 1].delta))
			sum += mis_term(r, heuristic);
	}
	return 1.0f / sum;
}
#endif
