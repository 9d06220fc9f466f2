/* upload.h — the scene's arrays as device buffers, created and bound to a
 * kernel's leading arguments in the order of AJAR_SCENE_BUFFERS. */
#ifndef AJAR_UPLOAD_H
#define AJAR_UPLOAD_H
#include "device/device.h"
#include "prepare/prepare.h"

#define AJAR_MAX_BUFFERS 24

typedef struct {
	cl_mem mem[AJAR_MAX_BUFFERS];
	int count;
	size_t bytes;
} SceneBuffers;

ajar_status upload_scene(Device *d, const SceneData *sd, SceneBuffers *out);
/* Sets arguments 0 .. count-1 of k; returns the next free argument index in *next. */
ajar_status upload_bind(Device *d, cl_kernel k, const SceneBuffers *b, cl_uint *next);
void upload_free(SceneBuffers *b);
#endif
