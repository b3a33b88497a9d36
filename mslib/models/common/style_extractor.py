"""Paper B's style extractor: a motion encoder pre-trained CLIP-style (symmetric InfoNCE) against the
style corpus's captions, which name the style, then frozen — the workbook's analogue of MotionCLIP
(B §3.2). It is NOT the evaluator: its own data pipeline, weights and training.

API:
    enc = MotionEncoder(StyleExtractorConfig.preset("course"))
    emb = enc(x, mask)                       # x (B, T, 263) normalised features, dims 0..2 zeroed inside → (B, D) unit vectors
    clip = CLIPPair(cfg, vocab)              # motion tower `motion` + text tower `text` (mslib.models.common.text)
    enc = load_style_extractor(path=None)    # the frozen motion tower of the packaged checkpoint
Train: `python -m mslib train style_extractor --preset course --seed 0`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import torch
from torch import nn
from torch.nn import functional as Fn

from ...checkpoints import course_path, load_state, read_checkpoint
from ...data.datasets import StyleClips
from ...motion.features import N_FEATURES
from ...training import TrainConfig, fit, run_summary, seed_everything
from .config import Config
from .layers import PositionalEncoding, transformer_encoder
from .text import TextConfig, TextEncoder, Tokenizer

NAME = "style_extractor"
TRAJ_DIMS = slice(0, 3)  # root angular velocity and XZ velocity: the trajectory, not style (the first 3 dims of the 263-d vector)


@dataclass
class StyleExtractorConfig(Config):
    """Motion tower sizes and CLIP training settings."""

    dim: int = 256
    out_dim: int = 256
    heads: int = 4
    layers: int = 4
    down: int = 2  # frames per token
    temperature: float = 0.07
    text_dim: int = 256
    steps: int = 20000
    batch_size: int = 64
    lr: float = 1e-4

    PRESETS: ClassVar[dict] = {
        "paper": {},  # MotionCLIP-sized
        "course": dict(dim=96, out_dim=64, heads=4, layers=2, text_dim=64, steps=600, batch_size=64, lr=2e-3),
    }
    STORED_BESIDE: ClassVar[tuple] = ("text",)  # a checkpoint keeps the text tower's config (and vocabulary) too


class MotionEncoder(nn.Module):
    """Normalised features (trajectory dims zeroed) → per-frame linear → strided fold → transformer → mean → unit vector."""

    def __init__(self, cfg: StyleExtractorConfig):
        super().__init__()
        self.cfg = cfg
        self.inp = nn.Sequential(nn.Linear(N_FEATURES, cfg.dim), nn.GELU())
        self.fold = nn.Conv1d(cfg.dim, cfg.dim, cfg.down, stride=cfg.down)
        self.pos = PositionalEncoding(cfg.dim, max_len=512)
        self.body = transformer_encoder(cfg.dim, cfg.heads, cfg.layers, 2, 0.1)
        self.proj = nn.Linear(cfg.dim, cfg.out_dim)

    def forward(self, x: torch.Tensor, mask: torch.Tensor | None = None) -> torch.Tensor:
        if x.dim() != 3 or x.shape[-1] != N_FEATURES:
            raise ValueError(f"x: expected (B, T, {N_FEATURES}) normalised features, got {tuple(x.shape)}")
        B, T, _ = x.shape
        k = self.cfg.down
        mask = torch.ones(B, T, dtype=torch.bool, device=x.device) if mask is None else mask.bool()
        x = x.clone()
        x[..., TRAJ_DIMS] = 0.0  # B: the style condition sees no trajectory
        Tk = -(-T // k) * k
        x = torch.cat([x, x[:, -1:].expand(B, Tk - T, -1)], 1)
        h = self.fold(self.inp(x).transpose(1, 2)).transpose(1, 2)  # (B, T/k, D)
        valid = torch.arange(Tk // k, device=x.device)[None] < (mask.sum(1, keepdim=True) + k - 1) // k
        h = self.body(self.pos(h), src_key_padding_mask=~valid)
        w = valid.unsqueeze(-1).to(h.dtype)
        return Fn.normalize(self.proj((h * w).sum(1) / w.sum(1)), dim=-1)  # (B, out_dim)


def clip_loss(a: torch.Tensor, b: torch.Tensor, same: torch.Tensor, temperature: float) -> torch.Tensor:
    """Symmetric InfoNCE between unit vectors a, b (B, D); `same` (B, B) True where two items share a caption
    (every such pair counts as a positive, so repeated captions in a batch are not false negatives)."""
    logits = a @ b.t() / temperature  # (B, B)
    target = same.to(logits.dtype) / same.sum(1, keepdim=True).to(logits.dtype)
    return 0.5 * (-(target * logits.log_softmax(1)).sum(1).mean() - (target * logits.log_softmax(0).t()).sum(1).mean())


class CLIPPair(nn.Module):
    """The motion tower and the text tower trained together (CLIP-style) on (clip, caption) pairs."""

    def __init__(self, cfg: StyleExtractorConfig, vocab: list):
        super().__init__()
        self.cfg = cfg
        tcfg = TextConfig(dim=cfg.text_dim, out_dim=cfg.out_dim)
        self.config = {**cfg.to_dict(), "text": {"vocab": list(vocab), **tcfg.to_dict()}}
        self.motion = MotionEncoder(cfg)
        self.text = TextEncoder(vocab, tcfg)

    def _embed(self, batch):
        x, lengths = batch["features"], batch["length"]
        mask = torch.arange(x.shape[1], device=x.device)[None] < lengths[:, None]
        m = self.motion(x, mask)
        t = self.text.encode_text(list(batch["caption"]))
        caps = list(batch["caption"])
        same = torch.tensor([[c == d for d in caps] for c in caps], device=x.device)
        return m, t, same

    def training_step(self, batch: dict) -> dict:
        m, t, same = self._embed(batch)
        loss = clip_loss(m, t, same, self.cfg.temperature)
        return {"loss": loss}

    @torch.no_grad()
    def validation_step(self, batch: dict) -> dict:
        m, t, same = self._embed(batch)
        hit = same[torch.arange(len(m)), (m @ t.t()).argmax(1)]  # motion → caption retrieval
        return {"loss": float(clip_loss(m, t, same, self.cfg.temperature)), "top1": float(hit.float().mean())}


class _Captioned(torch.utils.data.Dataset):
    """Style clips (normalised with `mean`/`std`) with their caption and length."""

    def __init__(self, base, mean, std):
        self.base, self.mean, self.std = base, torch.as_tensor(mean), torch.as_tensor(std)

    def __len__(self):
        return len(self.base)

    def __getitem__(self, i):
        it = self.base[i]
        return {"features": (it["features"] - self.mean) / self.std, "length": len(it["features"]),
                "caption": it["caption"]}


def load_style_extractor(path=None, device="cpu") -> MotionEncoder:
    """The frozen motion tower of a style_extractor checkpoint (default: the packaged one), eval mode."""
    path = course_path(NAME) if path is None else path
    blob = read_checkpoint(path, NAME)
    pair = CLIPPair(StyleExtractorConfig.from_dict(blob["config"]), blob["config"]["text"]["vocab"])
    load_state(path, pair, NAME)
    enc = pair.motion.to(device).eval()
    for p in enc.parameters():
        p.requires_grad_(False)
    return enc


def run(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True) -> dict:
    """CLIP-style pre-training of the style extractor (and the text encoder) on the style corpus's captions.
    Features are normalised with the content folder's statistics, as the VAE's are."""
    from ...data.datasets import ContentClips
    cfg = StyleExtractorConfig.preset(preset)
    if steps:
        cfg.steps = int(steps)
    out = course_path(NAME) if out is None else out
    stats = ContentClips(content, "train", normalize=False)
    mean, std = stats.mean, stats.std
    sets = {s: _Captioned(StyleClips(style, s, normalize=False, joints=False), mean, std) for s in ("train", "val")}
    vocab = Tokenizer.from_captions([r["caption"] for r in sets["train"].base.rows]).vocab
    seed_everything(seed)  # the initial weights too: a process's own torch seed differs from run to run
    model = CLIPPair(cfg, vocab)
    tc = TrainConfig(steps=cfg.steps, batch_size=cfg.batch_size, lr=cfg.lr, weight_decay=0.01,
                     warmup_steps=min(50, cfg.steps // 10), val_every=max(1, cfg.steps // 4), seed=seed)
    history = fit(model, sets["train"], tc, sets["val"], model_name=NAME, out=out, resume=resume, device=device,
                  progress=progress)
    return run_summary(NAME, out, history, val_loss=round(history["val"]["loss"][-1], 3),
                       val_top1=round(history["val"]["top1"][-1], 3))



