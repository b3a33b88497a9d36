"""Registration (A §3.1): joint maps by dialect and `auto`, axes, units, fps, canonical frame, windows."""
import numpy as np
import pytest

from mslib.data import joint_maps as JM
from mslib.data import retarget as R
from mslib.motion import features as F
from mslib.motion import rotations as rot
from mslib.motion import skeleton as sk
from mslib.motion.bvh import BVHMotion, format_bvh, parse_bvh_text, read_bvh
from tests.test_features import synthetic_motion

CONVENTIONS = {
    # template joint → a name in that convention (same tree as the template)
    "mixamo": ["mixamorig:Hips", "mixamorig:LeftUpLeg", "mixamorig:RightUpLeg", "mixamorig:Spine",
               "mixamorig:LeftLeg", "mixamorig:RightLeg", "mixamorig:Spine1", "mixamorig:LeftFoot",
               "mixamorig:RightFoot", "mixamorig:Spine2", "mixamorig:LeftToeBase", "mixamorig:RightToeBase",
               "mixamorig:Neck", "mixamorig:LeftShoulder", "mixamorig:RightShoulder", "mixamorig:Head",
               "mixamorig:LeftArm", "mixamorig:RightArm", "mixamorig:LeftForeArm", "mixamorig:RightForeArm",
               "mixamorig:LeftHand", "mixamorig:RightHand"],
    # 100STYLE-like: 'Hip' is the thigh and 'Shoulder' the upper arm
    "style100": ["Hips", "LeftHip", "RightHip", "Chest", "LeftKnee", "RightKnee", "Chest2", "LeftAnkle",
                 "RightAnkle", "Chest3", "LeftToe", "RightToe", "Neck", "LeftCollar", "RightCollar", "Head",
                 "LeftShoulder", "RightShoulder", "LeftElbow", "RightElbow", "LeftWrist", "RightWrist"],
    # Blender-like suffix markers
    "blender": ["pelvis", "thigh.L", "thigh.R", "spine", "shin.L", "shin.R", "chest", "foot.L", "foot.R",
                "upper_chest", "toe.L", "toe.R", "neck", "clavicle.L", "clavicle.R", "head", "upper_arm.L",
                "upper_arm.R", "forearm.L", "forearm.R", "hand.L", "hand.R"],
    # 3ds Max biped-like infix markers
    "biped": ["Bip01_Pelvis", "Bip01_L_Thigh", "Bip01_R_Thigh", "Bip01_Spine", "Bip01_L_Calf",
              "Bip01_R_Calf", "Bip01_Spine1", "Bip01_L_Foot", "Bip01_R_Foot", "Bip01_Spine2",
              "Bip01_L_Toe0", "Bip01_R_Toe0", "Bip01_Neck", "Bip01_L_Clavicle", "Bip01_R_Clavicle",
              "Bip01_Head", "Bip01_L_UpperArm", "Bip01_R_UpperArm", "Bip01_L_Forearm", "Bip01_R_Forearm",
              "Bip01_L_Hand", "Bip01_R_Hand"],
}


def template_take(T=45, seed=0):
    """A template motion with its local rotations (FK), canonical, as ground truth."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, T)[:, None, None]
    aa = 0.35 * np.sin(2 * np.pi * (t * rng.uniform(0.5, 2, (1, 22, 3)) + rng.uniform(0, 1, (1, 22, 3))))
    aa[:, 0] = [0, 0.3, 0]
    root = np.stack([0.2 * t[:, 0, 0], 0.95 + 0 * t[:, 0, 0], 1.0 * t[:, 0, 0]], -1)
    return rot.axis_angle_to_matrix(aa), root


def as_bvh(names, local, root, fps=20.0, scale=1.0, up="y", body=1.0):
    """The template take written on a renamed skeleton, in other units/up axis/body size."""
    offsets, root = sk.HUMANML3D.offsets * scale * body, root * scale * body
    if up == "z":  # turn the whole world, rest pose included, so that +Y becomes +Z
        q = rot.quat_to_matrix(rot.quat_between(np.array([0, 1.0, 0]), np.array([0, 0, 1.0])))
        offsets, local, root = offsets @ q.T, q @ local @ q.T, root @ q.T
    skel = sk.Skeleton(tuple(names), sk.PARENTS, offsets)
    return BVHMotion.from_arrays(skel, local, root, fps)


def truth(local, root):
    return R.canonicalize(sk.forward_kinematics(sk.HUMANML3D, local, root))


@pytest.mark.parametrize("convention", sorted(CONVENTIONS))
def test_auto_maps_every_convention_and_recovers_the_motion(convention):
    local, root = template_take()
    motion = as_bvh(CONVENTIONS[convention], local, root, scale=100.0, up="z", body=1.07)
    jmap = JM.auto_joint_map(motion.skeleton)
    assert list(jmap.values()) == CONVENTIONS[convention]
    reg = R.register_motion(motion, "auto")
    assert reg.info["up"] == "z"
    np.testing.assert_allclose(reg.positions, truth(local, root), atol=1e-4)  # cm, Z up, 7% taller: undone


def test_fps_resampling_slerps_rotations():
    local, root = template_take(T=91)
    at60 = as_bvh(sk.JOINT_NAMES, local, root, fps=60.0)
    reg = R.register_motion(at60, {n: n for n in sk.JOINT_NAMES})
    assert reg.fps == 20 and len(reg.positions) == 31  # frames 0, 3, 6, …, 90
    want = truth(local[::3], root[::3])
    np.testing.assert_allclose(reg.positions, want, atol=1e-4)
    # 30 → 20 fps lands between source frames: slerp keeps bone lengths exactly
    at30 = R.resample(as_bvh(sk.JOINT_NAMES, local, root, fps=30.0), 20)
    bones = sk.positions_bone_lengths(at30.global_positions(), sk.PARENTS)[:, 1:]
    np.testing.assert_allclose(bones, np.broadcast_to(sk.REFERENCE_BONE_LENGTHS, bones.shape), atol=1e-9)
    assert at30.n_frames == 61


def test_canonical_frame_floor_origin_facing():
    p = R.canonicalize(synthetic_motion(T=40) @ rot.axis_angle_to_matrix(np.array([0, 2.0, 0])).T + [3, 0.2, -1])
    assert abs(p[..., 1].min()) < 1e-12
    np.testing.assert_allclose(p[0, 0, [0, 2]], 0, atol=1e-12)
    np.testing.assert_allclose(R.facing_direction(p[0]), [0, 0, 1], atol=1e-9)
    assert p[0, 1, 0] > p[0, 2, 0]  # left hip on +X


def test_mirror_twice_is_identity():
    local, root = template_take()
    motion = as_bvh(sk.JOINT_NAMES, local, root)
    jmap = {n: n for n in sk.JOINT_NAMES}
    plain = R.register_motion(motion, jmap).positions
    once = R.register_motion(motion, jmap, mirror=True).positions
    twice = R.canonicalize(sk.mirror_positions(once))
    np.testing.assert_allclose(twice, plain, atol=1e-5)
    assert not np.allclose(once, plain, atol=1e-3)


def test_windows_32_frames_8_overlap():
    assert R.window_starts(32) == [0]
    assert R.window_starts(80) == [0, 24, 48]
    assert R.window_starts(31) == []
    wins = R.cut_windows(synthetic_motion(T=80))
    assert len(wins) == 3 and all(w.shape == (32, 22, 3) for w in wins)
    np.testing.assert_allclose(wins[1][0, 0, [0, 2]], 0, atol=1e-12)
    with pytest.raises(ValueError, match="overlap"):
        R.window_starts(50, 8, 8)


def test_auto_failure_lists_the_unmapped_joints():
    names = list(CONVENTIONS["mixamo"])
    names = [n.replace("Foot", "Paw").replace("Toe", "Claw") for n in names]
    skel = sk.Skeleton(tuple(n.replace("mixamorig:", "") for n in names), sk.PARENTS, sk.HUMANML3D.offsets)
    with pytest.raises(ValueError, match=r"could not map template joints \[.*left_ankle.*\]"):
        JM.auto_joint_map(skel, "weird.bvh")
    with pytest.raises(ValueError, match="unknown 'nope'"):
        JM.resolve_joint_map(skel, "nope")
    with pytest.raises(ValueError, match="not in the file"):
        JM.resolve_joint_map(skel, "xia")


def test_side_and_part_rules():
    assert JM.joint_side("LHipJoint") == "left" and JM.joint_side("RThumb") == "right"
    assert JM.joint_side("LowerBack") is None and JM.joint_side("Hips") is None
    assert JM.joint_side("hand_r") == "right" and JM.joint_side("Bip01 L Foot") == "left"
    assert JM.joint_part("LeftForeArm") == "forearm" and JM.joint_part("LeftArm") == "upperarm"
    assert JM.joint_part("LeftUpLeg") == "upleg" and JM.joint_part("LeftLeg") == "knee"
    assert JM.joint_part("LeftHandIndex1") == "finger" and JM.joint_part("LeftToeBase") == "toe"


# ---------------------------------------------------------------- real data (../shared/data)
def xia_files(shared_data):
    files = sorted((shared_data / "xia_grid").glob("*.bvh"))
    assert len(files) == 40
    return files


@pytest.mark.parametrize("dialect", ["auto", "xia"])
def test_xia_grid_registers(shared_data, dialect):
    for f in xia_files(shared_data):
        reg = R.register_bvh(f, dialect)
        p = reg.positions.astype(np.float64)
        assert reg.fps == 20 and reg.features.shape == (len(p) - 1, 263)
        bones = sk.positions_bone_lengths(p, sk.PARENTS)[:, 1:]
        assert np.abs(bones - sk.REFERENCE_BONE_LENGTHS).max() <= 1e-4, f.name
        lower_foot = np.minimum(p[:, [7, 10], 1].min(1), p[:, [8, 11], 1].min(1))
        assert abs(np.percentile(lower_foot, 5)) <= 0.02, f.name
        fwd = R.facing_direction(p[0])
        assert np.degrees(np.arccos(np.clip(fwd[2], -1, 1))) <= 10, f.name
        if "_01_" in f.name:  # walks move forward at a human pace
            speed = np.linalg.norm(np.diff(p[:, 0, [0, 2]], axis=0), axis=-1).sum() / ((len(p) - 1) / 20)
            assert 0.4 <= speed <= 2.5, (f.name, speed)
        np.testing.assert_allclose(F.decode(reg.features.astype(np.float64)), p[:-1], atol=1e-4)


def test_xia_auto_equals_named_dialect(shared_data):
    skel = read_bvh(xia_files(shared_data)[0]).skeleton
    assert JM.auto_joint_map(skel) == JM.resolve_joint_map(skel, "xia")


def test_xia_mirror_twice_is_identity(shared_data):
    f = xia_files(shared_data)[0]
    plain = R.register_bvh(f).positions
    twice = R.canonicalize(sk.mirror_positions(R.register_bvh(f, mirror=True).positions))
    np.testing.assert_allclose(twice, plain, atol=1e-5)


def test_registration_survives_a_bvh_round_trip(shared_data):
    f = xia_files(shared_data)[3]
    motion = read_bvh(f)
    again = parse_bvh_text(format_bvh(motion), "again.bvh")
    np.testing.assert_allclose(R.register_motion(again).positions, R.register_motion(motion).positions, atol=1e-4)


def test_builtin_takes_come_back_through_registration():
    """Registered built-in BVH takes match the generator's truth (on the reference body)."""
    from mslib.data.mocap_skeleton import to_bvh_motion
    from mslib.data.styles import STYLE_CONTENTS, STYLES
    from mslib.data.synth import generate_clip, resample

    for i, (content, style) in enumerate([(c, s) for c in STYLE_CONTENTS for s in STYLES[::3]]):
        take = generate_clip(content, style, seed=3, index=i, fps=30.0, canonical=False)
        text = format_bvh(to_bvh_motion(take.rotations, take.root, take.skeleton))
        for dialect in ("builtin", "auto"):
            reg = R.register_motion(parse_bvh_text(text, "take.bvh"), dialect).positions
            truth = R.canonicalize(R.rescale_to_reference(resample(take, 20).positions))
            n = min(len(reg), len(truth))
            a, b = reg[:n] - reg[:n, :1], truth[:n] - truth[:n, :1]
            assert np.linalg.norm(a - b, axis=-1).mean() <= 0.02, (content, style)
            agree = (F.foot_contacts(reg[:n]) == F.foot_contacts(truth[:n])).mean()
            assert agree >= 0.95, (content, style, agree)
