"""The scenes bundled with rtweekend, as TOML files (see docs/scenes.md).

This file only makes the folder importable as `rtweekend.scenes`, so that the
scenes are found the same way from a source checkout and from an install.
"""
