#!/usr/bin/env python3
"""Writes the door-ajar scene (door-ajar.gltf + door-ajar.bin) for Ajar.

Two closed diffuse rooms side by side share one 0.1 m thick wall with a
0.9 x 2.1 m door opening. The door leaf is hinged at one jamb and opened a few
degrees into the light room, so only a narrow wedge-shaped gap at its free edge
lets the light of a small ceiling emitter into the camera's room. A portal quad
covers the door opening. Python 3 standard library only; the output is
byte-for-byte the same on every run.

    python3 make_door_ajar.py                      # writes next to this script
    python3 make_door_ajar.py --angle 0 --out /tmp/door-closed   # leak test

Coordinates: metres, +Y up. Camera room z in [0, 4], shared wall z in
[4, 4.1], light room z in [4.1, 8.1]; both rooms x in [0, 4], y in [0, 2.6].
"""

import argparse
import json
import math
import os
import struct

ROOM_W = 4.0        # x extent of both rooms
ROOM_H = 2.6        # floor to ceiling
CAM_D = 4.0         # camera room depth (z)
WALL_T = 0.1        # shared wall thickness
LIGHT_D = 4.0       # light room depth (z)
Z_WALL0 = CAM_D                 # camera-room face of the shared wall
Z_WALL1 = CAM_D + WALL_T        # light-room face of the shared wall
Z_END = Z_WALL1 + LIGHT_D       # far wall of the light room

DOOR_X0 = 1.3       # hinge jamb
DOOR_W = 0.9
DOOR_H = 2.1
DOOR_X1 = DOOR_X0 + DOOR_W      # free-edge jamb
LEAF_T = 0.04
# The closed leaf sits in the middle of the wall, z in [4.03, 4.07]; it turns
# about the vertical edge at (DOOR_X0, LEAF_Z1), its light-room side, so it
# swings into the light room and never cuts the jamb it hangs on.
LEAF_Z0 = Z_WALL0 + 0.5 * (WALL_T - LEAF_T)
LEAF_Z1 = LEAF_Z0 + LEAF_T
DEFAULT_ANGLE_DEG = 8.0

LIGHT_SIZE = 0.5
LIGHT_Y = ROOM_H - 0.01         # just below the ceiling, not coplanar with it
LIGHT_CENTER = (3.0, 5.0)       # (x, z): beside the free edge of the door
LIGHT_RADIANCE = 50.0

CAMERA_POS = (3.3, 1.5, 0.9)
CAMERA_TARGET = (1.6, 0.7, 3.6)
CAMERA_YFOV = 0.9

F32 = struct.Struct("<f")


def f32(x):
	"""The float32 value of x, so accessor min/max match the stored data."""
	return F32.unpack(F32.pack(x))[0]


def sub(a, b):
	return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
	return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
		a[0] * b[1] - a[1] * b[0])


def normalize(a):
	n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
	return (a[0] / n, a[1] / n, a[2] / n)


class Mesh:
	"""Flat-shaded triangles built from quads and triangles, each with its own vertices."""

	def __init__(self):
		self.pos = []
		self.nrm = []
		self.idx = []

	def quad(self, a, b, c, d):
		"""Quad a-b-c-d, counter-clockwise seen from the side its normal faces."""
		n = normalize(cross(sub(b, a), sub(d, a)))
		base = len(self.pos)
		self.pos += [a, b, c, d]
		self.nrm += [n] * 4
		self.idx += [base, base + 1, base + 2, base, base + 2, base + 3]
		return self

	def tri(self, a, b, c):
		"""Triangle a-b-c, counter-clockwise seen from the side its normal faces."""
		n = normalize(cross(sub(b, a), sub(c, a)))
		base = len(self.pos)
		self.pos += [a, b, c]
		self.nrm += [n] * 3
		self.idx += [base, base + 1, base + 2]
		return self

	def box(self, x0, y0, z0, x1, y1, z1, bottom=True):
		"""Axis-aligned box with outward normals; no bottom face when it rests on a floor."""
		self.quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))   # +y
		if bottom:
			self.quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))   # -y
		self.quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))   # +x
		self.quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))   # -x
		self.quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))   # +z
		self.quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0))   # -z
		return self


def rect_y(x0, x1, z0, z1, y, up):
	"""Horizontal rectangle at height y, normal +y when up, else -y."""
	m = Mesh()
	if up:
		return m.quad((x0, y, z0), (x0, y, z1), (x1, y, z1), (x1, y, z0))
	return m.quad((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1))


def rect_x(z0, z1, y0, y1, x, plus):
	"""Rectangle in the plane x = const, normal +x when plus, else -x."""
	m = Mesh()
	if plus:
		return m.quad((x, y0, z0), (x, y1, z0), (x, y1, z1), (x, y0, z1))
	return m.quad((x, y0, z0), (x, y0, z1), (x, y1, z1), (x, y1, z0))


def rect_z(x0, x1, y0, y1, z, plus):
	"""Rectangle in the plane z = const, normal +z when plus, else -z."""
	m = Mesh()
	if plus:
		return m.quad((x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z))
	return m.quad((x0, y0, z), (x0, y1, z), (x1, y1, z), (x1, y0, z))


def wall_with_door(z, plus):
	"""One face of the shared wall, with the door opening cut out (three quads)."""
	m = Mesh()
	for x0, x1, y0, y1 in ((0.0, DOOR_X0, 0.0, ROOM_H),
			(DOOR_X1, ROOM_W, 0.0, ROOM_H),
			(DOOR_X0, DOOR_X1, DOOR_H, ROOM_H)):
		r = rect_z(x0, x1, y0, y1, z, plus)
		base = len(m.pos)
		m.pos += r.pos
		m.nrm += r.nrm
		m.idx += [base + i for i in r.idx]
	return m


def quat_y(deg):
	"""Rotation about +y by deg degrees as a glTF quaternion [x, y, z, w]."""
	h = math.radians(deg) * 0.5
	return [0.0, math.sin(h), 0.0, math.cos(h)]


def look_at_quat(eye, target):
	"""Quaternion turning the glTF camera (looking down -z, +y up) toward target."""
	f = normalize(sub(target, eye))
	r = normalize(cross(f, (0.0, 1.0, 0.0)))
	u = cross(r, f)
	# Columns of the rotation matrix: local x = r, local y = u, local z = -f.
	m = ((r[0], u[0], -f[0]), (r[1], u[1], -f[1]), (r[2], u[2], -f[2]))
	tr = m[0][0] + m[1][1] + m[2][2]
	if tr > 0.0:
		s = math.sqrt(tr + 1.0) * 2.0
		q = [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s,
			(m[1][0] - m[0][1]) / s, 0.25 * s]
	elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
		s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2.0
		q = [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s,
			(m[2][1] - m[1][2]) / s]
	elif m[1][1] > m[2][2]:
		s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2.0
		q = [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s,
			(m[0][2] - m[2][0]) / s]
	else:
		s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2.0
		q = [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s,
			(m[1][0] - m[0][1]) / s]
	return [round(c, 9) for c in q]


def lambert(name, rgb):
	"""Pure Lambertian material: no glTF dielectric specular layer."""
	return {
		"name": name,
		"pbrMetallicRoughness": {
			"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0],
			"metallicFactor": 0.0,
			"roughnessFactor": 1.0,
		},
		"doubleSided": True,
		"extensions": {"KHR_materials_specular": {"specularFactor": 0.0}},
	}


MATERIALS = [
	lambert("wall_cam_room", (0.75, 0.75, 0.72)),
	lambert("wall_light_room", (0.7, 0.72, 0.75)),
	lambert("floor_cam_room", (0.6, 0.55, 0.5)),
	lambert("floor_light_room", (0.55, 0.55, 0.55)),
	lambert("ceiling", (0.8, 0.8, 0.8)),
	lambert("door_frame", (0.7, 0.65, 0.55)),
	lambert("door_leaf", (0.65, 0.55, 0.5)),
	lambert("box_blue", (0.5, 0.55, 0.7)),
	lambert("box_red", (0.7, 0.5, 0.5)),
	lambert("box_green", (0.5, 0.7, 0.55)),
	{
		# One-sided (emits downward only), black so it reflects nothing.
		"name": "light",
		"pbrMetallicRoughness": {
			"baseColorFactor": [0.0, 0.0, 0.0, 1.0],
			"metallicFactor": 0.0,
			"roughnessFactor": 1.0,
		},
		"doubleSided": False,
		"emissiveFactor": [1.0, 1.0, 1.0],
		"extensions": {
			"KHR_materials_emissive_strength": {"emissiveStrength": LIGHT_RADIANCE},
			"KHR_materials_specular": {"specularFactor": 0.0},
		},
	},
]
MAT = {m["name"]: i for i, m in enumerate(MATERIALS)}


def scene_objects(angle_deg):
	"""(node name, mesh, material name or None for the portal, node TRS dict)."""
	objs = []

	def add(name, mesh, mat, **trs):
		objs.append((name, mesh, mat, trs))

	# Camera room: z in [0, Z_WALL0]; every normal points into the room.
	add("floor_cam_room", rect_y(0.0, ROOM_W, 0.0, Z_WALL0, 0.0, True), "floor_cam_room")
	add("ceiling_cam_room", rect_y(0.0, ROOM_W, 0.0, Z_WALL0, ROOM_H, False), "ceiling")
	add("wall_cam_room_x0", rect_x(0.0, Z_WALL0, 0.0, ROOM_H, 0.0, True), "wall_cam_room")
	add("wall_cam_room_x4", rect_x(0.0, Z_WALL0, 0.0, ROOM_H, ROOM_W, False), "wall_cam_room")
	add("wall_cam_room_back", rect_z(0.0, ROOM_W, 0.0, ROOM_H, 0.0, True), "wall_cam_room")
	add("shared_wall_cam_side", wall_with_door(Z_WALL0, False), "wall_cam_room")

	# Light room: z in [Z_WALL1, Z_END].
	add("floor_light_room", rect_y(0.0, ROOM_W, Z_WALL1, Z_END, 0.0, True), "floor_light_room")
	add("ceiling_light_room", rect_y(0.0, ROOM_W, Z_WALL1, Z_END, ROOM_H, False), "ceiling")
	add("wall_light_room_x0", rect_x(Z_WALL1, Z_END, 0.0, ROOM_H, 0.0, True), "wall_light_room")
	add("wall_light_room_x4", rect_x(Z_WALL1, Z_END, 0.0, ROOM_H, ROOM_W, False), "wall_light_room")
	add("wall_light_room_far", rect_z(0.0, ROOM_W, 0.0, ROOM_H, Z_END, False), "wall_light_room")
	add("shared_wall_light_side", wall_with_door(Z_WALL1, True), "wall_light_room")

	# Door frame: closes the sides of the opening through the wall's thickness,
	# meeting both wall faces edge to edge.
	add("door_jamb_hinge", rect_x(Z_WALL0, Z_WALL1, 0.0, DOOR_H, DOOR_X0, True), "door_frame")
	add("door_jamb_free", rect_x(Z_WALL0, Z_WALL1, 0.0, DOOR_H, DOOR_X1, False), "door_frame")
	add("door_lintel", rect_y(DOOR_X0, DOOR_X1, Z_WALL0, Z_WALL1, DOOR_H, False), "door_frame")
	add("door_threshold", rect_y(DOOR_X0, DOOR_X1, Z_WALL0, Z_WALL1, 0.0, True), "door_frame")

	# Door leaf: modelled with its hinge edge on the node's origin, turned
	# about +y. A negative turn about +y takes local +x toward +z (into the
	# light room).
	leaf = Mesh().box(0.0, 0.0, -LEAF_T, DOOR_W, DOOR_H, 0.0)
	add("door_leaf", leaf, "door_leaf",
		translation=[DOOR_X0, 0.0, LEAF_Z1], rotation=quat_y(-angle_deg))

	# Emitter on the light room's ceiling, facing down.
	lx, lz = LIGHT_CENTER
	h = 0.5 * LIGHT_SIZE
	add("light", rect_y(lx - h, lx + h, lz - h, lz + h, LIGHT_Y, False), "light")

	# Light room furniture (not visible from the camera).
	add("box_light_room_tall", Mesh().box(-0.3, 0.0, -0.3, 0.3, 1.2, 0.3, bottom=False), "box_blue",
		translation=[0.8, 0.0, 6.8], rotation=quat_y(20.0))
	add("box_light_room_low", Mesh().box(-0.4, 0.0, -0.25, 0.4, 0.5, 0.25, bottom=False), "box_green",
		translation=[3.1, 0.0, 7.2], rotation=quat_y(-15.0))
	add("box_light_room_small", Mesh().box(-0.2, 0.0, -0.2, 0.2, 0.4, 0.2, bottom=False), "box_red",
		translation=[1.9, 0.0, 6.0], rotation=quat_y(40.0))

	# Camera room furniture, both in view: the table stands in the path of
	# the light from the gap and casts a shadow on the lit floor wedge.
	add("box_cam_room_stool", Mesh().box(-0.3, 0.0, -0.25, 0.3, 0.5, 0.25, bottom=False), "box_red",
		translation=[0.85, 0.0, 2.6], rotation=quat_y(10.0))
	add("box_cam_room_crate", Mesh().box(-0.25, 0.0, -0.25, 0.25, 0.4, 0.25, bottom=False), "box_blue",
		translation=[2.9, 0.0, 2.9], rotation=quat_y(-25.0))

	# Portal: the gap itself. Light reaches the camera room only through the
	# wedge between the open leaf and the wall's light-room face, which is
	# open to the light room on two sides: the slit from the free jamb's
	# corner (DOOR_X1, Z_WALL1) to the leaf's free edge, full height, and a
	# thin triangle over the leaf's top (the lintel only spans the wall's
	# thickness). Both are portal triangles; nothing else lets light through.
	if angle_deg > 0.0:
		t = math.radians(angle_deg)
		# The leaf's camera-side face: x(u), z(u) for u along the leaf.
		fx0, fz0 = DOOR_X0 + LEAF_T * math.sin(t), LEAF_Z1 - LEAF_T * math.cos(t)
		ex, ez = fx0 + DOOR_W * math.cos(t), fz0 + DOOR_W * math.sin(t)
		assert ez > Z_WALL1, "the free edge must clear the wall for the gap portal"
		u = (Z_WALL1 - fz0) / math.sin(t)  # where that face crosses the wall's light-room plane
		cx = fx0 + u * math.cos(t)
		gap = Mesh()
		gap.quad((DOOR_X1, 0.0, Z_WALL1), (ex, 0.0, ez), (ex, DOOR_H, ez), (DOOR_X1, DOOR_H, Z_WALL1))
		gap.tri((cx, DOOR_H, Z_WALL1), (ex, DOOR_H, ez), (DOOR_X1, DOOR_H, Z_WALL1))
		add("portal_door_gap", gap, None, extras={"portal": True})
	return objs


def build(angle_deg, bin_name):
	blob = bytearray()
	views, accessors, meshes, nodes = [], [], [], []

	def view(data, target):
		while len(blob) % 4:
			blob.append(0)
		views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
			"target": target})
		blob.extend(data)
		return len(views) - 1

	def vec3(values, with_bounds):
		data = b"".join(struct.pack("<3f", *v) for v in values)
		acc = {"bufferView": view(data, 34962), "componentType": 5126,
			"count": len(values), "type": "VEC3"}
		if with_bounds:
			acc["min"] = [min(f32(v[k]) for v in values) for k in range(3)]
			acc["max"] = [max(f32(v[k]) for v in values) for k in range(3)]
		accessors.append(acc)
		return len(accessors) - 1

	def indices(values):
		data = struct.pack("<%dI" % len(values), *values)
		accessors.append({"bufferView": view(data, 34963), "componentType": 5125,
			"count": len(values), "type": "SCALAR"})
		return len(accessors) - 1

	for name, mesh, mat, trs in scene_objects(angle_deg):
		prim = {"attributes": {"POSITION": vec3(mesh.pos, True),
			"NORMAL": vec3(mesh.nrm, False)},
			"indices": indices(mesh.idx), "mode": 4}
		if mat is not None:
			prim["material"] = MAT[mat]
		meshes.append({"name": name, "primitives": [prim]})
		node = {"name": name, "mesh": len(meshes) - 1}
		node.update(trs)
		nodes.append(node)

	nodes.append({"name": "camera", "camera": 0, "translation": list(CAMERA_POS),
		"rotation": look_at_quat(CAMERA_POS, CAMERA_TARGET)})

	gltf = {
		"asset": {"version": "2.0", "generator": "Ajar make_door_ajar.py"},
		"extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_specular"],
		"scene": 0,
		# No "environment" in the scene extras: the emitter is the only light.
		"scenes": [{"name": "Scene", "nodes": list(range(len(nodes)))}],
		"nodes": nodes,
		"meshes": meshes,
		"materials": MATERIALS,
		"cameras": [{"name": "camera", "type": "perspective",
			"perspective": {"yfov": CAMERA_YFOV, "aspectRatio": 1.0, "znear": 0.01}}],
		"accessors": accessors,
		"bufferViews": views,
		"buffers": [{"uri": bin_name, "byteLength": len(blob)}],
	}
	return gltf, bytes(blob)


def main():
	ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
	ap.add_argument("--angle", type=float, default=DEFAULT_ANGLE_DEG,
		help="door opening angle in degrees (0: closed, for the leak test; default %(default)s)")
	ap.add_argument("--out", default=os.path.dirname(os.path.abspath(__file__)),
		help="output folder (default: next to this script)")
	ap.add_argument("--name", default="door-ajar",
		help="file name without extension, of the .gltf and its .bin (default %(default)s)")
	args = ap.parse_args()

	os.makedirs(args.out, exist_ok=True)
	gltf, blob = build(args.angle, args.name + ".bin")
	with open(os.path.join(args.out, args.name + ".bin"), "wb") as f:
		f.write(blob)
	with open(os.path.join(args.out, args.name + ".gltf"), "w", encoding="utf-8", newline="\n") as f:
		json.dump(gltf, f, indent=1)
		f.write("\n")


if __name__ == "__main__":
	main()
