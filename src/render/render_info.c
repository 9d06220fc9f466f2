/* render_info.c — what a renderer tells about itself: each device's
 * samples, speed and share (ajar_renderer_device_stats), the line of the
 * shares the render loop logs and the EXR header records (with a remote
 * device's idle time between its ranges), and the header's other fields. */
#include "render/render_info.h"

#include <stdio.h>
#include <string.h>

#include "render/render_state.h"

void render_info_device(const ajar_renderer *r, uint32_t index, ajar_device_stats *out)
{
	const RenderDevice *rd = &r->devs[index];
	memset(out, 0, sizeof *out);
	snprintf(out->name, sizeof out->name, "%.127s", rd->dev.name);
	snprintf(out->selector, sizeof out->selector, "%.31s", rd->dev.selector);
	pthread_mutex_lock((pthread_mutex_t *)&r->lock);
	out->samples = rd->spp_kept * r->width * r->height;
	out->samples_per_second = rd->busy_seconds > 0 ? out->samples / rd->busy_seconds : 0.0;
	out->share = r->spp_done ? (double)rd->spp_kept / r->spp_done : 0.0;
	out->failed = !rd->alive;
	pthread_mutex_unlock((pthread_mutex_t *)&r->lock);
}

void render_info_shares(const ajar_renderer *r, char *buf, size_t cap)
{
	size_t len = 0;
	buf[0] = '\0';
	for (uint32_t i = 0; i < r->ndev && len < cap; i++) {
		ajar_device_stats s;
		render_info_device(r, i, &s);
		len += (size_t)snprintf(buf + len, cap - len, "%s%s (%s): %.1f%% %.3g Msamples/s%s", i ? "; " : "",
					s.name, s.selector, 100 * s.share, s.samples_per_second * 1e-6,
					s.failed ? " (failed)" : "");
		/* Another rank's device: how long it waited there between its ranges. */
		const RenderDevice *rd = &r->devs[i];
		if (rd->job_ranges && len < cap)
			len += (size_t)snprintf(buf + len, cap - len, ", idle %.2f ms between ranges (mean of %u)",
						1e3 * rd->job_idle / rd->job_ranges, rd->job_ranges);
	}
}

static const char *integrator_name(ajar_integrator i)
{
	return i == AJAR_INTEGRATOR_BDPT ? "bdpt" : i == AJAR_INTEGRATOR_PORTAL ? "portal" : "pt";
}

void render_info(const ajar_renderer *r, RenderInfo *info)
{
	memset(info, 0, sizeof *info);
	info->width = r->width;
	info->height = r->height;
	info->spp = r->spp_done;
	info->seed = r->seed;
	info->max_depth = r->max_depth;
	info->seconds = r->elapsed;
	info->integrator = integrator_name(r->integrator);
	info->devices = r->device_names;
	render_info_shares(r, info->shares, sizeof info->shares);
	info->scene = r->scene_name;
	info->nlayers = r->nlayers;
	info->strategy_len = r->strategy_len;
	info->strategy_unweighted = r->strategy_unweighted;
	info->layers = r->film_splat + 3 * (size_t)r->width * r->height;
	info->aov = r->opt.aov;
}
