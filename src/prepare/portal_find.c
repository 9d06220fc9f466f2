/* portal_find.c — the openings of a scene found without markup.
 *
 * A portal is only a sampling aid: any set keeps every integrator unbiased
 * (the kernels' defensive shares cover directions outside all portals), so
 * this search risks noise, never the image's expectation. It runs on the
 * host with the kernels' own traversal, from fixed seeds, single-threaded:
 * the same scene always gets the same portals. The method, in steps (the
 * record, with why and the figures: src/prepare/README.md, "Found portals"):
 *
 *  1. The camera's space. Rays from the camera in every direction; the room
 *     scale R is twice the RMS distance of their hits from their centroid.
 *     Points just in front of the hits, halfway along some of them, and one
 *     diffuse bounce further are the room's points; one that sees too few of
 *     the first hits lies behind an opening and goes.
 *  2. Rays through openings. Cosine rays from the room's points that escape,
 *     hit an emitter's front, or hit a point lit by a light sample the room
 *     point does not see (lamps, emitters, and the points they light one
 *     bounce on, behind the openings). Glass (transmission > 0) is open.
 *  3. The ring test. Such a ray went through a hole if rays around it (8 at
 *     2, 5, 12 or 30 degrees) mostly stop well short of it: the wall. Their
 *     hits give the wall's plane, the ray's crossing and the surfaces near
 *     the hole. Where few crossings pass near a place and direction, more
 *     rays are aimed there, two rounds.
 *  4. Where the lines crowd. On each candidate plane (the surfaces the rings
 *     met) the open lines' crossings are rastered into patches, scored by
 *     sqrt(lines x origins) / area^0.75; the best patch, and the runner-up
 *     on another plane, go to step 5, the tighter result wins.
 *  5. Open cells. A grid over the patch in its plane (moved a little beyond
 *     the surface), a cell open if a ray from a nearby line's origin through
 *     it escapes, meets an emitter, a point lit from outside or a point under
 *     the sky; grown where open cells touch its border, turned to the open
 *     cells' own frame where that is much narrower; parts touching the border
 *     still are no openings. Each part's rectangle, its edges bisected onto
 *     the opening's.
 *  6. Portals. Rectangles with light behind them close the lines they catch;
 *     again until under MIN_SHARE of the lines remain. Rectangles of nearly
 *     one plane merge where one covers them with little more area (a row of
 *     panes). Portals face the side their lines come from. A gap's
 *     rectangle (4 times longer than wide) is turned onto the gap's
 *     narrowest section: the shortest span between solid points that its
 *     lines cross.
 *  7. Openings beside the portals. Where lamps or emitters light the scene,
 *     lines from the room's points to their light points that pass no
 *     portal found (nor along one) went through an opening the room's rays
 *     hardly met: the thin slit over a door leaf's top, which lets a far
 *     emitter's light straight in. Their patches, on every plane their rings
 *     met, are scored by what the room sees of their rectangles (area times
 *     the lines' cosine); of near ties the plane the lines cross first wins.
 *
 * A scene without openings (a closed box, a room lit only by a lamp in it)
 * gets none: nothing escapes, and lit points inside fail the ring test.
 * Here: the driver and light behind a rectangle; the steps' code is in
 * portal_find_{rays,room,crossings,planes,cells}.c (portal_find_parts.h). */
#include "prepare/portal_find_parts.h"

#include <time.h>

/* ---- Step 8: light behind a rectangle ---------------------------------------- */

static int light_behind(Ctx *c, const Rect *r)
{
	Rng rng = rng_init(0x70a7a1u, 4u, 0u, 0u);
	V3 out = v3_neg(r->n);
	for (int i = 0; i < 256; i++) {
		float p1 = r->lo1 + (r->hi1 - r->lo1) * rnd(&rng), p2 = r->lo2 + (r->hi2 - r->lo2) * rnd(&rng);
		V3 X = v3_add(r->o, v3_add(v3_scale(r->a1, p1), v3_scale(r->a2, p2)));
		V3 d = pf_dir_about(&rng, out, 1);
		Solid s;
		pf_trace(c, X, d, AJAR_INF, &s);
		if ((s.t == AJAR_INF && c->sky) || s.emit)
			return 1;
		if (c->nlp) {
			const LightPoint *l = &c->lp[(uint32_t)i % c->nlp];
			V3 to = v3_sub(l->p, X);
			if (v3_dot(to, out) > 0.0f && (v3_is_zero(l->n) || v3_dot(to, l->n) < 0.0f) && pf_clear(c, X, l->p))
				return 1;
		}
	}
	return 0;
}

/* ---- The search --------------------------------------------------------------- */

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int cmp_share(const void *a, const void *b)
{
	const FoundPortal *x = a, *y = b;
	if (x->share != y->share)
		return x->share > y->share ? -1 : 1;
	if (x->c.x != y->c.x)
		return x->c.x < y->c.x ? -1 : 1;
	if (x->c.y != y->c.y)
		return x->c.y < y->c.y ? -1 : 1;
	return x->c.z < y->c.z ? -1 : x->c.z > y->c.z;
}

/* What the rounds of steps 4 to 6 share: the lines, which are still open
 * (alive) and which a portal caught, the candidate planes, the rectangles. */
typedef struct {
	Ctx *c;
	Crossings xs;
	Rects rs;
	Raster g;
	Patch best[2];
	uint8_t *alive, *caught, *scratch;
	uint32_t cap;     /* lines the arrays hold */
	uint32_t nfirst;  /* lines of the first sample */
	uint32_t accepted;
	V3 pn[MAX_PLANES];
	float po[MAX_PLANES];
	int np;
	V3 blo, bhi;      /* the scene's bounds */
} Search;

/* The per-line arrays sized for xs.n lines; lines added since are open. */
static int lines_fit(Search *s, uint32_t had)
{
	uint32_t n = s->xs.n;
	if (n > s->cap) {
		uint32_t *i0 = realloc(s->best[0].idx, sizeof *i0 * n);
		if (i0)
			s->best[0].idx = i0;
		uint32_t *i1 = realloc(s->best[1].idx, sizeof *i1 * n);
		if (i1)
			s->best[1].idx = i1;
		uint8_t *a = realloc(s->alive, n);
		if (a)
			s->alive = a;
		uint8_t *cg = realloc(s->caught, n);
		if (cg)
			s->caught = cg;
		uint8_t *sc = realloc(s->scratch, n);
		if (sc)
			s->scratch = sc;
		int *co = realloc(s->g.cellof, sizeof *co * n);
		if (co)
			s->g.cellof = co;
		uint64_t *pa = realloc(s->g.pairs, sizeof *pa * n);
		if (pa)
			s->g.pairs = pa;
		if (!i0 || !i1 || !a || !cg || !sc || !co || !pa)
			return 0;
		s->cap = n;
	}
	for (uint32_t k = had; k < n; k++)
		s->alive[k] = 1, s->caught[k] = 0, s->scratch[k] = 0;
	return 1;
}

/* Whether accepted rectangle q nearly repeats rc: normals within DUP_COS,
 * rc's centre in q's plane (MERGE_GAP R), half of rc over q. A gap's
 * section found again from the lines the first one left out, a few
 * degrees askew, is one opening: q grows over rc. */
static int absorb(Rect *q, const Rect *rc, float R)
{
	if (!q->accepted || v3_dot(q->n, rc->n) < DUP_COS)
		return 0;
	V3 c = v3_add(rc->o, v3_add(v3_scale(rc->a1, 0.5f * (rc->lo1 + rc->hi1)), v3_scale(rc->a2, 0.5f * (rc->lo2 + rc->hi2))));
	if (fabs(v3_dot(q->n, v3_sub(c, q->o))) > MERGE_GAP * R)
		return 0;
	float lo1 = AJAR_INF, hi1 = -AJAR_INF, lo2 = AJAR_INF, hi2 = -AJAR_INF;
	for (int k = 0; k < 4; k++) {
		V3 p = v3_sub(v3_add(rc->o, v3_add(v3_scale(rc->a1, k & 1 ? rc->hi1 : rc->lo1),
						     v3_scale(rc->a2, k & 2 ? rc->hi2 : rc->lo2))),
			      q->o);
		float p1 = v3_dot(p, q->a1), p2 = v3_dot(p, q->a2);
		lo1 = fmin(lo1, p1), hi1 = fmax(hi1, p1), lo2 = fmin(lo2, p2), hi2 = fmax(hi2, p2);
	}
	double ov1 = fmin(q->hi1, hi1) - fmax(q->lo1, lo1), ov2 = fmin(q->hi2, hi2) - fmax(q->lo2, lo2);
	if (!(ov1 > 0.0 && ov2 > 0.0 && ov1 * ov2 >= 0.5 * (double)(hi1 - lo1) * (hi2 - lo2)))
		return 0;
	q->lo1 = fmin(q->lo1, lo1), q->hi1 = fmax(q->hi1, hi1);
	q->lo2 = fmin(q->lo2, lo2), q->hi2 = fmax(q->hi2, hi2);
	q->share += rc->share;
	return 1;
}

/* Step 6 for the rectangles rs[from..): those with light behind them
 * that catch MIN_SHARE of the lines become portals, and close the lines
 * they catch. Returns the lines still open. */
static uint32_t accept(Search *s, uint32_t from)
{
	Ctx *c = s->c;
	uint32_t n = s->xs.n;
	for (uint32_t r = from; r < s->rs.n; r++) {
		Rect *rc = &s->rs.r[r];
		if (!rc->alive || !light_behind(c, rc))
			continue;
		/* The lines it catches that no portal caught: their count
		 * decides (aimed rays count: a small opening found is kept),
		 * the first sample's share is its share. */
		uint32_t gain = 0, first = 0;
		for (uint32_t k = 0; k < n; k++) {
			s->scratch[k] = !s->caught[k] && pf_rect_catches(rc, &s->xs.x[k], c->R);
			if (s->scratch[k]) {
				s->caught[k] = 1;
				s->alive[k] = 0;
				gain++;
				first += (uint32_t)s->xs.x[k].weight;
			}
		}
		rc->accepted = (float)gain >= MIN_SHARE * (float)n;
		s->accepted += rc->accepted;
		/* A gap's section may leave a few of the doorway's lines (over a
		 * leaf's top): they are open again, for an opening of their own. */
		if (rc->accepted && pf_refit_gap(c, s->xs.x, n, rc))
			for (uint32_t k = 0; k < n; k++)
				if (s->scratch[k] && !pf_rect_catches(rc, &s->xs.x[k], c->R)) {
					s->caught[k] = 0;
					s->alive[k] = 1;
					first -= (uint32_t)s->xs.x[k].weight;
				}
		rc->share = s->nfirst ? (float)first / (float)s->nfirst : 0.0f;
		for (uint32_t q = 0; q < r && rc->accepted; q++)
			if (absorb(&s->rs.r[q], rc, c->R)) {
				rc->accepted = rc->alive = 0;
				s->accepted--;
			}
	}
	uint32_t left = 0;
	for (uint32_t k = 0; k < n; k++)
		left += s->alive[k];
	return left;
}

/* Steps 4 to 6: again and again, the patch of a candidate plane where the
 * open lines crowd most tightly; its open cells' rectangles with light
 * behind them become portals, and the lines they catch (any line, not only
 * the patch's) are closed, until under MIN_SHARE of them would remain for
 * a portal. */
static ajar_status rounds(Search *s)
{
	Ctx *c = s->c;
	uint32_t n = s->xs.n;
	const Crossings *xs = &s->xs;
	uint8_t *alive = s->alive;
	Patch *best = s->best;
	for (int round = 0; round < MAX_ROUNDS && s->accepted < MAX_PORTALS; round++) {
		pf_best_patch(c, xs, alive, s->pn, s->po, s->np, PATCH_DN, s->blo, s->bhi, &s->g, best);
		PF_DEBUG("round %d best %.1f plane %d m %u; next %.1f plane %d m %u\n", round, best[0].score, best[0].q,
			 best[0].m, best[1].score, best[1].q, best[1].m);
		if (best[0].score <= 0.0 || (float)best[0].m < MIN_SHARE * (float)n)
			break;
		/* The best patch, or the runner-up on another plane where its
		 * score comes close: the one whose rectangles catch the open lines
		 * more tightly (lines per area^0.75) wins. */
		uint32_t from = s->rs.n;
		int pick = 0;
		double tight[2] = {0.0, 0.0};
		for (int b = 0; b < 2; b++) {
			if (b == 1 && !(best[1].score >= RUNNER_UP * best[0].score && (float)best[1].m >= MIN_SHARE * (float)n))
				break;
			uint32_t mark = s->rs.n;
			ajar_status st = pf_open_rects(c, xs->x, best[b].idx, best[b].m, s->pn[best[b].q], s->po[best[b].q], n,
						       s->scratch, &s->rs);
			if (st != AJAR_OK)
				return st;
			pf_merge_rects(&s->rs, mark, c->R);
			double area = 0.0;
			uint32_t lines = 0;
			for (uint32_t k = 0; k < n; k++) {
				int in = 0;
				for (uint32_t r = mark; r < s->rs.n && !in; r++)
					in = s->rs.r[r].alive && pf_rect_catches(&s->rs.r[r], &xs->x[k], c->R);
				lines += alive[k] && in;
			}
			for (uint32_t r = mark; r < s->rs.n; r++)
				if (s->rs.r[r].alive)
					area += (double)(s->rs.r[r].hi1 - s->rs.r[r].lo1) * (s->rs.r[r].hi2 - s->rs.r[r].lo2);
			tight[b] = area > 0.0 ? lines / pow(area, 0.75) : 0.0;
			if (b == 1) {
				pick = tight[1] > tight[0];
				/* The loser's rectangles are dropped. */
				for (uint32_t r = pick ? from : mark; r < (pick ? mark : s->rs.n); r++)
					s->rs.r[r].alive = 0;
			}
		}
		PF_DEBUG("  tightness %.1f / %.1f: plane %d\n", tight[0], tight[1], best[pick].q);
		uint32_t m = best[pick].m, *idx = best[pick].idx;
		for (uint32_t i = 0; i < m; i++)
			alive[idx[i]] = 0; /* the patch is settled, caught or not */
		uint32_t left = accept(s, from);
		PF_DEBUG("round %d: plane %d patch %u lines, %u portals, %u left\n", round, best[pick].q, m, s->accepted, left);
		if ((float)left < MIN_SHARE * (float)n)
			break;
	}
	return AJAR_OK;
}

/* Step 7's rounds, for the few lines of openings beside the portals: the
 * best patch of every candidate plane (lines at any cosine but MEET_DN's:
 * a slit's lines may graze its own plane), its open cells' rectangles,
 * scored by lines caught per projected area^0.75 (the area times the mean
 * cosine of the lines it catches: what the room sees of it). The same
 * lines cross a thin opening and, beyond it, a strip of the next surface's
 * plane (over a door leaf's top: the lintel's plane, then the leaf's, just
 * above its edge), about as tightly: of planes within BESIDE_TIE of the
 * best score, the one the lines cross first, nearest the room, goes to
 * step 6. */
static ajar_status beside_rounds(Search *s)
{
	Ctx *c = s->c;
	uint32_t n = s->xs.n;
	Patch *pa = s->best;
	for (int round = 0; round < MAX_ROUNDS && s->accepted < MAX_PORTALS; round++) {
		uint32_t lo[MAX_PLANES], hi[MAX_PLANES];
		double tight[MAX_PLANES], along[MAX_PLANES], top = 0.0;
		for (int q = 0; q < s->np; q++) {
			tight[q] = 0.0;
			lo[q] = hi[q] = s->rs.n;
			pf_best_patch(c, &s->xs, s->alive, s->pn + q, s->po + q, 1, MEET_DN, s->blo, s->bhi, &s->g, pa);
			if (pa[0].score <= 0.0 || (float)pa[0].m < MIN_SHARE * (float)n)
				continue;
			ajar_status st = pf_open_rects(c, s->xs.x, pa[0].idx, pa[0].m, s->pn[q], s->po[q], n, s->scratch, &s->rs);
			if (st != AJAR_OK)
				return st;
			pf_merge_rects(&s->rs, lo[q], c->R);
			hi[q] = s->rs.n;
			double area = 0.0, dist = 0.0;
			uint32_t lines = 0;
			for (uint32_t r = lo[q]; r < hi[q]; r++) {
				const Rect *rc = &s->rs.r[r];
				double cs = 0.0;
				uint32_t in = 0;
				for (uint32_t k = 0; rc->alive && k < n; k++)
					if (s->alive[k] && pf_rect_catches(rc, &s->xs.x[k], c->R)) {
						const Crossing *x = &s->xs.x[k];
						float dn = v3_dot(rc->n, x->d);
						cs += fabs(dn);
						dist += (v3_dot(rc->n, rc->o) - v3_dot(rc->n, x->P)) / dn;
						in++;
					}
				lines += in;
				if (in)
					area += (double)(rc->hi1 - rc->lo1) * (rc->hi2 - rc->lo2) * cs / in;
			}
			tight[q] = area > 0.0 ? lines / pow(area, 0.75) : 0.0;
			along[q] = lines ? dist / lines : 0.0;
			top = fmax(top, tight[q]);
			PF_DEBUG("  beside plane %d: patch %u lines, tightness %.1f at %.3f\n", q, pa[0].m, tight[q], along[q]);
		}
		int bq = -1;
		for (int q = 0; q < s->np; q++)
			if (top > 0.0 && tight[q] >= BESIDE_TIE * top && (bq < 0 || along[q] < along[bq]))
				bq = q;
		if (bq < 0)
			break;
		for (int q = 0; q < s->np; q++)
			for (uint32_t r = lo[q]; q != bq && r < hi[q]; r++)
				s->rs.r[r].alive = 0;
		/* Its patch again (the same lines: the search is deterministic),
		 * settled, caught or not. */
		pf_best_patch(c, &s->xs, s->alive, s->pn + bq, s->po + bq, 1, MEET_DN, s->blo, s->bhi, &s->g, pa);
		for (uint32_t i = 0; i < pa[0].m; i++)
			s->alive[pa[0].idx[i]] = 0;
		uint32_t left = accept(s, lo[bq]);
		PF_DEBUG("beside round %d: plane %d, %u portals, %u left\n", round, bq, s->accepted, left);
		if ((float)left < MIN_SHARE * (float)n)
			break;
	}
	return AJAR_OK;
}

ajar_status portal_find(const SceneView *v, uint32_t ntris, const PortalFindInput *in, PortalSearch *out)
{
	double t0 = now();
	memset(out, 0, sizeof *out);
	Ctx c = {.v = v};
	RoomPts room = {0};
	Search s = {.c = &c, .best = {{0.0, -1, NULL, 0}, {0.0, -1, NULL, 0}}};
	ajar_status st = pf_room_points(&c, in->camera, &room);
	if (st == AJAR_OK && c.R > 0.0f)
		st = pf_light_points(&c, ntris, in, &room);
	if (st == AJAR_OK && c.R > 0.0f) {
		pf_room_lights(&c, &room);
		st = pf_find_crossings(&c, &room, &s.xs);
	}
	if (st != AJAR_OK || s.xs.n == 0)
		goto done;

	for (uint32_t k = 0; k < s.xs.n; k++)
		s.nfirst += (uint32_t)s.xs.x[k].weight;
	s.np = pf_candidate_planes(&s.xs, c.R, s.pn, s.po);
	s.g.count = malloc(sizeof *s.g.count * PATCH_MAX * PATCH_MAX);
	s.g.comp = malloc(sizeof *s.g.comp * PATCH_MAX * PATCH_MAX);
	s.g.stack = malloc(sizeof *s.g.stack * PATCH_MAX * PATCH_MAX);
	s.g.box = malloc(sizeof *s.g.box * PATCH_MAX * PATCH_MAX);
	out->portals = malloc(sizeof *out->portals * MAX_PORTALS);
	if (s.np < 0 || !lines_fit(&s, 0) || !s.g.count || !s.g.comp || !s.g.stack || !s.g.box || !out->portals) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
		goto done;
	}
	s.blo = v3(AJAR_INF, AJAR_INF, AJAR_INF), s.bhi = v3(-AJAR_INF, -AJAR_INF, -AJAR_INF);
	for (uint32_t i = 0; i < ntris; i++) {
		GLOBAL const Tri *t = &v->tris[i];
		s.blo = v3_min(s.blo, v3_min(t->p0, v3_min(t->p1, t->p2)));
		s.bhi = v3_max(s.bhi, v3_max(t->p0, v3_max(t->p1, t->p2)));
	}
	if ((st = rounds(&s)) != AJAR_OK)
		goto done;
	/* Step 7: openings beside the portals found, which the room's rays
	 * hardly met; their lines in rounds of their own, on the planes their
	 * rings met. */
	if (s.accepted && s.accepted < MAX_PORTALS) {
		uint32_t had = s.xs.n;
		if ((st = pf_beside(&c, &room, &s.xs, &s.rs)) != AJAR_OK)
			goto done;
		if (s.xs.n > had) {
			Crossings added = {s.xs.x + had, s.xs.n - had, s.xs.n - had};
			s.np = pf_candidate_planes(&added, c.R, s.pn, s.po);
			if (s.np < 0 || !lines_fit(&s, had)) {
				st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
				goto done;
			}
			/* The rounds before settled the other lines: too few
			 * were left for a portal, and stay so. */
			memset(s.alive, 0, had);
			if ((st = beside_rounds(&s)) != AJAR_OK)
				goto done;
		}
	}
	/* The portals: the accepted rectangles, those of one plane merged where
	 * one rectangle covers them with little more area. */
	for (uint32_t r = 0; r < s.rs.n; r++)
		s.rs.r[r].alive = s.rs.r[r].accepted;
	pf_merge_rects(&s.rs, 0, c.R);
	for (uint32_t r = 0; r < s.rs.n && out->count < MAX_PORTALS; r++) {
		const Rect *rc = &s.rs.r[r];
		if (!rc->alive)
			continue;
		FoundPortal *f = &out->portals[out->count++];
		float m1 = 0.5f * (rc->lo1 + rc->hi1), m2 = 0.5f * (rc->lo2 + rc->hi2);
		f->c = v3_add(rc->o, v3_add(v3_scale(rc->a1, m1), v3_scale(rc->a2, m2)));
		f->u = v3_scale(rc->a1, 0.5f * (rc->hi1 - rc->lo1));
		f->v = v3_scale(rc->a2, 0.5f * (rc->hi2 - rc->lo2));
		f->n = rc->n;
		f->share = rc->share;
		if (v3_dot(v3_cross(f->u, f->v), f->n) < 0.0f)
			f->v = v3_neg(f->v);
	}
	qsort(out->portals, out->count, sizeof *out->portals, cmp_share);
done:
	out->rays = c.rays;
	out->seconds = now() - t0;
	free(room.pt);
	free(s.xs.x);
	free(s.rs.r);
	free(s.best[0].idx), free(s.best[1].idx);
	free(s.alive);
	free(s.caught);
	free(s.scratch);
	free(s.g.count), free(s.g.comp), free(s.g.stack), free(s.g.box), free(s.g.cellof), free(s.g.pairs);
	free(c.lp);
	if (st != AJAR_OK)
		portal_search_free(out);
	return st;
}

void portal_search_free(PortalSearch *s)
{
	free(s->portals);
	s->portals = NULL;
	s->count = 0;
}

void portal_found_tris(const FoundPortal *f, PortalTri out[2])
{
	V3 c0 = v3_sub(v3_sub(f->c, f->u), f->v), c1 = v3_sub(v3_add(f->c, f->u), f->v),
	   c2 = v3_add(v3_add(f->c, f->u), f->v), c3 = v3_add(v3_sub(f->c, f->u), f->v);
	V3 tri[2][3] = {{c0, c1, c2}, {c0, c2, c3}};
	for (int k = 0; k < 2; k++) {
		PortalTri *p = &out[k];
		memset(p, 0, sizeof *p);
		p->p0 = tri[k][0];
		p->p1 = tri[k][1];
		p->p2 = tri[k][2];
		V3 cr = v3_cross(v3_sub(p->p1, p->p0), v3_sub(p->p2, p->p0));
		p->area = 0.5f * v3_len(cr);
		p->n = p->area > 0.0f ? v3_norm(cr) : f->n;
		p->side_plus = 0.5f;
	}
}
