/* render_state.c — what every room of the renderer asks of its state: the
 * clock, range lists, and the hashes that identify what a renderer renders
 * (a checkpoint is refused by another scene or parameter set, the ranks of
 * a job must agree). The scene hash covers the prepared arrays (what the
 * kernels read: geometry, materials, textures, environment, light tables),
 * the params hash the kernels' parameters (options and derived rates).
 * Also the faults tests inject (render_overrides.h), read by the device
 * passes and the scheduler; none in the product. */
#include "render/render_state.h"

#include <stdlib.h>
#include <time.h>

#include "render/render_overrides.h"

RenderFaults render_faults;

double render_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

int range_list_push(RangeList *l, Range g)
{
	if (l->n && l->r[l->n - 1].first + l->r[l->n - 1].count == g.first) {
		l->r[l->n - 1].count += g.count;
		return 1;
	}
	if (l->n == l->cap) {
		size_t cap = l->cap ? 2 * l->cap : 16;
		Range *p = realloc(l->r, cap * sizeof *p);
		if (!p)
			return 0;
		l->r = p;
		l->cap = cap;
	}
	l->r[l->n++] = g;
	return 1;
}

void render_ensure_hashes(ajar_renderer *r)
{
	if (r->hashed)
		return;
	const SceneData *d = &r->data;
	uint64_t h = 0;
#define AJAR_HASH_FIELD(type, name) \
	if ((void *)d->name != (void *)d->params) \
		h = checkpoint_hash(h, d->name, sizeof(type) * d->n_##name);
	AJAR_SCENE_BUFFERS(AJAR_HASH_FIELD)
#undef AJAR_HASH_FIELD
	r->scene_hash = h;
	r->params_hash = checkpoint_hash(0, d->params, sizeof *d->params);
	r->hashed = 1;
}
