"""motion/ik.py: joint positions → local rotations on the template tree, and the BVH it writes."""
import numpy as np
import pytest

from mslib.motion import rotations as rot
from mslib.motion.bvh import parse_bvh_text, format_bvh
from mslib.motion.ik import fit_error, fit_offsets, kabsch, positions_to_bvh, solve_rotations
from mslib.motion.skeleton import HUMANML3D, JOINT_NAMES, PARENTS, forward_kinematics


def random_motion(T=12, seed=0, offsets=None):
    """FK of random local rotations (up to ~50°) on a body with non-template branching offsets."""
    rng = np.random.default_rng(seed)
    aa = rng.normal(scale=0.5, size=(T, 22, 3))
    R = rot.axis_angle_to_matrix(aa)
    root = rng.normal(size=(T, 3))
    off = HUMANML3D.offsets.copy() if offsets is None else offsets
    return forward_kinematics(HUMANML3D, R, root, offsets=off), R


def test_kabsch_recovers_a_rotation():
    rng = np.random.default_rng(1)
    rest = rng.normal(size=(3, 3))
    R = rot.axis_angle_to_matrix(rng.normal(size=(5, 3)))
    np.testing.assert_allclose(kabsch(rest, np.einsum("tij,kj->tki", R, rest)), R, atol=1e-9)


def test_rigid_motion_is_reproduced_exactly():
    off = HUMANML3D.offsets.copy()
    off[[1, 2]] += [[0, -0.08, 0.01], [0, -0.08, 0.01]]  # SMPL-like hips: below and in front of the pelvis
    off[[13, 14]] += [[0, 0.05, -0.02], [0, 0.05, -0.02]]
    p, _ = random_motion(offsets=off)
    m = positions_to_bvh(p)
    assert fit_error(m, p) < 1e-9
    # the fitted rest offsets have the body's bone lengths
    np.testing.assert_allclose(np.linalg.norm(fit_offsets(p), axis=-1), np.linalg.norm(off, axis=-1), atol=1e-9)


def test_single_child_joints_add_no_twist():
    p, _ = random_motion()
    local = solve_rotations(p, fit_offsets(p))
    knee = JOINT_NAMES.index("left_knee")  # one child: the shortest arc, so its axis ⟂ the rest bone
    axis = rot.matrix_to_axis_angle(local[:, knee])
    assert np.abs(axis @ HUMANML3D.offsets[JOINT_NAMES.index("left_ankle")]).max() < 1e-9
    np.testing.assert_allclose(local[:, JOINT_NAMES.index("head")], np.broadcast_to(np.eye(3), (len(p), 3, 3)))


def test_units_and_text_round_trip():
    p, _ = random_motion(T=5)
    for units, scale in (("m", 1.0), ("cm", 100.0)):
        m = positions_to_bvh(p, units=units)
        back = parse_bvh_text(format_bvh(m))
        got = back.global_positions()[:, [back.skeleton.names.index(n) for n in JOINT_NAMES]]
        assert np.abs(got / scale - p).max() < 1e-4 and back.fps == 20
    assert list(back.skeleton.parents) != list(PARENTS)  # written depth-first: map joints by name


def test_stretching_bones_leave_a_reported_residual():
    p, _ = random_motion()
    p = p.copy()
    p[::2, 7] += 0.02 * (p[::2, 7] - p[::2, 4])  # the left shin 2 % longer every other frame
    m = positions_to_bvh(p)
    assert 1e-4 < fit_error(m, p) < 0.02


def test_bad_input():
    with pytest.raises(ValueError, match="units"):
        positions_to_bvh(np.zeros((3, 22, 3)), units="inch")
    with pytest.raises(ValueError, match="shape"):
        positions_to_bvh(np.zeros((3, 21, 3)))
