"""The classic ray tracer of Computer Graphics from Scratch: its kernel
(kernel.py) and rendering a Scene with it (render.py)."""
