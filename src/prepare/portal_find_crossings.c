/* portal_find_crossings.c — steps 2 and 3 of the portal search: rays from
 * the room that leave through openings, the ring test that finds their wall,
 * rays aimed where crossings are few; and step 7's lines from the room to
 * the light points that pass beside the portals found. */
#include "prepare/portal_find_parts.h"

static int cmp_float(const void *a, const void *b)
{
	float x = *(const float *)a, y = *(const float *)b;
	return x < y ? -1 : x > y;
}

static int push(Crossings *l, const Crossing *x)
{
	if (l->n == l->cap) {
		uint32_t cap = l->cap ? 2 * l->cap : 4096;
		Crossing *g = realloc(l->x, sizeof *g * cap);
		if (!g)
			return 0;
		l->x = g;
		l->cap = cap;
	}
	l->x[l->n++] = *x;
	return 1;
}

static int ring_test(Ctx *c, Rng *rng, Crossing *x)
{
	static const float deg[] = {2.0f, 5.0f, 12.0f, 30.0f};
	V3 a, b;
	v3_basis(x->d, &a, &b);
	float limit = x->t == AJAR_INF ? AJAR_INF : fmin(RING_NEAR * x->t, x->t - 0.05f * c->R);
	if (!(limit > 0.0f))
		return 0;
	float rot = rnd(rng);
	x->nn = 0;
	for (int r = 0; r < 4; r++) {
		float ang = deg[r] * AJAR_PI / 180.0f, ca = cos(ang), sa = sin(ang);
		V3 hp[RING_DIRS], hn[RING_DIRS];
		int blocked = 0;
		for (int j = 0; j < RING_DIRS; j++) {
			float phi = 2.0f * AJAR_PI * ((float)j + rot) / RING_DIRS;
			V3 d = v3_norm(v3_add(v3_scale(x->d, ca), v3_add(v3_scale(a, sa * cos(phi)), v3_scale(b, sa * sin(phi)))));
			Solid s;
			if (pf_trace(c, x->P, d, limit, &s)) {
				hp[blocked] = s.p;
				hn[blocked++] = s.ng;
				if (x->nn < RING_NORMALS) {
					x->rn[x->nn] = s.ng;
					x->rp[x->nn++] = s.p;
				}
			}
		}
		if (blocked < RING_NEED)
			continue;
		/* The wall: the normal most of the hits share, its median offset. */
		int best = -1, count = 0;
		for (int i = 0; i < blocked; i++) {
			int k = 0;
			for (int j = 0; j < blocked; j++)
				k += v3_dot(hn[i], hn[j]) > 0.94f;
			if (k > count)
				count = k, best = i;
		}
		float off[RING_DIRS];
		int m = 0;
		V3 wn = hn[best];
		for (int j = 0; j < blocked; j++)
			if (v3_dot(wn, hn[j]) > 0.94f)
				off[m++] = v3_dot(wn, hp[j]);
		qsort(off, (size_t)m, sizeof *off, cmp_float);
		float ws = off[m / 2], dn = v3_dot(wn, x->d);
		if (!(dn < -0.05f))
			return 0;
		/* A ray that meets the wall at once started in the opening (on
		 * a blind's slat, in a window's reveal): it says little of where
		 * the opening lies. */
		float tx = (ws - v3_dot(wn, x->P)) / dn;
		if (!(tx > NEAR_START * c->R) || !(tx < x->t))
			return 0;
		x->ring = ang;
		x->wn = wn;
		x->ws = ws;
		x->X = v3_madd(x->P, x->d, tx);
		return 1;
	}
	return 0;
}

/* Four light samples per room point, and whether it sees them. */
void pf_room_lights(Ctx *c, RoomPts *r)
{
	Rng rng = rng_init(0x70a7a1u, 5u, 0u, 0u);
	for (uint32_t i = 0; i < r->n; i++) {
		RoomPt *from = &r->pt[i];
		from->base = c->nlp ? rng_u32(&rng) % c->nlp : 0;
		for (int k = 0; k < 4; k++) {
			from->sees[k] = 0;
			if (!c->nlp)
				continue;
			const LightPoint *l = &c->lp[(from->base + (uint32_t)k) % c->nlp];
			V3 to = v3_sub(l->p, from->p);
			from->sees[k] = (v3_is_zero(l->n) || v3_dot(to, l->n) < 0.0f) && pf_clear(c, from->p, l->p);
		}
	}
}

/* A ray from room point `o` along d, kept in strong or weak if it
 * reaches light (step 2). */
static int room_ray(Ctx *c, const RoomPts *r, uint32_t o, V3 d, uint32_t j, Crossings *strong, Crossings *weak)
{
	Solid s;
	const RoomPt *from = &r->pt[o];
	pf_trace(c, from->p, d, AJAR_INF, &s);
	Crossing x = {.from = from, .origin = o, .P = from->p, .d = d, .t = s.t, .strong = s.t == AJAR_INF || s.emit};
	if (x.strong)
		return push(strong, &x);
	if (c->nlp && !from->sees[j % 4] && pf_lit_by(c, s.p, s.ng, &c->lp[(from->base + j % 4) % c->nlp]))
		return push(weak, &x);
	return 1;
}

/* Ring-tests up to `most` of the candidates in l, evenly spread, into xs. */
static int ring_all(Ctx *c, Rng *rng, const Crossings *l, uint32_t most, Crossings *xs)
{
	uint32_t stride = l->n > most ? (l->n + most - 1) / most : 1;
	for (uint32_t i = 0; i < l->n; i += stride) {
		Crossing x = l->x[i];
		if (ring_test(c, rng, &x) && !push(xs, &x))
			return 0;
	}
	return 1;
}

/* Rays aimed near crossing x: from room points within 0.3 R of its
 * origin (up to 16 of them, the origin's own among them), within its
 * ring's angle of the line to its far end (its opening as seen from
 * there). Many origins, not one: an opening is seen from all over. */
static int focus_rays(Ctx *c, Rng *rng, const RoomPts *r, const Crossing *x, uint32_t count, Crossings *strong,
		      Crossings *weak)
{
	uint32_t near[16], nn = 0;
	near[nn++] = x->origin;
	uint32_t start = rng_u32(rng) % r->n;
	for (uint32_t k = 0; k < r->n && nn < 16; k++) {
		uint32_t i = (start + k) % r->n;
		if (i != x->origin && v3_len2(v3_sub(r->pt[i].p, x->P)) < 0.09f * c->R * c->R)
			near[nn++] = i;
	}
	V3 aim = x->t == AJAR_INF ? v3_madd(x->P, x->d, 4.0f * c->R) : v3_madd(x->P, x->d, x->t);
	for (uint32_t j = 0; j < count; j++) {
		uint32_t o = near[j % nn];
		const RoomPt *from = &r->pt[o];
		V3 d = v3_norm(v3_sub(aim, from->p)), t, b;
		if (from->surf && v3_dot(d, from->n) <= 0.0f)
			continue;
		v3_basis(d, &t, &b);
		V3 w = sample_uniform_cone(rnd(rng), rnd(rng), cos(0.7f * x->ring));
		d = v3_norm(v3_from_local(w, t, b, d));
		if (!room_ray(c, r, o, d, j, strong, weak))
			return 0;
	}
	return 1;
}

ajar_status pf_find_crossings(Ctx *c, const RoomPts *r, Crossings *out)
{
	uint32_t per = r->n ? ROOM_RAYS / r->n : 0;
	if (per < 8)
		per = 8;
	Crossings strong = {0}, weak = {0}, more = {0};
	uint32_t *size = NULL;
	Rng rng = rng_init(0x70a7a1u, 3u, 0u, 0u);
	for (uint32_t i = 0; i < r->n; i++)
		for (uint32_t j = 0; j < per; j++)
			if (!room_ray(c, r, i, pf_dir_about(&rng, r->pt[i].n, r->pt[i].surf), j, &strong, &weak))
				goto oom;
	/* At most MAX_CANDIDATES, evenly spread, the rays that escaped or met
	 * an emitter first. */
	out->n = 0;
	if (!ring_all(c, &rng, &strong, MAX_CANDIDATES, out) ||
	    !ring_all(c, &rng, &weak, MAX_CANDIDATES - (out->n < MAX_CANDIDATES / 2 ? out->n : MAX_CANDIDATES / 2), out))
		goto oom;
	/* Small openings get few rays: more, aimed near each crossing, the
	 * fewer the more crossings already pass near it (within FOCUS_NEAR R,
	 * directions within 10 degrees: a slit above a door leaf is not a
	 * crowded gap beside it), in two rounds. Only the first rays weigh
	 * in the portals' shares: they sample the room's lines as they are. */
	for (uint32_t i = 0; i < out->n; i++)
		out->x[i].weight = 1;
	for (int round = 0; round < 2; round++) {
		uint32_t n = out->n;
		size = realloc(size, sizeof *size * (n ? n : 1));
		if (!size)
			goto oom;
		float near2 = FOCUS_NEAR * c->R * FOCUS_NEAR * c->R;
		for (uint32_t i = 0; i < n; i++)
			size[i] = 1;
		for (uint32_t i = 0; i < n; i++)
			for (uint32_t j = i + 1; j < n; j++)
				if (v3_dot(out->x[i].d, out->x[j].d) > 0.985f && v3_len2(v3_sub(out->x[i].X, out->x[j].X)) < near2)
					size[i]++, size[j]++;
		strong.n = weak.n = 0;
		/* A place with m < FOCUS_TARGET crossings gets 2 (FOCUS_TARGET - m)
		 * aimed rays (about half come through), shared by its crossings;
		 * at most FOCUS_MAX a round. */
		uint64_t want = 0;
		for (uint32_t i = 0; i < n; i++)
			want += size[i] < FOCUS_TARGET ? 2u * (FOCUS_TARGET - size[i]) / size[i] : 0u;
		double scale = want > FOCUS_MAX ? (double)FOCUS_MAX / (double)want : 1.0;
		for (uint32_t i = 0; i < n; i++) {
			uint32_t rays = size[i] < FOCUS_TARGET ? (uint32_t)(scale * (2u * (FOCUS_TARGET - size[i]) / size[i])) : 0u;
			if (rays && !focus_rays(c, &rng, r, &out->x[i], rays, &strong, &weak))
				goto oom;
		}
		more.n = 0;
		if (!ring_all(c, &rng, &strong, MAX_CANDIDATES, &more) || !ring_all(c, &rng, &weak, MAX_CANDIDATES, &more))
			goto oom;
		for (uint32_t i = 0; i < more.n; i++) {
			more.x[i].weight = 0;
			if (!push(out, &more.x[i]))
				goto oom;
		}
		PF_DEBUG("round %d: focus strong %u weak %u -> %u more, total %u\n", round, strong.n, weak.n, more.n, out->n);
	}
	PF_DEBUG("rooms %u R %.3f nlp %u crossings %u\n", r->n, c->R, c->nlp, out->n);
	free(strong.x), free(weak.x), free(more.x), free(size);
	return AJAR_OK;
oom:
	free(strong.x), free(weak.x), free(more.x), free(size);
	return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
}

/* Whether line x went through a portal already accepted: passes within
 * BESIDE_SLAB R of it (pf_rect_near). */
static int caught_by(const Rects *rs, const Crossing *x, float R)
{
	for (uint32_t i = 0; i < rs->n; i++)
		if (rs->r[i].accepted && pf_rect_near(&rs->r[i], x, BESIDE_SLAB * R, R))
			return 1;
	return 0;
}

ajar_status pf_beside(Ctx *c, const RoomPts *r, Crossings *xs, const Rects *rs)
{
	Crossings strong = {0}, weak = {0}, more = {0};
	Rng rng = rng_init(0x70a7a1u, 7u, 0u, 0u);
	uint32_t per = c->nlp, start = 0;
	if (r->n && per * r->n > BESIDE_PAIRS)
		per = BESIDE_PAIRS / r->n > 0 ? BESIDE_PAIRS / r->n : 1;
	for (uint32_t i = 0; i < r->n && c->nlp; i++) {
		const RoomPt *from = &r->pt[i];
		for (uint32_t k = 0; k < per; k++) {
			uint32_t li = (start + k * c->nlp / per) % c->nlp;
			const LightPoint *l = &c->lp[li];
			V3 to = v3_sub(l->p, from->p);
			float t = v3_len(to);
			if (!(t > 0.0f) || (from->surf && v3_dot(to, from->n) <= 0.0f) ||
			    (!v3_is_zero(l->n) && !(v3_dot(to, l->n) < 0.0f)))
				continue;
			Crossing x = {.from = from, .origin = i, .P = from->p, .d = v3_scale(to, 1.0f / t), .t = t};
			/* A light point the room point sees past every portal:
			 * its line went through another opening. */
			if (caught_by(rs, &x, c->R) || !pf_clear(c, from->p, l->p))
				continue;
			x.strong = li < c->ndirect; /* a lamp's or an emitter's point */
			if (!push(x.strong ? &strong : &weak, &x))
				goto oom;
		}
		start += 7919u;
	}
	if (!ring_all(c, &rng, &strong, MAX_CANDIDATES, &more) || !ring_all(c, &rng, &weak, MAX_CANDIDATES, &more))
		goto oom;
	for (uint32_t i = 0; i < more.n; i++) {
		more.x[i].weight = 0;
		if (!push(xs, &more.x[i]))
			goto oom;
	}
	PF_DEBUG("beside: strong %u weak %u -> %u lines\n", strong.n, weak.n, more.n);
	free(strong.x), free(weak.x), free(more.x);
	return AJAR_OK;
oom:
	free(strong.x), free(weak.x), free(more.x);
	return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
}
