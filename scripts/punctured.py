#!/usr/bin/env python3
"""Punctured test inputs: closed meshes of known genus with random holes punched in their surface,
the rest broken into pieces, some pieces flipped or duplicated, for measuring whether roar recovers
the genus of the object. Every input is remade exactly from its (object, seed).

    python3 scripts/punctured.py --out DIR [--objects torus,trefoil,...] [--seeds 0-9] [--data PATH]

Default: every object below, seeds 0-9. Objects (each checked when built to be closed, one
component, consistently and outward oriented, with no pinched vertex, of the genus its Euler
characteristic gives):

    rocker-arm   genus 1  20088 faces  DATA/clean/rocker-arm.obj
    fertility    genus 4   9000 faces  DATA/clean/fertility.off
    spot         genus 0   5856 faces  DATA/clean/spot.obj
    torus        genus 1  13056 faces  R = 1, r = 0.35, parametric
    thin-torus   genus 1  13312 faces  R = 1, r = 0.15, parametric
    trefoil      genus 1  14400 faces  tube of radius 0.36 (0.12 x 3, the knot's largest distance
                                       from its centre) around (sin t + 2 sin 2t, cos t - 2 cos 2t,
                                       -sin 3t), rotation-minimizing frames; the curve's strands
                                       stay 1.21 apart and it bends no tighter than radius 1.29,
                                       so the tube does not meet itself
    double-torus genus 2  15132 faces  two tori (R = 1, r = 0.35, centres 2.3 apart) joined by a
                                       smooth minimum; its zero set by marching tetrahedra on a
                                       grid of step 0.12, crossings kept 5 % of a step off the
                                       grid points so no triangle is a sliver

Open sheets, written once each as NAME-sheet.obj (split `sheet`): `plane` (a flat square),
`open-box` (the unit cube without its lid) and `leaf` (a pointed oval, cupped and arched). They
enclose nothing and must come back as thin closed plates.

DATA is --data, else $ROAR_TEST_DATA, else ../shared/data/meshes beside the repository. An object
whose file is missing (or is not the closed mesh of its genus) is skipped with a warning.

For seed s every draw comes from random.Random("OBJECT:s") (string seeds are hashed with SHA-512,
so they do not depend on PYTHONHASHSEED), in this order:
  1. a target removed fraction of the area, uniform in [0.10, 0.40];
  2. holes until the target is reached: a seed face (area-weighted among the free faces: those
     with no vertex on an earlier hole) and rho = u * (local feature size), u uniform in
     [0.25, 0.5] (so a hole is at most as wide as the local feature size: a tube's holes are up to
     its radius wide), capped at 0.1 x the bounding-box diagonal; the hole is the breadth-first
     patch of edge-adjacent free faces whose centroid is within rho of the seed face's centroid.
     Holes never touch, so each is one gap no wider than its feature, never a merger of several.
     The last hole stops at the face that reaches the target, so the removed fraction exceeds the
     target by less than one face's area; it falls short only when no free face is left (coarse
     tessellations);
  3. k pieces, k uniform in [8, 30]: k seed faces among those left grow round-robin by
     breadth-first search over edge adjacency; faces no seed reaches form one piece per
     connected part. Each piece has its own copies of its vertices;
  4. each piece is flipped (faces reversed) with probability 0.2, and duplicated with
     probability 0.15: a second copy, reversed with probability 0.5, otherwise identical;
  5. the pieces (duplicates as pieces of their own) are shuffled.

Local feature size: for the procedural objects the tube radius; for the file meshes half the
distance from the seed face's centroid along its inward normal to the first surface hit (the local
half-thickness, the tube radius of a tube; rays walk a uniform grid of the faces), at least the
mean edge length, and 0.1 x the diagonal when the ray escapes.

Writes DIR/OBJECT-sSEED.obj for every object and seed, DIR/OBJECT-original.obj (the closed
outward mesh), and DIR/manifest.tsv, readable by `roar batch`, with the columns
    id  path  object  genus  puncture_seed  removed_fraction  pieces  flipped  duplicated  split
where pieces counts the pieces before duplication (the file holds pieces + duplicated separate
parts), flipped and duplicated count pieces, and split is `tune` for seeds 0-4, `report` for
later seeds and `original` for the originals (puncture_seed and removed_fraction empty, 1
piece). One line per written file goes to stderr.
"""
import argparse
import bisect
import collections
import itertools
import math
import os
import random
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
PROG = 'punctured.py'

REMOVED_RANGE = (0.10, 0.40)
RHO_RANGE = (0.25, 0.5)
RHO_CAP = 0.1            # of the bounding-box diagonal
PIECES_RANGE = (8, 30)
FLIP_P = 0.2
DUPLICATE_P = 0.15
DUPLICATE_REVERSED_P = 0.5
TUNE_SEEDS = 5           # seeds below this are the tune split, the others the report split
MANIFEST_COLUMNS = ('id', 'path', 'object', 'genus', 'puncture_seed', 'removed_fraction', 'pieces',
                    'flipped', 'duplicated', 'split')


# ---------------------------------------------------------------------------------------------
# Vectors

def sub(a, b):
    """a - b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    """a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(a, s):
    """s a."""
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    """a . b."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    """a x b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    """|a|."""
    return math.sqrt(dot(a, a))


def unit(a):
    """a / |a| (a itself when it is zero)."""
    n = norm(a)
    return scale(a, 1.0 / n) if n > 0 else a


def rotate(v, axis, angle):
    """v rotated by angle about the unit axis (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return add(add(scale(v, c), scale(cross(axis, v), s)), scale(axis, dot(axis, v) * (1 - c)))


# ---------------------------------------------------------------------------------------------
# Reading meshes

def fan(polygon):
    """The triangles of a polygon's fan from its first corner."""
    return [(polygon[0], polygon[i], polygon[i + 1]) for i in range(1, len(polygon) - 1)]


def read_obj(path):
    """Vertices and fan-triangulated faces of an OBJ file's `v` and `f` lines."""
    verts, faces = [], []
    with open(path, errors='replace') as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == 'v':
                verts.append((float(parts[1]), float(parts[2]), float(parts[3])))
            elif parts[0] == 'f':
                corners = [int(c.split('/')[0]) for c in parts[1:]]
                faces.extend(fan([i - 1 if i > 0 else len(verts) + i for i in corners]))
    return verts, faces


def read_off(path):
    """Vertices and fan-triangulated faces of an OFF file, counts on the header line or next."""
    with open(path, errors='replace') as f:
        lines = [l.split('#')[0].split() for l in f]
    lines = [l for l in lines if l]
    if not lines or not lines[0][0].endswith('OFF'):
        raise ValueError('%s: no OFF header' % path)
    counts, at = (lines[0][1:], 1) if len(lines[0]) > 1 else (lines[1], 2)
    nv, nf = int(counts[0]), int(counts[1])
    verts = [tuple(float(x) for x in l[:3]) for l in lines[at:at + nv]]
    faces = []
    for l in lines[at + nv:at + nv + nf]:
        faces.extend(fan([int(i) for i in l[1:1 + int(l[0])]]))
    return verts, faces


def read_stl(path):
    """Vertices (one per corner, unwelded) and triangles of a binary or ASCII STL file."""
    with open(path, 'rb') as f:
        data = f.read()
    corners = []
    count = struct.unpack_from('<I', data, 80)[0] if len(data) >= 84 else -1
    if len(data) == 84 + 50 * count:
        for i in range(count):
            corners.extend(struct.unpack_from('<3f', data, 84 + 50 * i + 12 + 12 * k)
                           for k in range(3))
    else:
        corners = [tuple(float(x) for x in line.split()[1:4])
                   for line in data.decode('latin-1').splitlines()
                   if line.strip().startswith('vertex')]
    corners = corners[:len(corners) - len(corners) % 3]
    return corners, [(i, i + 1, i + 2) for i in range(0, len(corners), 3)]


def read_mesh(path):
    """Vertices and triangles of an OBJ, OFF or STL file."""
    lower = path.lower()
    if lower.endswith('.off'):
        return read_off(path)
    return read_stl(path) if lower.endswith('.stl') else read_obj(path)


def compact(verts, faces):
    """The mesh without unreferenced vertices, indices renumbered in order of first use."""
    index, out_verts, out_faces = {}, [], []
    for face in faces:
        tri = []
        for v in face:
            if v not in index:
                index[v] = len(out_verts)
                out_verts.append(verts[v])
            tri.append(index[v])
        out_faces.append(tuple(tri))
    return out_verts, out_faces


# ---------------------------------------------------------------------------------------------
# Checking closed meshes

def signed_volume(verts, faces):
    """The volume the faces enclose, positive when they face outward."""
    return sum(dot(verts[a], cross(verts[b], verts[c])) for a, b, c in faces) / 6.0


def face_components(faces):
    """The number of edge-connected components of the faces."""
    parent = list(range(len(faces)))

    def find(i):
        """The representative of face i's set."""
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    first = {}
    for f, (a, b, c) in enumerate(faces):
        for e in ((a, b), (b, c), (c, a)):
            key = (min(e), max(e))
            if key in first:
                parent[find(f)] = find(first[key])
            else:
                first[key] = f
    return len({find(f) for f in range(len(faces))})


def vertex_links_are_cycles(faces):
    """Whether the faces around every vertex form one cycle (no pinched vertices)."""
    link = collections.defaultdict(dict)
    for a, b, c in faces:
        for v, p, q in ((a, b, c), (b, c, a), (c, a, b)):
            if p in link[v]:
                return False
            link[v][p] = q
    for succ in link.values():
        start = next(iter(succ))
        p, n = succ[start], 1
        while p != start:
            if p not in succ:
                return False
            p, n = succ[p], n + 1
        if n != len(succ):
            return False
    return True


def mesh_report(verts, faces):
    """Closedness, orientation, Euler characteristic, genus, components and volume of a mesh."""
    directed = collections.Counter()
    for a, b, c in faces:
        directed[(a, b)] += 1
        directed[(b, c)] += 1
        directed[(c, a)] += 1
    undirected = collections.Counter()
    for (a, b), n in directed.items():
        undirected[(min(a, b), max(a, b))] += n
    used = {v for face in faces for v in face}
    closed = all(n == 2 for n in undirected.values())
    oriented = all(n == 1 and (b, a) in directed for (a, b), n in directed.items())
    euler = len(used) - len(undirected) + len(faces)
    components = face_components(faces)
    manifold = closed and oriented and vertex_links_are_cycles(faces)
    return {
        'faces': len(faces), 'vertices': len(used), 'edges': len(undirected),
        'closed': closed, 'oriented': oriented, 'manifold': manifold, 'euler': euler,
        'components': components, 'genus': (2 * components - euler) / 2.0,
        'volume': signed_volume(verts, faces),
    }


def closed_genus_problem(report, genus):
    """Why a mesh report is not one closed outward surface of `genus`, or None."""
    if not report['closed']:
        return 'not closed'
    if not report['oriented']:
        return 'not consistently oriented'
    if not report['manifold']:
        return 'has a pinched vertex'
    if report['components'] != 1:
        return '%d components' % report['components']
    if report['genus'] != genus:
        return 'genus %g, not %d' % (report['genus'], genus)
    if report['volume'] <= 0:
        return 'not outward'
    return None


# ---------------------------------------------------------------------------------------------
# Procedural objects

def tube(centres, normals, binormals, radius, around):
    """A closed tube of rings of `around` vertices, outward for right-handed frames."""
    n = len(centres)
    verts = []
    for c, nn, bb in zip(centres, normals, binormals):
        for j in range(around):
            a = 2 * math.pi * j / around
            offset = add(scale(nn, radius * math.cos(a)), scale(bb, radius * math.sin(a)))
            verts.append(add(c, offset))
    faces = []
    for i in range(n):
        i2 = (i + 1) % n
        for j in range(around):
            j2 = (j + 1) % around
            p, q = i * around + j, i * around + j2
            r, s = i2 * around + j2, i2 * around + j
            faces.append((p, q, r))
            faces.append((p, r, s))
    return verts, faces


def torus(major, minor, along, around):
    """A torus about the z axis: `along` rings of `around` vertices."""
    centres, normals, binormals = [], [], []
    for i in range(along):
        u = 2 * math.pi * i / along
        centres.append((major * math.cos(u), major * math.sin(u), 0.0))
        normals.append((math.cos(u), math.sin(u), 0.0))
        binormals.append((0.0, 0.0, -1.0))   # tangent x normal
    return tube(centres, normals, binormals, minor, around)


def trefoil_point(t):
    """The trefoil knot curve at parameter t."""
    return (math.sin(t) + 2 * math.sin(2 * t), math.cos(t) - 2 * math.cos(2 * t), -math.sin(3 * t))


def trefoil_tangent(t):
    """The unit tangent of the trefoil curve at t."""
    return unit((math.cos(t) + 4 * math.cos(2 * t), -math.sin(t) + 4 * math.sin(2 * t),
                 -3 * math.cos(3 * t)))


def arc_length_parameters(curve, count, samples=20000):
    """`count` parameters in [0, 2 pi) equally spaced in arc length along the closed curve."""
    ts = [2 * math.pi * i / samples for i in range(samples + 1)]
    pts = [curve(t) for t in ts]
    cum = [0.0]
    for i in range(samples):
        cum.append(cum[-1] + norm(sub(pts[i + 1], pts[i])))
    out = []
    for k in range(count):
        s = cum[-1] * k / count
        i = min(bisect.bisect_right(cum, s) - 1, samples - 1)
        f = (s - cum[i]) / (cum[i + 1] - cum[i])
        out.append(ts[i] + f * (ts[i + 1] - ts[i]))
    return out


def closed_rotation_minimizing_frames(points, tangents):
    """Normals and binormals of rotation-minimizing frames along a closed polyline."""
    # Double reflection (Wang et al. 2008); the twist left when the loop closes is spread evenly.
    n = len(points)
    t0 = tangents[0]
    helper = (1.0, 0.0, 0.0) if abs(t0[0]) < 0.9 else (0.0, 1.0, 0.0)
    r = unit(cross(t0, helper))
    rs = [r]
    for i in range(n):
        x0, x1 = points[i], points[(i + 1) % n]
        ti, t1 = tangents[i], tangents[(i + 1) % n]
        v1 = sub(x1, x0)
        c1 = dot(v1, v1)
        r_l = sub(r, scale(v1, 2 * dot(v1, r) / c1))
        t_l = sub(ti, scale(v1, 2 * dot(v1, ti) / c1))
        v2 = sub(t1, t_l)
        c2 = dot(v2, v2)
        r = sub(r_l, scale(v2, 2 * dot(v2, r_l) / c2)) if c2 > 0 else r_l
        rs.append(r)
    twist = math.atan2(dot(cross(rs[0], rs[n]), t0), dot(rs[0], rs[n]))
    normals, binormals = [], []
    for i in range(n):
        nn = unit(rotate(rs[i], tangents[i], -twist * i / n))
        nn = unit(sub(nn, scale(tangents[i], dot(nn, tangents[i]))))
        normals.append(nn)
        binormals.append(cross(tangents[i], nn))
    return normals, binormals


TREFOIL_RADIUS = 0.12 * 3.0     # 0.12 x the knot's size: its points are at most 3 from its centre


def trefoil(along, around):
    """A tube of radius TREFOIL_RADIUS around the trefoil knot."""
    ts = arc_length_parameters(trefoil_point, along)
    points = [trefoil_point(t) for t in ts]
    tangents = [trefoil_tangent(t) for t in ts]
    normals, binormals = closed_rotation_minimizing_frames(points, tangents)
    return tube(points, normals, binormals, TREFOIL_RADIUS, around)


DOUBLE_TORUS = {'major': 1.0, 'minor': 0.35, 'centre': 1.15, 'blend': 0.2}


def double_torus_distance(x, y, z):
    """Signed distance-like function of two tori about x = -1.15 and 1.15, smoothly united."""
    d = DOUBLE_TORUS
    a = math.hypot(math.hypot(x - d['centre'], y) - d['major'], z) - d['minor']
    b = math.hypot(math.hypot(x + d['centre'], y) - d['major'], z) - d['minor']
    k = d['blend']
    h = max(k - abs(a - b), 0.0) / k
    return min(a, b) - h * h * k / 4


# The six tetrahedra of a cube around its diagonal 0-7 (corner bit 1: +x, 2: +y, 4: +z). The same
# split in every cube makes the tetrahedra of neighbouring cubes meet face to face.
KUHN_TETS = tuple((0, a, a | b, 7) for a, b in ((1, 2), (1, 4), (2, 1), (2, 4), (4, 1), (4, 2)))


# Where a crossing may lie on a grid edge, as a fraction of it: keeping crossings off the grid
# points keeps slivers out of the mesh (they move by at most this fraction of the step).
EDGE_CLAMP = 0.05


class MarchingTetrahedra:
    """The zero set of a function sampled on a grid, each cube cut into KUHN_TETS."""

    def __init__(self, func, lo, hi, step, iso):
        self.dims = [int(math.ceil((hi[a] - lo[a]) / step)) + 1 for a in range(3)]
        self.coords = [[lo[a] + i * step for i in range(self.dims[a])] for a in range(3)]
        xs, ys, zs = self.coords
        self.values = [func(x, y, z) - iso for x in xs for y in ys for z in zs]
        self.edge_vertex, self.verts, self.faces = {}, [], []

    def gid(self, i, j, k):
        """The index of grid point (i, j, k)."""
        return (i * self.dims[1] + j) * self.dims[2] + k

    def position(self, g):
        """The coordinates of grid point g."""
        ny, nz = self.dims[1], self.dims[2]
        return (self.coords[0][g // (ny * nz)], self.coords[1][(g // nz) % ny],
                self.coords[2][g % nz])

    def crossing(self, g, h):
        """The vertex where the zero set crosses grid edge g-h, made once per edge."""
        key = (g, h) if g < h else (h, g)
        v = self.edge_vertex.get(key)
        if v is None:
            pg, ph = self.position(g), self.position(h)
            t = self.values[g] / (self.values[g] - self.values[h])
            t = min(max(t, EDGE_CLAMP), 1 - EDGE_CLAMP)
            v = self.edge_vertex[key] = len(self.verts)
            self.verts.append(add(pg, scale(sub(ph, pg), t)))
        return v

    def emit(self, tri, inside, outside):
        """Adds a triangle, wound to face from the inside points towards the outside ones."""
        a, b, c = (self.verts[v] for v in tri)
        n = cross(sub(b, a), sub(c, a))
        side = sum(dot(sub(self.position(o), a), n) for o in outside)
        side -= sum(dot(sub(self.position(i), a), n) for i in inside)
        self.faces.append(tri if side > 0 else (tri[0], tri[2], tri[1]))

    def tetrahedron(self, corners):
        """Adds the zero set inside one tetrahedron of grid points: none, a triangle or a quad."""
        inside = [g for g in corners if self.values[g] < 0]
        outside = [g for g in corners if self.values[g] >= 0]
        if len(inside) in (1, 3):
            lone, rest = (inside[0], outside) if len(inside) == 1 else (outside[0], inside)
            self.emit(tuple(self.crossing(lone, g) for g in rest), inside, outside)
        elif len(inside) == 2:
            (i1, i2), (o1, o2) = inside, outside
            q = (self.crossing(i1, o1), self.crossing(i1, o2), self.crossing(i2, o2),
                 self.crossing(i2, o1))
            self.emit((q[0], q[1], q[2]), inside, outside)
            self.emit((q[0], q[2], q[3]), inside, outside)

    def run(self):
        """The vertices and faces of the zero set, cube by cube in grid order."""
        offsets = [self.gid(c & 1, (c >> 1) & 1, (c >> 2) & 1) for c in range(8)]
        nx, ny, nz = self.dims
        for i in range(nx - 1):
            for j in range(ny - 1):
                for k in range(nz - 1):
                    base = self.gid(i, j, k)
                    corners = [base + o for o in offsets]
                    inside = sum(1 for g in corners if self.values[g] < 0)
                    if 0 < inside < 8:
                        for tet in KUHN_TETS:
                            self.tetrahedron([corners[c] for c in tet])
        return self.verts, self.faces


def marching_tetrahedra(func, lo, hi, step, iso=1e-7):
    """The closed outward zero set of func - iso (negative inside) over the box lo..hi."""
    return MarchingTetrahedra(func, lo, hi, step, iso).run()


def double_torus(step):
    """The genus-2 surface of two fused tori, by marching tetrahedra at grid `step`."""
    d = DOUBLE_TORUS
    reach_x = d['centre'] + d['major'] + d['minor'] + 2 * step
    reach_y = d['major'] + d['minor'] + 2 * step
    reach_z = d['minor'] + 2 * step
    return marching_tetrahedra(double_torus_distance, (-reach_x, -reach_y, -reach_z),
                               (reach_x, reach_y, reach_z), step)


# ---------------------------------------------------------------------------------------------
# The objects

class Spec:
    """How to make one object: its genus, and a file or a builder taking a detail factor."""

    def __init__(self, genus, file=None, build=None, feature=None):
        self.genus, self.file, self.build, self.feature = genus, file, build, feature


def _res(n, detail, least=3):
    """A resolution n scaled by detail, at least `least`."""
    return max(least, int(round(n * detail)))


OBJECTS = collections.OrderedDict([
    ('rocker-arm', Spec(1, file='clean/rocker-arm.obj')),
    ('fertility', Spec(4, file='clean/fertility.off')),
    ('spot', Spec(0, file='clean/spot.obj')),
    ('torus', Spec(1, build=lambda d: torus(1.0, 0.35, _res(136, d), _res(48, d)), feature=0.35)),
    ('thin-torus', Spec(1, build=lambda d: torus(1.0, 0.15, _res(208, d), _res(32, d)),
                        feature=0.15)),
    ('trefoil', Spec(1, build=lambda d: trefoil(_res(300, d), _res(24, d)),
                     feature=TREFOIL_RADIUS)),
    ('double-torus', Spec(2, build=lambda d: double_torus(0.12 / d),
                          feature=DOUBLE_TORUS['minor'])),
])


def default_data_root():
    """$ROAR_TEST_DATA, else ../shared/data/meshes beside the repository."""
    return os.environ.get('ROAR_TEST_DATA') or os.path.join(REPO, '..', 'shared', 'data', 'meshes')


class MissingObject(Exception):
    """An object's file is absent or not the closed surface of its genus."""


def load_object(name, data_root=None, detail=1.0):
    """The closed outward mesh (vertices, faces) of an object, else MissingObject."""
    spec = OBJECTS[name]
    if spec.file is None:
        verts, faces = spec.build(detail)
    else:
        path = os.path.join(data_root or default_data_root(), spec.file)
        if not os.path.isfile(path):
            raise MissingObject('no file %s' % path)
        verts, faces = compact(*read_mesh(path))
        if signed_volume(verts, faces) < 0:
            faces = [(a, c, b) for a, b, c in faces]
    problem = closed_genus_problem(mesh_report(verts, faces), spec.genus)
    if problem:
        raise MissingObject('%s is %s' % (spec.file or name, problem))
    return verts, faces


# ---------------------------------------------------------------------------------------------
# Surface queries

class FaceGrid:
    """A uniform grid of the faces' bounding boxes, for casting rays."""

    def __init__(self, verts, faces):
        self.verts, self.faces = verts, faces
        self.lo = tuple(min(v[a] for v in verts) for a in range(3))
        hi = tuple(max(v[a] for v in verts) for a in range(3))
        extent = [max(hi[a] - self.lo[a], 1e-12) for a in range(3)]
        self.cell = (extent[0] * extent[1] * extent[2] / max(len(faces), 1)) ** (1 / 3.0) * 1.5
        self.dims = [max(1, int(math.ceil(e / self.cell))) for e in extent]
        self.cells = collections.defaultdict(list)
        for f, tri in enumerate(faces):
            ps = [verts[v] for v in tri]
            lo = [self.index(min(p[a] for p in ps), a) for a in range(3)]
            hi = [self.index(max(p[a] for p in ps), a) for a in range(3)]
            for i in range(lo[0], hi[0] + 1):
                for j in range(lo[1], hi[1] + 1):
                    for k in range(lo[2], hi[2] + 1):
                        self.cells[(i, j, k)].append(f)

    def index(self, x, axis):
        """The grid cell index of coordinate x along an axis, clamped to the grid."""
        return min(max(int((x - self.lo[axis]) / self.cell), 0), self.dims[axis] - 1)

    def hit(self, f, origin, direction):
        """Distance along the ray to face f, or None (Moller-Trumbore)."""
        a, b, c = (self.verts[v] for v in self.faces[f])
        e1, e2 = sub(b, a), sub(c, a)
        p = cross(direction, e2)
        det = dot(e1, p)
        if abs(det) < 1e-300:
            return None
        s = sub(origin, a)
        u = dot(s, p) / det
        if u < 0 or u > 1:
            return None
        q = cross(s, e1)
        v = dot(direction, q) / det
        if v < 0 or u + v > 1:
            return None
        t = dot(e2, q) / det
        return t if t > 0 else None

    def first_hit(self, origin, direction, skip):
        """Distance along a unit ray to the first face but `skip`, or None (3D DDA walk)."""
        cell = [self.index(origin[a], a) for a in range(3)]
        step, t_max, t_delta = [0] * 3, [math.inf] * 3, [math.inf] * 3
        for a in range(3):
            if direction[a] > 0:
                step[a] = 1
                t_max[a] = (self.lo[a] + (cell[a] + 1) * self.cell - origin[a]) / direction[a]
                t_delta[a] = self.cell / direction[a]
            elif direction[a] < 0:
                step[a] = -1
                t_max[a] = (self.lo[a] + cell[a] * self.cell - origin[a]) / direction[a]
                t_delta[a] = -self.cell / direction[a]
        best, seen = math.inf, {skip}
        while True:
            for f in self.cells.get(tuple(cell), ()):
                if f in seen:
                    continue
                seen.add(f)
                t = self.hit(f, origin, direction)
                if t is not None and t < best:
                    best = t
            a = min(range(3), key=lambda i: t_max[i])
            if best <= t_max[a]:
                return best
            cell[a] += step[a]
            if not 0 <= cell[a] < self.dims[a]:
                return best if best < math.inf else None
            t_max[a] += t_delta[a]


class Surface:
    """A closed mesh with the per-face data puncturing needs."""

    def __init__(self, name, verts, faces, feature=None):
        self.name, self.verts, self.faces = name, verts, faces
        self.genus = OBJECTS[name].genus if name in OBJECTS else None
        self.centroids, self.normals, self.areas = [], [], []
        for a, b, c in faces:
            pa, pb, pc = verts[a], verts[b], verts[c]
            n = cross(sub(pb, pa), sub(pc, pa))
            self.centroids.append(scale(add(add(pa, pb), pc), 1 / 3.0))
            self.areas.append(0.5 * norm(n))
            self.normals.append(unit(n))
        self.cumulative = []
        total = 0.0
        for area in self.areas:
            total += area
            self.cumulative.append(total)
        self.total_area = total
        self.neighbours = self._neighbours()
        lo = [min(v[a] for v in verts) for a in range(3)]
        hi = [max(v[a] for v in verts) for a in range(3)]
        self.diagonal = norm(sub(hi, lo))
        self.fixed_feature = feature
        self._grid, self._features = None, {}
        edges = {(min(p, q), max(p, q)) for a, b, c in faces for p, q in ((a, b), (b, c), (c, a))}
        self.mean_edge = sum(norm(sub(verts[p], verts[q])) for p, q in sorted(edges)) / len(edges)

    def _neighbours(self):
        """The edge-adjacent faces of every face, sorted."""
        by_edge = collections.defaultdict(list)
        for f, (a, b, c) in enumerate(self.faces):
            for p, q in ((a, b), (b, c), (c, a)):
                by_edge[(min(p, q), max(p, q))].append(f)
        out = [[] for _ in self.faces]
        for fs in by_edge.values():
            for f in fs:
                out[f].extend(g for g in fs if g != f)
        return [sorted(set(n)) for n in out]

    def feature_size(self, f):
        """The local feature size at face f (see the module docstring)."""
        if self.fixed_feature is not None:
            return self.fixed_feature
        if f not in self._features:
            if self._grid is None:
                self._grid = FaceGrid(self.verts, self.faces)
            t = self._grid.first_hit(self.centroids[f], scale(self.normals[f], -1.0), f)
            size = RHO_CAP * self.diagonal if t is None else max(0.5 * t, self.mean_edge)
            self._features[f] = size
        return self._features[f]

    def sample_face(self, rng):
        """A face drawn with probability proportional to its area."""
        i = bisect.bisect_right(self.cumulative, rng.random() * self.total_area)
        return min(i, len(self.faces) - 1)

    def sample_face_where(self, rng, keep):
        """A face drawn with probability proportional to its area among those `keep` accepts, or
        None when it accepts none. Draws from all faces first and lists the kept ones only when
        64 draws miss, so the common case costs no pass over the faces."""
        for _ in range(64):
            f = self.sample_face(rng)
            if keep(f):
                return f
        kept = [f for f in range(len(self.faces)) if keep(f)]
        if not kept:
            return None
        cumulative = list(itertools.accumulate(self.areas[f] for f in kept))
        i = bisect.bisect_right(cumulative, rng.random() * cumulative[-1])
        return kept[min(i, len(kept) - 1)]

    def patch(self, seed, radius, keep=lambda f: True):
        """Faces `keep` accepts with centroid within `radius` of seed's, reached breadth-first
        from seed over edge-adjacent accepted faces, in order."""
        centre = self.centroids[seed]
        r2 = radius * radius
        order, seen = [seed], {seed}
        queue = collections.deque([seed])
        while queue:
            f = queue.popleft()
            for g in self.neighbours[f]:
                if g in seen or not keep(g):
                    continue
                seen.add(g)
                d = sub(self.centroids[g], centre)
                if dot(d, d) <= r2:
                    order.append(g)
                    queue.append(g)
        return order


# ---------------------------------------------------------------------------------------------
# Puncturing

def punch_holes(surface, rng):
    """Removed flags, removed area and hole count after holes up to a drawn area fraction."""
    target = rng.uniform(*REMOVED_RANGE) * surface.total_area
    removed = bytearray(len(surface.faces))
    on_hole = bytearray(len(surface.verts))
    removed_area, holes = 0.0, 0
    cap = RHO_CAP * surface.diagonal

    def free(f):
        return not any(on_hole[v] for v in surface.faces[f])

    while removed_area < target:
        seed = surface.sample_face_where(rng, free)
        if seed is None:
            break
        rho = min(rng.uniform(*RHO_RANGE) * surface.feature_size(seed), cap)
        holes += 1
        hole = []
        for f in surface.patch(seed, rho, free):
            hole.append(f)
            removed_area += surface.areas[f]
            if removed_area >= target:
                break
        for f in hole:
            removed[f] = 1
            for v in surface.faces[f]:
                on_hole[v] = 1
    return removed, removed_area, holes


def flood(surface, removed, owner, seeds):
    """Round-robin breadth-first growth of pieces from their seeds over unowned faces left."""
    queues = []
    for piece, seed in seeds:
        owner[seed] = piece
        queues.append((piece, collections.deque([seed])))
    active = True
    while active:
        active = False
        for i, queue in queues:
            if not queue:
                continue
            active = True
            f = queue.popleft()
            for g in surface.neighbours[f]:
                if not removed[g] and owner[g] < 0:
                    owner[g] = i
                    queue.append(g)


def grow_pieces(surface, removed, rng):
    """The faces left in pieces grown from random seeds, plus one per part no seed reaches."""
    left = [f for f in range(len(surface.faces)) if not removed[f]]
    seeds = rng.sample(left, min(rng.randint(*PIECES_RANGE), len(left)))
    owner = [-1] * len(surface.faces)
    flood(surface, removed, owner, list(enumerate(seeds)))
    count = len(seeds)
    for f in left:
        if owner[f] < 0:
            flood(surface, removed, owner, [(count, f)])
            count += 1
    pieces = [[] for _ in range(count)]
    for f in left:
        pieces[owner[f]].append(f)
    return pieces


class Part:
    """One written piece: original face indices, whether reversed, and which piece it copies."""

    def __init__(self, faces, reversed_, piece, copy):
        self.faces, self.reversed, self.piece, self.copy = faces, reversed_, piece, copy


def flip_and_duplicate(pieces, rng):
    """The parts to write: pieces, some flipped, some with a second copy, shuffled."""
    parts = []
    for i, faces in enumerate(pieces):
        flip = rng.random() < FLIP_P
        parts.append(Part(faces, flip, i, False))
        if rng.random() < DUPLICATE_P:
            parts.append(Part(faces, flip != (rng.random() < DUPLICATE_REVERSED_P), i, True))
    rng.shuffle(parts)
    return parts


class Punctured:
    """A punctured input: its parts and the numbers the manifest records."""

    def __init__(self, surface, seed, parts, removed_area, removed_faces, pieces, holes):
        self.surface, self.seed, self.parts = surface, seed, parts
        self.removed_fraction = removed_area / surface.total_area
        self.removed_faces = removed_faces
        self.pieces = pieces
        self.holes = holes
        self.flipped = sum(1 for p in parts if not p.copy and p.reversed)
        self.duplicated = sum(1 for p in parts if p.copy)
        self.face_count = sum(len(p.faces) for p in parts)

    @property
    def id(self):
        """The input's id, OBJECT-sSEED."""
        return '%s-s%d' % (self.surface.name, self.seed)


def seeded_rng(name, seed):
    """The random generator of one object and seed."""
    return random.Random('%s:%d' % (name, seed))


def puncture(surface, seed):
    """The punctured input of a surface for a seed."""
    rng = seeded_rng(surface.name, seed)
    removed, removed_area, holes = punch_holes(surface, rng)
    pieces = grow_pieces(surface, removed, rng)
    parts = flip_and_duplicate(pieces, rng)
    return Punctured(surface, seed, parts, removed_area, sum(removed), len(pieces), holes)


# ---------------------------------------------------------------------------------------------
# Writing

def obj_text(verts, triangles, comment):
    """An OBJ file of vertices (%.9g) and 1-based triangles, after a comment line."""
    out = ['# %s\n' % comment]
    out.extend('v %.9g %.9g %.9g\n' % v for v in verts)
    out.extend('f %d %d %d\n' % (a + 1, b + 1, c + 1) for a, b, c in triangles)
    return ''.join(out)


def soup(punctured):
    """The vertices and triangles of a punctured input, each part with its own vertices."""
    surface = punctured.surface
    verts, triangles = [], []
    for part in punctured.parts:
        local = {}
        for f in part.faces:
            tri = []
            for v in surface.faces[f]:
                if v not in local:
                    local[v] = len(verts)
                    verts.append(surface.verts[v])
                tri.append(local[v])
            triangles.append((tri[0], tri[2], tri[1]) if part.reversed else tuple(tri))
    return verts, triangles


def punctured_obj(punctured):
    """The OBJ text of a punctured input."""
    verts, triangles = soup(punctured)
    comment = 'punctured %s, seed %d: %d pieces, %.4f of the area removed' % (
        punctured.surface.name, punctured.seed, punctured.pieces, punctured.removed_fraction)
    return obj_text(verts, triangles, comment)


def original_obj(surface):
    """The OBJ text of an object's closed outward mesh."""
    comment = '%s, closed, genus %d' % (surface.name, surface.genus)
    return obj_text(surface.verts, surface.faces, comment)


def split_of(seed):
    """The manifest split of a seed: tune for the first seeds, report for the others."""
    return 'tune' if seed < TUNE_SEEDS else 'report'


def manifest_row(punctured, path):
    """The manifest fields of a punctured input."""
    s = punctured.surface
    return [punctured.id, path, s.name, str(s.genus), str(punctured.seed),
            '%.4f' % punctured.removed_fraction, str(punctured.pieces), str(punctured.flipped),
            str(punctured.duplicated), split_of(punctured.seed)]


def original_row(surface, path):
    """The manifest fields of an object's original."""
    return ['%s-original' % surface.name, path, surface.name, str(surface.genus), '', '', '1',
            '0', '0', 'original']


def write_text(path, text):
    """Writes text to a file."""
    with open(path, 'w', newline='\n') as f:
        f.write(text)


# ---------------------------------------------------------------------------------------------
# Command line

class ArgumentError(Exception):
    """A bad command-line argument."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line."""

    def error(self, message):
        """Raises ArgumentError instead of printing the usage and exiting."""
        raise ArgumentError(message)


def parse_seeds(text):
    """Seeds from '0-9', '3' or '0,2,5-7', sorted and distinct."""
    seeds = set()
    for part in text.split(','):
        bounds = part.strip().split('-')
        if len(bounds) > 2 or not all(b.strip().isdigit() for b in bounds):
            raise ArgumentError('bad seeds %r (want e.g. 0-9 or 0,3,5-7)' % text)
        lo, hi = int(bounds[0]), int(bounds[-1])
        if lo > hi:
            raise ArgumentError('bad seed range %r' % part)
        seeds.update(range(lo, hi + 1))
    return sorted(seeds)


def parse_objects(text):
    """Object names from a comma-separated list, in the order given, each once."""
    names = []
    for name in (n.strip() for n in text.split(',')):
        if name not in OBJECTS:
            raise ArgumentError('unknown object %r (known: %s)' % (name, ', '.join(OBJECTS)))
        if name not in names:
            names.append(name)
    return names


def parse_args(argv):
    """The options of the command line."""
    p = Parser(prog=PROG, description='Writes punctured test inputs of known genus.')
    p.add_argument('--out', required=True, help='output folder')
    p.add_argument('--objects', default=','.join(OBJECTS), help='comma-separated object names')
    p.add_argument('--seeds', default='0-9', help='seeds, e.g. 0-9 or 0,3,5-7')
    p.add_argument('--data', default=None, help='folder holding clean/ (default $ROAR_TEST_DATA)')
    args = p.parse_args(argv)
    args.objects = parse_objects(args.objects)
    args.seeds = parse_seeds(args.seeds)
    return args


# ---------------------------------------------------------------------------------------------
# Open sheets: surfaces that enclose nothing, which must come back as thin closed plates

def grid_sheet(point, nu, nv):
    """An open sheet of (nu x nv) quads, two triangles each, over point(u, v) for u, v in [0, 1]."""
    verts = [point(i / nu, j / nv) for j in range(nv + 1) for i in range(nu + 1)]
    faces = []
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b, c, d = a + 1, a + nu + 2, a + nu + 1
            faces.extend([(a, b, c), (a, c, d)])
    return verts, faces


def plane_sheet():
    """A flat square sheet of side 2."""
    return grid_sheet(lambda u, v: (2 * u - 1, 2 * v - 1, 0.0), 40, 40)


def open_box():
    """The unit cube's five sides without its lid (+z), each a 20 x 20 grid, facing outward."""
    verts, faces = [], []
    sides = [  # corner, edge u, edge v; u x v points outward
        ((0, 0, 0), (0, 1, 0), (1, 0, 0)),   # bottom, -z
        ((0, 0, 0), (1, 0, 0), (0, 0, 1)),   # -y
        ((1, 1, 0), (-1, 0, 0), (0, 0, 1)),  # +y
        ((0, 1, 0), (0, -1, 0), (0, 0, 1)),  # -x
        ((1, 0, 0), (0, 1, 0), (0, 0, 1)),   # +x
    ]
    index = {}
    for o, du, dv in sides:
        v, f = grid_sheet(lambda u, w: add(o, add(scale(du, u), scale(dv, w))), 20, 20)
        ids = [index.setdefault(p, len(index)) for p in v]   # sides share their seams
        faces.extend(tuple(ids[k] for k in t) for t in f)
    verts = sorted(index, key=index.get)
    return verts, faces


def leaf():
    """A leaf-like open sheet: a pointed oval, cupped across and arched along its length."""
    def point(u, v):
        x = 2 * u - 1                        # along the leaf, -1..1
        half_width = 0.45 * (1 - x * x) ** 0.8
        y = (2 * v - 1) * half_width
        z = 0.35 * (y * y) / 0.2 - 0.15 * x * x   # cupped across, arched along
        return (x, y, z)
    return compact(*grid_sheet(point, 60, 16))


SHEETS = collections.OrderedDict([('plane', plane_sheet), ('open-box', open_box), ('leaf', leaf)])


def write_sheets(out, log=sys.stderr):
    """Writes DIR/NAME-sheet.obj for every open sheet; their manifest rows."""
    rows = []
    for name, make in SHEETS.items():
        verts, faces = make()
        path = '%s-sheet.obj' % name
        write_text(os.path.join(out, path), obj_text(verts, faces, '%s, an open sheet' % name))
        rows.append(['%s-sheet' % name, path, name, '', '', '', '1', '0', '0', 'sheet'])
        print('%s-sheet: %d faces' % (name, len(faces)), file=log)
    return rows


def generate(out, names, seeds, data_root=None, log=sys.stderr):
    """Writes the inputs and originals of the objects, the open sheets and the manifest; the
    manifest's rows."""
    os.makedirs(out, exist_ok=True)
    rows = write_sheets(out, log)
    for name in names:
        try:
            verts, faces = load_object(name, data_root)
        except MissingObject as e:
            print('%s: warning: skipping %s: %s' % (PROG, name, e), file=log)
            continue
        surface = Surface(name, verts, faces, OBJECTS[name].feature)
        path = '%s-original.obj' % name
        write_text(os.path.join(out, path), original_obj(surface))
        rows.append(original_row(surface, path))
        print('%s-original: %d faces, genus %d' % (name, len(faces), surface.genus), file=log)
        for seed in seeds:
            p = puncture(surface, seed)
            path = '%s.obj' % p.id
            write_text(os.path.join(out, path), punctured_obj(p))
            rows.append(manifest_row(p, path))
            print('%s: %d faces, %d pieces, %.1f%% removed'
                  % (p.id, p.face_count, p.pieces, 100 * p.removed_fraction), file=log)
    lines = ['\t'.join(MANIFEST_COLUMNS)] + ['\t'.join(r) for r in rows]
    write_text(os.path.join(out, 'manifest.tsv'), '\n'.join(lines) + '\n')
    return rows


def main(argv=None):
    """Runs the command line; the exit code."""
    try:
        args = parse_args(sys.argv[1:] if argv is None else argv)
    except ArgumentError as e:
        print('%s: error: %s' % (PROG, e), file=sys.stderr)
        return 2
    rows = generate(args.out, args.objects, args.seeds, args.data)
    if not rows:
        print('%s: error: no object could be made' % PROG, file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
