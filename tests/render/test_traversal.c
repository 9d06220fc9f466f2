/* test_traversal.c — the device's own traversal is watertight: rays from
 * inside a closed mesh, aimed exactly at its shared edges and vertices,
 * all hit it. test_bvh checks the same code compiled for the host; this
 * runs the trace_closest kernel as the device compiler built it, which may
 * differ (OpenCL C contracts a * b - c * d into a fused multiply-add unless
 * told not to, and then the two triangles of an edge no longer compute
 * exactly opposite edge functions; kernels/geom/bvh.h). Without the pragma
 * that forbids it, PoCL's build missed 159 of these 103,680 rays. */
#include <math.h>
#include <stdlib.h>

#include "ajar.h"
#include "device/device_build.h"
#include "device/kernel_source.h"
#include "prepare/prepare.h"
#include "scene/scene.h"
#include "testutil.h"
#include "device/upload.h"
#include "geom/bvh.h"

#define GRID 24 /* quads per cube face edge */

/* A cube of GRID x GRID quads per face pushed out onto the unit sphere:
 * a closed mesh whose shared edges run in every direction. */
static void add_sphere(ajar_scene *s, float **verts, uint32_t *nverts, uint32_t **idx, uint32_t *ntris)
{
	const int n = GRID + 1;
	float *p = malloc(sizeof(float) * 3 * 6 * n * n);
	uint32_t *ix = malloc(sizeof(uint32_t) * 6 * 6 * GRID * GRID);
	assert_non_null(p);
	assert_non_null(ix);
	uint32_t nv = 0, ni = 0;
	/* Face f: axis a = f / 2 fixed at sign; (u, v) along the other two,
	 * ordered so the quads face outward. */
	for (int f = 0; f < 6; f++) {
		int a = f / 2, sign = (f & 1) ? -1 : 1;
		int b = (a + 1) % 3, c = (a + 2) % 3;
		uint32_t base = nv;
		for (int j = 0; j < n; j++)
			for (int i = 0; i < n; i++) {
				/* From integer lattice coordinates, in x, y, z order, so
				 * a point on two faces' borders gets the same bits in both. */
				float q[3];
				q[a] = (float)(sign * GRID);
				q[b] = (float)(2 * i - GRID);
				q[c] = (float)((2 * j - GRID) * sign);
				float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
				for (int k = 0; k < 3; k++)
					p[3 * nv + k] = q[k] / len;
				nv++;
			}
		for (int j = 0; j < GRID; j++)
			for (int i = 0; i < GRID; i++) {
				uint32_t v00 = base + (uint32_t)(j * n + i), v10 = v00 + 1, v01 = v00 + (uint32_t)n,
					 v11 = v01 + 1;
				uint32_t t[6] = {v00, v10, v11, v00, v11, v01};
				for (int k = 0; k < 6; k++)
					ix[ni++] = t[k];
			}
	}
	ajar_material m;
	uint32_t mat;
	ajar_material_default(&m);
	assert_int_equal(ajar_scene_add_material(s, &m, &mat), AJAR_OK);
	ajar_mesh mesh = {p, NULL, NULL, nv, ix, ni / 3, mat, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	*verts = p;
	*nverts = nv;
	*idx = ix;
	*ntris = ni / 3;
}

static float frand(unsigned *s)
{
	*s = *s * 1664525u + 1013904223u;
	return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

static void test_closed_mesh_has_no_cracks(void **state)
{
	(void)state;
	ajar_scene *s;
	float *p;
	uint32_t *ix, nv, nt;
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	add_sphere(s, &p, &nv, &ix, &nt);
	ajar_camera cam = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
	SceneData sd;
	ajar_options po;
	ajar_options_default(&po);
	po.max_depth = 8;
	po.mis = AJAR_MIS_POWER;
	assert_int_equal(prepare_scene(s, &po, 16, 16, NULL, &sd), AJAR_OK);

	/* Per triangle edge, rays toward its two ends and three points along
	 * it, each from its own origin near the centre. */
	const uint32_t per_edge = 5, nrays = nt * 3 * per_edge;
	float *rays = malloc(sizeof(float) * 6 * nrays);
	assert_non_null(rays);
	unsigned seed = 11;
	uint32_t r = 0;
	for (uint32_t t = 0; t < nt; t++)
		for (int e = 0; e < 3; e++) {
			const float *a = p + 3 * ix[3 * t + e], *b = p + 3 * ix[3 * t + (e + 1) % 3];
			for (uint32_t k = 0; k < per_edge; k++) {
				float w = (float)k / (float)(per_edge - 1), *ray = rays + 6 * r++;
				for (int c = 0; c < 3; c++) {
					ray[c] = 0.3f * (frand(&seed) - 0.5f);
					ray[3 + c] = a[c] + w * (b[c] - a[c]) - ray[c];
				}
			}
		}

	Device d;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t ndev;
	if (device_select(NULL, &plat, &id, 1, &ndev) != AJAR_OK || device_open(&d, plat, id) != AJAR_OK ||
	    device_build(&d, ajar_kernel_source, KERNEL_OPTIONS "0") != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	SceneBuffers buf;
	cl_kernel k;
	cl_mem mrays, mhits;
	cl_uint arg, count = nrays;
	assert_int_equal(upload_scene(&d, &sd, &buf), AJAR_OK);
	assert_int_equal(device_kernel(&d, "trace_closest", &k), AJAR_OK);
	assert_int_equal(upload_bind(&d, k, &buf, &arg), AJAR_OK);
	assert_int_equal(device_buffer(&d, CL_MEM_READ_ONLY, sizeof(float) * 6 * nrays, rays, &mrays), AJAR_OK);
	assert_int_equal(device_buffer(&d, CL_MEM_WRITE_ONLY, sizeof(int) * nrays, NULL, &mhits), AJAR_OK);
	assert_int_equal(clSetKernelArg(k, arg, sizeof mrays, &mrays), CL_SUCCESS);
	assert_int_equal(clSetKernelArg(k, arg + 1, sizeof mhits, &mhits), CL_SUCCESS);
	assert_int_equal(clSetKernelArg(k, arg + 2, sizeof count, &count), CL_SUCCESS);
	/* Groups of 64, as render_pass runs: PoCL's own choice (thousands of
	 * work-items) would hold every one's traversal stack on one thread's
	 * stack, too much for the general program's (instances included). */
	size_t local = 64, global = (nrays + local - 1) / local * local;
	assert_int_equal(clEnqueueNDRangeKernel(d.queue, k, 1, NULL, &global, &local, 0, NULL, NULL), CL_SUCCESS);
	int *hits = malloc(sizeof(int) * nrays);
	assert_non_null(hits);
	assert_int_equal(
		clEnqueueReadBuffer(d.queue, mhits, CL_TRUE, 0, sizeof(int) * nrays, hits, 0, NULL, NULL),
		CL_SUCCESS);
	/* The host's build of the same traversal (never contracted) checks
	 * the test itself: the mesh really is closed. */
	SceneView sc;
#define VIEW(type, name) sc.name = sd.name;
	AJAR_SCENE_BUFFERS(VIEW)
#undef VIEW
	uint32_t misses = 0, host_misses = 0;
	for (uint32_t i = 0; i < nrays; i++) {
		const float *ray = rays + 6 * i;
		Hit h;
		host_misses += !bvh_intersect(&sc, v3(ray[0], ray[1], ray[2]), v3(ray[3], ray[4], ray[5]), AJAR_INF, &h);
		misses += hits[i] < 0;
	}
	print_message("%u rays at the edges and corners of %u triangles: %u missed on the device, %u on the host\n",
		      nrays, nt, misses, host_misses);
	assert_int_equal(host_misses, 0);
	assert_int_equal(misses, 0);

	free(hits);
	clReleaseMemObject(mrays);
	clReleaseMemObject(mhits);
	clReleaseKernel(k);
	upload_free(&buf);
	device_close(&d);
	prepare_free(&sd);
	ajar_scene_destroy(&s);
	free(rays);
	free(p);
	free(ix);
}

int main(void)
{
	const struct CMUnitTest tests[] = {cmocka_unit_test(test_closed_mesh_has_no_cracks)};
	return cmocka_run_group_tests_name("traversal", tests, NULL, NULL);
}
