/* gltf_instancing.c — which meshes the glTF loader keeps once, as
 * instances, rather than flattened into world space. */
#include "scene/gltf_parts.h"

/* The rule that keeps a mesh used more than once as instances (one copy
 * of its triangles, transformed per ray) rather than flattened into world
 * space (a copy per use): when its copies would add at least
 * INSTANCE_MIN_EXTRA triangles. Measured (AJAR_BENCH_RULE=1 make bench,
 * one thread): instances trace 0.64-0.82x as fast as flattened copies up
 * to 17k triangles in all, 0.94x (and once 1.59x) at 65k, 1.14x at 260k
 * and 2.07x at 4M (src/scene/README.md, "Instances"); 65k flat triangles
 * cost 10 MiB. */
#define INSTANCE_MIN_EXTRA 65536

int gltf_mesh_instanced(uint64_t triangles, uint64_t uses)
{
	return uses >= 2 && triangles * (uses - 1) >= INSTANCE_MIN_EXTRA;
}

uint64_t gltf_mode_triangles(int mode, uint64_t count)
{
	if (mode == GLTF_MODE_TRIANGLES)
		return count / 3;
	if (mode == GLTF_MODE_TRIANGLE_STRIP || mode == GLTF_MODE_TRIANGLE_FAN)
		return count > 2 ? count - 2 : 0;
	return 0;
}
