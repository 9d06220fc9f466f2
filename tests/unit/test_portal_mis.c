/* test_portal_mis.c — the portal integrator's MIS, checked on the host with
 * the kernels' own code (tests/support/kernel_host.h), against design.md:
 * for random paths of every strategy (bdpt and intermediate) in scenes
 * with one, two and four portals, under skies with a sun and with punctual
 * lights, the kernel's records equal an independent oracle's
 * (tests/support/mis_oracle.h: densities, portal crossings counted in
 * double precision, pair densities), and the weights of all strategies
 * that can produce each path, every crossing of every edge counted, sum to
 * 1 for the power and the balance heuristic. Paths that cross portals on
 * two consecutive edges (the note's portal-surface-portal sequence) are
 * among them, and their weights still sum to 1: the other strategies cover
 * what each intermediate strategy cannot. The weights the kernel joins
 * from a path's two ends (path_join_weight) and its bdpt weights
 * (bdpt_weight's shortcut) equal the whole path's union weight. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mis_oracle.h"
#include "portal_scenes.h"
#include "testutil.h"

typedef struct {
	int paths, portal_paths, consecutive, records, off, weights, woff;
} MisStats;

/* Checks one assembled path: kernel records against the oracle, and the
 * union weights summing to 1. */
static void check_path(const SceneView *sc, const PathRef *P, MisStats *st)
{
	int k = P->k;
	PathVertex x[4 * SUBPATH_MAX];
	int dl[4 * SUBPATH_MAX], cross[4 * SUBPATH_MAX], ocross[4 * SUBPATH_MAX];
	float lps[4 * SUBPATH_MAX], lcur;
	MisVertex rec[4 * SUBPATH_MAX], orc[4 * SUBPATH_MAX];
	for (int i = 0; i < k; i++) {
		x[i] = *P->x[i];
		dl[i] = x[i].delta;
	}
	dl[0] = dl[k - 1] = 0;
	if (P->c1 >= 0)
		dl[P->c1] = dl[P->c1 + 1] = 0;
	if (P->c2 >= 0)
		dl[P->c2] = dl[P->c2 + 1] = 0;
	if (x[0].type == VERTEX_SURFACE)
		x[0].type = VERTEX_LIGHT;
	/* The kernel builds the records its weights read: the first n
	 * vertices, and the edges below s_max + sp_max. */
	GLOBAL const Params *prm = sc->params;
	MisPortalSet set = path_portal_set(prm);
	int n = mis_horizon(set, k), elo, ehi;
	mis_pair_edges(set, k, n, &elo, &ehi);
	path_records(sc, P, MIS_POWER, set, n, rec, cross, lps, &lcur);
	oracle(sc, x, dl, k, orc);
	for (int i = 0; i < n; i++) {
		if (i == k - 1)
			continue; /* the camera's pf is never used */
		double diff = rel_diff(rec[i].pr, orc[i].pr);
		/* else no weight reads pf; pf_0 only strategies with s >= 2 */
		if (mis_needs_pf(set) && (i > 0 || set.light_paths || set.s_max >= 2 || k < 3))
			diff = fmax(diff, rel_diff(rec[i].pf, orc[i].pf));
		if (i == 0)
			diff = fmax(diff, rel_diff(rec[0].pn, orc[0].pn));
		/* Narrow glossy lobes amplify the ray-offset direction change
		 * (mis_oracle.h), most where an edge near the vertex is short
		 * (near_contact): such records are not counted, as one such path
		 * repeats in many strategies. Bugs are systematic and fail the 1%
		 * count. */
		int contact = near_contact(x, k, i, sc->params->scene_radius);
		st->records += !contact;
		st->off += diff > 1e-2 && !contact;
		if ((diff > 0.5 && !contact) || rec[i].delta != orc[i].delta)
			fail_msg("path (s=%d, s'=%d, t'=%d, t=%d), vertex %d of %d: kernel pf %g pr %g pn %g delta %d, "
				 "oracle pf %g pr %g pn %g delta %d",
				 P->s, P->sp, P->tp, P->t, i, k, rec[i].pf, rec[i].pr, i ? 0 : rec[0].pn, rec[i].delta,
				 orc[i].pf, orc[i].pr, i ? 0 : orc[0].pn, orc[i].delta);
	}
	/* Crossings and pair densities from the oracle; each crossing is a
	 * strategy of its own. */
	double lpc[4 * SUBPATH_MAX][4], pts[4][3];
	int any = 0;
	float lcur_o = 0;
	for (int i = 0; i + 1 < k; i++) {
		ocross[i] = oracle_pair_logs(sc, &x[i], &x[i + 1], lpc[i], i == P->pair ? pts : NULL, 4);
		if (i == P->pair) {
			if (ocross[i] == 0) { /* w_0 at a portal's border, lost to rounding */
				ocross[i] = 1;
				lpc[i][0] = 0;
				float dummy[4 * SUBPATH_MAX];
				MisVertex mv2[4 * SUBPATH_MAX];
				int cr2[4 * SUBPATH_MAX];
				path_records(sc, P, MIS_POWER, set, n, mv2, cr2, dummy, &lcur_o);
				lpc[i][0] = lcur_o;
			}
			/* The current strategy's own crossing: the one nearest w_0. */
			double best = 1e30;
			for (int c = 0; c < ocross[i] && c < 4; c++) {
				double dx = pts[c][0] - x[i].w0.x, dy = pts[c][1] - x[i].w0.y, dz = pts[c][2] - x[i].w0.z;
				if (dx * dx + dy * dy + dz * dz < best) {
					best = dx * dx + dy * dy + dz * dz;
					lcur_o = (float)lpc[i][c];
				}
			}
		}
		if (i >= elo && i < ehi && ocross[i] != cross[i] && !near_contact(x, k, i, sc->params->scene_radius))
			fail_msg("path (s=%d, s'=%d, t'=%d, t=%d): edge %d crosses %d portals, kernel says %d", P->s, P->sp,
				 P->tp, P->t, i, ocross[i], cross[i]);
		any += ocross[i] > 0;
		if (i > 0 && ocross[i] > 0 && ocross[i - 1] > 0)
			st->consecutive++;
	}
	for (int heur = 0; heur < 2; heur++) {
		double beta = heur == MIS_BALANCE ? 1 : 2;
		float lpsum[4 * SUBPATH_MAX];
		for (int i = 0; i + 1 < k; i++) {
			double sum = 0;
			for (int c = 0; c < ocross[i] && c < 4; c++)
				sum += exp(beta * lpc[i][c]);
			lpsum[i] = ocross[i] ? (float)log(sum) : -AJAR_INF;
		}
		/* The kernel's own pair densities for this heuristic agree. */
		{
			MisVertex mv2[4 * SUBPATH_MAX];
			int cr2[4 * SUBPATH_MAX];
			float ks[4 * SUBPATH_MAX], kcur;
			path_records(sc, P, heur, set, n, mv2, cr2, ks, &kcur);
			for (int i = elo; i < ehi; i++)
				if (ocross[i] && ocross[i] == cr2[i] && fabs(ks[i] - lpsum[i]) > 1e-2 * fmax(1.0, fabs(lpsum[i])) &&
				    !near_contact(x, k, i, prm->scene_radius))
					fail_msg("edge %d: kernel log pair sum %g, oracle %g", i, ks[i], lpsum[i]);
			if (P->pair >= 0 && fabs(kcur - lcur_o) > 1e-2 * fmax(1.0, fabs(lcur_o)))
				fail_msg("current pair log density: kernel %g, oracle %g", kcur, lcur_o);
		}
		double sum = 0;
		for (int s = 0; s < k; s++)
			if (strategy_valid(orc, k, s) && (set.light_paths || (s <= 1 && s < k - 1))) {
				MisStrategy j = {1, s, 0, 0};
				sum += mis_union_weight(orc, k, k, ocross, lpsum, 0, j, set, heur);
			}
		for (int m = 0; m + 2 < k; m++)
			for (int s = 0; ocross[m] > 0 && s <= m; s++)
				for (int tp = 1; m + tp <= k - 2; tp++) {
					if (s > set.s_max || m - s + 1 > set.sp_max || tp > set.tp_max ||
					    k - m - tp - 1 > set.t_max)
						continue; /* not in use */
					/* orc[0].delta: a punctual light, which the <- half cannot
					 * reach (s = 0) but next-event estimation can (s = 1) */
					if ((s == 0 && orc[0].delta) || (s >= 2 && orc[s - 1].delta) || (s > 0 && orc[s].delta))
						continue;
					if (orc[m + tp].delta || orc[m + tp + 1].delta)
						continue;
					MisStrategy j = {2, s, m, tp};
					for (int c = 0; c < ocross[m] && c < 4; c++) /* each crossing */
						sum += mis_union_weight(orc, k, k, ocross, lpsum, (float)lpc[m][c], j, set, heur);
				}
		if (fabs(sum - 1) > 1e-3)
			fail_msg("path (s=%d, s'=%d, t'=%d, t=%d): weights sum to %.6f (heuristic %d)", P->s, P->sp, P->tp,
				 P->t, sum, heur);
		/* The kernel's weight of the path's own strategy, from its
		 * records within the horizon, against the oracle's over the
		 * whole path. */
		int in_use = P->sp ? P->s <= set.s_max && P->sp <= set.sp_max && P->tp <= set.tp_max && P->t <= set.t_max
				   : set.light_paths || P->s <= 1;
		if (heur == prm->mis && in_use) {
			MisStrategy cur = {P->sp ? 2 : 1, P->s, P->pair, P->tp};
			/* bdpt paths: bdpt_weight, the kernel's (l = x_0.., e = x_{k-1}..) */
			float wk = P->sp ? path_union_weight(sc, P, cur) : bdpt_weight(sc, P->x[0], P->s, P->x[k - 1], P->t);
			float wo = mis_union_weight(orc, k, k, ocross, lpsum, P->pair >= 0 ? lcur_o : 0, cur, set, heur);
			st->weights++;
			st->woff += fabs(wk - wo) > 1e-2;
			if (!(fabs(wk - wo) <= 0.5))
				fail_msg("path (s=%d, s'=%d, t'=%d, t=%d): kernel weight %g, oracle %g", P->s, P->sp, P->tp,
					 P->t, wk, wo);
		}
	}
	st->paths++;
	st->portal_paths += any > 0;
}

/* The subpaths of random sample n (stream `seed`): light, eye (through a
 * random point of the image) and intermediate, as a pixel sample traces
 * them. */
static void trace_subpaths(SceneView *sc, uint seed, int n, PathVertex *l, int *nl, PathVertex *e, int *ne,
			   PathVertex *R, int *nR, PathVertex *F, int *nF)
{
	const Params *prm = sc->params;
	Rng rng = rng_init(seed, (uint)n, 0, 3);
	float px = rng_f(&rng) * prm->camera.width, py = rng_f(&rng) * prm->camera.height;
	*nl = bdpt_light_subpath(sc, l, prm->max_depth, &rng);
	*ne = bdpt_eye_subpath(sc, px, py, e, prm->max_depth + 1, &rng);
	portal_intermediate(sc, R, nR, F, nF, &rng);
}

/* Weights joined from each end's records (path_join_weight, what the
 * kernel uses for every set) against path_union_weight for
 * every pair of ends of random intermediate subpaths: the same, bit for
 * bit. Returns how many weights it compared. */
static int check_join_weights(HostScene *h, int nsamples)
{
	SceneView *sc = &h->view;
	Params *prm = h->data.params;
	PathVertex l[SUBPATH_MAX], e[SUBPATH_MAX], R[SUBPATH_MAX], F[SUBPATH_MAX];
	int depth = prm->max_depth, compared = 0, whole = 0;
	MisPortalSet set = path_portal_set(prm);
	assert_true(path_join_exact(set));
	for (int n = 0; n < nsamples; n++) {
		int nl, ne, nR, nF;
		trace_subpaths(sc, 91, n, l, &nl, e, &ne, R, &nR, F, &nF);
		Rng rng = rng_init(92, (uint)n, 0, 3); /* next-event samples */
		float lF[2 * SUBPATH_MAX], lE[2 * SUBPATH_MAX];
		path_vertex_logs(F, nF, mis_needs_pf(set), lF);
		path_vertex_logs(e, ne, mis_needs_pf(set), lE);
		for (int a = 1; a < nR; a++)
			for (int s = 0; s <= nl && s <= prm->portal_s_max; s++) {
				if (s >= 1 && R[a].type != VERTEX_SURFACE)
					break;
				PathVertex y;
				const PathVertex *lp = l;
				if (s == 1) {
					if (v3_is_zero(bdpt_nee(sc, &R[a], &R[a - 1], &y, &rng)))
						continue;
					lp = &y;
				}
				MisLightEnd L;
				MisPnCache pc = {{0, 0}, 0}; /* shared by the light end's joins, as in the kernel */
				path_light_end(sc, set, lp, s, R, a, F, e, &L);
				for (int b = 1; b < nF; b++)
					for (int t = 1; t <= ne && t <= prm->portal_t_max && s + a + b + t - 1 <= depth; t++) {
						MisRecord r[2 * SUBPATH_MAX];
						MisEyeEnd E;
						path_eye_end(sc, set, R, F, b, e, t, lF, lE, &E, r);
						MisStrategy cur = {2, s, s + a - 1, b};
						PathRef P;
						path_ref(&P, lp, s, R, a, F, b, e, t);
						float want = path_union_weight(sc, &P, cur);
						float got = path_join_weight(sc, set, &L, &E, r, b >= 2 ? &F[2] : &e[t - 1], R, &pc, cur);
						if (!(fabs(got - want) <= 1e-5f + 1e-4f * want))
							fail_msg("path (s=%d, s'=%d, t'=%d, t=%d): joined weight %.9g, whole path %.9g", s,
								 a, b, t, got, want);
						compared++;
						whole += L.other || E.first_cross < min(E.nr - 1, prm->portal_s_max + prm->portal_sp_max - L.m - 1);
					}
			}
	}
	print_message("%d joined weights, %d of them over the whole path (two crossings)\n", compared, whole);
	return compared;
}

static void use_all_portal_strategies(HostScene *h);

/* Scenes with emitters: door-ajar and bathroom, the default set and every
 * strategy; the round trip through a mirror (delta vertices) below. */
static void test_join_weights(void **state)
{
	static const char *scenes[] = {SCENE("door-ajar/door-ajar.gltf"), SCENE("bathroom/bathroom.gltf")};
	for (int i = 0; i < 2; i++) {
		HostScene h;
		host_scene_open(&h, scenes[i], NULL, 24, 24, INTEGRATOR_PORTAL, 8);
		assert_true(check_join_weights(&h, 200) > 1000);
		use_all_portal_strategies(&h);
		assert_true(check_join_weights(&h, 80) > 1000);
		host_scene_close(&h);
	}
}

/* Random samples: every bdpt path and every portal path they can form. */
static MisStats check_scene_mis(HostScene *h, int nsamples)
{
	SceneView *sc = &h->view;
	Params *prm = h->data.params;
	PathVertex l[SUBPATH_MAX], e[SUBPATH_MAX], R[SUBPATH_MAX], F[SUBPATH_MAX];
	MisStats st = {0, 0, 0, 0, 0, 0, 0};
	int depth = prm->max_depth;
	for (int n = 0; n < nsamples; n++) {
		int nl, ne, nR, nF;
		trace_subpaths(sc, 77, n, l, &nl, e, &ne, R, &nR, F, &nF);
		Rng rng = rng_init(78, (uint)n, 0, 3); /* next-event samples */
		PathRef P;
		/* bdpt paths (s >= 2 connections and s = 0 hits; the light's own
		 * first vertex stands in for s = 1) */
		for (int t = 2; t <= ne; t++) {
			const PathVertex *z = &e[t - 1];
			if (z->type == VERTEX_ENV)
				break;
			for (int s = 0; s <= nl && s + t - 1 <= depth; s++) {
				if (s == 0 && (sc->tris[z->tri].emitter < 0 || v3_is_zero(bdpt_emitted(sc, z, z->wo))))
					continue;
				if (s >= 2 && v3_is_zero(bdpt_connect(sc, &l[s - 1], z)))
					continue;
				PathVertex y;
				const PathVertex *lp = l;
				if (s == 1) { /* next-event estimation, as the kernel does it */
					if (v3_is_zero(bdpt_nee(sc, z, &e[t - 2], &y, &rng)))
						continue;
					lp = &y;
				}
				path_ref(&P, lp, s, 0, 0, 0, 0, e, t);
				check_path(sc, &P, &st);
			}
		}
		/* light tracing (t = 1): the light subpath's own first vertex
		 * stands for x_0 here, not a next-event sample */
		for (int s = 1; s <= nl && s <= depth; s++) {
			V3 w = v3_sub(e[0].p, l[s - 1].p);
			if (vertex_infinite(&l[s - 1]) || (s == 1 && vertex_delta_light(&l[0])) ||
			    (s >= 2 && v3_is_zero(bdpt_scatter(&l[s - 1], v3_norm(w), BSDF_IMPORTANCE))))
				continue;
			path_ref(&P, l, s, 0, 0, 0, 0, e, 1);
			check_path(sc, &P, &st);
		}
		/* portal paths */
		for (int a = 1; a < nR; a++)
			for (int s = 0; s <= nl && s <= prm->portal_s_max; s++) {
				const PathVertex *z = &R[a];
				if (s == 0 && !(z->type == VERTEX_ENV || (z->tri >= 0 && sc->tris[z->tri].emitter >= 0 &&
									  !v3_is_zero(bdpt_emitted(sc, z, z->wo)))))
					continue;
				if (s >= 1 && z->type != VERTEX_SURFACE)
					continue;
				if (s >= 2 && v3_is_zero(bdpt_connect(sc, &l[s - 1], z)))
					continue;
				PathVertex y;
				const PathVertex *lp = l;
				if (s == 1) {
					if (v3_is_zero(bdpt_nee(sc, z, &R[a - 1], &y, &rng)))
						continue;
					lp = &y;
				}
				for (int b = 1; b < nF; b++)
					for (int t = 2; t <= ne && s + a + b + t - 1 <= depth; t++) {
						if (e[t - 1].type != VERTEX_SURFACE || v3_is_zero(bdpt_connect(sc, &F[b], &e[t - 1])))
							continue;
						path_ref(&P, lp, s, R, a, F, b, e, t);
						check_path(sc, &P, &st);
					}
			}
	}
	print_message("%d paths (%d crossing portals, %d consecutive crossings); %d of %d records beyond 1%%; "
		      "%d of %d kernel weights off the oracle's by 0.01\n",
		      st.paths, st.portal_paths, st.consecutive, st.off, st.records, st.woff, st.weights);
	assert_true(st.off <= st.records / 100);
	assert_true(st.woff <= st.weights / 100);
	return st;
}

/* Every intermediate strategy in use, not only the default set. */
static void use_all_portal_strategies(HostScene *h)
{
	Params *prm = h->data.params;
	prm->portal_s_max = prm->portal_sp_max = prm->portal_tp_max = SUBPATH_MAX;
	prm->portal_t_max = SUBPATH_MAX + 1;
	prm->light_paths = 1;
}

static void test_mis_window_room(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room.gltf"), NULL, 24, 24, INTEGRATOR_PORTAL, 8);
	assert_true(check_scene_mis(&h, 200).portal_paths > 100); /* the default set */
	use_all_portal_strategies(&h);
	MisStats st = check_scene_mis(&h, 400);
	assert_true(st.portal_paths > 200);
	host_scene_close(&h);
}

/* A pane 2 cm inside the window (the portal's plane is the opening's):
 * paths cross it by null events, intermediate subpaths from the portal
 * cross it on their -> half. */
static void test_mis_glazed(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room-glazed.gltf"), NULL, 24, 24, INTEGRATOR_PORTAL, 8);
	assert_true(check_scene_mis(&h, 200).portal_paths > 100);
	use_all_portal_strategies(&h);
	assert_true(check_scene_mis(&h, 400).portal_paths > 200);
	host_scene_close(&h);
}

static void test_mis_living_room(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("living-room/living-room.gltf"), NULL, 32, 18, INTEGRATOR_PORTAL, 8);
	use_all_portal_strategies(&h);
	MisStats st = check_scene_mis(&h, 300);
	assert_true(st.portal_paths > 100);
	host_scene_close(&h);
}

static void test_mis_bathroom(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("bathroom/bathroom.gltf"), NULL, 24, 24, INTEGRATOR_PORTAL, 8);
	assert_true(check_scene_mis(&h, 150).portal_paths > 20);
	use_all_portal_strategies(&h);
	MisStats st = check_scene_mis(&h, 300);
	assert_true(st.portal_paths > 50);
	host_scene_close(&h);
}

/* The gap portal: a slit and a triangle in two planes, an emitter behind. */
static void test_mis_door_ajar(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 24, 24, INTEGRATOR_PORTAL, 8);
	assert_true(check_scene_mis(&h, 300).portal_paths > 50);
	use_all_portal_strategies(&h);
	assert_true(check_scene_mis(&h, 300).portal_paths > 50);
	host_scene_close(&h);
}

/* With the portals the search finds (the marked ones taken out): a
 * window under a constant sky (every strategy as well) and a door's gap
 * with an emitter behind it. */
static void test_mis_found_portals(void **state)
{
	(void)state;
	HostScene h;
	host_scene_open(&h, NULL, without_portals(SCENE("window-room/window-room.gltf")), 24, 24, INTEGRATOR_PORTAL, 8);
	assert_int_equal(h.data.portal_source, POLICY_PORTALS_FOUND);
	assert_true(h.data.n_portals >= 2);
	assert_true(check_scene_mis(&h, 200).portal_paths > 100);
	use_all_portal_strategies(&h);
	assert_true(check_scene_mis(&h, 300).portal_paths > 150);
	host_scene_close(&h);
	host_scene_open(&h, NULL, without_portals(SCENE("door-ajar/door-ajar.gltf")), 24, 24, INTEGRATOR_PORTAL, 8);
	assert_int_equal(h.data.portal_source, POLICY_PORTALS_FOUND);
	assert_true(h.data.n_portals >= 2);
	assert_true(check_scene_mis(&h, 300).portal_paths > 50);
	host_scene_close(&h);
}

/* Scenes lit only by the sky (no light subpaths, bdpt strategies s <= 1,
 * short eye parts, records within a horizon): the constant-sky window room
 * and window-room-forest (a sky image with a sun, portal planes), with the
 * sky's set without light subpaths (the constant sky's default; the sky
 * image's before its light subpaths started on the portals), the longer ->
 * halves of set 1,2,3,4 at rate 1, and light subpaths with short eye parts
 * (1,2,3,4,1). */
static void set_portal_set(HostScene *h, int s_max, int sp_max, int tp_max, int t_max, int light_paths, float rate)
{
	Params *prm = h->data.params;
	prm->portal_s_max = s_max;
	prm->portal_sp_max = sp_max;
	prm->portal_tp_max = tp_max;
	prm->portal_t_max = t_max;
	prm->light_paths = light_paths;
	prm->portal_rate = rate;
}

static void test_join_weights_sky(void **state)
{
	static const char *scenes[] = {SCENE("window-room/window-room.gltf"),
				       SCENE("window-room-forest/window-room-forest.gltf")};
	for (int i = 0; i < 2; i++) {
		HostScene h;
		host_scene_open(&h, scenes[i], NULL, 24, 24, INTEGRATOR_PORTAL, 8);
		/* The sky image's default has light subpaths (they start on the
		 * portals); its set without them is the old default's. */
		assert_int_equal(h.data.params->light_paths, i == 1);
		set_portal_set(&h, 1, 2, 1, 3, 0, i == 1 ? 0.3f : 0.1f);
		assert_true(check_join_weights(&h, 300) > 300);
		set_portal_set(&h, 1, 2, 3, 4, 0, 1.0f);
		assert_true(check_join_weights(&h, 200) > 1000);
		set_portal_set(&h, 1, 2, 3, 4, 1, 0.5f);
		assert_true(check_join_weights(&h, 100) > 500);
		host_scene_close(&h);
	}
}

/* The bdpt strategies' weights in the portal integrator (bdpt_weight)
 * against the full union weight
 * (path_union_weight) for every bdpt path of random samples: the same up to
 * float rounding (bit for bit without light subpaths), where the shortcut
 * (no pairing edge crosses a portal) is taken and where it is not. Adds to
 * *fast and *full how many paths took each. */
static void check_bdpt_weights(HostScene *h, int nsamples, int *fast, int *full)
{
	SceneView *sc = &h->view;
	Params *prm = h->data.params;
	PathVertex l[SUBPATH_MAX], e[SUBPATH_MAX], R[SUBPATH_MAX], F[SUBPATH_MAX];
	MisPortalSet set = path_portal_set(prm);
	int depth = prm->max_depth;
	double worst = 0;
	for (int n = 0; n < nsamples; n++) {
		int nl, ne, nR, nF;
		trace_subpaths(sc, 93, n, l, &nl, e, &ne, R, &nR, F, &nF);
		if (!prm->light_paths)
			nl = 0; /* the kernel traces none */
		Rng rng = rng_init(94, (uint)n, 0, 3);
		for (int t = 1; t <= ne; t++) {
			const PathVertex *z = &e[t - 1];
			for (int s = 0; s <= max(nl, 1) && s + t - 1 <= depth; s++) {
				PathVertex y;
				const PathVertex *lp = l;
				if (t == 1) { /* light tracing */
					if (s == 0 || s > nl || vertex_infinite(&l[s - 1]) ||
					    (s == 1 && vertex_delta_light(&l[0])) ||
					    (s >= 2 &&
					     v3_is_zero(bdpt_scatter(&l[s - 1], v3_norm(v3_sub(e[0].p, l[s - 1].p)), BSDF_IMPORTANCE))))
						continue;
				} else if (s == 0) {
					if (!(z->type == VERTEX_ENV || sc->tris[z->tri].emitter >= 0) ||
					    v3_is_zero(bdpt_emitted(sc, z, z->wo)))
						continue;
				} else if (z->type != VERTEX_SURFACE) {
					continue;
				} else if (s == 1) {
					if (v3_is_zero(bdpt_nee(sc, z, &e[t - 2], &y, &rng)))
						continue;
					lp = &y;
				} else if (s > nl || v3_is_zero(bdpt_connect(sc, &l[s - 1], z))) {
					continue;
				}
				PathRef P;
				path_ref(&P, lp, s, 0, 0, 0, 0, e, t);
				MisStrategy cur = {1, s, 0, 0};
				float want = path_union_weight(sc, &P, cur), got = bdpt_weight(sc, lp, s, e, t);
				/* without light subpaths the same sum, bit for bit */
				if (!(fabs(got - want) <= 1e-5f + 1e-4f * want) || (!prm->light_paths && got != want))
					fail_msg("bdpt path (s=%d, t=%d): weight %.9g, full union weight %.9g", s, t, got, want);
				worst = fmax(worst, fabs(got - want));
				if (path_bdpt_pairs(sc, &P, set, mis_horizon(set, P.k)))
					++*full;
				else
					++*fast;
			}
		}
	}
	print_message("bdpt weights: %d by the shortcut, %d in full; largest difference %.3g\n", *fast, *full, worst);
}

/* Lamp scenes (the default set: the sky's, with light subpaths), a sky
 * image (the same default) and the sky's set without light subpaths (s <=
 * 1, a 2-term sum), the rich sky set, and a
 * scene with emitters (every strategy); each branch is taken often. */
static void test_bdpt_weight_shortcut(void **state)
{
	static const char *scenes[] = {SCENE("window-room-sun/window-room-sun.gltf"),
				       SCENE("window-room-lamp/window-room-lamp.gltf"),
				       SCENE("window-room-forest/window-room-forest.gltf"),
				       SCENE("door-ajar/door-ajar.gltf")};
	for (int i = 0; i < 4; i++) {
		for (int heur = 0; heur < 2; heur++) {
			HostScene h;
			if (i < 3) /* the sun lamp, the lamp and the sky image: bdpt by default */
				open_portal_kept(&h, scenes[i], NULL, 24, 24, 8);
			else
				host_scene_open(&h, scenes[i], NULL, 24, 24, INTEGRATOR_PORTAL, 8);
			h.data.params->mis = heur;
			int fast = 0, full = 0;
			check_bdpt_weights(&h, 150, &fast, &full);
			if (i == 2) {
				assert_true(h.data.params->light_paths); /* a sky image's (src/prepare/prepare.c) */
				set_portal_set(&h, 1, 2, 1, 3, 0, 0.3f);
				check_bdpt_weights(&h, 150, &fast, &full);
				set_portal_set(&h, 1, 2, 3, 4, 0, 1.0f);
				check_bdpt_weights(&h, 150, &fast, &full);
			}
			assert_true(fast > 100);
			assert_true(full > 20);
			host_scene_close(&h);
		}
	}
}

/* The window room with the sun through its window (light subpaths start
 * on the portal), a point light and a spot, and its sky; door-ajar with a
 * sun outside its house and the lights beside its emitter. */
static void test_mis_punctual(void **state)
{
	HostScene h;
	open_portal_kept(&h, NULL, sun_window_room(1, 1), 24, 24, 8);
	assert_true(h.data.params->light_paths);
	assert_true(check_scene_mis(&h, 200).portal_paths > 100);
	use_all_portal_strategies(&h);
	assert_true(check_scene_mis(&h, 300).portal_paths > 100);
	host_scene_close(&h);
	const float sun[3] = {-0.4f, -0.6f, 0.5f}, p[3] = {2.0f, 2.0f, 6.0f}, q[3] = {1.0f, 2.4f, 2.0f};
	host_scene_open(&h, NULL, punctual_scene(SCENE("door-ajar/door-ajar.gltf"), sun, 1, p, q, 0), 24, 24,
			INTEGRATOR_PORTAL, 8);
	assert_true(check_scene_mis(&h, 300).portal_paths > 50);
	assert_true(check_join_weights(&h, 100) > 500);
	host_scene_close(&h);
}

static void test_mis_portal_surface_portal(void **state)
{
	HostScene h;
	host_scene_open(&h, NULL, round_trip_scene(), 24, 24, INTEGRATOR_PORTAL, 8);
	use_all_portal_strategies(&h);
	MisStats st = check_scene_mis(&h, 400);
	assert_true(st.consecutive > 20);
	host_scene_close(&h);
}

static void test_mis_window_room_sun(void **state)
{
	HostScene h;
	open_portal_kept(&h, NULL, sun_room(0, 3000.0f), 24, 24, 8);
	assert_true(h.data.params->num_portal_planes == 1);
	assert_true(check_scene_mis(&h, 200).portal_paths > 100); /* the default set */
	use_all_portal_strategies(&h);
	assert_true(check_scene_mis(&h, 300).portal_paths > 150);
	host_scene_close(&h);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_mis_window_room),
		cmocka_unit_test(test_mis_glazed), cmocka_unit_test(test_mis_living_room),
		cmocka_unit_test(test_mis_bathroom),
		cmocka_unit_test(test_mis_door_ajar),
		cmocka_unit_test(test_mis_found_portals),
		cmocka_unit_test(test_mis_portal_surface_portal),
		cmocka_unit_test(test_mis_window_room_sun),
		cmocka_unit_test(test_join_weights),
		cmocka_unit_test(test_join_weights_sky),
		cmocka_unit_test(test_bdpt_weight_shortcut),
		cmocka_unit_test(test_mis_punctual),
	};
	return cmocka_run_group_tests_name("portal MIS", tests, NULL, NULL);
}
