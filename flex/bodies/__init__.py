"""Bodies: beam theory, plate meshes and FE modes, Craig-Bampton reductions, the nonlinear FE
coupler, the spring.
"""
