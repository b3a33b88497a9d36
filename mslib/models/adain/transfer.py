"""Paper A at inference: the packaged stage-1 and stage-2 models and the benchmark's two methods."""
from __future__ import annotations

import numpy as np

from ...checkpoints import course_path, load_model
from .dsdn import DSDN
from .model import AdainTransfer


def load_adain(path=None, device="cpu") -> AdainTransfer:
    """The stage-1 model from a checkpoint (default: the packaged course one)."""
    return load_model(path or course_path("adain"), "adain", AdainTransfer, device)


def load_dsdn(path=None, device="cpu") -> DSDN:
    """The stage-2 model from a checkpoint (default: the packaged course one)."""
    return load_model(path or course_path("dsdn"), "dsdn", DSDN, device)


def adain_method(device="cpu", path=None):
    """transfer(content, style) → stylized features with the course checkpoint (or `path`)."""
    model = load_adain(path, device)

    def transfer(content: dict, style: dict) -> np.ndarray:
        return model.transfer_features(content["features"], style["features"])
    transfer.n_parameters = sum(p.numel() for p in model.parameters())
    return transfer


def adain_dsdn_method(device="cpu"):
    """transfer(content, style) → features: stage 1 (course adain), then stage 2 (course dsdn)."""
    stage1, stage2 = load_adain(device=device), load_dsdn(device=device)

    def transfer(content: dict, style: dict) -> np.ndarray:
        return stage2.correct_features(stage1.transfer_features(content["features"], style["features"]))
    transfer.n_parameters = sum(p.numel() for m in (stage1, stage2) for p in m.parameters())
    return transfer
