/* bsdf_albedo.h — what each lobe reflects: Fresnel, the albedos, the
 * Kulla-Conty factors, and the lobe selection they weight. */
#ifndef AJAR_BSDF_ALBEDO_H
#define AJAR_BSDF_ALBEDO_H
#include "material/bsdf_setup.h"

/* Contains some delta lobe (smooth metal or glass with a non-zero weight). */
INLINE int bsdf_has_delta(const Bsdf *bs)
{
	return bsdf_smooth(bs) && (bsdf_w_metal(bs) > 0.0f || bsdf_w_glass(bs) > 0.0f);
}

/* No non-delta lobe at all: skip light sampling and connections. */
INLINE int bsdf_is_delta(const Bsdf *bs)
{
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs))
		return 0;
#endif
	return bsdf_smooth(bs) && !(bsdf_w_plastic(bs) > 0.0f);
}

INLINE V3 bsdf_fresnel_metal(const Bsdf *bs, float c)
{
	float w = bsdf_schlick_w(c);
	V3 f0 = bs->base_color;
	return v3(f0.x + (1.0f - f0.x) * w, f0.y + (1.0f - f0.y) * w, f0.z + (1.0f - f0.z) * w);
}

INLINE float bsdf_fresnel_coat(const Bsdf *bs, float c)
{
	float r = (bs->ior - 1.0f) / (bs->ior + 1.0f);
	float f0 = r * r;
	return bs->specular * (f0 + (1.0f - f0) * bsdf_schlick_w(c));
}

/* The coat's single-scattering albedo Es(mu), Fresnel included; *e1 is E1(mu)
 * at the coat's alpha, which its multiple scattering needs. */
INLINE float bsdf_coat_albedo(const Bsdf *bs, float mu, float *e1)
{
	BsdfTabAt a = bsdf_tab_at(bsdf_coat_alpha(bs), mu);
	*e1 = bsdf_tab2(bsdf_tab_e1, a);
	return bs->coat_s1 * *e1 + bs->coat_sw * bsdf_tab2(bsdf_tab_ew, a);
}

/* The coat's whole albedo Et = Es + coat_fms (1 - E1), from Es and E1. */
INLINE float bsdf_coat_total(const Bsdf *bs, float es, float e1) { return es + bs->coat_fms * (1.0f - e1); }

/* The metal's single-scattering albedo with Fresnel 1, E1(mu) (isotropic:
 * also thin glass's). */
INLINE float bsdf_metal_albedo(const Bsdf *bs, float mu) { return bsdf_tab2(bsdf_tab_e1, bsdf_tab_at(bs->alpha, mu)); }

/* E1 of the metal (and the coat) at local direction w: anisotropic
 * materials' depends on its azimuth too. */
INLINE float bsdf_metal_albedo_w(const Bsdf *bs, V3 w)
{
#ifndef AJAR_NO_ANISOTROPY
	if (BSDF_IS_ANISO(bs))
		return bsdf_aniso_e1(bs, w);
#endif
	return bsdf_metal_albedo(bs, w.z);
}

/* bsdf_coat_albedo at local direction w. Anisotropic: E1 from
 * bsdf_aniso_e1 and Ew the isotropic table's at alpha_rms scaled by the
 * same ratio to the isotropic E1 (its average alike, bsdf_setup_energy). */
INLINE float bsdf_coat_albedo_w(const Bsdf *bs, V3 w, float *e1)
{
#ifndef AJAR_NO_ANISOTROPY
	if (BSDF_IS_ANISO(bs)) {
		BsdfTabAt a = bsdf_tab_at(bs->an_rms, w.z);
		*e1 = bsdf_aniso_e1(bs, w);
		return bs->coat_s1 * *e1 + bs->coat_sw * bsdf_tab2(bsdf_tab_ew, a) * *e1 / fmax(bsdf_tab2(bsdf_tab_e1, a), 1e-7f);
	}
#endif
	return bsdf_coat_albedo(bs, w.z, e1);
}

/* The diffuse base's factor (1 - Et(mu_o)) (1 - Et(mu_i)) / (pi (1 - Etavg)),
 * from Et(mu_o) and Et(mu_i). */
INLINE float bsdf_base_factor(const Bsdf *bs, float et_o, float et_i)
{
	if (!(bs->specular > 0.0f))
		return AJAR_INV_PI; /* no coat: exactly Lambertian */
	return (1.0f - et_o) * (1.0f - et_i) * AJAR_INV_PI / (1.0f - bs->coat_eavg);
}

/* Kulla and Conty's (1 - E1(mu_o)) (1 - E1(mu_i)) / (pi (1 - E1avg)), without its colour. */
INLINE float bsdf_kc_factor(float e_o, float e_i, float eavg)
{
	return (1.0f - e_o) * (1.0f - e_i) * AJAR_INV_PI / fmax(1.0f - eavg, 1e-7f);
}

/* Multiple scattering of the metal without its colour Fms, at local wi. */
INLINE float bsdf_ms_factor(const Bsdf *bs, float e_o, V3 wi)
{
	return bsdf_kc_factor(e_o, bsdf_metal_albedo_w(bs, wi), bs->metal_eavg);
}

/* Single-scattering albedo of rough glass at mu, reflection and
 * transmission together, from outside (Go) or inside (Gi). */
INLINE float bsdf_glass_albedo(const Bsdf *bs, int outside, float mu)
{
	return bsdf_tab3(outside ? bsdf_tab_go : bsdf_tab_gi, bs->glass_k, bs->glass_i, bs->glass_wk, bs->glass_wr, mu);
}

/* Multiple scattering of rough glass as energy (importance transport),
 * without the tint: c (1 - G(mu_o)) (1 - G'(mu_i)) / pi, G of wo's side
 * and G' of wi's, c = c_oo, c_ii (reflection) or c_oi, c_io (refraction
 * from outside, inside). Reciprocal as the adjoint needs; a white glass
 * loses nothing from either side. */
INLINE float bsdf_glass_ms(const Bsdf *bs, int outside, int reflect, float e_o, float mu_i)
{
	int wi_outside = reflect ? outside : !outside;
	float c = bs->glass_c[reflect ? (outside ? 0 : 1) : (outside ? 2 : 3)];
	return c * (1.0f - e_o) * (1.0f - bsdf_glass_albedo(bs, wi_outside, mu_i)) * AJAR_INV_PI;
}

/* Pure Lambertian (glTF with specular 0, no metal, no transmission) and
 * not black: the diffuse lobe is then the only one. */
INLINE int bsdf_lambert(const Bsdf *bs) { return bs->flags & BSDF_LAMBERT; /* set by bsdf_setup_mr */ }

/* Lobe selection for local outgoing wo (wo.z > 0) on the side of relative
 * ior eta: weight x albedo estimate. */
INLINE BsdfLobes bsdf_lobes_calc(const Bsdf *bs, V3 wo, float eta)
{
	float cos_o = wo.z;
	BsdfLobes p;
	if (bsdf_lambert(bs)) { /* what the general case gives, the same bits, without its tables */
		float d = v3_avg(bs->base_color);
		p.metal = p.coat = p.glass = p.ms = p.glass_r = p.glass_t = 0.0f;
		p.diffuse = d * (1.0f / d);
		p.e_metal = p.e_glass = 1.0f;
		p.e_coat = 0.0f;
		p.e_coat1 = 1.0f;
		return p;
	}
	float wm = bsdf_w_metal(bs), wp = bsdf_w_plastic(bs);
	p.e_metal = wm > 0.0f && !bsdf_smooth(bs) ? bsdf_metal_albedo_w(bs, wo) : 1.0f;
	p.e_coat1 = 1.0f;
	p.e_coat = wp > 0.0f && bs->specular > 0.0f ? bsdf_coat_albedo_w(bs, wo, &p.e_coat1) : 0.0f; /* 0 without a coat */
	p.metal = wm * v3_avg(bsdf_fresnel_metal(bs, cos_o)) * p.e_metal;
	float cms = bs->coat_fms * (1.0f - p.e_coat1); /* the coat's multiple scattering */
	p.ms = wm * v3_avg(bs->metal_fms) * (1.0f - p.e_metal) + wp * cms;
	p.coat = wp * p.e_coat;
	p.diffuse = wp * (1.0f - (p.e_coat + cms)) * v3_avg(bs->base_color);
	float wg = bsdf_w_glass(bs);
	if (bsdf_thin(bs)) { /* E1 (Fresnel 1) and the multiple scattering split by Favg */
		p.e_glass = wg > 0.0f && !bsdf_smooth(bs) ? bsdf_metal_albedo(bs, cos_o) : 1.0f;
		p.glass = wg * p.e_glass;
		p.glass_r = wg * (1.0f - p.e_glass) * bs->glass_x;
		p.glass_t = wg * (1.0f - p.e_glass) * (1.0f - bs->glass_x) * v3_avg(bs->base_color);
	} else {
		p.e_glass = wg > 0.0f && !bsdf_smooth(bs) ? bsdf_glass_albedo(bs, eta > 1.0f, cos_o) : 1.0f;
		float xs = eta > 1.0f ? bs->glass_x : bs->glass_y;
		p.glass = wg * p.e_glass;
		p.glass_r = wg * (1.0f - p.e_glass) * (1.0f - xs);
		p.glass_t = wg * (1.0f - p.e_glass) * xs * v3_avg(bs->base_color);
	}
	float sum = p.metal + p.coat + p.diffuse + p.glass + p.ms + p.glass_r + p.glass_t;
	float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
	p.metal *= inv;
	p.coat *= inv;
	p.diffuse *= inv;
	p.glass *= inv;
	p.ms *= inv;
	p.glass_r *= inv;
	p.glass_t *= inv;
	return p;
}

/* bsdf_lobes_calc, or the same values cached for that (wo, eta) by
 * bsdf_cache_wo: the living-room's portal render evaluated 208,789 lobes
 * for 53,524 hits, a vertex many times from its own wo (kernels/material/
 * README.md, "Cost"). Equal keys give equal bits. */
INLINE BsdfLobes bsdf_lobes(const Bsdf *bs, V3 wo, float eta)
{
	if (wo.z == bs->lc_z && wo.x == bs->lc_x && wo.y == bs->lc_y && eta == bs->lc_eta && !bsdf_lambert(bs))
		return bs->lc;
	return bsdf_lobes_calc(bs, wo, eta);
}

#endif
