"""Offscreen z-buffer renderer for the pictures in the docs (numpy + pillow only).

Usage: python docs/render.py mesh.ply out.png [azimuth_deg] [elevation_deg] [wire]
       python docs/render.py a.ply,b.ply,... out.png [...]   (side by side, same view)
Reads binary little-endian or ASCII PLY as vstree writes it. Back faces are drawn brown."""
import sys, struct, numpy as np
from PIL import Image

TYPES = {'float': '<f4', 'float32': '<f4', 'double': '<f8', 'float64': '<f8', 'uchar': 'u1', 'uint8': 'u1',
         'char': 'i1', 'int8': 'i1', 'ushort': '<u2', 'uint16': '<u2', 'short': '<i2', 'int16': '<i2',
         'uint': '<u4', 'uint32': '<u4', 'int': '<i4', 'int32': '<i4'}

def read_ply(path):
    """Vertices (n, 3) and triangles (m, 3) of a triangle PLY: ASCII or binary little endian,
    any scalar vertex properties (x, y, z first), faces as a list of 3 indices."""
    data = open(path, 'rb').read()
    head_end = data.index(b'end_header') + len(b'end_header\n')
    header = data[:head_end].decode().splitlines()
    nv = nf = 0; props = []; fmt = 'binary_little_endian'; cur = None; count_t = index_t = 'u1'
    for l in header:
        t = l.split()
        if not t: continue
        if t[0] == 'format': fmt = t[1]
        if t[0] == 'element': cur = t[1]; n = int(t[2]); nv = n if cur == 'vertex' else nv; nf = n if cur == 'face' else nf
        if t[0] == 'property' and cur == 'vertex': props.append((t[-1], TYPES[t[1]]))
        if t[0] == 'property' and cur == 'face' and t[1] == 'list': count_t, index_t = TYPES[t[2]], TYPES[t[3]]
    body = data[head_end:]
    if fmt == 'ascii':
        lines = body.decode().split('\n')
        V = np.array([[float(x) for x in lines[i].split()[:3]] for i in range(nv)])
        F = np.array([[int(x) for x in lines[nv+i].split()[1:4]] for i in range(nf)]) if nf else np.zeros((0,3),int)
        return V, F
    vt = np.dtype([(name, typ) for name, typ in props])
    vs = np.frombuffer(body[:nv*vt.itemsize], dtype=vt)
    V = np.stack([vs['x'], vs['y'], vs['z']], 1).astype(float)
    ft = np.dtype([('n', count_t), ('i', index_t, (3,))])
    F = np.frombuffer(body[nv*vt.itemsize:nv*vt.itemsize + nf*ft.itemsize], dtype=ft)['i'].astype(int) if nf else np.zeros((0,3),int)
    return V, F

def render(V, F, az=30, el=20, wire=False, W=700):
    a, e = np.radians(az), np.radians(el)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    R = np.array([[1, 0, 0], [0, np.cos(e), -np.sin(e)], [0, np.sin(e), np.cos(e)]]) @ R
    c = (V.max(0) + V.min(0)) / 2; s = (V.max(0) - V.min(0)).max()
    P = (V - c) / s @ R.T
    img = np.full((W, W, 3), 255, np.uint8); z = np.full((W, W), -1e9)
    xy = (P[:, :2] * 0.9 + 0.5) * W; xy[:, 1] = W - xy[:, 1]
    tri = P[F]; n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]); n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-12
    light = np.array([0.3, 0.5, 1.0]); light /= np.linalg.norm(light)
    shade = np.clip(n @ light, 0, 1) * 0.8 + 0.2
    back = n[:, 2] < 0
    for k in np.argsort(tri[:, :, 2].mean(1)):
        p = xy[F[k]]; zz = P[F[k], 2]
        x0, y0 = np.floor(p.min(0)).astype(int); x1, y1 = np.ceil(p.max(0)).astype(int)
        x0, y0 = max(x0, 0), max(y0, 0); x1, y1 = min(x1, W-1), min(y1, W-1)
        if x1 < x0 or y1 < y0: continue
        X, Y = np.meshgrid(np.arange(x0, x1+1) + .5, np.arange(y0, y1+1) + .5)
        d = (p[1,1]-p[2,1])*(p[0,0]-p[2,0]) + (p[2,0]-p[1,0])*(p[0,1]-p[2,1])
        if abs(d) < 1e-12: continue
        l0 = ((p[1,1]-p[2,1])*(X-p[2,0]) + (p[2,0]-p[1,0])*(Y-p[2,1])) / d
        l1 = ((p[2,1]-p[0,1])*(X-p[2,0]) + (p[0,0]-p[2,0])*(Y-p[2,1])) / d
        l2 = 1 - l0 - l1
        m = (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
        zv = l0*zz[0] + l1*zz[1] + l2*zz[2]
        ys, xs = np.nonzero(m)
        ys += y0; xs += x0; zv = zv[m]
        upd = zv > z[ys, xs]
        ys, xs, zv = ys[upd], xs[upd], zv[upd]
        z[ys, xs] = zv
        col = np.array([200, 120, 60]) if back[k] else np.array([120, 170, 220])
        cc = (col * shade[k]).astype(np.uint8)
        if wire:
            lm = np.minimum(np.minimum(l0, l1), l2)[m][upd]
            edge = lm < 0.06
            img[ys, xs] = cc; img[ys[edge], xs[edge]] = (30, 30, 30)
        else:
            img[ys, xs] = cc
    return img

az = float(sys.argv[3]) if len(sys.argv) > 3 else 30
el = float(sys.argv[4]) if len(sys.argv) > 4 else 20
images = [render(*read_ply(path), az, el, len(sys.argv) > 5) for path in sys.argv[1].split(',')]
Image.fromarray(np.concatenate(images, axis=1)).save(sys.argv[2])
