/* bsdf_eval.h — bsdf_eval and bsdf_pdf_w, the entry points that evaluate,
 * and the lobes cached for a vertex's wo. */
#ifndef AJAR_BSDF_EVAL_H
#define AJAR_BSDF_EVAL_H
#include "material/bsdf_layers.h"

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

#endif
