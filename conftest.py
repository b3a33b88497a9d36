"""pytest at the project root: nbval's notebook kernels start with one numeric code path (mslib.cpu_paths)."""
from mslib.cpu_paths import pin_cpu_code_paths


def pytest_configure(config):
    pin_cpu_code_paths()  # before any kernel starts: the stored outputs were written the same way
