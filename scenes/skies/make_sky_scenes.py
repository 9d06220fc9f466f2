#!/usr/bin/env python3
"""Writes the sky-lit variants of the window room and the living room.

Each variant is the shipped room under one of the CC0 skies of this folder,
in a folder of its own with copies of the room's .bin and textures and of the
sky (Ajar reads no file outside a scene's folder unless told to), the sky turned
about +Y so that the sun's rays pass through a window onto a chosen surface,
or, for window-room-sun, a KHR_lights_punctual directional light as the sun
under a constant sky, for window-room-lamp a point lamp in the room under
the room's own sky, and for door-ajar-lamp a point lamp for door-ajar's
emitter, behind the door. Python 3 standard library only; the output is
byte-for-byte the same on every run.

    python3 make_sky_scenes.py          # writes ../<variant>/ (glTF and copies)

The sun of each sky is its brightest pixel (SOURCE.md; tests/unit/test_exr.c checks
it). Ajar's convention (README, kernels/light/env.h): pixel (x, y) of a W x H
equirectangular image has u = (x + 0.5) / W, v = (y + 0.5) / H and looks along
    d = (sin v pi sin phi, cos v pi, -sin v pi cos phi),  phi = 2 pi (u - 0.5)
(phi is the azimuth from -Z toward +X), and `rotation` a (degrees, about +Y,
right-handed: counter-clockwise seen from above) moves a feature at azimuth
phi to phi - a. So the sun lands at azimuth phi_world when a = phi_img - phi_world.
"""

import json
import math
import os
import shutil

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.dirname(HERE)

# The skies: size and the sun's (brightest) pixel.
SKIES = {
	"forest": {"size": (1024, 512), "sun": (613, 199)},
	"sunset": {"size": (1024, 512), "sun": (614, 246)},
}

# Forest's sun and sky for the lamp variant, from the image (pixels of
# luminance above 50 are the sun): the sun's irradiance on a plane facing it,
# sum of L x texel solid angle, and the average radiance of the rest.
FOREST_SUN_IRRADIANCE = (1.082, 0.912, 0.709)   # W/m^2 (Ajar's radiance units x sr)
FOREST_SKY_RADIANCE = (0.671, 0.703, 0.757)
LUMENS_PER_WATT = 683.0   # KHR_lights_punctual lux -> W/m^2, as Blender's importer ("Standard")


def sun_direction(sky):
	"""(elevation, azimuth phi_img) in degrees of the sky's sun pixel centre."""
	w, h = SKIES[sky]["size"]
	x, y = SKIES[sky]["sun"]
	u, v = (x + 0.5) / w, (y + 0.5) / h
	return 90.0 - 180.0 * v, 360.0 * (u - 0.5)


def rotation_for(sky, phi_world):
	"""The rotation (degrees) that puts the sky's sun at azimuth phi_world."""
	_, phi_img = sun_direction(sky)
	a = phi_img - phi_world
	return round((a + 180.0) % 360.0 - 180.0, 4)


def sun_vector(elev_deg, phi_deg):
	"""Unit direction toward the sun (from the scene to the sky)."""
	e, p = math.radians(elev_deg), math.radians(phi_deg)
	return (math.cos(e) * math.sin(p), math.sin(e), -math.cos(e) * math.cos(p))


def quat_minus_z_to(t):
	"""Unit quaternion (x, y, z, w) turning -Z onto the unit vector t."""
	# Half-way vector between -Z and t; rotation axis (-Z) x t.
	a = (0.0, 0.0, -1.0)
	c = (a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0])
	w = 1.0 + (a[0] * t[0] + a[1] * t[1] + a[2] * t[2])
	n = math.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2 + w * w)
	return [round(c[0] / n, 9), round(c[1] / n, 9), round(c[2] / n, 9), round(w / n, 9)]


# The variants: the room, and either a sky with the sun's azimuth in the scene
# or a lamp. Where the light lands is worked out in each note.
VARIANTS = {
	# Low sun (3.3 degrees): through the 0.8 m window (z = 0, y 1.0-1.8) it
	# crosses the 3 m room and drops 0.17 m, a patch on the far wall
	# (z = 3, y about 0.8-1.6) facing the camera, right of centre
	# (azimuth -9.5 degrees: 0.5 m toward +X over 3 m).
	"window-room-sunset": {"room": "window-room", "sky": "sunset", "phi": -9.5},
	# The forest's sun (19.9 degrees): from the window it reaches the floor
	# 2.8-5.0 m out, so at the foot of the far wall; turned 20 degrees
	# toward +X it grazes the top of the blue box.
	"window-room-forest": {"room": "window-room", "sky": "forest", "phi": -20.0},
	# The forest's sun through the two windows of the x = -0.44 wall (light
	# travelling +X, a little toward +Z): from sills at 0.72 m and heads at
	# 2.44 m it lands on the floor 2.0-6.8 m in, patches on the floor in
	# front of the camera.
	"living-room-forest": {"room": "living-room", "sky": "forest", "phi": -105.0},
	# A directional lamp as the sun, higher than either sky's (32 degrees),
	# onto the floor in view, on the -X side of the box (azimuth 15 degrees: light
	# travelling +Z and toward -X); the forest sun's irradiance, and the
	# forest's average sky without its sun as a constant sky.
	"window-room-sun": {"room": "window-room", "lamp": (32.0, 15.0)},
	# A point lamp under the ceiling in the far left corner (x 0.8, y 2.2,
	# z 2.2: 0.5 m below the ceiling, 0.8 m from the walls), 1000 cd of warm
	# white (1.46 W/sr, a Blender lamp of 18.4 W), with the room's own sky
	# through the window: a lamp inside the room beside the light through
	# an opening.
	"window-room-lamp": {"room": "window-room",
			     "point": {"position": [0.8, 2.2, 2.2], "intensity": 1000.0, "color": [1.0, 0.75, 0.5]}},
	# door-ajar with a point lamp for its ceiling emitter (turned off), 0.14 m
	# below where the emitter was (x 3, z 5, the far room): 2134 cd of white
	# (3.125 W/sr, the emitter's 39.3 W spread over the sphere), so the
	# camera's room is lit only through the gap of the door, by a lamp.
	"door-ajar-lamp": {"room": "door-ajar", "emitter_off": "light",
			   "point": {"position": [3.0, 2.45, 5.0], "intensity": 2134.0, "color": [1.0, 1.0, 1.0]}},
}


def copy(src, dst):
	"""Copies src to dst unless dst already holds the same bytes."""
	os.makedirs(os.path.dirname(dst), exist_ok=True)
	if os.path.exists(dst):
		with open(src, "rb") as a, open(dst, "rb") as b:
			if a.read() == b.read():
				return
	shutil.copyfile(src, dst)


def make(name, spec):
	room = spec["room"]
	out = os.path.join(SCENES, name)
	with open(os.path.join(SCENES, room, room + ".gltf")) as f:
		g = json.load(f)
	for item in g.get("buffers", []) + g.get("images", []):
		if "uri" in item and not item["uri"].startswith("data:"):
			copy(os.path.join(SCENES, room, item["uri"]), os.path.join(out, item["uri"]))
	g["asset"]["generator"] = "scenes/skies/make_sky_scenes.py (from scenes/%s)" % room
	extras = g["scenes"][0].setdefault("extras", {})
	if "sky" in spec:
		copy(os.path.join(HERE, spec["sky"] + ".exr"), os.path.join(out, spec["sky"] + ".exr"))
		extras["environment"] = {"image": "%s.exr" % spec["sky"], "strength": 1.0,
					 "rotation": rotation_for(spec["sky"], spec["phi"])}
	elif "point" in spec:
		for m in g["materials"]:
			if m.get("name") == spec.get("emitter_off"):
				m["emissiveFactor"] = [0.0, 0.0, 0.0]
				m.get("extensions", {}).pop("KHR_materials_emissive_strength", None)
		if not any("KHR_materials_emissive_strength" in m.get("extensions", {}) for m in g["materials"]):
			g["extensionsUsed"] = [e for e in g.get("extensionsUsed", []) if e != "KHR_materials_emissive_strength"]
		lamp = spec["point"]
		g.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
		g.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": [{
			"name": "lamp", "type": "point", "color": lamp["color"], "intensity": lamp["intensity"]}]}
		g["nodes"].append({"name": "lamp", "translation": lamp["position"],
				   "extensions": {"KHR_lights_punctual": {"light": 0}}})
		g["scenes"][0]["nodes"].append(len(g["nodes"]) - 1)
	else:
		elev, phi = spec["lamp"]
		to_sun = sun_vector(elev, phi)
		travel = tuple(-c for c in to_sun)
		peak = max(FOREST_SUN_IRRADIANCE)
		g.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
		g.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": [{
			"name": "sun", "type": "directional",
			"color": [round(c / peak, 4) for c in FOREST_SUN_IRRADIANCE],
			"intensity": round(peak * LUMENS_PER_WATT, 2)}]}
		g["nodes"].append({"name": "sun", "rotation": quat_minus_z_to(travel),
				   "extensions": {"KHR_lights_punctual": {"light": 0}}})
		g["scenes"][0]["nodes"].append(len(g["nodes"]) - 1)
		extras["environment"] = {"color": list(FOREST_SKY_RADIANCE)}
	os.makedirs(out, exist_ok=True)
	with open(os.path.join(out, name + ".gltf"), "w") as f:
		json.dump(g, f, indent=1, sort_keys=False)
		f.write("\n")
	return extras.get("environment")


def main():
	for sky in sorted(SKIES):
		e, p = sun_direction(sky)
		print("%s: sun at elevation %.2f, azimuth %.2f degrees (unturned)" % (sky, e, p))
	for name, spec in VARIANTS.items():
		print(name, json.dumps(make(name, spec)))


if __name__ == "__main__":
	main()
