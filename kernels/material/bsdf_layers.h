/* bsdf_layers.h — the sheen and the clear coat over the core (bsdf.h's
 * top): what they pass each way, their own lobes, their f. */
#ifndef AJAR_BSDF_LAYERS_H
#define AJAR_BSDF_LAYERS_H
#include "material/bsdf_eval_lobes.h"

#ifndef AJAR_NO_LAYERS
/* The core's f (all but the layers, bsdf.h's top), its diffuse-like part added
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
 * layers' normals, bsdf.h's top). */
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

/* What passes the layers each way (bsdf.h's top): *tg for the core's
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
 * in importance mode), times |wl . m| / |wl . n| as bent lobes are
 * (bsdf.h's top), the sheen's under the clear coat by tsh; and, added to *pdf,
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

/* bsdf_eval of a layered BSDF (bsdf.h's top). */
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

#endif
