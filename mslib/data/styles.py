"""Style and content tables of the built-in stylized mocap.

A *style* is a distribution over a flat set of motion parameters (PARAMS): posture angles in degrees,
amplitude and tempo multipliers, and dynamics. Every style has a mean per parameter and three named
*sub-styles* that override some of those means — the intra-style diversity that paper D's
prototypes model. A take draws its parameters from a Gaussian around the (sub-)style mean with the
per-parameter spread of PARAMS.

Where the means come from. STYLE_TABLE below is written by hand: what each style does, in the
generator's terms. The means of the parameters that real walking shows most (posture, arm
carriage and swing, stride, knee lift, cadence, bounce, sway) are then *fitted to real motion
capture* — the Xia train split — by `tools/fit_styles.py`, which stores them in
`fitted_styles.json` beside this file with the command that made them and the digest of what it
read. The fitted values replace the hand-written ones; the sub-styles are the fitted ones too (the
real takes of a style split into thirds along the axis on which they differ most, each third named
after its most distinctive cue). Runs, jumps, punches and kicks are then fitted on their own where the
real takes have them (a real depressed person walks slowly but punches nearly as fast as a neutral
one): such a content fit shifts the style's means for that content only. Without that file the
hand-written table is used as it is.

A *content* is what the body does (walk, run, punch, ...): its kind picks the generator (gait or
action), and its own random draws (speed, curvature, hand, ...) happen in `sample_content`.
Captions are filled from templates: the content corpus names the content ("a person walks forward
slowly"), the style corpus also names the style ("an old person walks forward").
"""
from __future__ import annotations

import numpy as np

from .fitted import FITTED_FILE, load_fitted

# name → (neutral value, per-take spread, lower bound, upper bound, meaning)
PARAMS = {
    # posture (degrees)
    "lean": (2.0, 1.5, -15, 40, "trunk pitch forward"),
    "chest": (0.0, 1.5, -20, 25, "upper-spine extension: chest out (+) or rounded back (−)"),
    "head": (0.0, 2.5, -30, 45, "head pitch down (+) relative to level gaze"),
    "head_tilt": (0.0, 1.5, -20, 20, "head roll to the side"),
    "shoulder_raise": (0.0, 1.5, -12, 15, "shoulder elevation (+) or droop (−)"),
    "shoulder_back": (0.0, 2.0, -20, 25, "shoulder retraction (+) or rounding (−)"),
    "arm_out": (8.0, 2.0, 0, 45, "arm abduction away from the body"),
    "elbow": (15.0, 3.0, 0, 100, "baseline elbow flexion"),
    "knee": (3.0, 1.0, 0, 25, "baseline knee flexion (crouch)"),
    "toe_out": (8.0, 2.5, -10, 30, "feet turned out"),
    "width": (1.0, 0.06, 0.6, 1.8, "stance width multiplier"),
    "cross": (0.0, 0.8, -5, 15, "hip adduction in gait: steps toward the midline (crossing)"),
    "akimbo": (0.0, 0.0, 0, 1, "hands on hips (1) instead of free arms"),
    "cane": (0.0, 0.0, 0, 1, "right hand held forward as if on a cane, with a limp"),
    # amplitudes (multipliers of the neutral motion)
    "arm_swing": (1.0, 0.1, 0.0, 3.0, "arm swing amplitude"),
    "stride": (1.0, 0.05, 0.3, 1.6, "step length"),
    "knee_lift": (1.0, 0.07, 0.25, 2.6, "swing knee and thigh lift"),
    "hip_sway": (1.0, 0.1, 0.2, 4.0, "pelvis obliquity and lateral shift"),
    "twist": (1.0, 0.1, 0.2, 3.0, "pelvis and thorax rotation"),
    "sway": (0.0, 0.4, 0.0, 10.0, "trunk side-to-side roll (degrees)"),
    "head_bob": (0.0, 0.4, 0.0, 10.0, "head nod with every step (degrees)"),
    # tempo
    "cadence": (1.0, 0.04, 0.5, 1.6, "step frequency multiplier"),
    "action_speed": (1.0, 0.06, 0.4, 1.8, "tempo of punches, kicks and waves (not jumps: actions.py)"),
    "action_amp": (1.0, 0.06, 0.4, 1.6, "range of punches, kicks and waves (not jumps: actions.py)"),
    # dynamics
    "bounce": (0.0, 0.08, 0.0, 2.5, "springy knee flexion in stance"),
    "tremor": (0.0, 0.05, 0.0, 4.0, "tremor of head, arms and trunk (degrees)"),
    "jerk": (0.0, 0.04, 0.0, 1.0, "abruptness of arm swing and actions"),
    "duty": (0.0, 0.008, -0.25, 0.1, "change of the stance fraction of the gait cycle"),
    "limp": (0.0, 0.0, 0.0, 0.3, "left/right asymmetry of the gait"),
}
HAND_NEUTRAL = {k: v[0] for k, v in PARAMS.items()}

# style → (mean overrides, {sub-style: overrides on top of the style}, caption adjective, article)
STYLE_TABLE = {
    "neutral": (
        {},
        {"relaxed": {"arm_out": 5.0, "elbow": 10.0, "shoulder_raise": -3.0},
         "brisk": {"lean": 7.0, "elbow": 35.0, "shoulder_back": 3.0, "cadence": 1.1, "stride": 1.08,
                   "arm_swing": 1.3},
         "casual": {"toe_out": 18.0, "width": 1.2, "head_tilt": 6.0, "arm_out": 14.0, "lean": -1.0,
                    "twist": 1.3}},
        "", "a"),
    "angry": (
        {"lean": 9, "head": 8, "shoulder_raise": 6, "shoulder_back": -4, "arm_out": 15, "elbow": 45,
         "arm_swing": 1.5, "stride": 1.12, "cadence": 1.18, "knee_lift": 1.1, "twist": 1.35,
         "jerk": 0.65, "width": 1.15, "action_speed": 1.35, "action_amp": 1.25},
        {"stomping": {"knee": 12, "width": 1.4, "knee_lift": 1.5, "bounce": 0.6, "lean": 6, "cadence": 1.1},
         "fist-shaking": {"elbow": 90, "shoulder_raise": 12, "tremor": 2.5, "head": 14, "arm_out": 22,
                          "arm_swing": 0.8},
         "charging": {"lean": 22, "head": 16, "arm_out": 10, "elbow": 35, "cadence": 1.3, "stride": 1.22,
                      "arm_swing": 1.8}},
        "angry", "an"),
    "childlike": (
        {"lean": -2, "head": -6, "arm_out": 18, "elbow": 22, "arm_swing": 1.7, "stride": 0.85,
         "cadence": 1.3, "knee_lift": 1.35, "bounce": 0.8, "twist": 1.2, "sway": 3.0, "jerk": 0.3,
         "toe_out": 2.0, "head_bob": 4.0, "action_speed": 1.2, "action_amp": 1.15},
        {"skipping": {"duty": -0.17, "knee_lift": 1.6, "bounce": 1.2, "elbow": 42, "head": -13, "arm_out": 11},
         "bouncy": {"bounce": 1.9, "head_bob": 9.0, "knee": 8, "lean": 3, "arm_out": 17},
         "flailing": {"arm_swing": 2.4, "arm_out": 36, "elbow": 6, "head_tilt": 6}},
        "childlike", "a"),
    "depressed": (
        {"lean": 14, "head": 60, "chest": -8, "shoulder_raise": -6, "shoulder_back": -10, "arm_out": 2,
         "elbow": 8, "arm_swing": 0.25, "stride": 0.62, "cadence": 0.72, "knee_lift": 0.7,
         "twist": 0.5, "hip_sway": 0.6, "width": 0.9, "action_speed": 0.6, "action_amp": 0.55},
        {"slumped": {"lean": 22, "head": 70},
         "dragging": {"knee_lift": 0.45, "stride": 0.5, "cadence": 0.65, "knee": 9},
         "listless": {"arm_swing": 0.05, "sway": 2.5, "hip_sway": 1.2, "head_tilt": 10}},
        "depressed", "a"),
    "old": (
        {"lean": 20, "head": -6, "chest": -6, "shoulder_back": -6, "knee": 13, "arm_out": 12,
         "elbow": 25, "arm_swing": 0.4, "stride": 0.55, "cadence": 0.82, "knee_lift": 0.65,
         "width": 1.35, "toe_out": 16, "tremor": 1.5, "twist": 0.5, "hip_sway": 1.3,
         "action_speed": 0.55, "action_amp": 0.55},
        {"stooped": {"lean": 32, "head": -14, "knee": 16},
         "shuffling": {"knee_lift": 0.35, "stride": 0.42, "cadence": 0.95, "lean": 13, "knee": 8,
                       "width": 1.55},
         "cane-like": {"cane": 1.0, "limp": 0.12, "lean": 22, "head_tilt": -7, "shoulder_raise": -4}},
        "old", "an"),
    "proud": (
        {"lean": -4, "chest": 9, "head": -12, "shoulder_back": 12, "shoulder_raise": 2,
         "arm_out": 10, "elbow": 12, "arm_swing": 1.1, "stride": 1.1, "cadence": 0.92,
         "knee_lift": 1.05, "twist": 0.8, "width": 1.0, "toe_out": 6},
        {"chest-out": {"chest": 18, "shoulder_back": 20, "head": -8},
         "chin-up": {"head": -26, "chest": 6, "lean": -8},
         "hands-on-hips": {"akimbo": 1.0, "arm_swing": 0.0}},
        "proud", "a"),
    "sexy": (
        {"lean": -2, "chest": 4, "head": -3, "head_tilt": 6, "shoulder_back": 4, "arm_out": 6,
         "elbow": 20, "arm_swing": 0.9, "hip_sway": 2.8, "cross": 7, "twist": 1.5, "sway": 3.0,
         "cadence": 0.9, "toe_out": 2.0, "stride": 0.95},
        {"catwalk": {"cross": 12, "hip_sway": 3.2, "toe_out": -4.0, "arm_out": 4, "chest": 9},
         "swaying": {"sway": 8.0, "hip_sway": 3.6, "cadence": 0.82, "arm_out": 12},
         "flirty": {"head_tilt": 14, "twist": 2.0, "shoulder_raise": 6, "elbow": 42, "lean": 2}},
        "sexy", "a"),
    "strutting": (
        {"lean": -3, "chest": 8, "head": -6, "shoulder_back": 8, "arm_out": 10, "elbow": 10,
         "arm_swing": 1.5, "stride": 1.2, "cadence": 0.95, "knee_lift": 1.7, "sway": 4.0,
         "head_bob": 4.0, "twist": 1.6, "hip_sway": 1.4, "bounce": 0.4, "width": 1.3, "toe_out": 17},
        {"high-knee": {"knee_lift": 2.2, "chest": 13},
         "swagger": {"twist": 2.3, "sway": 7.0, "arm_swing": 1.2, "arm_out": 20, "head_tilt": 7,
                     "shoulder_back": 2, "lean": -1},
         "marching": {"arm_swing": 2.0, "elbow": 3, "knee_lift": 2.0, "sway": 1.0, "lean": -8,
                      "chest": 14, "arm_out": 4}},
        "strutting", "a"),
}
STYLES = tuple(STYLE_TABLE)


def _fitted_styles() -> dict:
    """{style: {"params": {...}, "substyles": {name: {"params": {...}}}}} of the fitted table, or {}."""
    table = load_fitted("styles")
    unknown = sorted(set(table) - set(STYLES)) + sorted(
        {k for e in table.values() for p in [e["params"], *(v["params"] for v in e["substyles"].values())]
         for k in p} - set(PARAMS))
    if unknown:
        raise ValueError(f"{FITTED_FILE}: unknown styles or parameters {unknown}; refit with tools/fit_styles.py")
    return table


FITTED = _fitted_styles()
SUBSTYLES = {s: tuple(FITTED[s]["substyles"]) if s in FITTED else tuple(STYLE_TABLE[s][1]) for s in STYLES}

# content → (kind, caption template); {adv}, {side}, {dir} are filled by sample_content
CONTENT_TABLE = {
    "walk": ("gait", "walks forward{adv}"),
    "run": ("gait", "runs forward{adv}"),
    "jump": ("jump", "{jump_text}"),
    "punch": ("punch", "punches with the {side} hand"),
    "kick": ("kick", "kicks with the {side} leg"),
    "wave": ("wave", "waves with the {side} hand"),
    "turn_walk": ("gait", "walks in a curve to the {dir}"),
    "side_step": ("gait", "side steps to the {dir}"),
    "walk_backward": ("gait", "walks backward{adv}"),
    "stand": ("stand", "stands still and looks around"),
}
CONTENTS = tuple(CONTENT_TABLE)
STYLE_CONTENTS = ("walk", "run", "jump", "punch", "kick")  # the Xia set


def _check(name, value, allowed):
    if value not in allowed:
        raise ValueError(f"{name}: must be one of {list(allowed)}, got {value!r}")


def hand_mean(style: str, substyle: str | None = None) -> dict:
    """The hand-written parameter means of a style (and one of its hand-written sub-styles)."""
    _check("style", style, STYLES)
    base, subs, _, _ = STYLE_TABLE[style]
    out = dict(HAND_NEUTRAL)
    out.update(base)
    if substyle is not None:
        _check("substyle", substyle, subs)
        out.update(subs[substyle])
    return {k: float(v) for k, v in out.items()}


def style_mean(style: str, substyle: str | None = None, content: str | None = None) -> dict:
    """The parameter means of a style (and sub-style, and content): fitted where fitted, else hand-written.

    A content the fit saw on its own (an action or a run, section "contents" of the fitted style) moves
    the parameters it fitted by how far that content's fit lies from the style's walking fit, so a
    sub-style keeps its difference from its style in every content (until `sample_style` clips a
    parameter at its bound, where that difference is lost)."""
    _check("style", style, STYLES)
    if content is not None:
        _check("content", content, CONTENTS)
    if style not in FITTED:
        return hand_mean(style, substyle)
    out = hand_mean(style)
    out.update(FITTED[style]["params"])
    if substyle is not None:
        _check("substyle", substyle, SUBSTYLES[style])
        out.update(FITTED[style]["substyles"][substyle]["params"])
    own = FITTED[style].get("contents", {}).get(content)
    if own:
        for k, v in own["params"].items():
            out[k] += v - FITTED[style]["params"][k]
    return {k: float(v) for k, v in out.items()}


NEUTRAL = style_mean("neutral")


def sample_style(rng: np.random.Generator, style: str, substyle: str | None = None,
                 intensity: float = 1.0, spread: float = 1.0, content: str | None = None) -> dict:
    """Draw one take's parameters: neutral + intensity·(style mean − neutral) + Gaussian spread
    (both means those of `content` when given)."""
    if not 0.0 <= intensity <= 1.5:
        raise ValueError(f"intensity: must be in [0, 1.5], got {intensity}")
    mean = style_mean(style, substyle, content)
    neutral = NEUTRAL if content is None else style_mean("neutral", None, content)
    noise = rng.standard_normal(len(PARAMS))
    out = {}
    for (k, (_, sd, lo, hi, _)), z in zip(PARAMS.items(), noise.tolist()):
        v = neutral[k] + intensity * (mean[k] - neutral[k]) + spread * sd * z
        out[k] = min(max(v, lo), hi)
    return out


def sample_content(rng: np.random.Generator, content: str) -> dict:
    """Draw a content's own parameters (speed, curvature, side, jump shape, ...)."""
    _check("content", content, CONTENTS)
    side = "right" if rng.random() < 0.7 else "left"
    direction = "left" if rng.random() < 0.5 else "right"
    c = {"content": content, "side": side, "dir": direction}
    if content in ("walk", "turn_walk"):
        c.update(speed=rng.uniform(0.85, 1.55), direction=0.0)
        c["curvature"] = (rng.uniform(0.25, 0.6) * (1 if direction == "left" else -1)
                          if content == "turn_walk" else rng.uniform(-0.04, 0.04))
    elif content == "run":
        c.update(speed=rng.uniform(1.9, 3.0), direction=0.0, curvature=rng.uniform(-0.03, 0.03))
    elif content == "side_step":
        c.update(speed=rng.uniform(0.35, 0.7), direction=90.0 if direction == "left" else -90.0,
                 curvature=0.0)
    elif content == "walk_backward":
        c.update(speed=rng.uniform(0.4, 0.8), direction=180.0, curvature=rng.uniform(-0.03, 0.03))
    elif content == "jump":
        c.update(height=rng.uniform(0.144, 0.54), distance=rng.choice([0.0, rng.uniform(0.3, 0.9)]))
    return c


def speed_adverb(content: str, speed: float) -> str:
    """' slowly', '' or ' quickly' for a gait's measured speed (m/s)."""
    slow, fast = {"walk": (1.0, 1.45), "run": (2.2, 2.8), "walk_backward": (0.5, 0.75)}.get(
        content, (-1.0, 1e9))
    return " slowly" if speed < slow else (" quickly" if speed > fast else "")


def caption(content_params: dict, style: str | None = None, speed: float | None = None,
            name_neutral: bool = False) -> str:
    """'a person walks forward slowly' — or, with a style, 'an old person walks forward slowly'
    (neutral: 'a person walks forward slowly in a neutral style' when name_neutral)."""
    content = content_params["content"]
    _check("content", content, CONTENTS)
    template = CONTENT_TABLE[content][1]
    jump = content_params.get("distance", 0.0)
    fields = {
        "adv": speed_adverb(content, speed) if speed is not None else "",
        "side": content_params.get("side", "right"), "dir": content_params.get("dir", "left"),
        "jump_text": "jumps forward" if jump > 0 else "jumps up in place",
    }
    verb = template.format(**fields)
    if style == "neutral" and name_neutral:
        return f"a person {verb} in a neutral style"
    if style is None or style == "neutral":
        return f"a person {verb}"
    _check("style", style, STYLES)
    _, _, adjective, article = STYLE_TABLE[style]
    return f"{article} {adjective} person {verb}"
