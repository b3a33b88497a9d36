"""The library's shape: no import circle anywhere in mslib, layers import downward only (models never see the
evaluator, viz sees only motion), and no module grows past about 500 lines."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "mslib"


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in PACKAGE.rglob("*.py")}


def imports_of(name: str) -> set:
    """The mslib modules `name` imports anywhere in its file (module level or inside functions)."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            # `from pkg import sub` imports the submodule when there is one, else a name from pkg itself
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
        else:
            continue
        found.update(t for t in targets if t in MODULES and t != name)
    return found


GRAPH = {name: imports_of(name) for name in MODULES}


def find_cycle(graph: dict):
    """One import circle as a list of modules, or None (depth-first search with colours)."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                cycle = visit(nxt)
                if cycle:
                    return cycle
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node)
            if cycle:
                return cycle
    return None


def test_the_cycle_finder_finds_a_known_circle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) is None


def test_the_import_walker_resolves_relative_imports():
    assert "mslib.models.common.layers" in GRAPH["mslib.models.adain.model"]
    assert "mslib.models.registry" in GRAPH["mslib.evaluation.bench"]
    assert "mslib.models.common.style_extractor" in GRAPH["mslib.models.common"]  # `from . import style_extractor`


def test_no_import_circle_in_mslib():
    cycle = find_cycle(GRAPH)
    assert cycle is None, "import circle: " + " → ".join(cycle)


@pytest.mark.parametrize("below, above", [("mslib.models", "mslib.evaluation"), ("mslib.models", "mslib.cli"),
                                          ("mslib.motion", "mslib.data"), ("mslib.motion", "mslib.models"),
                                          ("mslib.data", "mslib.models"), ("mslib.viz", "mslib.data"),
                                          ("mslib.viz", "mslib.models"), ("mslib.viz", "mslib.evaluation")])
def test_layers_import_downward_only(below, above):
    wrong = sorted(f"{m} → {t}" for m, ts in GRAPH.items() if m == below or m.startswith(below + ".")
                   for t in ts if t == above or t.startswith(above + "."))
    assert not wrong, f"{below} must not import {above}: {wrong}"


def test_no_module_past_about_500_lines():
    long = {name: n for name, path in MODULES.items() if (n := len(path.read_text().splitlines())) > 520}
    assert not long, f"modules past ~500 lines: {long}"


def test_each_paper_package_declares_its_methods_and_trainers_in_one_place():
    import importlib

    import mslib.evaluation.bench  # noqa: F401 (registers the two reference rows)
    from mslib.cli import trainers
    from mslib.models.registry import PACKAGES, known_methods
    for name in PACKAGES:
        package = importlib.import_module(name)
        assert isinstance(package.METHODS, dict) and isinstance(package.TRAINERS, dict), name
        for method, (factory, description) in package.METHODS.items():
            assert callable(factory) and description, (name, method)
    assert {"adain", "adain+dsdn", "mcm_ldm", "contrastive", "clusterstyle", "identity", "copy_style"} <= set(known_methods())
    # every packaged checkpoint can be retrained by `python -m mslib train NAME`
    packaged = {p.stem for p in (PACKAGE / "checkpoints").glob("*.pt")}
    assert packaged <= set(trainers()), f"checkpoints without a trainer: {sorted(packaged - set(trainers()))}"
