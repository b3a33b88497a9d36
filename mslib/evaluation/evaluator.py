"""The independent evaluator: content and style classifiers on joint positions.

Input per frame: the root height and the 21 joints relative to the root's ground point in the
facing frame (the HumanML3D "ric" block, i.e. positions with the root trajectory removed), 64-d.
A temporal conv net classifies 32-frame windows; a long motion is scored by averaging its windows'
logits, and its features (the penultimate layer, for FMD) by averaging theirs; a motion shorter
than a window is padded by holding its last frame. Real takes are often that short (most Xia takes
last about a second), so in training a share of the windows (SHORT_SHARE) is cut shorter and padded
the same way: otherwise the held frames are something the classifier never saw. No method trains
on these classifiers or their features. `Augment` (mirror, tempo, noise) is there for the search of
tools/evaluator_augment.py; the packaged classifiers train without it, since no augmentation — nor weight
decay, more dropout, a narrower net or a slower learning rate — recognised more real takes than a second
training seed does.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..motion.features import check_positions, root_relative
from ..motion.skeleton import mirror_positions

WINDOW = 32
INPUT_DIM = 64
SHORT_SHARE, SHORT_MIN = 0.5, 12  # training windows cut to 12–31 frames and padded, and how many


def classifier_input(positions) -> np.ndarray:
    """(T, 22, 3) positions → (T, 64): root height + root-relative joints in the facing frame.

    The same numbers as blocks [3] and [4:67] of the 263-d vector, without its rotation solve.
    """
    p = check_positions(positions)
    return np.concatenate([p[:, 0, 1:2], root_relative(p)], axis=1)


def windows_of(x: np.ndarray, length: int = WINDOW, stride: int = 16) -> np.ndarray:
    """(T, D) → (n, length, D) windows; a short sequence is padded by repeating its last frame."""
    if len(x) < length:
        x = np.concatenate([x, np.repeat(x[-1:], length - len(x), 0)], 0)
    starts = list(range(0, len(x) - length + 1, stride))
    if starts[-1] != len(x) - length:
        starts.append(len(x) - length)
    return np.stack([x[s:s + length] for s in starts])


@dataclass(frozen=True)
class Augment:
    """Nuisance changes to training windows, so the classifier learns style rather than quirks of one corpus."""

    mirror: float = 0.0  # share of windows with left and right swapped (a style has no handedness)
    tempo: float = 0.0  # windows replayed at a speed drawn log-uniformly from [1/(1+tempo), 1+tempo]
    noise: float = 0.0  # Gaussian noise added to every input, in units of that input's std over the corpus

    def __post_init__(self):
        if not 0.0 <= self.mirror <= 1.0 or self.tempo < 0.0 or self.noise < 0.0:
            raise ValueError(f"augment: mirror a share in [0, 1], tempo and noise ≥ 0, got {self}")


def replay_at(x: np.ndarray, speed: float) -> np.ndarray:
    """(T, D) → (≈T/speed, D): the sequence replayed `speed` times as fast (linear interpolation)."""
    n = max(2, int(round(len(x) / speed)))
    if len(x) < 2:
        return np.repeat(x, n, 0)
    t = np.linspace(0.0, len(x) - 1, n)
    i = np.minimum(t.astype(int), len(x) - 2)
    f = (t - i)[:, None]
    return x[i] * (1 - f) + x[i + 1] * f


@dataclass
class ClassifierConfig:
    """Sizes of the temporal conv net."""

    kind: str = "style"  # which label it predicts: "content" or "style"
    n_classes: int = 8
    width: int = 128
    feature_dim: int = 128
    dropout: float = 0.1


class MotionClassifier(nn.Module):
    """Conv1d ×3 over time → mean pool → 128-d features → class logits."""

    def __init__(self, cfg: ClassifierConfig, classes: list[str]):
        super().__init__()
        if len(classes) != cfg.n_classes:
            raise ValueError(f"classes: {len(classes)} names for n_classes={cfg.n_classes}")
        self.cfg, self.classes = cfg, list(classes)
        self.config = {**asdict(cfg), "classes": self.classes}
        w = cfg.width
        self.register_buffer("mean", torch.zeros(INPUT_DIM))
        self.register_buffer("std", torch.ones(INPUT_DIM))
        self.net = nn.Sequential(
            nn.Conv1d(INPUT_DIM, w, 5, padding=2), nn.GELU(),
            nn.Conv1d(w, w, 5, padding=2, stride=2), nn.GELU(),
            nn.Conv1d(w, w, 3, padding=1), nn.GELU(),
        )
        self.proj = nn.Sequential(nn.Linear(w, cfg.feature_dim), nn.GELU(), nn.Dropout(cfg.dropout))
        self.head = nn.Linear(cfg.feature_dim, cfg.n_classes)

    def features(self, x: torch.Tensor) -> torch.Tensor:
        """(B, T, 64) → (B, feature_dim), the penultimate layer."""
        h = self.net(((x - self.mean) / self.std).transpose(1, 2))  # (B, w, T/2)
        return self.proj(h.mean(-1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """(B, T, 64) → (B, n_classes) logits."""
        return self.head(self.features(x))

    def training_step(self, batch):
        x, y = batch
        logits = self(x)
        loss = nn.functional.cross_entropy(logits, y)
        return {"loss": loss, "acc": (logits.argmax(-1) == y).float().mean()}

    def validation_step(self, batch):
        x, y = batch
        logits = self(x)
        return {"loss": nn.functional.cross_entropy(logits, y), "acc": (logits.argmax(-1) == y).float().mean()}

    @torch.no_grad()
    def score(self, motions) -> tuple[np.ndarray, np.ndarray]:
        """Window-averaged logits (N, C) and features (N, D) of a list of (T, 22, 3) motions."""
        self.eval()
        logits, feats = [], []
        for m in motions:
            w = torch.as_tensor(windows_of(classifier_input(m)), dtype=torch.float32)
            f = self.features(w)
            feats.append(f.mean(0))
            logits.append(self.head(f).mean(0))
        return torch.stack(logits).numpy(), torch.stack(feats).numpy()


class WindowDataset(torch.utils.data.Dataset):
    """Random 32-frame windows of labelled motions (one window per clip per epoch); a `short` share of
    them cut to SHORT_MIN–31 frames and padded by holding the last frame, as `score` pads a short motion;
    `augment` (an Augment) mirrors, replays faster or slower and adds noise."""

    def __init__(self, motions, labels, seed: int = 0, length: int = WINDOW, short: float = 0.0,
                 augment: Augment | None = None):
        if len(motions) != len(labels) or not len(motions):
            raise ValueError(f"motions/labels: need the same non-zero number, got {len(motions)} and {len(labels)}")
        if not 0.0 <= short <= 1.0:
            raise ValueError(f"short: a share in [0, 1], got {short}")
        self.augment = augment or Augment()
        self.inputs = [classifier_input(m).astype(np.float32) for m in motions]
        self.mirrored = ([classifier_input(mirror_positions(np.asarray(m))).astype(np.float32) for m in motions]
                         if self.augment.mirror else None)
        self.labels = [int(y) for y in labels]
        self.length, self.short, self.rng = length, short, np.random.default_rng(seed)
        self.scale = self.stats()[1].numpy() if self.augment.noise else None

    def __len__(self):
        return len(self.inputs)

    def __getitem__(self, i):
        aug, rng = self.augment, self.rng
        x = self.mirrored[i] if aug.mirror and rng.random() < aug.mirror else self.inputs[i]
        if aug.tempo:
            x = replay_at(x, float(np.exp(rng.uniform(-1, 1) * np.log1p(aug.tempo))))
        n = self.length
        if self.short and rng.random() < self.short:
            n = int(rng.integers(min(SHORT_MIN, self.length), self.length))
        if len(x) > n:
            s = int(rng.integers(0, len(x) - n + 1))
            x = x[s:s + n]
        w = windows_of(x, self.length)[0]
        if aug.noise:
            w = w + aug.noise * self.scale * rng.standard_normal(w.shape)
        return torch.from_numpy(np.ascontiguousarray(w, dtype=np.float32)), torch.tensor(self.labels[i])

    def stats(self) -> tuple[torch.Tensor, torch.Tensor]:
        """Per-dimension mean and std over all frames (stored in the classifier)."""
        allx = np.concatenate(self.inputs, 0)
        return torch.as_tensor(allx.mean(0)), torch.as_tensor(allx.std(0) + 1e-6)


# ---------------------------------------------------------------- training and loading
PRESETS = {  # steps of the one training loop (mslib.training) per classifier
    "course": {"steps": 1200, "batch_size": 64, "lr": 2e-3, "warmup_steps": 50, "val_every": 200},
    "paper": {"steps": 6000, "batch_size": 128, "lr": 1e-3, "warmup_steps": 200, "val_every": 500},
}
NAMES = {"content": "evaluator_content", "style": "evaluator_style"}
NET_FIELDS = ("width", "feature_dim", "dropout")  # what `net` may change of ClassifierConfig


def _load_split(folder, split: str | None, label: str):
    """Joint arrays and label names of one split of a dataset folder (split None: every clip)."""
    from ..data.dataset_folder import read_labels
    rows = [r for r in read_labels(folder) if (split is None or r["split"] == split) and r.get(label)]
    if not rows:
        raise ValueError(f"{folder}: no {split} clips with a {label!r} label")
    joints = [np.load(Path(folder) / "joints" / f"{r['clip_id']}.npy") for r in rows]
    return joints, [r[label] for r in rows]


def train_classifier(kind: str, folder, preset: str = "course", seed: int = 0, out=None,
                     device: str = "cpu", progress: bool = True, classes=None, resume=None,
                     augment: Augment | None = None, net: dict | None = None, **overrides) -> tuple:
    """Train the content or style classifier on a dataset folder's train split; returns (model, history).
    `net` changes the network's sizes (NET_FIELDS), `overrides` the preset's training settings."""
    _check_training(kind, preset, net)  # before reading the folder: fail fast
    label = kind
    train_j, train_y = _load_split(folder, "train", label)
    val_j, val_y = _load_split(folder, "val", label)
    classes = sorted(set(train_y) | set(val_y)) if classes is None else list(classes)
    index = {c: i for i, c in enumerate(classes)}
    unknown = sorted(set(train_y + val_y) - set(index))
    if unknown:
        raise ValueError(f"{folder}: labels {unknown} are not among the classes {classes}")
    train_set = WindowDataset(train_j, [index[y] for y in train_y], seed=seed, short=SHORT_SHARE, augment=augment)
    val_set = WindowDataset(val_j, [index[y] for y in val_y], seed=seed + 1)
    return fit_classifier(kind, train_set, val_set, classes, preset, seed, out, device, progress, resume, net,
                          **overrides)


def fit_classifier(kind: str, train_set: WindowDataset, val_set: WindowDataset, classes, preset: str = "course",
                   seed: int = 0, out=None, device: str = "cpu", progress: bool = True, resume=None,
                   net: dict | None = None, **overrides) -> tuple:
    """The training loop of `train_classifier` on datasets made by the caller (e.g. with inputs moved)."""
    from ..training import TrainConfig, fit
    _check_training(kind, preset, net)
    torch.manual_seed(seed)
    model = MotionClassifier(ClassifierConfig(kind=kind, n_classes=len(classes), **(net or {})), list(classes))
    model.mean, model.std = train_set.stats()
    cfg = TrainConfig(seed=seed, **{**PRESETS[preset], **overrides})
    history = fit(model, train_set, cfg, val_set=val_set, model_name=NAMES[kind], out=out,
                  device=device, progress=progress, resume=resume)
    return model.eval(), history


def _check_training(kind: str, preset: str, net) -> None:
    """ValueError for an unknown kind, preset or network field."""
    if kind not in NAMES:
        raise ValueError(f"kind: expected 'content' or 'style', got {kind!r}")
    if preset not in PRESETS:
        raise ValueError(f"preset: expected one of {list(PRESETS)}, got {preset!r}")
    unknown_net = sorted(set(net or {}) - set(NET_FIELDS))
    if unknown_net:
        raise ValueError(f"net: {unknown_net} cannot be changed; expected some of {list(NET_FIELDS)}")


def load_classifier(kind: str, path=None) -> MotionClassifier:
    """A trained classifier from its checkpoint (the packaged course one by default)."""
    from ..checkpoints import course_path, load_state, read_checkpoint
    if kind not in NAMES:
        raise ValueError(f"kind: expected 'content' or 'style', got {kind!r}")
    path = course_path(NAMES[kind]) if path is None else Path(path)
    blob = read_checkpoint(path, NAMES[kind])
    cfg = {k: v for k, v in blob["config"].items() if k != "classes"}
    model = MotionClassifier(ClassifierConfig(**cfg), blob["config"]["classes"])
    load_state(path, model, NAMES[kind])
    return model.eval()


@torch.no_grad()
def test_accuracy(model: MotionClassifier, folder, split: str | None = "test") -> float:
    """Top-1 accuracy (%) on a split of a dataset folder (None: all of it), whole clips (window-averaged)."""
    joints, names = _load_split(folder, split, model.cfg.kind)
    logits, _ = model.score(joints)
    pred = [model.classes[i] for i in logits.argmax(-1)]
    return 100.0 * float(np.mean([p == n for p, n in zip(pred, names)]))

