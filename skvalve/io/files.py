"""Atomic file writes: a temporary file beside the target, then one rename.

An interrupted run never leaves a partial file under the final name, and concurrent writers never
share a temporary name (process id plus a random token).
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable
from pathlib import Path

__all__ = ["replace_atomically"]


def replace_atomically(path, write: Callable[[Path], object]) -> Path:
    """Call ``write(temporary)`` for a temporary file beside ``path`` (same suffix), then rename it to ``path``.

    The temporary is removed if ``write`` fails (or is interrupted); the previous ``path``, if any, is kept.
    """
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.{secrets.token_hex(4)}.tmp{path.suffix}")
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return path
