#!/usr/bin/env python3
"""Writes a room lit by emitters close to what they light, for measuring how points on large lights are sampled:
a 4 x 2.6 x 3 m room with a 2 x 1 m ceiling panel 4 cm below the ceiling, a 1 x 0.6 m wall washer 6 cm from the
red wall and facing it, and a 0.5 x 0.3 m panel 3 cm above a desk, facing down.
  tools/panel_scene.py OUT_DIR      -> OUT_DIR/panel.obj, panel.mtl, direct.json (depth 1), path.json (depth 5)
Standard library only. The files go to a build folder, never into git."""
import json
import os
import sys

MATERIALS = """newmtl floor
Kd 0.6 0.6 0.6
newmtl white
Kd 0.75 0.75 0.75
newmtl red
Kd 0.7 0.15 0.1
newmtl green
Kd 0.15 0.6 0.15
newmtl panel
Kd 0 0 0
Ke 6 6 5.5
newmtl washer
Kd 0 0 0
Ke 10 9 7
newmtl desklamp
Kd 0 0 0
Ke 20 20 20
"""


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: panel_scene.py OUT_DIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    verts, faces = [], []

    def quad(a, b, c, d, material):
        """Quad a b c d, counter-clockwise seen from the side it faces (an emitter's emitting side)."""
        i = len(verts) + 1
        verts.extend([a, b, c, d])
        faces.append((material, i))

    x_len, y_len, z_len = 4.0, 2.6, 3.0
    quad((0, 0, 0), (0, 0, z_len), (x_len, 0, z_len), (x_len, 0, 0), "floor")
    quad((0, y_len, 0), (x_len, y_len, 0), (x_len, y_len, z_len), (0, y_len, z_len), "white")  # ceiling
    quad((0, 0, 0), (x_len, 0, 0), (x_len, y_len, 0), (0, y_len, 0), "white")  # back wall
    quad((0, 0, 0), (0, y_len, 0), (0, y_len, z_len), (0, 0, z_len), "red")  # left wall
    quad((x_len, 0, 0), (x_len, 0, z_len), (x_len, y_len, z_len), (x_len, y_len, 0), "green")  # right wall
    y = y_len - 0.04
    quad((1, y, 1), (3, y, 1), (3, y, 2), (1, y, 2), "panel")  # faces down
    x = 0.06
    quad((x, 1.2, 1.8), (x, 1.8, 1.8), (x, 1.8, 0.8), (x, 1.2, 0.8), "washer")  # faces the red wall (-x)
    quad((2.5, 0.75, 0.3), (2.5, 0.75, 1.1), (3.7, 0.75, 1.1), (3.7, 0.75, 0.3), "white")  # desk top
    y = 0.78
    quad((2.8, y, 0.5), (3.3, y, 0.5), (3.3, y, 0.8), (2.8, y, 0.8), "desklamp")  # faces down
    with open(os.path.join(out, "panel.mtl"), "w") as f:
        f.write(MATERIALS)
    with open(os.path.join(out, "panel.obj"), "w") as f:
        f.write("mtllib panel.mtl\n")
        for v in verts:
            f.write("v %g %g %g\n" % v)
        for material, i in faces:
            f.write("usemtl %s\nf %d %d %d\nf %d %d %d\n" % (material, i, i + 1, i + 2, i, i + 2, i + 3))
    for mode, depth in (("direct", 1), ("path", 5)):
        scene = {"mesh": "panel.obj",
                 "camera": {"eye": [3.6, 1.5, 2.9], "target": [1.2, 0.9, 0.4], "up": [0, 1, 0], "fov_y_deg": 65},
                 "image": {"width": 320, "height": 240},
                 "render": {"spp": 64, "max_depth": depth, "seed": 0}}
        with open(os.path.join(out, mode + ".json"), "w") as f:
            json.dump(scene, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
