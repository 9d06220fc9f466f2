/* bsdf_types.h — the Bsdf: its constants and flags, the lobe selection
 * record, the sample record. The model is in bsdf.h's top comment. */
#ifndef AJAR_BSDF_TYPES_H
#define AJAR_BSDF_TYPES_H
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
#define BSDF_TILTED (1 << 30)  /* in Bsdf.flags: n differs from ng, normals may bend (bsdf.h's top) */
#define BSDF_LAMBERT (1 << 29) /* in Bsdf.flags: only the diffuse lobe (bsdf_lambert) */
#define BSDF_LAYERED (1 << 28) /* in Bsdf.flags: a sheen or a clear coat over the core (bsdf.h's top) */
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
	/* Layers (bsdf.h's top): sheen colour, roughness (perceptual), max(colour)
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

#endif
