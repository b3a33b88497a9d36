"""The training loop: learning, history, validation, time budget, resume, checkpoints, DDP on gloo."""
import subprocess
import sys
import textwrap

import pytest
import torch
from torch.utils.data import TensorDataset

from mslib.checkpoints import FORMAT_VERSION, load_state, read_checkpoint, save_checkpoint, trained_seed
from mslib.training import TrainConfig, fit, lr_factor, pretrain_then_freeze, run_summary


class Linear(torch.nn.Module):
    """y = Wx + b learned by MSE: a model with a known answer."""

    def __init__(self, dim=4):
        super().__init__()
        self.config = {"dim": dim}
        self.lin = torch.nn.Linear(dim, 1)

    def training_step(self, batch):
        x, y = batch
        loss = torch.nn.functional.mse_loss(self.lin(x), y)
        return {"loss": loss, "mse": loss.detach()}

    def validation_step(self, batch):
        x, y = batch
        return {"mse": torch.nn.functional.mse_loss(self.lin(x), y)}


def data(n=256, seed=0):
    g = torch.Generator().manual_seed(seed)
    x = torch.randn(n, 4, generator=g)
    w = torch.tensor([[1.0], [-2.0], [0.5], [3.0]])
    return TensorDataset(x, x @ w + 0.7)


def test_learns_the_known_answer_and_logs(tmp_path):
    torch.manual_seed(0)
    m = Linear()
    cfg = TrainConfig(steps=300, batch_size=32, lr=5e-2, val_every=100, seed=0)
    h = fit(m, data(), cfg, val_set=data(64, 1), model_name="linear", out=tmp_path / "m.pt", progress=False)
    assert h["step"][-1] == 300 and len(h["train"]["loss"]) == 300
    assert h["val_step"] == [100, 200, 300]
    assert h["val"]["mse"][-1] < 1e-3 < h["train"]["loss"][0]
    torch.testing.assert_close(m.lin.weight.detach(), torch.tensor([[1.0, -2.0, 0.5, 3.0]]), atol=2e-2, rtol=0)
    blob = read_checkpoint(tmp_path / "m.pt", "linear")
    assert blob["format_version"] == FORMAT_VERSION and blob["config"] == {"dim": 4}
    assert "optimizer" not in blob["extra"]  # final checkpoints stay small


def test_same_seed_same_weights():
    ws = []
    for _ in range(2):
        torch.manual_seed(123)
        m = Linear()
        fit(m, data(), TrainConfig(steps=20, lr=1e-2, seed=3), progress=False)
        ws.append(m.lin.weight.detach().clone())
    torch.testing.assert_close(ws[0], ws[1], atol=0, rtol=0)


def test_resume_continues_where_it_stopped(tmp_path):
    cfg = TrainConfig(steps=40, lr=1e-2, seed=1, checkpoint_every=20)
    torch.manual_seed(0)
    full = Linear()
    fit(full, data(), cfg, model_name="linear", progress=False)
    torch.manual_seed(0)
    half = Linear()
    h = fit(half, data(), TrainConfig(steps=40, lr=1e-2, seed=1, checkpoint_every=20, time_budget_s=0.0),
            model_name="linear", out=tmp_path / "ck.pt", progress=False)
    assert h["stopped"].startswith("time budget") and h["step"][-1] == 1
    blob = read_checkpoint(tmp_path / "ck.pt", "linear")
    assert blob["extra"]["step"] == 1 and "optimizer" in blob["extra"]
    torch.manual_seed(0)
    resumed = Linear()
    h2 = fit(resumed, data(), cfg, model_name="linear", resume=tmp_path / "ck.pt", progress=False)
    assert h2["step"][-1] == 40 and len(h2["train"]["loss"]) == 40
    assert torch.isfinite(resumed.lin.weight).all()


class TwoPhase(Linear):
    """Linear that counts the steps it trains in its pretraining phase."""

    pretraining = False
    pretrain_steps_seen = 0

    def training_step(self, batch):
        self.pretrain_steps_seen += self.pretraining
        return super().training_step(batch)


def test_pretrain_runs_unless_the_resume_file_exists(tmp_path):
    cfg = TrainConfig(steps=5, lr=1e-2, seed=4)
    fresh = TwoPhase()
    phase2 = pretrain_then_freeze(fresh, data(), cfg, 7, [fresh.lin], resume=tmp_path / "missing.pt", progress=False)
    assert fresh.pretrain_steps_seen == 7 and phase2.seed == 5  # a missing file: a fresh start, phase 1 included
    assert not any(p.requires_grad for p in fresh.lin.parameters())
    save_checkpoint(tmp_path / "cut.pt", fresh, fresh.config, "linear")
    cut = TwoPhase()
    pretrain_then_freeze(cut, data(), cfg, 7, [cut.lin], resume=tmp_path / "cut.pt", progress=False)
    assert cut.pretrain_steps_seen == 0  # phase 2 resumes from the file; phase 1 is not run again


def test_lr_schedule():
    cfg = TrainConfig(steps=100, warmup_steps=10)
    assert lr_factor(0, cfg) == pytest.approx(0.1) and lr_factor(9, cfg) == pytest.approx(1.0)
    assert lr_factor(100, cfg) == pytest.approx(0.1)
    with pytest.raises(ValueError, match="schedule"):
        lr_factor(50, TrainConfig(schedule="nope"))


def test_checkpoint_errors_name_the_file(tmp_path):
    m = Linear()
    p = save_checkpoint(tmp_path / "a.pt", m, m.config, "linear")
    with pytest.raises(ValueError, match="expected 'other'"):
        read_checkpoint(p, "other")
    with pytest.raises(ValueError, match="shape mismatch"):
        load_state(p, Linear(dim=5), "linear")
    blob = torch.load(p, weights_only=True)
    blob["format_version"] = 999
    torch.save(blob, tmp_path / "old.pt")
    with pytest.raises(ValueError, match=r"old\.pt: format version 999.*retrain it with `python -m mslib train linear"):
        read_checkpoint(tmp_path / "old.pt")
    (tmp_path / "junk.pt").write_bytes(b"garbage")
    with pytest.raises(ValueError, match="junk.pt: cannot be read safely"):
        read_checkpoint(tmp_path / "junk.pt")
    with pytest.raises(ValueError, match="no such file"):
        read_checkpoint(tmp_path / "missing.pt")
    with pytest.raises(TypeError):
        save_checkpoint(tmp_path / "b.pt", m, {"bad": object()}, "linear")


def test_trained_seed_is_the_command_seed_for_one_and_two_phase_recipes(tmp_path):
    """A two-phase recipe (pretrain_steps > 0) stores its second phase's seed, S + 1; trained_seed gives S."""
    m = Linear()
    one = save_checkpoint(tmp_path / "one.pt", m, {**m.config, "pretrain_steps": 0}, "linear",
                          extra={"train_config": {"seed": 5}})
    two = save_checkpoint(tmp_path / "two.pt", m, {**m.config, "pretrain_steps": 30}, "linear",
                          extra={"train_config": {"seed": 5}})
    assert (trained_seed(one, "linear"), trained_seed(two, "linear")) == (5, 4)


@pytest.mark.bench
def test_ddp_two_processes_on_gloo_end_with_identical_weights(tmp_path):
    script = tmp_path / "ddp_train.py"
    script.write_text(textwrap.dedent(f"""
        import sys, torch, torch.distributed as dist
        sys.path.insert(0, {str(tmp_path)!r})
        from tests.test_training import Linear, data
        from mslib.training import TrainConfig, fit
        torch.manual_seed(0)
        m = Linear()
        fit(m, data(), TrainConfig(steps=5, batch_size=16, lr=1e-2, seed=0), model_name="linear", progress=False)
        torch.save(m.state_dict(), {str(tmp_path)!r} + f"/rank{{dist.get_rank()}}.pt")
        dist.destroy_process_group()
    """))
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    env = {"PYTHONPATH": str(root), "OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"}
    r = subprocess.run([sys.executable, "-m", "torch.distributed.run", "--standalone",
                        "--nproc_per_node", "2", str(script)], capture_output=True, text=True, env=env,
                       cwd=root, timeout=240)
    assert r.returncode == 0, r.stderr[-2000:]
    a = torch.load(tmp_path / "rank0.pt", weights_only=True)
    b = torch.load(tmp_path / "rank1.pt", weights_only=True)
    for k in a:
        torch.testing.assert_close(a[k], b[k], atol=0, rtol=0)
    torch.manual_seed(0)
    start = Linear()
    assert not torch.equal(start.lin.weight, a["lin.weight"])  # they trained, and agree


def test_packaged_checkpoints_are_safe_small_and_current():
    from mslib.checkpoints import PACKAGE_DIR
    files = sorted(PACKAGE_DIR.glob("*.pt"))
    assert len(files) >= 8, [f.name for f in files]
    assert sum(f.stat().st_size for f in files) <= 40 * 2 ** 20  # issue 5: all together ≤ 40 MB
    for f in files:
        blob = read_checkpoint(f)  # weights_only=True, format version checked
        assert blob["model"] == f.stem, f"{f.name} holds model {blob['model']!r}"


def test_run_summary_heads_every_train_command():
    history = {"step": [10, 20], "seconds": 3.14159, "stopped": "steps"}
    s = run_summary("toy", "/tmp/toy.pt", history, val_loss=0.5, seconds=2.0)
    assert s == {"model": "toy", "out": "/tmp/toy.pt", "steps": 20, "seconds": 2.0, "stopped": "steps", "val_loss": 0.5}
    assert run_summary("toy", "x.pt", {"step": [], "seconds": 0.04, "stopped": "budget"})["steps"] == 0


def _trainer(name, tmp_path):
    """A tiny run of one trainer with seed 3, returning the trained module."""
    from mslib.data.corpora import load_builtin
    p = load_builtin(progress=False)
    if name == "adain":
        from mslib.models import adain as A
        cfg = A.AdainConfig.preset("course", hidden=16, content_blocks=1, decoder_blocks=1, heads=2, clip_frames=24,
                                   pretrain_steps=2)
        return lambda: A.train_adain("course", p["content"], p["style"], seed=3, progress=False, config=cfg,
                                     train_config=TrainConfig(steps=2, batch_size=4, val_every=2, val_batches=1))[0]
    if name == "dsdn":
        from mslib.models import adain as A
        g = torch.Generator().manual_seed(0)
        clean = torch.randn(8, 16, 263, generator=g).cumsum(1) * 0.1
        data = ((clean[:6] + 0.1, clean[:6]), (clean[6:] + 0.1, clean[6:]))
        cfg = A.DsdnConfig.preset("course", static_channels=(16, 32), lstm_hidden=8, regressor_hidden=8,
                                  gate_hidden=8, clip_frames=16)
        stage1 = A.AdainTransfer(A.AdainConfig(hidden=8, content_blocks=1, decoder_blocks=1, heads=2))
        return lambda: A.train_dsdn("course", None, None, seed=3, progress=False, config=cfg, stage1=stage1, data=data,
                                    train_config=TrainConfig(steps=3, batch_size=4, val_every=3, val_batches=1))[0]
    if name == "mcm_ldm":
        from types import SimpleNamespace
        from mslib.models import mcm_ldm as M
        g = torch.Generator().manual_seed(0)
        tens = {"z0": torch.randn(8, 3, 8, generator=g), "zc": torch.randn(8, 3, 8, generator=g),
                "style": torch.randn(8, 6, generator=g), "traj": torch.randn(8, 24, 3, generator=g),
                "length": torch.full((8,), 24)}
        cfg = M.MCMConfig(width=32, heads=2, blocks=2, mlp_ratio=2, traj_layers=1, traj_down=4, steps=3, batch_size=4)
        vae = SimpleNamespace(cfg=SimpleNamespace(latent_tokens=3, latent_dim=8))
        style_cfg = {"dim": 16, "out_dim": 6, "heads": 2, "layers": 1}
        return lambda: M.train_mcm(cfg, tens, None, vae, style_cfg, seed=3, progress=False)[0]
    if name == "style_extractor":
        from mslib.models.common import style_extractor as SE

        def train():
            SE.run("course", p["content"], p["style"], seed=3, out=tmp_path / "se.pt", steps=2, progress=False)
            return SE.load_style_extractor(tmp_path / "se.pt")
        return train
    from mslib.models.clusterstyle.train import train_style_model
    return lambda: train_style_model("course", p["content"], p["style"], seed=3, out=None, steps=2, progress=False)[0]


@pytest.mark.parametrize("trainer", ["adain", "dsdn", "mcm_ldm", "style_extractor", "clusterstyle_style"])
def test_a_run_seed_fixes_the_initial_weights(trainer, tmp_path):
    """Two runs with one seed agree whatever torch's own seed was (a process starts with a random one)."""
    train, weights = _trainer(trainer, tmp_path), []
    for noise in (1, 2):
        torch.manual_seed(noise)  # another process, another starting seed
        weights.append(torch.cat([q.detach().flatten() for q in train().parameters()]))
    assert torch.equal(*weights)
