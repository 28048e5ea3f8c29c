#!/usr/bin/env python3
"""Tests of scripts/evaluate_punctured.py's table: python3 scripts/test_evaluate_punctured.py"""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evaluate_punctured as ep  # noqa: E402


def row(id_, obj, genus, split, path=None):
    return {'id': id_, 'object': obj, 'genus': genus, 'split': split, 'path': path or id_ + '.obj'}


def result(id_, budget, genus, chamfer, pieces=1, tag='roar', faces=None, intersecting=0):
    return {'id': id_, 'budget': budget, 'tag': tag, 'genus': genus, 'components': pieces,
            'closed': True, 'faces': budget if faces is None else faces,
            'self_intersecting': intersecting, 'chamfer': chamfer}


class Table(unittest.TestCase):
    rows = [row('torus-original', 'torus', '1', 'original'),
            row('torus-s5', 'torus', '1', 'report'),
            row('torus-s6', 'torus', '1', 'report'),
            row('torus-s7', 'torus', '1', 'report'),
            row('leaf-sheet', 'leaf', '', 'sheet')]

    def test_counts_one_piece_of_the_object_genus_and_the_chamfer_ratio(self):
        results = [result('torus-original', 1000, 1, 1e-3),
                   result('torus-s5', 1000, 1, 1.2e-3),              # counts, ratio 1.2
                   result('torus-s6', 1000, 3, 1.0e-3),              # two handles over
                   result('torus-s7', 1000, 1, 2.0e-3, pieces=2),    # two pieces, ratio 2
                   result('leaf-sheet', 1000, 0, 5e-4),
                   result('leaf-sheet', 1000, 0, 6e-4, tag='baseline')]
        text = ep.table(self.rows, results, [1000], baseline=True)
        torus = [l for l in text.splitlines() if l.startswith('| torus |')][0]
        cells = [c.strip() for c in torus.strip('|').split('|')]
        self.assertEqual(cells[:6], ['torus', '1', '1000', '3', '1', '2'])
        self.assertEqual(cells[7], '1.20')      # median of 1.2, 1.0, 2.0
        self.assertEqual(cells[8], '2')         # 1.2 and 1.0 are within 1.25
        self.assertIn('| leaf | 1000 | 5.000e-04 | 6.000e-04 | 0 | 1 |', text)
        self.assertIn('failures: 0', text)

    def test_a_wrong_budget_or_an_intersection_does_not_count_and_errors_are_listed(self):
        results = [result('torus-original', 1000, 1, 1e-3),
                   result('torus-s5', 1000, 1, 1e-3, faces=998),
                   result('torus-s6', 1000, 1, 1e-3, intersecting=4),
                   {'id': 'torus-s7', 'budget': 1000, 'tag': 'roar', 'error': 'boom'}]
        text = ep.table(self.rows, results, [1000], baseline=False)
        torus = [l for l in text.splitlines() if l.startswith('| torus |')][0]
        self.assertEqual(torus.split('|')[5].strip(), '0')
        self.assertIn('failures: 1', text)
        self.assertIn('torus-s7 @ 1000 (roar): boom', text)


if __name__ == '__main__':
    unittest.main()
