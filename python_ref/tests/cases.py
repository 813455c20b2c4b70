"""The small tube case shared by the Python tests that drive `tubemem run` (L/R = 8, 16 around,
24 along, eighth model, inflated to lambda_s* = 1.2 in 4 steps)."""

GEOMETRY = """
[geometry]
radius = 1.0
length = 8.0
[material]
model = "abb"
shear_modulus = 1.0
kuhn = 30
"""
GENERATED_MESH = '[mesh]\naround = 16\nalong = 24\nsymmetry = "eighth"\n'
INFLATE = """
[[stage]]
kind = "inflate"
control = "volume"
target_stretch = 1.2
steps = 4
"""
SQUEEZE = """
[[stage]]
kind = "squeeze"
target_rho = 1.0
steps = 4
"""
SMALL = GEOMETRY + GENERATED_MESH + INFLATE
