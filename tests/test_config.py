"""The one config idiom (mslib.models.common.config): paper defaults, presets as overrides, from_dict refusing
unknown keys, retired options, what a checkpoint keeps beside the fields; and the shared configs built on it."""
from dataclasses import dataclass
from typing import ClassVar

import pytest

from mslib.models.common.config import Config
from mslib.models.common.style_extractor import StyleExtractorConfig
from mslib.models.common.text import TextConfig
from mslib.models.common.vae import VAEConfig


@dataclass
class ToyConfig(Config):
    width: int = 256  # the "paper's"
    sizes: tuple = (3, 4)
    PRESETS: ClassVar[dict] = {"paper": {}, "course": {"width": 16}}
    RETIRED: ClassVar[dict] = {"old_switch": False}
    STORED_BESIDE: ClassVar[tuple] = ("vocab",)


def test_presets_are_overrides_of_the_paper_defaults():
    assert ToyConfig.preset("paper") == ToyConfig()
    assert ToyConfig.preset("course") == ToyConfig(width=16)
    assert ToyConfig.preset("course", sizes=(1,)) == ToyConfig(width=16, sizes=(1,))
    with pytest.raises(ValueError, match="preset: expected one of \\['course', 'paper'\\], got 'gpu'"):
        ToyConfig.preset("gpu")


def test_from_dict_round_trips_and_names_unknown_keys():
    cfg = ToyConfig(width=8, sizes=(5, 6))
    assert ToyConfig.from_dict(cfg.to_dict()) == cfg
    assert ToyConfig.from_dict({"sizes": [5, 6]}).sizes == (5, 6)  # JSON lists come back as tuples
    with pytest.raises(ValueError, match="unknown keys \\['widht'\\]"):
        ToyConfig.from_dict({"widht": 8})
    with pytest.raises(ValueError, match="overrides: unknown keys \\['depth'\\]"):
        ToyConfig.preset("course", depth=2)


def test_retired_options_and_what_is_stored_beside():
    assert ToyConfig.from_dict({"width": 8, "old_switch": False}) == ToyConfig(width=8)  # the kept behaviour loads
    with pytest.raises(ValueError, match="'old_switch' was removed .*git checkout"):
        ToyConfig.from_dict({"width": 8, "old_switch": True})
    assert ToyConfig.from_dict({"width": 8, "vocab": ["a", "b"]}) == ToyConfig(width=8)


@pytest.mark.parametrize("cls", [VAEConfig, TextConfig, StyleExtractorConfig])
def test_shared_configs_follow_the_idiom(cls):
    assert cls.preset("paper") == cls()
    course = cls.preset("course")
    assert cls.from_dict(course.to_dict()) == course
    with pytest.raises(ValueError, match="unknown keys \\['not_a_field'\\]"):
        cls.from_dict({**course.to_dict(), "not_a_field": 1})


def test_the_course_vae_is_the_conv_one_and_the_paper_vae_mlds():
    assert VAEConfig.preset("course").arch == "conv" and VAEConfig.preset("course").latent_tokens == 50
    assert (VAEConfig().arch, VAEConfig().latent_tokens, VAEConfig().latent_dim) == ("transformer", 7, 256)
