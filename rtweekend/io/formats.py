"""The image formats rtweekend writes, by extension (no imports: the command's
--help lists them without loading NumPy or imageio)."""

LDR = (".png", ".jpg", ".jpeg", ".bmp", ".tga")   # tone-mapped, 8 bits (imageio)
HDR = (".npy", ".exr")                             # linear radiance, float32
FORMATS = LDR + HDR
