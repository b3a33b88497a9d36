"""Blocks shared by the method modules: channel statistics and AdaIN, residual conv blocks,
sinusoidal positions and timestep embeddings, transformer encoders, the 263-d normaliser and last-frame
padding. Shapes are (B, T, D) at
module boundaries unless a docstring says (B, C, T) (the Conv1d layout)."""
from __future__ import annotations

import math

import torch
from torch import nn

from ...motion.features import N_FEATURES

EPS = 1e-5


def channel_stats(x: torch.Tensor, mask: torch.Tensor | None = None, eps: float = EPS) -> tuple:
    """μ and σ over time of (B, T, C) features, per channel → (B, 1, C) each; `mask` (B, T) True on frames."""
    if mask is None:
        mu = x.mean(1, keepdim=True)
        var = x.var(1, keepdim=True, unbiased=False)
    else:
        w = mask.to(x.dtype).unsqueeze(-1)  # (B, T, 1)
        n = w.sum(1, keepdim=True).clamp_min(1.0)
        mu = (x * w).sum(1, keepdim=True) / n
        var = (((x - mu) ** 2) * w).sum(1, keepdim=True) / n
    return mu, torch.sqrt(var + eps)


def adain(content: torch.Tensor, style_mu: torch.Tensor, style_sigma: torch.Tensor,
          mask: torch.Tensor | None = None, use_mean: bool = True, use_std: bool = True,
          eps: float = EPS) -> torch.Tensor:
    """A Eq. 2: AdaIN(c, s) = σ(s)·(c − μ(c))/σ(c) + μ(s), over time per channel; (B, T, C).

    `use_mean=False` keeps the content's own mean (variance-only transfer), `use_std=False` its own
    σ (mean-only transfer) — the switches behind A Fig. 2. `eps` floors the content's variance."""
    mu_c, sigma_c = channel_stats(content, mask, eps)
    scale = style_sigma if use_std else sigma_c
    shift = style_mu if use_mean else mu_c
    return scale * (content - mu_c) / sigma_c + shift


class ResBlock1d(nn.Module):
    """Two same-length Conv1d layers with a skip: x + conv(act(conv(act(x)))); (B, C, T) → (B, C, T)."""

    def __init__(self, channels: int, kernel: int = 3, act: type = nn.LeakyReLU):
        super().__init__()
        pad = kernel // 2
        self.body = nn.Sequential(act(), nn.Conv1d(channels, channels, kernel, padding=pad),
                                  act(), nn.Conv1d(channels, channels, kernel, padding=pad))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.body(x)


def sinusoid(positions: torch.Tensor, dim: int, max_period: float = 10000.0) -> torch.Tensor:
    """Sinusoidal embedding of (N,) positions or timesteps → (N, dim) (Vaswani et al.)."""
    half = dim // 2
    freqs = torch.exp(-math.log(max_period) * torch.arange(half, dtype=torch.float32, device=positions.device) / half)
    args = positions.float()[:, None] * freqs[None]
    emb = torch.cat([torch.cos(args), torch.sin(args)], -1)
    return emb if dim % 2 == 0 else torch.cat([emb, torch.zeros_like(emb[:, :1])], -1)


class PositionalEncoding(nn.Module):
    """Adds fixed sinusoidal positions to (B, T, D) tokens."""

    def __init__(self, dim: int, max_len: int = 1024):
        super().__init__()
        self.register_buffer("table", sinusoid(torch.arange(max_len), dim), persistent=False)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if x.shape[1] > len(self.table):
            raise ValueError(f"sequence of {x.shape[1]} tokens is longer than max_len={len(self.table)}")
        return x + self.table[: x.shape[1]]


class TimestepEmbedding(nn.Module):
    """Diffusion step t → (B, D): sinusoid then a two-layer MLP."""

    def __init__(self, dim: int):
        super().__init__()
        self.dim = dim
        self.mlp = nn.Sequential(nn.Linear(dim, dim), nn.SiLU(), nn.Linear(dim, dim))

    def forward(self, t: torch.Tensor) -> torch.Tensor:
        return self.mlp(sinusoid(t, self.dim))


def transformer_encoder(dim: int, heads: int, layers: int, ff_mult: int = 4, dropout: float = 0.1) -> nn.TransformerEncoder:
    """A pre-norm, batch-first, GELU transformer encoder on (B, T, D)."""
    layer = nn.TransformerEncoderLayer(dim, heads, ff_mult * dim, dropout, activation="gelu",
                                       batch_first=True, norm_first=True)
    return nn.TransformerEncoder(layer, layers, enable_nested_tensor=False)


class Normalized(nn.Module):
    """Base of the models that hold their training corpus's 263-d mean and std (buffers `mean`, `std`, saved
    with the weights) and move features between raw and normalised units: x = (f − μ) / σ, f = x·σ + μ."""

    def __init__(self, mean=None, std=None):
        super().__init__()
        self.register_buffer("mean", torch.zeros(N_FEATURES) if mean is None else
                             torch.as_tensor(mean, dtype=torch.float32).clone())  # (263,)
        self.register_buffer("std", torch.ones(N_FEATURES) if std is None else
                             torch.as_tensor(std, dtype=torch.float32).clone())  # (263,)

    def normalize(self, f: torch.Tensor) -> torch.Tensor:
        """Raw (…, 263) → normalised."""
        return (f - self.mean) / self.std

    def denormalize(self, x: torch.Tensor) -> torch.Tensor:
        """Normalised (…, 263) → raw."""
        return x * self.std + self.mean


def pad_last(x: torch.Tensor, length: int) -> torch.Tensor:
    """(…, T, C) → (…, length, C), longer clips repeating their last frame (a held pose, not a jump to zero)."""
    extra = int(length) - x.shape[-2]
    if extra <= 0:
        return x
    return torch.cat([x, x[..., -1:, :].expand(*x.shape[:-2], extra, x.shape[-1])], -2)


def pad_batch(clips: list) -> tuple:
    """A list of (T_i, C) tensors → (B, max T, C), each padded with its last frame, and mask (B, max T) True on frames."""
    if not clips:
        raise ValueError("clips: empty list")
    lengths = torch.tensor([len(c) for c in clips])
    T = int(lengths.max())
    return torch.stack([pad_last(c, T) for c in clips]), torch.arange(T)[None] < lengths[:, None]
