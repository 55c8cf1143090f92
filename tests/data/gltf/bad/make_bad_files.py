#!/usr/bin/env python3
"""Writes the small bad glTF inputs of this folder (see README.md).

Each starts from the same valid skinned triangle (2 joints, 1 rotation
channel) and breaks one thing. Run from this folder; output is deterministic.
"""
import base64
import copy
import json
import math
import struct


def base_model():
    positions = [0, 0, 0, 1, 0, 0, 0, 1, 0]
    joints = [0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0]
    weights = [0.5, 0.5, 0, 0, 0.5, 0.5, 0, 0, 1, 0, 0, 0]
    indices = [0, 1, 2]
    ibms = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
            1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1]
    times = [0.0, 1.0]
    rotations = [0, 0, 0, 1, 0, 0, math.sin(0.25), math.cos(0.25)]
    chunks = [
        (struct.pack("<9f", *positions), 5126, "VEC3", 3),
        (struct.pack("<12H", *joints), 5123, "VEC4", 3),
        (struct.pack("<12f", *weights), 5126, "VEC4", 3),
        (struct.pack("<3H", *indices) + b"\0\0", 5123, "SCALAR", 3),
        (struct.pack("<32f", *ibms), 5126, "MAT4", 2),
        (struct.pack("<2f", *times), 5126, "SCALAR", 2),
        (struct.pack("<8f", *rotations), 5126, "VEC4", 2),
    ]
    data = b""
    views, accessors = [], []
    for blob, ctype, atype, count in chunks:
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(blob)})
        accessors.append({"bufferView": len(views) - 1, "componentType": ctype,
                          "type": atype, "count": count})
        data += blob
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "tip", "translation": [0, 1, 0]},
            {"name": "mesh", "mesh": 0, "skin": 0},
        ],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": 4}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1,
                                                   "WEIGHTS_0": 2}, "indices": 3}]}],
        "animations": [{"samplers": [{"input": 5, "output": 6}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }
    return doc, data


def write(name, doc):
    with open(name, "w") as f:
        json.dump(doc, f, indent=1)


def main():
    doc, data = base_model()

    d = copy.deepcopy(doc)
    d["buffers"][0]["uri"] = "../outside.bin"
    write("uri_dotdot.gltf", d)

    d = copy.deepcopy(doc)
    d["buffers"][0]["uri"] = "/etc/passwd"
    write("uri_absolute.gltf", d)

    d = copy.deepcopy(doc)
    d["accessors"][0]["count"] = 1000
    write("accessor_out_of_range.gltf", d)

    d = copy.deepcopy(doc)
    nan_data = struct.pack("<f", float("nan")) + data[4:]
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(nan_data).decode()
    write("nan_position.gltf", d)

    d = copy.deepcopy(doc)
    bad_joints = bytearray(data)
    struct.pack_into("<H", bad_joints, 36 + 2 * 4 * 2, 2)  # vertex 2, slot 0 -> skin joint 2 of 2
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(bad_joints)).decode()
    write("joint_past_skin.gltf", d)

    d = copy.deepcopy(doc)
    d["nodes"][1]["children"] = [0]
    write("node_cycle.gltf", d)

    # JSON cut mid-object: tinygltf's own parse error must come through.
    with open("broken_json.gltf", "w") as f:
        f.write(json.dumps(doc)[:200])

    # A valid GLB, then cut short in its BIN chunk.
    d = copy.deepcopy(doc)
    del d["buffers"][0]["uri"]
    text = json.dumps(d).encode()
    text += b" " * (-len(text) % 4)
    bin_chunk = data + b"\0" * (-len(data) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    glb = struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body
    with open("truncated.glb", "wb") as f:
        f.write(glb[: len(glb) - 40])


if __name__ == "__main__":
    main()
