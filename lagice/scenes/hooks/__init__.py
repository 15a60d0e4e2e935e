"""Small ``module:function`` hooks of the bundled scenes (``examples/*.toml``):
what a scene needs beyond data — a time-series diagnostic, a wind pattern, a
domain shape, a prescribed velocity, a figure. No hook runs a time loop."""
