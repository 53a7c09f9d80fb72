"""Integer type tags for the flat scene arrays (one module, so kernels agree)."""

# Object kinds (obj_i[:, OBJ_KIND]).  Boxes and rotated rects are stored as
# RECT (a parallelogram with perpendicular edges), so only two kinds remain.
SPHERE = 0
RECT = 1

# Columns of obj_i.
OBJ_KIND = 0
OBJ_MAT = 1

# Material kinds (mat_i).
LAMBERTIAN = 0
METAL = 1
DIELECTRIC = 2
DIFFUSE_LIGHT = 3
PHONG = 4            # the classic ray tracer's material (classic.py)

# Background kinds.
BG_COLOR = 0
BG_SKY = 1

# "No object": closest_hit found nothing / a ray that starts at no surface.
NO_HIT = -1

# Classic (Computer Graphics from Scratch) light kinds.
AMBIENT = 0
POINT = 1
DIRECTIONAL = 2
