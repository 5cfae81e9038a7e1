#!/usr/bin/env python3
"""Writes the fuzzers' seed inputs into fuzz/seeds/<target>/: a tetrahedron in every format
the readers take (PLY ascii and both binary byte orders, OBJ, OFF, XYZ), its PLY bodies in
each layout of fuzz_targets/ply_header.rs, and a few C-API inputs. Small on purpose; libFuzzer grows its working corpus under target/ from these.
Run: python3 fuzz/make_seeds.py (the output is committed)."""

import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
P = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
N = [(-0.577, -0.577, -0.577), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def ply_header(fmt, normals=True):
    lines = ["ply", "format %s 1.0" % fmt, "comment vstree fuzz seed", "element vertex 4"]
    lines += ["property float %s" % c for c in "xyz"]
    if normals:
        lines += ["property float n%s" % c for c in "xyz"]
    lines += ["element face 4", "property list uchar int vertex_indices", "end_header"]
    return ("\n".join(lines) + "\n").encode()


def ply_binary(order):
    out = ply_header("binary_%s_endian" % ("little" if order == "<" else "big"))
    for p, n in zip(P, N):
        out += struct.pack(order + "6f", *p, *n)
    for f in F:
        out += struct.pack(order + "B3i", 3, *f)
    return out


# The layouts of fuzz_targets/ply_header.rs, in its order: the coordinate type, normals,
# colours, and the face list (count type, index type, a flag byte after it), None without faces.
PLY_LAYOUTS = [
    ("f", False, False, ("B", "i", False)),
    ("f", True, False, ("B", "i", False)),
    ("d", False, False, ("i", "i", False)),
    ("f", False, False, None),
    ("f", False, True, ("B", "I", True)),
]


def ply_body_seed(index, order):
    """A body fuzzer's input for the tetrahedron: layout byte (plus 5 for big endian), the
    vertex and face counts, the body; `order` is None for ASCII."""
    coord, normals, colours, face = PLY_LAYOUTS[index]
    vertices = [list(p) + (list(n) if normals else []) + ([200, 100, 50] if colours else [])
                for p, n in zip(P, N)]
    faces = [[3, *f] + ([1] if face and face[2] else []) for f in F] if face else []
    if order is None:
        body = "".join(" ".join("%g" % v for v in row) + "\n" for row in vertices + faces).encode()
        selector = index
    else:
        vertex_format = order + coord * 3 + ("fff" if normals else "") + ("BBB" if colours else "")
        body = b"".join(struct.pack(vertex_format, *row) for row in vertices)
        if face:
            face_format = order + face[0] + face[1] * 3 + ("B" if face[2] else "")
            body += b"".join(struct.pack(face_format, *row) for row in faces)
        selector = index + (5 if order == ">" else 0)
    return bytes([selector, len(P), len(F)]) + body


def seeds():
    ply_ascii = ply_header("ascii", normals=False)
    ply_ascii += "".join("%g %g %g\n" % p for p in P).encode()
    ply_ascii += "".join("3 %d %d %d\n" % f for f in F).encode()
    obj = "".join("v %g %g %g\n" % p for p in P) + "".join("vn %g %g %g\n" % n for n in N)
    obj += "".join("f %d//%d %d//%d %d//%d\n" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1)
                   for a, b, c in F)
    off = "OFF\n4 4 6\n" + "".join("%g %g %g\n" % p for p in P)
    off += "".join("3 %d %d %d\n" % f for f in F)
    xyz = "".join("%g %g %g %g %g %g\n" % (*p, *n) for p, n in zip(P, N))
    files = {
        "ply": {"ascii.ply": ply_ascii, "le.ply": ply_binary("<"), "be.ply": ply_binary(">")},
        "obj": {"tetra.obj": obj.encode()},
        "off": {"tetra.off": off.encode()},
        "xyz": {"tetra.xyz": xyz.encode(), "points.xyz": b"0 0 0\n1 0 0\n0 1 0\n"},
    }
    files["ply_ascii_body"] = {"layout%d" % i: ply_body_seed(i, None) for i in range(len(PLY_LAYOUTS))}
    files["ply_binary_body"] = {
        "layout%d_%s" % (i, name): ply_body_seed(i, order)
        for i in range(len(PLY_LAYOUTS)) for order, name in (("<", "le"), (">", "be"))
    }
    # capi_load: a selector byte (0 ply, 1 obj, 2 off, 3 xyz) then the file.
    files["capi_load"] = {
        "ply": b"\x00" + ply_binary("<"),
        "obj": b"\x01" + obj.encode(),
        "off": b"\x02" + off.encode(),
        "xyz": b"\x03" + xyz.encode(),
    }
    # capi_arrays: n, t, flags, then 12 parameter/behaviour bytes, then the arrays.
    def arrays(flags, behaviour):
        head = bytes([4, 4, flags]) + bytes(behaviour)
        if flags & 1:
            body = bytes(int(v * 16) & 0xFF for p in P for v in p)
        else:
            body = b"".join(struct.pack("<3f", *p) for p in P)
        if flags & 2:
            body += bytes(int(v * 64) & 0xFF for n in N for v in n)
        body += bytes(i for f in F for i in f)
        return head + body

    def sphere_cloud(n):
        points = []
        for i in range(n):
            z = 1 - (2 * i + 1) / n
            r = math.sqrt(1 - z * z)
            a = math.pi * (3 - math.sqrt(5)) * i
            points.append((r * math.cos(a), r * math.sin(a), z))
        head = bytes([n, 0, 2]) + bytes(12)
        body = b"".join(struct.pack("<3f", *p) for p in points)
        body += bytes(int(v * 63) & 0xFF for p in points for v in p)
        return head + body

    files["capi_arrays"] = {
        "floats": arrays(0, [0] * 12),
        "ints_normals_progress": arrays(1 | 2 | 4, [0, 0, 1, 0, 1, 0, 33, 24, 1, 0, 3, 1]),
        "cancel": arrays(1 | 4, [0, 0, 0, 0, 0, 0, 0, 24, 0, 0, 2, 0]),
        # 120 points of a sphere with normals, no triangles: enough for vstree_reconstruct
        # (its parameter bytes follow the arrays; none here, so the first choice of each).
        "sphere_cloud": sphere_cloud(120),
    }
    return files


def main():
    for target, items in seeds().items():
        folder = os.path.join(HERE, "seeds", target)
        os.makedirs(folder, exist_ok=True)
        for name, data in items.items():
            with open(os.path.join(folder, name), "wb") as f:
                f.write(data)


if __name__ == "__main__":
    main()
