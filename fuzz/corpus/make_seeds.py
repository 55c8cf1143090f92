#!/usr/bin/env python3
"""Writes the valid glTF seeds of fuzz/corpus/gltf: the skinned triangle that
tests/data/gltf/bad/make_bad_files.py breaks, as .gltf (data: URI) and as .glb.
Run from this folder; output is deterministic."""
import importlib.util
import json
import os
import struct

here = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location(
    "bad", os.path.join(here, "..", "..", "tests", "data", "gltf", "bad", "make_bad_files.py"))
bad = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bad)

doc, data = bad.base_model()
with open(os.path.join(here, "gltf", "seed_triangle.gltf"), "w") as f:
    json.dump(doc, f, separators=(",", ":"))

# GLB: the same document with the buffer moved into the BIN chunk.
del doc["buffers"][0]["uri"]
js = json.dumps(doc, separators=(",", ":")).encode()
js += b" " * ((4 - len(js) % 4) % 4)
bin_ = data + b"\0" * ((4 - len(data) % 4) % 4)
total = 12 + 8 + len(js) + 8 + len(bin_)
glb = struct.pack("<4sII", b"glTF", 2, total)
glb += struct.pack("<I4s", len(js), b"JSON") + js
glb += struct.pack("<I4s", len(bin_), b"BIN\0") + bin_
with open(os.path.join(here, "gltf", "seed_triangle.glb"), "wb") as f:
    f.write(glb)
