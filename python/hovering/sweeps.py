"""Old home of the checkpoints: :mod:`hovering.parallel.checkpoint` (the one checkpoint format)."""

from .parallel.checkpoint import Checkpoint, check_row  # noqa: F401

__all__ = ["Checkpoint", "check_row"]
