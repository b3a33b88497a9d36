"""Paper C: self-supervised contrastive disentanglement of content and style.

E_c maps a motion to a content code h×t over time, E_s to a style vector; the generator G decodes
a content code with AdaIN parameters predicted from a style code; an MLP discriminator judges
realism. A training pair is a target M^T and a source M^S, drawn at random and never labelled, both
from the union of the content and style corpora (C's one set X; `pairs="across"` draws M^T from the
content corpus and M^S from the style corpus, the benchmark's direction); M^G = G(E_c(M^T) | E_s(M^S)).
Losses: C Eq. 1 reconstruction, C Eq. 2 adversarial (non-saturating form), C Eq. 3 InfoNCE with a
bilinear score on content codes, C Eq. 4 triplet with margin 1 on style codes, C Eq. 5 their weighted sum.

Three departures from C, all in the course preset only (the `paper` preset is C as written):
- `content_skip=True`: G's output is added to the target's movement around its time mean, so G
  supplies the posture and any change of the movement. It trains in CPU minutes (the paper-literal
  variant, `content_skip=False, content_norm=False`, scores below the course recipe on a validation
  draw, with the worst FMD: `tools/contrastive_findings.py`), but the movement bypasses E_c, leaving
  InfoNCE little to enforce, and the posture comes from the style code alone, so the style clip's
  content can leak into the transfer (measured in notebook 03).
- `pretrain_steps`: E_c, E_s, G and D first train as an autoencoder on C Eq. 1–2 alone; then E_s is
  frozen and the rest trains on all of C Eq. 5. Trained jointly, C Eq. 4 also trains its own judge:
  E_s can meet the triplet by moving its codes instead of G moving the style.
- `style_views=0.3`: while E_s trains (the autoencoder phase), δ·`recording_nce`, InfoNCE between the style codes
  of two windows of one recording, the batch's other recordings as negatives (no labels), so that the judge C Eq. 4
  freezes knows what stays the same through a recording, not only what G needs to reconstruct it. On validation
  pairs it lifted H on both seeds it was judged by, by a rule fixed before they were scored (notebook 03 §4).
`style_strength` w (default 1, C's transfer) decodes E_s(M^T) + w·(E_s(M^S) − E_s(M^T)), C Fig. 10–11's
mix of two style codes with the target's own as one end (`tools/contrastive_findings.py strength`
sweeps it on validation pairs).

`skip_adain=True` (in neither preset) instance-normalises the skipped movement and rescales it by a σ per
dimension that G predicts from the style code (A Eq. 2 on the skip), so the style code must carry the
movement's scale; on validation pairs it carries the style clip's content with it (notebook 03 §4).

`style_negatives="batch"` (in neither preset) adds the other pairs' source codes to C Eq. 4's negatives, so
E_s(M^G) must lie nearer its own source's code than any other source's, not only nearer than the target's.

C Eq. 2's real motions are the source clips M^S, as C writes. With `pairs="across"` they are the style
corpus alone, and D pulls every transfer toward style-corpus motion, content included; `disc_real="both"`
shows D the target clips as real too (neither is in a preset; notebook 03 §4 measures both).

The discriminator has its own optimiser, owned by the model and stepped inside `training_step`
on detached generated motion; the one loop (`mslib.training.fit`) optimises everything else,
given `parameters=model.generator_parameters()`.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from ...motion.features import N_FEATURES
from ...training import TrainConfig
from .data import check_pairs
from ..common.layers import ResBlock1d, adain

NAME = "contrastive"


@dataclass
class ContrastiveConfig:
    """Sizes, loss weights and optimisation of paper C; `paper` and `course` presets."""

    feature_dim: int = N_FEATURES
    hidden: int = 144          # content code channels h (C §4.1: 144×16 for 32 frames)
    style_dim: int = 144       # style code length l (C §4.1: 144)
    down: int = 2              # temporal stride of E_c: t = T / down
    disc_hidden: int = 256
    disc_window: int = 4       # the MLP discriminator scores windows of this many frames
    disc_dims: tuple = (3, 67)  # … of these dims: root height + root-relative joints (what decode reads)
    alpha: float = 1.0         # C Eq. 5: adversarial weight
    beta: float = 0.3          # C Eq. 5: InfoNCE weight
    gamma: float = 0.3         # C Eq. 5: triplet weight
    margin: float = 1.0        # C Eq. 4: λ
    style_views: float = 0.0   # weight δ of InfoNCE between E_s codes of two windows of one recording, while E_s trains (not in C)
    style_tau: float = 0.1     # … its temperature (cosine similarities)
    style_negatives: str = "target"  # C Eq. 4's negatives: "target" (E_s(M^T), C) or "batch" (… and the other pairs' E_s(M^S))
    keep_root: int = 3         # transfer keeps these leading dims (root trajectory) from the content
    content_skip: bool = False  # G adds the target's own movement around its time mean (course preset)
    skip_adain: bool = False   # … that movement instance-normalised and rescaled by a σ G predicts from the style code
    skip_eps: float = 1e-2     # the variance floor of that normalisation (normalised units: σ ≥ 0.1)
    skip_gain: bool = False    # … that movement scaled per dim by exp(A·(E_s(M^S) − E_s(M^T))), A zero at the start
    content_norm: bool = True  # E_c ends with instance normalisation over time (drops each channel's time mean)
    pairs: str = "union"       # M^T and M^S both drawn from content ∪ style corpus (C's one set X), or "across":
                               # M^T from the content corpus, M^S from the style corpus (the benchmark's direction)
    disc_real: str = "source"  # C Eq. 2's real motions: "source" (M^S) or "both" (M^S and M^T)
    crop: int = 31             # training clips: 31 feature rows = 32-frame clips (C §4.1)
    d_lr: float = 1e-4         # the discriminator's own optimiser
    steps: int = 200_000
    batch_size: int = 16
    lr: float = 1e-4
    warmup_steps: int = 0
    pretrain_steps: int = 0    # autoencoder steps (C Eq. 1 + 2 only) before E_s is frozen; 0: C's joint training
    style_strength: float = 1.0  # transfer with E_s(M^T) + w·(E_s(M^S) − E_s(M^T)) (C Fig. 10–11's mix); 1: C's transfer

    def __post_init__(self):
        if self.disc_real not in ("source", "both"):
            raise ValueError(f"disc_real: expected 'source' or 'both', got {self.disc_real!r}")
        check_pairs(self.pairs)
        if self.style_negatives not in ("target", "batch"):
            raise ValueError(f"style_negatives: expected 'target' or 'batch', got {self.style_negatives!r}")
        if self.style_views < 0 or self.style_tau <= 0:
            raise ValueError(f"style_views, style_tau: need δ ≥ 0 and τ > 0, got {self.style_views}, {self.style_tau}")
        if (self.skip_adain or self.skip_gain) and not self.content_skip:
            raise ValueError("skip_adain/skip_gain: need content_skip=True (they act on the content skip)")
        if self.skip_adain and self.skip_gain:
            raise ValueError("skip_adain, skip_gain: choose one way to restyle the skipped movement")

    @classmethod
    def preset(cls, name: str, **overrides) -> "ContrastiveConfig":
        """`paper` (C §4.1: batch 16, lr 1e-4, 200k iterations, 144-d codes) or `course` (CPU, minutes)."""
        if name == "paper":
            cfg = cls()
        elif name == "course":
            cfg = cls(hidden=64, style_dim=64, disc_hidden=128, steps=10000, batch_size=32, lr=1e-3,
                      d_lr=5e-4, warmup_steps=100, content_skip=True, pretrain_steps=2500, style_views=0.3)
        else:
            raise ValueError(f"preset: expected 'paper' or 'course', got {name!r}")
        known = {f.name for f in fields(cls)}
        bad = sorted(set(overrides) - known)
        if bad:
            raise ValueError(f"overrides: unknown config fields {bad}")
        return replace(cfg, **overrides)

    def train_config(self, seed: int = 0) -> TrainConfig:
        """The one loop's settings for this config."""
        return TrainConfig(steps=self.steps, batch_size=self.batch_size, lr=self.lr, seed=seed,
                           warmup_steps=self.warmup_steps, val_every=max(1, self.steps // 5), val_batches=2)


# ---------------------------------------------------------------- networks
def _conv(cin: int, cout: int, kernel: int = 3, stride: int = 1) -> nn.Conv1d:
    return nn.Conv1d(cin, cout, kernel, stride=stride, padding=(kernel - stride + 1) // 2)


class ContentEncoder(nn.Module):
    """E_c: 3 Conv1d (the first strided) + 3 residual blocks, instance-normalised over time; (B, T, D) → (B, h, T/down)."""

    def __init__(self, cfg: ContrastiveConfig):
        super().__init__()
        h = cfg.hidden
        self.net = nn.Sequential(
            _conv(cfg.feature_dim, h, 4 if cfg.down == 2 else 3, cfg.down), nn.LeakyReLU(0.2),
            _conv(h, h), nn.LeakyReLU(0.2),
            _conv(h, h), nn.InstanceNorm1d(h),
            *[ResBlock1d(h) for _ in range(3)], nn.InstanceNorm1d(h) if cfg.content_norm else nn.Identity())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.net(x.transpose(1, 2))  # (B, h, t)


class StyleEncoder(nn.Module):
    """E_s: 3 Conv1d (the first two strided) + 3 residual blocks, mean over time, linear; (B, T, D) → (B, l)."""

    def __init__(self, cfg: ContrastiveConfig):
        super().__init__()
        h = cfg.hidden
        self.net = nn.Sequential(
            _conv(cfg.feature_dim, h, 4, 2), nn.LeakyReLU(0.2),
            _conv(h, h, 4, 2), nn.LeakyReLU(0.2),
            _conv(h, h), *[ResBlock1d(h) for _ in range(3)], nn.LeakyReLU(0.2))
        self.out = nn.Linear(h, cfg.style_dim)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.out(self.net(x.transpose(1, 2)).mean(-1))  # (B, l)


class AdaINResBlock(nn.Module):
    """x + conv(act(AdaIN(conv(act(AdaIN(x, s₁))), s₂))), AdaIN parameters from the style code; (B, C, t)."""

    def __init__(self, channels: int, style_dim: int):
        super().__init__()
        self.conv1, self.conv2 = _conv(channels, channels), _conv(channels, channels)
        self.affine = nn.Linear(style_dim, 4 * channels)  # μ₁, σ₁, μ₂, σ₂

    def forward(self, x: torch.Tensor, style: torch.Tensor) -> torch.Tensor:
        mu1, s1, mu2, s2 = self.affine(style)[:, None].chunk(4, -1)  # (B, 1, C) each
        h = adain(x.transpose(1, 2), mu1, 1 + s1).transpose(1, 2)   # A Eq. 2 with learned style stats
        h = self.conv1(F.leaky_relu(h, 0.2))
        h = adain(h.transpose(1, 2), mu2, 1 + s2).transpose(1, 2)
        return x + self.conv2(F.leaky_relu(h, 0.2))


class Generator(nn.Module):
    """G: 4 AdaIN residual blocks, upsample back to T, a conv and a per-frame linear map to D; (B, h, t), (B, l), T → (B, T, D)."""

    def __init__(self, cfg: ContrastiveConfig):
        super().__init__()
        h = cfg.hidden
        self.style_mlp = nn.Sequential(nn.Linear(cfg.style_dim, h), nn.LeakyReLU(0.2), nn.Linear(h, h))
        self.blocks = nn.ModuleList(AdaINResBlock(h, h) for _ in range(4))
        self.head = nn.Sequential(_conv(h, h), nn.LeakyReLU(0.2), nn.Conv1d(h, cfg.feature_dim, 1))
        if cfg.content_skip:  # start as the identity on the content's movement (zero-initialised output layer)
            nn.init.zeros_(self.head[-1].weight)
            nn.init.zeros_(self.head[-1].bias)
        self.skip_log_sigma = nn.Linear(h, cfg.feature_dim) if cfg.skip_adain else None
        if self.skip_log_sigma is not None:  # start at σ = 1 for every dim
            nn.init.zeros_(self.skip_log_sigma.weight)
            nn.init.zeros_(self.skip_log_sigma.bias)

    def skip_sigma(self, style: torch.Tensor) -> torch.Tensor:
        """σ per feature dim for the content skip's movement (`skip_adain`): (B, l) → (B, 1, D)."""
        return self.skip_log_sigma(self.style_mlp(style)).clamp(-5.0, 3.0).exp()[:, None]

    def forward(self, content: torch.Tensor, style: torch.Tensor, length: int) -> torch.Tensor:
        s = self.style_mlp(style)  # (B, h)
        x = content
        for block in self.blocks:
            x = block(x, s)
        x = F.interpolate(x, size=length, mode="linear", align_corners=False)  # (B, h, T)
        return self.head(x).transpose(1, 2)  # (B, T, D)


class Discriminator(nn.Module):
    """MLP on windows of `disc_window` frames of dims `disc_dims`; (B, T, D) → (B, T // w) logits."""

    def __init__(self, cfg: ContrastiveConfig):
        super().__init__()
        self.w, (self.lo, self.hi) = cfg.disc_window, cfg.disc_dims
        self.mlp = nn.Sequential(nn.Linear((self.hi - self.lo) * self.w, cfg.disc_hidden), nn.LeakyReLU(0.2),
                                 nn.Linear(cfg.disc_hidden, cfg.disc_hidden), nn.LeakyReLU(0.2),
                                 nn.Linear(cfg.disc_hidden, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = x[..., self.lo:self.hi]
        B, T, D = x.shape
        n = T // self.w
        if n < 1:
            raise ValueError(f"x: needs at least disc_window={self.w} frames, got {T}")
        return self.mlp(x[:, :n * self.w].reshape(B, n, self.w * D)).squeeze(-1)


# ---------------------------------------------------------------- losses
def reconstruction_loss(recon: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """C Eq. 1 (one term): mean per-frame Euclidean distance, divided by √D so Eq. 5's weights act on O(1) terms."""
    return ((recon - x).pow(2).mean(-1) + 1e-8).sqrt().mean()


def adversarial_losses(d_real: torch.Tensor, d_fake: torch.Tensor) -> tuple:
    """C Eq. 2 in its non-saturating form: (D loss, G loss) from logits.

    D: −log σ(D(M^S)) − log(1 − σ(D(M^G))); G: −log σ(D(M^G)) (instead of log(1 − σ), which saturates)."""
    d_loss = F.softplus(-d_real).mean() + F.softplus(d_fake).mean()
    g_loss = F.softplus(-d_fake).mean()
    return d_loss, g_loss


def info_nce(query: torch.Tensor, keys: torch.Tensor, W: torch.Tensor) -> torch.Tensor:
    """C Eq. 3 with f(q, k) = qᵀWk / √h: every time step i of `query` (B, h, t) is a query, step i of
    `keys` (B, h, t) its positive, the other t − 1 steps of the same motion its negatives.

    The positive is included in the softmax's denominator (the usual CPC form), so the loss is ≥ 0."""
    if query.shape != keys.shape or query.dim() != 3:
        raise ValueError(f"query/keys: need equal (B, h, t) shapes, got {tuple(query.shape)} and {tuple(keys.shape)}")
    h = query.shape[1]
    scores = torch.einsum("bhi,hg,bgj->bij", query, W, keys) / h ** 0.5  # (B, t, t): f(q_i, k_j)
    target = torch.arange(scores.shape[-1], device=scores.device).expand(scores.shape[0], -1)  # (B, t)
    return F.cross_entropy(scores.reshape(-1, scores.shape[-1]), target.reshape(-1))


def triplet_loss(query: torch.Tensor, positive: torch.Tensor, negative: torch.Tensor,
                 margin: float = 1.0) -> torch.Tensor:
    """C Eq. 4: [‖q − k⁺‖ − ‖q − k⁻‖ + λ]₊ averaged over the batch; codes (B, l)."""
    d_pos = (query - positive).norm(dim=-1)  # (B,)
    d_neg = (query - negative).norm(dim=-1)
    return F.relu(d_pos - d_neg + margin).mean()


def triplet_loss_batch(query: torch.Tensor, positive: torch.Tensor, negative: torch.Tensor,
                       margin: float = 1.0) -> torch.Tensor:
    """C Eq. 4 with more negatives: for pair i, the hinge against E_s(M^T_i) and against every other pair's
    positive k⁺_j (j ≠ i), averaged over those B negatives and the batch; C Eq. 4 itself when B = 1. Codes (B, l)."""
    B = query.shape[0]
    d_pos = (query - positive).norm(dim=-1)                 # (B,)
    d_others = torch.cdist(query, positive)                  # (B, B): ‖q_i − k⁺_j‖
    d_neg = torch.cat([(query - negative).norm(dim=-1)[:, None],
                       d_others[~torch.eye(B, dtype=torch.bool, device=query.device)].view(B, B - 1)], 1)  # (B, B)
    return F.relu(d_pos[:, None] - d_neg + margin).mean()


def recording_nce(codes: torch.Tensor, views: torch.Tensor, tau: float = 0.1) -> torch.Tensor:
    """InfoNCE between two windows of each recording (not in C): code i's positive is view i, its negatives the
    other views in the batch, scored by cosine / τ, in both directions; codes (B, l). No labels: a recording keeps
    its style over time, so codes that find their own recording's other window must carry what stays the same."""
    if codes.shape != views.shape or codes.dim() != 2:
        raise ValueError(f"codes/views: need equal (B, l) shapes, got {tuple(codes.shape)} and {tuple(views.shape)}")
    scores = F.normalize(codes, dim=-1) @ F.normalize(views, dim=-1).T / tau  # (B, B)
    target = torch.arange(len(codes), device=codes.device)
    return 0.5 * (F.cross_entropy(scores, target) + F.cross_entropy(scores.T, target))


# ---------------------------------------------------------------- the model
class ContrastiveModel(nn.Module):
    """E_c, E_s, G, D and the bilinear W, with C's losses and the normaliser of the training data."""

    def __init__(self, cfg: ContrastiveConfig | None = None, mean=None, std=None):
        super().__init__()
        self.cfg = cfg or ContrastiveConfig.preset("course")
        self.config = asdict(self.cfg)
        self.content_encoder = ContentEncoder(self.cfg)
        self.style_encoder = StyleEncoder(self.cfg)
        self.generator = Generator(self.cfg)
        self.discriminator = Discriminator(self.cfg)
        self.W = nn.Parameter(torch.eye(self.cfg.hidden))  # C Eq. 3: bilinear score qᵀWk
        D = self.cfg.feature_dim
        self.register_buffer("mean", torch.zeros(D) if mean is None else torch.as_tensor(mean, dtype=torch.float32))
        self.register_buffer("std", torch.ones(D) if std is None else torch.as_tensor(std, dtype=torch.float32))
        self._d_opt = None
        # `skip_gain`: log-gain per feature dim, linear in the style codes' difference, zero at the start (gain 1);
        # made without drawing random numbers, so every other weight and batch is as without it
        self.movement_gain = None
        if self.cfg.skip_gain:
            self.movement_gain = nn.utils.skip_init(nn.Linear, self.cfg.style_dim, D, bias=False)
            nn.init.zeros_(self.movement_gain.weight)

    pretraining = False  # True while `train` runs the autoencoder steps (C Eq. 3–4 logged, not used)

    # -- pieces
    def generator_parameters(self) -> list:
        """Everything but the discriminator (the one loop's optimiser)."""
        return [p for n, p in self.named_parameters() if not n.startswith("discriminator.")]

    def d_optimizer(self) -> torch.optim.Optimizer:
        """The discriminator's own Adam (created on first use, on the model's device)."""
        if self._d_opt is None:
            self._d_opt = torch.optim.Adam(self.discriminator.parameters(), lr=self.cfg.d_lr, betas=(0.5, 0.999))
        return self._d_opt

    def normalize(self, x: torch.Tensor) -> torch.Tensor:
        return (x - self.mean) / self.std

    def denormalize(self, x: torch.Tensor) -> torch.Tensor:
        return x * self.std + self.mean

    def encode_content(self, x: torch.Tensor) -> torch.Tensor:
        """Normalised (B, T, D) → content code (B, h, t)."""
        return self.content_encoder(x)

    def encode_style(self, x: torch.Tensor) -> torch.Tensor:
        """Normalised (B, T, D) → style code (B, l)."""
        return self.style_encoder(x)

    def generate(self, content_code: torch.Tensor, style_code: torch.Tensor, length: int,
                 content: torch.Tensor | None = None, content_style: torch.Tensor | None = None) -> torch.Tensor:
        """G(E_c(·) | E_s(·)) → normalised (B, length, D); with `content_skip`, plus the content
        motion's own movement around its time mean, x − μ_t(x) (x: the normalised content, (B, length, D)),
        with `skip_adain` as AdaIN gives it: σ̂(style code)·(x − μ_t(x))/σ_t(x), with `skip_gain` times
        exp(A·(s − s_x)), s_x = `content_style`, the content's own style code (default: E_s(x))."""
        out = self.generator(content_code, style_code, length)
        if self.cfg.content_skip:
            if content is None:
                raise ValueError("content: needed by a model with content_skip=True")
            if self.cfg.skip_adain:  # A Eq. 2 on the skip, σ from the style code, μ from G's output
                return out + adain(content, 0.0, self.generator.skip_sigma(style_code), eps=self.cfg.skip_eps)
            move = content - content.mean(1, keepdim=True)  # (B, T, D)
            if self.movement_gain is not None:  # 1 when the two codes agree: reconstruction never trains A
                own = self.encode_style(content) if content_style is None else content_style  # (B, l)
                move = move * self.movement_gain(style_code - own).clamp(-3.0, 3.0).exp()[:, None]
            out = out + move
        return out

    def _check(self, x, name):
        if x.dim() != 3 or x.shape[-1] != self.cfg.feature_dim:
            raise ValueError(f"{name}: expected (B, T, {self.cfg.feature_dim}), got {tuple(x.shape)}")
        if x.shape[1] < max(4, self.cfg.disc_window):
            raise ValueError(f"{name}: needs at least {max(4, self.cfg.disc_window)} frames, got {x.shape[1]}")

    # -- training
    def losses(self, target: torch.Tensor, source: torch.Tensor, source_view: torch.Tensor | None = None) -> dict:
        """Every term of C Eq. 1–5 for normalised target M^T and source M^S (B, T, D), without the D step;
        with `source_view` (another window of each source's recording) also `recording_nce` as "views"."""
        self._check(target, "target")
        self._check(source, "source")
        T = target.shape[1]
        c_t, c_s = self.encode_content(target), self.encode_content(source)  # (B, h, t)
        s_t, s_s = self.encode_style(target), self.encode_style(source)      # (B, l)
        rec = (reconstruction_loss(self.generate(c_s, s_s, source.shape[1], source, s_s), source)  # C Eq. 1
               + reconstruction_loss(self.generate(c_t, s_t, T, target, s_t), target))
        fake = self.generate(c_t, s_s, T, target, s_t)  # M^G = G(E_c(M^T) | E_s(M^S))
        nce = info_nce(self.encode_content(fake), c_t, self.W)                              # C Eq. 3
        triplet = triplet_loss_batch if self.cfg.style_negatives == "batch" else triplet_loss
        tri = triplet(self.encode_style(fake), s_s, s_t, self.cfg.margin)                   # C Eq. 4
        out = {"rec": rec, "nce": nce, "tri": tri, "fake": fake}
        if source_view is not None:
            out["views"] = recording_nce(s_s, self.encode_style(source_view), self.cfg.style_tau)
        return out

    def training_step(self, batch: dict) -> dict:
        target, source = batch["target"], batch["source"]
        trains_judge = self.cfg.style_views > 0 and self.style_encoder.out.weight.requires_grad  # phase 1, or joint
        views = batch.get("source_view") if trains_judge else None  # once E_s is frozen the term has nothing to train
        out = self.losses(target, source, views)
        fake = out.pop("fake")
        if self.cfg.alpha > 0:  # the discriminator's step, on detached M^G (its own optimiser)
            opt = self.d_optimizer()
            real = source if self.cfg.disc_real == "source" else torch.cat([source, target])  # (B or 2B, T, D)
            d_loss, _ = adversarial_losses(self.discriminator(real), self.discriminator(fake.detach()))
            opt.zero_grad(set_to_none=True)
            d_loss.backward()
            opt.step()
            g_adv = F.softplus(-self.discriminator(fake)).mean()  # C Eq. 2, non-saturating G term
        else:
            d_loss = g_adv = torch.zeros((), device=target.device)
        c = self.cfg
        beta, gamma = (0.0, 0.0) if self.pretraining else (c.beta, c.gamma)
        loss = out["rec"] + c.alpha * g_adv + beta * out["nce"] + gamma * out["tri"]  # C Eq. 5
        if "views" in out:
            loss = loss + c.style_views * out["views"]
        return {"loss": loss, **{k: v.detach() for k, v in out.items()}, "adv": g_adv.detach(), "d": d_loss.detach()}

    def validation_step(self, batch: dict) -> dict:
        out = self.losses(batch["target"], batch["source"], batch.get("source_view"))  # views only when δ > 0 (`train`)
        out.pop("fake")
        return {k: float(v) for k, v in out.items()}

    # -- inference
    @torch.no_grad()
    def transfer_features(self, content: np.ndarray, style: np.ndarray, strength: float | None = None) -> np.ndarray:
        """Unnormalised (Tc, D) content and (Ts, D) style features → unnormalised (Tc, D) output;
        the first `keep_root` dims (the root trajectory) are the content's own. `strength` w (default
        `cfg.style_strength`) mixes the style codes: E_s(content) + w·(E_s(style) − E_s(content))."""
        w = self.cfg.style_strength if strength is None else float(strength)
        dev = self.mean.device
        c, s = (torch.as_tensor(np.asarray(a), dtype=torch.float32, device=dev)[None] for a in (content, style))
        self._check(c, "content")
        self._check(s, "style")
        c, s = self.normalize(c), self.normalize(s)
        code, own = self.encode_style(s), None  # (1, l); `generate` finds the content's own code if it needs it
        if w != 1.0:
            own = self.encode_style(c)
            code = own + w * (code - own)
        out = self.denormalize(self.generate(self.encode_content(c), code, c.shape[1], c, own))[0]
        out = out.cpu().numpy().astype(np.float64)
        k = self.cfg.keep_root
        out[:, :k] = np.asarray(content, np.float64)[:, :k]
        return out

    @torch.no_grad()
    def style_codes(self, clips, batch_size: int = 64) -> np.ndarray:
        """Style codes (N, l) of unnormalised (T, D) feature arrays (equal lengths within a batch)."""
        self.eval()
        codes = []
        for i in range(0, len(clips), batch_size):
            x = torch.as_tensor(np.stack(clips[i:i + batch_size]), dtype=torch.float32, device=self.mean.device)
            codes.append(self.encode_style(self.normalize(x)).cpu().numpy())
        return np.concatenate(codes, 0)
