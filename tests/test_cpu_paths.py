"""The pinned numeric code path: which CPUs get it, what it sets, and that kernels and commands inherit it."""
import os
import subprocess
import sys

import pytest

from mslib.cpu_paths import PINNED_CPU_ENV, has_avx2, pin_cpu_code_paths

ZEN = "processor\t: 0\nflags\t\t: fpu sse2 avx fma avx2 bmi2\n"
OLD = "processor\t: 0\nflags\t\t: fpu sse2 avx\n"


def test_avx2_is_read_from_the_cpu_flags():
    assert has_avx2("x86_64", ZEN) and has_avx2("AMD64", ZEN)
    assert not has_avx2("x86_64", OLD)
    assert not has_avx2("x86_64", "")          # cannot tell: leave the libraries alone
    assert not has_avx2("aarch64", ZEN)        # not x86: the caps mean nothing there


def test_pin_sets_only_what_is_unset_and_only_on_avx2():
    env = {"MKL_CBWR": "COMPATIBLE"}
    added = pin_cpu_code_paths(env, avx2=True)
    assert env["MKL_CBWR"] == "COMPATIBLE" and "MKL_CBWR" not in added   # the user's choice stays
    assert {k: env[k] for k in PINNED_CPU_ENV if k != "MKL_CBWR"} == added
    assert pin_cpu_code_paths(env, avx2=True) == {}                      # a second call changes nothing
    assert pin_cpu_code_paths({}, avx2=False) == {}


@pytest.mark.skipif(not has_avx2(), reason="this CPU has no AVX2: the code path is not pinned here")
def test_root_conftest_pins_this_run_and_commands_inherit_it():
    for key, value in PINNED_CPU_ENV.items():  # set before nbval starts a kernel (or the user's own value)
        assert key in os.environ, key
    env = {k: v for k, v in os.environ.items() if k not in PINNED_CPU_ENV}
    out = subprocess.run([sys.executable, "-m", "mslib.cpu_paths", sys.executable, "-c",
                          "import os, torch; print(os.environ['OPENBLAS_CORETYPE'], torch.backends.cpu.get_cpu_capability())"],
                         env=env, capture_output=True, text=True, check=True).stdout.split()
    assert out == ["Haswell", "AVX2"]
