"""assets.py — textured Khronos sample assets rendered by Ajar and by Cycles
through Blender's own glTF importer (the reference reading of glTF's
materials, textures, alpha modes, normal maps, texture transforms and vertex
colours), compared block by block (part of `make bench-peers`; alone:
`sh tests/peers/run.sh assets`).

  build/peers/venv/bin/python tests/peers/assets.py

For each asset in scenes/khronos (ASSETS_LIST, default "AlphaBlendModeTest
TextureTransformTest VertexColorTest NormalTangentMirrorTest"): the asset's
folder is copied to build/peers/assets/<name>/ and a view of it written
there, <name>-view.gltf: the asset unchanged plus a perspective camera on its
+Z side framing the bounding box of its meshes, and a uniform white sky
(Ajar: scene extras environment; Cycles: the world's background, colour 1,
strength 1). Ajar's `pt` and Cycles (the importer's node tree untouched,
the camera's vertical field of view set as Ajar reads it) render it at
ASSETS_SPP (256) samples per pixel, ASSETS_SIZE (192) wide, depth
ASSETS_DEPTH (16), box pixel filter, no denoising or clamping, seeds 1 and
2 each. An entry "scene:<path>" (a .gltf under scenes/, e.g.
scene:sofa-room/sofa-room.gltf) renders that scene as it is, with its own
camera and constant sky (Cycles: the importer's camera, the sky's colour as
the world), ASSETS_SIZE wide at the camera's aspect. The images are cut into 16 x 16-pixel blocks; per block the mean
over its pixels and channels; a block matches if Ajar's and Cycles' means
differ by at most ASSETS_TOL (5%) of Cycles'. Printed per asset: the
fraction of matching blocks (all, and "object" blocks: those where Cycles
is not the bare sky within 1% everywhere), the median and worst block
differences with the worst blocks' positions, the image means, and the
noise (the two seeds' block difference, per renderer). Side-by-side PNGs
(Ajar | Cycles | block map: green within ASSETS_TOL, red beyond) go to
build/peers/assets/<name>-side.png. Exits 0: a report, not a gate. An entry "glass:<roughness>" renders a
generated scene instead (write_glass_view): a faceted rough glass sphere on
a grey floor, the check of Ajar's rough glass against Cycles' in a scene.
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

BLOCK = 16


def quat_matrix(q):
	x, y, z, w = q
	return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
			 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
			 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def node_matrix(n):
	if "matrix" in n:
		return np.array(n["matrix"], dtype=np.float64).reshape(4, 4).T
	m = np.eye(4)
	m[:3, :3] = quat_matrix(n.get("rotation", [0, 0, 0, 1])) @ np.diag(n.get("scale", [1, 1, 1]))
	m[:3, 3] = n.get("translation", [0, 0, 0])
	return m


def bounds(g):
	"""World-space box of every mesh's POSITION min/max corners."""
	lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
	sc = g["scenes"][g.get("scene", 0)]
	stack = [(i, np.eye(4)) for i in sc["nodes"]]
	while stack:
		i, parent = stack.pop()
		n = g["nodes"][i]
		world = parent @ node_matrix(n)
		if "mesh" in n:
			for p in g["meshes"][n["mesh"]]["primitives"]:
				a = g["accessors"][p["attributes"]["POSITION"]]
				for c in range(8):
					v = np.array([(a["max"] if c >> k & 1 else a["min"])[k] for k in range(3)] + [1.0])
					w = world @ v
					lo, hi = np.minimum(lo, w[:3]), np.maximum(hi, w[:3])
		stack += [(c, world) for c in n.get("children", [])]
	return lo, hi


def write_view(name, out_dir, width, height):
	src = os.path.join(os.path.dirname(HERE), "..", "scenes", "khronos", name)
	src = os.path.abspath(src)
	if os.path.exists(out_dir):
		shutil.rmtree(out_dir)
	shutil.copytree(src, out_dir)
	g = json.load(open(os.path.join(src, name + ".gltf")))
	lo, hi = bounds(g)
	c, half = (lo + hi) / 2, (hi - lo) / 2
	yfov, aspect = 0.5, width / height
	# Distance at which the box's front face fills the view with 8% margin.
	fit = max(half[1], half[0] / aspect) * 1.08
	dist = half[2] + fit / np.tan(yfov / 2)
	g.setdefault("cameras", []).append({"type": "perspective", "perspective": {
		"yfov": yfov, "aspectRatio": aspect, "znear": 0.01 * dist, "zfar": 100 * dist}})
	g["nodes"].append({"name": "peers-camera", "camera": len(g["cameras"]) - 1,
			   "translation": [float(c[0]), float(c[1]), float(c[2] + dist)]})
	sc = g["scenes"][g.get("scene", 0)]
	sc["nodes"].append(len(g["nodes"]) - 1)
	sc.setdefault("extras", {})["environment"] = {"color": [1, 1, 1]}
	path = os.path.join(out_dir, name + "-view.gltf")
	json.dump(g, open(path, "w"), indent=1)
	return path, yfov


def write_glass_view(roughness, out_dir, width, height):
	"""A generated scene (ASSETS_LIST entry "glass:<roughness>"): a faceted
	glass sphere (KHR_materials_transmission 1, ior 1.5, white) of radius
	0.5 resting on a grey plastic floor, a white sky, the same camera rule."""
	import base64
	nt, npp = 24, 48
	pos, idx = [], []
	for i in range(nt + 1):
		for j in range(npp):
			th, ph = math.pi * i / nt, 2 * math.pi * j / npp
			pos.append((0.5 * math.sin(th) * math.cos(ph), 0.5 + 0.5 * math.cos(th), 0.5 * math.sin(th) * math.sin(ph)))
	for i in range(nt):
		for j in range(npp):
			a, b = i * npp + j, i * npp + (j + 1) % npp
			c, d = a + npp, b + npp
			if i > 0:
				idx += [a, b, c]
			if i < nt - 1:
				idx += [b, d, c]
	floor = [(-2, 0, -2), (2, 0, -2), (2, 0, 2), (-2, 0, 2)]
	fidx = [0, 2, 1, 0, 3, 2]
	blob = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<3f", *p) for p in floor)
	off_i = len(blob)
	blob += b"".join(struct.pack("<I", k) for k in idx) + b"".join(struct.pack("<I", k) for k in fidx)
	lo = [min(p[k] for p in pos) for k in range(3)]
	hi = [max(p[k] for p in pos) for k in range(3)]
	n1, n2 = len(pos) * 12, len(floor) * 12
	g = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
	     "scenes": [{"nodes": [0, 1]}], "nodes": [{"mesh": 0}, {"mesh": 1}],
	     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
			{"primitives": [{"attributes": {"POSITION": 1}, "indices": 3, "material": 1}]}],
	     "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
						      "roughnessFactor": roughness},
			    "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
					   "KHR_materials_ior": {"ior": 1.5}}},
			   {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
						      "roughnessFactor": 0.5}, "doubleSided": True}],
	     "buffers": [{"byteLength": len(blob),
			  "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
	     "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": n1},
			     {"buffer": 0, "byteOffset": n1, "byteLength": n2},
			     {"buffer": 0, "byteOffset": off_i, "byteLength": 4 * len(idx)},
			     {"buffer": 0, "byteOffset": off_i + 4 * len(idx), "byteLength": 4 * len(fidx)}],
	     "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi},
			   {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2],
			    "max": [2, 0, 2]},
			   {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
			   {"bufferView": 3, "componentType": 5125, "count": len(fidx), "type": "SCALAR"}]}
	os.makedirs(out_dir, exist_ok=True)
	yfov, aspect = 0.5, width / height
	c = [0.0, 0.5, 0.0]
	dist = 0.5 + 0.75 / math.tan(yfov / 2)
	g["cameras"] = [{"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.01,
								"zfar": 1000}}]
	# Looking down 15 degrees at the sphere's centre.
	e = math.radians(15)
	g["nodes"].append({"camera": 0, "translation": [0, c[1] + dist * math.sin(e), dist * math.cos(e)],
			   "rotation": [-math.sin(e / 2), 0, 0, math.cos(e / 2)]})
	g["scenes"][0]["nodes"].append(2)
	g["scenes"][0]["extras"] = {"environment": {"color": [1, 1, 1]}}
	path = os.path.join(out_dir, "glass-view.gltf")
	json.dump(g, open(path, "w"))
	return path, yfov


def cycles_main(argv):
	"""Child process: render a view with Cycles through Blender's importer."""
	path, out, w, h, spp, seed, depth, threads, yfov = argv
	w, h, spp, seed, depth, threads, yfov = int(w), int(h), int(spp), int(seed), int(depth), int(threads), float(yfov)
	import tempfile
	import bpy
	bpy.ops.wm.read_factory_settings(use_empty=True)
	bpy.ops.import_scene.gltf(filepath=path)
	sc = bpy.context.scene
	for o in list(sc.objects):  # portals (extras "portal", a custom property after import) are no surfaces
		if o.get("portal"):
			bpy.data.objects.remove(o, do_unlink=True)
	cams = [o for o in sc.objects if o.type == "CAMERA"]
	if len(cams) != 1:
		raise SystemExit(f"assets: {path}: {len(cams)} cameras after import")
	cam = cams[0]
	cam.data.sensor_fit = "VERTICAL"
	cam.data.angle_y = yfov
	sc.camera = cam
	world = bpy.data.worlds.new("world")
	world.use_nodes = True
	bg = world.node_tree.nodes.get("Background") or world.node_tree.nodes.new("ShaderNodeBackground")
	bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
	bg.inputs["Strength"].default_value = 1.0
	sc.world = world
	r = sc.render
	r.engine = "CYCLES"
	r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
	r.film_transparent = False
	r.threads_mode = "FIXED"
	r.threads = threads
	r.image_settings.file_format = "OPEN_EXR"
	r.image_settings.color_depth = "32"
	r.image_settings.color_mode = "RGB"
	sc.view_settings.view_transform = "Raw"
	sc.view_settings.look = "None"
	cy = sc.cycles
	cy.device = "CPU"
	cy.use_adaptive_sampling = False
	cy.use_denoising = False
	for vl in sc.view_layers:
		vl.cycles.use_denoising = False
	cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
	cy.light_sampling_threshold = 0.0
	cy.blur_glossy = 0.0
	b = max(0, depth - 2)
	cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = b
	cy.transparent_max_bounces = max(b, 64)
	cy.min_light_bounces = cy.min_transparent_bounces = 0
	cy.pixel_filter_type = "BOX"
	cy.filter_width = 1.0
	cy.seed = seed
	cy.samples = spp
	with tempfile.TemporaryDirectory(prefix="peers-assets-") as tmp:
		r.filepath = os.path.join(tmp, "out.exr")
		bpy.ops.render.render(write_still=True)
		img = bpy.data.images.load(r.filepath)
		img.colorspace_settings.is_data = True
		px = np.empty(w * h * img.channels, dtype=np.float32)
		img.pixels.foreach_get(px)
	np.save(out, px.reshape(h, w, img.channels)[::-1, :, :3])


def blocks(rgb):
	h, w = rgb.shape[0] // BLOCK * BLOCK, rgb.shape[1] // BLOCK * BLOCK
	m = rgb[:h, :w].mean(axis=2).reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK)
	return m.mean(axis=(1, 3))


def side_by_side(path, a, c, ok, tol):
	import images
	from PIL import Image
	h, w = a.shape[:2]
	gap = 4
	canvas = np.full((h, 3 * w + 2 * gap, 3), 255, dtype=np.uint8)
	canvas[:, :w] = images.to_srgb8(a)
	canvas[:, w + gap:2 * w + gap] = images.to_srgb8(c)
	rel = np.abs(blocks(a) - blocks(c)) / np.maximum(blocks(c), 1e-6)
	mapimg = np.zeros((h, w, 3), dtype=np.uint8)
	for by in range(rel.shape[0]):
		for bx in range(rel.shape[1]):
			col = (40, 170, 60) if rel[by, bx] <= tol else (210, 40, 40)
			if not ok[by, bx]:
				col = tuple(int(0.5 * x + 100) for x in col)  # bare sky: faded
			mapimg[by * BLOCK:(by + 1) * BLOCK, bx * BLOCK:(bx + 1) * BLOCK] = col
	canvas[:, 2 * w + 2 * gap:] = mapimg
	Image.fromarray(canvas).save(path)


def main():
	import driver
	names = os.environ.get("ASSETS_LIST",
			       "AlphaBlendModeTest TextureTransformTest VertexColorTest NormalTangentMirrorTest").split()
	spp = int(os.environ.get("ASSETS_SPP", "256"))
	width = int(os.environ.get("ASSETS_SIZE", "192"))
	depth = int(os.environ.get("ASSETS_DEPTH", "16"))
	tol = float(os.environ.get("ASSETS_TOL", "0.05"))
	base = os.path.join(driver.OUT, "assets")
	os.makedirs(base, exist_ok=True)
	driver.ensure_ajar()
	report = []
	for name in names:
		if name.startswith("scene:"):
			path = os.path.join(driver.ROOT, "scenes", name[6:])
			g = json.load(open(path))
			persp = g["cameras"][0]["perspective"]
			yfov = persp["yfov"]
			height = int(round(width / persp.get("aspectRatio", 1.0) / BLOCK)) * BLOCK
			name = os.path.splitext(os.path.basename(path))[0]
		elif name.startswith("glass:"):
			height = width
			path, yfov = write_glass_view(float(name[6:]), os.path.join(base, name.replace(":", "-")), width, height)
			name = name.replace(":", "-")
		else:
			g = json.load(open(os.path.join(driver.ROOT, "scenes", "khronos", name, name + ".gltf")))
			lo, hi = bounds(g)
			ext = hi - lo
			height = int(round(width * min(max(ext[1] / max(ext[0], 1e-9), 0.5), 1.5) / BLOCK)) * BLOCK
			path, yfov = write_view(name, os.path.join(base, name), width, height)
		imgs = {}
		for r in ("ajar", "cycles"):
			imgs[r] = []
			for seed in (1, 2):
				out = os.path.join(base, f"{name}-{r}-{seed}")
				if r == "ajar":
					rgb, info = driver.run_ajar("pt", path, (width, height), depth, out + ".exr", spp=spp, seed=seed)
					if rgb is None:
						raise SystemExit(f"assets: ajar failed on {path}")
				else:
					cmd = [sys.executable, os.path.abspath(__file__), "--cycles", path, out + ".npy", str(width),
					       str(height), str(spp), str(seed), str(depth), str(driver.env_threads()), str(yfov)]
					p, wall, cpu = driver.run_timed(cmd, cwd=driver.ROOT, env=driver.sub_env(), capture_output=True,
									text=True)
					if p.returncode != 0:
						raise SystemExit(f"assets: cycles failed on {path}: {(p.stderr or p.stdout)[-800:]}")
					rgb = np.load(out + ".npy").astype(np.float64)
					# kept: build/peers/assets/<name>-cycles-<seed>.npy, for a closer look
				imgs[r].append(rgb)
		a = (imgs["ajar"][0] + imgs["ajar"][1]) / 2
		c = (imgs["cycles"][0] + imgs["cycles"][1]) / 2
		ba, bc = blocks(a), blocks(c)
		rel = np.abs(ba - bc) / np.maximum(bc, 1e-6)
		# Noise of a block difference: the seeds' halved difference, both renderers.
		na = np.abs(blocks(imgs["ajar"][0]) - blocks(imgs["ajar"][1])) / 2 / np.maximum(bc, 1e-6)
		nc = np.abs(blocks(imgs["cycles"][0]) - blocks(imgs["cycles"][1])) / 2 / np.maximum(bc, 1e-6)
		hh, ww = ba.shape[0] * BLOCK, ba.shape[1] * BLOCK
		sky = np.abs(c[:hh, :ww] - 1.0).max(axis=2).reshape(ba.shape[0], BLOCK, ba.shape[1], BLOCK).max(axis=(1, 3))
		obj = sky > 0.01
		within = rel <= tol
		worst = np.argsort(rel, axis=None)[::-1][:3]
		w_txt = ", ".join(f"({i % ba.shape[1]}, {i // ba.shape[1]}) {100 * rel.flat[i]:+.1f}%"
				  f" [ajar {ba.flat[i]:.3f} cycles {bc.flat[i]:.3f}]"
				  for i in worst)
		row = {"asset": name, "size": f"{width}x{height}", "blocks": int(rel.size), "object_blocks": int(obj.sum()),
		       "within_all": float(within.mean()), "within_object": float(within[obj].mean()) if obj.any() else 1.0,
		       "median_object": float(np.median(rel[obj])) if obj.any() else 0.0,
		       "worst": float(rel.max()), "noise_rms": float(np.sqrt(np.mean(na[obj] ** 2 + nc[obj] ** 2)))
		       if obj.any() else 0.0,
		       "mean_ajar": float(a.mean()), "mean_cycles": float(c.mean())}
		report.append(row)
		driver.log(f"{name} {row['size']}: {100 * row['within_all']:.1f}% of {row['blocks']} blocks within "
			   f"{100 * tol:.0f}% ({100 * row['within_object']:.1f}% of {row['object_blocks']} object blocks); "
			   f"object median {100 * row['median_object']:.2f}%, noise rms {100 * row['noise_rms']:.2f}%; "
			   f"image mean ajar {row['mean_ajar']:.4f} cycles {row['mean_cycles']:.4f} "
			   f"({100 * (row['mean_ajar'] / row['mean_cycles'] - 1):+.2f}%); worst blocks (x, y): {w_txt}")
		side_by_side(os.path.join(base, f"{name}-side.png"), a, c, obj, tol)
	json.dump(report, open(os.path.join(base, "report.json"), "w"), indent=1)
	print("| asset | blocks within %d%% (all) | object blocks within %d%% | object median | worst | "
	      "noise rms | image mean Ajar / Cycles |" % (100 * tol, 100 * tol))
	print("|---|---|---|---|---|---|---|")
	for r in report:
		print(f"| {r['asset']} | {100 * r['within_all']:.1f}% of {r['blocks']} | {100 * r['within_object']:.1f}% of "
		      f"{r['object_blocks']} | {100 * r['median_object']:.2f}% | {100 * r['worst']:.1f}% | "
		      f"{100 * r['noise_rms']:.2f}% | {100 * (r['mean_ajar'] / r['mean_cycles'] - 1):+.2f}% |")


if __name__ == "__main__":
	if len(sys.argv) > 1 and sys.argv[1] == "--cycles":
		cycles_main(sys.argv[2:])
	else:
		main()
