"""The 263-d HumanML3D vector: the real release sample is the spec; round trips; normaliser; bad input."""
import numpy as np
import pytest
import torch

from mslib.motion import features as F
from mslib.motion import rotations as rot
from mslib.motion import skeleton as sk


def synthetic_motion(T=60, seed=0):
    """A moving, turning FK motion on the template with the frame-0 root XZ at the origin."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, T)[:, None, None]
    aa = 0.4 * np.sin(2 * np.pi * (t * rng.uniform(0.5, 2, (1, 22, 3)) + rng.uniform(0, 1, (1, 22, 3))))
    aa[:, 0] = 0
    aa[:, 0, 1] = 1.5 * t[:, 0, 0]  # the body turns about Y while it walks
    root = np.stack([0.8 * t[:, 0, 0], 0.9 + 0.03 * np.sin(8 * t[:, 0, 0]), 1.2 * t[:, 0, 0] ** 2], -1)
    return sk.forward_kinematics(sk.HUMANML3D, rot.axis_angle_to_matrix(aa), root)


def test_decode_reproduces_release_positions(shared_data):
    vec = np.load(shared_data / "humanml3d/new_joint_vecs/012314.npy")
    joints = np.load(shared_data / "humanml3d/new_joints/012314.npy")
    assert np.abs(F.decode(vec) - joints).max() <= 1e-4
    assert np.abs(F.decode(torch.as_tensor(vec)).numpy() - joints).max() <= 1e-4


def test_encode_reproduces_release_vector(shared_data):
    vec = np.load(shared_data / "humanml3d/new_joint_vecs/012314.npy")
    joints = np.load(shared_data / "humanml3d/new_joints/012314.npy")
    enc = F.encode(joints)
    assert enc.shape == (len(joints) - 1, 263) and enc.dtype == np.float32
    for name, sl in F.BLOCKS.items():  # every block over the first 100 rows (the release's smoothing edge)
        err = np.abs(enc[:100, sl] - vec[:100, sl]).max()
        assert err <= 1e-4, f"block {name}: max abs error {err}"
    np.testing.assert_array_equal(enc[:, F.BLOCKS["contacts"]], vec[: len(enc), F.BLOCKS["contacts"]])


def test_real_vectors_decode_to_the_reference_body(shared_data):
    for f in sorted((shared_data / "humanml3d_format").glob("*.npy")):
        p = F.decode(np.load(f))
        bones = sk.positions_bone_lengths(p, sk.PARENTS)[:, 1:]
        assert np.abs(bones - sk.REFERENCE_BONE_LENGTHS).max() < 1e-3, f.name
        assert abs(p[:, [7, 8, 10, 11], 1].min()) < 0.02, f.name  # feet reach the floor


def test_round_trip_on_a_turning_motion():
    p = synthetic_motion()
    feats = F.encode(p)
    np.testing.assert_allclose(F.decode(feats.astype(np.float64)), p[:-1], atol=1e-5)
    # rotations in the vector rebuild the bone directions through the per-chain convention
    quats = rot.sixd_to_quat(feats[:, F.BLOCKS["rot6d"]].reshape(-1, 21, 6).astype(np.float64))
    r_rot = F.root_rotations(p)[:-1]
    for chain in sk.KINEMATIC_CHAINS:
        R = r_rot
        for a, b in zip(chain[:-1], chain[1:]):
            R = rot.quat_mul(R, quats[:, b - 1])
            bone = rot.quat_rotate(rot.quat_inv(r_rot), rot.quat_rotate(R, np.broadcast_to(sk.REST_DIRECTIONS[b], (len(R), 3))))
            want = rot.normalize(rot.quat_rotate(rot.quat_inv(r_rot), p[:-1, b] - p[:-1, a]))
            np.testing.assert_allclose(bone, want, atol=1e-4)


def test_facing_exactly_backward_is_a_half_turn_about_y():
    # a body facing −Z exactly: quat_between's fallback for opposite directions picks a horizontal axis, which
    # tipped the root over and zeroed the yaw step (a built-in turning walk drifted 2 cm from its own features)
    a, b, c, d = F.FACE_JOINTS
    p = np.zeros((6, 22, 3))
    for k, x in ((a, 1.0), (b, -1.0), (c, 1.0), (d, -1.0)):  # hips and shoulders 1e-5 rad off the X axis
        p[:, k, 0], p[:, k, 2] = x * 0.1, x * 0.1 * 1e-5
    forward = np.cross([0.0, 1.0, 0.0], (p[0, a] - p[0, b]) + (p[0, c] - p[0, d]))
    if forward[2] > 0:  # make the body face −Z whatever the sign convention of the face joints
        p[..., 0] *= -1
    q = F.root_rotations(p)
    np.testing.assert_allclose(np.abs(q[1:]), np.broadcast_to([0.0, 0.0, 1.0, 0.0], (5, 4)), atol=1e-9)
    from mslib.data.batch_features import _root_rotations  # the corpora's batched encoder agrees
    np.testing.assert_allclose(_root_rotations(p[None])[0], q, atol=1e-12)


def test_invariances_and_known_answers():
    p = synthetic_motion(seed=1)
    feats = F.encode(p)
    # a 1 m step along X: the root velocity block doesn't care, the ric block doesn't either
    moved = p + np.array([1.0, 0, 0])
    np.testing.assert_allclose(F.encode(moved), feats, atol=1e-5)
    # standing still: zero velocities, all four contacts on; only row 0 turns, since frame 0's root
    # rotation is the identity by convention and frame 1's faces the pose's real direction (+Z here
    # after turning by the pose's yaw): row 0 holds half that yaw
    still = np.repeat(p[:1], 10, 0)
    fs = F.encode(still)
    assert np.abs(fs[1:, 0:3]).max() < 1e-7 and np.abs(fs[:, F.BLOCKS["local_vel"]]).max() < 1e-7
    facing = rot.quat_rotate(rot.quat_inv(F.root_rotations(still)[1]), np.array([0, 0, 1.0]))
    assert np.isclose(abs(fs[0, 0]), abs(np.arctan2(facing[0], facing[2])) / 2, atol=1e-5)
    assert (fs[:, F.BLOCKS["contacts"]] == 1).all()
    # root height block is the pelvis height
    np.testing.assert_allclose(feats[:, 3], p[:-1, 0, 1], atol=1e-6)


def test_contacts_follow_the_velocity_rule():
    p = np.zeros((3, 22, 3))
    p[1, 10, 0] = 0.05   # left foot moves 5 cm: 0.0025 m² ≥ 0.002 → no contact on rows 0 and 1
    c = F.foot_contacts(p)
    assert c.shape == (2, 4)
    np.testing.assert_array_equal(c[:, 1], [0, 0])
    np.testing.assert_array_equal(c[:, [0, 2, 3]], np.ones((2, 3)))


def test_normalizer_block_std_round_trip_and_io(tmp_path):
    arrays = [F.encode(synthetic_motion(seed=s)) for s in range(3)]
    norm = F.Normalizer.fit(arrays)
    for sl in F.BLOCKS.values():
        assert np.ptp(norm.std[sl]) == 0  # one std per block
    x = arrays[0]
    np.testing.assert_allclose(norm.denormalize(norm.normalize(x)), x, atol=1e-5)
    xt = torch.as_tensor(x)
    np.testing.assert_allclose(norm.normalize(xt).numpy(), norm.normalize(x), atol=1e-6)
    norm.save(tmp_path)
    again = F.Normalizer.load(tmp_path)
    np.testing.assert_array_equal(again.mean, norm.mean)
    with pytest.raises(ValueError, match="mean.npy"):
        F.Normalizer.load(tmp_path / "missing")


def test_release_statistics_are_block_averaged(shared_data):
    std = np.load(shared_data / "humanml3d/Std.npy")
    norm = F.Normalizer.load(shared_data / "humanml3d")
    np.testing.assert_allclose(F.block_averaged_std(std)[4:], std[4:], rtol=1e-5)
    assert norm.mean.shape == (263,)


@pytest.mark.parametrize("bad, match", [
    (np.zeros((1, 22, 3)), "at least 2 frames"),
    (np.zeros((5, 21, 3)), r"\(T, 22, 3\)"),
    (np.full((5, 22, 3), np.nan), "NaN"),
    (np.full((5, 22, 3), np.inf), "Inf"),
])
def test_encode_rejects_bad_positions(bad, match):
    with pytest.raises(ValueError, match=match):
        F.encode(bad)


def test_decode_rejects_bad_features():
    with pytest.raises(ValueError, match="263"):
        F.decode(np.zeros((5, 262)))
    with pytest.raises(ValueError, match="NaN"):
        F.decode(np.full((5, 263), np.nan))
    with pytest.raises(ValueError, match="Normalizer"):
        F.Normalizer(np.zeros(262), np.ones(262))
