/* render_portals.c — the portals a renderer found over the scene's openings
 * (ajar_renderer_found_portals), for reports and `ajar render --portals-out`. */
#include "core/error.h"
#include "prepare/found_portals.h"
#include "render/render_state.h"

ajar_status ajar_renderer_found_portals(const ajar_renderer *r, ajar_portal *out, uint32_t capacity, uint32_t *count,
					double *seconds)
{
	if (!r || !count || (capacity && !out))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_found_portals: NULL renderer, count or portals");
	portals_to_api(&r->data.found, out, capacity, count, seconds);
	return AJAR_OK;
}
