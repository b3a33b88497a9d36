"""Rotation conversions: round trips, known answers, scipy agreement, numpy ↔ torch agreement."""
import itertools

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from mslib.motion import rotations as rot

RNG = np.random.default_rng(0)
QUATS = rot.normalize(RNG.normal(size=(5, 7, 4)))
ORDERS = ["".join(p) for p in itertools.permutations("XYZ")]


def both(x):
    """The same values as numpy and as a float64 tensor."""
    return [x, torch.as_tensor(x)]


def as_np(x):
    return x.numpy() if isinstance(x, torch.Tensor) else x


def same_rotation(q1, q2, atol=1e-9):
    """Quaternions equal up to sign."""
    q1, q2 = as_np(q1), as_np(q2)
    return np.allclose(np.abs((q1 * q2).sum(-1)), 1.0, atol=atol)


@pytest.mark.parametrize("q", both(QUATS))
def test_quat_matrix_round_trip_and_scipy(q):
    m = rot.quat_to_matrix(q)
    assert m.shape == (5, 7, 3, 3)
    ref = Rotation.from_quat(as_np(q).reshape(-1, 4)[:, [1, 2, 3, 0]]).as_matrix().reshape(5, 7, 3, 3)
    np.testing.assert_allclose(as_np(m), ref, atol=1e-12)
    assert same_rotation(rot.matrix_to_quat(m), q)


def test_matrix_to_quat_handles_every_branch():
    # 180° turns about each axis exercise the non-trace branches of Shepperd's method
    for aa in [[np.pi, 0, 0], [0, np.pi, 0], [0, 0, np.pi], [0, 0, 0], [2.5, -1.0, 0.3]]:
        m = Rotation.from_rotvec(aa).as_matrix()
        for x in both(m):
            q = as_np(rot.matrix_to_quat(x))
            np.testing.assert_allclose(as_np(rot.quat_to_matrix(q)), m, atol=1e-12)


@pytest.mark.parametrize("q", both(QUATS))
def test_rotate_matches_matrix(q):
    v = RNG.normal(size=(5, 7, 3))
    v = torch.as_tensor(v) if isinstance(q, torch.Tensor) else v
    via_q = as_np(rot.quat_rotate(q, v))
    via_m = as_np((rot.quat_to_matrix(q) @ v[..., None])[..., 0])
    np.testing.assert_allclose(via_q, via_m, atol=1e-12)


def test_quat_mul_composes_like_matrices():
    a, b = QUATS[0], QUATS[1]
    np.testing.assert_allclose(rot.quat_to_matrix(rot.quat_mul(a, b)),
                               rot.quat_to_matrix(a) @ rot.quat_to_matrix(b), atol=1e-12)
    ident = rot.quat_mul(a, rot.quat_inv(a))
    np.testing.assert_allclose(np.abs(ident[..., 0]), 1, atol=1e-12)


def test_known_answer_z_quarter_turn():
    q = rot.axis_angle_to_quat(np.array([0, 0, np.pi / 2]))
    np.testing.assert_allclose(rot.quat_rotate(q, np.array([1.0, 0, 0])), [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize("q", both(QUATS))
def test_6d_round_trip_and_layout(q):
    d6 = rot.quat_to_6d(q)
    m = as_np(rot.quat_to_matrix(q))
    np.testing.assert_allclose(as_np(d6)[..., :3], m[..., :, 0], atol=1e-12)  # column 0 first
    np.testing.assert_allclose(as_np(d6)[..., 3:], m[..., :, 1], atol=1e-12)
    assert same_rotation(rot.sixd_to_quat(d6), q)
    # Gram–Schmidt also repairs a perturbed 6-D vector into a proper rotation
    noisy = as_np(d6) + 0.05 * RNG.normal(size=d6.shape)
    r = rot.sixd_to_matrix(noisy)
    np.testing.assert_allclose(np.linalg.det(r), 1, atol=1e-9)


@pytest.mark.parametrize("aa", both(np.concatenate([RNG.normal(size=(20, 3)), np.zeros((1, 3)), [[1e-9, 0, 0]]])))
def test_axis_angle_round_trip_and_scipy(aa):
    m = rot.axis_angle_to_matrix(aa)
    np.testing.assert_allclose(as_np(m), Rotation.from_rotvec(as_np(aa)).as_matrix(), atol=1e-12)
    back = as_np(rot.matrix_to_axis_angle(m))
    np.testing.assert_allclose(Rotation.from_rotvec(back).as_matrix(), as_np(m), atol=1e-9)


@pytest.mark.parametrize("order", ORDERS)
def test_euler_any_order_numpy_and_torch(order):
    angles = RNG.uniform(-80, 80, size=(10, 3))
    ref = Rotation.from_euler(order, angles, degrees=True).as_matrix()
    np.testing.assert_allclose(rot.euler_to_matrix(angles, order, degrees=True), ref, atol=1e-12)
    mt = rot.euler_to_matrix(torch.as_tensor(angles), order, degrees=True)
    np.testing.assert_allclose(mt.numpy(), ref, atol=1e-12)
    # intrinsic: "ZYX" composes as Rz · Ry · Rx
    a = np.deg2rad(angles[0])
    prod = np.eye(3)
    for axis, ang in zip(order, a):
        prod = prod @ Rotation.from_euler(axis, ang).as_matrix()
    np.testing.assert_allclose(ref[0], prod, atol=1e-12)
    for m in both(ref):
        back = as_np(rot.matrix_to_euler(m, order, degrees=True))
        np.testing.assert_allclose(back, angles, atol=1e-8)


def test_bad_input_names_the_problem():
    with pytest.raises(ValueError, match="order"):
        rot.euler_to_matrix(np.zeros(3), "XXY")
    with pytest.raises(ValueError, match="quat_to_matrix"):
        rot.quat_to_matrix(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="sixd_to_matrix"):
        rot.sixd_to_matrix(np.zeros((2, 5)))


def test_quat_between_including_opposite():
    u = rot.normalize(RNG.normal(size=(50, 3)))
    v = rot.normalize(RNG.normal(size=(50, 3)))
    v[0] = -u[0]
    v[1] = u[1]
    for uu, vv in (both(u)[0], both(v)[0]), (both(u)[1], both(v)[1]):
        q = rot.quat_between(uu, vv)
        np.testing.assert_allclose(as_np(rot.quat_rotate(q, uu)), as_np(vv), atol=1e-9)


def test_quat_fix_and_slerp():
    q = np.tile(QUATS[0, 0], (6, 1))
    q[[1, 3]] *= -1
    fixed = rot.quat_fix(q)
    assert ((fixed * fixed[0]).sum(-1) > 0).all()
    a = rot.axis_angle_to_quat(np.array([0, 0.0, 0]))
    b = rot.axis_angle_to_quat(np.array([0, 1.0, 0]))
    mid = rot.quat_slerp(a, b, 0.25)
    np.testing.assert_allclose(rot.quat_to_axis_angle(mid), [0, 0.25, 0], atol=1e-12)
    mid_t = rot.quat_slerp(torch.as_tensor(a), torch.as_tensor(b), 0.25)
    np.testing.assert_allclose(mid_t.numpy(), mid, atol=1e-12)


def test_torch_gradients_flow():
    aa = torch.tensor([[0.3, -0.2, 0.5]], requires_grad=True)
    m = rot.axis_angle_to_matrix(aa)
    rot.matrix_to_6d(m).sum().backward()
    assert torch.isfinite(aa.grad).all() and aa.grad.abs().sum() > 0
