"""Paper C: losses against known answers, shapes, the discriminator's own step, a tiny training run,
the packaged checkpoint and the bench entry, and the findings' measures."""
import importlib
import json
import math

import numpy as np
import pytest
import torch
from torch.utils.data import Dataset

from mslib.checkpoints import course_path, read_checkpoint
from mslib.models import contrastive as C
from mslib.training import fit


def tiny(**kw):
    return C.ContrastiveConfig.preset("course", hidden=16, style_dim=8, disc_hidden=16, **kw)


# ---------------------------------------------------------------- losses
def test_info_nce_known_answers():
    torch.manual_seed(0)
    W = torch.eye(8)
    same = torch.zeros(2, 8, 5)  # every key scores the same: log t
    assert C.info_nce(same, same, W).item() == pytest.approx(math.log(5), abs=1e-6)
    q = 10 * torch.eye(8)[:, :5].expand(3, -1, -1).contiguous()  # orthogonal steps, positive = query
    assert C.info_nce(q, q, W).item() < 1e-3
    shuffled = q[:, :, [1, 2, 3, 4, 0]]  # the positive at step i is another step's vector
    assert C.info_nce(q, shuffled, W).item() > 5
    k = torch.randn(4, 8, 6)
    assert C.info_nce(k + 0.1 * torch.randn_like(k), k, W) < C.info_nce(torch.randn_like(k), k, W)


def test_info_nce_rejects_bad_shapes():
    with pytest.raises(ValueError, match="query/keys"):
        C.info_nce(torch.zeros(2, 8, 5), torch.zeros(2, 8, 4), torch.eye(8))


def test_triplet_known_answers():
    q = torch.zeros(2, 3)
    far = torch.tensor([[2.0, 0, 0], [0, 0, 3.0]])
    assert C.triplet_loss(q, q, far, 1.0).item() == 0.0  # margin satisfied
    near = torch.tensor([[0.5, 0, 0], [0, 0.5, 0]])
    assert C.triplet_loss(q, q, near, 1.0).item() == pytest.approx(0.5)
    assert C.triplet_loss(q, near, q, 1.0).item() == pytest.approx(1.5)


def test_recording_nce_known_answers():
    """Two recordings: views aligned with their own code score low, swapped views high; all equal: log B."""
    codes = torch.tensor([[1.0, 0.0], [0.0, 2.0]])
    tau = 0.5  # cosines 1 (own) and 0 (other): each row's loss is log(1 + e^(−1/τ)) in both directions
    assert C.recording_nce(codes, 3 * codes, tau).item() == pytest.approx(math.log(1 + math.exp(-1 / tau)), rel=1e-5)
    assert C.recording_nce(codes, codes.flip(0), tau).item() == pytest.approx(math.log(1 + math.exp(1 / tau)), rel=1e-5)
    same = torch.ones(5, 3)
    assert C.recording_nce(same, same).item() == pytest.approx(math.log(5), rel=1e-5)
    with pytest.raises(ValueError, match="codes/views"):
        C.recording_nce(codes, codes[:1])
    for bad in (dict(style_views=-0.1), dict(style_tau=0.0)):
        with pytest.raises(ValueError, match="style_views, style_tau"):
            C.ContrastiveConfig.preset("course", **bad)


def test_adversarial_and_reconstruction_known_answers():
    d, g = C.adversarial_losses(torch.zeros(4, 3), torch.zeros(4, 3))
    assert d.item() == pytest.approx(2 * math.log(2)) and g.item() == pytest.approx(math.log(2))
    x = torch.zeros(2, 5, 4)
    assert C.reconstruction_loss(x + 3.0, x).item() == pytest.approx(3.0, rel=1e-5)


# ---------------------------------------------------------------- the model
def test_shapes_and_keep_root():
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny()).eval()
    x = torch.randn(3, 31, 263)
    assert m.encode_content(x).shape == (3, 16, 15)   # h × t, t = T // 2
    assert m.encode_style(x).shape == (3, 8)
    assert m.generate(m.encode_content(x), m.encode_style(x), 31, x).shape == (3, 31, 263)
    sk = C.ContrastiveModel(tiny(content_skip=True)).eval()
    with pytest.raises(ValueError, match="content_skip"):
        sk.generate(sk.encode_content(x), sk.encode_style(x), 31)
    plain = C.ContrastiveModel(tiny(content_skip=False)).eval()
    plain.load_state_dict(sk.state_dict())
    skip = sk.generate(sk.encode_content(x), sk.encode_style(x), 31, x) - plain.generate(
        sk.encode_content(x), sk.encode_style(x), 31)
    torch.testing.assert_close(skip, x - x.mean(1, keepdim=True))  # the content's own movement
    normed = m.encode_content(x + 3.0)  # E_c ends with instance normalisation over time: no time mean (posture)
    torch.testing.assert_close(normed.mean(-1), torch.zeros(3, 16), atol=1e-5, rtol=0)
    assert m.discriminator(x).shape == (3, 7)
    content, style = np.random.default_rng(0).normal(size=(50, 263)), np.random.default_rng(1).normal(size=(31, 263))
    out = m.transfer_features(content, style)
    assert out.shape == (50, 263) and np.array_equal(out[:, :3], content[:, :3])
    assert not np.allclose(out[:, 3:], content[:, 3:])
    with pytest.raises(ValueError, match="content"):
        m.transfer_features(content[:, :100], style)


def test_style_strength_mixes_the_style_codes():
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny()).eval()
    torch.nn.init.normal_(m.generator.head[-1].weight, std=0.1)  # the course G starts as zero: let the code show
    rng = np.random.default_rng(0)
    content, style, other = rng.normal(size=(40, 263)), rng.normal(size=(31, 263)), rng.normal(size=(31, 263))
    assert m.cfg.style_strength == 1.0  # the course preset's: C's transfer
    full = m.transfer_features(content, style, 1.0)
    np.testing.assert_allclose(m.transfer_features(content, style), full)
    np.testing.assert_allclose(m.transfer_features(content, style, 0.0),                   # the content's own code
                               m.transfer_features(content, content, 1.0), atol=1e-5)
    assert not np.allclose(m.transfer_features(content, style, 0.5), full)
    m.cfg = C.ContrastiveConfig.preset("course", hidden=16, style_dim=8, disc_hidden=16, style_strength=0.0)
    np.testing.assert_allclose(m.transfer_features(content, other), m.transfer_features(content, style), atol=1e-5)


def test_a_long_content_is_transferred_on_overlapping_windows():
    from mslib.models.common.windows import window_starts
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny()).eval()
    torch.nn.init.normal_(m.generator.head[-1].weight, std=0.1)  # the course G starts as zero: let G show
    rng = np.random.default_rng(0)
    content, style = rng.normal(size=(130, 263)), rng.normal(size=(31, 263))
    w = m.cfg.transfer_window
    out = m.transfer_features(content, style)
    assert not np.allclose(out, m.transfer_features(content, style, window=0))  # 130 rows' statistics are not 48's
    starts = window_starts(len(content), w)
    np.testing.assert_allclose(out[:starts[1]], m.transfer_features(content[:w], style)[:starts[1]],
                               atol=1e-5)  # before the second window starts: the first window's transfer alone
    alone = len(content) - (starts[-2] + w)  # after the last but one window ends: the last window's alone
    np.testing.assert_allclose(out[-alone:], m.transfer_features(content[-w:], style)[-alone:], atol=1e-5)
    short = content[:40]  # no longer than a window: transferred whole
    np.testing.assert_allclose(m.transfer_features(short, style), m.transfer_features(short, style, window=0))
    assert np.array_equal(out[:, :3], content[:, :3])  # the root trajectory stays the content's
    with pytest.raises(ValueError, match="transfer_window"):
        tiny(transfer_window=4)


def test_discriminator_has_its_own_optimiser():
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny())
    assert not any(p is q for p in m.generator_parameters() for q in m.discriminator.parameters())
    before = [p.detach().clone() for p in m.discriminator.parameters()]
    logs = m.training_step({"target": torch.randn(4, 31, 263), "source": torch.randn(4, 31, 263)})
    assert set(logs) >= {"loss", "rec", "adv", "nce", "tri", "d"}
    assert all(not torch.equal(a, b) for a, b in zip(before, m.discriminator.parameters()))
    c = m.cfg  # C Eq. 5
    total = logs["rec"] + c.alpha * logs["adv"] + c.beta * logs["nce"] + c.gamma * logs["tri"]
    assert logs["loss"].item() == pytest.approx(total.item(), rel=1e-5)


def test_discriminator_real_motions_are_the_source_clips():
    """C Eq. 2's real motions: the source clips M^S."""
    target, source = torch.randn(4, 31, 263), torch.randn(4, 31, 263)
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny())
    seen = []
    m.discriminator.register_forward_pre_hook(lambda module, args: seen.append(args[0]))
    m.training_step({"target": target, "source": source})
    assert len(seen) == 3 and seen[0] is source  # D's step on M^S and the detached M^G, then G's term on M^G
    assert not seen[1].requires_grad and seen[2].requires_grad


class Smooth(Dataset):
    """Random smooth (target, source) pairs: one sine per channel, each clip with its own time shift."""

    def __init__(self, n=64):
        g = torch.Generator().manual_seed(0)
        phase = 6 * torch.rand(1, 263, generator=g)
        t = torch.arange(31.0)[:, None]
        self.items = [{k: torch.sin(0.3 * (t + 20 * torch.rand(1, generator=g)) + phase)
                       for k in ("target", "source")} for _ in range(n)]

    def __len__(self):
        return len(self.items)

    def __getitem__(self, i):
        return self.items[i]


def test_tiny_training_run_lowers_the_loss():
    torch.manual_seed(0)
    cfg = tiny(steps=60, batch_size=8, lr=3e-3, warmup_steps=0)
    m = C.ContrastiveModel(cfg)
    h = fit(m, Smooth(), cfg.train_config(0), model_name="contrastive", progress=False,
            parameters=m.generator_parameters())
    rec = h["train"]["rec"]
    assert np.mean(rec[-10:]) < 0.7 * np.mean(rec[:5])
    assert np.mean(h["train"]["nce"][-10:]) < np.mean(h["train"]["nce"][:5])


def test_autoencoder_steps_drop_the_contrastive_terms():
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny())
    m.pretraining = True
    logs = m.training_step({"target": torch.randn(4, 31, 263), "source": torch.randn(4, 31, 263)})
    assert logs["nce"].item() > 0 and logs["tri"].item() >= 0  # still logged
    assert logs["loss"].item() == pytest.approx((logs["rec"] + m.cfg.alpha * logs["adv"]).item(), rel=1e-5)


def test_recording_views_train_the_style_encoder_only_while_it_trains():
    """style_views δ adds δ·recording_nce while E_s trains (autoencoder phase) and nothing once it is frozen."""
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny(style_views=0.5))
    batch = {k: torch.randn(4, 31, 263) for k in ("target", "source", "source_view")}
    m.pretraining = True
    logs = m.training_step(batch)
    assert logs["loss"].item() == pytest.approx((logs["rec"] + m.cfg.alpha * logs["adv"] + 0.5 * logs["views"]).item(),
                                                rel=1e-5)
    m.pretraining = False
    m.style_encoder.requires_grad_(False)  # phase 2: the judge is frozen, the term is not even computed
    logs = m.training_step(batch)
    c = m.cfg
    assert logs["loss"].item() == pytest.approx(
        (logs["rec"] + c.alpha * logs["adv"] + c.beta * logs["nce"] + c.gamma * logs["tri"]).item(), rel=1e-5)
    assert "views" not in logs and "views" not in C.ContrastiveModel(tiny(style_views=0.0)).training_step(batch)  # δ = 0: C


def test_two_phase_training_freezes_the_style_encoder(monkeypatch):
    from mslib.data.corpora import load_builtin
    builtin = load_builtin(progress=False)
    calls = []
    import mslib.training
    real_fit = mslib.training.fit

    def recording_fit(model, data, tcfg, **kw):
        calls.append({"steps": tcfg.steps, "seed": tcfg.seed, "pretraining": model.pretraining,
                      "style": [p.detach().clone() for p in model.style_encoder.parameters()],
                      "content": [p.detach().clone() for p in model.content_encoder.parameters()]})
        return real_fit(model, data, tcfg, **kw)

    monkeypatch.setattr(importlib.import_module("mslib.models.contrastive.train"), "fit", recording_fit)  # phase 2 (C.train) and phase 1 (the shared two-phase helper)
    monkeypatch.setattr("mslib.training.fit", recording_fit)
    cfg = tiny(steps=3, pretrain_steps=2, batch_size=4, warmup_steps=0)
    m, h = C.train(cfg, builtin["content"], builtin["style"], seed=5, progress=False, val=False)
    assert [(c["steps"], c["seed"], c["pretraining"]) for c in calls] == [(2, 5, True), (3, 6, False)]
    assert m.pretrain_history["step"][-1] == 2 and h["step"][-1] == 3
    assert not any(p.requires_grad for p in m.style_encoder.parameters())
    assert all(torch.equal(a, b) for a, b in zip(calls[1]["style"], m.style_encoder.parameters()))   # frozen
    assert any(not torch.equal(a, b) for a, b in zip(calls[0]["style"], calls[1]["style"]))          # trained in 1
    assert any(not torch.equal(a, b) for a, b in zip(calls[1]["content"], m.content_encoder.parameters()))


def test_a_cut_run_resumes_its_second_phase(tmp_path, monkeypatch):
    from mslib.data.corpora import load_builtin
    builtin = load_builtin(progress=False)
    cfg, out = tiny(steps=4, pretrain_steps=2, batch_size=4, warmup_steps=0), tmp_path / "cut.pt"
    calls = []
    real_step = C.ContrastiveModel.training_step

    def cut_at_phase_2_step_3(model, batch):
        calls.append(model.pretraining)
        if calls.count(False) == 3 and len(calls) < 6:
            raise KeyboardInterrupt("the session ended")
        return real_step(model, batch)

    monkeypatch.setattr(C.ContrastiveModel, "training_step", cut_at_phase_2_step_3)
    with pytest.raises(KeyboardInterrupt):
        C.train(cfg, builtin["content"], builtin["style"], seed=1, out=out, progress=False, val=False,
                checkpoint_every=2)
    assert read_checkpoint(out, C.NAME)["extra"]["step"] == 2  # the checkpoint written at phase-2 step 2
    calls.clear()
    m, h = C.train(cfg, builtin["content"], builtin["style"], seed=1, out=out, progress=False, val=False,
                   resume=out, checkpoint_every=2)
    assert calls == [False, False]  # no autoencoder steps again; phase 2's steps 3 and 4
    assert h["step"] == [1, 2, 3, 4] and read_checkpoint(out, C.NAME)["extra"]["step"] == 4
    assert not any(p.requires_grad for p in m.style_encoder.parameters())


def test_paired_clips_leave_a_style_out():
    from mslib.data.corpora import load_builtin
    builtin = load_builtin(progress=False)
    ds = C.PairedClips(builtin["content"], builtin["style"], "val", exclude_styles=("depressed",))
    assert all(ds.style.rows[i]["style"] != "depressed" for i in ds.style_index)
    assert all(ds.content.rows[i]["style"] != "depressed" for i in ds.content_index)
    full = C.PairedClips(builtin["content"], builtin["style"], "val")
    assert len(ds.style_index) < len(full.style_index) and len(ds) < len(full) == len(full.content) + len(full.style)
    item = ds[0]
    assert item["target"].shape == (31, 263) and item["source"].shape == (31, 263)
    with pytest.raises(ValueError, match="exclude_styles"):
        C.PairedClips(builtin["content"], builtin["style"], "val",
                      exclude_styles=("neutral", "angry", "childlike", "depressed", "old", "proud", "sexy", "strutting"))


def test_paired_clips_views_are_other_windows_of_the_same_recording():
    """views=True: a style clip's view is another window of its take; a content clip's, another crop of it."""
    from mslib.data.corpora import load_builtin, take_of
    builtin = load_builtin(progress=False)
    ds = C.PairedClips(builtin["content"], builtin["style"], "val", views=True)
    n = len(ds.content_index)
    key = lambda a: a.numpy().tobytes()  # noqa: E731
    windows = {key(torch.from_numpy(((ds._clip(j) - ds.mean) / ds.std).astype(np.float32))): j for j in range(n, len(ds))}
    take = lambda j: take_of(ds.style.rows[ds.style_index[j - n]]["clip_id"])  # noqa: E731
    np.random.seed(1)
    seen = 0
    for i in range(80):
        item = ds[i]
        j = windows.get(key(item["source"]))
        if j is None:  # a content clip: the view is a window of the same clip
            clip = ((ds._clip(next(k for k in range(n) if _holds(ds, k, item["source"]))) - ds.mean) / ds.std)
            assert _holds_array(clip.astype(np.float32), item["source_view"])
            continue
        v = windows[key(item["source_view"])]
        assert take(v) == take(j) and (v != j or not ds.same_take[j])
        seen += v != j
    assert seen > 0
    assert "source_view" not in C.PairedClips(builtin["content"], builtin["style"], "val")[0]


def _holds_array(clip: np.ndarray, window: torch.Tensor) -> bool:
    """Whether `window` (T, D) is a run of consecutive rows of `clip` (edge padding included)."""
    w = window.numpy()
    if len(clip) < len(w):
        clip = np.concatenate([clip, np.repeat(clip[-1:], len(w) - len(clip), 0)]).astype(np.float32)
    return any(np.array_equal(clip[s:s + len(w)], w) for s in range(len(clip) - len(w) + 1))


def _holds(ds, k: int, window: torch.Tensor) -> bool:
    return _holds_array(((ds._clip(k) - ds.mean) / ds.std).astype(np.float32), window)


def test_paired_clips_draw_from_the_union_of_the_corpora():
    """M^T and M^S both from content ∪ style (C's one set X)."""
    from mslib.data.corpora import load_builtin
    builtin = load_builtin(progress=False)
    union = C.PairedClips(builtin["content"], builtin["style"], "val")
    n_content, n_style = len(union.content_index), len(union.style_index)
    assert len(union) == n_content + n_style

    def norm(ds, i):  # a style clip is exactly one window long, so its window is the whole clip
        return ((ds.style._arrays(ds.style_index[i])[0] - ds.mean) / ds.std).astype(np.float32).tobytes()
    style_windows = {norm(union, i) for i in range(n_style)}
    assert union[n_content + 3]["target"].numpy().tobytes() == norm(union, 3)       # target: clip i of the union
    np.random.seed(0)
    from_style = [union[i]["source"].numpy().tobytes() in style_windows for i in range(60)]
    assert 0 < sum(from_style) < 60                                                   # sources from both corpora


# ---------------------------------------------------------------- the packaged checkpoint and bench
needs_ckpt = pytest.mark.skipif(not course_path("contrastive").is_file(), reason="no course checkpoint")


@needs_ckpt
def test_course_checkpoint_loads_and_bench_transfer_gives_positions():
    from mslib.evaluation import bench
    m = C.load()
    assert m.cfg == C.ContrastiveConfig.preset("course") and m.config == m.cfg.to_dict()
    content, style = bench.load_pairs(seed=0, n_pairs=1)[0]
    out = bench.positions(bench.get_method("contrastive")(content, style))
    assert out.shape == (len(content["features"]), 22, 3) and np.isfinite(out).all()
    # the root trajectory is the content's: same root path as decoding the content
    from mslib.motion.features import decode
    np.testing.assert_allclose(out[:, 0, [0, 2]], decode(content["features"])[:, 0, [0, 2]], atol=1e-5)


def test_interpolation_ends_match_transfer():
    torch.manual_seed(0)
    m = C.ContrastiveModel(tiny()).eval()
    rng = np.random.default_rng(0)
    content, sa, sb = rng.normal(size=(40, 263)), rng.normal(size=(31, 263)), rng.normal(size=(31, 263))
    strip = C.interpolate_styles(m, content, sa, sb, (0.0, 0.5, 1.0))
    assert len(strip) == 3 and strip[0].shape == (40, 22, 3)
    from mslib.motion.features import decode
    np.testing.assert_allclose(strip[0], decode(m.transfer_features(content, sa)), atol=1e-4)
    np.testing.assert_allclose(strip[-1], decode(m.transfer_features(content, sb)), atol=1e-4)


def _findings_tool():
    """tools/contrastive_findings.py, imported by path (tools/ is not a package)."""
    import importlib.util
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "tools" / "contrastive_findings.py"
    spec = importlib.util.spec_from_file_location("contrastive_findings", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_statistics_mix_and_posture_shift_known_answers():
    tool = _findings_tool()
    rng = np.random.default_rng(0)
    c, s = rng.normal(size=(40, 263)), rng.normal(2.0, 3.0, size=(50, 263))
    assert np.allclose(tool.stats_mix(c, s, 0.0, 0.0), c)  # nothing moved: the identity
    full = tool.stats_mix(c, s, 1.0, 0.0)  # the posture swapped, the movement kept
    assert np.allclose(full[:, :3], c[:, :3])  # the root trajectory stays the content's
    assert np.allclose(full[:, 3:].mean(0), s[:, 3:].mean(0))
    assert np.allclose((full - full.mean(0))[:, 3:], (c - c.mean(0))[:, 3:])
    amp = tool.stats_mix(c, s, 0.0, 1.0)  # A Eq. 2's σ part: each dim's spread becomes the style clip's
    assert np.allclose(amp[:, 3:].std(0), (s.std(0) + 1e-3)[3:] / (c.std(0) + 1e-3)[3:] * c.std(0)[3:])
    assert np.allclose(amp.mean(0), c.mean(0))
    for w in (0.0, 0.25, 1.0):
        moved = c + w * (s.mean(0) - c.mean(0))
        assert math.isclose(tool.posture_moved(moved, c, s), w, abs_tol=1e-9)
    assert math.isclose(tool.posture_moved(tool.stats_mix(c, s, 0.5, 0.5), c, s), 0.5, abs_tol=1e-9)


def test_config_presets_and_stored_configs(tmp_path):
    from mslib.checkpoints import save_checkpoint
    from mslib.models.common.config import RETIRED_AT
    paper = C.ContrastiveConfig()
    assert paper == C.ContrastiveConfig.preset("paper")  # the defaults are C's (§4.1)
    assert (paper.hidden, paper.style_dim, paper.batch_size, paper.lr, paper.steps) == (144, 144, 16, 1e-4, 200_000)
    assert (paper.alpha, paper.beta, paper.gamma, paper.margin) == (1.0, 0.3, 0.3, 1.0)  # C Eq. 4–5
    assert not paper.content_skip and paper.pretrain_steps == 0 and paper.style_views == 0.0  # no course departure
    assert paper.transfer_window == 0  # C transfers the whole clip at once
    course = C.ContrastiveConfig.preset("course")
    assert course.content_skip and course.pretrain_steps == 2500 and course.style_views == 0.3 and course.hidden == 64
    assert C.ContrastiveConfig.preset("course", hidden=8).hidden == 8
    assert C.ContrastiveConfig.from_dict(course.to_dict()) == course
    assert C.ContrastiveModel(course.to_dict()).cfg == course  # a stored config builds the same model
    with pytest.raises(ValueError, match="widht"):
        C.ContrastiveConfig.preset("course", widht=3)
    with pytest.raises(ValueError, match="preset"):
        C.ContrastiveConfig.preset("huge")
    # the packaged checkpoint was trained after the research options left: its config is the course preset's
    stored = read_checkpoint(course_path(C.NAME), C.NAME)["config"]
    assert not set(C.ContrastiveConfig.RETIRED) & set(stored)
    assert C.ContrastiveConfig.from_dict(stored) == course
    older = {k: v for k, v in course.to_dict().items() if k != "transfer_window"}  # stored before the option came
    assert C.ContrastiveConfig.from_dict(older).transfer_window == 0  # … transfers as it did: the whole clip
    # a retired research option loads when it holds the value the library always uses, else is refused, naming it
    cfg = tiny()
    for option, other in (("pairs", "across"), ("skip_adain", True), ("skip_gain", True), ("disc_real", "both"),
                          ("style_negatives", "batch"), ("content_norm", False)):
        kept = C.ContrastiveConfig.RETIRED[option]
        assert C.ContrastiveConfig.from_dict({**cfg.to_dict(), option: kept}) == cfg
        with pytest.raises(ValueError, match=option):
            C.ContrastiveConfig.from_dict({**cfg.to_dict(), option: other})
    old = {**cfg.to_dict(), "pairs": "across"}  # a research checkpoint: load() names the commit that still has it
    save_checkpoint(tmp_path / "across.pt", C.ContrastiveModel(cfg), old, C.NAME)
    with pytest.raises(ValueError, match=f"'pairs'.*{RETIRED_AT}"):
        C.load(tmp_path / "across.pt")


def test_seed_table_and_ceiling_refuse_other_recipes_repeated_seeds_and_missing_files(tmp_path, monkeypatch):
    """`contrastive_findings.py seeds` (and `ceiling`) check every checkpoint before they score any."""
    from dataclasses import asdict

    from mslib.checkpoints import save_checkpoint, trained_seed
    tool = _findings_tool()
    packaged_seed = trained_seed(course_path(C.NAME), C.NAME)
    scored = []
    monkeypatch.setattr(tool, "score", lambda *a, **k: scored.append(a) or {})
    course = C.ContrastiveConfig.preset("course")
    other = C.ContrastiveConfig.preset("course", beta=0.0)
    for name, cfg, seed in (("other.pt", other, packaged_seed + 1), ("same.pt", course, packaged_seed)):
        save_checkpoint(tmp_path / name, C.ContrastiveModel(cfg), asdict(cfg), C.NAME,
                        extra={"train_config": {"seed": seed + 1}})  # phase 2 runs at seed + 1
    with pytest.raises(SystemExit, match="not trained with the course preset"):
        tool.main(["seeds", str(tmp_path / "other.pt")])
    with pytest.raises(SystemExit, match=f"seed {packaged_seed} twice"):  # the packaged checkpoint's seed again
        tool.main(["seeds", str(tmp_path / "same.pt")])
    with pytest.raises(SystemExit, match="no such file"):
        tool.main(["seeds", str(tmp_path / "missing.pt")])
    assert scored == []
    monkeypatch.setattr(tool, "ceiling", lambda *a, **k: scored.append(a) or {})
    with pytest.raises(SystemExit, match="expected `course` or LABEL=PATH"):  # a bare path: saved under which name?
        tool.main(["ceiling", str(tmp_path / "same.pt")])
    with pytest.raises(SystemExit, match="no such file"):
        tool.main(["ceiling", f"plain={tmp_path / 'missing.pt'}"])
    assert scored == []


def test_seed_rule_picks_the_highest_h_at_the_course_strength():
    tool = _findings_tool()
    rows = [{"seed": 2, "strength": 1.0, "h": 0.60}, {"seed": 0, "strength": 1.0, "h": 0.65},
            {"seed": 1, "strength": 1.0, "h": 0.62}, {"seed": 1, "strength": 1.2, "h": 0.70}]
    assert tool.best_seed(rows, 1.0) == 0 and tool.best_seed(rows, 1.2) == 1
    with pytest.raises(ValueError, match="no row at the course style strength 0.8"):
        tool.best_seed(rows, 0.8)


def test_recipe_variants_keep_the_schedule_they_were_compared_at():
    """The recipe rows reproduce whatever the course preset: every variant but `course` pins the schedule it was
    compared at, and every one compared before the preset took up `style_views` pins δ = 0 (the `plain` recipe)."""
    from dataclasses import replace

    tool = _findings_tool()
    course = C.ContrastiveConfig.preset("course")
    cfg = {k: C.ContrastiveConfig.preset("course", **v) for k, v in tool.VARIANTS.items()}
    two_phases = (tool.SHORT["pretrain_steps"], tool.SHORT["steps"])
    assert (cfg["union_short"].pretrain_steps, cfg["union_short"].steps) == two_phases
    assert (cfg["union_mid"].pretrain_steps, cfg["union_mid"].steps) == (tool.SHORT["pretrain_steps"], 2 * tool.SHORT["steps"])
    assert cfg["course"] == course == cfg["course_views"] and course.style_views == 0.3
    plain = cfg["plain"]
    assert replace(plain, style_views=course.style_views) == course and plain.style_views == 0.0
    assert {k for k, c in cfg.items() if c.style_views > 0} == {"course", "course_views"}
    for name in ("union_short", "union_mid"):  # the plain recipe but for a shorter second phase
        assert replace(cfg[name], steps=plain.steps) == plain and plain.steps > cfg[name].steps
    assert replace(cfg["course_long"], steps=plain.steps) == plain and cfg["course_long"].steps == 2 * plain.steps


def test_recipe_table_rows_name_their_commit_and_removed_variants_keep_theirs():
    """Every stored row and section names the command and commit that made it; the rows of variants whose options
    left the library stay, though `train` no longer offers them (they reproduce at the commit the docstring names)."""
    tool = _findings_tool()
    stored = json.loads(tool.RECIPES_JSON.read_text())
    sections = [v for v in stored.values() if isinstance(v, dict)]
    assert all(r["commit"] and r["command"] for r in stored["rows"] + sections)
    removed = {"literal", "joint", "autoencoder", "across", "d_real_both", "skip_adain", "course_gain", "course_negatives"}
    assert removed <= {r["variant"] for r in stored["rows"]} and not removed & set(tool.VARIANTS)
    assert "git checkout 3748be4" in tool.__doc__
    findings = json.loads((tool.DATA_DIR / "03_contrastive_findings.json").read_text())
    assert findings["commit"] and findings["command"]


def test_checkpoint_arguments_are_checked_before_any_loads(tmp_path, monkeypatch):
    tool = _findings_tool()
    loaded = []
    monkeypatch.setattr(tool.C, "load", lambda path=None: loaded.append(path) or path)
    (tmp_path / "run_s0.pt").write_bytes(b"")
    got = tool.labelled_models(["course", str(tmp_path / "run_s0.pt"), f"mine={tmp_path / 'run_s0.pt'}"])
    assert got == [("course", None), ("run_s0", str(tmp_path / "run_s0.pt")), ("mine", str(tmp_path / "run_s0.pt"))]
    loaded.clear()
    with pytest.raises(SystemExit, match="nope.pt: no such file"):
        tool.labelled_models([str(tmp_path / "run_s0.pt"), f"x={tmp_path / 'nope.pt'}"])
    assert loaded == []  # nothing loaded before every path was checked


def test_recipe_rows_merge_by_label_and_keep_their_commands():
    tool = _findings_tool()
    saved = {"rows": [{"variant": "a", "h": 1, "command": "old", "commit": "c0"},
                      {"variant": "course", "h": 2, "command": "old", "commit": "c0"}]}
    rows = tool.merge_rows(saved, [{"variant": "course", "h": 3}, {"variant": "b", "h": 4}], "new", "c1")
    assert [(r["variant"], r["h"], r["command"], r["commit"]) for r in rows] == [
        ("a", 1, "old", "c0"), ("b", 4, "new", "c1"), ("course", 3, "new", "c1")]
    assert tool.merge_rows({}, [{"variant": "a", "h": 1}], "new", "c1") == [
        {"variant": "a", "h": 1, "command": "new", "commit": "c1"}]


def test_recipe_json_sections_are_replaced_and_the_others_kept(tmp_path, monkeypatch):
    tool = _findings_tool()
    monkeypatch.setattr(tool, "RECIPES_JSON", tmp_path / "data" / "recipes.json")
    tool.save({"strength": {"rows": [1]}, "val_pairs": 200})
    tool.save({"rows": [{"variant": "a"}], "strength": {"rows": [2]}})
    assert json.loads(tool.RECIPES_JSON.read_text()) == {"strength": {"rows": [2]}, "val_pairs": 200,
                                                          "rows": [{"variant": "a"}]}
    assert [p.name for p in tool.RECIPES_JSON.parent.iterdir()] == ["recipes.json"]  # no temporary file left
    assert set(tool._made("python tools/contrastive_findings.py strength --save")) == {"command", "commit"}


def test_findings_tool_help_runs():
    tool = _findings_tool()
    with pytest.raises(SystemExit) as exit_info:
        tool.main(["--help"])
    assert exit_info.value.code == 0
