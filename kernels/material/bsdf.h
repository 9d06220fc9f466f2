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
 * agree, and integrates to 1 - P(delta lobes).
 *
 * Layers (BSDF_LAYERED; KHR_materials_sheen and _clearcoat, glTF's order:
 * the clear coat over the sheen over all of the above, "the core"):
 *   f = cc fc + Ld fsheen + Tg fg + Td fd,
 * fc the clear coat (a GGX dielectric at ior 1.5 with the exact Fresnel, as
 * Blender's coat: Schlick's is a fifth low at cos 0.55; in its own normal,
 * with its Kulla-Conty lobe as the plastic's coat),
 * fsheen the Charlie sheen times its colour, divided by N(mu_o) N(mu_i)
 * (N = max(1, its tabulated albedo): the fitted lobe reflects more than it
 * receives near grazing below sheen roughness 0.5), fg the core's
 * microfacet lobes, fd its diffuse base and multiple-scattering lobes. A
 * layer of albedo E over a base passes it (1 - E) each way; the base's
 * diffuse-like lobes take (1 - E(mu_o)) (1 - E(mu_i)) / (1 - Eavg), exact
 * for a Lambertian base as the plastic's base is, its microfacet lobes
 * sqrt((1 - E(mu_o)) (1 - E(mu_i))), exact for a mirror; both symmetric,
 * so the BSDF stays reciprocal. E is max(sheen colour) Es for the sheen
 * (the specification's albedo scaling), Et of the clear coat, which mixes
 * by its factor cc: Ld = 1 - cc + cc Sd. Layers are sampled first, by
 * weight x albedo at wo, then the core as above.
 * Anisotropy (BSDF_ANISO; KHR_materials_anisotropy): the metal's and the
 * coat's GGX take alpha_t = alpha_b + (1 - alpha_b) s^2 along the frame's t
 * (the anisotropy direction), alpha_b = roughness^2 along b, sampled by
 * their visible normals; E1 (and Ew, scaled from the isotropic table at
 * the same alpha_rms) depends on the azimuth too (bsdf_aniso_e1). Glass
 * stays isotropic. A specular colour (BSDF_TINT, KHR_materials_specular)
 * tints the coat's F0 per channel: its albedo, multiple scattering and
 * the base's share are then per channel (bsdf_tint_*). */
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
#define BSDF_LAYERED (1 << 28) /* in Bsdf.flags: a sheen or a clear coat over the core (the top) */
#define BSDF_ANISO (1 << 27)   /* in Bsdf.flags: anisotropic metal and coat */
#define BSDF_TINT (1 << 26)    /* in Bsdf.flags: the coat's F0 tinted per channel */
#define BSDF_TILT_COS 0.99999f /* n . ng below this counts as tilted */
#define BSDF_CC_IOR 1.5f       /* the clear coat's ior, as KHR_materials_clearcoat fixes it */
/* Scenes without sheen, clear coats or specular colours are built with
 * AJAR_NO_LAYERS, without anisotropy with AJAR_NO_ANISOTROPY
 * (src/prepare/prepare.c, kernel_omit): their code and Bsdf fields are
 * left out, and such scenes keep their programs and bits. */
#ifdef AJAR_NO_LAYERS
#define BSDF_IS_LAYERED(bs) 0
#define BSDF_IS_TINT(bs) 0
#else
#define BSDF_IS_LAYERED(bs) ((bs)->flags & BSDF_LAYERED)
#define BSDF_IS_TINT(bs) ((bs)->flags & BSDF_TINT)
#endif
#ifdef AJAR_NO_ANISOTROPY
#define BSDF_IS_ANISO(bs) 0
#else
#define BSDF_IS_ANISO(bs) ((bs)->flags & BSDF_ANISO)
#endif
/* Whether bs's normal may bend. A scene whose shading normals are all
 * within BSDF_TILT_COS of ng (src/prepare/prepare.c, tri_may_tilt) is built with
 * AJAR_NO_BENT_NORMALS: then never, and the bent code is left out. */
#ifdef AJAR_NO_BENT_NORMALS
#define BSDF_IS_TILTED(bs) 0
#else
#define BSDF_IS_TILTED(bs) ((bs)->flags & BSDF_TILTED)
#endif

/* Selection probabilities of the seven sampled lobes for one outgoing
 * direction (ms: the metal's and the coat's multiple scattering, both
 * cosine-shaped in the glossy normal; glass_r, glass_t: the glass's), and
 * the albedos at it that bsdf_eval_local reuses. */
typedef struct {
	float metal, coat, diffuse, glass, ms, glass_r, glass_t;
	float e_metal, e_coat, e_coat1, e_glass; /* E1 at alpha, Es, E1 at the coat's alpha, Go or Gi */
} BsdfLobes;

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
#ifndef AJAR_NO_LAYERS
	/* Layers (the top): sheen colour, roughness (perceptual), max(colour)
	 * and that times its albedo's mean; the clear coat's factor, alpha,
	 * Kulla-Conty colour, E1avg and whole albedo's mean Etavg, its normal
	 * (on ng's side). A tinted coat's per-channel s F0, Fms and Etavg. */
	V3 sheen;
	float sheen_r, sheen_c, sheen_eavg;
	float cc, cc_alpha, cc_fms, cc_e1avg, cc_eavg;
	V3 cc_n;
	V3 tint_s1, tint_fms, tint_eavg;
#endif
	/* The lobe probabilities for one outgoing direction, the vertex's own
	 * (bsdf_cache_wo): connections evaluate a vertex's BSDF many times from
	 * it (bsdf_lobes). Its local coordinates and eta are the key. */
	float lc_x, lc_y, lc_z, lc_eta;
	BsdfLobes lc;
#ifndef AJAR_NO_ANISOTROPY
	/* Anisotropic GGX: alpha along t and b, alpha_rms, the azimuth warp
	 * and where (r, s) falls in the anisotropic table (bsdf_aniso_e1). */
	float ax, ay, an_rms, an_k;
	int an_i, an_j;
	float an_wr, an_ws;
#endif
} Bsdf;

typedef struct {
	V3 wi;
	V3 f;            /* without the cosine */
	float pdf_w;     /* density of wi given wo (lobe probability for delta) */
	float pdf_rev_w; /* density of wo given wi (lobe probability for delta) */
	int delta;
} BsdfSample;

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

/* The energy compensation's constants for the lobes bs has (the top). */
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
 * min(F0 tint, 1), times the specular factor as before (the top). */
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
#ifndef AJAR_NO_ANISOTROPY
	if (BSDF_IS_ANISO(bs)) { /* the anisotropy direction, turned with the normal */
		V3 t = v3_madd(bs->t, f.n, -v3_dot(bs->t, f.n));
		float lt = v3_len2(t);
		if (lt > 1e-12f) {
			f.t = v3_scale(t, 1.0f / sqrt(lt));
			f.b = v3_cross(f.n, f.t);
		}
	}
#endif
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
 * pz, wi's cosine with n. In the own frame gr = 1 and fz = pz = wi.z.
 * With fd, the diffuse-like part of f (the diffuse base and the
 * multiple-scattering lobes) is added to *fd too, for the layers above
 * (the top); f itself is computed as without. */
INLINE V3 bsdf_eval_lobes(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w, float gr, float fz,
			  float pz, V3 *fd)
{
	V3 f = v3(0.0f, 0.0f, 0.0f);
	float pdf = 0.0f;
	if (bsdf_lambert(bs)) { /* the common case, exactly what the lobes below give */
		*pdf_w = pdf_cosine_hemisphere_w(pz);
		f = wi.z > 0.0f && fz > 0.0f ? v3_scale(bs->base_color, AJAR_INV_PI) : f;
		if (fd)
			*fd = v3_add(*fd, f);
		return f;
	}
	BsdfLobes p = bsdf_lobes(bs, wo, eta);
	int smooth = bsdf_smooth(bs);
	if (wi.z > 0.0f) {
		V3 h = v3_norm(v3_add(wo, wi));
		float cos_oh = v3_dot(wo, h);
		float jac = 1.0f / (4.0f * cos_oh); /* dh / dwi for reflection */
		float inv4 = 1.0f / (4.0f * wo.z * wi.z);
		if (!smooth && bsdf_w_metal(bs) > 0.0f) {
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs)) {
				float spec = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay) * inv4;
				f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec * gr);
				pdf += p.metal * ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay) * jac;
			} else
#endif
			{
				float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4;
				f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec * gr);
			}
			f = v3_madd(f, bs->metal_fms, bsdf_w_metal(bs) * bsdf_ms_factor(bs, p.e_metal, wi) * gr);
			if (fd)
				*fd = v3_madd(*fd, bs->metal_fms, bsdf_w_metal(bs) * bsdf_ms_factor(bs, p.e_metal, wi) * gr);
			if (!BSDF_IS_ANISO(bs))
				pdf += p.metal * ggx_pdf_visible(wo, h, bs->alpha) * jac;
		}
		pdf += p.ms * pdf_cosine_hemisphere_w(wi.z); /* metal and coat multiple scattering */
		float wp = bsdf_w_plastic(bs);
#ifndef AJAR_NO_LAYERS
		if (wp > 0.0f && BSDF_IS_TINT(bs)) { /* per channel (bsdf_setup_tint) */
			float a = bsdf_coat_alpha(bs), d = ggx_d(h, a) * ggx_g2(wo, wi, a), pv = ggx_pdf_visible(wo, h, a);
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs)) {
				d = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay);
				pv = ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay);
			}
#endif
			float e1_o, e1_i, sw = bsdf_schlick_w(cos_oh);
			float es_o = bsdf_coat_albedo_w(bs, wo, &e1_o), es_i = bsdf_coat_albedo_w(bs, wi, &e1_i);
			/* Ew from Es = s1 E1 + sw Ew with the untinted s1, sw */
			float ew_o = (es_o - bs->coat_s1 * e1_o) / fmax(bs->coat_sw, 1e-7f);
			float ew_i = (es_i - bs->coat_s1 * e1_i) / fmax(bs->coat_sw, 1e-7f);
			float kc = bsdf_kc_factor(e1_o, e1_i, bs->coat_e1avg);
			float s1[3] = {bs->tint_s1.x, bs->tint_s1.y, bs->tint_s1.z};
			float fm[3] = {bs->tint_fms.x, bs->tint_fms.y, bs->tint_fms.z};
			float ea[3] = {bs->tint_eavg.x, bs->tint_eavg.y, bs->tint_eavg.z};
			float bc[3] = {bs->base_color.x, bs->base_color.y, bs->base_color.z}, fc[3], dc[3];
			for (int c = 0; c < 3; c++) {
				float swc = bs->specular - s1[c];
				float et_o = s1[c] * e1_o + swc * ew_o + fm[c] * (1.0f - e1_o);
				float et_i = s1[c] * e1_i + swc * ew_i + fm[c] * (1.0f - e1_i);
				float kd = fz > 0.0f ? (1.0f - et_o) * (1.0f - et_i) * AJAR_INV_PI / fmax(1.0f - ea[c], 1e-7f) : 0.0f;
				dc[c] = wp * (fm[c] * kc * gr + bc[c] * kd);
				fc[c] = wp * (d * inv4 * (s1[c] + swc * sw)) * gr + dc[c];
			}
			f = v3_add(f, v3(fc[0], fc[1], fc[2]));
			if (fd)
				*fd = v3_add(*fd, v3(dc[0], dc[1], dc[2]));
			pdf += p.coat * pv * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
			wp = 0.0f; /* done */
		}
#endif
		if (wp > 0.0f) {
			float a = bsdf_coat_alpha(bs);
			float spec = ggx_d(h, a) * ggx_g2(wo, wi, a) * inv4 * bsdf_fresnel_coat(bs, cos_oh);
#ifndef AJAR_NO_ANISOTROPY
			float pv = 0.0f;
			if (BSDF_IS_ANISO(bs)) {
				spec = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay) * inv4 *
				       bsdf_fresnel_coat(bs, cos_oh);
				pv = ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay);
			}
#endif
			float kd = AJAR_INV_PI, ms = 0.0f;
			if (bs->specular > 0.0f) {
				float e1_i, es_i = bsdf_coat_albedo_w(bs, wi, &e1_i);
				float kc = bsdf_kc_factor(p.e_coat1, e1_i, bs->coat_e1avg);
				spec += bs->coat_fms * kc;
				ms = bs->coat_fms * kc; /* for fd */
				kd = bsdf_base_factor(bs, bsdf_coat_total(bs, p.e_coat, p.e_coat1), bsdf_coat_total(bs, es_i, e1_i));
			}
			kd = fz > 0.0f ? kd : 0.0f;
			float ws = wp * spec * gr;
			f = v3_add(f, v3_madd(v3(ws, ws, ws), bs->base_color, wp * kd));
			if (fd) {
				float wm = wp * ms * gr;
				*fd = v3_add(*fd, v3_madd(v3(wm, wm, wm), bs->base_color, wp * kd));
			}
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs))
				pdf += p.coat * pv * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
			else
#endif
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
			if (fd) {
				float wgm = bsdf_w_glass(bs) * ms * gr;
				*fd = v3_add(*fd, v3(wgm, wgm, wgm));
			}
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
		if (fd)
			*fd = v3_add(*fd, v3_scale(bs->base_color, bsdf_w_glass(bs) * (1.0f - bs->glass_x) *
								  bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wm.z), bs->glass_y) * gr));
		pdf = p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) / (4.0f * cos_oh) +
		      p.glass_t * pdf_cosine_hemisphere_w(wm.z);
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f) {
		V3 h;
		float t = bsdf_glass_ms(bs, eta > 1.0f, 0, p.e_glass, -wi.z);
		if (fd)
			*fd = v3_add(*fd, v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr *
								  (mode == BSDF_RADIANCE ? 1.0f / (eta * eta) : 1.0f)));
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
	return bsdf_eval_lobes(bs, wo, wi, eta, mode, pdf_w, 1.0f, wi.z, wi.z, 0);
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
INLINE V3 bsdf_eval_bent(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w, int rev, V3 *fd)
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
			f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, 1.0f, li.z, li.z, fd);
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
	V3 fd0 = fd ? *fd : f;
	if (bsdf_pair(bs, &fo, wo, wi, &lo, &li, &eta))
		f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, gr, fz, pzo, fd);
	if (rev && bsdf_pair(bs, &fi, wi, wo, &lo, &li, &eta))
		bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_rev_w, 1.0f, pzi, pzi, 0);
	if (!radiance && ti != to) { /* the camera side is wi: f in wi's normal */
		f = v3(0.0f, 0.0f, 0.0f);
		if (fd)
			*fd = fd0;
		if (bsdf_pair(bs, &fi, wo, wi, &lo, &li, &eta))
			f = bsdf_eval_lobes(bs, lo, li, eta, mode, &unused, gr, fz, pzo, fd);
	}
	return f;
}

#ifndef AJAR_NO_LAYERS
/* The core's f (all but the layers, the top), its diffuse-like part added
 * to *fd, pdf_w and, if `rev`, pdf_rev_w. */
INLINE V3 bsdf_eval_core(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w, int rev, V3 *fd)
{
	V3 lo, li;
	float eta;
	*pdf_w = *pdf_rev_w = 0.0f;
	if (BSDF_IS_TILTED(bs))
		return bsdf_eval_bent(bs, wo, wi, mode, pdf_w, pdf_rev_w, rev, fd);
	BsdfFrame fr = bsdf_frame_own(bs);
	if (!bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta))
		return v3(0.0f, 0.0f, 0.0f);
	V3 f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, 1.0f, li.z, li.z, fd);
	if (rev && bsdf_pair(bs, &fr, wi, wo, &lo, &li, &eta))
		bsdf_eval_local(bs, lo, li, eta, mode, pdf_rev_w);
	return f;
}

/* The clear coat's single-scattering albedo at mu (Fresnel at ior 1.5
 * included), bilinear in its table (bsdf_tables.h). */
INLINE float bsdf_cc_albedo(const Bsdf *bs, float mu)
{
	float x = sqrt(bsdf_clamp01(bs->cc_alpha)) * (BSDF_TAB_CR - 1), y = sqrt(bsdf_clamp01(mu)) * (BSDF_TAB_CMU - 1);
	int i = min((int)x, BSDF_TAB_CR - 2), j = min((int)y, BSDF_TAB_CMU - 2);
	float wr = x - (float)i, wm = y - (float)j;
	CONSTANT float *r0 = bsdf_tab_ecc + i * BSDF_TAB_CMU + j, *r1 = r0 + BSDF_TAB_CMU;
	float v0 = r0[0] + (r0[1] - r0[0]) * wm, v1 = r1[0] + (r1[1] - r1[0]) * wm;
	return v0 + (v1 - v0) * wr;
}

/* The normal n's frame for direction w, n turned toward ng along their arc
 * just far enough that w's mirror image lies min(0.9 cos, 0.01) above the
 * surface where it would not (bsdf_bend_t's rule, for any normal: the
 * layers' normals, the top). */
INLINE BsdfFrame bsdf_frame_about(const Bsdf *bs, V3 n, V3 w)
{
	BsdfFrame f;
	float iz = v3_dot(w, bs->ng), sgn = iz < 0.0f ? -1.0f : 1.0f, nz = v3_dot(n, bs->ng);
	iz *= sgn;
	float thr = fmin(0.9f * iz, 0.01f);
	f.n = n;
	if (sgn * 2.0f * v3_dot(w, n) * nz - iz < thr) {
		V3 d = v3_madd(n, bs->ng, -nz);
		float l = v3_len(d), ix;
		V3 x = l > 0.0f ? v3_scale(d, 1.0f / l) : bs->t;
		float tn = fast_atan2(l, fmax(nz, 0.0f));
		ix = sgn * v3_dot(w, x);
		float a = sqrt(ix * ix + iz * iz), t = 0.0f;
		if (a > 0.0f) {
			float c = fmin(thr / a, 1.0f);
			t = fmin(fmax(0.5f * (fast_atan2(ix, iz) + fast_atan2(sqrt((1.0f - c) * (1.0f + c)), c)), 0.0f), tn);
		}
		float st, ct;
		fast_sincos(t, &st, &ct);
		f.n = v3_norm(v3_add(v3_scale(x, st), v3_scale(bs->ng, ct)));
	}
	v3_basis(f.n, &f.t, &f.b);
	return f;
}

/* What the layers are seen from direction w on side `side` of ng: the
 * sheen's and the clear coat's normals for w (bsdf_frame_about: where a
 * normal map turns them away, as the core's bend), the sheen lobe's albedo
 * (colour 1) and its normaliser N, the clear coat's E1, single-scattering
 * albedo (Fresnel included) and whole albedo Et. */
typedef struct {
	BsdfFrame fs, fc;
	float es, ns, e1c, esc, etc;
} BsdfLayerAt;

INLINE BsdfLayerAt bsdf_layer_at(const Bsdf *bs, V3 w, float side)
{
	BsdfLayerAt l;
	l.es = 0.0f;
	l.ns = 1.0f;
	l.e1c = 1.0f;
	l.esc = l.etc = 0.0f;
	l.fs = l.fc = bsdf_frame_own(bs);
	if (bs->sheen_c > 0.0f) {
		if (BSDF_IS_TILTED(bs))
			l.fs = bsdf_frame_about(bs, bs->n, w);
		BsdfTabAt a = bsdf_sheen_at(bs->sheen_r, side * v3_dot(w, l.fs.n));
		l.es = bsdf_tab2(bsdf_tab_sheen, a);
		l.ns = fmax(bsdf_tab2(bsdf_tab_sheenr, a), 1.0f);
	}
	if (bs->cc > 0.0f) {
		l.fc = bsdf_frame_about(bs, bs->cc_n, w);
		BsdfTabAt a = bsdf_tab_at(bs->cc_alpha, side * v3_dot(w, l.fc.n));
		l.e1c = bsdf_tab2(bsdf_tab_e1, a);
		l.esc = bsdf_cc_albedo(bs, side * v3_dot(w, l.fc.n));
		l.etc = l.esc + bs->cc_fms * (1.0f - l.e1c);
	}
	return l;
}

/* Selection probabilities seen from a direction: the clear coat's GGX and
 * Kulla-Conty lobes, the sheen, the core; weight x albedo (the core's
 * guessed from its base colour). */
typedef struct {
	float ccs, ccm, sh, core;
} BsdfLayerP;

INLINE BsdfLayerP bsdf_layer_p(const Bsdf *bs, BsdfLayerAt l)
{
	BsdfLayerP p;
	float pass = fmax(1.0f - bs->cc * l.etc, 0.0f);
	p.ccs = bs->cc * l.esc;
	p.ccm = bs->cc * (l.etc - l.esc);
	p.sh = pass * v3_avg(bs->sheen) * l.es;
	p.core = pass * fmax(1.0f - bs->sheen_c * l.es, 0.0f) * fmax(v3_avg(bs->base_color), 0.2f);
	float sum = p.ccs + p.ccm + p.sh + p.core;
	if (!(sum > 0.0f)) {
		p.ccs = p.ccm = p.sh = 0.0f;
		p.core = 1.0f;
		return p;
	}
	float inv = 1.0f / sum;
	p.ccs *= inv;
	p.ccm *= inv;
	p.sh *= inv;
	p.core *= inv;
	return p;
}

/* What passes the layers each way (the top): *tg for the core's
 * microfacet lobes, *td for its diffuse-like ones, *tsh for the sheen
 * under the clear coat. A layer of albedo E passes a diffuse-like lobe
 * (1 - E(mu_o)) (1 - E(mu_i)) / (1 - Eavg) (exact for a Lambertian base),
 * a microfacet lobe (1 - E(mu_o)) (1 - E(mu_i)) / sqrt((1 - Eo') (1 - Ei'))
 * with E' = E + r (Eavg - E), r the core's roughness: the lobe's own mean
 * of E, guessed; exact for a mirror (r = 0), Eavg for a rough lobe. Both
 * symmetric. White furnace over glossy bases (test_layer_furnace):
 * within 3.2%, where sqrt((1 - E(mu_o)) (1 - E(mu_i))) gained 17% at
 * grazing views and min(1 - E(mu_o), 1 - E(mu_i)) lost 5.7%. */
INLINE void bsdf_layer_t(const Bsdf *bs, BsdfLayerAt o, BsdfLayerAt i, float *tg, float *td, float *tsh)
{
	float r = bsdf_smooth(bs) ? 0.0f : sqrt(bsdf_clamp01(bs->alpha));
#ifndef AJAR_NO_ANISOTROPY
	if (BSDF_IS_ANISO(bs))
		r = sqrt(bsdf_clamp01(bs->an_rms));
#endif
	float eo = bs->sheen_c * o.es, ei = bs->sheen_c * i.es, ea = bs->sheen_eavg;
	float go = fmax(1.0f - eo, 0.0f), gi = fmax(1.0f - ei, 0.0f);
	float bo = fmax(1.0f - (eo + r * (ea - eo)), 1e-7f), bi = fmax(1.0f - (ei + r * (ea - ei)), 1e-7f);
	float sg = go * gi / sqrt(bo * bi), sd = go * gi / fmax(1.0f - ea, 1e-7f);
	ea = bs->cc_eavg;
	float co = fmax(1.0f - o.etc, 0.0f), ci = fmax(1.0f - i.etc, 0.0f);
	bo = fmax(1.0f - (o.etc + r * (ea - o.etc)), 1e-7f);
	bi = fmax(1.0f - (i.etc + r * (ea - i.etc)), 1e-7f);
	float lg = 1.0f - bs->cc + bs->cc * co * ci / sqrt(bo * bi);
	float ld = 1.0f - bs->cc + bs->cc * co * ci / fmax(1.0f - ea, 1e-7f);
	*tg = lg * sg;
	*td = ld * sd;
	*tsh = ld;
}

/* The layers' own lobes for a reflection pair (both on side so): f in the
 * frames of the camera side's direction (lo_at's in radiance mode, li_at's
 * in importance mode), times |wl . m| / |wl . n| as bent lobes are (the
 * top), the sheen's under the clear coat by tsh; and, added to *pdf,
 * their densities from wo (its frames) with p's probabilities. */
INLINE V3 bsdf_layer_lobes(const Bsdf *bs, V3 wo, V3 wi, float so, BsdfLayerAt lo_at, BsdfLayerAt li_at, float tsh,
			   int mode, BsdfLayerP p, float *pdf)
{
	V3 f = v3(0.0f, 0.0f, 0.0f);
	int radiance = mode == BSDF_RADIANCE;
	V3 wl = radiance ? wi : wo;
	if (bs->sheen_c > 0.0f) {
		const BsdfFrame *fr = radiance ? &lo_at.fs : &li_at.fs;
		V3 lo = bsdf_local(fr, wo, so), li = bsdf_local(fr, wi, so);
		float sh = sheen_f(lo, li, sheen_alpha(bs->sheen_r)) / (lo_at.ns * li_at.ns);
		f = v3_scale(bs->sheen, tsh * sh * bsdf_bend_ratio(bs, fr->n, wl));
		*pdf += p.sh * pdf_cosine_hemisphere_w(so * v3_dot(wi, lo_at.fs.n));
	}
	if (bs->cc > 0.0f) {
		const BsdfFrame *fr = radiance ? &lo_at.fc : &li_at.fc;
		V3 lo = bsdf_local(fr, wo, so), li = bsdf_local(fr, wi, so);
		float a = bs->cc_alpha;
		if (lo.z > 0.0f && li.z > 0.0f) {
			V3 h = v3_norm(v3_add(lo, li));
			float fr0 = bsdf_fresnel_dielectric(v3_dot(lo, h), BSDF_CC_IOR);
			float spec = ggx_d(h, a) * ggx_g2(lo, li, a) * fr0 / (4.0f * lo.z * li.z);
			float ms = bs->cc_fms * bsdf_kc_factor(lo_at.e1c, li_at.e1c, bs->cc_e1avg);
			float w = bs->cc * (spec + ms) * bsdf_bend_ratio(bs, fr->n, wl);
			f = v3_add(f, v3(w, w, w));
		}
		lo = bsdf_local(&lo_at.fc, wo, so);
		li = bsdf_local(&lo_at.fc, wi, so);
		if (lo.z > 0.0f && li.z > 0.0f) {
			V3 h = v3_norm(v3_add(lo, li));
			*pdf += p.ccs * ggx_pdf_visible(lo, h, a) / (4.0f * v3_dot(lo, h)) +
				p.ccm * pdf_cosine_hemisphere_w(li.z);
		}
	}
	return f;
}

/* bsdf_eval of a layered BSDF (the top). */
INLINE V3 bsdf_eval_layered(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w, int rev)
{
	V3 fd = v3(0.0f, 0.0f, 0.0f);
	float pc, pcr, tg, td, tsh;
	*pdf_w = *pdf_rev_w = 0.0f;
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return fd;
	V3 fc = bsdf_eval_core(bs, wo, wi, mode, &pc, &pcr, rev, &fd);
	BsdfLayerAt lo = bsdf_layer_at(bs, wo, so), li = bsdf_layer_at(bs, wi, si);
	bsdf_layer_t(bs, lo, li, &tg, &td, &tsh);
	V3 f = v3_add(v3_scale(v3_sub(fc, fd), tg), v3_scale(fd, td));
	BsdfLayerP po = bsdf_layer_p(bs, lo), pi = bsdf_layer_p(bs, li);
	*pdf_w = po.core * pc;
	if (rev)
		*pdf_rev_w = pi.core * pcr;
	if (so == si) {
		float pl = 0.0f, plr = 0.0f;
		f = v3_add(f, bsdf_layer_lobes(bs, wo, wi, so, lo, li, tsh, mode, po, &pl));
		*pdf_w += pl;
		if (rev) {
			bsdf_layer_lobes(bs, wi, wo, so, li, lo, tsh, mode, pi, &plr);
			*pdf_rev_w += plr;
		}
	}
	return f;
}
#endif

/* f without the cosine, of the non-delta lobes only, and pdf_w of
 * sampling wi given wo: what connections and next-event estimation need. */
INLINE V3 bsdf_eval_fwd(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w)
{
	V3 lo, li;
	float eta, unused;
	*pdf_w = 0.0f;
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs))
		return bsdf_eval_layered(bs, wo, wi, mode, pdf_w, &unused, 0);
#endif
	if (BSDF_IS_TILTED(bs))
		return bsdf_eval_bent(bs, wo, wi, mode, pdf_w, &unused, 0, 0);
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
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs))
		return bsdf_eval_layered(bs, wo, wi, mode, pdf_w, pdf_rev_w, 1);
#endif
	if (BSDF_IS_TILTED(bs))
		return bsdf_eval_bent(bs, wo, wi, mode, pdf_w, pdf_rev_w, 1, 0);
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

/* Keeps the lobes for world direction wo in bs (bsdf_lobes): the vertex's
 * own direction toward its predecessor, from which it is sampled and
 * connected. */
INLINE void bsdf_cache_wo(Bsdf *bs, V3 wo)
{
	float so = bsdf_side(bs, wo);
	int bent;
	if (bsdf_lambert(bs) || so == 0.0f)
		return;
	BsdfFrame fr = bsdf_frame_for(bs, wo, &bent);
	V3 lo = bsdf_local(&fr, wo, so);
	if (!(lo.z > 0.0f))
		return;
	float eta = bsdf_eta(bs, so);
	bs->lc = bsdf_lobes_calc(bs, lo, eta);
	bs->lc_x = lo.x;
	bs->lc_y = lo.y;
	bs->lc_z = lo.z;
	bs->lc_eta = eta;
}

/* Only the solid-angle density of sampling wi given wo (non-delta lobes):
 * what MIS needs when it recomputes a vertex's density. */
INLINE float bsdf_pdf_w(const Bsdf *bs, V3 wo, V3 wi)
{
	V3 lo, li;
	float eta, pdf = 0.0f;
	int bent;
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs)) {
		float unused;
		bsdf_eval_layered(bs, wo, wi, BSDF_RADIANCE, &pdf, &unused, 0);
		return pdf;
	}
#endif
	BsdfFrame fr = bsdf_frame_for(bs, wo, &bent);
	if (bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta)) {
		float pz = bent ? bsdf_side(bs, wo) * v3_dot(wi, bs->n) : li.z; /* the diffuse base's, in n */
		bsdf_eval_lobes(bs, lo, li, eta, BSDF_RADIANCE, &pdf, 1.0f, pz, pz, 0);
	}
	return pdf;
}

/* Probability of picking smooth glass's reflection (reflect = 1) or
 * refraction for wo (flipped-local, eta of its side): for pdf_rev_w. */
INLINE float bsdf_glass_delta_prob(const Bsdf *bs, V3 wo, float eta, int reflect)
{
	float fr = bsdf_fresnel_dielectric(wo.z, eta);
	return bsdf_lobes(bs, wo, eta).glass * (reflect ? fr : 1.0f - fr);
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
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs)) /* the core's share of the sampling (bsdf_sample_layered) */
		return bsdf_layer_p(bs, bsdf_layer_at(bs, wo, so)).core * bsdf_lobes(bs, lo, bsdf_eta(bs, so)).glass *
		       (1.0f - bsdf_thin_fresnel(bs, wo));
#endif
	return bsdf_lobes(bs, lo, bsdf_eta(bs, so)).glass * (1.0f - bsdf_thin_fresnel(bs, wo));
}

/* The transmittance of smooth thin glass crossed along w: wg (1 - F)
 * base_color, what a shadow ray or connection through it carries, and
 * what a walk's null event carries divided by bsdf_null_prob. */
INLINE V3 bsdf_null_weight(const Bsdf *bs, V3 w)
{
	if (!bsdf_has_null(bs))
		return v3(0.0f, 0.0f, 0.0f);
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs)) { /* through the layers on both sides, at one cosine */
		float tg, td, tsh, sw = bsdf_side(bs, w);
		BsdfLayerAt l = bsdf_layer_at(bs, w, sw == 0.0f ? 1.0f : sw);
		bsdf_layer_t(bs, l, l, &tg, &td, &tsh);
		return v3_scale(bs->base_color, bsdf_w_glass(bs) * (1.0f - bsdf_thin_fresnel(bs, w)) * tg);
	}
#endif
	return v3_scale(bs->base_color, bsdf_w_glass(bs) * (1.0f - bsdf_thin_fresnel(bs, w)));
}

/* Returns 0 if no sample. For delta samples f is the lobe's weight (Fresnel
 * included) divided by |wi.n| (shading normal), so f |wi.n| / pdf_w is the
 * throughput (in a bent normal m, times |wl . m| / |wl . n| as every f, the
 * top); pdf_w and pdf_rev_w are then the probabilities of picking that delta
 * event from wo and from wi. */
INLINE int bsdf_sample_core(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s, int rev)
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
	BsdfLobes p = bsdf_lobes(bs, lo, eta);
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
#ifndef AJAR_NO_ANISOTROPY
		if (BSDF_IS_ANISO(bs))
			li = bsdf_reflect(lo, ggx_sample_visible_aniso(lo, bs->ax, bs->ay, u1, u2));
		else
#endif
			li = bsdf_reflect(lo, ggx_sample_visible(lo, bs->alpha, u1, u2));
	} else if (u0 < p.metal + p.coat) {
#ifndef AJAR_NO_ANISOTROPY
		if (BSDF_IS_ANISO(bs))
			li = bsdf_reflect(lo, ggx_sample_visible_aniso(lo, bs->ax, bs->ay, u1, u2));
		else
#endif
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
			s->pdf_rev_w = bsdf_lobes(bs, ri, bsdf_eta(bs, so)).glass * bsdf_thin_fresnel(bs, s->wi);
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

#ifndef AJAR_NO_LAYERS
/* bsdf_sample of a layered BSDF: a layer's lobe with its probability from
 * wo (bsdf_layer_p), else the core with u0 rescaled, whose delta events
 * are then weighed by what passes the layers (bsdf_layer_t) and by the
 * core's probability from each end (a null event's weight and reverse
 * probability come from bsdf_null_weight and bsdf_null_prob, which have
 * them). u0's low end is the layers', so a null event stays at its high
 * end (vertex_scatter). */
INLINE int bsdf_sample_layered(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s, int rev)
{
	float so = bsdf_side(bs, wo);
	if (so == 0.0f)
		return 0;
	BsdfLayerAt at = bsdf_layer_at(bs, wo, so);
	BsdfLayerP p = bsdf_layer_p(bs, at);
	V3 wi;
	if (u0 < p.ccs + p.ccm) {
		V3 lo = bsdf_local(&at.fc, wo, so);
		if (!(lo.z > 0.0f))
			return 0;
		V3 li = u0 < p.ccs ? bsdf_reflect(lo, ggx_sample_visible(lo, bs->cc_alpha, u1, u2))
				   : sample_cosine_hemisphere(u1, u2);
		if (!(li.z > 0.0f))
			return 0;
		wi = bsdf_world(&at.fc, li, so);
	} else if (u0 < p.ccs + p.ccm + p.sh) {
		wi = bsdf_world(&at.fs, sample_cosine_hemisphere(u1, u2), so);
	} else {
		float u = fmin((u0 - (p.ccs + p.ccm + p.sh)) / p.core, 0.99999994f);
		if (!bsdf_sample_core(bs, wo, u, u1, u2, mode, s, rev))
			return 0;
		if (s->delta) {
			float si = bsdf_side(bs, s->wi), tg, td, tsh;
			BsdfLayerAt li = bsdf_layer_at(bs, s->wi, si == 0.0f ? so : si);
			if (s->delta != BSDF_NULL) {
				bsdf_layer_t(bs, at, li, &tg, &td, &tsh);
				s->f = v3_scale(s->f, tg);
				s->pdf_rev_w *= bsdf_layer_p(bs, li).core;
			}
			s->pdf_w *= p.core;
		}
		return s->pdf_w > 0.0f;
	}
	if (bsdf_side(bs, wi) != so) /* below the surface: lost */
		return 0;
	s->wi = wi;
	s->delta = 0;
	s->pdf_rev_w = 0.0f;
	s->f = rev ? bsdf_eval(bs, wo, wi, mode, &s->pdf_w, &s->pdf_rev_w) : bsdf_eval_fwd(bs, wo, wi, mode, &s->pdf_w);
	return s->pdf_w > 0.0f;
}
#endif

INLINE int bsdf_sample_in(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s, int rev)
{
#ifndef AJAR_NO_LAYERS
	if (BSDF_IS_LAYERED(bs))
		return bsdf_sample_layered(bs, wo, u0, u1, u2, mode, s, rev);
#endif
	return bsdf_sample_core(bs, wo, u0, u1, u2, mode, s, rev);
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
