"""Evaluation metrics, each defined in its docstring: pure functions on numpy arrays.

Motions are joint positions (T, 22, 3) in metres, Y up, 20 fps, HumanML3D joint order; feature
sets are (N, D) arrays from the independent evaluator. Nothing here imports `mslib.models`.

Definitional choices (the field leaves room; these are the workbook's):
- FSF counts a (foot, frame t) step t→t+1 as "in contact" when that foot is below `height` at
  BOTH t and t+1, the same contact test as FSR. Measured on real HumanML3D motions
  this gives 0.50–1.69 cm/frame, the field's published range for natural capture; testing frame t only
  counts take-off steps (a jump scores 5.3 instead of 1.1). Steps of both feet are pooled.
- FSR follows SMooDi/GMD: the 5-frame moving average is centred with zeros beyond the clip ends,
  and the ratio is over the T−1 velocity frames.
- TSI averages over all min(T, T') common frames, frame 0 included (its distance is 0 by
  construction), so an offset d appearing from frame 1 on gives d·(n−1)/n.
- Heights are the raw Y coordinate: the HumanML3D processing puts the floor at Y = 0.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy import linalg
from scipy.ndimage import uniform_filter1d
from scipy.spatial.distance import pdist

from mslib.motion.features import check_positions

__all__ = [
    "frechet_distance", "kid", "accuracy", "harmonic_score", "trajectory_similarity_index",
    "trajectory_similarity_index_batch", "foot_slide_fsf", "foot_skating_ratio_fsr", "diversity",
    "gram_matrix", "style_distance", "content_distance", "jitter", "pose_offset",
]

FEET = (10, 11)  # left foot, right foot (HumanML3D order)
ROOT = 0
XZ = [0, 2]  # the horizontal plane (Y up)
FSR_WINDOW = 5  # frames of SMooDi's moving average
WORKBOOK_FPS = 20.0


# ---------------------------------------------------------------- validation helpers
def _numpy(x, name: str) -> np.ndarray:
    """Any array-like (torch tensors included) as a float64 numpy array with finite values."""
    if hasattr(x, "detach"):  # torch.Tensor, without importing torch here
        x = x.detach().cpu().numpy()
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name}: not a numeric array ({err})") from None
    if a.size and not np.isfinite(a).all():
        raise ValueError(f"{name}: contains NaN or Inf values")
    return a


def _matrix(x, name: str, min_rows: int = 1) -> np.ndarray:
    """A finite (N, D) feature matrix with N ≥ min_rows and D ≥ 1."""
    a = _numpy(x, name)
    if a.ndim != 2 or a.shape[1] < 1:
        raise ValueError(f"{name}: expected shape (N, D), got {a.shape}")
    if a.shape[0] < min_rows:
        raise ValueError(f"{name}: need at least {min_rows} samples, got {a.shape[0]}")
    return a


def _same_dim(a: np.ndarray, b: np.ndarray, name_b: str) -> None:
    if a.shape[1] != b.shape[1]:
        raise ValueError(f"{name_b}: feature dimension {b.shape[1]} differs from the first set's {a.shape[1]}")


def _positive(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a positive number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name}: expected a positive finite number, got {value!r}")
    return v


def _count(value, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name}: expected an integer ≥ {minimum}, got {value!r}")
    return int(value)


def _positions(x, name: str, min_frames: int) -> np.ndarray:
    return check_positions(_numpy(x, name), name, min_frames=min_frames)


# ---------------------------------------------------------------- distribution metrics
def _sqrt_of_product(cov_a: np.ndarray, cov_b: np.ndarray, eps: float) -> np.ndarray:
    """Real part of (Σa Σb)^{1/2}, retried with eps·I on both covariances when not finite/real."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", linalg.LinAlgWarning)  # singular products are handled below
        root = linalg.sqrtm(cov_a @ cov_b)
        bad = not np.isfinite(root).all() or (np.iscomplexobj(root) and np.abs(root.imag).max() > 1e-3)
        if bad:
            offset = eps * np.eye(cov_a.shape[0])
            root = linalg.sqrtm((cov_a + offset) @ (cov_b + offset))  # ((Σa+εI)(Σb+εI))^{1/2}
    return np.real(root)


def frechet_distance(feats_a, feats_b, eps: float = 1e-6) -> float:
    """FMD between two feature sets (N, D) and (M, D): Fréchet distance of their Gaussian fits."""
    a = _matrix(feats_a, "feats_a", min_rows=2)
    b = _matrix(feats_b, "feats_b", min_rows=2)
    _same_dim(a, b, "feats_b")
    eps = _positive(eps, "eps")
    mu_a, mu_b = a.mean(0), b.mean(0)
    cov_a = np.atleast_2d(np.cov(a, rowvar=False))  # unbiased sample covariance (N − 1)
    cov_b = np.atleast_2d(np.cov(b, rowvar=False))
    covmean = _sqrt_of_product(cov_a, cov_b, eps)
    diff = mu_a - mu_b
    fmd = diff @ diff + np.trace(cov_a + cov_b - 2 * covmean)  # ‖μa−μb‖² + Tr(Σa + Σb − 2(ΣaΣb)^{1/2})
    return float(max(fmd, 0.0))  # ≥ 0 in exact arithmetic; round-off can dip a hair below


def kid(feats_a, feats_b, n_subsets: int = 100, subset_size: int = 1000, seed: int = 0):
    """KID: unbiased MMD² with the cubic polynomial kernel, averaged over random subsets → (mean, std)."""
    a = _matrix(feats_a, "feats_a", min_rows=2)
    b = _matrix(feats_b, "feats_b", min_rows=2)
    _same_dim(a, b, "feats_b")
    n_subsets = _count(n_subsets, "n_subsets")
    m = min(_count(subset_size, "subset_size", 2), len(a), len(b))
    dim = a.shape[1]
    rng = np.random.default_rng(seed)

    def kernel(x, y):
        return (x @ y.T / dim + 1.0) ** 3  # k(x, y) = (γ xᵀy + coef0)³, γ = 1/dim, coef0 = 1

    values = np.empty(n_subsets)
    for s in range(n_subsets):
        x = a[rng.choice(len(a), m, replace=False)]
        y = b[rng.choice(len(b), m, replace=False)]
        kxx, kyy, kxy = kernel(x, x), kernel(y, y), kernel(x, y)
        # MMD²_u = Σ_{i≠j} k(xi,xj)/(m(m−1)) + Σ_{i≠j} k(yi,yj)/(m(m−1)) − 2 Σ_{i,j} k(xi,yj)/m²
        values[s] = ((kxx.sum() - np.trace(kxx)) + (kyy.sum() - np.trace(kyy))) / (m * (m - 1)) \
            - 2.0 * kxy.mean()
    return float(values.mean()), float(values.std())


def diversity(features, n_pairs: int | None = None, seed: int = 0) -> float:
    """Mean Euclidean distance between the features of paired samples (all pairs, or n_pairs random ones)."""
    f = _matrix(features, "features", min_rows=2)
    if n_pairs is None:
        return float(pdist(f).mean())  # exact: mean over all N(N−1)/2 pairs of distinct samples
    n_pairs = _count(n_pairs, "n_pairs")
    rng = np.random.default_rng(seed)
    i = rng.integers(0, len(f), n_pairs)
    j = rng.integers(0, len(f) - 1, n_pairs)
    j = j + (j >= i)  # j uniform over the indices other than i
    return float(np.linalg.norm(f[i] - f[j], axis=1).mean())  # (1/P) Σ ‖f_i − f_j‖


# ---------------------------------------------------------------- classification metrics
def accuracy(logits_or_probs, labels, top_k: int = 1) -> float:
    """Top-k accuracy in percent of scores (N, C) against integer labels (N,)."""
    scores = _matrix(logits_or_probs, "logits_or_probs")
    lab = _numpy(labels, "labels")
    if lab.ndim != 1 or len(lab) != len(scores):
        raise ValueError(f"labels: expected shape ({len(scores)},), got {lab.shape}")
    n_classes = scores.shape[1]
    if (lab != np.round(lab)).any() or lab.min() < 0 or lab.max() >= n_classes:
        raise ValueError(f"labels: expected integers in [0, {n_classes}), got values {np.unique(lab)[:8]}")
    top_k = _count(top_k, "top_k")
    if top_k > n_classes:
        raise ValueError(f"top_k: {top_k} exceeds the number of classes {n_classes}")
    ranked = np.argsort(-scores, axis=1, kind="stable")[:, :top_k]  # ties go to the lower class index
    hit = (ranked == lab.astype(np.int64)[:, None]).any(1)
    return float(100.0 * hit.mean())  # 100 · (1/N) Σ [label ∈ top-k]


def _percent(x, name: str) -> float:
    if np.ndim(x) != 0:
        raise ValueError(f"{name}: expected a scalar percentage, got shape {np.shape(x)}")
    v = float(_numpy(x, name))
    if not 0.0 <= v <= 100.0:
        raise ValueError(f"{name}: expected a percentage in [0, 100], got {v}")
    return v


def harmonic_score(sra, cra) -> float:
    """H in [0, 1] from SRA and CRA given in percent; 0 when both are 0."""
    s, c = _percent(sra, "sra"), _percent(cra, "cra")
    if s + c == 0.0:
        return 0.0
    return 2.0 * s * c / (s + c) / 100.0  # H = 2·SRA·CRA / (SRA + CRA), percent → [0, 1]


# ---------------------------------------------------------------- trajectory and feet
def trajectory_similarity_index(output, content) -> float:
    """TSI (m): mean distance between the frame-0-anchored root XZ paths over the common length."""
    o = _positions(output, "output", min_frames=1)
    c = _positions(content, "content", min_frames=1)
    n = min(len(o), len(c))
    path_o = o[:n, ROOT][:, XZ] - o[0, ROOT, XZ]  # r_out(t) − r_out(0) in XZ
    path_c = c[:n, ROOT][:, XZ] - c[0, ROOT, XZ]  # r_con(t) − r_con(0) in XZ
    return float(np.linalg.norm(path_o - path_c, axis=-1).mean())  # (1/n) Σ_t ‖Δ_out(t) − Δ_con(t)‖


def trajectory_similarity_index_batch(outputs, contents) -> float:
    """Mean TSI (m) over paired lists of output and content motions."""
    if not isinstance(outputs, (list, tuple)) or len(outputs) == 0:
        raise ValueError("outputs: expected a non-empty list of (T, 22, 3) motions")
    if not isinstance(contents, (list, tuple)) or len(contents) != len(outputs):
        raise ValueError(f"contents: expected a list of {len(outputs)} motions, one per output")
    return float(np.mean([trajectory_similarity_index(o, c) for o, c in zip(outputs, contents)]))


def _feet(positions, fps, height):
    """Foot XZ steps (T−1, 2) in metres and the both-frames contact mask (T−1, 2)."""
    p = _positions(positions, "positions", min_frames=2)
    _positive(fps, "fps")
    h = _positive(height, "height")
    feet = p[:, FEET]  # (T, 2, 3)
    step = np.linalg.norm(feet[1:][..., XZ] - feet[:-1][..., XZ], axis=-1)  # ‖x_{t+1} − x_t‖ in XZ
    low = feet[..., 1] < h
    contact = low[:-1] & low[1:]  # below `height` at t and at t+1
    return step, contact


def foot_slide_fsf(positions, fps: float = 20, height: float = 0.05) -> float:
    """FSF (paper B): mean horizontal step in cm per (20 fps) frame of feet 10, 11 while in contact."""
    step, contact = _feet(positions, fps, height)
    if not contact.any():
        return 0.0
    # FSF = (1/|C|) Σ_{(foot,t) ∈ C} 100·‖x_{t+1} − x_t‖_XZ, rescaled to a 20 fps frame for other rates
    return float(100.0 * step[contact].mean() * float(fps) / WORKBOOK_FPS)


def foot_skating_ratio_fsr(positions, fps: float = 20, height: float = 0.05, speed: float = 0.5) -> float:
    """FSR (SMooDi): fraction of the T−1 frames in which either foot skates."""
    step, contact = _feet(positions, fps, height)
    v_min = _positive(speed, "speed")
    vel = step * float(fps)  # horizontal speed, m/s
    vel_avg = uniform_filter1d(vel, size=FSR_WINDOW, axis=0, mode="constant")  # centred, zeros past the ends
    skating = contact & (vel > v_min) & (vel_avg > v_min)
    return float(skating.any(axis=1).mean())  # |{t : either foot skates}| / (T − 1)


# ---------------------------------------------------------------- Gatys-style distances (paper C)
def _feature_maps(x, name: str) -> np.ndarray:
    f = _numpy(x, name)
    if f.ndim not in (2, 3) or 0 in f.shape:
        raise ValueError(f"{name}: expected shape (C, T) or (B, C, T) with no empty axis, got {f.shape}")
    return f


def gram_matrix(feature_maps) -> np.ndarray:
    """Gram matrix of feature maps (C, T) → (C, C), or (B, C, T) → (B, C, C), normalised by C·T."""
    f = _feature_maps(feature_maps, "feature_maps")
    c, t = f.shape[-2:]
    return f @ np.swapaxes(f, -1, -2) / (c * t)  # G = F Fᵀ / (C·T)


def _pair(fa, fb):
    a, b = _feature_maps(fa, "fa"), _feature_maps(fb, "fb")
    if a.ndim != b.ndim or a.shape[:-1] != b.shape[:-1]:
        raise ValueError(f"fb: shape {b.shape} does not match fa's {a.shape} (batch and channels must agree)")
    return a, b


def style_distance(fa, fb) -> float:
    """Frobenius distance between the Gram matrices of two feature maps (mean over a batch)."""
    a, b = _pair(fa, fb)
    diff = gram_matrix(a) - gram_matrix(b)
    return float(np.sqrt((diff ** 2).sum(axis=(-2, -1))).mean())  # ‖G(a) − G(b)‖_F


def content_distance(fa, fb) -> float:
    """Mean over time (and batch) of the L2 distance between two feature maps' channel vectors."""
    a, b = _pair(fa, fb)
    if a.shape != b.shape:
        raise ValueError(f"fb: shape {b.shape} does not match fa's {a.shape} (content needs equal lengths)")
    return float(np.linalg.norm(a - b, axis=-2).mean())  # (1/T) Σ_t ‖a[:, t] − b[:, t]‖₂


# ---------------------------------------------------------------- smoothness and offsets
def jitter(positions, fps: float = 20) -> float:
    """Mean joint acceleration magnitude (m/s²) from second differences."""
    p = _positions(positions, "positions", min_frames=3)
    fps = _positive(fps, "fps")
    acc = (p[2:] - 2 * p[1:-1] + p[:-2]) * fps ** 2  # a_t = (p_{t+1} − 2p_t + p_{t−1}) · fps²
    return float(np.linalg.norm(acc, axis=-1).mean())  # mean over frames and joints of ‖a_t‖


def pose_offset(a, b) -> float:
    """Mean joint distance (m) between two motions over their common length."""
    pa = _positions(a, "a", min_frames=1)
    pb = _positions(b, "b", min_frames=1)
    n = min(len(pa), len(pb))
    return float(np.linalg.norm(pa[:n] - pb[:n], axis=-1).mean())  # (1/(n·22)) Σ_{t,j} ‖a_tj − b_tj‖


# A Fig. 2: AdaIN's two halves — (use_mean, use_std) switches of an AdaIN transfer
ADAIN_HALVES = {"full": (True, True), "variance only": (False, True), "mean only": (True, False)}


def transfer_noise(model, pairs, halves=ADAIN_HALVES) -> dict:
    """Per pair, (jitter, pose offset to the content) of the content and of each half's transfer (A Fig. 2)."""
    out = {"content": [(jitter(c["joints"]), 0.0) for c, _ in pairs]}
    for name, (use_mean, use_std) in halves.items():
        moved = [(c, model.transfer(c["features"], s["features"], use_mean=use_mean, use_std=use_std))
                 for c, s in pairs]
        out[name] = [(jitter(m), pose_offset(m, c["joints"])) for c, m in moved]
    return out
