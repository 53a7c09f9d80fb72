"""What a kind of material is, in the terms the estimators ask about
(materials.has): one bit each, declared by each kind's module (its FLAGS), so
that no estimator tests a kind.  A new kind says which apply to it; an
estimator that needs another distinction adds a flag here."""
DELTA = 1      # sampled only, never evaluated: no density (metal, the books' glass)
EMITS = 2      # emits light from its front side and scatters none (a diffuse light)
JOIN = 4       # bidirectional strategies may join a subpath there (bdpt.py)
PHOTON = 8     # the caustic photon maps keep photons there, and the camera reads them
FORKS = 16    # a delta material with two branches the light-seen pass follows both of
MEDIUM = 32    # a medium's phase function, met inside a volume, never on a surface
GLOSSY = 64    # a glossy lobe (microfacets): compiled into a scene's kernels only
               # when one of its materials has it (SceneArrays.glossy)
REFRACTS = 128  # a smooth interface a chain of refractions crosses (manifold.py)
