"""One config idiom for every model: a dataclass whose defaults are the paper's, and named presets.

    cfg = AdainConfig.preset("course")                 # the CPU course recipe
    cfg = AdainConfig.preset("paper", dropout=0.0)     # the paper's sizes, one field changed
    cfg = AdainConfig.from_dict(checkpoint["config"])  # what a checkpoint stored

`PRESETS` maps a preset name to the fields it changes from the paper's defaults ("paper" changes
none). `from_dict` refuses a key the config does not have, with a `ValueError` naming it, so a typo
never trains a model silently without the change it asked for.

`RETIRED` lists options that research recipes once had and the library no longer does (they live in
the history, at the commit named in `RETIRED_AT`): a stored config holding such a key with the value
the library now always uses loads as before; with any other value it is refused, naming the option.
`STORED_BESIDE` names what a checkpoint's dict keeps next to the fields (a tokenizer's vocabulary, a
sub-model's config), which its owner reads and `from_dict` skips.
"""
from __future__ import annotations

from dataclasses import asdict, fields
from typing import ClassVar

PRESET_NAMES = ("course", "paper")
RETIRED_AT = "3748be4"  # the last commit with the research options in the model files


class Config:
    """Mixin for the model config dataclasses (`@dataclass class XConfig(Config): …`)."""

    PRESETS: ClassVar[dict] = {"paper": {}, "course": {}}
    RETIRED: ClassVar[dict] = {}  # option → the value the library now always uses
    STORED_BESIDE: ClassVar[tuple] = ()  # keys a checkpoint keeps beside the fields (read by their owner, skipped here)

    @classmethod
    def preset(cls, name: str = "course", **overrides):
        """The preset `name` ("course" or "paper"), with `overrides` on top."""
        if name not in cls.PRESETS:
            raise ValueError(f"preset: expected one of {sorted(cls.PRESETS)}, got {name!r}")
        return cls.from_dict({**cls.PRESETS[name], **overrides}, what=f"{cls.__name__}.preset({name!r}) overrides")

    @classmethod
    def from_dict(cls, d: dict, what: str | None = None):
        """A config from a plain dict (a checkpoint's, JSON's); unknown keys are a ValueError naming them."""
        d = {k: v for k, v in d.items() if k not in cls.STORED_BESIDE}
        for key, kept in cls.RETIRED.items():
            if key in d and d.pop(key) != kept:
                raise ValueError(f"{what or cls.__name__}: option {key!r} was removed from the library (it only served "
                                 f"a research recipe); this config needs `git checkout {RETIRED_AT}`")
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise ValueError(f"{what or cls.__name__}: unknown keys {unknown}; {cls.__name__} has {sorted(known)}")
        defaults = cls()
        # JSON and older checkpoints store tuples as lists: give a tuple field its tuple back
        values = {k: tuple(v) if isinstance(v, list) and isinstance(getattr(defaults, k), tuple) else v
                  for k, v in d.items()}
        return cls(**values)

    def to_dict(self) -> dict:
        """The JSON-able dict a checkpoint stores."""
        return asdict(self)
