"""profiles.py — a material's directional albedo, Ajar against Cycles: a
unit sphere of it under a white sky, seen from 40 units away (so the view
cosine mu of a pixel is that of its surface point), rendered by both (pt and
Cycles through Blender's importer, 128 x 128, 64 spp, depth 8); printed, the
mean pixel in bands of mu. With a black specular-free base the bands are
the layer's own albedo E(mu) (kernels/material/README.md, "Layers and
anisotropy").

    build/peers/venv/bin/python tests/peers/profiles.py sheen-0.4 sheen-1 coat coat-metal

Materials: sheen-<r> (black base, white sheen of roughness r), coat (black
base, clear coat of roughness 0.1), metal and coat-metal (metal 0.6 0.4 0.25
at roughness 0.6, without and with that coat), coat-white-metal.
"""
import base64
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import driver  # noqa: E402

W = 128
BANDS = [(0.9, 1.0), (0.7, 0.8), (0.5, 0.6), (0.3, 0.4), (0.15, 0.25)]


def material(name):
	black = {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1}
	metal = {"baseColorFactor": [0.6, 0.4, 0.25, 1], "metallicFactor": 1, "roughnessFactor": 0.6}
	coat = {"KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.1}}
	if name.startswith("sheen-"):
		return {"pbrMetallicRoughness": black, "extensions": {"KHR_materials_specular": {"specularFactor": 0},
			"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": float(name[6:])}}}
	if name == "coat":
		return {"pbrMetallicRoughness": black, "extensions": dict(coat, KHR_materials_specular={"specularFactor": 0})}
	if name == "metal":
		return {"pbrMetallicRoughness": metal}
	if name == "coat-metal":
		return {"pbrMetallicRoughness": metal, "extensions": coat}
	if name == "coat-white-metal":
		return {"pbrMetallicRoughness": dict(metal, baseColorFactor=[1, 1, 1, 1]), "extensions": coat}
	raise SystemExit(f"profiles: unknown material {name}")


def write_sphere(name, path):
	nt, npp = 64, 128
	pos, idx = [], []
	for i in range(nt + 1):
		for j in range(npp):
			th, ph = math.pi * i / nt, 2 * math.pi * j / npp
			pos.append((math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)))
	for i in range(nt):
		for j in range(npp):
			a, b = i * npp + j, i * npp + (j + 1) % npp
			idx += [a, b, a + npp, b, b + npp, a + npp]
	blob = b"".join(struct.pack("<3f", *p) for p in pos) * 2  # positions, and the same as normals
	off = len(blob)
	blob += b"".join(struct.pack("<I", k) for k in idx)
	n, dist = len(pos) * 12, 40.0
	yfov = 2 * math.atan(1.05 / dist)
	g = {"asset": {"version": "2.0"},
	     "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_specular", "KHR_materials_clearcoat"],
	     "scenes": [{"nodes": [0, 1], "extras": {"environment": {"color": [1, 1, 1]}}}],
	     "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, dist]}],
	     "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": 1, "znear": 1, "zfar": 100}}],
	     "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
	     "materials": [material(name)],
	     "buffers": [{"byteLength": len(blob),
			  "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
	     "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": n}, {"buffer": 0, "byteOffset": n, "byteLength": n},
			     {"buffer": 0, "byteOffset": off, "byteLength": 4 * len(idx)}],
	     "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
			    "min": [-1, -1, -1], "max": [1, 1, 1]},
			   {"bufferView": 1, "componentType": 5126, "count": len(pos), "type": "VEC3"},
			   {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"}]}
	json.dump(g, open(path, "w"))
	return yfov


def bands(img):
	c, R = (W - 1) / 2.0, W / 2.0 / 1.05
	yy, xx = np.mgrid[0:W, 0:W]
	rr = np.sqrt((xx - c) ** 2 + (yy - c) ** 2) / R
	mu = np.sqrt(np.clip(1 - rr ** 2, 0, 1))
	v = img[..., :3].mean(axis=2)
	return [float(v[(rr < 0.98) & (mu >= lo) & (mu < hi)].mean()) for lo, hi in BANDS]


def main():
	out = os.path.join(driver.OUT, "profiles")
	os.makedirs(out, exist_ok=True)
	driver.ensure_ajar()
	print("material: renderer, mean pixel at mu " + " ".join(f"{(a + b) / 2:.2f}" for a, b in BANDS))
	for name in sys.argv[1:]:
		path = os.path.join(out, name + ".gltf")
		yfov = write_sphere(name, path)
		a, _ = driver.run_ajar("pt", path, (W, W), 8, os.path.join(out, name + "-ajar.exr"), spp=64, seed=1)
		npy = os.path.join(out, name + "-cycles.npy")
		subprocess.run([sys.executable, os.path.join(HERE, "assets.py"), "--cycles", path, npy, str(W), str(W), "64", "1",
				"8", str(driver.env_threads()), str(yfov)], capture_output=True, check=True)
		c = np.load(npy)
		print(f"{name}: ajar   " + " ".join(f"{x:.3f}" for x in bands(a)))
		print(f"{name}: cycles " + " ".join(f"{x:.3f}" for x in bands(c)), flush=True)


if __name__ == "__main__":
	main()
