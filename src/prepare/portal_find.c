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
 * gets none: nothing escapes, and lit points inside fail the ring test. */
#include "prepare/portal_find.h"

#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <time.h>

#include "core/error.h"
#include "geom/bvh.h"
#include "sample/rng.h"
#include "sample/sampling.h"

/* -DPORTAL_FIND_DEBUG prints the search's steps on stderr. */
#ifdef PORTAL_FIND_DEBUG
#define PF_DEBUG(...) fprintf(stderr, __VA_ARGS__)
#else
#define PF_DEBUG(...) ((void)0)
#endif

#define CAMERA_RAYS 1024   /* step 1 */
#define SECOND_RAYS 512
#define ROOM_PEERS 16      /* a room point sees ROOM_SEES of these */
#define ROOM_SEES 3
#define ROOM_RAYS 65536    /* step 2, over all room points */
#define MAX_CANDIDATES 2048
#define FOCUS_TARGET 96    /* crossings a place (and direction) should have */
#define FOCUS_NEAR 0.05f   /* x R: a place's radius */
#define FOCUS_MAX 32768    /* aimed rays a round at most */
#define LIGHT_POINTS 64    /* light samples of emitters and lamps */
#define BOUNCE_POINTS 64   /* and of what they light */
#define RING_DIRS 8        /* step 3 */
#define RING_NEED 7
#define RING_NEAR 0.85f
#define RING_NORMALS 16    /* hit normals kept per crossing */
#define NEAR_START 0.1f    /* x R: crossings nearer their start are left out */
#define MAX_PLANES 32      /* step 4: surfaces around the holes tried */
#define PATCH_CELL 0.01f   /* x R: cells of the crossings' raster on a plane */
#define PATCH_JOIN 3       /* crossings this many cells apart join one patch */
#define PATCH_FLOOR 0.05f  /* x R: a patch counts as at least this square */
#define PATCH_MAX 384      /* at most this many a side */
#define PATCH_DN 0.3f      /* lines that cross a plane at a shallower cosine do not count there */
#define MAX_ROUNDS 32
#define RUNNER_UP 0.5      /* a patch on another plane this close to the best is tried too */
#define MEET_DN 0.05f      /* a line crossing a portal at a shallower cosine does not count */
#define PLANE_OFFSET 1e-3f /* x R: a portal lies this far beyond the surface it was found in */
#define GRID 64            /* step 5: cells a side */
#define CELL_ORIGINS 3
#define SKY_RAYS 4         /* a point under the sky: SKY_SEEN of SKY_RAYS rays escape */
#define SKY_SEEN 2
#define REFRAME 0.6f       /* open cells this much narrower in a turned frame: the grid turns */
#define GROW_TRIES 3       /* the grid grows where open cells touch its border */
#define EDGE_STEPS 4       /* bisections of each edge of a rectangle (to 1/16 cell) */
#define EDGE_PROBES 16     /* points along it each */
#define EDGE_MARGIN 0.25f  /* x a cell: a rectangle's margin beyond its opening */
#define SLIDE_STEP 0.005f  /* x R: a rectangle slides out through a tunnel by these steps */
#define SLIDE_STEPS 24
#define RIM_GAP 0.03f      /* x its size: its rim lies this far outside it */
#define SLIDE_SOLID 0.1f   /* x R */
#define CONNECT 2          /* open cells this many cells apart join */
#define MERGE_AREA 1.25    /* step 6 */
#define MERGE_GAP 0.03f    /* x R: rectangles of planes this close may merge */
#define MIN_SHARE 0.02f    /* lines a portal must catch */
#define MAX_PORTALS 16

typedef struct {
	V3 p, n; /* a point; n the emitting side (zero for a lamp) */
} LightPoint;

typedef struct {
	const SceneView *v;
	float R;       /* room scale */
	uint64_t rays;
	LightPoint *lp;
	uint32_t nlp;
	int sky;       /* a sky or a sun: what escapes finds light */
} Ctx;

/* A ray's first solid hit (glass passed through); t = AJAR_INF: escaped. */
typedef struct {
	float t;
	V3 p, ng; /* ng unit, facing the ray's origin */
	int emit; /* an emitter's front face */
} Solid;

static int trace(Ctx *c, V3 o, V3 d, float tmax, Solid *s)
{
	float acc = 0.0f;
	for (int k = 0; k < 16; k++) {
		Hit h;
		c->rays++;
		if (!bvh_intersect(c->v, o, d, tmax - acc, &h))
			break;
		GLOBAL const Tri *tri = &c->v->tris[h.tri];
		GLOBAL const Material *m = &c->v->materials[tri->material];
		V3 p = v3_madd(o, d, h.t), ng = tri_normal(tri);
		if (m->transmission > 0.0f) { /* glass counts as open */
			o = ray_offset(p, ng, d);
			acc += h.t;
			continue;
		}
		float side = v3_dot(ng, d);
		s->t = acc + h.t;
		s->p = p;
		s->ng = v3_norm(side < 0.0f ? ng : v3_neg(ng));
		s->emit = side < 0.0f && !v3_is_zero(m->emission);
		return 1;
	}
	s->t = AJAR_INF;
	s->emit = 0;
	return 0;
}

/* Whether the segment a -> b is free (b excluded). */
static int clear(Ctx *c, V3 a, V3 b)
{
	V3 d = v3_sub(b, a);
	float l = v3_len(d);
	if (!(l > 0.0f))
		return 1;
	Solid s;
	return !trace(c, a, v3_scale(d, 1.0f / l), l * 0.9999f, &s);
}

/* Whether light point l lights a surface point p with normal n (facing
 * where the ray came from). */
static int lit_by(Ctx *c, V3 p, V3 n, const LightPoint *l)
{
	V3 to = v3_sub(l->p, p);
	if (!(v3_dot(to, n) > 0.0f))
		return 0;
	if (!v3_is_zero(l->n) && !(v3_dot(to, l->n) < 0.0f))
		return 0;
	return clear(c, v3_madd(p, n, 1e-4f * c->R), l->p);
}

static float rnd(Rng *r) { return rng_f(r); }

static V3 dir_about(Rng *r, V3 n, int cosine)
{
	if (!cosine)
		return sample_uniform_sphere(rnd(r), rnd(r));
	V3 t, b;
	v3_basis(n, &t, &b);
	float u1 = rnd(r), u2 = rnd(r);
	return v3_norm(v3_from_local(sample_cosine_hemisphere(u1, u2), t, b, n));
}

static int cmp_float(const void *a, const void *b)
{
	float x = *(const float *)a, y = *(const float *)b;
	return x < y ? -1 : x > y;
}

/* The k-th smallest of a[0..n) (reorders a). */
static float select_k(float *a, int n, int k)
{
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		float piv = a[(lo + hi) / 2];
		int i = lo, j = hi;
		while (i <= j) {
			while (a[i] < piv)
				i++;
			while (a[j] > piv)
				j--;
			if (i <= j) {
				float t = a[i];
				a[i] = a[j];
				a[j] = t;
				i++;
				j--;
			}
		}
		if (k <= j)
			hi = j;
		else if (k >= i)
			lo = i;
		else
			break;
	}
	return a[k];
}

/* The trimmed range [q, 1 - q] of a[0..n) (reorders a). */
static void trimmed(float *a, int n, float q, float *lo, float *hi)
{
	int k = (int)(q * (float)n);
	*lo = select_k(a, n, k);
	*hi = select_k(a, n, n - 1 - k);
}

/* ---- Step 1: the camera's space ------------------------------------------ */

typedef struct {
	V3 p, n;
	int surf; /* on a surface (rays leave about n) */
	uint32_t base; /* its four light samples: lp[(base + k) % nlp] */
	int sees[4];   /* whether it sees them */
} RoomPt;

typedef struct {
	RoomPt *pt;
	uint32_t n, cap;
} RoomPts;

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

static ajar_status room_points(Ctx *c, V3 cam, RoomPts *r)
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
		dirs[i] = dir_about(&rng, v3(0, 1, 0), 0);
		if (trace(c, cam, dirs[i], AJAR_INF, &first[i]))
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
		V3 d = dir_about(&rng, from.n, 1);
		Solid s;
		if (trace(c, from.p, d, AJAR_INF, &s) && !room_add(r, in_front(c, from.p, d, &s), s.ng, 1))
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
			seen += q != &r->pt[i] && clear(c, r->pt[i].p, q->p);
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

static ajar_status light_points(Ctx *c, uint32_t ntris, const PortalFindInput *in, const RoomPts *room)
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
	uint32_t direct = c->nlp;
	for (uint32_t i = 0; direct && i < BOUNCE_POINTS; i++) {
		const LightPoint *l = &c->lp[i % direct];
		V3 d = dir_about(&rng, l->n, !v3_is_zero(l->n));
		Solid s;
		if (!trace(c, l->p, d, AJAR_INF, &s))
			continue;
		/* Only behind the openings: one the room sees (light already
		 * in, or a lamp's own room) would make the room's walls look lit
		 * from outside. */
		V3 q = v3_madd(s.p, s.ng, 1e-4f * c->R);
		int seen = 0;
		for (uint32_t k = 0; k < ROOM_PEERS && k < room->n && !seen; k++) {
			V3 from = room->pt[(k * 2654435761u + i) % room->n].p;
			seen = v3_dot(v3_sub(from, q), s.ng) > 0.0f && clear(c, from, q);
		}
		if (!seen) {
			c->lp[c->nlp].p = q;
			c->lp[c->nlp++].n = s.ng;
		}
	}
	return AJAR_OK;
}

/* ---- Steps 2 and 3: rays through openings, the ring test ------------------ */

typedef struct {
	const RoomPt *from; /* its room point (P, light samples) */
	uint32_t origin;    /* that point's index */
	V3 P, d;      /* the ray */
	float t;      /* its far hit, AJAR_INF escaped */
	int strong;   /* escaped or met an emitter (else: a point lit by a light P does not see) */
	int weight;   /* 1: a ray of the first sample, which the shares count; 0: an aimed one */
	float ring;   /* the ring's angle that found the wall, radians */
	V3 X;         /* where it crosses the wall */
	V3 wn;        /* the wall's normal, facing the room */
	float ws;     /* the wall's offset, wn . x */
	int nn;       /* ring hit normals and points */
	V3 rn[RING_NORMALS], rp[RING_NORMALS];
} Crossing;

typedef struct {
	Crossing *x;
	uint32_t n, cap;
} Crossings;

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
			if (trace(c, x->P, d, limit, &s)) {
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
static void room_lights(Ctx *c, RoomPts *r)
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
			from->sees[k] = (v3_is_zero(l->n) || v3_dot(to, l->n) < 0.0f) && clear(c, from->p, l->p);
		}
	}
}

/* A ray from room point `o` along d, kept in strong or weak if it
 * reaches light (step 2). */
static int room_ray(Ctx *c, const RoomPts *r, uint32_t o, V3 d, uint32_t j, Crossings *strong, Crossings *weak)
{
	Solid s;
	const RoomPt *from = &r->pt[o];
	trace(c, from->p, d, AJAR_INF, &s);
	Crossing x = {.from = from, .origin = o, .P = from->p, .d = d, .t = s.t, .strong = s.t == AJAR_INF || s.emit};
	if (x.strong)
		return push(strong, &x);
	if (c->nlp && !from->sees[j % 4] && lit_by(c, s.p, s.ng, &c->lp[(from->base + j % 4) % c->nlp]))
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

static ajar_status find_crossings(Ctx *c, const RoomPts *r, Crossings *out)
{
	uint32_t per = r->n ? ROOM_RAYS / r->n : 0;
	if (per < 8)
		per = 8;
	Crossings strong = {0}, weak = {0}, more = {0};
	uint32_t *size = NULL;
	Rng rng = rng_init(0x70a7a1u, 3u, 0u, 0u);
	for (uint32_t i = 0; i < r->n; i++)
		for (uint32_t j = 0; j < per; j++)
			if (!room_ray(c, r, i, dir_about(&rng, r->pt[i].n, r->pt[i].surf), j, &strong, &weak))
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

/* ---- Steps 5 to 7: the waist, open cells, rectangles ----------------------- */

typedef struct {
	V3 o, a1, a2, n; /* plane point, in-plane axes, normal (facing the room) */
	float lo1, hi1, lo2, hi2;
	float share;
	int alive;
	int accepted; /* a portal: light behind it, MIN_SHARE of the lines */
} Rect;

typedef struct {
	Rect *r;
	uint32_t n, cap;
} Rects;

static int rect_add(Rects *rs, const Rect *r)
{
	if (rs->n == rs->cap) {
		uint32_t cap = rs->cap ? 2 * rs->cap : 16;
		Rect *g = realloc(rs->r, sizeof *g * cap);
		if (!g)
			return 0;
		rs->r = g;
		rs->cap = cap;
	}
	rs->r[rs->n++] = *r;
	return 1;
}

/* An in-plane frame: the first axis the world's up projected, or x for
 * horizontal planes. */
static void plane_frame(V3 n, V3 *a1, V3 *a2)
{
	V3 up = fabs(n.y) < 0.9f ? v3(0, 1, 0) : v3(1, 0, 0);
	*a1 = v3_norm(v3_madd(up, n, -v3_dot(up, n)));
	*a2 = v3_cross(n, *a1);
}

/* Where line (P, d) meets the plane n . x = s, if between its start and
 * its far hit: 1 and the distance. */
static int meet(const Crossing *x, V3 n, float s, float R, float min_dn, float *t)
{
	float dn = v3_dot(n, x->d);
	if (!(fabs(dn) > min_dn))
		return 0;
	*t = (s - v3_dot(n, x->P)) / dn;
	return *t > 0.01f * R && *t < x->t;
}

/* Candidate portal planes: the surfaces the rings met around the holes
 * (walls, jambs, frames, a door leaf), as (normal, offset) buckets of 10
 * degrees and 0.01 R, the most met first; up to MAX_PLANES with at least
 * 0.5% of the hits. Each normal faces where the lines come from. */
static int candidate_planes(const Crossings *xs, float R, V3 *cand, float *offs)
{
	enum { MAXB = 512 };
	V3 *bn = malloc(sizeof *bn * MAXB);
	float(*bs)[2] = malloc(sizeof *bs * MAXB); /* offset sum, count */
	if (!bn || !bs) {
		free(bn), free(bs);
		return -1;
	}
	int nb = 0;
	float total = 0.0f;
	for (uint32_t i = 0; i < xs->n; i++) {
		const Crossing *x = &xs->x[i];
		for (int k = -1; k < x->nn; k++) {
			V3 nrm = k < 0 ? x->wn : x->rn[k];
			float off = k < 0 ? x->ws : v3_dot(nrm, x->rp[k]);
			/* One orientation per plane: its largest component positive. */
			float big = fabs(nrm.x) >= fabs(nrm.y) && fabs(nrm.x) >= fabs(nrm.z) ? nrm.x
				    : fabs(nrm.y) >= fabs(nrm.z)			  ? nrm.y
										  : nrm.z;
			if (big < 0.0f) {
				nrm = v3_neg(nrm);
				off = -off;
			}
			int b = 0;
			while (b < nb && !(v3_dot(bn[b], nrm) > 0.985f && fabs(bs[b][0] / bs[b][1] - off) < 0.01f * R))
				b++;
			if (b == nb) {
				if (nb == MAXB)
					continue;
				bn[nb] = nrm;
				bs[nb][0] = bs[nb][1] = 0.0f;
				nb++;
			}
			bs[b][0] += off;
			bs[b][1] += 1.0f;
			total += 1.0f;
		}
	}
	int nc = 0;
	while (nc < MAX_PLANES) {
		int best = -1;
		for (int b = 0; b < nb; b++)
			if (bs[b][1] > 0.0f && (best < 0 || bs[b][1] > bs[best][1]))
				best = b;
		if (best < 0 || bs[best][1] < 0.005f * total)
			break;
		cand[nc] = bn[best];
		offs[nc++] = bs[best][0] / bs[best][1];
		PF_DEBUG("plane n(%.3f %.3f %.3f) s %.3f hits %.0f\n", bn[best].x, bn[best].y, bn[best].z, bs[best][0] / bs[best][1], bs[best][1]);
		bs[best][1] = -1.0f;
	}
	free(bn), free(bs);
	return nc;
}

/* Of the lines still open (alive), where they crowd most tightly on one
 * candidate plane: the lines through one connected patch of their
 * crossings (cells within PATCH_JOIN join). A patch scores the geometric
 * mean of its lines and of the room points they start from (an opening
 * is seen from all over the room; lines from a few points meet near
 * them by chance) over its bounding box's area to the power 0.75 (two
 * windows a little apart score lower together than the larger alone), the
 * area at least PATCH_FLOOR squared. best[0] gets the best patch, best[1]
 * the best on another plane (score 0: none). */
typedef struct {
	double score; /* 0: none */
	int q;        /* its plane */
	uint32_t *idx, m; /* its lines */
} Patch;

typedef struct {
	float cell;
	int w, h;
	uint32_t *count;
	int *comp, *stack, *cellof;
	int (*box)[4];
	uint64_t *pairs;
} Raster;

static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
	return x < y ? -1 : x > y;
}

static void best_patch(Ctx *c, const Crossings *xs, const uint8_t *alive, const V3 *pn, const float *po, int np,
		       V3 blo, V3 bhi, Raster *g, Patch best[2])
{
	best[0].score = best[1].score = 0.0;
	best[0].q = best[1].q = -1;
	float R = c->R;
	for (int k = 0; k < np; k++) {
		V3 a1, a2;
		plane_frame(pn[k], &a1, &a2);
		/* The raster spans the scene's bounds projected on the plane. */
		float l1 = AJAR_INF, h1 = -AJAR_INF, l2 = AJAR_INF, h2 = -AJAR_INF;
		for (int corner = 0; corner < 8; corner++) {
			V3 p = v3(corner & 1 ? bhi.x : blo.x, corner & 2 ? bhi.y : blo.y, corner & 4 ? bhi.z : blo.z);
			l1 = fmin(l1, v3_dot(p, a1)), h1 = fmax(h1, v3_dot(p, a1));
			l2 = fmin(l2, v3_dot(p, a2)), h2 = fmax(h2, v3_dot(p, a2));
		}
		g->cell = fmax(PATCH_CELL * R, fmax(h1 - l1, h2 - l2) / PATCH_MAX);
		g->w = (int)((h1 - l1) / g->cell) + 1, g->h = (int)((h2 - l2) / g->cell) + 1;
		size_t cells = (size_t)g->w * g->h;
		memset(g->count, 0, sizeof *g->count * cells);
		for (uint32_t i = 0; i < xs->n; i++) {
			float t;
			g->cellof[i] = -1;
			if (!alive[i] || !meet(&xs->x[i], pn[k], po[k], R, PATCH_DN, &t))
				continue;
			V3 y = v3_madd(xs->x[i].P, xs->x[i].d, t);
			int ci = (int)((v3_dot(y, a1) - l1) / g->cell), cj = (int)((v3_dot(y, a2) - l2) / g->cell);
			if (ci >= 0 && cj >= 0 && ci < g->w && cj < g->h) {
				g->cellof[i] = cj * g->w + ci;
				g->count[g->cellof[i]]++;
			}
		}
		/* Label the patches 0, 1, ... with their boxes. */
		int nc = 0;
		for (size_t i = 0; i < cells; i++)
			g->comp[i] = -1;
		for (size_t start = 0; start < cells; start++) {
			if (!g->count[start] || g->comp[start] >= 0)
				continue;
			int sp = 0, *box = g->box[nc];
			box[0] = g->w, box[1] = -1, box[2] = g->h, box[3] = -1;
			g->stack[sp++] = (int)start;
			g->comp[start] = nc;
			while (sp) {
				int cq = g->stack[--sp], qi = cq % g->w, qj = cq / g->w;
				box[0] = qi < box[0] ? qi : box[0], box[1] = qi > box[1] ? qi : box[1];
				box[2] = qj < box[2] ? qj : box[2], box[3] = qj > box[3] ? qj : box[3];
				for (int dj = -PATCH_JOIN; dj <= PATCH_JOIN; dj++)
					for (int di = -PATCH_JOIN; di <= PATCH_JOIN; di++) {
						int ni = qi + di, nj = qj + dj;
						if (ni < 0 || nj < 0 || ni >= g->w || nj >= g->h)
							continue;
						int nq = nj * g->w + ni;
						if (g->count[nq] && g->comp[nq] < 0) {
							g->comp[nq] = nc;
							g->stack[sp++] = nq;
						}
					}
			}
			nc++;
		}
		/* Lines and distinct origins per patch, from sorted (patch, origin). */
		uint32_t np2 = 0;
		for (uint32_t i = 0; i < xs->n; i++)
			if (g->cellof[i] >= 0)
				g->pairs[np2++] = (uint64_t)g->comp[g->cellof[i]] << 32 | xs->x[i].origin;
		qsort(g->pairs, np2, sizeof *g->pairs, cmp_u64);
		for (uint32_t i = 0; i < np2;) {
			uint32_t patch = (uint32_t)(g->pairs[i] >> 32), lines = 0, origins = 0;
			for (; i < np2 && (uint32_t)(g->pairs[i] >> 32) == patch; i++) {
				lines++;
				origins += i == 0 || g->pairs[i] != g->pairs[i - 1];
			}
			const int *box = g->box[patch];
			double area = (double)(box[1] - box[0] + 1) * (box[3] - box[2] + 1) * g->cell * g->cell;
			double score = sqrt((double)lines * origins) / pow(fmax(area, PATCH_FLOOR * PATCH_FLOOR * R * R), 0.75);
			/* The best, and the best on another plane. */
			int slot = score > best[0].score ? 0 : score > best[1].score && best[0].q != k ? 1 : -1;
			if (slot < 0)
				continue;
			if (slot == 0 && best[0].q != k) {
				Patch t = best[1];
				best[1] = best[0];
				best[0] = t;
			}
			Patch *b = &best[slot];
			b->score = score;
			b->q = k;
			b->m = 0;
			for (uint32_t j = 0; j < xs->n; j++)
				if (g->cellof[j] >= 0 && g->comp[g->cellof[j]] == (int)patch)
					b->idx[b->m++] = j;
		}
	}
}

/* The plane of a cell test: its point o, axes a1, a2 and normal n, and
 * the lines crossing it (yl, at u1, u2 in the plane's coordinates). */
typedef struct {
	const Crossing *xs;
	const uint32_t *yl;
	const float *u1, *u2;
	uint32_t k;
	V3 o, a1, a2, n;
} CellPlane;

/* Whether surface point p (normal n, facing where the ray came from) is
 * under the open sky: at least SKY_SEEN of SKY_RAYS cosine rays escape. */
static int sees_sky(Ctx *c, V3 p, V3 n, uint32_t seed)
{
	Rng rng = rng_init(0x70a7a1u, 6u, seed, 0u);
	V3 o = v3_madd(p, n, 1e-4f * c->R);
	int seen = 0;
	for (int i = 0; i < SKY_RAYS && seen < SKY_SEEN; i++) {
		Solid s;
		seen += !trace(c, o, dir_about(&rng, n, 1), AJAR_INF, &s);
	}
	return seen >= SKY_SEEN;
}

/* The cell test (step 6) at (p1, p2) of the plane: open if, from the
 * origin of one of the CELL_ORIGINS lines that cross the plane nearest it,
 * a ray through the point goes on: escapes, meets an emitter, a point lit
 * by a light that origin does not see, or a point
 * lit from outside (under the sky). `pick` chooses the origin's light
 * sample. */
static int point_open(Ctx *c, const CellPlane *cp, float p1, float p2, uint32_t pick)
{
	/* Rays start a little before the point (the plane lies PLANE_OFFSET R
	 * beyond a surface: a quarter of that). */
	float back = 0.25f * PLANE_OFFSET * c->R;
	V3 X = v3_add(cp->o, v3_add(v3_scale(cp->a1, p1), v3_scale(cp->a2, p2)));
	uint32_t near[CELL_ORIGINS];
	float nd[CELL_ORIGINS];
	int nn = 0;
	for (uint32_t q = 0; q < cp->k; q++) {
		float dd = (cp->u1[q] - p1) * (cp->u1[q] - p1) + (cp->u2[q] - p2) * (cp->u2[q] - p2);
		int pos = nn < CELL_ORIGINS ? nn++ : CELL_ORIGINS;
		while (pos > 0 && nd[pos - 1] > dd) {
			if (pos < CELL_ORIGINS)
				near[pos] = near[pos - 1], nd[pos] = nd[pos - 1];
			pos--;
		}
		if (pos < CELL_ORIGINS)
			near[pos] = q, nd[pos] = dd;
	}
	for (int q = 0; q < nn; q++) {
		const Crossing *line = &cp->xs[cp->yl[near[q]]];
		V3 P = line->P, d = v3_sub(X, P);
		float l = v3_len(d);
		d = v3_scale(d, 1.0f / l);
		V3 start = v3_madd(X, d, -back);
		if (!clear(c, P, start))
			continue;
		Solid sol;
		trace(c, start, d, AJAR_INF, &sol);
		if (sol.t == AJAR_INF || sol.emit)
			return 1;
		pick %= 4;
		if (c->nlp && !line->from->sees[pick] &&
		    lit_by(c, sol.p, sol.ng, &c->lp[(line->from->base + pick) % c->nlp]))
			return 1;
		/* Something outside under the sky (a garden, a facade): it sees
		 * the sky more than a room's wall does. */
		if (c->sky && sees_sky(c, sol.p, sol.ng, pick))
			return 1;
	}
	return 0;
}

/* The cell test on a GRID x GRID grid from (l1, l2) in cells c1 x c2. */
static void test_cells(Ctx *c, const CellPlane *cp, float l1, float l2, float c1, float c2, uint8_t *open)
{
	for (int j = 0; j < GRID; j++)
		for (int i = 0; i < GRID; i++)
			open[j * GRID + i] = (uint8_t)point_open(c, cp, l1 + ((float)i + 0.5f) * c1, l2 + ((float)j + 0.5f) * c2,
							(uint32_t)(i + j));
}

/* Moves one edge of rectangle r onto the opening's: the edge lies between
 * `closed` (a coordinate along axis `axis` where the grid found no open
 * cell next to the part) and `open` (its outermost open cell's centre);
 * EDGE_STEPS bisections, each probing EDGE_PROBES points along the edge
 * within the part's extent [from, to] on the other axis. Returns the
 * coordinate, on the closed side of the opening's edge. */
static float refine_edge(Ctx *c, const CellPlane *cp, int axis, float closed, float open, float from, float to)
{
	for (int step = 0; step < EDGE_STEPS; step++) {
		float mid = 0.5f * (closed + open);
		int any = 0;
		for (int q = 0; q < EDGE_PROBES && !any; q++) {
			float along = from + (to - from) * ((float)q + 0.5f) / EDGE_PROBES;
			any = axis == 0 ? point_open(c, cp, mid, along, (uint32_t)q) : point_open(c, cp, along, mid, (uint32_t)q);
		}
		if (any)
			open = mid;
		else
			closed = mid;
	}
	return closed;
}

/* Slides rectangle r outward (along -n) through a tunnel: a roof slab's
 * opening, a window in a thick wall, found at the face the room sees. It
 * moves by SLIDE_STEP R while, in the moved plane, its inside stays open
 * (9 in 10 points) and its rim (points just outside its edges) lies inside
 * solid matter (9 in 10 of them meet a surface within SLIDE_SOLID R both
 * ways along n): still in the tunnel, not yet out in the open.
 * A sun's light enters at the tunnel's far end, where no light path that
 * grazes in past its edge is lost. */
static void slide_out(Ctx *c, const CellPlane *cp, Rect *r)
{
	float w1 = r->hi1 - r->lo1, w2 = r->hi2 - r->lo2, rim = RIM_GAP * fmax(w1, w2);
	int good = 0;
	for (int k = 1; k <= SLIDE_STEPS; k++) {
		CellPlane moved = *cp;
		moved.o = v3_madd(cp->o, cp->n, -(float)k * SLIDE_STEP * c->R);
		int in = 0, solid = 0;
		for (int q = 0; q < 36; q++) {
			float f1 = ((float)(q % 6) + 0.5f) / 6.0f, f2 = ((float)(q / 6) + 0.5f) / 6.0f;
			in += point_open(c, &moved, r->lo1 + (0.1f + 0.8f * f1) * w1, r->lo2 + (0.1f + 0.8f * f2) * w2,
					 (uint32_t)q);
			/* Rim points, around the four edges in turn. */
			float t = ((float)(q / 4) + 0.5f) / 9.0f, p1, p2;
			switch (q % 4) {
			case 0: p1 = r->lo1 - rim, p2 = r->lo2 + t * w2; break;
			case 1: p1 = r->hi1 + rim, p2 = r->lo2 + t * w2; break;
			case 2: p1 = r->lo1 + t * w1, p2 = r->lo2 - rim; break;
			default: p1 = r->lo1 + t * w1, p2 = r->hi2 + rim; break;
			}
			V3 X = v3_add(moved.o, v3_add(v3_scale(cp->a1, p1), v3_scale(cp->a2, p2)));
			Solid sa, sb;
			solid += trace(c, X, cp->n, SLIDE_SOLID * c->R, &sa) && trace(c, X, v3_neg(cp->n), SLIDE_SOLID * c->R, &sb);
		}
		if (in < 32 || solid < 32)
			break;
		good = k;
	}
	r->o = v3_madd(r->o, r->n, -(float)good * SLIDE_STEP * c->R);
}

/* Open cells of plane (n, s) over the footprint, their connected parts as
 * rectangles into rs; the lines each rectangle catches are marked in
 * caught (steps 6 and 7). */
static ajar_status open_rects(Ctx *c, const Crossing *xs, const uint32_t *idx, uint32_t m, V3 n, float s,
			      uint32_t total, uint8_t *caught, Rects *rs)
{
	float R = c->R;
	V3 *y = malloc(sizeof *y * m);
	float *u1 = malloc(sizeof *u1 * m), *u2 = malloc(sizeof *u2 * m), *w1 = malloc(sizeof *w1 * m),
	      *w2 = malloc(sizeof *w2 * m);
	uint32_t *yl = malloc(sizeof *yl * m);
	uint8_t *open = calloc(GRID * GRID, 1);
	int *comp = malloc(sizeof *comp * GRID * GRID), *stack = malloc(sizeof *stack * GRID * GRID);
	ajar_status st = AJAR_OK;
	if (!y || !u1 || !u2 || !w1 || !w2 || !yl || !open || !comp || !stack) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
		goto done;
	}
	uint32_t k = 0;
	V3 o = v3_scale(n, s), room = v3(0, 0, 0);
	for (uint32_t i = 0; i < m; i++) {
		const Crossing *x = &xs[idx[i]];
		float t;
		if (!meet(x, n, s, R, MEET_DN, &t))
			continue;
		y[k] = v3_madd(x->P, x->d, t);
		room = v3_add(room, v3_sub(x->P, y[k]));
		yl[k++] = idx[i];
	}
	if (k < 4)
		goto done;
	if (v3_dot(room, n) < 0.0f) { /* face the room */
		n = v3_neg(n);
		s = -s;
	}
	/* Candidate planes are surfaces' (a wall, a jamb): a portal in one
	 * would share points with it, where a path vertex on the surface lies
	 * exactly in the portal and its crossings hang on rounding. The portal
	 * goes PLANE_OFFSET R beyond it, along the lines' way out. */
	s -= PLANE_OFFSET * R;
	o = v3_scale(n, s);
	for (uint32_t i = 0; i < k; i++) {
		const Crossing *x = &xs[yl[i]];
		y[i] = v3_madd(x->P, x->d, (s - v3_dot(n, x->P)) / v3_dot(n, x->d));
	}
	/* The footprint's narrowest frame, in 2-degree turns. */
	V3 f1, f2;
	plane_frame(n, &f1, &f2);
	float best = AJAR_INF, b1 = 0.0f;
	for (int r = 0; r < 45; r++) {
		float a = (float)r * AJAR_PI / 90.0f;
		V3 a1 = v3_add(v3_scale(f1, cos(a)), v3_scale(f2, sin(a))), a2 = v3_cross(n, a1);
		for (uint32_t i = 0; i < k; i++) {
			w1[i] = v3_dot(y[i], a1);
			w2[i] = v3_dot(y[i], a2);
		}
		float l1, h1, l2, h2;
		trimmed(w1, (int)k, 0.02f, &l1, &h1);
		trimmed(w2, (int)k, 0.02f, &l2, &h2);
		float area = (h1 - l1) * (h2 - l2);
		if (area < best)
			best = area, b1 = a;
	}
	V3 a1 = v3_add(v3_scale(f1, cos(b1)), v3_scale(f2, sin(b1))), a2 = v3_cross(n, a1);
	for (uint32_t i = 0; i < k; i++) {
		u1[i] = w1[i] = v3_dot(v3_sub(y[i], o), a1);
		u2[i] = w2[i] = v3_dot(v3_sub(y[i], o), a2);
	}
	float l1, h1, l2, h2;
	trimmed(w1, (int)k, 0.01f, &l1, &h1);
	trimmed(w2, (int)k, 0.01f, &l2, &h2);
	float e1 = h1 - l1, e2 = h2 - l2;
	l1 -= 0.25f * e1 + 0.02f * R, h1 += 0.25f * e1 + 0.02f * R;
	l2 -= 0.25f * e2 + 0.02f * R, h2 += 0.25f * e2 + 0.02f * R;
	CellPlane cp = {.xs = xs, .yl = yl, .u1 = u1, .u2 = u2, .k = k, .o = o, .a1 = a1, .a2 = a2, .n = n};
	float c1 = 0.0f, c2 = 0.0f;
	int touch = 0;
	for (int pass = 0; pass < 2; pass++) {
		/* The grid grows (by half, up to GROW_TRIES times) on each side
		 * where an open cell touches its border: the opening goes on. */
		for (int attempt = 0; attempt <= GROW_TRIES; attempt++) {
			c1 = (h1 - l1) / GRID, c2 = (h2 - l2) / GRID;
			test_cells(c, &cp, l1, l2, c1, c2, open);
			touch = 0;
			for (int q = 0; q < GRID; q++) {
				touch |= open[q * GRID] ? 1 : 0;              /* low a1 */
				touch |= open[q * GRID + GRID - 1] ? 2 : 0;   /* high a1 */
				touch |= open[q] ? 4 : 0;                     /* low a2 */
				touch |= open[(GRID - 1) * GRID + q] ? 8 : 0; /* high a2 */
			}
			if (!touch || attempt == GROW_TRIES)
				break;
			float g1 = 0.5f * (h1 - l1), g2 = 0.5f * (h2 - l2);
			l1 -= touch & 1 ? g1 : 0.0f, h1 += touch & 2 ? g1 : 0.0f;
			l2 -= touch & 4 ? g2 : 0.0f, h2 += touch & 8 ? g2 : 0.0f;
		}
		if (pass == 1)
			break;
		/* An opening askew to the lines' frame (a thin wedge over a door
		 * leaf's top): the open cells' own narrowest frame, if it is much
		 * narrower, and the grid again in it. */
		float bestq = AJAR_INF, bq = 0.0f, box[4] = {0, 0, 0, 0}, axis_area = 0.0f;
		for (int r = 0; r < 45; r++) {
			float a = (float)r * AJAR_PI / 90.0f, ca = cos(a), sa = sin(a);
			float q0 = AJAR_INF, q1 = -AJAR_INF, q2 = AJAR_INF, q3 = -AJAR_INF;
			for (int j = 0; j < GRID; j++)
				for (int i = 0; i < GRID; i++) {
					if (!open[j * GRID + i])
						continue;
					float p1 = l1 + ((float)i + 0.5f) * c1, p2 = l2 + ((float)j + 0.5f) * c2;
					float r1 = ca * p1 + sa * p2, r2 = -sa * p1 + ca * p2;
					q0 = fmin(q0, r1), q1 = fmax(q1, r1), q2 = fmin(q2, r2), q3 = fmax(q3, r2);
				}
			float area = (q1 - q0 + c1) * (q3 - q2 + c2);
			if (r == 0)
				axis_area = area;
			if (area < bestq)
				bestq = area, bq = a, box[0] = q0, box[1] = q1, box[2] = q2, box[3] = q3;
		}
		if (!(bestq < REFRAME * axis_area))
			break;
		float ca = cos(bq), sa = sin(bq);
		a1 = v3_add(v3_scale(cp.a1, ca), v3_scale(cp.a2, sa));
		a2 = v3_cross(n, a1);
		cp.a1 = a1, cp.a2 = a2;
		for (uint32_t i = 0; i < k; i++) {
			u1[i] = v3_dot(v3_sub(y[i], o), a1);
			u2[i] = v3_dot(v3_sub(y[i], o), a2);
		}
		float m = fmax(c1, c2);
		l1 = box[0] - 2.0f * m - 0.25f * (box[1] - box[0]), h1 = box[1] + 2.0f * m + 0.25f * (box[1] - box[0]);
		l2 = box[2] - 2.0f * m - 0.25f * (box[3] - box[2]), h2 = box[3] + 2.0f * m + 0.25f * (box[3] - box[2]);
	}
#ifdef PORTAL_FIND_DEBUG
	{
		fprintf(stderr, "grid n(%.3f %.3f %.3f) s %.4f a1(%.3f %.3f %.3f) [%.3f %.3f] a2(%.3f %.3f %.3f) [%.3f %.3f]\n", n.x, n.y, n.z, s, a1.x, a1.y, a1.z, l1, h1, a2.x, a2.y, a2.z, l2, h2);
		for (int j = GRID - 1; j >= 0; j--) {
			for (int i = 0; i < GRID; i++)
				fputc(open[j * GRID + i] ? '#' : '.', stderr);
			fputc('\n', stderr);
		}
	}
#endif
	/* Connected parts, each bounded and grown by a cell. */
	for (int i = 0; i < GRID * GRID; i++)
		comp[i] = -1;
	for (int start = 0; start < GRID * GRID; start++) {
		if (!open[start] || comp[start] >= 0)
			continue;
		int sp = 0, cells = 0, i0 = GRID, i1 = -1, j0 = GRID, j1 = -1;
		stack[sp++] = start;
		comp[start] = start;
		while (sp) {
			int q = stack[--sp], qi = q % GRID, qj = q / GRID;
			cells++;
			i0 = qi < i0 ? qi : i0, i1 = qi > i1 ? qi : i1;
			j0 = qj < j0 ? qj : j0, j1 = qj > j1 ? qj : j1;
			/* Cells within CONNECT of each other join: slats of a blind
			 * and thin mullions do not split an opening. */
			for (int dj = -CONNECT; dj <= CONNECT; dj++)
				for (int di = -CONNECT; di <= CONNECT; di++) {
					int ni = qi + di, nj = qj + dj;
					if (ni < 0 || nj < 0 || ni >= GRID || nj >= GRID)
						continue;
					int nq = nj * GRID + ni;
					if (open[nq] && comp[nq] < 0) {
						comp[nq] = start;
						stack[sp++] = nq;
					}
				}
		}
		/* Open up to the grid's border even after it grew: no wall
		 * around it, so no opening (a plane across the room). */
		if (cells < 2 || ((touch & 1) && i0 == 0) || ((touch & 2) && i1 == GRID - 1) || ((touch & 4) && j0 == 0) ||
		    ((touch & 8) && j1 == GRID - 1))
			continue;
		Rect r = {.o = o, .a1 = a1, .a2 = a2, .n = n, .alive = 1};
		/* Each edge between its outermost open cell's centre and the next
		 * centre out, bisected onto the opening's edge, then EDGE_MARGIN
		 * of a cell beyond it. */
		float in1 = l1 + ((float)i0 + 0.5f) * c1, out1 = in1 - c1, in2 = l1 + ((float)i1 + 0.5f) * c1, out2 = in2 + c1;
		float in3 = l2 + ((float)j0 + 0.5f) * c2, out3 = in3 - c2, in4 = l2 + ((float)j1 + 0.5f) * c2, out4 = in4 + c2;
		r.lo1 = refine_edge(c, &cp, 0, out1, in1, in3 - 0.5f * c2, in4 + 0.5f * c2) - EDGE_MARGIN * c1;
		r.hi1 = refine_edge(c, &cp, 0, out2, in2, in3 - 0.5f * c2, in4 + 0.5f * c2) + EDGE_MARGIN * c1;
		r.lo2 = refine_edge(c, &cp, 1, out3, in3, in1 - 0.5f * c1, in2 + 0.5f * c1) - EDGE_MARGIN * c2;
		r.hi2 = refine_edge(c, &cp, 1, out4, in4, in1 - 0.5f * c1, in2 + 0.5f * c1) + EDGE_MARGIN * c2;
		uint32_t hits = 0;
		for (uint32_t q = 0; q < k; q++)
			if (u1[q] >= r.lo1 && u1[q] <= r.hi1 && u2[q] >= r.lo2 && u2[q] <= r.hi2) {
				hits++;
				caught[yl[q]] = 1;
			}
		slide_out(c, &cp, &r);
		r.share = (float)hits / (float)total;
		if (!rect_add(rs, &r)) {
			st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "portal search: out of memory");
			goto done;
		}
	}
done:
	free(y), free(u1), free(u2), free(w1), free(w2), free(yl), free(open), free(comp), free(stack);
	return st;
}

/* Steps 5 to 7 for the lines idx[0..m) of one opening. */
/* Rectangles of one plane (normals within 1 degree, planes within
 * MERGE_GAP R: a window found twice, at its frame and at its blind) merge
 * while one rectangle covers two with at most MERGE_AREA times the area
 * they cover together. The merged one lies in the first's plane. */
static void merge_rects(Rects *rs, uint32_t from, float R)
{
	for (int changed = 1; changed;) {
		changed = 0;
		for (uint32_t i = from; i < rs->n; i++)
			for (uint32_t j = i + 1; j < rs->n; j++) {
				Rect *a = &rs->r[i], *b = &rs->r[j];
				if (!a->alive || !b->alive || v3_dot(a->n, b->n) < 0.9998f ||
				    fabs(v3_dot(a->n, v3_sub(a->o, b->o))) > MERGE_GAP * R)
					continue;
				/* b's corners in a's frame. */
				float lo1 = AJAR_INF, hi1 = -AJAR_INF, lo2 = AJAR_INF, hi2 = -AJAR_INF;
				for (int k = 0; k < 4; k++) {
					V3 p = v3_add(b->o, v3_add(v3_scale(b->a1, k & 1 ? b->hi1 : b->lo1),
								   v3_scale(b->a2, k & 2 ? b->hi2 : b->lo2)));
					float q1 = v3_dot(v3_sub(p, a->o), a->a1), q2 = v3_dot(v3_sub(p, a->o), a->a2);
					lo1 = fmin(lo1, q1), hi1 = fmax(hi1, q1), lo2 = fmin(lo2, q2), hi2 = fmax(hi2, q2);
				}
				double ov1 = fmin(a->hi1, hi1) - fmax(a->lo1, lo1), ov2 = fmin(a->hi2, hi2) - fmax(a->lo2, lo2);
				double overlap = ov1 > 0 && ov2 > 0 ? ov1 * ov2 : 0.0;
				double area_a = (double)(a->hi1 - a->lo1) * (a->hi2 - a->lo2);
				double area_b = (double)(hi1 - lo1) * (hi2 - lo2);
				lo1 = fmin(lo1, a->lo1), hi1 = fmax(hi1, a->hi1), lo2 = fmin(lo2, a->lo2), hi2 = fmax(hi2, a->hi2);
				if ((double)(hi1 - lo1) * (hi2 - lo2) > MERGE_AREA * (area_a + area_b - overlap))
					continue;
				a->lo1 = lo1, a->hi1 = hi1, a->lo2 = lo2, a->hi2 = hi2;
				a->share += b->share;
				b->alive = 0;
				changed = 1;
			}
	}
}

/* Whether line x passes through rectangle r before its far hit. */
static int rect_catches(const Rect *r, const Crossing *x, float R)
{
	float t;
	if (!meet(x, r->n, v3_dot(r->n, r->o), R, MEET_DN, &t))
		return 0;
	V3 y = v3_sub(v3_madd(x->P, x->d, t), r->o);
	float p1 = v3_dot(y, r->a1), p2 = v3_dot(y, r->a2);
	return p1 >= r->lo1 && p1 <= r->hi1 && p2 >= r->lo2 && p2 <= r->hi2;
}

/* ---- Step 8: light behind a rectangle ---------------------------------------- */

static int light_behind(Ctx *c, const Rect *r)
{
	Rng rng = rng_init(0x70a7a1u, 4u, 0u, 0u);
	V3 out = v3_neg(r->n);
	for (int i = 0; i < 256; i++) {
		float p1 = r->lo1 + (r->hi1 - r->lo1) * rnd(&rng), p2 = r->lo2 + (r->hi2 - r->lo2) * rnd(&rng);
		V3 X = v3_add(r->o, v3_add(v3_scale(r->a1, p1), v3_scale(r->a2, p2)));
		V3 d = dir_about(&rng, out, 1);
		Solid s;
		trace(c, X, d, AJAR_INF, &s);
		if ((s.t == AJAR_INF && c->sky) || s.emit)
			return 1;
		if (c->nlp) {
			const LightPoint *l = &c->lp[(uint32_t)i % c->nlp];
			V3 to = v3_sub(l->p, X);
			if (v3_dot(to, out) > 0.0f && (v3_is_zero(l->n) || v3_dot(to, l->n) < 0.0f) && clear(c, X, l->p))
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
	ajar_status st = room_points(&c, in->camera, &room);
	if (st == AJAR_OK && c.R > 0.0f)
		st = light_points(&c, ntris, in, &room);
	if (st == AJAR_OK && c.R > 0.0f) {
		room_lights(&c, &room);
		st = find_crossings(&c, &room, &xs);
	}
	if (st != AJAR_OK || xs.n == 0)
		goto done;

	uint32_t n = xs.n, nfirst = 0;
	for (uint32_t k = 0; k < n; k++)
		nfirst += (uint32_t)xs.x[k].weight;
	int np = candidate_planes(&xs, c.R, pn, po);
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
		best_patch(&c, &xs, alive, pn, po, np, blo, bhi, &g, best);
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
			if ((st = open_rects(&c, xs.x, best[b].idx, best[b].m, pn[best[b].q], po[best[b].q], n, scratch, &rs)) !=
			    AJAR_OK)
				goto done;
			merge_rects(&rs, mark, c.R);
			double area = 0.0;
			uint32_t lines = 0;
			for (uint32_t k = 0; k < n; k++) {
				int in = 0;
				for (uint32_t r = mark; r < rs.n && !in; r++)
					in = rs.r[r].alive && rect_catches(&rs.r[r], &xs.x[k], c.R);
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
				if (!caught[k] && rect_catches(rc, &xs.x[k], c.R)) {
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
	merge_rects(&rs, 0, c.R);
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
