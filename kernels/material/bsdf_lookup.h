/* bsdf_lookup.h — reading bsdf_tables.h (bi- and trilinear), the three
 * lobes' weights, the anisotropic GGX's E1. */
#ifndef AJAR_BSDF_LOOKUP_H
#define AJAR_BSDF_LOOKUP_H
#include "material/bsdf_types.h"

/* Where (alpha, mu) falls in bsdf_tables.h's grid: the lower row and column
 * and the weights of the upper ones. */
typedef struct {
	int i, j;
	float wr, wm;
} BsdfTabAt;

INLINE BsdfTabAt bsdf_tab_at(float alpha, float mu)
{
	BsdfTabAt a;
	float x = bsdf_clamp01(sqrt(fmax(alpha, 0.0f))) * (BSDF_TAB_NR - 1);
	float y = sqrt(bsdf_clamp01(mu)) * (BSDF_TAB_NMU - 1);
	a.i = min((int)x, BSDF_TAB_NR - 2);
	a.j = min((int)y, BSDF_TAB_NMU - 2);
	a.wr = x - (float)a.i;
	a.wm = y - (float)a.j;
	return a;
}

INLINE float bsdf_tab2(CONSTANT float *t, BsdfTabAt a)
{
	CONSTANT float *r0 = t + a.i * BSDF_TAB_NMU + a.j, *r1 = r0 + BSDF_TAB_NMU;
	float v0 = r0[0] + (r0[1] - r0[0]) * a.wm, v1 = r1[0] + (r1[1] - r1[0]) * a.wm;
	return v0 + (v1 - v0) * a.wr;
}

/* A per-roughness table (the averages), linear in sqrt(alpha). */
INLINE float bsdf_tab1(CONSTANT float *t, BsdfTabAt a) { return t[a.i] + (t[a.i + 1] - t[a.i]) * a.wr; }

/* The glass tables: blocks of BSDF_TAB_GR x BSDF_TAB_GMU per ior node;
 * trilinear in (t, sqrt(alpha), sqrt(mu)), or bilinear for the averages. */
INLINE float bsdf_tab3(CONSTANT float *t, int k, int i, float wk, float wr, float mu)
{
	float y = sqrt(bsdf_clamp01(mu)) * (BSDF_TAB_GMU - 1);
	int j = min((int)y, BSDF_TAB_GMU - 2);
	float wm = y - (float)j, v[4];
	for (int c = 0; c < 4; c++) {
		CONSTANT float *r = t + ((k + (c >> 1)) * BSDF_TAB_GR + i + (c & 1)) * BSDF_TAB_GMU + j;
		v[c] = r[0] + (r[1] - r[0]) * wm;
	}
	float v0 = v[0] + (v[1] - v[0]) * wr, v1 = v[2] + (v[3] - v[2]) * wr;
	return v0 + (v1 - v0) * wk;
}

INLINE float bsdf_tab3avg(CONSTANT float *t, int k, int i, float wk, float wr)
{
	CONSTANT float *r0 = t + k * BSDF_TAB_GR + i, *r1 = r0 + BSDF_TAB_GR;
	float v0 = r0[0] + (r0[1] - r0[0]) * wr, v1 = r1[0] + (r1[1] - r1[0]) * wr;
	return v0 + (v1 - v0) * wk;
}

INLINE float bsdf_w_metal(const Bsdf *bs) { return bs->metallic; }
INLINE float bsdf_w_plastic(const Bsdf *bs) { return (1.0f - bs->metallic) * (1.0f - bs->transmission); }
INLINE float bsdf_w_glass(const Bsdf *bs) { return (1.0f - bs->metallic) * bs->transmission; }
INLINE int bsdf_smooth(const Bsdf *bs) { return bs->alpha < BSDF_DELTA_ALPHA; }
/* Thin-walled glass (no KHR_materials_volume): one interface, no bending. */
INLINE int bsdf_thin(const Bsdf *bs) { return !(bs->flags & MATERIAL_VOLUME); }
INLINE float bsdf_coat_alpha(const Bsdf *bs) { return fmax(bs->alpha, BSDF_MIN_ALPHA); }

#ifndef AJAR_NO_ANISOTROPY
/* E1 of the anisotropic GGX at local direction w (x along t): the
 * isotropic table at alpha_rms plus the tabulated residual, quadrilinear in
 * (sqrt(alpha_b), s, sqrt(mu), psi), psi the warped azimuth (tan psi =
 * tan phi / an_k, bsdf_tables.c) folded into [0, pi/2] (E1 is even in both
 * frame axes). */
INLINE float bsdf_aniso_e1(const Bsdf *bs, V3 w)
{
	float e = bsdf_tab2(bsdf_tab_e1, bsdf_tab_at(bs->an_rms, w.z));
	float y = sqrt(bsdf_clamp01(w.z)) * (BSDF_TAB_AMU - 1);
	float z = fast_atan2(fabs(w.y), bs->an_k * fabs(w.x)) * (2.0f * AJAR_INV_PI) * (BSDF_TAB_APHI - 1);
	int k = min((int)y, BSDF_TAB_AMU - 2), l = min(max((int)z, 0), BSDF_TAB_APHI - 2);
	float wm = y - (float)k, wp = bsdf_clamp01(z - (float)l), r = 0.0f;
	for (int c = 0; c < 4; c++) {
		int di = c & 1, dj = c >> 1;
		float wc = (di ? bs->an_wr : 1.0f - bs->an_wr) * (dj ? bs->an_ws : 1.0f - bs->an_ws);
		CONSTANT float *t0 =
			bsdf_tab_aniso + (((bs->an_i + di) * BSDF_TAB_AS + bs->an_j + dj) * BSDF_TAB_APHI + l) * BSDF_TAB_AMU + k;
		CONSTANT float *t1 = t0 + BSDF_TAB_AMU;
		float v0 = t0[0] + (t0[1] - t0[0]) * wm, v1 = t1[0] + (t1[1] - t1[0]) * wm;
		r += wc * (v0 + (v1 - v0) * wp);
	}
	return e + r;
}

/* E1's cosine- and azimuth-weighted mean: the isotropic one at alpha_rms
 * plus the residual's. */
INLINE float bsdf_aniso_e1avg(const Bsdf *bs)
{
	CONSTANT float *t = bsdf_tab_anisoavg + bs->an_i * BSDF_TAB_AS + bs->an_j;
	float v0 = t[0] + (t[1] - t[0]) * bs->an_ws, v1 = t[BSDF_TAB_AS] + (t[BSDF_TAB_AS + 1] - t[BSDF_TAB_AS]) * bs->an_ws;
	return bsdf_tab1(bsdf_tab_e1avg, bsdf_tab_at(bs->an_rms, 1.0f)) + v0 + (v1 - v0) * bs->an_wr;
}

#endif

#endif
