/* policy.c — the rendering choices (policy.h), each beside the
 * measurement that decided it. The records: kernels/integrator/README.md
 * ("Strategy sets and the rate", "Where light subpaths come in, portal is
 * bdpt", "Connections to the first two light vertices", "A lamp behind a
 * portal counts as an emitter"), kernels/mis/README.md ("The heuristic:
 * power, balance, auto"), kernels/light/README.md ("Table resolution",
 * "Sky light subpaths through the portals", "A sun's share through the
 * openings"). The commands that measure them: tests/peers/sky_eff.py
 * (variance and time per sample of one integrator on one scene, after
 * changing a choice here) and `make bench-peers`. */
#include "prepare/policy.h"

#include "ajar.h"
#include "base/types.h"
#include "core/error.h"

/* Rates of intermediate subpaths (Params.portal_rate), chosen at equal time:
 * with next-event estimation through the portals a sky needs them seldom;
 * light from emitters behind an opening (door-ajar) often. Under a sky
 * image sampled through planar portals without light subpaths, the <-
 * halves guided by the sky's importance find the sun and the -> halves the
 * patch it lights: worth a higher rate than a constant sky. */
#define RATE_SKY 0.1f
#define RATE_EMITTERS 1.0f
#define RATE_SKY_IMAGE 0.3f

/* Cells a side of the planes' sky tables (kernels/light/portal_sky.h). With
 * 128 cells (1.4 degrees at the centre) a sun of a sky of 2048 columns or
 * more (0.53 degrees) covers a fraction of its cell, and pt's next-event
 * samples drawn into that cell mostly miss it: 512 cells halved pt's
 * variance per sample (2k and 4k skies, window-room and living-room:
 * 1.7-2x less variance x time), and 256 gave it 3-22% under 1k skies.
 * bdpt and portal keep 128: their light subpaths bring the sun in by the
 * image's own table, their MIS weights read the tables many times, and
 * finer ones gave them 1-6% less variance for up to 30% more time. */
static int sky_res(const PolicyInput *in, int integrator)
{
	if (integrator == INTEGRATOR_PT && in->env_type == ENV_IMAGE && in->portals > 0)
		return in->env_width >= 2048 ? 512 : 256;
	return 128;
}

/* Portals. A scene that marks some is taken at its word; one that marks
 * none (Blender's glTF exporter writes no custom properties unless asked)
 * gets the openings the search finds (portal_find.c): without portals,
 * next-event estimation of a sky through a window and the intermediate
 * subpaths have nothing to aim at, and on window-room-forest's stripped
 * copy pt's relative variance was 9x, portal's 109x the marked scene's
 * (src/prepare/README.md, "Found portals"). */
int policy_portals(int option, uint32_t marked)
{
	switch (option) {
	case AJAR_PORTALS_MARKED: return marked ? POLICY_PORTALS_MARKED : POLICY_PORTALS_NONE;
	case AJAR_PORTALS_FOUND: return POLICY_PORTALS_FOUND;
	case AJAR_PORTALS_NONE: return POLICY_PORTALS_NONE;
	default: return marked ? POLICY_PORTALS_MARKED : POLICY_PORTALS_FOUND;
	}
}

void policy_choose(const PolicyInput *in, const PolicyOverrides *over, const char *source, Policy *p)
{
	static const PolicyOverrides none;
	if (!over)
		over = &none;
	if (!source)
		source = "scene";
	/* Without portals the portal integrator is bdpt, sample for sample. */
	p->integrator = in->integrator == INTEGRATOR_PORTAL && in->portals == 0 ? INTEGRATOR_BDPT : in->integrator;

	/* Whether a sky image's sun shines in through the portals: its share
	 * of the sky light through them (portal_flux.c, portal_sun_share) is at
	 * least POLICY_SKY_SUN_SHARE, between an overcast sky's 0.020, where
	 * bdpt and portal without light subpaths were even, and
	 * window-room-sunset's 0.066, where bdpt won by 1.3-1.4x. */
	int sun_in = p->integrator != INTEGRATOR_PT && in->env_type == ENV_IMAGE && in->portals > 0 &&
		     in->sun_share >= POLICY_SKY_SUN_SHARE;

	/* The MIS heuristic. auto takes the balance heuristic where a sky
	 * image's sun shining in through the portals is the only light: there it
	 * lowered bdpt's and portal's variance per sample by 9-20% at the same
	 * time on every sky scene with a sun (three pairs of seeds each), while
	 * under lamps and constant skies it went either way, up to 34% worse;
	 * power elsewhere. */
	_Static_assert(AJAR_MIS_POWER == MIS_POWER && AJAR_MIS_BALANCE == MIS_BALANCE, "the kernels read ajar_mis");
	p->mis = in->mis;
	if (in->mis == AJAR_MIS_AUTO) {
		p->mis = sun_in && in->emitters == 0 && in->lamps == 0 ? MIS_BALANCE : MIS_POWER;
		if (p->mis == MIS_BALANCE)
			log_msg(AJAR_LOG_INFO, "%s: a sky image's sun shines in through the portals; MIS by the balance heuristic",
				source);
	}

	/* Light subpaths. A constant sky's start on a disk as wide as the scene
	 * and rarely find an opening: where such a sky is the only light, the
	 * intermediate subpaths (which start on the portals) do their work, and
	 * portal leaves light subpaths out. A sky image's start on lines through
	 * the portals (kernels/light/lights.h, line_sample) and pay where its
	 * sun shines in: better per CPU second on window-room-forest,
	 * living-room-forest and window-room-sunset. Emitters and punctual
	 * lights keep theirs (a sun lamp's start on the portals and find its
	 * patch). */
	p->light_paths = p->integrator != INTEGRATOR_PORTAL || in->emitters > 0 || in->lamps > 0 ||
			 (p->integrator == INTEGRATOR_PORTAL && sun_in);

	/* The intermediate strategies in use (kernels/integrator/portal.h).
	 * Where the sky is the only light, next-event estimation through the
	 * portals takes the direct light, and short halves and eye parts of at
	 * most 3 vertices do best. With emitters behind an opening (door-ajar)
	 * the intermediate subpaths carry the indirect light on both sides of
	 * it, with halves and eye parts as long as the depth allows; a point or
	 * spot light behind a portal counts as such an emitter (door-ajar with a
	 * point lamp: the long halves at rate 1 did 1.5x better than bdpt and
	 * 1.25x better than the sky's set). Punctual lights on the camera's side
	 * take the sky's set: on window-room-sun the long halves at rate 1 cost
	 * 3x the time for no less noise, on window-room-lamp 3.5x bdpt's
	 * inefficiency. */
	int long_set = p->light_paths && (p->integrator != INTEGRATOR_PORTAL || in->emitters > 0 ||
					  in->lamp_behind_portal);
	p->portal_s_max = 1;
	p->portal_sp_max = long_set ? AJAR_BIDIR_MAX_DEPTH : 2;
	p->portal_tp_max = long_set ? AJAR_BIDIR_MAX_DEPTH : 1;
	p->portal_t_max = long_set ? 1 << 20 : 3; /* any t, or 3 */
	if (over->portal_set_given) {
		p->portal_s_max = over->portal_set[0];
		p->portal_sp_max = over->portal_set[1];
		p->portal_tp_max = over->portal_set[2];
		p->portal_t_max = over->portal_set[3];
		p->light_paths = over->portal_set[4] != 0;
	}
	if (!p->light_paths && p->portal_s_max > 1)
		p->portal_s_max = 1; /* larger s needs light subpaths */

	/* Where light subpaths bring the light in through the openings (a sky
	 * image with a sun, punctual lights without emitters), the sky's
	 * intermediate strategies carry under 1.5% of the image, and the union
	 * weights of every path that crosses a portal cost 1.1-1.3x bdpt's time
	 * per sample for the same variance per sample: portal renders as bdpt
	 * there, joining eye vertices to the first POLICY_PORTAL_BDPT_CONN light
	 * vertices. A forced strategy set keeps the intermediate subpaths. */
	p->bdpt_conn = 0;
	if (p->integrator == INTEGRATOR_PORTAL && p->light_paths && !long_set && !over->portal_set_given) {
		p->integrator = INTEGRATOR_BDPT;
		p->bdpt_conn = POLICY_PORTAL_BDPT_CONN;
		log_msg(AJAR_LOG_INFO,
			"%s: light subpaths bring the light in through the portals; portal renders as bdpt, connecting "
			"eye vertices to the first %d light vertices",
			source, POLICY_PORTAL_BDPT_CONN);
	}
	if (over->bdpt_conn_given && p->integrator == INTEGRATOR_BDPT)
		p->bdpt_conn = over->bdpt_conn;

	p->sky_res = over->sky_res ? over->sky_res : sky_res(in, p->integrator);

	float rate = long_set ? RATE_EMITTERS : RATE_SKY;
	if (!p->light_paths && in->sky_planes > 0)
		rate = RATE_SKY_IMAGE;
	if (over->portal_rate > 0.0f)
		rate = over->portal_rate;
	/* Layers without MIS weights (tests) take every intermediate subpath. */
	p->portal_rate = in->strategy_unweighted ? 1.0f : rate;
}
