"""The nbgrader markers of the notebook sources (tools/build_notebooks.py) and handing the workbook out and grading
it (tools/release.py): on a toy notebook (tests/fixtures/release/, seconds) and on the real workbook (minutes)."""
import json
import shutil
from pathlib import Path

import nbformat
import pytest

from tools import build_notebooks, release

ROOT = Path(__file__).resolve().parents[1]
FIXTURE = ROOT / "tests" / "fixtures" / "release"
parse_percent = build_notebooks.parse_percent

SOURCE = """# %% [markdown]
# # Title

# %%
x = 1

# %% [nbgrader solution id=ex02_adain]
def f():
    ### BEGIN SOLUTION
    return x
    ### END SOLUTION

# %% [nbgrader tests id=ex02_adain_check points=2]
assert f() == 1
### BEGIN HIDDEN TESTS
assert f() != 2
### END HIDDEN TESTS
"""


# ---------------------------------------------------------------- the markers
def test_markers_give_nbgrader_metadata_and_plain_cells_none():
    cells = parse_percent(SOURCE, "99_x.py")
    assert [(kind, meta) for kind, _, meta in cells] == [
        ("markdown", {}),
        ("code", {}),
        ("code", {"nbgrader": {"grade": False, "solution": True, "locked": False, "grade_id": "ex02_adain",
                               "schema_version": 3}}),
        ("code", {"nbgrader": {"grade": True, "solution": False, "locked": True, "points": 2,
                               "grade_id": "ex02_adain_check", "schema_version": 3}}),
    ]
    assert cells[0][1] == "# Title" and cells[1][1] == "x = 1"
    assert cells[2][1] == "def f():\n    ### BEGIN SOLUTION\n    return x\n    ### END SOLUTION"
    assert cells[3][1].endswith("### END HIDDEN TESTS")


def test_plain_headers_keep_their_old_meaning():
    text = "# %% a title\ny = 2\n# %% [markdown]\n# some *text*\n#\n# %%\n\n# %%\nz = 3\n"
    assert parse_percent(text) == [("code", "y = 2", {}), ("markdown", "some *text*\n", {}), ("code", "z = 3", {})]


@pytest.mark.parametrize("points, expected", [("3", 3), ("1.5", 1.5), ("2.0", 2)])
def test_points_are_numbers(points, expected):
    text = f"# %% [nbgrader tests id=t points={points}]\nassert True\n"
    assert parse_percent(text)[0][2]["nbgrader"]["points"] == expected


BAD_MARKERS = [
    ("# %% [nbgrader answer id=a]\nx = 1\n", 1, "unknown nbgrader cell kind 'answer'"),
    ("# %% [nbgrader]\nx = 1\n", 1, "unknown nbgrader cell kind nothing"),
    ("# %% [nbgrader solution]\n### BEGIN SOLUTION\n### END SOLUTION\n", 1, "needs id=NAME"),
    ("# %% [nbgrader tests id=a/b points=1]\nx = 1\n", 1, "needs id=NAME"),
    ("# %% [nbgrader tests id=a]\nx = 1\n", 1, "positive number, got None"),
    ("# %% [nbgrader tests id=a points=0]\nx = 1\n", 1, "positive number, got '0'"),
    ("# %% [nbgrader tests id=a points=-2]\nx = 1\n", 1, "positive number, got '-2'"),
    ("# %% [nbgrader tests id=a points=two]\nx = 1\n", 1, "positive number, got 'two'"),
    ("# %% [nbgrader tests id=a points=nan]\nx = 1\n", 1, "positive number, got 'nan'"),
    ("# %% [nbgrader solution id=a points=2]\n### BEGIN SOLUTION\n### END SOLUTION\n", 1, "not its solution"),
    ("# %% [nbgrader tests id=a points=1 weight=2]\nx = 1\n", 1, "bad nbgrader option 'weight=2'"),
    ("# %% [nbgrader tests id=a id=b points=1]\nx = 1\n", 1, "bad nbgrader option 'id=b'"),
    ("# %% [markdown nbgrader task id=a]\n# text\n", 1, "malformed nbgrader marker"),
    ("# %%\nx = 1\n# %% [nbgrader tests id=a points=1]\nx = 2\n# %% [nbgrader tests id=a points=1]\nx = 3\n", 5,
     "grade id 'a' already used at line 3"),
    ("# %%\nx = 1\n### BEGIN SOLUTION\n", 3, "outside an nbgrader solution cell"),
    ("# %% [markdown]\n# ### END SOLUTION\n", 2, "outside an nbgrader solution cell"),
    ("# %% [nbgrader solution id=a]\n### BEGIN HIDDEN TESTS\n### BEGIN SOLUTION\n### END SOLUTION\n", 2,
     "outside an nbgrader tests cell"),
    ("# %% [nbgrader solution id=a]\nx = 1\n### BEGIN SOLUTION\n", 3, "never closed"),
    ("# %% [nbgrader solution id=a]\n### BEGIN SOLUTION\n### BEGIN SOLUTION\n### END SOLUTION\n", 3,
     "inside the region opened on line 2"),
    ("# %% [nbgrader tests id=a points=1]\n### END HIDDEN TESTS\n", 2, "without a BEGIN HIDDEN TESTS"),
    ("# %% [nbgrader solution id=a]\nx = 1\n", 1, "has no ### BEGIN SOLUTION"),
    ("# %% [nbgrader tests id=a points=1]\n\n", 1, "nbgrader cell 'a' is empty"),
]


@pytest.mark.parametrize("text, line, message", BAD_MARKERS, ids=[m for _, _, m in BAD_MARKERS])
def test_bad_markers_are_value_errors_naming_file_and_line(text, line, message):
    with pytest.raises(ValueError, match=rf"^99_bad\.py, line {line}: .*") as error:
        parse_percent(text, "99_bad.py")
    assert message in str(error.value)


def test_sync_sources_writes_the_nbgrader_metadata_and_keeps_outputs(tmp_path):
    plain = (SOURCE.replace("# %% [nbgrader tests id=ex02_adain_check points=2]", "# %%")
             .replace("BEGIN HIDDEN TESTS", "hidden").replace("END HIDDEN TESTS", "shown"))
    src = tmp_path / "99_sync.py"
    src.write_text(plain)
    nb = nbformat.v4.new_notebook()
    nb.cells = [build_notebooks.new_cell(*cell) for cell in build_notebooks.read_cells(src)]
    nb.cells[1].outputs = [nbformat.v4.new_output("stream", text="kept\n")]
    nb.cells[2].metadata["tags"] = ["mine"]
    nbformat.write(nb, tmp_path / "99_sync.ipynb")
    src.write_text(SOURCE)
    assert build_notebooks.sync_sources(src, out_dir=tmp_path) == 1
    saved = nbformat.read(tmp_path / "99_sync.ipynb", as_version=4)
    assert saved.cells[3].metadata["nbgrader"]["points"] == 2 and saved.cells[1].outputs[0].text == "kept\n"
    assert saved.cells[2].metadata["tags"] == ["mine"] and saved.cells[2].metadata["nbgrader"]["solution"]
    assert "### BEGIN HIDDEN TESTS" in saved.cells[3].source
    src.write_text(plain)
    assert build_notebooks.sync_sources(src, out_dir=tmp_path) == 1
    assert "nbgrader" not in nbformat.read(tmp_path / "99_sync.ipynb", as_version=4).cells[3].metadata


def test_format_table():
    result = {"notebooks": {"00_a": 0.0, "02_b": 3.0}, "max_score": 3.0, "failed": {"carol": "boom"},
              "students": {"alice": {"notebooks": {"00_a": 0.0, "02_b": 1.5}, "score": 1.5}}}
    assert release.format_table(result).splitlines() == [
        "student  02_b (/3)  total (/3)",
        "-------  ---------  ----------",
        "alice          1.5         1.5",
        "carol            -  not graded",
    ]


# ---------------------------------------------------------------- release and grade, on the toy notebook
def code_cells(path: Path) -> list:
    """The code cells of a saved notebook."""
    return [c for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code"]


def errors(cell) -> list:
    """The error outputs of one code cell."""
    return [o for o in cell.get("outputs", []) if o.output_type == "error"]


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    """The toy notebook built (executed, solutions in) and released into a course: (folder, notebook, course)."""
    folder = tmp_path_factory.mktemp("toy")
    notebooks = folder / "notebooks"
    shutil.copytree(FIXTURE / "data", notebooks / "data")
    build_notebooks.build(FIXTURE / "99_toy.py", timeout=120, out_dir=notebooks)
    instructor = notebooks / "99_toy.ipynb"
    course = folder / "course"
    student = release.release(course, notebooks=[instructor], files=release.runtime_files(notebooks))
    assert student == course / "release" / "workbook"
    return folder, instructor, course


def test_the_student_version_has_no_solution_no_hidden_tests_no_outputs(toy):
    folder, instructor, course = toy
    assert any(c.outputs for c in code_cells(instructor)) and release.has_nbgrader_cells(instructor)
    student = course / "release" / "workbook" / "99_toy.ipynb"
    text = student.read_text()
    for secret in ("BEGIN SOLUTION", "v * scale", "HIDDEN TESTS", "rescale([])", "rescale([-1.5])"):
        assert secret not in text
    assert "raise NotImplementedError()" in text and "assert rescale([1, 2])" in text
    assert all(not c.outputs and c.execution_count is None for c in code_cells(student))
    assert json.loads((course / "release" / "workbook" / "data" / "99_toy.json").read_text()) == {"scale": 3}
    config = (course / "nbgrader_config.py").read_text()
    assert "motion-style-workbook" in config and "c.Execute.timeout = 600" in config


def test_grade_gives_the_solution_full_marks_and_the_untouched_student_version_none(toy, capsys):
    folder, instructor, course = toy
    subs = folder / "subs"
    for student, notebook in (("teacher", instructor), ("kid", course / "release" / "workbook" / "99_toy.ipynb")):
        (subs / student).mkdir(parents=True)
        shutil.copy(notebook, subs / student)
    result = release.grade(subs, course)
    assert result["failed"] == {} and result["notebooks"] == {"99_toy": 3.0} and result["max_score"] == 3.0
    assert result["students"] == {"kid": {"notebooks": {"99_toy": 0.0}, "score": 0.0},
                                  "teacher": {"notebooks": {"99_toy": 3.0}, "score": 3.0}}
    graded = code_cells(course / "autograded" / "kid" / "workbook" / "99_toy.ipynb")
    plain = [c for c in graded if "nbgrader" not in c.metadata]
    assert len(plain) == 2 and all(c.outputs and not errors(c) for c in plain)  # data/ was found beside it
    assert [e.ename for c in graded if c.metadata.get("nbgrader", {}).get("grade") for e in errors(c)] == \
        ["NotImplementedError"]
    with pytest.raises(ValueError, match="kid: already handed in .*pass --force"):
        release.grade(subs, course)
    # a rebuilt course keeps the grades; the command line prints them as JSON
    with pytest.raises(ValueError, match="already exists; pass --force"):
        release.release(course, notebooks=[instructor], files=release.runtime_files(instructor.parent))
    release.release(course, notebooks=[instructor], files=release.runtime_files(instructor.parent), force=True)
    assert release.scores(course, ["teacher"])["students"]["teacher"]["score"] == 3.0
    shutil.rmtree(subs / "kid")
    capsys.readouterr()
    assert release.main(["grade", str(subs), "--course", str(course), "--force", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["students"] == {"teacher": {"notebooks": {"99_toy": 3.0}, "score": 3.0}} and printed["failed"] == {}


def test_grade_refuses_bad_submission_folders(toy, tmp_path):
    folder, instructor, course = toy
    with pytest.raises(ValueError, match=r"SUBMISSIONS_DIR .*nowhere: no such folder"):
        release.grade(tmp_path / "nowhere", course)
    with pytest.raises(ValueError, match="no student folder"):
        release.grade(tmp_path, course)
    (tmp_path / "alice").mkdir()
    with pytest.raises(ValueError, match="alice: no notebook"):
        release.grade(tmp_path, course)
    shutil.copy(instructor, tmp_path / "alice" / "99_other.ipynb")
    with pytest.raises(ValueError, match=r"alice/99_other.ipynb: not a notebook of the workbook \(expected one of "
                                         r"99_toy.ipynb\)"):
        release.grade(tmp_path, course)
    (tmp_path / "bob.ipynb").write_text("{}")
    with pytest.raises(ValueError, match=r"expected one folder per student, found files \['bob.ipynb'\]"):
        release.grade(tmp_path, course)
    with pytest.raises(ValueError, match="not a course folder"):
        release.grade(tmp_path, tmp_path)
    (tmp_path / "bob.ipynb").unlink()
    (tmp_path / "al[1]").mkdir()
    with pytest.raises(ValueError, match=r"al\[1\]: a student folder's name cannot hold"):
        release.grade(tmp_path, course)
    assert release.main(["grade", str(tmp_path / "nowhere"), "--course", str(course)]) == 2


def test_release_refuses_missing_inputs_and_a_folder_that_is_not_a_course(tmp_path):
    with pytest.raises(ValueError, match="no such file: .*missing.ipynb"):
        release.release(tmp_path / "c", notebooks=[tmp_path / "missing.ipynb"], files={})
    (tmp_path / "c").mkdir()
    (tmp_path / "nb.ipynb").write_text("{}")
    with pytest.raises(ValueError, match="is not a course folder .*even with --force"):
        release.release(tmp_path / "c", notebooks=[tmp_path / "nb.ipynb"], files={}, force=True)


def test_the_workbook_release_carries_the_tables_the_notebooks_read():
    files = release.runtime_files()
    assert "data/07_bench.json" in files and all(p.is_file() for p in files.values())
    assert [p.name for p in release.workbook_notebooks()][0] == "00_motion_data.ipynb"


# ---------------------------------------------------------------- the real workbook (slow: a few minutes)
def test_slow_real_workbook_solutions_score_full_marks_and_the_student_version_zero(tmp_path):
    """Every notebook with exercises: the instructor version (as a submission) gets every point, the released
    student version none, and its cells outside the exercises run without errors (runs each such notebook
    twice under nbgrader: ~20-30 s each on 2 cores)."""
    exercises = [n for n in release.workbook_notebooks() if release.has_nbgrader_cells(n)]
    if not exercises:
        pytest.skip("no notebook of notebooks/ has nbgrader cells yet (# %% [nbgrader ...] markers in notebooks/src)")
    course = tmp_path / "course"
    student_version = release.release(course)
    subs = tmp_path / "subs"
    for who, folder in (("instructor", ROOT / "notebooks"), ("student", student_version)):
        (subs / who).mkdir(parents=True)
        for notebook in exercises:
            shutil.copy(folder / notebook.name, subs / who)
    result = release.grade(subs, course)
    assert result["failed"] == {}
    for notebook in exercises:
        name, most = notebook.stem, result["notebooks"][notebook.stem]
        assert most > 0, f"{name}: has nbgrader cells but no points (no tests cell?)"
        assert result["students"]["instructor"]["notebooks"][name] == most, f"{name}: the solutions lose points"
        assert result["students"]["student"]["notebooks"][name] == 0, f"{name}: the student version scores points"
        for who in ("instructor", "student"):
            graded = code_cells(course / "autograded" / who / "workbook" / notebook.name)
            broken = [i for i, c in enumerate(graded) if "nbgrader" not in c.metadata and errors(c)]
            assert broken == [], f"{name} ({who}): code cells {broken} outside the exercises raised errors"
