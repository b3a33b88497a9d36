"""mslib — the Motion Style Workbook library: papers A–D on motion style transfer."""
__version__ = "0.1.0"


def setup_notebook(seed: int = 0):
    """Seed everything and make notebook output stable for nbval."""
    from .notebook import setup_notebook as _setup
    return _setup(seed)
