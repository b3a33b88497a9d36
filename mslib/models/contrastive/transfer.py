"""Paper C at inference: the packaged model, style interpolation (C Fig. 10–11) and the benchmark's method."""
from __future__ import annotations

import numpy as np
import torch

from ...checkpoints import course_path, load_state, read_checkpoint
from ...motion.features import decode
from .model import NAME, ContrastiveConfig, ContrastiveModel


def load(path=None, device="cpu") -> ContrastiveModel:
    """The model stored in a checkpoint (default: the packaged course one), in eval mode."""
    path = course_path(NAME) if path is None else path
    blob = read_checkpoint(path, NAME)
    model = ContrastiveModel(ContrastiveConfig.from_dict(blob["config"], what=f"checkpoint {path}"))
    load_state(path, model, NAME)
    return model.to(device).eval()


def contrastive_method(device="cpu"):
    """transfer(content, style) → stylized (T, N_FEATURES) features with the course checkpoint."""
    model = load(device=device)

    def transfer(content, style):
        return model.transfer_features(content["features"], style["features"])
    transfer.n_parameters = sum(p.numel() for p in model.parameters())
    return transfer


@torch.no_grad()
def interpolate_styles(model: ContrastiveModel, content: np.ndarray, style_a: np.ndarray, style_b: np.ndarray,
                       weights=(0.0, 0.3, 0.6, 1.0)) -> list:
    """C Fig. 10–11: decode one content with (1 − w)·E_s(a) + w·E_s(b) → list of (T, N_JOINTS, 3) positions."""
    dev = model.mean.device
    t = lambda a: model.normalize(torch.as_tensor(np.asarray(a), dtype=torch.float32, device=dev))[None]  # noqa: E731
    c = t(content)
    sa, sb = model.encode_style(t(style_a)), model.encode_style(t(style_b))
    k = model.cfg.keep_root
    out = []
    for w in weights:
        f = model.decode_content(c, (1 - w) * sa + w * sb)  # (T, D), on the course's windows
        f[:, :k] = np.asarray(content, np.float64)[:, :k]
        out.append(decode(f))
    return out
