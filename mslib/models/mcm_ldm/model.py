"""Paper B: MCM-LDM — latent diffusion in the motion VAE's space with three conditions: content (the
VAE encoding through a StyleRemover, prepended to the noisy tokens, B Eq. 6), style (a frozen
CLIP-pre-trained motion encoder, on the attention branch) and trajectory (on the MLP branch), both
through AdaLN-Zero (B Eq. 7–8); self-reconstruction training with the style dropped 25% of the time;
transfer by DDIM with classifier-free guidance (B Eq. 5).

API:
    model = MCMLDM(MCMConfig.preset("course"), latent_tokens, latent_dim, style_dim)
    cond = model.conditions(z_content, style, traj, traj_mask)        # once per clip
    eps = model.denoise(z_t, t, cond)                                   # (B, N, d)
    m = load_mcm_ldm(); out = m.transfer(content_raw (T, 263), style_raw (S, 263), scale=2.5) -> (T, 263) raw
Ablations of B Table 2 are config switches: use_remover, use_traj, pretrained_style.
Train: `python -m mslib train style_extractor …` then `python -m mslib train mcm_ldm --preset course --seed 0`
(the VAE first: `python -m mslib train vae …`).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import torch
from torch import nn

from ..common import style_extractor as SE
from ..common.diffusion import Schedule, cfg_combine, ddim_sample, eps_loss
from ..common.layers import PositionalEncoding, TimestepEmbedding, transformer_encoder

NAME = "mcm_ldm"
TRAJ = slice(0, 3)  # FIELD_FACTS: the trajectory condition is the first 3 normalised dims
STYLE_WINDOW = 32  # frames of a clip the style extractor sees in training (the style corpus's window)


@dataclass
class MCMConfig:
    """Denoiser sizes, conditions, ablation switches and training settings (paper: FIELD_FACTS "MCM-LDM")."""

    width: int = 256
    heads: int = 4
    blocks: int = 9
    mlp_ratio: int = 4
    traj_layers: int = 2
    traj_down: int = 1  # frames per trajectory token (1 = every frame, as released)
    traj_frames: int = 0  # 0: the trajectory is one vector (B Eq. 8); F > 0: one per denoiser token, F = frames the latent spans
    remover_layers: int = 1
    remover_norm: str = "channel"  # InstanceNorm axis of the StyleRemover ("channel" over tokens, or "token")
    content_bottleneck: int = 0  # 0: none (paper); else the width of a narrow layer on each content token
    content_noise: float = 0.0  # std of Gaussian noise on the content latent in training (a softer bottleneck)
    patch: int = 1  # consecutive VAE tokens per denoiser token (0: auto, the largest divisor of N giving ≤ 12)
    p_drop_style: float = 0.25  # B §3.3: null style (zeros) for classifier-free guidance
    cfg_scale: float = 2.5  # λ, B Eq. 5
    ddim_steps: int = 50
    use_remover: bool = True  # B Table 2 "w/o StyleRemover" when False
    use_traj: bool = True  # B Table 2 "w/o trajectory" when False
    pretrained_style: bool = True  # False: a fresh style encoder trained with the denoiser (B Table 2)
    steps: int = 100000
    batch_size: int = 128
    lr: float = 1e-4

    @classmethod
    def preset(cls, name: str) -> "MCMConfig":
        """`paper` or `course`."""
        if name == "paper":
            return cls()
        if name == "course":
            return cls(width=96, heads=4, blocks=4, mlp_ratio=2, traj_layers=1, traj_down=8, steps=6000,
                       batch_size=64, lr=1e-3, patch=0)
        raise ValueError(f"preset: expected 'paper' or 'course', got {name!r}")

    @classmethod
    def from_dict(cls, d: dict) -> "MCMConfig":
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in known})


def per_token(m: torch.Tensor) -> torch.Tensor:
    """A modulation as (B, L or 1, D): (B, D) is broadcast over tokens, (B, L, D) is one per token."""
    return m[:, None] if m.dim() == 2 else m


def modulate(x: torch.Tensor, shift: torch.Tensor, scale: torch.Tensor) -> torch.Tensor:
    """AdaLN: x·(1 + scale) + shift, modulations (B, D) for every token or (B, L, D) per token."""
    return x * (1 + per_token(scale)) + per_token(shift)


class Block(nn.Module):
    """DiT block with two conditions: style c_s modulates the attention branch (B Eq. 7), trajectory c_τ
    the MLP branch (B Eq. 8), each by (shift, scale, gate) from a zero-initialised linear (AdaLN-Zero)."""

    def __init__(self, width: int, heads: int, mlp_ratio: int):
        super().__init__()
        self.norm1 = nn.LayerNorm(width, elementwise_affine=False, eps=1e-6)
        self.attn = nn.MultiheadAttention(width, heads, batch_first=True)
        self.norm2 = nn.LayerNorm(width, elementwise_affine=False, eps=1e-6)
        self.mlp = nn.Sequential(nn.Linear(width, mlp_ratio * width), nn.GELU(), nn.Linear(mlp_ratio * width, width))
        self.ada_attn = nn.Sequential(nn.SiLU(), nn.Linear(width, 3 * width))
        self.ada_mlp = nn.Sequential(nn.SiLU(), nn.Linear(width, 3 * width))
        for ada in (self.ada_attn, self.ada_mlp):  # AdaLN-Zero: every block starts as the identity
            nn.init.zeros_(ada[1].weight)
            nn.init.zeros_(ada[1].bias)

    def forward(self, h: torch.Tensor, c_style: torch.Tensor, c_traj: torch.Tensor) -> torch.Tensor:
        s1, k1, g1 = self.ada_attn(c_style).chunk(3, -1)  # (B, W) each
        a = modulate(self.norm1(h), s1, k1)
        h = h + g1[:, None] * self.attn(a, a, a, need_weights=False)[0]  # B Eq. 7
        s2, k2, g2 = self.ada_mlp(c_traj).chunk(3, -1)  # (B, W) or (B, L, W) each
        return h + per_token(g2) * self.mlp(modulate(self.norm2(h), s2, k2))  # B Eq. 8


def auto_patch(tokens: int, most: int = 12) -> int:
    """The smallest group size p dividing `tokens` with tokens / p ≤ most (1 when tokens ≤ most)."""
    return next(p for p in range(1, tokens + 1) if tokens % p == 0 and tokens // p <= most)


def patchify(z: torch.Tensor, p: int) -> torch.Tensor:
    """(B, N, d) → (B, N/p, p·d): p consecutive latent tokens side by side."""
    return z.reshape(z.shape[0], z.shape[1] // p, p * z.shape[2])


class StyleRemover(nn.Module):
    """B §3.2: InstanceNorm of the VAE content tokens, a projection and a transformer layer, a linear map
    N → N−1 tokens. `norm="channel"`: each latent channel normalised over the N tokens (statistics
    across tokens removed, as AdaIN removes them across time); `"token"`: each token over its channels."""

    def __init__(self, tokens: int, latent_dim: int, width: int, heads: int, layers: int, norm: str = "channel",
                 bottleneck: int = 0, patch: int = 1):
        super().__init__()
        if norm not in ("channel", "token"):
            raise ValueError(f"norm: expected 'channel' or 'token', got {norm!r}")
        if patch < 1 or tokens % patch:
            raise ValueError(f"patch: {patch} does not divide the {tokens} latent tokens")
        self.norm_axis, self.patch = norm, patch
        self.norm = nn.InstanceNorm1d(latent_dim if norm == "channel" else tokens)
        self.proj = nn.Linear(patch * latent_dim, width)
        self.body = transformer_encoder(width, heads, layers, 2, 0.0)
        m = tokens // patch
        self.squeeze = nn.Linear(m, m - 1)  # mixes tokens: N → N−1 (N/p → N/p − 1 with patches)
        # optional narrow channel bottleneck (course): W → b → W per content token
        self.narrow = nn.Sequential(nn.Linear(width, bottleneck), nn.Linear(bottleneck, width)) if bottleneck else None

    def forward(self, z: torch.Tensor) -> torch.Tensor:
        """(B, N, d) content latent → (B, N/p − 1, W) content tokens (the norm acts on the N VAE tokens)."""
        n = self.norm(z.transpose(1, 2)).transpose(1, 2) if self.norm_axis == "channel" else self.norm(z)
        h = self.body(self.proj(patchify(n, self.patch)))  # (B, N/p, W)
        c = self.squeeze(h.transpose(1, 2)).transpose(1, 2)  # (B, N−1, W)
        return self.narrow(c) if self.narrow is not None else c


class TrajectoryEncoder(nn.Module):
    """(B, T, 3) root velocities → linear per frame, `down` frames per token, a summary token, transformer → (B, W).

    With `tokens` = m > 0 (course, for a temporal latent): the trajectory is padded to `frames`, folded
    into m segments aligned with the m denoiser tokens, and encoded to (B, m, W), one condition per token."""

    def __init__(self, width: int, heads: int, layers: int, down: int = 1, tokens: int = 0, frames: int = 0):
        super().__init__()
        if tokens:
            if frames < tokens or frames % tokens:
                raise ValueError(f"traj_frames: {frames} frames do not split into {tokens} denoiser tokens")
            down = frames // tokens
        self.down, self.tokens, self.frames = down, int(tokens), int(frames)
        self.inp = nn.Linear(3, width)
        self.fold = nn.Conv1d(width, width, down, stride=down)
        self.summary = nn.Parameter(torch.zeros(1, 1, width))
        self.pos = PositionalEncoding(width, max_len=512)
        self.body = transformer_encoder(width, heads, layers, 2, 0.0)

    def forward(self, traj: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        B, T, _ = traj.shape
        k = self.down
        if self.tokens:  # per token: zero-padded to the latent's frames, as the VAE pads the clip
            if T > self.frames:
                raise ValueError(f"traj: {T} frames, the latent spans at most {self.frames}")
            traj = torch.cat([traj * mask[..., None].to(traj.dtype), traj.new_zeros(B, self.frames - T, 3)], 1)
            h = self.fold(self.inp(traj).transpose(1, 2)).transpose(1, 2)  # (B, m, W)
            return self.body(self.pos(h))  # (B, m, W): token i sees all, its own segment in its input
        Tk = -(-T // k) * k
        traj = torch.cat([traj, traj[:, -1:].expand(B, Tk - T, -1)], 1)
        h = self.fold(self.inp(traj).transpose(1, 2)).transpose(1, 2)  # (B, T/k, W)
        valid = torch.arange(Tk // k, device=traj.device)[None] < (mask.sum(1, keepdim=True) + k - 1) // k
        h = torch.cat([self.summary.expand(B, -1, -1), h], 1)
        pad = torch.cat([torch.zeros(B, 1, dtype=torch.bool, device=traj.device), ~valid], 1)
        return self.body(self.pos(h), src_key_padding_mask=pad)[:, 0]


class MCMLDM(nn.Module):
    """The multi-condition denoiser ε_θ(z_t, t, content, style, trajectory) with its training step."""

    def __init__(self, cfg: MCMConfig, latent_tokens: int, latent_dim: int, style_dim: int,
                 style_cfg: dict | None = None):
        super().__init__()
        self.cfg, self.n, self.d = cfg, int(latent_tokens), int(latent_dim)
        self.config = {**asdict(cfg), "latent_tokens": self.n, "latent_dim": self.d, "style_dim": int(style_dim),
                       "style_cfg": style_cfg or {}}
        W = cfg.width
        self.p = auto_patch(self.n) if cfg.patch == 0 else int(cfg.patch)
        if self.n % self.p:
            raise ValueError(f"patch: {self.p} does not divide the {self.n} latent tokens")
        self.config["patch"] = self.p  # resolved, so a checkpoint rebuilds the same model
        self.m = self.n // self.p  # denoiser tokens of the noisy latent
        self.sched = Schedule()
        self.in_proj = nn.Linear(self.p * self.d, W)
        self.content_proj = None if cfg.use_remover else nn.Linear(self.p * self.d, W)
        self.remover = StyleRemover(self.n, self.d, W, cfg.heads, cfg.remover_layers, cfg.remover_norm,
                                    cfg.content_bottleneck, self.p) \
            if cfg.use_remover else None
        self.n_content = self.m - 1 if cfg.use_remover else self.m
        self.token_pos = nn.Parameter(torch.randn(1, self.n_content + self.m, W) * 0.02)
        self.time = TimestepEmbedding(W)
        self.style_proj = nn.Linear(int(style_dim), W)
        self.traj = TrajectoryEncoder(W, cfg.heads, cfg.traj_layers, cfg.traj_down, self.m if cfg.traj_frames else 0,
                                      cfg.traj_frames) if cfg.use_traj else None
        self.blocks = nn.ModuleList(Block(W, cfg.heads, cfg.mlp_ratio) for _ in range(cfg.blocks))
        self.norm_out = nn.LayerNorm(W, elementwise_affine=False, eps=1e-6)
        self.out = nn.Linear(W, self.p * self.d)
        # "from scratch" ablation: a fresh style encoder trained by the diffusion loss alone
        self.style_net = None if cfg.pretrained_style else SE.MotionEncoder(
            SE.StyleExtractorConfig.from_dict(style_cfg or {}))

    def conditions(self, z_content: torch.Tensor, style: torch.Tensor, traj: torch.Tensor | None,
                   traj_mask: torch.Tensor | None) -> dict:
        """Per-clip conditions, computed once: content tokens (B, N−1, W), style (B, W), trajectory (B, W)
        or, per token, (B, N, W) (N: denoiser tokens)."""
        c = self.remover(z_content) if self.remover is not None else \
            self.content_proj(patchify(z_content, self.p))  # B Eq. 6
        tr = self.traj(traj, traj_mask) if self.traj is not None else torch.zeros_like(c[:, 0])
        return {"content": c, "style": self.style_proj(style), "traj": tr}

    def denoise(self, z_t: torch.Tensor, t: torch.Tensor, cond: dict) -> torch.Tensor:
        """ε̂ for (B, N, d) noisy latents: [content tokens; noisy tokens] → blocks → the last N tokens."""
        temb = self.time(t)  # (B, W)
        h = torch.cat([cond["content"], self.in_proj(patchify(z_t, self.p))], 1) + self.token_pos  # B Eq. 6
        c_style, c_traj = temb + cond["style"], cond["traj"]
        if c_traj.dim() == 3:  # per token: the content prefix gets the clip's mean trajectory feature
            c_traj = torch.cat([c_traj.mean(1, keepdim=True).expand(-1, self.n_content, -1), c_traj], 1)
        c_traj = per_token(temb) + c_traj if c_traj.dim() == 3 else temb + c_traj  # (B, L, W) or (B, W)
        for blk in self.blocks:
            h = blk(h, c_style, c_traj)
        return self.out(self.norm_out(h[:, self.n_content:])).reshape(z_t.shape)  # (B, N/p, p·d) → (B, N, d)

    def _style_of(self, batch: dict) -> torch.Tensor:
        if self.style_net is None:
            return batch["style"]
        return self.style_net(batch["style_window"])

    def training_step(self, batch: dict) -> dict:
        z0, B = batch["z0"], batch["z0"].shape[0]
        style = self._style_of(batch)
        keep = (torch.rand(B, device=z0.device) >= self.cfg.p_drop_style).to(z0.dtype)[:, None]
        style = style * keep  # null style = zeros, 25% of the time
        T = int(batch["length"].max())
        traj_mask = torch.arange(T, device=z0.device)[None] < batch["length"][:, None]
        zc = batch["zc"]
        if self.cfg.content_noise > 0:
            zc = zc + self.cfg.content_noise * torch.randn_like(zc)
        cond = self.conditions(zc, style, batch["traj"][:, :T], traj_mask)
        t = self.sched.sample_timesteps(B, device=z0.device)
        z_t, eps = self.sched.training_pair(z0, t)
        return {"loss": eps_loss(self.denoise(z_t, t, cond), eps)}  # B Eq. 4

    @torch.no_grad()
    def sample(self, cond: dict, null_style: torch.Tensor, shape: tuple, scale: float | None = None,
               steps: int | None = None, generator: torch.Generator | None = None, callback=None) -> torch.Tensor:
        """DDIM with classifier-free guidance; cond and uncond in one batched forward per step (B Eq. 5)."""
        scale = self.cfg.cfg_scale if scale is None else float(scale)
        both = {k: torch.cat([v, v]) for k, v in cond.items()}
        both["style"] = torch.cat([cond["style"], null_style.expand_as(cond["style"])])

        def eps_fn(x, t):
            e = self.denoise(torch.cat([x, x]), torch.cat([t, t]), both)
            e_c, e_u = e.chunk(2)
            return cfg_combine(e_u, e_c, scale)

        return ddim_sample(eps_fn, shape, self.sched, n_steps=steps or self.cfg.ddim_steps,
                           generator=generator, callback=callback)

