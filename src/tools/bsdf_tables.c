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
	printf("#endif\n");
	return 0;
}
