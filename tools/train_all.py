"""Retrain every packaged checkpoint with its course seed, in dependency order, one thread per job.

    python tools/train_all.py --force [--jobs 2] [--only NAME,...] [--logs DIR] [--summary FILE]
    python tools/train_all.py --dry-run            # the commands, in the order one lane would run them

Each job is `python -m mslib train NAME --preset course --seed SEED --json` with OMP_NUM_THREADS=1 (two
torch processes with more threads each stall one another on a 2-core machine), started once the
checkpoints it reads are trained; at most `--jobs` run at once, the longest ready job first. The seconds
of each job (one core) go to `--summary`. A checkpoint is written over only with `--force`: the packaged
ones are what the notebooks, the benchmark tables and the findings were measured with.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from mslib.checkpoints import COURSE_SEEDS  # noqa: E402

# name → (the course seed, the packaged checkpoints its training reads, minutes on one core, roughly)
COURSE = {name: (COURSE_SEEDS[name], reads, minutes) for name, reads, minutes in (
    ("evaluator_style", (), 1),
    ("evaluator_content", (), 1),
    ("vae", (), 11),
    ("style_extractor", (), 1),
    ("clusterstyle_style", (), 1),
    ("clusterstyle_t2m", ("vae",), 9),
    ("clusterstyle", ("clusterstyle_t2m", "clusterstyle_style", "vae"), 10),
    ("contrastive", (), 24),
    ("adain", (), 5),
    ("dsdn", ("adain",), 2),
    ("mcm_ldm", ("vae", "style_extractor"), 12),
)}
POLL_SECONDS = 2.0


def command(name: str) -> list:
    """The training command of one checkpoint."""
    return [sys.executable, "-m", "mslib.cpu_paths", sys.executable, "-m", "mslib", "train", name,
            "--preset", "course", "--seed", str(COURSE[name][0]), "--json"]


def plan(names) -> list:
    """`names` in an order where every job comes after the checkpoints it reads (those outside `names` are
    taken as trained), longest first among the ready ones."""
    unknown = sorted(set(names) - set(COURSE))
    if unknown:
        raise ValueError(f"--only: unknown checkpoints {unknown}; known {sorted(COURSE)}")
    todo, order = set(names), []
    while todo:
        ready = [n for n in todo if not set(COURSE[n][1]) & todo]
        nxt = max(sorted(ready), key=lambda n: COURSE[n][2])
        order.append(nxt)
        todo.remove(nxt)
    return order


def run(names, jobs: int, logs: Path) -> dict:
    """Run the plan on `jobs` lanes; {name: {"started", "seconds", "returncode", "log"}} (seconds; "started"
    from the start of the run). Starts no job after a failure."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    start = time.time()
    logs.mkdir(parents=True, exist_ok=True)
    waiting, running, done, failed = plan(names), {}, {}, False
    while waiting or running:
        ready = [n for n in waiting if not set(COURSE[n][1]) & (set(waiting) | set(running))]
        while ready and len(running) < jobs and not failed:
            name = ready.pop(0)
            waiting.remove(name)
            log = logs / f"{name}.log"
            proc = subprocess.Popen(command(name), cwd=ROOT, env=env, stdout=log.open("w"), stderr=subprocess.STDOUT)
            running[name] = (proc, time.time(), log)
            print(f"started {name} (seed {COURSE[name][0]})", flush=True)
        if failed and not running:
            break
        time.sleep(POLL_SECONDS)
        for name, (proc, t0, log) in list(running.items()):
            if proc.poll() is not None:
                done[name] = {"started": round(t0 - start, 1), "seconds": round(time.time() - t0, 1),
                              "returncode": proc.returncode, "log": str(log)}
                failed |= proc.returncode != 0
                del running[name]
                print(f"{name}: {'ok' if proc.returncode == 0 else 'FAILED, see ' + str(log)} "
                      f"in {done[name]['seconds']:.0f} s", flush=True)
    return done


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--jobs", type=int, default=2, help="jobs at once (one core each)")
    ap.add_argument("--only", default=",".join(COURSE), help="comma-separated checkpoints (default: all)")
    ap.add_argument("--logs", default=str(Path(tempfile.gettempdir()) / "mslib_train_all"),
                    help="folder for each job's output (default: %(default)s)")
    ap.add_argument("--summary", default=None, help="write {name: seconds, …} here as JSON")
    ap.add_argument("--dry-run", action="store_true", help="print the commands in plan order and stop")
    ap.add_argument("--force", action="store_true", help="write over the packaged checkpoints")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error(f"--jobs: must be at least 1, got {args.jobs}")
    try:
        order = plan([n for n in args.only.split(",") if n])
    except ValueError as e:
        ap.error(str(e))
    if args.dry_run:
        for name in order:
            print(" ".join(["python"] + command(name)[4:]))
        return 0
    from mslib.checkpoints import course_path
    present = [n for n in order if course_path(n).is_file()]
    if present and not args.force:
        ap.error(f"would write over the packaged checkpoints {present}; pass --force to retrain them")
    done = run(order, args.jobs, Path(args.logs))
    if args.summary:
        Path(args.summary).write_text(json.dumps(done, indent=1) + "\n")
    return 0 if all(d["returncode"] == 0 for d in done.values()) and len(done) == len(order) else 1


if __name__ == "__main__":
    raise SystemExit(main())
