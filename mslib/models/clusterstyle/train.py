"""Paper D's three training stages: the prototype style model, the text-to-motion denoiser, the SMA."""
from __future__ import annotations

import re
from dataclasses import asdict

import torch
from torch.utils.data import ConcatDataset, Dataset

from ...checkpoints import course_path
from ...data.datasets import ContentClips, StyleClips
from ...training import TrainConfig, fit, run_summary
from ..common.text import Tokenizer
from ..common.vae import load_vae, pad_batch
from .model import MAX_STYLE_ROWS, NAME, STYLE_NAME, T2M_NAME, ClusterStyle, ClusterStyleConfig, load_clusterstyle
from .prototypes import PrototypeConfig, PrototypeStyleModel, load_style_model, train_style_model

# ---------------------------------------------------------------- captions and precomputed tensors
def content_caption(caption: str) -> str:
    """A style-corpus caption with its style words removed: "an old person walks" → "a person walks"."""
    c = re.sub(r"\s+in an? [\w-]+ style\b", "", caption.strip())
    return re.sub(r"^an? [\w-]+ person\b", "a person", c)


class Frozen:
    """The frozen parts a ClusterStyle stage precomputes with: the VAE and (stage 3) the style model."""

    def __init__(self, vae, style: PrototypeStyleModel | None):
        self.vae, self.style = vae.eval(), None if style is None else style.eval()

    @torch.no_grad()
    def style_tokens(self, normed: list, max_tokens: int) -> tuple:
        """Normalised clips → style tokens (M, S, Ds) padded to max_tokens and pad (M, S)."""
        out = torch.zeros(len(normed), max_tokens, self.style.cfg.dim)
        pad = torch.ones(len(normed), max_tokens, dtype=torch.bool)
        for i, x in enumerate(normed):
            s = self.style.style_tokens(x[None, :MAX_STYLE_ROWS])[0]
            out[i, :len(s)], pad[i, :len(s)] = s, False
        return out, pad

    @torch.no_grad()
    def latents(self, normed: list, batch: int = 64) -> torch.Tensor:
        """Normalised clips → VAE diffusion latents (M, N, d) (μ / latent_scale)."""
        zs = [self.vae.encode(*pad_batch(normed[i:i + batch])) for i in range(0, len(normed), batch)]
        return torch.cat(zs)


class Precomputed(Dataset):
    """Items {z, caption, style, style_pad, is_style} from precomputed tensors."""

    def __init__(self, tensors: dict, captions: list):
        self.t, self.captions = tensors, list(captions)

    def __len__(self) -> int:
        return len(self.captions)

    def __getitem__(self, i: int) -> dict:
        return {"caption": self.captions[i], **{k: v[i] for k, v in self.t.items()}}


def corpus_captions(folder, kind: str, split: str | None = "train") -> list:
    """The captions of a corpus split, style words removed from the style corpus's."""
    ds = ContentClips(folder, split) if kind == "content" else StyleClips(folder, split, joints=False)
    return [content_caption(r["caption"]) for r in ds.rows]


def precompute(frozen: Frozen, folder, kind: str, split: str, max_style_tokens: int) -> Precomputed:
    """A corpus split as precomputed tensors: VAE latents, captions (style words removed), style tokens."""
    ds = (ContentClips(folder, split, normalize=False) if kind == "content"
          else StyleClips(folder, split, normalize=False, joints=False))
    vae = frozen.vae
    normed = [vae.normalize(ds[i]["features"][:vae.cfg.max_len]) for i in range(len(ds))]
    t = {"z": frozen.latents(normed), "is_style": torch.full((len(ds),), kind == "style")}
    if frozen.style is not None:
        t["style"], t["style_pad"] = frozen.style_tokens(normed, max_style_tokens)
    return Precomputed(t, [content_caption(r["caption"]) for r in ds.rows])


def train_configs(preset: str, seed: int = 0) -> dict:
    """Model config and the TrainConfig of each diffusion stage for a preset."""
    if preset == "course":  # batch 32: the course VAE's temporal latent has 50 tokens per clip; each stage
        # takes 15–20 minutes on one core (a quarter of the steps gave clearly weaker transfers on val)
        return {"model": ClusterStyleConfig.course(),
                "t2m": TrainConfig(steps=6000, batch_size=32, lr=1e-3, warmup_steps=100, val_every=300, seed=seed),
                "sma": TrainConfig(steps=6000, batch_size=32, lr=1e-3, warmup_steps=100, val_every=300, seed=seed)}
    if preset == "paper":  # D §3.5: AdamW, batch 128, lr 2e-5, 500 warm-up then 3000 constant
        paper = TrainConfig(steps=3500, batch_size=128, lr=2e-5, warmup_steps=500, schedule="constant",
                            val_every=500, seed=seed)
        return {"model": ClusterStyleConfig(), "t2m": TrainConfig(steps=100000, batch_size=128, lr=1e-4,
                                                                   warmup_steps=1000, seed=seed), "sma": paper}
    raise ValueError(f"preset: expected 'course' or 'paper', got {preset!r}")


def _summary(name, out, history, **extra) -> dict:
    return run_summary(name, out, history, **{k: round(v[-1], 4) for k, v in history["val"].items()}, **extra)


def _stage(preset, seed, steps, stage, out, name) -> tuple:
    """(out path, configs, the stage's TrainConfig with a --steps override), torch seeded."""
    cfgs = train_configs(preset, seed)
    if steps:
        cfgs[stage].steps = int(steps)
    torch.manual_seed(seed)
    return course_path(name) if out is None else out, cfgs, cfgs[stage]


def run_style(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True,
              head: str = "prototypes") -> dict:
    """Stage 1: the style encoder and prototypes on the style corpus (D §3.2–3.3)."""
    out = course_path(STYLE_NAME) if out is None else out
    model, history = train_style_model(preset, content, style, seed, out, device, steps, resume, progress, head=head)
    return _summary(STYLE_NAME, out, history)


def run_t2m(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True,
            vae=None) -> dict:
    """Stage 2: text-to-motion latent diffusion (and the text encoder) on the content corpus."""
    out, cfgs, tc = _stage(preset, seed, steps, "t2m", out, T2M_NAME)
    vae = vae or load_vae(device=device)
    frozen = Frozen(vae, None)
    sets = {s: precompute(frozen, content, "content", s, cfgs["model"].max_style_tokens) for s in ("train", "val")}
    vocab = Tokenizer.from_captions(corpus_captions(content, "content", None) + corpus_captions(style, "style", None)).vocab
    model = ClusterStyle(cfgs["model"], PrototypeConfig.course() if preset == "course" else PrototypeConfig.paper(),
                         vae.cfg.latent_tokens, vae.cfg.latent_dim, vocab, stage="t2m")
    style_params = {id(p) for p in model.denoiser.style_parameters()}
    params = [p for p in model.denoiser.parameters() if id(p) not in style_params] + list(model.text.parameters())
    history = fit(model, sets["train"], tc, sets["val"], model_name=T2M_NAME, out=out, resume=resume,
                  device=device, progress=progress, parameters=params)
    return _summary(T2M_NAME, out, history)


def build_sma_model(preset: str, t2m_path=None, style_path=None, device="cpu") -> ClusterStyle:
    """Stage 3's starting point: the t2m denoiser and the trained style model, in one ClusterStyle."""
    model = load_clusterstyle(t2m_path, device, name=T2M_NAME, stage="sma")
    model.style = load_style_model(style_path)
    model.style_cfg = model.style.cfg
    model.config["prototypes"] = asdict(model.style.cfg)
    model.cfg = ClusterStyleConfig.from_dict({**asdict(model.cfg), **asdict(train_configs(preset)["model"])})
    model.config["model"] = asdict(model.cfg)
    return model.to(device)


def run_sma(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True,
            t2m_path=None, style_path=None, vae=None) -> dict:
    """Stage 3: the SMA's style branch and λ on the style corpus + the content prior (D Eq. 1–3, 11)."""
    out, cfgs, tc = _stage(preset, seed, steps, "sma", out, NAME)
    model = build_sma_model(preset, t2m_path, style_path, device)
    vae = vae or load_vae(device=device)
    frozen = Frozen(vae, model.style)
    n = model.cfg.max_style_tokens
    sets = {s: ConcatDataset([precompute(frozen, style, "style", s, n), precompute(frozen, content, "content", s, n)])
            for s in ("train", "val")}
    params = model.freeze_for_sma()
    history = fit(model, sets["train"], tc, sets["val"], model_name=NAME, out=out, resume=resume,
                  device=device, progress=progress, parameters=params)
    lam = [round(float(b.sma.lam.detach()), 3) for b in model.denoiser.blocks]
    return _summary(NAME, out, history, **{"lambda": lam})

