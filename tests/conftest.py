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

# A packaged method checkpoint trained on the built-in corpora from before their styles were fitted to real
# capture ([real-styles]): on the refitted corpora and under the retrained evaluator it misses a bar it met.
# [real-methods] retrains every checkpoint; these marks are strict, so a retrained one that passes fails
# loudly until its mark is removed.
TRAINED_ON_OLD_CORPORA = pytest.mark.xfail(
    strict=True, reason="checkpoint trained on the corpora before the fitted styles; retrained in [real-methods]")
