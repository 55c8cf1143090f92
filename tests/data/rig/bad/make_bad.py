#!/usr/bin/env python3
"""Writes the malformed rig-file corpus of this folder and its README.md.

Each case is one edit of a valid rig (BASE below) or a whole file of its own.
The part of the message each must produce is written here by hand and
asserted by tests/app/cli_bad_rig_test.cpp (exit code 2, the message on the
first stderr line, no output file). The files also seed fuzz/rig_fuzzer.cpp.
Run from anywhere: python3 make_bad.py
"""
import json
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def base():
    return {
        "character": "mannequin",
        "motion": {"file": "../../../../samples/data/bend.bvh"},
        "global": "ssd",
        "patches": [{"name": "left_elbow",
                     "region": {"joint": "LeftForeArm", "radius": 14},
                     "grid": [6, 6], "sampling": [8, 8]}],
        "render": {"size": [64, 36], "camera": "fixed"},
    }


def edit(fn):
    doc = base()
    fn(doc)
    return json.dumps(doc, indent=2) + "\n"


def text_base():
    return json.dumps(base(), indent=2) + "\n"


CASES = []  # (file, content, what it guards against, expected message part)


def case(name, content, guards, expect):
    CASES.append((name, content, guards, expect))


case("empty.json", "", "an empty file", "1:1: error: invalid JSON")
case("truncated.json", text_base()[:120], "a file cut in the middle",
     ": error: invalid JSON: syntax error")
rng = random.Random(9)
case("binary.json", bytes(rng.randrange(256) for _ in range(2048)), "binary noise",
     "1:1: error: invalid JSON")
case("nan_radius.json", text_base().replace('"radius": 14', '"radius": NaN'),
     "NaN (not JSON) as a number", "12:19: error: invalid JSON: syntax error while parsing value - invalid literal")
case("inf_radius.json", text_base().replace('"radius": 14', '"radius": 1e999'),
     "a number beyond double range (inf)", "12:19: error: invalid JSON: number overflow parsing '1e999'")
case("size_absurd.json", edit(lambda d: d["render"].update(size=[100000, 100000])),
     "an absurd image size", "render.size: error: expected an array of two integers in 16..16384")
case("size_zero.json", edit(lambda d: d["render"].update(size=[0, 0])),
     "a zero image size", "render.size: error: expected an array of two integers in 16..16384")
case("grid_absurd.json", edit(lambda d: d["patches"][0].update(grid=[1000, 1000])),
     "an absurd control grid", "patches[0].grid: error: expected an array of two integers in 4..64")
case("sampling_absurd.json", edit(lambda d: d["patches"][0].update(sampling=[100000, 8])),
     "an absurd sample grid", "patches[0].sampling: error: expected an array of two integers in 4..256")
case("radius_negative.json",
     edit(lambda d: d["patches"][0]["region"].update(radius=-5)),
     "a negative radius", "patches[0].region.radius: error: expected a number in 1e-06..1e+06, found -5")
case("radius_string.json",
     edit(lambda d: d["patches"][0]["region"].update(radius="5")),
     "a string for a number", "patches[0].region.radius: error: expected a number in 1e-06..1e+06, found \"5\"")
case("fps_absurd.json", edit(lambda d: d["motion"].update(fps=1e9)),
     "an absurd frame rate", "motion.fps: error: expected a number in 0..10000, found 1000000000.0")
case("vertex_index_huge.json",
     edit(lambda d: d["patches"][0].update(region={"vertices": [1, 2, 10**12]})),
     "a vertex index beyond any mesh", "patches[0].region.vertices[2]: error: expected a vertex index")
case("unknown_field.json", edit(lambda d: d.update(colour="red")),
     "an unknown top-level field", "colour: error: unknown field (expected one of: character, motion")
case("unknown_render_field.json", edit(lambda d: d["render"].update(fps=30)),
     "an unknown nested field", "render.fps: error: unknown field (expected one of: size, camera")
case("too_many_patches.json",
     edit(lambda d: d.update(patches=[{"name": "p%d" % i,
                                       "region": {"joint": "LeftForeArm", "radius": 14}}
                                      for i in range(65)])),
     "more patches than the limit", "patches: error: expected at most 64 patches")
case("deep_nesting.json",
     text_base().replace('"patches": [', '"patches": [' + "[" * 100000 + "]" * 100000 + ",", 1),
     "10^5 nested arrays (the message must not recurse)",
     "patches[0]: error: expected an object, found an array (1 item)")
case("patches_not_array.json", edit(lambda d: d.update(patches={"name": "x"})),
     "an object where the patch list belongs", "patches: error: expected an array of patch objects, found an object")
case("output_dotdot.json", edit(lambda d: d["render"].update(output="../../x_####.png")),
     "an output pattern leaving the rig's folder",
     "render.output: error: expected a relative path inside the rig's output folder")
case("output_absolute.json", edit(lambda d: d["render"].update(output="/tmp/x_####.png")),
     "an absolute output pattern",
     "render.output: error: expected a relative path inside the rig's output folder")
case("frames_reversed.json", edit(lambda d: d["render"].update(frames="9:2")),
     "a reversed frame range in the rig", "render.frames: error: range 9:2 is outside the motion's frames")
case("motion_missing.json", edit(lambda d: d["motion"].update(file="no_such.bvh")),
     "a motion file that does not exist", "no_such.bvh: error: no such file")
case("motion_directory.json", edit(lambda d: d["motion"].update(file=".")),
     "a folder where the motion file belongs", "found a directory")


def main():
    rows = []
    for name, content, guards, expect in CASES:
        mode = "wb" if isinstance(content, bytes) else "w"
        with open(os.path.join(HERE, name), mode) as f:
            f.write(content)
        rows.append("| `%s` | %s | `%s` |" % (name, guards, expect.replace("|", "\\|")))
    with open(os.path.join(HERE, "README.md"), "w") as f:
        f.write("# Malformed rig-file corpus\n\n"
                "Written by `make_bad.py` (edits of one valid rig that renders the mannequin with\n"
                "`samples/data/bend.bvh`). `tests/app/cli_bad_rig_test.cpp` renders each one and\n"
                "asserts exit code 2, the message part below on the first stderr line (after the\n"
                "file name) and that no output file was written; `fuzz/rig_fuzzer.cpp` uses them\n"
                "as seeds. Every file here must have a row below and in the test.\n\n"
                "| file | guards against | message contains |\n| --- | --- | --- |\n")
        f.write("\n".join(rows) + "\n")


main()
