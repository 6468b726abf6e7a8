"""Helpers shared by the test folders: independent references (``numpy_reference`` for the
truncated map, ``flow_reference`` for the flow) and the objects ``pickle_helpers`` builds.

``tests/conftest.py`` puts ``tests/`` on ``sys.path``, so every folder imports them as
``from helpers import numpy_reference as ref``.
"""
