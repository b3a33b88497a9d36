"""Paper D: ClusterStyle — text-to-motion latent diffusion with a Stylistic Modulation Adapter (D §3.1, §3.4).

A denoiser ε_θ(z_t, t, c, s) works on the motion VAE's latent z (the `common/vae.py` course VAE: a
temporal latent of N tokens); text c enters by cross-attention, the style representation s = [f_g; f_l]
of `prototypes.py` by a second, parallel cross-attention — the SMA:

    h = CrossAttn(z, c) + λ · CrossAttn(z, s),  λ a learnable scalar                        (D Eq. 11)

Training (noising z_t = √ᾱ_t z₀ + √(1 − ᾱ_t) ε, `common/diffusion.py`):

    L_style-diff    = E ‖ε − ε_θ(z_t, t, c, s)‖²          style clips, captions without style words  (D Eq. 1)
    L_content-prior = E ‖ε − ε_θ(z_t^c, t, c^c, s^c)‖²    content clips, with their own style feature (D Eq. 2)
    L = L_style-diff + w·L_content-prior   (+ λ_s·L_style of the style encoder in D Eq. 3 — see below)

Each condition is dropped with probability 0.1 for classifier-free guidance (D App. A.1): a dropped text
is one zero token, a dropped style silences the SMA's style branch.

Three stages, each a `python -m mslib train NAME` entry (`train.py`):
  clusterstyle_style  the style encoder and its prototypes (D §3.2–3.3, `prototypes.py`);
  clusterstyle_t2m    text-to-motion diffusion on the content corpus and its captions — the "pre-trained
                      MLD" D builds on; the text slot is a `common/text.py` TextEncoder learned jointly here,
                      over the words of *all* built-in captions (the packaged style_extractor's text tower only
                      knows the style corpus's words, so "waves", "side steps", "backward" would read as <unk>);
  clusterstyle        the SMA's style branch and λ on the style corpus, the rest frozen, plus the content
                      prior on content clips (D Eq. 1–3, §3.5: only the SMA and the style encoder train).
Inference — guidance, generation, SDEdit transfer, the bench entry — is `transfer.py`.

Departures from D, and why:
- The style encoder trains in its own stage and is then frozen (D trains it with the SMA, adding λ_s·L_style
  to Eq. 3): its tokens are then computed once per clip, which keeps every stage within CPU minutes.
- The text condition is one token, the pooled caption embedding of a small learned encoder (D: a frozen CLIP
  ViT-L/14), a slot that a real sentence encoder can fill.
- The latent is the course VAE's temporal one (one token per 4 frames; D, after MLD, uses a few latent
  vectors), and the denoiser a pre-norm transformer over its tokens (self-attention → SMA → MLP, the timestep
  embedding added to every token); D's sizes are lost in our copy, the `paper` defaults are MLD's (9 × 256).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import torch
import torch.nn.functional as F
from torch import nn

from ...checkpoints import course_path, load_state, read_checkpoint
from ..common.config import Config
from ..common.diffusion import Schedule, eps_loss
from ..common.layers import TimestepEmbedding
from ..common.text import TextConfig, TextEncoder
from .prototypes import PrototypeConfig, PrototypeStyleModel

STYLE_NAME, T2M_NAME, NAME = "clusterstyle_style", "clusterstyle_t2m", "clusterstyle"
MAX_STYLE_ROWS = 64  # the style encoder reads at most this many rows of a clip (6 local windows of the course's w)


@dataclass
class ClusterStyleConfig(Config):
    """Denoiser, training and inference settings; defaults are paper D's (§3.5, App. A), `course` the CPU recipe.

    The course recipe: a 4-layer, 96-wide denoiser on the course VAE's temporal latent, 20 DDIM steps. Style
    comes from classifier-based guidance (D §3.5: "classifier guidance for style motions") with a w in the
    thousands — on this latent the cosine's gradient is small next to a noise prediction (notebook 06 measures it), so a
    w of order 1 does nothing — and the SMA's style branch at its plain conditional strength (s_s = 1); both
    chosen on a validation draw (`tools/clusterstyle_findings.py --only guidance`), w by the best mean of that H and
    the H on real val pairs (`tools/real_val.py`)."""

    dim: int = 256
    layers: int = 9
    heads: int = 4
    ff_mult: int = 4
    text_drop: float = 0.1  # D App. A.1: each condition dropped with probability 0.1
    style_drop: float = 0.1
    lambda_init: float = 1.0  # λ of D Eq. 11 (learnable)
    content_weight: float = 1.0  # w of the content-prior loss (D Eq. 3, 19)
    max_style_tokens: int = 1 + MAX_STYLE_ROWS // 10 + 8  # style positions: [global; ≤ 6 local] + spare
    # inference (transfer.py)
    ddim_steps: int = 50  # D §3.5
    cfg_text: float = 2.5  # s_t of D Eq. 12
    cfg_style: float = 2.5  # s_s of D Eq. 12
    t0: int = 600  # SDEdit start step (D App. C's value is lost in our copy; SMooDi restarts at ≈ 581 of 1000)
    guide_weight: float = 0.4  # w of D Eq. 15 (its value is lost in our copy of D; 0.4 is SMooDi's transfer scale)
    guide_below: int = 300  # D App. A.2: classifier-based style guidance only for t < 300

    PRESETS: ClassVar[dict] = {
        "paper": {},
        "course": dict(dim=96, layers=4, ff_mult=2, ddim_steps=20, cfg_style=1.0, guide_weight=1500.0),
    }


# ---------------------------------------------------------------- the Stylistic Modulation Adapter
def attention_kv(attn: nn.MultiheadAttention, s: torch.Tensor) -> tuple:
    """Keys and values W_k s + b_k, W_v s + b_v of tokens s (B, S, D) for `attn`, each (B, heads, S, D/heads) —
    computed as nn.MultiheadAttention computes them, so that `attend` gives its numbers exactly."""
    d, heads = attn.embed_dim, attn.num_heads
    kv = F.linear(s.transpose(0, 1), attn.in_proj_weight[d:], attn.in_proj_bias[d:])  # (S, B, 2D)
    kv = kv.unflatten(-1, (2, d)).unsqueeze(0).transpose(0, -2).squeeze(-2).contiguous()  # (2, S, B, D)
    n, b = s.shape[1], s.shape[0]
    return tuple(x.view(n, b * heads, d // heads).transpose(0, 1).view(b, heads, n, d // heads) for x in kv)


def attend(attn: nn.MultiheadAttention, h: torch.Tensor, kv: tuple) -> torch.Tensor:
    """attn(h, s, s) (no masks, no dropout) from the keys and values of s precomputed by `attention_kv`:
    softmax(q kᵀ / √d_h) v per head, then W_o; h (B, N, D) → (B, N, D)."""
    d, heads = attn.embed_dim, attn.num_heads
    b, n = h.shape[0], h.shape[1]
    q = F.linear(h.transpose(0, 1), attn.in_proj_weight[:d], attn.in_proj_bias[:d])  # (N, B, D)
    q = q.view(n, b * heads, d // heads).transpose(0, 1).view(b, heads, n, d // heads)
    out = F.scaled_dot_product_attention(q, *kv).permute(2, 0, 1, 3).reshape(b * n, d)  # (N·B, D)
    return F.linear(out, attn.out_proj.weight, attn.out_proj.bias).view(n, b, d).transpose(0, 1)


@dataclass
class SamplingCache:
    """What the sampling steps reuse in one SMA: it depends on the conditions only, not on z_t or t."""

    text_out: torch.Tensor  # (B, N, D) the content branch (one text token: see `Denoiser.sampler`)
    style_kv: tuple | None  # keys and values of the style tokens of the rows that have a style, or None


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

    def cached(self, h, cache: SamplingCache, style_rows) -> torch.Tensor:
        """The same during sampling: the content branch precomputed, the style branch only on `style_rows` (B',)
        (the other rows' style is dropped, so their branch would be multiplied by 0)."""
        if cache.style_kv is None:
            return cache.text_out
        s = attend(self.style_attn, h[style_rows], cache.style_kv)  # (B', N, D)
        return cache.text_out.index_add(0, style_rows, self.lam * s)  # D Eq. 11 on those rows


class Block(nn.Module):
    """Pre-norm transformer block: self-attention → SMA (cross-attention to text and style) → MLP."""

    def __init__(self, dim: int, heads: int, ff_mult: int, lambda_init: float):
        super().__init__()
        self.n1, self.n2, self.n3 = nn.LayerNorm(dim), nn.LayerNorm(dim), nn.LayerNorm(dim)
        self.attn = nn.MultiheadAttention(dim, heads, batch_first=True)
        self.sma = SMA(dim, heads, lambda_init)
        self.mlp = nn.Sequential(nn.Linear(dim, ff_mult * dim), nn.GELU(), nn.Linear(ff_mult * dim, dim))

    def forward(self, h, text, text_pad, style=None, style_pad=None, style_keep=None, cache=None, style_rows=None):
        """h (B, N, D); the SMA's conditions, or (sampling) its `cache` and the rows that have a style."""
        x = self.n1(h)
        h = h + self.attn(x, x, x, need_weights=False)[0]
        x = self.n2(h)
        h = h + (self.sma(x, text, text_pad, style, style_pad, style_keep) if cache is None
                 else self.sma.cached(x, cache, style_rows))
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

    def project(self, text, style=None) -> tuple:
        """Text (B, L, Dt) and style (B, S, Ds) tokens at the model width (style tokens + their positions)."""
        if style is not None and style.shape[1] > self.style_pos.shape[1]:
            raise ValueError(f"style: {style.shape[1]} tokens, at most {self.style_pos.shape[1]}")
        st = None if style is None else self.style_proj(style) + self.style_pos[:, :style.shape[1]]
        return self.text_proj(text), st

    def forward(self, z_t, t, text, text_pad, style=None, style_pad=None, style_keep=None):
        tx, st = self.project(text, style)  # (B, L, D), (B, S, D)
        h = self.inp(z_t) + self.pos + self.time(t)[:, None]  # (B, N, D)
        for blk in self.blocks:
            h = blk(h, tx, text_pad, st, style_pad, style_keep)
        return self.out(self.norm(h))

    @torch.no_grad()
    def sampler(self, text, text_pad, style=None, style_keep=None):
        """ε̂(z_t, t) for the sampling steps — the same numbers as `forward` — with what depends on the
        conditions only computed once: the projected tokens, each SMA's content branch and its style keys and
        values. text (B, 1, Dt) one token per row (the pooled caption), style (B, S, Ds) unpadded, keep (B,) 0/1.

        With one text token the content branch's attention has one key, which takes all the weight whatever
        the query: CrossAttn(z, c) = W_o(W_v c + b_v) + b_o at every step (computed once, from a zero query)."""
        if text.shape[1] != 1:
            raise ValueError(f"text: the sampler takes one token per row, got {text.shape[1]}")
        tx, st = self.project(text, style)
        rows = None if style is None else torch.arange(len(st), device=st.device) if style_keep is None \
            else style_keep.nonzero().squeeze(1)  # (B',) the rows whose style branch runs
        rows = None if rows is None or len(rows) == 0 else rows
        zero_query = torch.zeros(len(tx), self.pos.shape[1], self.pos.shape[2], device=tx.device)  # (B, N, D)
        caches = [SamplingCache(b.sma.text_attn(zero_query, tx, tx, key_padding_mask=text_pad, need_weights=False)[0],
                                None if rows is None else attention_kv(b.sma.style_attn, st[rows]))
                  for b in self.blocks]

        def eps(z_t, t):  # z_t (B, N, d_z), t (B,) → ε̂ (B, N, d_z)
            h = self.inp(z_t) + self.pos + self.time(t)[:, None]  # (B, N, D)
            for blk, cache in zip(self.blocks, caches):
                h = blk(h, None, None, cache=cache, style_rows=rows)
            return self.out(self.norm(h))
        return eps


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
        self.config = {"model": cfg.to_dict(), "prototypes": style_cfg.to_dict(), "latent_tokens": latent_tokens,
                       "latent_dim": latent_dim, "text": {"vocab": list(vocab), **text_cfg.to_dict()}}
        self.text = TextEncoder(vocab, text_cfg)  # the text slot: anything with encode_text(list) -> (B, D)
        self.denoiser = Denoiser(cfg, latent_tokens, latent_dim, text_cfg.out_dim, style_cfg.dim)
        self.style = PrototypeStyleModel(style_cfg)
        self.sched = Schedule(1000, 0.00085, 0.012)  # MLD's "scaled linear" schedule, which D builds on (as B does)

    @classmethod
    def from_config(cls, config: dict, stage: str = "sma") -> "ClusterStyle":
        return cls(ClusterStyleConfig.from_dict(config["model"]), PrototypeConfig.from_dict(config["prototypes"]),
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
