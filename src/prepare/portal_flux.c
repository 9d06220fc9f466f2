/* portal_flux.c — the direct light that arrives through each portal
 * triangle from each of its sides, estimated at load time with the
 * kernels' own code run on the host: from uniform points on the triangle,
 * cosine-distributed rays toward the side find the environment where they
 * escape, and next-event samples of the emitters and punctual lights (with
 * shadow rays) find those behind that side. Per side, the flux is
 *     Phi = A (pi E[L_env escaping] + E[L_e cos cos' / (d^2 p_A)]),
 * a punctual light's term E_perp cos / p_select.
 * From it:
 *   - env_side: the side the environment is seen through (next-event
 *     estimation through portals, kernels/light/env_portal.h), 0 if neither;
 *   - side_plus: the probability that an intermediate subpath's <- half
 *     leaves toward +n, SIDE_FLOOR + (1 - 2 SIDE_FLOOR) Phi+ / (Phi+ + Phi-);
 *   - pdf_select: the triangle choice, (1 - AREA_SHARE) by flux and
 *     AREA_SHARE by area, a defence for what direct light misses (light
 *     that arrives after a bounce).
 * The kernels' densities read these numbers, so any values are unbiased;
 * the estimate only decides how well the samples are spent. Fixed seeds:
 * a scene always gets the same tables. */
#include "prepare/portal_flux.h"

#include <stdlib.h>

#include "core/error.h"
#include "prepare/light_tables.h"
#include "light/lights.h"
#include "sample/rng.h"
#include "geom/surface.h"
#include "geom/visibility.h"

#define FLUX_SAMPLES 2048
#define SIDE_FLOOR 0.1f
#define AREA_SHARE 0.25

/* Direct light arriving at triangle pt from side `side` (+1 / -1): the
 * environment's share in env[0], the emitters' in emit[0]. */
static void side_flux(const SceneView *sc, const PortalTri *pt, uint32_t index, int side, double *env, double *emit)
{
	V3 n = v3_scale(pt->n, (float)side), t, b;
	v3_basis(n, &t, &b);
	double se = 0.0, sl = 0.0;
	Rng rng = rng_init(0x9e3779b9u, index, side > 0 ? 1u : 2u, 7u);
	for (int i = 0; i < FLUX_SAMPLES; i++) {
		V3 p, ng;
		sample_triangle_point(pt->p0, pt->p1, pt->p2, rng_f(&rng), rng_f(&rng), &p, &ng);
		float u1 = rng_f(&rng), u2 = rng_f(&rng);
		V3 d = v3_from_local(sample_cosine_hemisphere(u1, u2), t, b, n);
		/* Panes in the opening let the sky through (geom/visibility.h). */
		V3 Tsky = ray_transmittance(sc, p, d, AJAR_INF);
		if (!v3_is_zero(Tsky))
			se += v3_lum(v3_mul(env_radiance(sc, d), Tsky));
		/* The emitters: a point by power, seen from this side; or a
		 * punctual light, chosen in the same table. */
		/* Drawn in the order gcc evaluated the three arguments of the
		 * emitter_sample call this replaced (right to left), so the
		 * tables of scenes without punctual lights stay as they were. */
		float pdf_a, ub = rng_f(&rng), ua = rng_f(&rng), u_sel = rng_f(&rng);
		V3 q, nq;
		int k = light_pick(sc, u_sel);
		if (k < 0)
			continue;
		if (k >= sc->params->num_emitters) {
			GLOBAL const PunctualLight *l = &sc->punctual[k - sc->params->num_emitters];
			V3 wi;
			float dist;
			V3 E = punctual_arrive(l, p, &wi, &dist);
			float cos_p = v3_dot(wi, n);
			if (!(cos_p > 0.0f) || !(l->pdf_select > 0.0f) || v3_is_zero(E))
				continue;
			V3 T = dist < AJAR_INF ? segment_transmittance(sc, p, n, l->pos, v3_neg(wi))
					       : ray_transmittance(sc, p, wi, AJAR_INF);
			if (!v3_is_zero(T))
				sl += v3_lum(v3_mul(E, T)) * cos_p / l->pdf_select;
			continue;
		}
		int tri = emitter_point(sc, k, ua, ub, &q, &nq, &pdf_a);
		if (!(pdf_a > 0.0f))
			continue;
		V3 to = v3_sub(q, p);
		float d2 = v3_len2(to);
		if (!(d2 > 0.0f))
			continue;
		V3 w = v3_scale(to, 1.0f / sqrt(d2));
		float cos_p = v3_dot(w, n), cos_q = -v3_dot(w, nq);
		if (!(cos_p > 0.0f) || !(cos_q > 0.0f))
			continue;
		V3 T = segment_transmittance(sc, p, n, q, nq);
		if (v3_is_zero(T))
			continue;
		sl += v3_lum(v3_mul(emitter_emission(sc, tri, q), T)) * cos_p * cos_q / (d2 * pdf_a);
	}
	*env = pt->area * AJAR_PI * se / FLUX_SAMPLES;
	*emit = pt->area * sl / FLUX_SAMPLES;
}

ajar_status portal_flux_build(const SceneView *sc, PortalTri *portals, uint32_t n, float *portal_cdf)
{
	if (n == 0)
		return AJAR_OK;
	double *w = calloc(n, sizeof *w), *flux = calloc(n, sizeof *flux);
	if (!w || !flux) {
		free(w);
		free(flux);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "portals: out of memory for %u portal triangles", n);
	}
	double area_total = 0.0, flux_total = 0.0;
	for (uint32_t j = 0; j < n; j++) {
		PortalTri *pt = &portals[j];
		double env_p, emit_p, env_m, emit_m;
		side_flux(sc, pt, j, 1, &env_p, &emit_p);
		side_flux(sc, pt, j, -1, &env_m, &emit_m);
		pt->env_side = env_p > env_m ? 1 : (env_m > 0.0 ? -1 : 0);
		double plus = env_p + emit_p, minus = env_m + emit_m;
		pt->side_plus = plus + minus > 0.0 ? SIDE_FLOOR + (1.0f - 2.0f * SIDE_FLOOR) * (float)(plus / (plus + minus))
						   : 0.5f;
		flux[j] = plus + minus;
		flux_total += flux[j];
		area_total += pt->area;
	}
	for (uint32_t j = 0; j < n; j++)
		w[j] = flux_total > 0.0 ? AREA_SHARE * portals[j].area / area_total + (1.0 - AREA_SHARE) * flux[j] / flux_total
					: portals[j].area;
	cdf_build(portal_cdf, w, n, 0);
	for (uint32_t j = 0; j < n; j++)
		portals[j].pdf_select = portal_cdf[j + 1] - portal_cdf[j];
	free(w);
	free(flux);
	return AJAR_OK;
}

/* The sun's share of the sky's power that comes in through the portals:
 * each texel of the sky image weighted by the portals' area projected
 * toward it from the side they see the sky through (env_side), so a sun
 * behind the wall, or low along it, counts for nothing or little. Walls
 * and eaves outside are not traced: the weight is geometric. It varies
 * smoothly, so it is evaluated at the centres of a grid of at most
 * SUN_GRID_W x SUN_GRID_H cells (cost: cells x portal triangles). */
#define SUN_GRID_W 256
#define SUN_GRID_H 128
typedef struct {
	const float *cell;
	uint32_t w, h, gw, gh;
} SunGrid;

static double projected_area(uint32_t x, uint32_t y, void *ctx)
{
	const SunGrid *g = ctx;
	return g->cell[(size_t)(y * g->gh / g->h) * g->gw + x * g->gw / g->w];
}

/* The portals' area projected toward each cell's centre from their sky
 * side, on the grid g (g->cell left NULL when out of memory). */
static void projected_area_grid(GLOBAL const Params *prm, const PortalTri *portals, uint32_t n, SunGrid *g)
{
	g->w = (uint32_t)prm->env_width;
	g->h = (uint32_t)prm->env_height;
	g->gw = g->w < SUN_GRID_W ? g->w : SUN_GRID_W;
	g->gh = g->h < SUN_GRID_H ? g->h : SUN_GRID_H;
	float *cell = malloc(sizeof(float) * g->gw * g->gh);
	g->cell = cell;
	if (!cell)
		return;
	for (uint32_t j = 0; j < g->gh; j++)
		for (uint32_t i = 0; i < g->gw; i++) {
			V3 d = env_dir(prm, (i + 0.5f) / g->gw, (j + 0.5f) / g->gh);
			double a = 0.0;
			for (uint32_t k = 0; k < n; k++) {
				float c = v3_dot(d, portals[k].n) * (float)portals[k].env_side;
				a += c > 0.0f ? portals[k].area * c : 0.0;
			}
			cell[(size_t)j * g->gw + i] = (float)a;
		}
}

float portal_sun_share(const SceneView *sc, const PortalTri *portals, uint32_t n)
{
	GLOBAL const Params *prm = sc->params;
	if (prm->env_type != ENV_IMAGE || n == 0)
		return 0.0f;
	SunGrid g;
	projected_area_grid(prm, portals, n, &g);
	if (!g.cell)
		return 0.0f;
	float share = env_sun_share_weighted(sc->env + ENV_PIXELS(g.w, g.h), g.w, g.h, projected_area, &g);
	free((float *)g.cell);
	return share;
}

ajar_status portal_sky_lines_build(GLOBAL const Params *prm, const PortalTri *portals, uint32_t n, float **env,
				   size_t *nenv)
{
	uint32_t w = (uint32_t)prm->env_width, h = (uint32_t)prm->env_height;
	size_t need = ENV_LINE_FLOATS((size_t)w, (size_t)h);
	float *grown = realloc(*env, sizeof(float) * need);
	if (!grown)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the sky's table through the portals (%ux%u)",
			       w, h);
	*env = grown;
	*nenv = need;
	SunGrid g;
	projected_area_grid(prm, portals, n, &g);
	double *wt = malloc(sizeof(double) * (size_t)w * h), *rows = malloc(sizeof(double) * h);
	if (!g.cell || !wt || !rows) {
		free((float *)g.cell);
		free(wt);
		free(rows);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the sky's table through the portals (%ux%u)",
			       w, h);
	}
	/* lum sin(theta) (the image's own weight) and the same times the
	 * projected area, each normalised, mixed. */
	const float *pix = grown + ENV_PIXELS(w, h);
	double sum = 0.0, sum_a = 0.0;
	for (uint32_t y = 0; y < h; y++) {
		double sin_theta = sin(AJAR_PI * ((double)y + 0.5) / h);
		for (uint32_t x = 0; x < w; x++) {
			const float *p = pix + 3 * ((size_t)y * w + x);
			float lum = v3_lum(v3(p[0], p[1], p[2]));
			double e = lum > 0.0f ? lum * sin_theta : 0.0;
			wt[(size_t)y * w + x] = e;
			sum += e;
			sum_a += e * projected_area(x, y, &g);
		}
	}
	double mix = sum_a > 0.0 ? SKY_LINES_PORTAL_MIX : 0.0;
	for (uint32_t y = 0; y < h; y++) {
		for (uint32_t x = 0; x < w; x++) {
			double e = wt[(size_t)y * w + x];
			wt[(size_t)y * w + x] = e > 0.0 ? (1.0 - mix) * e / sum + (mix > 0.0 ? mix * e * projected_area(x, y, &g) / sum_a : 0.0) : 0.0;
		}
		rows[y] = cdf_build(grown + ENV_LINE_CONDITIONAL(w, h) + (size_t)y * (w + 1), wt + (size_t)y * w, w, 1);
	}
	cdf_build(grown + ENV_LINE_MARGINAL(w, h), rows, h, 1);
	free((float *)g.cell);
	free(wt);
	free(rows);
	return AJAR_OK;
}
