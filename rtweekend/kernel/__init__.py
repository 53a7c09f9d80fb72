"""What both integrators' kernels are made of: how they are compiled (jit), vec3
tuples, the counter-based random numbers, and the order rows go to threads."""
