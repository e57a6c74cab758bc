#!/usr/bin/env python3
"""Writes a many-light stress scene (issue 5): N small emissive triangles (facing down) in a grid under a
100 m x 100 m ceiling, over a floor, with 16 emission levels spanning 3 decades, plus a few occluding walls.
  tools/stress_scene.py N OUT_DIR      -> OUT_DIR/stress_N.obj, .mtl, direct.json
Deterministic (fixed seed); standard library only. The files go to a build folder, never into git."""
import os
import random
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: stress_scene.py N OUT_DIR")
    n = int(sys.argv[1])
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    name = "stress_%d" % n
    rng = random.Random(12345)
    with open(os.path.join(out, name + ".mtl"), "w") as m:
        m.write("newmtl floor\nKd 0.5 0.5 0.5\n")
        m.write("newmtl wall\nKd 0.4 0.4 0.4\n")
        for k in range(16):
            le = 10 ** (3 * k / 15)
            m.write("newmtl lamp%d\nKd 0 0 0\nKe %.4g %.4g %.4g\n" % (k, le, le * 0.9, le * 0.8))
    lines = ["mtllib %s.mtl\n" % name, "usemtl floor\n",
             "v -50 0 -50\nv -50 0 50\nv 50 0 50\nv 50 0 -50\nf 1 2 3 4\n"]
    vcount = 4
    # Occluders: 9 walls 3 m high across the room.
    lines.append("usemtl wall\n")
    for i in range(9):
        x = -40 + 10 * i
        lines.append("v %g 0 -30\nv %g 3 -30\nv %g 3 30\nv %g 0 30\n" % (x, x, x, x))
        lines.append("f %d %d %d %d\n" % (vcount + 1, vcount + 2, vcount + 3, vcount + 4))
        lines.append("f %d %d %d %d\n" % (vcount + 4, vcount + 3, vcount + 2, vcount + 1))
        vcount += 4
    side = int(n ** 0.5 + 0.999999)
    pitch = 98.0 / side
    s = min(0.05, 0.4 * pitch)
    written = 0
    chunk = []
    for level in range(16):
        chunk.append("usemtl lamp%d\n" % level)
        for i in range(level, n, 16):
            gx, gz = i % side, i // side
            x = -49 + pitch * (gx + rng.random() * 0.5)
            z = -49 + pitch * (gz + rng.random() * 0.5)
            y = 4 + rng.random()
            # Counter-clockwise seen from below: the emitting side faces -y.
            chunk.append("v %.5f %.5f %.5f\nv %.5f %.5f %.5f\nv %.5f %.5f %.5f\nf %d %d %d\n" %
                         (x, y, z, x + s, y, z, x, y, z + s, vcount + 1, vcount + 2, vcount + 3))
            vcount += 3
            written += 1
            if len(chunk) > 65536:
                lines.append("".join(chunk))
                chunk = []
    lines.append("".join(chunk))
    with open(os.path.join(out, name + ".obj"), "w") as f:
        f.writelines(lines)
    with open(os.path.join(out, "direct.json"), "w") as f:
        f.write('{\n  "mesh": "%s.obj",\n  "camera": {"eye": [0, 2, 45], "target": [0, 1.5, 0], "fov_y_deg": 60},\n'
                '  "image": {"width": 160, "height": 120},\n  "render": {"spp": 4, "max_depth": 1, "seed": 0}\n}\n'
                % name)
    print("%s: %d emissive triangles" % (os.path.join(out, name + ".obj"), written))


if __name__ == "__main__":
    main()
