/* bsdf.h — glTF metallic-roughness as one BSDF: evaluation, sampling, pdfs.
 *
 * Three lobes, mixed by the glTF weights (base_color is factor x texture):
 *   metal   weight metallic: GGX conductor, Schlick Fresnel with F0 = base_color;
 *   plastic weight (1 - metallic)(1 - transmission): a GGX dielectric coat
 *           with Fs(c) = specular * Schlick(F0 = ((ior-1)/(ior+1))^2, c), over
 *           a diffuse base_color / pi * (1 - Fs(cos_o)) * (1 - Fs(cos_i)).
 *           The product of the two (1 - F) factors is reciprocal and keeps
 *           the albedo <= 1 at grazing angles, where glTF's fresnel_mix with
 *           F(h.wo) does not; specular = 0 gives exactly base_color / pi
 *           (KHR_materials_specular scales the whole Fresnel term, as glTF does);
 *   glass   weight (1 - metallic) transmission: rough dielectric (Walter et
 *           al. 2007) with exact Fresnel, transmission tinted by base_color.
 * GGX alpha = roughness^2. Metal and glass with alpha < BSDF_DELTA_ALPHA are
 * delta lobes (mirror, smooth glass); the plastic coat never is: its alpha is
 * clamped to >= BSDF_MIN_ALPHA. Microfacet terms: height-correlated Smith G2
 * = 1 / (1 + L(wo) + L(wi)), visible-normal sampling (Heitz 2018), so pdfs
 * are D_wo(h) times the reflection or refraction Jacobian.
 *
 * Frames: reflection is two-sided: the frame is flipped to the side of wo as
 * the geometric normal ng sees it. Reflection needs wo, wi on the same side of
 * ng, transmission on opposite sides (no light leaks through shading
 * normals); both must also lie on the right side of the shading normal n, or
 * the BSDF is 0. Glass's outside (ior on the far side) is the side ng points to.
 *
 * Lobe selection for sampling is proportional to weight x albedo estimate at
 * the outgoing direction; pdf_w is the mixture over all non-delta lobes, so
 * sampling and bsdf_eval agree, and integrates to 1 - P(delta lobes). */
#ifndef AJAR_BSDF_H
#define AJAR_BSDF_H
#include "types.h"
#include "sampling.h"

#define BSDF_RADIANCE 0   /* wo points toward the camera (eye paths) */
#define BSDF_IMPORTANCE 1 /* wo points toward the light (light paths); no eta^2 scaling on refraction */

#define BSDF_DELTA_ALPHA 1e-3f /* metal and glass below this GGX alpha are delta */
#define BSDF_MIN_ALPHA 1e-3f   /* the plastic coat's alpha floor */
#define BSDF_MIN_IOR 1.01f     /* eta = 1 makes the refraction half vector vanish */
#define BSDF_MAX_IOR 4.0f

typedef struct {
	V3 t, b, n;      /* shading frame, n on the side of ng */
	V3 ng;           /* geometric normal, unflipped: glass's outside */
	V3 base_color;   /* linear, in [0, 1] */
	float metallic, alpha, transmission, ior, specular;
	int flags;       /* the Material's MATERIAL_* flags */
} Bsdf;

typedef struct {
	V3 wi;
	V3 f;            /* without the cosine */
	float pdf_w;     /* density of wi given wo (lobe probability for delta) */
	float pdf_rev_w; /* density of wo given wi (lobe probability for delta) */
	int delta;
} BsdfSample;

/* Selection probabilities of the four sampled lobes for one outgoing direction. */
typedef struct {
	float metal, coat, diffuse, glass;
} BsdfLobes;

INLINE float bsdf_clamp01(float x) { return fmin(fmax(x, 0.0f), 1.0f); }

/* The BSDF of material m with metallic and roughness given (textured, surface.h). */
INLINE void bsdf_setup_mr(Bsdf *bs, GLOBAL const Material *m, V3 base_color, float metallic, float roughness, V3 ns,
			  V3 ng)
{
	float lg = v3_len(ng);
	bs->ng = lg > 0.0f ? v3_scale(ng, 1.0f / lg) : v3(0.0f, 0.0f, 1.0f);
	float ls = v3_len(ns);
	V3 n = ls > 0.0f ? v3_scale(ns, 1.0f / ls) : bs->ng;
	if (!(v3_dot(n, n) > 0.5f))
		n = bs->ng; /* NaN or infinite shading normal */
	if (v3_dot(n, bs->ng) < 0.0f)
		n = v3_neg(n);
	bs->n = n;
	v3_basis(n, &bs->t, &bs->b);
	bs->base_color = v3(bsdf_clamp01(base_color.x), bsdf_clamp01(base_color.y), bsdf_clamp01(base_color.z));
	bs->metallic = bsdf_clamp01(metallic);
	float r = bsdf_clamp01(roughness);
	bs->alpha = r * r;
	bs->transmission = bsdf_clamp01(m->transmission);
	bs->ior = fmin(fmax(m->ior, BSDF_MIN_IOR), BSDF_MAX_IOR);
	bs->specular = bsdf_clamp01(m->specular);
	bs->flags = m->flags;
}

/* The BSDF of material m, its metallic and roughness untextured. */
INLINE void bsdf_setup(Bsdf *bs, GLOBAL const Material *m, V3 base_color, V3 ns, V3 ng)
{
	bsdf_setup_mr(bs, m, base_color, m->metallic, m->roughness, ns, ng);
}

INLINE float bsdf_w_metal(const Bsdf *bs) { return bs->metallic; }
INLINE float bsdf_w_plastic(const Bsdf *bs) { return (1.0f - bs->metallic) * (1.0f - bs->transmission); }
INLINE float bsdf_w_glass(const Bsdf *bs) { return (1.0f - bs->metallic) * bs->transmission; }
INLINE int bsdf_smooth(const Bsdf *bs) { return bs->alpha < BSDF_DELTA_ALPHA; }
INLINE float bsdf_coat_alpha(const Bsdf *bs) { return fmax(bs->alpha, BSDF_MIN_ALPHA); }

/* Contains some delta lobe (smooth metal or glass with a non-zero weight). */
INLINE int bsdf_has_delta(const Bsdf *bs)
{
	return bsdf_smooth(bs) && (bsdf_w_metal(bs) > 0.0f || bsdf_w_glass(bs) > 0.0f);
}

/* No non-delta lobe at all: skip light sampling and connections. */
INLINE int bsdf_is_delta(const Bsdf *bs) { return bsdf_smooth(bs) && !(bsdf_w_plastic(bs) > 0.0f); }

/* (1 - c)^5, Schlick's Fresnel weight. */
INLINE float bsdf_schlick_w(float c)
{
	float m = bsdf_clamp01(1.0f - c);
	float m2 = m * m;
	return m2 * m2 * m;
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

/* Exact unpolarised dielectric Fresnel reflectance; cos_i > 0 on the side of
 * the incident direction, eta = eta_transmitted / eta_incident. */
INLINE float bsdf_fresnel_dielectric(float cos_i, float eta)
{
	cos_i = bsdf_clamp01(cos_i);
	float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0f)
		return 1.0f; /* total internal reflection */
	float cos_t = sqrt(1.0f - sin2_t);
	float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
	float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
	return 0.5f * (r_par * r_par + r_perp * r_perp);
}

/* GGX normal distribution of a unit local h; written with the tangential
 * part so it stays accurate near h = z at tiny alpha. */
INLINE float ggx_d(V3 h, float alpha)
{
	if (h.z <= 0.0f)
		return 0.0f;
	float a2 = alpha * alpha;
	float d = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
	return a2 / (AJAR_PI * d * d);
}

/* Smith Lambda of GGX. */
INLINE float ggx_lambda(V3 w, float alpha)
{
	float z2 = w.z * w.z;
	if (!(z2 > 0.0f))
		return AJAR_INF;
	float a2t2 = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
	return 0.5f * (sqrt(1.0f + a2t2) - 1.0f);
}

INLINE float ggx_g2(V3 wo, V3 wi, float alpha)
{
	return 1.0f / (1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

/* Density of the visible normal h seen from wo (wo.z > 0):
 * G1(wo) max(0, wo.h) D(h) / wo.z. */
INLINE float ggx_pdf_visible(V3 wo, V3 h, float alpha)
{
	float c = v3_dot(wo, h);
	if (c <= 0.0f)
		return 0.0f;
	return ggx_d(h, alpha) * c / ((1.0f + ggx_lambda(wo, alpha)) * wo.z);
}

/* Visible-normal sampling (Heitz 2018): stretch wo to the alpha = 1
 * configuration, sample the projected hemisphere as a disk whose lower half
 * is squashed by the view's slope, unstretch. */
INLINE V3 ggx_sample_visible(V3 wo, float alpha, float u1, float u2)
{
	V3 vh = v3_norm(v3(alpha * wo.x, alpha * wo.y, wo.z));
	float len2 = vh.x * vh.x + vh.y * vh.y;
	V3 t1 = len2 > 1e-14f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrt(len2)) : v3(1.0f, 0.0f, 0.0f);
	V3 t2 = v3_cross(vh, t1);
	float r = sqrt(u1), sp, cp;
	fast_sincos(AJAR_PI * (2.0f * u2 - 1.0f), &sp, &cp);
	float p1 = r * cp, p2 = r * sp;
	float s = 0.5f * (1.0f + vh.z);
	p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
	V3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
		       v3_scale(vh, sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2))));
	return v3_norm(v3(alpha * nh.x, alpha * nh.y, fmax(1e-7f, nh.z)));
}

INLINE V3 bsdf_reflect(V3 w, V3 h) { return v3_sub(v3_scale(h, 2.0f * v3_dot(w, h)), w); }

/* Refraction of w (on the side h points to) through h; eta = eta_t / eta_i.
 * Returns 0 on total internal reflection. */
INLINE int bsdf_refract(V3 w, V3 h, float eta, V3 *wt)
{
	float cos_i = v3_dot(w, h);
	float sin2_t = fmax(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0f)
		return 0;
	float cos_t = sqrt(1.0f - sin2_t);
	*wt = v3_add(v3_scale(w, -1.0f / eta), v3_scale(h, cos_i / eta - cos_t));
	return 1;
}

/* Half vector of a refraction pair in the flipped frame (wo.z > 0 > wi.z):
 * Walter's generalized h, oriented to +z; 0 if degenerate or if either
 * direction is on the wrong side of the microfacet. */
INLINE int bsdf_half_refract(V3 wo, V3 wi, float eta, V3 *h)
{
	V3 m = v3_add(wo, v3_scale(wi, eta));
	float l2 = v3_len2(m);
	if (!(l2 > 1e-20f))
		return 0;
	m = v3_scale(m, 1.0f / sqrt(l2));
	if (m.z < 0.0f)
		m = v3_neg(m);
	if (!(v3_dot(wo, m) > 0.0f) || !(v3_dot(wi, m) < 0.0f))
		return 0;
	*h = m;
	return 1;
}

/* Pure Lambertian (glTF with specular 0, no metal, no transmission) and
 * not black: the diffuse lobe is then the only one. */
INLINE int bsdf_lambert(const Bsdf *bs)
{
	return bs->metallic == 0.0f && bs->transmission == 0.0f && bs->specular == 0.0f && v3_maxc(bs->base_color) > 0.0f;
}

/* Lobe selection for outgoing cos_o > 0: weight x albedo estimate. */
INLINE BsdfLobes bsdf_lobes(const Bsdf *bs, float cos_o)
{
	BsdfLobes p;
	float fc = bsdf_fresnel_coat(bs, cos_o);
	p.metal = bsdf_w_metal(bs) * v3_avg(bsdf_fresnel_metal(bs, cos_o));
	p.coat = bsdf_w_plastic(bs) * fc;
	p.diffuse = bsdf_w_plastic(bs) * (1.0f - fc) * v3_avg(bs->base_color);
	p.glass = bsdf_w_glass(bs);
	float sum = p.metal + p.coat + p.diffuse + p.glass;
	float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
	p.metal *= inv;
	p.coat *= inv;
	p.diffuse *= inv;
	p.glass *= inv;
	return p;
}

/* Local coordinates of w in the frame flipped by `side` (+-1). */
INLINE V3 bsdf_local(const Bsdf *bs, V3 w, float side)
{
	return v3(v3_dot(w, bs->t), v3_dot(w, bs->b), side * v3_dot(w, bs->n));
}

INLINE V3 bsdf_world(const Bsdf *bs, V3 w, float side)
{
	return v3_from_local(v3(w.x, w.y, side * w.z), bs->t, bs->b, bs->n);
}

/* Relative ior eta_t / eta_i for light leaving toward the side `side` of ng. */
INLINE float bsdf_eta(const Bsdf *bs, float side) { return side > 0.0f ? bs->ior : 1.0f / bs->ior; }

/* Non-delta f and pdf in the frame flipped to wo (wo.z > 0). wi.z > 0 is
 * reflection, wi.z < 0 transmission; the caller has checked the sides. */
INLINE V3 bsdf_eval_local(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w)
{
	V3 f = v3(0.0f, 0.0f, 0.0f);
	float pdf = 0.0f;
	if (bsdf_lambert(bs)) { /* the common case, exactly what the lobes below give */
		*pdf_w = wi.z > 0.0f ? wi.z * AJAR_INV_PI : 0.0f;
		return wi.z > 0.0f ? v3_scale(bs->base_color, AJAR_INV_PI) : f;
	}
	BsdfLobes p = bsdf_lobes(bs, wo.z);
	int smooth = bsdf_smooth(bs);
	if (wi.z > 0.0f) {
		V3 h = v3_norm(v3_add(wo, wi));
		float cos_oh = v3_dot(wo, h);
		float jac = 1.0f / (4.0f * cos_oh); /* dh / dwi for reflection */
		float inv4 = 1.0f / (4.0f * wo.z * wi.z);
		if (!smooth && bsdf_w_metal(bs) > 0.0f) {
			float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4;
			f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec);
			pdf += p.metal * ggx_pdf_visible(wo, h, bs->alpha) * jac;
		}
		float wp = bsdf_w_plastic(bs);
		if (wp > 0.0f) {
			float a = bsdf_coat_alpha(bs);
			float spec = ggx_d(h, a) * ggx_g2(wo, wi, a) * inv4 * bsdf_fresnel_coat(bs, cos_oh);
			float kd = (1.0f - bsdf_fresnel_coat(bs, wo.z)) * (1.0f - bsdf_fresnel_coat(bs, wi.z)) * AJAR_INV_PI;
			f = v3_add(f, v3_madd(v3(wp * spec, wp * spec, wp * spec), bs->base_color, wp * kd));
			pdf += p.coat * ggx_pdf_visible(wo, h, a) * jac + p.diffuse * pdf_cosine_hemisphere_w(wi.z);
		}
		if (!smooth && bsdf_w_glass(bs) > 0.0f) {
			float fr = bsdf_fresnel_dielectric(cos_oh, eta);
			float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4 * fr;
			float wg = bsdf_w_glass(bs) * spec;
			f = v3_add(f, v3(wg, wg, wg));
			pdf += p.glass * fr * ggx_pdf_visible(wo, h, bs->alpha) * jac;
		}
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f) {
		V3 h;
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
			float t = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * (1.0f - fr) *
				  fabs(cos_ih * cos_oh / (wo.z * wi.z * denom));
			if (mode == BSDF_RADIANCE)
				t /= eta * eta;
			f = v3_scale(bs->base_color, bsdf_w_glass(bs) * t);
			pdf = p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) * fabs(cos_ih) / denom;
		}
	}
	*pdf_w = pdf;
	return f;
}

/* Side of w as ng sees it: +1, -1, or 0 when w lies in the surface. */
INLINE float bsdf_side(const Bsdf *bs, V3 w)
{
	float c = v3_dot(w, bs->ng);
	return c > 0.0f ? 1.0f : (c < 0.0f ? -1.0f : 0.0f);
}

/* The flipped local pair for world wo, wi, or 0 if the pair is on
 * inconsistent sides of ng and n. */
INLINE int bsdf_pair(const Bsdf *bs, V3 wo, V3 wi, V3 *lo, V3 *li, float *eta)
{
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return 0;
	*lo = bsdf_local(bs, wo, so);
	*li = bsdf_local(bs, wi, so);
	*eta = bsdf_eta(bs, so);
	if (!(lo->z > 0.0f))
		return 0;
	return so == si ? li->z > 0.0f : li->z < 0.0f;
}

/* f without the cosine, of the non-delta lobes only, and pdf_w of
 * sampling wi given wo: what connections and next-event estimation need. */
INLINE V3 bsdf_eval_fwd(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w)
{
	V3 lo, li;
	float eta;
	*pdf_w = 0.0f;
	if (!bsdf_pair(bs, wo, wi, &lo, &li, &eta))
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
	if (!bsdf_pair(bs, wo, wi, &lo, &li, &eta))
		return v3(0.0f, 0.0f, 0.0f);
	V3 f = bsdf_eval_local(bs, lo, li, eta, mode, pdf_w);
	if (bsdf_pair(bs, wi, wo, &lo, &li, &eta))
		bsdf_eval_local(bs, lo, li, eta, mode, pdf_rev_w);
	return f;
}

/* Only the solid-angle density of sampling wi given wo (non-delta lobes):
 * what MIS needs when it recomputes a vertex's density. */
INLINE float bsdf_pdf_w(const Bsdf *bs, V3 wo, V3 wi)
{
	V3 lo, li;
	float eta, pdf = 0.0f;
	if (bsdf_pair(bs, wo, wi, &lo, &li, &eta))
		bsdf_eval_local(bs, lo, li, eta, BSDF_RADIANCE, &pdf);
	return pdf;
}

/* Probability of picking smooth glass's reflection (reflect = 1) or
 * refraction for wo (flipped-local, eta of its side): for pdf_rev_w. */
INLINE float bsdf_glass_delta_prob(const Bsdf *bs, V3 wo, float eta, int reflect)
{
	float fr = bsdf_fresnel_dielectric(wo.z, eta);
	return bsdf_lobes(bs, wo.z).glass * (reflect ? fr : 1.0f - fr);
}

/* Returns 0 if no sample. For delta samples f is the lobe's weight (Fresnel
 * included) divided by |wi.n| (shading normal), so f |wi.n| / pdf_w is the
 * throughput; pdf_w and pdf_rev_w are then the probabilities of picking
 * that delta event from wo and from wi. */
CALLED int bsdf_sample(const Bsdf *bs, V3 wo, float u0, float u1, float u2, int mode, BsdfSample *s)
{
	float so = bsdf_side(bs, wo);
	if (so == 0.0f)
		return 0;
	V3 lo = bsdf_local(bs, wo, so);
	if (!(lo.z > 0.0f))
		return 0;
	float eta = bsdf_eta(bs, so);
	BsdfLobes p = bsdf_lobes(bs, lo.z);
	int smooth = bsdf_smooth(bs), reflect = 1;
	V3 li;
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
			s->wi = bsdf_world(bs, li, so);
			return bsdf_side(bs, s->wi) == so;
		}
		li = bsdf_reflect(lo, ggx_sample_visible(lo, bs->alpha, u1, u2));
	} else if (u0 < p.metal + p.coat) {
		li = bsdf_reflect(lo, ggx_sample_visible(lo, bsdf_coat_alpha(bs), u1, u2));
	} else if (u0 < p.metal + p.coat + p.diffuse) {
		li = sample_cosine_hemisphere(u1, u2);
	} else if (p.glass > 0.0f) {
		float ug = fmin((u0 - (p.metal + p.coat + p.diffuse)) / p.glass, 0.99999994f);
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
			s->wi = bsdf_world(bs, li, so);
			float si = bsdf_side(bs, s->wi);
			if (si != (reflect ? so : -so))
				return 0;
			V3 ri = bsdf_local(bs, s->wi, si);
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
	s->wi = bsdf_world(bs, li, so);
	s->delta = 0;
	s->f = bsdf_eval(bs, wo, s->wi, mode, &s->pdf_w, &s->pdf_rev_w);
	return s->pdf_w > 0.0f;
}

#endif
