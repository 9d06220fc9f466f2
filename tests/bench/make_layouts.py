#!/usr/bin/env python3
"""make_layouts.py -- rooms of layouts no shipped scene has, for the portal search.

  make_layouts.py [--sky-color R,G,B] OUTDIR

Writes OUTDIR/l-room.gltf, terrace.gltf, terrace-one-face.gltf, bay.gltf and
skylight.gltf (each with its .bin and a copy of scenes/skies/forest.exr), under the
forest sky (or a sky of one colour: tests/data/layouts, test_portal_find), each
opening marked by hand with a
portal node (extras.portal) as a user would place it: on the room's face of the
wall, the size of the opening. `make bench-portals` takes them as arguments
(tests/bench/bench_portals.c) to compare the portals Ajar finds with the marked ones
on layouts the search was not tuned on:

  l-room   an L-shaped room (4 x 3 m, and a 2 x 4 m leg); the camera in one leg
           looks into the other, whose end wall and side wall have open windows
           (0.25 m reveals); none in the camera's leg.
  terrace  a 5 x 4 m room whose glazed door (1.6 x 2.2 m, a thin pane of clear
           glass: KHR_materials_transmission without a volume) opens to a
           garden (a ground plane and a hedge outside), and a small open window
           high in the side wall; terrace-one-face the same with walls of one
           face (the room's, and the openings' reveals), as quick models have.
  bay      a row of three windows (mullions of 10 cm) under a balcony slab,
           a ground outside, and a window in the side wall.
  skylight a room under a 30 cm roof slab with a 1 x 1 m skylight the camera
           does not see, and a small window.

Python 3 standard library only; the same bytes on every run.
"""
import json
import os
import shutil
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scenes", "door-ajar"))
from make_door_ajar import Mesh, f32, lambert, look_at_quat  # noqa: E402

H = 2.6       # floor to ceiling
REVEAL = 0.25  # depth of an opening through the wall


def wall(axis, c, lo, hi, normal_sign, holes, faces=2):
	"""The room's face of a wall in the plane axis = c (axis 'x' or 'z'), spanning
	[lo, hi] along the other horizontal axis and [0, H] up, its normal toward
	normal_sign along axis, and its outer face REVEAL behind (a solid wall);
	holes: (s0, s1, y0, y1) cut out, each lined by a reveal. Returns (mesh,
	portal meshes)."""
	def pt(s, y, off=0.0):
		d = c - normal_sign * off
		return (d, y, s) if axis == "x" else (s, y, d)

	def quad(s0, s1, y0, y1, off=0.0):
		a, b, cc, d = pt(s0, y0, off), pt(s1, y0, off), pt(s1, y1, off), pt(s0, y1, off)
		# Counter-clockwise seen from the room: the normal points along
		# normal_sign; the outer face (off = REVEAL) the other way.
		flip = ((normal_sign > 0) == (axis == "z")) == (off == 0.0)
		return (a, b, cc, d) if flip else (a, d, cc, b)

	m = Mesh()
	cuts = sorted(holes)
	for off in (0.0, REVEAL)[:faces]:  # the room's face and the outer one: a solid wall
		s = lo
		for s0, s1, y0, y1 in cuts:  # columns beside and between the holes
			if s0 > s:
				m.quad(*quad(s, s0, 0.0, H, off))
			if y0 > 0.0:
				m.quad(*quad(s0, s1, 0.0, y0, off))
			if y1 < H:
				m.quad(*quad(s0, s1, y1, H, off))
			s = s1
		if s < hi:
			m.quad(*quad(s, hi, 0.0, H, off))
	portals = []
	for s0, s1, y0, y1 in cuts:
		# Reveal: four faces from the room's face outward, facing the hole.
		for e0, e1 in (((s0, y0), (s0, y1)), ((s0, y1), (s1, y1)), ((s1, y1), (s1, y0)), ((s1, y0), (s0, y0))):
			a, b = pt(*e0), pt(*e1)
			a2, b2 = pt(*e0, REVEAL), pt(*e1, REVEAL)
			quad_r = Mesh().quad(a, b, b2, a2)
			hc = pt((s0 + s1) / 2, (y0 + y1) / 2, REVEAL / 2)  # the hole's axis
			em = tuple((p + q) / 2 for p, q in zip(a, b2))
			if sum(n * (h - e) for n, h, e in zip(quad_r.nrm[0], hc, em)) < 0.0:
				quad_r = Mesh().quad(a, a2, b2, b)
			m.pos += quad_r.pos
			m.nrm += quad_r.nrm
			base = len(m.pos) - 4
			m.idx += [base, base + 1, base + 2, base, base + 2, base + 3]
		portals.append(Mesh().quad(*quad(s0, s1, y0, y1)))
	return m, portals


def floor_ceiling(x0, x1, z0, z1):
	f = Mesh().quad((x0, 0.0, z0), (x0, 0.0, z1), (x1, 0.0, z1), (x1, 0.0, z0))
	c = Mesh().quad((x0, H, z0), (x1, H, z0), (x1, H, z1), (x0, H, z1))
	return f, c


MATERIALS = [
	lambert("wall", (0.75, 0.74, 0.7)),
	lambert("floor", (0.55, 0.45, 0.35)),
	lambert("ceiling", (0.8, 0.8, 0.8)),
	lambert("furniture", (0.45, 0.5, 0.62)),
	lambert("ground", (0.25, 0.3, 0.2)),
	{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0,
						   "roughnessFactor": 0.0},
	 "doubleSided": True, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}},
]
MAT = {m["name"]: i for i, m in enumerate(MATERIALS)}


def l_room():
	objs = []
	fa, ca = floor_ceiling(0.0, 4.0, 0.0, 3.0)
	fb, cb = floor_ceiling(0.0, 2.0, 3.0, 7.0)
	objs += [("floor_a", fa, "floor"), ("floor_b", fb, "floor"), ("ceiling_a", ca, "ceiling"), ("ceiling_b", cb, "ceiling")]
	portals = []
	for name, args in (("wall_back", ("z", 0.0, 0.0, 4.0, 1, [])), ("wall_east", ("x", 4.0, 0.0, 3.0, -1, [])),
			   ("wall_corner", ("z", 3.0, 2.0, 4.0, -1, [])), ("wall_leg", ("x", 2.0, 3.0, 7.0, -1, [])),
			   ("wall_end", ("z", 7.0, 0.0, 2.0, -1, [(0.4, 1.6, 0.9, 2.3)])),
			   ("wall_west", ("x", 0.0, 0.0, 7.0, 1, [(4.4, 5.6, 0.9, 2.3)]))):
		m, ps = wall(*args)
		objs.append((name, m, "wall"))
		portals += ps
	objs.append(("table", Mesh().box(0.5, 0.0, 4.2, 1.3, 0.75, 5.2, bottom=False), "furniture"))
	objs.append(("cabinet", Mesh().box(3.2, 0.0, 1.0, 3.9, 1.1, 2.2, bottom=False), "furniture"))
	return objs, portals, (3.6, 1.4, 0.4), (0.8, 1.0, 5.5)


def terrace(faces=2):
	objs = []
	f, c = floor_ceiling(0.0, 5.0, 0.0, 4.0)
	objs += [("floor", f, "floor"), ("ceiling", c, "ceiling")]
	portals = []
	door = (1.7, 3.3, 0.0, 2.2)
	for name, args in (("wall_back", ("z", 0.0, 0.0, 5.0, 1, [])), ("wall_east", ("x", 5.0, 0.0, 4.0, -1, [])),
			   ("wall_garden", ("z", 4.0, 0.0, 5.0, -1, [door])),
			   ("wall_west", ("x", 0.0, 0.0, 4.0, 1, [(1.2, 2.0, 1.8, 2.4)]))):
		m, ps = wall(*args, faces=faces)
		objs.append((name, m, "wall"))
		portals += ps
	zp = 4.0 + 0.5 * REVEAL  # the pane in the middle of the wall's depth
	objs.append(("pane", Mesh().quad((door[0], 0.0, zp), (door[0], door[3], zp), (door[1], door[3], zp), (door[1], 0.0, zp)), "glass"))
	objs.append(("ground", Mesh().quad((-20.0, -0.01, 4.0 + REVEAL), (-20.0, -0.01, 30.0), (25.0, -0.01, 30.0), (25.0, -0.01, 4.0 + REVEAL)), "ground"))
	objs.append(("hedge", Mesh().box(-3.0, 0.0, 9.0, 8.0, 1.6, 10.0), "ground"))
	objs.append(("sofa", Mesh().box(0.8, 0.0, 0.6, 3.2, 0.8, 1.5, bottom=False), "furniture"))
	return objs, portals, (4.5, 1.5, 0.5), (2.0, 1.0, 4.0)


def bay():
	objs = []
	f, c = floor_ceiling(0.0, 6.0, 0.0, 4.0)
	objs += [("floor", f, "floor"), ("ceiling", c, "ceiling")]
	portals = []
	row = [(0.9 + 1.0 * k, 1.8 + 1.0 * k, 0.8, 2.2) for k in range(3)]  # mullions of 10 cm
	for name, args in (("wall_back", ("z", 0.0, 0.0, 6.0, 1, [])), ("wall_west", ("x", 0.0, 0.0, 4.0, 1, [])),
			   ("wall_bay", ("z", 4.0, 0.0, 6.0, -1, row)),
			   ("wall_east", ("x", 6.0, 0.0, 4.0, -1, [(1.0, 2.2, 0.9, 2.1)]))):
		m, ps = wall(*args)
		objs.append((name, m, "wall"))
		portals += ps
	objs.append(("balcony", Mesh().box(-1.0, 2.7, 4.0 + REVEAL, 7.0, 2.9, 5.6), "wall"))
	objs.append(("ground", Mesh().quad((-20.0, -0.01, 4.0 + REVEAL), (-20.0, -0.01, 30.0), (25.0, -0.01, 30.0), (25.0, -0.01, 4.0 + REVEAL)), "ground"))
	objs.append(("desk", Mesh().box(1.0, 0.0, 3.0, 3.5, 0.75, 3.7, bottom=False), "furniture"))
	return objs, portals, (5.4, 1.5, 0.4), (2.2, 1.2, 4.0)


def skylight():
	"""A 4 x 4 m room under a roof slab 0.3 m thick with a 1 x 1 m skylight, and a
	small window; the camera does not see the sky through the skylight."""
	objs = []
	f, _ = floor_ceiling(0.0, 4.0, 0.0, 4.0)
	objs.append(("floor", f, "floor"))
	x0, x1, z0, z1, t = 1.6, 2.6, 1.4, 2.4, 0.3
	ceiling, roof = Mesh(), Mesh()
	for a0, a1, b0, b1 in ((0.0, 4.0, 0.0, z0), (0.0, 4.0, z1, 4.0), (0.0, x0, z0, z1), (x1, 4.0, z0, z1)):
		ceiling.quad((a0, H, b0), (a1, H, b0), (a1, H, b1), (a0, H, b1))
		roof.quad((a0, H + t, b0), (a0, H + t, b1), (a1, H + t, b1), (a1, H + t, b0))
	shaft = Mesh()
	shaft.quad((x0, H, z0), (x0, H + t, z0), (x1, H + t, z0), (x1, H, z0))
	shaft.quad((x0, H, z1), (x1, H, z1), (x1, H + t, z1), (x0, H + t, z1))
	shaft.quad((x0, H, z0), (x0, H, z1), (x0, H + t, z1), (x0, H + t, z0))
	shaft.quad((x1, H, z0), (x1, H + t, z0), (x1, H + t, z1), (x1, H, z1))
	objs += [("ceiling", ceiling, "ceiling"), ("roof", roof, "wall"), ("shaft", shaft, "wall")]
	portals = [Mesh().quad((x0, H, z0), (x1, H, z0), (x1, H, z1), (x0, H, z1))]
	for name, args in (("wall_back", ("z", 0.0, 0.0, 4.0, 1, [(2.6, 3.4, 1.2, 2.0)])), ("wall_front", ("z", 4.0, 0.0, 4.0, -1, [])),
			   ("wall_west", ("x", 0.0, 0.0, 4.0, 1, [])), ("wall_east", ("x", 4.0, 0.0, 4.0, -1, []))):
		m, ps = wall(*args)
		objs.append((name, m, "wall"))
		portals += ps
	objs.append(("table", Mesh().box(1.4, 0.0, 1.6, 2.6, 0.75, 2.4, bottom=False), "furniture"))
	return objs, portals, (3.6, 1.4, 3.6), (1.5, 0.8, 1.0)


def write(path, objs, portals, eye, target, env):
	blob = bytearray()
	views, accessors, meshes, nodes = [], [], [], []

	def view(data, tgt):
		while len(blob) % 4:
			blob.append(0)
		views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": tgt})
		blob.extend(data)
		return len(views) - 1

	def vec3(values, bounds):
		acc = {"bufferView": view(b"".join(struct.pack("<3f", *v) for v in values), 34962), "componentType": 5126,
		       "count": len(values), "type": "VEC3"}
		if bounds:
			acc["min"] = [min(f32(v[k]) for v in values) for k in range(3)]
			acc["max"] = [max(f32(v[k]) for v in values) for k in range(3)]
		accessors.append(acc)
		return len(accessors) - 1

	def add(name, mesh, mat, extras=None):
		accessors.append({"bufferView": view(struct.pack("<%dI" % len(mesh.idx), *mesh.idx), 34963),
				  "componentType": 5125, "count": len(mesh.idx), "type": "SCALAR"})
		idx = len(accessors) - 1
		prim = {"attributes": {"POSITION": vec3(mesh.pos, True), "NORMAL": vec3(mesh.nrm, False)},
			"indices": idx, "mode": 4}
		if mat is not None:
			prim["material"] = MAT[mat]
		meshes.append({"name": name, "primitives": [prim]})
		node = {"name": name, "mesh": len(meshes) - 1}
		if extras:
			node["extras"] = extras
		nodes.append(node)

	for name, mesh, mat in objs:
		add(name, mesh, mat)
	for i, p in enumerate(portals):
		add("portal_%d" % i, p, None, {"portal": True})
	nodes.append({"name": "camera", "camera": 0, "translation": list(eye), "rotation": look_at_quat(eye, target)})
	base = os.path.splitext(os.path.basename(path))[0]
	gltf = {
		"asset": {"version": "2.0", "generator": "Ajar tests/bench/make_layouts.py"},
		"extensionsUsed": ["KHR_materials_specular", "KHR_materials_transmission"],
		"scene": 0,
		"scenes": [{"name": "Scene", "nodes": list(range(len(nodes))),
			    "extras": {"environment": env}}],
		"nodes": nodes, "meshes": meshes, "materials": MATERIALS,
		"cameras": [{"name": "camera", "type": "perspective",
			     "perspective": {"yfov": 1.0, "aspectRatio": 1.0, "znear": 0.01}}],
		"accessors": accessors, "bufferViews": views,
		"buffers": [{"uri": base + ".bin", "byteLength": len(blob)}],
	}
	with open(os.path.join(os.path.dirname(path), base + ".bin"), "wb") as f:
		f.write(blob)
	with open(path, "w", encoding="utf-8", newline="\n") as f:
		json.dump(gltf, f, indent=1)
		f.write("\n")


def main():
	args = sys.argv[1:]
	color = None
	if len(args) == 3 and args[0] == "--sky-color":
		color = [float(c) for c in args[1].split(",")]
		args = args[2:]
	if len(args) != 1 or (color is not None and len(color) != 3):
		sys.exit(__doc__)
	out = args[0]
	os.makedirs(out, exist_ok=True)
	if color is None:
		shutil.copyfile(os.path.join(HERE, "..", "..", "scenes", "skies", "forest.exr"), os.path.join(out, "forest.exr"))
		env = {"image": "forest.exr", "strength": 1.0, "rotation": 40.0}
	else:
		env = {"color": color}
	for name, make in (("l-room", l_room), ("terrace", terrace), ("terrace-one-face", lambda: terrace(1)),
			   ("bay", bay), ("skylight", skylight)):
		objs, portals, eye, target = make()
		write(os.path.join(out, name + ".gltf"), objs, portals, eye, target, env)


if __name__ == "__main__":
	main()
