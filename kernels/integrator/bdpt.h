/* bdpt.h — bidirectional path tracing (Veach 1997, ch. 10) in the
 * notation of design.md: one light subpath and one eye subpath per pixel
 * sample, every (s, t) strategy evaluated and weighted by mis_path_weight.
 *
 *   s = 0   the eye subpath hits an emitter or escapes to the environment;
 *   s = 1   next-event estimation: a fresh light point connected to eye
 *           vertex t-1 (for the sky, aimed through portals: its density pn_0
 *           differs from the light subpath's origin density, mis.h);
 *   t = 1   light vertex s-1 connected to the camera and splatted into the
 *           pixel it lands in (light tracing);
 *   others  light vertex s-1 connected to eye vertex t-1.
 * For each strategy the path's MIS records are those of the subpaths but
 * for the four densities next to the connection, which its evaluation
 * finds (BdptConnPdf); the weight reads the records around the connection
 * and, beyond them, the sums each subpath vertex carries (bdpt_mis_tails,
 * mis.h). bdpt_mis_path builds all the records, recomputing those four
 * from the vertices, for the tests and for callers without the tails.
 *
 * Light subpaths leave an emitter by power, a uniform point on it and a
 * cosine direction, or the environment by its importance, along a line on
 * a disk of the scene's bounding radius perpendicular to the direction (a
 * sky image with portals: through the portals or the disk, as a
 * directional light's, lights.h line_sample), or a
 * punctual light (KHR_lights_punctual, chosen in the emitters' table):
 * a point or spot light in a direction on the sphere or in the outer
 * cone, a directional light along a line through the portals or the disk
 * (lights.h, line_sample). A punctual light is a delta in position or
 * direction: no ray hits it (no s = 0), the camera does not see it (no
 * s = 1, t = 1, as in pt), and next-event estimation (s = 1) and light
 * subpaths (s >= 2) both reach it with the probability of its choice,
 * which cancels in the MIS ratios (mis.h). The camera
 * direction density is that of a uniform point on the whole image (camera.h):
 * with one light path per pixel sample, light tracing takes W H times as
 * many samples per pixel as each eye strategy and has W H times smaller
 * density per pixel, so n p agrees and the MIS counts are right. */
#ifndef AJAR_BDPT_H
#define AJAR_BDPT_H
#include "geom/camera.h"
#include "film/film.h"
#include "mis/union_mis.h"
#include "mis/strategies.h"
#include "integrator/pane_mirror.h"

/* pn_0 of one light subpath's origin for the two sides of its first
 * vertex's normal: bdpt_nee_pdf reads a path's x_2 only for the side of
 * x_1 it lies on (vertex_nee_side), so every connection (s >= 2) of the
 * light subpath takes one of these two; a sky image's costs a lookup
 * through the portals' tables, once per side instead of once per
 * connection. With them, pf_0, the origin's own density, which is the same
 * in every connection too. bdpt_strategies clears it (have = 0) per light
 * subpath. */
typedef struct {
	float pn[2];
	float pf0;
	int have;  /* bit i < 2: pn[i] is set; bit 2: pf0 */
	int tails; /* the subpaths' vertices carry their MIS tails (bdpt_mis_tails) */
} BdptPnCache;

/* The solid-angle densities that evaluating a connection found at its
 * ends (bdpt_connect, bdpt_to_camera, bdpt_nee): each end's BSDF sampling
 * the other end (fwd) and sampling its own subpath predecessor from the
 * other end (rev). They are the four records next to the connection in
 * solid angle, so the weight need not evaluate the BSDFs again. */
typedef struct {
	float l_fwd, l_rev; /* at the light end (s >= 2; l_rev for t = 1 too) */
	float e_fwd, e_rev; /* at the eye end (t >= 2) */
} BdptConnPdf;

/* One record as its subpath left it. */
INLINE void bdpt_record(MisVertex *m, VCRef x)
{
	m->pf = VGETF(x, pf);
	m->pr = VGETF(x, pr);
	m->delta = VGETI(x, delta);
	m->infinite = VREF_INFINITE(x);
}

/* x_0's densities pf_0 and pn_0 (and for s = 0, pf_1), as
 * bdpt_mis_records describes. */
INLINE void bdpt_records_x0(const SceneView *sc, VCRef l, int s, VCRef e, int t, MisVertex *mv, int nee_stored,
			    BdptPnCache *pc)
{
	int k = s + t;
	VTMP(t0);
	VTMP(t1);
	VTMP(t2);
	const PathVertex *x0 = VLOAD(s > 0 ? VAT(l, 0) : VAT(e, t - 1), t0);
	/* x_1 and x_2 (k >= 3 for the second): light vertices, then eye vertices. */
	const PathVertex *x1 = VLOAD(s >= 2 ? VAT(l, 1) : (s == 1 ? VAT(e, t - 1) : VAT(e, t - 2)), t1);
	const PathVertex *x2 = VLOAD(s >= 3 ? VAT(l, 2) : VAT(e, max(t + s - 3, 0)), t2);
	/* With the cache, a sky sample's own density (bdpt_light_vertex), the
	 * same bits as bdpt_nee_pdf's (test_lights, test_sky_pdf_views). */
	if (nee_stored || (pc && s == 1 && t >= 2 && x0->type == VERTEX_ENV)) {
		mv[0].pf = bdpt_origin_pdf(sc, x0);
		mv[0].pn = x0->pf;
	} else if (pc && s >= 2) { /* k >= 3 */
		int side = vertex_nee_side(x1, x2);
		if (!(pc->have & 4)) {
			pc->pf0 = bdpt_origin_pdf(sc, x0);
			pc->have |= 4;
		}
		mv[0].pf = pc->pf0;
		if (!(pc->have >> side & 1)) {
			pc->pn[side] = bdpt_nee_pdf(sc, x0, x1, x2);
			pc->have |= 1 << side;
		}
		mv[0].pn = pc->pn[side];
	} else {
		bdpt_light_records(sc, mv, x0, x1, x2, k);
	}
	if (s == 0 && t >= 3) /* e[t-1] is the light: its emission density */
		mv[1].pf = bdpt_emission_pdf(sc, x0, x1);
}

/* The MIS records of the path made of light vertices l[0..s-1] and eye
 * vertices e[t-1..0], with the densities next to the connection
 * recomputed: pr of l[s-1] and l[s-2], pf of e[t-1] and e[t-2]. With
 * `nee_stored` (the portal integrator, bdpt_weight) a next-event light
 * vertex (s = 1, t >= 2) brings its pn_0 and pr_0 (bdpt_nee), as
 * path_records_part takes them, instead of a second sky lookup. With `pc`
 * (bdpt_strategies) pn_0 comes from the cache of this light subpath, and
 * a next-event sky vertex's from its sample (the same bits). With
 * `window`, only the records mis_path_weight_tails reads: x_{s-3} ..
 * x_{s+2}, and x_0's densities only when s <= 3 (beyond, x_0 and x_1 lie
 * in the light tail). With `cp`, the connection's densities from its
 * evaluation. */
INLINE int bdpt_mis_records(const SceneView *sc, VCRef l, int s, VCRef e, int t, MisVertex *mv, int nee_stored,
			    BdptPnCache *pc, int window, const BdptConnPdf *cp)
{
	GLOBAL const Camera *cam = &sc->params->camera;
	int k = s + t;
	int lo = window ? max(0, s - 3) : 0, hi = window ? min(k - 1, s + 2) : k - 1;
	for (int i = lo; i < s; i++)
		bdpt_record(&mv[i], VAT(l, i));
	for (int i = max(s, lo); i <= hi; i++)
		bdpt_record(&mv[i], VAT(e, k - 1 - i));
	/* The connection's ends scatter through non-delta lobes on this path,
	 * whatever their subpaths sampled next (pbrt does the same). */
	if (s > 0)
		mv[s - 1].delta = 0;
	mv[s].delta = 0;
	if (s > 0 && lo == 0) /* a punctual light (mis.h) */
		mv[0].delta = VREF_DELTA_LIGHT(VAT(l, 0));
	nee_stored = nee_stored && s == 1 && t >= 2;
	if (lo == 0)
		bdpt_records_x0(sc, l, s, e, t, mv, nee_stored, pc);
	if (s == 0)
		return k;
	VTMP(t0);
	VTMP(t1);
	VTMP(t2);
	VTMP(t3);
	const PathVertex *ls = VLOAD(VAT(l, s - 1), t0), *es = VLOAD(VAT(e, t - 1), t1);
	/* Eye side of the connection: pf of e[t-1], then of e[t-2]. */
	if (t >= 2) {
		if (s == 1)
			mv[s].pf = bdpt_emission_pdf(sc, ls, es);
		else
			mv[s].pf = cp ? vertex_density_a(ls, es, cp->l_fwd)
				      : bdpt_pdf_a(sc, ls, VLOAD(VAT(l, s - 2), t2), es, BSDF_IMPORTANCE);
		if (t >= 3) {
			const PathVertex *e2 = VLOAD(VAT(e, t - 2), t3);
			mv[s + 1].pf = cp ? vertex_density_a(es, e2, cp->e_rev) : bdpt_pdf_a(sc, es, ls, e2, BSDF_RADIANCE);
		}
	}
	/* Light side: pr of l[s-1] (from the eye vertex or the camera), then of l[s-2]. */
	if (t == 1) {
		float px, py, cos_c;
		V3 d = v3_sub(ls->p, cam->pos);
		float d2 = v3_len2(d);
		camera_raster(cam, v3_scale(d, 1.0f / sqrt(d2)), &px, &py, &cos_c);
		mv[s - 1].pr = vertex_density_a(es, ls, camera_pdf_w(cam, cos_c));
	} else if (cp) {
		mv[s - 1].pr = vertex_density_a(es, ls, cp->e_fwd);
	} else if (!(nee_stored && ls->pr > 0.0f)) {
		mv[s - 1].pr = bdpt_pdf_a(sc, es, VLOAD(VAT(e, t - 2), t3), ls, BSDF_RADIANCE);
	}
	if (s >= 2) {
		const PathVertex *l2 = VLOAD(VAT(l, s - 2), t2);
		mv[s - 2].pr = cp ? vertex_density_a(ls, l2, cp->l_rev) : bdpt_pdf_a(sc, ls, es, l2, BSDF_IMPORTANCE);
	}
	return k;
}

INLINE int bdpt_mis_path(const SceneView *sc, VCRef l, int s, VCRef e, int t, MisVertex *mv, int nee_stored)
{
	return bdpt_mis_records(sc, l, s, e, t, mv, nee_stored, 0, 0, 0);
}

/* The path's first vertex after x_0 that scatters by a non-delta lobe
 * (mis_first_scatter) for bdpt strategy (s, t): a light vertex before the
 * connection's light end, or that end, or for s = 1 the eye end; for s = 0
 * an eye vertex, or the camera. */
INLINE int bdpt_first_scatter(VCRef l, int s, VCRef e, int t)
{
	int j = 1;
	if (s >= 1)
		while (j < s - 1 && VGETI(VAT(l, j), delta))
			j++;
	else
		while (j < t - 1 && VGETI(VAT(e, t - 1 - j), delta))
			j++;
	return j;
}

/* mis_path_weight of bdpt strategy (s, t) over the strategies of
 * Params.bdpt_conn; from the connection's neighbourhood and the subpaths'
 * tails where they carry them (with `cp`, the connection's densities; 0
 * for s = 0). A path the eye found through a delta vertex at x_1 (s = 0)
 * may hold strategies of more light vertices than the eye tails count
 * (mis.h, mis_eye_tail): the whole path. */
INLINE float bdpt_path_weight(const SceneView *sc, VCRef l, int s, VCRef e, int t, MisVertex *mv, int nee_stored,
			      BdptPnCache *pc, const BdptConnPdf *cp)
{
	int heuristic = sc->params->mis, conn = sc->params->bdpt_conn;
	int first = conn ? bdpt_first_scatter(l, s, e, t) : 1, limit = mis_conn_limit(conn, first);
	if (!(pc && pc->tails) || (s == 0 && first > 1)) {
		int k = bdpt_mis_records(sc, l, s, e, t, mv, nee_stored, pc, 0, 0);
		return mis_path_weight_conn(mv, k, s, heuristic, limit);
	}
	int k = bdpt_mis_records(sc, l, s, e, t, mv, nee_stored, pc, 1, cp);
	float ltail = s >= 3 ? VGETF(VAT(l, s - 3), tail) : 0.0f, etail = t >= 4 ? VGETF(VAT(e, t - 3), tail) : 0.0f;
	return mis_path_weight_tails(mv, k, s, heuristic, limit, ltail, etail);
}

/* Every vertex's MIS tail (mis.h) for the weights of bdpt_strategies:
 * light vertices 0 .. nl - 3 (A_m, for s = m + 3), eye vertices 1 .. ne - 3
 * (B_a, for t = a + 3). x_0's densities as bdpt_mis_records finds them for
 * s >= 3, where x_1, x_2 are l[1], l[2]; pn_0 through the cache. */
INLINE void bdpt_mis_tails(const SceneView *sc, VRef l, int nl, VRef e, int ne, BdptPnCache *pc)
{
	int heuristic = sc->params->mis, conn = sc->params->bdpt_conn;
	MisVertex mv[SUBPATH_MAX];
	float A[SUBPATH_MAX];
	if (nl >= 3) {
		for (int i = 0; i < nl - 2; i++)
			bdpt_record(&mv[i], VAT(l, i));
		mv[0].delta = VREF_DELTA_LIGHT(VAT(l, 0));
		bdpt_records_x0(sc, l, 3, e, 1, mv, 0, pc);
		mis_light_tails(mv, nl - 2, heuristic, conn, A);
		for (int m = 0; m < nl - 2; m++)
			VSETF(VAT(l, m), tail, A[m]);
	}
	float b = 0.0f;
	if (ne >= 4)
		bdpt_record(&mv[0], VAT(e, 0));
	for (int a = 1; a <= ne - 3; a++) {
		bdpt_record(&mv[a], VAT(e, a));
		b = mis_eye_tail(mv, a, heuristic, conn, b);
		VSETF(VAT(e, a), tail, b);
	}
	pc->tails = 1;
}

/* The weight of bdpt strategy (s, t): over the bdpt strategies alone, or,
 * in the portal integrator, over both families (union_mis.h). There, where
 * no edge that an intermediate strategy in use pairs on crosses a portal
 * (path_bdpt_pairs), none of them produces the path and the union sum
 * holds only the bdpt strategies in use, with no crossings or pair
 * densities to find. With light subpaths (every s) that is bdpt's own
 * weight, from bdpt's records (the next-event vertex's stored densities,
 * as path_records_part takes them) by its ratios, without the logs of up
 * to 33 records and an exponential per strategy: equal to the full union
 * weight up to float rounding. Without them (s <= 1) it is the full
 * computation's sum, bit for bit (path_unpaired_weight). test_portal's
 * test_bdpt_weight_shortcut checks both. On window-room-lamp every path
 * from the lamp takes the shortcut; on the sun scenes every path of 6 or
 * more vertices, whose first edge, through the window, is then no
 * pairing edge (lo = k - 5 with the sky's set, mis_pair_edges). */
CALLED float bdpt_weight_cached(const SceneView *sc, VCRef l, int s, VCRef e, int t, BdptPnCache *pc,
				const BdptConnPdf *cp)
{
	MisVertex mv[2 * SUBPATH_MAX];
	if (PARAMS_INTEGRATOR(sc->params) == INTEGRATOR_PORTAL) {
		PathRef P;
		MisStrategy cur = {1, s, 0, 0};
		path_ref(&P, l, s, 0, 0, 0, 0, e, t);
		MisPortalSet set = path_portal_set(sc->params);
		int n = mis_horizon(set, P.k);
		if (path_bdpt_pairs(sc, &P, set, n))
			return path_union_weight(sc, &P, cur);
		if (!set.light_paths)
			return path_unpaired_weight(sc, &P, set, n, cur);
		return bdpt_path_weight(sc, l, s, e, t, mv, 1, pc, cp);
	}
	return bdpt_path_weight(sc, l, s, e, t, mv, 0, pc, cp);
}

INLINE float bdpt_weight(const SceneView *sc, VCRef l, int s, VCRef e, int t)
{
	return bdpt_weight_cached(sc, l, s, e, t, 0, 0);
}

/* Beer-Lambert over the segment between vertices a and b where it runs
 * inside a solid that either end lies on (geom/visibility.h). */
INLINE V3 bdpt_absorption(const SceneView *sc, const PathVertex *a, const PathVertex *b)
{
	V3 d = v3_sub(b->p, a->p);
	float len = v3_len(d);
	if (a->type == VERTEX_SURFACE && volume_inside(sc, a->material, a->ng, d))
		return volume_attenuation(sc, a->material, a->ng, d, len);
	if (b->type == VERTEX_SURFACE)
		return volume_attenuation(sc, b->material, b->ng, v3_neg(d), len);
	return v3(1.0f, 1.0f, 1.0f);
}

/* What the segment between two vertices lets through (either may be the
 * camera, which sits in free space and is not offset): 0 if occluded, the
 * panes' transmittance and a solid's absorption. */
INLINE V3 bdpt_visible(const SceneView *sc, const PathVertex *a, const PathVertex *b)
{
	if (a->type == VERTEX_CAMERA || b->type == VERTEX_CAMERA) {
		const PathVertex *c = a->type == VERTEX_CAMERA ? a : b, *v = a->type == VERTEX_CAMERA ? b : a;
		V3 d = v3_sub(c->p, v->p);
		float len = v3_len(d);
		if (!(len > 0.0f))
			return v3(0.0f, 0.0f, 0.0f);
		d = v3_scale(d, 1.0f / len);
		return ray_transmittance(sc, ray_offset(v->p, v->ng, d), d, len * (1.0f - 1e-4f));
	}
	V3 T = segment_transmittance(sc, a->p, a->ng, b->p, b->ng);
	return v3_is_zero(T) ? T : v3_mul(T, bdpt_absorption(sc, a, b));
}

/* f (with the shading-normal correction on light subpaths) times the
 * shading cosine toward wi, at a surface vertex v whose subpath
 * predecessor lies along v->wo, from the BSDF the vertex keeps; and the
 * solid-angle density *pdf_w of that BSDF sampling wi. */
INLINE V3 bdpt_scatter_pdf(const PathVertex *v, V3 wi, int mode, float *pdf_w)
{
	V3 f = bsdf_eval_fwd(&v->bs, v->wo, wi, mode, pdf_w);
	float k = fabs(v3_dot(v->ns, wi));
	if (mode == BSDF_IMPORTANCE)
		k *= vertex_shading_correction(v, v->wo, wi);
	return v3_scale(f, k);
}

INLINE V3 bdpt_scatter(const PathVertex *v, V3 wi, int mode)
{
	float pdf_w;
	return bdpt_scatter_pdf(v, wi, mode, &pdf_w);
}

/* The solid-angle density of v's BSDF sampling its subpath predecessor
 * (along v->wo) from direction w: a connection's rev density, found only
 * once the connection is known to be unoccluded (most are not, in
 * door-ajar). */
INLINE float bdpt_rev_pdf(const PathVertex *v, V3 w) { return bsdf_pdf_w(&v->bs, w, v->wo); }

/* A light subpath from punctual light i (chosen with probability pf):
 * from a point or spot light in a direction by punctual_dir_sample (u3,
 * u4), its intensity windowed by the first hit's distance; from a
 * directional light along a line by line_sample (u1, u3, u4), parallel
 * rays whose density is per perpendicular area. */
INLINE int bdpt_punctual_subpath(const SceneView *sc, VRef l, int i, float pf, float u1, float u3, float u4,
				 int max_verts, Rng *rng)
{
	GLOBAL const PunctualLight *pl = &sc->punctual[i];
	VTMP(yt);
	PathVertex *y = VEDIT(VAT(l, 0), yt);
	y->tri = i;
	y->pf = pf;
	if (!(pf > 0.0f))
		return 0;
	y->beta = v3(1.0f / pf, 1.0f / pf, 1.0f / pf);
	if (pl->type == LIGHT_DIRECTIONAL) {
		V3 o;
		float pdf_perp;
		y->type = VERTEX_SUN;
		y->p = v3_neg(pl->dir);
		y->ng = y->ns = y->wo = pl->dir;
		VCOMMIT(VAT(l, 0), y);
		if (!line_sample(sc, pl->dir, pl->disk_radius, u1, u3, u4, &o, &pdf_perp))
			return 1;
		V3 beta = v3_scale(pl->intensity, 1.0f / (pf * pdf_perp));
		return vertex_walk(sc, l, 1, max_verts, o, pl->dir, beta, pdf_perp, 1, 1, 0, rng);
	}
	y->type = VERTEX_PUNCTUAL;
	y->p = pl->pos;
	V3 dir = punctual_dir_sample(pl, u3, u4);
	float pdf_dir = punctual_dir_pdf(pl, dir);
	y->ng = y->ns = y->wo = dir;
	VCOMMIT(VAT(l, 0), y);
	if (!(pdf_dir > 0.0f) || max_verts < 2 ||
	    !vertex_trace(sc, l, 1, pl->pos, dir, v3(1.0f, 1.0f, 1.0f), pdf_dir, 0, 1, 0, rng))
		return 1;
	/* I(w) window(d) cos / d^2 over (pf pdf_dir cos / d^2), times the panes
	 * the ray crossed (the beta vertex_trace kept). */
	V3 beta1 = v3_scale(punctual_intensity(pl, dir, v3_len(v3_sub(VGET3(VAT(l, 1), p), pl->pos))),
			    1.0f / (pf * pdf_dir));
	beta1 = v3_mul(beta1, VGET3(VAT(l, 1), beta));
	VSET3(VAT(l, 1), beta, beta1);
	if (v3_is_zero(beta1))
		return 1;
	return vertex_extend(sc, l, 2, max_verts, 1, 0, fmax(v3_maxc(beta1), 1e-30f), rng);
}

/* Traces the light subpath into l[]; returns its vertex count (0 if the
 * scene has nothing to start from). */
CALLED int bdpt_light_subpath(const SceneView *sc, VRef l, int max_verts, Rng *rng)
{
	GLOBAL const Params *prm = sc->params;
	float ps = prm->env_pdf_select;
	float u_sel = rng_f(rng), u1 = rng_f(rng), u2 = rng_f(rng), u3 = rng_f(rng), u4 = rng_f(rng);
	if (max_verts < 1)
		return 0;
	VTMP(yt);
	PathVertex *y = VNEW(VAT(l, 0), yt);
	y->delta = 0;
	y->pr = 0.0f;
	y->base = v3(0.0f, 0.0f, 0.0f);
	y->material = -1;
	if (u_sel < ps) {
		float pdf_w;
		V3 dir;
		V3 Le = env_light_sample(sc, u1, u2, &dir, &pdf_w);
		if (!(pdf_w > 0.0f))
			return 0;
		y->type = VERTEX_ENV;
		y->p = dir;
		y->ng = y->ns = y->wo = v3_neg(dir);
		y->tri = -1;
		y->pf = ps * pdf_w;
		y->beta = v3(1.0f / y->pf, 1.0f / y->pf, 1.0f / y->pf);
		V3 o;
		float pdf_perp;
		if (env_lines_through_portals(sc)) {
			/* A sky image's line along -dir as a directional light's (lights.h,
			 * line_sample), u_sel's rest choosing the disk or a portal. */
			VCOMMIT(VAT(l, 0), y);
			if (!line_sample(sc, v3_neg(dir), prm->scene_radius, u_sel / ps, u3, u4, &o, &pdf_perp))
				return 1;
		} else {
			/* Uniform on the disk of the scene's radius. */
			float r = prm->scene_radius, dx, dy;
			V3 t, b;
			v3_basis(dir, &t, &b);
			sample_concentric_disk(u3, u4, &dx, &dy);
			o = v3_add(v3_add(prm->scene_center, v3_scale(dir, r)),
				   v3_add(v3_scale(t, dx * r), v3_scale(b, dy * r)));
			pdf_perp = 1.0f / (AJAR_PI * r * r);
			VCOMMIT(VAT(l, 0), y);
		}
		V3 beta = v3_scale(Le, 1.0f / (y->pf * pdf_perp));
		return vertex_walk(sc, l, 1, max_verts, o, v3_neg(dir), beta, pdf_perp, 1, 1, 0, rng);
	}
	float u = fmin((u_sel - ps) / (1.0f - ps), 0.99999994f), pdf_a;
	V3 p, n;
	int k = light_pick(sc, u);
	if (k < 0)
		return 0;
	if (k >= prm->num_emitters) {
		int i = k - prm->num_emitters;
		VCOMMIT(VAT(l, 0), y);
		return bdpt_punctual_subpath(sc, l, i, (1.0f - ps) * sc->punctual[i].pdf_select, u1, u3, u4, max_verts,
					     rng);
	}
	int tri = emitter_point(sc, k, u1, u2, &p, &n, &pdf_a);
	if (!(pdf_a > 0.0f))
		return 0;
	y->type = VERTEX_LIGHT;
	y->p = p;
	y->ng = y->ns = y->wo = n;
	y->tri = tri;
	y->pf = (1.0f - ps) * pdf_a;
	y->beta = v3(1.0f / y->pf, 1.0f / y->pf, 1.0f / y->pf);
	V3 t, b;
	v3_basis(n, &t, &b);
	V3 lc = sample_cosine_hemisphere(u3, u4);
	VCOMMIT(VAT(l, 0), y);
	if (!(lc.z > 0.0f))
		return 1;
	V3 dir = v3_from_local(lc, t, b, n);
	V3 Le = emitter_radiance(sc, tri, p, dir);
	/* Le cos / (pf_0 cos / pi) */
	V3 beta = v3_scale(Le, AJAR_PI / y->pf);
	return vertex_walk(sc, l, 1, max_verts, ray_offset(p, n, dir), dir, beta, lc.z * AJAR_INV_PI, 0, 1, 0,
			   rng);
}

/* Where a sample's contributions go: the pixel's own sum (eye strategies),
 * the splat film (t = 1), and optionally one layer per strategy (s, t) for
 * paths of up to strategy_len segments: layer (n - 1)(n + 2)/2 + s for
 * n = s + t - 1 segments, each a width x height x 3 fixed-point image. */
typedef struct {
	GLOBAL long *splat;
	GLOBAL long *layers; /* 0 when strategy_len is 0 */
	uint pixel;
	V3 L;                /* this pixel's eye-strategy sum */
} BdptFilm;

INLINE void film_add(GLOBAL long *film, uint pixel, V3 c, Rng *rng)
{
	atom_add(&film[3 * pixel + 0], film_fixed(c.x, rng_pcg_f(rng)));
	atom_add(&film[3 * pixel + 1], film_fixed(c.y, rng_pcg_f(rng)));
	atom_add(&film[3 * pixel + 2], film_fixed(c.z, rng_pcg_f(rng)));
}

/* Records the unweighted contribution c of a path of n segments with MIS
 * weight w: into this sample's pixel sum, or, when it reached the camera
 * by a connection (t = 1), splatted into `pixel`; and into strategy layer
 * `layer` when layers are kept for length n. */
INLINE void bdpt_film_add(const SceneView *sc, BdptFilm *out, int n, int layer, int splat, V3 c, float w, uint pixel,
			  Rng *rng)
{
	GLOBAL const Params *prm = sc->params;
	if (n < prm->min_depth)
		return;
	V3 cw = v3_scale(c, w);
	if (splat)
		film_add(out->splat, pixel, cw, rng);
	else
		out->L = v3_add(out->L, cw);
	if (n <= prm->strategy_len) {
		uint npix = (uint)(prm->camera.width * prm->camera.height);
		film_add(out->layers + 3 * (ulong)npix * (uint)layer, pixel, prm->strategy_unweighted ? c : cw, rng);
	}
}

/* Bdpt strategy (s, t): a path of s + t - 1 segments. */
INLINE void bdpt_add(const SceneView *sc, BdptFilm *out, int s, int t, V3 c, float w, uint pixel, Rng *rng)
{
	int n = s + t - 1;
	bdpt_film_add(sc, out, n, bdpt_layer(n, s), t == 1, c, w, pixel, rng);
}

/* Connecting light vertex y (s >= 2) to eye vertex z (t >= 2), both on
 * surfaces: f_y G f_z without the betas, or 0 if occluded or either BSDF
 * is black toward the other; and, with cp, the densities the MIS weight
 * needs. */
CALLED V3 bdpt_connect_pdf(const SceneView *sc, const PathVertex *y, const PathVertex *z, BdptConnPdf *cp)
{
	V3 d = v3_sub(z->p, y->p);
	float d2 = v3_len2(d);
	if (!(d2 > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	V3 w = v3_scale(d, 1.0f / sqrt(d2));
	float pdf_y, pdf_z;
	V3 fy = bdpt_scatter_pdf(y, w, BSDF_IMPORTANCE, &pdf_y);
	if (v3_is_zero(fy))
		return fy;
	V3 fz = bdpt_scatter_pdf(z, v3_neg(w), BSDF_RADIANCE, &pdf_z);
	if (v3_is_zero(fz))
		return v3(0.0f, 0.0f, 0.0f);
	V3 T = bdpt_visible(sc, y, z);
	if (v3_is_zero(T))
		return T;
	if (cp) {
		cp->l_fwd = pdf_y;
		cp->e_fwd = pdf_z;
		cp->l_rev = bdpt_rev_pdf(y, w);
		cp->e_rev = bdpt_rev_pdf(z, v3_neg(w));
	}
	return v3_scale(v3_mul(v3_mul(fy, fz), T), 1.0f / d2);
}

INLINE V3 bdpt_connect(const SceneView *sc, const PathVertex *y, const PathVertex *z)
{
	return bdpt_connect_pdf(sc, y, z, 0);
}

/* Light-side vertex y (its subpath predecessor along y->wo; `origin` if it
 * is a light subpath's first vertex, which emits rather than scatters)
 * connected to the camera cam_v: the contribution without MIS weight, and
 * the pixel it lands in; 0 if it misses the image or is occluded. */
INLINE V3 bdpt_to_camera_pdf(const SceneView *sc, const PathVertex *y, int origin, const PathVertex *cam_v,
			     uint *pixel, BdptConnPdf *cp)
{
	GLOBAL const Camera *cam = &sc->params->camera;
	V3 zero = v3(0.0f, 0.0f, 0.0f);
	V3 d = v3_sub(cam->pos, y->p);
	float d2 = v3_len2(d), px, py, cos_c;
	/* A punctual light itself is never seen (as in pt, whose rays never hit it). */
	if (!(d2 > 0.0f) || vertex_infinite(y) || (origin && vertex_delta_light(y)))
		return zero;
	V3 w = v3_scale(d, 1.0f / sqrt(d2));
	if (!camera_raster(cam, v3_neg(w), &px, &py, &cos_c))
		return zero;
	V3 fy = origin ? v3_scale(bdpt_emitted(sc, y, w), fabs(v3_dot(y->ng, w))) : bdpt_scatter(y, w, BSDF_IMPORTANCE);
	if (v3_is_zero(fy))
		return zero;
	V3 T = bdpt_visible(sc, y, cam_v);
	if (v3_is_zero(T))
		return zero;
	fy = v3_mul(fy, T);
	if (cp && !origin)
		cp->l_rev = bdpt_rev_pdf(y, w);
	*pixel = (uint)py * (uint)cam->width + (uint)px;
	/* We G = cos_c / (A cos_c^4) / d^2 for the pinhole (camera.h). */
	return v3_scale(v3_mul(y->beta, fy), camera_pdf_w(cam, cos_c) / d2);
}

INLINE V3 bdpt_to_camera(const SceneView *sc, const PathVertex *y, int origin, const PathVertex *cam_v, uint *pixel)
{
	return bdpt_to_camera_pdf(sc, y, origin, cam_v, pixel, 0);
}

/* Light vertex s - 1 seen by the camera: splats its weighted contribution. */
CALLED void bdpt_light_to_camera(const SceneView *sc, VCRef l, int s, VCRef cam_v, BdptFilm *out, BdptPnCache *pc,
				 Rng *rng)
{
	uint pixel;
	VTMP(yt);
	VTMP(ct);
	BdptConnPdf cp, *cpp = pc->tails ? &cp : 0;
	V3 c = bdpt_to_camera_pdf(sc, VLOAD(VAT(l, s - 1), yt), s == 1, VLOAD(cam_v, ct), &pixel, cpp);
	if (!v3_is_zero(c))
		bdpt_add(sc, out, s, 1, c, bdpt_weight_cached(sc, l, s, cam_v, 1, pc, cpp), pixel, rng);
}

/* Traces the eye subpath through raster point (px, py) into e[]; e[0] is
 * the camera. Returns its vertex count. */
CALLED int bdpt_eye_subpath(const SceneView *sc, float px, float py, VRef e, int max_verts, Rng *rng)
{
	GLOBAL const Camera *cam = &sc->params->camera;
	VTMP(zt);
	PathVertex *z0 = VNEW(VAT(e, 0), zt);
	z0->type = VERTEX_CAMERA;
	z0->p = cam->pos;
	z0->ng = z0->ns = z0->wo = cam->forward;
	z0->beta = v3(1.0f, 1.0f, 1.0f);
	z0->base = v3(0.0f, 0.0f, 0.0f);
	z0->pf = 0.0f;
	z0->pr = 1.0f;
	z0->delta = 0;
	z0->material = z0->tri = -1;
	V3 dir = camera_ray_dir(cam, px, py);
	float cos_c = v3_dot(dir, cam->forward);
	VCOMMIT(VAT(e, 0), z0);
	return vertex_walk(sc, e, 1, max_verts, cam->pos, dir, z0->beta, camera_pdf_w(cam, cos_c), 0, 0, 1, rng);
}

/* The light vertex of a next-event sample (s = 1). Its pf holds the
 * sample's own density (solid angle for the environment, area for
 * emitters); MIS records recompute pf_0 and pn_0 from the path
 * (vertex_density.h, bdpt_light_records). */
INLINE void bdpt_light_vertex(PathVertex *y, const LightSample *ls)
{
	int sun = ls->delta && !(ls->dist < AJAR_INF);
	y->type = ls->is_env ? VERTEX_ENV : sun ? VERTEX_SUN : ls->delta ? VERTEX_PUNCTUAL : VERTEX_LIGHT;
	y->p = ls->is_env || sun ? ls->wi : ls->p;
	y->ng = y->ns = y->wo = ls->n;
	y->base = v3(0.0f, 0.0f, 0.0f);
	y->beta = v3(1.0f, 1.0f, 1.0f);
	y->delta = 0;
	y->material = -1;
	y->tri = ls->delta ? ls->light : ls->tri; /* the portal direction density needs the emitter */
	y->cross = 0;
	/* A punctual light's: the probability of its choice. */
	y->pf = ls->is_env || ls->delta ? ls->pdf_w : ls->pdf_w * fabs(v3_dot(ls->n, ls->wi)) / (ls->dist * ls->dist);
	y->pr = 0.0f;
}

/* What reaches surface vertex z from the light sample: 0 if occluded, the
 * panes' transmittance and a solid's absorption. */
INLINE V3 bdpt_nee_visible(const SceneView *sc, const PathVertex *z, const LightSample *ls)
{
	if (ls->is_env || !(ls->dist < AJAR_INF)) /* the sky, a directional light */
		return ray_transmittance(sc, ray_offset(z->p, z->ng, ls->wi), ls->wi, AJAR_INF);
	V3 T = segment_transmittance(sc, z->p, z->ng, ls->p, ls->n);
	return v3_is_zero(T) ? T : v3_mul(T, volume_attenuation(sc, z->material, z->ng, ls->wi, ls->dist));
}

/* Next-event estimation at eye-side surface vertex z, whose neighbour on
 * the eye side is `from`: the light sample's vertex
 * *y (with pr, z's density of sampling it, which MIS records need) and the
 * contribution from z's throughput on, 0 if occluded. */
CALLED V3 bdpt_nee_conn(const SceneView *sc, const PathVertex *z, const PathVertex *from, PathVertex *y, Rng *rng,
			BdptConnPdf *cp)
{
	LightSample ls;
	float u0, u1, u2, pdf_w;
	rng_nee3(rng, &u0, &u1, &u2);
	V3 zero = v3(0.0f, 0.0f, 0.0f);
	if (!light_sample(sc, z->p, vertex_nee_normal(z, from), u0, u1, u2, &ls) || v3_is_zero(ls.Le))
		return zero;
	bdpt_light_vertex(y, &ls);
	V3 f = bdpt_scatter_pdf(z, ls.wi, BSDF_RADIANCE, &pdf_w);
	if (v3_is_zero(f))
		return zero;
	V3 T = bdpt_nee_visible(sc, z, &ls);
	if (v3_is_zero(T))
		return zero;
	f = v3_mul(f, T);
	y->pr = vertex_density_a(z, y, pdf_w);
	if (cp) {
		cp->e_fwd = pdf_w;
		cp->e_rev = bdpt_rev_pdf(z, ls.wi);
	}
	return v3_scale(v3_mul(v3_mul(z->beta, f), ls.Le), 1.0f / ls.pdf_w);
}

INLINE V3 bdpt_nee(const SceneView *sc, const PathVertex *z, const PathVertex *from, PathVertex *y, Rng *rng)
{
	return bdpt_nee_conn(sc, z, from, y, rng, 0);
}

#ifndef AJAR_NO_PANES
/* Whether the eye walk's hit of the sky at e[t-1] left a pane's mirror
 * for it after a vertex that sampled that mirrored sky (pane_mirror.h):
 * then it counts there, by bdpt_pane_mirror. */
INLINE int bdpt_pane_mirror_family(const SceneView *sc, VCRef e, int t)
{
	if (!sc->params->num_pane_planes || sc->params->cross_filter || t < 4 ||
	    VGETI(VAT(e, t - 2), type) != VERTEX_SURFACE || !VGETI(VAT(e, t - 2), delta) ||
	    VGETI(VAT(e, t - 3), type) != VERTEX_SURFACE || VGETI(VAT(e, t - 3), delta))
		return 0;
	VTMP(ht);
	VTMP(xt);
	const PathVertex *h = VLOAD(VAT(e, t - 2), ht);
	int i = pane_mirror_plane(sc, h->tri, h->p, h->ng, &h->bs);
	if (i < 0)
		return 0;
	const PathVertex *x = VLOAD(VAT(e, t - 3), xt);
	return !bsdf_is_delta(&x->bs) && pane_sky_side(sc, i, x->p);
}

/* The sky mirrored in the panes whose sky side eye vertex e[t-1] lies on
 * (pane_mirror.h), each a path of the eye vertices, the pane point and
 * the sky, weighted as the eye walk's hit of that sky (s = 0, t + 2)
 * would be: its two vertices are put in e[t], e[t + 1] for the weight and
 * the subpath's own put back after. */
INLINE void bdpt_pane_mirror(const SceneView *sc, VCRef l, VRef e, int t, BdptFilm *out, Rng *rng)
{
	GLOBAL const Params *prm = sc->params;
	VTMP(zt);
	VTMP(ft);
	const PathVertex *z = VLOAD(VAT(e, t - 1), zt);
	if (z->type != VERTEX_SURFACE || bsdf_is_delta(&z->bs))
		return;
	V3 n_nee = vertex_nee_normal(z, VLOAD(VAT(e, t - 2), ft));
	for (int i = 0; i < prm->num_pane_planes; i++) {
		if (!pane_sky_side(sc, i, z->p))
			continue;
		float u0, u1, u2, pdf_m, pdf_z;
		rng_f3(rng, &u0, &u1, &u2);
		V3 wx, wsky;
		Surface hs;
		PathVertex h, sky;
		V3 c = pane_mirror_sample(sc, i, z->p, z->ng, n_nee, u0, u1, u2, &wx, &wsky, &pdf_m, &hs, &h.bs);
		if (v3_is_zero(c))
			continue;
		V3 f = bdpt_scatter_pdf(z, wx, BSDF_RADIANCE, &pdf_z);
		if (v3_is_zero(f))
			continue;
		h.type = VERTEX_SURFACE;
		h.p = hs.p;
		h.ng = hs.ng;
		h.ns = hs.ns;
		h.wo = v3_neg(wx);
		h.beta = z->beta;
		h.base = surface_base_color(sc, &hs);
		h.pf = 0.0f;
		h.pr = vertex_density_a(z, &h, pdf_z);
		h.delta = 1;
		h.material = hs.material;
		h.tri = hs.tri;
		h.cross = portal_crossings(sc, z->p, hs.p, 0);
		h.w0 = h.p;
		h.w0_tri = -1;
		h.tail = 0.0f;
		sky.type = VERTEX_ENV;
		sky.p = wsky;
		sky.ng = sky.ns = sky.wo = v3_neg(wsky);
		sky.beta = z->beta;
		sky.base = v3(0.0f, 0.0f, 0.0f);
		sky.pf = sky.pr = 0.0f; /* after a delta vertex */
		sky.delta = 0;
		sky.material = sky.tri = -1;
		sky.cross = portal_crossings(sc, hs.p, wsky, 1);
		sky.w0 = sky.p;
		sky.w0_tri = -1;
		sky.tail = 0.0f;
		sky.bs = h.bs;
		VTMP(s0);
		VTMP(s1);
		PathVertex keep0 = *VLOAD(VAT(e, t), s0), keep1 = *VLOAD(VAT(e, t + 1), s1); /* copies */
		float z_pf = VGETF(VAT(e, t - 1), pf);
		int z_delta = VGETI(VAT(e, t - 1), delta);
		VSETF(VAT(e, t - 1), pf, 0.0f); /* from the pane's mirror: a delta density */
		VSETI(VAT(e, t - 1), delta, 0);
		VSTORE(VAT(e, t), &h);
		VSTORE(VAT(e, t + 1), &sky);
		/* From the whole path's records: e[t - 1]'s eye tail holds its
		 * own subpath's densities. */
		float w = bdpt_weight_cached(sc, l, 0, e, t + 2, 0, 0);
		VSTORE(VAT(e, t), &keep0);
		VSTORE(VAT(e, t + 1), &keep1);
		VSETF(VAT(e, t - 1), pf, z_pf);
		VSETI(VAT(e, t - 1), delta, z_delta);
		bdpt_add(sc, out, 0, t + 2, v3_mul(v3_mul(z->beta, f), c), w, out->pixel, rng);
	}
}
#endif

/* Every bdpt strategy of one light and one eye subpath: adds the eye
 * strategies to out->L and splats light tracing (t = 1). */
CALLED void bdpt_strategies(const SceneView *sc, VRef l, int nl, VRef e, int ne, BdptFilm *out, Rng *rng)
{
	int depth = sc->params->max_depth, conn = sc->params->bdpt_conn;
	BdptPnCache pc;
	pc.have = pc.tails = 0;
	/* The tails and the connections' densities serve bdpt's own weights;
	 * portal without light subpaths weighs by the union (union_mis.h) and
	 * would only pay for them. */
	if (sc->params->light_paths)
		bdpt_mis_tails(sc, l, nl, e, ne, &pc);
	BdptConnPdf cp, *cpp = pc.tails ? &cp : 0;

	/* t = 1: every light vertex to the camera. */
	for (int s = 1; s <= nl && s <= depth; s++)
		if (s > 1 || !VREF_DELTA_LIGHT(VAT(l, 0))) /* a punctual light is not seen */
			bdpt_light_to_camera(sc, l, s, VAT(e, 0), out, &pc, rng);

	for (int t = 2; t <= ne; t++) {
		VTMP(zt);
		VTMP(ft);
		VTMP(lt);
		const PathVertex *z = VLOAD(VAT(e, t - 1), zt);
		/* s = 0: the eye subpath found the light (a sky mirrored in a pane
		 * counts at the vertex that sampled it, bdpt_pane_mirror). */
#ifndef AJAR_NO_PANES
		if (z->type == VERTEX_ENV && bdpt_pane_mirror_family(sc, e, t))
			break;
#endif
		if (z->type == VERTEX_ENV || sc->tris[z->tri].emitter >= 0) {
			V3 Le = bdpt_emitted(sc, z, z->wo);
			if (!v3_is_zero(Le))
				bdpt_add(sc, out, 0, t, v3_mul(z->beta, Le), bdpt_weight_cached(sc, l, 0, e, t, &pc, 0),
					 out->pixel, rng);
		}
		if (z->type == VERTEX_ENV)
			break;
		if (t > depth) /* no room for another vertex */
			continue;
		/* s = 1: next-event estimation with a fresh light sample. */
		{
			PathVertex y;
			V3 c = bdpt_nee_conn(sc, z, VLOAD(VAT(e, t - 2), ft), &y, rng, cpp);
			if (!v3_is_zero(c))
				bdpt_add(sc, out, 1, t, c, bdpt_weight_cached(sc, VNEE(e, y), 1, e, t, &pc, cpp),
					 out->pixel, rng);
		}
#ifndef AJAR_NO_PANES
		if (sc->params->num_pane_planes && !sc->params->cross_filter && t + 1 <= depth)
			bdpt_pane_mirror(sc, l, e, t, out, rng);
#endif
		/* s >= 2: light vertex s-1 to eye vertex t-1, in the set of conn
		 * (mis.h, mis_conn_in_set). */
		for (int s = 2; s <= nl && s + t - 1 <= depth &&
				(conn == 0 || s <= mis_conn_limit(conn, bdpt_first_scatter(l, s, e, t)));
		     s++) {
			const PathVertex *ly = VLOAD(VAT(l, s - 1), lt);
			V3 c = bdpt_connect_pdf(sc, ly, z, cpp);
			if (v3_is_zero(c))
				continue;
			bdpt_add(sc, out, s, t, v3_mul(v3_mul(ly->beta, c), z->beta),
				 bdpt_weight_cached(sc, l, s, e, t, &pc, cpp), out->pixel, rng);
		}
	}
}

/* One bdpt pixel sample at raster (px, py) of pixel out->pixel. l and e
 * hold SUBPATH_MAX vertices each. */
INLINE void bdpt_sample(const SceneView *sc, float px, float py, VRef l, VRef e, BdptFilm *out, Rng *rng)
{
	int depth = sc->params->max_depth;
	Rng lr = rng_fork(rng); /* the light subpath's own stream */
	int nl = bdpt_light_subpath(sc, l, depth, &lr);
	int ne = bdpt_eye_subpath(sc, px, py, e, depth + 1, rng);
	bdpt_strategies(sc, l, nl, e, ne, out, rng);
}
#endif
