/* bsdf_check.h — what the BSDF tests (tests/unit/test_bsdf*.c) share: the
 * material families and outgoing directions they try, a Bsdf made from
 * them, the chi-square test of bsdf_sample against bsdf_eval's pdf_w, the
 * Monte Carlo albedo, and the tilted normals of the bent-normal cases. */
#ifndef AJAR_BSDF_CHECK_H
#define AJAR_BSDF_CHECK_H
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "material/bsdf.h"
#include "sample/rng.h"

#define N_ALBEDO 100000
#define ALPHA_TOTAL 1e-3

typedef struct {
	const char *name;
	float r, g, b, metallic, roughness, transmission, ior, specular;
	int volume; /* refracting solid glass (KHR_materials_volume); else transmission is thin-walled */
} Mat;

#define N_MATS 17
extern const Mat mats[N_MATS];

/* Outgoing directions as (cos theta, phi) about the shading normal;
 * negative cos is the back side. */
static const float wos[][2] = {{0.9f, 0.3f}, {0.5f, 2.0f}, {0.15f, 4.0f}, {-0.6f, 1.0f}};
#define N_WOS ((int)(sizeof(wos) / sizeof(wos[0])))

Material material(const Mat *m);
/* A tilted normal so the frame code is exercised; ns == ng. */
Bsdf make_bsdf(const Material *m);
V3 dir(const Bsdf *bs, float z, float phi);
int finite3(V3 v);
/* Relative closeness; values below 1e-2 are compared absolutely (float
 * cancellation in 1 - F near total internal reflection). */
int rel_close(float a, float b, float tol);
/* 20,000 random direction pairs: f_radiance(wo, wi) == f_importance(wi, wo)
 * (the adjoint BSDF), f(wo, wi) == f(wi, wo) where both lie on one side and
 * `reciprocal` (reflection), pdf_rev_w(wo, wi) == pdf_w(wi, wo), every value
 * finite; f within tol relative. Fails the test naming `name`; returns how
 * many pairs had f != 0. */
int reciprocity_check(const char *name, const Bsdf *bs, Rng *r, float tol, int reciprocal);
/* One chi-square test; returns its p-value. Also checks that the pdf
 * integrates to the non-delta probability and that samples agree with eval. */
double chi2_run(const char *name, uint seed, const Bsdf *bsp, V3 wo, int wo_index, int mode, double alpha_each);
/* Monte Carlo albedo of f |cos_i| / pdf per channel, delta samples included.
 * Importance mode is the energy-conservation integral for every BSDF (the
 * radiance mode of glass from the inside is scaled by eta^2 on purpose). */
V3 albedo(const Bsdf *bs, V3 wo, int mode, uint seed, V3 *sigma);
/* A shading normal tilted from ng = +z by `deg` degrees toward +x (a
 * normal map), and a direction at elevation `elev` degrees above ng with
 * azimuth `az` degrees from +x (180: the side the normal faces away from). */
V3 tilted_n(float deg);
V3 elev_dir(float elev, float az);

#endif
