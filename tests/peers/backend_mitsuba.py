"""backend_mitsuba.py — the scene in Mitsuba 3, `path` integrator.

Variant llvm_ad_rgb (a JIT-compiled wavefront path tracer on the CPU; needs
LLVM >= 16: DRJIT_LIBLLVM_PATH names Debian's libLLVM-19), else scalar_rgb.
Each material's triangles are one PLY mesh with face normals (no shading
normals); diffuse is wrapped in `twosided` (Mitsuba's is one-sided, Ajar's
two-sided); area emitters are one-sided on the CCW front, as Ajar's. The
camera is `perspective` with the vertical field of view, the film `hdrfilm`
with the 1-pixel box filter. max_depth D counts segments from the camera,
as Ajar's --max-depth does. Russian roulette is Mitsuba's default (unbiased).

The sky image is an `envmap`: Mitsuba's lookup is Ajar's turned by half a
turn about +Y (checked with a sky of numbered columns), so its to_world is
a rotation of (rotation + 180) degrees about +Y. Its lookup is bilinear,
Ajar's nearest-texel: the image goes in clamped to >= 0 (as Ajar reads
it) and upsampled 4x by repetition, so the two differ only within a
quarter texel of each texel edge. KHR_lights_punctual lights become
`directional` (irradiance = colour x lux / 683 W/m^2, `direction` where
the light travels), `point` and `spot` (intensity = colour x cd / 683
W/sr; cutoff_angle the outer cone, beam_width the inner).

Smooth thin-walled panes (scene.py, is_pane) get `gltf_thin_pane`, a BSDF
written here (register_pane), since none of Mitsuba's is glTF's thin model
(`thindielectric` is a slab with inter-reflections, T = (1 - F) / (1 + F) at
normal incidence, not 1 - F). It samples a delta reflection with probability
F and a pass-through (wo = -wi) with probability 1 - F, weights 1 and the
base colour, F the exact dielectric Fresnel at |cos theta| (mi.fresnel), so
both sides see the same pane. The pass-through is flagged Null. Mitsuba's
`path` treats Null as it treats DeltaTransmission (both are in
BSDFFlags.Delta): no emitter sampling at the pane (the BSDF has no Smooth
component), and an emitter reached right after it is counted with MIS
weight 1 (prev_bsdf_delta); only the alpha channel differs. Its shadow rays
stop at the pane (ray_test sees every shape), so light through a window is
found only by BSDF sampling: unbiased, slower. Unlike Ajar's (which takes
no vertex) and Cycles' (a transparent bounce, counted apart), the crossing
counts as a bounce of max_depth: a path that crosses k panes is cut k
segments earlier (at depth 32 well below the noise).

Sampler: `independent` (Mitsuba's default), or with --integrator ld
(renderer name mitsuba-ld) `ldsampler`, Mitsuba's low-discrepancy sampler
(padded, scrambled (0,2)-sequences, as Ajar's), in passes of a power of two
samples per pixel so each pass is a whole net.

Equal time: the image is rendered in passes of a few samples per pixel
with different seeds and averaged; passes run until the time is used up (the
last pass may overshoot; the real time is reported). One warm-up pass,
which pays the JIT compilation, is not counted.
"""
import math
import os
import struct
import tempfile
import time

import numpy as np


def write_ply(path, v, f):
	with open(path, "wb") as fh:
		fh.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n"
			  "property float x\nproperty float y\nproperty float z\n"
			  f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
		fh.write(np.ascontiguousarray(v, dtype="<f4").tobytes())
		rec = np.zeros(len(f), dtype=[("n", "u1"), ("i", "<i4", 3)])
		rec["n"] = 3
		rec["i"] = f
		fh.write(rec.tobytes())


def set_variant(mi):
	want = os.environ.get("PEERS_MITSUBA_VARIANT", "llvm_ad_rgb")
	for v in (want, "scalar_rgb"):
		try:
			mi.set_variant(v)
			return v
		except Exception:
			continue
	raise RuntimeError("no usable Mitsuba variant")


def load_sky(mi, scene):
	"""The sky image as Mitsuba gets it (clamped, upsampled), or None: from
	the driver's .npy where given (Mitsuba's EXR reader hangs in a process
	bound to one CPU), else read here, before drjit's thread count is set."""
	if scene.sky is None:
		return None
	if scene.sky.get("array"):
		px = np.maximum(np.load(scene.sky["array"]).astype(np.float32)[:, :, :3], 0.0)
	else:
		px = np.maximum(np.array(mi.Bitmap(scene.sky["path"]), dtype=np.float32)[:, :, :3], 0.0)
	return np.repeat(np.repeat(px, 4, axis=0), 4, axis=1)


def register_pane(mi, dr):
	"""Registers `gltf_thin_pane` (see the module comment): props ior (1.5)
	and tint_r, tint_g, tint_b (the base colour x transmission)."""

	class ThinPane(mi.BSDF):
		def __init__(self, props):
			mi.BSDF.__init__(self, props)
			self.ior = props.get("ior", 1.5)
			self.tint = mi.Color3f(*[float(props.get("tint_" + c, 1.0)) for c in "rgb"])
			both = mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
			self.m_components = [mi.BSDFFlags.DeltaReflection | both, mi.BSDFFlags.Null | both]
			self.m_flags = self.m_components[0] | self.m_components[1]

		def sample(self, ctx, si, sample1, sample2, active):
			# |cos|: the pane is the same interface (air | air) from either side.
			f = mi.fresnel(dr.abs(mi.Frame3f.cos_theta(si.wi)), self.ior)[0]
			reflect = sample1 < f
			bs = dr.zeros(mi.BSDFSample3f)
			bs.wo = dr.select(reflect, mi.reflect(si.wi), -si.wi)
			bs.pdf = dr.select(reflect, f, 1.0 - f)
			bs.eta = 1.0
			bs.sampled_component = dr.select(reflect, mi.UInt32(0), mi.UInt32(1))
			bs.sampled_type = dr.select(reflect, mi.UInt32(+mi.BSDFFlags.DeltaReflection),
						    mi.UInt32(+mi.BSDFFlags.Null))
			weight = dr.select(reflect, mi.Color3f(1.0), self.tint)
			ok = active & (bs.pdf > 0)
			return bs, dr.select(ok, weight, mi.Color3f(0.0))

		def eval(self, ctx, si, wo, active):
			return mi.Color3f(0.0)  # delta lobes only

		def pdf(self, ctx, si, wo, active):
			return mi.Float(0.0)

		def eval_pdf(self, ctx, si, wo, active):
			return mi.Color3f(0.0), mi.Float(0.0)

		def eval_null_transmission(self, si, active):
			f = mi.fresnel(dr.abs(mi.Frame3f.cos_theta(si.wi)), self.ior)[0]
			return self.tint * (1.0 - f)

		def to_string(self):
			return f"ThinPane[ior={self.ior}]"

	mi.register_bsdf("gltf_thin_pane", lambda props: ThinPane(props))


def build(mi, scene, a, tmp, sky_px=None):
	d = {"type": "scene", "integrator": {"type": "path", "max_depth": a.depth}}
	c = scene.camera
	origin = [float(x) for x in c["pos"]]
	target = [float(x) for x in c["pos"] + c["forward"]]
	up = [float(x) for x in c["up"]]
	try:
		to_world = mi.ScalarTransform4f().look_at(origin=origin, target=target, up=up)
	except TypeError:
		to_world = mi.ScalarTransform4f.look_at(origin=origin, target=target, up=up)
	d["sensor"] = {
		"type": "perspective", "fov_axis": "y", "fov": math.degrees(c["yfov"]), "to_world": to_world,
		"near_clip": 1e-3, "far_clip": 1e5,
		"film": {"type": "hdrfilm", "width": a.width, "height": a.height, "rfilter": {"type": "box"},
			 "pixel_format": "rgb", "sample_border": False},
		"sampler": {"type": "ldsampler", "sample_count": 4} if a.integrator == "ld" else {"type": "independent", "sample_count": 1},
	}
	for mi_index, (v, f) in scene.by_material().items():
		m = scene.materials[mi_index]
		path = os.path.join(tmp, f"mesh{mi_index}.ply")
		write_ply(path, v, f)
		if m["pane"]:
			bsdf = {"type": "gltf_thin_pane", "ior": float(m["ior"])}
			for c, x in zip("rgb", m["base"]):
				bsdf["tint_" + c] = float(x) * float(m["transmission"])
		else:
			bsdf = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {
				"type": "rgb", "value": [float(x) for x in m["base"]]}}}
		shape = {"type": "ply", "filename": path, "face_normals": True, "bsdf": bsdf}
		if m["emission"].max() > 0:
			shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": [float(x) for x in m["emission"]]}}
		d[f"mesh{mi_index}"] = shape
	if scene.environment is not None:
		d["env"] = {"type": "constant", "radiance": {"type": "rgb", "value": scene.environment}}
	if sky_px is not None:
		d["env"] = {"type": "envmap", "bitmap": mi.Bitmap(sky_px), "scale": float(scene.sky["strength"]),
			    "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], scene.sky["rotation"] + 180.0)}
	for k, li in enumerate(scene.lights):
		rgb = [float(c) * li["intensity"] / 683.0 for c in li["color"]]
		pos = [float(x) for x in li["position"]]
		if li["type"] == "directional":
			d[f"light{k}"] = {"type": "directional", "direction": [float(x) for x in li["direction"]],
					  "irradiance": {"type": "rgb", "value": rgb}}
		elif li["type"] == "point":
			d[f"light{k}"] = {"type": "point", "position": pos, "intensity": {"type": "rgb", "value": rgb}}
		else:
			target = [p + float(x) for p, x in zip(pos, li["direction"])]
			up = [0, 1, 0] if abs(li["direction"][1]) < 0.9 else [1, 0, 0]
			d[f"light{k}"] = {"type": "spot", "intensity": {"type": "rgb", "value": rgb},
					  "cutoff_angle": math.degrees(li["outer"]), "beam_width": math.degrees(li["inner"]),
					  "to_world": mi.ScalarTransform4f().look_at(origin=pos, target=target, up=up)}
	return mi.load_dict(d)


def render(scene, a, t0):
	import mitsuba as mi
	import drjit as dr
	variant = set_variant(mi)
	register_pane(mi, dr)
	sky_px = load_sky(mi, scene)
	try:
		dr.set_thread_count(a.threads)
	except Exception:
		pass
	with tempfile.TemporaryDirectory(prefix="peers-mi-") as tmp:
		sc = build(mi, scene, a, tmp, sky_px)
	# Passes small enough for the wavefront to stay in memory (about 1M lanes).
	per_pass = max(1, min(256, (1 << 20) // (a.width * a.height)))
	if a.integrator == "ld":
		per_pass = 1 << (per_pass.bit_length() - 1)
	if variant.startswith("scalar"):
		per_pass = max(1, min(per_pass, 16))
	if a.spp:
		per_pass = min(per_pass, a.spp)
	seed = a.seed * 100003
	np.array(mi.render(sc, spp=per_pass, seed=seed))  # warm-up: JIT compilation, not counted
	setup = time.perf_counter() - t0
	acc = np.zeros((a.height, a.width, 3))
	spp, k = 0, 0
	start = time.perf_counter()
	while True:
		n = per_pass if not a.spp else min(per_pass, a.spp - spp)
		k += 1
		img = np.array(mi.render(sc, spp=n, seed=seed + k), dtype=np.float64)
		acc += img[:, :, :3] * n
		spp += n
		el = time.perf_counter() - start
		if (a.spp and spp >= a.spp) or (a.seconds and el >= a.seconds):
			break
	return acc / spp, {"renderer": "mitsuba", "variant": variant, "spp": spp, "render_seconds": round(el, 3),
			   "setup_seconds": setup, "passes": k}
