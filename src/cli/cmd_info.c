/* cmd_info.c — `ajar info`: what a scene holds, and the portals a render
 * would find over its openings (--portals-out writes them as glTF). */
#include <math.h>
#include <stdio.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands_shared.h"
#include "cli/portals_gltf.h"

static const char usage_info[] =
	"usage: ajar info SCENE.gltf|SCENE.glb [options]\n"
	"\n"
	"Prints what the scene holds: triangles, materials, lights, marked portals,\n"
	"the portals a render finds over its openings where it marks none, the\n"
	"environment, bounds and camera.\n"
	"\n"
	"  --portals WHICH          auto: search the openings even where portals are\n"
	"                           marked; marked or none: no search\n"
	"  --portals-out FILE.gltf  write the found portals as a glTF file\n"
	"  --sky, --sky-color, --sky-strength, --sky-rotation, --sun\n"
	"                           as for 'ajar render' (the search looks for light\n"
	"                           from them)\n"
	"  --allow-outside-files    let the scene read files outside its folder\n"
	"  -h, --help               this text\n";

int cmd_info(int argc, char **argv)
{
	InfoArgs ia;
	int rc = args_parse_info(argc, argv, &ia);
	if (rc != EXIT_OK)
		return rc;
	if (ia.help) {
		fputs(usage_info, stdout);
		return EXIT_OK;
	}
	if (ia.sc.portals_out && (rc = check_output("--portals-out", ia.sc.portals_out)) != EXIT_OK)
		return rc;
	ajar_scene *scene = NULL;
	rc = load_scene(ia.scene, ia.allow_outside_files, &scene);
	if (rc == EXIT_OK)
		rc = apply_scene_args(scene, &ia.sc);
	if (rc != EXIT_OK) {
		ajar_scene_destroy(&scene);
		return rc;
	}
	ajar_scene_info in;
	ajar_status st = ajar_scene_build_bvh(scene);
	if (st == AJAR_OK)
		st = ajar_scene_info_get(scene, &in);
	if (st != AJAR_OK) {
		report(st, ia.scene);
		ajar_scene_destroy(&scene);
		return exit_code(st);
	}
	static const char *const env[] = {"none", "colour", "image"};
	printf("scene:        %s\n", ia.scene);
	printf("triangles:    %llu (%llu unique, %u instances)\n", (unsigned long long)in.triangles,
	       (unsigned long long)in.unique_triangles, in.instances);
	printf("materials:    %u\n", in.materials);
	printf("emissive:     %u triangles\n", in.emissive_triangles);
	printf("portals:      %u objects, %u triangles (marked)\n", in.portals, in.portal_triangles);
	/* The portals a render would find: where none is marked, or asked for. */
	ajar_portal found[FOUND_MAX];
	uint32_t nfound = 0;
	double seconds = 0.0;
	int search = (in.portal_triangles == 0 && ia.sc.portals == AJAR_PORTALS_DEFAULT) || ia.search ||
		     ia.sc.portals_out;
	if (search && ia.sc.portals != AJAR_PORTALS_NONE && ia.sc.portals != AJAR_PORTALS_MARKED) {
		st = ajar_scene_find_portals(scene, found, FOUND_MAX, &nfound, &seconds);
		if (st != AJAR_OK) {
			report(st, ia.scene);
			ajar_scene_destroy(&scene);
			return exit_code(st);
		}
		printf("found:        %u portal%s over openings (search %.2f s)%s\n", nfound, nfound == 1 ? "" : "s",
		       seconds, in.portal_triangles && !ia.search ? "; a render uses the marked ones" : "");
		print_found(found, nfound);
	} else if (in.portal_triangles) {
		printf("found:        not searched (the scene marks portals; --portals auto searches)\n");
	}
	printf("lights:       %u (KHR_lights_punctual)\n", in.lights);
	for (uint32_t i = 0; i < in.lights; i++) {
		ajar_light l;
		if (ajar_scene_light_get(scene, i, &l) != AJAR_OK)
			break;
		static const char *const kind[] = {"directional", "point", "spot"};
		printf("  [%u] %-11s", i, kind[l.type]);
		if (l.type != AJAR_LIGHT_DIRECTIONAL)
			printf(" at (%g, %g, %g)", l.position[0], l.position[1], l.position[2]);
		if (l.type != AJAR_LIGHT_POINT)
			printf(" toward (%.3f, %.3f, %.3f)", l.direction[0], l.direction[1], l.direction[2]);
		printf(", colour (%g, %g, %g), %g %s", l.color[0], l.color[1], l.color[2], l.intensity,
		       l.type == AJAR_LIGHT_DIRECTIONAL ? "lx" : "cd");
		if (l.type == AJAR_LIGHT_SPOT)
			printf(", cone %.1f..%.1f deg", l.inner_cone * 180.0 / M_PI, l.outer_cone * 180.0 / M_PI);
		if (l.type != AJAR_LIGHT_DIRECTIONAL && l.range > 0.0f)
			printf(", range %g", l.range);
		printf("\n");
	}
	printf("textures:     %u (%u base colour, %u metallic-roughness, %u emissive, %u normal; %.1f MiB)\n",
	       in.textures, in.base_color_textures, in.metallic_roughness_textures, in.emissive_textures,
	       in.normal_textures,
	       (double)in.texture_bytes / (1024.0 * 1024.0));
	printf("alpha-tested: %llu triangles\n", (unsigned long long)in.alpha_triangles);
	printf("memory:       geometry %.1f MiB, BVH %.1f MiB, textures %.1f MiB\n", in.geometry_bytes / 1048576.0,
	       in.bvh_bytes / 1048576.0, in.texture_bytes / 1048576.0);
	printf("times:        loaded in %.2f s, BVH built in %.2f s\n", in.load_seconds, in.bvh_seconds);
	printf("environment:  %s\n", in.environment >= 0 && in.environment <= 2 ? env[in.environment] : "?");
	printf("bounds:       (%g, %g, %g) .. (%g, %g, %g)\n", in.bounds_min[0], in.bounds_min[1],
	       in.bounds_min[2], in.bounds_max[0], in.bounds_max[1], in.bounds_max[2]);
	const ajar_camera *c = &in.camera;
	float d[3] = {c->target[0] - c->position[0], c->target[1] - c->position[1], c->target[2] - c->position[2]};
	float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	if (len > 0)
		for (int k = 0; k < 3; k++)
			d[k] /= len;
	printf("camera:       %sposition (%g, %g, %g), direction (%.3f, %.3f, %.3f), yfov %.1f deg\n",
	       in.has_camera ? "" : "none in the file; default view framing the bounds: ", c->position[0],
	       c->position[1], c->position[2], d[0], d[1], d[2], c->yfov * 180.0 / M_PI);
	if (in.width && in.height)
		printf("resolution:   %ux%u (suggested by the scene)\n", in.width, in.height);
	else
		printf("resolution:   none suggested (renders 512 wide at the camera's aspect)\n");
	ajar_scene_destroy(&scene);
	if (ia.sc.portals_out)
		return portals_write_gltf(ia.sc.portals_out, found, nfound > FOUND_MAX ? FOUND_MAX : nfound);
	return EXIT_OK;
}
