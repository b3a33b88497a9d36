"""Explorers for the notebooks: pick a content clip, a style and a method (or two styles and a mix weight, a
style prototype, a guidance scale) and see the output in the 3-D viewer beside its inputs, with the independent
style evaluator's probabilities P(style | output) as bars.

    static twin (numbers, checked by nbval)                widget (controls + viewer + bars)
    transfer_view(content, style, method)                  explore_transfer(content, style, method)
    interpolation_view(content, style_a, style_b, weight)  explore_interpolation(...)   C Fig. 10–11
    prototype_view(style, prototype, caption, seed, ...)   explore_prototypes(...)      D §4.4, Fig. 5
    guidance_view(content, style, scale)                   explore_guidance(...)        B Eq. 5, the scale λ

A `*_view` function is the static twin: the computation the widget runs, for fixed choices, returning a `View`
(the motions shown, the evaluator's probabilities, a few numbers) whose `summary()` a notebook prints (rounded,
so that nbval sees stable text). `explore_*` takes the same arguments as the widget's starting choices and
returns a `mslib.widgets.Explorer`; its cell carries `# NBVAL_IGNORE_OUTPUT`. In a notebook, one line each:

    from mslib.explorers import explore_transfer, transfer_view
    explore_transfer("c00000", "old", "adain")                   # the widget
    print(transfer_view("c00000", "old", "adain").summary())     # its static twin

Choices. A content is a built-in clip id (c00000, …; the dropdown offers the first test clip of each content
type). A style is a style label — one of the evaluator's classes, meaning the first test clip of that style in
the style corpus (the notebooks' `first(style)`) — or a built-in clip id. A method is a registry name
(`mslib.models.registry.known_methods`). Unknown names raise a ValueError that lists the known ones.

Cost. Every method is deterministic (fixed seeds), so each output is computed once and kept in a small
in-memory cache keyed by the choices: going back to a choice is instant. The feed-forward methods (A, C) take
milliseconds and run live; the diffusion samplers (B: 50 DDIM steps, D: 20 steps with guidance) take a few
tenths of a second on a CPU, and the status line says so while they sample.
"""
from __future__ import annotations

import functools
import math
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from .evaluation.bench import positions
from .evaluation.transfer_io import builtin_folders, load_clip
from .models.registry import get_method, known_methods

SPLIT = "test"                          # where style labels and the content dropdown take their clips
SAMPLED = ("mcm_ldm", "clusterstyle")   # diffusion samplers: the status line says "sampling …" while they run
CACHE_SIZE = 256                        # outputs kept (each a few hundred kB at most)
SCALES = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)   # the λ slider's stops (B's default: 2.5)
CAPTION = "a person walks forward"
_CACHE: OrderedDict = OrderedDict()


# ---------------------------------------------------------------- what is shown
@dataclass
class View:
    """What an explorer shows for one set of choices: motions side by side and the style evaluator's view."""

    kind: str                 # "transfer", "interpolation", "prototypes" or "guidance"
    title: str                # one line naming the choices
    motions: list             # positions (T, 22, 3), metres, in viewer order
    titles: list              # one viewer title per motion
    roles: tuple              # a short name per motion ("content", "output", "style", …)
    classes: list             # the style evaluator's classes
    probabilities: np.ndarray  # (len(motions), len(classes)): P(style | motion), softmax of the logits
    targets: tuple            # the style label(s) asked for
    facts: dict = field(default_factory=dict)   # the choices' numbers (rounded), printed by summary()
    cached: bool = False      # the output came from the cache

    @property
    def output(self) -> np.ndarray:
        """Positions (T, 22, 3) of the output."""
        return self.motions[self.roles.index("output")]

    @property
    def output_probabilities(self) -> np.ndarray:
        """(len(classes),) P(style | output)."""
        return self.probabilities[self.roles.index("output")]

    def summary(self) -> str:
        """The title, the numbers, P(style | output) for every class and P(target) for every motion shown."""
        lines = [self.title]
        if self.facts:
            lines.append("  " + "; ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}"
                                          for k, v in self.facts.items()))
        lines.append("  P(style | output): " + "  ".join(f"{c} {p:.2f}"
                                                        for c, p in zip(self.classes, self.output_probabilities)))
        for t in self.targets:
            k = self.classes.index(t)
            lines.append(f"  P({t}): " + ", ".join(f"{r} {p[k]:.2f}" for r, p in zip(self.roles, self.probabilities)))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"View({self.title!r})"


def _view(kind, title, shown, targets, facts, cached) -> View:
    """shown: (role, viewer title, positions) per motion; scored by the style evaluator in one call."""
    motions = [np.asarray(m, np.float64) for _, _, m in shown]
    clf = _classifier()
    logits = clf.score(motions)[0]                                          # (N, C)
    e = np.exp(logits - logits.max(1, keepdims=True))
    return View(kind, title, motions, [t for _, t, _ in shown], tuple(r for r, _, _ in shown), list(clf.classes),
                e / e.sum(1, keepdims=True), tuple(targets), facts, cached)


# ---------------------------------------------------------------- loading (once) and the output cache
def _cached(key: tuple, compute):
    """(value, was cached) for `key`, computing and keeping it (the last CACHE_SIZE) on a miss."""
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key], True
    value = compute()
    _CACHE[key] = value
    while len(_CACHE) > CACHE_SIZE:
        _CACHE.popitem(last=False)
    return value, False


def clear_cache() -> None:
    """Forget every computed output (the loaded models stay)."""
    _CACHE.clear()


@functools.cache
def _classifier():
    from .evaluation.evaluator import load_classifier
    return load_classifier("style")


@functools.cache
def _rows(corpus: str) -> tuple:
    from .data.dataset_folder import read_labels
    return tuple(read_labels(builtin_folders()[corpus]))


@functools.cache
def _method(name: str):
    return get_method(name)


@functools.cache
def _contrastive():
    from .models.contrastive import load
    return load()


@functools.cache
def _mcm_ldm():
    from .models.mcm_ldm import load_mcm_ldm
    return load_mcm_ldm()


@functools.cache
def _pipeline():
    from .models.clusterstyle import load_pipeline
    return load_pipeline()


@functools.lru_cache(maxsize=128)
def _clip(clip_id: str, arg: str) -> dict:
    if not isinstance(clip_id, str):
        raise ValueError(f"{arg}: expected a built-in clip id (a string like c00000), got {clip_id!r}")
    return load_clip(clip_id, arg=arg)


# ---------------------------------------------------------------- choices
def style_labels() -> list:
    """The style labels a `style` may be: the style evaluator's classes."""
    return list(_classifier().classes)


def style_clip(label: str) -> str:
    """The clip a style label stands for: the first SPLIT clip of that style in the style corpus."""
    if label not in style_labels():
        raise ValueError(f"style {label!r} is not a style label; known: {', '.join(style_labels())}")
    return next(r["clip_id"] for r in _rows("style") if r["split"] == SPLIT and r["style"] == label)


def resolve_style(style) -> tuple:
    """(clip id, style label) of a style label or a built-in clip id."""
    if style in style_labels():
        return style_clip(style), style
    for corpus in ("style", "content"):
        for r in _rows(corpus):
            if r["clip_id"] == style:
                return style, r["style"]
    raise ValueError(f"style {style!r} is neither a style label ({', '.join(style_labels())}) nor a built-in "
                     f"clip id (style ids look like t0203_old_walk_w00, content ids like c00000)")


def content_choices() -> list:
    """(label, clip id) of the first SPLIT clip of each content type of the content corpus."""
    seen = {}
    for r in _rows("content"):
        if r["split"] == SPLIT and r["content"] not in seen:
            seen[r["content"]] = r["clip_id"]
    return [(f"{cid} · {content}", cid) for content, cid in seen.items()]


def check_method(method: str, allowed=None) -> str:
    names = known_methods() if allowed is None else list(allowed)
    if method not in names:
        raise ValueError(f"method {method!r} is unknown; known methods: {', '.join(names)}")
    return method


def _number(x, name: str, lo: float, hi: float = math.inf) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {x!r}") from None
    if not (math.isfinite(v) and lo <= v <= hi):
        raise ValueError(f"{name}: must lie in [{lo:g}, {hi:g}], got {x!r}")
    return round(v, 6)  # a slider's 0.30000000000000004 is 0.3


def _moved_cm(out: np.ndarray, ref: np.ndarray) -> float:
    """Mean joint distance (cm) between two motions over their common frames."""
    n = min(len(out), len(ref))
    return round(float(100 * np.linalg.norm(out[:n] - ref[:n], axis=-1).mean()), 1)


# ---------------------------------------------------------------- the static twins
def transfer_view(content: str = "c00000", style: str = "old", method: str = "adain") -> View:
    """A registered method's transfer of `content` to `style`, shown as content | output | style."""
    check_method(method)
    c = _clip(content, "content")
    s_id, label = resolve_style(style)
    s = _clip(s_id, "style")
    f, cached = _cached(("transfer", method, content, s_id), lambda: np.asarray(_method(method)(c, s), np.float64))
    out = positions(f)
    shown = [("content", f"content {content}", c["joints"]), ("output", f"{method} → {label}", out),
             ("style", f"style {s_id}", s["joints"])]
    title = f"transfer · {method} · content {content} ({c['content']}) → style {label} ({s_id})"
    facts = {"output frames": len(out), "moved from the content (cm)": _moved_cm(out, positions(c["features"]))}
    return _view("transfer", title, shown, (label,), facts, cached)


def interpolation_view(content: str = "c00000", style_a: str = "depressed", style_b: str = "proud",
                       weight: float = 0.5) -> View:
    """Paper C's mix of two style codes, (1 − w)·E_s(a) + w·E_s(b) (C Fig. 10–11): content | a | output | b."""
    w = _number(weight, "weight", 0.0, 1.0)
    c = _clip(content, "content")
    (a_id, a_label), (b_id, b_label) = resolve_style(style_a), resolve_style(style_b)
    a, b = _clip(a_id, "style_a"), _clip(b_id, "style_b")

    def mix():
        from .models.contrastive import interpolate_styles
        return interpolate_styles(_contrastive(), c["features"], a["features"], b["features"], (w,))[0]
    out, cached = _cached(("interpolation", content, a_id, b_id, w), mix)
    shown = [("content", f"content {content}", c["joints"]), ("style a", f"a: {a_label}", a["joints"]),
             ("output", f"w = {w:g}", out), ("style b", f"b: {b_label}", b["joints"])]
    title = (f"interpolation · contrastive · content {content} ({c['content']}) · "
             f"{a_label} ({a_id}) → {b_label} ({b_id}), w = {w:g}")
    facts = {"w": w, "moved from the content (cm)": _moved_cm(out, positions(c["features"]))}
    return _view("interpolation", title, shown, tuple(dict.fromkeys((a_label, b_label))), facts, cached)


def n_prototypes() -> int:
    """K, the global prototypes per style of the packaged ClusterStyle."""
    return int(_pipeline().model.style_cfg.k_global)


def _prototype_choice(prototype):
    if isinstance(prototype, str) and prototype == "reference":
        return "reference"
    k = n_prototypes()
    if isinstance(prototype, (int, np.integer)) and not isinstance(prototype, bool) and 0 <= prototype < k:
        return int(prototype)
    raise ValueError(f"prototype: expected 'reference' or a global prototype index 0…{k - 1}, got {prototype!r}")


def prototype_view(style: str = "old", prototype=0, caption: str = CAPTION, seed: int = 0, content: str | None = None,
                   length: int = 63) -> View:
    """Paper D with the reference's global style feature replaced by prototype k of its style (and the guidance
    aimed at it, D Eq. 16), or kept (prototype="reference"): generation from `caption` (style | output), or with
    a `content` clip the SDEdit transfer of it, captioned by its own caption (content | output | style)."""
    from .data.datasets import STYLE_INDEX
    from .data.styles import STYLES
    choice = _prototype_choice(prototype)
    seed = int(_number(seed, "seed", 0))
    s_id, label = resolve_style(style)
    s = _clip(s_id, "style")
    c = _clip(content, "content") if content else None
    if c is None and not (isinstance(caption, str) and caption.strip()):
        raise ValueError(f"caption: generation needs a non-empty caption, got {caption!r}")
    pipe = _pipeline()

    def sample():
        tokens = pipe.style_tokens(s["features"])
        guide = "reference"
        if choice != "reference":
            tokens, guide = pipe.prototype_tokens(tokens, global_k=choice, style=STYLE_INDEX[label]), ("global", choice)
        if c is None:
            return pipe.generate(caption, s["features"], length, guide=guide, seed=seed, style_tokens=tokens)
        return pipe.transfer(c["features"], s["features"], caption=c.get("caption") or None, guide=guide, seed=seed,
                             style_tokens=tokens)
    key = ("prototypes", s_id, label, choice, seed) + ((content,) if c is not None else (caption, int(length)))
    f, cached = _cached(key, sample)
    out = positions(f)
    near_style, near_k = pipe.nearest_global_prototype(pipe.style_tokens(f))
    name = "reference feature" if choice == "reference" else f"prototype {choice}"
    shown = [("output", f"{label}, {name}", out), ("style", f"style {s_id}", s["joints"])]
    if c is None:
        source = f"caption {caption!r}"
        shown = shown[::-1]
    else:
        source = f"content {content} ({c['content']})"
        shown.insert(0, ("content", f"content {content}", c["joints"]))
    title = f"prototypes · clusterstyle · {source} · style {label} ({s_id}), {name}, seed {seed}"
    facts = {"output frames": len(out), "nearest global prototype of the output": f"{STYLES[near_style]} {near_k}"}
    return _view("prototypes", title, shown, (label,), facts, cached)


def _course_scale() -> float:
    """The packaged MCM-LDM's guidance scale λ (its course preset's, chosen on validation pairs)."""
    return float(_mcm_ldm().model.cfg.cfg_scale)


def guidance_view(content: str = "c00000", style: str = "angry", scale: float | None = None) -> View:
    """Paper B at guidance scale λ (B Eq. 5: ε̂ = ε(∅) + λ·(ε(s) − ε(∅))), shown as content | output | style;
    `scale` None: the course model's λ."""
    lam = _course_scale() if scale is None else _number(scale, "scale", 0.0)
    c = _clip(content, "content")
    s_id, label = resolve_style(style)
    s = _clip(s_id, "style")
    f, cached = _cached(("guidance", content, s_id, lam),
                        lambda: np.asarray(_mcm_ldm()(c["features"], s["features"], scale=lam), np.float64))
    out = positions(f)
    shown = [("content", f"content {content}", c["joints"]), ("output", f"λ = {lam:g} → {label}", out),
             ("style", f"style {s_id}", s["joints"])]
    title = f"guidance · mcm_ldm · content {content} ({c['content']}) → style {label} ({s_id}), λ = {lam:g}"
    facts = {"λ": lam, "moved from the content (cm)": _moved_cm(out, positions(c["features"]))}
    return _view("guidance", title, shown, (label,), facts, cached)


# ---------------------------------------------------------------- the widgets
def _dropdown(options: list, value, description: str):
    import ipywidgets as W
    if value not in [v for _, v in options]:
        options = [(str(value), value)] + options
    return W.Dropdown(options=options, value=value, description=description, layout=W.Layout(width="260px"))


def _style_dropdown(style, description: str = "style"):
    resolve_style(style)
    return _dropdown([(s, s) for s in style_labels()], style, description)


def _content_dropdown(content, description: str = "content"):
    _clip(content, "content")
    return _dropdown(content_choices(), content, description)


def explore_transfer(content: str = "c00000", style: str = "old", method: str = "adain", methods=None):
    """Dropdowns for the content clip, the style and the method (default: every registered one)."""
    from .widgets import Explorer
    methods = known_methods() if methods is None else [check_method(m) for m in methods]
    check_method(method, methods)
    controls = {"content": _content_dropdown(content), "style": _style_dropdown(style),
                "method": _dropdown([(m, m) for m in methods], method, "method")}
    return Explorer("transfer", transfer_view, controls,
                    busy=lambda ch: f"sampling {ch['method']} (diffusion) …" if ch["method"] in SAMPLED else None)


def explore_interpolation(content: str = "c00000", style_a: str = "depressed", style_b: str = "proud",
                          weight: float = 0.5):
    """Dropdowns for the content and the two styles, a slider for the mix weight w (C Fig. 10–11)."""
    import ipywidgets as W

    from .widgets import Explorer
    w = _number(weight, "weight", 0.0, 1.0)
    controls = {"content": _content_dropdown(content), "style_a": _style_dropdown(style_a, "style a"),
                "style_b": _style_dropdown(style_b, "style b"),
                "weight": W.FloatSlider(value=w, min=0.0, max=1.0, step=0.1, description="w", readout_format=".1f",
                                        continuous_update=False, layout=W.Layout(width="300px"))}
    return Explorer("interpolation", interpolation_view, controls)


def explore_prototypes(style: str = "old", prototype=0, caption: str = CAPTION, seed: int = 0,
                       content: str | None = None):
    """A style dropdown, a button per global prototype (and the reference feature), the caption, the seed, and
    the source: generation from the caption, or the transfer of a content clip (D §4.4, Fig. 5)."""
    import ipywidgets as W

    from .widgets import Explorer
    choice = _prototype_choice(prototype)
    sources = [("from the caption", "")] + content_choices()
    controls = {"style": _style_dropdown(style),
                "prototype": W.ToggleButtons(options=[("reference", "reference")] + [(f"prototype {k}", k) for k in
                                                                                     range(n_prototypes())],
                                             value=choice, description="feature",
                                             style={"button_width": "105px"}),
                "caption": W.Text(value=caption, description="caption", continuous_update=False,
                                  layout=W.Layout(width="360px")),
                "seed": W.BoundedIntText(value=int(seed), min=0, max=999, description="seed",
                                         layout=W.Layout(width="160px")),
                "content": _dropdown(sources, content or "", "source")}
    if content:
        _clip(content, "content")
    return Explorer("prototypes", prototype_view, controls, busy=lambda ch: "sampling clusterstyle (diffusion) …")


def explore_guidance(content: str = "c00000", style: str = "angry", scale: float | None = None, scales=SCALES):
    """Dropdowns for the content and the style, a slider over the guidance scales λ (B Eq. 5), starting at
    `scale` (None: the course model's λ)."""
    import ipywidgets as W

    from .widgets import Explorer, _check_values
    lam = _course_scale() if scale is None else _number(scale, "scale", 0.0)
    steps = _mcm_ldm().model.cfg.ddim_steps
    values = _check_values(sorted(set(_check_values(scales, "scales")) | {lam}), "scales")
    if values[0] < 0:
        raise ValueError(f"scales: a guidance scale is ≥ 0, got {values[0]:g}")
    controls = {"content": _content_dropdown(content), "style": _style_dropdown(style),
                "scale": W.SelectionSlider(options=[(f"{v:g}", v) for v in values], value=lam, description="λ",
                                           continuous_update=False, layout=W.Layout(width="360px"))}
    return Explorer("guidance", guidance_view, controls, busy=lambda ch: f"sampling mcm_ldm ({steps} DDIM steps) …")
