"""Paper D inference: three-way classifier-free guidance, style guidance by the prototypes' feature space,
stylized generation, SDEdit style transfer and the prototype variants of D Fig. 5.

    pipe = load_pipeline(device="cpu")            # the course VAE + ClusterStyle checkpoints
    raw = pipe.transfer(content_raw, style_raw, caption=None, t0=600)     # (T−1, 263) unnormalised
    raw = pipe.generate("a person walks forward", style_raw, length=63, seed=0)
    raws = pipe.variants(content_raw, style_raw, kind="global")           # one output per global prototype

At each DDIM step t (deterministic, η = 0; `common/diffusion.py`), with text c and style representation s:

    CFG        ε̃ = ε(∅,∅) + s_t·(ε(c,∅) − ε(∅,∅)) + s_s·(ε(c,s) − ε(c,∅)),  ε(c,s) = ε_θ(z_t, t, c, s)   (D Eq. 12)
    x̂₀         x̂₀ = (z_t − √(1 − ᾱ_t)·ε̃) / √ᾱ_t                                                    (D Eq. 13)
    guidance   G = cos(f(D(x̂₀)), target), D the VAE decoder, f the style encoder's feature:       (D Eq. 14)
                 the global feature against the reference's (the transfer default) or a global
                 prototype p_k (D Eq. 16); or (1/W)·Σ_j cos(f_l^j, p_{k_j}), the local features
                 against chosen local prototypes (D Eq. 17)
    update     ε̂ = ε̃ − w·√(1 − ᾱ_t)·∇_{z_t} G,  only for t < guide_below (D App. A.2: 300)        (D Eq. 15)

Transfer is SDEdit (D App. C): encode the content, noise it to t₀ (z_{t₀} = √ᾱ_{t₀} z₀ + √(1 − ᾱ_{t₀}) ε),
denoise from t₀ with the above, decode. Generation starts from pure noise at t = T − 1.

Cost per step: the three CFG rows in one batched denoiser call, the conditions' parts computed once per
sample (`Denoiser.sampler`); the guidance gradient (decode, style feature, backprop) only below the
threshold and with autograd only there, decoding only the latent tokens the style encoder's rows read
(`decode_rows`).

Departures from D: the guidance's style feature is ClusterStyle's own style encoder (D App. A.2 trains a
separate style feature extractor, after SMooDi), so that the prototypes and the guidance share one space;
w is on the scale of the course latent (see ClusterStyleConfig).
"""
from __future__ import annotations

import itertools

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ..common.diffusion import ddim_sample
from ..common.layers import ResBlock1d
from ..common.vae import load_vae
from ...motion.features import N_FEATURES, decode
from .model import MAX_STYLE_ROWS, ClusterStyle, load_clusterstyle, null_text


class Pipeline:
    """A trained ClusterStyle (text encoder inside) with its frozen VAE, for sampling."""

    def __init__(self, model: ClusterStyle, vae, device="cpu"):
        self.device = torch.device(device)
        self.model, self.vae = model.to(self.device).eval(), vae.to(self.device).eval()
        self.cfg = model.cfg

    # ---------------------------------------------------------------- conditions
    def normalize(self, raw) -> torch.Tensor:
        """Unnormalised (T, 263) → normalised (T, 263) tensor with the VAE's statistics."""
        x = torch.as_tensor(np.asarray(raw), dtype=torch.float32, device=self.device)
        if x.ndim != 2 or x.shape[1] != N_FEATURES:
            raise ValueError(f"features: expected (T, {N_FEATURES}), got shape {tuple(x.shape)}")
        return self.vae.normalize(x)

    @torch.no_grad()
    def style_tokens(self, style_raw) -> torch.Tensor:
        """[global; local] style features of a reference motion, (1, 1 + W, Ds) (D §3.3)."""
        return self.model.style.style_tokens(self.normalize(style_raw)[None, :MAX_STYLE_ROWS])

    @torch.no_grad()
    def text_tokens(self, caption: str | None) -> tuple:
        """Caption tokens (1, L, Dt) and padding (1, L); None → the null text (one zero token)."""
        tokens, pad = self.model.text_tokens(["" if caption is None else caption])
        if caption is None:
            return null_text(tokens, pad, torch.zeros(1, dtype=torch.bool, device=self.device))
        return tokens, pad

    @torch.no_grad()
    def nearest_global_prototype(self, tokens: torch.Tensor) -> tuple[int, int]:
        """(style c, prototype k) of the global prototype nearest (cosine) to the global feature of `tokens`."""
        protos = F.normalize(self.model.style.global_bank.prototypes, dim=-1)  # (C, K, D)
        sim = torch.einsum("d,ckd->ck", F.normalize(tokens[0, 0], dim=0), protos)  # (C, K)
        c, k = divmod(int(sim.argmax()), sim.shape[1])
        return c, k

    def style_of(self, tokens: torch.Tensor) -> int:
        """The style a reference belongs to: the style of its nearest global prototype (no labels)."""
        return self.nearest_global_prototype(tokens)[0]

    def prototype_tokens(self, tokens: torch.Tensor, global_k: int | None = None, local_perm=None,
                         style: int | None = None) -> torch.Tensor:
        """Style tokens with the global feature replaced by global prototype k and/or the local ones by
        the local prototypes in `local_perm` order (D §4.4, Fig. 5)."""
        bank = self.model.style
        c = self.style_of(tokens) if style is None else int(style)
        out = tokens.clone()
        if global_k is not None:
            out[0, 0] = bank.global_bank.prototypes[c, int(global_k)]
        if local_perm is not None:
            for j in range(1, out.shape[1]):
                out[0, j] = bank.local_bank.prototypes[c, int(local_perm[(j - 1) % len(local_perm)])]
        return out

    # ---------------------------------------------------------------- the guided noise prediction
    def eps_fn(self, text, text_pad, style, n_rows: int, target=None, cfg_text=None, cfg_style=None,
               weight=None, below=None):
        """ε̂(z_t, t): three-way CFG (D Eq. 12), then style guidance for t < `below` (D Eq. 15).

        text (1, 1, Dt) and pad (1, 1); style (1, S, Ds); n_rows: the clip's length in feature rows;
        target: None, or ("global", (D,) unit vector), or ("local", (W, D) unit vectors)."""
        st = self.cfg.cfg_text if cfg_text is None else cfg_text
        ss = self.cfg.cfg_style if cfg_style is None else cfg_style
        w = self.cfg.guide_weight if weight is None else weight
        below = self.cfg.guide_below if below is None else below
        den, sched = self.model.denoiser, self.model.sched
        null_tx, null_pad = null_text(text, text_pad, torch.zeros(1, dtype=torch.bool, device=self.device))
        texts = torch.cat([null_tx, text, text])
        pads = torch.cat([null_pad, text_pad, text_pad])
        styles = style.expand(3, -1, -1)
        keep = torch.tensor([0.0, 0.0, 1.0], device=self.device)
        denoise = den.sampler(texts, pads, styles, keep)  # the conditions' parts computed once, not per step

        def fn(z_t, t):
            e = denoise(z_t.expand(3, -1, -1), t.expand(3))  # (3, N, d): ε(∅,∅), ε(c,∅), ε(c,s) in one call
            eps = e[0:1] + st * (e[1:2] - e[0:1]) + ss * (e[2:3] - e[1:2])  # D Eq. 12, (1, N, d)
            if target is not None and w > 0 and int(t[0]) < below:  # autograd only at these steps
                eps = eps - w * (1 - float(sched.alphas_cumprod[int(t[0])])) ** 0.5 * self.guidance_grad(
                    z_t, t, eps, n_rows, target)  # D Eq. 15: ε̂ = ε̃ − w·√(1 − ᾱ_t)·∇_{z_t} G
            return eps
        return fn

    def guidance_grad(self, z_t, t, eps, n_rows: int, target) -> torch.Tensor:
        """∇_{z_t} G, G = cos(f(D(x̂₀)), target) (D Eq. 14, 16, 17), ε̂ held fixed (x̂₀: D Eq. 13)."""
        with torch.enable_grad():
            z = z_t.detach().requires_grad_(True)
            x0 = self.model.sched.predict_x0(z, t, eps.detach())  # D Eq. 13
            motion = decode_rows(self.vae, x0, min(n_rows, MAX_STYLE_ROWS))  # (1, ≤64, 263) normalised
            g, loc = self.model.style.features(motion)
            kind, tgt = target
            if kind == "global":
                score = F.cosine_similarity(g[0], tgt, dim=0)  # D Eq. 14 (reference) / 16 (prototype)
            else:
                n = min(len(tgt), loc.shape[1])
                score = F.cosine_similarity(loc[0, :n], tgt[:n], dim=1).mean()  # D Eq. 17
            (grad,) = torch.autograd.grad(score, z)
        return grad

    # ---------------------------------------------------------------- sampling
    def _sample(self, z_start, t_start, text, text_pad, style, n_rows, target, seed, **kw) -> np.ndarray:
        gen = torch.Generator().manual_seed(int(seed))
        if z_start is None:  # generation: pure noise
            shape = (1, self.model.config["latent_tokens"], self.model.config["latent_dim"])
            z_start = torch.randn(shape, generator=gen).to(self.device)
        else:  # SDEdit: q(z_{t₀} | z₀)
            noise = torch.randn(z_start.shape, generator=gen).to(z_start)
            z_start = self.model.sched.q_sample(z_start, torch.full((1,), int(t_start), dtype=torch.long), noise)
        fn = self.eps_fn(text, text_pad, style, n_rows, target, **kw)
        z0 = ddim_sample(fn, z_start, self.model.sched, n_steps=self.cfg.ddim_steps, t_start=t_start, generator=gen)
        with torch.no_grad():
            x = self.vae.denormalize(decode_rows(self.vae, z0, n_rows))[0]
        return x.double().cpu().numpy()

    def _target(self, guide, style_tokens):
        """Guidance target from a spec: "reference", None, ("global", k) or ("local", permutation)."""
        if guide is None:
            return None
        if guide == "reference":
            return ("global", style_tokens[0, 0])
        kind, arg = guide
        c = self.style_of(style_tokens)
        if kind == "global":
            return ("global", self.model.style.global_bank.prototypes[c, int(arg)])
        if kind == "local":
            return ("local", self.model.style.local_bank.prototypes[c, torch.as_tensor(list(arg))])
        raise ValueError(f"guide: expected None, 'reference', ('global', k) or ('local', perm), got {guide!r}")

    def transfer(self, content_raw, style_raw, caption: str | None = None, t0: int | None = None,
                 guide="reference", seed: int = 0, style_tokens=None, **kw) -> np.ndarray:
        """SDEdit transfer (D App. C): encode the content, noise to t₀, denoise with the style → (T−1, 263)."""
        x = self.normalize(content_raw)[: self.vae.cfg.max_len]
        t0 = self.cfg.t0 if t0 is None else int(t0)
        if not 0 <= t0 < self.model.sched.steps:
            raise ValueError(f"t0: must lie in [0, {self.model.sched.steps}), got {t0}")
        with torch.no_grad():
            z_c = self.vae.encode(x[None])  # (1, N, d)
        s = self.style_tokens(style_raw) if style_tokens is None else style_tokens
        text, pad = self.text_tokens(caption)
        return self._sample(z_c, t0, text, pad, s, len(x), self._target(guide, s), seed, **kw)

    def generate(self, caption: str | None, style_raw, length: int = 63, guide="reference", seed: int = 0,
                 style_tokens=None, **kw) -> np.ndarray:
        """Stylized generation from (caption, style motion) (D §4.2): pure noise → (length, 263)."""
        if not 1 <= int(length) <= self.vae.cfg.max_len:
            raise ValueError(f"length: must lie in [1, {self.vae.cfg.max_len}], got {length}")
        s = self.style_tokens(style_raw) if style_tokens is None else style_tokens
        text, pad = self.text_tokens(caption)
        return self._sample(None, None, text, pad, s, int(length), self._target(guide, s), seed, **kw)

    def variants(self, content_raw, style_raw, kind: str = "global", caption=None, seed=0,
                 n: int | None = None, mode: str = "transfer", length: int = 63, **kw) -> list:
        """D Fig. 5: one output per global prototype (kind="global") or per permutation of local
        prototypes (kind="local"), each used as the style feature and as the guidance target.
        `seed`: one seed for every variant, or a sequence with one seed per variant."""
        s = self.style_tokens(style_raw)
        cfg = self.model.style_cfg
        if kind == "global":
            specs = [(self.prototype_tokens(s, global_k=k), ("global", k)) for k in range(cfg.k_global)]
        elif kind == "local":  # random permutations of the style's local prototypes, one per segment
            rng = np.random.default_rng(seed if np.isscalar(seed) else seed[0])
            perms = [rng.permutation(cfg.k_local)[: s.shape[1] - 1].tolist() for _ in range(n or cfg.k_global)]
            specs = [(self.prototype_tokens(s, local_perm=p), ("local", p)) for p in perms]
        else:
            raise ValueError(f"kind: expected 'global' or 'local', got {kind!r}")
        specs = specs[: n or len(specs)]
        seeds = [int(seed)] * len(specs) if np.isscalar(seed) else [int(x) for x in seed]
        if len(seeds) != len(specs):
            raise ValueError(f"seed: expected one seed or {len(specs)} seeds, got {len(seeds)}")
        out = []
        for (tokens, guide), sd in zip(specs, seeds):
            if mode == "transfer":
                out.append(self.transfer(content_raw, style_raw, caption, guide=guide, seed=sd, style_tokens=tokens, **kw))
            else:
                out.append(self.generate(caption, style_raw, length, guide=guide, seed=sd, style_tokens=tokens, **kw))
        return out

    def seed_variants(self, content_raw, style_raw, seeds=(0, 1, 2), caption=None, mode: str = "transfer",
                      length: int = 63, **kw) -> list:
        """The same reference style feature (and guidance) with different seeds — D Fig. 5's baseline."""
        if mode == "transfer":
            return [self.transfer(content_raw, style_raw, caption, seed=s, **kw) for s in seeds]
        return [self.generate(caption, style_raw, length, seed=s, **kw) for s in seeds]


# ---------------------------------------------------------------- decoding only what is read
def last_input(module: nn.Module, last: int) -> int:
    """The last input position that output positions 0..`last` of a stack of 1-D convolutions read."""
    if isinstance(module, nn.Sequential):
        for m in reversed(module):
            last = last_input(m, last)
        return last
    if isinstance(module, ResBlock1d):  # x + body(x)
        return max(last, last_input(module.body, last))
    if isinstance(module, nn.ConvTranspose1d):  # output o = s·i − p + d·j, 0 ≤ j < k: i ≤ (o + p) / s
        return (last + module.padding[0]) // module.stride[0]
    if isinstance(module, nn.Conv1d):  # output o reads inputs s·o − p + d·j, 0 ≤ j < k
        return last * module.stride[0] - module.padding[0] + module.dilation[0] * (module.kernel_size[0] - 1)
    if isinstance(module, (nn.LeakyReLU, nn.ReLU, nn.GELU, nn.SiLU, nn.Identity)):  # pointwise
        return last
    raise TypeError(f"last_input: no rule for {type(module).__name__}")


# Fewest latent tokens `decode_rows` decodes. The rows' receptive field needs fewer (21 for 64 rows), but PyTorch
# picks a convolution's CPU kernel by input size (oneDNN for one clip above 20480 input values), and only from
# 27 tokens (108 frames × 192 channels) do the course VAE's full-resolution layers run the kernel they run in a
# whole-latent decode; with fewer, the guidance changes in the last float digits.
MIN_DECODE_TOKENS = 27


def decode_rows(vae, z: torch.Tensor, rows: int) -> torch.Tensor:
    """The first `rows` rows of the VAE's decoding of z (B, N, d) → (B, rows, 263), normalised.

    The course VAE's decoder is convolutional, so those rows read the first latent tokens only (its receptive
    field, `last_input`): only those are decoded — the same numbers as decoding all and cutting. Other VAEs
    decode the whole latent."""
    if vae.cfg.arch != "conv":
        return vae.decode(z, [rows] * len(z))[:, :rows]
    n = min(z.shape[1], max(MIN_DECODE_TOKENS, last_input(vae.conv.dec, rows - 1) + 1))
    return vae.conv.decode(z[:, :n] * vae.latent_scale)[:, :rows]


def pose_diversity(features_list: list) -> float:
    """Mean over pairs of outputs of their mean root-relative joint distance (cm) — how different they look."""
    if len(features_list) < 2:
        raise ValueError("features_list: need at least two motions")
    poses = []
    for f in features_list:
        p = decode(np.asarray(f, np.float64))
        poses.append(p - p[:, :1])  # root-relative positions (T, 22, 3)
    n = min(len(p) for p in poses)
    d = [np.linalg.norm(a[:n] - b[:n], axis=-1).mean() for a, b in itertools.combinations(poses, 2)]
    return float(100 * np.mean(d))


# ---------------------------------------------------------------- loading and the bench entry
def load_pipeline(device="cpu", path=None, vae_path=None) -> Pipeline:
    """The packaged course ClusterStyle (with its text encoder) and the course VAE."""
    return Pipeline(load_clusterstyle(path, device), load_vae(vae_path, device), device)


def clusterstyle_method(device="cpu"):
    """transfer(content, style) → stylized features: SDEdit with the course checkpoints."""
    pipe = load_pipeline(device)

    def transfer(content: dict, style: dict) -> np.ndarray:
        return pipe.transfer(content["features"], style["features"], caption=content.get("caption") or None, seed=0)
    transfer.n_parameters = sum(p.numel() for m in (pipe.model, pipe.vae) for p in m.parameters())
    return transfer
