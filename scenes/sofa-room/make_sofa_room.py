"""make_sofa_room.py — writes sofa-room.gltf and sofa-room.bin (python3, no
dependencies): a room lit by a white sky through a 2 x 1.4 m window, with a
velvet sofa (KHR_materials_sheen) on a varnished floor
(KHR_materials_clearcoat), the materials of issue 44 that Cycles can be
compared with through Blender's importer. +Y up, metres. With --table, a
brushed-steel table too (KHR_materials_anisotropy along its TANGENT):
sofa-room-table.gltf (Blender's importer leaves an anisotropic material
without a texture on Cycles' default radial tangent, so that one is not
compared).

    python3 scenes/sofa-room/make_sofa_room.py
"""
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


class Builder:
	def __init__(self):
		self.blob = bytearray()
		self.views, self.accessors, self.meshes, self.nodes = [], [], [], []

	def _view(self, data):
		while len(self.blob) % 4:
			self.blob.append(0)
		self.views.append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)})
		self.blob += data
		return len(self.views) - 1

	def _acc(self, values, n, kind, minmax=False):
		flat = [c for v in values for c in v] if n > 1 else list(values)
		if kind == "idx":
			a = {"bufferView": self._view(struct.pack("<%dI" % len(flat), *flat)), "componentType": 5125,
			     "count": len(flat), "type": "SCALAR"}
		else:
			a = {"bufferView": self._view(struct.pack("<%df" % len(flat), *flat)), "componentType": 5126,
			     "count": len(values), "type": {2: "VEC2", 3: "VEC3", 4: "VEC4"}[n]}
			if minmax:
				a["min"] = [min(v[k] for v in values) for k in range(n)]
				a["max"] = [max(v[k] for v in values) for k in range(n)]
		self.accessors.append(a)
		return len(self.accessors) - 1

	def mesh(self, name, quads, material, tangent=None, portal=False):
		"""quads: lists of four corners, counter-clockwise seen from the front."""
		pos, nrm, tan, idx = [], [], [], []
		for q in quads:
			e1 = [q[1][k] - q[0][k] for k in range(3)]
			e2 = [q[3][k] - q[0][k] for k in range(3)]
			n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
			ln = math.sqrt(sum(c * c for c in n))
			n = [c / ln for c in n]
			b = len(pos)
			for p in q:
				pos.append(p)
				nrm.append(n)
				if tangent:  # the tangent in the face's plane, w = 1
					t = [tangent[k] - n[k] * sum(tangent[j] * n[j] for j in range(3)) for k in range(3)]
					lt = math.sqrt(sum(c * c for c in t))
					tan.append([c / lt for c in t] + [1.0] if lt > 1e-6 else [n[1], n[2], n[0], 1.0])
			idx += [b, b + 1, b + 2, b, b + 2, b + 3]
		attr = {"POSITION": self._acc(pos, 3, "f", True), "NORMAL": self._acc(nrm, 3, "f")}
		if tangent:
			attr["TANGENT"] = self._acc(tan, 4, "f")
		prim = {"attributes": attr, "indices": self._acc(idx, 1, "idx"), "mode": 4}
		if material is not None:
			prim["material"] = material
		self.meshes.append({"name": name, "primitives": [prim]})
		node = {"name": name, "mesh": len(self.meshes) - 1}
		if portal:
			node["extras"] = {"portal": True}
		self.nodes.append(node)


def box(x0, x1, y0, y1, z0, z1, bottom=False):
	"""The faces of an axis-aligned box, outward (no bottom unless asked)."""
	f = [[(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # top
	     [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # +z
	     [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)],  # -z
	     [(x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)],  # +x
	     [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)]]  # -x
	if bottom:
		f.append([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)])
	return f


def look_at(eye, target):
	"""The unit quaternion turning -Z to eye -> target with +Y up."""
	f = [target[k] - eye[k] for k in range(3)]
	lf = math.sqrt(sum(c * c for c in f))
	f = [c / lf for c in f]
	r = [-f[2], 0.0, f[0]]  # f x up
	lr = math.sqrt(sum(c * c for c in r))
	r = [c / lr for c in r]
	u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
	m = [[r[0], u[0], -f[0]], [r[1], u[1], -f[1]], [r[2], u[2], -f[2]]]  # columns: x, y, z axes
	tr = m[0][0] + m[1][1] + m[2][2]
	w = math.sqrt(max(0.0, 1.0 + tr)) / 2
	x = math.copysign(math.sqrt(max(0.0, 1 + m[0][0] - m[1][1] - m[2][2])) / 2, m[2][1] - m[1][2])
	y = math.copysign(math.sqrt(max(0.0, 1 - m[0][0] + m[1][1] - m[2][2])) / 2, m[0][2] - m[2][0])
	z = math.copysign(math.sqrt(max(0.0, 1 - m[0][0] - m[1][1] + m[2][2])) / 2, m[1][0] - m[0][1])
	return [x, y, z, w]


def main(table):
	W, H, D = 5.0, 2.7, 4.0
	wx0, wx1, wy0, wy1 = 1.5, 3.5, 0.8, 2.2  # the window in the wall z = 0
	b = Builder()
	name = "sofa-room-table" if table else "sofa-room"
	lambert = {"KHR_materials_specular": {"specularFactor": 0.0}}
	materials = [
		{"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.75, 0.75, 1], "metallicFactor": 0,
							  "roughnessFactor": 1}, "doubleSided": True, "extensions": lambert},
		{"name": "varnished floor", "pbrMetallicRoughness": {"baseColorFactor": [0.36, 0.22, 0.12, 1],
								     "metallicFactor": 0, "roughnessFactor": 0.55},
		 "doubleSided": True,
		 "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.05}}},
		{"name": "velvet", "pbrMetallicRoughness": {"baseColorFactor": [0.10, 0.16, 0.40, 1], "metallicFactor": 0,
							    "roughnessFactor": 0.9}, "doubleSided": True,
		 "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.85, 0.85, 0.95],
							"sheenRoughnessFactor": 0.4}}},
		{"name": "brushed steel", "pbrMetallicRoughness": {"baseColorFactor": [0.78, 0.78, 0.80, 1],
								   "metallicFactor": 1, "roughnessFactor": 0.3},
		 "doubleSided": True,
		 "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.7, "anisotropyRotation": 0.0}}},
	]
	b.mesh("floor", [[(0, 0, D), (W, 0, D), (W, 0, 0), (0, 0, 0)]], 1)
	b.mesh("ceiling", [[(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)]], 0)
	b.mesh("walls", [[(0, 0, D), (0, H, D), (W, H, D), (W, 0, D)],  # back, facing -z
			 [(0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D)],  # x = 0
			 [(W, 0, D), (W, H, D), (W, H, 0), (W, 0, 0)],  # x = W
			 [(0, 0, 0), (W, 0, 0), (W, wy0, 0), (0, wy0, 0)],  # the window wall, z = 0, facing +z
			 [(0, wy1, 0), (W, wy1, 0), (W, H, 0), (0, H, 0)],
			 [(0, wy0, 0), (wx0, wy0, 0), (wx0, wy1, 0), (0, wy1, 0)],
			 [(wx1, wy0, 0), (W, wy0, 0), (W, wy1, 0), (wx1, wy1, 0)]], 0)
	sofa = (box(1.8, 4.0, 0.05, 0.45, 3.05, 3.95, True) + box(1.8, 4.0, 0.45, 0.95, 3.7, 3.95) +
		box(1.8, 2.05, 0.45, 0.7, 3.05, 3.7) + box(3.75, 4.0, 0.45, 0.7, 3.05, 3.7))
	b.mesh("sofa", sofa, 2)
	if table:
		b.mesh("table", box(2.3, 3.5, 0.0, 0.35, 1.9, 2.5), 3, tangent=(1.0, 0.0, 0.0))
	b.mesh("window_portal", [[(wx0, wy0, 0), (wx1, wy0, 0), (wx1, wy1, 0), (wx0, wy1, 0)]], None, portal=True)
	eye, target = (0.7, 1.55, 0.5), (3.0, 0.55, 3.4)
	b.nodes.append({"name": "camera", "camera": 0, "translation": list(eye), "rotation": look_at(eye, target)})
	g = {"asset": {"version": "2.0", "generator": "scenes/sofa-room/make_sofa_room.py"},
	     "extensionsUsed": ["KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen"] +
			       (["KHR_materials_anisotropy"] if table else []),
	     "scene": 0,
	     "scenes": [{"nodes": list(range(len(b.nodes))), "extras": {"environment": {"color": [1.0, 1.0, 1.0]}}}],
	     "nodes": b.nodes, "meshes": b.meshes, "materials": materials if table else materials[:3],
	     "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 16 / 9, "znear": 0.05,
								   "zfar": 100}, "extras": {"resolution": [192, 108]}}],
	     "buffers": [{"uri": name + ".bin", "byteLength": len(b.blob)}], "bufferViews": b.views,
	     "accessors": b.accessors}
	with open(os.path.join(HERE, name + ".bin"), "wb") as f:
		f.write(bytes(b.blob))
	with open(os.path.join(HERE, name + ".gltf"), "w") as f:
		json.dump(g, f, indent=1)
		f.write("\n")


if __name__ == "__main__":
	main(False)
	main(True)
