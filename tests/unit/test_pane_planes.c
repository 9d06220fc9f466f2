/* test_pane_planes.c — the planes of a scene's panes whose mirrored sky
 * next-event estimation samples (src/prepare/pane_planes.c): panes of one
 * plane grouped (either winding, offsets within the tolerance), planes by
 * area, each facing the sky side of its nearest portal, none without a
 * portal of a known sky side, at most PANE_PLANES_MAX. */
#include <math.h>
#include <string.h>

#include "testutil.h"

#include "prepare/pane_planes.h"

static Tri pane(V3 a, V3 b, V3 c)
{
	Tri t;
	memset(&t, 0, sizeof t);
	t.p0 = a;
	t.p1 = b;
	t.p2 = c;
	t.flags = TRI_PANE;
	t.emitter = -1;
	return t;
}

/* A square pane of half-size h in the plane z = z0 (wound toward +z, or -z). */
static void square(Tri *t, float cx, float cy, float z0, float h, int flip)
{
	V3 a = v3(cx - h, cy - h, z0), b = v3(cx + h, cy - h, z0), c = v3(cx + h, cy + h, z0), d = v3(cx - h, cy + h, z0);
	t[0] = flip ? pane(a, c, b) : pane(a, b, c);
	t[1] = flip ? pane(a, d, c) : pane(a, c, d);
}

/* A portal triangle around (cx, cy, z0) whose normal is +z, the sky on env_side of it. */
static PortalTri portal(float cx, float cy, float z0, int env_side)
{
	PortalTri p;
	memset(&p, 0, sizeof p);
	p.p0 = v3(cx - 1, cy - 1, z0);
	p.p1 = v3(cx + 1, cy - 1, z0);
	p.p2 = v3(cx, cy + 1, z0);
	p.n = v3(0, 0, 1);
	p.env_side = env_side;
	return p;
}

/* Two panes of one window, wound either way and 1e-6 apart, are one plane;
 * a larger window elsewhere in another plane comes first; each faces its
 * portal's sky. */
static void test_grouped_by_area_facing_the_sky(void **state)
{
	(void)state;
	Tri t[6];
	square(t, 0, 0, 0.02f, 0.5f, 0);
	square(t + 2, 1.2f, 0, 0.020001f, 0.5f, 1); /* the same window's second pane */
	square(t + 4, 0, 0, 5.02f, 1.5f, 0);       /* a bigger window: 4.5 against 2 */
	t[5].flags = 0;                            /* no pane: its half of that window counts nothing */
	PortalTri p[2] = {portal(0, 0, 0, -1), portal(0, 0, 5, +1)};
	Params prm;
	memset(&prm, 0, sizeof prm);
	pane_planes_build(t, 6, p, 2, 10.0f, &prm);
	assert_int_equal(prm.num_pane_planes, 2);
	/* first: z = 5.02, its sky on +z: normal +z, d = 5.02 */
	assert_true(prm.pane_n[0].z > 0.9999f);
	assert_float_equal(prm.pane_d[0], 5.02f, 1e-5f);
	/* then: z = 0.02, its sky on -z: normal -z, d = -0.02 */
	assert_true(prm.pane_n[1].z < -0.9999f);
	assert_float_equal(prm.pane_d[1], -0.02f, 1e-5f);
}

/* No portal with a known sky side: no plane; more planes than the table
 * holds: the largest PANE_PLANES_MAX, largest first. */
static void test_no_sky_and_the_cap(void **state)
{
	(void)state;
	enum { N = PANE_PLANES_MAX + 3 };
	Tri t[2 * N];
	for (int i = 0; i < N; i++)
		square(t + 2 * i, 0, 0, (float)i, 0.1f + 0.01f * (float)i, 0);
	PortalTri none = portal(0, 0, -1, 0), sky = portal(0, 0, -1, -1);
	Params prm;
	memset(&prm, 0, sizeof prm);
	pane_planes_build(t, 2 * N, &none, 1, 10.0f, &prm);
	assert_int_equal(prm.num_pane_planes, 0);
	pane_planes_build(t, 2 * N, &sky, 1, 10.0f, &prm);
	assert_int_equal(prm.num_pane_planes, PANE_PLANES_MAX);
	for (int i = 0; i < PANE_PLANES_MAX; i++) /* z = N - 1, N - 2, ...: the sky below, normal -z */
		assert_float_equal(prm.pane_d[i], -(float)(N - 1 - i), 1e-5f);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_grouped_by_area_facing_the_sky),
		cmocka_unit_test(test_no_sky_and_the_cap),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
