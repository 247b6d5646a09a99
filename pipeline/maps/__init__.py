"""Configuration maps: the public rollout API over the kernels (``simulate``,
with the MuJoCo cross-check rig ``mujoco_rig``), the sweep that writes map
shards (``sweep``), shard and JSON files written atomically (``io``) and the
catalog that indexes the shards (``catalog``: the only way downstream reads
maps).

Imports parts, ``config`` and the top-level utilities; never planning or
anything above it.
"""
