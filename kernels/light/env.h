/* env.h — the environment: a constant colour or an equirectangular image,
 * evaluated and importance-sampled by its own 2-D table (src/prepare/light_tables.c).
 *
 * Convention: a unit direction d pointing from the scene out to the sky
 * maps to u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, row 0
 * at the top (+Y), so the image centre looks down -Z. That is the image
 * frame; the sky is turned by Params.env_rotation (radians) about +Y,
 * right-handed (positive = counter-clockwise seen from above, so +X turns
 * toward -Z): a feature at image-frame direction d is seen in the scene at
 * R(a) d. Every direction meets the image through env_texel (world to
 * image, R(-a)) and env_dir (image to world, R(a)); a rotation leaves
 * solid angles, hence every density below, unchanged. The angles are
 * fastmath.h's polynomials, not the builtins (PoCL's generic atan2, acos
 * and sin/cos argument reduction were a sixth of a sky-image `portal`
 * sample, and builtins may differ between devices): theta is
 * atan2(sin(theta), y), which keeps its accuracy at the poles where acos
 * loses it, and the rotation's cos and sin come from the host
 * (Params.env_rot_cos, env_rot_sin). Radiance is
 * piecewise constant per texel (nearest texel); a texel is sampled
 * uniformly in (u, v), so the solid-angle density is
 * p_row p_col W H / (2 pi^2 sin(theta)), and env_sample reports exactly
 * what env_pdf_w returns for the same direction. */
#ifndef AJAR_KERNEL_ENV_H
#define AJAR_KERNEL_ENV_H
#include "base/types.h"
#include "sample/sampling.h"
#include "base/fastmath.h"

/* d turned by `sign` x the environment's rotation about +Y. Exactly d
 * when there is no rotation, so unrotated skies keep their bits. */
INLINE V3 env_turn(GLOBAL const Params *prm, V3 d, float sign)
{
	if (prm->env_rotation == 0.0f)
		return d;
	float c = prm->env_rot_cos, s = sign * prm->env_rot_sin;
	return v3(c * d.x + s * d.z, d.y, c * d.z - s * d.x);
}

/* Scene direction of equirect coordinates (u, v) in [0,1]^2. */
INLINE V3 env_dir(GLOBAL const Params *prm, float u, float v)
{
	float sp, cp, st, ct;
	fast_sincos(2.0f * AJAR_PI * (u - 0.5f), &sp, &cp);
	fast_sincos(AJAR_PI * v, &st, &ct);
	return env_turn(prm, v3(st * sp, ct, -st * cp), 1.0f);
}

/* Equirect coordinates (u, v) of unit scene direction d; returns
 * sin(theta) of d. Within 2e-7 of the exact map (test_lights,
 * test_env_uv_exact). */
INLINE float env_uv(GLOBAL const Params *prm, V3 d, float *u, float *v)
{
	d = env_turn(prm, d, -1.0f);
	/* Not sqrt(1 - y^2): near the poles y rounds to 1 long before
	 * sin(theta) is negligible. */
	float st = sqrt(d.x * d.x + d.z * d.z);
	*u = 0.5f + fast_atan2(d.x, -d.z) * AJAR_INV_2PI;
	*v = fast_atan2(st, d.y) * AJAR_INV_PI;
	return st;
}

/* Texel (row, col) under unit scene direction d; returns sin(theta) of d. */
INLINE float env_texel(GLOBAL const Params *prm, V3 d, int *row, int *col)
{
	float u, v, st = env_uv(prm, d, &u, &v);
	int w = prm->env_width, h = prm->env_height;
	int c = (int)(u * (float)w), r = (int)(v * (float)h);
	*col = c < 0 ? 0 : (c >= w ? w - 1 : c);
	*row = r < 0 ? 0 : (r >= h ? h - 1 : r);
	return st;
}

INLINE V3 env_pixel(const SceneView *sc, int row, int col)
{
	int w = sc->params->env_width;
	GLOBAL const float *p = sc->env + ENV_PIXELS(w, sc->params->env_height) + 3 * (row * w + col);
	return v3(p[0], p[1], p[2]);
}

/* The image's two tables: its own (line = 0) and, with Params.env_lines,
 * the one of light subpaths that start on lines through the portals
 * (line = 1: texels weighted by the light they bring in through the
 * portals, src/prepare/portal_flux.c, portal_sky_lines_build). */
INLINE GLOBAL const float *env_marginal(const SceneView *sc, int line)
{
	int w = sc->params->env_width, h = sc->params->env_height;
	return sc->env + (line ? ENV_LINE_MARGINAL(w, h) : ENV_MARGINAL(w, h));
}

INLINE GLOBAL const float *env_conditional(const SceneView *sc, int line, int row)
{
	int w = sc->params->env_width, h = sc->params->env_height;
	return sc->env + (line ? ENV_LINE_CONDITIONAL(w, h) : ENV_CONDITIONAL(w, h)) + row * (w + 1);
}

/* Solid-angle density of table `line`'s sampling at texel (row, col). */
INLINE float env_table_pdf_w(const SceneView *sc, int line, int row, int col, float sin_theta)
{
	int w = sc->params->env_width, h = sc->params->env_height;
	if (!(sin_theta > 0.0f))
		return 0.0f;
	GLOBAL const float *marg = env_marginal(sc, line);
	GLOBAL const float *cond = env_conditional(sc, line, row);
	float p_uv = (marg[row + 1] - marg[row]) * (cond[col + 1] - cond[col]) * (float)(w * h);
	return p_uv / (2.0f * AJAR_PI * AJAR_PI * sin_theta);
}

/* Solid-angle density of the image's own sampling at texel (row, col). */
INLINE float env_texel_pdf_w(const SceneView *sc, int row, int col, float sin_theta)
{
	return env_table_pdf_w(sc, 0, row, col, sin_theta);
}

/* Radiance arriving from the sky along -d (d points to the sky). */
INLINE V3 env_radiance(const SceneView *sc, V3 d)
{
	GLOBAL const Params *prm = sc->params;
	if (prm->env_type == ENV_COLOR)
		return prm->env_color;
	if (prm->env_type != ENV_IMAGE)
		return v3(0.0f, 0.0f, 0.0f);
	int row, col;
	env_texel(prm, d, &row, &col);
	return env_pixel(sc, row, col);
}

/* env_radiance and env_pdf_w of one direction from one texel lookup. */
INLINE V3 env_radiance_pdf(const SceneView *sc, V3 d, float *pdf_w)
{
	GLOBAL const Params *prm = sc->params;
	*pdf_w = 0.0f;
	if (prm->env_type == ENV_COLOR) {
		*pdf_w = pdf_uniform_sphere_w();
		return prm->env_color;
	}
	if (prm->env_type != ENV_IMAGE)
		return v3(0.0f, 0.0f, 0.0f);
	int row, col;
	float sin_theta = env_texel(prm, d, &row, &col);
	*pdf_w = env_texel_pdf_w(sc, row, col, sin_theta);
	return env_pixel(sc, row, col);
}

/* Samples a sky direction *d by table `line` of the environment (env_marginal)
 * and returns its radiance; *pdf_w = 0 (and black) if there is none, or,
 * very rarely, if rounding carried the sample into a texel that has none. */
INLINE V3 env_table_sample(const SceneView *sc, int line, float u1, float u2, V3 *d, float *pdf_w)
{
	GLOBAL const Params *prm = sc->params;
	*pdf_w = 0.0f;
	*d = v3(0.0f, 1.0f, 0.0f);
	if (prm->env_type == ENV_COLOR) {
		*d = sample_uniform_sphere(u1, u2);
		*pdf_w = pdf_uniform_sphere_w();
		return prm->env_color;
	}
	if (prm->env_type != ENV_IMAGE)
		return v3(0.0f, 0.0f, 0.0f);
	int w = prm->env_width, h = prm->env_height;
	float p_row, p_col, ur, uc;
	int row = sample_cdf(env_marginal(sc, line), h, u1, &p_row, &ur);
	if (row < 0)
		return v3(0.0f, 0.0f, 0.0f);
	int col = sample_cdf(env_conditional(sc, line, row), w, u2, &p_col, &uc);
	if (col < 0)
		return v3(0.0f, 0.0f, 0.0f);
	/* The drawn texel's radiance is read now, so the load (a cache miss in
	 * a large image: a tenth of pt's time under a sky image) runs while d
	 * and its texel are computed; d's texel is nearly always this one. */
	V3 drawn = env_pixel(sc, row, col);
	int row_d = row, col_d = col;
	*d = env_dir(prm, ((float)col + uc) / (float)w, ((float)row + ur) / (float)h);
	/* Density and radiance from d's own texel, exactly what env_pdf_w
	 * and env_radiance return for d, even where rounding put a sample on
	 * a texel edge into the neighbour. */
	float sin_theta = env_texel(prm, *d, &row, &col);
	*pdf_w = env_table_pdf_w(sc, line, row, col, sin_theta);
	if (!(*pdf_w > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	return row == row_d && col == col_d ? drawn : env_pixel(sc, row, col);
}

/* By the environment's own distribution. */
INLINE V3 env_sample(const SceneView *sc, float u1, float u2, V3 *d, float *pdf_w)
{
	return env_table_sample(sc, 0, u1, u2, d, pdf_w);
}

/* Solid-angle density with which env_sample returns direction d. */
INLINE float env_pdf_w(const SceneView *sc, V3 d)
{
	GLOBAL const Params *prm = sc->params;
	if (prm->env_type == ENV_COLOR)
		return pdf_uniform_sphere_w();
	if (prm->env_type != ENV_IMAGE)
		return 0.0f;
	int row, col;
	float sin_theta = env_texel(prm, d, &row, &col);
	return env_texel_pdf_w(sc, row, col, sin_theta);
}

/* The direction of a light subpath from the environment: by the light
 * that comes in through the portals where its lines start on them
 * (Params.env_lines), else by the image's own distribution. */
INLINE V3 env_light_sample(const SceneView *sc, float u1, float u2, V3 *d, float *pdf_w)
{
	return env_table_sample(sc, sc->params->env_lines, u1, u2, d, pdf_w);
}

/* Solid-angle density with which env_light_sample returns direction d. */
INLINE float env_light_pdf_w(const SceneView *sc, V3 d)
{
	GLOBAL const Params *prm = sc->params;
	if (!prm->env_lines)
		return env_pdf_w(sc, d);
	int row, col;
	float sin_theta = env_texel(prm, d, &row, &col);
	return env_table_pdf_w(sc, 1, row, col, sin_theta);
}

#endif
