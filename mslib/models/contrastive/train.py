"""Paper C's training recipe: the one loop on unlabelled (target, source) pairs, C Eq. 5; with `pretrain_steps`
(the course preset) an autoencoder phase first (C Eq. 1 + 2, and δ·L_views), after which E_s is frozen."""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import torch

from ...checkpoints import course_path
from ...training import fit, pretrain_then_freeze, run_summary
from .data import PairedClips
from .model import NAME, ContrastiveConfig, ContrastiveModel


def train(cfg: ContrastiveConfig, content, style, seed: int = 0, out=None, device="cpu", resume=None,
          progress: bool = True, exclude_styles=(), val: bool = True, checkpoint_every: int = 0):
    """Build the model and data, run the one loop; returns (model, history). `checkpoint_every` > 0 also
    saves `out` every that many phase-2 steps, so `resume=out` continues a cut run."""
    torch.manual_seed(seed)
    views = cfg.style_views > 0
    data = PairedClips(content, style, "train", cfg.crop, exclude_styles, views=views)
    model = ContrastiveModel(cfg, data.mean, data.std)
    val_set = PairedClips(content, style, "val", cfg.crop, exclude_styles, views=views) if val else None
    # 1: E_c, E_s, G (and D) as an autoencoder, C Eq. 1 + 2; 2: E_s frozen as C Eq. 4's judge, the rest on C Eq. 5
    tcfg = pretrain_then_freeze(model, data, replace(cfg.train_config(seed), checkpoint_every=checkpoint_every),
                                cfg.pretrain_steps, [model.style_encoder],
                                resume=resume, val_set=val_set, model_name=f"{NAME} (autoencoder)", device=device,
                                progress=progress, parameters=model.generator_parameters())
    history = fit(model, data, tcfg, val_set=val_set, model_name=NAME, out=out,
                  resume=resume, device=device, progress=progress, parameters=model.generator_parameters())
    return model, history


def run(preset, content, style, seed=0, out=None, device="cpu", steps=None, resume=None, progress=True):
    """`python -m mslib train contrastive --preset course|paper`."""
    cfg = ContrastiveConfig.preset(preset, **({"steps": int(steps)} if steps else {}))
    out = out or course_path(NAME)
    t0 = time.time()
    model, history = train(cfg, content, style, seed, out, device, resume, progress)
    tr = history["train"]
    last = lambda k: round(float(np.mean(tr[k][-50:])), 4)  # noqa: E731
    pre = getattr(model, "pretrain_history", None)
    extra = {"autoencoder_steps": pre["step"][-1]} if pre else {}
    return run_summary(NAME, out, history, seconds=round(time.time() - t0, 1), **extra,
                       **{k: last(k) for k in ("rec", "nce", "tri", "adv", "d")})

