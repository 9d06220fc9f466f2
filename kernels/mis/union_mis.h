/* union_mis.h — the MIS weight of a whole path over the union of bdpt and
 * portal strategies (mis_union_weight), for paths assembled from the
 * subpaths that sampled them: l[0..s-1] (light), R[sp..1] (the <- half of
 * an intermediate subpath), F[1..tp] (its -> half), e[t-1..0] (eye).
 *
 * The records come from the densities the walks stored; the ones that a
 * walk could not know (next to each connection, next to the portal pair,
 * and the light's own when an eye-side walk found it) are recomputed from
 * the path, as are the portal crossings of the connection edges. */
#ifndef AJAR_PATH_MIS_H
#define AJAR_PATH_MIS_H
#include "geom/camera.h"
#include "mis/vertex_density.h"
#include "mis/mis.h"
#include "light/lights.h"
#include "geom/portal_crossing.h"

/* A path assembled from up to four subpath segments, light first:
 * l[0..s-1], R[sp..1], F[1..tp], e[t-1..0]; sp = tp = 0 for bdpt paths. */
typedef struct {
	VCRef x[4 * SUBPATH_MAX];
	int k, s, sp, tp, t;
	int c1;   /* connection edge light side (x_{c1}, x_{c1+1}), or -1 */
	int c2;   /* connection edge on the eye side, or -1 */
	int pair; /* the portal pair's edge m, or -1 */
} PathRef;

INLINE void path_ref(PathRef *P, VCRef l, int s, VCRef R, int sp, VCRef F, int tp, VCRef e, int t)
{
	int k = 0;
	for (int i = 0; i < s; i++)
		P->x[k++] = VAT(l, i);
	for (int j = sp; j >= 1; j--)
		P->x[k++] = VAT(R, j);
	for (int j = 1; j <= tp; j++)
		P->x[k++] = VAT(F, j);
	for (int j = t - 1; j >= 0; j--)
		P->x[k++] = VAT(e, j);
	P->k = k;
	P->s = s;
	P->sp = sp;
	P->tp = tp;
	P->t = t;
	if (sp == 0) { /* bdpt: one connection, unless the eye found the light */
		P->pair = -1;
		P->c1 = s > 0 ? s - 1 : -1;
		P->c2 = -1;
	} else {
		P->pair = s + sp - 1;
		P->c1 = s > 0 ? s - 1 : -1;
		P->c2 = P->pair + tp;
	}
}

/* The standard densities of x_i from the path alone (design.md): pf from
 * x_{i-1} given x_{i-2}, pr from x_{i+1} given x_{i+2}; 0 after a delta
 * scattering (mis.h's convention). */
INLINE float path_pf(const SceneView *sc, const PathRef *P, const MisVertex *mv, int i)
{
	const VCRef *x = P->x;
	VTMP(t0);
	VTMP(t1);
	VTMP(t2);
	if (i == 0)
		return bdpt_origin_pdf(sc, VLOAD(x[0], t0));
	if (i == 1)
		return bdpt_emission_pdf(sc, VLOAD(x[0], t0), VLOAD(x[1], t1));
	if (i == P->k - 1 || mv[i - 1].delta)
		return 0.0f;
	return bdpt_pdf_a(sc, VLOAD(x[i - 1], t0), VLOAD(x[i - 2], t1), VLOAD(x[i], t2), BSDF_IMPORTANCE);
}

INLINE float path_pr(const SceneView *sc, const PathRef *P, const MisVertex *mv, int i)
{
	const VCRef *x = P->x;
	int k = P->k;
	VTMP(t0);
	VTMP(t1);
	VTMP(t2);
	if (i == k - 1)
		return 1.0f;
	if (i == k - 2) {
		GLOBAL const Camera *cam = &sc->params->camera;
		const PathVertex *xi = VLOAD(x[i], t0);
		V3 d = vertex_infinite(xi) ? v3_neg(xi->p) : v3_norm(v3_sub(xi->p, cam->pos));
		return vertex_density_a(VLOAD(x[k - 1], t1), xi, camera_pdf_w(cam, v3_dot(d, cam->forward)));
	}
	if (mv[i + 1].delta)
		return 0.0f;
	return bdpt_pdf_a(sc, VLOAD(x[i + 1], t0), VLOAD(x[i + 2], t1), VLOAD(x[i], t2), BSDF_RADIANCE);
}

/* The portal direction density, per projected solid angle about the
 * normal of portal triangle pt, of the intermediate subpath whose <- half
 * leaves portal point w toward x_m (kernels/integrator/portal.h): a mixture of
 *   - PORTAL_COSINE: a side, +n with probability pt->side_plus, and a
 *     cosine direction on it (side / pi per projected solid angle);
 *   - the rest: a light sample from w, which only counts when the <- half
 *     reaches the sampled light point: x_m on an emitter's front face, or
 *     the environment by its importance folded onto the portal's sky side
 *     (a direction and its mirror image in the portal's plane both lead
 *     there). */
#ifndef PORTAL_COSINE /* -D overrides it for experiments, as PORTAL_NEE_MIX */
#define PORTAL_COSINE 0.5f
#endif

INLINE V3 portal_mirror(V3 d, V3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

INLINE float portal_direction_psa(const SceneView *sc, GLOBAL const PortalTri *pt, const PathVertex *xm, V3 w)
{
	float ce, ps = guided_env_share(sc, &ce);
	V3 to_m; /* from w toward x_m */
	float guided = 0.0f; /* never toward a punctual light (portal.h) */
	if (vertex_infinite(xm)) {
		to_m = xm->p;
		if (xm->type == VERTEX_ENV) {
			float pe = env_pdf_w(sc, to_m);
			if (pt->env_side != 0)
				pe = (float)pt->env_side * v3_dot(to_m, pt->n) > 0.0f
					     ? pe + env_pdf_w(sc, portal_mirror(to_m, pt->n))
					     : 0.0f;
			guided = ps * pe;
		}
	} else {
		V3 d = v3_sub(xm->p, w);
		float dist = v3_len(d);
		if (!(dist > 0.0f))
			return 0.0f;
		to_m = v3_scale(d, 1.0f / dist);
		if (xm->type != VERTEX_PUNCTUAL && xm->tri >= 0 && sc->tris[xm->tri].emitter >= 0) {
			float cos_l = -v3_dot(xm->ng, to_m); /* ng is the front face */
			guided = cos_l > 0.0f && ce > 0.0f
					 ? (1.0f - ps) * emitter_pdf_a(sc, xm->tri, xm->p) / ce * dist * dist / cos_l
					 : 0.0f;
		}
	}
	float cn = v3_dot(to_m, pt->n), c = fabs(cn);
	float side = cn > 0.0f ? pt->side_plus : 1.0f - pt->side_plus;
	return PORTAL_COSINE * side * AJAR_INV_PI + (c > 0.0f ? (1.0f - PORTAL_COSINE) * guided / c : 0.0f);
}

/* log p_pair = log(p_A q(w | portal point) G(x_m, x_{m+1})), geometric
 * normals, for the crossing of edge (a = x_m, b = x_{m+1}) at point w of
 * portal triangle pt, picked with probability pt->pdf_select. */
INLINE float portal_pair_log(const SceneView *sc, GLOBAL const PortalTri *pt, const PathVertex *a,
			     const PathVertex *b, V3 w)
{
	float pa = pt->pdf_select / pt->area;
	float g;
	if (vertex_infinite(a)) {
		g = fabs(v3_dot(b->ng, a->p));
	} else {
		V3 d = v3_sub(b->p, a->p);
		float d2 = v3_len2(d);
		g = fabs(v3_dot(a->ng, d)) * fabs(v3_dot(b->ng, d)) / (d2 * d2);
	}
	return fast_log(fmax(pa * portal_direction_psa(sc, pt, a, w) * g, 1e-30f));
}

/* The edge a -> b as a ray for the portal crossing test: from b toward a
 * sky vertex a (a direction, t up to infinity), else from a to b (t in
 * [0, 1]); returns tmax. */
INLINE float path_edge_ray(const PathVertex *a, const PathVertex *b, V3 *o, V3 *d)
{
	*o = vertex_infinite(a) ? b->p : a->p;
	*d = vertex_infinite(a) ? a->p : v3_sub(b->p, a->p);
	return vertex_infinite(a) ? AJAR_INF : 1.0f;
}

/* For edge (x_i, x_{i+1}): log of the sum over its portal crossings of
 * p_pair^beta, and in *found how many the geometric test finds. With `w0`
 * (the pair edge of the current portal strategy), its own crossing is
 * taken at the sampled w0, log p_pair in *lcur, and geometric crossings
 * within a hair of it are dropped: the crossing test is not watertight,
 * and at a portal quad's diagonal it can find the sampled point twice or
 * not at all. */
INLINE float path_pair_logsum(const SceneView *sc, const PathRef *P, int i, float beta, const V3 *w0, float *lcur,
			      int *found)
{
	VTMP(at);
	VTMP(bt);
	const PathVertex *a = VLOAD(P->x[i], at), *b = VLOAD(P->x[i + 1], bt);
	V3 o, d;
	float tmax = path_edge_ray(a, b, &o, &d);
	float sum = -AJAR_INF, hair2 = 1e-8f * sc->params->scene_radius * sc->params->scene_radius;
	*found = 0;
	if (w0) {
		*lcur = portal_pair_log(sc, &sc->portals[a->w0_tri], a, b, *w0);
		sum = beta * *lcur;
	}
	for (int j = 0; j < sc->params->num_portals; j++) {
		GLOBAL const PortalTri *pt = &sc->portals[j];
		float t;
		if (!portal_tri_crossing(o, d, tmax, pt->p0, pt->p1, pt->p2, &t))
			continue;
		++*found;
		V3 w = v3_add(o, v3_scale(d, t));
		if (w0 && v3_len2(v3_sub(w, *w0)) < hair2)
			continue;
		sum = mis_logadd(sum, beta * portal_pair_log(sc, pt, a, b, w));
	}
	return sum;
}

/* MIS records of the first n vertices of an assembled path, and the
 * crossings and pair densities (lpsum, lpair_cur as in mis_union_weight)
 * of the edges the weights read (path_records), or only those of one end
 * of a portal path (`part`, below). */
#define PATH_WHOLE 0
#define PATH_LIGHT_END 1 /* x_0..x_m, pf_{m+1} and edges 0..m only (path_light_end) */
#define PATH_EYE_END 2   /* x_{m+1}.., pr_m and edges after m only (path_eye_end) */
#define PATH_NO_PAIRS 3  /* the whole path's densities, no crossings (path_unpaired_weight) */

INLINE void path_records_part(const SceneView *sc, const PathRef *P, int heuristic, MisPortalSet set, int n,
			      MisVertex *mv, int *cross, float *lpsum, float *lpair_cur, int part)
{
	const VCRef *x = P->x;
	int k = P->k, need_pf = mis_needs_pf(set);
	int nr = min(k, n + 1); /* x_n's delta flag is read too */
	for (int i = 0; i < nr; i++) {
		mv[i].pf = VGETF(x[i], pf);
		mv[i].pr = VGETF(x[i], pr);
		mv[i].delta = VGETI(x[i], delta);
		mv[i].infinite = VREF_INFINITE(x[i]);
	}
	/* Connection ends, the light and the camera scatter through non-delta
	 * lobes on this path whatever their subpaths did next. */
	int conn[2] = {P->c1, P->c2};
	mv[0].delta = 0;
	if (k - 1 < nr)
		mv[k - 1].delta = 0;
	for (int j = 0; j < 2; j++)
		for (int i = conn[j]; conn[j] >= 0 && i <= conn[j] + 1 && i < nr; i++)
			mv[i].delta = 0;
	mv[0].delta = VREF_DELTA_LIGHT(x[0]); /* a punctual light (mis.h) */
	/* Densities the subpaths could not know. A next-event light vertex
	 * (s = 1, t >= 2) carries its own sample density, which is pn, and
	 * its pr when the caller stored it (bdpt_nee). */
	int nee = P->s == 1 && k >= 3; /* else a light subpath's origin (t = 1) */
	if (part != PATH_EYE_END) {
		VTMP(t0);
		VTMP(t1);
		VTMP(t2);
		const PathVertex *x0 = VLOAD(x[0], t0);
		/* pf_0 enters only strategies with s >= 2 light vertices (and pn_0
		 * where k < 3): without light subpaths it cancels, and for the sky
		 * it is an image lookup per weight. */
		mv[0].pf = set.light_paths || set.s_max >= 2 || k < 3 ? bdpt_origin_pdf(sc, x0) : 0.0f;
		mv[0].pn = k < 3 ? mv[0].pf : (nee ? x0->pf : bdpt_nee_pdf(sc, x0, VLOAD(x[1], t1), VLOAD(x[2], t2)));
		if (need_pf && P->s == 0 && k > 2)
			mv[1].pf = path_pf(sc, P, mv, 1);
	}
	for (int j = 0; j < 2; j++) {
		int c = conn[j];
		if (c < 0 || (j == 0 && part == PATH_EYE_END) || (j == 1 && part == PATH_LIGHT_END))
			continue;
		if (c < n && !(c == 0 && nee && VGETF(x[0], pr) > 0.0f))
			mv[c].pr = path_pr(sc, P, mv, c);
		if (c >= 1 && c - 1 < n)
			mv[c - 1].pr = path_pr(sc, P, mv, c - 1);
		if (need_pf && c + 1 <= k - 2 && c + 1 < n)
			mv[c + 1].pf = path_pf(sc, P, mv, c + 1);
		if (need_pf && c + 2 <= k - 2 && c + 2 < n)
			mv[c + 2].pf = path_pf(sc, P, mv, c + 2);
	}
	if (P->pair >= 0 && P->pair < n) {
		if (need_pf && P->pair + 1 < n && part != PATH_EYE_END)
			mv[P->pair + 1].pf = path_pf(sc, P, mv, P->pair + 1);
		if (part != PATH_LIGHT_END)
			mv[P->pair].pr = path_pr(sc, P, mv, P->pair);
	}
	if (part == PATH_NO_PAIRS)
		return;
	/* Crossings and pair densities of the edges intermediate strategies
	 * can pair on (mis_pair_edges), and the current sample's own crossing
	 * (its w_0, kept in the pair's vertices). Each subpath's vertices
	 * cached the crossings of their edge to the previous vertex of their
	 * own walk; connection edges are counted here. */
	int s = P->s, m = P->pair, tp = P->tp, lo, hi;
	float beta = mis_beta(heuristic);
	mis_pair_edges(set, k, n, &lo, &hi);
	*lpair_cur = 0.0f;
	for (int i = 0; i < hi; i++) {
		int conn = i == P->c1 || i == P->c2, c = 0, found;
		lpsum[i] = -AJAR_INF;
		if ((part == PATH_LIGHT_END && i > m) || (part == PATH_EYE_END && i <= m)) {
			cross[i] = 0; /* the other end's edge */
			continue;
		}
		if (i < lo && i != m)
			c = 0;
		else if (conn)
			c = -1; /* below */
		else if (i + 1 < s) /* light subpath: x_{i+1}'s predecessor is x_i */
			c = VGETI(x[i + 1], cross);
		else if (m >= 0 && i <= m) /* <- half (and the pair edge): x_i's predecessor is x_{i+1} */
			c = VGETI(x[i], cross);
		else if (m >= 0 && i < m + tp) /* -> half */
			c = VGETI(x[i + 1], cross);
		else /* eye subpath */
			c = VGETI(x[i], cross);
		if (c != 0 || i == m) {
			V3 w0 = i == m ? VGET3(x[i], w0) : v3(0.0f, 0.0f, 0.0f);
			lpsum[i] = path_pair_logsum(sc, P, i, beta, i == m ? &w0 : 0, lpair_cur, &found);
			if (conn)
				c = found;
		}
		if (i == m && c <= 0) /* the sampled crossing, whatever the test found */
			c = 1;
		cross[i] = c;
	}
	for (int i = max(hi, 0); i < k - 1; i++) { /* never read, but defined for path_join_weight's copies */
		cross[i] = 0;
		lpsum[i] = -AJAR_INF;
	}
}

/* MIS records of the first n vertices of an assembled path, and the
 * crossings and pair densities (lpsum, lpair_cur as in mis_union_weight)
 * of the edges the weights read: what mis_union_weight needs for the
 * strategies in `set`. */
CALLED void path_records(const SceneView *sc, const PathRef *P, int heuristic, MisPortalSet set, int n, MisVertex *mv,
			 int *cross, float *lpsum, float *lpair_cur)
{
	path_records_part(sc, P, heuristic, set, n, mv, cross, lpsum, lpair_cur, PATH_WHOLE);
}

INLINE MisPortalSet path_portal_set(GLOBAL const Params *prm)
{
	MisPortalSet set = {prm->portal_s_max, prm->portal_sp_max, prm->portal_tp_max, prm->portal_t_max,
			    prm->light_paths, fast_log(prm->portal_rate)};
	return set;
}

CALLED float path_union_weight(const SceneView *sc, const PathRef *P, MisStrategy cur)
{
	MisVertex mv[4 * SUBPATH_MAX];
	int cross[4 * SUBPATH_MAX];
	float lpsum[4 * SUBPATH_MAX], lpair_cur;
	int heuristic = sc->params->mis;
	MisPortalSet set = path_portal_set(sc->params);
	int n = mis_horizon(set, P->k);
	path_records(sc, P, heuristic, set, n, mv, cross, lpsum, &lpair_cur);
	return mis_union_weight(mv, P->k, n, cross, lpsum, lpair_cur, cur, set, heuristic);
}

/* Whether an edge of bdpt path P crosses a portal that intermediate
 * strategies in use could pair on: the tests path_records_part makes for
 * the crossings it counts (mis_pair_edges; a connection edge by geometry,
 * path_pair_logsum's, a walk's edge from its cache), over the edges
 * mis_union_sum reads (m + 2 < k). */
INLINE int path_bdpt_pairs(const SceneView *sc, const PathRef *P, MisPortalSet set, int n)
{
	int k = P->k, lo, hi;
	mis_pair_edges(set, k, n, &lo, &hi);
	for (int i = lo; i < hi && i + 2 < k; i++) {
		if (i != P->c1) {
			if (VGETI(P->x[i + 1 < P->s ? i + 1 : i], cross) != 0)
				return 1;
			continue;
		}
		VTMP(at);
		VTMP(bt);
		const PathVertex *a = VLOAD(P->x[i], at), *b = VLOAD(P->x[i + 1], bt);
		V3 o, d;
		float tmax = path_edge_ray(a, b, &o, &d);
		for (int j = 0; j < sc->params->num_portals; j++) {
			GLOBAL const PortalTri *pt = &sc->portals[j];
			float t;
			if (portal_tri_crossing(o, d, tmax, pt->p0, pt->p1, pt->p2, &t))
				return 1;
		}
	}
	return 0;
}

/* The union weight of bdpt strategy cur.s (s <= 1) for the bdpt path P
 * without light subpaths where path_bdpt_pairs finds no pairing edge: the
 * union sum with no crossings or pair densities to find, bit for bit what
 * path_union_weight gives (the records stop at the horizon, 5 with the
 * sky's set, so the logs are few). bdpt_weight uses it. */
INLINE float path_unpaired_weight(const SceneView *sc, const PathRef *P, MisPortalSet set, int n, MisStrategy cur)
{
	MisVertex mv[4 * SUBPATH_MAX];
	int cross[4 * SUBPATH_MAX], heuristic = sc->params->mis;
	float lpsum[1] = {-AJAR_INF}; /* not read */
	path_records_part(sc, P, heuristic, set, n, mv, 0, 0, 0, PATH_NO_PAIRS);
	for (int i = 0; i < n; i++)
		cross[i] = 0;
	return mis_union_weight(mv, P->k, n, cross, lpsum, 0.0f, cur, set, heuristic);
}

/* ---- Portal paths that share an intermediate subpath ---------------------
 *
 * portal.h joins every light-side end (s, s' = a: x_0..x_m = l[0..s-1],
 * R[a..1]) with every eye-side end (t' = b, t: x_{m+1}.. = F[1..b],
 * e[t-1..0]) of one intermediate subpath. Every record of x_0..x_m, and
 * the crossings of edges 0..m (the pair edge m included), depend on the
 * light-side end alone; every record of x_{m+1}.. and the crossings of the
 * later edges on the eye-side end alone; but for pr_m (read from x_{m+1},
 * x_{m+2}), pf_{m+1} (read from x_{m-1}, x_m) and, where s = 0 and s' = 1,
 * pn_0 (read from x_2). path_records is what says so: each end's records
 * are taken from path_records on one path through that end.
 *
 * The weight's sum over strategies then splits too. A bdpt strategy s'
 * has log density LPF(s') - PR[s'] + PR[k]; those with s' <= m read the
 * light-side records only, those with s' >= m + 2 the eye-side ones but for
 * a common term, and s' = m + 1 is one term across. The intermediate
 * strategies that pair on edge m take their s from the light side and
 * their t' from the eye side, so their sum is a product of two sums. Each
 * end keeps its sums as logs, and a pair of ends adds a handful of terms.
 * Strategies pairing on another edge (a path that crosses portals twice)
 * are summed over the whole path (mis_union_sum). Exact for every set
 * (path_join_exact). */
typedef struct {
	float lf, lr; /* logs of the remapped pf and pr */
	float lpsum;  /* of the edge to the next record */
	int bits;     /* delta | infinite << 1 | the edge's crossings << 2 */
} MisRecord;

INLINE int mis_record_delta(const MisRecord *r) { return r->bits & 1; }
INLINE int mis_record_infinite(const MisRecord *r) { return r->bits >> 1 & 1; }
INLINE int mis_record_cross(const MisRecord *r) { return r->bits >> 2; }

/* Whether strategies with j light-side vertices x_0..x_{j-1} can connect
 * to x_j, from the records of x_0..: never at a delta vertex; x_0's delta
 * flag marks a punctual light, which j = 0 cannot reach and j = 1 (next-event
 * estimation) can (mis.h). */
INLINE int mis_record_light_conn(const MisRecord *r, int j)
{
	if (j == 0)
		return !mis_record_delta(&r[0]);
	return !((j >= 2 && mis_record_delta(&r[j - 1])) || mis_record_delta(&r[j]));
}

typedef struct {
	MisRecord r[2 * SUBPATH_MAX]; /* x_0 .. x_m and edges 0 .. m */
	int m;
	float lf_next;   /* log pf_{m+1} */
	float lpn;       /* log pn_0, unless pn_from_x2 */
	int pn_from_x2;  /* (then m = 0) */
	float lpair_cur;
	float pf_m1;     /* PF[m + 1] */
	float pr_m;      /* PR[m] */
	float cur;       /* LPF(s) + PR[m] - PR[s] of its own s */
	float bdpt;      /* log sum over valid s' <= m of exp(beta (LPF(s') - PR[s'])) */
	float pair;      /* log sum over the s pairing on edge m of exp(beta (LPF(s) + PR[m] - PR[s])) */
	int other;       /* an earlier edge crosses portals within the pairing edges */
} MisLightEnd;

typedef struct {
	int nr;          /* records x_{m+1} .. x_{k-1} */
	float lr_m;      /* log pr_m */
	float pr_rest;   /* PR[k] - PR[m + 1] */
	float cur;       /* PF[m+b+1] - PF[m+2] + PR[k] - PR[m+b+1] of its own b */
	float bdpt;      /* log sum over valid s' = m+1+o, o >= 1, of exp(beta (PF[s'] - PF[m+2] - PR[s'] + PR[m+1])) */
	float pair;      /* log sum over the t' with edge m of exp(beta (PF[m+t'+1] - PF[m+2] + PR[k] - PR[m+t'+1])) */
	int first_cross; /* first of its edges (0: x_{m+1} to x_{m+2}) that crosses portals, or nr */
} MisEyeEnd;

/* Whether joined weights are path_union_weight's for every path of set:
 * for every set. Without light subpaths the bdpt strategies are s' <= 1
 * (path_light_end, path_join_weight), and the records past the horizon
 * that the per-path weight leaves out are a factor common to all
 * strategies; an eye part longer than t_max pairs no t' (path_eye_end). */
INLINE int path_join_exact(MisPortalSet set)
{
	(void)set;
	return 1;
}

/* Whether portal.h joins weights (else one per path, path_union_weight):
 * where many ends share each other's records, light subpaths and long eye
 * parts, or -> halves of more than one vertex (window-room-forest, set
 * 1,2,3,4 at rate 1: 70.4 -> 62.1 ms per sample). The sky-only default
 * (t' <= 1, t <= 3) gained nothing measurable and keeps the per-path
 * weight, whose images the constant-sky scenes have had. */
INLINE int path_join_use(MisPortalSet set)
{
	return (set.light_paths && set.tp_max + set.t_max >= SUBPATH_MAX) || set.tp_max >= 2;
}

INLINE void mis_record_set(MisRecord *r, float lf, float lr, const MisVertex *v, const int *cross, const float *lpsum,
			   int i, int edge)
{
	r->lf = lf;
	r->lr = lr;
	r->bits = (v[i].delta != 0) | (v[i].infinite != 0) << 1 | (edge ? cross[i] : 0) << 2;
	r->lpsum = edge ? lpsum[i] : -AJAR_INF;
}

INLINE void mis_record_keep(MisRecord *r, const MisVertex *v, const int *cross, const float *lpsum, int i, int edge,
			    int need_pf)
{
	mis_record_set(r, need_pf ? fast_log(mis_remap0(v[i].pf)) : 0.0f, fast_log(mis_remap0(v[i].pr)), v, cross,
		       lpsum, i, edge);
}

/* Logs of the remapped stored densities of n subpath vertices, lpf and lpr
 * in turn (lpf 0 unless need_pf): the eye-side ends of one intermediate
 * subpath share most of their records, and reuse the logs of those that
 * path_records left as stored. */
INLINE void path_vertex_logs(VCRef v, int n, int need_pf, float *out)
{
	for (int i = 0; i < n; i++) {
		out[2 * i] = need_pf ? fast_log(mis_remap0(VGETF(VAT(v, i), pf))) : 0.0f;
		out[2 * i + 1] = fast_log(mis_remap0(VGETF(VAT(v, i), pr)));
	}
}

/* The light-side end l[0..s-1], R[a..1] (lp = l, or the next-event sample
 * when s = 1), taken from the path that joins it to F[1] and the camera. */
CALLED void path_light_end(const SceneView *sc, MisPortalSet set, VCRef lp, int s, VCRef R, int a, VCRef F, VCRef e,
			   MisLightEnd *L)
{
	PathRef P;
	MisVertex mv[4 * SUBPATH_MAX];
	int cross[4 * SUBPATH_MAX];
	float lpsum[4 * SUBPATH_MAX];
	int need_pf = mis_needs_pf(set);
	float beta = mis_beta(sc->params->mis);
	path_ref(&P, lp, s, R, a, F, 1, e, 1);
	path_records_part(sc, &P, sc->params->mis, set, P.k, mv, cross, lpsum, &L->lpair_cur, PATH_LIGHT_END);
	int m = P.pair;
	for (int i = 0; i <= m; i++)
		mis_record_keep(&L->r[i], mv, cross, lpsum, i, 1, need_pf);
	L->m = m;
	L->lf_next = need_pf ? fast_log(mis_remap0(mv[m + 1].pf)) : 0.0f;
	L->lpn = fast_log(mis_remap0(mv[0].pn));
	L->pn_from_x2 = s == 0 && a == 1;
	float PF[2 * SUBPATH_MAX + 1], PR[2 * SUBPATH_MAX + 1];
	PF[0] = PR[0] = 0.0f;
	for (int i = 0; i <= m; i++) {
		PF[i + 1] = PF[i] + L->r[i].lf;
		PR[i + 1] = PR[i] + L->r[i].lr;
	}
	L->pf_m1 = PF[m + 1];
	L->pr_m = PR[m];
	L->cur = mis_lpf(PF, L->lpn, s) + PR[m] - PR[s];
	float x[2 * SUBPATH_MAX];
	int nx = 0;
	for (int j = 0; j <= m && (set.light_paths || j <= 1); j++) /* without light subpaths s' <= 1 */
		if (mis_record_light_conn(L->r, j))
			x[nx++] = beta * (mis_lpf(PF, L->lpn, j) - PR[j]);
	L->bdpt = mis_logsumexp(x, nx);
	nx = 0;
	for (int j = max(0, m + 1 - set.sp_max); j <= m && j <= set.s_max; j++)
		if (mis_record_light_conn(L->r, j))
			x[nx++] = beta * (mis_lpf(PF, L->lpn, j) + PR[m] - PR[j]);
	L->pair = mis_logsumexp(x, nx);
	int S = set.s_max + set.sp_max; /* edges past it pair no strategy */
	L->other = m >= S;
	for (int i = 0; i < m && i < S; i++)
		L->other |= mis_record_cross(&L->r[i]) > 0;
}

/* The eye-side end F[1..b], e[t-1..0] into E and its records r[0..b+t-1],
 * taken from the path that joins it to A alone (s = 0, s' = 1); lF and lE
 * are path_vertex_logs of F[0..b] and e[0..t-1]. */
CALLED void path_eye_end(const SceneView *sc, MisPortalSet set, VCRef R, VCRef F, int b, VCRef e, int t,
			 const float *lF, const float *lE, MisEyeEnd *E, MisRecord *r)
{
	PathRef P;
	MisVertex mv[4 * SUBPATH_MAX];
	int cross[4 * SUBPATH_MAX];
	float lpsum[4 * SUBPATH_MAX], lpair_cur;
	int need_pf = mis_needs_pf(set);
	float beta = mis_beta(sc->params->mis);
	path_ref(&P, 0, 0, R, 1, F, b, e, t);
	path_records_part(sc, &P, sc->params->mis, set, P.k, mv, cross, lpsum, &lpair_cur, PATH_EYE_END);
	int nr = P.k - 1;
	for (int i = 1; i < P.k; i++) {
		const float *lv = i <= b ? &lF[2 * i] : &lE[2 * (t + b - i)]; /* x_i is F[i] or e[t + b - i] */
		VCRef xv = P.x[i];
		float lf = !need_pf ? 0.0f : mv[i].pf == VGETF(xv, pf) ? lv[0] : fast_log(mis_remap0(mv[i].pf));
		float lr = mv[i].pr == VGETF(xv, pr) ? lv[1] : fast_log(mis_remap0(mv[i].pr));
		mis_record_set(&r[i - 1], lf, lr, mv, cross, lpsum, i, i + 1 < P.k);
	}
	E->nr = nr;
	E->lr_m = fast_log(mis_remap0(mv[0].pr));
	/* FR[o] = PF[m+1+o] - PF[m+2] (o >= 1), RR[o] = PR[m+1+o] - PR[m+1] */
	float FR[2 * SUBPATH_MAX + 1], RR[2 * SUBPATH_MAX + 1];
	FR[1] = 0.0f;
	RR[0] = 0.0f;
	for (int o = 0; o < nr; o++) {
		RR[o + 1] = RR[o] + r[o].lr;
		if (o >= 1)
			FR[o + 1] = FR[o] + r[o].lf;
	}
	E->pr_rest = RR[nr];
	E->cur = FR[b] + RR[nr] - RR[b];
	float x[2 * SUBPATH_MAX];
	int nx = 0;
	for (int o = 1; o < nr; o++) /* s' = m + 1 + o < k */
		if (!(mis_record_delta(&r[o - 1]) || mis_record_delta(&r[o])) && !(mis_record_infinite(&r[o - 1]) && o == nr - 1))
			x[nx++] = beta * (FR[o] - RR[o]);
	E->bdpt = mis_logsumexp(x, nx);
	nx = 0;
	for (int tp = 1; tp <= nr - 1 && tp <= set.tp_max; tp++)
		if (!(mis_record_delta(&r[tp - 1]) || mis_record_delta(&r[tp])) && nr - tp <= set.t_max)
			x[nx++] = beta * (FR[tp] + RR[nr] - RR[tp]);
	E->pair = mis_logsumexp(x, nx);
	E->first_cross = nr;
	for (int o = nr - 2; o >= 0; o--)
		if (mis_record_cross(&r[o]) > 0)
			E->first_cross = o;
}

/* The weight of portal strategy cur for the path over the whole of both
 * ends' records (mis_union_sum), for paths that cross portals twice. */
INLINE float path_join_whole(const SceneView *sc, MisPortalSet set, const MisLightEnd *L, const MisEyeEnd *E,
			     const MisRecord *r, float lpn, MisStrategy cur)
{
	MisVertex v[4 * SUBPATH_MAX];
	int cross[4 * SUBPATH_MAX];
	float lf[4 * SUBPATH_MAX], lr[4 * SUBPATH_MAX], lpsum[4 * SUBPATH_MAX];
	float PF[4 * SUBPATH_MAX + 1], PR[4 * SUBPATH_MAX + 1];
	int m = L->m, k = m + 1 + E->nr;
	for (int i = 0; i < k; i++) {
		const MisRecord *q = i <= m ? &L->r[i] : &r[i - m - 1];
		lf[i] = q->lf;
		lr[i] = q->lr;
		v[i].delta = mis_record_delta(q);
		v[i].infinite = mis_record_infinite(q);
		cross[i] = mis_record_cross(q);
		lpsum[i] = q->lpsum;
	}
	lr[m] = E->lr_m;
	lf[m + 1] = L->lf_next;
	mis_prefix(lf, lr, k, PF, PR);
	return mis_union_sum(v, k, k, PF, PR, lpn, cross, lpsum, L->lpair_cur, cur, set, sc->params->mis);
}

/* log pn_0 where the light-side end is the <- half's first vertex alone
 * (L->pn_from_x2: s = 0, s' = 1): A = R[1] as a next-event sample from
 * B = R[0], which reads the path's x_2 only for the side of B's normal that
 * faces it (vertex_nee_normal, bdpt_nee_pdf). The two sides' logs are kept
 * in *c, which the caller clears (have = 0) for each light-side end, so its
 * eye-side ends share one sky lookup per side. */
typedef struct {
	float lpn[2];
	int have; /* bit i: lpn[i] is set */
} MisPnCache;

INLINE float path_join_lpn(const SceneView *sc, VCRef R, VCRef x2, MisPnCache *c)
{
	VTMP(t0);
	VTMP(t1);
	VTMP(t2);
	const PathVertex *a = VLOAD(VAT(R, 1), t0), *b = VLOAD(VAT(R, 0), t1), *x = VLOAD(x2, t2);
	int side = vertex_nee_side(b, x);
	if (!(c->have >> side & 1)) {
		c->lpn[side] = fast_log(mis_remap0(bdpt_nee_pdf(sc, a, b, x)));
		c->have |= 1 << side;
	}
	return c->lpn[side];
}

/* The weight of portal strategy cur (L's s and s', E's t' and t) for the
 * path that joins light-side end L to eye-side end E, whose records are r;
 * x2 is the path's x_2, read when L->pn_from_x2 (path_join_lpn, with the
 * light-side end's cache pc). set is path_portal_set(sc->params), which the
 * caller makes once. */
CALLED float path_join_weight(const SceneView *sc, MisPortalSet set, const MisLightEnd *L, const MisEyeEnd *E,
			      const MisRecord *r, VCRef x2, VCRef R, MisPnCache *pc, MisStrategy cur)
{
	int m = L->m;
	float lpn = L->pn_from_x2 ? path_join_lpn(sc, R, x2, pc) : L->lpn;
	if (L->other || E->first_cross < min(E->nr - 1, set.s_max + set.sp_max - m - 1))
		return path_join_whole(sc, set, L, E, r, lpn, cur);
	float beta = mis_beta(sc->params->mis);
	float lcur = L->cur + L->lpair_cur + E->cur + set.lrate;
	float pr_m1 = L->pr_m + E->lr_m;              /* PR[m + 1] */
	float g = beta * (pr_m1 + E->pr_rest - lcur); /* beta (PR[k] - lcur) */
	/* bdpt: s' <= m, s' = m + 1, s' >= m + 2 */
	float lpf_m1 = m == 0 ? lpn : L->pf_m1; /* LPF(m + 1) */
	float total = fast_exp(g + L->bdpt);
	if ((set.light_paths || m == 0) && !((m >= 1 && mis_record_delta(&L->r[m])) || mis_record_delta(&r[0])))
		total += fast_exp(g + beta * (lpf_m1 - pr_m1));
	if (set.light_paths) /* else bdpt strategies have s' <= 1 */
		total += fast_exp(g + beta * (L->pf_m1 + L->lf_next - pr_m1) + E->bdpt);
	/* intermediate strategies pairing on edge m */
	total += fast_exp(L->r[m].lpsum + beta * (set.lrate - lcur) + L->pair + E->pair);
	return 1.0f / total;
}

#endif
