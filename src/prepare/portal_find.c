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
 *     panes). Portals face the side their lines come from.
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

ajar_status portal_find(const SceneView *v, uint32_t ntris, const PortalFindInput *in, PortalSearch *out)
{
	double t0 = now();
	memset(out, 0, sizeof *out);
	Ctx c = {.v = v};
	RoomPts room = {0};
	Crossings xs = {0};
	Rects rs = {0};
	Raster g = {0};
	Patch best[2] = {{0.0, -1, NULL, 0}, {0.0, -1, NULL, 0}};
	uint8_t *alive = NULL, *caught = NULL, *scratch = NULL;
	V3 pn[MAX_PLANES];
	float po[MAX_PLANES];
	ajar_status st = pf_room_points(&c, in->camera, &room);
	if (st == AJAR_OK && c.R > 0.0f)
		st = pf_light_points(&c, ntris, in, &room);
	if (st == AJAR_OK && c.R > 0.0f) {
		pf_room_lights(&c, &room);
		st = pf_find_crossings(&c, &room, &xs);
	}
	if (st != AJAR_OK || xs.n == 0)
		goto done;

	uint32_t n = xs.n, nfirst = 0;
	for (uint32_t k = 0; k < n; k++)
		nfirst += (uint32_t)xs.x[k].weight;
	int np = pf_candidate_planes(&xs, c.R, pn, po);
	best[0].idx = malloc(sizeof *best[0].idx * n);
	best[1].idx = malloc(sizeof *best[1].idx * n);
	alive = malloc(n);
	caught = calloc(n, 1);
	scratch = calloc(n, 1);
	g.count = malloc(sizeof *g.count * PATCH_MAX * PATCH_MAX);
	g.comp = malloc(sizeof *g.comp * PATCH_MAX * PATCH_MAX);
	g.stack = malloc(sizeof *g.stack * PATCH_MAX * PATCH_MAX);
	g.box = malloc(sizeof *g.box * PATCH_MAX * PATCH_MAX);
	g.cellof = malloc(sizeof *g.cellof * n);
	g.pairs = malloc(sizeof *g.pairs * n);
	out->portals = malloc(sizeof *out->portals * MAX_PORTALS);
	if (np < 0 || !best[0].idx || !best[1].idx || !alive || !caught || !scratch || !g.count || !g.comp || !g.stack || !g.box || !g.cellof ||
	    !g.pairs || !out->portals) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
		goto done;
	}
	memset(alive, 1, n);
	V3 blo = v3(AJAR_INF, AJAR_INF, AJAR_INF), bhi = v3(-AJAR_INF, -AJAR_INF, -AJAR_INF);
	for (uint32_t i = 0; i < ntris; i++) {
		GLOBAL const Tri *t = &v->tris[i];
		blo = v3_min(blo, v3_min(t->p0, v3_min(t->p1, t->p2)));
		bhi = v3_max(bhi, v3_max(t->p0, v3_max(t->p1, t->p2)));
	}

	/* Steps 4 to 8: again and again, the patch of a candidate plane where
	 * the open lines crowd most tightly; its open cells' rectangles with
	 * light behind them become portals, and the lines they catch (any
	 * line, not only the patch's) are closed, until under MIN_SHARE of
	 * them would remain for a portal. */
	uint32_t left = n;
	uint32_t accepted = 0;
	for (int round = 0; round < MAX_ROUNDS && accepted < MAX_PORTALS; round++) {
		pf_best_patch(&c, &xs, alive, pn, po, np, blo, bhi, &g, best);
		PF_DEBUG("round %d best %.1f plane %d m %u; next %.1f plane %d m %u\n", round, best[0].score, best[0].q,
			 best[0].m, best[1].score, best[1].q, best[1].m);
		if (best[0].score <= 0.0 || (float)best[0].m < MIN_SHARE * (float)n)
			break;
		/* The best patch, or the runner-up on another plane where its
		 * score comes close: the one whose rectangles catch the open lines
		 * more tightly (lines per area^0.75) wins. */
		uint32_t from = rs.n;
		int pick = 0;
		double tight[2] = {0.0, 0.0};
		for (int b = 0; b < 2; b++) {
			if (b == 1 && !(best[1].score >= RUNNER_UP * best[0].score && (float)best[1].m >= MIN_SHARE * (float)n))
				break;
			uint32_t mark = rs.n;
			if ((st = pf_open_rects(&c, xs.x, best[b].idx, best[b].m, pn[best[b].q], po[best[b].q], n, scratch, &rs)) !=
			    AJAR_OK)
				goto done;
			pf_merge_rects(&rs, mark, c.R);
			double area = 0.0;
			uint32_t lines = 0;
			for (uint32_t k = 0; k < n; k++) {
				int in = 0;
				for (uint32_t r = mark; r < rs.n && !in; r++)
					in = rs.r[r].alive && pf_rect_catches(&rs.r[r], &xs.x[k], c.R);
				lines += alive[k] && in;
			}
			for (uint32_t r = mark; r < rs.n; r++)
				if (rs.r[r].alive)
					area += (double)(rs.r[r].hi1 - rs.r[r].lo1) * (rs.r[r].hi2 - rs.r[r].lo2);
			tight[b] = area > 0.0 ? lines / pow(area, 0.75) : 0.0;
			if (b == 1) {
				pick = tight[1] > tight[0];
				/* The loser's rectangles are dropped. */
				for (uint32_t r = pick ? from : mark; r < (pick ? mark : rs.n); r++)
					rs.r[r].alive = 0;
			}
		}
		PF_DEBUG("  tightness %.1f / %.1f: plane %d\n", tight[0], tight[1], best[pick].q);
		int q = best[pick].q;
		uint32_t m = best[pick].m, *idx = best[pick].idx;
		(void)q;
		for (uint32_t i = 0; i < m; i++)
			alive[idx[i]] = 0; /* the patch is settled, caught or not */
		for (uint32_t r = from; r < rs.n; r++) {
			Rect *rc = &rs.r[r];
			if (!rc->alive || !light_behind(&c, rc))
				continue;
			/* The lines it catches that no portal caught: their count
			 * decides (aimed rays count: a small opening found is
			 * kept), the first sample's share is its share. */
			uint32_t gain = 0, first = 0;
			for (uint32_t k = 0; k < n; k++)
				if (!caught[k] && pf_rect_catches(rc, &xs.x[k], c.R)) {
					caught[k] = 1;
					alive[k] = 0;
					gain++;
					first += (uint32_t)xs.x[k].weight;
				}
			rc->share = nfirst ? (float)first / (float)nfirst : 0.0f;
			rc->accepted = (float)gain >= MIN_SHARE * (float)n;
			accepted += rc->accepted;
		}
		left = 0;
		for (uint32_t k = 0; k < n; k++)
			left += alive[k];
		PF_DEBUG("round %d: plane n(%.3f %.3f %.3f) s %.3f patch %u lines, %u portals, %u left\n", round, pn[q].x, pn[q].y, pn[q].z, po[q], m, accepted, left);
		if ((float)left < MIN_SHARE * (float)n)
			break;
	}
	/* The portals: the accepted rectangles, those of one plane merged where
	 * one rectangle covers them with little more area. */
	for (uint32_t r = 0; r < rs.n; r++)
		rs.r[r].alive = rs.r[r].accepted;
	pf_merge_rects(&rs, 0, c.R);
	for (uint32_t r = 0; r < rs.n && out->count < MAX_PORTALS; r++) {
		const Rect *rc = &rs.r[r];
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
	free(xs.x);
	free(rs.r);
	free(best[0].idx), free(best[1].idx);
	free(alive);
	free(caught);
	free(scratch);
	free(g.count), free(g.comp), free(g.stack), free(g.box), free(g.cellof), free(g.pairs);
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
