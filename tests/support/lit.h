/* lit.h — what the light tests (tests/unit/test_lights_*.c) share: a
 * scene built triangle by triangle, its light tables (src/prepare/light_tables.c)
 * and the SceneView the kernels read (Lit); a seeded uniform generator; the
 * scene of emitters and the windows that light_sample's tests look from;
 * and the chi-square check of light_sample against light_pdf_w.
 * lit.c includes the kernels' light code, which reads sky tables of
 * PORTAL_SKY_RES cells a side: the Makefile builds it once more for the
 * fine tables (lit_fine.o). */
#ifndef AJAR_LIT_H
#define AJAR_LIT_H
#include "testutil.h"

#include "prepare/light_tables.h"
#include "scene/scene.h"
#include "light/lights.h"

#define ALPHA 1e-3 /* chi-square significance; fixed seeds make it reproducible */

/* PCG32 (O'Neill) state: each test sets its own seed. */
extern uint64_t rng_state;
/* Uniform in the open interval (0, 1): a 0 would put a portal sample
 * exactly on a triangle's corner or edge (sph_tri_sample), which the
 * neighbouring triangles share, so that one direction would count as
 * crossing several (measure zero, but the density checks compare each
 * sample's density exactly). */
float rnd(void);

/* A scene, its light tables and the SceneView the kernels read. */
typedef struct {
	Scene *s;
	Tri *tris;
	LightTables lt;
	Params prm;
	SceneView sc;
	PortalPlane *planes; /* lit_planes (test_lights_sky_planes) */
	float *sky;
} Lit;

/* A material of base colour 0.5 emitting `emission`; its index. */
uint32_t add_material(Scene *s, V3 emission);
/* One triangle a b c of material `mat`. */
void add_tri(Scene *s, V3 a, V3 b, V3 c, uint32_t mat);
/* l->s's light tables and the view of them (no portal planes). */
void lit_build(Lit *l);
void lit_free(Lit *l);
/* A w x h sky: a bright blob near the top, a dimmer one below the
 * horizon, a black row and a black column, colour varying along u. */
float *synthetic_sky(uint32_t w, uint32_t h);

/* Emitters around x = (0, 0, 0): a square above, a triangle in front with
 * another behind it (overlapping as seen from x), one facing away, and a
 * non-emissive occluder (light sampling ignores it). */
void build_light_scene(Lit *l);
/* Portals around x = (0.1, 0.2, 0.05): a window in front, a triangle
 * behind it, a tiny far one, one with x on its sky side and one with no
 * sky behind it (the last two get their sides from the callers). */
void add_window_portals(Lit *l);
/* The window [-1, 1] x [-0.6, 0.9] at z = 1 as a 4 x 3 grid of quads. */
enum { GRID_NX = 4, GRID_NY = 3, GRID_NV = (GRID_NX + 1) * (GRID_NY + 1), GRID_NT = 2 * GRID_NX * GRID_NY };
void grid_window(float *pos, uint32_t *idx);

/* Directions from x (receiver normal n) binned into equal-area cells
 * (cos theta about +Y, phi), expected counts from light_pdf_w integrated
 * over each cell; one more cell for samples light_sample refused
 * (back-facing emitters). */
void check_light_sample(Lit *l, V3 x, V3 n, const char *name);
#endif
