"""Paper A's training recipes: stage 1 on (content, style) pairs (A §3.2.2) and stage 2 on neutral-transfer pairs (A §4.3.1)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch
from torch.utils.data import Dataset, TensorDataset

from ...checkpoints import course_path
from ...data.datasets import ContentClips, StyleClips
from ...training import TrainConfig, fit, pretrain_then_freeze, run_summary, seed_everything
from .dsdn import DSDN, DsdnConfig
from .model import AdainConfig, AdainTransfer
from .transfer import load_adain

# the one loop's settings per preset (the model configs carry their own presets)
ADAIN_TRAINING = {
    "course": TrainConfig(steps=6000, batch_size=16, lr=2e-3, warmup_steps=50, val_every=250, val_batches=4),
    "paper": TrainConfig(steps=40000, batch_size=64, lr=2e-4, warmup_steps=1000, val_every=1000),
}
DSDN_TRAINING = {
    "course": TrainConfig(steps=600, batch_size=32, lr=1e-3, warmup_steps=20, val_every=100, val_batches=4),
    "paper": TrainConfig(steps=20000, batch_size=64, lr=1e-3, val_every=500),
}


def train_settings(table: dict, preset: str, seed: int, steps=None, train_config: TrainConfig | None = None):
    """The preset's TrainConfig (or `train_config`) with this run's seed and step count."""
    if preset not in table:
        raise ValueError(f"preset: expected one of {sorted(table)}, got {preset!r}")
    return replace(train_config or table[preset], seed=seed, **({"steps": steps} if steps else {}))

# ---------------------------------------------------------------- data: (content clip, style clip) pairs
class TransferPairs(Dataset):
    """Item i = {"content": content clip i (normalised, cropped), "style": a style clip (unnormalised)};
    the style clip is drawn at random in training and fixed per index otherwise."""

    def __init__(self, content_folder, style_folder, split: str = "train", length: int = 64, seed: int = 0,
                 random_style: bool = True):
        self.content = ContentClips(content_folder, split, length=length, random_crop=split == "train", seed=seed)
        self.style = StyleClips(style_folder, split, normalize=False, joints=False)
        self.random_style, self.seed = random_style, seed

    def __len__(self) -> int:
        return len(self.content)

    def __getitem__(self, i: int) -> dict:
        j = int(torch.randint(len(self.style), ())) if self.random_style else (i * 7919 + self.seed) % len(self.style)
        c, s = self.content[i], self.style[j]
        return {"content": {"features": c["features"]}, "style": {"features": s["features"]}}


def train_adain(preset: str, content, style, seed: int = 0, out=None, device="cpu", steps=None, resume=None,
                progress=True, config: AdainConfig | None = None, train_config: TrainConfig | None = None):
    """Train the stage-1 model on the content and style folders; returns (model, history)."""
    tcfg = train_settings(ADAIN_TRAINING, preset, seed, steps, train_config)
    cfg = config or AdainConfig.preset(preset)
    train = TransferPairs(content, style, "train", cfg.clip_frames, seed)
    val = TransferPairs(content, style, "val", cfg.clip_frames, seed, random_style=False)
    seed_everything(seed)  # the initial weights too: a process's own torch seed differs from run to run
    model = AdainTransfer(cfg, train.content.mean, train.content.std)
    # 1: E (and E_s) with the decoder, as an autoencoder; 2: the encoders frozen, the decoder on A Eq. 5
    tcfg = pretrain_then_freeze(model, train, tcfg, cfg.pretrain_steps,
                                filter(None, (model.content_encoder, model.style_encoder)), resume=resume,
                                val_set=val, model_name="adain (autoencoder)", device=device, progress=progress)
    history = fit(model, train, tcfg, val, model_name="adain", out=out, resume=resume,
                  device=device, progress=progress)
    return model, history


# ---------------------------------------------------------------- training pairs (A §4.3.1)
def neutral_pairs(stage1, content_folder, style_folder, split: str, length: int, seed: int = 0):
    """(noisy, clean) normalised tensors (N, length, 263): each content clip of the split and its
    transfer to a neutral style clip of the same split by the stage-1 model."""
    content = ContentClips(content_folder, split, normalize=False, length=length, random_crop=split == "train",
                           seed=seed)
    style = StyleClips(style_folder, split, normalize=False, joints=False)
    neutral = [i for i, r in enumerate(style.rows) if r["style"] == "neutral"]
    if not neutral:
        raise ValueError(f"style_folder: no neutral clips in split {split!r} to build training pairs from")
    rng = np.random.default_rng([seed, 7])
    mean, std = stage1.mean.cpu().numpy(), stage1.std.cpu().numpy()
    noisy, clean = [], []
    for i in range(len(content)):
        c = content[i]["features"].numpy().astype(np.float64)
        s = style[neutral[int(rng.integers(len(neutral)))]]["features"].numpy()
        noisy.append((stage1.transfer_features(c, s) - mean) / std)
        clean.append((c - mean) / std)
    return (torch.as_tensor(np.stack(noisy), dtype=torch.float32),
            torch.as_tensor(np.stack(clean), dtype=torch.float32))


def train_dsdn(preset: str, content, style, seed: int = 0, out=None, device="cpu", steps=None, resume=None,
               progress=True, config: DsdnConfig | None = None, train_config: TrainConfig | None = None,
               stage1=None, data=None):
    """Train the stage-2 model on neutral-transfer pairs; returns (model, history).

    data: precomputed ((noisy, clean) train, (noisy, clean) val) tensors, e.g. to train the three
    ablation modes on the same pairs; default: built from the stage-1 model (`stage1`, default the
    packaged adain checkpoint)."""
    tcfg = train_settings(DSDN_TRAINING, preset, seed, steps, train_config)
    cfg = config or DsdnConfig.preset(preset)
    stage1 = stage1 or load_adain(device="cpu")
    if data is None:
        data = tuple(neutral_pairs(stage1, content, style, split, cfg.clip_frames, seed) for split in ("train", "val"))
    seed_everything(seed)  # the initial weights too
    model = DSDN(cfg, stage1.mean.cpu(), stage1.std.cpu())
    history = fit(model, TensorDataset(*data[0]), tcfg, TensorDataset(*data[1]), model_name="dsdn", out=out,
                  resume=resume, device=device, progress=progress)
    return model, history



def run_adain(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True) -> dict:
    out = out or course_path("adain")
    model, h = train_adain(preset, content, style, seed, out=out, device=device, steps=steps, resume=resume,
                           progress=progress)
    pre = getattr(model, "pretrain_history", None)
    extra = {"autoencoder_steps": pre["step"][-1], "autoencoder_val_content": round(pre["val"]["content"][-1], 4)} if pre else {}
    return run_summary("adain", out, h, **extra, **{f"{part}_{k}": round(h[part][k][-1], 4)
                                                   for part in ("train", "val") for k in ("content", "style")})


def run_dsdn(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True) -> dict:
    out = out or course_path("dsdn")
    _, h = train_dsdn(preset, content, style, seed, out=out, device=device, steps=steps, resume=resume,
                      progress=progress)
    return run_summary("dsdn", out, h, **{f"{part}_{k}": round(h[part][k][-1], 4)
                                          for part in ("train", "val") for k in ("rec", "vel")})

