"""Motion layer: rotations, skeletons and FK, the 263-d HumanML3D vector, BVH files."""
