#!/usr/bin/env python3
"""Writes configs/models/patrol_boat.obj: a 20 m patrol boat built from convex solids, and
configs/models/patrol_boat_stack.obj: its stack alone, 2 cm wider and taller, so that a second
entity with a hot material (configs/flir.yaml) can cover the boat's own stack.

Axes follow glTF: +Y up, +Z forward (bow), +X to port; metres; the waterline is y = 0.
Each solid is convex, so outward face winding is fixed by comparing each face's Newell
normal with the direction from the solid's centroid to the face's centroid.
"""
import math
import os
import sys


def newell(poly):
    nx = ny = nz = 0.0
    for i, (x0, y0, z0) in enumerate(poly):
        x1, y1, z1 = poly[(i + 1) % len(poly)]
        nx += (y0 - y1) * (z0 + z1)
        ny += (z0 - z1) * (x0 + x1)
        nz += (x0 - x1) * (y0 + y1)
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    return (nx / length, ny / length, nz / length)


def centroid(points):
    n = float(len(points))
    return tuple(sum(p[i] for p in points) / n for i in range(3))


class Obj:
    def __init__(self):
        self.v, self.vn, self.faces = [], [], []

    def solid(self, name, faces):
        """faces: polygons (lists of xyz tuples) of one convex solid, any winding."""
        body = centroid([p for f in faces for p in f])
        self.faces.append(("o", name))
        for poly in faces:
            n = newell(poly)
            c = centroid(poly)
            outward = sum(n[i] * (c[i] - body[i]) for i in range(3))
            if outward < 0:
                poly = list(reversed(poly))
                n = tuple(-x for x in n)
            self.vn.append(n)
            ni = len(self.vn)
            idx = []
            for p in poly:
                self.v.append(p)
                idx.append(len(self.v))
            self.faces.append(("f", [(i, ni) for i in idx]))

    def prism(self, name, outline, y0, y1):
        """Vertical prism: outline is a convex list of (x, z) points."""
        bottom = [(x, y0, z) for x, z in outline]
        top = [(x, y1, z) for x, z in outline]
        faces = [bottom, top]
        for i in range(len(outline)):
            j = (i + 1) % len(outline)
            faces.append([bottom[i], bottom[j], top[j], top[i]])
        self.solid(name, faces)

    def write(self, path, what="20 m patrol boat"):
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            f.write(f"# seasense example model: {what} (scripts/make_example_model.py)\n")
            f.write("# glTF axes: +Y up, +Z forward (bow), +X port; metres; waterline y = 0\n")
            for x, y, z in self.v:
                f.write(f"v {x:.4f} {y:.4f} {z:.4f}\n")
            for x, y, z in self.vn:
                f.write(f"vn {x:.6f} {y:.6f} {z:.6f}\n")
            for kind, data in self.faces:
                if kind == "o":
                    f.write(f"o {data}\n")
                else:
                    f.write("f " + " ".join(f"{v}//{n}" for v, n in data) + "\n")
        os.replace(tmp, path)


def stack_outline(radius):
    """Octagonal stack aft of the bridge."""
    return [(radius * math.cos(a), -5.5 + radius * math.sin(a))
            for a in (2 * math.pi * k / 8 for k in range(8))]


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "configs", "models")
    os.makedirs(folder, exist_ok=True)
    m = Obj()
    # Hull: 20 m long, 5 m beam, pointed bow, 1 m draft, 1.6 m freeboard.
    hull = [(2.5, -10.0), (2.5, 5.0), (0.0, 10.0), (-2.5, 5.0), (-2.5, -10.0)]
    m.prism("hull", hull, -1.0, 1.6)
    # Superstructure (bridge) amidships.
    bridge = [(1.8, -4.0), (1.8, 2.0), (-1.8, 2.0), (-1.8, -4.0)]
    m.prism("bridge", bridge, 1.6, 4.2)
    m.prism("stack", stack_outline(0.6), 1.6, 6.0)
    m.write(os.path.join(folder, "patrol_boat.obj"))
    # The stack for its own material: 2 cm outside the boat's stack on every side but the
    # bottom, which stands on the deck.
    s = Obj()
    s.prism("stack", stack_outline(0.62), 1.6, 6.02)
    s.write(os.path.join(folder, "patrol_boat_stack.obj"), "stack of the 20 m patrol boat")


if __name__ == "__main__":
    main()
