"""One numeric code path on every x86-64 CPU with AVX2, so outputs stored on one machine can match on another.

PyTorch, MKL, oneDNN, OpenBLAS and numpy each pick, at run time, the widest kernels the CPU offers
(AVX-512 where there is one), and those round differently: the same notebook on an AVX2 and on an
AVX-512 machine prints numbers that differ in the last digits, which strict nbval reports as failures
(seen here: notebooks 02, 04, 06 and 07 after a change of machine). The variables below cap each
library at AVX2 (checked so far on an AVX2 machine only: there they change nothing, and an SSE-level
cap does change the digits, so the libraries read them). They must be set before a library loads, so
they act on processes started afterwards: the root `conftest.py` sets them for nbval's kernels,
`tools/build_notebooks.py` for the kernels that write the stored outputs. Variables already set are left alone; CPUs without AVX2 are left alone.
"""
from __future__ import annotations

import os
import platform
from pathlib import Path

PINNED_CPU_ENV = {
    "ATEN_CPU_CAPABILITY": "avx2",        # PyTorch's own vectorised kernels
    "MKL_CBWR": "AVX2",                   # MKL's reproducible-results mode (PyTorch's BLAS)
    "ONEDNN_MAX_CPU_ISA": "AVX2",         # oneDNN (PyTorch's convolutions)
    "OPENBLAS_CORETYPE": "Haswell",       # the OpenBLAS of numpy and scipy
    "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",  # numpy's own SIMD loops
}


def has_avx2(machine: str | None = None, cpuinfo: str | None = None) -> bool:
    """Whether this is an x86-64 CPU with AVX2 (read from /proc/cpuinfo; False where it cannot tell)."""
    if (machine or platform.machine()).lower() not in ("x86_64", "amd64"):
        return False
    if cpuinfo is None:
        path = Path("/proc/cpuinfo")
        cpuinfo = path.read_text(errors="replace") if path.is_file() else ""
    flags = next((line.split(":", 1)[1].split() for line in cpuinfo.splitlines() if line.startswith("flags")), [])
    return "avx2" in flags


def pin_cpu_code_paths(environ=None, avx2: bool | None = None) -> dict:
    """Set PINNED_CPU_ENV in `environ` (default os.environ) where unset, on AVX2 CPUs; returns what it set."""
    environ = os.environ if environ is None else environ
    if not (has_avx2() if avx2 is None else avx2):
        return {}
    added = {k: v for k, v in PINNED_CPU_ENV.items() if k not in environ}
    environ.update(added)
    return added


def main(argv=None) -> None:
    """`python -m mslib.cpu_paths COMMAND ...`: run COMMAND with the pinned code path (`make lab` does)."""
    import sys
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        raise SystemExit("usage: python -m mslib.cpu_paths COMMAND [ARGS ...]")
    pin_cpu_code_paths()
    os.execvp(argv[0], argv)


if __name__ == "__main__":
    main()
