"""Where work runs and how finished work is kept.

:class:`Executor` (the one ``executor=`` argument: local threads, a Dask cluster, pieces, a
checkpoint) lives in :mod:`hovering.parallel.executor`; the one checkpoint format (JSON lines keyed
by a canonical record of the parameters) in :mod:`hovering.parallel.checkpoint`.
"""

from .checkpoint import Checkpoint
from .executor import Executor, as_executor

__all__ = ["Executor", "as_executor", "Checkpoint"]
