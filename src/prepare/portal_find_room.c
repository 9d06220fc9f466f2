/* portal_find_room.c — steps 1 and 2 of the portal search: the camera's
 * space (the room's points and its scale R) and the light samples of
 * emitters and lamps. */
#include "prepare/portal_find_parts.h"

static int room_add(RoomPts *r, V3 p, V3 n, int surf)
{
	if (r->n == r->cap) {
		uint32_t cap = r->cap ? 2 * r->cap : 1024;
		RoomPt *g = realloc(r->pt, sizeof *g * cap);
		if (!g)
			return 0;
		r->pt = g;
		r->cap = cap;
	}
	r->pt[r->n].p = p;
	r->pt[r->n].n = n;
	r->pt[r->n++].surf = surf;
	return 1;
}

/* A point just in front of hit s of the ray o + t d. */
static V3 in_front(const Ctx *c, V3 o, V3 d, const Solid *s)
{
	float back = fmin(0.03f * c->R, 0.25f * s->t);
	return v3_madd(v3_madd(o, d, s->t - back), s->ng, 1e-4f * c->R);
}

ajar_status pf_room_points(Ctx *c, V3 cam, RoomPts *r)
{
	Rng rng = rng_init(0x70a7a1u, 1u, 0u, 0u);
	Solid *first = malloc(sizeof *first * CAMERA_RAYS);
	V3 *dirs = malloc(sizeof *dirs * CAMERA_RAYS);
	float *dist = malloc(sizeof *dist * CAMERA_RAYS);
	if (!first || !dirs || !dist) {
		free(first), free(dirs), free(dist);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
	}
	int nd = 0;
	for (int i = 0; i < CAMERA_RAYS; i++) {
		dirs[i] = pf_dir_about(&rng, v3(0, 1, 0), 0);
		if (pf_trace(c, cam, dirs[i], AJAR_INF, &first[i]))
			dist[nd++] = first[i].t;
	}
	/* The room scale: twice the RMS distance of the hits from their
	 * centroid (a near sofa does not shrink it, as it would a median). */
	c->R = 0.0f;
	if (nd >= CAMERA_RAYS / 2) { /* else the camera stands outside: no room */
		double sx = 0, sy = 0, sz = 0, s2 = 0;
		for (int i = 0; i < CAMERA_RAYS; i++)
			if (first[i].t != AJAR_INF) {
				V3 p = first[i].p;
				sx += p.x, sy += p.y, sz += p.z;
				s2 += (double)p.x * p.x + (double)p.y * p.y + (double)p.z * p.z;
			}
		double var = s2 / nd - (sx * sx + sy * sy + sz * sz) / ((double)nd * nd);
		c->R = (float)(2.0 * sqrt(var > 0.0 ? var : 0.0));
	}
	ajar_status st = AJAR_OK;
	if (c->R > 0.0f && !room_add(r, cam, v3(0, 1, 0), 0))
		st = AJAR_ERROR_OUT_OF_MEMORY;
	uint32_t surf0 = r->n;
	for (int i = 0; c->R > 0.0f && st == AJAR_OK && i < CAMERA_RAYS; i++) {
		if (first[i].t == AJAR_INF)
			continue;
		if (!room_add(r, in_front(c, cam, dirs[i], &first[i]), first[i].ng, 1) ||
		    (i % 4 == 0 && !room_add(r, v3_madd(cam, dirs[i], 0.5f * first[i].t), v3(0, 1, 0), 0)))
			st = AJAR_ERROR_OUT_OF_MEMORY;
	}
	/* One diffuse bounce further, from the surface points of the first. */
	uint32_t nfirst = r->n;
	for (uint32_t j = 0; c->R > 0.0f && st == AJAR_OK && j < SECOND_RAYS && nfirst > surf0; j++) {
		RoomPt from = r->pt[surf0 + (j * 7919u) % (nfirst - surf0)];
		if (!from.surf)
			continue;
		V3 d = pf_dir_about(&rng, from.n, 1);
		Solid s;
		if (pf_trace(c, from.p, d, AJAR_INF, &s) && !room_add(r, in_front(c, from.p, d, &s), s.ng, 1))
			st = AJAR_ERROR_OUT_OF_MEMORY;
	}
	/* Points seen through an opening (a garden through the window, the
	 * casing behind it) lie outside: a point stays in the room if it sees
	 * at least ROOM_SEES of ROOM_PEERS surface points seen from the camera. */
	uint32_t kept = 1;
	for (uint32_t i = 1; c->R > 0.0f && st == AJAR_OK && i < r->n; i++) {
		int seen = 0;
		for (int k = 0; k < ROOM_PEERS && seen < ROOM_SEES && nfirst > surf0; k++) {
			const RoomPt *q = &r->pt[surf0 + ((uint32_t)k * 2654435761u + i) % (nfirst - surf0)];
			seen += q != &r->pt[i] && pf_clear(c, r->pt[i].p, q->p);
		}
		if (seen >= ROOM_SEES)
			r->pt[kept++] = r->pt[i];
	}
	if (r->n)
		r->n = kept;
	free(first), free(dirs), free(dist);
	return st ? err_set(st, "portal search: out of memory") : AJAR_OK;
}

/* ---- Step 2: the light ---------------------------------------------------- */

ajar_status pf_light_points(Ctx *c, uint32_t ntris, const PortalFindInput *in, const RoomPts *room)
{
	const SceneView *v = c->v;
	c->sky = in->env_type != ENV_NONE;
	uint32_t lamps = 0;
	for (uint32_t i = 0; i < in->nlights; i++) {
		if (in->lights[i].type == AJAR_LIGHT_DIRECTIONAL)
			c->sky = 1;
		else
			lamps++;
	}
	double total = 0.0;
	for (uint32_t i = 0; i < ntris; i++) {
		GLOBAL const Material *m = &v->materials[v->tris[i].material];
		if (!v3_is_zero(m->emission))
			total += 0.5 * v3_len(tri_normal(&v->tris[i])) * v3_lum(m->emission);
	}
	uint32_t nemit = total > 0.0 ? LIGHT_POINTS : 0;
	c->lp = malloc(sizeof *c->lp * (lamps + nemit + BOUNCE_POINTS + 1));
	if (!c->lp)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
	for (uint32_t i = 0; i < in->nlights; i++)
		if (in->lights[i].type != AJAR_LIGHT_DIRECTIONAL) {
			const float *q = in->lights[i].position;
			c->lp[c->nlp].p = v3(q[0], q[1], q[2]);
			c->lp[c->nlp++].n = v3(0, 0, 0);
		}
	/* Emitter points by power: stratified picks along the triangles' sum. */
	Rng rng = rng_init(0x70a7a1u, 2u, 0u, 0u);
	double acc = 0.0;
	uint32_t k = 0;
	for (uint32_t i = 0; i < ntris && k < nemit; i++) {
		GLOBAL const Tri *t = &v->tris[i];
		GLOBAL const Material *m = &v->materials[t->material];
		if (v3_is_zero(m->emission))
			continue;
		acc += 0.5 * v3_len(tri_normal(t)) * v3_lum(m->emission);
		while (k < nemit && (k + 0.5) * total / nemit <= acc) {
			V3 p, n;
			sample_triangle_point(t->p0, t->p1, t->p2, rnd(&rng), rnd(&rng), &p, &n);
			c->lp[c->nlp].p = v3_madd(p, n, 1e-4f * c->R);
			c->lp[c->nlp++].n = n;
			k++;
		}
	}
	/* Points the lights light, one bounce on (virtual lights): light that
	 * comes in only after a bounce behind the opening (over a door leaf's
	 * top, from the lit floor of the room behind) shows on what they
	 * light. From each light point in turn, a ray (cosine about an
	 * emitter's normal, any way from a lamp); a point just in front of its
	 * hit, lighting that side. */
	uint32_t direct = c->ndirect = c->nlp;
	for (uint32_t i = 0; direct && i < BOUNCE_POINTS; i++) {
		const LightPoint *l = &c->lp[i % direct];
		V3 d = pf_dir_about(&rng, l->n, !v3_is_zero(l->n));
		Solid s;
		if (!pf_trace(c, l->p, d, AJAR_INF, &s))
			continue;
		/* Only behind the openings: one the room sees (light already
		 * in, or a lamp's own room) would make the room's walls look lit
		 * from outside. */
		V3 q = v3_madd(s.p, s.ng, 1e-4f * c->R);
		int seen = 0;
		for (uint32_t k = 0; k < ROOM_PEERS && k < room->n && !seen; k++) {
			V3 from = room->pt[(k * 2654435761u + i) % room->n].p;
			seen = v3_dot(v3_sub(from, q), s.ng) > 0.0f && pf_clear(c, from, q);
		}
		if (!seen) {
			c->lp[c->nlp].p = q;
			c->lp[c->nlp++].n = s.ng;
		}
	}
	return AJAR_OK;
}
