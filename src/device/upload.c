/* upload.c — SceneData on one device, one read-only buffer per array. A
 * device on the CPU reads the host's arrays where they are
 * (CL_MEM_USE_HOST_PTR: PoCL makes no copy), so the scene's geometry stays
 * one copy in memory (issue 42); other devices get copies. Params alone is
 * copied everywhere: the host rewrites it (render_device_reset). */
#include "device/upload.h"

#include <string.h>

ajar_status upload_scene(Device *d, const SceneData *sd, SceneBuffers *b)
{
	ajar_status st;
	memset(b, 0, sizeof *b);
#define AJAR_UPLOAD(type, name)                                                                        \
	if ((st = device_buffer(d, CL_MEM_READ_ONLY | (d->is_cpu && strcmp(#name, "params") ?         \
							   CL_MEM_USE_HOST_PTR : 0),                     \
				sizeof(type) * sd->n_##name, sd->name, &b->mem[b->count])) != AJAR_OK) {        \
		upload_free(b);                                                                        \
		return st;                                                                             \
	}                                                                                              \
	b->bytes += sizeof(type) * sd->n_##name;                                                       \
	b->count++;
	AJAR_SCENE_BUFFERS(AJAR_UPLOAD)
#undef AJAR_UPLOAD
	return AJAR_OK;
}

ajar_status upload_bind(Device *d, cl_kernel k, const SceneBuffers *b, cl_uint *next)
{
	for (int i = 0; i < b->count; i++)
		CL_TRY(d, clSetKernelArg(k, (cl_uint)i, sizeof(cl_mem), &b->mem[i]));
	*next = (cl_uint)b->count;
	return AJAR_OK;
}

void upload_free(SceneBuffers *b)
{
	for (int i = 0; i < b->count; i++)
		if (b->mem[i])
			clReleaseMemObject(b->mem[i]);
	memset(b, 0, sizeof *b);
}
