#!/usr/bin/env python3
"""Writes the malformed BVH corpus of this folder and its README.md.

Each case is a small edit of one valid file (BASE below). The expected error
code and line:column are written here by hand, from the edit, and asserted by
tests/mocap/bvh_bad_corpus_test.cpp. Run from anywhere: python3 make_bad.py
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))

BASE = [
    "HIERARCHY",                                                               # 1
    "ROOT Hips",                                                               # 2
    "{",                                                                       # 3
    "\tOFFSET 0 0 0",                                                          # 4
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",  # 5
    "\tJOINT Chest",                                                           # 6
    "\t{",                                                                     # 7
    "\t\tOFFSET 0 10 0",                                                       # 8
    "\t\tCHANNELS 3 Zrotation Xrotation Yrotation",                            # 9
    "\t\tEnd Site",                                                            # 10
    "\t\t{",                                                                   # 11
    "\t\t\tOFFSET 0 5 0",                                                      # 12
    "\t\t}",                                                                   # 13
    "\t}",                                                                     # 14
    "}",                                                                       # 15
    "MOTION",                                                                  # 16
    "Frames: 3",                                                               # 17
    "Frame Time: 0.0333333",                                                   # 18
    "0 90 0 0 0 0 1 2 3",                                                      # 19
    "0 91 0 0 0 0 4 5 6",                                                      # 20
    "0 92 0 0 0 0 7 8 9",                                                      # 21
]


def text(lines, final_newline=True):
    return "\n".join(lines) + ("\n" if final_newline else "")


def with_line(n, new):
    lines = list(BASE)
    lines[n - 1] = new
    return text(lines)


def without_line(n):
    lines = list(BASE)
    del lines[n - 1]
    return text(lines)


def inserted_after(n, new):
    lines = list(BASE)
    lines.insert(n, new)
    return text(lines)


def deep(levels):
    lines = ["HIERARCHY"]
    for k in range(levels):
        lines += [("ROOT J%d" if k == 0 else "JOINT J%d") % k, "{", "OFFSET 0 1 0", "CHANNELS 0"]
    lines += ["}"] * levels
    lines += ["MOTION", "Frames: 0", "Frame Time: 0.1"]
    return text(lines)


channels_after_child = list(BASE)
moved = channels_after_child.pop(4)          # root CHANNELS line
channels_after_child.insert(13, moved)       # after Chest's closing brace

# (file, contents, code, line, column, what it guards against)
CASES = [
    ("empty.bvh", "", "syntax", 1, 1, "an empty file"),
    ("no_hierarchy.bvh", with_line(1, "HIERARCHIE"), "syntax", 1, 1, "a file that does not start with HIERARCHY"),
    ("no_root.bvh", with_line(2, "BONE Hips"), "syntax", 2, 1, "an unknown keyword where ROOT belongs"),
    ("root_without_name.bvh", with_line(2, "ROOT"), "syntax", 2, 5, "a ROOT without a name"),
    ("missing_open_brace.bvh", without_line(3), "syntax", 3, 2, "a joint without its '{'"),
    ("missing_close_brace.bvh", without_line(14), "syntax", 15, 1, "a joint block never closed before MOTION"),
    ("truncated_hierarchy.bvh", text(BASE[:9]), "syntax", 10, 1, "a file cut inside the hierarchy"),
    ("offset_not_number.bvh", with_line(8, "\t\tOFFSET 0 ten 0"), "bad-number", 8, 12, "a word in OFFSET"),
    ("offset_nan.bvh", with_line(4, "\tOFFSET 0 nan 0"), "non-finite", 4, 11, "NaN in OFFSET"),
    ("offset_missing_value.bvh", with_line(4, "\tOFFSET 0 0"), "bad-number", 5, 2, "an OFFSET with two values"),
    ("channels_count_too_big.bvh", with_line(9, "\t\tCHANNELS 7 Zrotation Xrotation Yrotation"), "bad-channel", 9, 12,
     "a channel count above 6"),
    ("channels_count_not_number.bvh", with_line(9, "\t\tCHANNELS three Zrotation Xrotation Yrotation"), "bad-number",
     9, 12, "a word as channel count"),
    ("channels_negative.bvh", with_line(9, "\t\tCHANNELS -1"), "bad-channel", 9, 12, "a negative channel count"),
    ("bad_channel_name.bvh", with_line(9, "\t\tCHANNELS 3 Zrotation Xrot Yrotation"), "bad-channel", 9, 24,
     "an unknown channel name"),
    ("duplicate_channel.bvh", with_line(9, "\t\tCHANNELS 3 Zrotation Xrotation Zrotation"), "bad-channel", 9, 34,
     "the same channel twice in one joint"),
    ("too_few_channel_names.bvh", with_line(9, "\t\tCHANNELS 4 Zrotation Xrotation Yrotation"), "bad-channel", 10, 3,
     "a CHANNELS count larger than the names that follow"),
    ("channels_after_child.bvh", text(channels_after_child), "syntax", 14, 2,
     "CHANNELS after a child joint (would break the column order)"),
    ("second_offset.bvh", inserted_after(4, "\tOFFSET 1 1 1"), "syntax", 5, 2, "two OFFSET lines in one joint"),
    ("joint_without_offset.bvh", without_line(8), "syntax", 13, 2, "a joint with no OFFSET"),
    ("end_site_misspelled.bvh", with_line(10, "\t\tEnd Sight"), "syntax", 10, 7, "'End' not followed by 'Site'"),
    ("end_site_with_channels.bvh", inserted_after(12, "\t\t\tCHANNELS 0"), "syntax", 13, 4,
     "an End Site holding more than OFFSET"),
    ("unknown_keyword.bvh", inserted_after(4, "\tSCALE 1 1 1"), "syntax", 5, 2, "an unknown keyword inside a joint"),
    ("depth_limit.bvh", deep(300), "limit-exceeded", 1026, 1,
     "nesting deeper than the default limit of 256 (no unbounded recursion)"),
    ("no_motion.bvh", text(BASE[:15]), "syntax", 16, 1, "a file without a MOTION section"),
    ("frames_missing.bvh", with_line(17, "Frame: 3"), "syntax", 17, 1, "MOTION not followed by 'Frames:'"),
    ("frames_not_number.bvh", with_line(17, "Frames: three"), "bad-number", 17, 9, "a word as frame count"),
    ("frames_negative.bvh", with_line(17, "Frames: -3"), "bad-number", 17, 9, "a negative frame count"),
    ("frames_absurd.bvh", with_line(17, "Frames: 99999999999999999999"), "limit-exceeded", 17, 9,
     "a frame count beyond any integer type"),
    ("frames_huge_declared.bvh", with_line(17, "Frames: 2000000000"), "count-mismatch", 22, 1,
     "a huge declared count on a small file (no allocation from the declared count)"),
    ("fewer_frames.bvh", with_line(17, "Frames: 5"), "count-mismatch", 22, 1, "fewer data lines than 'Frames:' declares"),
    ("frame_time_zero.bvh", with_line(18, "Frame Time: 0"), "bad-number", 18, 13, "a zero frame time"),
    ("frame_time_text.bvh", with_line(18, "Frame Time: fast"), "bad-number", 18, 13, "a word as frame time"),
    ("frame_time_inf.bvh", with_line(18, "Frame Time: inf"), "non-finite", 18, 13, "an infinite frame time"),
    ("short_line.bvh", with_line(20, "0 91 0 0 0 0 4 5"), "count-mismatch", 20, 17, "a frame with too few values"),
    ("long_line.bvh", with_line(20, "0 91 0 0 0 0 4 5 6 7"), "count-mismatch", 20, 20, "a frame with too many values"),
    ("value_not_number.bvh", with_line(21, "0 92 0 0 abc 0 7 8 9"), "bad-number", 21, 10, "a word in the motion data"),
    ("value_nan.bvh", with_line(19, "0 nan 0 0 0 0 1 2 3"), "non-finite", 19, 3, "NaN in the motion data"),
    ("value_inf.bvh", with_line(19, "0 90 -inf 0 0 0 1 2 3"), "non-finite", 19, 6, "-inf in the motion data"),
    ("value_overflow.bvh", with_line(19, "0 1e999 0 0 0 0 1 2 3"), "non-finite", 19, 3,
     "a value too large for a float"),
    ("value_trailing_garbage.bvh", with_line(20, "0 91 0 0 0 0 4 5 6x"), "bad-number", 20, 18,
     "a number that does not fill its token"),
    ("value_comma_decimal.bvh", with_line(19, "0 90,5 0 0 0 0 1 2 3"), "bad-number", 19, 3,
     "a decimal comma (locale-formatted numbers)"),
    ("value_double_sign.bvh", with_line(19, "+-1 90 0 0 0 0 1 2 3"), "bad-number", 19, 1, "two signs before a number"),
    ("truncated_motion.bvh", text(BASE[:20] + ["0 92 0 0 0"], final_newline=False), "count-mismatch", 21, 11,
     "a file cut in the middle of the last frame"),
]


def main():
    readme = [
        "# Malformed BVH corpus",
        "",
        "Each file is a small edit of one valid 2-joint, 9-channel, 3-frame file (see `make_bad.py`,",
        "which writes them all). `tests/mocap/bvh_bad_corpus_test.cpp` asserts the exact error code",
        "and line:column of each; every file here must have a row below and in the test.",
        "",
        "| file | guards against | code | line:col |",
        "| --- | --- | --- | --- |",
    ]
    for name, contents, code, line, col, what in CASES:
        with open(os.path.join(HERE, name), "w", newline="") as f:
            f.write(contents)
        readme.append(f"| `{name}` | {what} | {code} | {line}:{col} |")
    with open(os.path.join(HERE, "README.md"), "w") as f:
        f.write("\n".join(readme) + "\n")


if __name__ == "__main__":
    main()
