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
		shape = {"type": "ply", "filename": path, "face_normals": True,
			 "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {
				 "type": "rgb", "value": [float(x) for x in m["base"]]}}}}
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
