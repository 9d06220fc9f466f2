"""scene.py — the one glTF reader of the peer benchmark (tests/peers).

Reads an Ajar glTF scene into world-space numpy triangles grouped by material,
with what every peer renderer needs to rebuild the same scene: the camera,
the uniform environment, emitters and the portal quads. It follows Ajar's
loader (src/scene/gltf.cpp) where that matters for matching:
  - nodes are walked depth first, parents before children, in file order, and
    the first perspective camera met sets the camera (forward = the node's
    -Z, up = its +Y, vertical field of view yfov; the aspect is the image's);
  - a node whose transform has a negative determinant has its winding
    reversed, so the front face (CCW, glTF's) stays the front face: emitters
    emit from the front only (kernels/light/lights.h, emitter_radiance);
  - a node with extras {"portal": true} (or a non-zero number) is a portal:
    its triangles are not geometry;
  - emission = emissiveFactor x KHR_materials_emissive_strength;
  - scene extras {"environment": {"color": [r, g, b], "strength": s}} is a
    uniform environment of radiance color x strength; {"environment":
    {"image": "sky.exr", "strength": s, "rotation": a}} a sky image (path
    relative to the glTF), turned by a degrees about +Y, right-handed
    (counter-clockwise seen from above; kernels/light/env.h);
  - KHR_lights_punctual lights on nodes: position the node's origin,
    direction its -Z, colour x intensity (lux for directional, candela for
    point and spot), spot cones in radians; range ignored (Ajar's, and
    the peers' lights, have none).
Normals are not read: the peers get flat triangles, so shading normals cannot
make them differ (scenes whose normals are not flat are rendered through a
matched variant without normals, see lambert_variant).

It also writes that matched variant: every material Lambertian with its base
colour (a base colour texture replaced by the mean of its texels decoded from
sRGB to linear, times the factor, as Ajar samples it), solid glass removed,
geometry flattened to world space without normals. Ajar renders the variant
too, so all renderers see the same scene.

One non-Lambertian material is kept as it is: the smooth thin-walled pane
(is_pane: KHR_materials_transmission 1 without KHR_materials_volume or with
thickness 0, roughness 0, metallic 0, no texture, specular layer untouched).
glTF makes it one interface that does not bend light: specular reflection
with weight F and straight-through transmission (wi = -wo) with weight
(1 - F) baseColor, F the exact unpolarised dielectric Fresnel at ior for
|cos| to the surface, the same from both sides. Every peer builds exactly
that (backend_mitsuba.py, backend_cycles.py); LuxCore is not given such
scenes (driver.supports). Any other transmissive material (a volume, a
rough or partly transmissive surface) has its meshes removed.
"""
import base64
import json
import math
import os
import shutil
import struct

import numpy as np

COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def srgb_to_linear(c):
	c = np.asarray(c, dtype=np.float64)
	return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def quat_matrix(q):
	x, y, z, w = q
	return np.array([
		[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
		[2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
		[2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
	])


def node_local(n):
	if "matrix" in n:
		return np.array(n["matrix"], dtype=np.float64).reshape(4, 4).T  # glTF is column major
	m = np.eye(4)
	r = quat_matrix(n.get("rotation", [0, 0, 0, 1]))
	s = np.diag(n.get("scale", [1, 1, 1]))
	m[:3, :3] = r @ s
	m[:3, 3] = n.get("translation", [0, 0, 0])
	return m


class Scene:
	"""World-space triangles of one glTF scene.

	materials: list of dicts name, base (linear RGB), emission (radiance RGB),
	  lambertian (True if the BSDF is exactly base/pi: no metal, no
	  transmission, specularFactor 0), metallic, transmission, specular;
	meshes: list of (material index, vertices (n, 3) float64, faces (m, 3) int);
	portals: list of (name, vertices, faces); camera: dict pos, forward, up,
	yfov, aspect (the glTF aspectRatio, 0 if none); environment: RGB or None
	(a uniform sky); sky: dict path (absolute), strength, rotation (degrees)
	or None (a sky image); lights: list of dicts type (directional, point,
	spot), color, intensity, position, direction (unit, where the light
	shines), inner, outer (spot cone angles, radians).
	"""

	def __init__(self, path):
		self.path = path
		self.dir = os.path.dirname(os.path.abspath(path))
		with open(path) as f:
			self.g = json.load(f)
		self.buffers = [self._buffer(b) for b in self.g.get("buffers", [])]
		self.materials = [self._material(i, m) for i, m in enumerate(self.g.get("materials", []))]
		self.default_material = None
		self.meshes, self.portals, self.camera, self.lights = [], [], None, []
		self.light_defs = self.g.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
		sc = self.g["scenes"][self.g.get("scene", 0)]
		self._walk(sc.get("nodes", []))
		self.environment = None
		self.sky = None
		env = sc.get("extras", {}).get("environment")
		if env is not None:
			strength = float(env.get("strength", 1.0))
			if "image" in env:
				self.sky = {"path": os.path.join(self.dir, env["image"]), "strength": strength,
					    "rotation": float(env.get("rotation", 0.0))}
			elif "color" in env:
				self.environment = [float(c) * strength for c in env["color"]]
			else:
				raise ValueError(f"{path}: environment needs color or image")
		if self.camera is None:
			raise ValueError(f"{path}: no perspective camera")

	def _buffer(self, b):
		uri = b["uri"]
		if uri.startswith("data:"):
			return base64.b64decode(uri.split(",", 1)[1])
		with open(os.path.join(self.dir, uri), "rb") as f:
			return f.read()

	def accessor(self, i):
		a = self.g["accessors"][i]
		bv = self.g["bufferViews"][a["bufferView"]]
		dt = np.dtype(COMPONENT[a["componentType"]])
		nc = NCOMP[a["type"]]
		start = bv.get("byteOffset", 0) + a.get("byteOffset", 0)
		stride = bv.get("byteStride", 0) or dt.itemsize * nc
		buf = self.buffers[bv["buffer"]]
		raw = np.frombuffer(buf, dtype=np.uint8, count=stride * (a["count"] - 1) + dt.itemsize * nc, offset=start)
		out = np.lib.stride_tricks.as_strided(raw, shape=(a["count"], nc * dt.itemsize), strides=(stride, 1))
		return np.ascontiguousarray(out).view(dt).reshape(a["count"], nc)

	def texture_mean(self, tex_index):
		"""Mean linear RGB of a texture's texels (sRGB-decoded, as Ajar does)."""
		from PIL import Image
		src = self.g["textures"][tex_index]["source"]
		im = self.g["images"][src]
		img = Image.open(os.path.join(self.dir, im["uri"])).convert("RGB")
		a = np.asarray(img, dtype=np.float64) / 255.0
		return srgb_to_linear(a).reshape(-1, 3).mean(axis=0)

	def _material(self, i, m):
		pbr = m.get("pbrMetallicRoughness", {})
		ext = m.get("extensions", {})
		base = np.array(pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], dtype=np.float64)
		tex = pbr.get("baseColorTexture")
		strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
		emission = np.array(m.get("emissiveFactor", [0, 0, 0]), dtype=np.float64) * strength
		metallic = pbr.get("metallicFactor", 1.0)
		transmission = ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0)
		specular = ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0)
		roughness = pbr.get("roughnessFactor", 1.0)
		ior = ext.get("KHR_materials_ior", {}).get("ior", 1.5)
		# glTF: a volume only with a thickness; without one the surface is thin-walled.
		volume = ext.get("KHR_materials_volume", {}).get("thicknessFactor", 0.0) > 0
		spec_ext = ext.get("KHR_materials_specular", {})
		plain_spec = (spec_ext.get("specularFactor", 1.0) == 1.0 and
			      list(spec_ext.get("specularColorFactor", [1, 1, 1])) == [1, 1, 1] and
			      "specularTexture" not in spec_ext and "specularColorTexture" not in spec_ext)
		pane = (transmission == 1.0 and not volume and roughness == 0 and metallic == 0 and tex is None and
			plain_spec and emission.max() == 0 and
			"transmissionTexture" not in ext.get("KHR_materials_transmission", {}) and
			"metallicRoughnessTexture" not in pbr)
		return {
			"name": m.get("name", f"material{i}"), "base": base, "texture": tex["index"] if tex else None,
			"emission": emission, "metallic": metallic, "transmission": transmission,
			"specular": specular, "roughness": roughness, "ior": ior, "double_sided": m.get("doubleSided", False),
			"volume": volume, "pane": pane,
			"lambertian": metallic == 0 and transmission == 0 and specular == 0 and tex is None,
			"portal_material": bool(m.get("extras", {}).get("portal_material", False)),
		}

	def _default(self):
		"""The glTF default material (white, metallic 1, roughness 1)."""
		if self.default_material is None:
			self.materials.append({
				"name": "default", "base": np.ones(3), "texture": None, "emission": np.zeros(3),
				"metallic": 1.0, "transmission": 0.0, "specular": 1.0, "roughness": 1.0, "ior": 1.5, "double_sided": False,
				"volume": False, "pane": False, "lambertian": False, "portal_material": False})
			self.default_material = len(self.materials) - 1
		return self.default_material

	def _walk(self, roots):
		stack = [(r, np.eye(4)) for r in reversed(roots)]
		while stack:
			ni, parent = stack.pop()
			n = self.g["nodes"][ni]
			world = parent @ node_local(n)
			if "mesh" in n:
				self._mesh(ni, n, world)
			if "camera" in n and self.camera is None:
				self._camera(n, world)
			light = n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
			if light is not None:
				self._light(light, world)
			for c in reversed(n.get("children", [])):
				stack.append((c, world))

	def _mesh(self, ni, n, world):
		portal = n.get("extras", {}).get("portal", False)
		portal = portal is True or (isinstance(portal, (int, float)) and not isinstance(portal, bool) and portal != 0)
		flip = np.linalg.det(world[:3, :3]) < 0
		pv, pf = [], []
		for p in self.g["meshes"][n["mesh"]]["primitives"]:
			if p.get("mode", 4) != 4:
				raise ValueError(f"{self.path}: nodes[{ni}]: only triangle lists are supported")
			pos = self.accessor(p["attributes"]["POSITION"]).astype(np.float64)
			pos = pos @ world[:3, :3].T + world[:3, 3]
			if "indices" in p:
				idx = self.accessor(p["indices"]).reshape(-1, 3).astype(np.int64)
			else:
				idx = np.arange(len(pos)).reshape(-1, 3)
			if flip:
				idx = idx[:, [0, 2, 1]]
			if portal:
				pf.append(idx + sum(len(v) for v in pv))
				pv.append(pos)
			else:
				mat = p.get("material")
				self.meshes.append((self._default() if mat is None else mat, pos, idx))
		if portal and pv:
			self.portals.append((n.get("name", f"node{ni}"), np.concatenate(pv), np.concatenate(pf)))

	def _camera(self, n, world):
		c = self.g["cameras"][n["camera"]]
		if c.get("type") != "perspective":
			return
		r = world[:3, :3]
		fwd = -r[:, 2] / np.linalg.norm(r[:, 2])
		up = r[:, 1] / np.linalg.norm(r[:, 1])
		self.camera = {"pos": world[:3, 3].copy(), "forward": fwd, "up": up,
			       "yfov": float(c["perspective"]["yfov"]),
			       "aspect": float(c["perspective"].get("aspectRatio", 0.0))}

	def _light(self, i, world):
		d = self.light_defs[i]
		z = world[:3, 2]
		spot = d.get("spot", {})
		self.lights.append({
			"type": d["type"], "color": np.array(d.get("color", [1, 1, 1]), dtype=np.float64),
			"intensity": float(d.get("intensity", 1.0)), "position": world[:3, 3].copy(),
			"direction": -z / np.linalg.norm(z), "inner": float(spot.get("innerConeAngle", 0.0)),
			"outer": float(spot.get("outerConeAngle", math.pi / 4))})

	# ---- what the peers use ----

	def has_sky(self):
		"""A uniform environment or a sky image: light enters through openings."""
		return self.environment is not None or self.sky is not None

	def has_panes(self):
		"""Whether a mesh is a smooth thin-walled pane (see the module comment)."""
		return any(self.materials[mi]["pane"] for mi, _, _ in self.meshes)

	def check_lambertian(self):
		"""Raise unless every used material is exactly Lambertian or a smooth
		thin-walled pane, the two every peer builds exactly."""
		for mi, _, _ in self.meshes:
			m = self.materials[mi]
			if not (m["lambertian"] or m["pane"]):
				raise ValueError(f"{self.path}: material {m['name']} is not Lambertian (metallic {m['metallic']}, "
						 f"transmission {m['transmission']}, specular {m['specular']}, texture {m['texture']}); "
						 "render the Lambertian variant")

	def by_material(self):
		"""{material index: (vertices, faces)} with each material's meshes merged."""
		groups = {}
		for mi, v, f in self.meshes:
			groups.setdefault(mi, []).append((v, f))
		out = {}
		for mi, parts in groups.items():
			vs, fs, base = [], [], 0
			for v, f in parts:
				vs.append(v)
				fs.append(f + base)
				base += len(v)
			out[mi] = (np.concatenate(vs), np.concatenate(fs))
		return out

	def portal_rects(self):
		"""Each portal as a rectangle: centre, unit axes u, v (u x v = the
		portal's front normal, which points into the room), half sizes.
		Portal nodes here are planar quads (two triangles)."""
		rects = []
		for name, v, f in self.portals:
			n = np.cross(v[f[0, 1]] - v[f[0, 0]], v[f[0, 2]] - v[f[0, 0]])
			n /= np.linalg.norm(n)
			pts = np.unique(np.round(v[np.unique(f)], 6), axis=0)
			c = pts.mean(axis=0)
			# The quad's edges: the longest vertex-to-vertex vectors that are not diagonals.
			e = pts[1:] - pts[0]
			lens = np.linalg.norm(e, axis=1)
			order = np.argsort(lens)
			u = e[order[0]] / lens[order[0]]
			w = np.cross(n, u)
			du = np.abs((pts - c) @ u).max()
			dv = np.abs((pts - c) @ w).max()
			area = sum(0.5 * np.linalg.norm(np.cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]])) for t in f)
			if abs(area - 4 * du * dv) > 1e-3 * area:
				raise ValueError(f"{self.path}: portal {name} is not a rectangle (area {area}, box {4 * du * dv})")
			rects.append({"name": name, "center": c, "u": u, "v": w, "normal": n, "half": (du, dv)})
		return rects


def write_lambert_variant(scene, out_path, pbr=False):
	"""The matched variant of `scene` (see the module comment) as glTF at
	out_path (+ .bin beside it). Returns a list of lines saying what changed.
	With pbr, materials keep their metallic, roughness, specular and ior
	(glTF's specular layers stay on: the energy comparison, energy.py); only
	textures become their mean and transmissive meshes are removed. Smooth
	thin-walled panes are kept as they are in both."""
	notes = []
	mats, remap = [], {}
	used = sorted({mi for mi, _, _ in scene.meshes})
	panes = False
	for mi in used:
		m = scene.materials[mi]
		if m["pane"]:
			notes.append(f"material {m['name']}: smooth thin-walled pane (ior {m['ior']:g}, "
				     f"base colour {np.round(m['base'], 4).tolist()}): kept")
			remap[mi] = len(mats)
			mats.append({"name": m["name"], "pbrMetallicRoughness": {
				"baseColorFactor": [float(x) for x in m["base"]] + [1.0], "metallicFactor": 0.0,
				"roughnessFactor": 0.0}, "doubleSided": True, "extensions": {
				"KHR_materials_transmission": {"transmissionFactor": 1.0},
				"KHR_materials_ior": {"ior": float(m["ior"])}}})
			panes = True
			continue
		if m["transmission"] > 0:
			kind = "with a volume" if m["volume"] else "not a smooth thin pane"
			notes.append(f"material {m['name']}: transmission {m['transmission']} ({kind}): its meshes removed")
			continue
		base = m["base"].copy()
		was = []
		if m["texture"] is not None:
			mean = scene.texture_mean(m["texture"])
			base = base * mean
			was.append(f"texture (mean linear colour {np.round(mean, 4).tolist()})")
		if m["metallic"] > 0 and not pbr:
			was.append(f"metallic {m['metallic']:g}")
		if m["metallic"] < 1 and m["specular"] > 0 and not pbr:
			was.append(f"dielectric layer (specular {m['specular']:g})")
		if was:
			notes.append(f"material {m['name']}: " + ", ".join(was) + " -> " + ("base colour" if pbr else "Lambertian") +
				     f" {np.round(base, 4).tolist()}")
		remap[mi] = len(mats)
		mat = {"name": m["name"], "pbrMetallicRoughness": {"baseColorFactor": [float(x) for x in base] + [1.0],
								   "metallicFactor": 0.0, "roughnessFactor": 1.0},
		       "doubleSided": True, "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}
		if pbr:
			mat["pbrMetallicRoughness"]["metallicFactor"] = float(m["metallic"])
			mat["pbrMetallicRoughness"]["roughnessFactor"] = float(m["roughness"])
			mat["extensions"] = {"KHR_materials_specular": {"specularFactor": float(m["specular"])},
					     "KHR_materials_ior": {"ior": float(m["ior"])}}
		if m["emission"].max() > 0:
			s = float(m["emission"].max())
			mat["emissiveFactor"] = [float(x) / s for x in m["emission"]]
			mat["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": s}
		mats.append(mat)
	blob = bytearray()
	accessors, views, meshes, nodes = [], [], [], []

	def add(arr, comp, typ, target):
		data = np.ascontiguousarray(arr).tobytes()
		views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
		blob.extend(data)
		while len(blob) % 4:
			blob.append(0)
		acc = {"bufferView": len(views) - 1, "componentType": comp, "count": int(arr.shape[0] * (arr.shape[1] if typ == "SCALAR" else 1)),
		       "type": typ}
		if typ == "VEC3":
			acc["min"] = [float(x) for x in arr.min(axis=0)]
			acc["max"] = [float(x) for x in arr.max(axis=0)]
		accessors.append(acc)
		return len(accessors) - 1

	def add_mesh(name, v, f, material):
		p = add(v.astype(np.float32), 5126, "VEC3", 34962)
		i = add(f.astype(np.uint32).reshape(-1, 1), 5125, "SCALAR", 34963)
		prim = {"attributes": {"POSITION": p}, "indices": i, "mode": 4}
		if material is not None:
			prim["material"] = material
		meshes.append({"name": name, "primitives": [prim]})
		return len(meshes) - 1

	for mi, (v, f) in scene.by_material().items():
		if mi in remap:
			nodes.append({"name": scene.materials[mi]["name"], "mesh": add_mesh(scene.materials[mi]["name"], v, f, remap[mi])})
	for name, v, f in scene.portals:
		nodes.append({"name": name, "mesh": add_mesh(name, v, f, None), "extras": {"portal": True}})
	c = scene.camera
	right = np.cross(c["forward"], c["up"])
	right /= np.linalg.norm(right)
	up = np.cross(right, c["forward"])
	m = np.eye(4)
	m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, up, -c["forward"], c["pos"]
	cam = {"type": "perspective", "perspective": {"yfov": c["yfov"], "znear": 0.01}}
	if c["aspect"] > 0:
		cam["perspective"]["aspectRatio"] = c["aspect"]
	nodes.insert(0, {"name": "camera", "camera": 0, "matrix": [float(x) for x in m.T.reshape(-1)]})
	scene_extras = {}
	if scene.environment is not None:
		scene_extras["environment"] = {"color": scene.environment}
	if scene.sky is not None:
		# A copy beside the variant: Ajar reads no file outside a scene's folder.
		sky = os.path.splitext(os.path.basename(out_path))[0] + "-sky" + os.path.splitext(scene.sky["path"])[1]
		shutil.copyfile(scene.sky["path"], os.path.join(os.path.dirname(os.path.abspath(out_path)), sky))
		scene_extras["environment"] = {"image": sky, "strength": scene.sky["strength"],
					       "rotation": scene.sky["rotation"]}
	used = ["KHR_materials_specular", "KHR_materials_emissive_strength"]
	light_defs = []
	for li in scene.lights:
		d = {"type": li["type"], "color": [float(x) for x in li["color"]], "intensity": li["intensity"]}
		if li["type"] == "spot":
			d["spot"] = {"innerConeAngle": li["inner"], "outerConeAngle": li["outer"]}
		light_defs.append(d)
		# A frame whose -Z is the light's direction.
		z = -li["direction"]
		a = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
		x = np.cross(a, z)
		x /= np.linalg.norm(x)
		y = np.cross(z, x)
		m = np.eye(4)
		m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, li["position"]
		nodes.append({"name": f"light{len(light_defs) - 1}", "matrix": [float(v) for v in m.T.reshape(-1)],
			      "extensions": {"KHR_lights_punctual": {"light": len(light_defs) - 1}}})
	base = os.path.splitext(os.path.basename(out_path))[0]
	g = {"asset": {"version": "2.0", "generator": "Ajar tests/peers/scene.py (Lambertian variant)"},
	     "extensionsUsed": used + (["KHR_materials_ior"] if pbr or panes else []) +
			       (["KHR_materials_transmission"] if panes else []) + (["KHR_lights_punctual"] if light_defs else []),
	     "scene": 0, "scenes": [{"nodes": list(range(len(nodes))), "extras": scene_extras}],
	     "nodes": nodes, "meshes": meshes, "materials": mats, "cameras": [cam],
	     "accessors": accessors, "bufferViews": views,
	     "buffers": [{"uri": base + ".bin", "byteLength": len(blob)}]}
	if light_defs:
		g["extensions"] = {"KHR_lights_punctual": {"lights": light_defs}}
	with open(os.path.join(os.path.dirname(out_path), base + ".bin"), "wb") as f:
		f.write(blob)
	with open(out_path, "w") as f:
		json.dump(g, f)
	return notes


def image_size(scene, spec):
	"""'WxH', or 'W' (height from the camera's aspectRatio, square if none)."""
	if "x" in spec:
		w, h = spec.split("x")
		return int(w), int(h)
	w = int(spec)
	a = scene.camera["aspect"] or 1.0
	return w, max(1, int(round(w / a)))


if __name__ == "__main__":
	import sys
	s = Scene(sys.argv[1])
	print(len(s.meshes), "meshes", sum(len(f) for _, _, f in s.meshes), "triangles;", len(s.portals), "portals")
	print("camera", s.camera, "environment", s.environment, "sky", s.sky, "lights", s.lights)
	for r in s.portal_rects():
		print("portal", r)
