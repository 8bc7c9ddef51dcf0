#!/usr/bin/env python3
"""Writes the small, valid seed inputs of the fuzz targets (run once; the files are committed).

scripts/fuzz.sh seeds each target's corpus from these, from tests/data/bad/ (broken inputs)
and from assets/ and experiments/ (real ones). Each file here is small and exercises one
feature of its format, so the fuzzer starts from every branch a real file would take.
"""
import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def write(target, name, data):
    os.makedirs(os.path.join(HERE, target), exist_ok=True)
    with open(os.path.join(HERE, target, name), "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


# --- OBJ ---
write("obj", "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
write("obj", "quad_uv_normals.obj",
      "# a quad with texture coordinates and normals\no quad\ng side\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
      "usemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
write("obj", "negative_indices.obj",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -1 -2\n")
write("obj", "polygon_colors.obj",
      "mtllib none.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 0\nv -1 0.5 0 0 1 1\n"
      "s 1\nf 1 2 3 4 5\nl 1 2\np 3\n")
write("obj", "normals_only.obj",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//2\nf 3//2 2//1 1//1\n")
write("obj", "mixed_attributes.obj",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1e-3\nvt 0.5 0.5\nf 1/1 2/1 3/1\nf 2 4 3\n")

# An excerpt of the bundled cow (assets/spot.obj, 330 KB: too slow a seed): its first 60
# faces, with the positions and texture coordinates they use, renumbered in first-use order.
with open(os.path.join(HERE, "..", "..", "assets", "spot.obj")) as f:
    lines = f.read().split("\n")
positions = [l for l in lines if l.startswith("v ")]
texcoords = [l for l in lines if l.startswith("vt ")]
faces = [l.split()[1:] for l in lines if l.startswith("f ")][:60]
used_v, used_vt = {}, {}
for face in faces:
    for corner in face:
        v, vt = corner.split("/")[:2]
        used_v.setdefault(int(v), len(used_v) + 1)
        used_vt.setdefault(int(vt), len(used_vt) + 1)
excerpt = ["# the first 60 faces of assets/spot.obj", "o spot"]
excerpt += [positions[v - 1] for v in used_v] + [texcoords[t - 1] for t in used_vt]
excerpt += ["f " + " ".join(f"{used_v[int(c.split('/')[0])]}/{used_vt[int(c.split('/')[1])]}" for c in face)
            for face in faces]
write("obj", "spot_excerpt.obj", "\n".join(excerpt) + "\n")

# --- PLY ---
def ply(fmt, vertex_props, vertices, faces, face_prop="property list uchar int vertex_indices",
        extra=""):
    header = (f"ply\nformat {fmt} 1.0\ncomment fuzz seed\nelement vertex {len(vertices)}\n"
              + "".join(f"property {t} {n}\n" for t, n in vertex_props)
              + f"element face {len(faces)}\n{face_prop}\n{extra}end_header\n").encode()
    if fmt == "ascii":
        body = "".join(" ".join(str(x) for x in v) + "\n" for v in vertices)
        body += "".join(f"{len(f)} " + " ".join(str(i) for i in f) + "\n" for f in faces)
        return header + body.encode()
    order = "<" if fmt == "binary_little_endian" else ">"
    codes = {"float": "f", "double": "d", "uchar": "B", "char": "b", "short": "h", "ushort": "H",
             "int": "i", "uint": "I"}
    body = b""
    for v in vertices:
        body += b"".join(struct.pack(order + codes[t], x) for (t, _), x in zip(vertex_props, v))
    count, index = face_prop.split()[2:4]
    for f in faces:
        body += struct.pack(order + codes[count], len(f)) + b"".join(struct.pack(order + codes[index], i) for i in f)
    return header + body


XYZ = [("float", "x"), ("float", "y"), ("float", "z")]
SQUARE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
FACES = [(0, 1, 2), (0, 2, 3)]
RICH = XYZ + [("float", "nx"), ("float", "ny"), ("float", "nz"), ("float", "s"), ("float", "t"),
              ("uchar", "red"), ("uchar", "green"), ("uchar", "blue"), ("uchar", "alpha"), ("float", "confidence")]
RICH_VERTICES = [v + (0, 0, 1, v[0], v[1], 255, 128, 0, 255, 0.5) for v in SQUARE]
for fmt, short in [("ascii", "ascii"), ("binary_little_endian", "le"), ("binary_big_endian", "be")]:
    write("ply", f"square_{short}.ply", ply(fmt, XYZ, SQUARE, FACES))
    write("ply", f"rich_{short}.ply", ply(fmt, RICH, RICH_VERTICES, [(0, 1, 2, 3)]))
write("ply", "double_ushort_le.ply",
      ply("binary_little_endian", [("double", "x"), ("double", "y"), ("double", "z")], SQUARE, FACES,
          face_prop="property list uchar ushort vertex_index"))
write("ply", "uint_list_be.ply",
      ply("binary_big_endian", XYZ, SQUARE, FACES, face_prop="property list uint uint vertex_indices"))
write("ply", "extra_element_ascii.ply",
      ply("ascii", XYZ, SQUARE, FACES, extra="element edge 1\nproperty int vertex1\nproperty int vertex2\n")
      + b"0 1\n")
write("ply", "uv_pairs_ascii.ply",
      ply("ascii", XYZ + [("float", "texture_u"), ("float", "texture_v"), ("short", "label")],
          [v + (v[0], v[1], 7) for v in SQUARE], FACES))


# --- glTF / GLB ---
def triangle_buffer():
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3f", 1, 1, 0)
    normals = struct.pack("<12f", *([0, 0, 1] * 4))
    uvs = struct.pack("<8f", 0, 0, 1, 0, 0, 1, 1, 1)
    indices = struct.pack("<6H", 0, 1, 2, 2, 1, 3)
    return positions, normals, uvs, indices


def gltf_document(uri=None, mode=None, strip=False, skinned=False, sparse=False):
    positions, normals, uvs, indices = triangle_buffer()
    if strip:
        indices = struct.pack("<4H", 0, 1, 2, 3)
    views_data = [positions, normals, uvs, indices]
    targets = [34962, 34962, 34962, 34963]
    if skinned:
        joints = struct.pack("<16B", *([0, 1, 0, 0] * 4))
        weights = struct.pack("<16f", *([0.5, 0.5, 0, 0] * 4))
        ibm = struct.pack("<32f", *([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] * 2))
        views_data += [joints, weights, ibm]
        targets += [34962, 34962, None]
    if sparse:
        views_data += [struct.pack("<H", 1) + b"\0\0", struct.pack("<3f", 2, 0, 0)]
        targets += [None, None]
    bin_ = b""
    views = []
    for data, target in zip(views_data, targets):
        while len(bin_) % 4:
            bin_ += b"\0"
        view = {"buffer": 0, "byteOffset": len(bin_), "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        bin_ += data
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": 4 if strip else 6, "type": "SCALAR"},
    ]
    attributes = {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}
    if skinned:
        accessors += [
            {"bufferView": 4, "componentType": 5121, "count": 4, "type": "VEC4"},
            {"bufferView": 5, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 6, "componentType": 5126, "count": 2, "type": "MAT4"},
        ]
        attributes.update({"JOINTS_0": 4, "WEIGHTS_0": 5})
    if sparse:
        first = len(views) - 2
        accessors[0]["sparse"] = {"count": 1, "indices": {"bufferView": first, "componentType": 5123},
                                  "values": {"bufferView": first + 1}}
        accessors[0]["max"] = [2, 1, 0]
    primitive = {"attributes": attributes, "indices": 3}
    if strip:
        primitive["mode"] = 5
    elif mode is not None:
        primitive["mode"] = mode
    nodes = [{"mesh": 0, "children": [1], "translation": [1, 2, 3], "scale": [-1, 1, 1]},
             {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]}]
    doc = {
        "asset": {"version": "2.0", "generator": "triorder fuzz seed"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"name": "seed", "primitives": [primitive]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(bin_)}],
    }
    if skinned:
        nodes.append({"rotation": [0, 0, 0.7071068, 0.7071068], "children": [3]})
        nodes.append({"translation": [0, 1, 0]})
        nodes[1]["skin"] = 0
        doc["scenes"][0]["nodes"].append(2)
        doc["skins"] = [{"joints": [2, 3], "inverseBindMatrices": 6}]
    if uri:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bin_).decode()
    return doc, bin_


def glb(doc, bin_):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    bin_ += b"\0" * (-len(bin_) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(bin_), b"BIN\0") + bin_
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


VARIANTS = {"indexed": {}, "strip": {"strip": True}, "fan": {"mode": 6}, "points": {"mode": 0},
            "skinned": {"skinned": True}, "sparse": {"sparse": True}}
for name, options in VARIANTS.items():
    doc, bin_ = gltf_document(uri=True, **options)
    write("gltf", f"{name}.gltf", json.dumps(doc, indent=1))
    doc, bin_ = gltf_document(**options)
    write("glb", f"{name}.glb", glb(doc, bin_))
# A sparse POSITION accessor without a buffer view: zeros but its substitutions.
doc, bin_ = gltf_document(uri=True, sparse=True)
del doc["accessors"][0]["bufferView"]
write("gltf", "sparse_viewless.gltf", json.dumps(doc, indent=1))
doc, bin_ = gltf_document(sparse=True)
del doc["accessors"][0]["bufferView"]
write("glb", "sparse_viewless.glb", glb(doc, bin_))
write("gltf", "no_meshes.gltf", json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]}))
