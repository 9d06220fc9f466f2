#!/usr/bin/env python3
"""Writes scenes/atrium-forest: a room lit from above, through an opening in
its roof, under the forest sky with its sun shining in.

The room is 4 x 3 x 4 m (x, y up, z), grey Lambertian walls and a brown floor;
its roof is a slab 5 cm thick with a 1.4 x 1.4 m opening in the middle, closed
on every side (no light leaks through the slab), and a portal over the
opening, facing up. The sky is turned (rotation, degrees about +Y) so that the
sun, 19.9 deg high, shines in toward +x +z and lays its patch high on the far
walls, where the camera looks. Every other shipped sky scene has its
openings in walls; this one has the horizontal portal of an atrium or a
skylight. Python 3 standard library only; the output is byte-for-byte the same
on every run.

    python3 make_atrium.py          # writes ../atrium-forest/
"""

import json
import math
import os
import shutil
import struct

from make_sky_scenes import rotation_for

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(os.path.dirname(HERE), "atrium-forest")

W, H, D = 4.0, 3.0, 4.0  # the room
T = 0.05                 # the roof's thickness
X0, X1 = 1.3, 2.7        # the opening, in x and in z
SUN_AZIMUTH = -40.0      # where the sun stands (degrees from -Z toward +X): its rays go toward +x +z


def quads():
	"""(name, four corners, outward normal of the lit side, material)."""
	q = [("floor", [(0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0)], (0, 1, 0), 1),
	     ("wall_x0", [(0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D)], (1, 0, 0), 0),
	     ("wall_x4", [(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)], (-1, 0, 0), 0),
	     ("wall_z0", [(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)], (0, 0, 1), 0),
	     ("wall_z4", [(0, 0, D), (0, H, D), (W, H, D), (W, 0, D)], (0, 0, -1), 0)]
	# The slab around the opening: its underside (the ceiling) and top, in four strips.
	strips = [(0, W, 0, X0), (0, W, X1, D), (0, X0, X0, X1), (X1, W, X0, X1)]
	for i, (a, b, c, d) in enumerate(strips):
		q.append((f"ceiling_{i}", [(a, H, c), (b, H, c), (b, H, d), (a, H, d)], (0, -1, 0), 0))
		q.append((f"roof_{i}", [(a, H + T, c), (a, H + T, d), (b, H + T, d), (b, H + T, c)], (0, 1, 0), 0))
	# Its edges: the opening's four sides and the outer rim.
	for name, lo, hi, sign in (("opening", X0, X1, -1), ("rim", 0.0, W, 1)):
		q.append((f"{name}_x0", [(lo, H, lo), (lo, H, hi), (lo, H + T, hi), (lo, H + T, lo)], (-sign, 0, 0), 0))
		q.append((f"{name}_x1", [(hi, H, lo), (hi, H + T, lo), (hi, H + T, hi), (hi, H, hi)], (sign, 0, 0), 0))
		q.append((f"{name}_z0", [(lo, H, lo), (lo, H + T, lo), (hi, H + T, lo), (hi, H, lo)], (0, 0, -sign), 0))
		q.append((f"{name}_z1", [(lo, H, hi), (hi, H, hi), (hi, H + T, hi), (lo, H + T, hi)], (0, 0, sign), 0))
	q.append(("roof_portal", [(X0, H + T, X0), (X0, H + T, X1), (X1, H + T, X1), (X1, H + T, X0)], (0, 1, 0), -1))
	return q


def cross(a, b):
	return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def main():
	buf, accessors, views, meshes, nodes = bytearray(), [], [], [], []

	def add(data, component, count, kind, target, bounds=None):
		views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "target": target})
		buf.extend(data)
		acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": kind}
		if bounds:
			acc["min"], acc["max"] = bounds
		accessors.append(acc)
		return len(accessors) - 1

	for name, corners, n, material in quads():
		lo = [min(c[i] for c in corners) for i in range(3)]
		hi = [max(c[i] for c in corners) for i in range(3)]
		pos = add(b"".join(struct.pack("<3f", *c) for c in corners), 5126, 4, "VEC3", 34962, (lo, hi))
		nrm = add(struct.pack("<3f", *n) * 4, 5126, 4, "VEC3", 34962)
		e1 = [corners[1][i] - corners[0][i] for i in range(3)]
		e2 = [corners[2][i] - corners[0][i] for i in range(3)]
		front = sum(x * y for x, y in zip(cross(e1, e2), n)) > 0  # counter-clockwise seen from the lit side
		idx = add(struct.pack("<6I", *((0, 1, 2, 0, 2, 3) if front else (0, 2, 1, 0, 3, 2))), 5125, 6, "SCALAR",
			  34963)
		prim = {"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx, "mode": 4}
		if material >= 0:
			prim["material"] = material
		meshes.append({"name": name, "primitives": [prim]})
		node = {"name": name, "mesh": len(meshes) - 1}
		if material < 0:
			node["extras"] = {"portal": True}
		nodes.append(node)
	# The camera in the corner at x = z = 0.4, 1.2 m up, looking at the far corner:
	# -Z turned by yaw -135 deg about +Y after a pitch of 4 deg down about +X.
	yaw, pitch = math.radians(-135.0) / 2, math.radians(-4.0) / 2
	rot = [math.cos(yaw) * math.sin(pitch), math.sin(yaw) * math.cos(pitch), -math.sin(yaw) * math.sin(pitch),
	       math.cos(yaw) * math.cos(pitch)]
	nodes.append({"name": "camera", "camera": 0, "translation": [0.4, 1.2, 0.4],
		      "rotation": [round(c, 6) for c in rot]})
	gltf = {
		"asset": {"version": "2.0", "generator": "scenes/skies/make_atrium.py"},
		"scene": 0,
		"scenes": [{"name": "Scene", "nodes": list(range(len(nodes))),
			    "extras": {"environment": {"image": "forest.exr", "strength": 1.0,
						       "rotation": rotation_for("forest", SUN_AZIMUTH)}}}],
		"nodes": nodes,
		"meshes": meshes,
		"materials": [
			{"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0],
								  "metallicFactor": 0.0, "roughnessFactor": 1.0}},
			{"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.4, 0.3, 1.0],
								   "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
		"cameras": [{"type": "perspective",
			     "perspective": {"yfov": 1.2, "aspectRatio": 1.0, "znear": 0.01, "zfar": 100.0}}],
		"accessors": accessors,
		"bufferViews": views,
		"buffers": [{"byteLength": len(buf), "uri": "atrium.bin"}],
	}
	os.makedirs(OUT, exist_ok=True)
	with open(os.path.join(OUT, "atrium.bin"), "wb") as f:
		f.write(buf)
	with open(os.path.join(OUT, "atrium-forest.gltf"), "w") as f:
		json.dump(gltf, f, indent=1)
		f.write("\n")
	shutil.copyfile(os.path.join(HERE, "forest.exr"), os.path.join(OUT, "forest.exr"))


if __name__ == "__main__":
	main()
