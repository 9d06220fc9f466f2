/* gltf_confine.c — the scene-folder rule's test: whether a file the scene
 * names resolves, after `..` and symbolic links, inside the scene file's
 * folder (src/scene/README.md, "Scene files stay in their folder"). */
#include "scene/gltf_parts.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

int gltf_path_inside(const char *root, const char *path, char *real)
{
	if (!realpath(path, real))
		return -1;
	size_t n = strlen(root);
	return strncmp(real, root, n) == 0 && (real[n] == '\0' || real[n] == '/' || strcmp(root, "/") == 0);
}
