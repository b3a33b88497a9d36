"""The built-in motion generator: plausibility of every content × style, labels, determinism,
ranges, the mocap skeleton and its BVH round trip, the batched feature encoder."""
import itertools

import numpy as np
import pytest

from mslib.data import mocap_skeleton as M
from mslib.data.batch_features import encode_many
from mslib.data.styles import (CONTENTS, PARAMS, STYLE_CONTENTS, STYLES, SUBSTYLES, caption,
                               sample_style, style_mean)
from mslib.data.synth import (DURATION_RANGE, facing_yaw, generate_clip, generate_clips,
                              plausibility, resample)
from mslib.motion.features import encode
from mslib.motion.skeleton import JOINT_NAMES, PARENTS

FEET = [7, 10, 8, 11]
VERB = {"walk": "walks forward", "run": "runs", "jump": "jumps", "punch": "punches", "kick": "kicks",
        "wave": "waves", "turn_walk": "walks in a curve", "side_step": "side steps",
        "walk_backward": "walks backward", "stand": "stands"}


@pytest.fixture(scope="module")
def every_combination():
    """Every content × style, at two seeds (default draws: sub-style, duration, speed, body)."""
    specs = [dict(content=c, style=s, seed=seed, index=k)
             for k, (c, s) in enumerate(itertools.product(CONTENTS, STYLES)) for seed in (0, 3)]
    return specs, generate_clips(specs)


def check_plausible(positions, contacts, fps, label):
    """The four physical rules of the built-in data, exactly as the issue states them."""
    p = np.asarray(positions)
    c = np.asarray(contacts, bool)
    pl = plausibility(p, c, fps)
    assert pl["max_contact_slide"] <= 0.002, (label, pl)  # planted joints slide ≤ 2 mm / frame
    feet = p[:, FEET]
    lowest = feet[..., 1].min(1)
    assert abs(lowest.min()) <= 0.01, (label, lowest.min())  # the lowest foot point touches y = 0
    assert lowest.min() >= -0.01, label  # and never goes through the floor
    down = c.reshape(len(c), 2, 2).any(-1)  # a foot with a planted joint
    foot_low = feet.reshape(len(p), 2, 2, 3)[..., 1].min(-1)
    assert np.abs(foot_low[down]).max() <= 0.01, label  # a planted foot is on the floor
    assert pl["bone_length_spread"] <= 1e-5, (label, pl)  # rigid bones
    assert pl["max_joint_speed"] <= 12.0, (label, pl)  # human joint speeds
    # independent of the generator's flags: joints low in two frames do not slide
    low = (feet[1:, :, 1] < 0.01) & (feet[:-1, :, 1] < 0.01)
    step = np.linalg.norm(feet[1:, :, [0, 2]] - feet[:-1, :, [0, 2]], axis=-1)
    assert not low.any() or step[low].max() <= 0.002, (label, step[low].max())


def test_every_content_and_style_is_physically_plausible(every_combination):
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        check_plausible(clip.positions, clip.contacts, clip.fps, spec)
        assert clip.positions.shape == (clip.n_frames, 22, 3)
        assert np.isfinite(clip.positions).all()


def knee_flexion_degrees(p):
    """Signed knee angle (T, 2) of each leg: positive when the shank folds behind the thigh (flexion), negative
    when the knee bends backward; measured about the hips' left-right axis."""
    across = p[:, 1] - p[:, 2]
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    out = []
    for hip, knee, ankle in ((1, 4, 7), (2, 5, 8)):
        thigh, shank = p[:, knee] - p[:, hip], p[:, ankle] - p[:, knee]
        sin = (np.cross(thigh, shank) * across).sum(-1) / np.linalg.norm(thigh, axis=-1) / np.linalg.norm(shank, axis=-1)
        out.append(np.degrees(np.arcsin(np.clip(sin, -1.0, 1.0))))
    return np.stack(out, 1)


def test_knee_flexion_sign_on_a_hand_made_leg():
    p = np.zeros((2, 22, 3))
    p[:, 1], p[:, 2] = [0.1, 1.0, 0.0], [-0.1, 1.0, 0.0]  # left hip at +x: the body faces +z
    p[:, 4], p[:, 5] = [0.1, 0.55, 0.05], [-0.1, 0.55, 0.05]  # knees ahead of the hips
    p[0, 7], p[0, 8] = [0.1, 0.1, -0.1], [-0.1, 0.1, -0.1]  # frame 0: ankles behind (flexed)
    p[1, 7], p[1, 8] = [0.1, 0.1, 0.2], [-0.1, 0.1, 0.2]  # frame 1: ankles far ahead (bent backward)
    a = knee_flexion_degrees(p)
    assert (a[0] > 20).all() and (a[1] < -5).all()


def test_knees_never_bend_backward(every_combination):
    """The leg IK bends every knee toward the front of its thigh (footlock.KNEE_POLE_FORWARD); with the pole at the
    planned knee, a straight stance leg under a tilted pelvis bent backward by up to 68° (generator v8). A kicking
    leg, planned rather than solved, may straighten a few degrees past straight at full extension, as a real knee
    can (v9: an old person's kick, 7° in 2 % of its frames)."""
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        angle = knee_flexion_degrees(clip.positions)
        assert angle.min() >= -8.0, spec
        assert (angle < -2.0).mean() <= 0.03, spec


def test_planted_feet_exist_and_flight_only_where_expected(every_combination):
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        down = clip.contacts.reshape(-1, 2, 2).any(-1).any(-1)
        if spec["content"] in ("run", "jump"):
            assert 0.2 < down.mean() < 1.0, spec  # some flight, mostly grounded
        elif spec["content"] in ("punch", "wave", "stand"):
            assert down.all(), spec
        else:
            assert down.mean() > 0.6, spec


def test_captions_name_the_content_and_style_captions_the_style(every_combination):
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        assert VERB[spec["content"]] in clip.meta["caption"], (spec, clip.meta["caption"])
        assert clip.meta["caption"].startswith("a person ")
        style_cap = clip.meta["style_caption"]
        assert VERB[spec["content"]] in style_cap
        assert spec["style"] in style_cap, style_cap  # "an old person ...", "... in a neutral style"
        assert clip.meta["substyle"] in SUBSTYLES[spec["style"]]


def test_canonical_placement_duration_and_body(every_combination):
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        m = clip.meta
        assert DURATION_RANGE[0] <= m["duration"] <= DURATION_RANGE[1] + 1e-9
        assert clip.n_frames == int(round(m["duration"] * 20)) + 1 and m["fps"] == 20
        assert np.allclose(clip.positions[0, 0, [0, 2]], 0, atol=1e-9)  # root over the origin
        assert abs(facing_yaw(clip.positions)) < 1e-6  # facing +Z
        lengths = np.linalg.norm(clip.skeleton.offsets, axis=-1)[1:]
        ref = np.linalg.norm(generate_clip("stand", seed=0, index=0).skeleton.offsets, axis=-1)[1:]
        assert np.all(np.abs(lengths / ref - 1) < 0.2)  # a body within a few percent per bone


def test_speed_and_direction_ranges(every_combination):
    specs, clips = every_combination
    for spec, clip in zip(specs, clips):
        v, d = clip.meta["speed"], clip.meta["travel_direction"]
        c = spec["content"]
        if c in ("walk", "turn_walk"):
            assert 0.3 < v < 2.6, (spec, v)
        if c == "walk":
            assert abs(d) < 30, (spec, d)
        if c == "run":
            assert 0.8 < v < 4.5 and abs(d) < 30, (spec, v, d)
        if c == "side_step":
            assert 0.1 < v < 1.3 and 55 < abs(d) < 125, (spec, v, d)
            assert (d > 0) == ("left" in clip.meta["caption"]), spec  # +X is the left
        if c == "walk_backward":
            assert 0.1 < v < 1.5 and abs(d) > 150, (spec, v, d)
        if c in ("stand", "punch", "wave"):
            assert np.ptp(clip.positions[:, 0, [0, 2]], axis=0).max() < 0.25, spec


def test_turning_walk_curves_to_the_named_side():
    for i in range(4):
        clip = generate_clip("turn_walk", seed=1, index=i)
        step = np.diff(clip.positions[::5, 0, [0, 2]], axis=0)
        heading = np.unwrap(np.arctan2(step[:, 0], step[:, 1]))  # from +Z toward +X (the left)
        turn = np.degrees(heading[-1] - heading[0])
        assert abs(turn) > 20, turn
        assert (turn > 0) == ("left" in clip.meta["caption"]), (turn, clip.meta["caption"])


def test_determinism_and_batch_independence():
    a = generate_clip("walk", "old", seed=4, index=9)
    b = generate_clip("walk", "old", seed=4, index=9)
    assert np.array_equal(a.positions, b.positions) and a.meta["caption"] == b.meta["caption"]
    c = generate_clip("walk", "old", seed=5, index=9)
    assert c.positions.shape != a.positions.shape or not np.allclose(c.positions, a.positions)
    d = generate_clip("walk", "old", seed=4, index=10)
    assert d.positions.shape != a.positions.shape or not np.allclose(d.positions, a.positions)
    batch = generate_clips([dict(content="run", seed=4, index=3), dict(content="walk", style="old", seed=4,
                                                                      index=9)])
    assert np.allclose(batch[1].positions, a.positions, atol=1e-12)


def test_a_clip_past_the_limits_is_made_again_with_a_weaker_layer(monkeypatch):
    """A layer that swings every angle six times as wide drives a punch past the speed limit; the clip comes
    back within the limits, made with the layer weakened, and the same spec gives the same clip again."""
    from mslib.data import joint_moments as jm
    from mslib.data import synth
    wild = np.zeros(jm.N_PARAMS)
    wild[jm.N_OFFSET:jm.N_OFFSET + jm.N_GAIN] = np.log(6.0)  # every gain × 6: the fist at about 17 m/s
    monkeypatch.setattr(jm, "cell_moments", lambda style, content, intensity=1.0, table=None: wild)
    strengths = []
    prepare = synth._prepare
    monkeypatch.setattr(synth, "_prepare", lambda spec, layer_strength=1.0: (strengths.append(layer_strength),
                                                                            prepare(spec, layer_strength))[1])
    spec = dict(content="punch", style="angry", seed=3, index=25)
    clip = generate_clips([spec])[0]
    assert synth.within_limits(clip) and strengths[0] == 1.0 and strengths[-1] < 1.0, strengths
    assert np.array_equal(generate_clips([spec])[0].positions, clip.positions)
    monkeypatch.undo()
    plain = generate_clips([spec])[0]  # the fitted layer: within the limits as made
    assert synth.within_limits(plain) and not np.array_equal(plain.positions, clip.positions)


def test_styles_and_substyles_are_distinct_distributions():
    assert len(STYLES) == 8 and set(STYLE_CONTENTS) <= set(CONTENTS) and len(CONTENTS) >= 8
    for s in STYLES:
        assert 2 <= len(SUBSTYLES[s]) <= 4
        means = [style_mean(s, ss) for ss in SUBSTYLES[s]]
        for m1, m2 in itertools.combinations(means, 2):
            assert any(abs(m1[k] - m2[k]) > 2 * max(PARAMS[k][1], 1e-3) for k in PARAMS), s
    rng = np.random.default_rng(0)
    sub = SUBSTYLES["old"][0]
    draws = [sample_style(rng, "old", sub)["lean"] for _ in range(50)]
    assert np.std(draws) > 0 and abs(np.mean(draws) - style_mean("old", sub)["lean"]) < 1.5
    assert caption({"content": "walk"}, "old", 0.7) == "an old person walks forward slowly"
    assert caption({"content": "punch", "side": "right"}) == "a person punches with the right hand"


@pytest.mark.parametrize("kwargs, name", [
    (dict(content="fly"), "content"), (dict(content="walk", style="sad"), "style"),
    (dict(content="walk", style="old", substyle="sneaky"), "substyle"),
    (dict(content="walk", fps=0), "fps"), (dict(content="walk", duration=0.1), "duration"),
    (dict(content="walk", seed=-1), "seed"),
])
def test_bad_arguments_name_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        generate_clip(**kwargs)


def test_mocap_skeleton_is_distinct_and_in_centimetres():
    clip = generate_clip("walk", "proud", seed=2, index=1, fps=30, canonical=False)
    sk = M.mocap_skeleton(clip.skeleton)
    assert sk.n_joints >= 25
    assert not set(sk.names) & set(JOINT_NAMES)
    assert len(M.TEMPLATE_JOINTS) == 22 and len(M.TEMPLATE_TO_MOCAP) == 22
    rest = sk.rest_positions()
    legs = rest[sk.index("LeftUpLeg"), 1] - rest[sk.index("LeftFoot"), 1]
    assert 70 < legs < 100  # centimetres
    arm = rest[sk.index("LeftHand")] - rest[sk.index("LeftArm")]
    assert arm[0] > 0.95 * np.linalg.norm(arm)  # T-pose: the arm points along +X at rest
    template_rest = clip.skeleton.rest_positions()
    assert template_rest[20, 1] < template_rest[16, 1] - 0.4  # the template's arms hang down


def test_template_motion_is_recovered_from_the_mocap_bvh(tmp_path):
    from mslib.data.retarget import resample as resample_bvh
    from mslib.motion.bvh import read_bvh, write_bvh
    clip = generate_clip("run", "angry", seed=1, index=2, fps=30, canonical=False)
    path = write_bvh(tmp_path / "take.bvh", M.to_bvh_motion(clip.rotations, clip.root, clip.skeleton))
    motion = read_bvh(path)
    assert motion.fps == pytest.approx(30) and motion.n_joints == 32
    back = M.template_positions(motion.global_positions())  # pick the joints, cm → m
    assert np.abs(back - clip.positions).max() < 1e-4
    # write → read → pick → /100 → resample to 20 fps: the generator's 20 fps truth within 1 cm
    at20 = M.template_positions(resample_bvh(motion, 20).global_positions())
    same = resample(clip, 20, relock=False)  # the generator's motion, resampled the same way
    assert at20.shape == same.positions.shape
    assert np.linalg.norm(at20 - same.positions, axis=-1).max() < 0.01
    stored = resample(clip, 20)  # the style corpus's truth: feet locked again at 20 fps
    assert np.linalg.norm(at20 - stored.positions, axis=-1).mean() < 0.01  # MPJPE
    check_plausible(stored.positions, stored.contacts, 20, "resampled take")


def test_batched_encoder_matches_features_encode():
    clips = generate_clips([dict(content=c, seed=2, index=i) for i, c in enumerate(CONTENTS)])
    positions = [c.positions for c in clips] + [clips[0].positions[:32], clips[1].positions[5:37]]
    for a, b in zip(encode_many(positions), positions):
        ref = encode(b)
        assert a.shape == ref.shape and a.dtype == np.float32
        assert np.abs(a - ref).max() < 1e-5


def test_parents_of_the_generator_are_the_template():
    clip = generate_clip("wave", seed=0, index=0)
    assert clip.skeleton.parents == PARENTS and clip.skeleton.names == JOINT_NAMES


def test_every_style_jumps_alike_in_time_and_height_and_the_pelvis_tips_in_the_crouch():
    """Real jumps of every style last and rise about alike (actions.py): only the posture differs."""
    from mslib.data import actions
    cp = {"content": "jump", "height": 0.3, "distance": 0.0}
    plans = {s: actions.jump(100, 20, np.random.default_rng(3), sample_style(np.random.default_rng(4), s, content="jump"),
                             cp, 0.9) for s in ("neutral", "old", "angry")}
    grounded = {s: p.contacts.any(1) for s, p in plans.items()}
    assert plans["old"].info["height"] == plans["angry"].info["height"] == 0.3
    assert (grounded["old"] == grounded["angry"]).all() and not grounded["neutral"].all()  # same flights
    tilt = plans["neutral"].angles.a[:, 0, 0]  # pelvis pitch (+ forward)
    assert tilt.max() - tilt.min() >= 0.9 * actions.PELVIS_TILT
