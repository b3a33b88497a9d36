"""Safe file writing: atomic replace, never overwrite without permission."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np


def check_writable(path, force: bool = False, arg: str = "output") -> Path:
    """Refuse an existing output unless `force`; make the parent folder."""
    path = Path(path)
    if path.exists() and not force:
        raise ValueError(f"{arg} {path} already exists; pass --force (force=True) to overwrite it")
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def file_digest(path) -> str:
    """The first 12 hex digits of a file's SHA-256: which file a stored result read."""
    import hashlib
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:12]


def atomic_write_bytes(path, data: bytes) -> None:
    """Write bytes to a temporary file beside `path`, then rename it into place."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file ordinary permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_save_npy(path, array, force: bool = False, arg: str = "output") -> Path:
    """np.save that is atomic and refuses to overwrite unless `force`."""
    import io
    path = check_writable(path, force, arg)
    buf = io.BytesIO()
    np.save(buf, np.asarray(array))
    atomic_write_bytes(path, buf.getvalue())
    return path


def load_npy(path, arg: str = "input") -> np.ndarray:
    """np.load without pickles, with a ValueError naming the file when it can't be read."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{arg} {path}: no such file")
    try:
        return np.load(path, allow_pickle=False)
    except Exception as e:  # corrupt header, pickled object arrays, truncated data
        raise ValueError(f"{arg} {path}: not a readable .npy array ({e})") from None
