/* portal_find_planes.c — step 4 of the portal search: the candidate planes
 * around the holes and the patch where the open lines crowd most tightly. */
#include "prepare/portal_find_parts.h"

/* An in-plane frame: the first axis the world's up projected, or x for
 * horizontal planes. */
void pf_plane_frame(V3 n, V3 *a1, V3 *a2)
{
	V3 up = fabs(n.y) < 0.9f ? v3(0, 1, 0) : v3(1, 0, 0);
	*a1 = v3_norm(v3_madd(up, n, -v3_dot(up, n)));
	*a2 = v3_cross(n, *a1);
}

/* Where line (P, d) meets the plane n . x = s, if between its start and
 * its far hit: 1 and the distance. */
int pf_meet(const Crossing *x, V3 n, float s, float R, float min_dn, float *t)
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
int pf_candidate_planes(const Crossings *xs, float R, V3 *cand, float *offs)
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
static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
	return x < y ? -1 : x > y;
}

void pf_best_patch(Ctx *c, const Crossings *xs, const uint8_t *alive, const V3 *pn, const float *po, int np,
		   float min_dn, V3 blo, V3 bhi, Raster *g, Patch best[2])
{
	best[0].score = best[1].score = 0.0;
	best[0].q = best[1].q = -1;
	float R = c->R;
	for (int k = 0; k < np; k++) {
		V3 a1, a2;
		pf_plane_frame(pn[k], &a1, &a2);
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
			if (!alive[i] || !pf_meet(&xs->x[i], pn[k], po[k], R, min_dn, &t))
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
