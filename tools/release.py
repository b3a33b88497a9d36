"""Hand the workbook out as an nbgrader course and grade what the students hand back (make release, make grade).

    .venv/bin/python tools/release.py release [--out release] [--force]
    .venv/bin/python tools/release.py grade SUBMISSIONS_DIR [--course release] [--force] [--json]

`release` lays out an nbgrader course in --out (default course/, git-ignored): the instructor notebooks
(notebooks/*.ipynb, solutions filled in) as the assignment `workbook` in source/workbook/, the tables they read
(notebooks/data/*.json) beside them, an nbgrader_config.py, and the gradebook. `nbgrader generate_assignment`
then writes the student version to release/workbook/ inside the course (nbgrader's name for the handout): solutions replaced by
`raise NotImplementedError()`, hidden tests removed, outputs cleared. That folder is what students get.
The checkpoints and built-in data come with the installed `mslib`, so nothing else is copied.

`grade` takes one folder per student holding the notebooks they hand back (SUBMISSIONS_DIR/alice/
02_adain_transfer.ipynb, ...), copies them into the course's submitted/<student>/workbook/, runs
`nbgrader autograde workbook` for each student (students are added to the gradebook as they come) and prints
each student's points per notebook and in total, read from the gradebook.

Cells become exercises through markers in the notebook sources (tools/build_notebooks.py):
`# %% [nbgrader solution id=NAME]` and `# %% [nbgrader tests id=NAME points=N]`.
An existing course folder, or a student already graded, is replaced only with --force. nbgrader comes from
requirements-instructor.txt (make release / make grade install it); the students' environment does not need it.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tools.common import ROOT  # noqa: E402

WORKBOOK = "workbook"                       # the nbgrader assignment: every notebook of the workbook
COURSE_ID = "motion-style-workbook"
DEFAULT_COURSE = ROOT / "course"
NOTEBOOKS = ROOT / "notebooks"
CELL_TIMEOUT = 600                          # seconds one cell may run under autograde (nbgrader's default is 30)
REPLACED_ON_FORCE = ("nbgrader_config.py", "source", "release", "gradebook.db")  # grades and submissions stay

CONFIG = '''"""nbgrader configuration of the Motion Style Workbook course (written by tools/release.py)."""
import os

c = get_config()  # noqa: F821 (traitlets provides it)
c.CourseDirectory.course_id = {course_id!r}
c.CourseDirectory.root = os.path.dirname(os.path.abspath(__file__))  # this folder, wherever it is moved
c.Execute.timeout = {timeout}  # seconds per cell; some of the workbook's cells train for ~20 s on 2 cores
'''


def workbook_notebooks(folder: Path = NOTEBOOKS) -> list:
    """The instructor notebooks of the workbook: every `NN_name.ipynb` in `folder`."""
    return sorted(Path(folder).glob("*.ipynb"))


def runtime_files(folder: Path = NOTEBOOKS) -> dict:
    """{path relative to `folder`: file} of what its notebooks read at run time: the tables in data/."""
    folder = Path(folder)
    return {p.relative_to(folder).as_posix(): p for p in sorted((folder / "data").glob("*.json"))}


def has_nbgrader_cells(notebook: Path) -> bool:
    """Whether a saved notebook holds a cell with nbgrader metadata (an exercise or its tests)."""
    cells = json.loads(Path(notebook).read_text(encoding="utf-8"))["cells"]
    return any("nbgrader" in cell.get("metadata", {}) for cell in cells)


def nbgrader(course: Path, *args: str) -> str:
    """Run `python -m nbgrader ARGS` in `course`; returns its log (a RuntimeError with its tail on failure)."""
    from mslib.cpu_paths import pin_cpu_code_paths
    env = dict(os.environ)
    pin_cpu_code_paths(env)  # the kernels run on the numeric code path the stored outputs were written with
    # nbgrader's gradebook runs the `alembic` command of its environment by name: put this Python's bin first
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    run = subprocess.run([sys.executable, "-m", "nbgrader", *args], cwd=course, env=env, capture_output=True,
                         text=True)
    log = run.stdout + run.stderr
    if run.returncode != 0:
        tail = "\n".join(log.strip().splitlines()[-25:])
        raise RuntimeError(f"nbgrader {' '.join(args)} failed in {course} (exit {run.returncode}):\n{tail}")
    return log


def write_course(course: Path, notebooks, files: dict, timeout: int) -> None:
    """Write the config and source/workbook/ (the notebooks and `files`) into the empty folder `course`."""
    text = CONFIG.format(course_id=COURSE_ID, timeout=int(timeout))
    (course / "nbgrader_config.py").write_text(text, encoding="utf-8")
    source = course / "source" / WORKBOOK
    source.mkdir(parents=True)
    for notebook in notebooks:
        shutil.copy2(notebook, source / Path(notebook).name)
    for relative, path in files.items():
        (source / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, source / relative)


def check_release_inputs(notebooks, files: dict) -> list:
    """The notebooks as Paths; a ValueError for none, a missing file or two notebooks of one name."""
    notebooks = [Path(n) for n in notebooks]
    if not notebooks:
        raise ValueError("notebooks: no notebook to release")
    missing = [str(p) for p in [*notebooks, *files.values()] if not Path(p).is_file()]
    if missing:
        raise ValueError(f"no such file: {', '.join(missing)}")
    names = [n.name for n in notebooks]
    if len(set(names)) != len(names):
        raise ValueError(f"notebooks: two notebooks share a name ({sorted(names)})")
    return notebooks


def release(course: Path = DEFAULT_COURSE, notebooks=None, files=None, force: bool = False,
            timeout: int = CELL_TIMEOUT) -> Path:
    """Lay out the course in `course` (staged beside it, then moved in) and generate the student version; returns
    its folder. An existing course only with `force`: its source and student version are rebuilt, grades kept."""
    course = Path(course).resolve()
    files = runtime_files() if files is None else dict(files)
    notebooks = check_release_inputs(workbook_notebooks() if notebooks is None else notebooks, files)
    if course.exists() and not force:
        raise ValueError(f"--out {course} already exists; pass --force (make release FORCE=1) to rebuild its "
                         "source and student version")
    if course.exists() and not (course / "nbgrader_config.py").is_file():
        raise ValueError(f"--out {course} exists and is not a course folder (no nbgrader_config.py); "
                         "refusing to replace it even with --force")
    course.parent.mkdir(parents=True, exist_ok=True)
    staging = staging_folder(course.parent, course.name)
    try:
        write_course(staging, notebooks, files, timeout)
        if (course / "gradebook.db").is_file():
            shutil.copy2(course / "gradebook.db", staging / "gradebook.db")
        nbgrader(staging, "generate_assignment", WORKBOOK, "--force")
        move_into_place(staging, course)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return course / "release" / WORKBOOK


def staging_folder(parent: Path, name: str) -> Path:
    """A new temporary folder `.NAME.*.tmp` in `parent`, with ordinary permissions (mkdtemp makes it 0700)."""
    staging = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".tmp", dir=parent))
    umask = os.umask(0)
    os.umask(umask)
    staging.chmod(0o777 & ~umask)
    return staging


def move_into_place(staging: Path, course: Path) -> None:
    """Rename the staged course to `course`, or swap the REPLACED_ON_FORCE parts into an existing one."""
    if not course.exists():
        os.replace(staging, course)
        return
    old = staging / ".replaced"
    old.mkdir()
    for name in REPLACED_ON_FORCE:
        if (course / name).exists():
            os.replace(course / name, old / name)
        if (staging / name).exists():
            os.replace(staging / name, course / name)


def check_course(course: Path) -> Path:
    """The course folder, resolved; a ValueError when it is not one `release` made."""
    course = Path(course).resolve()
    if not (course / "nbgrader_config.py").is_file() or not (course / "source" / WORKBOOK).is_dir():
        raise ValueError(f"--course {course}: not a course folder (no nbgrader_config.py or source/{WORKBOOK}/); "
                         "make one with `make release` (tools/release.py release)")
    return course


def collect_submissions(folder: Path, workbook: list) -> dict:
    """{student: [notebooks]} of a folder of student folders; a ValueError naming what is not (`workbook`: names)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"SUBMISSIONS_DIR {folder}: no such folder")
    entries = [p for p in sorted(folder.iterdir()) if not p.name.startswith(".")]
    stray = [p.name for p in entries if not p.is_dir()]
    if stray:
        raise ValueError(f"SUBMISSIONS_DIR {folder}: expected one folder per student, found files {stray}")
    if not entries:
        raise ValueError(f"SUBMISSIONS_DIR {folder}: no student folder in it")
    found = {}
    for student in entries:
        if set(student.name) & set("*?[]"):  # nbgrader takes the student id as a file glob
            raise ValueError(f"{student}: a student folder's name cannot hold * ? [ or ] (nbgrader reads it as a glob)")
        notebooks = sorted(student.glob("*.ipynb"))
        unknown = [p for p in notebooks if p.name not in workbook]
        if unknown:
            raise ValueError(f"{unknown[0]}: not a notebook of the {WORKBOOK} (expected one of {', '.join(workbook)})")
        if not notebooks:
            raise ValueError(f"{student}: no notebook (.ipynb) in this student's folder")
        found[student.name] = notebooks
    return found


def check_not_graded(course: Path, students, force: bool) -> None:
    """A ValueError naming a student handed in or graded before, unless `force`."""
    for student in students:
        done = [course / step / student / WORKBOOK for step in ("submitted", "autograded")]
        if any(path.exists() for path in done) and not force:
            raise ValueError(f"{student}: already handed in at {done[0]}; pass --force (make grade ... FORCE=1) "
                             "to replace it and grade again")


def submit(course: Path, student: str, notebooks: list) -> None:
    """Copy one student's notebooks into submitted/<student>/workbook/ (staged, then renamed into place)."""
    target = course / "submitted" / student / WORKBOOK
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = staging_folder(target.parent, WORKBOOK)
    try:
        for notebook in notebooks:
            shutil.copy2(notebook, staging / notebook.name)
        if target.exists():
            shutil.rmtree(target)
        os.replace(staging, target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def grade(submissions: Path, course: Path = DEFAULT_COURSE, force: bool = False) -> dict:
    """Hand in and autograde every student of `submissions`; returns `scores` plus "failed": {student: error}."""
    course = check_course(course)
    workbook = sorted(p.name for p in (course / "source" / WORKBOOK).glob("*.ipynb"))
    handed_in = collect_submissions(submissions, workbook)
    check_not_graded(course, handed_in, force)
    for student, notebooks in handed_in.items():
        submit(course, student, notebooks)
    failed = {}
    for student in handed_in:
        try:
            nbgrader(course, "autograde", WORKBOOK, "--student", student, *(["--force"] if force else []))
        except RuntimeError as error:
            failed[student] = str(error)
    graded = [s for s in handed_in if s not in failed]
    return {**scores(course, graded), "failed": failed}


def scores(course: Path, students: list) -> dict:
    """Each student's points per notebook and in total from the gradebook, beside the notebooks' maxima."""
    from nbgrader.api import Gradebook
    db_url = f"sqlite:///{Path(course).resolve() / 'gradebook.db'}"
    with Gradebook(db_url, course_id=COURSE_ID) as gradebook:
        assignment = gradebook.find_assignment(WORKBOOK)
        maxima = {nb.name: float(nb.max_score) for nb in sorted(assignment.notebooks, key=lambda nb: nb.name)}
        table = {}
        for student in students:
            points = {name: float(gradebook.find_submission_notebook(name, WORKBOOK, student).score)
                      for name in maxima}
            table[student] = {"notebooks": points, "score": sum(points.values())}
    return {"course": str(course), "assignment": WORKBOOK, "notebooks": maxima, "max_score": sum(maxima.values()),
            "students": table}


def format_table(result: dict) -> str:
    """`grade`'s result as a plain-text table: a row per student, a column per notebook that has points."""
    columns = [name for name, most in result["notebooks"].items() if most > 0]
    header = ["student", *[f"{name} (/{most:g})" for name, most in result["notebooks"].items() if most > 0],
              f"total (/{result['max_score']:g})"]
    rows = [[student, *[f"{row['notebooks'][name]:g}" for name in columns], f"{row['score']:g}"]
            for student, row in result["students"].items()]
    rows += [[student, *["-"] * len(columns), "not graded"] for student in result.get("failed", {})]
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in enumerate(zip(r, widths)))
             for r in [header, *rows]]
    return "\n".join([lines[0], "  ".join("-" * w for w in widths), *lines[1:]])


def main(argv=None) -> int:
    """`python tools/release.py release|grade ...` (see the module's docstring)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    out = commands.add_parser("release", help="lay out the nbgrader course and generate the student version")
    out.add_argument("--out", type=Path, default=DEFAULT_COURSE, help="the course folder (default: course/)")
    out.add_argument("--force", action="store_true", help="rebuild an existing course's source and student version")
    marks = commands.add_parser("grade", help="autograde the notebooks of one folder per student")
    marks.add_argument("submissions", type=Path, metavar="SUBMISSIONS_DIR", help="one folder per student")
    marks.add_argument("--course", type=Path, default=DEFAULT_COURSE, help="the course folder (default: course/)")
    marks.add_argument("--force", action="store_true", help="grade again a student handed in before")
    marks.add_argument("--json", action="store_true", help="print the points as JSON instead of a table")
    args = parser.parse_args(argv)
    try:
        if args.command == "release":
            return report_release(release(args.out, force=args.force))
        result = grade(args.submissions, args.course, force=args.force)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except RuntimeError as error:  # nbgrader failed to generate the student version
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(json.dumps(result, indent=1) if args.json else format_table(result))
    for student, error in result["failed"].items():
        print(f"\n{student}: not graded\n{error}", file=sys.stderr)
    return 1 if result["failed"] else 0


def report_release(student_version: Path) -> int:
    """Print where the student version is and which notebooks hold exercises."""
    notebooks = sorted(student_version.glob("*.ipynb"))
    exercises = [n.stem for n in notebooks if has_nbgrader_cells(n)]
    print(f"student version: {student_version} ({len(notebooks)} notebooks; with exercises: "
          f"{', '.join(exercises) or 'none yet'})")
    course = student_version.parents[1]
    how = "make grade DIR=SUBMISSIONS_DIR" if course == DEFAULT_COURSE.resolve() else \
        f"python tools/release.py grade SUBMISSIONS_DIR --course {course}"
    print(f"hand that folder out; grade what comes back with: {how}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
