/* pt.h — the unidirectional path tracer, the reference every other
 * integrator is checked against.
 *
 * Next-event estimation to emitters and the environment, combined with BSDF
 * sampling by the power heuristic; Russian roulette (roulette.h) from vertex
 * rr_depth on scales only the throughput, so it enters neither strategy's
 * density and the MIS weights stay consistent (design.md, Pitfalls).
 * max_depth counts path segments, camera segment included (Mitsuba's
 * max_depth); paths of fewer than min_depth segments are left out, so
 * max_depth = min_depth = k gives the image of paths of exactly k segments,
 * which each bidirectional strategy must reproduce. With Params.cross_filter (a test mode) each
 * path counts as many times as it crosses portals on the edges that one
 * group of intermediate-subpath strategies can sample (pt_cross_weight):
 * the image those strategies must reproduce. */

#ifndef AJAR_PT_H
#define AJAR_PT_H
#include "material/bsdf.h"
#include "geom/bvh.h"
#include "geom/camera.h"
#include "light/lights.h"
#include "mis/mis.h"
#include "geom/portal_crossing.h"
#include "sample/rng.h"
#include "sample/roulette.h"
#include "geom/surface.h"
#include "geom/visibility.h"
#include "integrator/pane_mirror.h"

#define PT_CROSS_EDGES 33
#define PT_PANES_MAX 64 /* panes one segment may cross (vertex.h's guard) */

/* The test mode's weight of a path of n segments whose eye-side edges
 * (edge 0 leaves the camera) cross portals cnt[j] times; `last` replaces
 * cnt[n - 1] (a next-event edge). 1 when the mode is off. */
INLINE float pt_cross_weight(GLOBAL const Params *prm, const int *cnt, int n, int last)
{
	if (!prm->cross_filter)
		return 1.0f;
	int w = 0;
	for (int j = prm->cross_lo; j <= n - 1 - prm->cross_hi; j++)
		w += j == n - 1 ? last : (j < PT_CROSS_EDGES ? cnt[j] : 0);
	return (float)w;
}

INLINE V3 pt_radiance(const SceneView *sc, V3 o, V3 d, Rng *rng)
{
	GLOBAL const Params *prm = sc->params;
	V3 L = v3(0.0f, 0.0f, 0.0f), beta = v3(1.0f, 1.0f, 1.0f);
	float prev_pdf_w = 0.0f;
	int prev_delta = 1; /* the camera ray counts emission in full */
	V3 prev_p = o, prev_n = v3(0.0f, 0.0f, 0.0f); /* prev_n: vertex_nee_normal's */
	V3 prev_ng = prev_n;
	int prev_mat = -1; /* the material the ray leaves, for a solid's absorption */
	float beta_ref = 1.0f;
	int prev_nee = 0;    /* the previous vertex had next-event estimation (a non-delta BSDF) */
	int mirror_fam = 0;  /* this edge leaves a pane's mirror for the sky sampled at the vertex
			      * before it (pane_mirror.h): a sky it finds counts there, not here */
	int cnt[PT_CROSS_EDGES];
	for (int depth = 0;; depth++) {
		Hit h;
		Surface s;
		int hit, c_edge = 0;
		float edge_t = 0.0f; /* the edge's length before the last pane crossed */
		float exist = 1.0f;  /* the probability of a vertex where the walk stopped */
		/* The next hit, crossing panes by their null event (vertex.h, vertex_trace). */
		for (int panes = 0;; panes++) {
			hit = bvh_intersect(sc, o, d, AJAR_INF, &h);
			if (prm->cross_filter)
				c_edge += hit ? portal_crossings(sc, o, v3_add(o, v3_scale(d, h.t)), 0)
					      : portal_crossings(sc, o, d, 1);
			if (!hit)
				break;
			surface_from_hit(sc, &h, &s);
#ifndef AJAR_NO_PANES
			if ((sc->tris[s.tri].flags & TRI_PANE) && panes < PT_PANES_MAX) {
				Bsdf pb;
				surface_bsdf(sc, &s, surface_base_color(sc, &s), &pb);
				float pn = bsdf_null_prob(&pb, v3_neg(d));
				if (pn > 0.0f && rng_f(rng) < pn) {
					beta = v3_mul(beta, v3_scale(bsdf_null_weight(&pb, d), 1.0f / pn));
					V3 q = ray_offset(s.p, s.ng, d);
					edge_t += v3_len(v3_sub(q, o));
					o = q;
					continue;
				}
				exist = 1.0f - pn;
			}
#endif
			break;
		}
		if (depth < PT_CROSS_EDGES)
			cnt[depth] = c_edge;
		if (!hit) {
			float pe;
			V3 Le = env_radiance_pdf(sc, d, &pe);
			if (!v3_is_zero(Le)) {
				float w = prev_delta ? 1.0f : mis_power(prev_pdf_w, light_env_pdf_w(sc, prev_p, prev_n, d, pe));
				w *= pt_cross_weight(prm, cnt, depth + 1, c_edge);
				if (depth + 1 >= prm->min_depth && !mirror_fam)
					L = v3_add(L, v3_scale(v3_mul(beta, Le), w));
			}
			break;
		}
		float dist = edge_t + h.t;
		beta = v3_mul(beta, volume_attenuation(sc, prev_mat, prev_ng, d, dist));
		V3 wo = v3_neg(d);
		if (sc->tris[s.tri].emitter >= 0 && depth + 1 >= prm->min_depth) {
			V3 Le = emitter_radiance(sc, s.tri, s.p, wo);
			if (!v3_is_zero(Le)) {
				float w = 1.0f;
				if (!prev_delta) {
					float cos_l = fabs(v3_dot(s.ng, wo));
					w = mis_power(prev_pdf_w, light_pdf_w(sc, prev_p, prev_n, d, s.tri, dist, cos_l));
				}
				w *= pt_cross_weight(prm, cnt, depth + 1, c_edge);
				L = v3_add(L, v3_scale(v3_mul(beta, Le), w));
			}
		}
		/* The next vertex would make depth + 2 segments. */
		if (depth + 2 > prm->max_depth)
			break;
		Bsdf bs;
		surface_bsdf(sc, &s, surface_base_color(sc, &s), &bs);
		bsdf_cache_wo(&bs, wo); /* next-event estimation and sampling both start from wo */
		/* The normal next-event samples are weighed by (env_portal.h): turned
		 * toward wo here; pt's two densities at a vertex both read n_nee. */
		V3 n_nee = v3_dot(s.ns, wo) < 0.0f ? v3_neg(s.ns) : s.ns;
		if (!bsdf_is_delta(&bs) && depth + 2 >= prm->min_depth) {
			LightSample ls;
			float u0, u1, u2;
			rng_nee3(rng, &u0, &u1, &u2);
			if (light_sample(sc, s.p, n_nee, u0, u1, u2, &ls) && ls.pdf_w > 0.0f && !v3_is_zero(ls.Le)) {
				float pdf_bsdf_w;
				V3 f = bsdf_eval_fwd(&bs, wo, ls.wi, BSDF_RADIANCE, &pdf_bsdf_w);
				if (!v3_is_zero(f)) {
					int far = ls.is_env || !(ls.dist < AJAR_INF); /* the sky, a directional light */
					V3 T = far ? ray_transmittance(sc, ray_offset(s.p, s.ng, ls.wi), ls.wi, AJAR_INF)
						   : segment_transmittance(sc, s.p, s.ng, ls.p, ls.n);
					if (!far && !v3_is_zero(T))
						T = v3_mul(T, volume_attenuation(sc, s.material, s.ng, ls.wi, ls.dist));
					if (!v3_is_zero(T)) {
						int c_nee = !prm->cross_filter ? 0
								: far ? portal_crossings(sc, s.p, ls.wi, 1)
									    : portal_crossings(sc, s.p, ls.p, 0);
						/* A punctual light is sampled by next-event estimation alone. */
						float w = (ls.delta ? 1.0f : mis_power(ls.pdf_w, pdf_bsdf_w)) *
							  pt_cross_weight(prm, cnt, depth + 2, c_nee);
						float k = fabs(v3_dot(s.ns, ls.wi)) * w / (ls.pdf_w * exist);
						L = v3_add(L, v3_scale(v3_mul(v3_mul(v3_mul(beta, f), T), ls.Le), k));
					}
				}
			}
		}
#ifndef AJAR_NO_PANES
		/* The sky mirrored in the panes whose sky side this is, a path of
		 * depth + 3 segments (pane_mirror.h). */
		int nee = !bsdf_is_delta(&bs);
		if (nee && prm->num_pane_planes && !prm->cross_filter && depth + 3 <= prm->max_depth &&
		    depth + 3 >= prm->min_depth)
			for (int i = 0; i < prm->num_pane_planes; i++) {
				if (!pane_sky_side(sc, i, s.p))
					continue;
				float u0, u1, u2, pdf_m, pb;
				rng_f3(rng, &u0, &u1, &u2);
				V3 wx, wsky;
				Surface hs;
				Bsdf hb;
				V3 c = pane_mirror_sample(sc, i, s.p, s.ng, n_nee, u0, u1, u2, &wx, &wsky, &pdf_m, &hs, &hb);
				if (!v3_is_zero(c)) {
					V3 f = bsdf_eval_fwd(&bs, wo, wx, BSDF_RADIANCE, &pb);
					L = v3_add(L, v3_scale(v3_mul(v3_mul(beta, f), c), fabs(v3_dot(s.ns, wx)) / exist));
				}
			}
#endif
		BsdfSample bsm;
		float u0, u1, u2;
		rng_f3(rng, &u0, &u1, &u2);
#ifndef AJAR_NO_PANES
		float rest = 1.0f; /* the share of the BSDF's sampling left to the vertex */
		if (sc->tris[s.tri].flags & TRI_PANE) /* the null event was decided against where it was hit */
			rest = 1.0f - bsdf_null_prob(&bs, wo);
		u0 *= rest;
#endif
		if (!bsdf_sample_fwd(&bs, wo, u0, u1, u2, BSDF_RADIANCE, &bsm) || !(bsm.pdf_w > 0.0f))
			break;
		if (bsm.delta == BSDF_NULL) /* smooth thin glass that is no pane: a delta vertex */
			bsm.delta = 1;
		float k = fabs(v3_dot(s.ns, bsm.wi)) / bsm.pdf_w;
#ifndef AJAR_NO_PANES
		k *= rest / exist; /* a pane's vertex had probability exist, its lobes the share rest */
#endif
		beta = v3_mul(beta, v3_scale(bsm.f, k));
#ifndef AJAR_NO_PANES
		/* A pane's mirror left for the sky after a vertex that sampled it
		 * (pane_mirror.h, the family of that sample). */
		mirror_fam = 0;
		if (prm->num_pane_planes && !prm->cross_filter && bsm.delta && prev_nee && !prev_delta) {
			int i = pane_mirror_plane(sc, s.tri, s.p, s.ng, &bs);
			mirror_fam = i >= 0 && pane_sky_side(sc, i, prev_p);
		}
		prev_nee = nee;
#endif
		prev_pdf_w = bsm.pdf_w;
		prev_delta = bsm.delta;
		prev_p = s.p;
		prev_n = n_nee;
		prev_ng = s.ng;
		prev_mat = s.material;
		o = ray_offset(s.p, s.ng, bsm.wi);
		d = bsm.wi;
		if (depth == 0)
			beta_ref = fmax(v3_maxc(beta), 1e-30f); /* roulette.h */
		else if (depth + 1 >= prm->rr_depth && !rr_survive(&beta, beta_ref, RR_BOOST, rng))
			break;
		if (v3_is_zero(beta))
			break;
	}
	return L;
}
#endif
