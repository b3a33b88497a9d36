"""Shared test fixtures: the real data in ../shared/data, read in place (never copied)."""
from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """../shared/data beside the clone; skips the test where it is absent (a student's clone)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real motion data not found at {SHARED_DATA} (only developers and CI have ../shared)")
    return SHARED_DATA
