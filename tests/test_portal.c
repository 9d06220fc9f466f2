/* test_portal.c — the portal integrator, checked on the host with the
 * kernels' own code (tests/kernel_host.h), against design.md:
 *   - MIS over the union: for random paths of every strategy (bdpt and
 *     intermediate) in scenes with one, two and four portals, the kernel's
 *     records equal an independent oracle's (densities, portal crossings
 *     counted in double precision, pair densities), and the weights of all
 *     strategies that can produce each path, every crossing of every edge
 *     counted, sum to 1 for the power and the balance heuristic. Paths that
 *     cross portals on two consecutive edges (the note's portal-surface-
 *     portal sequence) are among them, and their weights still sum to 1:
 *     the other strategies cover what each intermediate strategy cannot.
 *   - Each group of intermediate strategies (length n, light vertices s,
 *     eye vertices t), unweighted, converges to the path tracer's image of
 *     paths of n segments counted once per portal crossing on the edges
 *     those strategies can cross (Params.cross_filter).
 *   - The default strategy sets and rates, and the environment variables
 *     that override them (taken whole or not at all).
 * (That the portal integrator without portals is bdpt to the bit is
 * checked through the device in test_render.c.)
 * Statistics as in test_bdpt.c: batch means, 5 standard errors. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel_host.h"
#include "mis_oracle.h"
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
		st->records++;
		st->off += diff > 1e-2;
		/* Narrow glossy lobes amplify the ray-offset direction change
		 * (mis_oracle.h); bugs are systematic and fail the 1% count. */
		if ((diff > 0.5 && !near_contact(x, k, i, sc->params->scene_radius)) || rec[i].delta != orc[i].delta)
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
		assert_true(check_join_weights(&h, 150) > 1000);
		use_all_portal_strategies(&h);
		assert_true(check_join_weights(&h, 60) > 1000);
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

/* ---- Found portals ------------------------------------------------------ */

static void check_directions(HostScene *h, int j, int SUB, const char *name);

/* `path` as an exporter hands it over: its marked portals taken out, so
 * the render finds its own (src/prepare/portal_find.c). */
static Scene *without_portals(const char *path)
{
	Scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	s->nportal_tris = 0;
	s->nportals = 0;
	return s;
}

/* MIS over the union and the <- directions' chi-square with the portals
 * the search finds: a window (a constant sky, every strategy as well) and a
 * door's gap with an emitter behind it. */
static void test_found_portals(void **state)
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
	host_scene_open(&h, NULL, without_portals(SCENE("window-room/window-room.gltf")), 8, 8, INTEGRATOR_PORTAL, 8);
	check_directions(&h, 0, 8, "window-room, found portal");
	host_scene_close(&h);

	host_scene_open(&h, NULL, without_portals(SCENE("door-ajar/door-ajar.gltf")), 24, 24, INTEGRATOR_PORTAL, 8);
	assert_int_equal(h.data.portal_source, POLICY_PORTALS_FOUND);
	assert_true(h.data.n_portals >= 2);
	assert_true(check_scene_mis(&h, 300).portal_paths > 50);
	host_scene_close(&h);
	host_scene_open(&h, NULL, without_portals(SCENE("door-ajar/door-ajar.gltf")), 8, 8, INTEGRATOR_PORTAL, 8);
	check_directions(&h, 0, 64, "door-ajar, found portal");
	host_scene_close(&h);
}

/* ---- Punctual lights --------------------------------------------------- */

/* `path` with a directional light at `dir` and, if `inside`, a point light
 * at p and a spot at q pointing down; `sky` 0 removes the environment. */
static Scene *punctual_scene(const char *path, const float dir[3], int inside, const float p[3], const float q[3],
			     int sky)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	memcpy(l.direction, dir, sizeof l.direction);
	l.color[2] = 0.8f;
	l.intensity = 683.0f * 4.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	if (inside) {
		ajar_light_default(&l);
		memcpy(l.position, p, sizeof l.position);
		l.intensity = 683.0f * 0.5f;
		l.range = 6.0f;
		assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
		ajar_light_default(&l);
		l.type = AJAR_LIGHT_SPOT;
		memcpy(l.position, q, sizeof l.position);
		l.direction[0] = 0.2f;
		l.direction[1] = -1.0f;
		l.direction[2] = 0.1f;
		l.inner_cone = 0.2f;
		l.outer_cone = 0.6f;
		l.intensity = 683.0f;
		assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	}
	if (!sky)
		s->env_type = ENV_NONE;
	return s;
}

static const float sun_in[3] = {0.3f, -0.5f, 0.8f}; /* through window-room's window */
static const float wr_p[3] = {1.0f, 2.2f, 2.0f}, wr_q[3] = {3.0f, 2.5f, 1.5f};

/* The sky's strategy set with light subpaths, the default where portal now
 * renders as bdpt: a forced set keeps the intermediate strategies. */
static const PolicyOverrides SKY_SET = {.portal_set_given = 1, .portal_set = {1, 2, 1, 3, 1}};

/* Opens a scene where portal renders as bdpt by default (light subpaths
 * bring the light in: a sky image with a sun, punctual lights on the
 * camera's side; src/prepare/policy.c) with the sky's set forced, which
 * keeps the intermediate strategies these tests check. */
static void open_portal_kept(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int depth)
{
	host_scene_open_with(h, path, built, w, hgt, INTEGRATOR_PORTAL, depth, &SKY_SET);
	assert_int_equal(h->data.params->integrator, INTEGRATOR_PORTAL);
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

static Scene *sun_window_room(int inside, int sky)
{
	return punctual_scene(SCENE("window-room/window-room.gltf"), sun_in, inside, wr_p, wr_q, sky);
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

/* portal against pt in the window room lit by the sun, a point light and
 * a spot (no sky, so they carry all the light). */
static void test_portal_matches_pt_punctual(void **state)
{
	HostScene hq, hp;
	Estimate q, p;
	open_portal_kept(&hq, NULL, sun_window_room(1, 0), 12, 12, 6);
	host_scene_open(&hp, NULL, sun_window_room(1, 0), 12, 12, INTEGRATOR_PT, 6);
	host_batch_estimate(&hq, 4, -1, 32, 2000, &q);
	host_batch_estimate(&hp, 16, -1, 32, 2000, &p);
	for (int c = 0; c < 3; c++) {
		double se = sqrt(q.se[c] * q.se[c] + p.se[c] * p.se[c]), z = (q.mean[c] - p.mean[c]) / se;
		print_message("window room with punctual lights, portal vs pt, channel %d: %.5f +- %.5f vs %.5f +- %.5f "
			      "(%.1f se)\n", c, q.mean[c], q.se[c], p.mean[c], p.se[c], z);
		if (fabs(z) > 5)
			fail_msg("channel %d: portal and pt differ by %.1f standard errors", c, z);
	}
	host_scene_close(&hq);
	host_scene_close(&hp);
}

/* A room lit by a ceiling light, with a window portal and, outside, a
 * white wall facing it and a mirror: light leaves through the window,
 * bounces outside and comes back in (portal - surface - portal). */
static Scene *round_trip_scene(void)
{
	ajar_scene *s;
	ajar_material m;
	uint32_t white, light, mirror;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material_default(&m);
	assert_int_equal(ajar_scene_add_material(s, &m, &white), AJAR_OK);
	m.emission[0] = m.emission[1] = m.emission[2] = 10;
	assert_int_equal(ajar_scene_add_material(s, &m, &light), AJAR_OK);
	ajar_material_default(&m);
	m.metallic = 1;
	m.roughness = 0;
	assert_int_equal(ajar_scene_add_material(s, &m, &mirror), AJAR_OK);
	/* The room [0,2]^3 without its x = 2 wall, which has a window. */
	static const float room[] = {0, 0, 0, 2, 0, 0, 2, 0, 2, 0, 0, 2,  0, 2, 0, 0, 2, 2, 2, 2, 2, 2, 2, 0,
				     0, 0, 0, 0, 0, 2, 0, 2, 2, 0, 2, 0,  0, 0, 0, 0, 2, 0, 2, 2, 0, 2, 0, 0,
				     0, 0, 2, 2, 0, 2, 2, 2, 2, 0, 2, 2};
	static const uint32_t quads[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10, 8, 10, 11,
					 12, 13, 14, 12, 14, 15, 16, 17, 18, 16, 18, 19};
	ajar_mesh mesh = {room, NULL, NULL, 20, quads, 10, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	/* x = 2 wall around a window y, z in [0.7, 1.3] */
	static const float wall[] = {2, 0, 0, 2, 0.7f, 0, 2, 0.7f, 2, 2, 0, 2,  2, 1.3f, 0, 2, 2, 0, 2, 2, 2, 2, 1.3f, 2,
				     2, 0.7f, 0, 2, 1.3f, 0, 2, 1.3f, 0.7f, 2, 0.7f, 0.7f,
				     2, 0.7f, 1.3f, 2, 1.3f, 1.3f, 2, 1.3f, 2, 2, 0.7f, 2};
	static const uint32_t wq[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10, 8, 10, 11, 12, 13, 14, 12, 14, 15};
	ajar_mesh wm = {wall, NULL, NULL, 16, wq, 8, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &wm), AJAR_OK);
	/* Outside: a white wall at x = 3 and a mirror at x = 2.6 below the window. */
	static const float out[] = {3, -1, -1, 3, 3, -1, 3, 3, 3, 3, -1, 3};
	static const float mir[] = {2.6f, 0, 0.6f, 2.6f, 0.6f, 0.6f, 2.6f, 0.6f, 1.4f, 2.6f, 0, 1.4f};
	static const uint32_t q[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh om = {out, NULL, NULL, 4, q, 2, white, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &om), AJAR_OK);
	om.positions = mir;
	om.material = mirror;
	assert_int_equal(ajar_scene_add_mesh(s, &om), AJAR_OK);
	/* A light on the ceiling, facing down. */
	static const float lp[] = {0.7f, 1.99f, 0.7f, 1.3f, 1.99f, 0.7f, 1.3f, 1.99f, 1.3f, 0.7f, 1.99f, 1.3f};
	static const uint32_t lq[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh lm = {lp, NULL, NULL, 4, lq, 2, light, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &lm), AJAR_OK);
	static const float portal[] = {2, 0.7f, 0.7f, 2, 1.3f, 0.7f, 2, 1.3f, 1.3f, 2, 0.7f, 1.3f};
	ajar_mesh pm = {portal, NULL, NULL, 4, q, 2, 0, NULL};
	assert_int_equal(ajar_scene_add_portal(s, &pm), AJAR_OK);
	ajar_camera cam = {{0.3f, 1.2f, 1.0f}, {2, 0.8f, 1.0f}, {0, 1, 0}, 1.2f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
	return s;
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

/* window-room under a sky with a sun: a gradient and a small disc of
 * radiance sun_l (the sky's is below 1), high (the patch on the floor) or low (on the far
 * wall), its light through the window (which faces -z). */
static Scene *sun_room(int low, float sun_l)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float e = low ? 0.14f : 0.84f; /* elevation: 8 and 48 degrees */
	float *sky = test_sun_sky(256, 128, 0.1f, sinf(e), -cosf(e), 0.03f, sun_l);
	assert_int_equal(scene_set_env_image(s, 256, 128, sky, 1.0f), AJAR_OK);
	return s;
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

/* ---- Convergence ------------------------------------------------------- */

#define BATCHES 32

static void batch_layer(HostScene *h, uint32_t spp, int layer, Estimate *est)
{
	host_batch_estimate(h, spp, layer, BATCHES, 500, est);
}

/* Only channel 1 (the scenes are grey), 5 standard errors. Returns
 * whether the group carried light. */
static int agree1(const char *what, const Estimate *a, const Estimate *b)
{
	double se = sqrt(a->se[1] * a->se[1] + b->se[1] * b->se[1]);
	double z = se > 0 ? (a->mean[1] - b->mean[1]) / se : 0;
	print_message("%s: %.6f +- %.6f vs %.6f +- %.6f (%+.1f se)\n", what, a->mean[1], a->se[1], b->mean[1], b->se[1],
		      z);
	if (fabs(z) > 5)
		fail_msg("%s: differ by %.1f standard errors", what, z);
	if ((a->mean[1] > 0) != (b->mean[1] > 0))
		fail_msg("%s: only one of the two carried light", what);
	return a->mean[1] > 0;
}

/* Returns how many groups carried light (some cannot in a given scene:
 * with only a sky outside, no <- end outside gets a light sample). */
static int check_groups(HostScene *hp, HostScene *ht, int len, uint32_t spp_portal, uint32_t spp_pt)
{
	int lit = 0;
	Params *pp = hp->data.params, *pt = ht->data.params;
	pp->portal_s_max = pp->portal_sp_max = pp->portal_tp_max = SUBPATH_MAX; /* every group */
	pp->portal_t_max = SUBPATH_MAX + 1;
	pp->light_paths = 1;
	pp->strategy_len = len;
	pp->strategy_unweighted = 1;
	/* Every group's layer from one render per batch. */
	Estimate *groups = malloc(sizeof *groups * portal_layer_count(len));
	host_batch_estimates(hp, spp_portal, bdpt_layer_count(len), portal_layer_count(len), BATCHES, 500, groups);
	/* Lit by punctual lights alone, s = 0 groups carry nothing (their <-
	 * half would have to hit a delta light), while the crossing filter
	 * also counts paths that cross a portal on the light's own edge, which
	 * only bdpt's strategies sample: compare from s = 1. */
	int s0 = pp->num_emitters == 0 && pp->env_type == ENV_NONE;
	for (int n = 2; n <= len; n++)
		for (int t = 1; t < n; t++)
			for (int s = s0; s + t < n; s++) {
				Estimate a = groups[portal_layer(n, s, t)], b;
				char what[96];
				pt->min_depth = pt->max_depth = n;
				pt->cross_filter = 1;
				pt->cross_lo = t;
				pt->cross_hi = s;
				batch_layer(ht, spp_pt, -1, &b);
				snprintf(what, sizeof what, "length %d, intermediate strategies with s=%d, t=%d", n, s, t);
				lit += agree1(what, &a, &b);
			}
	free(groups);
	return lit;
}

/* Sky through the window: s = 0 groups carry the light. Unweighted, they
 * have heavy tails: at 8 spp per pixel (standard error 5% of the mean)
 * all three came out 2-4.5 standard errors low, and a bias below about 25%
 * went unseen. 256 spp make the standard error 1% of the mean, so 5
 * standard errors catch a bias of 5%. */
#define GROUP_SPP 256

static void test_groups_unbiased_window_room(void **state)
{
	HostScene hp, ht;
	host_scene_open(&hp, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 3);
	host_scene_open(&ht, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PT, 3);
	assert_true(check_groups(&hp, &ht, 3, GROUP_SPP, 64) >= 3);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* The same under skies with a sun, high and low: next-event samples
 * through the portal by the sky's radiance (kernels/light/portal_sky.h), <-
 * halves guided toward the sun. The sun's light is noisier: 1024 spp
 * (and 512 for pt) keep the combined standard error near 1% of the mean
 * (1.1% at most), so a bias of about 5.5% is caught. */
#ifdef __SANITIZE_ADDRESS__
#define SUN_ROOMS 1 /* sanitizers: the low sun alone, at the same samples (the suite's time) */
#else
#define SUN_ROOMS 2
#endif

static void test_groups_unbiased_window_room_sun(void **state)
{
	for (int low = 2 - SUN_ROOMS; low < 2; low++) {
		HostScene hp, ht;
		open_portal_kept(&hp, NULL, sun_room(low, 300.0f), 8, 8, 3);
		host_scene_open(&ht, NULL, sun_room(low, 300.0f), 8, 8, INTEGRATOR_PT, 3);
		assert_true(check_groups(&hp, &ht, 3, 4 * GROUP_SPP, 2 * GROUP_SPP) >= 3);
		host_scene_close(&hp);
		host_scene_close(&ht);
	}
}

/* A light inside, bouncing outside: s >= 1 groups carry the light. */
static void test_groups_unbiased_round_trip(void **state)
{
	HostScene hp, ht;
	host_scene_open(&hp, NULL, round_trip_scene(), 8, 8, INTEGRATOR_PORTAL, 4);
	host_scene_open(&ht, NULL, round_trip_scene(), 8, 8, INTEGRATOR_PT, 4);
	/* Lambertian only: the mirror outside would hide paths from connections. */
	Material *m = (Material *)&hp.data.materials[2], *m2 = (Material *)&ht.data.materials[2];
	m->metallic = m2->metallic = 0;
	m->specular = m2->specular = 0;
	assert_true(check_groups(&hp, &ht, 4, 8, 32) >= 5);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* door-ajar lit only by punctual lights: a sun outside its house (a
 * directional light's light subpaths start on the portals), a point light
 * and a spot where its emitter was (its emission set to 0), no sky. Only
 * the s >= 1 groups can carry their light through the gap (next-event
 * estimation of a delta light from <- vertices, light subpaths from them;
 * a <- half never hits a delta light). In the window rooms nothing lies
 * outside the window for a -> half to hit, so there only the sky's s = 0
 * groups carry light, as test_groups_unbiased_window_room checks. 64 and
 * 128 spp (about 15 s) give standard errors of 3-9% of each group's mean:
 * a bias above about a third is caught, not a small one. */
static Scene *door_ajar_lamps(void)
{
	const float sun[3] = {-0.4f, -0.6f, 0.5f}, lp[3] = {2.0f, 2.0f, 6.0f}, lq[3] = {1.0f, 2.4f, 2.0f};
	Scene *s = punctual_scene(SCENE("door-ajar/door-ajar.gltf"), sun, 1, lp, lq, 0);
	for (uint32_t i = 0; i < s->nmaterials; i++)
		s->materials[i].emission = v3(0.0f, 0.0f, 0.0f);
	return s;
}

static void test_groups_unbiased_punctual(void **state)
{
	(void)state;
	HostScene hp, ht;
	host_scene_open(&hp, NULL, door_ajar_lamps(), 8, 8, INTEGRATOR_PORTAL, 4);
	host_scene_open(&ht, NULL, door_ajar_lamps(), 8, 8, INTEGRATOR_PT, 4);
	assert_true(hp.data.params->num_emitters == 0 && hp.data.params->num_lights == 3);
	assert_true(check_groups(&hp, &ht, 4, 64, 128) >= 3);
	host_scene_close(&hp);
	host_scene_close(&ht);
}

/* ---- Where intermediate subpaths go ------------------------------------ */

/* The <- half's first vertex along unit wl from portal point w0, as
 * portal_intermediate makes it; an escape is an environment vertex even
 * without an environment (its direction density is then the cosine part). */
static PathVertex first_hit(const SceneView *sc, V3 w0, V3 n, V3 wl)
{
	PathVertex tmp[2];
	tmp[0].type = VERTEX_SURFACE;
	tmp[0].p = w0;
	tmp[0].ng = tmp[0].ns = n;
	tmp[0].material = tmp[0].tri = -1;
	Rng rng = rng_init(5, 0, 0, 0); /* for panes, which these scenes have none of */
	if (!vertex_trace(sc, tmp, 1, w0, wl, v3(1, 1, 1), 0.0f, 0, 0, 1, &rng)) {
		tmp[1].type = VERTEX_ENV;
		tmp[1].p = wl;
		tmp[1].tri = -1;
	}
	return tmp[1];
}

/* Chi-square of the <- directions from the centre of portal triangle j
 * against portal_direction_psa integrated over equal-solid-angle cells
 * about the portal normal (each quadrature direction traced for its first
 * hit); one more cell for guided samples that missed their light point. */
static void check_directions_about(HostScene *h, int j, int SUB, const char *name, int pole_in_plane)
{
	enum { CT = 16, CP = 32, N = 200000, NC = CT * CP + 1 };
	static double obs[NC], expct[NC];
	const SceneView *sc = &h->view;
	GLOBAL const PortalTri *pt = &sc->portals[j];
	V3 w0 = v3_scale(v3_add(pt->p0, v3_add(pt->p1, pt->p2)), 1.0f / 3.0f), t, b, pole = pt->n;
	v3_basis(pt->n, &t, &b);
	if (pole_in_plane) { /* the bins' pole in the portal's plane: its normal on their equator */
		pole = t;
		t = b;
		b = v3_cross(pole, t);
	}
	double total = 0;
	for (int ct = 0; ct < CT; ct++)
		for (int cp = 0; cp < CP; cp++) {
			double sum = 0;
			for (int jj = 0; jj < SUB; jj++)
				for (int ii = 0; ii < SUB; ii++) {
					float c = 1.0f - 2.0f * (ct + (jj + 0.5f) / SUB) / CT;
					float phi = 2.0f * AJAR_PI * (cp + (ii + 0.5f) / SUB) / CP;
					float sn = sqrtf(fmaxf(0.0f, 1.0f - c * c));
					V3 wl = v3_from_local(v3(sn * cosf(phi), sn * sinf(phi), c), t, b, pole);
					PathVertex A = first_hit(sc, w0, pt->n, wl);
					sum += portal_direction_psa(sc, pt, &A, w0) * fabsf(v3_dot(wl, pt->n));
				}
			expct[ct * CP + cp] = sum * (4.0 * M_PI / (CT * CP)) / (SUB * SUB) * N;
			total += expct[ct * CP + cp] / N;
		}
	expct[NC - 1] = N * (1.0 - total);
	memset(obs, 0, sizeof obs);
	Rng rng = rng_init(77, (uint)j, 0, 0);
	for (int k = 0; k < N; k++) {
		V3 wl;
		int genv;
		float gdist;
		float u_mix = rng_f(&rng), u1 = rng_f(&rng), u2 = rng_f(&rng), u3 = rng_f(&rng);
		int how = portal_direction_sample(sc, pt, w0, u_mix, u1, u2, u3, &wl, &genv, &gdist);
		PathVertex A;
		if (how == 2)
			A = first_hit(sc, w0, pt->n, wl);
		if (how == 0 || (how == 2 && !portal_guided_reached(sc, &A, w0, genv, gdist))) {
			obs[NC - 1] += 1;
			continue;
		}
		float c = fminf(fmaxf(v3_dot(wl, pole), -1.0f), 1.0f);
		float phi = atan2f(v3_dot(wl, b), v3_dot(wl, t));
		if (phi < 0)
			phi += 2.0f * AJAR_PI;
		int ct = (int)((1.0f - c) * 0.5f * CT), cp = (int)(phi / (2.0f * AJAR_PI) * CP);
		ct = ct < 0 ? 0 : (ct >= CT ? CT - 1 : ct);
		cp = cp < 0 ? 0 : (cp >= CP ? CP - 1 : cp);
		obs[ct * CP + cp] += 1;
	}
	if (pole_in_plane) {
		/* Under the sun sky nothing lies outside window-room's window, so no
		 * sample misses: the quadrature's total (within 2e-3 of 1) is its
		 * error, and the shape is what is tested. */
		assert_true(fabs(total - 1.0) < 2e-3);
		assert_true(obs[NC - 1] == 0);
		for (int q = 0; q < NC - 1; q++)
			expct[q] /= total;
		expct[NC - 1] = 0;
	}
	double p = chi2_test(obs, expct, NC, 5.0);
	printf("  %s: <- directions p = %.3f (missed light points %.3f, expected %.3f)\n", name, p, obs[NC - 1] / N,
	       expct[NC - 1] / N);
	assert_true(p > 1e-3);
}

static void check_directions(HostScene *h, int j, int SUB, const char *name)
{
	check_directions_about(h, j, SUB, name, 0);
}

static void test_directions_window_room(void **state)
{
	(void)state;
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	/* The sky side found by src/prepare/portal_flux.c is the one away from the
	 * camera, which is in the room. */
	for (int j = 0; j < h.view.params->num_portals; j++) {
		GLOBAL const PortalTri *pt = &h.view.portals[j];
		float cam = v3_dot(v3_sub(h.view.params->camera.pos, pt->p0), pt->n);
		assert_true(pt->env_side != 0 && (float)pt->env_side * cam < 0.0f);
		assert_true((pt->env_side > 0) == (pt->side_plus > 0.5f));
	}
	check_directions(&h, 0, 8, "window-room");
	host_scene_close(&h);
}

static void test_directions_door_ajar(void **state)
{
	(void)state;
	HostScene h;
	host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	for (int j = 0; j < h.view.params->num_portals; j++)
		assert_int_equal(h.view.portals[j].env_side, 0); /* no sky */
	check_directions(&h, 0, 32, "door-ajar"); /* a small emitter: finer quadrature */
	host_scene_close(&h);
}

/* Under a sky image with a sun, the guided <- directions follow the
 * environment's importance folded onto the window's sky side
 * (portal_guided_sample): a sun high (48 degrees) and low (8), the
 * radiance 3000 times the sky's, so most guided sky samples aim at a disc
 * of a few texels: finer quadrature (at 48 x 48 points a bin the density's
 * texel steps left the low sun's total 2.3e-3 above 1; at 64, 4e-4). The
 * sun's share of the guided sky samples is printed. */
static void test_directions_window_room_sun(void **state)
{
	(void)state;
	for (int low = 0; low < 2; low++) {
		HostScene h;
		host_scene_open(&h, NULL, sun_room(low, 3000.0f), 8, 8, INTEGRATOR_PORTAL, 8);
		const SceneView *sc = &h.view;
		assert_true(sc->params->num_portal_planes == 1);
		float e = low ? 0.14f : 0.84f;
		V3 sun = v3_norm(v3(0.1f, sinf(e), -cosf(e))); /* sun_room's disc: 0.104 rad */
		GLOBAL const PortalTri *pt = &sc->portals[0];
		V3 w0 = v3_scale(v3_add(pt->p0, v3_add(pt->p1, pt->p2)), 1.0f / 3.0f);
		int hits = 0, n = 20000;
		Rng rng = rng_init(78, 0, 0, 0);
		for (int k = 0; k < n; k++) {
			V3 w = v3(0.0f, 0.0f, 0.0f);
			int genv;
			float gdist, u1 = rng_f(&rng), u2 = rng_f(&rng);
			assert_true(portal_guided_sample(sc, pt, w0, 0.0f, u1, u2, &w, &genv, &gdist) && genv);
			hits += v3_dot(w, sun) > cosf(0.11f);
		}
		printf("  sun %s: %.3f of the guided sky directions on the sun\n", low ? "low" : "high",
		       (double)hits / n);
		assert_true(hits > n / 2);
		/* Bins about an axis in the window's plane: near the pole of bins about
		 * its normal, the quadrature is too coarse in angle for a sun 10
		 * degrees off the normal (the low one). No sample can miss there. */
		check_directions_about(&h, 0, 64, low ? "window-room, low sun" : "window-room, high sun", 1);
		host_scene_close(&h);
	}
}

/* The share of intermediate subpaths that are wasted (a half escapes, or
 * a guided direction misses its light point), with the tables from
 * src/prepare/portal_flux.c and with the choices of before it (area, both sides
 * alike, no sky side), both measured here. */
static double wasted(HostScene *h, int n)
{
	PathVertex *R = malloc(sizeof *R * SUBPATH_MAX), *F = malloc(sizeof *F * SUBPATH_MAX);
	int bad = 0;
	for (int i = 0; i < n; i++) {
		Rng rng = rng_init(5, (uint)i, 0, 3);
		int nR, nF;
		portal_intermediate(&h->view, R, &nR, F, &nF, &rng);
		bad += nR < 2 || nF < 2;
	}
	free(R);
	free(F);
	return (double)bad / n;
}

static void check_wasted(const char *path, Scene *built, const char *name)
{
	HostScene h;
	enum { N = 20000 };
	host_scene_open(&h, path, built, 8, 8, INTEGRATOR_PORTAL, 8);
	double now = wasted(&h, N);
	double area = 0;
	for (int j = 0; j < h.view.params->num_portals; j++)
		area += h.data.portals[j].area;
	for (int j = 0; j < h.view.params->num_portals; j++) {
		PortalTri *pt = &h.data.portals[j];
		pt->side_plus = 0.5f;
		pt->env_side = 0;
		pt->pdf_select = pt->area / area;
		h.data.portal_cdf[j + 1] = h.data.portal_cdf[j] + pt->pdf_select;
	}
	h.data.portal_cdf[h.view.params->num_portals] = 1.0f;
	double before = wasted(&h, N);
	printf("  %s: wasted intermediate subpaths %.1f%%, with area choice and both sides alike %.1f%%\n", name,
	       100 * now, 100 * before);
	if (before > 0) /* door-ajar's rooms are closed: nothing escapes */
		assert_true(now < before - 5 * sqrt(before * (1 - before) / N));
	host_scene_close(&h);
}

/* The default strategy sets, and a forced set taken whole. */
static void test_portal_set(void **state)
{
	HostScene h;
	const int M = AJAR_BIDIR_MAX_DEPTH;
	const struct {
		const char *scene;
		int forced, set[5];
		int expect[5]; /* s, s', t', t, light paths */
	} cases[] = {
		{"window-room/window-room.gltf", 0, {0}, {1, 2, 1, 3, 0}},
		{"window-room-forest/window-room-forest.gltf", 0, {0}, {1, 2, 1, 3, 1}}, /* a sky image: light subpaths */
		{"window-room-forest/window-room-forest.gltf", 1, {1, 2, 1, 3, 0}, {1, 2, 1, 3, 0}},
		{"door-ajar/door-ajar.gltf", 0, {0}, {1, M, M, 1 << 20, 1}},
		{"door-ajar/door-ajar.gltf", 1, {2, 4, 5, 1 << 20, 1}, {2, 4, 5, 1 << 20, 1}},
		{"door-ajar/door-ajar.gltf", 1, {1, 2, 2, 4, 0}, {1, 2, 2, 4, 0}},
		{"window-room/window-room.gltf", 1, {3, 2, 1, 3, 0}, {1, 2, 1, 3, 0}}, /* s > 1 needs light subpaths */
	};
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		PolicyOverrides over = {.portal_set_given = cases[i].forced};
		memcpy(over.portal_set, cases[i].set, sizeof over.portal_set);
		char path[256];
		snprintf(path, sizeof path, SCENE("%s"), cases[i].scene);
		host_scene_open_with(&h, path, NULL, 8, 8, INTEGRATOR_PORTAL, 8, &over);
		const Params *p = h.data.params;
		int got[5] = {p->portal_s_max, p->portal_sp_max, p->portal_tp_max, p->portal_t_max, p->light_paths};
		for (int j = 0; j < 5; j++)
			if (got[j] != cases[i].expect[j])
				fail_msg("%s, case %u: field %d is %d, expected %d", cases[i].scene, i, j, got[j],
					 cases[i].expect[j]);
		host_scene_close(&h);
	}
}

/* A lamp at `pos` (range 0: unlimited) with window-room's constant sky. */
static Scene *window_room_lamp_at(float x, float y, float z, float range)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.position[0] = x;
	l.position[1] = y;
	l.position[2] = z;
	l.intensity = 683.0f;
	l.range = range;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	return s;
}

/* Where light subpaths bring the light in through the portals (a sky
 * image with a sun, punctual lights none of which lies behind a portal),
 * portal renders as bdpt; a point light behind a portal counts as an
 * emitter (the long set at rate 1); constant skies, a sky without a sun
 * (no light subpaths, test_sky_sun_share) and emitters keep their intermediate subpaths,
 * and so does a forced strategy set (src/prepare/policy.c). */
static void test_portal_as_bdpt(void **state)
{
	(void)state;
	const struct {
		const char *scene;
		Scene *built;
		int integrator, long_set;
	} cases[] = {
		{"window-room/window-room.gltf", NULL, INTEGRATOR_PORTAL, 0},
		{"window-room-sunset/window-room-sunset.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"door-ajar/door-ajar.gltf", NULL, INTEGRATOR_PORTAL, 1},
		{"window-room-forest/window-room-forest.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"window-room-sun/window-room-sun.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"window-room-lamp/window-room-lamp.gltf", NULL, INTEGRATOR_BDPT, 0},
		{"atrium-forest/atrium-forest.gltf", NULL, INTEGRATOR_BDPT, 0}, /* the sun through the roof */
		{NULL, sun_window_room(1, 1), INTEGRATOR_BDPT, 0},     /* sun, lamp and spot in the room */
		{NULL, door_ajar_lamps(), INTEGRATOR_PORTAL, 1},      /* a point light behind the door */
		{NULL, window_room_lamp_at(2.0f, 1.4f, -1.0f, 0.0f), INTEGRATOR_PORTAL, 1}, /* outside the window */
		{NULL, window_room_lamp_at(2.0f, 1.4f, -1.0f, 0.5f), INTEGRATOR_BDPT, 0},   /* its range ends short of it */
		{NULL, window_room_lamp_at(2.0f, 1.4f, 2.0f, 0.0f), INTEGRATOR_BDPT, 0},    /* inside */
	};
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		char path[256];
		if (cases[i].scene)
			snprintf(path, sizeof path, SCENE("%s"), cases[i].scene);
		HostScene h;
		host_scene_open(&h, cases[i].scene ? path : NULL, cases[i].built, 8, 8, INTEGRATOR_PORTAL, 8);
		const Params *p = h.data.params;
		if (p->integrator != cases[i].integrator || (p->portal_sp_max == AJAR_BIDIR_MAX_DEPTH) != cases[i].long_set)
			fail_msg("case %u (%s): integrator %d, s' <= %d, expected %d and %s", i,
				 cases[i].scene ? cases[i].scene : "built", p->integrator, p->portal_sp_max,
				 cases[i].integrator, cases[i].long_set ? "the long set" : "the sky's");
		if (cases[i].long_set)
			assert_float_equal(p->portal_rate, 1.0f, 0.0f);
		/* as bdpt, eye vertices join the first light vertices only */
		assert_int_equal(p->bdpt_conn, p->integrator == INTEGRATOR_BDPT ? POLICY_PORTAL_BDPT_CONN : 0);
		host_scene_close(&h);
	}
	HostScene h;
	host_scene_open_with(&h, SCENE("window-room-forest/window-room-forest.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8,
			     &SKY_SET);
	assert_int_equal(h.data.params->integrator, INTEGRATOR_PORTAL);
	host_scene_close(&h);
}

/* The whole sky's share of a sky image's power in its brightest texels. */
static float whole_sky_share(const HostScene *h)
{
	GLOBAL const Params *p = h->data.params;
	uint32_t w = (uint32_t)p->env_width, hh = (uint32_t)p->env_height;
	return env_sun_share_weighted(h->data.env + ENV_PIXELS(w, hh), w, hh, NULL, NULL);
}

/* The sun's share of a sky image's power (src/prepare/light_tables.c, env_sun_share_weighted),
 * of the sky light through the portals (src/prepare/portal_flux.c,
 * portal_sun_share) and what portal makes of it (src/prepare/prepare.c,
 * SKY_SUN_SHARE): a uniform sky with a disc 5000 times as bright covering
 * 0.008% of the sphere gets the share the texels' solid angles give
 * exactly; behind the wall, the disc brings no light subpaths, and turned
 * by 180 degrees into the window it does, with the whole sky's share
 * unchanged; the shipped skies their measured shares; light subpaths from
 * the sky only with a sun through the window: window-room-forest,
 * window-room-sunset and a strong synthetic sun yes, that sun turned
 * behind the window's wall or a sky without a sun no (the sky set's rate
 * 0.3). */
static void test_sky_sun_share(void **state)
{
	(void)state;
	enum { W = 256, H = 128 };
	float *rgb = malloc(sizeof(float) * 3 * W * H);
	assert_non_null(rgb);
	double cos_r = cos(0.02), disc = 0.0, all = 0.0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			double phi = 2.0 * M_PI * ((x + 0.5) / W - 0.5), theta = M_PI * (y + 0.5) / H;
			double dy = cos(theta), dz = -sin(theta) * cos(phi), sa = sin(theta);
			int in = dy * 0.6 + dz * 0.8 > cos_r; /* the sun toward (0, 0.6, 0.8) */
			for (int c = 0; c < 3; c++)
				rgb[3 * (y * W + x) + c] = in ? 5000.0f : 1.0f;
			disc += in ? sa : 0.0;
			all += sa;
		}
	assert_true(disc > 0.0 && disc < 1e-3 * all);
	float *turned = malloc(sizeof(float) * 3 * W * H); /* scene_set_env_image takes each */
	assert_non_null(turned);
	memcpy(turned, rgb, sizeof(float) * 3 * W * H);
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(scene_set_env_image(s, W, H, rgb, 1.0f), AJAR_OK);
	HostScene h;
	host_scene_open(&h, NULL, s, 8, 8, INTEGRATOR_PORTAL, 8);
	double want = (5000.0 * disc + (1e-3 * all - disc)) / (all + 4999.0 * disc);
	printf("  disc of %.3g%% of the sphere: share %.5f, expected %.5f\n", 100.0 * disc / all,
	       whole_sky_share(&h), want);
	assert_float_equal(whole_sky_share(&h), want, 1e-4 * want);
	printf("  behind the wall: share through the portals %.5f\n", h.data.sun_share_portals);
	assert_true(h.data.sun_share_portals < 0.01f);
	assert_false(h.data.params->light_paths);
	host_scene_close(&h);
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(scene_set_env_image(s, W, H, turned, 1.0f), AJAR_OK);
	assert_int_equal(scene_set_env_rotation(s, 180.0f), AJAR_OK);
	host_scene_open(&h, NULL, s, 8, 8, INTEGRATOR_PORTAL, 8);
	printf("  turned into the window: share %.5f, through the portals %.5f\n", whole_sky_share(&h),
	       h.data.sun_share_portals);
	assert_float_equal(whole_sky_share(&h), want, 1e-3 * want);
	/* Each texel's power times the portals' area projected toward its
	 * turned direction from their sky side: the disc's, and of the rest
	 * the part of solid angle that fills the brightest 0.1%. */
	double in_disc = 0.0, in_rest = 0.0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			double phi = 2.0 * M_PI * ((x + 0.5) / W - 0.5), theta = M_PI * (y + 0.5) / H;
			double dx = sin(theta) * sin(phi), dy = cos(theta), dz = -sin(theta) * cos(phi);
			double a = 0.0;
			for (size_t k = 0; k < h.data.n_portals; k++) {
				const PortalTri *pt = &h.data.portals[k];
				double c = (-dx * pt->n.x + dy * pt->n.y - dz * pt->n.z) * pt->env_side;
				a += c > 0.0 ? pt->area * c : 0.0;
			}
			if (dy * 0.6 + dz * 0.8 > cos_r)
				in_disc += 5000.0 * sin(theta) * a;
			else
				in_rest += sin(theta) * a;
		}
	double want_in = (in_disc + in_rest * (1e-3 * all - disc) / (all - disc)) / (in_disc + in_rest);
	printf("  expected through the portals %.5f\n", want_in);
	assert_float_equal(h.data.sun_share_portals, want_in, 2e-3 * want_in);
	assert_true(h.data.params->light_paths);
	host_scene_close(&h);

	struct {
		const char *scene;
		Scene *sky;
		float lo, hi;
		int light_paths;
	} cases[] = {
		{SCENE("window-room-forest/window-room-forest.gltf"), NULL, 0.18f, 0.30f, 1},
		{SCENE("window-room-sunset/window-room-sunset.gltf"), NULL, 0.05f, 0.09f, 1},
		{NULL, sun_room(0, 3000.0f), 0.25f, 1.0f, 1},
		{NULL, sun_room(0, 3000.0f), 0.0f, 0.01f, 0}, /* turned by 120 degrees, behind the wall's plane */
		{NULL, sun_room(0, 0.5f), 0.0f, 0.02f, 0},    /* the "sun" no brighter than the sky */
	};
	assert_int_equal(scene_set_env_rotation(cases[3].sky, 120.0f), AJAR_OK);
	for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		host_scene_open(&h, cases[i].scene, cases[i].sky, 8, 8, INTEGRATOR_PORTAL, 8);
		float share = h.data.sun_share_portals;
		printf("  case %u: sun share %.4f, through the portals %.4f, light subpaths %d, rate %g\n", i,
		       whole_sky_share(&h), share, h.data.params->light_paths, h.data.params->portal_rate);
		if (!(share >= cases[i].lo && share <= cases[i].hi))
			fail_msg("case %u: sun share through the portals %g outside [%g, %g]", i, share, cases[i].lo,
				 cases[i].hi);
		assert_int_equal(h.data.params->light_paths, cases[i].light_paths);
		assert_float_equal(h.data.params->portal_rate, cases[i].light_paths ? 0.1f : 0.3f, 0.0f);
		host_scene_close(&h);
	}
}

/* The rate of intermediate subpaths: 0.1 where a constant sky is the only
 * light and where a sky image is (with its light subpaths), 0.3 under a
 * sky image (sampled through planar portals) without light subpaths, 1
 * with emitters; a forced rate replaces it, and strategy layers without
 * MIS weights take every intermediate subpath. */
static void test_portal_rate(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	assert_float_equal(h.data.params->portal_rate, 0.1f, 0.0f);
	host_scene_close(&h);
	host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8);
	assert_float_equal(h.data.params->portal_rate, 1.0f, 0.0f);
	host_scene_close(&h);
	host_scene_open(&h, NULL, sun_room(0, 300.0f), 8, 8, INTEGRATOR_PORTAL, 8); /* a sky image */
	assert_float_equal(h.data.params->portal_rate, 0.1f, 0.0f);
	host_scene_close(&h);
	const PolicyOverrides no_lines = {.portal_set_given = 1, .portal_set = {1, 2, 1, 3, 0}};
	host_scene_open_with(&h, NULL, sun_room(0, 300.0f), 8, 8, INTEGRATOR_PORTAL, 8, &no_lines);
	assert_float_equal(h.data.params->portal_rate, 0.3f, 0.0f);
	host_scene_close(&h);
	const float rates[] = {0.25f, 1.0f};
	for (int i = 0; i < 2; i++) {
		const PolicyOverrides over = {.portal_rate = rates[i]};
		host_scene_open_with(&h, SCENE("window-room/window-room.gltf"), NULL, 8, 8, INTEGRATOR_PORTAL, 8, &over);
		assert_float_equal(h.data.params->portal_rate, rates[i], 0.0f);
		host_scene_close(&h);
	}
	/* Unweighted strategy layers (the strategy tests) take every intermediate subpath. */
	const PolicyOverrides over = {.portal_rate = 0.25f};
	Scene *s;
	assert_int_equal(ajar_scene_load(SCENE("window-room/window-room.gltf"), &s), AJAR_OK);
	ajar_options o;
	ajar_options_default(&o);
	o.integrator = AJAR_INTEGRATOR_PORTAL;
	o.max_depth = 8;
	o.strategy_len = 4;
	o.strategy_unweighted = 1;
	SceneData d;
	assert_int_equal(prepare_scene(s, &o, 8, 8, &over, &d), AJAR_OK);
	assert_float_equal(d.params->portal_rate, 1.0f, 0.0f);
	prepare_free(&d);
	ajar_scene_destroy(&s);
}

/* Scenes lit by punctual lights without emitters (window-room-sun,
 * window-room-lamp): light subpaths on, the sky's strategy set and rate
 * (src/prepare/policy.c); the guided <- direction never lost to a punctual light
 * (guided_env_share): under the sun lamp and a constant sky every guided
 * pick is a sky direction; and the direction density against its sampling
 * (chi-square) there and in door-ajar with a sun, a point light and a spot
 * beside its emitter, where the guided choice divides the emitters' shares
 * by their part of the table. Prints the wasted intermediate subpaths. */
static void test_punctual_choices(void **state)
{
	(void)state;
	HostScene h;
	const char *scenes[] = {SCENE("window-room-sun/window-room-sun.gltf"), SCENE("window-room-lamp/window-room-lamp.gltf")};
	for (int i = 0; i < 2; i++) {
		host_scene_open(&h, scenes[i], NULL, 8, 8, INTEGRATOR_PORTAL, 8);
		const Params *p = h.data.params;
		int got[5] = {p->portal_s_max, p->portal_sp_max, p->portal_tp_max, p->portal_t_max, p->light_paths};
		const int want[5] = {1, 2, 1, 3, 1};
		for (int j = 0; j < 5; j++)
			if (got[j] != want[j])
				fail_msg("%s: strategy set field %d is %d, expected %d", scenes[i], j, got[j], want[j]);
		assert_float_equal(p->portal_rate, 0.1f, 0.0f);
		assert_true(p->num_lights == 1 && p->num_emitters == 0 && p->env_pdf_select > 0.0f &&
			    p->env_pdf_select < 1.0f);
		GLOBAL const PortalTri *pt = &h.view.portals[0];
		V3 w0 = v3_scale(v3_add(pt->p0, v3_add(pt->p1, pt->p2)), 1.0f / 3.0f);
		Rng rng = rng_init(9, (uint)i, 0, 0);
		int lost = 0;
		for (int k = 0; k < 10000; k++) {
			V3 wl;
			int genv;
			float gdist, u = rng_f(&rng), u1 = rng_f(&rng), u2 = rng_f(&rng);
			lost += !portal_guided_sample(&h.view, pt, w0, u, u1, u2, &wl, &genv, &gdist) || !genv;
		}
		if (lost)
			fail_msg("%s: %d of 10000 guided directions lost", scenes[i], lost);
		check_directions(&h, 0, 8, scenes[i]);
		printf("  %s: wasted intermediate subpaths %.1f%%\n", scenes[i], 100 * wasted(&h, 20000));
		host_scene_close(&h);
	}
	const float sun[3] = {-0.4f, -0.6f, 0.5f}, lp[3] = {2.0f, 2.0f, 6.0f}, lq[3] = {1.0f, 2.4f, 2.0f};
	host_scene_open(&h, NULL, punctual_scene(SCENE("door-ajar/door-ajar.gltf"), sun, 1, lp, lq, 0), 8, 8,
			INTEGRATOR_PORTAL, 8);
	float ce;
	assert_float_equal(guided_env_share(&h.view, &ce), 0.0f, 0.0f); /* no sky */
	assert_true(ce > 0.0f && ce < 1.0f);
	check_directions(&h, 0, 32, "door-ajar with a sun, a point light and a spot");
	host_scene_close(&h);
}

static void test_wasted_fewer(void **state)
{
	(void)state;
	check_wasted(SCENE("window-room/window-room.gltf"), NULL, "window-room");
	check_wasted(SCENE("living-room/living-room.gltf"), NULL, "living-room");
	check_wasted(SCENE("door-ajar/door-ajar.gltf"), NULL, "door-ajar");
	/* Skies with a sun: guided <- halves aim at the sky's importance. */
	check_wasted(NULL, sun_room(0, 3000.0f), "window-room, high sun");
	check_wasted(NULL, sun_room(1, 3000.0f), "window-room, low sun");
	/* The shipped sky scenes (kernels/lights.md, "Sky images through portals"). */
	check_wasted(SCENE("window-room-forest/window-room-forest.gltf"), NULL, "window-room-forest");
	check_wasted(SCENE("window-room-sunset/window-room-sunset.gltf"), NULL, "window-room-sunset");
	check_wasted(SCENE("living-room-forest/living-room-forest.gltf"), NULL, "living-room-forest");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_mis_window_room),
		cmocka_unit_test(test_mis_glazed), cmocka_unit_test(test_mis_living_room),
		cmocka_unit_test(test_mis_bathroom),
		cmocka_unit_test(test_mis_door_ajar),
		cmocka_unit_test(test_found_portals),
		cmocka_unit_test(test_mis_portal_surface_portal),
		cmocka_unit_test(test_mis_window_room_sun),
		cmocka_unit_test(test_join_weights),
		cmocka_unit_test(test_join_weights_sky),
		cmocka_unit_test(test_bdpt_weight_shortcut),
		cmocka_unit_test(test_groups_unbiased_window_room),
		cmocka_unit_test(test_groups_unbiased_window_room_sun),
		cmocka_unit_test(test_groups_unbiased_round_trip),
		cmocka_unit_test(test_directions_window_room),
		cmocka_unit_test(test_directions_door_ajar),
		cmocka_unit_test(test_directions_window_room_sun),
		cmocka_unit_test(test_wasted_fewer),
		cmocka_unit_test(test_punctual_choices),
		cmocka_unit_test(test_groups_unbiased_punctual),
		cmocka_unit_test(test_portal_set),
		cmocka_unit_test(test_portal_as_bdpt),
		cmocka_unit_test(test_portal_rate),
		cmocka_unit_test(test_sky_sun_share),
		cmocka_unit_test(test_mis_punctual),
		cmocka_unit_test(test_portal_matches_pt_punctual),
	};
	return cmocka_run_group_tests_name("portal", tests, NULL, NULL);
}
