"""PLY files for tests/hosts, standard library only (runs with the host's python3).

  ply.py torus OUT.ply [MAJOR MINOR]   writes a closed triangulated torus (genus 1)
  ply.py torus-points OUT.ply [MAJOR MINOR]  the same torus's vertices only (a point cloud)
  ply.py obj2ply IN.obj OUT.ply       the OBJ's vertices and faces as binary PLY (MeshLab
                                       2020.09's OBJ reader aborts on some files)
  ply.py stats IN.ply|IN.obj           prints "vertices V faces F closed 0|1 euler X"
                                       (closed: every edge is on exactly two faces)
Reads ascii and binary_little_endian PLY with any scalar vertex properties and a face list,
and the v/f lines of OBJ.
"""

import math
import struct
import sys

TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


def torus(path, major=96, minor=32, r1=1.0, r2=0.35, with_faces=True):
    verts, faces = [], []
    for i in range(major):
        u = 2 * math.pi * i / major
        for j in range(minor):
            v = 2 * math.pi * j / minor
            verts.append(((r1 + r2 * math.cos(v)) * math.cos(u), (r1 + r2 * math.cos(v)) * math.sin(u), r2 * math.sin(v)))
    for i in range(major):
        for j in range(minor):
            a = i * minor + j
            b = ((i + 1) % major) * minor + j
            c = ((i + 1) % major) * minor + (j + 1) % minor
            d = i * minor + (j + 1) % minor
            faces += [(a, b, c), (a, c, d)]
    if not with_faces:
        faces = []
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(faces)))
        f.writelines("%.6f %.6f %.6f\n" % v for v in verts)
        f.writelines("3 %d %d %d\n" % t for t in faces)


def read_obj(path, positions=None):
    nverts, faces = 0, []
    with open(path, "rb") as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == b"v":
                nverts += 1
                if positions is not None:
                    positions.append(tuple(float(t) for t in w[1:4]))
            elif w[0] == b"f":  # 1-based, or negative (relative); v/vt/vn
                idx = [int(t.split(b"/")[0]) for t in w[1:]]
                faces.append([i - 1 if i > 0 else nverts + i for i in idx])
    return nverts, faces


def obj2ply(src, dst):
    positions = []
    _, faces = read_obj(src, positions)
    with open(dst, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                b"property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                % (len(positions), len(faces)))
        f.write(b"".join(struct.pack("<3f", *p) for p in positions))
        f.write(b"".join(struct.pack("<B%di" % len(t), len(t), *t) for t in faces))


def read(path):
    if path.lower().endswith(".obj"):
        return read_obj(path)
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    elements, fmt = [], None
    for line in data[:end].decode("ascii", "replace").splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(("list", w[2], w[3]) if w[1] == "list" else ("scalar", w[1]))
    if fmt not in ("ascii", "binary_little_endian"):
        raise SystemExit("%s: PLY format %s not read here" % (path, fmt))
    body = data[end:]
    faces, nverts = [], 0
    if fmt == "ascii":
        tokens = body.split()
        k = 0
        for name, count, props in elements:
            for _ in range(count):
                row = None
                for p in props:
                    if p[0] == "list":
                        n = int(tokens[k])
                        row = [int(t) for t in tokens[k + 1:k + 1 + n]]
                        k += 1 + n
                    else:
                        k += 1
                if name == "face":
                    faces.append(row)
            if name == "vertex":
                nverts = count
    else:
        off = 0
        for name, count, props in elements:
            for _ in range(count):
                row = None
                for p in props:
                    if p[0] == "list":
                        (n,) = struct.unpack_from("<" + TYPES[p[1]], body, off)
                        off += struct.calcsize(TYPES[p[1]])
                        row = list(struct.unpack_from("<%d%s" % (n, TYPES[p[2]]), body, off))
                        off += n * struct.calcsize(TYPES[p[2]])
                    else:
                        off += struct.calcsize(TYPES[p[1]])
                if name == "face":
                    faces.append(row)
            if name == "vertex":
                nverts = count
    return nverts, faces


def stats(path):
    nverts, faces = read(path)
    edges = {}
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1]):
            e = (min(a, b), max(a, b))
            edges[e] = edges.get(e, 0) + 1
    closed = bool(edges) and all(n == 2 for n in edges.values())
    used = len({i for f in faces for i in f})
    print("vertices %d faces %d closed %d euler %d" % (nverts, len(faces), closed, used - len(edges) + len(faces)))


if __name__ == "__main__":
    if sys.argv[1] == "torus":
        torus(sys.argv[2], *(int(a) for a in sys.argv[3:5]))
    elif sys.argv[1] == "torus-points":
        torus(sys.argv[2], *(int(a) for a in sys.argv[3:5]), with_faces=False)
    elif sys.argv[1] == "obj2ply":
        obj2ply(sys.argv[2], sys.argv[3])
    elif sys.argv[1] == "stats":
        stats(sys.argv[2])
    else:
        raise SystemExit(__doc__)
