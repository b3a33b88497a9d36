"""`python -m mslib perf`: timing rows, the parameter-count protocol, targets, JSON and errors."""
import json
import math

import numpy as np
import torch

from mslib.cli import main
from mslib.evaluation import bench, perf


def run(capsys, *args):
    rc = main(["perf", *args])
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def test_json_report_for_the_reference_methods(capsys):
    rc, out, _ = run(capsys, "--json", "--methods", "identity,copy_style")
    report = json.loads(out.strip().splitlines()[-1])
    assert rc == 0 and report["frames"] == 64 and report["repeats"] == 20 and report["device"] == "cpu"
    assert [r["method"] for r in report["rows"]] == ["identity", "copy_style"]
    for r in report["rows"]:
        assert set(perf.JSON_KEYS) <= set(r) and r["repeats"] == 20 and r["n_parameters"] == 0
        assert 0 <= r["ms_min"] <= r["ms_median"] <= r["ms_max"] and math.isfinite(r["ms_max"])
        assert r["target_ms"] is None and r["met"] is None


def test_table_and_content_clip(capsys):
    rc, out, _ = run(capsys, "--methods", "identity", "--repeats", "3")
    assert rc == 0 and out.splitlines()[0].split()[:2] == ["method", "ms"]
    assert out.splitlines()[1].split()[0] == "identity" and "median of 3 runs" in out
    content, style = perf.perf_inputs()
    assert content["features"].shape == (64, 263) and content["joints"].shape == (65, 22, 3)
    assert len(style["features"]) >= 1


def test_met_column_follows_the_target(capsys, monkeypatch):
    content, style = perf.perf_inputs()
    for target in (0.0, 1e6):
        monkeypatch.setitem(perf.TARGETS_MS, "identity", target)
        row = perf.time_method("identity", content, style, repeats=20)
        assert row["target_ms"] == target and row["met"] == (row["ms_median"] <= target)
    assert row["met"] is True and perf.time_method("copy_style", content, style, 20)["met"] is None


def test_parameter_count_protocol():
    def plain(c, s):
        return c["joints"]
    assert perf.parameter_count(plain) is None
    plain.n_parameters = 7
    assert perf.parameter_count(plain) == 7
    assert perf.parameter_count(torch.nn.Linear(3, 4)) == 16  # an nn.Module: weights + biases


def test_a_method_that_cannot_load_is_reported_not_fatal(capsys, monkeypatch):
    def broken(device="cpu"):
        raise ValueError("checkpoint missing.pt: no such file")
    monkeypatch.setitem(bench.METHODS, "zz_broken", broken)
    rc, out, _ = run(capsys, "--json", "--methods", "zz_broken,identity", "--repeats", "2")
    rows = json.loads(out.strip().splitlines()[-1])["rows"]
    assert rc == 0 and "missing.pt" in rows[0]["error"] and rows[0]["ms_median"] is None
    assert rows[1]["method"] == "identity" and np.isfinite(rows[1]["ms_median"])


def test_errors(capsys):
    rc, _, err = run(capsys, "--methods", "identity,no_such_method")
    assert rc == 2 and "--methods" in err and "no_such_method" in err and "copy_style" in err
    rc, _, err = run(capsys, "--methods", "identity", "--repeats", "0")
    assert rc == 2 and "--repeats" in err
