#!/usr/bin/env python3
"""Makes the compact copies of the reference meshes in this folder from the
OBJ files of ../shared/data/meshes (see README.md). Standard library only.

    python3 convert.py ../../../../shared/data/meshes
"""
import json, shutil, struct, sys
from pathlib import Path


def read_obj(path):
    """Vertices (as f32-rounded floats) and triangles (0-based) of a triangle OBJ."""
    v, f = [], []
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            v.append(tuple(struct.unpack("<3f", struct.pack("<3f", *map(float, w[1:4])))))
        elif w[0] == "f":
            idx = [int(t.split("/")[0]) - 1 for t in w[1:]]
            assert len(idx) == 3, "triangles only"
            f.append(idx)
    return v, f


def write_ply_z_up(path, v, f):
    """Binary little-endian PLY, turned from y-up to z-up: (x, y, z) -> (x, -z, y)."""
    head = (f"ply\nformat binary_little_endian 1.0\ncomment {path.stem}: converted from the y-up OBJ, z up\n"
            f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3f", x, -z, y) for x, y, z in v)
    body += b"".join(struct.pack("<B3i", 3, *t) for t in f)
    path.write_bytes(head + body)


def write_glb_y_up(path, v, f):
    """GLB, y-up as glTF requires, u16 indices (fewer than 65 536 vertices)."""
    assert len(v) < 65536
    pos = b"".join(struct.pack("<3f", *p) for p in v)
    idx = b"".join(struct.pack("<3H", *t) for t in f)
    idx += b"\0" * (-len(idx) % 4)
    lo = [min(p[i] for p in v) for i in range(3)]
    hi = [max(p[i] for p in v) for i in range(3)]
    doc = {"asset": {"version": "2.0", "generator": "evflow nodes/tests/data/convert.py"},
           "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": path.stem}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "buffers": [{"byteLength": len(pos) + len(idx)}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                           {"buffer": 0, "byteOffset": len(pos), "byteLength": 6 * len(f), "target": 34963}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3", "min": lo, "max": hi},
                         {"bufferView": 1, "componentType": 5123, "count": 3 * len(f), "type": "SCALAR"}]}
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary = pos + idx
    total = 12 + 8 + len(js) + 8 + len(binary)
    out = b"glTF" + struct.pack("<II", 2, total)
    out += struct.pack("<I", len(js)) + b"JSON" + js + struct.pack("<I", len(binary)) + b"BIN\0" + binary
    path.write_bytes(out)


src = Path(sys.argv[1])
here = Path(__file__).parent
shutil.copyfile(src / "suzanne.obj", here / "suzanne.obj")
write_ply_z_up(here / "fandisk.ply", *read_obj(src / "fandisk.obj"))
write_glb_y_up(here / "bunny.glb", *read_obj(src / "stanford-bunny.obj"))
