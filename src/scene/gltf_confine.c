/* gltf_confine.c — the scene-folder rule's test: whether a file the scene
 * names resolves, after `..` and symbolic links, inside the scene file's
 * folder (src/scene/README.md, "Scene files stay in their folder"). */
#include "scene/gltf_parts.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int gltf_path_inside(const char *root, const char *path, char *real)
{
	if (!realpath(path, real))
		return -1;
	size_t n = strlen(root);
	return strncmp(real, root, n) == 0 && (real[n] == '\0' || real[n] == '/' || strcmp(root, "/") == 0);
}

int gltf_confined(const char *root, int allow_outside, const char *path, const char *uri, char *why, size_t size)
{
	why[0] = '\0';
	if (allow_outside)
		return 1;
	char real[PATH_MAX];
	int r = gltf_path_inside(root, path, real);
	if (r == 0)
		snprintf(why, size,
			 "'%s' resolves to %s, outside the scene's folder %s (allow it with --allow-outside-files or "
			 "ajar_load_options.allow_outside_files)",
			 uri, real, root);
	return r > 0;
}
