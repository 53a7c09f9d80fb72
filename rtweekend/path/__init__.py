"""The path tracer of the books: packing (layout, pack), the kernels (shapes,
bvh, materials, pdf, camera, integrator, film, kernel) and the Renderer that
holds one image being rendered."""
