#!/usr/bin/env python3
"""Tests of scripts/punctured.py: `python3 scripts/test_punctured.py` (standard library only, no
data files, some 20 seconds).

Only the procedural objects are used: their meshes are checked closed, oriented, outward and of
their genus, then punctured inputs are checked against the original mesh face by face."""
import collections
import importlib.util
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, 'punctured.py')

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
_spec = importlib.util.spec_from_file_location('punctured', SCRIPT)
pu = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pu)

PROCEDURAL = ('torus', 'thin-torus', 'trefoil', 'double-torus')
SMALL = 0.4   # tessellation detail of the quick tests


def run_script(*args):
    p = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)
    return p.returncode, p.stderr


def surface(name, detail=SMALL):
    verts, faces = pu.load_object(name, detail=detail)
    return pu.Surface(name, verts, faces, pu.OBJECTS[name].feature)


def parse_obj(text):
    """Vertex lines (as written) and 0-based triangles of an OBJ text."""
    verts, faces = [], []
    for line in text.splitlines():
        parts = line.split()
        if parts and parts[0] == 'v':
            verts.append(tuple(parts[1:]))
        elif parts and parts[0] == 'f':
            faces.append(tuple(int(i) - 1 for i in parts[1:]))
    return verts, faces


def vertex_groups(faces):
    """The indices into `faces` grouped by connection through shared vertex indices."""
    parent = {}

    def find(v):
        parent.setdefault(v, v)
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for a, b, c in faces:
        parent[find(a)] = find(b)
        parent[find(b)] = find(c)
    groups = collections.defaultdict(list)
    for k, face in enumerate(faces):
        groups[find(face[0])].append(k)
    return list(groups.values())


def vertex_components(faces):
    """The number of groups of faces connected through shared vertex indices."""
    return len(vertex_groups(faces))


def rotations(tri):
    return {tri, (tri[1], tri[2], tri[0]), (tri[2], tri[0], tri[1])}


class Objects(unittest.TestCase):
    def check_closed(self, name, detail):
        verts, faces = pu.OBJECTS[name].build(detail)
        r = pu.mesh_report(verts, faces)
        label = '%s at detail %g: %r' % (name, detail, r)
        self.assertTrue(r['closed'], label)
        self.assertTrue(r['oriented'], label)
        self.assertTrue(r['manifold'], label)
        self.assertEqual(r['components'], 1, label)
        self.assertEqual(r['euler'], 2 - 2 * pu.OBJECTS[name].genus, label)
        self.assertGreater(r['volume'], 0, label)
        return r

    def test_procedural_objects_are_closed_outward_surfaces_of_their_genus(self):
        for name in PROCEDURAL:
            for detail in (SMALL, 1.0):
                r = self.check_closed(name, detail)
                if detail == 1.0:
                    self.assertTrue(10000 <= r['faces'] <= 20000, (name, r['faces']))

    def test_torus_volume_is_close_to_the_exact_one(self):
        r = pu.mesh_report(*pu.OBJECTS['torus'].build(1.0))
        exact = 2 * math.pi ** 2 * 1.0 * 0.35 ** 2
        self.assertAlmostEqual(r['volume'] / exact, 1.0, delta=0.01)

    def test_trefoil_tube_keeps_its_radius_from_every_strand(self):
        # Every vertex lies at the tube radius from the curve point it was built around; a tube
        # crossing another strand would have vertices nearer than that to the curve.
        verts, _ = pu.OBJECTS['trefoil'].build(SMALL)
        radius = pu.TREFOIL_RADIUS
        samples = [pu.trefoil_point(2 * math.pi * i / 6000) for i in range(6000)]
        cells = collections.defaultdict(list)
        for p in samples:
            cells[tuple(int(math.floor(x / radius)) for x in p)].append(p)
        nearest = math.inf
        for v in verts:
            c = tuple(int(math.floor(x / radius)) for x in v)
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    for dz in (-1, 0, 1):
                        for p in cells.get((c[0] + dx, c[1] + dy, c[2] + dz), ()):
                            nearest = min(nearest, pu.norm(pu.sub(v, p)))
        self.assertGreater(nearest, 0.99 * radius)
        self.assertLess(nearest, 1.01 * radius)

    def test_trefoil_frames_turn_smoothly_and_close(self):
        ts = pu.arc_length_parameters(pu.trefoil_point, 120)
        points = [pu.trefoil_point(t) for t in ts]
        tangents = [pu.trefoil_tangent(t) for t in ts]
        normals, binormals = pu.closed_rotation_minimizing_frames(points, tangents)
        for i in range(len(ts)):
            j = (i + 1) % len(ts)
            self.assertGreater(pu.dot(normals[i], normals[j]), 0.95, i)
            self.assertAlmostEqual(pu.dot(normals[i], tangents[i]), 0.0, places=9)
            self.assertAlmostEqual(pu.dot(pu.cross(tangents[i], normals[i]), binormals[i]), 1.0,
                                   places=9)

    def test_ray_feature_size_of_a_torus_is_its_tube_radius(self):
        verts, faces = pu.OBJECTS['torus'].build(SMALL)
        s = pu.Surface('torus', verts, faces, feature=None)
        sizes = [s.feature_size(f) for f in range(0, len(faces), 5)]
        self.assertTrue(all(abs(x / 0.35 - 1) < 0.03 for x in sizes), (min(sizes), max(sizes)))


    def test_open_sheets_are_open_and_consistently_oriented(self):
        for name, make in pu.SHEETS.items():
            verts, faces = make()
            self.assertFalse(pu.mesh_report(verts, faces)['closed'], name)
            directed = collections.Counter((t[k], t[(k + 1) % 3]) for t in faces for k in range(3))
            self.assertEqual(set(directed.values()), {1}, name)   # consistently oriented
            self.assertEqual(pu.face_components(faces), 1, name)


class Readers(unittest.TestCase):
    def write(self, name, text):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        path = os.path.join(tmp.name, name)
        with open(path, 'w') as f:
            f.write(text)
        return path

    def test_obj_polygons_corner_syntax_and_negative_indices(self):
        path = self.write('a.obj', 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\n'
                                   'f 1/1/1 2/1/1 3//1 4\nv 0 0 1\nf -1 -5 -4\n')
        verts, faces = pu.read_obj(path)
        self.assertEqual(len(verts), 5)
        self.assertEqual(faces, [(0, 1, 2), (0, 2, 3), (4, 0, 1)])

    def test_off_with_counts_on_the_next_line_or_the_header(self):
        body = '0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n'
        for text in ('OFF\n# comment\n4 1 0\n' + body, 'OFF 4 1 0\n' + body):
            verts, faces = pu.read_off(self.write('a.off', text))
            self.assertEqual(len(verts), 4)
            self.assertEqual(faces, [(0, 1, 2), (0, 2, 3)])

    def test_binary_and_ascii_stl_give_the_same_corners(self):
        triangle = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.5)]
        binary = b'solid but binary'.ljust(80) + struct.pack('<I', 2)
        ascii_text = 'solid t\n'
        for _ in range(2):
            binary += struct.pack('<12fH', 0, 0, 1, *[x for c in triangle for x in c], 0)
            ascii_text += ('facet normal 0 0 1\nouter loop\n'
                           + ''.join('vertex %g %g %g\n' % c for c in triangle)
                           + 'endloop\nendfacet\n')
        ascii_text += 'endsolid t\n'
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        path = os.path.join(tmp.name, 'b.stl')
        with open(path, 'wb') as f:
            f.write(binary)
        for verts, faces in (pu.read_mesh(path), pu.read_mesh(self.write('a.stl', ascii_text))):
            self.assertEqual(verts, triangle + triangle)
            self.assertEqual(faces, [(0, 1, 2), (3, 4, 5)])


class Puncturing(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.surfaces = {name: surface(name) for name in PROCEDURAL}

    def cases(self):
        for name in PROCEDURAL:
            for seed in (0, 1, 7):
                yield self.surfaces[name], seed

    def test_removed_fraction_reaches_the_drawn_target_by_at_most_one_face(self):
        # The last hole stops at the face that reaches the target: the fraction is in
        # [target, target + largest face area / total area), target in [0.10, 0.40]; it falls
        # short only when every face left touches a hole.
        short = 0
        for s, seed in self.cases():
            removed, area, _ = pu.punch_holes(s, pu.seeded_rng(s.name, seed))
            target = pu.seeded_rng(s.name, seed).uniform(*pu.REMOVED_RANGE)
            slack = max(s.areas) / s.total_area
            self.assertTrue(0.10 <= target <= 0.40)
            self.assertLess(area / s.total_area, target + slack, (s.name, seed))
            if area / s.total_area < target - 1e-12:
                short += 1
                on_hole = {v for f, r in enumerate(removed) if r for v in s.faces[f]}
                free = [f for f in range(len(s.faces)) if not on_hole & set(s.faces[f])]
                self.assertEqual(free, [], (s.name, seed))
        self.assertLess(short, len(list(self.cases())), 'no case reached its target')

    def test_holes_stay_apart_so_each_is_one_patch_no_wider_than_its_feature(self):
        # No two holes share a vertex, so the removed faces fall into exactly as many
        # vertex-connected gaps as holes were punched; and each gap is one patch: its centroids lie
        # within 2 x the largest radius (0.5 x the tube radius) of each other.
        for s, seed in self.cases():
            removed, _, holes = pu.punch_holes(s, pu.seeded_rng(s.name, seed))
            gone = [f for f, r in enumerate(removed) if r]
            gaps = vertex_groups([s.faces[f] for f in gone])
            self.assertEqual(len(gaps), holes, (s.name, seed))
            self.assertGreater(holes, 1, (s.name, seed))
            widest = 2 * max(pu.RHO_RANGE) * s.feature_size(0)
            for gap in gaps:
                centroids = [s.centroids[gone[k]] for k in gap]
                span = max(pu.norm(pu.sub(a, b)) for a in centroids for b in centroids)
                self.assertLessEqual(span, widest + 1e-9, (s.name, seed))

class CommandLine(unittest.TestCase):
    def out_dir(self):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        return tmp.name

    def generate(self, *args):
        out = self.out_dir()
        code, err = run_script('--out', out, *args)
        self.assertEqual(code, 0, err)
        return out, err

    def read(self, out, name):
        with open(os.path.join(out, name), 'rb') as f:
            return f.read()

    def test_same_object_and_seed_give_identical_files_and_seeds_differ(self):
        args = ('--objects', 'torus,double-torus', '--seeds', '0-1')
        a, _ = self.generate(*args)
        b, _ = self.generate(*args)
        self.assertEqual(sorted(os.listdir(a)), sorted(os.listdir(b)))
        for name in os.listdir(a):
            self.assertEqual(self.read(a, name), self.read(b, name), name)
        for obj in ('torus', 'double-torus'):
            self.assertNotEqual(self.read(a, obj + '-s0.obj'), self.read(a, obj + '-s1.obj'))

    def test_manifest_lists_originals_and_inputs_with_their_splits(self):
        out, err = self.generate('--objects', 'thin-torus', '--seeds', '4-5')
        with open(os.path.join(out, 'manifest.tsv')) as f:
            lines = f.read().splitlines()
        self.assertEqual(lines[0].split('\t'), list(pu.MANIFEST_COLUMNS))
        rows = [dict(zip(pu.MANIFEST_COLUMNS, l.split('\t'))) for l in lines[1:]]
        sheets, rows = rows[:len(pu.SHEETS)], rows[len(pu.SHEETS):]
        self.assertEqual([r['id'] for r in sheets], [n + '-sheet' for n in pu.SHEETS])
        self.assertEqual({r['split'] for r in sheets}, {'sheet'})
        self.assertEqual([r['id'] for r in rows],
                         ['thin-torus-original', 'thin-torus-s4', 'thin-torus-s5'])
        self.assertEqual([r['split'] for r in rows], ['original', 'tune', 'report'])
        self.assertEqual([r['puncture_seed'] for r in rows], ['', '4', '5'])
        self.assertEqual(rows[0]['removed_fraction'], '')
        for r in rows:
            self.assertEqual(len(r), len(pu.MANIFEST_COLUMNS))
            self.assertEqual(r['genus'], '1')
            self.assertTrue(os.path.isfile(os.path.join(out, r['path'])), r['path'])
        for r in rows[1:]:
            _, faces = parse_obj(self.read(out, r['path']).decode())
            self.assertEqual(vertex_components(faces), int(r['pieces']) + int(r['duplicated']))
            self.assertTrue(0.10 <= float(r['removed_fraction']) <= 0.41)
        verts, faces = parse_obj(self.read(out, 'thin-torus-original.obj').decode())
        r = pu.mesh_report([tuple(map(float, v)) for v in verts], faces)
        self.assertTrue(r['closed'] and r['oriented'] and r['genus'] == 1 and r['volume'] > 0)
        self.assertEqual(len(err.splitlines()), 3 + len(pu.SHEETS), err)

    def test_a_missing_file_is_skipped_with_a_warning(self):
        out, err = self.generate('--objects', 'spot,torus', '--seeds', '0',
                                 '--data', self.out_dir())
        warnings = [l for l in err.splitlines() if 'warning' in l]
        self.assertEqual(len(warnings), 1, err)
        self.assertIn('spot', warnings[0])
        self.assertFalse(os.path.exists(os.path.join(out, 'spot-s0.obj')))
        self.assertTrue(os.path.exists(os.path.join(out, 'torus-s0.obj')))

    def test_bad_arguments_fail_with_one_line(self):
        out = self.out_dir()
        for args in (('--seeds', '9-3'), ('--seeds', 'x'), ('--objects', 'teapot'), ('--bogus',)):
            code, err = run_script('--out', out, *args)
            self.assertNotEqual(code, 0, args)
            self.assertEqual(len(err.strip().splitlines()), 1, (args, err))
        code, err = run_script('--seeds', '0')
        self.assertNotEqual(code, 0)
        self.assertEqual(len(err.strip().splitlines()), 1, err)

    def test_seed_lists(self):
        self.assertEqual(pu.parse_seeds('0-3'), [0, 1, 2, 3])
        self.assertEqual(pu.parse_seeds('5,0,2-3,2'), [0, 2, 3, 5])


if __name__ == '__main__':
    unittest.main()
