"""The HumanML3D template and forward kinematics."""
import numpy as np
import pytest
import torch

from mslib.motion import rotations as rot
from mslib.motion import skeleton as sk


def test_template_facts():
    s = sk.HUMANML3D
    assert s.n_joints == 22 and s.parents == (-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19)
    np.testing.assert_allclose(s.bone_lengths()[1:], sk.REFERENCE_BONE_LENGTHS)
    rest = s.rest_positions()
    assert rest[1, 0] > 0 > rest[2, 0]           # left hip at +X
    assert rest[12, 1] > rest[9, 1] > rest[0, 1]   # neck above chest above pelvis
    assert rest[15, 2] > rest[12, 2]              # the head offset points forward (+Z) in the rest pose
    assert rest[10, 2] > rest[7, 2]              # feet point forward (+Z)
    for chain in sk.KINEMATIC_CHAINS:
        for a, b in zip(chain[:-1], chain[1:]):
            assert s.parents[b] == a


def test_mirror_table_is_an_involution_that_swaps_sides():
    m = np.array(sk.MIRROR)
    assert (m[m] == np.arange(22)).all()
    for i, name in enumerate(sk.JOINT_NAMES):
        other = sk.JOINT_NAMES[m[i]]
        assert other == name.replace("left", "#").replace("right", "left").replace("#", "right")


def test_fk_known_answer_and_batching():
    s = sk.HUMANML3D
    R = np.broadcast_to(np.eye(3), (4, 22, 3, 3)).copy()
    R[:, 0] = rot.axis_angle_to_matrix(np.array([0, np.pi / 2, 0]))  # turn the body 90° about Y
    root = np.array([[0, 1.0, 0]] * 4)
    p = sk.forward_kinematics(s, R, root)
    assert p.shape == (4, 22, 3)
    # the left hip offset (+X · 0.1031) turns to −Z
    np.testing.assert_allclose(p[0, 1], [0, 1, -sk.REFERENCE_BONE_LENGTHS[0]], atol=1e-12)
    # bone lengths are kept under any rotation
    Rr = rot.axis_angle_to_matrix(np.random.default_rng(1).normal(size=(3, 22, 3)))
    pr = sk.forward_kinematics(s, Rr, np.zeros((3, 3)))
    np.testing.assert_allclose(sk.positions_bone_lengths(pr, s.parents)[:, 1:],
                               np.broadcast_to(sk.REFERENCE_BONE_LENGTHS, (3, 21)), atol=1e-12)


def test_fk_torch_matches_numpy_and_accepts_quaternions():
    s = sk.HUMANML3D
    q = rot.normalize(np.random.default_rng(2).normal(size=(5, 22, 4)))
    root = np.random.default_rng(3).normal(size=(5, 3))
    p_np = sk.forward_kinematics(s, q, root)
    p_t = sk.forward_kinematics(s, torch.as_tensor(q), torch.as_tensor(root))
    np.testing.assert_allclose(p_t.numpy(), p_np, atol=1e-12)
    p_m = sk.forward_kinematics(s, rot.quat_to_matrix(q), root)
    np.testing.assert_allclose(p_m, p_np, atol=1e-12)


def test_bad_skeletons_and_shapes():
    with pytest.raises(ValueError, match="parent"):
        sk.Skeleton(("a", "b"), (-1, 1), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="offsets"):
        sk.Skeleton(("a", "b"), (-1, 0), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="local_rotations"):
        sk.forward_kinematics(sk.HUMANML3D, np.zeros((2, 21, 4)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="bone_lengths"):
        sk.humanml3d_skeleton(np.ones(20))


def test_mirror_positions_twice_is_identity():
    p = np.random.default_rng(4).normal(size=(3, 22, 3))
    np.testing.assert_array_equal(sk.mirror_positions(sk.mirror_positions(p)), p)
    assert sk.mirror_positions(p)[0, 1, 0] == -p[0, 2, 0]
