/* portal_find_cells.c — steps 5 to 7 of the portal search: open cells on a
 * grid in the patch's plane, their rectangles, edges refined onto the
 * opening, rectangles of one plane merged. */
#include "prepare/portal_find_parts.h"

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

/* The plane of a cell test: its point o, axes a1, a2 and normal n, and
 * the lines crossing it (yl, at u1, u2 in the plane's coordinates). */
typedef struct {
	const Crossing *xs;
	const uint32_t *yl;
	const float *u1, *u2;
	uint32_t k;
	V3 o, a1, a2, n;
	const Rects *done; /* the portals accepted before: what is seen through them is found */
} CellPlane;

/* Whether the segment from P along d (length l) passes through a portal
 * accepted before. */
static int through_done(const CellPlane *cp, V3 P, V3 d, float l)
{
	for (uint32_t i = 0; cp->done && i < cp->done->n; i++) {
		const Rect *r = &cp->done->r[i];
		float dn = v3_dot(r->n, d);
		if (!r->accepted || !(fabs(dn) > 1e-6f))
			continue;
		float t = v3_dot(r->n, v3_sub(r->o, P)) / dn;
		if (!(t > 0.0f && t < l))
			continue;
		V3 y = v3_sub(v3_madd(P, d, t), r->o);
		float p1 = v3_dot(y, r->a1), p2 = v3_dot(y, r->a2);
		if (p1 >= r->lo1 && p1 <= r->hi1 && p2 >= r->lo2 && p2 <= r->hi2)
			return 1;
	}
	return 0;
}

/* Whether surface point p (normal n, facing where the ray came from) is
 * under the open sky: at least SKY_SEEN of SKY_RAYS cosine rays escape. */
static int sees_sky(Ctx *c, V3 p, V3 n, uint32_t seed)
{
	Rng rng = rng_init(0x70a7a1u, 6u, seed, 0u);
	V3 o = v3_madd(p, n, 1e-4f * c->R);
	int seen = 0;
	for (int i = 0; i < SKY_RAYS && seen < SKY_SEEN; i++) {
		Solid s;
		seen += !pf_trace(c, o, pf_dir_about(&rng, n, 1), AJAR_INF, &s);
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
		/* From the room's side only: a garden seen through a glazed door
		 * holds room points too, and a wall of one face hides nothing
		 * from behind. */
		if (!(v3_dot(cp->n, d) < 0.0f))
			continue;
		float l = v3_len(d);
		d = v3_scale(d, 1.0f / l);
		V3 start = v3_madd(X, d, -back);
		/* Seen through a portal found before: no new opening there (the
		 * room behind a door's gap, seen through it). */
		if (through_done(cp, P, d, l - back) || !pf_clear(c, P, start))
			continue;
		Solid sol;
		pf_trace(c, start, d, AJAR_INF, &sol);
		if (sol.t == AJAR_INF || sol.emit)
			return 1;
		pick %= 4;
		if (c->nlp && !line->from->sees[pick] &&
		    pf_lit_by(c, sol.p, sol.ng, &c->lp[(line->from->base + pick) % c->nlp]))
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
 * solid matter along three edges at least (7 of an edge's 9 points meet a
 * surface within SLIDE_SOLID R both ways along n): still in the tunnel,
 * not yet out in the open. Three, not four: a door's or a French window's
 * fourth edge is the floor, often one face with nothing under it.
 * A sun's light enters at the tunnel's far end, where no light path that
 * grazes in past its edge is lost (a door's portal at the wall's face the
 * room sees, 25 cm from its far end: 2.4 times the error of `pt`). */
static void slide_out(Ctx *c, const CellPlane *cp, Rect *r)
{
	float w1 = r->hi1 - r->lo1, w2 = r->hi2 - r->lo2, rim = RIM_GAP * fmax(w1, w2);
	int good = 0;
	for (int k = 1; k <= SLIDE_STEPS; k++) {
		CellPlane moved = *cp;
		moved.o = v3_madd(cp->o, cp->n, -(float)k * SLIDE_STEP * c->R);
		int in = 0, solid[4] = {0, 0, 0, 0};
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
			solid[q % 4] +=
				pf_trace(c, X, cp->n, SLIDE_SOLID * c->R, &sa) && pf_trace(c, X, v3_neg(cp->n), SLIDE_SOLID * c->R, &sb);
		}
		int edges = (solid[0] >= 7) + (solid[1] >= 7) + (solid[2] >= 7) + (solid[3] >= 7);
		if (in < 32 || edges < 3)
			break;
		good = k;
	}
	r->o = v3_madd(r->o, r->n, -(float)good * SLIDE_STEP * c->R);
}

/* Open cells of plane (n, s) over the footprint, their connected parts as
 * rectangles into rs; the lines each rectangle catches are marked in
 * caught (steps 6 and 7). */
ajar_status pf_open_rects(Ctx *c, const Crossing *xs, const uint32_t *idx, uint32_t m, V3 n, float s,
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
		if (!pf_meet(x, n, s, R, MEET_DN, &t))
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
	pf_plane_frame(n, &f1, &f2);
	float best = AJAR_INF, b1 = 0.0f;
	for (int r = 0; r < 45; r++) {
		float a = (float)r * AJAR_PI / 90.0f;
		V3 a1 = v3_add(v3_scale(f1, cos(a)), v3_scale(f2, sin(a))), a2 = v3_cross(n, a1);
		for (uint32_t i = 0; i < k; i++) {
			w1[i] = v3_dot(y[i], a1);
			w2[i] = v3_dot(y[i], a2);
		}
		float l1, h1, l2, h2;
		pf_trimmed(w1, (int)k, 0.02f, &l1, &h1);
		pf_trimmed(w2, (int)k, 0.02f, &l2, &h2);
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
	pf_trimmed(w1, (int)k, 0.01f, &l1, &h1);
	pf_trimmed(w2, (int)k, 0.01f, &l2, &h2);
	float e1 = h1 - l1, e2 = h2 - l2;
	l1 -= 0.25f * e1 + 0.02f * R, h1 += 0.25f * e1 + 0.02f * R;
	l2 -= 0.25f * e2 + 0.02f * R, h2 += 0.25f * e2 + 0.02f * R;
	CellPlane cp = {.xs = xs, .yl = yl, .u1 = u1, .u2 = u2, .k = k, .o = o, .a1 = a1, .a2 = a2, .n = n, .done = rs};
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
void pf_merge_rects(Rects *rs, uint32_t from, float R)
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
int pf_rect_catches(const Rect *r, const Crossing *x, float R)
{
	float t;
	if (!pf_meet(x, r->n, v3_dot(r->n, r->o), R, MEET_DN, &t))
		return 0;
	V3 y = v3_sub(v3_madd(x->P, x->d, t), r->o);
	float p1 = v3_dot(y, r->a1), p2 = v3_dot(y, r->a2);
	return p1 >= r->lo1 && p1 <= r->hi1 && p2 >= r->lo2 && p2 <= r->hi2;
}

/* Whether line x passes within m of rectangle r: through it, or along it
 * (a gap's lines that graze the plane its portal lies in, past the
 * portal's end, went through it too): the part of the line inside the
 * slab |n . (y - o)| <= m, clipped to the rectangle, is not empty. */
int pf_rect_near(const Rect *r, const Crossing *x, float m, float R)
{
	float h = v3_dot(r->n, v3_sub(x->P, r->o)), dn = v3_dot(r->n, x->d);
	float t0 = 0.0f, t1 = x->t == AJAR_INF ? 8.0f * R : x->t;
	if (fabs(dn) > 1e-9f) {
		float ta = (-m - h) / dn, tb = (m - h) / dn;
		t0 = fmax(t0, fmin(ta, tb)), t1 = fmin(t1, fmax(ta, tb));
	} else if (fabs(h) > m) {
		return 0;
	}
	V3 y = v3_sub(x->P, r->o);
	float p[2] = {v3_dot(y, r->a1), v3_dot(y, r->a2)}, q[2] = {v3_dot(x->d, r->a1), v3_dot(x->d, r->a2)};
	float lo[2] = {r->lo1, r->lo2}, hi[2] = {r->hi1, r->hi2};
	for (int a = 0; a < 2 && t0 <= t1; a++) {
		if (fabs(q[a]) < 1e-9f) {
			if (p[a] < lo[a] || p[a] > hi[a])
				return 0;
			continue;
		}
		float ua = (lo[a] - p[a]) / q[a], ub = (hi[a] - p[a]) / q[a];
		t0 = fmax(t0, fmin(ua, ub)), t1 = fmin(t1, fmax(ua, ub));
	}
	return t0 <= t1;
}

/* The lines of xs[0..n) that rectangle r catches. */
static uint32_t catches(const Rect *r, const Crossing *xs, uint32_t n, const uint8_t *pick, float R)
{
	uint32_t k = 0;
	for (uint32_t i = 0; i < n; i++)
		k += pick[i] && pf_rect_catches(r, &xs[i], R);
	return k;
}

/* A segment between two solid points of a gap's cross-section, by length. */
typedef struct {
	float l2;
	uint16_t i, j;
} Span;

static int cmp_span(const void *a, const void *b)
{
	const Span *x = a, *y = b;
	if (x->l2 != y->l2)
		return x->l2 < y->l2 ? -1 : 1;
	return x->i != y->i ? (x->i < y->i ? -1 : 1) : (x->j > y->j) - (x->j < y->j);
}

/* Whether line x, seen along L (both projected on the plane normal to
 * L), crosses segment a b before its far hit. */
static int crosses(const Crossing *x, V3 L, V3 a, V3 b)
{
	V3 p = v3_madd(x->P, L, -v3_dot(L, x->P)), d = v3_madd(x->d, L, -v3_dot(L, x->d));
	V3 e = v3_sub(b, a), q = v3_sub(a, p);
	V3 den = v3_cross(d, e);
	float dd = v3_dot(den, L);
	if (!(fabs(dd) > 1e-12f))
		return 0;
	float t = v3_dot(v3_cross(q, e), L) / dd, s = v3_dot(v3_cross(q, d), L) / dd;
	return t > 0.0f && t < x->t && s >= 0.0f && s <= 1.0f;
}

int pf_refit_gap(Ctx *c, const Crossing *xs, uint32_t n, Rect *r)
{
	float w1 = r->hi1 - r->lo1, w2 = r->hi2 - r->lo2;
	int turned = 0;
	if (!(fmin(w1, w2) < GAP_ASPECT * fmax(w1, w2)))
		return 0;
	V3 L = w1 >= w2 ? r->a1 : r->a2, S = w1 >= w2 ? r->a2 : r->a1;
	float half = 0.5f * fmax(w1, w2), lo = w1 >= w2 ? r->lo2 : r->lo1, hi = w1 >= w2 ? r->hi2 : r->hi1;
	float mid = 0.5f * (w1 >= w2 ? r->lo1 + r->hi1 : r->lo2 + r->hi2);
	V3 C = v3_madd(r->o, L, mid); /* on the long axis's middle, S-coordinate 0 */
	/* The lines through the gap: those passing near the rectangle. */
	uint8_t *near = malloc(n ? n : 1);
	uint32_t *li = malloc(sizeof *li * (n ? n : 1)), m = 0;
	Span *sp = malloc(sizeof *sp * GAP_DIRS * GAP_DIRS / 2);
	if (!near || !li || !sp)
		goto done;
	for (uint32_t i = 0; i < n; i++)
		if ((near[i] = (uint8_t)pf_rect_near(r, &xs[i], GAP_SLAB * c->R, c->R)))
			li[m++] = i;
	if (m < 8)
		goto done;
	/* The solid around the gap in its cross-section through the long
	 * axis's middle: hits of rays in that plane from GAP_FROM points across
	 * the rectangle. */
	V3 hp[GAP_DIRS];
	int nh = 0;
	float reach = GAP_REACH * c->R + 2.0f * (hi - lo);
	for (int f = 0; f < GAP_FROM; f++) {
		V3 X = v3_madd(C, S, lo + (hi - lo) * ((float)f + 0.5f) / GAP_FROM);
		for (int i = 0; i < GAP_DIRS / GAP_FROM; i++) {
			float ph = 2.0f * AJAR_PI * ((float)i + 0.5f) / (GAP_DIRS / GAP_FROM);
			Solid h;
			if (pf_trace(c, X, v3_add(v3_scale(S, cos(ph)), v3_scale(r->n, sin(ph))), reach, &h))
				hp[nh++] = h.p;
		}
	}
	/* Its narrowest section: the shortest segment between two of them
	 * that the lines (GAP_CROSS of them) cross, seen along the long axis
	 * (a door's jamb corner to its leaf's face by the free edge; a segment
	 * on one wall is crossed by none). */
	uint32_t ns = 0;
	for (int i = 0; i < nh; i++)
		for (int j = i + 1; j < nh; j++) {
			V3 e = v3_sub(hp[j], hp[i]);
			e = v3_madd(e, L, -v3_dot(L, e));
			sp[ns++] = (Span){v3_len2(e), (uint16_t)i, (uint16_t)j};
		}
	qsort(sp, ns, sizeof *sp, cmp_span);
	uint32_t miss_most = m - (uint32_t)(GAP_CROSS * (float)m);
	int found = -1;
	for (uint32_t k = 0; k < ns && found < 0; k++) {
		if (!(sp[k].l2 > 0.0f))
			continue;
		uint32_t miss = 0;
		for (uint32_t q = 0; q < m && miss <= miss_most; q++)
			miss += !crosses(&xs[li[q]], L, hp[sp[k].i], hp[sp[k].j]);
		if (miss <= miss_most)
			found = (int)k;
	}
	if (found < 0)
		goto done;
	V3 A = hp[sp[found].i], B = hp[sp[found].j];
	V3 AB = v3_sub(B, A);
	AB = v3_madd(AB, L, -v3_dot(L, AB));
	V3 nt = v3_norm(v3_cross(L, AB));
	if (v3_dot(nt, r->n) < 0.0f)
		nt = v3_neg(nt);
	/* The section's rectangle, its long sides as before, a little beyond
	 * the solid points as step 5's planes are; kept where it catches more
	 * of the lines (grazing lines cross a jamb's plane past the
	 * rectangle's end, not the gap). */
	float wd = sqrtf(sp[found].l2), mg = EDGE_MARGIN / GRID * wd;
	V3 M = v3_madd(v3_scale(v3_add(A, v3_madd(A, AB, 1.0f)), 0.5f), L, v3_dot(L, v3_sub(C, A)));
	Rect t = *r;
	t.n = nt, t.a1 = L, t.a2 = v3_cross(nt, L);
	t.o = v3_madd(M, nt, -PLANE_OFFSET * c->R);
	t.lo1 = -half, t.hi1 = half;
	t.lo2 = -0.5f * wd - mg, t.hi2 = 0.5f * wd + mg;
	uint32_t before = catches(r, xs, n, near, c->R), after = catches(&t, xs, n, near, c->R);
	PF_DEBUG("gap section: %u lines, width %.4f, normal (%.3f %.3f %.3f), catches %u -> %u\n", m, wd, nt.x, nt.y, nt.z,
		 before, after);
	float shrink = (t.hi1 - t.lo1) * (t.hi2 - t.lo2) / (w1 * w2);
	if (after > before || (m >= GAP_SURE && (float)after >= GAP_KEEP * (float)before && shrink <= GAP_SHRINK))
		*r = t, turned = 1;
done:
	free(near), free(li), free(sp);
	return turned;
}
