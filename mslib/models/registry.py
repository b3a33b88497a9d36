"""The method registry: each model module registers a transfer factory under a name.

A factory (given a device) returns a function
    transfer(content: dict, style: dict) -> positions (T, 22, 3)
where each dict holds "features" ((T−1)×263, unnormalised), "joints" (T×22×3) and its labels.
It lives in `models` so a model registers itself without importing `mslib.evaluation` (DESIGN.md §1:
the evaluator stays independent); the benchmark (evaluation/bench.py) reads it from above.

Parameter count (for `python -m mslib perf`): a factory may give the transfer callable an attribute
`n_parameters` (every parameter the method uses at inference), or return an nn.Module.
"""
from __future__ import annotations

import importlib

METHODS: dict = {}
DESCRIPTIONS: dict = {}
# modules whose import registers their methods (missing ones are skipped)
METHOD_MODULES = ("mslib.models.adain", "mslib.models.dsdn", "mslib.models.contrastive",
                  "mslib.models.mcm_ldm", "mslib.models.clusterstyle")


def register(name: str, description: str = ""):
    """Decorator: register a method factory under `name`."""
    def wrap(factory):
        METHODS[name] = factory
        DESCRIPTIONS[name] = description or (factory.__doc__ or "").strip().splitlines()[0]
        return factory
    return wrap


def known_methods() -> list:
    """Names of every registered method (importing the model modules that exist)."""
    for mod in METHOD_MODULES:
        try:
            importlib.import_module(mod)
        except ModuleNotFoundError as e:
            if e.name != mod:
                raise
    return sorted(METHODS)


def get_method(name: str, device: str = "cpu"):
    """The transfer function of a registered method; unknown names list the known ones."""
    names = known_methods()
    if name not in METHODS:
        raise ValueError(f"--method {name!r} is unknown; known methods: {', '.join(names)}")
    return METHODS[name](device)
