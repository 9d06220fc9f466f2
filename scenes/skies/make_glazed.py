#!/usr/bin/env python3
"""Writes the glazed variants of the sky-lit rooms: the same room with a pane of
glass in each window, as a glTF exporter writes a window pane.

Each pane is a quad 2 cm inside the room from a portal of the room (portal normals
point into the room), the portal's size, with KHR_materials_transmission 1,
KHR_materials_ior 1.5, roughness 0 and no KHR_materials_volume: thin-walled glass,
as glTF defines transmission without a volume. The variant is written beside the
room (`<room>-glazed.gltf`), reading the room's own .bin and sky; the panes'
vertices are a data: URI. Python 3 standard library only; the output is
byte-for-byte the same on every run.

    python3 make_glazed.py          # writes ../window-room-forest/window-room-forest-glazed.gltf, ...
"""

import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.dirname(HERE)
ROOMS = ["window-room", "window-room-forest", "living-room-forest"]
INSET = 0.02  # metres from the portal into the room


def accessor_floats(gltf, folder, index):
	"""The float VEC3 values of accessor `index` (tightly packed, as the rooms store them)."""
	acc = gltf["accessors"][index]
	view = gltf["bufferViews"][acc["bufferView"]]
	buf = gltf["buffers"][view["buffer"]]
	with open(os.path.join(folder, buf["uri"]), "rb") as f:
		data = f.read()
	off = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
	return [struct.unpack_from("<3f", data, off + 12 * i) for i in range(acc["count"])]


def portal_triangles(gltf, folder):
	"""World-space triangles of the nodes marked as portals (the rooms' portal
	nodes carry no transform) and their unit normals."""
	tris = []
	for node in gltf["nodes"]:
		if not node.get("extras", {}).get("portal"):
			continue
		assert not any(k in node for k in ("matrix", "translation", "rotation", "scale")), "portal with a transform"
		for prim in gltf["meshes"][node["mesh"]]["primitives"]:
			pos = accessor_floats(gltf, folder, prim["attributes"]["POSITION"])
			if "indices" in prim:
				acc = gltf["accessors"][prim["indices"]]
				view = gltf["bufferViews"][acc["bufferView"]]
				with open(os.path.join(folder, gltf["buffers"][view["buffer"]]["uri"]), "rb") as f:
					data = f.read()
				fmt = {5121: "B", 5123: "H", 5125: "I"}[acc["componentType"]]
				size = struct.calcsize(fmt)
				off = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
				idx = [struct.unpack_from("<" + fmt, data, off + size * i)[0] for i in range(acc["count"])]
			else:
				idx = list(range(len(pos)))
			for k in range(0, len(idx), 3):
				tris.append([pos[idx[k]], pos[idx[k + 1]], pos[idx[k + 2]]])
	return tris


def sub(a, b):
	return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
	return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def glaze(room):
	folder = os.path.join(SCENES, room)
	src = os.path.join(folder, room + ".gltf")
	with open(src) as f:
		gltf = json.load(f)
	tris = portal_triangles(gltf, folder)
	assert tris, room + ": no portals"
	verts = []
	for t in tris:
		n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
		ln = sum(c * c for c in n) ** 0.5
		n = tuple(c / ln for c in n)
		for p in t:
			verts.append(tuple(p[c] + INSET * n[c] for c in range(3)))
	data = b"".join(struct.pack("<3f", *v) for v in verts)
	lo = [min(v[c] for v in verts) for c in range(3)]
	hi = [max(v[c] for v in verts) for c in range(3)]
	gltf["buffers"].append({
		"uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode(),
		"byteLength": len(data),
	})
	gltf["bufferViews"].append({"buffer": len(gltf["buffers"]) - 1, "byteOffset": 0, "byteLength": len(data),
				    "target": 34962})
	gltf["accessors"].append({"bufferView": len(gltf["bufferViews"]) - 1, "componentType": 5126,
				  "count": len(verts), "type": "VEC3", "min": lo, "max": hi})
	gltf["materials"].append({
		"name": "window_glass",
		"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
					 "roughnessFactor": 0.0},
		"doubleSided": True,
		"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
			       "KHR_materials_ior": {"ior": 1.5}},
	})
	gltf["meshes"].append({"name": "window_panes", "primitives": [
		{"attributes": {"POSITION": len(gltf["accessors"]) - 1}, "material": len(gltf["materials"]) - 1,
		 "mode": 4}]})
	gltf["nodes"].append({"name": "window_panes", "mesh": len(gltf["meshes"]) - 1})
	gltf["scenes"][gltf.get("scene", 0)]["nodes"].append(len(gltf["nodes"]) - 1)
	used = gltf.setdefault("extensionsUsed", [])
	for ext in ("KHR_materials_ior", "KHR_materials_transmission"):
		if ext not in used:
			used.append(ext)
	gltf.setdefault("asset", {})["extras"] = dict(gltf["asset"].get("extras", {}),
						      glazed="scenes/skies/make_glazed.py: one thin pane 2 cm inside each window")
	out = os.path.join(folder, room + "-glazed.gltf")
	with open(out, "w") as f:
		json.dump(gltf, f, indent=1)
		f.write("\n")
	print(out, len(verts) // 3, "pane triangles")


if __name__ == "__main__":
	for r in ROOMS:
		glaze(r)
