/* sky_tables.c — planar portals and their sky tables (see portal_sky.h and
 * kernels/light/portal_sky.h). Each plane's frame has t along the longest edge of
 * its triangles, so a rectangular window fills its bounding rectangle.
 * A table cell (i, j) holds the integral over its (u, v) square of the
 * sky's luminance times dw / (du dv), from SKY_SS x SKY_SS points (a sun
 * of a few texels is caught), plus SKY_FLOOR times the mean cell, so that
 * no direction in a rectangle has zero density; its summed-area table is
 * summed in double and stored as float pairs (hi, lo). */
#include "prepare/sky_tables.h"
#include "prepare/portal_groups.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "light/env.h"
#include "light/portal_sky.h"

#define SKY_SS 4
#define SKY_FLOOR 1e-3

/* Frame and bounding rectangle of the triangles k with root[k] == g: the
 * smallest (portal_group_rect), as the sky is tabulated over it and a
 * direction in the rectangle but beside the triangles is a sample lost. */
static int plane_frame(const PortalTri *portals, const uint32_t *root, uint32_t n, uint32_t g, PortalPlane *P)
{
	const PortalTri *first = &portals[g];
	memset(P, 0, sizeof *P);
	P->o = first->p0;
	P->n = v3_scale(first->n, (float)first->env_side);
	float r[4];
	if (!(portal_group_rect(portals, root, n, g, P->n, P->o, &P->t, &P->b, r) > 0.0f))
		return 0;
	P->a0 = r[0];
	P->a1 = r[1];
	P->b0 = r[2];
	P->b1 = r[3];
	/* A little margin, so rounding at the border loses no direction. */
	float m = 1e-4f * fmaxf(P->a1 - P->a0, P->b1 - P->b0);
	P->a0 -= m;
	P->a1 += m;
	P->b0 -= m;
	P->b1 += m;
	return P->a1 > P->a0 && P->b1 > P->b0;
}

static int plane_table(const SceneView *sc, const PortalPlane *P, int N, float *out)
{
	double *cell = malloc(sizeof(double) * N * N), sum = 0.0;
	double *S = calloc((size_t)(N + 1) * (N + 1), sizeof(double));
	if (!cell || !S) {
		free(cell);
		free(S);
		return 0;
	}
	const double du = M_PI / N;
	for (int j = 0; j < N; j++)
		for (int i = 0; i < N; i++) {
			double acc = 0.0;
			for (int b = 0; b < SKY_SS; b++)
				for (int a = 0; a < SKY_SS; a++) {
					double u = -0.5 * M_PI + (i + (a + 0.5) / SKY_SS) * du;
					double v = -0.5 * M_PI + (j + (b + 0.5) / SKY_SS) * du;
					double X = tan(u), Y = tan(v), q = 1.0 + X * X + Y * Y;
					V3 w = v3_norm(v3_add(v3_add(v3_scale(P->t, (float)X), v3_scale(P->b, (float)Y)), P->n));
					double lum = v3_lum(env_radiance(sc, w));
					acc += fmax(lum, 0.0) * (1.0 + X * X) * (1.0 + Y * Y) / (q * sqrt(q));
				}
			cell[j * N + i] = acc / (SKY_SS * SKY_SS) * du * du;
			sum += cell[j * N + i];
		}
	double floor_mass = sum > 0.0 ? SKY_FLOOR * sum / (N * N) : du * du;
	/* S(i, j) = sum over rows < j and columns < i, row by row. */
	for (int j = 1; j <= N; j++) {
		double row = 0.0;
		for (int i = 1; i <= N; i++) {
			row += cell[(j - 1) * N + (i - 1)] + floor_mass;
			S[j * (N + 1) + i] = S[(j - 1) * (N + 1) + i] + row;
		}
	}
	for (int k = 0; k < (N + 1) * (N + 1); k++) {
		float hi = (float)S[k];
		out[2 * k] = hi;
		out[2 * k + 1] = (float)(S[k] - (double)hi);
	}
	free(cell);
	free(S);
	return 1;
}

ajar_status portal_sky_planes(const PortalTri *portals, uint32_t n, PortalPlane **planes, size_t *nplanes)
{
	*planes = NULL;
	*nplanes = 0;
	if (n == 0)
		return AJAR_OK;
	uint32_t *root = malloc(sizeof *root * n);
	if (!root)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portals: out of memory grouping %u triangles", n);
	portal_groups(portals, n, 1, root);
	uint32_t groups = 0;
	for (uint32_t k = 0; k < n; k++)
		groups += root[k] == k && portals[k].env_side != 0;
	if (groups == 0) {
		free(root);
		return AJAR_OK;
	}
	PortalPlane *pl = malloc(sizeof *pl * groups);
	if (!pl) {
		free(root);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portals: out of memory for %u planes", groups);
	}
	size_t np = 0;
	for (uint32_t g = 0; g < n; g++) {
		if (root[g] != g || portals[g].env_side == 0 || !plane_frame(portals, root, n, g, &pl[np]))
			continue;
		np++;
	}
	free(root);
	if (np == 0) {
		free(pl);
		pl = NULL;
	}
	*planes = pl;
	*nplanes = np;
	return AJAR_OK;
}

ajar_status portal_sky_tables(const SceneView *sc, PortalPlane *planes, size_t nplanes, int res, float **sky,
			      size_t *nsky)
{
	const size_t floats = PORTAL_SKY_FLOATS_OF((size_t)res);
	*sky = NULL;
	*nsky = 0;
	if (nplanes == 0)
		return AJAR_OK;
	float *tab = malloc(sizeof *tab * nplanes * floats);
	if (!tab)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portals: out of memory for %zu sky tables", nplanes);
	for (size_t k = 0; k < nplanes; k++) {
		planes[k].table = (int)(k * floats);
		if (!plane_table(sc, &planes[k], res, tab + k * floats)) {
			free(tab);
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portals: out of memory for a sky table");
		}
	}
	*sky = tab;
	*nsky = nplanes * floats;
	return AJAR_OK;
}
