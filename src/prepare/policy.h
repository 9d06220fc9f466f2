/* policy.h — every rendering choice Ajar makes for a scene, in one place.
 *
 * The public options say what the user asked for (an integrator, a MIS
 * heuristic or "auto"); the scene says what it is lit by. From both,
 * policy_choose decides once, before anything is uploaded, which program
 * runs, which strategies it uses and how often, which heuristic weighs
 * them and how fine the sky tables are. None of these choices changes the
 * image's expectation, only its noise, so each default is the one that
 * measured best and names that measurement (policy.c). Tests may force a
 * choice through PolicyOverrides (src/render/render_overrides.h); the
 * product never does. */
#ifndef AJAR_POLICY_H
#define AJAR_POLICY_H
#include <stdint.h>

/* What the policy reads of a prepared scene and of the options. */
typedef struct {
	int integrator;       /* INTEGRATOR_* asked for */
	int mis;              /* AJAR_MIS_* asked for */
	int strategy_unweighted; /* strategy layers without MIS weights */
	uint32_t portals;     /* portal triangles */
	int env_type;         /* ENV_* */
	uint32_t env_width;   /* columns of a sky image */
	uint32_t emitters;    /* emissive triangles */
	uint32_t lamps;       /* punctual lights */
	int lamp_behind_portal; /* a point or spot light on the far side of a portal from the camera */
	int sky_planes;       /* planar portals with a sky table (src/prepare/sky_tables.c) */
	float sun_share;      /* a sky image's sun's share of the light through the portals (portal_sun_share) */
} PolicyInput;

/* What the policy decided; prepare_scene copies it into Params. */
typedef struct {
	int integrator;       /* the program that runs (PARAMS_INTEGRATOR) */
	int mis;              /* MIS_POWER or MIS_BALANCE */
	int light_paths;      /* portal: light subpaths traced (bdpt's s >= 2 and t = 1) */
	int portal_s_max, portal_sp_max, portal_tp_max, portal_t_max; /* intermediate strategies in use */
	int bdpt_conn;        /* bdpt: light vertices eye vertices join (0: all) */
	float portal_rate;    /* probability a pixel sample traces an intermediate subpath */
	int sky_res;          /* cells a side of the planes' sky tables (PORTAL_SKY_RES) */
} Policy;

/* Choices forced from outside the policy (tests only; zero: none). */
typedef struct {
	int portal_set_given; /* portal_set holds s, s', t', t and light paths (0/1) */
	int portal_set[5];
	float portal_rate;    /* in (0, 1]; 0: the policy's */
	int bdpt_conn_given;  /* bdpt_conn (0, 1 or 2) for bdpt */
	int bdpt_conn;
	int sky_res;          /* 128, 256 or 512; 0: the policy's */
	int panes_opaque;     /* panes are surfaces no connection crosses (delta transmission): a brute force */
} PolicyOverrides;

/* The sun's share of the light through the portals (PolicyInput.sun_share)
 * from which a sky image's sun counts as shining in. */
#define POLICY_SKY_SUN_SHARE 0.04f

/* Where portal renders as bdpt (light subpaths bring the light in), its
 * strategies other than light tracing join eye vertices to at most this many
 * light vertices, delta ones not counted (kernels/mis/mis.h, mis_conn_limit): the longer
 * connections cost a third of the time and lowered no variance on
 * window-room-sunset and -forest; 1 was 1.24x worse on window-room-forest. */
#define POLICY_PORTAL_BDPT_CONN 2

/* Where a render's portals come from (policy_portals). */
enum { POLICY_PORTALS_NONE, POLICY_PORTALS_MARKED, POLICY_PORTALS_FOUND };
/* The portals a render uses, from the option (ajar_portals) and the number
 * of portal triangles the scene marks. */
int policy_portals(int option, uint32_t marked);

/* Decides *out from in (and over, which may be NULL); `source` names the
 * scene in the informational messages it logs. */
void policy_choose(const PolicyInput *in, const PolicyOverrides *over, const char *source, Policy *out);
#endif
