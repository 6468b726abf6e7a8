"""Where work runs and how finished work is kept: :mod:`hovering.parallel.checkpoint`."""
