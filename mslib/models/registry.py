"""The methods the benchmark runs and the models `python -m mslib train` trains, read from one list of packages.

Each package under `mslib.models` declares, in its `__init__.py`,
    METHODS  = {name: (factory, description)}   factory(device) → transfer(content, style) → features
    TRAINERS = {name: run}                      run(preset, content, style, seed=0, out=None, device="cpu",
                                                    steps=None, resume=None, progress=True) → summary dict
A transfer takes two dicts, each with "features" ((T−1)×263, unnormalised), "joints" (T×22×3) and
labels, and returns the stylized features ((T−1)×263, unnormalised); the benchmark derives joint
positions from them in one place (`mslib.evaluation.bench`). A factory may give the transfer an
attribute `n_parameters` (every parameter used at inference) for `python -m mslib perf`.

The registry lives in `models` so that `models` never imports `mslib.evaluation` (the evaluator
stays independent); the benchmark adds its two reference rows with `register`.
"""
from __future__ import annotations

import importlib

# the one list of model packages: shared blocks, then paper A, B, C, D
PACKAGES = ("mslib.models.common", "mslib.models.adain", "mslib.models.mcm_ldm",
            "mslib.models.contrastive", "mslib.models.clusterstyle")

METHODS: dict = {}  # name → factory (the packages' and the benchmark's reference rows)
DESCRIPTIONS: dict = {}  # name → one line


def register(name: str, description: str = ""):
    """Decorator: register a method factory under `name` (the benchmark's reference rows use it)."""
    def wrap(factory):
        METHODS[name] = factory
        DESCRIPTIONS[name] = description or (factory.__doc__ or "").strip().splitlines()[0]
        return factory
    return wrap


def _packages() -> list:
    return [importlib.import_module(name) for name in PACKAGES]


def known_methods() -> list:
    """Names of every method: the packages' and any registered with `register`."""
    for package in _packages():
        for name, (factory, description) in getattr(package, "METHODS", {}).items():
            if name not in METHODS:
                register(name, description)(factory)
    return sorted(METHODS)


def get_method(name: str, device: str = "cpu"):
    """The transfer function of a method; unknown names list the known ones."""
    names = known_methods()
    if name not in METHODS:
        raise ValueError(f"--method {name!r} is unknown; known methods: {', '.join(names)}")
    return METHODS[name](device)


def trainers() -> dict:
    """Every trainable model's name → its run function, from the packages' TRAINERS."""
    found = {}
    for package in _packages():
        found.update(getattr(package, "TRAINERS", {}))
    return found
