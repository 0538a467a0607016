#!/usr/bin/env python3
"""The <collision> capsules of robots/ur5e.urdf and robots/panda.urdf, from the makers' collision
meshes: for each link, the smallest capsule along one of the link frame's axes (through the
centre of the mesh's box) that holds every vertex, edge midpoint and face centroid, its ends
rounded to 1 mm and its radius then rounded up to the next 1 mm with at least 0.1 mm to spare.
Prints each link's capsule (in the rccx URDF's link frame) and how far inside the mesh's points
stay.

    python3 scripts/capsules_from_meshes.py UR_MESHES PANDA_MESHES

UR_MESHES: Universal_Robots_ROS2_Description's meshes/ur5e/collision (base.stl ... wrist3.stl);
PANDA_MESHES: franka_ros's franka_description/meshes/collision (link0.stl ... link7.stl).
Plain Python, no numpy.
"""
import math
import struct
import sys


def stl(path):
    """The triangles of an STL file, binary or text."""
    b = open(path, 'rb').read()
    if b[:5] == b'solid' and b'facet' in b[:300]:
        pts = [tuple(map(float, line.split()[1:4])) for line in b.decode().splitlines()
               if line.split()[:1] == ['vertex']]
        return [pts[i:i + 3] for i in range(0, len(pts), 3)]
    n = struct.unpack('<I', b[80:84])[0]
    return [[v[3:6], v[6:9], v[9:12]] for v in
            (struct.unpack('<12f', b[84 + 50 * i:84 + 50 * i + 48]) for i in range(n))]


def rpy(r, p, y, xyz=(0, 0, 0)):
    """URDF's origin: Rot(z, y) Rot(y, p) Rot(x, r), then the translation."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    R = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
         [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
         [-sp, cp * sr, cp * cr]]
    return [R[0] + [xyz[0]], R[1] + [xyz[1]], R[2] + [xyz[2]], [0, 0, 0, 1]]


def app(T, v):
    return tuple(sum(T[i][k] * v[k] for k in range(3)) + T[i][3] for i in range(3))


def seg_dist(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    L = sum(x * x for x in ab)
    t = 0 if L == 0 else max(0, min(1, sum(ab[i] * ap[i] for i in range(3)) / L))
    return math.dist(p, [a[i] + t * ab[i] for i in range(3)])


def points(tris, T):
    out = []
    for t in tris:
        v = [app(T, x) for x in t]
        out += v
        out.append(tuple(sum(x[i] for x in v) / 3 for i in range(3)))
        out += [tuple((v[a][i] + v[b][i]) / 2 for i in range(3)) for a, b in ((0, 1), (1, 2), (2, 0))]
    return out


def best_capsule(pts):
    lo = [min(p[i] for p in pts) for i in range(3)]
    hi = [max(p[i] for p in pts) for i in range(3)]
    c = [(lo[i] + hi[i]) / 2 for i in range(3)]
    best = None
    for u in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
        ts = [sum((p[i] - c[i]) * u[i] for i in range(3)) for p in pts]
        ds = [math.sqrt(max(0, sum((p[i] - c[i] - t * u[i]) ** 2 for i in range(3)))) for p, t in zip(pts, ts)]
        rmin = max(ds)
        for k in range(200):
            R = rmin * (1 + k * 0.01)
            s1 = max(t - math.sqrt(R * R - d * d) for t, d in zip(ts, ds))
            s0 = min(t + math.sqrt(R * R - d * d) for t, d in zip(ts, ds))
            if s0 > s1:
                s0 = s1 = (s0 + s1) / 2
            a = [c[i] + s0 * u[i] for i in range(3)]
            b = [c[i] + s1 * u[i] for i in range(3)]
            r = max(seg_dist(p, a, b) for p in pts)
            vol = math.pi * r * r * math.dist(a, b) + 4 / 3 * math.pi * r ** 3
            if best is None or vol < best[0]:
                best = (vol, a, b, r)
    _, a, b, _ = best
    a = [round(x, 3) for x in a]
    b = [round(x, 3) for x in b]
    r = math.ceil((max(seg_dist(p, a, b) for p in pts) + 1e-4) * 1000) / 1000
    return a, b, r


def report(name, pts):
    a, b, r = best_capsule(pts)
    inside = -max(seg_dist(p, a, b) - r for p in pts)
    print(f'{name}: from {a} to {b} radius {r} m; the mesh stays {inside * 1000:.2f} mm inside')


pi = math.pi
# The UR5e: ur_macro.xacro's mesh origins in its link frames, and its link frames in ours (the
# DH frames of robots/ur5e.urdf): the same orientation, shifted along z by 0.1625 (shoulder),
# 0.1333 (wrist 1), 0.0997 (wrist 2) and 0.0996 m (wrist 3); base_link_inertia is our base_link.
ur = [('base_link', 'base', rpy(0, 0, pi), 0), ('shoulder_link', 'shoulder', rpy(0, 0, pi), 0.1625),
      ('upper_arm_link', 'upperarm', rpy(pi / 2, 0, -pi / 2, (0, 0, 0.138)), 0),
      ('forearm_link', 'forearm', rpy(pi / 2, 0, -pi / 2, (0, 0, 0.007)), 0),
      ('wrist_1_link', 'wrist1', rpy(pi / 2, 0, 0, (0, 0, -0.127)), 0.1333),
      ('wrist_2_link', 'wrist2', rpy(0, 0, 0, (0, 0, -0.0997)), 0.0997),
      ('wrist_3_link', 'wrist3', rpy(pi / 2, 0, 0, (0, 0, -0.0989)), 0.0996)]
for link, mesh, origin, shift in ur:
    T = [row[:] for row in origin]
    T[2][3] += shift
    report(f'ur5e {link}', points(stl(f'{sys.argv[1]}/{mesh}.stl'), T))
# The Panda: franka_description's meshes are in its link frames, which are robots/panda.urdf's.
for k in range(8):
    report(f'panda panda_link{k}', points(stl(f'{sys.argv[2]}/link{k}.stl'), rpy(0, 0, 0)))
