#!/usr/bin/env python3
"""Writes the broken mesh files of this directory (run once; the files are committed).

Each file is broken in exactly one way; tests/bad_input.rs loads each and checks the error
names the file and where the problem is. README.md lists them.
"""
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def ply_header(fmt, vertices=4, faces=2, vertex_props="property float x\nproperty float y\nproperty float z\n",
               face_prop="property list uchar int vertex_indices\n"):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {vertices}\n{vertex_props}"
            f"element face {faces}\n{face_prop}end_header\n").encode()


SQUARE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
FACES = [(0, 1, 2), (0, 2, 3)]


def binary_ply(order, vertices=SQUARE, faces=FACES):
    out = ply_header("binary_little_endian" if order == "<" else "binary_big_endian", len(vertices), len(faces))
    for v in vertices:
        out += struct.pack(order + "3f", *v)
    for f in faces:
        out += struct.pack(order + "B3i", 3, *f)
    return out


# --- PLY ---
full = binary_ply("<")
write("ply_truncated_le.ply", full[: len(ply_header("binary_little_endian")) + 12 * 2 + 5])  # inside vertex 2
full = binary_ply(">")
write("ply_truncated_be.ply", full[:-7])  # inside face 1
write("ply_header_only.ply", ply_header("ascii"))
write("ply_nan_vertex.ply", binary_ply("<", vertices=[(0, 0, 0), (1, float("nan"), 0), (1, 1, 0), (0, 1, 0)]))
write("ply_nan_ascii.ply", ply_header("ascii") + b"0 0 0\n1 nan 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
write("ply_index_past_end.ply", ply_header("ascii") + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 7\n")
write("ply_face_two_indices.ply", ply_header("ascii") + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 1\n3 0 2 3\n")
write("ply_no_vertex_element.ply",
      b"ply\nformat ascii 1.0\nelement point 3\nproperty float x\nproperty float y\nproperty float z\n"
      b"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
write("ply_float_index_list.ply",
      ply_header("ascii", face_prop="property list uchar float vertex_indices\n")
      + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
write("ply_no_faces.ply", ply_header("ascii", faces=0) + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n")
write("ply_duplicate_property.ply",
      ply_header("ascii", vertex_props="property float x\nproperty float y\nproperty float x\n")
      + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
write("ply_extra_value.ply", ply_header("ascii") + b"0 0 0\n1 0 0 5\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
# A face whose list claims four billion indices: must fail at the end of the data, not allocate.
huge = ply_header("binary_little_endian", faces=1, face_prop="property list uint int vertex_indices\n")
write("ply_huge_list.ply", huge + b"".join(struct.pack("<3f", *v) for v in SQUARE) + struct.pack("<I3i", 4_000_000_000, 0, 1, 2))
write("ply_bad_header_line.ply",
      ply_header("ascii", vertex_props="property float x\nproperty flot y\nproperty float z\n")
      + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
write("empty.ply", b"")
write("not_a_mesh.ply", "This is a shopping list, not a mesh.\n- eggs\n- flour\n")

# --- OBJ ---
QUAD = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
write("obj_nan.obj", "v 0 0 0\nv 1 0 0\nv 1 nan 0\nf 1 2 3\n")
write("obj_inf.obj", "v 0 0 0\nv 1 inf 0\nv 1 1 0\nf 1 2 3\n")
write("obj_non_numeric.obj", "# a comment\nv 0 0 0\nv 1 0 0\nv 1 one 0\nf 1 2 3\n")
write("obj_index_past_end.obj", QUAD + "f 1 2 3\nf 1 3 9\n")
write("obj_negative_index.obj", "# four vertices\n" + QUAD + "f -4 -3 -2\nf 1 3 -9\n")
write("obj_face_two_vertices.obj", QUAD + "f 1 2 3\nf 1 2\n")
write("obj_zero_index.obj", QUAD + "f 0 1 2\n")
# A negative texture-coordinate index before the start: tobj wraps it to a huge index and its
# index arithmetic overflows (a panic in debug builds).
write("obj_negative_uv_index.obj", QUAD + "vt 0 0\nf 1/1 2/-5 3/1\n")
write("obj_no_faces.obj", QUAD)
write("empty.obj", "")

# --- glTF / GLB ---
def glb(document, bin_chunk, magic=b"glTF", length=None):
    js = json.dumps(document).encode()
    js += b" " * (-len(js) % 4)
    bin_chunk += b"\0" * (-len(bin_chunk) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js
    if bin_chunk:
        body += struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    total = 12 + len(body)
    return magic + struct.pack("<II", 2, total if length is None else length) + body


TRIANGLE_BIN = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def triangle_gltf(accessor=None, view=None, position=0, buffer=None):
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": position}}]}],
        "accessors": [dict({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                            "min": [0, 0, 0], "max": [1, 1, 0]}, **(accessor or {}))],
        "bufferViews": [dict({"buffer": 0, "byteLength": 36}, **(view or {}))],
        "buffers": [buffer or {"byteLength": 36}],
    }
    return doc


write("glb_bad_magic.glb", glb(triangle_gltf(), TRIANGLE_BIN, magic=b"gLTf"))
write("glb_view_past_end.glb", glb(triangle_gltf(view={"byteOffset": 24}), TRIANGLE_BIN))
write("glb_accessor_past_view.glb", glb(triangle_gltf(accessor={"byteOffset": 12}), TRIANGLE_BIN))
write("glb_accessor_index_out_of_range.glb", glb(triangle_gltf(position=5), TRIANGLE_BIN))
write("glb_header_length_zero.glb", glb(triangle_gltf(), TRIANGLE_BIN, length=0))
cycle = triangle_gltf()
cycle["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
write("glb_node_cycle.glb", glb(cycle, TRIANGLE_BIN))
write("gltf_missing_bin.gltf", json.dumps(triangle_gltf(buffer={"byteLength": 36, "uri": "missing.bin"}), indent=1))
# "%FF" decodes to a byte that is not UTF-8: the gltf crate's URI decoding panics on it.
write("gltf_bad_uri.gltf", json.dumps(triangle_gltf(buffer={"byteLength": 36, "uri": "%FF.bin"}), indent=1))
write("empty.glb", b"")
# The header's total length covers the JSON chunk only; the BIN chunk follows it anyway.
short = glb(triangle_gltf(), TRIANGLE_BIN)
write("glb_length_shorter_than_file.glb", short[:8] + struct.pack("<I", len(short) - 44) + short[12:])
write("not_a_mesh.glb", "This is a shopping list, not a mesh.\n- eggs\n- flour\n")

write("ply_format_version_2.ply", ply_header("ascii").replace(b"ascii 1.0", b"ascii 2.0")
      + b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")

# --- other ---
write("mesh.stl", "solid triangle\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\nendsolid triangle\n")
