"""Motion VAE shared by paper B (MCM-LDM) and paper D (ClusterStyle): a transformer encoder maps a
variable-length normalised 263-d clip to N latent tokens, a transformer decoder maps them back.

API (stable):
    vae = MotionVAE(VAEConfig.preset("course"), mean, std)     # mean/std: the 263-d normaliser
    vae = load_vae(path=None, device="cpu")                      # the packaged course checkpoint, eval mode
    x = vae.normalize(raw); raw = vae.denormalize(x)             # (…, 263) torch tensors
    mu, logvar = vae.encode_dist(x, mask)                        # x (B, T, 263) normalised, mask (B, T) True on frames
    z = vae.encode(x, mask, sample=False)                        # (B, N, d) latent, divided by vae.latent_scale
    x = vae.decode(z, lengths)                                   # (B, max(lengths), 263) normalised features
    z = vae.encode_raw([raw (T, 263) arrays]); raw = vae.decode_raw(z, lengths) -> list of (T_i, 263) numpy
The diffusion models work on `z` (scaled to about unit variance: `latent_scale` is the std of the
training set's μ, measured after training, as in latent diffusion). `paper` preset: 7 × 256 tokens from a
9-layer, 4-head transformer (B §4.1, MLD's VAE). `course` (a departure): a convolutional VAE with a
temporal latent (50 tokens × 16, one token per 4 frames of a clip padded to 200 frames). Why: in the
course's CPU minutes a small transformer VAE loses the style before any diffusion begins (its
reconstructions of style clips no longer read as their style), while a conv VAE, whose tokens are local
in time, learns in minutes what a transformer needs hours on a GPU for.
Train: `python -m mslib train vae --preset course --seed 0` → mslib/checkpoints/vae.pt.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import torch
from torch import nn
from torch.utils.data import ConcatDataset, Dataset

from ...checkpoints import course_path, load_state, read_checkpoint, save_checkpoint
from ...data.datasets import ContentClips, StyleClips
from ...motion.features import N_FEATURES
from ...motion.features import decode as decode_positions
from ...training import TrainConfig, fit, run_summary
from .config import Config
from .layers import Normalized, PositionalEncoding, ResBlock1d, pad_batch, transformer_encoder

NAME = "vae"


@dataclass
class VAEConfig(Config):
    """Sizes and training settings; `paper` = MCM-LDM's 7×256 VAE, `course` = a CPU-minutes one."""

    arch: str = "transformer"  # "transformer" (MLD's, B's paper VAE) or "conv" (a temporal latent, the course one)
    latent_tokens: int = 7  # conv: max_len // down, one token per `down` frames of a clip padded to max_len
    latent_dim: int = 256
    dim: int = 256
    heads: int = 4
    layers: int = 9
    ff_mult: int = 4
    dropout: float = 0.1
    kl_weight: float = 1e-4
    root_weight: float = 1.0  # extra weight of the root dims 0..3 in the reconstruction loss
    down: int = 4  # frames per encoder token (a strided conv before the transformer)
    max_len: int = 200
    min_len: int = 32
    steps: int = 100000
    batch_size: int = 64
    lr: float = 1e-4
    time_budget_s: float | None = None

    PRESETS: ClassVar[dict] = {
        "paper": {},
        # a conv VAE: in CPU minutes a small transformer loses the style (module docstring)
        "course": dict(arch="conv", latent_tokens=50, latent_dim=16, dim=192, layers=3, dropout=0.0, root_weight=4.0,
                       steps=1800, batch_size=32, lr=1e-3, max_len=200, down=4),
    }

    def __post_init__(self):
        if self.arch not in ("transformer", "conv"):
            raise ValueError(f"arch: expected 'transformer' or 'conv', got {self.arch!r}")
        if self.arch == "conv" and (self.down != 4 or self.max_len % 4 or self.latent_tokens != self.max_len // 4):
            raise ValueError(f"conv VAE: needs down=4 and latent_tokens = max_len // 4, got down={self.down}, "
                             f"max_len={self.max_len}, latent_tokens={self.latent_tokens}")


class ConvCodec(nn.Module):
    """The course VAE's encoder/decoder: residual Conv1d over time, two stride-2 steps (T → T/4 latent
    tokens of `latent_dim` channels); a clip is padded with its last frame to max_len, so every clip has
    the same N = max_len/4 tokens and token i describes frames 4i…4i+3 (a temporal latent)."""

    def __init__(self, cfg: "VAEConfig"):
        super().__init__()
        h, d, L = cfg.dim, cfg.latent_dim, cfg.layers
        self.max_len = cfg.max_len
        self.enc = nn.Sequential(
            nn.Conv1d(N_FEATURES, h, 3, padding=1), *[ResBlock1d(h) for _ in range(L - 2)],
            nn.Conv1d(h, h, 4, 2, 1), ResBlock1d(h), nn.Conv1d(h, h, 4, 2, 1), ResBlock1d(h),  # T → T/2 → T/4
            nn.LeakyReLU(0.2), nn.Conv1d(h, 2 * d, 1))  # μ and log σ² per latent token
        self.dec = nn.Sequential(
            nn.Conv1d(d, h, 1), ResBlock1d(h), nn.ConvTranspose1d(h, h, 4, 2, 1), ResBlock1d(h),
            nn.ConvTranspose1d(h, h, 4, 2, 1), *[ResBlock1d(h) for _ in range(L - 2)],  # T/4 → T/2 → T
            nn.LeakyReLU(0.2), nn.Conv1d(h, N_FEATURES, 3, padding=1))

    def encode(self, x: torch.Tensor, mask: torch.Tensor, pad_to: int | None = None) -> tuple:
        """(B, T, 263) normalised + mask → μ, log σ² each (B, pad_to/4, d); pad_to = max_len for the fixed
        N tokens the diffusion models see (training pads only to the batch's length: convolutions are local)."""
        L = self.max_len if pad_to is None else -(-int(pad_to) // 4) * 4
        last = (mask.sum(1) - 1).clamp(min=0)  # index of each clip's last real frame
        idx = torch.minimum(torch.arange(L, device=x.device)[None], last[:, None])  # (B, L)
        x = torch.gather(x, 1, idx[..., None].expand(-1, -1, x.shape[-1]))  # padded with the last real frame
        mu, logvar = self.enc(x.transpose(1, 2)).chunk(2, 1)  # (B, d, L/4) each
        return mu.transpose(1, 2), logvar.transpose(1, 2).clamp(-20, 10)

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """(B, N, d) unscaled latent → (B, 4N, 263) normalised features."""
        return self.dec(z.transpose(1, 2)).transpose(1, 2)


class MotionVAE(Normalized):
    """The motion VAE: `arch="transformer"` — learned latent queries read the clip, frame queries read the
    latent (MLD's design, B's paper VAE); `arch="conv"` — the ConvCodec's temporal latent (the course VAE)."""

    def __init__(self, cfg: VAEConfig, mean=None, std=None):
        super().__init__(mean, std)
        self.cfg = cfg
        self.config = cfg.to_dict()
        self.register_buffer("latent_scale", torch.ones(()))
        if cfg.arch == "conv":
            self.conv = ConvCodec(cfg)
            return
        n, d = cfg.latent_tokens, cfg.dim
        k = cfg.down
        # frames → tokens: a per-frame linear, then `down` frames folded into one token (a strided conv)
        self.inp = nn.Sequential(nn.Linear(N_FEATURES, d), nn.GELU())
        self.fold = nn.Conv1d(d, d, k, stride=k)
        self.queries = nn.Parameter(torch.randn(1, n, d) * 0.02)  # the N latent tokens' queries
        self.pos = PositionalEncoding(d, max_len=cfg.max_len // k + 2 * n + 8)
        self.encoder = transformer_encoder(d, cfg.heads, cfg.layers, cfg.ff_mult, cfg.dropout)
        self.to_mu = nn.Linear(d, cfg.latent_dim)
        self.to_logvar = nn.Linear(d, cfg.latent_dim)
        self.from_z = nn.Linear(cfg.latent_dim, d)
        self.frame_query = nn.Parameter(torch.randn(1, 1, d) * 0.02)
        self.decoder = transformer_encoder(d, cfg.heads, cfg.layers, cfg.ff_mult, cfg.dropout)
        self.unfold = nn.ConvTranspose1d(d, d, k, stride=k)  # one token → `down` frames
        self.out = nn.Sequential(nn.GELU(), nn.Linear(d, N_FEATURES))

    # ---------------------------------------------------------------- encoder / decoder
    def encode_dist(self, x: torch.Tensor, mask: torch.Tensor | None = None) -> tuple:
        """(B, T, 263) normalised → μ, log σ² each (B, N, d)."""
        if x.dim() != 3 or x.shape[-1] != N_FEATURES:
            raise ValueError(f"x: expected (B, T, {N_FEATURES}) features, got {tuple(x.shape)}")
        B, T, _ = x.shape
        if T > self.cfg.max_len:
            raise ValueError(f"x: {T} frames is longer than this VAE's max_len={self.cfg.max_len}")
        n, k = self.cfg.latent_tokens, self.cfg.down
        mask = torch.ones(B, T, dtype=torch.bool, device=x.device) if mask is None else mask.bool()
        if self.cfg.arch == "conv":
            return self.conv.encode(x, mask)
        Tk = -(-T // k) * k  # pad to a multiple of `down` by repeating the last frame
        x = torch.cat([x, x[:, -1:].expand(B, Tk - T, -1)], 1)
        h = self.fold(self.inp(x).transpose(1, 2)).transpose(1, 2)  # (B, T/k, D)
        valid = torch.arange(Tk // k, device=x.device)[None] < (mask.sum(1, keepdim=True) + k - 1) // k
        tokens = torch.cat([self.queries.expand(B, -1, -1), h], 1)  # (B, N + T/k, D)
        pad = torch.cat([torch.zeros(B, n, dtype=torch.bool, device=x.device), ~valid], 1)
        h = self.encoder(self.pos(tokens), src_key_padding_mask=pad)[:, :n]  # (B, N, D)
        return self.to_mu(h), self.to_logvar(h).clamp(-20, 10)

    def encode(self, x: torch.Tensor, mask: torch.Tensor | None = None, sample: bool = False,
               generator: torch.Generator | None = None) -> torch.Tensor:
        """The diffusion latent: μ (or a sample) / latent_scale, (B, N, d)."""
        mu, logvar = self.encode_dist(x, mask)
        if sample:
            mu = mu + torch.randn(mu.shape, generator=generator).to(mu) * (0.5 * logvar).exp()
        return mu / self.latent_scale

    def decode(self, z: torch.Tensor, lengths) -> torch.Tensor:
        """(B, N, d) diffusion latent + lengths (B,) → (B, max(lengths), 263) normalised features."""
        lengths = torch.as_tensor(lengths, device=z.device).reshape(-1)
        if z.dim() != 3 or z.shape[1:] != (self.cfg.latent_tokens, self.cfg.latent_dim):
            raise ValueError(f"z: expected (B, {self.cfg.latent_tokens}, {self.cfg.latent_dim}), got {tuple(z.shape)}")
        if len(lengths) != z.shape[0] or int(lengths.min()) < 1 or int(lengths.max()) > self.cfg.max_len:
            raise ValueError(f"lengths: need {z.shape[0]} lengths in [1, {self.cfg.max_len}], got {lengths.tolist()}")
        B, n, T, k = z.shape[0], self.cfg.latent_tokens, int(lengths.max()), self.cfg.down
        if self.cfg.arch == "conv":
            return self.conv.decode(z * self.latent_scale)[:, :T]
        Tk = -(-T // k)
        frames = self.frame_query.expand(B, Tk, -1)  # (B, T/k, D); positions tell the tokens apart
        tokens = torch.cat([self.from_z(z * self.latent_scale), frames], 1)
        pad = torch.cat([torch.zeros(B, n, dtype=torch.bool, device=z.device),
                         torch.arange(Tk, device=z.device)[None] >= (lengths[:, None] + k - 1) // k], 1)
        h = self.decoder(self.pos(tokens), src_key_padding_mask=pad)[:, n:]  # (B, T/k, D)
        h = self.unfold(h.transpose(1, 2)).transpose(1, 2)[:, :T]  # (B, T, D)
        return self.out(h)

    # ---------------------------------------------------------------- raw numpy helpers
    @torch.no_grad()
    def encode_raw(self, clips: list) -> torch.Tensor:
        """A list of unnormalised (T_i, 263) arrays → (B, N, d) diffusion latents (μ)."""
        x, mask = pad_batch([self.normalize(torch.as_tensor(np.asarray(c), dtype=torch.float32,
                                                            device=self.mean.device)) for c in clips])
        return self.encode(x, mask)

    @torch.no_grad()
    def decode_raw(self, z: torch.Tensor, lengths) -> list:
        """(B, N, d) latents → a list of unnormalised (T_i, 263) float64 arrays."""
        x = self.denormalize(self.decode(z, lengths))
        return [x[i, :int(n)].double().cpu().numpy() for i, n in enumerate(torch.as_tensor(lengths).reshape(-1))]

    # ---------------------------------------------------------------- training
    def loss_terms(self, x: torch.Tensor, mask: torch.Tensor) -> dict:
        """Masked feature MSE (root dims weighted) + KL(q(z|x) ‖ N(0, I)) · kl_weight."""
        if self.cfg.arch == "conv":  # only as many tokens as the batch needs
            mu, logvar = self.conv.encode(x, mask, pad_to=x.shape[1])
            z = mu + torch.randn_like(mu) * (0.5 * logvar).exp()
            rec = self.conv.decode(z)[:, :x.shape[1]]
        else:
            mu, logvar = self.encode_dist(x, mask)
            z = mu + torch.randn_like(mu) * (0.5 * logvar).exp()
            rec = self.decode(z / self.latent_scale, mask.sum(1))
        x, mask = x[:, :rec.shape[1]], mask[:, :rec.shape[1]]
        w = torch.ones(N_FEATURES, device=x.device)
        w[:4] = self.cfg.root_weight
        m = mask.to(x.dtype).unsqueeze(-1)
        mse = (((rec - x) ** 2) * w * m).sum() / (m.sum() * w.sum())
        kl = 0.5 * (mu ** 2 + logvar.exp() - 1 - logvar).mean()
        return {"loss": mse + self.cfg.kl_weight * kl, "rec": mse.detach(), "kl": kl.detach()}

    def training_step(self, batch: dict) -> dict:
        x, mask = random_window(*trim(batch), self.cfg.min_len, self.cfg.max_len)
        return self.loss_terms(x, mask)

    @torch.no_grad()
    def validation_step(self, batch: dict) -> dict:
        x, mask = trim(batch)
        mu, _ = self.encode_dist(x, mask)
        rec = self.decode(mu / self.latent_scale, mask.sum(1))
        m = mask.to(x.dtype).unsqueeze(-1)
        return {"rec": float((((rec - x) ** 2) * m).sum() / (m.sum() * N_FEATURES))}


# ---------------------------------------------------------------- batches
def trim(batch: dict) -> tuple:
    """A fixed-size padded batch ("features" (B, L, C), "length" (B,)) → features cut to the longest clip, mask."""
    lengths = batch["length"]
    T = int(lengths.max())
    mask = torch.arange(T, device=lengths.device)[None] < lengths[:, None]
    return batch["features"][:, :T], mask


def random_window(x: torch.Tensor, mask: torch.Tensor, min_len: int, max_len: int) -> tuple:
    """Crop a whole batch to one random length L in [min_len, max_len] (each clip at a random start),
    so most steps see short, cheap batches while every length stays in the mix."""
    L = int(torch.randint(min_len, max_len + 1, ()))
    if x.shape[1] <= L:
        return x, mask
    lengths = mask.sum(1)
    xs, ls = [], []
    for i in range(len(x)):
        n = int(lengths[i])
        s = int(torch.randint(0, max(n - L, 0) + 1, ()))
        xs.append(x[i, s:s + L])
        ls.append(min(n, L))
    lengths = torch.tensor(ls, device=x.device)
    return torch.stack(xs), torch.arange(L, device=x.device)[None] < lengths[:, None]


class Cropped(Dataset):
    """Clips of a dataset (unnormalised features) normalised with a given mean/std, randomly cropped to
    [min_len, max_len] frames and padded to max_len so the default collate stacks them; "length" = real frames."""

    def __init__(self, base, mean, std, max_len: int, min_len: int = 32, random: bool = True):
        self.base, self.max_len, self.min_len, self.random = base, int(max_len), int(min_len), random
        self.mean, self.std = torch.as_tensor(mean, dtype=torch.float32), torch.as_tensor(std, dtype=torch.float32)

    def __len__(self) -> int:
        return len(self.base)

    def __getitem__(self, i: int) -> dict:
        item = self.base[i]
        f = (item["features"] - self.mean) / self.std
        T = len(f)
        if self.random and T > self.min_len:
            L = int(torch.randint(self.min_len, min(T, self.max_len) + 1, ()))
            s = int(torch.randint(0, T - L + 1, ()))
            f = f[s:s + L]
        elif T > self.max_len:
            s = (T - self.max_len) // 2
            f = f[s:s + self.max_len]
        n = len(f)
        return {"features": torch.cat([f, f[-1:].expand(self.max_len - n, -1)]), "length": n}


def motion_sets(content, style, split: str, max_len: int, min_len: int = 32, random: bool = True):
    """Content + style clips of a split, normalised with the content folder's statistics; returns (dataset, mean, std)."""
    c = ContentClips(content, split, normalize=False)
    s = StyleClips(style, split, normalize=False, joints=False)
    sets = [Cropped(ds, c.mean, c.std, max_len, min_len, random) for ds in (c, s)]
    return ConcatDataset(sets), c.mean, c.std


# ---------------------------------------------------------------- evaluation helper (model-side)
@torch.no_grad()
def reconstruction_mpjpe(vae: MotionVAE, folder, split: str = "test", batch_size: int = 32) -> dict:
    """Mean per-joint position error (cm) of decode(features) vs decode(VAE reconstruction) over a split's
    clips: global (root path integrated from the velocities) and root-relative (pelvis subtracted)."""
    ds = ContentClips(folder, split, normalize=False)
    glob, local, n = 0.0, 0.0, 0
    dev = vae.mean.device
    for start in range(0, len(ds), batch_size):
        raws = [ds[i]["features"].to(dev) for i in range(start, min(start + batch_size, len(ds)))]
        raws = [r[:vae.cfg.max_len] for r in raws]
        z = vae.encode_raw(raws)
        recs = vae.decode_raw(z, [len(r) for r in raws])
        for r, rec in zip(raws, recs):
            p = decode_positions(r.double().cpu().numpy())
            q = decode_positions(rec)
            glob += float(np.linalg.norm(p - q, axis=-1).mean())
            local += float(np.linalg.norm((p - p[:, :1]) - (q - q[:, :1]), axis=-1).mean())
            n += 1
    return {"mpjpe_cm": 100 * glob / n, "mpjpe_local_cm": 100 * local / n, "clips": n}


@torch.no_grad()
def calibrate_scale(vae: MotionVAE, dataset, n: int = 512, batch_size: int = 64) -> float:
    """Set `latent_scale` to the std of μ over up to n clips of `dataset` (so diffusion latents are ~unit scale)."""
    vae.latent_scale.fill_(1.0)
    mus = []
    for start in range(0, min(n, len(dataset)), batch_size):
        items = [dataset[i] for i in range(start, min(start + batch_size, n, len(dataset)))]
        batch = {"features": torch.stack([it["features"] for it in items]),
                 "length": torch.tensor([it["length"] for it in items])}
        x, mask = trim({k: v.to(vae.mean.device) for k, v in batch.items()})
        mus.append(vae.encode_dist(x, mask)[0])
    scale = float(torch.cat(mus).std())
    vae.latent_scale.fill_(scale)
    return scale


# ---------------------------------------------------------------- loading and training
def load_vae(path=None, device="cpu") -> MotionVAE:
    """The VAE of a checkpoint (default: the packaged course one), in eval mode."""
    path = course_path(NAME) if path is None else path
    blob = read_checkpoint(path, NAME)
    vae = MotionVAE(VAEConfig.from_dict(blob["config"]))
    load_state(path, vae, NAME)
    return vae.to(device).eval()


def run(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True) -> dict:
    """Train the VAE on content + style clips, calibrate the latent scale, report test MPJPE."""
    cfg = VAEConfig.preset(preset)
    if steps:
        cfg.steps = int(steps)
    out = course_path(NAME) if out is None else out
    torch.manual_seed(seed)
    train, mean, std = motion_sets(content, style, "train", cfg.max_len, cfg.min_len)
    val, _, _ = motion_sets(content, style, "val", cfg.max_len, cfg.min_len, random=False)
    vae = MotionVAE(cfg, mean, std)
    tc = TrainConfig(steps=cfg.steps, batch_size=cfg.batch_size, lr=cfg.lr, warmup_steps=min(100, cfg.steps // 10),
                     val_every=max(1, cfg.steps // 5), time_budget_s=cfg.time_budget_s, seed=seed)
    history = fit(vae, train, tc, val, model_name=NAME, out=out, resume=resume, device=device, progress=progress)
    vae.eval()
    scale = calibrate_scale(vae, motion_sets(content, style, "train", cfg.max_len, cfg.min_len, random=False)[0])
    extra = read_checkpoint(out, NAME)["extra"]
    save_checkpoint(out, vae, vae.config, NAME, extra)
    err = reconstruction_mpjpe(vae, content, "test")
    return run_summary(NAME, out, history, latent_scale=round(scale, 4), test_mpjpe_cm=round(err["mpjpe_cm"], 2),
                       test_mpjpe_local_cm=round(err["mpjpe_local_cm"], 2),
                       val_rec=round(history["val"]["rec"][-1], 4) if history["val"].get("rec") else math.nan)



