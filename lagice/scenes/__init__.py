"""Scenes: TOML files (``examples/*.toml``, or any user file) plus small
``module:function`` hooks (:mod:`lagice.scenes.hooks`), built by
:mod:`lagice.scenes.builder` into a :class:`~lagice.simulation.Simulation`.

One registry (:func:`lagice.scenes.config.list_scenes`: the bundled TOML files
with their descriptions) and one override syntax (``--set table.key=value``)
for every scene.
"""
DEFAULT_SCENE = "uniaxial_compression"
