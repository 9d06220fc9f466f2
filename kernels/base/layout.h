/* layout.h — the shared structs' sizes and field offsets, listed once. The
 * host checks them with static asserts (src/device/layout_check.c) and a probe kernel
 * reports the device compiler's view (tests/test_layout.c). */
#ifndef AJAR_LAYOUT_H
#define AJAR_LAYOUT_H
#include "base/types.h"

#define AJAR_LAYOUT_TYPES(X) \
	X(BvhNode, 256) X(Tri, 48) X(TriShade, 64) X(TriExtra, 128) X(Material, 176) X(Texture, 48) \
	X(Emitter, 16) X(PortalTri, 64) X(Camera, 64) X(Params, 384) \
	X(PortalPlane, 80) X(PunctualLight, 64) X(Instance, 112)

#define AJAR_LAYOUT_FIELDS(X)                                                          \
	X(BvhNode, lo_x) X(BvhNode, lo_z) X(BvhNode, hi_x) X(BvhNode, hi_z) X(BvhNode, child)\
	X(Tri, p0) X(Tri, p1) X(Tri, p2) X(Tri, material) X(Tri, emitter)              \
	X(TriShade, n0) X(TriShade, n2) X(TriShade, u0) X(TriShade, v2)                \
	X(TriShade, has_normals) X(TriExtra, u0) X(TriExtra, c0) X(TriExtra, c2)      \
	X(TriExtra, t0) X(TriExtra, t2) X(Material, normal_tex) X(Material, normal_scale)\
	X(Tri, flags)                                                                   \
	X(Material, base_color) X(Material, base_tex) X(Material, emission)            \
	X(Material, metallic) X(Material, roughness) X(Material, transmission)         \
	X(Material, ior) X(Material, specular) X(Material, flags)                      \
	X(Material, alpha_cutoff) X(Material, mr_tex) X(Material, emissive_tex)         \
	X(Material, base_alpha) X(Material, transmission_tex) X(Material, sigma)       \
	X(Material, specular_tex) X(Material, specular_color) X(Material, sheen_color)  \
	X(Material, sheen_rough_tex) X(Material, clearcoat) X(Material, clearcoat_normal_tex) \
	X(Material, clearcoat_normal_scale) X(Material, anisotropy) X(Material, anisotropy_tex) \
	X(Texture, offset) X(Texture, width) X(Texture, height) X(Texture, flags)      \
	X(Texture, xf)                                                                  \
	X(Emitter, tri) X(Emitter, area) X(Emitter, pdf_select) X(Emitter, cell)       \
	X(PortalTri, p0) X(PortalTri, p2) X(PortalTri, n) X(PortalTri, area)          \
	X(PortalTri, pdf_select) X(PortalTri, side_plus) X(PortalTri, env_side)       \
	X(Camera, pos) X(Camera, tan_half_fov_y) X(Camera, right) X(Camera, aspect)    \
	X(Camera, up) X(Camera, width) X(Camera, forward) X(Camera, height)            \
	X(Params, camera) X(Params, num_tris) X(Params, num_emitters)                  \
	X(Params, num_portals) X(Params, num_textures) X(Params, env_type)             \
	X(Params, env_width) X(Params, env_height) X(Params, env_strength)             \
	X(Params, env_color) X(Params, env_pdf_select) X(Params, scene_center)         \
	X(Params, scene_radius) X(Params, max_depth) X(Params, rr_depth)               \
	X(Params, integrator) X(Params, seed) X(Params, emitter_power)                 \
	X(Params, env_power) X(Params, mis) X(Params, min_depth)                       \
	X(Params, strategy_len) X(Params, strategy_unweighted) X(Params, cross_filter)  \
	X(Params, cross_lo) X(Params, cross_hi) X(Params, portal_s_max)                   \
	X(Params, portal_sp_max) X(Params, portal_tp_max) X(Params, light_paths) \
	X(Params, portal_t_max) X(Params, portal_rate) X(Params, env_rotation)          \
	X(Params, num_lights) X(Params, light_power)                                    \
	X(PunctualLight, pos) X(PunctualLight, type) X(PunctualLight, dir)            \
	X(PunctualLight, pdf_select) X(PunctualLight, intensity) X(PunctualLight, range)\
	X(PunctualLight, cos_outer) X(PunctualLight, cone_scale)                       \
	X(PunctualLight, disk_radius)                                                  \
	X(Params, num_portal_planes) X(Params, env_rot_cos) X(Params, env_rot_sin)     \
	X(Params, bdpt_conn) X(Params, env_lines) X(Params, num_panes)                 \
	X(Params, num_pane_planes) X(Params, pane_n) X(Params, pane_d)                 \
	X(PortalPlane, o) X(PortalPlane, a0) X(PortalPlane, t) X(PortalPlane, n)      \
	X(PortalPlane, b1) X(PortalPlane, table)                                       \
	X(Instance, xf) X(Instance, inv) X(Instance, root) X(Instance, flags) X(Instance, mesh)
#endif
