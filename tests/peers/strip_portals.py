"""strip_portals.py — a shipped scene as a user's exporter would hand it to
Ajar: its portal nodes (extras.portal) taken out of the graph. Python 3,
standard library only.

  python3 tests/peers/strip_portals.py SCENE.gltf OUT.gltf [--show PORTALS.gltf]

OUT.gltf refers to the original buffers and images by relative paths (no
copy of the .bin files), so it lies outside their folder: render it with
--allow-outside-files. --show adds the quads of a `--portals-out` file as
visible geometry (translucent red, no longer portals), to look at where the
search put them (`ajar render OUT.gltf ... --png`)."""
import copy
import json
import os
import sys


def truthy(v):
	return v is True or (isinstance(v, (int, float)) and not isinstance(v, bool) and v != 0)


def strip(doc):
	"""Detaches every portal node from the scenes and parents (the node
	entries stay, so no index changes)."""
	portal = {i for i, n in enumerate(doc.get("nodes", [])) if truthy((n.get("extras") or {}).get("portal"))}
	for n in doc.get("nodes", []):
		if "children" in n:
			n["children"] = [c for c in n["children"] if c not in portal]
	for s in doc.get("scenes", []):
		s["nodes"] = [c for c in s.get("nodes", []) if c not in portal]
	return len(portal)


def relocate(doc, src_dir, out_dir):
	for key in ("buffers", "images"):
		for item in doc.get(key, []):
			uri = item.get("uri")
			if uri and not uri.startswith("data:"):
				item["uri"] = os.path.relpath(os.path.join(src_dir, uri), out_dir)


def show(doc, extra):
	"""Appends extra's meshes (a --portals-out file) as visible geometry."""
	base = {k: len(doc.setdefault(k, [])) for k in ("buffers", "bufferViews", "accessors", "materials", "meshes", "nodes")}
	doc["buffers"] += extra.get("buffers", [])
	for v in extra.get("bufferViews", []):
		v = dict(v, buffer=v["buffer"] + base["buffers"])
		doc["bufferViews"].append(v)
	for a in extra.get("accessors", []):
		doc["accessors"].append(dict(a, bufferView=a["bufferView"] + base["bufferViews"]))
	doc["materials"].append({"name": "found portal (shown)", "doubleSided": True, "alphaMode": "BLEND",
				 "pbrMetallicRoughness": {"baseColorFactor": [1, 0.05, 0.02, 0.35], "metallicFactor": 0,
							  "roughnessFactor": 1},
				 "emissiveFactor": [1, 0.05, 0.02]})
	mat = len(doc["materials"]) - 1
	for m in extra.get("meshes", []):
		m = copy.deepcopy(m)
		for p in m["primitives"]:
			p["attributes"] = {k: v + base["accessors"] for k, v in p["attributes"].items()}
			p["indices"] += base["accessors"]
			p["material"] = mat
		doc["meshes"].append(m)
	for n in extra.get("nodes", []):
		doc["nodes"].append({"name": n.get("name", "portal") + " (shown)", "mesh": n["mesh"] + base["meshes"]})
		doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)


def main():
	args = sys.argv[1:]
	extra = None
	if "--show" in args:
		k = args.index("--show")
		with open(args[k + 1]) as f:
			extra = json.load(f)
		del args[k:k + 2]
	if len(args) != 2:
		raise SystemExit(__doc__)
	src, out = args
	with open(src) as f:
		doc = json.load(f)
	n = strip(doc)
	out_dir = os.path.dirname(os.path.abspath(out))
	os.makedirs(out_dir, exist_ok=True)
	relocate(doc, os.path.dirname(os.path.abspath(src)), out_dir)
	if extra:
		show(doc, extra)
	# The environment image of the scene extras is a URI too.
	env = ((doc.get("scenes") or [{}])[doc.get("scene", 0)].get("extras") or {}).get("environment") or {}
	if isinstance(env, dict) and isinstance(env.get("image"), str):
		env["image"] = os.path.relpath(os.path.join(os.path.dirname(os.path.abspath(src)), env["image"]), out_dir)
	with open(out, "w") as f:
		json.dump(doc, f, indent=1)
	print(f"{out}: {n} portal node{'s' if n != 1 else ''} taken out")


if __name__ == "__main__":
	main()
