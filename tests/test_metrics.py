"""Evaluation metrics against known answers (closed forms, constructed motions) and bad inputs."""
import ast
import inspect

import numpy as np
import pytest
import torch

from mslib.evaluation import metrics as M
from mslib.motion import features as F
from mslib.motion import skeleton as sk

FPS = 20


# ---------------------------------------------------------------- helpers
def gaussian_set(mean, cov, n=400, seed=0):
    """Samples whose sample mean and (N−1) covariance are exactly `mean` and `cov`."""
    rng = np.random.default_rng(seed)
    z = rng.standard_normal((n, len(mean)))
    z -= z.mean(0)
    z = z @ np.linalg.inv(np.linalg.cholesky(np.cov(z, rowvar=False))).T  # whitened: cov(z) = I
    return z @ np.linalg.cholesky(cov).T + mean


def standing(T=40):
    """The template rest pose held still, feet on the floor (lowest joint at Y = 0)."""
    rest = sk.HUMANML3D.rest_positions()
    rest = rest - [0.0, rest[:, 1].min(), 0.0]
    return np.repeat(rest[None], T, 0).astype(np.float64)


def slid(motion, joints, metres_per_frame, axis=0):
    """A copy with `joints` moved horizontally by a fixed step per frame."""
    out = motion.copy()
    out[:, joints, axis] += metres_per_frame * np.arange(len(motion))[:, None]
    return out


# ---------------------------------------------------------------- FMD
def test_fmd_identical_sets_is_zero():
    a = np.random.default_rng(1).standard_normal((300, 6))
    assert M.frechet_distance(a, a) <= 1e-6 * np.trace(np.cov(a, rowvar=False))


def test_fmd_matches_closed_form_for_diagonal_gaussians():
    mu_a, mu_b = np.array([0.0, 1.0, -2.0, 0.5]), np.array([1.0, 0.0, 0.0, 0.5])
    va, vb = np.array([1.0, 4.0, 0.25, 2.0]), np.array([2.0, 1.0, 1.0, 2.0])
    a, b = gaussian_set(mu_a, np.diag(va), seed=1), gaussian_set(mu_b, np.diag(vb), n=250, seed=2)
    expected = ((mu_a - mu_b) ** 2).sum() + ((np.sqrt(va) - np.sqrt(vb)) ** 2).sum()
    assert M.frechet_distance(a, b) == pytest.approx(expected, rel=1e-6)


def test_fmd_full_covariances_match_symmetric_form():
    rng = np.random.default_rng(3)
    A, B = rng.standard_normal((5, 5)), rng.standard_normal((5, 5))
    ca, cb = A @ A.T + 0.5 * np.eye(5), B @ B.T + 0.5 * np.eye(5)
    mu_a, mu_b = rng.standard_normal(5), rng.standard_normal(5)
    # Tr (Σa Σb)^{1/2} = Σ √λ(Σa^{1/2} Σb Σa^{1/2}), an independent route
    w, V = np.linalg.eigh(ca)
    ra = V @ np.diag(np.sqrt(w)) @ V.T
    tr_sqrt = np.sqrt(np.clip(np.linalg.eigvalsh(ra @ cb @ ra), 0, None)).sum()
    expected = ((mu_a - mu_b) ** 2).sum() + np.trace(ca) + np.trace(cb) - 2 * tr_sqrt
    got = M.frechet_distance(gaussian_set(mu_a, ca, seed=4), gaussian_set(mu_b, cb, seed=5))
    assert got == pytest.approx(expected, rel=1e-6)


def test_fmd_shift_adds_squared_norm():
    a = gaussian_set(np.zeros(3), np.diag([1.0, 2.0, 3.0]), seed=6)
    b = gaussian_set(np.zeros(3), np.diag([2.0, 2.0, 0.5]), seed=7)
    v = np.array([0.3, -1.2, 2.0])
    assert M.frechet_distance(a, b + v) - M.frechet_distance(a, b) == pytest.approx(v @ v, rel=1e-6)
    assert M.frechet_distance(a, a + v) == pytest.approx(v @ v, rel=1e-6)


def test_fmd_singular_covariance_is_finite_and_accepts_torch():
    rng = np.random.default_rng(8)
    a, b = rng.standard_normal((5, 12)), rng.standard_normal((6, 12))  # N < D: rank-deficient Σ
    d = M.frechet_distance(a, b)
    assert np.isfinite(d) and d >= 0
    ta = torch.tensor(a, requires_grad=True)
    assert M.frechet_distance(ta, torch.tensor(b)) == pytest.approx(d)


# ---------------------------------------------------------------- KID
def test_kid_self_near_zero_and_shift_larger():
    rng = np.random.default_rng(9)
    a, b = rng.standard_normal((300, 8)), rng.standard_normal((300, 8))
    shifted, _ = M.kid(a, a + 0.5, n_subsets=20, subset_size=100)
    same, same_std = M.kid(a, a, n_subsets=20, subset_size=100)
    # with itself, subsets share samples (k(x, x) enters the cross term): a small negative bias
    assert abs(same) < 0.1 * shifted and same_std >= 0
    independent, _ = M.kid(a, b, n_subsets=20, subset_size=100)  # same law, independent draws
    assert abs(independent) < 0.1 * shifted
    assert M.kid(a, b, n_subsets=5, subset_size=50, seed=3) == M.kid(a, b, n_subsets=5, subset_size=50, seed=3)


def test_kid_full_subset_matches_direct_unbiased_mmd():
    rng = np.random.default_rng(10)
    x, y = rng.standard_normal((7, 3)), rng.standard_normal((7, 3)) + 0.3
    k = lambda p, q: (p @ q / 3 + 1) ** 3  # noqa: E731
    m = len(x)
    xx = sum(k(x[i], x[j]) for i in range(m) for j in range(m) if i != j) / (m * (m - 1))
    yy = sum(k(y[i], y[j]) for i in range(m) for j in range(m) if i != j) / (m * (m - 1))
    xy = sum(k(x[i], y[j]) for i in range(m) for j in range(m)) / m ** 2
    mean, std = M.kid(x, y, n_subsets=4, subset_size=1000)  # subsets = whole sets, permuted
    assert mean == pytest.approx(xx + yy - 2 * xy, rel=1e-10) and std == pytest.approx(0, abs=1e-9)


# ---------------------------------------------------------------- accuracy, H, diversity
def test_accuracy_top1_top3():
    scores = np.array([[0.9, 0.05, 0.03, 0.02],   # label 0: top-1 hit
                       [0.1, 0.2, 0.3, 0.4],      # label 1: rank 3
                       [0.5, 0.4, 0.06, 0.04],    # label 1: rank 2
                       [0.1, 0.2, 0.3, 0.4]])     # label 0: rank 4
    labels = np.array([0, 1, 1, 0])
    assert M.accuracy(scores, labels) == pytest.approx(25.0)
    assert M.accuracy(scores, labels, top_k=2) == pytest.approx(50.0)
    assert M.accuracy(scores, labels, top_k=3) == pytest.approx(75.0)
    assert M.accuracy(scores, labels, top_k=4) == pytest.approx(100.0)
    assert M.accuracy(torch.tensor(np.log(scores)), torch.tensor(labels), top_k=3) == pytest.approx(75.0)


def test_harmonic_score():
    for x in (0.0, 12.5, 50.0, 100.0):
        assert M.harmonic_score(x, x) == pytest.approx(x / 100)
    assert M.harmonic_score(0, 80) == 0.0 and M.harmonic_score(80, 0) == 0.0
    assert M.harmonic_score(30, 90) == pytest.approx(M.harmonic_score(90, 30))
    assert M.harmonic_score(30, 90) == pytest.approx(2 * 0.3 * 0.9 / 1.2)


def test_diversity_known_answers():
    assert M.diversity(np.ones((10, 4))) == 0.0
    assert M.diversity(np.ones((10, 4)), n_pairs=50) == 0.0
    r = 2.5
    two = np.array([[0.0, 0.0, 0.0], [0.0, r * 0.6, r * 0.8]])
    assert M.diversity(two) == pytest.approx(r)
    assert M.diversity(two, n_pairs=17) == pytest.approx(r)  # distinct indices: never a zero pair
    f = np.random.default_rng(11).standard_normal((60, 5))
    assert M.diversity(f, n_pairs=4000, seed=1) == pytest.approx(M.diversity(f), rel=0.05)
    assert M.diversity(f, n_pairs=30, seed=2) == M.diversity(f, n_pairs=30, seed=2)


# ---------------------------------------------------------------- TSI
def test_tsi_known_answers():
    content = standing(30)
    content[:, :, 0] += 0.02 * np.arange(30)[:, None]  # content walks along X
    assert M.trajectory_similarity_index(content, content) == 0.0
    assert M.trajectory_similarity_index(content + [3.0, 0.0, -2.0], content) == pytest.approx(0.0, abs=1e-12)
    d = np.array([0.3, 0.0, 0.4])  # |d_XZ| = 0.5
    jumped = content.copy()
    jumped[1:] += d  # offset appears from frame 1 on; frame 0 is the anchor
    assert M.trajectory_similarity_index(jumped, content) == pytest.approx(0.5 * 29 / 30)


def test_tsi_moving_output_against_still_content():
    T, v = 41, 1.5
    still = standing(T)
    moving = slid(still, slice(None), v / FPS, axis=2)
    # distance at frame t is v·t/fps → mean v/fps·(T−1)/2
    assert M.trajectory_similarity_index(moving, still) == pytest.approx(v / FPS * (T - 1) / 2)
    assert M.trajectory_similarity_index(moving, still[:11]) == pytest.approx(v / FPS * 10 / 2)
    batch = M.trajectory_similarity_index_batch([moving, still], [still, still])
    assert batch == pytest.approx(v / FPS * (T - 1) / 4)


# ---------------------------------------------------------------- FSF / FSR
def test_standing_has_no_sliding_or_skating():
    m = standing()
    assert M.foot_slide_fsf(m) == 0.0 and M.foot_skating_ratio_fsr(m) == 0.0


@pytest.mark.parametrize("d_cm", [0.5, 1.0, 2.0])
def test_fsf_rises_by_injected_slide(d_cm):
    rng = np.random.default_rng(12)
    base = standing(60)
    base[:, :, [0, 2]] += rng.normal(0, 0.0005, (60, 22, 2))  # ~1 mm sway, still planted
    f0 = M.foot_slide_fsf(base)
    assert M.foot_slide_fsf(slid(base, slice(None), d_cm / 100)) - f0 == pytest.approx(d_cm, abs=0.1)
    # one foot planted and sliding, the other lifted (not in contact): FSF is the planted foot's slide
    one = slid(standing(60), [7, 10], d_cm / 100)
    one[:, [8, 11], 1] += 0.2
    assert M.foot_slide_fsf(one) == pytest.approx(d_cm)


def test_fsf_zero_without_contact_and_per_20fps_frame():
    lifted = standing(20)
    lifted[:, :, 1] += 0.3
    assert M.foot_slide_fsf(slid(lifted, slice(None), 0.05)) == 0.0
    m = slid(standing(40), slice(None), 0.01)  # 1 cm per frame
    assert M.foot_slide_fsf(m, fps=40) == pytest.approx(2.0)  # 40 cm/s = 2 cm per 20 fps frame


def test_fsr_skating_throughout_and_lifted_foot():
    skate = slid(standing(50), slice(None), 1.0 / FPS)  # feet on the floor, 1 m/s
    assert M.foot_skating_ratio_fsr(skate) == pytest.approx(1.0)
    swing = slid(standing(50), [7, 10], 2.0 / FPS)  # left foot 2 m/s ...
    swing[:, [7, 10], 1] += 0.1  # ... lifted 10 cm; right foot planted and still
    assert M.foot_skating_ratio_fsr(swing) == 0.0
    assert M.foot_skating_ratio_fsr(slid(standing(50), slice(None), 0.4 / FPS)) == 0.0  # below 0.5 m/s


def test_fsr_needs_the_moving_average_too():
    m = standing(40)
    m[20:, :, 0] += 0.03  # one 3 cm step (0.6 m/s) in one frame: its 5-frame average is 0.12 m/s
    assert M.foot_skating_ratio_fsr(m) == 0.0
    m = standing(41)
    m[:, :, 0] += np.where(np.arange(41) < 21, 0.0, 0.04 * (np.arange(41) - 20))[:, None]  # skates 2nd half
    # 20 of the 40 velocity frames move at 0.8 m/s; at the onset and at the clip's last frame only
    # 3 of the 5 window samples move (zeros past the end), average 0.48 m/s: 18 frames skate
    assert M.foot_skating_ratio_fsr(m) == pytest.approx(18 / 40)


def test_foot_metrics_on_real_motions(shared_data):
    motions = [np.load(shared_data / "humanml3d/new_joints/012314.npy")]
    for name in ("walk_circle", "old", "Chicken_FW_00_feat"):
        motions.append(F.decode(np.load(shared_data / f"humanml3d_format/{name}.npy").astype(np.float64)))
    for m in motions:
        assert 0.4 <= M.foot_slide_fsf(m) <= 1.8  # natural capture: 0.5–1.7 (the field's published range)
        assert 0.0 <= M.foot_skating_ratio_fsr(m) <= 0.4  # natural capture: 0.0–0.38


# ---------------------------------------------------------------- Gram / style / content
def test_gram_and_gatys_distances():
    rng = np.random.default_rng(13)
    fa, fb = rng.standard_normal((8, 30)), rng.standard_normal((8, 30))
    assert M.gram_matrix(np.ones((4, 10))) == pytest.approx(np.full((4, 4), 1 / 4))  # Σ_t 1/(C·T)
    assert M.gram_matrix(np.stack([fa, fb])).shape == (2, 8, 8)
    assert M.style_distance(fa, fa) == 0.0 and M.content_distance(fa, fa) == 0.0
    perm = rng.permutation(30)
    assert M.style_distance(fa, fa[:, perm]) == pytest.approx(0.0, abs=1e-12)
    assert M.content_distance(fa, fa[:, perm]) > 0.5
    assert M.style_distance(fa, fb) > 0
    assert M.style_distance(fa, fb[:, :17]) > 0  # style compares different lengths
    assert M.content_distance(np.zeros((3, 5)), np.full((3, 5), 2.0)) == pytest.approx(2 * np.sqrt(3))
    batch = M.style_distance(np.stack([fa, fa]), np.stack([fa, fb]))
    assert batch == pytest.approx(M.style_distance(fa, fb) / 2)


# ---------------------------------------------------------------- jitter, pose offset
def test_jitter_constant_velocity_and_sinusoid():
    assert M.jitter(slid(standing(30), slice(None), 0.07)) == pytest.approx(0.0, abs=1e-9)
    T, A, w = 201, 0.05, 2 * np.pi  # 1 Hz, 5 cm, 10 periods
    m = standing(T)
    s = A * np.sin(w * np.arange(T) / FPS)
    m[:, :, 0] += s[:, None]
    # discrete: |Δ²x| fps² = A (2 − 2cos(w/fps)) fps² |sin|; continuous limit A w² · 2/π
    exact = A * (2 - 2 * np.cos(w / FPS)) * FPS ** 2 * np.abs(np.sin(w * np.arange(1, T - 1) / FPS)).mean()
    assert M.jitter(m) == pytest.approx(exact, rel=1e-9)
    assert M.jitter(m) == pytest.approx(A * w ** 2 * 2 / np.pi, rel=0.02)


def test_pose_offset():
    a = standing(20)
    assert M.pose_offset(a, a) == 0.0
    assert M.pose_offset(a, a[:7] + [0.0, 0.06, 0.08]) == pytest.approx(0.1)


# ---------------------------------------------------------------- bad inputs
GOOD = standing(10)
FEATS = np.random.default_rng(14).standard_normal((6, 3))
NAN_POS = GOOD.copy()
NAN_POS[3, 4, 1] = np.nan


@pytest.mark.parametrize("call, name", [
    (lambda: M.frechet_distance(FEATS[:1], FEATS), "feats_a"),
    (lambda: M.frechet_distance(FEATS, np.full((4, 3), np.inf)), "feats_b"),
    (lambda: M.frechet_distance(FEATS, FEATS[:, :2]), "feats_b"),
    (lambda: M.frechet_distance(FEATS.ravel(), FEATS), "feats_a"),
    (lambda: M.frechet_distance(FEATS, FEATS, eps=0), "eps"),
    (lambda: M.kid(np.empty((0, 3)), FEATS), "feats_a"),
    (lambda: M.kid(FEATS, FEATS, n_subsets=0), "n_subsets"),
    (lambda: M.kid(FEATS, FEATS, subset_size=1), "subset_size"),
    (lambda: M.accuracy(np.full((2, 3), np.nan), [0, 1]), "logits_or_probs"),
    (lambda: M.accuracy(FEATS, [0, 1]), "labels"),
    (lambda: M.accuracy(FEATS, [0, 1, 2, 3, 4, 5]), "labels"),
    (lambda: M.accuracy(FEATS, [0, 1, 2, 0, 1, 2], top_k=4), "top_k"),
    (lambda: M.harmonic_score(101, 50), "sra"),
    (lambda: M.harmonic_score(50, np.nan), "cra"),
    (lambda: M.trajectory_similarity_index(GOOD[:, :21], GOOD), "output"),
    (lambda: M.trajectory_similarity_index(GOOD, NAN_POS), "content"),
    (lambda: M.trajectory_similarity_index(GOOD[:0], GOOD), "output"),
    (lambda: M.trajectory_similarity_index_batch([], []), "outputs"),
    (lambda: M.trajectory_similarity_index_batch([GOOD], [GOOD, GOOD]), "contents"),
    (lambda: M.foot_slide_fsf(GOOD[:1]), "positions"),
    (lambda: M.foot_slide_fsf(NAN_POS), "positions"),
    (lambda: M.foot_slide_fsf(GOOD, height=-1), "height"),
    (lambda: M.foot_skating_ratio_fsr(GOOD[:1]), "positions"),
    (lambda: M.foot_skating_ratio_fsr(GOOD, fps=0), "fps"),
    (lambda: M.foot_skating_ratio_fsr(GOOD, speed=np.inf), "speed"),
    (lambda: M.diversity(FEATS[:1]), "features"),
    (lambda: M.diversity(FEATS, n_pairs=0), "n_pairs"),
    (lambda: M.gram_matrix(np.ones(5)), "feature_maps"),
    (lambda: M.style_distance(np.ones((4, 5)), np.ones((3, 5))), "fb"),
    (lambda: M.content_distance(np.ones((4, 5)), np.ones((4, 6))), "fb"),
    (lambda: M.content_distance(np.ones((4, 0)), np.ones((4, 0))), "fa"),
    (lambda: M.jitter(GOOD[:2]), "positions"),
    (lambda: M.pose_offset(GOOD, GOOD[..., :2]), "b"),
])
def test_bad_inputs_name_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name}:"):
        call()


def test_metrics_do_not_import_models():
    tree = ast.parse(inspect.getsource(M))
    mods = [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    mods += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert not [m for m in mods if "models" in m], mods


def test_transfer_noise_measures_each_adain_half():
    class Shift:  # mean-only moves the pose by 1 m, variance-only leaves it
        def transfer(self, content, style, use_mean=True, use_std=True):
            return decode(np.asarray(content)) + (1.0 if use_mean else 0.0)
    from mslib.evaluation.metrics import ADAIN_HALVES, transfer_noise
    from mslib.motion.features import decode, encode
    rng = np.random.default_rng(0)
    joints = np.cumsum(rng.normal(scale=0.01, size=(12, 22, 3)), 0) + np.array([0, 1.0, 0])
    c = {"joints": decode(encode(joints)), "features": encode(joints)}
    out = transfer_noise(Shift(), [(c, c), (c, c)])
    assert list(out) == ["content", *ADAIN_HALVES] and all(len(v) == 2 for v in out.values())
    assert out["variance only"][0][1] < 1e-9 and abs(out["mean only"][0][1] - np.sqrt(3)) < 1e-6
    assert abs(out["full"][0][0] - out["content"][0][0]) < 1e-4 * out["content"][0][0]  # a shift adds no jitter
