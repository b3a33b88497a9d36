"""Paper D's style prototypes (D §3.2–3.3): a style encoder whose features cluster around K per-style
prototypes, so that one style is represented by several sub-style patterns, not one point.

A transformer style encoder E turns a motion x (T, 263) into per-frame tokens E(x) (T, D). Its style
features (D §3.3), all L2-normalised:

    global   f_g   = normalise(mean_t E(x)_t)                                               (D,)
    local    f_l^j = normalise(mean of E(x)_t over window j of w frames),  j = 1..W = ⌊T/w⌋   (W, D)

Each style c owns K global and K' local prototypes P^c = [p_1 … p_K] (unit vectors, D × K). They are
*not* trained by gradients (D §3.2):

    assignment   (D Eq. 4)  Q* = argmax_Q Tr(Qᵀ P^cᵀ F) + ε H(Q),  Q ∈ R₊^{K×N},  Q 1_N = 1_K/K,  Qᵀ 1_K = 1_N/N
                 F: the N features of style c in the batch, one per column; every feature assigned once,
                 every prototype about N/K times. A few Sinkhorn–Knopp iterations on exp(P^cᵀ F / ε), then
                 each feature's argmax is its prototype p⁺.
    update       (D Eq. 8)  p⁺ ← normalise(m·p⁺ + (1 − m)·mean of the features assigned to it)
    inter-style  (D Eq. 5)  L_inter = −log e^{cos(f,p⁺)/τ} / (e^{cos(f,p⁺)/τ} + Σ_{p⁻ of other styles} e^{cos(f,p⁻)/τ})
    intra-style  (D Eq. 6)  L_intra = −log e^{cos(f,p⁺)/τ} / Σ_{every prototype p} e^{cos(f,p)/τ}
    style loss   (D Eq. 7, 10)  L_style = L_g + L_l,  each level's L = L_inter + L_intra

The prototypes freeze after `freeze_after` steps (D §3.5). The style representation the SMA reads is
[f_g; f_l^1 … f_l^W] (1 + W tokens, D §3.3).

Input: the 263-d features normalised with the model's Normalizer (the content corpus statistics, the
same the motion VAE uses). Why not joint positions (paper A's choice): prototype guidance (D Eq. 9)
differentiates the style feature of the VAE decoder's output, which *is* a normalised 263-d vector, and
that vector already holds the root-relative joint positions (posture) besides velocities (tempo, bounce)
and contacts — no differentiable decoding to positions is needed.

Switches for D's ablations: `head="classifier"` swaps the prototypes for a learnable linear head trained
with cross-entropy, the "w/o clustering" row of D Table 3; `k_global` and `k_local` are the prototype
numbers of its other rows.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import torch
import torch.distributed as dist
import torch.nn.functional as F
from torch import nn

from ...motion.features import N_FEATURES
from ..common.config import Config
from ..common.layers import PositionalEncoding, transformer_encoder

HEADS = ("prototypes", "classifier")


@dataclass
class PrototypeConfig(Config):
    """Style encoder and prototype settings; defaults are paper D's (§3.5), `course` is the CPU recipe.

    The course recipe, for the built-in style corpus: k_global = 3, as in D: every built-in style has 2–4
    named sub-styles (3 on average; ~155 train clips per style, so ~50 clips per prototype). window = 10
    frames ≈ one step at 20 fps, so a 32-frame clip (31 feature rows) gives 3 local features; k_local = 6
    ≈ 3 sub-styles × the two halves of a gait cycle (~470 local features per style, ~80 per prototype) —
    30 prototypes would leave ~15 features each, too few for stable centroids. Training is 300 steps and
    the prototypes freeze after 150 (D's ratio, 1800/3500 ≈ 0.5). No dropout: it makes a CPU step much
    slower and the style loss does not overfit in 300 steps."""

    n_styles: int = 8
    dim: int = 512  # D §3.5: 6 layers, width 512
    layers: int = 6
    heads: int = 8
    dropout: float = 0.1
    k_global: int = 3  # K of D §3.5 and Table 3
    k_local: int = 30  # K'
    window: int = 16  # w: local segment length in frames (not given in D's text)
    epsilon: float = 0.05  # ε: Sinkhorn entropy weight (D Eq. 4; its value is lost in our copy of D)
    sinkhorn_iters: int = 3
    momentum: float = 0.95  # m of D Eq. 8
    tau: float = 0.05  # τ of D Eq. 5–6
    freeze_after: int = 1800  # D §3.5: prototype updates stop after 1800 of 3500 iterations
    head: str = "prototypes"  # or "classifier" (D Table 3, first row)

    PRESETS: ClassVar[dict] = {
        "paper": {},
        "course": dict(dim=64, layers=2, heads=4, dropout=0.0, k_local=6, window=10, freeze_after=150),
    }
    RETIRED: ClassVar[dict] = {"input_dim": N_FEATURES}  # the encoder always reads the 263-d vector

    def __post_init__(self):
        if self.head not in HEADS:
            raise ValueError(f"head: expected one of {HEADS}, got {self.head!r}")
        for name in ("n_styles", "dim", "layers", "heads", "k_global", "k_local", "window", "sinkhorn_iters"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name}: must be a positive integer, got {getattr(self, name)}")
        if not 0.0 <= self.momentum < 1.0:
            raise ValueError(f"momentum: must be in [0, 1), got {self.momentum}")
        if self.epsilon <= 0 or self.tau <= 0:
            raise ValueError(f"epsilon and tau: must be positive, got {self.epsilon} and {self.tau}")


# ---------------------------------------------------------------- the pieces, as functions
def sinkhorn(scores: torch.Tensor, epsilon: float = 0.05, iters: int = 3) -> torch.Tensor:
    """Balanced soft assignment of N features to K prototypes from scores (N, K) → Q (N, K).

    D Eq. 4 with F (d, N) and P (d, K), so that scores = FᵀP and Q are both (N, K):
    Q = argmax Tr(Qᵀ FᵀP) + ε H(Q) with every prototype used about N/K times, solved by Sinkhorn–Knopp
    on exp(FᵀP / ε): alternately scale the prototype columns to 1/K and the feature rows to 1/N. Returned rows sum to 1 (one feature, one unit of mass); column sums ≈ N/K."""
    if scores.ndim != 2 or scores.shape[0] < 1 or scores.shape[1] < 1:
        raise ValueError(f"scores: expected a non-empty (N, K) matrix, got shape {tuple(scores.shape)}")
    n, k = scores.shape
    s = scores.detach().double() / epsilon
    q = torch.exp(s - s.max())  # (N, K), ≤ 1
    q = q / q.sum()
    for _ in range(int(iters)):
        q = q / q.sum(0, keepdim=True).clamp_min(1e-300) / k  # each prototype holds 1/K of the mass
        q = q / q.sum(1, keepdim=True).clamp_min(1e-300) / n  # each feature holds 1/N
    return (q * n).to(scores.dtype)


def ema_update(prototypes: torch.Tensor, means: torch.Tensor, momentum: float) -> torch.Tensor:
    """D Eq. 8: p ← normalise(m·p + (1 − m)·mean of assigned features); (K, D) each."""
    return F.normalize(momentum * prototypes + (1.0 - momentum) * means, dim=-1)


def prototype_nce(features: torch.Tensor, styles: torch.Tensor, assigned: torch.Tensor,
                  prototypes: torch.Tensor, tau: float = 0.05) -> tuple:
    """Inter- and intra-style prototype InfoNCE (D Eq. 5–6) → (L_inter, L_intra), scalars.

    features (N, D) and prototypes (C, K, D) unit vectors; styles (N,) in [0, C); assigned (N,) in [0, K).
    Positive: the assigned prototype of the feature's own style. Inter: negatives are the other
    styles' prototypes only; intra: every other prototype, own style's included."""
    c, k, _ = prototypes.shape
    logits = features @ prototypes.reshape(c * k, -1).T / tau  # cos / τ, (N, C·K)
    target = styles * k + assigned  # (N,)
    l_intra = F.cross_entropy(logits, target)  # D Eq. 6
    own = (torch.arange(c * k, device=features.device)[None] // k) == styles[:, None]  # (N, C·K)
    own = own & (torch.arange(c * k, device=features.device)[None] != target[:, None])
    l_inter = F.cross_entropy(logits.masked_fill(own, float("-inf")), target)  # D Eq. 5
    return l_inter, l_intra


def local_means(tokens: torch.Tensor, window: int) -> torch.Tensor:
    """Means of (B, T, D) tokens over non-overlapping windows of `window` frames → (B, T // window, D).

    A trailing remainder shorter than a window is left out; a clip shorter than one window gives one
    segment (its whole length)."""
    b, t, d = tokens.shape
    n = max(1, t // window)
    w = min(window, t)
    return tokens[:, :n * w].reshape(b, n, w, d).mean(2)


# ---------------------------------------------------------------- the modules
class StyleEncoder(nn.Module):
    """E: transformer on normalised 263-d features (B, T, 263) → per-frame tokens (B, T, D)."""

    def __init__(self, cfg: PrototypeConfig):
        super().__init__()
        self.inp = nn.Linear(N_FEATURES, cfg.dim)
        self.pos = PositionalEncoding(cfg.dim)
        self.body = transformer_encoder(cfg.dim, cfg.heads, cfg.layers, dropout=cfg.dropout)
        self.out = nn.LayerNorm(cfg.dim)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.out(self.body(self.pos(self.inp(x))))  # (B, T, D)


class PrototypeBank(nn.Module):
    """Per-style prototypes (C, K, D) as buffers: Sinkhorn assignment, EMA update, freezing."""

    def __init__(self, n_styles: int, k: int, dim: int, seed: int = 0):
        super().__init__()
        g = torch.Generator().manual_seed(seed)
        self.register_buffer("prototypes", F.normalize(torch.randn(n_styles, k, dim, generator=g), dim=-1))
        self.register_buffer("frozen", torch.zeros((), dtype=torch.bool))

    @property
    def k(self) -> int:
        return self.prototypes.shape[1]

    @torch.no_grad()
    def assign(self, features: torch.Tensor, styles: torch.Tensor, epsilon: float = 0.05,
               iters: int = 3) -> torch.Tensor:
        """Prototype index (N,) of each feature among its own style's, by Sinkhorn then argmax."""
        out = torch.zeros(len(features), dtype=torch.long, device=features.device)
        for c in styles.unique():
            rows = (styles == c).nonzero().squeeze(1)
            scores = features[rows] @ self.prototypes[c].T  # cos, (n_c, K)
            out[rows] = sinkhorn(scores, epsilon, iters).argmax(1)
        return out

    @torch.no_grad()
    def update(self, features: torch.Tensor, styles: torch.Tensor, assigned: torch.Tensor, momentum: float):
        """EMA of every prototype that received features this step (summed over DDP ranks)."""
        if bool(self.frozen):
            return
        c, k, d = self.prototypes.shape
        slot = styles * k + assigned  # (N,)
        sums = torch.zeros(c * k, d, device=features.device).index_add_(0, slot, features.float())
        counts = torch.bincount(slot, minlength=c * k).float()
        if dist.is_available() and dist.is_initialized():
            dist.all_reduce(sums)
            dist.all_reduce(counts)
        hit = counts > 0
        flat = self.prototypes.reshape(c * k, d).clone()
        flat[hit] = ema_update(flat[hit], sums[hit] / counts[hit, None], momentum)
        self.prototypes.copy_(flat.reshape(c, k, d))

    def freeze(self) -> None:
        """Stop EMA updates from now on (D §3.5)."""
        self.frozen.fill_(True)


class PrototypeStyleModel(nn.Module):
    """Style encoder + global and local prototype banks (or a classification head) and L_style (D Eq. 10)."""

    def __init__(self, cfg: PrototypeConfig | None = None, seed: int = 0):
        super().__init__()
        self.cfg = cfg or PrototypeConfig.preset("course")
        self.config = {"prototypes": self.cfg.to_dict()}
        self.encoder = StyleEncoder(self.cfg)
        if self.cfg.head == "prototypes":
            self.global_bank = PrototypeBank(self.cfg.n_styles, self.cfg.k_global, self.cfg.dim, seed)
            self.local_bank = PrototypeBank(self.cfg.n_styles, self.cfg.k_local, self.cfg.dim, seed + 1)
        else:  # D Table 3, "w/o clustering": learnable class vectors, cross-entropy
            self.global_head = nn.Linear(self.cfg.dim, self.cfg.n_styles)
            self.local_head = nn.Linear(self.cfg.dim, self.cfg.n_styles)
        self.register_buffer("steps", torch.zeros((), dtype=torch.long))

    def features(self, x: torch.Tensor) -> tuple:
        """Normalised features (B, T, 263) → global (B, D) and local (B, W, D) unit vectors (D §3.3)."""
        if x.ndim != 3 or x.shape[-1] != N_FEATURES:
            raise ValueError(f"x: expected (B, T, {N_FEATURES}) features, got shape {tuple(x.shape)}")
        tokens = self.encoder(x)  # (B, T, D)
        g = F.normalize(tokens.mean(1), dim=-1)  # global: mean over time
        loc = F.normalize(local_means(tokens, self.cfg.window), dim=-1)  # local: means over windows
        return g, loc

    def style_tokens(self, x: torch.Tensor) -> torch.Tensor:
        """The style representation for the SMA: [global; local] features, (B, 1 + W, D) (D §3.3)."""
        g, loc = self.features(x)
        return torch.cat([g[:, None], loc], 1)

    def style_loss(self, x: torch.Tensor, styles: torch.Tensor, update: bool = True) -> dict:
        """L_style = L_g + L_l, each L_inter + L_intra (D Eq. 7, 10); EMA-updates unless frozen."""
        g, loc = self.features(x)
        w = loc.shape[1]
        loc_flat, loc_styles = loc.reshape(-1, loc.shape[-1]), styles.repeat_interleave(w)
        if self.cfg.head == "classifier":
            l_g = F.cross_entropy(self.global_head(g), styles)
            l_l = F.cross_entropy(self.local_head(loc_flat), loc_styles)
            return {"loss": l_g + l_l, "global": l_g.detach(), "local": l_l.detach()}
        logs = {}
        total = 0.0
        for name, f, s, bank in (("global", g, styles, self.global_bank), ("local", loc_flat, loc_styles, self.local_bank)):
            assigned = bank.assign(f.detach(), s, self.cfg.epsilon, self.cfg.sinkhorn_iters)
            l_inter, l_intra = prototype_nce(f, s, assigned, bank.prototypes.clone(), self.cfg.tau)  # EMA below is in place
            if update and self.training:
                bank.update(f.detach(), s, assigned, self.cfg.momentum)
            total = total + l_inter + l_intra  # D Eq. 7 per level, summed over levels (Eq. 10)
            logs[f"{name}_inter"], logs[f"{name}_intra"] = l_inter.detach(), l_intra.detach()
        logs["loss"] = total
        return logs

    def tick(self) -> None:
        """Count a training step; freeze both banks once `freeze_after` steps have passed."""
        self.steps += 1
        if self.cfg.head == "prototypes" and int(self.steps) >= self.cfg.freeze_after:
            self.global_bank.freeze()
            self.local_bank.freeze()

    @torch.no_grad()
    def predict_style(self, x: torch.Tensor) -> torch.Tensor:
        """Style index (B,) of the nearest global prototype (or the head's argmax)."""
        g, _ = self.features(x)
        if self.cfg.head == "classifier":
            return self.global_head(g).argmax(1)
        sims = torch.einsum("bd,ckd->bck", g, self.global_bank.prototypes)  # (B, C, K)
        return sims.amax(2).argmax(1)

    @torch.no_grad()
    def assign_global(self, x: torch.Tensor, styles: torch.Tensor) -> torch.Tensor:
        """Nearest global prototype (B,) of each clip within its own style (no balancing)."""
        g, _ = self.features(x)
        return torch.einsum("bd,bkd->bk", g, self.global_bank.prototypes[styles]).argmax(1)

    def training_step(self, batch: dict) -> dict:
        logs = self.style_loss(batch["features"], batch["style_index"])
        self.tick()
        return logs

    @torch.no_grad()
    def validation_step(self, batch: dict) -> dict:
        pred = self.predict_style(batch["features"])
        return {"acc": float((pred == batch["style_index"]).float().mean())}


# ---------------------------------------------------------------- loading and analysis
def load_style_model(path=None, device="cpu") -> PrototypeStyleModel:
    """A trained style model (default: the packaged course `clusterstyle_style.pt`), in eval mode."""
    from ...checkpoints import course_path, load_state, read_checkpoint
    path = course_path("clusterstyle_style") if path is None else path
    model = PrototypeStyleModel(PrototypeConfig.from_dict(read_checkpoint(path)["config"]["prototypes"]))
    load_state(path, model)
    return model.to(device).eval()


@torch.no_grad()
def substyle_confusion(model: PrototypeStyleModel, x: torch.Tensor, styles: torch.Tensor,
                       substyles: torch.Tensor, n_substyles: int) -> torch.Tensor:
    """Counts (C, n_substyles, K): true sub-style (rows) × nearest global prototype of its own style (columns).

    x (B, T, 263) normalised clips; styles (B,) in [0, C); substyles (B,) in [0, n_substyles)."""
    if not len(x) == len(styles) == len(substyles):
        raise ValueError(f"x, styles, substyles: lengths differ ({len(x)}, {len(styles)}, {len(substyles)})")
    k = model.assign_global(x, styles)  # (B,)
    table = torch.zeros(model.cfg.n_styles, int(n_substyles), model.cfg.k_global, dtype=torch.long)
    table.index_put_((styles.cpu(), substyles.cpu(), k.cpu()), torch.ones(len(k), dtype=torch.long), accumulate=True)
    return table


def matched_purity(table) -> float:
    """Fraction of clips on the best one-to-one sub-style ↔ prototype matching of each style's table (C, S, K)."""
    from scipy.optimize import linear_sum_assignment
    t = torch.as_tensor(table).numpy()
    hit = sum(t[c][linear_sum_assignment(-t[c])].sum() for c in range(len(t)))
    return float(hit / max(t.sum(), 1))
