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
/* The parts in the order they build on each other. */
#include "material/bsdf_types.h"
#include "material/bsdf_lookup.h"
#include "material/bsdf_setup.h"
#include "material/bsdf_albedo.h"
#include "material/bsdf_frame.h"
#include "material/bsdf_eval_lobes.h"
#include "material/bsdf_layers.h"
#include "material/bsdf_eval.h"
#include "material/bsdf_delta.h"
#include "material/bsdf_sample.h"
#endif
