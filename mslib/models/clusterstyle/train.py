"""Paper D's three training stages: the prototype style model, the text-to-motion denoiser, the SMA (D §3.5).

D trains for 3500 iterations (AdamW, batch 128, lr 2e-5: 500 warm-up, then constant), the prototypes
frozen after 1800; the `paper` preset keeps that for the style and SMA stages. The `course` preset fits
each stage into CPU minutes (a higher learning rate, smaller batches, the model sizes of the configs'
`course` presets). The diffusion stages train on precomputed tensors — VAE latents and, in stage 3, the
frozen style encoder's tokens — computed once per clip.
"""
from __future__ import annotations

import re

import torch
from torch.utils.data import ConcatDataset, Dataset

from ...checkpoints import course_path
from ...data.datasets import ContentClips, StyleClips
from ...motion.features import Normalizer
from ...training import TrainConfig, fit, run_summary
from ..common.config import PRESET_NAMES
from ..common.layers import pad_batch
from ..common.text import Tokenizer
from ..common.vae import load_vae
from .model import MAX_STYLE_ROWS, NAME, STYLE_NAME, T2M_NAME, ClusterStyle, ClusterStyleConfig, load_clusterstyle
from .prototypes import PrototypeConfig, PrototypeStyleModel, load_style_model


def _check_preset(preset: str) -> None:
    if preset not in PRESET_NAMES:
        raise ValueError(f"preset: expected one of {PRESET_NAMES}, got {preset!r}")


# ---------------------------------------------------------------- stage 1: the style encoder and its prototypes
class NormalizedClips(Dataset):
    """A dataset of unnormalised clips, normalised with given 263-d mean/std (the model's statistics)."""

    def __init__(self, dataset, mean, std):
        self.dataset = dataset
        self.mean = torch.as_tensor(mean, dtype=torch.float32)
        self.std = torch.as_tensor(std, dtype=torch.float32)

    def __len__(self) -> int:
        return len(self.dataset)

    def __getitem__(self, i: int) -> dict:
        item = dict(self.dataset[i])
        item["features"] = (item["features"] - self.mean) / self.std
        return item


STYLE_STEPS = {"course": 300, "paper": 3500}


def style_train_config(preset: str, seed: int = 0, steps: int | None = None, **overrides) -> tuple:
    """(PrototypeConfig, TrainConfig) of the style stage for a preset; a `steps` override moves the freezing
    step with it (same fraction of the run), `overrides` set PrototypeConfig fields on top."""
    _check_preset(preset)
    if preset == "course":
        train = TrainConfig(steps=300, batch_size=64, lr=1e-3, warmup_steps=30, schedule="cosine",
                            val_every=100, seed=seed)
    else:  # D §3.5: AdamW, batch 128, lr 2e-5, 500 warm-up + 3000 constant
        train = TrainConfig(steps=3500, batch_size=128, lr=2e-5, warmup_steps=500, schedule="constant",
                            val_every=250, seed=seed)
    if steps:
        train.steps = int(steps)
        freeze = PrototypeConfig.preset(preset).freeze_after
        overrides = {"freeze_after": max(1, int(round(freeze * steps / STYLE_STEPS[preset]))), **overrides}
    return PrototypeConfig.preset(preset, **overrides), train


def train_style_model(preset: str, content, style, seed: int = 0, out=None, device: str = "cpu",
                      steps: int | None = None, resume=None, progress: bool = True, head: str = "prototypes",
                      model_name: str = STYLE_NAME, **overrides) -> tuple:
    """Train the style encoder and its prototypes (or a classifier head) on the style corpus; (model, history)."""
    cfg, train = style_train_config(preset, seed, steps, head=head, **overrides)
    norm = Normalizer.load(content)  # the content corpus statistics, shared with the motion VAE
    torch.manual_seed(seed)  # the encoder's initial weights (the banks take `seed` themselves)
    model = PrototypeStyleModel(cfg, seed=seed)
    model.config["normalizer"] = "content"
    data = {s: NormalizedClips(StyleClips(style, s, normalize=False, joints=False), norm.mean, norm.std)
            for s in ("train", "val")}
    history = fit(model, data["train"], train, val_set=data["val"], model_name=model_name, out=out,
                  resume=resume, device=device, progress=progress)
    return model, history


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
    _check_preset(preset)
    if preset == "course":  # batch 32: the course VAE's temporal latent has 50 tokens per clip; 6000 steps
        # per stage (a quarter of the steps gave clearly weaker transfers on val)
        return {"model": ClusterStyleConfig.preset("course"),
                "t2m": TrainConfig(steps=6000, batch_size=32, lr=1e-3, warmup_steps=100, val_every=300, seed=seed),
                "sma": TrainConfig(steps=6000, batch_size=32, lr=1e-3, warmup_steps=100, val_every=300, seed=seed)}
    # D §3.5 for the SMA stage: AdamW, batch 128, lr 2e-5, 500 warm-up then 3000 constant; D starts from a
    # pre-trained MLD, whose recipe the t2m stage stands in for
    paper = TrainConfig(steps=3500, batch_size=128, lr=2e-5, warmup_steps=500, schedule="constant",
                        val_every=500, seed=seed)
    return {"model": ClusterStyleConfig.preset("paper"),
            "t2m": TrainConfig(steps=100000, batch_size=128, lr=1e-4, warmup_steps=1000, seed=seed), "sma": paper}


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
    model = ClusterStyle(cfgs["model"], PrototypeConfig.preset(preset), vae.cfg.latent_tokens, vae.cfg.latent_dim,
                         vocab, stage="t2m")
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
    model.config["prototypes"] = model.style.cfg.to_dict()
    model.cfg = train_configs(preset)["model"]  # the stage's inference settings replace the t2m checkpoint's
    model.config["model"] = model.cfg.to_dict()
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

