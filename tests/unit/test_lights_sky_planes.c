/* test_lights_sky_planes.c — sky images through planar portals
 * (src/prepare/sky_tables.c, kernels/light/portal_sky.h): each plane's (U, V)
 * sampler against its density, exactly, and its directions; the whole
 * next-event sample (the sky through the planes by radiance, the
 * environment's own sampling, the emitters) against light_pdf_w; the sky's
 * next-event density with the planes' views the same bits as computed from
 * scratch. Built twice: at the default 128 cells a side and, as
 * test_lights_sky_planes_fine, at 512 (-DPORTAL_SKY_RES=512). */
#include "lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "prepare/sky_tables.h"

/* Planar portals with sky tables (src/prepare/sky_tables.c) from the portal
 * triangles' sky sides as they are now; returns how many. */
static int lit_planes(Lit *l)
{
	size_t np, ns;
	free(l->planes);
	free(l->sky);
	np = ns = 0;
	l->planes = NULL;
	l->sky = NULL;
	if (l->prm.env_type == ENV_IMAGE) { /* prepare_scene builds planes under a sky image only */
		assert_int_equal(portal_sky_planes(l->s->portals, l->s->nportal_tris, &l->planes, &np), AJAR_OK);
		assert_int_equal(portal_sky_tables(&l->sc, l->planes, np, PORTAL_SKY_RES, &l->sky, &ns), AJAR_OK);
	}
	l->sc.portal_planes = l->planes;
	l->sc.portal_sky = l->sky;
	l->prm.num_portal_planes = (int)np;
	return (int)np;
}

/* Plane k's (U, V) sampler from x against its density, exactly: the
 * density is constant on each table cell within x's rectangle, so a bin
 * of whole cells expects the sum of density times area. Also the
 * directions: (U, V) -> w -> (U, V) round trips, and w lies in the plane's
 * sky half. */
static void check_sky_uv(Lit *l, int k, V3 x, const char *name)
{
	enum { B = PORTAL_SKY_RES / 32, NB = (PORTAL_SKY_RES / B) * (PORTAL_SKY_RES / B), N = 200000 };
	static double obs[NB], expct[NB];
	const PortalPlane *P = &l->planes[k];
	const float *S = l->sky + P->table;
	SkyRect r;
	assert_true(sky_rect(P, x, &r));
	float total = sky_rect_integral(S, &r);
	assert_true(total > 0.0f);
	memset(obs, 0, sizeof obs);
	memset(expct, 0, sizeof expct);
	double sum = 0.0;
	for (int j = (int)r.V0; j < PORTAL_SKY_RES && j < r.V1; j++)
		for (int i = (int)r.U0; i < PORTAL_SKY_RES && i < r.U1; i++) {
			float ulo = fmaxf((float)i, r.U0), uhi = fminf((float)(i + 1), r.U1);
			float vlo = fmaxf((float)j, r.V0), vhi = fminf((float)(j + 1), r.V1);
			double area = (double)(uhi - ulo) * (vhi - vlo);
			if (!(area > 0.0))
				continue;
			double pc = sky_pdf_uv(S, &r, total, 0.5f * (ulo + uhi), 0.5f * (vlo + vhi));
			assert_true(pc > 0.0); /* the floor: no cell within the rectangle is left out */
			expct[(j / B) * (PORTAL_SKY_RES / B) + i / B] += pc * area * N;
			sum += pc * area;
		}
	assert_float_equal(sum, 1.0, 1e-3);
	for (int n = 0; n < N; n++) {
		float U, V, jac, U2, V2, jac2;
		assert_true(sky_sample_uv(S, &r, total, rnd(), rnd(), &U, &V));
		assert_true(U >= r.U0 && U <= r.U1 && V >= r.V0 && V <= r.V1);
		int i = (int)U, j = (int)V;
		i = i >= PORTAL_SKY_RES ? PORTAL_SKY_RES - 1 : i;
		j = j >= PORTAL_SKY_RES ? PORTAL_SKY_RES - 1 : j;
		obs[(j / B) * (PORTAL_SKY_RES / B) + i / B] += 1.0;
		if (n % 16 == 0) {
			V3 w = sky_dir(P, U, V, &jac);
			assert_float_equal(v3_len(w), 1.0f, 1e-5f);
			assert_true(v3_dot(w, P->n) > 0.0f);
			sky_coords(P, w, &U2, &V2, &jac2);
			assert_float_equal(U2, U, 2e-3f);
			assert_float_equal(V2, V, 2e-3f);
			assert_float_equal(jac2, jac, 1e-3f * jac);
		}
	}
	double p = chi2_test(obs, expct, NB, 5.0);
	printf("  sky through plane %d %-12s p = %.3f (rectangle %.1f..%.1f x %.1f..%.1f cells)\n", k, name, p, r.U0,
	       r.U1, r.V0, r.V1);
	assert_true(p > ALPHA);
}

/* The light scene under a sky with a sun seen from x through the window
 * (add_window_portals), its portals' sky sides set as seen from x (the
 * fifth faces the other way, the sixth has no sky): 4 planes. Returns the
 * sun's direction. */
static V3 window_sun_scene(Lit *l, V3 x)
{
	build_light_scene(l);
	V3 sun = v3_norm(v3(0.15f, 0.5f, 1.0f));
	assert_int_equal(scene_set_env_image(l->s, 128, 64, test_sun_sky(128, 64, sun.x, sun.y, sun.z, 0.06f, 300.0f), 0.05f), AJAR_OK);
	add_window_portals(l);
	for (int j = 0; j < 5; j++) {
		PortalTri *pt = &l->s->portals[j];
		float dn = v3_dot(v3_sub(x, pt->p0), pt->n);
		pt->env_side = j == 4 ? (dn > 0 ? 1 : -1) : (dn > 0 ? -1 : 1);
	}
	l->s->portals[5].env_side = 0;
	assert_int_equal(lit_planes(l), 4);
	return sun;
}

/* The portals of test_light_sample_env_portals (a window quad in front of
 * x, an overlapping triangle behind it, a tiny far one in the same plane
 * but apart, one x sees from its sky side, one without sky) and a sky
 * with a sun: they group into four planes, each plane's sampler follows
 * its density, and the whole next-event sample (sky through the planes by
 * radiance, the environment's own sampling as defence, the emitters)
 * follows light_pdf_w, with the sun inside the window's view and outside
 * every portal's. */
static void test_light_sample_sky_portals(void **state)
{
	rng_state = 31;
	Lit l;
	V3 x = v3(0.1f, 0.2f, 0.05f);
	V3 sun = window_sun_scene(&l, x);
	SkyRect r;
	int seen = 0;
	for (int k = 0; k < 4; k++)
		if (sky_rect(&l.planes[k], x, &r)) {
			seen++;
			check_sky_uv(&l, k, x, "");
		}
	assert_int_equal(seen, 3); /* not the one x sees from its sky side */
	check_light_sample(&l, x, v3_norm(v3(0.3f, -0.2f, 0.9f)), "+ sky, planes");
	check_light_sample(&l, x, v3(1, 0, 0), "+ sky sideways");
	check_light_sample(&l, x, v3(0, 0, 0), "+ sky, no n");
	/* From a point that sees the sun through no portal (above the window,
	 * beside the triangle behind it, within that triangle's bounding
	 * rectangle: a direction a plane's sampler may draw that the
	 * triangles do not pass). */
	V3 x2 = v3(-0.2f, 0.45f, 0.2f), nx = v3_norm(v3(0.3f, -0.2f, 0.9f));
	SkyWeights sw;
	sky_weights(&l.sc, x, nx, &sw);
	assert_true(sky_portal_pdf_w(&l.sc, &sw, x, nx, sun) > 0.0f);
	assert_int_equal(portal_crossings(&l.sc, x2, sun, 1), 0);
	int sun_in_rect = 0;
	for (int k = 0; k < 4; k++)
		if (sky_rect(&l.planes[k], x2, &r)) {
			check_sky_uv(&l, k, x2, "");
			float U, V, jac;
			if (v3_dot(sun, l.planes[k].n) > 0.0f) {
				sky_coords(&l.planes[k], sun, &U, &V, &jac);
				sun_in_rect |= U >= r.U0 && U <= r.U1 && V >= r.V0 && V <= r.V1;
			}
		}
	assert_true(sun_in_rect);
	check_light_sample(&l, x2, v3(0, 0, 1), "+ sun outside");
	lit_free(&l);
}

/* The portal part of the sky's next-event density as env_portal.h
 * computed it before the views and the tangent test (session 22): every plane's rectangle, integral and weight again, and sky_coords
 * and sky_pdf_uv for every plane that faces wi. */
static float sky_portal_pdf_ref(const Lit *l, V3 x, V3 n, V3 wi)
{
	int np = l->prm.num_portal_planes;
	SkyRect r[8];
	float mass[8], w[8], W = 0.0f, p = 0.0f;
	assert_true(np <= 8);
	for (int k = 0; k < np; k++) {
		const PortalPlane *P = &l->planes[k];
		w[k] = 0.0f;
		if (!sky_rect(P, x, &r[k]))
			continue;
		mass[k] = sky_rect_integral(l->sky + P->table, &r[k]);
		if (!(mass[k] > 0.0f))
			continue;
		V3 d = v3_sub(sky_plane_centre(P), x);
		float cr = fmaxf(PORTAL_COS_MIN, v3_dot(d, n) / sqrtf(v3_len2(d)));
		w[k] = mass[k] * cr;
		W += w[k];
	}
	if (!(W > 0.0f))
		return -1.0f;
	for (int k = 0; k < np; k++) {
		const PortalPlane *P = &l->planes[k];
		float U, V, jac;
		if (!(v3_dot(wi, P->n) > 0.0f) || !(w[k] > 0.0f))
			continue;
		sky_coords(P, wi, &U, &V, &jac);
		float puv = sky_pdf_uv(l->sky + P->table, &r[k], mass[k], U, V);
		if (puv > 0.0f && jac > 0.0f)
			p += w[k] / W * puv / jac;
	}
	return p;
}

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* The sky's next-event density is the same bits with the planes' views
 * and their tangent test (env_portal.h) as computed from scratch
 * (sky_portal_pdf_ref): from points all about the window, toward
 * directions at random and just inside and outside every rectangle's
 * edges (where the tangent test must keep what sky_pdf_uv keeps), with
 * both sides' normals at one point; and a next-event sample's density,
 * which reuses its drawn cell's knots, is the one computed afresh. */
static void test_sky_pdf_views(void **state)
{
	rng_state = 41;
	Lit l;
	window_sun_scene(&l, v3(0.1f, 0.2f, 0.05f));
	enum { NX = 7 };
	V3 xs[NX];
	for (int i = 0; i < NX; i++)
		xs[i] = v3(4.0f * rnd() - 2.0f, 4.0f * rnd() - 2.0f, 2.5f * rnd() - 1.5f);
	int checked = 0, edge = 0, nonzero = 0, sampled = 0;
	for (int it = 0; it < 4000; it++) {
		V3 x = xs[(it * 5 + it / 7) % NX];
		V3 n = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		if (it % 3 == 1)
			n = v3_neg(n);
		V3 wi;
		int k = (int)(rnd() * 4.0f) & 3;
		SkyRect r;
		if (it % 2 == 0 && sky_rect(&l.planes[k], x, &r)) {
			/* just inside or outside an edge of plane k's rectangle */
			float e = (rnd() - 0.5f) * 2e-3f, U = r.U0 + (r.U1 - r.U0) * rnd(), V = r.V0 + (r.V1 - r.V0) * rnd();
			int side = (int)(rnd() * 4.0f) & 3;
			if (side == 0)
				U = r.U0 + e;
			else if (side == 1)
				U = r.U1 + e;
			else if (side == 2)
				V = r.V0 + e;
			else
				V = r.V1 + e;
			float jac;
			wi = sky_dir(&l.planes[k], fminf(fmaxf(U, 1e-3f), PORTAL_SKY_RES - 1e-3f),
				     fminf(fmaxf(V, 1e-3f), PORTAL_SKY_RES - 1e-3f), &jac);
			edge++;
		} else {
			wi = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		}
		float ref = sky_portal_pdf_ref(&l, x, n, wi);
		SkyWeights a;
		sky_weights(&l.sc, x, n, &a);
		if (ref < 0.0f) {
			assert_false(a.W > 0.0f);
			continue;
		}
		assert_true(same_bits(sky_portal_pdf_w(&l.sc, &a, x, n, wi), ref));
		checked++;
		nonzero += ref > 0.0f;
	}
	/* next-event samples */
	for (int it = 0; it < 2000; it++) {
		V3 x = xs[(it * 3 + it / 5) % NX], n = v3_norm(v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
		float um = rnd(), u1 = rnd(), u2 = rnd(), pa;
		V3 wa = v3(0, 0, 0);
		sky_nee_sample(&l.sc, x, n, um, u1, u2, &wa, &pa);
		/* through a plane: the density with the drawn cell's knots is the
		 * one computed afresh from the direction */
		if (um < PORTAL_SKY_NEE_MIX && pa > 0.0f) {
			assert_true(same_bits(pa, sky_nee_pdf_w(&l.sc, x, n, wa, env_pdf_w(&l.sc, wa))));
			sampled++;
		}
	}
	printf("  %d densities (%d nonzero, %d toward rectangle edges) and %d samples' the same bits\n", checked,
	       nonzero, edge, sampled);
	assert_true(checked > 1000 && nonzero > 300 && edge > 1000 && sampled > 500);
	lit_free(&l);
}

/* A window in a grid of 24 triangles (one plane), seen from close by and
 * off its centre, and single-triangle portals (directions in their
 * bounding rectangles but outside them are valid samples of the plane). */
static void test_light_sample_sky_grid(void **state)
{
	rng_state = 37;
	Lit l;
	build_light_scene(&l);
	V3 sun = v3_norm(v3(-0.2f, 0.3f, 1.0f));
	assert_int_equal(scene_set_env_image(l.s, 128, 64, test_sun_sky(128, 64, sun.x, sun.y, sun.z, 0.05f, 500.0f), 0.05f), AJAR_OK);
	enum { NV = GRID_NV, NT = GRID_NT };
	float pos[3 * NV + 36];
	uint32_t idx[3 * NT + 12];
	grid_window(pos, idx);
	/* A triangle in the plane x = 1.2, tilted against the grid, and three
	 * apart in the plane z = 1.6 behind it: more planes than the sampler
	 * keeps weights for (SKY_KEPT), so the rest are weighed again. */
	const float tri[4][9] = {{1.2f, -0.5f, -0.5f, 1.2f, 0.9f, 0.2f, 1.2f, 0.0f, 0.8f},
				 {-0.6f, 0.2f, 1.6f, -0.3f, 0.2f, 1.6f, -0.4f, 0.5f, 1.6f},
				 {0.1f, -0.3f, 1.6f, 0.4f, -0.3f, 1.6f, 0.3f, 0.0f, 1.6f},
				 {0.5f, 0.4f, 1.6f, 0.8f, 0.4f, 1.6f, 0.7f, 0.7f, 1.6f}};
	for (int k = 0; k < 4; k++) {
		memcpy(&pos[3 * (NV + 3 * k)], tri[k], sizeof tri[k]);
		for (int c = 0; c < 3; c++)
			idx[3 * (NT + k) + c] = (uint32_t)(NV + 3 * k + c);
	}
	assert_int_equal(scene_add_portal(l.s, "grid", pos, NV + 12, idx, NT + 4), AJAR_OK);
	lit_build(&l);
	V3 x = v3(0.3f, 0.1f, 0.75f);
	for (int j = 0; j < NT + 4; j++)
		l.s->portals[j].env_side = v3_dot(v3_sub(x, l.s->portals[j].p0), l.s->portals[j].n) > 0 ? -1 : 1;
	assert_int_equal(lit_planes(&l), 5);
	assert_true(5 > SKY_KEPT);
	check_sky_uv(&l, 0, x, "near");
	check_sky_uv(&l, 1, x, "triangle");
	check_light_sample(&l, x, v3_norm(v3(0.2f, -0.3f, 0.9f)), "+ sky grid");
	lit_free(&l);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_light_sample_sky_portals),
		cmocka_unit_test(test_light_sample_sky_grid),
		cmocka_unit_test(test_sky_pdf_views),
	};
	/* test_lights_sky_planes_fine (Makefile): the planes' tables at
	 * PORTAL_SKY_RES cells a side, as pt takes them under large skies
	 * (src/prepare/policy.c, sky_res). */
	return cmocka_run_group_tests_name(PORTAL_SKY_RES == 128 ? "lights, sky planes" : "lights, sky planes, fine tables",
					   tests, NULL, NULL);
}
