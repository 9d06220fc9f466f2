/* test_scene_gltf.c — the glTF loader (src/scene/gltf_load.c): small files
 * written here exercise one feature each (node hierarchies with TRS and
 * matrices, scenes without "scenes", strips and fans, interleaved, sparse
 * and normalized accessors, data URIs, .glb, portals and the environment
 * colour, KHR_lights_punctual); broken files fail with the right status
 * and a message naming the file and the element. Materials and textures:
 * test_scene_materials; environment images: test_scene_env. */
#include "scene_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

static void test_hierarchy_trs(void **state)
{
	/* Parent: translate (1,2,3), scale 2; child 1: 90 degrees about +Y with
	 * the mesh; child 2: the camera, 1 unit along the parent's +Z. */
	char json[4096];
	write_tri_bin();
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":["
		 "{\"translation\":[1,2,3],\"scale\":[2,2,2],\"children\":[1,2]},"
		 "{\"rotation\":[0,0.7071067811865476,0,0.7071067811865476],\"mesh\":0},"
		 "{\"camera\":0,\"translation\":[0,0,1],\"extras\":{\"resolution\":[320,240]}}],"
		 "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}");
	write_text("trs.gltf", json);
	Scene *s = load_ok("trs.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p0, 1, 2, 3);
	assert_v3(s->tris[0].p1, 1, 2, 1);
	assert_v3(s->tris[0].p2, 1, 4, 3);
	assert_v3(s->shade[0].n0, 1, 0, 0);
	assert_true(s->has_camera);
	assert_v3(s->cam_pos, 1, 2, 5);
	assert_v3(s->cam_forward, 0, 0, -1);
	assert_v3(s->cam_up, 0, 1, 0);
	assert_float_equal(s->cam_yfov, 0.5f, 0.0);
	assert_float_equal(s->cam_aspect, 0.0f, 0.0);
	assert_int_equal(s->width, 320);
	assert_int_equal(s->height, 240);
	/* No material: glTF's default (white, metallic 1, roughness 1). */
	assert_int_equal(s->nmaterials, 1);
	assert_v3(s->materials[0].base_color, 1, 1, 1);
	assert_float_equal(s->materials[0].metallic, 1.0f, 0.0);
	assert_float_equal(s->materials[0].roughness, 1.0f, 0.0);
	assert_int_equal(s->materials[0].base_tex, -1);
	ajar_scene_destroy(&s);
}

static void test_hierarchy_matrix(void **state)
{
	/* Column-major matrix: mirror x, then move to z = 5. Mirroring keeps
	 * the normal (inverse transpose) and reverses the winding. */
	write_tri_gltf("matrix.gltf", "0", "{\"matrix\":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1],\"mesh\":0}", "");
	Scene *s = load_ok("matrix.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p0, 0, 0, 5);
	assert_v3(s->tris[0].p1, 0, 1, 5);
	assert_v3(s->tris[0].p2, -1, 0, 5);
	V3 ng = v3_cross(v3_sub(s->tris[0].p1, s->tris[0].p0), v3_sub(s->tris[0].p2, s->tris[0].p0));
	assert_v3(ng, 0, 0, 1);
	assert_v3(s->shade[0].n1, 0, 0, 1);
	assert_false(s->has_camera);
	ajar_scene_destroy(&s);
}

static void test_no_scenes_all_roots(void **state)
{
	/* No "scenes": every root node is shown; node 1 is node 0's child. */
	write_tri_bin();
	write_text("roots.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0,\"children\":[1]},"
				 "{\"mesh\":0,\"translation\":[0,0,1]},{\"mesh\":0,\"translation\":[0,0,2]}]," TRI_BUFFERS(
					 "tri.bin") "," TRI_ACCESSORS(3) "}");
	Scene *s = load_ok("roots.gltf");
	assert_int_equal(s->ntris, 3);
	assert_float_equal(s->tris[1].p0.z, 1.0f, 0.0);
	assert_float_equal(s->tris[2].p0.z, 2.0f, 0.0);
	ajar_scene_destroy(&s);
}

static void test_interleaved_strip_fan(void **state)
{
	/* Four vertices interleaved (position, normal, normalized u16 uv;
	 * stride 28) and three primitives over u8 indices: a triangle list, a
	 * strip, a fan; plus a point primitive that is skipped. */
	struct {
		float p[3], n[3];
		uint16_t uv[2];
	} v[4] = {
		{{0, 0, 0}, {0, 0, 1}, {0, 0}},
		{{1, 0, 0}, {0, 0, 1}, {65535, 0}},
		{{0, 1, 0}, {0, 0, 1}, {0, 32768}},
		{{1, 1, 0}, {0, 0, 1}, {65535, 65535}},
	};
	_Static_assert(sizeof v == 112, "packed vertices");
	uint8_t bin[124];
	const uint8_t idx[11] = {0, 1, 2, 0, 1, 2, 3, 0, 1, 3, 2};
	memcpy(bin, v, 112);
	memcpy(bin + 112, idx, 11);
	write_bytes("inter.bin", bin, 123);
	write_text("inter.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":["
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3},"
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":4,\"mode\":5},"
		   "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":5,\"mode\":6},"
		   "{\"attributes\":{\"POSITION\":0},\"mode\":0}]}],"
		   "\"buffers\":[{\"uri\":\"inter.bin\",\"byteLength\":123}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":112,\"byteStride\":28},"
		   "{\"buffer\":0,\"byteOffset\":112,\"byteLength\":11}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		   "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		   "{\"bufferView\":0,\"byteOffset\":24,\"componentType\":5123,\"normalized\":true,\"count\":4,"
		   "\"type\":\"VEC2\"},"
		   "{\"bufferView\":1,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"},"
		   "{\"bufferView\":1,\"byteOffset\":3,\"componentType\":5121,\"count\":4,\"type\":\"SCALAR\"},"
		   "{\"bufferView\":1,\"byteOffset\":7,\"componentType\":5121,\"count\":4,\"type\":\"SCALAR\"}]}");
	Scene *s = load_ok("inter.gltf");
	assert_int_equal(s->ntris, 5);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->shade[0].n2, 0, 0, 1);
	assert_float_equal(s->shade[0].u1, 1.0f, 0.0);
	assert_float_equal(s->shade[0].v2, 32768.0f / 65535.0f, 1e-7);
	/* Strip 0 1 2 3: (0 1 2), (1 3 2). Fan 0 1 3 2: (1 3 0), (3 2 0). */
	assert_v3(s->tris[2].p0, 1, 0, 0);
	assert_v3(s->tris[2].p1, 1, 1, 0);
	assert_v3(s->tris[2].p2, 0, 1, 0);
	assert_v3(s->tris[3].p0, 1, 0, 0);
	assert_v3(s->tris[3].p2, 0, 0, 0);
	assert_v3(s->tris[4].p0, 1, 1, 0);
	assert_v3(s->tris[4].p1, 0, 1, 0);
	for (uint32_t i = 0; i < s->ntris; i++) {
		V3 ng = v3_cross(v3_sub(s->tris[i].p1, s->tris[i].p0), v3_sub(s->tris[i].p2, s->tris[i].p0));
		assert_true(ng.z > 0.0f); /* all counter-clockwise seen from +Z */
	}
	ajar_scene_destroy(&s);
}

static void test_sparse(void **state)
{
	/* POSITION: the triangle with vertex 2 replaced by (5, 5, 5) through a
	 * sparse u8 index; NORMAL: no buffer view (zeros) with one sparse
	 * value at vertex 1, so the triangle falls back to its geometric normal. */
	uint8_t bin[128];
	tri_bin(bin, idx012, 1.0f); /* bytes 0..77 */
	const uint8_t sidx[4] = {2, 1, 0, 0};
	const float sval[6] = {5, 5, 5, 0, 0, 3};
	memcpy(bin + 80, sidx, 4);
	memcpy(bin + 84, sval, 24);
	write_bytes("sparse.bin", bin, 108);
	write_text("sparse.gltf",
		   "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
		   "\"buffers\":[{\"uri\":\"sparse.bin\",\"byteLength\":108}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6},"
		   "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":84,\"byteLength\":24}],"
		   "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
		   "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":2,\"componentType\":5121},"
		   "\"values\":{\"bufferView\":3}}},"
		   "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
		   "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":2,\"byteOffset\":1,\"componentType\":5121},"
		   "\"values\":{\"bufferView\":3,\"byteOffset\":12}}},"
		   "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}");
	Scene *s = load_ok("sparse.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->tris[0].p2, 5, 5, 5);
	assert_int_equal(s->shade[0].has_normals, 0);
	ajar_scene_destroy(&s);
}

static char *base64(const uint8_t *p, size_t n)
{
	static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
	assert_non_null(out);
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
		*o++ = tab[v >> 18];
		*o++ = tab[(v >> 12) & 63];
		*o++ = i + 1 < n ? tab[(v >> 6) & 63] : '=';
		*o++ = i + 2 < n ? tab[v & 63] : '=';
	}
	*o = '\0';
	return out;
}

static void test_data_uri(void **state)
{
	uint8_t bin[80];
	char *b64 = base64(bin, tri_bin(bin, idx012, 1.0f));
	char *json = malloc(8192);
	assert_non_null(json);
	snprintf(json, 8192,
		 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,"
		 "\"translation\":[0,0,-1]}],\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\","
		 "\"byteLength\":78}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},"
		 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]," TRI_ACCESSORS(
			 3) "}",
		 b64);
	write_text("datauri.gltf", json);
	free(json);
	free(b64);
	Scene *s = load_ok("datauri.gltf");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p2, 0, 1, -1);
	ajar_scene_destroy(&s);
}

static void put_u32(uint8_t *p, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static void test_glb(void **state)
{
	/* GLB: 12-byte header, a JSON chunk padded with spaces, a BIN chunk
	 * padded with zeros, all little-endian. The file has no extension
	 * hint (.glb) that the loader relies on; it checks the magic. */
	char json[2048];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		 "\"buffers\":[{\"byteLength\":78}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},"
		 "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]," TRI_ACCESSORS(
			 3) "}");
	size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3, blen = 80;
	size_t total = 12 + 8 + jpad + 8 + blen;
	uint8_t *glb = calloc(1, total);
	assert_non_null(glb);
	memcpy(glb, "glTF", 4);
	put_u32(glb + 4, 2);
	put_u32(glb + 8, (uint32_t)total);
	put_u32(glb + 12, (uint32_t)jpad);
	put_u32(glb + 16, 0x4E4F534A); /* "JSON" */
	memcpy(glb + 20, json, jlen);
	memset(glb + 20 + jlen, ' ', jpad - jlen);
	uint8_t *b = glb + 20 + jpad;
	put_u32(b, (uint32_t)blen);
	put_u32(b + 4, 0x004E4942); /* "BIN" */
	tri_bin(b + 8, idx012, 1.0f);
	write_bytes("tri.glb", glb, total);
	free(glb);
	Scene *s = load_ok("tri.glb");
	assert_int_equal(s->ntris, 1);
	assert_v3(s->tris[0].p1, 1, 0, 0);
	assert_v3(s->shade[0].n0, 0, 0, 1);
	ajar_scene_destroy(&s);
}

static void test_portals_and_environment(void **state)
{
	/* Node 0 is a portal (marked 1, as Blender writes custom properties);
	 * its child is not; node 2 is a portal marked true at z = 3; the
	 * environment colour is scaled by its strength. */
	write_tri_gltf("portal.gltf", "0,2",
		       "{\"mesh\":0,\"extras\":{\"portal\":1},\"children\":[1]},"
		       "{\"mesh\":0,\"translation\":[0,0,1]},"
		       "{\"mesh\":0,\"translation\":[0,0,3],\"extras\":{\"portal\":true}}",
		       ",\"extras\":{\"environment\":{\"color\":[0.5,1,2],\"strength\":2},\"resolution\":[64,32]}");
	Scene *s = load_ok("portal.gltf");
	assert_int_equal(s->ntris, 1);
	assert_float_equal(s->tris[0].p0.z, 1.0f, 0.0);
	assert_int_equal(s->nportals, 2);
	assert_int_equal(s->nportal_tris, 2);
	assert_float_equal(s->portals[1].p0.z, 3.0f, 0.0);
	assert_float_equal(s->portals[0].area, 0.5f, 1e-7);
	assert_int_equal(s->env_type, ENV_COLOR);
	assert_v3(s->env_color, 1, 2, 4);
	assert_int_equal(s->width, 64);
	assert_int_equal(s->height, 32);
	ajar_scene_destroy(&s);
}

static void test_broken_files(void **state)
{
	/* Truncated JSON. */
	FILE *f = fopen(SCENE("cornell/cornell.gltf"), "rb");
	assert_non_null(f);
	char head[3000];
	assert_int_equal(fread(head, 1, sizeof head, f), sizeof head);
	fclose(f);
	write_bytes("trunc.gltf", head, sizeof head);
	load_fails("trunc.gltf", AJAR_ERROR_BAD_INPUT, "parse error");

	/* A buffer file that is not there. */
	write_text("nobin.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("missing.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("nobin.gltf", AJAR_ERROR_BAD_INPUT, "missing.bin");

	/* Index 7 with 3 vertices. */
	uint8_t bin[80];
	const uint16_t idx017[3] = {0, 1, 7};
	write_bytes("badidx.bin", bin, tri_bin(bin, idx017, 1.0f));
	write_text("badidx.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("badidx.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("badidx.gltf", AJAR_ERROR_BAD_INPUT, "meshes[0].primitives[0]: index 7 (at 2) out of range (3 vertices)");

	/* POSITION claims 4 vertices (48 bytes) of a 36-byte view. */
	write_tri_bin();
	write_text("pastend.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("tri.bin") "," TRI_ACCESSORS(4) "}");
	load_fails("pastend.gltf", AJAR_ERROR_BAD_INPUT,
		   "meshes[0].primitives[0]: accessors[0] (POSITION): needs 48 bytes at offset 0 but bufferViews[0] has 36");

	/* A buffer view past the end of its buffer. */
	write_text("viewpast.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   "\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":78}],"
		   "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":60,\"byteLength\":36},"
		   "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}],"
		   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
		   TRI_ACCESSORS(3) "}");
	load_fails("viewpast.gltf", AJAR_ERROR_BAD_INPUT, "bufferViews[0]: needs 36 bytes at offset 60 but buffers[0] has 78");

	/* A NaN position. */
	write_bytes("nan.bin", bin, tri_bin(bin, idx012, NAN));
	write_text("nan.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
		   TRI_BUFFERS("nan.bin") "," TRI_ACCESSORS(3) "}");
	load_fails("nan.gltf", AJAR_ERROR_BAD_INPUT, "meshes[0].primitives[0]: vertex 1: position is not finite");

	/* Nothing to render: a portal alone. */
	write_tri_gltf("onlyportal.gltf", "0", "{\"mesh\":0,\"extras\":{\"portal\":true}}", "");
	load_fails("onlyportal.gltf", AJAR_ERROR_BAD_INPUT, "scenes[0]: no triangles to render (portals do not count)");

	/* A node that is its own grandchild. */
	write_tri_gltf("cycle.gltf", "0", "{\"mesh\":0,\"children\":[1]},{\"children\":[0]}", "");
	load_fails("cycle.gltf", AJAR_ERROR_BAD_INPUT, "nodes[0]: reached twice");

	/* An extension we cannot honour. */
	write_text("draco.gltf", "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
		   "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}");
	load_fails("draco.gltf", AJAR_ERROR_BAD_INPUT, "extensionsRequired: KHR_draco_mesh_compression");

	/* A missing file is an I/O error. */
	load_fails("nonexistent.gltf", AJAR_ERROR_IO, "cannot open");
}

/* The one-triangle scene with `nodes` after the mesh node (nodes[0]) and
 * root lights `lights`, the extension required. */
static void write_lights_gltf(const char *name, const char *scene_nodes, const char *nodes, const char *lights)
{
	write_tri_bin();
	char json[4096];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
		 "\"extensionsRequired\":[\"KHR_lights_punctual\"],"
		 "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}},"
		 "\"scene\":0,\"scenes\":[{\"nodes\":[0,%s]}],\"nodes\":[{\"mesh\":0},%s]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}",
		 lights, scene_nodes, nodes);
	write_text(name, json);
}

#define LIGHT_NODE(i) "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":" #i "}}"

/* ---- Images that lie about their size -----------------------------------
 * tinygltf decoded every image from the size its header declares: a
 * 688-byte JPEG declaring 20000 x 20000 texels loaded (4.7 GB, and a
 * garbage texture, as stb reads past the end as zeros). Refused now before
 * decoding (more than 16384 a side, a Huffman table stb would overflow,
 * a format other than glTF's PNG and JPEG) or when the decoder reads past
 * the end, each message naming the image by its URI. */
static void spill_image(void *ctx, void *data, int n)
{
	FILE *f = ctx;
	assert_int_equal(fwrite(data, 1, (size_t)n, f), (size_t)n);
}

/* test_dir/name: an 8 x 8 JPEG (or PNG) whose header declares w x h, cut
 * to `keep` bytes (0: whole); w = -1: a JPEG whose first Huffman table
 * counts 512 codes; w = -2: one whose scan uses an AC table never defined
 * (stb read tables it never set: an out-of-bounds read, fuzz_texture). */
static void write_lying_image(const char *name, int jpeg, int w, int h, size_t keep)
{
	unsigned char rgb[8 * 8 * 3];
	for (int i = 0; i < 8 * 8 * 3; i++)
		rgb[i] = (unsigned char)(i * 37);
	if (jpeg == 2) { /* a 99-byte TGA declaring 8224 x 8224 texels, which stb would read */
		unsigned char tga[99];
		memset(tga, ' ', sizeof tga);
		memcpy(tga, "\xff\x00\x0a\xd8", 4);
		write_bytes(name, tga, sizeof tga);
		return;
	}
	char *p = test_tmp(name);
	FILE *f = fopen(p, "wb");
	assert_non_null(f);
	assert_true(jpeg ? stbi_write_jpg_to_func(spill_image, f, 8, 8, 3, rgb, 90)
			 : stbi_write_png_to_func(spill_image, f, 8, 8, 3, rgb, 24));
	assert_int_equal(fclose(f), 0);
	f = fopen(p, "rb");
	unsigned char buf[4096];
	size_t n = fread(buf, 1, sizeof buf, f);
	fclose(f);
	for (size_t i = 0; jpeg && w < 0 && i + 21 < n; i++)
		if (buf[i] == 0xff && buf[i + 1] == 0xc4) { /* DHT: length, class/id, 16 counts */
			if (w == -1) {
				memset(buf + i + 5, 0x20, 16); /* 512 codes: stb wrote past its tables */
			} else { /* the second table, AC 0, becomes DC 0 again: AC 0 is never defined */
				size_t codes = 0;
				for (int k = 0; k < 16; k++)
					codes += buf[i + 5 + k];
				buf[i + 4 + 17 + codes] = 0x00;
			}
			w = h = 8;
			break;
		}
	for (size_t i = 0; jpeg && i + 9 < n; i++)
		if (buf[i] == 0xff && buf[i + 1] == 0xc0) { /* SOF0: length, precision, height, width */
			buf[i + 5] = (unsigned char)(h >> 8), buf[i + 6] = (unsigned char)h;
			buf[i + 7] = (unsigned char)(w >> 8), buf[i + 8] = (unsigned char)w;
			break;
		}
	if (!jpeg) { /* IHDR's width and height, big-endian at 16 */
		for (int k = 0; k < 4; k++) {
			buf[16 + k] = (unsigned char)(w >> (24 - 8 * k));
			buf[20 + k] = (unsigned char)(h >> (24 - 8 * k));
		}
	}
	write_bytes(name, buf, keep ? keep : n);
	free(p);
}

static void test_lying_images(void **state)
{
	write_tri_bin();
	static const struct {
		const char *name;
		int jpeg, w, h;
		size_t keep;
		const char *why;
	} cases[] = {
		{"huge.jpg", 1, 20000, 20000, 0, "'huge.jpg'): 20000x20000 texels: at most 16384 a side"},
		{"wide.png", 0, 16385, 1, 0, "'wide.png'): 16385x1 texels: at most 16384 a side"},
		{"cut.jpg", 1, 1000, 1000, 0, "'cut.jpg'): the image data is cut short"},
		{"cut8.jpg", 1, 8, 8, 300, "'cut8.jpg'): the image data is cut short"},
		{"junk.png", 0, 8, 8, 20, "'junk.png'): "},
		{"dht.jpg", 1, -1, -1, 0, "'dht.jpg'): corrupt JPEG: a Huffman table of more than 256 codes"},
		{"tga.png", 2, 0, 0, 0, "'tga.png'): not a PNG or JPEG image"},
		{"noac.jpg", 1, -2, -2, 0, "'noac.jpg'): corrupt JPEG: a scan uses a Huffman table never defined"},
	};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		write_lying_image(cases[k].name, cases[k].jpeg, cases[k].w, cases[k].h, cases[k].keep);
		char json[2048];
		snprintf(json, sizeof json,
			 "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]," TRI_BUFFERS(
				 "tri.bin") "," TRI_ACCESSORS(3) ",\"images\":[{\"uri\":\"%s\"}]}",
			 cases[k].name);
		write_text("lying.gltf", json);
		load_fails("lying.gltf", AJAR_ERROR_BAD_INPUT, cases[k].why);
		assert_non_null(strstr(ajar_last_error(), "images[0] ("));
	}
	/* An image in a buffer view that runs past its buffer (tinygltf
	 * passed it on: the decoder read past the buffer, ASan's
	 * heap-buffer-overflow in fuzz_gltf). */
	write_text("viewpast.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
				    "\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":78}],"
				    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
				    "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6},"
				    "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":4000}],"
				    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
				    TRI_ACCESSORS(3) ",\"images\":[{\"bufferView\":3,\"mimeType\":\"image/png\"}]}");
	load_fails("viewpast.gltf", AJAR_ERROR_BAD_INPUT, "images[0] (bufferViews[3]): its bufferView lies outside its buffer");
	/* The same files whole and honest load. */
	write_lying_image("ok.jpg", 1, 8, 8, 0);
	write_lying_image("ok.png", 0, 8, 8, 0);
	write_text("honest.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]," TRI_BUFFERS(
					  "tri.bin") "," TRI_ACCESSORS(3) ",\"images\":[{\"uri\":\"ok.jpg\"},{\"uri\":\"ok.png\"}]}");
	Scene *s = load_ok("honest.gltf");
	scene_free(s);
}

static void test_lights_punctual(void **state)
{
	/* nodes[1]: the directional light turned -90 degrees about X (-Z to
	 * -Y); nodes[2]: the point light at (1, 2, 3); nodes[3] (scaled, child
	 * of nodes[4] at (0, 1, 0)): the spot, pointing down -Z. */
	write_lights_gltf("lights.gltf", "1,2,4",
			  LIGHT_NODE(0) ",\"rotation\":[-0.70710678,0,0,0.70710678]}," LIGHT_NODE(
				  1) ",\"translation\":[1,2,3]}," LIGHT_NODE(2) ",\"scale\":[2,2,2]},"
				     "{\"translation\":[0,1,0],\"children\":[3]}",
			  "{\"type\":\"directional\",\"color\":[1,0.5,0.25],\"intensity\":3},"
			  "{\"type\":\"point\",\"range\":5},"
			  "{\"type\":\"spot\",\"intensity\":683,\"spot\":{\"innerConeAngle\":0.1,\"outerConeAngle\":0.3}}");
	Scene *s = load_ok("lights.gltf");
	ajar_scene_info in;
	assert_int_equal(ajar_scene_info_get(s, &in), AJAR_OK);
	assert_int_equal(in.lights, 3);
	ajar_light l;
	assert_int_equal(ajar_scene_light_get(s, 0, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_DIRECTIONAL);
	assert_float_equal(l.direction[0], 0.0f, 1e-6f);
	assert_float_equal(l.direction[1], -1.0f, 1e-6f);
	assert_float_equal(l.direction[2], 0.0f, 1e-6f);
	assert_float_equal(l.color[1], 0.5f, 0.0f);
	assert_float_equal(l.intensity, 3.0f, 0.0f);
	assert_int_equal(ajar_scene_light_get(s, 1, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_POINT);
	assert_float_equal(l.position[0], 1.0f, 0.0f);
	assert_float_equal(l.position[1], 2.0f, 0.0f);
	assert_float_equal(l.position[2], 3.0f, 0.0f);
	assert_float_equal(l.color[0], 1.0f, 0.0f); /* the spec's defaults */
	assert_float_equal(l.intensity, 1.0f, 0.0f);
	assert_float_equal(l.range, 5.0f, 0.0f);
	/* The scene walks the root nodes in order: the spot (child of
	 * nodes[4]) comes last. */
	assert_int_equal(ajar_scene_light_get(s, 2, &l), AJAR_OK);
	assert_int_equal(l.type, AJAR_LIGHT_SPOT);
	assert_float_equal(l.position[1], 1.0f, 0.0f);
	assert_float_equal(l.direction[2], -1.0f, 1e-6f); /* scale leaves it unit */
	assert_float_equal(l.inner_cone, 0.1f, 1e-7f);
	assert_float_equal(l.outer_cone, 0.3f, 1e-7f);
	assert_float_equal(l.range, 0.0f, 0.0f); /* infinite */
	assert_int_equal(ajar_scene_light_get(s, 3, &l), AJAR_ERROR_INVALID_ARGUMENT);
	ajar_scene_destroy(&s);

	/* A spot without blend, as Blender exports it: inner = outer. */
	write_lights_gltf("hard.gltf", "1", LIGHT_NODE(0) "}",
			  "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.5,\"outerConeAngle\":0.5}}");
	s = load_ok("hard.gltf");
	ajar_scene_destroy(&s);

	write_lights_gltf("nolight.gltf", "1", LIGHT_NODE(7) "}", "{\"type\":\"point\"}");
	load_fails("nolight.gltf", AJAR_ERROR_BAD_INPUT, "nodes[1]: KHR_lights_punctual light 7 does not exist (1 lights)");
	write_lights_gltf("area.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"area\"}");
	load_fails("area.gltf", AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[0]: unknown type 'area'");
	write_lights_gltf("colour.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"color\":[1,1]}");
	load_fails("colour.gltf", AJAR_ERROR_BAD_INPUT, "color has 2 numbers, expected 3");
	write_lights_gltf("negative.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"intensity\":-1}");
	load_fails("negative.gltf", AJAR_ERROR_BAD_INPUT, "nodes[1]: KHR_lights_punctual.lights[0]: intensity -1");
	write_lights_gltf("range.gltf", "1", LIGHT_NODE(0) "}", "{\"type\":\"point\",\"range\":-2}");
	load_fails("range.gltf", AJAR_ERROR_BAD_INPUT, "range -2 must be finite and > 0");
	write_lights_gltf("cone.gltf", "1", LIGHT_NODE(0) "}",
			  "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.6,\"outerConeAngle\":0.5}}");
	load_fails("cone.gltf", AJAR_ERROR_BAD_INPUT, "spot cone angles 0.6, 0.5");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_hierarchy_trs),
		cmocka_unit_test(test_hierarchy_matrix),
		cmocka_unit_test(test_no_scenes_all_roots),
		cmocka_unit_test(test_interleaved_strip_fan),
		cmocka_unit_test(test_sparse),
		cmocka_unit_test(test_data_uri),
		cmocka_unit_test(test_glb),
		cmocka_unit_test(test_portals_and_environment),
		cmocka_unit_test(test_broken_files),
		cmocka_unit_test(test_lights_punctual),
		cmocka_unit_test(test_lying_images),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
