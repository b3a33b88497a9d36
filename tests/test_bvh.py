"""BVH reading and writing: the real Xia clips, round trips, known answers, malformed input, fuzzing."""
import json
import os
import random
import re
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from mslib.motion import rotations as rot
from mslib.motion.bvh import (BVHError, BVHMotion, bvh_info, channel_data, euler_degrees_to_matrix,
                              format_bvh, parse_bvh_text, read_bvh, write_bvh)
from mslib.motion.skeleton import HUMANML3D, Skeleton, forward_kinematics

SMALL = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Spine
  {
    OFFSET 0 1 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 0.5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.05
0 1 0 10 20 30 5 -5 15
0.1 1 0 11 21 31 6 -4 16
"""


# ---------------------------------------------------------------- helpers
def _axis_rotation(axis: str, degrees: float) -> np.ndarray:
    """The 3×3 rotation about one axis, written out (independent of the library)."""
    c, s = np.cos(np.deg2rad(degrees)), np.sin(np.deg2rad(degrees))
    return {"X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def _joint(name, offset, channels, children=(), end_site=None):
    """A joint of a synthetic hierarchy."""
    return {"name": name, "offset": offset, "channels": channels.split(), "children": list(children),
            "end_site": end_site}


def _synthetic_bvh(root, n_frames=7, seed=0, eol="\n", indent="  "):
    """BVH text for a joint tree with random channel data, plus the expected parse (independent FK)."""
    lines, joints, parents = ["HIERARCHY"], [], []
    stack = [(root, 0, -1, False)]
    while stack:  # depth-first, writing '}' when a joint's block closes
        j, depth, parent, closing = stack.pop()
        ind = indent * depth
        if closing:
            if j["end_site"] is not None:
                lines += [f"{ind}{indent}End Site", f"{ind}{indent}{{",
                          f"{ind}{indent * 2}OFFSET " + " ".join(map(str, j["end_site"])), f"{ind}{indent}}}"]
            lines.append(f"{ind}}}")
            continue
        lines += [f"{ind}{'ROOT' if parent < 0 else 'JOINT'} {j['name']}", f"{ind}{{",
                  f"{ind}{indent}OFFSET " + " ".join(map(str, j["offset"])),
                  f"{ind}{indent}CHANNELS {len(j['channels'])} " + " ".join(j["channels"])]
        joints.append(j)
        parents.append(parent)
        me = len(joints) - 1
        stack += [(j, depth, parent, True)] + [(c, depth + 1, me, False) for c in reversed(j["children"])]
    rng = np.random.default_rng(seed)
    n_channels = sum(len(j["channels"]) for j in joints)
    data = np.round(rng.uniform(-170, 170, (n_frames, n_channels)), 4)
    lines += ["MOTION", f"Frames: {n_frames}", "Frame Time: 0.04"]
    lines += [" ".join(f"{v:.4f}" for v in row) for row in data]
    J = len(joints)
    R = np.tile(np.eye(3), (n_frames, J, 1, 1))
    t = np.tile(np.array([j["offset"] for j in joints], float), (n_frames, 1, 1))
    col = 0
    for k, j in enumerate(joints):
        for ch in j["channels"]:
            axis = ch[0].upper()
            if ch.lower().endswith("position"):
                t[:, k, "XYZ".index(axis)] = data[:, col]
            else:
                R[:, k] = [r @ _axis_rotation(axis, a) for r, a in zip(R[:, k], data[:, col])]
            col += 1
    G, p = np.zeros_like(R), np.zeros_like(t)
    for k, par in enumerate(parents):
        G[:, k] = R[:, k] if par < 0 else G[:, par] @ R[:, k]
        p[:, k] = t[:, k] if par < 0 else p[:, par] + (G[:, par] @ t[:, k, :, None])[..., 0]
    return eol.join(lines) + eol, {"names": [j["name"] for j in joints], "parents": parents,
                                   "rotations": R, "translations": t, "global": p}


SYNTHETIC = {
    "xyz_and_yxz": _joint("root", (0, 0, 0), "Xposition Yposition Zposition Xrotation Yrotation Zrotation", [
        _joint("a", (0, 2, 0), "Yrotation Xrotation Zrotation", [
            _joint("b", (1.5, 0, 0.5), "Xrotation Yrotation Zrotation", end_site=(0, 0, 1))])]),
    "odd_channels": _joint("hips", (0.5, 0, 0), "Zrotation Xposition Yrotation Zposition Xrotation Yposition", [
        _joint("six", (0, 1, 0), "Yrotation Zposition Xrotation Xposition Zrotation Yposition", [
            _joint("none", (0, 1, 0), "", [_joint("two", (1, 0, 0), "Xrotation Zrotation", end_site=(1, 0, 0))]),
            _joint("slide", (0, 0, 2), "Yposition", end_site=(0, 0, 1))]),
        _joint("left", (-1, 0, 0), "Zrotation Yrotation Xrotation", end_site=(-1, 0, 0))]),
}


def _assert_same_motion(a: BVHMotion, b: BVHMotion, atol=1e-5):
    assert a.skeleton.names == b.skeleton.names and a.channels == b.channels and a.n_frames == b.n_frames
    np.testing.assert_allclose(b.global_positions(), a.global_positions(), atol=atol)
    np.testing.assert_allclose(b.local_rotations, a.local_rotations, atol=atol)
    assert b.end_sites.keys() == a.end_sites.keys() and b.fps == pytest.approx(a.fps, rel=1e-9)


# ---------------------------------------------------------------- the real Xia clips
@pytest.fixture(scope="module")
def xia_files(shared_data):
    """The 40 Xia BVH paths (skips without ../shared/data)."""
    files = sorted((shared_data / "xia_grid").glob("*.bvh"))
    assert len(files) == 40
    return files


@pytest.fixture(scope="module")
def xia(xia_files):
    """All 40 Xia clips, parsed once."""
    return {f: read_bvh(f) for f in xia_files}


def test_xia_all_files_parse_with_consistent_shapes(xia):
    for path, m in xia.items():
        declared = int(re.search(r"Frames:\s*(\d+)", path.read_text()).group(1))
        assert m.n_joints == 31 and m.n_frames == declared > 0, path.name
        assert m.fps == pytest.approx(120, abs=0.01) and m.frame_time == pytest.approx(0.008333)
        assert m.channels[0] == ["Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation"]
        assert all(c == ["Zrotation", "Yrotation", "Xrotation"] for c in m.channels[1:])
        assert set(m.rotation_orders) == {"ZYX"} and len(m.end_sites) == 7
        assert m.local_rotations.shape == (declared, 31, 3, 3) and m.positions.shape == (declared, 31, 3)
        R = m.local_rotations
        np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
        # joints without position channels keep their OFFSET in every frame
        np.testing.assert_array_equal(m.positions[:, 1:], np.broadcast_to(m.skeleton.offsets[1:], (declared, 30, 3)))


def test_xia_skeleton_facts(xia):
    first = next(iter(xia.values()))
    sk = first.skeleton
    parent = {name: (sk.names[p] if p >= 0 else None) for name, p in zip(sk.names, sk.parents)}
    assert sk.names[0] == "Hips" and parent["LeftUpLeg"] == "LHipJoint" and parent["LHipJoint"] == "Hips"
    assert parent["LThumb"] == "LeftHand" and parent["Head"] == "Neck1" and parent["LeftShoulder"] == "Spine1"
    assert {sk.names[j] for j in first.end_sites} == {
        "LeftToeBase", "RightToeBase", "Head", "LeftHandIndex1", "LThumb", "RightHandIndex1", "RThumb"}
    np.testing.assert_allclose(sk.offsets[sk.index("LeftUpLeg")], [1.36306, -1.79463, 0.83929])
    for m in xia.values():  # one shared header
        assert m.skeleton.names == sk.names and m.skeleton.parents == sk.parents
        np.testing.assert_array_equal(m.skeleton.offsets, sk.offsets)
        g = m.global_positions()  # Y is up: the head is above both toes on average
        head, toes = g[:, sk.index("Head"), 1], g[:, [sk.index("LeftToeBase"), sk.index("RightToeBase")], 1]
        assert head.mean() > toes.mean() + 10


def test_xia_round_trip_exact(xia, tmp_path):
    clips = list(xia.items())
    for path, m in [clips[6 * k] for k in range(5)]:  # five styles, each with a different content
        _assert_same_motion(m, parse_bvh_text(format_bvh(m), source=path.name))
    path, m = clips[0]
    out = write_bvh(tmp_path / path.name, m)
    _assert_same_motion(m, read_bvh(out))


def test_xia_info(xia_files):
    info = bvh_info(xia_files[0])
    json.dumps(info)
    assert info["n_joints"] == 31 and info["joints"][0] == "Hips" and info["total_channels"] == 96
    assert info["channels_per_joint"]["Hips"] == 6 and info["channels_per_joint"]["LeftArm"] == 3
    assert info["rotation_orders"] == ["ZYX"] and info["n_end_sites"] == 7 and info["file"] == str(xia_files[0])
    assert info["duration_s"] == pytest.approx(info["n_frames"] / 120, rel=1e-3)


# ---------------------------------------------------------------- synthetic hierarchies and known answers
@pytest.mark.parametrize("eol,indent", [("\n", "  "), ("\r\n", "\t"), ("\r", " \t ")])
@pytest.mark.parametrize("case", sorted(SYNTHETIC))
def test_synthetic_parse_matches_independent_fk_and_round_trips(case, eol, indent, tmp_path):
    text, expected = _synthetic_bvh(SYNTHETIC[case], eol=eol, indent=indent)
    m = parse_bvh_text(text, source=case)
    assert list(m.skeleton.names) == expected["names"] and list(m.skeleton.parents) == expected["parents"]
    np.testing.assert_allclose(m.local_rotations, expected["rotations"], atol=1e-12)
    np.testing.assert_allclose(m.positions, expected["translations"], atol=1e-12)
    np.testing.assert_allclose(m.global_positions(), expected["global"], atol=1e-9)
    assert m.fps == pytest.approx(25)
    _assert_same_motion(m, parse_bvh_text(format_bvh(m)))
    _assert_same_motion(m, read_bvh(write_bvh(tmp_path / "synthetic.bvh", m)))


def test_rotation_orders_and_end_sites_of_odd_hierarchy():
    m = parse_bvh_text(_synthetic_bvh(SYNTHETIC["odd_channels"])[0])
    assert m.skeleton.names == ("hips", "six", "none", "two", "slide", "left")
    assert m.rotation_orders == ["ZYX", "YXZ", "XYZ", "XZY", "XYZ", "ZYX"]
    assert m.channels[2] == [] and m.channels[4] == ["Yposition"]
    assert sorted(m.end_sites) == [3, 4, 5]
    np.testing.assert_array_equal(m.end_sites[4], [0, 0, 1])
    np.testing.assert_array_equal(m.local_rotations[:, 2], np.broadcast_to(np.eye(3), (7, 3, 3)))
    # the 'slide' joint keeps its OFFSET x and z, its Y comes from the channel
    assert (m.positions[:, 4, [0, 2]] == [0, 2]).all() and np.ptp(m.positions[:, 4, 1]) > 0


def test_known_answer_root_rotation_moves_child():
    text = SMALL.replace("Frames: 2", "Frames: 1").split("0 1 0 10")[0] + "1 2 3 90 0 0 0 0 0\n"
    m = parse_bvh_text(text.replace("OFFSET 0 1 0", "OFFSET 1 0 0"))
    np.testing.assert_allclose(m.global_positions()[0], [[1, 2, 3], [1, 3, 3]], atol=1e-12)
    np.testing.assert_allclose(m.root_positions, [[1, 2, 3]])


def test_known_answer_channels_compose_intrinsically_in_listed_order():
    # Zrotation 90 then Xrotation 90: R = Rz·Rx sends the child offset (0, 1, 0) to (0, 0, 1)
    text = ("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 2 Zrotation Xrotation\nJOINT c\n{\nOFFSET 0 1 0\n"
            "CHANNELS 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 1\n90 90\n")
    np.testing.assert_allclose(parse_bvh_text(text).global_positions()[0, 1], [0, 0, 1], atol=1e-12)


def test_six_channel_child_uses_channel_values_not_offset():
    text = ("HIERARCHY\nROOT r\n{\nOFFSET 9 9 9\nCHANNELS 3 Zrotation Yrotation Xrotation\nJOINT c\n{\n"
            "OFFSET 1 0 0\nCHANNELS 6 Zrotation Yrotation Xrotation Xposition Yposition Zposition\n}\n}\n"
            "MOTION\nFrames: 1\nFrame Time: 0.5\n90 0 0 0 0 0 5 0 0\n")
    m = parse_bvh_text(text)
    np.testing.assert_allclose(m.positions[0], [[9, 9, 9], [5, 0, 0]])
    np.testing.assert_allclose(m.global_positions()[0], [[9, 9, 9], [9, 14, 9]], atol=1e-12)
    assert m.fps == 2


def test_fast_euler_matches_rotations_module():
    angles = np.random.default_rng(3).uniform(-180, 180, (20, 4, 3))
    for order in ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"):
        np.testing.assert_allclose(euler_degrees_to_matrix(angles, order),
                                   rot.euler_to_matrix(angles, order, degrees=True), atol=1e-12)


def test_gimbal_lock_round_trip_is_exact_on_matrices():
    m = parse_bvh_text(SMALL.replace("10 20 30", "10 90 30").replace("5 -5 15", "5 90 15"))
    _assert_same_motion(m, parse_bvh_text(format_bvh(m)), atol=1e-6)


def test_from_arrays_template_skeleton_round_trip(tmp_path):
    rng = np.random.default_rng(7)
    T, J = 5, HUMANML3D.n_joints
    quats = rot.axis_angle_to_quat(rng.normal(0, 0.8, (T, J, 3)))
    root = rng.normal(0, 1, (T, 3))
    m = BVHMotion.from_arrays(HUMANML3D, quats, root, fps=20, rotation_order="YXZ", end_sites={"head": (0, 0.1, 0)})
    assert m.channels[0][:3] == ["Xposition", "Yposition", "Zposition"] and m.rotation_orders == ["YXZ"] * J
    expected = forward_kinematics(HUMANML3D, quats, root)
    np.testing.assert_allclose(m.global_positions(), expected, atol=1e-12)
    back = read_bvh(write_bvh(tmp_path / "template.bvh", m))
    # BVH stores joints depth-first, so the template (not depth-first) comes back reordered
    assert back.skeleton.names[:4] == ("pelvis", "left_hip", "left_knee", "left_ankle")
    idx = [back.skeleton.index(n) for n in HUMANML3D.names]
    np.testing.assert_allclose(back.global_positions()[:, idx], expected, atol=1e-5)
    np.testing.assert_allclose(back.local_rotations[:, idx], rot.quat_to_matrix(quats), atol=1e-5)
    assert [back.skeleton.names[j] for j in back.end_sites] == ["head"] and back.fps == pytest.approx(20)


def test_channel_data_recovers_the_file_values():
    m = parse_bvh_text(SMALL)
    np.testing.assert_allclose(channel_data(m), [[0, 1, 0, 10, 20, 30, 5, -5, 15],
                                                 [0.1, 1, 0, 11, 21, 31, 6, -4, 16]], atol=1e-9)


def test_zero_frames_and_tolerated_variants():
    m = parse_bvh_text(SMALL.split("Frames:")[0] + "Frames: 0\nFrame Time: 0.1\n")
    assert m.n_frames == 0 and m.global_positions().shape == (0, 2, 3)
    assert parse_bvh_text(format_bvh(m)).n_frames == 0
    variant = ("\ufeff" + SMALL.replace("Xrotation", "XROTATION").replace("End Site", "end site")
               .replace("ROOT Hips\n{", "ROOT Hips {").replace("Frames: 2", "Frames:2\n\n") + "\n\n")
    _assert_same_motion(parse_bvh_text(SMALL), parse_bvh_text(variant.encode("utf-8")), atol=0)


def test_invalid_motion_objects_are_rejected():
    m = parse_bvh_text(SMALL)
    with pytest.raises(ValueError, match="rotation order"):
        BVHMotion(m.skeleton, m.channels, ["XYZ", "ZXY"], m.local_rotations, m.positions, m.fps)
    with pytest.raises(ValueError, match="fps"):
        BVHMotion(m.skeleton, m.channels, m.rotation_orders, m.local_rotations, m.positions, 0.0)
    bad = m.positions.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        BVHMotion(m.skeleton, m.channels, m.rotation_orders, m.local_rotations, bad, m.fps)


# ---------------------------------------------------------------- malformed input
def _sub(old, new, count=1):
    assert old in SMALL
    return SMALL.replace(old, new, count)


MALFORMED = {
    "empty": ("", "empty"),
    "blank": (" \n\t\r\n", "empty"),
    "no_hierarchy": (SMALL.replace("HIERARCHY\n", ""), "HIERARCHY"),
    "no_motion": (SMALL.split("MOTION")[0], "MOTION"),
    "missing_close_brace": (_sub("    }\n  }\n}", "    }\n  }"), "brace"),
    "extra_close_brace": (_sub("}\nMOTION", "}\n}\nMOTION"), "brace"),
    "stray_open_brace": (_sub("OFFSET 0 1 0", "{ OFFSET 0 1 0"), "brace"),
    "unknown_channel": (_sub("Xrotation Yrotation", "Wrotation Yrotation"), "unknown channel"),
    "too_many_channels_declared": (_sub("CHANNELS 3", "CHANNELS 4"), "channel count"),
    "too_few_channels_declared": (_sub("CHANNELS 3", "CHANNELS 2"), "channel count"),
    "channel_count_not_a_number": (_sub("CHANNELS 3", "CHANNELS three"), "CHANNELS"),
    "duplicate_channel": (_sub("Zrotation Xrotation Yrotation", "Zrotation Xrotation Xrotation"), "duplicate"),
    "offset_non_numeric": (_sub("OFFSET 0 1 0", "OFFSET 0 one 0"), "non-numeric"),
    "offset_nan": (_sub("OFFSET 0 1 0", "OFFSET 0 nan 0"), "non-numeric"),
    "offset_missing_value": (_sub("OFFSET 0 1 0", "OFFSET 0 1"), "non-numeric"),
    "frame_value_non_numeric": (_sub("5 -5 15", "5 abc 15"), "non-numeric"),
    "frame_value_nan": (_sub("5 -5 15", "5 NaN 15"), "non-numeric"),
    "frame_value_inf": (_sub("5 -5 15", "5 inf 15"), "non-numeric"),
    "frame_value_overflow": (_sub("5 -5 15", "5 1e999 15"), "not finite"),
    "frame_value_underscore": (_sub("5 -5 15", "5 1_0 15"), "non-numeric"),
    "frame_value_arabic_digit": (_sub("5 -5 15", "5 \u0661 15"), "non-numeric"),
    "frames_non_numeric": (_sub("Frames: 2", "Frames: two"), "frame count"),
    "frames_negative": (_sub("Frames: 2", "Frames: -2"), "frame count"),
    "frames_huge": (_sub("Frames: 2", "Frames: " + "9" * 5000), "frame count"),
    "frames_line_missing": (_sub("Frames: 2\n", ""), "Frames:"),
    "frame_time_missing": (_sub("Frame Time: 0.05\n", ""), "Frame Time"),
    "frame_time_non_numeric": (_sub("Frame Time: 0.05", "Frame Time: fast"), "non-numeric"),
    "frame_time_zero": (_sub("Frame Time: 0.05", "Frame Time: 0"), "Frame Time"),
    "frame_time_negative": (_sub("Frame Time: 0.05", "Frame Time: -0.05"), "Frame Time"),
    "frame_time_inf": (_sub("Frame Time: 0.05", "Frame Time: inf"), "Frame Time"),
    "frame_time_subnormal": (_sub("Frame Time: 0.05", "Frame Time: 5e-324"), "Frame Time"),
    "fewer_rows_than_frames": (_sub("Frames: 2", "Frames: 3"), "truncated"),
    "more_rows_than_frames": (_sub("Frames: 2", "Frames: 1"), "frame count mismatch"),
    "truncated_mid_row": (SMALL[:-8], "expected 9 values, got"),
    "row_with_extra_value": (_sub("5 -5 15", "5 -5 15 16"), "line 19 (frame 1): expected 9 values, got 10"),
    "duplicate_joint_name": (_sub("JOINT Spine", "JOINT Hips"), "duplicate joint name"),
    "zero_joints": ("HIERARCHY\nMOTION\nFrames: 0\nFrame Time: 0.1\n", "zero joints"),
    "joint_without_name": (_sub("JOINT Spine", "JOINT"), "without a joint name"),
    "missing_offset": (_sub("    OFFSET 0 1 0\n", ""), "OFFSET"),
    "two_end_sites": (_sub("    End Site", "    End Site\n    {\n      OFFSET 0 0 0\n    }\n    End Site"),
                      "more than one End Site"),
    "channels_after_children": (_sub("    CHANNELS 3 Zrotation Xrotation Yrotation\n", "").replace(
        "    }\n  }", "    }\n    CHANNELS 3 Zrotation Xrotation Yrotation\n  }"), "after its children"),
    "unknown_keyword": (_sub("JOINT Spine", "BONE Spine"), "unexpected"),
    "two_roots": (_sub("}\nMOTION", "}\nROOT Other\n{\nOFFSET 0 0 0\n}\nMOTION"), "ROOT"),
    "end_without_site": (_sub("End Site", "End Sight"), "Site"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_input_raises_value_error_naming_the_source(case):
    text, fragment = MALFORMED[case]
    with pytest.raises(ValueError) as err:
        parse_bvh_text(text, source=f"{case}.bvh")
    message = str(err.value)
    assert message.startswith(f"{case}.bvh: ") and fragment.lower() in message.lower(), message
    assert isinstance(err.value, BVHError) and "internal error" not in message


def test_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "latin1.bvh"
    bad.write_bytes(SMALL.replace("Spine", "Sp\xefne").encode("latin-1"))
    with pytest.raises(ValueError, match=re.escape(str(bad)) + ".*UTF-8"):
        read_bvh(bad)
    truncated = tmp_path / "cut.bvh"
    truncated.write_text(SMALL[:-30])
    with pytest.raises(ValueError, match=re.escape(str(truncated))):
        read_bvh(truncated)
    with pytest.raises(ValueError, match="missing.bvh"):
        read_bvh(tmp_path / "missing.bvh")
    with pytest.raises(ValueError, match="missing.bvh"):
        bvh_info(tmp_path / "missing.bvh")


# ---------------------------------------------------------------- writing
def test_write_refuses_to_overwrite_and_leaves_no_temp_files(tmp_path):
    m = parse_bvh_text(SMALL)
    target = tmp_path / "clip.bvh"
    write_bvh(target, m)
    first = target.read_bytes()
    with pytest.raises(ValueError, match=re.escape(str(target)) + ".*overwrite"):
        write_bvh(target, m)
    assert target.read_bytes() == first
    m.positions[:, 0, 0] += 1
    write_bvh(target, m, overwrite=True, precision=3)
    assert read_bvh(target).root_positions[0, 0] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="precision"):
        write_bvh(tmp_path / "other.bvh", m, precision=-1)
    with pytest.raises(ValueError, match="does not exist"):
        write_bvh(tmp_path / "no_such_folder" / "x.bvh", m)
    with pytest.raises(ValueError, match="directory"):
        write_bvh(tmp_path, m, overwrite=True)
    odd = BVHMotion(Skeleton(("root", "a{b"), (-1, 0), np.zeros((2, 3))), m.channels, m.rotation_orders,
                    m.local_rotations, m.positions, m.fps)
    with pytest.raises(ValueError, match="a{b"):
        write_bvh(tmp_path / "odd.bvh", odd)
    assert os.listdir(tmp_path) == ["clip.bvh"]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask


def test_info_of_synthetic_file(tmp_path):
    path = tmp_path / "odd.bvh"
    path.write_text(_synthetic_bvh(SYNTHETIC["odd_channels"], n_frames=50)[0])
    info = bvh_info(path)
    assert json.loads(json.dumps(info)) == info
    assert info["n_frames"] == 50 and info["fps"] == pytest.approx(25) and info["duration_s"] == pytest.approx(2)
    assert info["channels_per_joint"] == {"hips": 6, "six": 6, "none": 0, "two": 2, "slide": 1, "left": 3}
    assert info["total_channels"] == 18 and info["n_end_sites"] == 3
    assert info["rotation_orders"] == ["XZY", "YXZ", "ZYX"]


def test_parse_speed_of_a_long_clip():
    rng = np.random.default_rng(0)
    motion = BVHMotion.from_arrays(HUMANML3D.scaled(100), rot.axis_angle_to_quat(rng.normal(0, 0.5, (100, 22, 3))),
                                   rng.normal(0, 50, (100, 3)), fps=120)
    header, rows = format_bvh(motion).split("Frame Time: ")
    rows = rows.split("\n", 1)[1] * 50  # 5000 frames of 69 channels
    text = header.replace("Frames: 100", "Frames: 5000") + "Frame Time: 0.008333333333\n" + rows
    start = time.perf_counter()
    back = parse_bvh_text(text)
    elapsed = time.perf_counter() - start
    assert back.n_frames == 5000 and elapsed < 2.0, f"parsing 5000 frames took {elapsed:.2f} s"
    first = parse_bvh_text(format_bvh(motion)).global_positions()[0]
    np.testing.assert_allclose(back.global_positions()[4100], first, atol=1e-12)


# ---------------------------------------------------------------- fuzzing
_PIECES = re.split(r"(\s+)", SMALL)
_VOCAB = ["HIERARCHY", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "MOTION", "Frames:", "Frame",
          "Time:", "{", "}", "Xrotation", "Yposition", "Qrotation", "0", "-1", "3", "6", "7", "1e999", "nan",
          "-inf", "0.0", "1_0", "\u0661", "0x10", "", "abc", "\x00", "9" * 30, "\n", "\r", "\ufeff", "é"]
_JUNK = "{}\n\r\t 0123456789.-+eE_:aZ\x00\x0b\x1c\x85é\u0661\u2028\ufeff"


def _mutated_bvh(seed: int):
    """The small valid BVH after 1-4 random token edits, truncations or junk insertions (20 % as bytes)."""
    rnd = random.Random(seed)
    pieces = list(_PIECES)
    for _ in range(rnd.randint(1, 4)):
        op = rnd.choice(["delete", "duplicate", "replace", "swap", "count", "truncate", "junk"])
        i = rnd.randrange(len(pieces))
        if op == "delete" and len(pieces) > 1:
            del pieces[i]
        elif op == "duplicate":
            pieces.insert(i, pieces[i])
        elif op == "replace":
            pieces[i] = rnd.choice(_VOCAB)
        elif op == "swap":
            k = rnd.randrange(len(pieces))
            pieces[i], pieces[k] = pieces[k], pieces[i]
        elif op == "count":
            pieces[i] = str(rnd.randint(-3, 12))
        elif op in ("truncate", "junk"):
            text = "".join(pieces)
            cut = rnd.randint(0, len(text))
            junk = "".join(rnd.choice(_JUNK) for _ in range(rnd.randint(1, 6)))
            text = text[:cut] + junk + text[cut:] if op == "junk" else text[:cut]
            pieces = re.split(r"(\s+)", text) if text else [""]
    text = "".join(pieces)
    if rnd.random() < 0.2:
        raw = bytearray(text.encode("utf-8"))
        if rnd.random() < 0.5:  # sometimes break the UTF-8
            raw.insert(rnd.randint(0, len(raw)), rnd.choice([0x80, 0xC3, 0xFF, 0xE2]))
        return bytes(raw)
    return text


_RANDOM_INPUTS = st.one_of(st.text(max_size=80), st.binary(max_size=80),
                           st.text(max_size=80).map(lambda s: "HIERARCHY\nROOT a\n{\n" + s))


def _check_parse_or_value_error(data):
    """Parsing either succeeds (and the motion can be written and read back) or raises ValueError."""
    try:
        motion = parse_bvh_text(data, source="fuzz.bvh")
    except ValueError as e:
        assert str(e).startswith("fuzz.bvh: ") and "internal error" not in str(e), str(e)
        return
    assert motion.local_rotations.shape == (motion.n_frames, motion.n_joints, 3, 3)
    again = parse_bvh_text(format_bvh(motion))
    assert again.skeleton.names == motion.skeleton.names and again.n_frames == motion.n_frames


@settings(max_examples=600, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much])
@given(seed=st.integers(0, 2**64), random_input=_RANDOM_INPUTS)
def test_fuzz_parse_succeeds_or_raises_value_error(seed, random_input):
    # 600 examples × (3 mutations of the valid BVH + 1 random text/bytes) = 2,400 inputs, in a few seconds
    for k in range(3):
        data = _mutated_bvh(seed * 3 + k)
        note(f"mutation {k}: {data!r}")
        _check_parse_or_value_error(data)
    _check_parse_or_value_error(random_input)
