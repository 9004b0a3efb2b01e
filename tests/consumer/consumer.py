"""The Python consumer of an installed embra (lib/python3/dist-packages/embra): the free fall of
consumer.c, checked against the same closed form. Prints "consumer ok" when it agrees."""

import sys

import embra

with embra.World(substeps=10) as world:
    body = world.create_body([(0.0, 0.0, 5.0)], mass=1.0)
    world.step(30)
    x, y, z = list(world.positions(body.first, 1).ravel() if embra.have_numpy() else world.positions(body.first, 1))
n, h = 300, (1.0 / 60.0) / 10
expected = 5.0 - 9.81 * h * h * n * (n + 1) / 2.0
print(f"embra {embra.version_string()} from {embra.library_path}: z = {z:.15f}, closed form {expected:.15f}")
if not (abs(z - expected) < 1e-10 and x == 0.0 and y == 0.0):
    sys.exit(1)
print("consumer ok")
