"""The one training loop for every model, on one process or under torchrun (DDP).

A trainable model is an `nn.Module` with
    training_step(batch) -> dict with "loss" (a scalar tensor) and any floats to log,
    validation_step(batch) -> dict of floats (optional),
and a JSON-able `config` dict. `fit` adds the optimiser and schedule from a `TrainConfig`,
gradient clipping, seeds, a progress bar, loss history, validation, a time budget, periodic
checkpoints and resume. Under `torchrun --nproc_per_node N` it wraps the model in
DistributedDataParallel (gloo on the CPU, nccl on GPUs) with a DistributedSampler.
"""
from __future__ import annotations

import math
import os
import random
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import torch
import torch.distributed as dist
from torch.utils.data import DataLoader, Dataset
from torch.utils.data.distributed import DistributedSampler
from tqdm.auto import tqdm

from .checkpoints import read_checkpoint, save_checkpoint


@dataclass
class TrainConfig:
    """Optimisation settings; each model's presets fill these in."""

    steps: int = 1000
    batch_size: int = 32
    lr: float = 1e-3
    weight_decay: float = 0.0
    betas: tuple = (0.9, 0.999)
    warmup_steps: int = 0
    schedule: str = "cosine"  # or "constant"
    grad_clip: float = 1.0
    val_every: int = 100
    val_batches: int = 4
    checkpoint_every: int = 0  # 0: only at the end
    time_budget_s: float | None = None  # stop early, cleanly, when exceeded
    seed: int = 0
    num_workers: int = 0
    extra: dict = field(default_factory=dict)


def seed_everything(seed: int) -> None:
    """Seed python, numpy and torch."""
    random.seed(seed)
    np.random.seed(seed % 2**32)
    torch.manual_seed(seed)


def distributed_context():
    """(rank, world_size) from torchrun's environment, initialising the process group once."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    if world <= 1:
        return 0, 1
    if not dist.is_initialized():
        dist.init_process_group("nccl" if torch.cuda.is_available() else "gloo")
    return dist.get_rank(), world


def lr_factor(step: int, cfg: TrainConfig) -> float:
    """Linear warm-up, then cosine decay to 10% (or constant)."""
    if cfg.warmup_steps and step < cfg.warmup_steps:
        return (step + 1) / cfg.warmup_steps
    if cfg.schedule == "constant":
        return 1.0
    if cfg.schedule != "cosine":
        raise ValueError(f"schedule: expected 'cosine' or 'constant', got {cfg.schedule!r}")
    progress = (step - cfg.warmup_steps) / max(1, cfg.steps - cfg.warmup_steps)
    return 0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * min(1.0, progress)))


def _to_device(batch, device):
    if isinstance(batch, torch.Tensor):
        return batch.to(device)
    if isinstance(batch, dict):
        return {k: _to_device(v, device) for k, v in batch.items()}
    if isinstance(batch, (list, tuple)):
        return type(batch)(_to_device(v, device) for v in batch)
    return batch


def _infinite(loader, sampler):
    epoch = 0
    while True:
        if sampler is not None:
            sampler.set_epoch(epoch)
        yield from loader
        epoch += 1


def fit(model: torch.nn.Module, train_set: Dataset, cfg: TrainConfig, val_set: Dataset | None = None,
        model_name: str = "model", out: str | Path | None = None, resume: str | Path | None = None,
        device: str | torch.device = "cpu", progress: bool = True, parameters=None) -> dict:
    """Train `model`; returns the history {"step", "train": {...}, "val": {...}, "seconds", "stopped"}."""
    rank, world = distributed_context()
    device = torch.device(device)
    if world > 1 and device.type == "cuda" and device.index is None:  # one GPU per process
        device = torch.device("cuda", int(os.environ.get("LOCAL_RANK", "0")))
    seed_everything(cfg.seed + rank)
    model.to(device)
    params = [p for p in (parameters if parameters is not None else model.parameters()) if p.requires_grad]
    if not params:
        raise ValueError(f"{model_name}: no trainable parameters")
    opt = torch.optim.AdamW(params, lr=cfg.lr, weight_decay=cfg.weight_decay, betas=tuple(cfg.betas))
    sched = torch.optim.lr_scheduler.LambdaLR(opt, lambda s: lr_factor(s, cfg))
    history = {"step": [], "train": {}, "val_step": [], "val": {}, "seconds": 0.0, "stopped": "steps"}
    start = 0
    if resume is not None and Path(resume).is_file():
        blob = read_checkpoint(resume, model_name)
        model.load_state_dict(blob["state_dict"])
        extra = blob.get("extra", {})
        if "optimizer" in extra:
            opt.load_state_dict(extra["optimizer"])
            sched.load_state_dict(extra["scheduler"])
        history = extra.get("history", history)
        start = int(extra.get("step", 0))
    wrapped = model
    if world > 1:
        wrapped = torch.nn.parallel.DistributedDataParallel(
            model, device_ids=[device.index] if device.type == "cuda" else None)
    sampler = DistributedSampler(train_set, shuffle=True, seed=cfg.seed) if world > 1 else None
    gen = torch.Generator().manual_seed(cfg.seed)
    loader = DataLoader(train_set, batch_size=cfg.batch_size, shuffle=sampler is None, sampler=sampler,
                        drop_last=len(train_set) >= cfg.batch_size * world, num_workers=cfg.num_workers,
                        generator=gen)
    batches = _infinite(loader, sampler)
    val_loader = DataLoader(val_set, batch_size=cfg.batch_size, shuffle=False) if val_set is not None else None

    def step_fn(batch):
        # DDP hooks run on forward(); training_step goes through the wrapper's module in one call
        return wrapped(batch, _mslib_step="train") if world > 1 else model.training_step(batch)

    if world > 1:
        _route_forward(model)
    t0 = time.time()
    bar = tqdm(total=cfg.steps, initial=start, desc=model_name, disable=not progress or rank != 0)
    model.train()
    step = start
    for step in range(start, cfg.steps):
        batch = _to_device(next(batches), device)
        logs = step_fn(batch)
        loss = logs["loss"]
        if not bool(torch.isfinite(loss.detach())):
            raise ValueError(f"{model_name}: loss became {loss.item()} at step {step}; lower the lr")
        opt.zero_grad(set_to_none=True)
        loss.backward()
        if cfg.grad_clip:
            torch.nn.utils.clip_grad_norm_(params, cfg.grad_clip)
        opt.step()
        sched.step()
        history["step"].append(step + 1)
        for k, v in logs.items():
            history["train"].setdefault(k, []).append(float(v.detach() if isinstance(v, torch.Tensor) else v))
        bar.update(1)
        if step % 10 == 0:
            bar.set_postfix(loss=f"{loss.item():.4f}")
        last = step + 1 == cfg.steps
        if val_loader is not None and ((step + 1) % cfg.val_every == 0 or last):
            _validate(model, val_loader, cfg.val_batches, device, history, step + 1)
        if out is not None and rank == 0 and cfg.checkpoint_every and (step + 1) % cfg.checkpoint_every == 0:
            _save(out, model, model_name, opt, sched, history, step + 1, cfg)
        if cfg.time_budget_s is not None and time.time() - t0 > cfg.time_budget_s:
            history["stopped"] = f"time budget after {step + 1} steps"
            if val_loader is not None and not last and (step + 1) % cfg.val_every:
                _validate(model, val_loader, cfg.val_batches, device, history, step + 1)
            step += 1
            break
    else:
        step = cfg.steps
    bar.close()
    history["seconds"] = history.get("seconds", 0.0) + (time.time() - t0)
    model.eval()
    if out is not None and rank == 0:
        _save(out, model, model_name, opt, sched, history, step, cfg)
    if world > 1:
        dist.barrier()
    return history


def _route_forward(model):
    """Let DDP's forward() call training_step, so gradients are all-reduced as usual."""
    if getattr(model, "_mslib_routed", False):
        return
    original = model.forward

    def forward(*args, _mslib_step=None, **kwargs):
        if _mslib_step == "train":
            return model.training_step(*args, **kwargs)
        return original(*args, **kwargs)

    model.forward = forward
    model._mslib_routed = True


@torch.no_grad()
def _validate(model, loader, max_batches, device, history, step):
    if not hasattr(model, "validation_step"):
        return
    model.eval()
    sums, n = {}, 0
    for i, batch in enumerate(loader):
        if i >= max_batches:
            break
        logs = model.validation_step(_to_device(batch, device))
        for k, v in logs.items():
            sums[k] = sums.get(k, 0.0) + float(v)
        n += 1
    model.train()
    history["val_step"].append(step)
    for k, v in sums.items():
        history["val"].setdefault(k, []).append(v / max(n, 1))


def _save(out, model, model_name, opt, sched, history, step, cfg):
    extra = {"step": step, "history": history, "train_config": _jsonable(asdict(cfg))}
    if step < cfg.steps:  # resumable: keep the optimiser state in intermediate checkpoints only
        extra.update(optimizer=opt.state_dict(), scheduler=sched.state_dict())
    save_checkpoint(out, model, getattr(model, "config", {}), model_name, extra)


def pretrain_then_freeze(model: torch.nn.Module, train_set: Dataset, cfg: TrainConfig, steps: int, frozen,
                         resume=None, **fit_kwargs) -> TrainConfig:
    """The course models' two-phase recipe (A stage 1, C): `steps` of `fit` with `model.pretraining=True`
    (the model's autoencoder losses; skipped when `resume` names an existing checkpoint of phase 2), then the
    `frozen` modules stop requiring gradients; returns phase 2's TrainConfig (seed + 1). steps = 0: `cfg` unchanged."""
    if not steps:
        return cfg
    if resume is None or not Path(resume).is_file():  # as in `fit`, a missing resume file means a fresh start
        model.pretraining = True
        try:
            model.pretrain_history = fit(model, train_set, replace(cfg, steps=int(steps)), **fit_kwargs)
        finally:
            model.pretraining = False
    for module in frozen:
        module.requires_grad_(False)
    return replace(cfg, seed=cfg.seed + 1)


def run_summary(name: str, out, history: dict, **extra) -> dict:
    """What every `python -m mslib train` prints: model, checkpoint, steps, seconds, why it stopped, then `extra`."""
    return {"model": name, "out": str(out), "steps": history["step"][-1] if history["step"] else 0,
            "seconds": round(history["seconds"], 1), "stopped": history["stopped"], **extra}


def _jsonable(d):
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}
