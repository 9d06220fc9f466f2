"""pane.py — each renderer's smooth thin pane against glTF's thin-walled model,
analytically (`sh tests/peers/run.sh pane`, seconds).

A camera with a narrow view (yfov 0.02) looks at a pane of KHR_materials_transmission
1 (ior 1.5, a tinted base colour, no volume: thin-walled) at PANE_ANGLE degrees (70)
from its normal, with no sky; a one-sided emitter of radiance 1 and black base
faces the pane either behind it, on the line of sight (the image is then the
transmittance (1 - F) base), or where the mirror image of the line of sight meets
it (the image is F, white). Each case is rendered with the pane's front face and
with its back face towards the camera (the winding reversed): glTF's pane is the
same from both sides. F is the exact unpolarised dielectric Fresnel reflectance.
Renderers: PANE_RENDERERS ("ajar-pt ajar-bdpt ajar-portal mitsuba cycles"),
PANE_SPP (4096), 8 x 8 pixels, depth 8. Prints measured / expected - 1 per channel
with the standard error of the image mean; exits non-zero where one differs by
more than 4 standard errors + 0.3%.
"""
import base64
import json
import math
import os
import struct
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import driver  # noqa: E402

TINT = (0.9, 0.6, 0.3)
IOR = 1.5


def fresnel(cos_i, eta):
	"""Exact unpolarised reflectance from the rarer side (as Ajar's microfacet.h)."""
	sin2_t = (1 - cos_i * cos_i) / (eta * eta)
	cos_t = math.sqrt(1 - sin2_t)
	r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
	r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
	return 0.5 * (r_par * r_par + r_perp * r_perp)


def quad(c, n, half):
	"""Two triangles of a square centred at c, CCW seen from the side n points to."""
	n = np.asarray(n, float) / np.linalg.norm(n)
	a = np.array([0.0, 1.0, 0.0]) if abs(n[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
	u = np.cross(a, n)
	u /= np.linalg.norm(u)
	v = np.cross(n, u)
	p = [c - half * u - half * v, c + half * u - half * v, c + half * u + half * v, c - half * u + half * v]
	return [p[0], p[1], p[2], p[0], p[2], p[3]]


def write_scene(path, theta, reflect, back):
	d = np.array([math.sin(theta), 0.0, math.cos(theta)])  # towards the camera
	pane = quad(np.zeros(3), [0, 0, -1.0 if back else 1.0], 1.0)
	if reflect:
		r = np.array([-d[0], 0.0, d[2]])
		emitter = quad(r, -r, 0.5)
	else:
		emitter = quad(-d, d, 0.5)
	blob = b"".join(struct.pack("<3f", *p) for p in pane + emitter)
	acc = []
	for k, tri in enumerate((pane, emitter)):
		pts = np.array(tri)
		acc.append({"bufferView": 0, "byteOffset": 72 * k, "componentType": 5126, "count": 6, "type": "VEC3",
			    "min": pts.min(axis=0).tolist(), "max": pts.max(axis=0).tolist()})
	z = d
	y = np.array([0.0, 1.0, 0.0])
	x = np.cross(y, z)
	cam = np.eye(4)
	cam[:3, 0], cam[:3, 1], cam[:3, 2], cam[:3, 3] = x, y, z, 3.0 * d
	g = {"asset": {"version": "2.0", "generator": "tests/peers/pane.py"},
	     "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_specular"],
	     "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
	     "nodes": [{"camera": 0, "matrix": cam.T.reshape(-1).tolist()}, {"mesh": 0}, {"mesh": 1}],
	     "cameras": [{"type": "perspective", "perspective": {"yfov": 0.02, "aspectRatio": 1.0, "znear": 0.01}}],
	     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]},
			{"primitives": [{"attributes": {"POSITION": 1}, "material": 1}]}],
	     "materials": [
		     {"name": "pane", "doubleSided": True,
		      "pbrMetallicRoughness": {"baseColorFactor": list(TINT) + [1.0], "metallicFactor": 0.0,
					       "roughnessFactor": 0.0},
		      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
				     "KHR_materials_ior": {"ior": IOR}}},
		     {"name": "emitter", "emissiveFactor": [1.0, 1.0, 1.0],
		      "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
		      "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}],
	     "accessors": acc, "bufferViews": [{"buffer": 0, "byteLength": len(blob)}],
	     "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode(),
			  "byteLength": len(blob)}]}
	with open(path, "w") as f:
		json.dump(g, f)


def main():
	theta = math.radians(float(os.environ.get("PANE_ANGLE", "70")))
	spp = int(os.environ.get("PANE_SPP", "4096"))
	renderers = os.environ.get("PANE_RENDERERS", "ajar-pt ajar-bdpt ajar-portal mitsuba cycles").split()
	out = os.path.join(driver.OUT, "pane")
	os.makedirs(out, exist_ok=True)
	if any(r.startswith("ajar-") for r in renderers):
		driver.ensure_ajar()
	f = fresnel(math.cos(theta), IOR)
	driver.log(f"pane at {math.degrees(theta):g} degrees, ior {IOR}: F = {f:.5f}, 1 - F = {1 - f:.5f}, "
		   f"tint {TINT}, {spp} spp")
	bad = 0
	for reflect in (False, True):
		expect = np.array([f, f, f]) if reflect else (1 - f) * np.array(TINT)
		for back in (False, True):
			case = f"{'reflection' if reflect else 'transmission'}, {'back' if back else 'front'} face"
			path = os.path.join(out, f"pane-{'r' if reflect else 't'}{'b' if back else 'f'}.gltf")
			write_scene(path, theta, reflect, back)
			for r in renderers:
				img, info = driver.render(r, path, (8, 8), 8, os.path.join(out, os.path.basename(path)[:-5] + "-" + r),
							  spp=spp, seed=3)
				if img is None:
					driver.log(f"  {case:28s} {r:12s} failed")
					bad += 1
					continue
				m = img.reshape(-1, 3).mean(axis=0)
				# Pixels are independent: the standard error of the mean from their spread.
				se = img.reshape(-1, 3).std(axis=0, ddof=1) / math.sqrt(64)
				dev = m / expect - 1
				ok = bool(np.all(np.abs(m - expect) <= 4 * se + 0.003 * expect))
				bad += not ok
				driver.log(f"  {case:28s} {r:12s} " + "  ".join(
					f"{m[c]:.5f} ({100 * dev[c]:+.2f}% +- {100 * se[c] / expect[c]:.2f}%)" for c in range(3)) +
					("" if ok else "  DIFFERS"))
	return 1 if bad else 0


if __name__ == "__main__":
	sys.exit(main())
