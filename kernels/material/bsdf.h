/* bsdf.h — glTF metallic-roughness as one BSDF: evaluation, sampling, pdfs.
 *
 * Three lobes, mixed by the glTF weights (base_color is factor x texture):
 *   metal   weight metallic: GGX conductor, Schlick Fresnel with F0 = base_color,
 *           plus Kulla and Conty's (2017) multiple-scattering lobe
 *           Fms (1 - E1(mu_o)) (1 - E1(mu_i)) / (pi (1 - E1avg)), where E1 is
 *           the single-scattering albedo with Fresnel 1 and
 *           Fms = Favg^2 E1avg / (1 - Favg (1 - E1avg)) (Favg = F0 + (1 - F0)/21,
 *           Schlick's cosine-weighted mean): with F = 1 it returns exactly the
 *           energy single scattering loses, and colours it as the light
 *           bouncing between coloured microfacets;
 *   plastic weight (1 - metallic)(1 - transmission): a GGX dielectric coat
 *           with Fs(c) = specular * Schlick(F0 = ((ior-1)/(ior+1))^2, c), plus
 *           the coat's own multiple-scattering lobe, Kulla and Conty's form
 *           as the metal's, Fc (1 - E1(mu_o)) (1 - E1(mu_i)) / (pi (1 - E1avg))
 *           with E1 at the coat's alpha and Fc = Fms at the coat's Fresnel
 *           mean Favg = specular (F0 + (1 - F0)/21): light that meets a second
 *           microfacet is reflected with Favg and otherwise enters the base,
 *           so the geometric series is the conductor's with Favg < 1 (what
 *           the series leaves is the base's share below); over a diffuse
 *           base that receives what the coat does not reflect:
 *           base_color (1 - Et(mu_o)) (1 - Et(mu_i)) / (pi (1 - Etavg)),
 *           Et = Es + Fc (1 - E1) the coat's directional albedo, single
 *           scattering (Es, Fresnel included) and multiple, and Etavg its
 *           cosine-weighted mean. Reciprocal, and a white base gives a
 *           directional albedo Et + (1 - Et) = 1 at every angle and roughness,
 *           a black one Et; specular = 0 gives exactly base_color / pi
 *           (KHR_materials_specular scales the whole Fresnel term, as glTF
 *           does);
 *   glass   weight (1 - metallic) transmission, thin-walled as glTF defines a
 *           material without KHR_materials_volume (bsdf_thin below), or, with
 *           a volume (MATERIAL_VOLUME), a
 *           rough dielectric (Walter et
 *           al. 2007) with exact Fresnel, transmission tinted by base_color,
 *           plus Kulla and Conty's multiple scattering for dielectrics: four
 *           cosine-shaped lobes (reflection outside and inside, refraction
 *           each way) c (1 - G(mu_o)) (1 - G'(mu_i)) / pi, G and G' the
 *           single-scattering albedos (reflection + refraction) of wo's and
 *           wi's sides, the constants c solved in bsdf_setup so that a white
 *           glass loses nothing from either side and the pair of refraction
 *           lobes obeys the adjoint relation (bsdf_glass_ms).
 * Thin-walled glass is one interface that does not bend light: reflection
 * F D G / (4 |cos_o cos_i|) as the dielectric's, and transmission the same
 * lobe mirrored through the surface (glTF's KHR_materials_transmission:
 * the reflected direction flipped to the far side), weighted by (1 - F)
 * and tinted by base_color, plus Kulla and Conty's multiple scattering
 * split between the two sides as Favg (reflection) and 1 - Favg, so a
 * white thin glass loses nothing: E1 + (1 - E1) (Favg + 1 - Favg) = 1.
 * Smooth, its transmission is the note's pass-through vertex (Eq. 5) with
 * the transmittance wg (1 - F) base_color: a null event (bsdf_null_prob,
 * bsdf_null_weight) that walks cross without a vertex and shadow rays and
 * connections cross multiplied by it (geom/visibility.h), its Fresnel
 * taken in the own shading normal so that both directions see the same.
 * GGX alpha = roughness^2. Metal and glass with alpha < BSDF_DELTA_ALPHA are
 * delta lobes (mirror, smooth glass); the plastic coat never is: its alpha is
 * clamped to >= BSDF_MIN_ALPHA. Microfacet terms: height-correlated Smith G2
 * = 1 / (1 + L(wo) + L(wi)), visible-normal sampling (Heitz 2018), so pdfs
 * are D_wo(h) times the reflection or refraction Jacobian.
 *
 * Frames: reflection is two-sided: the frame is flipped to the side of wo as
 * the geometric normal ng sees it. Reflection needs wo, wi on the same side of
 * ng, transmission on opposite sides (no light leaks through shading
 * normals). Glass's outside (ior on the far side) is the side ng points to.
 *
 * Shading normals that face away: where the shading normal n (interpolated
 * or normal-mapped) differs from ng, a direction above ng can lie below n,
 * or mirror about n to below ng; a BSDF that is 0 there paints black rims.
 * As Cycles (ensure_valid_specular_reflection) the normal of the glossy
 * lobes (metal, coat, glass and their multiple scattering) is then turned
 * toward ng, along the arc from n to ng, just far enough that the
 * direction's mirror image lies above ng (by min(0.9 cos, 0.01)):
 * bsdf_bend_t. The diffuse base keeps n, as Cycles' diffuse closure keeps
 * its N: it is there wherever the light side lies above n (and on the
 * camera side's side of ng), whatever the camera side, so it paints no
 * rims; its density is cosine sampling about n. The glossy BSDF of a
 * vertex is the one in the normal its camera-side direction needs: wo's in
 * radiance mode, wi's in importance mode, so f_radiance(wo, wi) =
 * f_importance(wi, wo) holds and a vertex has the same BSDF whichever
 * subpath made it. Sampling from wo uses wo's normal; pdf_w is that density
 * and pdf_rev_w the one from wi in wi's normal. Camera walks therefore
 * sample exactly the support of what they evaluate (unbiased alone, and
 * glossy lobes sample their peak); a light walk may not reach every
 * direction its f covers, and MIS gives those paths to the other
 * strategies (their pdf for it is 0). Integrators weigh by |wi . n| (and,
 * on light subpaths, Veach's correction with n, vertex.h); f is returned
 * multiplied by |wl . m| / |wl . n|, wl the direction toward the light (wi
 * in radiance mode, wo in importance mode), so their products are those of
 * the bent normal m (the diffuse base's f is not scaled: its normal is n).
 * Where n equals ng (flat shading) none of this runs.
 * Delta lobes reflect about wo's normal in both modes.
 *
 * E1, Es (and Et) and G come from bsdf_tables.h (src/tools/bsdf_tables.c integrates
 * them from microfacet.h at build time), bilinear in sqrt(alpha) and
 * sqrt(mu) (glass: trilinear, with (ior - 1) / (ior + 1));
 * the averages are those of the interpolated tables, so the compensation
 * is exact for the tables as read.
 *
 * Lobe selection for sampling is proportional to weight x albedo estimate at
 * the outgoing direction (the cosine-shaped lobes, diffuse base and the
 * metal's, coat's and glass's multiple-scattering reflection, are sampled
 * alike, the metal's and coat's as one lobe;
 * the glass's multiple-scattering refraction by a cosine on the far side);
 * pdf_w is the mixture over all non-delta lobes, so sampling and bsdf_eval
 * agree, and integrates to 1 - P(delta lobes). */
#ifndef AJAR_BSDF_H
#define AJAR_BSDF_H
#include "base/types.h"
#include "material/microfacet.h"
#include "material/bsdf_tables.h"

#define BSDF_RADIANCE 0   /* wo points toward the camera (eye paths) */
#define BSDF_IMPORTANCE 1 /* wo points toward the light (light paths); no eta^2 scaling on refraction */

#define BSDF_NULL 2 /* BsdfSample.delta of smooth thin glass's pass-through (wi = -wo) */

#define BSDF_DELTA_ALPHA 1e-3f /* metal and glass below this GGX alpha are delta */
#define BSDF_MIN_ALPHA 1e-3f   /* the plastic coat's alpha floor */
#define BSDF_MIN_IOR 1.01f     /* eta = 1 makes the refraction half vector vanish */
#define BSDF_MAX_IOR 4.0f
#define BSDF_TILTED (1 << 30)  /* in Bsdf.flags: n differs from ng, normals may bend (the top) */
#define BSDF_LAMBERT (1 << 29) /* in Bsdf.flags: only the diffuse lobe (bsdf_lambert) */
#define BSDF_TILT_COS 0.99999f /* n . ng below this counts as tilted */
/* Whether bs's normal may bend. A scene whose shading normals are all
 * within BSDF_TILT_COS of ng (src/prepare/prepare.c, tri_may_tilt) is built with
 * AJAR_NO_BENT_NORMALS: then never, and the bent code is left out. */
#ifdef AJAR_NO_BENT_NORMALS
#define BSDF_IS_TILTED(bs) 0
#else
#define BSDF_IS_TILTED(bs) ((bs)->flags & BSDF_TILTED)
#endif

typedef struct {
	V3 t, b, n;      /* shading frame, n on the side of ng */
	V3 ng;           /* geometric normal, unflipped: glass's outside */
	V3 base_color;   /* linear, in [0, 1] */
	float metallic, alpha, transmission, ior, specular;
	int flags;       /* the Material's MATERIAL_* flags */
	/* Energy compensation, set by bsdf_setup: the coat's single-scattering
	 * albedo is Es = coat_s1 E1 + coat_sw Ew, its multiple scattering's
	 * coat_fms (1 - E1) (E1 at the coat's alpha, mean coat_e1avg), the
	 * mean of both coat_eavg (Etavg); metal_eavg is E1avg at alpha and
	 * metal_fms the multiple-scattering colour Fms. */
	float coat_s1, coat_sw, coat_eavg, coat_fms, coat_e1avg, metal_eavg;
	V3 metal_fms;
	/* Rough glass: where (ior, alpha) falls in the glass tables, the share
	 * of the lost energy that multiple scattering transmits from outside
	 * (glass_x) and from inside (glass_y), and the lobes' constants c_oo,
	 * c_ii, c_oi, c_io (bsdf_glass_ms). Thin-walled rough glass keeps its
	 * Fresnel mean Favg in glass_x and E1avg in glass_y. */
	int glass_k, glass_i;
	float glass_wk, glass_wr, glass_x, glass_y;
	float glass_c[4];
} Bsdf;

typedef struct {
	V3 wi;
	V3 f;            /* without the cosine */
	float pdf_w;     /* density of wi given wo (lobe probability for delta) */
	float pdf_rev_w; /* density of wo given wi (lobe probability for delta) */
	int delta;
} BsdfSample;

/* Selection probabilities of the seven sampled lobes for one outgoing
 * direction (ms: the metal's and the coat's multiple scattering, both
 * cosine-shaped in the glossy normal; glass_r, glass_t: the glass's), and
 * the albedos at it that bsdf_eval_local reuses. */
typedef struct {
	float metal, coat, diffuse, glass, ms, glass_r, glass_t;
	float e_metal, e_coat, e_coat1, e_glass; /* E1 at alpha, Es, E1 at the coat's alpha, Go or Gi */
} BsdfLobes;

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

/* The BSDF of material m with metallic, roughness and transmission given
 * (textured, surface.h). */
INLINE void bsdf_setup_mr(Bsdf *bs, GLOBAL const Material *m, V3 base_color, float metallic, float roughness,
			  float transmission, V3 ns, V3 ng)
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
	bs->specular = bsdf_clamp01(m->specular);
	int lambert = bs->metallic == 0.0f && bs->transmission == 0.0f && bs->specular == 0.0f &&
		      v3_maxc(bs->base_color) > 0.0f;
	bs->flags = (m->flags & ~(BSDF_TILTED | BSDF_LAMBERT)) | (lambert ? BSDF_LAMBERT : 0);
#ifndef AJAR_NO_BENT_NORMALS
	bs->flags |= fabs(cn) < BSDF_TILT_COS ? BSDF_TILTED : 0;
#endif
	bs->coat_s1 = bs->coat_sw = bs->coat_eavg = bs->coat_fms = bs->coat_e1avg = bs->metal_eavg = 0.0f;
	bs->metal_fms = v3(0.0f, 0.0f, 0.0f);
	if (bsdf_w_plastic(bs) > 0.0f && bs->specular > 0.0f) {
		float q = (bs->ior - 1.0f) / (bs->ior + 1.0f);
		BsdfTabAt a = bsdf_tab_at(bsdf_coat_alpha(bs), 1.0f);
		bs->coat_s1 = bs->specular * q * q;
		bs->coat_sw = bs->specular - bs->coat_s1;
		float e1 = bsdf_tab1(bsdf_tab_e1avg, a);
		float fa = bs->coat_s1 + bs->coat_sw * (1.0f / 21.0f); /* specular (F0 + (1 - F0) / 21) */
		bs->coat_e1avg = e1;
		bs->coat_fms = fa * fa * e1 / (1.0f - fa * (1.0f - e1));
		bs->coat_eavg = bs->coat_s1 * e1 + bs->coat_sw * bsdf_tab1(bsdf_tab_ewavg, a) + bs->coat_fms * (1.0f - e1);
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
		V3 fa = v3_add(v3_scale(bs->base_color, 20.0f / 21.0f), v3(1.0f / 21.0f, 1.0f / 21.0f, 1.0f / 21.0f));
		bs->metal_eavg = e;
		bs->metal_fms = v3(fa.x * fa.x * e / (1.0f - fa.x * (1.0f - e)), fa.y * fa.y * e / (1.0f - fa.y * (1.0f - e)),
				   fa.z * fa.z * e / (1.0f - fa.z * (1.0f - e)));
	}
}

/* The BSDF of material m, its metallic, roughness and transmission untextured. */
INLINE void bsdf_setup(Bsdf *bs, GLOBAL const Material *m, V3 base_color, V3 ns, V3 ng)
{
	bsdf_setup_mr(bs, m, base_color, m->metallic, m->roughness, m->transmission, ns, ng);
}

/* Contains some delta lobe (smooth metal or glass with a non-zero weight). */
INLINE int bsdf_has_delta(const Bsdf *bs)
{
	return bsdf_smooth(bs) && (bsdf_w_metal(bs) > 0.0f || bsdf_w_glass(bs) > 0.0f);
}

/* No non-delta lobe at all: skip light sampling and connections. */
INLINE int bsdf_is_delta(const Bsdf *bs) { return bsdf_smooth(bs) && !(bsdf_w_plastic(bs) > 0.0f); }

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

/* The metal's single-scattering albedo with Fresnel 1, E1(mu). */
INLINE float bsdf_metal_albedo(const Bsdf *bs, float mu) { return bsdf_tab2(bsdf_tab_e1, bsdf_tab_at(bs->alpha, mu)); }

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

/* Multiple scattering of the metal without its colour Fms. */
INLINE float bsdf_ms_factor(const Bsdf *bs, float e_o, float mu_i)
{
	return bsdf_kc_factor(e_o, bsdf_metal_albedo(bs, mu_i), bs->metal_eavg);
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

/* Lobe selection for outgoing cos_o > 0 on the side of relative ior eta:
 * weight x albedo estimate. */
INLINE BsdfLobes bsdf_lobes(const Bsdf *bs, float cos_o, float eta)
{
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
	p.e_metal = wm > 0.0f && !bsdf_smooth(bs) ? bsdf_metal_albedo(bs, cos_o) : 1.0f;
	p.e_coat1 = 1.0f;
	p.e_coat = wp > 0.0f && bs->specular > 0.0f ? bsdf_coat_albedo(bs, cos_o, &p.e_coat1) : 0.0f; /* 0 without a coat */
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

/* A shading frame: the Bsdf's own, or a bent one (bsdf_bend_t). */
typedef struct {
	V3 t, b, n;
} BsdfFrame;

INLINE BsdfFrame bsdf_frame_own(const Bsdf *bs)
{
	BsdfFrame f;
	f.t = bs->t;
	f.b = bs->b;
	f.n = bs->n;
	return f;
}

/* The tilt of n from ng: *x the unit direction of n's component along the
 * surface; returns the angle tn between n and ng, n = sin tn x + cos tn ng.
 * Bent normals are kept as their angle from ng: a cosine rounds small
 * angles (1e-4) to 0. */
INLINE float bsdf_tilt(const Bsdf *bs, V3 *x)
{
	float nz = v3_dot(bs->n, bs->ng);
	V3 d = v3_madd(bs->n, bs->ng, -nz);
	float l = v3_len(d);
	*x = l > 0.0f ? v3_scale(d, 1.0f / l) : bs->t;
	return fast_atan2(l, fmax(nz, 0.0f));
}

/* Whether direction w keeps the own normal n: its mirror image about n lies
 * at least thr = min(0.9 |w . ng|, 0.01) above the surface on w's side,
 * 2 (w . n)(n . ng) - w . ng in w's side's sign (Cycles'
 * ensure_valid_specular_reflection test). By dot products alone: surfaces
 * with smooth normals ask it of every direction, and mostly keep n. */
INLINE int bsdf_keeps_n(const Bsdf *bs, V3 w)
{
	float iz = v3_dot(w, bs->ng);
	float sgn = iz < 0.0f ? -1.0f : 1.0f;
	iz *= sgn;
	float h = sgn * (2.0f * v3_dot(w, bs->n) * v3_dot(bs->n, bs->ng)) - iz;
	return h >= fmin(0.9f * iz, 0.01f);
}

/* The angle from ng of the normal that direction w needs, on the arc from
 * n (angle tn, tilt direction x) to ng: tn where w's mirror image about n
 * lies at least thr = min(0.9 |w . ng|, 0.01) above the surface (w's own
 * side), else the normal whose mirror image lies at exactly thr. With w =
 * (ix, iz) in (x, ng) (w's y does not enter) and the normal at angle t, the
 * mirror's height is 2 (w . N) cos t - iz = ix sin 2t + iz cos 2t
 * = A cos(2t - phi), A = |(ix, iz)|, phi = atan2(ix, iz): >= thr for t in
 * [0, (phi + acos(thr / A)) / 2], so every normal from there to ng keeps w
 * (and its mirror image) above it. */
INLINE float bsdf_bend_t(const Bsdf *bs, V3 x, float tn, V3 w)
{
	float iz = v3_dot(w, bs->ng);
	float sgn = iz < 0.0f ? -1.0f : 1.0f;
	iz *= sgn;
	float ix = sgn * v3_dot(w, x);
	float thr = fmin(0.9f * iz, 0.01f);
	if (bsdf_keeps_n(bs, w)) /* the height ix sin 2tn + iz cos 2tn >= thr */
		return tn;
	float a = sqrt(ix * ix + iz * iz);
	if (!(a > 0.0f))
		return 0.0f;
	/* acos c = atan2(sqrt((1 - c)(1 + c)), c), exact near c = 1 too. */
	float c = fmin(thr / a, 1.0f);
	float t = 0.5f * (fast_atan2(ix, iz) + fast_atan2(sqrt((1.0f - c) * (1.0f + c)), c));
	return fmin(fmax(t, 0.0f), tn);
}

/* The frame of the normal at angle t on the arc (the own frame at tn). */
INLINE BsdfFrame bsdf_frame_t(const Bsdf *bs, V3 x, float tn, float t)
{
	if (t == tn)
		return bsdf_frame_own(bs);
	BsdfFrame f;
	float st, ct;
	fast_sincos(t, &st, &ct); /* t in [0, pi / 2] */
	f.n = v3_norm(v3_add(v3_scale(x, st), v3_scale(bs->ng, ct)));
	v3_basis(f.n, &f.t, &f.b);
	return f;
}

/* Local coordinates of w in frame fr flipped by `side` (+-1). */
INLINE V3 bsdf_local(const BsdfFrame *fr, V3 w, float side)
{
	return v3(v3_dot(w, fr->t), v3_dot(w, fr->b), side * v3_dot(w, fr->n));
}

INLINE V3 bsdf_world(const BsdfFrame *fr, V3 w, float side)
{
	return v3_from_local(v3(w.x, w.y, side * w.z), fr->t, fr->b, fr->n);
}

/* |wl . m| / |wl . n| for the light-side direction wl (see the top): what
 * f is multiplied by where the normal m is bent; 0 where wl lies in n's
 * plane (the integrators' cosine is 0 there). */
INLINE float bsdf_bend_ratio(const Bsdf *bs, V3 m, V3 wl)
{
	float d = fabs(v3_dot(wl, bs->n));
	return d > 1e-7f ? fabs(v3_dot(wl, m)) / d : 0.0f;
}

/* Relative ior eta_t / eta_i for light leaving toward the side `side` of ng. */
INLINE float bsdf_eta(const Bsdf *bs, float side) { return side > 0.0f ? bs->ior : 1.0f / bs->ior; }

/* Non-delta f and pdf in the frame flipped to wo (wo.z > 0). wi.z > 0 is
 * reflection, wi.z < 0 transmission; the caller has checked the sides.
 * Where the frame is a bent one (the top), the glossy lobes' f is scaled
 * by gr (the light side's cosine ratio) and the diffuse base keeps the
 * own normal n: its f is there where fz, the light side's cosine with n,
 * is positive, and its density is that of cosine sampling about n at
 * pz, wi's cosine with n. In the own frame gr = 1 and fz = pz = wi.z. */
INLINE V3 bsdf_eval_lobes(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w, float gr, float fz,
			  float pz)
{
	V3 f = v3(0.0f, 0.0f, 0.0f);
	float pdf = 0.0f;
	if (bsdf_lambert(bs)) { /* the common case, exactly what the lobes below give */
		*pdf_w = pdf_cosine_hemisphere_w(pz);
		return wi.z > 0.0f && fz > 0.0f ? v3_scale(bs->base_color, AJAR_INV_PI) : f;
	}
	BsdfLobes p = bsdf_lobes(bs, wo.z, eta);
	int smooth = bsdf_smooth(bs);
	if (wi.z > 0.0f) {
		V3 h = v3_norm(v3_add(wo, wi));
		float cos_oh = v3_dot(wo, h);
		float jac = 1.0f / (4.0f * cos_oh); /* dh / dwi for reflection */
		float inv4 = 1.0f / (4.0f * wo.z * wi.z);
		if (!smooth && bsdf_w_metal(bs) > 0.0f) {
			float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4;
			f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec * gr);
			f = v3_madd(f, bs->metal_fms, bsdf_w_metal(bs) * bsdf_ms_factor(bs, p.e_metal, wi.z) * gr);
			pdf += p.metal * ggx_pdf_visible(wo, h, bs->alpha) * jac;
		}
		pdf += p.ms * pdf_cosine_hemisphere_w(wi.z); /* metal and coat multiple scattering */
		float wp = bsdf_w_plastic(bs);
		if (wp > 0.0f) {
			float a = bsdf_coat_alpha(bs);
			float spec = ggx_d(h, a) * ggx_g2(wo, wi, a) * inv4 * bsdf_fresnel_coat(bs, cos_oh);
			float kd = AJAR_INV_PI;
			if (bs->specular > 0.0f) {
				float e1_i, es_i = bsdf_coat_albedo(bs, wi.z, &e1_i);
				spec += bs->coat_fms * bsdf_kc_factor(p.e_coat1, e1_i, bs->coat_e1avg);
				kd = bsdf_base_factor(bs, bsdf_coat_total(bs, p.e_coat, p.e_coat1), bsdf_coat_total(bs, es_i, e1_i));
			}
			kd = fz > 0.0f ? kd : 0.0f;
			float ws = wp * spec * gr;
			f = v3_add(f, v3_madd(v3(ws, ws, ws), bs->base_color, wp * kd));
			pdf += p.coat * ggx_pdf_visible(wo, h, a) * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
		}
		if (!smooth && bsdf_w_glass(bs) > 0.0f) {
			int thin = bsdf_thin(bs);
			float fr = bsdf_fresnel_dielectric(cos_oh, thin ? bs->ior : eta);
			float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4 * fr;
			float ms = thin ? bs->glass_x * bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wi.z), bs->glass_y)
					: bsdf_glass_ms(bs, eta > 1.0f, 1, p.e_glass, wi.z);
			float wg = bsdf_w_glass(bs) * (spec + ms) * gr;
			f = v3_add(f, v3(wg, wg, wg));
			pdf += p.glass * fr * ggx_pdf_visible(wo, h, bs->alpha) * jac + p.glass_r * pdf_cosine_hemisphere_w(wi.z);
		}
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f && bsdf_thin(bs)) {
		/* Thin: the reflection lobe at wi mirrored to wo's side, (1 - F). */
		V3 wm = v3(wi.x, wi.y, -wi.z);
		V3 h = v3_norm(v3_add(wo, wm));
		float cos_oh = v3_dot(wo, h);
		float fr = bsdf_fresnel_dielectric(cos_oh, bs->ior);
		float t = ggx_d(h, bs->alpha) * ggx_g2(wo, wm, bs->alpha) * (1.0f - fr) / (4.0f * wo.z * wm.z);
		t += (1.0f - bs->glass_x) * bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wm.z), bs->glass_y);
		f = v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr);
		pdf = p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) / (4.0f * cos_oh) +
		      p.glass_t * pdf_cosine_hemisphere_w(wm.z);
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f) {
		V3 h;
		float t = bsdf_glass_ms(bs, eta > 1.0f, 0, p.e_glass, -wi.z);
		pdf = p.glass_t * pdf_cosine_hemisphere_w(-wi.z);
		if (bsdf_half_refract(wo, wi, eta, &h)) {
			float cos_oh = v3_dot(wo, h), cos_ih = v3_dot(wi, h);
			/* Fresnel from the rarer medium's side (F(theta_i, eta) =
			 * F(theta_t, 1 / eta)): the same value whichever way the
			 * pair is evaluated, and accurate near the critical angle,
			 * where the denser side's cos_t is a steep square root. */
			float fr = eta >= 1.0f ? bsdf_fresnel_dielectric(cos_oh, eta)
					       : bsdf_fresnel_dielectric(-cos_ih, 1.0f / eta);
			float denom = cos_ih + cos_oh / eta;
			denom *= denom;
			t += ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * (1.0f - fr) *
			     fabs(cos_ih * cos_oh / (wo.z * wi.z * denom));
			pdf += p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) * fabs(cos_ih) / denom;
		}
		if (mode == BSDF_RADIANCE)
			t /= eta * eta;
		f = v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr);
	}
	*pdf_w = pdf;
	return f;
}

/* bsdf_eval_lobes in the own frame. */
INLINE V3 bsdf_eval_local(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w)
{
	return bsdf_eval_lobes(bs, wo, wi, eta, mode, pdf_w, 1.0f, wi.z, wi.z);
}

/* Side of w as ng sees it: +1, -1, or 0 when w lies in the surface. */
INLINE float bsdf_side(const Bsdf *bs, V3 w)
{
	float c = v3_dot(w, bs->ng);
	return c > 0.0f ? 1.0f : (c < 0.0f ? -1.0f : 0.0f);
}

/* The flipped local pair for world wo, wi in frame fr, or 0 if the pair is
 * on inconsistent sides of ng and fr's normal. */
INLINE int bsdf_pair(const Bsdf *bs, const BsdfFrame *fr, V3 wo, V3 wi, V3 *lo, V3 *li, float *eta)
{
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return 0;
	*lo = bsdf_local(fr, wo, so);
	*li = bsdf_local(fr, wi, so);
	*eta = bsdf_eta(bs, so);
	if (!(lo->z > 0.0f))
		return 0;
	return so == si ? li->z > 0.0f : li->z < 0.0f;
}

/* bsdf_eval where n differs from ng (the top): the glossy lobes' f in the
 * camera side's normal (wo's in radiance mode, wi's in importance mode)
 * times the light side's cosine ratio, the diffuse base's in n; pdf_w
 * from wo (its normal) and, if `rev`, pdf_rev_w from wi (its normal). */
INLINE V3 bsdf_eval_bent(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w, int rev)
{
	V3 lo, li, x, f = v3(0.0f, 0.0f, 0.0f);
	float eta, unused;
	*pdf_w = *pdf_rev_w = 0.0f;
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return f;
	if (bsdf_keeps_n(bs, wo) && bsdf_keeps_n(bs, wi)) { /* no bend: the own frame, what the rest gives then */
		BsdfFrame fr = bsdf_frame_own(bs);
		if (bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta))
			f = bsdf_eval_local(bs, lo, li, eta, mode, pdf_w);
		if (rev && bsdf_pair(bs, &fr, wi, wo, &lo, &li, &eta))
			bsdf_eval_local(bs, lo, li, eta, mode, pdf_rev_w);
		return f;
	}
	float tn = bsdf_tilt(bs, &x);
	float to = bsdf_bend_t(bs, x, tn, wo), ti = bsdf_bend_t(bs, x, tn, wi);
	BsdfFrame fo = bsdf_frame_t(bs, x, tn, to), fi = ti == to ? fo : bsdf_frame_t(bs, x, tn, ti);
	int radiance = mode == BSDF_RADIANCE;
	float tf = radiance ? to : ti;
	V3 wl = radiance ? wi : wo;
	float gr = tf != tn ? bsdf_bend_ratio(bs, radiance ? fo.n : fi.n, wl) : 1.0f;
	float fz = so * v3_dot(wl, bs->n), pzo = so * v3_dot(wi, bs->n), pzi = si * v3_dot(wo, bs->n);
	if (bsdf_pair(bs, &fo, wo, wi, &lo, &li, &eta))
		f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, gr, fz, pzo);
	if (rev && bsdf_pair(bs, &fi, wi, wo, &lo, &li, &eta))
		bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_rev_w, 1.0f, pzi, pzi);
	if (!radiance && ti != to) { /* the camera side is wi: f in wi's normal */
		f = v3(0.0f, 0.0f, 0.0f);
		if (bsdf_pair(bs, &fi, wo, wi, &lo, &li, &eta))
			f = bsdf_eval_lobes(bs, lo, li, eta, mode, &unused, gr, fz, pzo);
	}
	return f;
}

/* f without the cosine, of the non-delta lobes only, and pdf_w of
 * sampling wi given wo: what connections and next-event estimation need. */
INLINE V3 bsdf_eval_fwd(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w)
{
	V3 lo, li;
	float eta, unused;
	*pdf_w = 0.0f;
	if (BSDF_IS_TILTED(bs))
		return bsdf_eval_bent(bs, wo, wi, mode, pdf_w, &unused, 0);
	BsdfFrame fr = bsdf_frame_own(bs);
	if (!bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta))
		return v3(0.0f, 0.0f, 0.0f);
	return bsdf_eval_local(bs, lo, li, eta, mode, pdf_w);
}

/* bsdf_eval_fwd and pdf_rev_w of sampling wo given wi (for BDPT). */
CALLED V3 bsdf_eval(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w)
{
	V3 lo, li;
	float eta;
	*pdf_w = 0.0f;
	*pdf_rev_w = 0.0f;
	if (BSDF_IS_TILTED(bs))
		return bsdf_eval_bent(bs, wo, wi, mode, pdf_w, pdf_rev_w, 1);
	BsdfFrame fr = bsdf_frame_own(bs);
	if (!bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta))
		return v3(0.0f, 0.0f, 0.0f);
	V3 f = bsdf_eval_local(bs, lo, li, eta, mode, pdf_w);
	if (bsdf_pair(bs, &fr, wi, wo, &lo, &li, &eta))
		bsdf_eval_local(bs, lo, li, eta, mode, pdf_rev_w);
	return f;
}

/* The frame that sampling from wo uses: the own one, or wo's bent normal. */
INLINE BsdfFrame bsdf_frame_for(const Bsdf *bs, V3 wo, int *bent)
{
	*bent = 0;
	if (!BSDF_IS_TILTED(bs) || bsdf_keeps_n(bs, wo))
		return bsdf_frame_own(bs);
	V3 x;
	float tn = bsdf_tilt(bs, &x), t = bsdf_bend_t(bs, x, tn, wo);
	*bent = t != tn;
	return bsdf_frame_t(bs, x, tn, t);
}

/* Only the solid-angle density of sampling wi given wo (non-delta lobes):
 * what MIS needs when it recomputes a vertex's density. */
INLINE float bsdf_pdf_w(const Bsdf *bs, V3 wo, V3 wi)
{
	V3 lo, li;
	float eta, pdf = 0.0f;
	int bent;
	BsdfFrame fr = bsdf_frame_for(bs, wo, &bent);
	if (bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta)) {
		float pz = bent ? bsdf_side(bs, wo) * v3_dot(wi, bs->n) : li.z; /* the diffuse base's, in n */
		bsdf_eval_lobes(bs, lo, li, eta, BSDF_RADIANCE, &pdf, 1.0f, pz, pz);
	}
	return pdf;
}

/* Probability of picking smooth glass's reflection (reflect = 1) or
 * refraction for wo (flipped-local, eta of its side): for pdf_rev_w. */
INLINE float bsdf_glass_delta_prob(const Bsdf *bs, V3 wo, float eta, int reflect)
{
	float fr = bsdf_fresnel_dielectric(wo.z, eta);
	return bsdf_lobes(bs, wo.z, eta).glass * (reflect ? fr : 1.0f - fr);
}

/* Smooth thin glass with a weight: its transmission is a null event. */
INLINE int bsdf_has_null(const Bsdf *bs)
{
	return bsdf_thin(bs) && bsdf_smooth(bs) && bsdf_w_glass(bs) > 0.0f;
}

/* Smooth thin glass's Fresnel for direction w (either way along it): in the
 * own shading normal, so that a crossing has one transmittance. */
INLINE float bsdf_thin_fresnel(const Bsdf *bs, V3 w) { return bsdf_fresnel_dielectric(fabs(v3_dot(w, bs->n)), bs->ior); }

/* The probability that bsdf_sample from wo picks the null event (the
 * glass lobe's share times 1 - F): walks decide it where they hit the
 * surface, and sample the rest with u0 scaled to [0, 1 - it). */
INLINE float bsdf_null_prob(const Bsdf *bs, V3 wo)
{
	float so = bsdf_side(bs, wo);
	if (!bsdf_has_null(bs) || so == 0.0f)
		return 0.0f;
	int bent;
	BsdfFrame frame = bsdf_frame_for(bs, wo, &bent);
	V3 lo = bsdf_local(&frame, wo, so);
	if (!(lo.z > 0.0f))
		return 0.0f;
	return bsdf_lobes(bs, lo.z, bsdf_eta(bs, so)).glass * (1.0f - bsdf_thin_fresnel(bs, wo));
}

/* The transmittance of smooth thin glass crossed along w: wg (1 - F)
 * base_color, what a shadow ray or connection through it carries, and
 * what a walk's null event carries divided by bsdf_null_prob. */
INLINE V3 bsdf_null_weight(const Bsdf *bs, V3 w)
{
	if (!bsdf_has_null(bs))
		return v3(0.0f, 0.0f, 0.0f);
	return v3_scale(bs->base_color, bsdf_w_glass(bs) * (1.0f - bsdf_thin_fresnel(bs, w)));
}

/* Returns 0 if no sample. For delta samples f is the lobe's weight (Fresnel
 * included) divided by |wi.n| (shading normal), so f |wi.n| / pdf_w is the
 * throughput (in a bent normal m, times |wl . m| / |wl . n| as every f, the
 * top); pdf_w and pdf_rev_w are then the probabilities of picking that delta
 * event from wo and from wi. */
INLINE int bsdf_sample_in(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s, int rev)
{
	float so = bsdf_side(bs, wo);
	if (so == 0.0f)
		return 0;
	int bent;
	BsdfFrame frame = bsdf_frame_for(bs, wo, &bent);
	V3 lo = bsdf_local(&frame, wo, so);
	if (!(lo.z > 0.0f))
		return 0;
	float eta = bsdf_eta(bs, so);
	BsdfLobes p = bsdf_lobes(bs, lo.z, eta);
	int smooth = bsdf_smooth(bs), reflect = 1;
	V3 li;
	BsdfFrame own;
	const BsdfFrame *fl = &frame; /* the frame li is in */
	/* Lobe by u0; u0 is then rescaled within the lobe and reused for the
	 * glass reflect/refract choice. */
	if (u0 < p.metal) {
		if (smooth) {
			if (!(lo.z > 1e-7f)) /* f = F / cos would overflow */
				return 0;
			li = v3(-lo.x, -lo.y, lo.z);
			V3 fm = bsdf_fresnel_metal(bs, lo.z);
			s->f = v3_scale(fm, bsdf_w_metal(bs) / lo.z);
			s->pdf_w = p.metal;
			s->pdf_rev_w = p.metal; /* the mirror pair has the same cosine */
			s->delta = 1;
			s->wi = bsdf_world(&frame, li, so);
			if (bent)
				s->f = v3_scale(s->f, bsdf_bend_ratio(bs, frame.n, mode == BSDF_RADIANCE ? s->wi : wo));
			return bsdf_side(bs, s->wi) == so;
		}
		li = bsdf_reflect(lo, ggx_sample_visible(lo, bs->alpha, u1, u2));
	} else if (u0 < p.metal + p.coat) {
		li = bsdf_reflect(lo, ggx_sample_visible(lo, bsdf_coat_alpha(bs), u1, u2));
	} else if (u0 < p.metal + p.coat + p.diffuse) {
		li = sample_cosine_hemisphere(u1, u2); /* the diffuse base, about n (bsdf_eval_lobes) */
		if (bent) {
			own = bsdf_frame_own(bs);
			fl = &own;
		}
	} else if (u0 < p.metal + p.coat + p.diffuse + p.ms + p.glass_r) {
		/* metal or glass multiple scattering (reflection) */
		li = sample_cosine_hemisphere(u1, u2);
	} else if (u0 < p.metal + p.coat + p.diffuse + p.ms + p.glass_r + p.glass_t) {
		li = sample_cosine_hemisphere(u1, u2); /* glass multiple scattering, refraction */
		li.z = -li.z;
		reflect = 0;
	} else if (p.glass > 0.0f && bsdf_thin(bs)) {
		float ug = fmin((u0 - (p.metal + p.coat + p.diffuse + p.ms + p.glass_r + p.glass_t)) / p.glass, 0.99999994f);
		if (smooth) {
			float fr = bsdf_thin_fresnel(bs, wo), c = fabs(v3_dot(wo, bs->n));
			if (!(lo.z > 1e-7f) || !(c > 1e-7f))
				return 0;
			if (ug >= fr) { /* the null event: straight through */
				s->wi = v3_neg(wo);
				s->f = v3_scale(bsdf_null_weight(bs, wo), 1.0f / c);
				s->pdf_w = p.glass * (1.0f - fr);
				s->pdf_rev_w = bsdf_null_prob(bs, s->wi);
				s->delta = BSDF_NULL;
				return s->pdf_w > 0.0f;
			}
			li = v3(-lo.x, -lo.y, lo.z);
			s->f = v3_scale(v3(1.0f, 1.0f, 1.0f), bsdf_w_glass(bs) * fr / lo.z);
			s->pdf_w = p.glass * fr;
			s->wi = bsdf_world(&frame, li, so);
			if (bent)
				s->f = v3_scale(s->f, bsdf_bend_ratio(bs, frame.n, mode == BSDF_RADIANCE ? s->wi : wo));
			if (bsdf_side(bs, s->wi) != so)
				return 0;
			V3 ri = bsdf_local(&frame, s->wi, so);
			s->pdf_rev_w = bsdf_lobes(bs, ri.z, bsdf_eta(bs, so)).glass * bsdf_thin_fresnel(bs, s->wi);
			s->delta = 1;
			return s->pdf_w > 0.0f;
		}
		V3 h = ggx_sample_visible(lo, bs->alpha, u1, u2);
		reflect = ug < bsdf_fresnel_dielectric(v3_dot(lo, h), bs->ior);
		li = bsdf_reflect(lo, h);
		if (!reflect)
			li.z = -li.z; /* mirrored through the surface */
	} else if (p.glass > 0.0f) {
		float ug = fmin((u0 - (p.metal + p.coat + p.diffuse + p.ms + p.glass_r + p.glass_t)) / p.glass, 0.99999994f);
		V3 h = smooth ? v3(0.0f, 0.0f, 1.0f) : ggx_sample_visible(lo, bs->alpha, u1, u2);
		float cos_oh = v3_dot(lo, h);
		float fr = bsdf_fresnel_dielectric(cos_oh, eta);
		reflect = ug < fr;
		if (reflect)
			li = bsdf_reflect(lo, h);
		else if (!bsdf_refract(lo, h, eta, &li))
			return 0;
		if (smooth) {
			float c = fabs(li.z);
			if (!(c > 1e-7f))
				return 0;
			float w = bsdf_w_glass(bs) * (reflect ? fr : 1.0f - fr) / c;
			s->f = reflect ? v3(w, w, w) : v3_scale(bs->base_color, w);
			if (!reflect && mode == BSDF_RADIANCE)
				s->f = v3_scale(s->f, 1.0f / (eta * eta));
			s->pdf_w = p.glass * (reflect ? fr : 1.0f - fr);
			s->wi = bsdf_world(&frame, li, so);
			if (bent)
				s->f = v3_scale(s->f, bsdf_bend_ratio(bs, frame.n, mode == BSDF_RADIANCE ? s->wi : wo));
			float si = bsdf_side(bs, s->wi);
			if (si != (reflect ? so : -so))
				return 0;
			V3 ri = bsdf_local(&frame, s->wi, si);
			s->pdf_rev_w = bsdf_glass_delta_prob(bs, ri, bsdf_eta(bs, si), reflect);
			s->delta = 1;
			return s->pdf_w > 0.0f;
		}
	} else {
		return 0;
	}
	/* A microfacet reflection that ends below the surface (or a refraction
	 * above it) is lost, not reinterpreted as the other event: eval's pdf
	 * of that direction belongs to the other event. */
	if (reflect ? !(li.z > 0.0f) : !(li.z < 0.0f))
		return 0;
	s->wi = bsdf_world(fl, li, so);
	if (fl != &frame && bsdf_side(bs, s->wi) != so) /* about n, below the surface: lost too */
		return 0;
	s->delta = 0;
	s->pdf_rev_w = 0.0f;
	s->f = rev ? bsdf_eval(bs, wo, s->wi, mode, &s->pdf_w, &s->pdf_rev_w) : bsdf_eval_fwd(bs, wo, s->wi, mode, &s->pdf_w);
	return s->pdf_w > 0.0f;
}

CALLED int bsdf_sample(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s)
{
	return bsdf_sample_in(bs, wo, u0, u1, u2, mode, s, 1);
}

/* bsdf_sample without pdf_rev_w of non-delta samples (left 0), which a
 * path tracer never reads: f and pdf_w are the same bits, one evaluation
 * of the lobes fewer. */
CALLED int bsdf_sample_fwd(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s)
{
	return bsdf_sample_in(bs, wo, u0, u1, u2, mode, s, 0);
}

#endif
