#!/usr/bin/env python3
"""Scenes with nothing to learn: every light is seen from everything, nothing occludes. Where the promise
"bayes no worse than 0.9x of the best fixed sampler" is tested beyond the Cornell box (stop 59: a review found
bayes at 0.10-0.47x in four of them; README, Choosing a light sampler).

    tools/simple_scenes.py OUTDIR      writes OUTDIR/NAME.{obj,mtl,json} for the names below

one_quad      one quad lamp over a floor
two_lamps     a bright small lamp and a dim large one (200:1)
grid64        64 small equal lamps in a grid over an open floor
split450      one 3x3 lamp split into 450 triangles (split8 / split32 / split128 / split242: the same lamp in fewer)
sun           a ground lit by a sun alone (one light: bayes is power sampling)
sun_lamp      the ground, the sun and one small lamp
ring32        32 lamps in a ring around a sphere (orientation, not occlusion)
glossy16      a glossy floor under 16 lamps of graded power
"""
import json
import math
import os
import sys


class Mesh:
    def __init__(self):
        self.v, self.faces, self.mats = [], [], {}

    def material(self, name, kd, ke=None, ks=None, ns=None):
        self.mats[name] = (kd, ke, ks, ns)

    def face(self, mat, *pts):  # counter-clockwise seen from the side the normal points to
        base = len(self.v) + 1
        self.v += pts
        self.faces.append((mat, list(range(base, base + len(pts)))))

    def write(self, out, name):
        with open(os.path.join(out, name + ".mtl"), "w") as f:
            for m, (kd, ke, ks, ns) in self.mats.items():
                f.write("newmtl %s\nKd %g %g %g\n" % ((m,) + tuple(kd)))
                if ke:
                    f.write("Ke %g %g %g\n" % tuple(ke))
                if ks:
                    f.write("Ks %g %g %g\nNs %g\n" % (tuple(ks) + (ns,)))
        with open(os.path.join(out, name + ".obj"), "w") as f:
            f.write("mtllib %s.mtl\n" % name)
            for p in self.v:
                f.write("v %.6f %.6f %.6f\n" % tuple(p))
            current = None
            for m, idx in self.faces:
                if m != current:
                    f.write("usemtl %s\n" % m)
                    current = m
                f.write("f " + " ".join(map(str, idx)) + "\n")


def floor(m, half=5.0, mat="white"):  # y = 0, facing +y
    m.face(mat, (-half, 0, -half), (-half, 0, half), (half, 0, half), (half, 0, -half))


def lamp_down(m, mat, cx, y, cz, hx, hz=None):  # a quad at height y facing -y
    hz = hz or hx
    m.face(mat, (cx - hx, y, cz - hz), (cx + hx, y, cz - hz), (cx + hx, y, cz + hz), (cx - hx, y, cz + hz))


def scene(out, name, eye=(0, 3.5, 8), target=(0, 0, 0), sun=None):
    desc = {"mesh": name + ".obj", "camera": {"eye": list(eye), "target": list(target), "fov_y_deg": 50},
            "image": {"width": 160, "height": 120}, "render": {"spp": 64, "max_depth": 1, "seed": 0}}
    if sun:
        desc["sun"] = sun
    with open(os.path.join(out, name + ".json"), "w") as f:
        json.dump(desc, f, indent=1)


def plain(ke):
    m = Mesh()
    m.material("white", (0.7, 0.7, 0.7))
    m.material("lamp", (0.5, 0.5, 0.5), ke=ke)
    return m


def split_lamp(out, name, n):  # a 3x3 lamp 4 above the floor in 2 n^2 triangles
    m = plain((5, 5, 5))
    floor(m)
    step = 3.0 / n
    for i in range(n):
        for j in range(n):
            x, z = -1.5 + i * step, -1.5 + j * step
            m.face("lamp", (x, 4, z), (x + step, 4, z), (x + step, 4, z + step))
            m.face("lamp", (x, 4, z), (x + step, 4, z + step), (x, 4, z + step))
    m.write(out, name)
    scene(out, name)


def main(out):
    os.makedirs(out, exist_ok=True)
    sun = {"direction": [0.4, 1, 0.3], "irradiance": [3, 3, 3], "angular_diameter_deg": 0.53}

    m = plain((10, 10, 10))
    floor(m)
    lamp_down(m, "lamp", 0, 4, 0, 1)
    m.write(out, "one_quad")
    scene(out, "one_quad")

    m = plain((1, 1, 1.2))
    m.material("bright", (0.5, 0.5, 0.5), ke=(200, 180, 160))
    floor(m)
    lamp_down(m, "bright", -2, 4, 0, 0.3)
    lamp_down(m, "lamp", 2, 4, 0, 1.0)
    m.write(out, "two_lamps")
    scene(out, "two_lamps")

    m = plain((20, 20, 20))
    floor(m)
    for i in range(8):
        for j in range(8):
            lamp_down(m, "lamp", -3.5 + i, 4, -3.5 + j, 0.1)
    m.write(out, "grid64")
    scene(out, "grid64")

    for n, name in ((2, "split8"), (4, "split32"), (8, "split128"), (11, "split242"), (15, "split450")):
        split_lamp(out, name, n)

    m = plain((1, 1, 1))
    floor(m, half=20)
    m.write(out, "sun")
    scene(out, "sun", sun=sun)

    m = plain((30, 25, 20))
    floor(m, half=20)
    lamp_down(m, "lamp", 0, 2, 0, 0.15)
    m.write(out, "sun_lamp")
    scene(out, "sun_lamp", sun=sun)

    m = plain((8, 8, 8))
    rings, segments = 24, 48
    def on_sphere(u, v):
        theta, phi = math.pi * v / rings, 2 * math.pi * u / segments
        return (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
    for u in range(segments):
        for v in range(rings):
            a, b, c, d = on_sphere(u, v), on_sphere(u + 1, v), on_sphere(u + 1, v + 1), on_sphere(u, v + 1)
            if v > 0:
                m.face("white", a, c, b)
            if v < rings - 1:
                m.face("white", a, d, c)
    for k in range(32):  # lamps 0.4 wide, 4 from the axis, facing it
        phi = 2 * math.pi * k / 32
        cx, cz, tx, tz = 4 * math.cos(phi), 4 * math.sin(phi), -math.sin(phi), math.cos(phi)
        p = [(cx + s * 0.2 * tx, t * 0.2, cz + s * 0.2 * tz) for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        m.face("lamp", *p)
    m.write(out, "ring32")
    scene(out, "ring32", eye=(0, 1.2, 3.2))

    m = Mesh()
    m.material("gloss", (0.3, 0.3, 0.3), ks=(0.4, 0.4, 0.4), ns=40)
    for k in range(16):
        m.material("lamp%d" % k, (0.5, 0.5, 0.5), ke=(2 + 3 * k,) * 3)
    floor(m, mat="gloss")
    for i in range(4):
        for j in range(4):
            lamp_down(m, "lamp%d" % (4 * i + j), -3 + 2 * i, 3, -3 + 2 * j, 0.15)
    m.write(out, "glossy16")
    scene(out, "glossy16", eye=(0, 2.2, 8))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
