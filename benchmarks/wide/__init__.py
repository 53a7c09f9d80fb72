"""A measured prototype of SIMD over rays (wavefront / packet tracing) for rtweekend.

Not part of the package: a benchmark that answers "would rtweekend be faster if
it traced batches of rays in structure-of-arrays form, with branch-free
intersection loops that LLVM vectorises, and shading grouped by material?"

  jitopts.py    compile flags, a cycle counter for the phase profile
  wscene.py     the scene regrouped by primitive kind (SoA tables per kind)
  intersect.py  the vectorisable intersection loops (objects outer, rays inner),
                and a packet BVH walk for weekend
  wave.py       the wavefront renderer: camera wave, intersect, classify and
                sort by material (the compaction), shade per material, film;
                or (sort=False) one fused surface + shade + compaction pass
  scalar_profile.py  rtweekend's render_row with a cycle counter around
                closest_hit: the scalar kernel's intersection share
  check.py      correctness: same estimator as rtweekend (block means, references,
                determinism across thread counts)
  asm.py        counts packed SIMD instructions in the compiled kernels
  bench.py      the benchmark: scalar rtweekend vs this, alternated fresh processes
  paired.py     the same, pass by pass in one process (the ratios to trust)
  README.md     what was measured, and why it wins (weekend) or not (Cornell)
"""
