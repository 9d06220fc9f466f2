/* test_scene_materials.c — materials and textures as the loader and the
 * scene build them: every material extension read (and one warning for
 * each member read but not used), texture coordinates, samplers, texture
 * transforms and vertex colours end to end, the Khronos sample assets
 * (scenes/khronos) with what each exercises, tangents generated where a
 * file has none, and normal maps that shade as the tilted plane. */
#include "scene_files.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/surface.h"

/* A 4 x 4 PNG (the one of uv_gltf below), for texture slots. */
#define UV_PNG_LAYERS "iVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAYAAACp8Z5+AAAAK0lEQVR4nBXIMQEAMBACMWaEIQxhWGvvhyyRrRcUgxwCxXJRAsV6MQLF8AFZeRxxtxm5jwAAAABJRU5ErkJggg=="

static void test_non_indexed_and_materials(void **state)
{
	/* Two non-indexed triangles, drawn twice: with a material using every
	 * extension we read, and without a material. */
	const float pos[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1};
	write_bytes("flat.bin", pos, sizeof pos);
	write_text("flat.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0},"
		   "{\"attributes\":{\"POSITION\":0}}]}],"
		   "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,0.125,1],"
		   "\"metallicFactor\":0.2,\"roughnessFactor\":0.3},\"emissiveFactor\":[1,0.5,0],"
		   "\"doubleSided\":true,\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25,\"extensions\":{"
		   "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4},"
		   "\"KHR_materials_transmission\":{\"transmissionFactor\":0.75},"
		   "\"KHR_materials_ior\":{\"ior\":1.33},\"KHR_materials_specular\":{\"specularFactor\":0.5}}}],"
		   "\"extensionsUsed\":[\"KHR_materials_emissive_strength\",\"KHR_materials_transmission\","
		   "\"KHR_materials_ior\",\"KHR_materials_specular\"],"
		   "\"extensionsRequired\":[\"KHR_materials_transmission\"],"
		   "\"buffers\":[{\"uri\":\"flat.bin\",\"byteLength\":72}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":72}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"}]}");
	Scene *s = load_ok("flat.gltf");
	assert_int_equal(s->ntris, 4);
	assert_v3(s->tris[1].p0, 0, 0, 1);
	assert_v3(s->tris[1].p2, 0, 1, 1);
	assert_int_equal(s->shade[0].has_normals, 0);
	assert_int_equal(s->nmaterials, 2);
	const Material *m = &s->materials[0];
	assert_v3(m->base_color, 0.5f, 0.25f, 0.125f);
	assert_v3(m->emission, 4.0f, 2.0f, 0.0f);
	assert_float_equal(m->metallic, 0.2f, 1e-7);
	assert_float_equal(m->roughness, 0.3f, 1e-7);
	assert_float_equal(m->transmission, 0.75f, 0.0);
	assert_float_equal(m->ior, 1.33f, 1e-7);
	assert_float_equal(m->specular, 0.5f, 0.0);
	assert_int_equal(m->flags, MATERIAL_DOUBLE_SIDED | MATERIAL_ALPHA_MASK);
	assert_float_equal(m->alpha_cutoff, 0.25f, 0.0);
	assert_int_equal(s->tris[0].material, 0);
	assert_int_equal(s->tris[2].material, 1);
	assert_float_equal(s->materials[1].metallic, 1.0f, 0.0);
	assert_int_equal(scene_count_emissive(s), 2);
	ajar_scene_destroy(&s);
}

static void test_unread_extension_members(void **state)
{
	(void)state;
	/* Members of the extensions we read that we do not use, and material
	 * extensions we do not read: one warning each, naming it; the factors
	 * still apply. */
	const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	write_bytes("unread.bin", pos, sizeof pos);
	const char *head = "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
			   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
			   "\"materials\":[{\"extensions\":{";
	const char *tail = "}}],\"buffers\":[{\"uri\":\"unread.bin\",\"byteLength\":36}],"
			   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
			   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
	const struct {
		const char *ext, *want;
		int warnings;
	} cases[] = {
		{"\"KHR_materials_transmission\":{\"transmissionFactor\":0.5},"
		 "\"KHR_materials_volume\":{\"thicknessFactor\":0.1,\"thicknessTexture\":{\"index\":0}}",
		 "KHR_materials_volume.thicknessTexture is not supported", 1},
		{"\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,1,1]}", "", 0},
		/* extensions Blender writes that Ajar does not model: one warning
		 * each, naming the material and the extension */
		{"\"KHR_materials_specular\":{\"specularFactor\":0.5},\"KHR_materials_dispersion\":{\"dispersion\":0.1}",
		 "KHR_materials_dispersion is not supported", 1},
		{"\"KHR_materials_specular\":{\"specularFactor\":0.5},\"KHR_materials_iridescence\":{\"iridescenceFactor\":1}",
		 "KHR_materials_iridescence is not supported", 1},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		char json[2048];
		snprintf(json, sizeof json, "%s%s%s", head, cases[k].ext, tail);
		write_text("unread.gltf", json);
		warnings = 0;
		last_warning[0] = '\0';
		ajar_set_log_callback(count_warnings, NULL);
		Scene *s = load_ok("unread.gltf");
		ajar_set_log_callback(NULL, NULL);
		assert_int_equal(warnings, cases[k].warnings);
		if (!strstr(last_warning, cases[k].want) || (cases[k].warnings && !strstr(last_warning, "materials[0]")))
			fail_msg("case %zu: warning \"%s\"", k, last_warning);
		assert_float_equal(k == 0 ? s->materials[0].transmission : s->materials[0].specular, 0.5f, 0.0);
		ajar_scene_destroy(&s);
	}
}

/* KHR_materials_sheen, _clearcoat, _anisotropy and _specular's colour and
 * textures: every factor and texture arrives (textures + 1), the specular
 * colour sets MATERIAL_TINTED only where it is not white, the rotation is
 * kept in [-pi, pi], tangents are generated for an anisotropic material
 * without a normal map; bad values are bad input naming the member. */
static void test_layer_extensions(void **state)
{
	(void)state;
	const float pos_uv[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
	write_bytes("layers.bin", pos_uv, 60);
	const char *fmt =
		"{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
		"\"materials\":[{\"extensions\":{%s}}],\"textures\":[{\"source\":0}],"
		"\"images\":[{\"uri\":\"data:image/png;base64," UV_PNG_LAYERS "\"}],"
		"\"buffers\":[{\"uri\":\"layers.bin\",\"byteLength\":60}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
		"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}]}";
	char json[4096];
	snprintf(json, sizeof json, fmt,
		 "\"KHR_materials_sheen\":{\"sheenColorFactor\":[0.9,0.5,0.25],\"sheenRoughnessFactor\":0.4,"
		 "\"sheenColorTexture\":{\"index\":0},\"sheenRoughnessTexture\":{\"index\":0}},"
		 "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":0.75,\"clearcoatRoughnessFactor\":0.125,"
		 "\"clearcoatTexture\":{\"index\":0},\"clearcoatRoughnessTexture\":{\"index\":0},"
		 "\"clearcoatNormalTexture\":{\"index\":0,\"scale\":0.5}},"
		 "\"KHR_materials_anisotropy\":{\"anisotropyStrength\":0.6,\"anisotropyRotation\":7.0,"
		 "\"anisotropyTexture\":{\"index\":0}},"
		 "\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,0.5,2],"
		 "\"specularTexture\":{\"index\":0},\"specularColorTexture\":{\"index\":0}}");
	write_text("layers.gltf", json);
	warnings = 0;
	ajar_set_log_callback(count_warnings, NULL);
	Scene *s = load_ok("layers.gltf");
	ajar_set_log_callback(NULL, NULL);
	assert_int_equal(warnings, 0);
	const Material *m = &s->materials[0];
	assert_v3(m->sheen_color, 0.9f, 0.5f, 0.25f);
	assert_float_equal(m->sheen_roughness, 0.4f, 1e-7);
	assert_float_equal(m->clearcoat, 0.75f, 0.0);
	assert_float_equal(m->clearcoat_roughness, 0.125f, 0.0);
	assert_float_equal(m->clearcoat_normal_scale, 0.5f, 0.0);
	assert_float_equal(m->anisotropy, 0.6f, 1e-7);
	assert_float_equal(m->anisotropy_rotation, 7.0 - 2 * M_PI, 1e-6);
	assert_float_equal(m->specular, 0.5f, 0.0);
	assert_v3(m->specular_color, 1.0f, 0.5f, 2.0f);
	assert_true(m->flags & MATERIAL_TINTED);
	const int tex[] = {m->sheen_color_tex, m->sheen_rough_tex, m->clearcoat_tex, m->clearcoat_rough_tex,
			   m->clearcoat_normal_tex, m->anisotropy_tex, m->specular_tex, m->specular_color_tex};
	for (int k = 0; k < 8; k++)
		assert_true(tex[k] >= 1 && tex[k] <= (int)s->ntextures);
	assert_true(s->tris[0].flags & TRI_TANGENT); /* anisotropy: tangents generated from TEXCOORD_0 */
	ajar_scene_destroy(&s);

	/* White specular colour: no tint; out-of-range values refused. */
	snprintf(json, sizeof json, fmt, "\"KHR_materials_specular\":{\"specularColorFactor\":[1,1,1]}");
	write_text("layers.gltf", json);
	s = load_ok("layers.gltf");
	assert_false(s->materials[0].flags & MATERIAL_TINTED);
	assert_int_equal(s->materials[0].anisotropy_tex, 0);
	ajar_scene_destroy(&s);
	const char *bad[] = {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[2,0,0]}",
			     "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":-1}",
			     "\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1.5}",
			     "\"KHR_materials_specular\":{\"specularColorFactor\":[1,1]}"};
	const char *member[] = {"sheenColorFactor", "clearcoatFactor", "anisotropyStrength", "specularColorFactor"};
	for (int k = 0; k < 4; k++) {
		snprintf(json, sizeof json, fmt, bad[k]);
		write_text("layers.gltf", json);
		load_fails("layers.gltf", AJAR_ERROR_BAD_INPUT, member[k]);
	}
}

/* ---- Texture coordinates, samplers, transforms, vertex colours ----------
 * One triangle (0,0,0) (1,0,0) (0,1,0) with TEXCOORD_0 = xy, TEXCOORD_1 =
 * (0.5 + x/2, 0.5 + y/2) and COLOR_0 red, green, blue (alpha 0.5) as
 * normalized bytes, and a 4 x 4 PNG whose texel (x, y) is
 * (60x + 10, 60y + 10, 0). Three materials: TEXCOORD_1 with a clamp (s) /
 * mirrored-repeat (t) nearest sampler; KHR_texture_transform offset
 * (0.25, 0), scale 0.5; rotation pi/2 and texCoord 1 (repeat, nearest). */
#define UV_BUFFER "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAPwAAAD8AAIA/AAAAPwAAAD8AAIA//wAA/wD/AP8AAP+A"
#define UV_PNG "iVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAYAAACp8Z5+AAAAK0lEQVR4nBXIMQEAMBACMWaEIQxhWGvvhyyRrRcUgxwCxXJRAsV6MQLF8AFZeRxxtxm5jwAAAABJRU5ErkJggg=="
static const char uv_gltf[] =
	"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_texture_transform\"],"
	"\"extensionsRequired\":[\"KHR_texture_transform\"],\"scenes\":[{\"nodes\":[0,1,2]}],"
	"\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"mesh\":2}],"
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"TEXCOORD_1\":2,\"COLOR_0\":3},\"material\":0}]},"
	"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1}]},"
	"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2}]}],"
	"\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1}}},"
	"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":"
	"{\"offset\":[0.25,0],\"scale\":[0.5,0.5]}}}}},"
	"{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":1,\"extensions\":{\"KHR_texture_transform\":"
	"{\"rotation\":1.5707963267948966,\"texCoord\":1}}}}}],"
	"\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":0,\"sampler\":1}],"
	"\"samplers\":[{\"magFilter\":9728,\"wrapS\":33071,\"wrapT\":33648},{\"magFilter\":9728}],"
	"\"images\":[{\"uri\":\"data:image/png;base64," UV_PNG "\"}],"
	"\"buffers\":[{\"byteLength\":96,\"uri\":\"data:application/octet-stream;base64," UV_BUFFER "\"}],"
	"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
	"{\"buffer\":0,\"byteOffset\":60,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":12}],"
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
	"{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
	"{\"bufferView\":3,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"}]}";

/* KHR_materials_volume and KHR_materials_transmission's texture: a
 * thickness above 0 makes a refracting solid (MATERIAL_VOLUME) absorbing
 * sigma = -ln(attenuationColor) / attenuationDistance; thickness 0 or no
 * volume is thin-walled, and smooth thin glass is a pane (TRI_PANE) that
 * shadow rays cross, rough or volume glass is not; the transmission
 * texture is kept (+1, as the other texture slots). Bad volume values are
 * bad input naming the member. */
static void test_volume_and_transmission(void **state)
{
	(void)state;
	static const char head[] =
		"{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_transmission\",\"KHR_materials_volume\"],"
		"\"scenes\":[{\"nodes\":[0,1,2,3]}],\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"mesh\":2},{\"mesh\":3}],"
		"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":1}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":2}]},"
		"{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":3}]}],"
		"\"materials\":[";
	static const char tail[] =
		"],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64," UV_PNG "\"}],"
		"\"buffers\":[{\"byteLength\":96,\"uri\":\"data:application/octet-stream;base64," UV_BUFFER "\"}],"
		"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
		"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
		"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}]}";
	static const char good[] =
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
		"\"KHR_materials_volume\":{\"thicknessFactor\":0.5,\"attenuationColor\":[0.5,0.25,1],\"attenuationDistance\":2}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
		"\"KHR_materials_volume\":{\"thicknessFactor\":0}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":0.8,"
		"\"transmissionTexture\":{\"index\":0}}}},"
		"{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0.5},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1}}}";
	char json[8192];
	snprintf(json, sizeof json, "%s%s%s", head, good, tail);
	write_text("volume.gltf", json);
	Scene *s = load_ok("volume.gltf");
	const Material *m = s->materials;
	assert_true(m[0].flags & MATERIAL_VOLUME);
	assert_v3(m[0].sigma, (float)(log(2.0) / 2), (float)(log(4.0) / 2), 0.0f);
	assert_false(m[1].flags & MATERIAL_VOLUME);
	assert_false(m[2].flags & MATERIAL_VOLUME);
	assert_int_equal(m[2].transmission_tex, s->materials[2].transmission_tex);
	assert_true(m[2].transmission_tex >= 1 && m[2].transmission_tex <= (int)s->ntextures);
	assert_float_equal(m[2].transmission, 0.8f, 1e-7);
	assert_int_equal(m[1].transmission_tex, 0);
	/* One triangle a mesh, in node order: the volume is no pane, thin
	 * smooth glass is (textured or not), rough thin glass is not. */
	assert_int_equal(s->ntris, 4);
	assert_false(s->tris[0].flags & TRI_PANE);
	assert_true(s->tris[1].flags & TRI_PANE);
	assert_true(s->tris[2].flags & TRI_PANE);
	assert_false(s->tris[3].flags & TRI_PANE);
	ajar_scene_destroy(&s);
	const char *bad[][2] = {
		{"\"attenuationDistance\":0", "attenuationDistance"},
		{"\"attenuationColor\":[1,2,1]", "attenuationColor"},
		{"\"attenuationColor\":[1,1]", "attenuationColor"},
		{"\"thicknessFactor\":-1", "thicknessFactor"},
	};
	for (int k = 0; k < 4; k++) {
		char mat[512];
		snprintf(mat, sizeof mat,
			 "{\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
			 "\"KHR_materials_volume\":{\"thicknessFactor\":1,%s}}},{},{},{}",
			 bad[k][0]);
		if (k == 3)
			snprintf(mat, sizeof mat, "{\"extensions\":{\"KHR_materials_volume\":{%s}}},{},{},{}", bad[k][0]);
		snprintf(json, sizeof json, "%s%s%s", head, mat, tail);
		write_text("volume.gltf", json);
		load_fails("volume.gltf", AJAR_ERROR_BAD_INPUT, bad[k][1]);
	}
}

/* Texel (x, y)'s red and green, as texture_rgba reads them undecoded. */
static void assert_texel(Rgba c, int x, int y)
{
	if (fabsf(c.rgb.x - (60 * x + 10) / 255.0f) > EPS || fabsf(c.rgb.y - (60 * y + 10) / 255.0f) > EPS)
		fail_msg("read (%g, %g), want texel (%d, %d)", c.rgb.x * 255, c.rgb.y * 255, x, y);
}

static void test_texture_coordinates(void **state)
{
	(void)state;
	write_text("uv.gltf", uv_gltf);
	Scene *s = load_ok("uv.gltf");
	assert_int_equal(s->nimages, 1);
	SceneView sc = scene_surface_view(s);
	int t0 = s->materials[0].base_tex, t1 = s->materials[1].base_tex, t2 = s->materials[2].base_tex;
	/* Wrap modes at and past the edges: clamp in s, mirrored repeat in t. */
	assert_texel(texture_rgba(&sc, t0, 1.3f, 0.1f, 0), 3, 0);
	assert_texel(texture_rgba(&sc, t0, -0.2f, 0.1f, 0), 0, 0);
	assert_texel(texture_rgba(&sc, t0, 0.99f, 0.99f, 0), 3, 3);
	assert_texel(texture_rgba(&sc, t0, 0.1f, 1.2f, 0), 0, 3);   /* 2 - 1.2 = 0.8 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, -0.1f, 0), 0, 0);  /* 0.1 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, 2.3f, 0), 0, 1);   /* 0.3 */
	assert_texel(texture_rgba(&sc, t0, 0.1f, -1.3f, 0), 0, 2);  /* 2 - 1.3 = 0.7 */
	/* Repeat (texture 1's sampler) and the transform: offset + scale x uv. */
	assert_texel(texture_rgba(&sc, t1, 0.1f, 0.1f, 0), 1, 0);   /* (0.3, 0.05) */
	assert_texel(texture_rgba(&sc, t1, 1.9f, 0.9f, 0), 0, 1);   /* (1.2, 0.45) -> 0.2 */
	/* Rotation pi/2: (u, v) -> (v, -u), as TextureTransformTest shows. */
	assert_true(s->textures[t2].flags & TEX_UV1);
	assert_texel(texture_rgba(&sc, t2, 0.1f, 0.6f, 0), 2, 3);   /* (0.6, -0.1) -> (0.6, 0.9) */
	/* Bilinear (a use with the default sampler): halfway between texel
	 * centres 0 and 1, blended before decoding (as Cycles: texture.h). */
	const float id[6] = {1, 0, 0, 0, 1, 0};
	uint32_t lin;
	assert_int_equal(scene_add_texture_use(s, 0, 0, id, &lin), AJAR_OK);
	sc.textures = s->textures;
	Rgba c = texture_rgba(&sc, (int)lin, 0.25f, 0.125f, 0);
	assert_float_equal(c.rgb.x, 40.0f / 255.0f, EPS);
	assert_float_equal(c.rgb.y, 10.0f / 255.0f, EPS);
	c = texture_rgba(&sc, (int)lin, 0.25f, 0.125f, 1);
	assert_float_equal(c.rgb.x, srgb_to_linear(40.0f / 255), EPS);
	assert_true(c.rgb.x < 0.5f * (srgb_to_linear(10.0f / 255) + srgb_to_linear(70.0f / 255)) - 0.005f);
	/* TEXCOORD_1 and COLOR_0 end to end: at barycentrics (0.2, 0.2) of
	 * triangle 0, TEXCOORD_1 is (0.6, 0.6) (texel (2, 2)) and the colour
	 * (0.6, 0.2, 0.2), alpha 0.6 + 0.2 + 0.2 x 128/255. */
	assert_true(s->tris[0].flags & TRI_EXTRA);
	assert_false(s->tris[1].flags & TRI_EXTRA);
	Hit h = {1.0f, 0.2f, 0.2f, 0, -1};
	Surface sf;
	surface_from_hit(&sc, &h, &sf);
	assert_float_equal(sf.alpha, 0.8f + 0.2f * 128.0f / 255.0f, EPS);
	V3 base = surface_base_color(&sc, &sf);
	float t22 = srgb_to_linear(130.0f / 255.0f);
	assert_v3(base, 0.6f * t22, 0.2f * t22, 0.0f);
	h.tri = 1; /* no COLOR_0: white */
	surface_from_hit(&sc, &h, &sf);
	assert_v3(sf.color, 1, 1, 1);
	ajar_scene_destroy(&s);
}

/* ---- The Khronos sample assets (scenes/khronos) ---------------------------
 * Each loads without a warning, and what it exercises arrives: required
 * KHR_texture_transform, clamp and mirror samplers, TEXCOORD_1, COLOR_0,
 * MASK and BLEND, sheen, clear coat and anisotropy. */
typedef struct {
	int warnings;
	char last[512];
} LogCount;

static void count_asset_warnings(ajar_log_level level, const char *msg, void *user)
{
	LogCount *c = user;
	if (level == AJAR_LOG_WARNING) {
		c->warnings++;
		snprintf(c->last, sizeof c->last, "%s", msg);
	}
}

static Scene *load_asset(const char *name, ajar_scene_info *in)
{
	char path[256];
	snprintf(path, sizeof path, SCENE("khronos/%s/%s.gltf"), name, name);
	LogCount c = {0, ""};
	ajar_set_log_callback(count_asset_warnings, &c);
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load(path, &s);
	ajar_set_log_callback(NULL, NULL);
	if (st)
		fail_msg("%s: %s", path, ajar_last_error());
	if (c.warnings)
		fail_msg("%s: %d warnings, the last: %s", path, c.warnings, c.last);
	assert_int_equal(ajar_scene_info_get(s, in), AJAR_OK);
	return s;
}

static void test_khronos_assets(void **state)
{
	(void)state;
	ajar_scene_info in;
	Scene *s = load_asset("TextureTransformTest", &in);
	int moved = 0, clamped = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		int t = s->materials[i].base_tex;
		if (t < 0)
			continue;
		moved += s->textures[t].xf[2] != 0.0f || s->textures[t].xf[5] != 0.0f || s->textures[t].xf[1] != 0.0f ||
			 s->textures[t].xf[0] != 1.0f;
		clamped += TEX_WRAP_S(s->textures[t].flags) == TEX_WRAP_CLAMP;
	}
	assert_true(moved >= 6);
	assert_true(clamped >= 1);
	ajar_scene_destroy(&s);

	s = load_asset("TextureSettingsTest", &in);
	int modes = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		int t = s->materials[i].base_tex;
		if (t >= 0)
			modes |= 1 << TEX_WRAP_S(s->textures[t].flags) | 8 << TEX_WRAP_T(s->textures[t].flags);
	}
	assert_int_equal(modes, 63); /* every mode on both axes */
	ajar_scene_destroy(&s);

	s = load_asset("MultiUVTest", &in);
	assert_int_equal(in.emissive_textures, 1);
	int uv1 = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++)
		if (s->materials[i].emissive_tex)
			uv1 += (s->textures[s->materials[i].emissive_tex - 1].flags & TEX_UV1) != 0;
	assert_int_equal(uv1, 1);
	assert_true(s->extra != NULL);
	ajar_scene_destroy(&s);

	s = load_asset("VertexColorTest", &in);
	uint32_t coloured = 0;
	for (uint32_t i = 0; i < s->ntris; i++)
		coloured += (s->tris[i].flags & TRI_EXTRA) != 0;
	assert_true(coloured > 0 && coloured < s->ntris);
	ajar_scene_destroy(&s);

	s = load_asset("AlphaBlendModeTest", &in);
	int mask = 0, blend = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		mask += (s->materials[i].flags & MATERIAL_ALPHA_MASK) != 0;
		blend += (s->materials[i].flags & MATERIAL_ALPHA_BLEND) != 0;
	}
	assert_int_equal(mask, 3);
	assert_int_equal(blend, 1);
	assert_int_equal(in.normal_textures, 1);
	assert_true(in.alpha_triangles > 0);
	ajar_scene_destroy(&s);

	s = load_asset("EmissiveStrengthTest", &in);
	assert_true(in.emissive_triangles > 0);
	ajar_scene_destroy(&s);

	/* The layers and anisotropy Blender writes (issue 44). */
	s = load_asset("SheenCloth", &in);
	assert_true(s->materials[0].sheen_color_tex && s->materials[0].sheen_rough_tex);
	assert_float_equal(s->materials[0].sheen_roughness, 1.0f, 0.0);
	ajar_scene_destroy(&s);
	s = load_asset("ClearcoatWicker", &in);
	assert_float_equal(s->materials[0].clearcoat, 1.0f, 0.0);
	assert_float_equal(s->materials[0].clearcoat_roughness, 0.1f, 1e-7);
	assert_true(s->materials[0].clearcoat_normal_tex && s->materials[0].normal_tex);
	ajar_scene_destroy(&s);
	s = load_asset("AnisotropyStrengthTest", &in);
	int aniso = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++)
		aniso += s->materials[i].anisotropy > 0.0f;
	assert_int_equal(aniso, 42); /* 7 roughnesses x strengths 1/6 .. 1 */
	ajar_scene_destroy(&s);
	s = load_asset("AnisotropyRotationTest", &in);
	int turned = 0, textured = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		turned += s->materials[i].anisotropy_rotation != 0.0f;
		textured += s->materials[i].anisotropy_tex != 0;
	}
	assert_int_equal(turned, 2);
	assert_int_equal(textured, 2);
	uint32_t tangents = 0;
	for (uint32_t i = 0; i < s->ntris; i++)
		tangents += (s->tris[i].flags & TRI_TANGENT) != 0;
	assert_true(tangents > 0);
	ajar_scene_destroy(&s);
}

/* Tangents generated for NormalTangentMirrorTest (its TANGENT left out of
 * a copy of the file) match the ones it stores: per triangle corner the
 * same handedness and, in the normal's plane, nearly the same direction.
 * The copy and the files it reads go to the test's folder. */
static void test_generated_tangents(void **state)
{
	(void)state;
	static const char *const files[] = {"NormalTangentMirrorTest.bin", "NormalTangentTest_Normal.png",
					    "NormalTangentMirrorTest_BaseColor.png",
					    "NormalTangentMirrorTest_OcclusionRoughnessMetallic.png"};
	char src[PATH_MAX], *dir = realpath(SCENE("khronos/NormalTangentMirrorTest"), NULL);
	assert_non_null(dir);
	static char data[1 << 22];
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		snprintf(src, sizeof src, "%s/%s", dir, files[i]);
		FILE *in = fopen(src, "rb");
		assert_non_null(in);
		size_t got = fread(data, 1, sizeof data, in);
		assert_true(got < sizeof data && !ferror(in));
		fclose(in);
		write_bytes(files[i], data, got);
	}
	snprintf(src, sizeof src, "%s/NormalTangentMirrorTest.gltf", dir);
	free(dir);
	FILE *f = fopen(src, "rb");
	assert_non_null(f);
	static char text[1 << 16];
	size_t n = fread(text, 1, sizeof text - 1, f);
	fclose(f);
	text[n] = 0;
	char *t = strstr(text, "\"TANGENT\" : 3, ");
	assert_non_null(t);
	memmove(t, t + strlen("\"TANGENT\" : 3, "), strlen(t + strlen("\"TANGENT\" : 3, ")) + 1);
	write_text("notangent.gltf", text);
	ajar_scene *stored = NULL;
	assert_int_equal(ajar_scene_load(SCENE("khronos/NormalTangentMirrorTest/NormalTangentMirrorTest.gltf"), &stored),
			 AJAR_OK);
	Scene *gen = load_ok("notangent.gltf");
	assert_int_equal(gen->ntris, stored->ntris);
	double worst = 1.0;
	for (uint32_t i = 0; i < gen->ntris; i++) {
		assert_true(gen->tris[i].flags & TRI_TANGENT);
		assert_true(stored->tris[i].flags & TRI_TANGENT);
		const float *g[3] = {gen->extra[i].t0, gen->extra[i].t1, gen->extra[i].t2};
		const float *s[3] = {stored->extra[i].t0, stored->extra[i].t1, stored->extra[i].t2};
		V3 nv[3] = {gen->shade[i].n0, gen->shade[i].n1, gen->shade[i].n2};
		for (int k = 0; k < 3; k++) {
			assert_float_equal(g[k][3], s[k][3], 0.0f);
			V3 a = v3(g[k][0], g[k][1], g[k][2]), b = v3(s[k][0], s[k][1], s[k][2]);
			a = v3_norm(v3_madd(a, nv[k], -v3_dot(a, nv[k])));
			b = v3_norm(v3_madd(b, nv[k], -v3_dot(b, nv[k])));
			worst = fmin(worst, v3_dot(a, b));
		}
	}
	printf("  generated vs stored tangents: worst cosine %.5f\n", worst);
	assert_true(worst > 0.99);
	ajar_scene_destroy(&gen);
	ajar_scene_destroy(&stored);
}

/* A normal map of constant tilt on a quad in z = 0 (u along +x, v along
 * +y, tangent +x with w = -1 as generated for such UVs) turns the shading
 * normal as the tilted plane's: the texel (r, g, b) read linearly as
 * (2r - 1, 2g - 1, 2b - 1), x and y scaled, along (t, w (n x t), n),
 * and the BSDF is built on it: it shades like that plane (f and the
 * densities equal a tilted plane's). */
static void test_normal_map(void **state)
{
	(void)state;
	Scene *s;
	assert_int_equal(scene_new("<test>", &s), AJAR_OK);
	uint8_t texel[4] = {200, 100, 220, 255};
	uint32_t img;
	assert_int_equal(scene_add_texture(s, 1, 1, texel, &img), AJAR_OK);
	Material m;
	memset(&m, 0, sizeof m);
	m.base_color = v3(1, 1, 1);
	m.base_tex = -1;
	m.roughness = 1.0f;
	m.ior = 1.5f;
	m.normal_tex = (int)img + 1;
	m.normal_scale = 0.5f;
	uint32_t mid;
	assert_int_equal(scene_add_material(s, &m, &mid), AJAR_OK);
	float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
	float uv[] = {0, 0, 1, 0, 1, 1, 0, 1}, tan[] = {1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles_ex(s, "quad", pos, nrm, uv, NULL, NULL, tan, 4, idx, 2, mid), AJAR_OK);
	assert_true(s->tris[0].flags & TRI_TANGENT);
	SceneView sc = scene_surface_view(s);
	float x = (2.0f * 200 / 255 - 1) * 0.5f, y = (2.0f * 100 / 255 - 1) * 0.5f, z = 2.0f * 220 / 255 - 1;
	/* b = w (n x t) = -(z x x) = -y */
	V3 want = v3_norm(v3(x, -y, z));
	for (int tri = 0; tri < 2; tri++) {
		Hit h = {1.0f, 0.3f, 0.2f, tri, -1};
		Surface sf;
		surface_from_hit(&sc, &h, &sf);
		assert_v3(sf.ns, want.x, want.y, want.z);
		Bsdf bs;
		surface_bsdf(&sc, &sf, v3(0.5f, 0.5f, 0.5f), &bs);
		assert_v3(bs.n, want.x, want.y, want.z);
		/* It shades as that plane: f |wi . n| and the densities of the
		 * normal-mapped quad equal those of a plane whose geometric normal
		 * is `want`, for directions above both surfaces whose mirror
		 * images stay above the quad (no bend, bsdf.h). */
		Bsdf plane;
		bsdf_setup(&plane, &sc.materials[sf.material], v3(0.5f, 0.5f, 0.5f), want, want);
		const V3 wos[] = {v3_norm(v3(0.1f, 0.2f, 1)), v3_norm(v3(0.6f, -0.3f, 1)), v3_norm(v3(-0.3f, 0.5f, 1))};
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++) {
				V3 wi = v3_norm(v3(wos[b].y, -wos[b].x, wos[b].z));
				float p1, r1, p2, r2;
				V3 f1 = bsdf_eval(&bs, wos[a], wi, BSDF_RADIANCE, &p1, &r1);
				V3 f2 = bsdf_eval(&plane, wos[a], wi, BSDF_RADIANCE, &p2, &r2);
				assert_true(f2.x > 0);
				assert_float_equal(f1.x, f2.x, 1e-5f * f2.x);
				assert_float_equal(p1, p2, 1e-5f * p2);
				assert_float_equal(r1, r2, 1e-5f * r2);
			}
	}
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_non_indexed_and_materials),
		cmocka_unit_test(test_unread_extension_members),
		cmocka_unit_test(test_volume_and_transmission),
		cmocka_unit_test(test_texture_coordinates),
		cmocka_unit_test(test_khronos_assets), cmocka_unit_test(test_layer_extensions),
		cmocka_unit_test(test_generated_tangents),
		cmocka_unit_test(test_normal_map),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
