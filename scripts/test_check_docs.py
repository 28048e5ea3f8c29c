#!/usr/bin/env python3
"""Tests of scripts/check-docs.py: `python3 scripts/test_check_docs.py`.

The fixtures spell the forbidden citations in pieces, so this file passes the check itself."""
import importlib.util
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, 'check-docs.py')

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
_spec = importlib.util.spec_from_file_location('check_docs', SCRIPT)
cd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cd)

SEC = '\u00a7'
COMMIT = 'e673cf' + '8'


def write_tree(root, files):
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        mode = 'wb' if isinstance(text, bytes) else 'w'
        with open(path, mode) as f:
            f.write(text if isinstance(text, bytes) else textwrap.dedent(text))


def run(root, *flags):
    p = subprocess.run([sys.executable, SCRIPT, '--root', root, *flags],
                       capture_output=True, text=True)
    lines = p.stdout.strip().split('\n')
    return p.returncode, lines[:-1], lines[-1]


class Tree(unittest.TestCase):
    def tree(self, files):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        write_tree(tmp.name, files)
        return tmp.name


DOCS = {
    'README.md': '''\
        # Project

        ![preview](docs/preview.png) and [the method](docs/a.md), [keys](docs/a.md#roar-eval---json-keys),
        [![badge](docs/preview.png)](docs/b.md#cross-check-the-same-extractions-decimated-by-meshlabs-qem)
        [web](https://example.com/nothing.md) [mail](mailto:someone@example.com) [top](#project)
        [second](docs/a.md#repeat-1) [angled](<docs/a.md>) [html anchor](docs/b.md#custom)
        Code: `[not a link](docs/nowhere.md)`.

        ```
        [inside a fence](docs/nowhere.md)
        ```

        [missing](docs/missing.md) and [bad anchor](docs/a.md#no-such-heading) and [self](#nope)
        [ref]: docs/also-missing.md
        ''',
    'docs/a.md': '''\
        # The method

        ## `roar eval --json` keys

        ## Repeat

        ## Repeat

        Back to the [readme](../README.md), the [example](../crates/x/src/lib.rs).
        ''',
    'docs/b.md': '''\
        Setext heading
        ==============

        ### Cross-check: the same extractions decimated by MeshLab's QEM

        <a id="custom"></a>
        [up](./a.md#the-method) [gone](../gone/)
        ''',
    'docs/preview.png': b'\x89PNG\r\n\x1a\n\0\0',
    'crates/x/src/lib.rs': '''\
        //! See `docs/a.md` and docs/b.md#setext-heading.
        //! Gone: `docs/missing.md`.
        /// Anchor: docs/a.md#nope, and a URL https://example.com/docs/x.md is not ours.
        // A plain comment naming docs/plain-missing.md is no doc comment.
        pub fn f() {}
        ''',
}


class Links(Tree):
    def test_broken_links_and_anchors(self):
        root = self.tree(DOCS)
        code, lines, last = run(root, '--links-only')
        self.assertEqual(code, 1)
        self.assertEqual(lines, [
            'README.md:13: broken link docs/missing.md: no file docs/missing.md',
            'README.md:13: broken anchor docs/a.md#no-such-heading: no heading #no-such-heading '
            'in docs/a.md',
            'README.md:13: broken anchor #nope: no heading #nope in README.md',
            'README.md:14: broken link docs/also-missing.md: no file docs/also-missing.md',
            'docs/b.md:7: broken link ../gone/: no file gone',
            'crates/x/src/lib.rs:2: broken link docs/missing.md: no file docs/missing.md',
            'crates/x/src/lib.rs:3: broken anchor docs/a.md#nope: no heading #nope in docs/a.md',
        ])
        self.assertTrue(last.startswith('check-docs: 7 broken of '), last)

    def test_clean_tree_passes(self):
        files = dict(DOCS)
        files['README.md'] = '# Project\n\n[the method](docs/a.md#the-method) [top](#project)\n'
        files['docs/b.md'] = '# B\n'
        files['crates/x/src/lib.rs'] = '//! See `docs/a.md`.\n'
        code, lines, last = run(self.tree(files), '--links-only')
        self.assertEqual((code, lines), (0, []))
        self.assertEqual(last, 'check-docs: 0 broken of 5 links (citations not checked: --links-only)')

    def test_slugs(self):
        self.assertEqual(cd.slug('`roar eval --json` keys'), 'roar-eval---json-keys')
        self.assertEqual(cd.slug("Cross-check: the same extractions decimated by MeshLab's QEM"),
                         'cross-check-the-same-extractions-decimated-by-meshlabs-qem')
        self.assertEqual(cd.slug('Measured: the shared networks against the 512³ reference'),
                         'measured-the-shared-networks-against-the-512³-reference')
        self.assertEqual(cd.slug('snake_case and [a link](x.md)'), 'snake_case-and-a-link')


class Citations(Tree):
    def test_each_forbidden_citation_and_bare_section_sign(self):
        root = self.tree({
            'README.md': 'Fine: paper %s2.1 and supplementary %sB.\n' % (SEC, SEC),
            'docs/a.md': textwrap.dedent('''\
                As in spec %s3.
                See DESIGN%s for the notes (OQ-%d).
                Verification%s: measured.
                A guess [%s] and a claim [%s].
                Timed against %s, then %s.
                Bare %s4 and paper%s5.
                ''') % (SEC, '.md', 1, ' note', 'INF', 'SUP', 'b9e97f' + 'a', COMMIT, SEC, SEC),
            'crates/x/src/lib.rs': '/// spec %s1.2\n' % SEC,
            'scripts/test_module_cycles.py': '# %s and spec %s9\n' % (COMMIT, SEC),
            'scripts/check-docs.py': '# %s\n' % COMMIT,
            'scripts/other.py': '# %s\n' % COMMIT,
            'elsewhere/notes.md': 'spec %s1 is not checked here\n' % SEC,
            'docs/binary.bin': b'\0spec \xc2\xa71',
        })
        code, lines, last = run(root)
        self.assertEqual(code, 1)
        self.assertEqual(sorted(lines), sorted([
            "crates/x/src/lib.rs:1: citation 'spec %s'" % SEC,
            "docs/a.md:1: citation 'spec %s'" % SEC,
            "docs/a.md:2: citation 'DESIGN%s'" % '.md',
            "docs/a.md:2: citation 'OQ-%d'" % 1,
            "docs/a.md:3: citation 'Verification%s'" % ' note',
            "docs/a.md:4: citation '[%s]'" % 'INF',
            "docs/a.md:4: citation '[%s]'" % 'SUP',
            "docs/a.md:5: citation '%s'" % ('b9e97f' + 'a'),
            "docs/a.md:5: citation '%s'" % COMMIT,
            "docs/a.md:6: '%s' not after 'paper ' or 'supplementary '" % SEC,
            "docs/a.md:6: '%s' not after 'paper ' or 'supplementary '" % SEC,
            "scripts/other.py:1: citation '%s'" % COMMIT,
            "scripts/test_module_cycles.py:1: citation 'spec %s'" % SEC,
        ]))
        self.assertEqual(last, 'check-docs: 13 offences (0 broken of 0 links, 13 citations)')

    def test_links_only_skips_citations(self):
        root = self.tree({'docs/a.md': 'spec %s3\n' % SEC})
        code, lines, last = run(root, '--links-only')
        self.assertEqual((code, lines), (0, []))

    def test_clean_tree_passes(self):
        root = self.tree({'README.md': 'paper %s1\n' % SEC, 'docs/a.md': 'Nothing here.\n'})
        code, lines, last = run(root)
        self.assertEqual((code, lines), (0, []))
        self.assertEqual(last, 'check-docs: 0 offences (0 broken of 0 links, 0 citations)')


if __name__ == '__main__':
    unittest.main()
