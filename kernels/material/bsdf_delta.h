/* bsdf_delta.h — smooth glass's choice between reflection and refraction,
 * smooth thin glass's null event and its transmittance. */
#ifndef AJAR_BSDF_DELTA_H
#define AJAR_BSDF_DELTA_H
#include "material/bsdf_eval.h"

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

#endif
