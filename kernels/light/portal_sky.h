/* portal_sky.h — directions through a planar portal (types.h, PortalPlane)
 * by the radiance of the sky behind it, after Bitterli et al. 2015
 * ("Portal-masked environment map sampling"; pbrt-v4's
 * PortalImageInfiniteLight). A direction w = (X, Y, 1) / |.| in the
 * plane's frame (t, b, n) has rectified coordinates (u, v) = (atan X,
 * atan Y) in (-pi/2, pi/2)^2. Seen from a point x on the room side at
 * height h below the plane, the plane's point (p_t, p_b) lies in direction
 * ((p_t - x_t) / h, (p_b - x_b) / h, 1), so the portal's bounding
 * rectangle maps to the axis-aligned rectangle
 *   [atan((a0 - x_t) / h), atan((a1 - x_t) / h)] x [same for b]
 * of (u, v), for every x: one table of the sky per plane serves every
 * shading point. The host (src/prepare/sky_tables.c) tabulates, on an N x N grid
 * of (u, v) cells, the cell's integral of luminance x dw/(du dv), with a
 * small floor, and stores its summed-area table S in double precision
 * split into two floats (hi, lo): differences of nearby entries are then
 * exact where float alone would lose a sky cell under a sun's mass.
 *
 * Within a rectangle R the (u, v) density is piecewise constant per cell
 * (f / I_R); u is sampled by inverting the piecewise-linear integral over
 * [U0, U] x [V0, V1] (knots B(i) at column boundaries), v by inverting
 * the chosen column's integral (knots C(j)). The density of a direction is
 * computed from those very knots, so sampling and density agree to
 * rounding, whatever the float SAT's errors. Coordinates U, V below are in
 * cell units, [0, N]. Directions in the rectangle but outside the portal's
 * triangles are valid samples, which the shadow ray rejects. */
#ifndef AJAR_KERNEL_PORTAL_SKY_H
#define AJAR_KERNEL_PORTAL_SKY_H
#include "base/types.h"
#include "base/fastmath.h"

/* Cells on a side of each plane's table: 128 (1.4 degrees at the centre)
 * unless the host builds the program with -DPORTAL_SKY_RES=N: pt takes 256,
 * or 512 under a sky image of 2048 columns or more, whose small sun a
 * 1.4-degree cell spreads thin (src/prepare/prepare.c, sky_table_res). */
#ifndef PORTAL_SKY_RES
#define PORTAL_SKY_RES 128
#endif
/* Floats of a table of n cells a side: (n + 1)^2 (hi, lo) pairs. */
#define PORTAL_SKY_FLOATS_OF(n) (2 * ((n) + 1) * ((n) + 1))
#define PORTAL_SKY_CELL (AJAR_PI / (float)PORTAL_SKY_RES) /* radians per cell */

/* What x sees of a plane: its rectangle in cell units, and the rows and
 * fractions of its v bounds. */
typedef struct {
	float U0, U1, V0, V1;
	int j0, j1;
	float f0, f1;
	int o0, o1; /* offsets of rows j0 and j1 in the table, sky_rect_rows */
} SkyRect;

#define SKY_ROW (2 * (PORTAL_SKY_RES + 1)) /* floats per table row */

/* r's row offsets from its rows. */
INLINE void sky_rect_rows(SkyRect *r)
{
	r->o0 = r->j0 * SKY_ROW;
	r->o1 = r->j1 * SKY_ROW;
}

INLINE float sky_coord(float angle)
{
	float c = (angle + 0.5f * AJAR_PI) * (1.0f / PORTAL_SKY_CELL);
	return fmin(fmax(c, 0.0f), (float)PORTAL_SKY_RES);
}

/* Cell index and fraction of coordinate c in [0, N]: N itself is the end
 * of the last cell. */
INLINE int sky_split(float c, float *f)
{
	int i = (int)c;
	i = i < 0 ? 0 : (i > PORTAL_SKY_RES - 1 ? PORTAL_SKY_RES - 1 : i);
	*f = c - (float)i;
	return i;
}

/* x's rectangle on plane P; 0 unless x is on its room side. Also x's
 * coordinates in P's frame, *xt and *xb, and its height *h below P. */
INLINE int sky_rect_at(GLOBAL const PortalPlane *P, V3 x, SkyRect *r, float *pxt, float *pxb, float *ph)
{
	V3 d = v3_sub(x, P->o);
	float h = -v3_dot(d, P->n);
	*ph = h;
	if (!(h > 0.0f))
		return 0;
	float xt = v3_dot(d, P->t), xb = v3_dot(d, P->b);
	*pxt = xt;
	*pxb = xb;
	r->U0 = sky_coord(fast_atan2(P->a0 - xt, h));
	r->U1 = sky_coord(fast_atan2(P->a1 - xt, h));
	r->V0 = sky_coord(fast_atan2(P->b0 - xb, h));
	r->V1 = sky_coord(fast_atan2(P->b1 - xb, h));
	r->j0 = sky_split(r->V0, &r->f0);
	r->j1 = sky_split(r->V1, &r->f1);
	sky_rect_rows(r);
	return r->U1 > r->U0 && r->V1 > r->V0;
}

INLINE int sky_rect(GLOBAL const PortalPlane *P, V3 x, SkyRect *r)
{
	float xt, xb, h;
	return sky_rect_at(P, x, r, &xt, &xb, &h);
}

/* B(i): the integral over [0, i] x [V0, V1], (S(i, j1) - S(i, j0)) +
 * f1 (S(i, j1 + 1) - S(i, j1)) - f0 (S(i, j0 + 1) - S(i, j0)), each
 * difference of (hi, lo) pairs taken as (hi_a - hi_b) + (lo_a - lo_b). */
INLINE float sky_band(GLOBAL const float *S, const SkyRect *r, int i)
{
	GLOBAL const float *p0 = S + r->o0 + 2 * i, *p1 = S + r->o1 + 2 * i;
	float h0 = p0[0], l0 = p0[1], h0n = p0[SKY_ROW], l0n = p0[SKY_ROW + 1];
	float h1 = p1[0], l1 = p1[1], h1n = p1[SKY_ROW], l1n = p1[SKY_ROW + 1];
	return ((h1 - h0) + (l1 - l0)) + r->f1 * ((h1n - h1) + (l1n - l1)) - r->f0 * ((h0n - h0) + (l0n - l0));
}

/* The integral over [0, U] x [V0, V1], linear between the knots. */
INLINE float sky_band_at(GLOBAL const float *S, const SkyRect *r, float U)
{
	float f;
	int i = sky_split(U, &f);
	float b = sky_band(S, r, i);
	return b + f * (sky_band(S, r, i + 1) - b);
}

/* C(j) of column i: its integral over rows [0, j), S(i + 1, j) - S(i, j). */
INLINE float sky_col(GLOBAL const float *S, int i, int j)
{
	GLOBAL const float *p = S + j * SKY_ROW + 2 * i;
	return (p[2] - p[0]) + (p[3] - p[1]);
}

INLINE float sky_col_at(GLOBAL const float *S, int i, float V)
{
	float f;
	int j = sky_split(V, &f);
	float c = sky_col(S, i, j);
	return c + f * (sky_col(S, i, j + 1) - c);
}

/* I_R, the integral over x's rectangle. */
INLINE float sky_rect_integral(GLOBAL const float *S, const SkyRect *r)
{
	return sky_band_at(S, r, r->U1) - sky_band_at(S, r, r->U0);
}

/* The knots of the cell (i, j) that sky_sample_uv drew from: column i's
 * mass B(i + 1) - B(i), its integrals H(V0), H(V1) at the rectangle's v
 * bounds and cell (i, j)'s C(j + 1) - C(j), for sky_pdf_uv_knots. */
typedef struct {
	int i, j;
	float colmass, h0, h1, cell;
} SkyKnots;

/* Density per unit U and V (cell units) of (U, V) within r, whose integral
 * is `total`; 0 outside r. Where (U, V) falls in kn's cell (kn not NULL),
 * the knots are kn's, which are the same numbers read again. */
INLINE float sky_pdf_uv_knots(GLOBAL const float *S, const SkyRect *r, float total, float U, float V,
			      const SkyKnots *kn)
{
	if (!(U >= r->U0 && U <= r->U1 && V >= r->V0 && V <= r->V1) || !(total > 0.0f))
		return 0.0f;
	float fu, fv;
	int i = sky_split(U, &fu), j = sky_split(V, &fv);
	float colmass, h0, h1, cell;
	if (kn && kn->i == i && kn->j == j) {
		colmass = kn->colmass;
		h0 = kn->h0;
		h1 = kn->h1;
		cell = kn->cell;
	} else {
		colmass = sky_band(S, r, i + 1) - sky_band(S, r, i);
		h0 = sky_col_at(S, i, r->V0);
		h1 = sky_col_at(S, i, r->V1);
		cell = sky_col(S, i, j + 1) - sky_col(S, i, j);
	}
	if (!(colmass > 0.0f) || !(h1 > h0) || !(cell > 0.0f))
		return 0.0f;
	return colmass / total * (cell / (h1 - h0));
}

INLINE float sky_pdf_uv(GLOBAL const float *S, const SkyRect *r, float total, float U, float V)
{
	return sky_pdf_uv_knots(S, r, total, U, V, 0);
}

/* Samples (U, V) within r (integral `total`) from u1, u2; 0 if none. The
 * drawn cell's knots go to *kn. */
INLINE int sky_sample_uv_knots(GLOBAL const float *S, const SkyRect *r, float total, float u1, float u2, float *U,
			       float *V, SkyKnots *kn)
{
	float fu0, fu1;
	int i0 = sky_split(r->U0, &fu0), i1 = sky_split(r->U1, &fu1);
	float b0 = sky_band(S, r, i0);
	float target = b0 + fu0 * (sky_band(S, r, i0 + 1) - b0) + u1 * total;
	/* The last column whose left knot is at most the target. The knots
	 * B(lo) and, once hi has moved, B(hi + 1) are kept from the search. */
	int lo = i0, hi = i1, moved = 0;
	float bl = b0, bh = 0.0f;
	while (lo < hi) {
		int mid = (lo + hi + 1) >> 1;
		float bm = sky_band(S, r, mid);
		if (bm <= target) {
			lo = mid;
			bl = bm;
		} else {
			hi = mid - 1;
			bh = bm;
			moved = 1;
		}
	}
	float slope = (moved ? bh : sky_band(S, r, lo + 1)) - bl;
	if (!(slope > 0.0f))
		return 0;
	*U = fmin(fmax((float)lo + (target - bl) / slope, fmax((float)lo, r->U0)), fmin((float)(lo + 1), r->U1));
	float h0 = sky_col_at(S, lo, r->V0), h1 = sky_col_at(S, lo, r->V1);
	if (!(h1 > h0))
		return 0;
	float t2 = h0 + u2 * (h1 - h0);
	int jl = r->j0, jh = r->j1;
	float cl = sky_col(S, lo, jl), ch = 0.0f;
	moved = 0;
	while (jl < jh) {
		int mid = (jl + jh + 1) >> 1;
		float cm = sky_col(S, lo, mid);
		if (cm <= t2) {
			jl = mid;
			cl = cm;
		} else {
			jh = mid - 1;
			ch = cm;
			moved = 1;
		}
	}
	float cs = (moved ? ch : sky_col(S, lo, jl + 1)) - cl;
	if (!(cs > 0.0f))
		return 0;
	*V = fmin(fmax((float)jl + (t2 - cl) / cs, fmax((float)jl, r->V0)), fmin((float)(jl + 1), r->V1));
	kn->i = lo;
	kn->j = jl;
	kn->colmass = slope;
	kn->h0 = h0;
	kn->h1 = h1;
	kn->cell = cs;
	return 1;
}

INLINE int sky_sample_uv(GLOBAL const float *S, const SkyRect *r, float total, float u1, float u2, float *U, float *V)
{
	SkyKnots kn;
	return sky_sample_uv_knots(S, r, total, u1, u2, U, V, &kn);
}

/* The tangent of the angle at coordinate c. */
INLINE float sky_tan(float c)
{
	float s, co;
	fast_sincos(c * PORTAL_SKY_CELL - 0.5f * AJAR_PI, &s, &co);
	return s / co;
}

/* Unit direction of (U, V) on plane P, and dw / (dU dV) there. */
INLINE V3 sky_dir(GLOBAL const PortalPlane *P, float U, float V, float *jac)
{
	float X = sky_tan(U), Y = sky_tan(V);
	float q = 1.0f + X * X + Y * Y, inv = 1.0f / sqrt(q);
	*jac = (1.0f + X * X) * (1.0f + Y * Y) * inv / q * (PORTAL_SKY_CELL * PORTAL_SKY_CELL);
	return v3_scale(v3_add(v3_add(v3_scale(P->t, X), v3_scale(P->b, Y)), P->n), inv);
}

/* (U, V) of unit direction w toward P's sky side (w . n > 0), and
 * dw / (dU dV) there. */
INLINE void sky_coords(GLOBAL const PortalPlane *P, V3 w, float *U, float *V, float *jac)
{
	float wt = v3_dot(w, P->t), wb = v3_dot(w, P->b), wn = v3_dot(w, P->n);
	*U = sky_coord(fast_atan2(wt, wn));
	*V = sky_coord(fast_atan2(wb, wn));
	float X = wt / wn, Y = wb / wn, q = 1.0f + X * X + Y * Y;
	*jac = (1.0f + X * X) * (1.0f + Y * Y) / (q * sqrt(q)) * (PORTAL_SKY_CELL * PORTAL_SKY_CELL);
}

/* Centre of P's rectangle. */
INLINE V3 sky_plane_centre(GLOBAL const PortalPlane *P)
{
	return v3_add(P->o, v3_add(v3_scale(P->t, 0.5f * (P->a0 + P->a1)), v3_scale(P->b, 0.5f * (P->b0 + P->b1))));
}
#endif
