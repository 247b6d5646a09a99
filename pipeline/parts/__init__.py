"""Parts: the canonical :class:`~pipeline.parts.part.Part` (stable id from its
normalised outline), part families and generators (``families``), and
outline readers for DXF and SVG (``outlines``).

Layer 1 of the pipeline: imports only ``kernels`` (geometry) and the
top-level utilities (``errors``, ...). See ``tests/house/test_layers.py``.
"""
