/* bsdf_sample.h — sampling wi from wo: the core's lobes, the layers',
 * bsdf_sample and bsdf_sample_fwd. */
#ifndef AJAR_BSDF_SAMPLE_H
#define AJAR_BSDF_SAMPLE_H
#include "material/bsdf_delta.h"

/* Returns 0 if no sample. For delta samples f is the lobe's weight (Fresnel
 * included) divided by |wi.n| (shading normal), so f |wi.n| / pdf_w is the
 * throughput (in a bent normal m, times |wl . m| / |wl . n| as every f,
 * bsdf.h's top); pdf_w and pdf_rev_w are then the probabilities of picking that delta
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
