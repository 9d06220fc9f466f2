/* portal_find_parts.h — what the portal search's files share (portal_find.c
 * drives the steps and has the method): its constants, the rays it traces,
 * the room's points, the crossings, the rectangles, and each step's entry.
 * The steps run single-threaded from fixed seeds: the same scene always
 * gets the same portals. */
#ifndef AJAR_PORTAL_FIND_PARTS_H
#define AJAR_PORTAL_FIND_PARTS_H
#include "prepare/portal_find.h"

#include <stdlib.h>
#include <string.h>
#include <stdio.h>

#include "core/error.h"
#include "geom/bvh.h"
#include "sample/rng.h"
#include "sample/sampling.h"

/* -DPORTAL_FIND_DEBUG prints the search's steps on stderr. */
#ifdef PORTAL_FIND_DEBUG
#define PF_DEBUG(...) fprintf(stderr, __VA_ARGS__)
#else
#define PF_DEBUG(...) ((void)0)
#endif

#define CAMERA_RAYS 1024   /* step 1 */
#define SECOND_RAYS 512
#define ROOM_PEERS 16      /* a room point sees ROOM_SEES of these */
#define ROOM_SEES 3
#define ROOM_RAYS 65536    /* step 2, over all room points */
#define MAX_CANDIDATES 2048
#define FOCUS_TARGET 96    /* crossings a place (and direction) should have */
#define FOCUS_NEAR 0.05f   /* x R: a place's radius */
#define FOCUS_MAX 32768    /* aimed rays a round at most */
#define BESIDE_PAIRS 131072 /* step 7: room points joined to light points */
#define BESIDE_SLAB GAP_SLAB /* a line this near a portal went through it */
#define BESIDE_TIE 0.7     /* planes scoring this near the best: the nearest the room wins */
#define LIGHT_POINTS 64    /* light samples of emitters and lamps */
#define BOUNCE_POINTS 64   /* and of what they light */
#define RING_DIRS 8        /* step 3 */
#define RING_NEED 7
#define RING_NEAR 0.85f
#define RING_NORMALS 16    /* hit normals kept per crossing */
#define NEAR_START 0.1f    /* x R: crossings nearer their start are left out */
#define MAX_PLANES 32      /* step 4: surfaces around the holes tried */
#define PATCH_CELL 0.01f   /* x R: cells of the crossings' raster on a plane */
#define PATCH_JOIN 3       /* crossings this many cells apart join one patch */
#define PATCH_FLOOR 0.05f  /* x R: a patch counts as at least this square */
#define PATCH_MAX 384      /* at most this many a side */
#define PATCH_DN 0.3f      /* lines that cross a plane at a shallower cosine do not count there */
#define MAX_ROUNDS 32
#define RUNNER_UP 0.5      /* a patch on another plane this close to the best is tried too */
#define MEET_DN 0.05f      /* a line crossing a portal at a shallower cosine does not count */
#define PLANE_OFFSET 1e-3f /* x R: a portal lies this far beyond the surface it was found in */
#define GRID 64            /* step 5: cells a side */
#define CELL_ORIGINS 3
#define SKY_RAYS 4         /* a point under the sky: SKY_SEEN of SKY_RAYS rays escape */
#define SKY_SEEN 2
#define REFRAME 0.6f       /* open cells this much narrower in a turned frame: the grid turns */
#define GROW_TRIES 3       /* the grid grows where open cells touch its border */
#define EDGE_STEPS 4       /* bisections of each edge of a rectangle (to 1/16 cell) */
#define EDGE_PROBES 16     /* points along it each */
#define EDGE_MARGIN 0.25f  /* x a cell: a rectangle's margin beyond its opening */
#define SLIDE_STEP 0.005f  /* x R: a rectangle slides out through a tunnel by these steps */
#define SLIDE_STEPS 24
#define RIM_GAP 0.03f      /* x its size: its rim lies this far outside it */
#define SLIDE_SOLID 0.1f   /* x R */
#define CONNECT 2          /* open cells this many cells apart join */
#define GAP_ASPECT 0.5f    /* a rectangle this narrow is a gap (a doorway too): its section refitted */
#define GAP_KEEP 0.9f      /* a section catching this share of its lines is kept */
#define GAP_SHRINK 0.7f    /* where its area is at most this share: the rest find their own */
#define GAP_SURE 128       /* lines near it, at least, for that: a few lost ones say little */
#define GAP_SLAB 0.003f    /* x R: its lines pass this near it */
#define GAP_DIRS 360       /* rays across it, from GAP_FROM points */
#define GAP_FROM 5
#define GAP_REACH 0.05f    /* x R: as far, and twice its width */
#define GAP_CROSS 0.9f     /* its section: crossed by this many of its lines */
#define MERGE_AREA 1.25    /* step 6 */
#define MERGE_GAP 0.03f    /* x R: rectangles of planes this close may merge */
#define DUP_COS 0.99f      /* an accepted portal grows over a new one this near its normal, half over it */
#define MIN_SHARE 0.02f    /* lines a portal must catch */
#define MAX_PORTALS 16

typedef struct {
	V3 p, n; /* a point; n the emitting side (zero for a lamp) */
} LightPoint;

typedef struct {
	const SceneView *v;
	float R;       /* room scale */
	uint64_t rays;
	LightPoint *lp;
	uint32_t nlp;
	uint32_t ndirect; /* lp[0..ndirect): on the lamps and emitters; after them, what they light */
	int sky;       /* a sky or a sun: what escapes finds light */
} Ctx;

/* A ray's first solid hit (glass passed through); t = AJAR_INF: escaped. */
typedef struct {
	float t;
	V3 p, ng; /* ng unit, facing the ray's origin */
	int emit; /* an emitter's front face */
} Solid;

typedef struct {
	V3 p, n;
	int surf; /* on a surface (rays leave about n) */
	uint32_t base; /* its four light samples: lp[(base + k) % nlp] */
	int sees[4];   /* whether it sees them */
} RoomPt;

typedef struct {
	RoomPt *pt;
	uint32_t n, cap;
} RoomPts;

typedef struct {
	const RoomPt *from; /* its room point (P, light samples) */
	uint32_t origin;    /* that point's index */
	V3 P, d;      /* the ray */
	float t;      /* its far hit, AJAR_INF escaped */
	int strong;   /* escaped or met an emitter (else: a point lit by a light P does not see) */
	int weight;   /* 1: a ray of the first sample, which the shares count; 0: an aimed one */
	float ring;   /* the ring's angle that found the wall, radians */
	V3 X;         /* where it crosses the wall */
	V3 wn;        /* the wall's normal, facing the room */
	float ws;     /* the wall's offset, wn . x */
	int nn;       /* ring hit normals and points */
	V3 rn[RING_NORMALS], rp[RING_NORMALS];
} Crossing;

typedef struct {
	Crossing *x;
	uint32_t n, cap;
} Crossings;

typedef struct {
	V3 o, a1, a2, n; /* plane point, in-plane axes, normal (facing the room) */
	float lo1, hi1, lo2, hi2;
	float share;
	int alive;
	int accepted; /* a portal: light behind it, MIN_SHARE of the lines */
} Rect;

typedef struct {
	Rect *r;
	uint32_t n, cap;
} Rects;

/* A patch of lines where they crowd (pf_best_patch), and the raster of
 * their crossings that finds it. */
typedef struct {
	double score; /* 0: none */
	int q;        /* its plane */
	uint32_t *idx, m; /* its lines */
} Patch;

typedef struct {
	float cell;
	int w, h;
	uint32_t *count;
	int *comp, *stack, *cellof;
	int (*box)[4];
	uint64_t *pairs;
} Raster;

/* The rays (portal_find_rays.c). */
int pf_trace(Ctx *c, V3 o, V3 d, float tmax, Solid *s);
/* Whether the segment a -> b is free (b excluded). */
int pf_clear(Ctx *c, V3 a, V3 b);
/* Whether light point l lights a surface point p with normal n (facing
 * where the ray came from). */
int pf_lit_by(Ctx *c, V3 p, V3 n, const LightPoint *l);
static inline float rnd(Rng *r) { return rng_f(r); }
V3 pf_dir_about(Rng *r, V3 n, int cosine);
/* The trimmed range [q, 1 - q] of a[0..n) (reorders a). */
void pf_trimmed(float *a, int n, float q, float *lo, float *hi);

/* Steps 1 and 2: the room, the light (portal_find_room.c). */
ajar_status pf_room_points(Ctx *c, V3 cam, RoomPts *r);
ajar_status pf_light_points(Ctx *c, uint32_t ntris, const PortalFindInput *in, const RoomPts *room);

/* Steps 2 and 3: crossings (portal_find_crossings.c). */
/* Four light samples per room point, and whether it sees them. */
void pf_room_lights(Ctx *c, RoomPts *r);
ajar_status pf_find_crossings(Ctx *c, const RoomPts *r, Crossings *out);

/* Step 4: planes and patches (portal_find_planes.c). */
/* An in-plane frame: the first axis the world's up projected, or x for
 * horizontal planes. */
void pf_plane_frame(V3 n, V3 *a1, V3 *a2);
/* Where line (P, d) meets the plane n . x = s, if between its start and
 * its far hit: 1 and the distance. */
int pf_meet(const Crossing *x, V3 n, float s, float R, float min_dn, float *t);
/* Candidate portal planes: the surfaces the rings met around the holes
 * (walls, jambs, frames, a door leaf), as (normal, offset) buckets of 10
 * degrees and 0.01 R, the most met first; up to MAX_PLANES with at least
 * 0.5% of the hits. Each normal faces where the lines come from. */
int pf_candidate_planes(const Crossings *xs, float R, V3 *cand, float *offs);
/* Of the lines still open (alive), where they crowd most tightly on one
 * candidate plane (lines crossing it at a cosine of at least min_dn):
 * best[0] the best patch, best[1] the best on another. */
void pf_best_patch(Ctx *c, const Crossings *xs, const uint8_t *alive, const V3 *pn, const float *po, int np,
		   float min_dn, V3 blo, V3 bhi, Raster *g, Patch best[2]);

/* Steps 5 to 7: open cells, rectangles (portal_find_cells.c). */
/* Open cells of plane (n, s) over the footprint, their connected parts as
 * rectangles into rs; the lines each rectangle catches are marked in
 * caught (steps 6 and 7). */
ajar_status pf_open_rects(Ctx *c, const Crossing *xs, const uint32_t *idx, uint32_t m, V3 n, float s,
			  uint32_t total, uint8_t *caught, Rects *rs);
/* Rectangles of one plane (normals within 1 degree, planes within
 * MERGE_GAP R: a window found twice, at its frame and at its blind) merge
 * while one rectangle covers two with at most MERGE_AREA times the area
 * they cover together. The merged one lies in the first's plane. */
void pf_merge_rects(Rects *rs, uint32_t from, float R);
/* Whether line x passes through rectangle r before its far hit. */
int pf_rect_catches(const Rect *r, const Crossing *x, float R);
/* Whether line x passes within m of rectangle r (through it or along it). */
int pf_rect_near(const Rect *r, const Crossing *x, float m, float R);
/* A gap's rectangle (GAP_ASPECT: longer than wide) turned about its long
 * axis onto the gap's narrowest section, the shortest segment between two
 * solid points that most of the lines of xs[0..n) passing near it cross
 * (a door's jamb corner to its leaf's face by the free edge), where it
 * catches more of those lines, or nearly as many (GAP_KEEP) of GAP_SURE
 * lines or more on a much smaller area (GAP_SHRINK: a door opened 20
 * degrees, whose doorway is four times the gap; not the slit over a
 * leaf's top, whose few lines say little and whose wedge's middle section
 * leaves out lines by its wide end, which would make a second portal).
 * Returns whether it turned; the lines it no longer catches are the
 * caller's to reopen. */
int pf_refit_gap(Ctx *c, const Crossing *xs, uint32_t n, Rect *r);

/* Step 7 (portal_find_crossings.c): lines through openings beside the
 * accepted rectangles of rs, added to xs with weight 0. */
ajar_status pf_beside(Ctx *c, const RoomPts *r, Crossings *xs, const Rects *rs);

#endif
