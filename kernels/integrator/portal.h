/* portal.h — portal-based bidirectional path tracing (the note in
 * shared/seed, design.md "Path sampling and MIS"): every bdpt strategy plus
 * the strategies of one intermediate subpath per pixel sample.
 *
 * An intermediate subpath starts at a point w_0 on a portal triangle,
 * picked mostly by the direct light arriving through it (src/prepare/portal_flux.c;
 * p_A = pdf_select / area), with a direction: with probability 1/2 a side,
 * mostly the one the light comes from, and a cosine direction on it for
 * the <- half, else the <- half toward a light sample from w_0, kept only
 * if it reaches that light point (so the density is a function of the
 * path: union_mis.h, portal_direction_psa). The <- half traces -w
 * toward the light, like an eye subpath, and its vertices connect to the
 * light subpath (s >= 2), to a fresh light sample (s = 1), or are the light
 * (s = 0). The -> half traces w, like a light subpath, and its vertices
 * connect to the eye subpath (t >= 2) or to the camera (t = 1, splatted).
 * Punctual lights reach the <- half only by next-event estimation (s = 1)
 * and light subpaths (s >= 2): the half never hits one, and a guided
 * direction never aims at one (portal_guided_sample).
 * The portal is invisible, so w_0 is no path vertex: the pair x_m, x_{m+1}
 * (the first hits of the two halves) has density p_A q(w) G(x_m, x_{m+1})
 * and the contribution carries 1 / (p_A q(w)).
 *
 * Every path, however it was sampled, is weighted over the union of both
 * families (mis_union_weight): its MIS records come from the stored
 * subpath densities, with the densities next to each connection and next to
 * the portal pair recomputed from the path itself, and the portal
 * crossings of every edge are counted.
 *
 * Arrays: l (light) and e (eye, e[0] the camera) as in bdpt.h; R holds the
 * <- half with R[0] a copy of the -> half's first hit B (the vertex on the
 * far side of the portal, as R's walk sees it) and R[1] = A its own first
 * hit; F holds the -> half with F[0] a copy of A and F[1] = B. */
#ifndef AJAR_PORTAL_H
#define AJAR_PORTAL_H
#include "integrator/bdpt.h"

/* ---- The intermediate subpath -------------------------------------------- */

/* A light sample from portal point w0 as the <- direction *wl: the
 * environment by its importance folded onto the portal's sky side, or an
 * emitter point at distance *dist facing w0 (union_mis.h,
 * portal_direction_psa). Returns 0 if there is none. */
INLINE int portal_guided_sample(const SceneView *sc, GLOBAL const PortalTri *pt, V3 w0, float u_sel, float u1,
				float u2, V3 *wl, int *is_env, float *dist)
{
	float ce, ps = guided_env_share(sc, &ce);
	*is_env = u_sel < ps;
	if (*is_env) {
		float pdf_w;
		env_sample(sc, u1, u2, wl, &pdf_w);
		if (!(pdf_w > 0.0f))
			return 0;
		if (pt->env_side != 0 && (float)pt->env_side * v3_dot(*wl, pt->n) < 0.0f)
			*wl = portal_mirror(*wl, pt->n);
		return 1;
	}
	LightSample ls;
	/* Not at a punctual light: its light reaches the <- half by next-event
	 * estimation and light subpaths; a guided direction at it would be a
	 * delta direction that no other strategy samples. The emitters' part
	 * of the table alone (guided_env_share); a pick that rounding still
	 * sends to a light is lost. */
	if (!(ce > 0.0f) ||
	    !light_sample_emitter(sc, w0, fmin((u_sel - ps) / (1.0f - ps), 0.99999994f) * ce, u1, u2, 1.0f - ps, &ls) ||
	    ls.delta)
		return 0;
	*wl = ls.wi;
	*dist = ls.dist;
	return 1;
}

/* The <- direction *wl from point w0 of portal triangle pt (union_mis.h,
 * portal_direction_psa): with probability PORTAL_COSINE a side, by what
 * lies behind it, and a cosine direction on it; else toward a light
 * sample (*guided_env, *guided_dist say which). Returns 0 if there is
 * none, 1 for a cosine direction, 2 for a light sample, which counts only
 * if the <- half reaches it (portal_guided_reached). */
INLINE int portal_direction_sample(const SceneView *sc, GLOBAL const PortalTri *pt, V3 w0, float u_mix, float u1,
				   float u2, float u3, V3 *wl, int *guided_env, float *guided_dist)
{
	*guided_env = 0;
	*guided_dist = 0.0f;
	if (u_mix < PORTAL_COSINE) {
		V3 ns = u3 < pt->side_plus ? pt->n : v3_neg(pt->n), t, b;
		v3_basis(ns, &t, &b);
		*wl = v3_from_local(sample_cosine_hemisphere(u1, u2), t, b, ns);
		return 1;
	}
	return portal_guided_sample(sc, pt, w0, u3, u1, u2, wl, guided_env, guided_dist) ? 2 : 0;
}

/* Whether the <- half's first vertex A is the light point a guided
 * direction aimed at. */
INLINE int portal_guided_reached(const SceneView *sc, const PathVertex *A, V3 w0, int guided_env, float guided_dist)
{
	if (guided_env)
		return A->type == VERTEX_ENV;
	return A->type == VERTEX_SURFACE && sc->tris[A->tri].emitter >= 0 &&
	       fabs(v3_len(v3_sub(A->p, w0)) - guided_dist) <= 1e-3f * guided_dist + 1e-6f;
}

/* Traces both halves; returns the vertex counts of R and F (each >= 2 when
 * the half has a first vertex, counting the copy at index 0), or 0 when
 * the sample is wasted. */
CALLED void portal_intermediate(const SceneView *sc, VRef R, int *nR, VRef F, int *nF, Rng *rng)
{
	GLOBAL const Params *prm = sc->params;
	int depth = prm->max_depth;
	float u0 = rng_f(rng), u1 = rng_f(rng), u2 = rng_f(rng), u3 = rng_f(rng), u4 = rng_f(rng), u5 = rng_f(rng);
	float u_mix = rng_f(rng);
	V3 w0, n;
	float pdf_a;
	*nR = *nF = 0;
	int j = portal_sample(sc, u0, u1, u2, &w0, &n, &pdf_a);
	if (j < 0 || !(pdf_a > 0.0f))
		return;
	GLOBAL const PortalTri *pt = &sc->portals[j];
	V3 wl;
	int guided_env;
	float guided_dist;
	int how = portal_direction_sample(sc, pt, w0, u_mix, u3, u4, u5, &wl, &guided_env, &guided_dist);
	if (how == 0)
		return;
	V3 w = v3_neg(wl);
	/* The two first hits. The walks' "previous vertex" of each first hit
	 * is the other one: the portal passes rays straight through. */
	PathVertex origin;
	origin.type = VERTEX_SURFACE;
	origin.p = w0;
	origin.ng = origin.ns = n;
	origin.material = origin.tri = -1;
	/* Both halves leave from a point a little behind w0 on the line, so that
	 * a pane lying in the portal's plane is crossed by the -> half alone,
	 * never by neither. */
	V3 o = w0;
	if (prm->num_panes > 0)
		o = v3_sub(w0, v3_scale(w, 1e-5f * prm->scene_radius));
	/* Each half's walk starts from the origin in its slot 0 (subpath storage, vertex.h). */
	VSTORE(VAT(F, 0), &origin);
	if (!vertex_trace(sc, F, 1, o, w, v3(1.0f, 1.0f, 1.0f), 0.0f, 0, 1, 0, rng))
		return; /* -> escaped: nothing in the scene to connect to the eye */
	VTMP(bt);
	VTMP(at);
	PathVertex B = *VLOAD(VAT(F, 1), bt);
	VSTORE(VAT(R, 0), &origin);
	if (!vertex_trace(sc, R, 1, o, v3_neg(w), v3(1.0f, 1.0f, 1.0f), 0.0f, 0, 0, 1, rng))
		return; /* <- escaped and there is no environment */
	PathVertex A = *VLOAD(VAT(R, 1), at);
	if (how == 2 && !portal_guided_reached(sc, &A, w0, guided_env, guided_dist))
		return;
	int cross_ab = A.type == VERTEX_ENV ? portal_crossings(sc, B.p, A.p, 1) : portal_crossings(sc, A.p, B.p, 0);
	A.cross = B.cross = cross_ab > 0 ? cross_ab : 1; /* w_0 lies on the edge */
	A.pf = A.pr = B.pf = B.pr = 0.0f; /* the pair's own densities are p_pair */
	A.w0 = B.w0 = w0;
	A.w0_tri = B.w0_tri = j;
	float q = portal_direction_psa(sc, pt, &A, w0);
	if (!(q > 0.0f))
		return;
	float k = 1.0f / (pdf_a * q); /* f / p_pair = 1 / (p_A q): G cancels */
	/* The halves' betas hold what the panes they crossed let through: the
	 * edge's transmittance, carried on the -> side. */
	B.beta = v3_scale(v3_mul(A.beta, B.beta), k);
	A.beta = v3(1.0f, 1.0f, 1.0f);
	VSTORE(VAT(R, 0), &B);
	VSTORE(VAT(R, 1), &A);
	VSTORE(VAT(F, 0), &A);
	VSTORE(VAT(F, 1), &B);
	/* Each half only as long as the strategies in use reach. */
	int rmax = min(depth, prm->portal_sp_max) + 1, fmax_ = min(depth, prm->portal_tp_max) + 1;
	*nR = A.type == VERTEX_ENV ? 2 : vertex_extend(sc, R, 2, rmax, 0, 1, 1.0f, rng);
	*nF = vertex_extend(sc, F, 2, fmax_, 1, 0, v3_maxc(B.beta), rng);
	/* The walks wrote A's pr into F[0] and B's pf into R[0]; those are the
	 * standard densities path_records recomputes anyway. */
}

/* Adds the contribution c (unweighted) of portal strategy (s, s', t', t)
 * with weight w: eye pixel or splat, and the strategy layers grouped by
 * (length, s, t) after the bdpt layers. */
INLINE void portal_add(const SceneView *sc, BdptFilm *out, int s, int sp, int tp, int t, V3 c, float w, uint pixel,
		       Rng *rng)
{
	int n = s + sp + tp + t - 1;
	int layer = bdpt_layer_count(sc->params->strategy_len) + portal_layer(n, s, t);
	bdpt_film_add(sc, out, n, layer, t == 1, v3_scale(c, 1.0f / sc->params->portal_rate), w, pixel, rng);
}

/* The eye-side end of portal strategies: -> vertex F[b] (a surface) to
 * eye vertex e[t-1] (t >= 2) or to the camera (t = 1): the contribution
 * from F[b]'s throughput on, and the pixel it lands in. */
CALLED V3 portal_right(const SceneView *sc, VCRef F, int b, VCRef e, int t, uint own_pixel, uint *pixel)
{
	VTMP(yt);
	VTMP(zt);
	*pixel = own_pixel;
	if (VGETI(VAT(F, b), type) != VERTEX_SURFACE)
		return v3(0.0f, 0.0f, 0.0f);
	const PathVertex *y = VLOAD(VAT(F, b), yt);
	if (t >= 2) {
		if (VGETI(VAT(e, t - 1), type) != VERTEX_SURFACE)
			return v3(0.0f, 0.0f, 0.0f);
		const PathVertex *z = VLOAD(VAT(e, t - 1), zt);
		V3 c = bdpt_connect(sc, y, z);
		return v3_mul(v3_mul(y->beta, c), z->beta);
	}
	return bdpt_to_camera(sc, y, 0, VLOAD(VAT(e, 0), zt), pixel);
}

#define PORTAL_RIGHT_MAX 48
#define PORTAL_RECORDS_MAX 512 /* the eye-side ends' MIS records in a chunk (>= 2 SUBPATH_MAX) */

/* One pixel sample of the portal integrator. */
INLINE void portal_sample_pixel(const SceneView *sc, float px, float py, VRef l, VRef e, VRef R, VRef F,
				BdptFilm *out, Rng *rng)
{
	int depth = sc->params->max_depth;
	/* The light and intermediate subpaths draw from streams of their
	 * own, so the camera walk keeps the low-discrepancy numbers (rng.h). */
	Rng lr = rng_fork(rng), ir = rng_fork(rng);
	int nl = sc->params->light_paths ? bdpt_light_subpath(sc, l, depth, &lr) : 0;
	int ne = bdpt_eye_subpath(sc, px, py, e, depth + 1, rng);
	int nR = 0, nF = 0;
	if (rng_pcg_f(&ir) < sc->params->portal_rate)
		portal_intermediate(sc, R, &nR, F, &nF, &ir);
	bdpt_strategies(sc, l, nl, e, ne, out, rng);

	/* Eye-side ends, in chunks so any number of them is handled. */
	V3 rc[PORTAL_RIGHT_MAX];
	int rb[PORTAL_RIGHT_MAX], rt[PORTAL_RIGHT_MAX];
	uint rpix[PORTAL_RIGHT_MAX];
	/* Each end's MIS records, built once (union_mis.h, path_join_weight). */
	MisPortalSet set = path_portal_set(sc->params);
	int join = path_join_use(set);
	MisRecord rrec[PORTAL_RECORDS_MAX];
	MisEyeEnd rend[PORTAL_RIGHT_MAX];
	float lF[2 * SUBPATH_MAX], lE[2 * SUBPATH_MAX];
	int logs = 0;
	int b0 = 1, t0 = 1;
	while (nR >= 2 && nF >= 2 && b0 < nF) {
		int nr = 0, nrec = 0, ready = 0;
		for (; b0 < nF && nr < PORTAL_RIGHT_MAX; b0++, t0 = 1) {
			for (; t0 <= ne && t0 <= sc->params->portal_t_max && nr < PORTAL_RIGHT_MAX; t0++) {
				if (b0 + t0 > depth) /* s = 0, s' = 1 is the shortest left end */
					continue;
				if (nrec + b0 + t0 > PORTAL_RECORDS_MAX)
					break;
				uint pix;
				V3 c = portal_right(sc, F, b0, e, t0, out->pixel, &pix);
				if (v3_is_zero(c))
					continue;
				rc[nr] = c;
				rb[nr] = b0;
				rt[nr] = t0;
				rpix[nr] = pix;
				nrec += b0 + t0;
				nr++;
			}
			if (t0 <= ne && t0 <= sc->params->portal_t_max)
				break; /* the chunk is full in the middle of b0 */
		}
		if (nr == 0)
			continue;
		/* Light-side ends: <- vertex R[a] is the light (s = 0), gets a
		 * light sample (s = 1), or meets light vertex l[s-1]. */
		for (int a = 1; a < nR; a++) {
			VTMP(zt);
			const PathVertex *z = VLOAD(VAT(R, a), zt);
			for (int s = 0; s <= sc->params->portal_s_max && (s <= 1 || s <= nl); s++) {
				V3 lcon = v3(0.0f, 0.0f, 0.0f);
				PathVertex y; /* the light sample for s = 1 */
				VCRef lp = l;
				VTMP(ft);
				if (s == 0) {
					if (z->type == VERTEX_ENV || sc->tris[z->tri].emitter >= 0)
						lcon = v3_mul(z->beta, bdpt_emitted(sc, z, z->wo));
				} else if (z->type != VERTEX_SURFACE) {
					break;
				} else if (s == 1) {
					lcon = bdpt_nee(sc, z, VLOAD(VAT(R, a - 1), ft), &y, &ir);
					if (!v3_is_zero(lcon))
						lp = VNEE(e, y);
				} else {
					const PathVertex *ly = VLOAD(VAT(l, s - 1), ft);
					V3 c = bdpt_connect(sc, ly, z);
					lcon = v3_mul(v3_mul(ly->beta, c), z->beta);
				}
				if (v3_is_zero(lcon))
					continue;
				MisLightEnd L;
				MisPnCache pc;
				pc.have = 0;
				if (join) {
					if (!logs) {
						path_vertex_logs(F, nF, mis_needs_pf(set), lF);
						path_vertex_logs(e, ne, mis_needs_pf(set), lE);
						logs = 1;
					}
					for (int j = 0, r = 0; !ready && j < nr; r += rb[j] + rt[j], j++)
						path_eye_end(sc, set, R, F, rb[j], e, rt[j], lF, lE, &rend[j], &rrec[r]);
					ready = 1;
					path_light_end(sc, set, lp, s, R, a, F, e, &L);
				}
				for (int j = 0, r = 0; j < nr; r += rb[j] + rt[j], j++) {
					int b = rb[j], t = rt[j];
					if (s + a + b + t - 1 > depth)
						continue;
					MisStrategy cur = {2, s, s + a - 1, b};
					float w;
					if (join) {
						w = path_join_weight(sc, set, &L, &rend[j], &rrec[r], b >= 2 ? VAT(F, 2) : VAT(e, t - 1),
								     R, &pc, cur);
					} else {
						PathRef P;
						path_ref(&P, lp, s, R, a, F, b, e, t);
						w = path_union_weight(sc, &P, cur);
					}
					portal_add(sc, out, s, a, b, t, v3_mul(lcon, rc[j]), w, rpix[j], rng);
				}
			}
		}
	}
}
#endif
