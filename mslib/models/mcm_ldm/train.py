"""Paper B's training recipe (B §3.3): self-reconstruction. The VAE and the style extractor are frozen, so
every clip's latent z_0, content latent, style embedding and trajectory are computed once (`build_tensors`);
the denoiser then trains on B Eq. 4 with the style dropped to ∅ at random (`MCMLDM.training_step`).
Departure: besides each clip, `views − 1` random crops of it (at least `MIN_VIEW` frames) add
training examples drawn from the small built-in corpora."""
from __future__ import annotations

from dataclasses import asdict

import numpy as np
import torch
from torch.utils.data import Dataset

from ...checkpoints import course_path
from ...data.datasets import ContentClips, StyleClips
from ...motion.features import TRAJECTORY_DIMS
from ...training import TrainConfig, fit, run_summary, seed_everything
from ..common import style_extractor as SE
from ..common.layers import pad_batch
from ..common.vae import MotionVAE, load_vae
from .model import MCMLDM, NAME, STYLE_WINDOW, MCMConfig

MIN_VIEW = 32  # frames of the shortest random crop (a further view of a clip)


# ---------------------------------------------------------------- training tensors
def _window(x: torch.Tensor, n: int) -> torch.Tensor:
    """The centre n frames of (T, C) (edge-padded when shorter)."""
    if len(x) < n:
        return torch.cat([x, x[-1:].expand(n - len(x), -1)])
    s = (len(x) - n) // 2
    return x[s:s + n]


@torch.no_grad()
def build_tensors(vae: MotionVAE, extractor, content, style, split: str, views: int = 2, seed: int = 0,
                  windows: bool = False, batch_size: int = 64, limit: int | None = None) -> dict:
    """Every clip of a split (content + style corpora) as fixed tensors: "z0" target latent (M, N, d),
    "zc" content latent of the features with the trajectory dims zeroed, "style" frozen style embedding of
    the centre STYLE_WINDOW frames (M, S), "traj" (M, max_len, 3), "length" (M,); view 0 = the clip, further
    views = random crops. `windows=True` also keeps "style_window" (M, STYLE_WINDOW, N_FEATURES) for the
    from-scratch ablation;
    `limit`: at most that many clips of each corpus (evenly spaced), for quick runs."""
    raws = []
    for ds in (ContentClips(content, split, normalize=False), StyleClips(style, split, normalize=False, joints=False)):
        idx = range(len(ds)) if limit is None else np.linspace(0, len(ds) - 1, min(int(limit), len(ds))).astype(int)
        raws += [ds[int(i)]["features"] for i in idx]
    g = torch.Generator().manual_seed(seed)
    L = vae.cfg.max_len
    clips = []
    for v in range(views):
        for r in raws:
            x = vae.normalize(r)[:L]
            if v > 0 and len(x) > MIN_VIEW:
                n = int(torch.randint(MIN_VIEW, len(x) + 1, (), generator=g))
                s = int(torch.randint(0, len(x) - n + 1, (), generator=g))
                x = x[s:s + n]
            clips.append(x)
    out = {k: [] for k in ("z0", "zc", "style", "traj", "length") + (("style_window",) if windows else ())}
    dev = vae.mean.device
    for start in range(0, len(clips), batch_size):
        part = clips[start:start + batch_size]
        x, mask = pad_batch(part)
        x, mask = x.to(dev), mask.to(dev)
        xc = x.clone()
        xc[..., TRAJECTORY_DIMS] = 0.0  # the content condition sees no trajectory (as released)
        win = torch.stack([_window(c, STYLE_WINDOW) for c in part]).to(dev)
        out["z0"].append(vae.encode(x, mask).cpu())
        out["zc"].append(vae.encode(xc, mask).cpu())
        out["style"].append(extractor(win).cpu() if extractor is not None else torch.zeros(len(part), 1))
        tr = torch.zeros(len(part), L, 3)
        tr[:, :x.shape[1]] = x[..., TRAJECTORY_DIMS].cpu() * mask[..., None].cpu()
        out["traj"].append(tr)
        out["length"].append(mask.sum(1).cpu())
        if windows:
            out["style_window"].append(win.cpu())
    return {k: torch.cat(v) for k, v in out.items()}


class TensorSet(Dataset):
    """Rows of a dict of equally long tensors."""

    def __init__(self, tensors: dict):
        self.t = tensors
        self.n = len(next(iter(tensors.values())))

    def __len__(self):
        return self.n

    def __getitem__(self, i):
        return {k: v[i] for k, v in self.t.items()}


# ---------------------------------------------------------------- training
def train_mcm(cfg: MCMConfig, train: dict, val: dict | None, vae: MotionVAE, style_cfg: dict, seed=0, out=None,
              device="cpu", resume=None, progress=True) -> tuple:
    """Fit a denoiser on prepared tensors (build_tensors); returns (model, history)."""
    style_dim = style_cfg["out_dim"]
    seed_everything(seed)  # the initial weights too: a process's own torch seed differs from run to run
    model = MCMLDM(cfg, vae.cfg.latent_tokens, vae.cfg.latent_dim, style_dim, style_cfg)
    tc = TrainConfig(steps=cfg.steps, batch_size=cfg.batch_size, lr=cfg.lr, warmup_steps=min(200, cfg.steps // 10),
                     val_every=max(1, cfg.steps // 5), seed=seed)
    val_set = None  # the denoising loss on held-out clips is noisy and says little about transfer
    history = fit(model, TensorSet(train), tc, val_set, model_name=NAME, out=out, resume=resume, device=device,
                  progress=progress)
    return model.eval(), history


def prepare(content, style, device="cpu", windows: bool = False, views: int = 2, vae_path=None) -> tuple:
    """(vae, extractor, style config dict, train tensors) from the VAE (default: the packaged one) and the
    packaged style extractor."""
    vae = load_vae(vae_path, device=device)
    extractor = SE.load_style_extractor(device=device)
    style_cfg = asdict(extractor.cfg)
    return vae, extractor, style_cfg, build_tensors(vae, extractor, content, style, "train", views=views,
                                                    windows=windows)


def run(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True,
        overrides: dict | None = None, prepared: tuple | None = None) -> dict:
    """Train MCM-LDM on the frozen VAE latents and style embeddings; `overrides`: MCMConfig fields on top of
    the preset (e.g. a B Table 2 switch)."""
    fields = {**(overrides or {}), **({"steps": int(steps)} if steps else {})}
    cfg = MCMConfig.preset(preset, **fields)  # an unknown field is a ValueError naming it
    out = course_path(NAME) if out is None else out
    vae, extractor, style_cfg, train = prepared or prepare(content, style, device, windows=not cfg.pretrained_style)
    model, history = train_mcm(cfg, train, None, vae, style_cfg, seed, out, device, resume, progress)
    return run_summary(NAME, out, history, final_loss=round(float(np.mean(history["train"]["loss"][-50:])), 4))

