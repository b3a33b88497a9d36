"""Paper D: ClusterStyle — a text-to-motion latent diffusion model with a Stylistic Modulation Adapter.

Three training stages, each a `python -m mslib train NAME` entry (TRAINABLE below):
  clusterstyle_style  the style encoder and its global/local prototypes (D §3.2–3.3, `prototypes.py`);
  clusterstyle_t2m    text-to-motion latent diffusion on the content corpus and its captions — the
                      "pre-trained MLD" D builds on (VAE: `vae.py`); the text slot is a `text.py`
                      TextEncoder learned jointly here, over the words of *all* built-in captions
                      (the packaged style_extractor's text tower only knows the style corpus's words,
                      so "waves", "side steps", "backward" would all read as <unk>);
  clusterstyle        the SMA's style branch and λ (D Eq. 11), trained on the style corpus with the
                      rest frozen, plus the content-prior loss on content clips (D Eq. 1–3).
Inference (CFG, prototype guidance, SDEdit transfer, the bench entry): `clusterstyle_guidance.py`.

Course simplification: the style encoder is trained in its own stage and then frozen (D trains it
jointly with the SMA, L = L_diff + λ·L_style); its tokens are precomputed once per clip, which keeps
every stage within CPU minutes.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import torch
from torch import nn

from ...checkpoints import course_path, load_state, read_checkpoint
from ..common.diffusion import Schedule, eps_loss
from ..common.layers import TimestepEmbedding
from .prototypes import PrototypeConfig, PrototypeStyleModel
from ..common.text import TextConfig, TextEncoder

STYLE_NAME, T2M_NAME, NAME = "clusterstyle_style", "clusterstyle_t2m", "clusterstyle"
MAX_STYLE_ROWS = 64  # the style encoder reads at most this many rows of a clip (6 local windows)


@dataclass
class ClusterStyleConfig:
    """Denoiser and training settings; defaults are paper D's (§3.5, App. A), `course()` the CPU preset."""

    dim: int = 256
    layers: int = 9
    heads: int = 4
    ff_mult: int = 4
    text_drop: float = 0.1  # D App. A.1: each condition dropped with probability 0.1
    style_drop: float = 0.1
    lambda_init: float = 1.0  # λ of D Eq. 11 (learnable)
    content_weight: float = 1.0  # weight of the content-prior loss (D Eq. 2–3)
    max_style_tokens: int = 1 + MAX_STYLE_ROWS // 10 + 8
    # inference (clusterstyle_guidance.py)
    ddim_steps: int = 50
    cfg_text: float = 2.5
    cfg_style: float = 2.5
    t0: int = 600  # SDEdit start step (SMooDi restarts at ≈ 581 of 1000)
    guide_weight: float = 0.4  # w of D Eq. 15 (its value is lost in our copy of D; 0.4 is SMooDi's transfer scale)
    guide_below: int = 300  # D App. A.2: classifier-based style guidance only for t < 300

    @classmethod
    def course(cls, **kw) -> "ClusterStyleConfig":
        """CPU preset: a 4-layer, 96-wide denoiser on the course VAE's 50×16 latent; 20 DDIM steps. Style by
        classifier-based guidance (D §3.5: "classifier guidance for style motions") with w = 1500 — the cosine's
        gradient on this latent has norm ≈ 0.1, so w ≈ 1 does nothing — and the style branch at its plain
        conditional strength (s_s = 1); both chosen on a validation draw (`tools/clusterstyle_findings.py
        --only guidance`)."""
        base = dict(dim=96, layers=4, heads=4, ff_mult=2, ddim_steps=20, cfg_style=1.0, guide_weight=1500.0)
        base.update(kw)
        return cls(**base)

    @classmethod
    def from_dict(cls, d: dict) -> "ClusterStyleConfig":
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in d.items() if k in known})


# ---------------------------------------------------------------- the Stylistic Modulation Adapter
class SMA(nn.Module):
    """D Eq. 11: h = CrossAttn(z, text) + λ·CrossAttn(z, style), λ a learnable scalar."""

    def __init__(self, dim: int, heads: int, lambda_init: float = 1.0):
        super().__init__()
        self.text_attn = nn.MultiheadAttention(dim, heads, batch_first=True)
        self.style_attn = nn.MultiheadAttention(dim, heads, batch_first=True)
        nn.init.zeros_(self.style_attn.out_proj.weight)  # the adapter starts as a no-op (IP-Adapter style)
        nn.init.zeros_(self.style_attn.out_proj.bias)
        self.lam = nn.Parameter(torch.tensor(float(lambda_init)))

    def forward(self, h, text, text_pad, style=None, style_pad=None, style_keep=None):
        """h (B, N, D); text (B, L, D) with pad (B, L) True on padding; style (B, S, D), keep (B,) 0/1."""
        out = self.text_attn(h, text, text, key_padding_mask=text_pad, need_weights=False)[0]  # content branch
        if style is not None:
            s = self.style_attn(h, style, style, key_padding_mask=style_pad, need_weights=False)[0]  # style branch
            if style_keep is not None:
                s = s * style_keep.to(s.dtype)[:, None, None]  # dropped style: the branch is silent
            out = out + self.lam * s  # D Eq. 11
        return out


class Block(nn.Module):
    """Pre-norm transformer block: self-attention → SMA (cross-attention to text and style) → MLP."""

    def __init__(self, dim: int, heads: int, ff_mult: int, lambda_init: float):
        super().__init__()
        self.n1, self.n2, self.n3 = nn.LayerNorm(dim), nn.LayerNorm(dim), nn.LayerNorm(dim)
        self.attn = nn.MultiheadAttention(dim, heads, batch_first=True)
        self.sma = SMA(dim, heads, lambda_init)
        self.mlp = nn.Sequential(nn.Linear(dim, ff_mult * dim), nn.GELU(), nn.Linear(ff_mult * dim, dim))

    def forward(self, h, text, text_pad, style=None, style_pad=None, style_keep=None):
        x = self.n1(h)
        h = h + self.attn(x, x, x, need_weights=False)[0]
        h = h + self.sma(self.n2(h), text, text_pad, style, style_pad, style_keep)
        return h + self.mlp(self.n3(h))


class Denoiser(nn.Module):
    """ε̂(z_t, t, text, style) on latent tokens (B, N, d_z)."""

    def __init__(self, cfg: ClusterStyleConfig, latent_tokens: int, latent_dim: int, text_dim: int, style_dim: int):
        super().__init__()
        d = cfg.dim
        self.inp = nn.Linear(latent_dim, d)
        self.pos = nn.Parameter(torch.randn(1, latent_tokens, d) * 0.02)
        self.time = TimestepEmbedding(d)
        self.text_proj = nn.Linear(text_dim, d)
        self.style_proj = nn.Linear(style_dim, d)
        self.style_pos = nn.Parameter(torch.randn(1, cfg.max_style_tokens, d) * 0.02)  # token 0 global, then local
        self.blocks = nn.ModuleList(Block(d, cfg.heads, cfg.ff_mult, cfg.lambda_init) for _ in range(cfg.layers))
        self.norm = nn.LayerNorm(d)
        self.out = nn.Linear(d, latent_dim)

    def style_parameters(self) -> list:
        """The SMA's style branch and λ: what the `clusterstyle` stage trains (D §3.5)."""
        params = [*self.style_proj.parameters(), self.style_pos]
        for b in self.blocks:
            params += [*b.sma.style_attn.parameters(), b.sma.lam]
        return params

    def forward(self, z_t, t, text, text_pad, style=None, style_pad=None, style_keep=None):
        if style is not None and style.shape[1] > self.style_pos.shape[1]:
            raise ValueError(f"style: {style.shape[1]} tokens, at most {self.style_pos.shape[1]}")
        h = self.inp(z_t) + self.pos + self.time(t)[:, None]  # (B, N, D)
        tx = self.text_proj(text)  # (B, L, D)
        st = None if style is None else self.style_proj(style) + self.style_pos[:, :style.shape[1]]
        for blk in self.blocks:
            h = blk(h, tx, text_pad, st, style_pad, style_keep)
        return self.out(self.norm(h))


# ---------------------------------------------------------------- the model and its training steps
class ClusterStyle(nn.Module):
    """Denoiser + style model; `stage` picks the training objective ("t2m" or "sma")."""

    def __init__(self, cfg: ClusterStyleConfig, style_cfg: PrototypeConfig, latent_tokens: int, latent_dim: int,
                 vocab: list, text_cfg: TextConfig | None = None, stage: str = "sma"):
        super().__init__()
        if stage not in ("t2m", "sma"):
            raise ValueError(f"stage: expected 't2m' or 'sma', got {stage!r}")
        text_cfg = text_cfg or TextConfig(dim=64, out_dim=64, heads=4, layers=1)
        self.cfg, self.style_cfg, self.stage = cfg, style_cfg, stage
        self.config = {"model": asdict(cfg), "prototypes": asdict(style_cfg), "latent_tokens": latent_tokens,
                       "latent_dim": latent_dim, "text": {"vocab": list(vocab), **asdict(text_cfg)}}
        self.text = TextEncoder(vocab, text_cfg)  # the text slot: anything with encode_text(list) -> (B, D)
        self.denoiser = Denoiser(cfg, latent_tokens, latent_dim, text_cfg.out_dim, style_cfg.dim)
        self.style = PrototypeStyleModel(style_cfg)
        self.sched = Schedule(1000, 0.00085, 0.012)  # FIELD_FACTS "MCM-LDM"; D builds on MLD's schedule

    @classmethod
    def from_config(cls, config: dict, stage: str = "sma") -> "ClusterStyle":
        return cls(ClusterStyleConfig.from_dict(config["model"]), PrototypeConfig(**config["prototypes"]),
                   config["latent_tokens"], config["latent_dim"], config["text"]["vocab"],
                   TextConfig.from_dict(config["text"]), stage)

    def text_tokens(self, captions: list) -> tuple:
        """Captions → text tokens (B, 1, Dt) (the pooled caption embedding) and padding (B, 1)."""
        uniq = sorted(set(captions))
        emb = self.text.encode_text(uniq)  # (U, Dt)
        where = {c: i for i, c in enumerate(uniq)}
        tokens = emb[torch.tensor([where[c] for c in captions], device=emb.device)][:, None]
        return tokens, torch.zeros(len(captions), 1, dtype=torch.bool, device=emb.device)

    def freeze_for_sma(self) -> list:
        """Stage 3 (D §3.5): freeze everything but the SMA's style branch and λ; returns those parameters."""
        for p in self.parameters():
            p.requires_grad_(False)
        params = self.denoiser.style_parameters()
        for p in params:
            p.requires_grad_(True)
        self.stage = "sma"
        return params

    def _drop(self, n: int, p: float, device) -> torch.Tensor:
        return (torch.rand(n, device=device) >= p) if self.training else torch.ones(n, dtype=torch.bool, device=device)

    def diffusion_loss(self, batch: dict, with_style: bool) -> torch.Tensor:
        """ε-MSE of a batch of precomputed latents (D Eq. 1 with style, the t2m objective without)."""
        z0 = batch["z"]
        t = self.sched.sample_timesteps(len(z0), device=z0.device)
        z_t, target = self.sched.training_pair(z0, t)
        text, text_pad = null_text(*self.text_tokens(batch["caption"]), self._drop(len(z0), self.cfg.text_drop, z0.device))
        style = style_pad = keep = None
        if with_style:
            style, style_pad = batch["style"], batch["style_pad"]
            keep = self._drop(len(z0), self.cfg.style_drop, z0.device)
        return eps_loss(self.denoiser(z_t, t, text, text_pad, style, style_pad, keep), target)

    def training_step(self, batch: dict) -> dict:
        if self.stage == "t2m":
            loss = self.diffusion_loss(batch, with_style=False)
            return {"loss": loss}
        is_style = batch["is_style"].bool()
        logs, total = {}, 0.0
        for name, rows, w in (("style_diff", is_style, 1.0), ("content_prior", ~is_style, self.cfg.content_weight)):
            if rows.any():  # D Eq. 3: L = L_style-diff + w·L_content-prior (L_style: the frozen stage)
                idx = rows.nonzero().squeeze(1).tolist()
                part = self.diffusion_loss({k: ([v[i] for i in idx] if isinstance(v, list) else v[rows])
                                            for k, v in batch.items()}, with_style=True)
                total = total + w * part
                logs[name] = part.detach()
        logs["loss"] = total
        logs["lambda"] = float(torch.stack([b.sma.lam.detach() for b in self.denoiser.blocks]).mean())
        return logs

    @torch.no_grad()
    def validation_step(self, batch: dict) -> dict:
        with torch.random.fork_rng(devices=[]):  # fixed timesteps and noise, the training stream untouched
            torch.manual_seed(0)
            return {"eps_mse": float(self.diffusion_loss(batch, with_style=self.stage == "sma"))}


def null_text(text: torch.Tensor, pad: torch.Tensor, keep: torch.Tensor) -> tuple:
    """Classifier-free dropping of the text: dropped rows become one zero token (B, L, D), pad (B, L)."""
    if bool(keep.all()):
        return text, pad
    k = keep.to(text.dtype)[:, None, None]
    null_pad = torch.ones_like(pad)
    null_pad[:, 0] = False
    return text * k, torch.where(keep[:, None], pad, null_pad)


# ---------------------------------------------------------------- the frozen parts and checkpoints
def load_clusterstyle(path=None, device="cpu", name: str = NAME, stage: str = "sma") -> ClusterStyle:
    """A ClusterStyle checkpoint (default: the packaged course `clusterstyle.pt`), in eval mode."""
    path = course_path(name) if path is None else path
    blob = read_checkpoint(path, name)
    model = ClusterStyle.from_config(blob["config"], stage)
    load_state(path, model, name)
    return model.to(device).eval()
