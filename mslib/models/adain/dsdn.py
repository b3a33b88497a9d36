"""Paper A stage 2: the Dual-Stream Denoising Network with adaptive gating (A §3.3).

The idea: a stage-1 transfer carries two kinds of error — fast, frame-to-frame jitter and slow drift of
the pose — and each is best removed by a different network, mixed frame by frame.
- Dynamic stream (A Eq. 6): a 1-layer LSTM (hidden 128) over the noisy 263-d sequence and a two-layer
  regressor, X_dyn = W2·tanh(W1·h_t + b1) + b2.
- Static stream (A Eq. 7): a conv autoencoder, two Conv1d (kernel 4, stride 2) up to 512 channels
  (T' = T/4) and a mirrored transposed-conv decoder.
- Adaptive Gating Fusion Unit (A Eq. 8–10): α_t = Softplus(W2·tanh(W1·x_t + b1) + b2) per frame, and the
  output P_o = α·X_dyn + (1 − α)·P̂_static (W2 is 1×64: the paper's 1×32 does not match W1's 64 rows).
Losses: L_rec = ‖P_o − P_c‖₁ against the clean content (A Eq. 11) and L_vel = ‖P_o[1:] − P_o[:−1]‖₁, the
output's own frame-to-frame change (A Eq. 12).
Training pairs (A §4.3.1): a content motion and its transfer to a neutral style clip by the stage-1 model;
at inference it corrects transfers to any style. `mode` = "dual" | "dynamic" | "static" gives the
single-stream ablations of A Table 2; `correction_strength` κ applies P + κ·(DSDN(P) − P) (κ = 1: A's full
correction; the course preset's κ, the best mean of the H on built-in and on real val pairs (`tools/real_val.py`),
keeps some of the stage-1 style).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import torch
from torch import nn

from ...motion.features import N_FEATURES, check_features
from ..common.config import Config
from ..common.layers import Normalized, pad_last
from .model import ROOT_DIMS

MODES = ("dual", "dynamic", "static")


@dataclass
class DsdnConfig(Config):
    """Sizes of the stage-2 model and the loss weight of L_vel; defaults are A §3.3's."""

    mode: str = "dual"  # "dual", "dynamic" (LSTM only) or "static" (conv AE only): A Table 2
    lstm_hidden: int = 128  # A §3.3.3
    regressor_hidden: int = 128  # A Eq. 6: W1
    static_channels: tuple = (256, 512)  # A §3.3.4: two Conv1d, kernel 4, stride 2, up to 512
    gate_hidden: int = 64  # A Eq. 8: W1 ∈ R^{64×D}
    lambda_vel: float = 1.0  # weight of L_vel (A Eq. 12) beside L_rec (A Eq. 11)
    clip_frames: int = 196  # training crop length (feature rows), a multiple of 4
    correction_strength: float = 1.0  # inference: κ in P + κ·(DSDN(P) − P); 1 = A's full correction

    PRESETS: ClassVar[dict] = {"paper": {}, "course": dict(clip_frames=64, correction_strength=0.5)}


class DynamicStream(nn.Module):
    """LSTM over time + two-layer regressor (A Eq. 6): (B, T, D) → (B, T, D)."""

    def __init__(self, cfg: DsdnConfig):
        super().__init__()
        self.lstm = nn.LSTM(N_FEATURES, cfg.lstm_hidden, num_layers=1, batch_first=True)
        self.w1 = nn.Linear(cfg.lstm_hidden, cfg.regressor_hidden)
        self.w2 = nn.Linear(cfg.regressor_hidden, N_FEATURES)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h, _ = self.lstm(x)  # h_t (B, T, 128)
        return self.w2(torch.tanh(self.w1(h)))  # A Eq. 6: X_dyn = W2·tanh(W1·h_t + b1) + b2


class StaticStream(nn.Module):
    """Conv autoencoder (A Eq. 7): C_s = E(P) at T/4 with 512 channels, P̂ = D(C_s); (B, T, D) → (B, T, D)."""

    def __init__(self, cfg: DsdnConfig):
        super().__init__()
        c1, c2 = cfg.static_channels
        self.encoder = nn.Sequential(nn.Conv1d(N_FEATURES, c1, 4, 2, 1), nn.LeakyReLU(0.2),
                                     nn.Conv1d(c1, c2, 4, 2, 1), nn.LeakyReLU(0.2))
        self.decoder = nn.Sequential(nn.ConvTranspose1d(c2, c1, 4, 2, 1), nn.LeakyReLU(0.2),
                                     nn.ConvTranspose1d(c1, N_FEATURES, 4, 2, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        T = x.shape[1]
        x = pad_last(x, T + (-T) % 4)  # the two stride-2 layers need T divisible by 4: repeat the last frame
        code = self.encoder(x.transpose(1, 2))  # C_s (B, 512, T/4)
        return self.decoder(code).transpose(1, 2)[:, :T]  # P̂ (B, T, D)


class GatingUnit(nn.Module):
    """AGFU (A Eq. 8–10): α = Softplus(W2·tanh(W1·x + b1) + b2) per frame; (B, T, D) → (B, T, 1)."""

    def __init__(self, cfg: DsdnConfig):
        super().__init__()
        self.w1 = nn.Linear(N_FEATURES, cfg.gate_hidden)  # A Eq. 8
        self.w2 = nn.Linear(cfg.gate_hidden, 1)  # A Eq. 9 (1×64; the paper's 1×32 is a typo)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return nn.functional.softplus(self.w2(torch.tanh(self.w1(x))))  # A Eq. 10


class DSDN(Normalized):
    """Dual-stream denoiser on normalised 263-d features; `mode` picks dual or a single stream."""

    def __init__(self, cfg: DsdnConfig | dict | None = None, mean=None, std=None):
        super().__init__(mean, std)
        cfg = DsdnConfig.from_dict(cfg) if isinstance(cfg, dict) else (cfg or DsdnConfig.preset("course"))
        if cfg.mode not in MODES:
            raise ValueError(f"mode: expected one of {MODES}, got {cfg.mode!r}")
        self.cfg, self.config = cfg, {**cfg.to_dict(), "static_channels": list(cfg.static_channels)}
        self.dynamic = DynamicStream(cfg) if cfg.mode in ("dual", "dynamic") else None
        self.static = StaticStream(cfg) if cfg.mode in ("dual", "static") else None
        self.gate = GatingUnit(cfg) if cfg.mode == "dual" else None

    def forward(self, x: torch.Tensor, return_gate: bool = False):
        """Normalised noisy motion (B, T, 263) → corrected (B, T, 263) [and α (B, T, 1)]."""
        if self.cfg.mode == "dynamic":
            out, alpha = self.dynamic(x), torch.ones_like(x[..., :1])
        elif self.cfg.mode == "static":
            out, alpha = self.static(x), torch.zeros_like(x[..., :1])
        else:
            alpha = self.gate(x)  # (B, T, 1)
            out = alpha * self.dynamic(x) + (1 - alpha) * self.static(x)  # fused: α·dynamic + (1−α)·static
        return (out, alpha) if return_gate else out

    def losses(self, batch) -> dict:
        """L_rec (A Eq. 11) against the clean content and L_vel (A Eq. 12) on the fused output."""
        noisy, clean = batch  # normalised (B, T, 263) each
        fused = self(noisy)
        l_rec = (fused - clean).abs().mean()  # A Eq. 11: ‖P_o − P_c‖₁
        l_vel = (fused[:, 1:] - fused[:, :-1]).abs().mean()  # A Eq. 12: ‖P[:, 1:] − P[:, :−1]‖₁
        return {"loss": l_rec + self.cfg.lambda_vel * l_vel, "rec": l_rec, "vel": l_vel}

    def training_step(self, batch) -> dict:
        logs = self.losses(batch)
        return {"loss": logs["loss"], "rec": float(logs["rec"].detach()), "vel": float(logs["vel"].detach())}

    def validation_step(self, batch) -> dict:
        return {k: float(v) for k, v in self.losses(batch).items()}

    @torch.no_grad()
    def correct_features(self, features, strength: float | None = None) -> np.ndarray:
        """Unnormalised stylized features (T, 263) → corrected (T, 263) float64; root dims 0..3 kept.

        strength κ (default `cfg.correction_strength`): the output moves from the input P towards the
        network's correction by κ, P + κ·(DSDN(P) − P); κ = 1 is A's full correction. A smaller κ keeps
        more of stage 1's style, part of which the evaluator reads in the very dynamics stage 2 smooths."""
        k = self.cfg.correction_strength if strength is None else float(strength)
        f = np.asarray(check_features(features, "features"))
        if f.ndim != 2:
            raise ValueError(f"features: expected one motion of shape (T, 263), got {f.shape}")
        x = torch.as_tensor(f, dtype=torch.float32, device=self.mean.device)[None]
        self.eval()
        out = self((x - self.mean) / self.std)[0] * self.std + self.mean
        out = x[0] + k * (out - x[0])
        out = torch.cat([x[0, :, ROOT_DIMS], out[:, 4:]], -1)  # the root path stays the content's
        return out.double().cpu().numpy()

    @torch.no_grad()
    def gate_weights(self, features) -> np.ndarray:
        """α per frame (T,) for unnormalised features (T, 263) (dual mode)."""
        x = torch.as_tensor(np.asarray(check_features(features, "features")), dtype=torch.float32,
                            device=self.mean.device)[None]
        return self((x - self.mean) / self.std, return_gate=True)[1][0, :, 0].double().cpu().numpy()


@torch.no_grad()
def evaluate_pairs(model: DSDN, pairs, batch_size: int = 64) -> dict:
    """Mean L_rec (A Eq. 11) and L_vel (A Eq. 12) over all (noisy, clean) pairs, e.g. the validation set."""
    noisy, clean = pairs
    model.eval()
    sums, n = {"rec": 0.0, "vel": 0.0}, 0
    for i in range(0, len(noisy), batch_size):
        logs = model.losses((noisy[i:i + batch_size], clean[i:i + batch_size]))
        k = len(noisy[i:i + batch_size])
        sums = {key: sums[key] + k * float(logs[key]) for key in sums}
        n += k
    return {key: v / max(n, 1) for key, v in sums.items()}
