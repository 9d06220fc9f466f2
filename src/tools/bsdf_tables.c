/* bsdf_tables.c — build tool: integrates the GGX microfacet lobes of
 * kernels/material/microfacet.h into the directional-albedo tables that bsdf.h's
 * energy compensation reads, and prints them as kernels/material/bsdf_tables.h.
 *
 * For roughness r = sqrt(alpha) and mu = cos(theta_o) on a grid:
 *   E1(mu, r) = integral of D G2 / (4 mu mu_i) mu_i dw_i    (Fresnel 1),
 *   Ew(mu, r) = the same with Schlick's weight (1 - wo.h)^5,
 * so a Schlick Fresnel F0 + (1 - F0)(1 - c)^5 scaled by s has the albedo
 * s (F0 E1 + (1 - F0) Ew) exactly; and over r alone the cosine-weighted
 * averages Eavg = 2 integral E(mu) mu dmu of the tables as bsdf.h
 * interpolates them (piecewise linear in sqrt(mu)), so the compensation lobes
 * built from them give a white furnace exactly what the tables lack.
 *
 * Each entry is the expectation of G2 / G1(wo) over the visible normals
 * (a reflected direction below the surface counts 0), by the midpoint rule
 * on a Q x Q grid of the same visible-normal warp the kernels sample with.
 * For glass, per ior on a third axis: Go and Gi, the albedo of reflection
 * and transmission together from outside and from inside (total internal
 * reflection included), their averages, and the mean Fresnel reflectance
 * Favg from outside.
 *
 * Sheen (KHR_materials_sheen's Charlie lobe, microfacet.h): its albedo
 * with colour 1, Esr(mu, r), over sheen roughness r and mu, exceeds 1 near
 * grazing below r = 0.5 (7.4 at r = 0.07, mu = 0.001; 1.7 at r = 0.3,
 * mu = 0.01: the fitted shadowing lets more out than comes in). The kernels
 * divide the lobe by N(mu_o) N(mu_i), N = max(1, Esr) read from the first
 * table, which bounds its albedo by 1 and leaves r >= 0.5 as it is; the
 * second table is that lobe's albedo Es(mu, r) as the kernels interpolate
 * N, and the cosine-weighted average per r is Es's, for the layering's
 * energy compensation.
 *
 * The clear coat (KHR_materials_clearcoat, ior 1.5): the albedo of GGX
 * reflection with the exact dielectric Fresnel, Ecc(mu, r), on 24 x 24
 * nodes (the constant memory left: 64 KB in all on NVIDIA), and its mean.
 *
 * Anisotropic GGX (KHR_materials_anisotropy: alpha_b = r^2, alpha_t =
 * alpha_b + (1 - alpha_b) s^2 for strength s): E1 depends on wo's azimuth
 * phi from the anisotropy direction too. Tabulated is the residual
 * R(r, s, mu, phi) = E1(mu, phi) - E1iso(alpha_rms, mu), E1iso read from
 * the isotropic table as the kernels interpolate it, alpha_rms =
 * sqrt((alpha_t^2 + alpha_b^2) / 2): the residual is small and smooth, so a
 * coarse grid (quadrilinear, 9 x 7 x 10 x 6) holds it within 1e-3 on
 * average (a plain 4-D table of E1 needs five times the nodes for that).
 * Along the smooth axis near grazing E1 climbs steeply in the last 20
 * degrees of phi at low roughness: the azimuth axis is warped, tan phi =
 * (alpha_t / alpha_b)^(1/4) tan psi with nodes uniform in psi, which puts
 * nodes there (a white furnace of anisotropic metal at cos 0.08, r 0.2 to
 * 0.3, erred by up to 3.2% with nodes uniform in phi, 1.7% so; the
 * exponent 1/2 overshoots, 2.1% at 45 degrees). Left: 3.2% at cos 0.08 for
 * r <= 0.1 at strength 0.3, between the strength nodes, where the
 * residual grows fast from 0 at s = 0. Its average over mu (cosine weighted)
 * and phi per (r, s) node makes E1avg with the isotropic average; over
 * phi by a fine midpoint rule of the interpolant, linear in psi.
 *
 * The output depends only on this file and microfacet.h, in float as the
 * kernels compute, summed in double: the same bits on every run. */
#include <stdio.h>
#include <string.h>

#include "material/microfacet.h"

#define NR 32   /* roughness nodes, r = i / (NR - 1) */
#define NMU 32  /* cosine nodes, sqrt(mu) = j / (NMU - 1) */
#define Q 128   /* quadrature points per axis */
#define GE 16   /* glass: ior nodes, t = (ior - 1) / (ior + 1) = GT_MAX k / (GE - 1) */
#define GR 16   /* glass: roughness nodes */
#define GMU 16  /* glass: cosine nodes */
#define GQ 64   /* glass: quadrature points per axis */
#define GT_MAX 0.6f /* ior 4, bsdf.h's BSDF_MAX_IOR */
#define MIN_IOR 1.01f /* bsdf.h's BSDF_MIN_IOR: ior node 0 */
#define MIN_ALPHA 1e-3f /* bsdf.h's BSDF_MIN_ALPHA: the tables start at it */
#define MU0 1e-4f /* stands in for mu = 0, where wo lies in the surface */
#define SR 16   /* sheen roughness nodes, r = SHEEN_MIN_R + (1 - SHEEN_MIN_R) (i / (SR - 1))^2: the lobe
		 * changes fastest at low roughness (its exponent is 1 / r^2) */
#define SQ 256  /* sheen: quadrature points per axis */
#define CR 24   /* clear coat: roughness nodes, r = i / (CR - 1) (alpha >= MIN_ALPHA) */
#define CMU 24  /* clear coat: cosine nodes, sqrt(mu) = j / (CMU - 1) */
#define CC_IOR 1.5f /* KHR_materials_clearcoat's fixed ior */
#define AR 9    /* anisotropy: roughness nodes, sqrt(alpha_b) = i / (AR - 1) */
#define AS 7    /* strength nodes, s = j / (AS - 1) */
#define AMU 10  /* cosine nodes, sqrt(mu) = k / (AMU - 1) */
#define APHI 6  /* azimuth nodes, phi = (pi / 2) l / (APHI - 1) */

static float node_alpha(int i, int n)
{
	float r = (float)i / (n - 1);
	return fmax(r * r, MIN_ALPHA);
}

/* Nodes are uniform in t = sqrt(mu): E changes fastest near grazing. */
static float node_mu(int j, int n)
{
	float t = (float)j / (n - 1);
	return j == 0 ? MU0 : t * t;
}

static float node_ior(int k)
{
	float t = GT_MAX * k / (GE - 1);
	return k == 0 ? MIN_IOR : (1.0f + t) / (1.0f - t);
}

/* E1 and Ew at one node. */
static void albedo(float mu, float alpha, double *e1, double *ew)
{
	V3 wo = v3(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
	float lo = ggx_lambda(wo, alpha);
	double s1 = 0, sw = 0;
	for (int a = 0; a < Q; a++)
		for (int b = 0; b < Q; b++) {
			V3 h = ggx_sample_visible(wo, alpha, (a + 0.5f) / Q, (b + 0.5f) / Q);
			V3 wi = bsdf_reflect(wo, h);
			if (!(wi.z > 0.0f))
				continue;
			double g = (1.0 + lo) / (1.0 + lo + ggx_lambda(wi, alpha));
			s1 += g;
			sw += g * bsdf_schlick_w(v3_dot(wo, h));
		}
	*e1 = s1 / ((double)Q * Q);
	*ew = sw / ((double)Q * Q);
}

/* Sheen albedo at one node: h drawn from D cos(theta_h) (the CDF of
 * theta_h is sin^(2 + 1/a)), so E = integral D G / (4 mu_o) dw_i becomes
 * the mean of G |wo.h| / (mu_o cos theta_h) over h, 0 where the mirror
 * direction lies below the surface. */
static const double *sheen_norm; /* Esr as computed, for N; NULL: N = 1 */
static float sheen_n(float r, float mu);

static double sheen_albedo(float mu, float r)
{
	float alpha = sheen_alpha(r);
	float no = sheen_norm ? sheen_n(r, mu) : 1.0f;
	V3 wo = v3(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
	float lo = sheen_lambda(mu, alpha), k = 1.0f / (2.0f + 1.0f / alpha);
	double s = 0;
	for (int a = 0; a < SQ; a++)
		for (int b = 0; b < SQ; b++) {
			float st = pow((a + 0.5f) / SQ, k), ct = sqrt(fmax(0.0f, 1.0f - st * st));
			float ph = 2.0f * AJAR_PI * (b + 0.5f) / SQ;
			V3 h = v3(st * cos(ph), st * sin(ph), ct);
			float c = v3_dot(wo, h);
			V3 wi = bsdf_reflect(wo, h);
			if (!(c > 0.0f) || !(wi.z > 0.0f) || !(ct > 0.0f))
				continue;
			float ni = sheen_norm ? sheen_n(r, wi.z) : 1.0f;
			s += (double)c / ((1.0 + lo + sheen_lambda(wi.z, alpha)) * mu * ct * no * ni);
		}
	return s / ((double)SQ * SQ);
}

/* N = max(1, Esr) as bsdf.h reads it: bilinear in (r, sqrt(mu)). */
static float sheen_n(float r, float mu)
{
	float x = sqrt(fmin(fmax((r - SHEEN_MIN_R) / (1.0f - SHEEN_MIN_R), 0.0f), 1.0f)) * (SR - 1);
	float y = sqrt(fmin(fmax(mu, 0.0f), 1.0f)) * (NMU - 1);
	int i = x < SR - 2 ? (int)x : SR - 2, j = y < NMU - 2 ? (int)y : NMU - 2;
	float wr = x - (float)i, wm = y - (float)j;
	const double *t = sheen_norm;
	float r00 = (float)t[i * NMU + j], r01 = (float)t[i * NMU + j + 1];
	float r10 = (float)t[(i + 1) * NMU + j], r11 = (float)t[(i + 1) * NMU + j + 1];
	float v0 = r00 + (r01 - r00) * wm, v1 = r10 + (r11 - r10) * wm;
	return fmax(v0 + (v1 - v0) * wr, 1.0f);
}

/* Anisotropic E1 at (mu, phi) for roughness ax along x, ay along y. */
static double aniso_albedo(float mu, float phi, float ax, float ay)
{
	float sm = sqrt(fmax(0.0f, 1.0f - mu * mu));
	V3 wo = v3(sm * cos(phi), sm * sin(phi), mu);
	float lo = ggx_lambda_aniso(wo, ax, ay);
	double s = 0;
	for (int a = 0; a < Q; a++)
		for (int b = 0; b < Q; b++) {
			V3 h = ggx_sample_visible_aniso(wo, ax, ay, (a + 0.5f) / Q, (b + 0.5f) / Q);
			V3 wi = bsdf_reflect(wo, h);
			if (!(wi.z > 0.0f))
				continue;
			s += (1.0 + lo) / (1.0 + lo + ggx_lambda_aniso(wi, ax, ay));
		}
	return s / ((double)Q * Q);
}

/* The isotropic E1 table as bsdf.h reads it (bsdf_tab_at, bsdf_tab2), in
 * float from the floats printed. */
static float e1_lookup(const double *e1, float alpha, float mu)
{
	float x = fmin(fmax(sqrt(fmax(alpha, 0.0f)), 0.0f), 1.0f) * (NR - 1);
	float y = sqrt(fmin(fmax(mu, 0.0f), 1.0f)) * (NMU - 1);
	int i = x < NR - 2 ? (int)x : NR - 2, j = y < NMU - 2 ? (int)y : NMU - 2;
	float wr = x - (float)i, wm = y - (float)j;
	float r00 = (float)e1[i * NMU + j], r01 = (float)e1[i * NMU + j + 1];
	float r10 = (float)e1[(i + 1) * NMU + j], r11 = (float)e1[(i + 1) * NMU + j + 1];
	float v0 = r00 + (r01 - r00) * wm, v1 = r10 + (r11 - r10) * wm;
	return v0 + (v1 - v0) * wr;
}

/* glTF's anisotropic roughness at table node (i, j). */
static void aniso_node(int i, int j, float *ax, float *ay)
{
	float r = (float)i / (AR - 1), st = (float)j / (AS - 1);
	*ay = fmax(r * r, MIN_ALPHA);
	*ax = *ay + (1.0f - *ay) * st * st;
}

/* The clear coat's albedo at one node: GGX reflection with the exact
 * dielectric Fresnel at ior 1.5, as Blender's coat has it (Schlick's
 * falls 0.017 short at cos 0.55, a fifth of the coat there). */
static double coat_albedo(float mu, float alpha)
{
	V3 wo = v3(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
	float lo = ggx_lambda(wo, alpha);
	double s = 0;
	for (int a = 0; a < Q; a++)
		for (int b = 0; b < Q; b++) {
			V3 h = ggx_sample_visible(wo, alpha, (a + 0.5f) / Q, (b + 0.5f) / Q);
			V3 wi = bsdf_reflect(wo, h);
			if (!(wi.z > 0.0f))
				continue;
			s += bsdf_fresnel_dielectric(v3_dot(wo, h), CC_IOR) * (1.0 + lo) / (1.0 + lo + ggx_lambda(wi, alpha));
		}
	return s / ((double)Q * Q);
}

/* Rough dielectric (Walter et al. 2007, exact Fresnel): reflection and
 * transmission together, eta = eta_t / eta_i of wo's side. As energy
 * (importance transport: no eta^2 on refraction) each visible normal
 * reflects with weight F G2 / G1 and refracts with (1 - F) G2 / G1. */
static double glass_albedo(float mu, float alpha, float eta)
{
	V3 wo = v3(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
	float lo = ggx_lambda(wo, alpha);
	double s = 0;
	for (int a = 0; a < GQ; a++)
		for (int b = 0; b < GQ; b++) {
			V3 h = ggx_sample_visible(wo, alpha, (a + 0.5f) / GQ, (b + 0.5f) / GQ);
			float f = bsdf_fresnel_dielectric(v3_dot(wo, h), eta);
			V3 wr = bsdf_reflect(wo, h), wt;
			if (wr.z > 0.0f)
				s += f * (1.0 + lo) / (1.0 + lo + ggx_lambda(wr, alpha));
			if (f < 1.0f && bsdf_refract(wo, h, eta, &wt) && wt.z < 0.0f)
				s += (1.0 - f) * (1.0 + lo) / (1.0 + lo + ggx_lambda(wt, alpha));
		}
	return s / ((double)GQ * GQ);
}

/* Favg = 2 integral F(mu) mu dmu of the exact Fresnel from outside (eta > 1). */
static double fresnel_average(float eta)
{
	double s = 0;
	const int n = 4096;
	for (int j = 0; j < n; j++) {
		float mu = (j + 0.5f) / n;
		s += bsdf_fresnel_dielectric(mu, eta) * mu;
	}
	return 2 * s / n;
}

/* 2 integral_0^1 E(mu) mu dmu = 4 integral_0^1 E t^3 dt of the interpolant
 * of one row, linear in t between nodes (node 0 taken at t = 0): per
 * segment [a, b] of width h, E = E_a + (E_b - E_a) (t - a) / h integrates
 * against t^3 in closed form. */
static double cosine_average(const double *row, int n)
{
	double s = 0, h = 1.0 / (n - 1);
	for (int j = 0; j + 1 < n; j++) {
		double a = j * h, b = (j + 1) * h;
		double i3 = (b * b * b * b - a * a * a * a) / 4;           /* int t^3 */
		double i4 = (b * b * b * b * b - a * a * a * a * a) / 5 - a * i3; /* int (t - a) t^3 */
		s += row[j] * i3 + (row[j + 1] - row[j]) / h * i4;
	}
	return 4 * s;
}

static void print_table(const char *name, const char *what, const double *v, int n)
{
	printf("/* %s */\n", what);
	printf("#ifndef AJAR_DEVICE\nstatic\n#endif\nCONSTANT float %s[%d] = {", name, n);
	for (int i = 0; i < n; i++) {
		char num[32];
		snprintf(num, sizeof num, "%.9g", (double)(float)v[i]);
		printf("%s%s%sf%s", i % 6 ? " " : "\n\t", num, strpbrk(num, ".e") ? "" : ".0", i + 1 < n ? "," : "\n");
	}
	printf("};\n\n");
}

int main(void)
{
	static double e1[NR * NMU], ew[NR * NMU], e1avg[NR], ewavg[NR];
	static double go[GE * GR * GMU], gi[GE * GR * GMU], goavg[GE * GR], giavg[GE * GR], gfavg[GE];
	for (int i = 0; i < NR; i++) {
		for (int j = 0; j < NMU; j++)
			albedo(node_mu(j, NMU), node_alpha(i, NR), &e1[i * NMU + j], &ew[i * NMU + j]);
		e1avg[i] = cosine_average(&e1[i * NMU], NMU);
		ewavg[i] = cosine_average(&ew[i * NMU], NMU);
	}
	for (int k = 0; k < GE; k++)
		gfavg[k] = fresnel_average(node_ior(k));
	for (int k = 0; k < GE; k++)
		for (int i = 0; i < GR; i++) {
			int row = k * GR + i;
			for (int j = 0; j < GMU; j++) {
				go[row * GMU + j] = glass_albedo(node_mu(j, GMU), node_alpha(i, GR), node_ior(k));
				gi[row * GMU + j] = glass_albedo(node_mu(j, GMU), node_alpha(i, GR), 1.0f / node_ior(k));
			}
			goavg[row] = cosine_average(&go[row * GMU], GMU);
			giavg[row] = cosine_average(&gi[row * GMU], GMU);
		}
	static double cc[CR * CMU], ccavg[CR];
	for (int i = 0; i < CR; i++) {
		for (int j = 0; j < CMU; j++)
			cc[i * CMU + j] = coat_albedo(node_mu(j, CMU), node_alpha(i, CR));
		ccavg[i] = cosine_average(&cc[i * CMU], CMU);
	}
	static double shr[SR * NMU], sh[SR * NMU], shavg[SR], an[AR * AS * AMU * APHI], anavg[AR * AS];
	for (int pass = 0; pass < 2; pass++) {
		sheen_norm = pass ? shr : NULL;
		for (int i = 0; i < SR; i++) {
			float t = (float)i / (SR - 1), r = SHEEN_MIN_R + (1.0f - SHEEN_MIN_R) * t * t;
			for (int j = 0; j < NMU; j++)
				(pass ? sh : shr)[i * NMU + j] = sheen_albedo(node_mu(j, NMU), r);
		}
	}
	for (int i = 0; i < SR; i++)
		shavg[i] = cosine_average(&sh[i * NMU], NMU);
	for (int i = 0; i < AR; i++)
		for (int j = 0; j < AS; j++) {
			float ax, ay;
			aniso_node(i, j, &ax, &ay);
			float arms = sqrt(0.5f * (ax * ax + ay * ay));
			double avg = 0, ravg[APHI];
			for (int l = 0; l < APHI; l++) {
				double *row = &an[((i * AS + j) * APHI + l) * AMU];
				/* Node l at the warped azimuth psi = (pi / 2) l / (APHI - 1):
				 * tan phi = k tan psi, k = sqrt(ax / ay) (bsdf.h). */
				float psi = 0.5f * AJAR_PI * l / (APHI - 1), kk = sqrt(sqrt(ax / ay));
				float phi = atan2(kk * sin(psi), cos(psi));
				for (int k = 0; k < AMU; k++) {
					float mu = node_mu(k, AMU);
					row[k] = aniso_albedo(mu, phi, ax, ay) - e1_lookup(e1, arms, mu);
				}
				ravg[l] = cosine_average(row, AMU);
			}
			/* The mean over phi of the interpolant, linear in psi between
			 * nodes: midpoint rule in phi, fine. */
			for (int q = 0; q < 4096; q++) {
				float phi = 0.5f * AJAR_PI * (q + 0.5f) / 4096;
				float psi = atan2(sin(phi), sqrt(sqrt(ax / ay)) * cos(phi)) * (APHI - 1) / (0.5f * AJAR_PI);
				int l = psi < APHI - 2 ? (int)psi : APHI - 2;
				avg += (ravg[l] + (ravg[l + 1] - ravg[l]) * (psi - l)) / 4096;
			}
			anavg[i * AS + j] = avg;
		}
	printf("/* bsdf_tables.h — generated by src/tools/bsdf_tables.c (make kernels/material/bsdf_tables.h).\n"
	       " * Do not edit. GGX directional albedos, row i: r = sqrt(alpha) = i / %d\n"
	       " * (alpha >= %g), column j: sqrt(mu) = sqrt(cos theta_o) = j / %d. */\n",
	       NR - 1, (double)MIN_ALPHA, NMU - 1);
	printf("/* Glass: block k: t = (ior - 1) / (ior + 1) = %g k / %d (ior >= %g), row i:\n"
	       " * r = i / %d, column j: sqrt(mu) = j / %d. */\n",
	       (double)GT_MAX, GE - 1, (double)MIN_IOR, GR - 1, GMU - 1);
	printf("#ifndef AJAR_BSDF_TABLES_H\n#define AJAR_BSDF_TABLES_H\n#include \"base/compat.h\"\n\n");
	printf("#define BSDF_TAB_NR %d\n#define BSDF_TAB_NMU %d\n", NR, NMU);
	printf("#define BSDF_TAB_GE %d\n#define BSDF_TAB_GR %d\n#define BSDF_TAB_GMU %d\n#define BSDF_TAB_GT_MAX %.9gf\n\n", GE, GR,
	       GMU, (double)GT_MAX);
	print_table("bsdf_tab_e1", "E1(mu, r): albedo with Fresnel 1", e1, NR * NMU);
	print_table("bsdf_tab_ew", "Ew(mu, r): albedo weighted by (1 - wo.h)^5", ew, NR * NMU);
	print_table("bsdf_tab_e1avg", "2 int E1 mu dmu per roughness", e1avg, NR);
	print_table("bsdf_tab_ewavg", "2 int Ew mu dmu per roughness", ewavg, NR);
	print_table("bsdf_tab_go", "Glass from outside (eta = ior): reflection + transmission", go, GE * GR * GMU);
	print_table("bsdf_tab_gi", "Glass from inside (eta = 1 / ior)", gi, GE * GR * GMU);
	print_table("bsdf_tab_goavg", "2 int Go mu dmu per ior and roughness", goavg, GE * GR);
	print_table("bsdf_tab_giavg", "2 int Gi mu dmu per ior and roughness", giavg, GE * GR);
	print_table("bsdf_tab_gfavg", "2 int F mu dmu of the exact Fresnel from outside, per ior", gfavg, GE);
	printf("/* Clear coat (KHR_materials_clearcoat): GGX reflection with the exact Fresnel at ior %g; row i:\n"
	       " * r = i / %d, column j: sqrt(mu) = j / %d. */\n",
	       (double)CC_IOR, CR - 1, CMU - 1);
	printf("#define BSDF_TAB_CR %d\n#define BSDF_TAB_CMU %d\n", CR, CMU);
	print_table("bsdf_tab_ecc", "Ecc(mu, r): the clear coat's single-scattering albedo", cc, CR * CMU);
	print_table("bsdf_tab_eccavg", "2 int Ecc mu dmu per roughness", ccavg, CR);
	printf("/* Sheen (KHR_materials_sheen): row i: r = %g + %g (i / %d)^2, column j as above. */\n",
	       (double)SHEEN_MIN_R, 1.0 - (double)SHEEN_MIN_R, SR - 1);
	printf("#define BSDF_TAB_SR %d\n", SR);
	print_table("bsdf_tab_sheenr", "Esr(mu, r): the Charlie lobe's albedo with colour 1", shr, SR * NMU);
	print_table("bsdf_tab_sheen", "Es(mu, r): the albedo of the lobe divided by max(1, Esr) at both ends", sh,
		    SR * NMU);
	print_table("bsdf_tab_sheenavg", "2 int Es mu dmu per sheen roughness", shavg, SR);
	printf("/* Anisotropic GGX: block (i, j): sqrt(alpha_b) = i / %d, s = j / %d, row l: phi = (pi / 2) l / %d,\n"
	       " * column k: sqrt(mu) = k / %d. */\n",
	       AR - 1, AS - 1, APHI - 1, AMU - 1);
	printf("#define BSDF_TAB_AR %d\n#define BSDF_TAB_AS %d\n#define BSDF_TAB_AMU %d\n#define BSDF_TAB_APHI %d\n", AR, AS,
	       AMU, APHI);
	printf("#ifndef AJAR_NO_ANISOTROPY\n");
	print_table("bsdf_tab_aniso", "E1(mu, phi) - E1iso(alpha_rms, mu) of anisotropic GGX", an, AR * AS * AMU * APHI);
	print_table("bsdf_tab_anisoavg", "its mean over mu (2 int .. mu dmu) and phi per (r, s)", anavg, AR * AS);
	printf("#endif\n");
	printf("#endif\n");
	return 0;
}
