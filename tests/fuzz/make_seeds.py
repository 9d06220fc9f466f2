#!/usr/bin/env python3
"""Writes the seed corpora of tests/fuzz/corpus/{gltf,hdr,texture}: small
files of every kind each harness reads, made here so they can be remade
(python3 tests/fuzz/make_seeds.py from the top of the tree). The EXR seeds
come from make_exr_seeds.cpp and tests/data/dwa; the checkpoint seeds from
`ajar render --checkpoint` (tests/fuzz/README.md)."""
import base64, json, os, struct, zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def put(kind, name, data):
    with open(os.path.join(OUT, kind, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# ---- PNG and JPEG textures --------------------------------------------------
def png(w, h, ctype, depth, rows, plte=None, interlace=0):
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    raw = b"".join(b"\x00" + r for r in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, ctype, 0, 0, interlace))
    if plte:
        out += chunk(b"PLTE", plte)
    return out + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def textures():
    w, h = 8, 6
    put("texture", "rgb8.png", png(w, h, 2, 8, [b"".join(bytes((x * 30, y * 40, 90)) for x in range(w)) for y in range(h)]))
    put("texture", "rgba8.png", png(w, h, 6, 8, [b"".join(bytes((x * 30, y * 40, 90, 255 - x * 20)) for x in range(w)) for y in range(h)]))
    put("texture", "grey8.png", png(w, h, 0, 8, [bytes(x * 30 + y for x in range(w)) for y in range(h)]))
    put("texture", "greya8.png", png(w, h, 4, 8, [b"".join(bytes((x * 30, 200)) for x in range(w)) for y in range(h)]))
    put("texture", "rgb16.png", png(w, h, 2, 16, [b"".join(struct.pack(">HHH", x * 8000, y * 9000, 300) for x in range(w)) for y in range(h)]))
    put("texture", "palette.png", png(w, h, 3, 4, [bytes(((x % 4) << 4 | (y % 4)) for x in range(w // 2)) for y in range(h)], plte=bytes(range(48))))
    put("texture", "grey1.png", png(16, 4, 0, 1, [bytes((0xa5, 0x3c)) for y in range(4)]))
    put("texture", "texture.png", png(4, 4, 6, 8, [bytes(range(16 * y, 16 * y + 16)) for y in range(4)]))


# ---- Radiance .hdr ----------------------------------------------------------
def hdr_flat(w, h):
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    return head + b"".join(bytes((128 + i % 100, 64, 10, 129)) for i in range(w * h))


def hdr_rle(w, h):
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    body = b""
    for y in range(h):
        body += bytes((2, 2, w >> 8, w & 255))
        for c in range(4):
            left = w
            while left:
                if c == 1 and left > 2:  # a dump of two, then runs
                    body += bytes((2, 90, 91))
                    left -= 2
                n = min(left, 127)
                body += bytes((128 + n, (100, 60, 20, 129)[c]))
                left -= n
    return head + body


def hdrs():
    put("hdr", "flat.hdr", hdr_flat(8, 4))
    put("hdr", "flat-narrow.hdr", hdr_flat(3, 2))
    put("hdr", "rle.hdr", hdr_rle(16, 3))
    put("hdr", "rle-wide.hdr", hdr_rle(300, 2))
    put("hdr", "rgbe.hdr", hdr_flat(8, 2).replace(b"#?RADIANCE", b"#?RGBE", 1))


# ---- glTF -------------------------------------------------------------------
TRI = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def datauri(b):
    return "data:application/octet-stream;base64," + base64.b64encode(b).decode()


def quad_buffer():
    pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    nrm = struct.pack("<12f", *([0, 0, 1] * 4))
    uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    tan = struct.pack("<16f", *([1, 0, 0, 1] * 4))
    col = bytes((255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128))
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    b = pos + nrm + uv + tan + col + idx
    views = [(0, 48), (48, 48), (96, 32), (128, 64), (192, 16), (208, 12)]
    return b, views


def gltf(extra_top=None, prim_extra=None, scene_extra=None, nodes=None, materials=None, buffer_uri=None):
    b, views = quad_buffer()
    d = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
         "nodes": nodes or [{"mesh": 0}],
         "meshes": [{"primitives": [dict({"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                         "indices": 5}, **(prim_extra or {}))]}],
         "buffers": [{"uri": buffer_uri or datauri(b), "byteLength": len(b)}],
         "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                        "min": [0, 0, 0], "max": [1, 1, 0]},
                       {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                       {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                       {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"},
                       {"bufferView": 4, "componentType": 5121, "normalized": True, "count": 4, "type": "VEC4"},
                       {"bufferView": 5, "componentType": 5123, "count": 6, "type": "SCALAR"}]}
    if materials is not None:
        d["materials"] = materials
    if scene_extra:
        d["scenes"][0].update(scene_extra)
    d.update(extra_top or {})
    return d


def glb(doc, binary):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def scenes():
    dump = lambda d: json.dumps(d, separators=(",", ":"))
    put("gltf", "quad.gltf", dump(gltf(materials=[{}])))
    tex = {"images": [{"uri": "tex.png"}], "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}],
           "textures": [{"source": 0, "sampler": 0}],
           "extensionsUsed": ["KHR_texture_transform", "KHR_materials_emissive_strength"]}
    mats = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
             {"offset": [0.25, 0], "scale": [2, 2], "rotation": 0.5}}}, "metallicRoughnessTexture": {"index": 0}},
             "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1], "normalTexture": {"index": 0, "scale": 0.5},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
             "alphaMode": "MASK", "alphaCutoff": 0.3}]
    put("gltf", "textured.gltf", dump(gltf(tex, {"material": 0, "attributes": {"POSITION": 0, "NORMAL": 1,
        "TEXCOORD_0": 2, "TEXCOORD_1": 2, "TANGENT": 3, "COLOR_0": 4}}, materials=mats)))
    glass = [{"pbrMetallicRoughness": {"roughnessFactor": 0},
              "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                             "KHR_materials_ior": {"ior": 1.5}, "KHR_materials_specular": {"specularFactor": 0.5},
                             "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationColor": [0.9, 0.5, 0.5],
                                                      "attenuationDistance": 2}}}]
    put("gltf", "glass.gltf", dump(gltf({"extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior",
        "KHR_materials_specular", "KHR_materials_volume"]}, {"material": 0}, materials=glass)))
    put("gltf", "sky-hdr.gltf", dump(gltf(scene_extra={"extras": {"environment": {"image": "sky.hdr",
        "strength": 2, "rotation": 30}}})))
    put("gltf", "sky-exr.gltf", dump(gltf(scene_extra={"extras": {"environment": {"image": "sky.exr"}}})))
    put("gltf", "sky-color.gltf", dump(gltf(scene_extra={"extras": {"environment": {"color": [1, 0.5, 0.2]},
        "resolution": [16, 8]}})))
    lights = {"extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "directional", "intensity": 3}, {"type": "point", "intensity": 100, "range": 5},
        {"type": "spot", "intensity": 50, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}]}}}
    nodes = [{"mesh": 0, "children": [1, 2, 3, 4]},
             {"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": [0, 0.7071, 0, 0.7071]},
             {"extensions": {"KHR_lights_punctual": {"light": 1}}, "translation": [0, 0, 2]},
             {"extensions": {"KHR_lights_punctual": {"light": 2}}, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 3, 1]},
             {"mesh": 0, "extras": {"portal": True}, "translation": [0, 0, 1], "scale": [2, 2, 2]}]
    d = gltf(lights, nodes=nodes, materials=[{"emissiveFactor": [1, 0.5, 0.5]}], prim_extra={"material": 0})
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}]
    d["nodes"].append({"camera": 0, "translation": [0, 0, 5]})
    d["nodes"][0]["children"].append(5)
    put("gltf", "lights-portal-camera.gltf", dump(d))
    put("gltf", "file-buffer.gltf", dump({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
        "indices": 2, "mode": 5}]}], "buffers": [{"uri": "tri.bin", "byteLength": 78}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 72, "byteStride": 12},
                        {"buffer": 0, "byteOffset": 72, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                      {"bufferView": 0, "byteOffset": 36, "componentType": 5126, "count": 3, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]}))
    sparse = bytes(TRI) + struct.pack("<2H", 1, 2) + struct.pack("<6f", 5, 0, 0, 0, 5, 0)
    put("gltf", "sparse-quantized.gltf", dump({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_mesh_quantization"],
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "mode": 6}]}],
        "buffers": [{"uri": datauri(sparse + bytes((0, 0, 255, 0, 0, 255))), "byteLength": len(sparse) + 6}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 4},
                        {"buffer": 0, "byteOffset": 40, "byteLength": 24}, {"buffer": 0, "byteOffset": 64, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "sparse": {"count": 2, "indices": {"bufferView": 1, "componentType": 5123},
                                  "values": {"bufferView": 2}}},
                      {"bufferView": 3, "componentType": 5121, "normalized": True, "count": 3, "type": "VEC2"}]}))
    b, views = quad_buffer()
    img = open(os.path.join(OUT, "texture", "texture.png"), "rb").read()
    doc = gltf(materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}], prim_extra={"material": 0})
    del doc["buffers"][0]["uri"]
    doc["buffers"][0]["byteLength"] = len(b) + len(img)
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(b), "byteLength": len(img)})
    doc.update({"images": [{"bufferView": 6, "mimeType": "image/png"}], "textures": [{"source": 0}]})
    put("gltf", "embedded.glb", glb(doc, b + img))
    # Blender's materials (issue 44): sheen, clear coat, anisotropy, specular colour, each with a texture.
    t = {"index": 0}
    layers = [{"pbrMetallicRoughness": {"metallicFactor": 0.5, "roughnessFactor": 0.4}, "normalTexture": t,
               "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.8, 0.7, 0.6], "sheenRoughnessFactor": 0.4,
                                                      "sheenColorTexture": t, "sheenRoughnessTexture": t},
                              "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.1,
                                                          "clearcoatTexture": t, "clearcoatRoughnessTexture": t,
                                                          "clearcoatNormalTexture": {"index": 0, "scale": 0.7}},
                              "KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": 0.8,
                                                           "anisotropyTexture": t},
                              "KHR_materials_specular": {"specularColorFactor": [1, 0.8, 0.6], "specularTexture": t,
                                                         "specularColorTexture": t}}}]
    put("gltf", "layers.gltf", dump(gltf({"images": [{"uri": "tex.png"}], "textures": [{"source": 0}],
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_anisotropy",
                           "KHR_materials_specular"]},
        {"material": 0, "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, materials=layers)))
    # Instances (issue 42): the quad drawn by two nodes and by 40,000 EXT_mesh_gpu_instancing copies (an
    # accessor without a buffer view is zeros), past the loader's rule, so the two-level BVH is built.
    d = gltf({"extensionsUsed": ["EXT_mesh_gpu_instancing"]}, nodes=[
        {"mesh": 0, "children": [1, 2]}, {"mesh": 0, "translation": [2, 0, 0], "scale": [1, -1, 2]},
        {"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 6}}}}])
    d["accessors"].append({"componentType": 5126, "count": 40000, "type": "VEC3"})
    put("gltf", "instanced.gltf", dump(d))


if __name__ == "__main__":
    textures()
    hdrs()
    scenes()
