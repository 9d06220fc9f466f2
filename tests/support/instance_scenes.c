/* instance_scenes.c — see instance_scenes.h. */
#include "instance_scenes.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
	float *f;
	size_t n, cap;
} Floats;

static void push(Floats *a, float v)
{
	if (a->n == a->cap) {
		a->cap = a->cap ? 2 * a->cap : 256;
		a->f = realloc(a->f, sizeof *a->f * a->cap);
	}
	a->f[a->n++] = v;
}

/* The binary buffer and the JSON pieces being written. */
typedef struct {
	unsigned char *bin;
	size_t nbin;
	char views[4096], accessors[8192];
	int nviews, naccessors;
} Gltf;

static int add_view(Gltf *g, const void *data, size_t bytes)
{
	g->bin = realloc(g->bin, g->nbin + bytes + 4);
	memcpy(g->bin + g->nbin, data, bytes);
	size_t off = g->nbin;
	g->nbin += (bytes + 3) & ~(size_t)3;
	snprintf(g->views + strlen(g->views), sizeof g->views - strlen(g->views),
		 "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", g->nviews ? "," : "", off, bytes);
	return g->nviews++;
}

/* An accessor over n float items of `comps` components (with min/max for
 * positions), or of uint32 indices (comps 0). */
static int add_accessor(Gltf *g, const void *data, size_t n, int comps, int minmax)
{
	static const char *const type[] = {"SCALAR", "SCALAR", "VEC2", "VEC3", "VEC4"};
	int view = add_view(g, data, n * 4 * (size_t)(comps ? comps : 1));
	char extra[256] = "";
	if (minmax) {
		const float *f = data;
		float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
		for (size_t i = 0; i < n; i++)
			for (int c = 0; c < 3; c++) {
				lo[c] = fminf(lo[c], f[3 * i + (size_t)c]);
				hi[c] = fmaxf(hi[c], f[3 * i + (size_t)c]);
			}
		snprintf(extra, sizeof extra, ",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]", lo[0], lo[1], lo[2], hi[0], hi[1],
			 hi[2]);
	}
	snprintf(g->accessors + strlen(g->accessors), sizeof g->accessors - strlen(g->accessors),
		 "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%zu,\"type\":\"%s\"%s}", g->naccessors ? "," : "",
		 view, comps ? 5126 : 5125, n, type[comps], extra);
	return g->naccessors++;
}

/* A primitive's JSON: positions, normals, uvs (may be NULL) and indices. */
static void add_primitive(Gltf *g, char *out, size_t cap, const Floats *pos, const Floats *nrm, const Floats *uv,
			  const uint32_t *idx, size_t nidx, int material)
{
	int p = add_accessor(g, pos->f, pos->n / 3, 3, 1);
	int n = add_accessor(g, nrm->f, nrm->n / 3, 3, 0);
	int u = uv ? add_accessor(g, uv->f, uv->n / 2, 2, 0) : -1;
	int i = add_accessor(g, idx, nidx, 0, 0);
	char uvs[32] = "";
	if (u >= 0)
		snprintf(uvs, sizeof uvs, ",\"TEXCOORD_0\":%d", u);
	snprintf(out, cap, "{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d%s},\"indices\":%d,\"material\":%d}", p, n,
		 uvs, i, material);
}

/* A bumpy sphere: positions, smooth normals of the unbumped sphere (so
 * shading normals tilt from the faces'), uvs. */
static void sphere(int stacks, int slices, Floats *pos, Floats *nrm, Floats *uv, uint32_t **idx, size_t *nidx)
{
	for (int i = 0; i <= stacks; i++)
		for (int j = 0; j <= slices; j++) {
			float th = 3.14159265f * (float)i / (float)stacks, ph = 6.2831853f * (float)j / (float)slices;
			float d[3] = {sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)};
			float r = 1.0f + 0.1f * sinf(3 * th) * sinf(2 * ph);
			for (int c = 0; c < 3; c++) {
				push(pos, r * d[c]);
				push(nrm, d[c]);
			}
			push(uv, (float)j / (float)slices);
			push(uv, (float)i / (float)stacks);
		}
	*idx = malloc(sizeof **idx * 6 * (size_t)stacks * (size_t)slices);
	*nidx = 0;
	int w = slices + 1;
	for (int i = 0; i < stacks; i++)
		for (int j = 0; j < slices; j++) {
			uint32_t a = (uint32_t)(i * w + j), b = a + 1, c = a + (uint32_t)w, e = c + 1;
			uint32_t t[6] = {a, b, c, b, e, c};
			for (int k = i > 0 ? 0 : 3; k < (i < stacks - 1 ? 6 : 3); k++)
				(*idx)[(*nidx)++] = t[k];
		}
}

/* An axis-aligned quad's four corners (CCW seen from its normal's side). */
static void quad(Floats *pos, Floats *nrm, Floats *uv, uint32_t *idx, size_t *nidx, const float c[4][3],
		 const float n[3])
{
	uint32_t base = (uint32_t)(pos->n / 3);
	for (int k = 0; k < 4; k++) {
		for (int a = 0; a < 3; a++) {
			push(pos, c[k][a]);
			push(nrm, n[a]);
		}
		push(uv, (float)(k == 1 || k == 2));
		push(uv, (float)(k >= 2));
	}
	uint32_t t[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
	memcpy(idx + *nidx, t, sizeof t);
	*nidx += 6;
}

void write_instance_scene(const char *dir, const char *name)
{
	Gltf g;
	memset(&g, 0, sizeof g);
	/* mesh 0: the room, 4 x 3 x 4 with a window hole in its +Z wall
	 * (x 1.5..2.5, y 1..2), faces inward. */
	Floats rp = {0}, rn = {0}, ru = {0};
	uint32_t ri[96];
	size_t nri = 0;
	const float floor_[4][3] = {{0, 0, 0}, {0, 0, 4}, {4, 0, 4}, {4, 0, 0}}, up[3] = {0, 1, 0};
	const float ceil_[4][3] = {{0, 3, 0}, {4, 3, 0}, {4, 3, 4}, {0, 3, 4}}, down[3] = {0, -1, 0};
	const float back[4][3] = {{0, 0, 0}, {4, 0, 0}, {4, 3, 0}, {0, 3, 0}}, pz[3] = {0, 0, 1};
	const float left[4][3] = {{0, 0, 0}, {0, 3, 0}, {0, 3, 4}, {0, 0, 4}}, px[3] = {1, 0, 0};
	const float right[4][3] = {{4, 0, 0}, {4, 0, 4}, {4, 3, 4}, {4, 3, 0}}, nx[3] = {-1, 0, 0};
	const float f1[4][3] = {{0, 0, 4}, {0, 3, 4}, {1.5f, 3, 4}, {1.5f, 0, 4}}, nz[3] = {0, 0, -1};
	const float f2[4][3] = {{2.5f, 0, 4}, {2.5f, 3, 4}, {4, 3, 4}, {4, 0, 4}};
	const float f3[4][3] = {{1.5f, 0, 4}, {1.5f, 1, 4}, {2.5f, 1, 4}, {2.5f, 0, 4}};
	const float f4[4][3] = {{1.5f, 2, 4}, {1.5f, 3, 4}, {2.5f, 3, 4}, {2.5f, 2, 4}};
	quad(&rp, &rn, &ru, ri, &nri, floor_, up);
	quad(&rp, &rn, &ru, ri, &nri, ceil_, down);
	quad(&rp, &rn, &ru, ri, &nri, back, pz);
	quad(&rp, &rn, &ru, ri, &nri, left, px);
	quad(&rp, &rn, &ru, ri, &nri, right, nx);
	quad(&rp, &rn, &ru, ri, &nri, f1, nz);
	quad(&rp, &rn, &ru, ri, &nri, f2, nz);
	quad(&rp, &rn, &ru, ri, &nri, f3, nz);
	quad(&rp, &rn, &ru, ri, &nri, f4, nz);
	char room[512], ball[512], lamp_e[512], lamp_s[512], window[512];
	add_primitive(&g, room, sizeof room, &rp, &rn, &ru, ri, nri, 0);
	/* mesh 1: a bumpy ball (smooth normals, uvs) */
	Floats bp = {0}, bn = {0}, bu = {0};
	uint32_t *bi;
	size_t nbi;
	sphere(8, 12, &bp, &bn, &bu, &bi, &nbi);
	add_primitive(&g, ball, sizeof ball, &bp, &bn, &bu, bi, nbi, 1);
	/* mesh 2: a lamp, an emitting quad facing -Y under a shade quad facing +Y */
	Floats ep = {0}, en = {0}, eu = {0}, sp = {0}, sn = {0}, su = {0};
	uint32_t ei[6], si[6];
	size_t nei = 0, nsi = 0;
	const float emit[4][3] = {{-0.2f, 0, -0.2f}, {0.2f, 0, -0.2f}, {0.2f, 0, 0.2f}, {-0.2f, 0, 0.2f}};
	const float shade[4][3] = {{-0.3f, 0.02f, -0.3f}, {-0.3f, 0.02f, 0.3f}, {0.3f, 0.02f, 0.3f}, {0.3f, 0.02f, -0.3f}};
	quad(&ep, &en, &eu, ei, &nei, emit, down);
	quad(&sp, &sn, &su, si, &nsi, shade, up);
	add_primitive(&g, lamp_e, sizeof lamp_e, &ep, &en, &eu, ei, nei, 2);
	add_primitive(&g, lamp_s, sizeof lamp_s, &sp, &sn, &su, si, nsi, 1);
	/* mesh 3: the window's portal */
	Floats wp = {0}, wn = {0}, wu = {0};
	uint32_t wi[6];
	size_t nwi = 0;
	const float win[4][3] = {{1.5f, 1, 4}, {1.5f, 2, 4}, {2.5f, 2, 4}, {2.5f, 1, 4}};
	quad(&wp, &wn, &wu, wi, &nwi, win, nz);
	add_primitive(&g, window, sizeof window, &wp, &wn, NULL, wi, nwi, 0);
	/* EXT_mesh_gpu_instancing: three balls along x, turned and scaled */
	const float it[9] = {-0.8f, 0, 0, 0, 0.1f, 0, 0.8f, 0.2f, 0.3f};
	const float ir[12] = {0, 0, 0, 1, 0, 0.3826834f, 0, 0.9238795f, 0.2588190f, 0, 0, 0.9659258f};
	const float is[9] = {0.2f, 0.2f, 0.2f, 0.3f, 0.15f, 0.2f, 0.25f, 0.25f, 0.1f};
	int at = add_accessor(&g, it, 3, 3, 0), ar = add_accessor(&g, ir, 3, 4, 0), as = add_accessor(&g, is, 3, 3, 0);
	size_t jcap = 64 * 1024;
	char *j = malloc(jcap);
	snprintf(j, jcap,
		 "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\","
		 "\"KHR_materials_emissive_strength\"],\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"],"
		 "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4,5,6,8,9,10,11],"
		 "\"extras\":{\"environment\":{\"color\":[1,1,1]}}}],"
		 "\"nodes\":["
		 /* 0 */ "{\"mesh\":0},"
		 /* 1: non-uniform scale, turned */
		 "{\"mesh\":1,\"translation\":[1,0.45,1],\"rotation\":[0,0.3826834,0,0.9238795],\"scale\":[0.3,0.45,0.6]},"
		 /* 2: mirrored */
		 "{\"mesh\":1,\"translation\":[3,0.4,1.2],\"scale\":[-0.35,0.4,0.3]},"
		 /* 3: nested: a turned parent, a scaled and moved child */
		 "{\"translation\":[2,0.5,2.5],\"rotation\":[0.2588190,0,0,0.9659258],\"children\":[7]},"
		 /* 4: GPU instancing under a moved node */
		 "{\"mesh\":1,\"translation\":[2,0.3,1.5],\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":"
		 "{\"TRANSLATION\":%d,\"ROTATION\":%d,\"SCALE\":%d}}}},"
		 /* 5, 6: lamps under the ceiling, one mirrored and turned */
		 "{\"mesh\":2,\"translation\":[1.2,2.7,2]},"
		 "{\"mesh\":2,\"translation\":[2.8,2.7,2.2],\"rotation\":[0,0.5,0,0.8660254],\"scale\":[-1,1,1.5]},"
		 /* 7: the nested child */
		 "{\"mesh\":1,\"translation\":[0.3,0,0],\"scale\":[0.25,0.4,0.25]},"
		 /* 8: the window's portal */
		 "{\"mesh\":3,\"extras\":{\"portal\":true}},"
		 /* 9: a ball left alone (used by its own nodes: 1, 2, 4, 7, 10) */
		 "{\"mesh\":1,\"translation\":[0.8,0.3,3],\"scale\":[0.3,0.3,0.3]},"
		 /* 10: the camera */
		 "{\"camera\":0,\"translation\":[2,1.6,0.3],\"rotation\":[0,1,0,0]},"
		 /* 11: a big ball through the back wall, partly outside */
		 "{\"mesh\":1,\"translation\":[3.6,1.5,0.1],\"scale\":[0.5,0.5,0.5]}"
		 "],"
		 "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":1.1,\"aspectRatio\":1,\"znear\":0.01}}],"
		 "\"meshes\":[{\"primitives\":[%s]},{\"primitives\":[%s]},{\"primitives\":[%s,%s]},{\"primitives\":[%s]}],"
		 "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.7,0.7,0.7,1],\"metallicFactor\":0,"
		 "\"roughnessFactor\":1}},"
		 "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.5,0.3,1],\"metallicFactor\":0,\"roughnessFactor\":0.5}},"
		 "{\"emissiveFactor\":[1,0.9,0.8],\"extensions\":{\"KHR_materials_emissive_strength\":"
		 "{\"emissiveStrength\":20}},\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]}}],"
		 "\"accessors\":[%s],\"bufferViews\":[%s],\"buffers\":[{\"uri\":\"%s.bin\",\"byteLength\":%zu}]}",
		 at, ar, as, room, ball, lamp_e, lamp_s, window, g.accessors, g.views, name, g.nbin);
	char path[1024];
	snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
	FILE *f = fopen(path, "w");
	fputs(j, f);
	fclose(f);
	snprintf(path, sizeof path, "%s/%s.bin", dir, name);
	f = fopen(path, "wb");
	fwrite(g.bin, 1, g.nbin, f);
	fclose(f);
	free(j);
	free(g.bin);
	free(bi);
	Floats *all[] = {&rp, &rn, &ru, &bp, &bn, &bu, &ep, &en, &eu, &sp, &sn, &su, &wp, &wn, &wu};
	for (size_t k = 0; k < sizeof all / sizeof all[0]; k++)
		free(all[k]->f);
}
