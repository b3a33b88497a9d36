"""Checkpoints: a plain state dict + a JSON-able config + a format version, loaded with weights_only=True.

Course checkpoints live beside this file (`<name>.pt`), each made by `python -m mslib train` with a
fixed seed. Nothing here unpickles code: `torch.load(..., weights_only=True)` only.
"""
from __future__ import annotations

import io
import json
from pathlib import Path

import torch

from ..fileio import atomic_write_bytes, file_digest

FORMAT_VERSION = 1
PACKAGE_DIR = Path(__file__).resolve().parent
# the seed each packaged checkpoint was trained with (`python -m mslib train NAME --preset course --seed S`),
# chosen on val pairs by each method's seed rule (tools/); tools/train_all.py retrains with these
COURSE_SEEDS = {"evaluator_style": 0, "evaluator_content": 0, "vae": 0, "style_extractor": 0, "clusterstyle_style": 0,
                "clusterstyle_t2m": 0, "clusterstyle": 1, "contrastive": 1, "adain": 2, "dsdn": 0, "mcm_ldm": 0}


def course_path(name: str) -> Path:
    """Where the packaged course checkpoint of a model lives."""
    return PACKAGE_DIR / f"{name}.pt"


def checkpoint_digest(name: str) -> str:
    """The first 12 hex digits of a packaged checkpoint's SHA-256: which model a stored result measured."""
    return file_digest(course_path(name))


def save_checkpoint(path, model: torch.nn.Module, config: dict, model_name: str, extra: dict | None = None) -> Path:
    """Write {format_version, model, config, state_dict, extra} atomically."""
    json.dumps(config)  # the config must be JSON-able: fail here, not at load time
    state = {k: v.detach().cpu() for k, v in model.state_dict().items()}
    blob = {"format_version": FORMAT_VERSION, "model": model_name, "config": config,
            "state_dict": state, "extra": extra or {}}
    buf = io.BytesIO()
    torch.save(blob, buf)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, buf.getvalue())
    return path


def read_checkpoint(path, model_name: str | None = None) -> dict:
    """Load a checkpoint dict safely and check its format version (and model name when given)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"checkpoint {path}: no such file; train one with `python -m mslib train "
                         f"{model_name or 'MODEL'} --preset course --out {path}`")
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # truncated file, pickled code, not a torch file
        raise ValueError(f"checkpoint {path}: cannot be read safely ({type(e).__name__}: {e})") from None
    if not isinstance(blob, dict) or "format_version" not in blob or "state_dict" not in blob:
        raise ValueError(f"checkpoint {path}: not an mslib checkpoint (no format_version/state_dict)")
    if blob["format_version"] != FORMAT_VERSION:
        raise ValueError(f"checkpoint {path}: format version {blob['format_version']}, this mslib reads "
                         f"{FORMAT_VERSION}; retrain it with `python -m mslib train {blob.get('model', 'MODEL')} "
                         f"--preset course --out {path}`")
    if model_name is not None and blob.get("model") != model_name:
        raise ValueError(f"checkpoint {path}: holds model {blob.get('model')!r}, expected {model_name!r}")
    return blob


def trained_seed(path, model_name: str | None = None) -> int:
    """The seed `python -m mslib train … --seed S` made the checkpoint with. A two-phase recipe (its config has
    `pretrain_steps` > 0: mslib.training.pretrain_then_freeze) stores its second phase's seed, S + 1."""
    blob = read_checkpoint(path, model_name)
    two_phase = isinstance(blob.get("config"), dict) and (blob["config"].get("pretrain_steps") or 0) > 0
    return int(blob["extra"]["train_config"]["seed"]) - int(two_phase)


def load_state(path, model: torch.nn.Module, model_name: str | None = None) -> dict:
    """Load a checkpoint's weights into `model` after checking names and shapes; returns the blob."""
    blob = read_checkpoint(path, model_name)
    own = model.state_dict()
    theirs = blob["state_dict"]
    missing = sorted(set(own) - set(theirs))
    unexpected = sorted(set(theirs) - set(own))
    wrong = sorted(k for k in set(own) & set(theirs) if tuple(own[k].shape) != tuple(theirs[k].shape))
    if missing or unexpected or wrong:
        detail = "; ".join(s for s in (
            f"missing {missing[:5]}" if missing else "", f"unexpected {unexpected[:5]}" if unexpected else "",
            "shape mismatch " + ", ".join(f"{k} {tuple(theirs[k].shape)} vs {tuple(own[k].shape)}"
                                          for k in wrong[:5]) if wrong else "") if s)
        raise ValueError(f"checkpoint {path}: does not fit this model ({detail}); was it trained with "
                         "another config or preset?")
    model.load_state_dict(theirs)
    return blob


def load_model(path, model_name: str, build, device="cpu") -> torch.nn.Module:
    """`build(config)` from a checkpoint's config, its weights loaded (names and shapes checked), eval mode on `device`."""
    model = build(read_checkpoint(path, model_name)["config"])
    load_state(path, model, model_name)
    return model.to(device).eval()
