/* bsdf_setup.h — a Bsdf from a material: frame, weights, the energy
 * compensation's constants, anisotropy, specular colour, layers. */
#ifndef AJAR_BSDF_SETUP_H
#define AJAR_BSDF_SETUP_H
#include "material/bsdf_lookup.h"

INLINE void bsdf_setup_energy(Bsdf *bs);

/* The BSDF of material m with metallic, roughness, transmission and
 * specular given (textured, surface.h). */
INLINE void bsdf_setup_mr(Bsdf *bs, GLOBAL const Material *m, V3 base_color, float metallic, float roughness,
			  float transmission, float specular, V3 ns, V3 ng)
{
	float lg = v3_len(ng);
	bs->ng = lg > 0.0f ? v3_scale(ng, 1.0f / lg) : v3(0.0f, 0.0f, 1.0f);
	float ls = v3_len(ns);
	V3 n = ls > 0.0f ? v3_scale(ns, 1.0f / ls) : bs->ng;
	if (!(v3_dot(n, n) > 0.5f))
		n = bs->ng; /* NaN or infinite shading normal */
	float cn = v3_dot(n, bs->ng);
	if (cn < 0.0f)
		n = v3_neg(n);
	bs->n = n;
	v3_basis(n, &bs->t, &bs->b);
	bs->base_color = v3(bsdf_clamp01(base_color.x), bsdf_clamp01(base_color.y), bsdf_clamp01(base_color.z));
	bs->metallic = bsdf_clamp01(metallic);
	float r = bsdf_clamp01(roughness);
	bs->alpha = r * r;
	bs->transmission = bsdf_clamp01(transmission);
	bs->ior = fmin(fmax(m->ior, BSDF_MIN_IOR), BSDF_MAX_IOR);
	bs->specular = bsdf_clamp01(specular);
	int lambert = bs->metallic == 0.0f && bs->transmission == 0.0f && bs->specular == 0.0f &&
		      v3_maxc(bs->base_color) > 0.0f;
	bs->flags = (m->flags & ~(BSDF_TILTED | BSDF_LAMBERT)) | (lambert ? BSDF_LAMBERT : 0);
#ifndef AJAR_NO_BENT_NORMALS
	bs->flags |= fabs(cn) < BSDF_TILT_COS ? BSDF_TILTED : 0;
#endif
	bs->lc_z = -1.0f; /* no cached lobes: a local wo has z > 0 */
	bsdf_setup_energy(bs);
}

/* The energy compensation's constants for the lobes bs has (bsdf.h's top). */
INLINE void bsdf_setup_energy(Bsdf *bs)
{
	bs->coat_s1 = bs->coat_sw = bs->coat_eavg = bs->coat_fms = bs->coat_e1avg = bs->metal_eavg = 0.0f;
	bs->metal_fms = v3(0.0f, 0.0f, 0.0f);
	if (bsdf_w_plastic(bs) > 0.0f && bs->specular > 0.0f) {
		float q = (bs->ior - 1.0f) / (bs->ior + 1.0f);
		BsdfTabAt a = bsdf_tab_at(bsdf_coat_alpha(bs), 1.0f);
		bs->coat_s1 = bs->specular * q * q;
		bs->coat_sw = bs->specular - bs->coat_s1;
		float e1 = bsdf_tab1(bsdf_tab_e1avg, a), ewavg = bsdf_tab1(bsdf_tab_ewavg, a);
#ifndef AJAR_NO_ANISOTROPY
		if (BSDF_IS_ANISO(bs)) { /* Ewavg scaled as Ew is (bsdf_coat_e) */
			BsdfTabAt ar = bsdf_tab_at(bs->an_rms, 1.0f);
			e1 = bsdf_aniso_e1avg(bs);
			ewavg = bsdf_tab1(bsdf_tab_ewavg, ar) * e1 / bsdf_tab1(bsdf_tab_e1avg, ar);
		}
#endif
		float fa = bs->coat_s1 + bs->coat_sw * (1.0f / 21.0f); /* specular (F0 + (1 - F0) / 21) */
		bs->coat_e1avg = e1;
		bs->coat_fms = fa * fa * e1 / (1.0f - fa * (1.0f - e1));
		bs->coat_eavg = bs->coat_s1 * e1 + bs->coat_sw * ewavg + bs->coat_fms * (1.0f - e1);
	}
	bs->glass_k = bs->glass_i = 0;
	bs->glass_wk = bs->glass_wr = bs->glass_x = bs->glass_y = 0.0f;
	bs->glass_c[0] = bs->glass_c[1] = bs->glass_c[2] = bs->glass_c[3] = 0.0f;
	if (bsdf_w_glass(bs) > 0.0f && !bsdf_smooth(bs) && bsdf_thin(bs)) {
		/* Thin: E1 at alpha and its mean, the Fresnel mean at ior. */
		float q = (bs->ior - 1.0f) / (bs->ior + 1.0f) * ((BSDF_TAB_GE - 1) / BSDF_TAB_GT_MAX);
		int k = min((int)q, BSDF_TAB_GE - 2);
		float wk = bsdf_clamp01(q - (float)k);
		bs->glass_x = bsdf_tab_gfavg[k] + (bsdf_tab_gfavg[k + 1] - bsdf_tab_gfavg[k]) * wk;
		bs->glass_y = bsdf_tab1(bsdf_tab_e1avg, bsdf_tab_at(bs->alpha, 1.0f));
	} else if (bsdf_w_glass(bs) > 0.0f && !bsdf_smooth(bs)) {
		float q = (bs->ior - 1.0f) / (bs->ior + 1.0f) * ((BSDF_TAB_GE - 1) / BSDF_TAB_GT_MAX);
		float x = bsdf_clamp01(sqrt(bs->alpha)) * (BSDF_TAB_GR - 1);
		bs->glass_k = min((int)q, BSDF_TAB_GE - 2);
		bs->glass_i = min((int)x, BSDF_TAB_GR - 2);
		bs->glass_wk = bsdf_clamp01(q - (float)bs->glass_k);
		bs->glass_wr = x - (float)bs->glass_i;
		int k = bs->glass_k, i = bs->glass_i;
		float wk = bs->glass_wk, wr = bs->glass_wr;
		float lo = fmax(1.0f - bsdf_tab3avg(bsdf_tab_goavg, k, i, wk, wr), 1e-7f);
		float li = fmax(1.0f - bsdf_tab3avg(bsdf_tab_giavg, k, i, wk, wr), 1e-7f);
		float fa = bsdf_tab_gfavg[k] + (bsdf_tab_gfavg[k + 1] - bsdf_tab_gfavg[k]) * wk;
		float eta2 = bs->ior * bs->ior;
		/* Energy: from outside c_oo lo + c_oi li = 1, from inside
		 * c_ii li + c_io lo = 1; the adjoint relation of refraction
		 * (radiance f divided by eta^2) needs c_io = c_oi / eta^2. From
		 * outside the lost light is transmitted in the share 1 - Favg,
		 * as single scattering transmits it, unless that asks more than
		 * everything of the inside (glass_y <= 1). */
		float xo = fmin(1.0f - fa, eta2 * li / lo);
		bs->glass_x = xo;
		bs->glass_y = fmin(xo * lo / (eta2 * li), 1.0f);
		bs->glass_c[0] = (1.0f - xo) / lo;
		bs->glass_c[1] = (1.0f - bs->glass_y) / li;
		bs->glass_c[2] = xo / li;
		bs->glass_c[3] = xo / (li * eta2);
	}
	if (bsdf_w_metal(bs) > 0.0f && !bsdf_smooth(bs)) {
		float e = bsdf_tab1(bsdf_tab_e1avg, bsdf_tab_at(bs->alpha, 1.0f));
#ifndef AJAR_NO_ANISOTROPY
		if (BSDF_IS_ANISO(bs))
			e = bsdf_aniso_e1avg(bs);
#endif
		V3 fa = v3_add(v3_scale(bs->base_color, 20.0f / 21.0f), v3(1.0f / 21.0f, 1.0f / 21.0f, 1.0f / 21.0f));
		bs->metal_eavg = e;
		bs->metal_fms = v3(fa.x * fa.x * e / (1.0f - fa.x * (1.0f - e)), fa.y * fa.y * e / (1.0f - fa.y * (1.0f - e)),
				   fa.z * fa.z * e / (1.0f - fa.z * (1.0f - e)));
	}
}

#ifndef AJAR_NO_ANISOTROPY
/* KHR_materials_anisotropy with strength s along the world direction dir
 * (the tangent turned by the rotation, surface.h): alpha_b = max(alpha,
 * 1e-3) (never a delta), alpha_t = alpha_b + (1 - alpha_b) s^2, the frame's
 * t along dir, and the energy compensation redone with the anisotropic
 * albedos. */
INLINE void bsdf_setup_aniso(Bsdf *bs, float strength, V3 dir)
{
	float st = bsdf_clamp01(strength);
	V3 t = v3_madd(dir, bs->n, -v3_dot(dir, bs->n));
	float lt = v3_len2(t);
	if (!(st > 0.0f) || !(lt > 1e-12f))
		return;
	bs->t = v3_scale(t, 1.0f / sqrt(lt));
	bs->b = v3_cross(bs->n, bs->t);
	bs->alpha = fmax(bs->alpha, BSDF_DELTA_ALPHA);
	bs->ay = bs->alpha;
	bs->ax = bs->ay + (1.0f - bs->ay) * st * st;
	bs->an_rms = sqrt(0.5f * (bs->ax * bs->ax + bs->ay * bs->ay));
	bs->an_k = sqrt(sqrt(bs->ax / bs->ay));
	float x = bsdf_clamp01(sqrt(bs->ay)) * (BSDF_TAB_AR - 1), y = st * (BSDF_TAB_AS - 1);
	bs->an_i = min((int)x, BSDF_TAB_AR - 2);
	bs->an_j = min((int)y, BSDF_TAB_AS - 2);
	bs->an_wr = x - (float)bs->an_i;
	bs->an_ws = y - (float)bs->an_j;
	bs->flags |= BSDF_ANISO;
	bsdf_setup_energy(bs);
}
#endif

#ifndef AJAR_NO_LAYERS
/* Where sheen roughness r and mu fall in the sheen tables (as bsdf_tab_at;
 * rows quadratic in r, bsdf_tables.h). */
INLINE BsdfTabAt bsdf_sheen_at(float r, float mu)
{
	BsdfTabAt a;
	float x = sqrt(bsdf_clamp01((r - SHEEN_MIN_R) * (1.0f / (1.0f - SHEEN_MIN_R)))) * (BSDF_TAB_SR - 1);
	float y = sqrt(bsdf_clamp01(mu)) * (BSDF_TAB_NMU - 1);
	a.i = min((int)x, BSDF_TAB_SR - 2);
	a.j = min((int)y, BSDF_TAB_NMU - 2);
	a.wr = x - (float)a.i;
	a.wm = y - (float)a.j;
	return a;
}

/* KHR_materials_specular's colour: the coat's F0 per channel is
 * min(F0 tint, 1), times the specular factor as before (bsdf.h's top). */
INLINE void bsdf_setup_tint(Bsdf *bs, V3 tint)
{
	if (!(bsdf_w_plastic(bs) > 0.0f && bs->specular > 0.0f))
		return;
	float q = (bs->ior - 1.0f) / (bs->ior + 1.0f), f0 = q * q, e1 = bs->coat_e1avg;
	float ew = (bs->coat_eavg - bs->coat_s1 * e1 - bs->coat_fms * (1.0f - e1)) / fmax(bs->coat_sw, 1e-7f);
	float c[3] = {tint.x, tint.y, tint.z}, s1[3], fms[3], ea[3];
	for (int k = 0; k < 3; k++) {
		float f0c = fmin(f0 * fmax(c[k], 0.0f), 1.0f), sw;
		s1[k] = bs->specular * f0c;
		sw = bs->specular - s1[k];
		float fa = s1[k] + sw * (1.0f / 21.0f);
		fms[k] = fa * fa * e1 / (1.0f - fa * (1.0f - e1));
		ea[k] = s1[k] * e1 + sw * ew + fms[k] * (1.0f - e1);
	}
	bs->tint_s1 = v3(s1[0], s1[1], s1[2]);
	bs->tint_fms = v3(fms[0], fms[1], fms[2]);
	bs->tint_eavg = v3(ea[0], ea[1], ea[2]);
	bs->flags |= BSDF_TINT;
}

/* KHR_materials_sheen (colour, roughness) and _clearcoat (factor,
 * roughness, normal cn) over the core. */
INLINE void bsdf_setup_layers(Bsdf *bs, V3 sheen, float sheen_r, float cc, float cc_r, V3 cn)
{
	bs->sheen = v3(bsdf_clamp01(sheen.x), bsdf_clamp01(sheen.y), bsdf_clamp01(sheen.z));
	bs->sheen_c = v3_maxc(bs->sheen);
	bs->sheen_r = fmin(fmax(sheen_r, SHEEN_MIN_R), 1.0f);
	bs->sheen_eavg = 0.0f;
	if (bs->sheen_c > 0.0f) {
		BsdfTabAt a = bsdf_sheen_at(bs->sheen_r, 1.0f);
		bs->sheen_eavg = bs->sheen_c * (bsdf_tab_sheenavg[a.i] + (bsdf_tab_sheenavg[a.i + 1] - bsdf_tab_sheenavg[a.i]) * a.wr);
	}
	bs->cc = bsdf_clamp01(cc);
	float r = bsdf_clamp01(cc_r);
	bs->cc_alpha = fmax(r * r, BSDF_MIN_ALPHA);
	bs->cc_fms = bs->cc_e1avg = bs->cc_eavg = 0.0f;
	float ln = v3_len(cn);
	bs->cc_n = ln > 0.0f ? v3_scale(cn, 1.0f / ln) : bs->n;
	if (!(v3_dot(bs->cc_n, bs->cc_n) > 0.5f))
		bs->cc_n = bs->n;
	if (v3_dot(bs->cc_n, bs->ng) < 0.0f)
		bs->cc_n = v3_neg(bs->cc_n);
	if (bs->cc > 0.0f) { /* Kulla-Conty with the exact Fresnel's mean at ior 1.5 (the glass tables' node) */
		BsdfTabAt a = bsdf_tab_at(bs->cc_alpha, 1.0f);
		float e1 = bsdf_tab1(bsdf_tab_e1avg, a), x = sqrt(bsdf_clamp01(bs->cc_alpha)) * (BSDF_TAB_CR - 1);
		float q = (BSDF_CC_IOR - 1.0f) / (BSDF_CC_IOR + 1.0f) * ((BSDF_TAB_GE - 1) / BSDF_TAB_GT_MAX);
		int k = min((int)q, BSDF_TAB_GE - 2), i = min((int)x, BSDF_TAB_CR - 2);
		float fa = bsdf_tab_gfavg[k] + (bsdf_tab_gfavg[k + 1] - bsdf_tab_gfavg[k]) * bsdf_clamp01(q - (float)k);
		bs->cc_e1avg = e1;
		bs->cc_fms = fa * fa * e1 / (1.0f - fa * (1.0f - e1));
		bs->cc_eavg = bsdf_tab_eccavg[i] + (bsdf_tab_eccavg[i + 1] - bsdf_tab_eccavg[i]) * (x - (float)i) +
			      bs->cc_fms * (1.0f - e1);
	}
	if (bs->sheen_c > 0.0f || bs->cc > 0.0f)
		bs->flags |= BSDF_LAYERED; /* BSDF_LAMBERT still says what the core is */
}
#endif

/* The BSDF of material m, its metallic, roughness and transmission untextured. */
INLINE void bsdf_setup(Bsdf *bs, GLOBAL const Material *m, V3 base_color, V3 ns, V3 ng)
{
	bsdf_setup_mr(bs, m, base_color, m->metallic, m->roughness, m->transmission, m->specular, ns, ng);
#ifndef AJAR_NO_ANISOTROPY
	if (m->anisotropy > 0.0f) /* no tangent here: along the frame's own t */
		bsdf_setup_aniso(bs, m->anisotropy, bs->t);
#endif
#ifndef AJAR_NO_LAYERS
	if (m->flags & MATERIAL_TINTED)
		bsdf_setup_tint(bs, m->specular_color);
	if (v3_maxc(m->sheen_color) > 0.0f || m->clearcoat > 0.0f)
		bsdf_setup_layers(bs, m->sheen_color, m->sheen_roughness, m->clearcoat, m->clearcoat_roughness, bs->n);
#endif
}

#endif
