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
 *     p_{s+1} / p_s = pf_s / pr_s,
 * except that for s = 1 x_0 is a next-event sample from x_1, whose density
 * pn_0 differs from the light subpath's pf_0 where next-event estimation
 * aims through portals (env_portal.h).
 * Weights are computed from these ratios, never from raw products, which
 * overflow float. A density that involves a delta lobe is stored as 0 and
 * counts as 1 in the ratios: the same delta appears in every strategy that
 * can sample the path, and strategies that would connect at a delta vertex
 * are left out of the sum. */
#ifndef AJAR_MIS_H
#define AJAR_MIS_H
#include "base/fastmath.h"
#include "base/types.h"

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
	float pn;     /* x_0 only: its density as a next-event sample from x_1 */
	int delta;    /* scattered by a delta lobe: never a connection end; on x_0, a
		       * punctual light: s = 0 is impossible, s = 1 (next-event estimation)
		       * is not, but for a path to the camera alone (the light unseen) */
	int infinite; /* the environment: cannot connect to the camera */
} MisVertex;

INLINE float mis_remap0(float p) { return p > 0.0f ? p : 1.0f; }

INLINE float mis_term(float r, int heuristic) { return heuristic == MIS_BALANCE ? r : r * r; }

/* Which bdpt strategies are in use: all (conn = 0), or light tracing
 * (t = 1, s = k - 1) with every light vertex and the other strategies with
 * at most conn light vertices that scatter by non-delta lobes, x_0 counted:
 * the portal integrator's set where light subpaths bring the light in
 * (src/prepare/policy.c, kernels/integrator/README.md, "Connections to the
 * first two light vertices"). A pane's or mirror's reflection on the light
 * side takes no place in the count: the sun mirrored by a pane onto the
 * wall beside it is joined to the eye vertices as the sun itself is. With
 * `first` the first vertex after x_0 that scatters by a non-delta lobe
 * (mis_first_scatter; the camera counts), that is s <= conn + first - 1:
 * mis_conn_limit. conn is 0, 1 or 2, which the tails below need. */
INLINE int mis_conn_limit(int conn, int first) { return conn == 0 ? 0 : conn + first - 1; }
INLINE int mis_conn_in_set(int limit, int k, int s) { return limit == 0 || s <= limit || s == k - 1; }

/* The first vertex x_j, j >= 1, of a path's records that scatters by a
 * non-delta lobe, or the camera x_{k-1}. */
INLINE int mis_first_scatter(const MisVertex *v, int k)
{
	int j = 1;
	while (j < k - 1 && v[j].delta)
		j++;
	return j;
}

/* The sum behind mis_path_weight and mis_path_weight_tails: the eye
 * side's terms for x_s .. x_{eye_hi - 1} moving to the light side, then
 * `etail` times the last ratio if eye_hi < k - 1 (the terms beyond); the
 * light side's for x_{s-1} down to x_{light_lo}, then `ltail` likewise if
 * light_lo > 0; over the strategies of the path's `limit` (mis_conn_limit,
 * mis_conn_in_set). x_0's
 * records are read only where the walk reaches x_1. */
INLINE float mis_path_sum(const MisVertex *v, int k, int s, int heuristic, int limit, int eye_hi, int light_lo,
			  float ltail, float etail)
{
	/* x_0's density is pn for s' = 1 and pf for s' >= 2. */
	float pn_pf = light_lo <= 1 ? mis_remap0(v[0].pn) / mis_remap0(v[0].pf) : 1.0f;
	float sum = 1.0f, r = 1.0f;
	for (int i = s; i < eye_hi; i++) { /* s' = i + 1: x_i moves to the light side */
		if (i == 0)
			r *= mis_remap0(v[0].pn) / mis_remap0(v[0].pr);
		else
			r *= mis_remap0(v[i].pf) / mis_remap0(v[i].pr) / (i == 1 ? pn_pf : 1.0f);
		if ((i == 0 || !v[i].delta) && !v[i + 1].delta &&
		    !((v[i].infinite || v[i].delta) && i + 1 == k - 1) && mis_conn_in_set(limit, k, i + 1))
			sum += mis_term(r, heuristic);
	}
	if (eye_hi < k - 1)
		sum += mis_term(r, heuristic) * etail;
	r = 1.0f;
	for (int i = s - 1; i >= light_lo; i--) { /* s' = i: x_i moves to the eye side */
		if (i == 0)
			r *= mis_remap0(v[0].pr) / mis_remap0(v[0].pn);
		else
			r *= mis_remap0(v[i].pr) / mis_remap0(v[i].pf) * (i == 1 ? pn_pf : 1.0f);
		if (!v[i].delta && (i <= 1 || !v[i - 1].delta) && mis_conn_in_set(limit, k, i))
			sum += mis_term(r, heuristic);
	}
	if (light_lo > 0)
		sum += mis_term(r, heuristic) * ltail;
	return sum;
}

/* Weight of strategy s (light vertices x_0..x_{s-1}) for the k-vertex path
 * v[0..k-1] among all strategies s' in [0, k-1] that can produce it (t' = 0
 * is impossible with a pinhole camera). The connection of s' joins
 * x_{s'-1} and x_{s'}; s' = 0 means the eye subpath hit the light. */
CALLED float mis_path_weight(const MisVertex *v, int k, int s, int heuristic)
{
	return 1.0f / mis_path_sum(v, k, s, heuristic, 0, k - 1, 0, 0.0f, 0.0f);
}

/* The same over the strategies of the path's `limit` (mis_conn_limit,
 * mis_conn_in_set; s among them). */
INLINE float mis_path_weight_conn(const MisVertex *v, int k, int s, int heuristic, int limit)
{
	return 1.0f / mis_path_sum(v, k, s, heuristic, limit, k - 1, 0, 0.0f, 0.0f);
}

/* ---- The same weight from the connection's neighbourhood and two tails ----
 *
 * Of mis_path_weight's ratios, only those of the two records on each side
 * of the connection change with it; beyond them the records are the
 * subpaths' own (bdpt.h recomputes pf of x_s, x_{s+1} and pr of x_{s-1},
 * x_{s-2}). So each subpath vertex can carry the sum of its side's terms
 * beyond a connection two vertices away, and one weight reads x_{s-3} ..
 * x_{s+2} and two tails instead of walking the whole path. The sums agree
 * with mis_path_weight's up to float rounding (test_bdpt,
 * test_pn_cache_same_bits). */

/* The light tail at x_m of a light subpath, for every strategy s >= m + 3:
 * A_m = sum over i <= m of the terms of s' = i (valid as mis_path_weight
 * tells) of prod_{j=i..m} q_j^beta, q_j = pr_j / pf_j (pr_0 / pn_0 and
 * the pn_0 / pf_0 of q_1 as there). Recurrence A_m = q_m^beta ([valid_m]
 * + A_{m-1}), A_{-1} = 0; v[0..n-1] are the light subpath's records (x_0's
 * delta: a punctual light). With conn (1 or 2) only the terms of s' = i in
 * the set count (mis_conn_in_set): i <= conn, or x_1 .. x_{i - conn} all
 * delta, which lie on the light subpath before the strategy's own
 * connection (s >= m + 3). */
INLINE void mis_light_tails(const MisVertex *v, int n, int heuristic, int conn, float *A)
{
	float pn_pf = mis_remap0(v[0].pn) / mis_remap0(v[0].pf), a = 0.0f;
	int first = n; /* the first of v[1..] that scatters by a non-delta lobe */
	for (int j = n - 1; j >= 1; j--)
		if (!v[j].delta)
			first = j;
	for (int m = 0; m < n; m++) {
		float q = m == 0 ? mis_remap0(v[0].pr) / mis_remap0(v[0].pn)
				 : mis_remap0(v[m].pr) / mis_remap0(v[m].pf) * (m == 1 ? pn_pf : 1.0f);
		int valid = !v[m].delta && (m <= 1 || !v[m - 1].delta) && (conn == 0 || m <= conn + first - 1);
		a = mis_term(q, heuristic) * ((valid ? 1.0f : 0.0f) + a);
		A[m] = a;
	}
}

/* The eye tail at eye vertex a >= 1 (e[0] the camera), for every strategy
 * with t >= a + 3, from the one at a - 1 (`prev`; 0 at a = 1): B_a =
 * u_a^beta ([valid_a] + B_{a-1}), u_a = pf / pr of e[a]; valid_a: neither
 * e[a] nor e[a-1] scattered by a delta lobe, and e[1] joins the camera
 * only from a surface. v[a] holds e[a]'s record. With conn (1 or 2) only
 * light tracing (a = 1) counts: the strategy of a >= 2 eye vertices that
 * a strategy (s >= 1) with t >= a + 3 reads here has s' >= s + 3 light
 * vertices, among them x_1 (or x_s, the connection's non-delta eye end)
 * and x_{s'-1}: more than conn that scatter by non-delta lobes. (s = 0
 * with a delta vertex at x_1 takes the whole path: bdpt_path_weight.) */
INLINE float mis_eye_tail(const MisVertex *v, int a, int heuristic, int conn, float prev)
{
	float u = mis_remap0(v[a].pf) / mis_remap0(v[a].pr);
	int valid = !v[a].delta && !v[a - 1].delta && !(a == 1 && v[a].infinite) && (conn == 0 || a == 1);
	return mis_term(u, heuristic) * ((valid ? 1.0f : 0.0f) + prev);
}

/* mis_path_weight_conn with v[] filled at x_{s-3} .. x_{s+2} (those that
 * exist; x_0 too when s <= 3) and the tails beyond, made with the same
 * conn (the path's limit here): `etail` the eye tail B_{t-3} (read when t
 * >= 4), `ltail` the light tail A_{s-3} (read when s >= 3). */
INLINE float mis_path_weight_tails(const MisVertex *v, int k, int s, int heuristic, int limit, float ltail,
				   float etail)
{
	return 1.0f / mis_path_sum(v, k, s, heuristic, limit, min(k - 1, s + 2), max(0, s - 2), ltail, etail);
}

/* ---- BDPT and intermediate-subpath strategies together (design.md) ----
 *
 * A portal strategy (s, m, t') samples the path with x_0..x_{s-1} from a
 * light subpath, x_s..x_m from the <- half of an intermediate subpath
 * (walking toward the light, densities pr), the pair x_m, x_{m+1} from the
 * portal point and direction, x_{m+2}..x_{m+t'} from the -> half (pf), and
 * the rest from the eye subpath:
 *   p = prod_{i<s} pf_i prod_{s<=i<m} pr_i p_pair(m) prod_{m+1<i<=m+t'} pf_i prod_{i>m+t'} pr_i
 * with p_pair(m) = p_A(w_0) / (2 pi) G(x_m, x_{m+1}). Every crossing of
 * edge m with a portal triangle is a separate strategy of the same
 * density, so the strategies of edge m count cross[m] times. Densities are
 * multiplied in log space, from prefix sums of their logs. */

typedef struct {
	int c;  /* 1: bdpt (s, t = k - s); 2: portal (s, m, t') */
	int s;
	int m;
	int tp;
} MisStrategy;

/* Which intermediate strategies are in use: at most s_max light vertices,
 * sp_max <- vertices (s' = m - s + 1), tp_max -> vertices and t_max eye
 * vertices. The weights sum over exactly these, so any choice is unbiased.
 * A pixel sample traces its intermediate subpath with probability `rate`:
 * those strategies take rate samples per pixel sample, so their densities
 * enter the heuristic as rate p (multi-sample MIS with sample counts) and
 * their contributions are divided by rate. */
typedef struct {
	int s_max, sp_max, tp_max;
	int t_max;       /* eye vertices, camera included */
	int light_paths; /* 0: bdpt strategies only with s <= 1 and t >= 2 (no light subpaths) */
	float lrate;     /* log of the rate */
} MisPortalSet;

INLINE int mis_bdpt_valid(const MisVertex *v, int k, int s)
{
	if (s == 0)
		return !v[0].delta;
	if (s >= k || (s >= 2 && v[s - 1].delta) || v[s].delta)
		return 0;
	return !((v[s - 1].infinite || v[s - 1].delta) && s == k - 1);
}

/* Logs of the remapped densities of x_0 .. x_{n-1}: lf stays 0 unless
 * `need_pf` (mis_needs_pf). */
INLINE void mis_logs(const MisVertex *v, int n, int need_pf, float *lf, float *lr)
{
	for (int i = 0; i < n; i++) {
		lf[i] = need_pf ? fast_log(mis_remap0(v[i].pf)) : 0.0f;
		lr[i] = fast_log(mis_remap0(v[i].pr));
	}
}

/* Their prefix sums: PF[j] = sum of log pf_i for i < j, PR likewise;
 * arrays of n + 1. */
INLINE void mis_prefix(const float *lf, const float *lr, int n, float *PF, float *PR)
{
	PF[0] = PR[0] = 0.0f;
	for (int i = 0; i < n; i++) {
		PF[i + 1] = PF[i] + lf[i];
		PR[i + 1] = PR[i] + lr[i];
	}
}

/* Whether any strategy in use has eye-side vertices sampled from the
 * light side: light subpaths, or -> halves of more than one vertex. Else
 * only pn of x_0 and the pr enter the weights. */
INLINE int mis_needs_pf(MisPortalSet set) { return set.light_paths || set.tp_max >= 2; }

/* How many of the path's first vertices the weights read. All of them with
 * light subpaths; without, bdpt strategies have s <= 1 and intermediate
 * ones reach x_{s_max + sp_max + tp_max} at most, and every pr beyond is
 * one factor common to all strategies, which cancels. */
INLINE int mis_horizon(MisPortalSet set, int k)
{
	if (set.light_paths || set.s_max >= k || set.sp_max >= k || set.tp_max >= k)
		return k;
	return min(k, set.s_max + set.sp_max + set.tp_max + 1);
}

/* log of the light side's density of strategies with s light vertices:
 * x_0 is a next-event sample (pn) when s = 1. */
INLINE float mis_lpf(const float *PF, float lpn, int s) { return s == 1 ? lpn : PF[s]; }

/* log of the density of bdpt strategy s; PR[n] is the eye side's whole. */
INLINE float mis_log_bdpt(const float *PF, float lpn, const float *PR, int n, int s)
{
	return mis_lpf(PF, lpn, s) + PR[n] - PR[s];
}

/* log(exp(a) + exp(b)) without overflow; -INF is the empty sum. */
INLINE float mis_logadd(float a, float b)
{
	float hi = fmax(a, b), lo = fmin(a, b);
	if (lo == -AJAR_INF) /* the empty sum */
		return hi;
	return hi + fast_log(1.0f + fast_exp(lo - hi));
}

/* log of the sum of exp(x[i]), i < n; -INF for none. */
INLINE float mis_logsumexp(const float *x, int n)
{
	float hi = -AJAR_INF, sum = 0.0f;
	for (int i = 0; i < n; i++)
		hi = fmax(hi, x[i]);
	if (n == 0 || hi == -AJAR_INF)
		return -AJAR_INF;
	for (int i = 0; i < n; i++)
		sum += fast_exp(x[i] - hi);
	return hi + fast_log(sum);
}

INLINE float mis_beta(int heuristic) { return heuristic == MIS_BALANCE ? 1.0f : 2.0f; }

/* The edges [*lo, *hi) that intermediate strategies in use can pair on:
 * m < s_max + sp_max (s <= s_max light vertices, s' = m - s + 1 <= sp_max),
 * t = k - m - t' - 1 <= t_max for some t' <= tp_max, and within the
 * records' horizon n. */
INLINE void mis_pair_edges(MisPortalSet set, int k, int n, int *lo, int *hi)
{
	*lo = max(0, k - 1 - set.tp_max - set.t_max);
	*hi = min(k - 1, min(n, set.s_max + set.sp_max));
}

/* Weight of strategy `cur` for the k-vertex path v among all BDPT and
 * portal strategies in use, from the prefix sums PF, PR of the logs of its
 * first n = mis_horizon(set, k) records (mis_prefix) and lpn, the log of
 * x_0's remapped pn; v gives the delta and infinite flags. cross[i] > 0
 * marks an edge (x_i, x_{i+1}) that crosses portals; lpsum[i] = log sum
 * over its crossings c of p_pair_c^beta (each crossing is a strategy of its
 * own, with its own direction density); lpair_cur is log p_pair of cur's
 * own crossing. Both are read for the edges of mis_pair_edges only. */
INLINE float mis_union_sum(const MisVertex *v, int k, int n, const float *PF, const float *PR, float lpn,
			   const int *cross, const float *lpsum, float lpair_cur, MisStrategy cur, MisPortalSet set,
			   int heuristic)
{
	float beta = mis_beta(heuristic);
	/* PR[n] stands in for PR[k]: the pr of x_n .. x_{k-1} are a factor of
	 * every strategy's density. */
	float lcur = cur.c == 1 ? mis_log_bdpt(PF, lpn, PR, n, cur.s)
				: mis_lpf(PF, lpn, cur.s) + (PR[cur.m] - PR[cur.s]) + lpair_cur +
					  (PF[cur.m + cur.tp + 1] - PF[cur.m + 2]) + (PR[n] - PR[cur.m + cur.tp + 1]) +
					  set.lrate;
	/* Sum of (p_j / p_cur)^beta, each ratio from its log: one that
	 * overflows makes the sum FLT_MAX or inf, and the weight 0, its limit. */
	float total = 0.0f;
	for (int s = 0; s < (set.light_paths ? k : min(2, k - 1)); s++)
		if (mis_bdpt_valid(v, k, s))
			total += fast_exp(beta * (mis_log_bdpt(PF, lpn, PR, n, s) - lcur));
	/* Intermediate strategies of edge m: s <= s_max light vertices and
	 * s' = m - s + 1 <= sp_max of the <- half, so m < s_max + sp_max. */
	int m_lo, m_hi;
	mis_pair_edges(set, k, n, &m_lo, &m_hi);
	for (int m = m_lo; m < m_hi && m + 2 < k; m++) {
		if (cross[m] <= 0)
			continue;
		float base = lpsum[m] + beta * (set.lrate - lcur);
		/* s in [0, m] with a valid light connection ... */
		for (int s = max(0, m + 1 - set.sp_max); s <= m && s <= set.s_max; s++) {
			/* x_0's delta flag: a punctual light, for s = 1 only (mis.h, MisVertex) */
			if ((s == 0 && v[0].delta) || (s >= 2 && v[s - 1].delta) || (s > 0 && v[s].delta))
				continue;
			float left = base + beta * (mis_lpf(PF, lpn, s) + PR[m] - PR[s]);
			/* ... and t' >= 1 with m + t' <= k - 2 and a valid eye connection. */
			for (int tp = 1; m + tp <= k - 2 && tp <= set.tp_max; tp++)
				if (!v[m + tp].delta && !v[m + tp + 1].delta && k - m - tp - 1 <= set.t_max)
					total += fast_exp(left + beta * ((PF[m + tp + 1] - PF[m + 2]) +
									 (PR[n] - PR[m + tp + 1])));
		}
	}
	return 1.0f / total;
}

/* The same weight from the records v[0..n-1] themselves. */
CALLED float mis_union_weight(const MisVertex *v, int k, int n, const int *cross, const float *lpsum, float lpair_cur,
			      MisStrategy cur, MisPortalSet set, int heuristic)
{
	float lf[4 * 33], lr[4 * 33], PF[4 * 33 + 1], PR[4 * 33 + 1];
	mis_logs(v, n, mis_needs_pf(set), lf, lr);
	mis_prefix(lf, lr, n, PF, PR);
	return mis_union_sum(v, k, n, PF, PR, fast_log(mis_remap0(v[0].pn)), cross, lpsum, lpair_cur, cur, set,
			     heuristic);
}
#endif
