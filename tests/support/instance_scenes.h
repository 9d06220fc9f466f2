/* instance_scenes.h — the glTF scene the instancing tests load twice, as
 * instances and flattened (tests/unit/test_instances.c,
 * tests/render/test_instances_render.c): a room lit through a window
 * (a portal, a white sky) and by two lamps under its ceiling, with a
 * bumpy ball (smooth normals, uvs) drawn by nodes under a non-uniform
 * scale, a mirroring scale, a nested parent and child, and three
 * EXT_mesh_gpu_instancing copies (TRANSLATION, ROTATION, SCALE, required);
 * the lamp mesh is an emitting quad and a shade, one copy mirrored. */
#ifndef AJAR_INSTANCE_SCENES_H
#define AJAR_INSTANCE_SCENES_H

/* dir/name.gltf and dir/name.bin. */
void write_instance_scene(const char *dir, const char *name);
#endif
