"""tools/contrastive_analysis.py: C's findings runner — the stored JSON round trip, and gram's known answer."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "contrastive_analysis", Path(__file__).resolve().parents[1] / "tools" / "contrastive_analysis.py")
CA = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(CA)


def test_gram_known_answer():
    x = np.random.default_rng(0).normal(size=(10, 3))
    np.testing.assert_allclose(CA.gram(x), x.T @ x / 10)


def test_missing_findings_name_the_command(tmp_path):
    with pytest.raises(ValueError, match="contrastive_analysis"):
        CA.load_findings(tmp_path / "none.json")


def test_findings_round_trip_and_load_before_compute(tmp_path):
    results = {"steps": 3, "sweep": [{"beta": 0.3, "content_distance": 0.5}], "labels": ["a", "b"]}
    path = CA.save_findings(results, tmp_path / "f.json")
    assert CA.load_findings(path) == results
    # an existing file is loaded, never recomputed (the folders given here do not exist)
    assert CA.findings(tmp_path / "no_content", tmp_path / "no_style", path=path) == results
