#!/usr/bin/env python3
"""Module import cycles and upward imports of crates.

    scripts/module-cycles.py crates/roar-ops/src     # one crate
    scripts/module-cycles.py crates/*/src python/src # each root checked on its own
    scripts/module-cycles.py                         # every crates/*/src

Modules come from the files (`a/b.rs` and `a/b/mod.rs` are `a::b`, `lib.rs` and `main.rs` the
crate root; a `main.rs` beside a `lib.rs` is a binary of its own and is skipped) and from inline
`mod x { .. }` blocks. Comments, string and char literals, and `#[cfg(test)]` items
(`#[cfg(test)] mod tests { .. }`, brace-matched) are dropped first. Every `crate::`, `$crate::`,
`super::` (also `super::super::`) and `self::` path, and every path through a child module
(`finish::finish(..)` in the parent), is read, in `use` trees with nested brace groups and inline,
and resolved to the module that *declares* the named item: the longest module prefix, then
through that module's imports and re-exports (`pub use config::X`, globs) to where the item is
defined; a path into another crate is no edge, and neither is a bare `mod x;` declaration.

A path from a module to an item defined in one of its ancestors (`use super::PipelineError` in
`pipeline/finish.rs`) is an *upward import*; a sibling through the parent (`super::optimize::X`)
is an edge to the sibling, and the parent calling its child (`finish::finish(..)`) is a downward
edge, which with an upward import makes a cycle.

Prints per root the module cycles (strongly connected components of more than one module, with
one line per edge inside them: its first file:line), the upward imports (file:line, the imported
name), the cycles between top-level modules and the top-level edges. Exits 1 when a root has a
cycle (between modules or top-level modules) or an upward import, 0 otherwise."""
import glob
import os
import re
import sys

IDENT = r'[A-Za-z_][A-Za-z0-9_]*'
ROOT_NAME = 'crate'


# ---------------------------------------------------------------------------------------------
# Lexing: comments and literals become spaces (newlines kept, so offsets and lines still hold).

def _spaces(s):
    return re.sub(r'[^\n]', ' ', s)


_RAW = re.compile(r'(?:b|c)?r(#*)"')
_STR = re.compile(r'(?:b|c)?"')
_CHAR = re.compile(r"'(?:\\(?:u\{[0-9A-Fa-f]*\}|x[0-9A-Fa-f]{2}|.)|[^\\'\n])'")


def blank_comments_and_literals(src):
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith('//', i):
            j = src.find('\n', i)
            j = n if j < 0 else j
            out.append(_spaces(src[i:j]))
            i = j
            continue
        if src.startswith('/*', i):
            depth, j = 1, i + 2
            while j < n and depth:
                if src.startswith('/*', j):
                    depth, j = depth + 1, j + 2
                elif src.startswith('*/', j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(_spaces(src[i:j]))
            i = j
            continue
        prev_ident = i > 0 and (src[i - 1].isalnum() or src[i - 1] == '_')
        if c in 'bcr"' and not prev_ident:
            m = _RAW.match(src, i)
            if m:
                end = src.find('"' + m.group(1), m.end())
                j = n if end < 0 else end + 1 + len(m.group(1))
                out.append(_spaces(src[i:j]))
                i = j
                continue
            m = _STR.match(src, i)
            if m:
                j = m.end()
                while j < n and src[j] != '"':
                    j += 2 if src[j] == '\\' else 1
                j = min(j + 1, n)
                out.append(_spaces(src[i:j]))
                i = j
                continue
        if c == "'":
            m = _CHAR.match(src, i)
            if m:
                out.append(_spaces(m.group(0)))
                i = m.end()
                continue
        out.append(c)
        i += 1
    return ''.join(out)


def match_close(text, open_at):
    """Offset just past the bracket closing the one at `open_at` (text without comments)."""
    pairs = {'{': '}', '(': ')', '[': ']'}
    stack = []
    for j in range(open_at, len(text)):
        ch = text[j]
        if ch in pairs:
            stack.append(pairs[ch])
        elif ch in ')]}':
            if stack and stack[-1] == ch:
                stack.pop()
            if not stack:
                return j + 1
    return len(text)


def item_end(text, start):
    """End of the item starting at `start`: its first `;` or its brace-matched body."""
    depth = 0
    for j in range(start, len(text)):
        ch = text[j]
        if ch in '([':
            depth += 1
        elif ch in ')]':
            depth -= 1
        elif depth <= 0 and ch == ';':
            return j + 1
        elif depth <= 0 and ch == '{':
            return match_close(text, j)
    return len(text)


_CFG_TEST = re.compile(r'#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]')
_INNER_CFG_TEST = re.compile(r'#\s*!\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]')
_ATTR = re.compile(r'\s*#\s*\[')
_MOD_DECL = re.compile(r'\s*(?:pub\s*(?:\([^)]*\))?\s*)?mod\s+(' + IDENT + r')\s*;')


def drop_cfg_test(text):
    """Blanks `#[cfg(test)]` items; returns the text and the names of test-only `mod x;`."""
    if _INNER_CFG_TEST.search(text):
        return _spaces(text), set()
    test_mods = set()
    pos = 0
    while True:
        m = _CFG_TEST.search(text, pos)
        if not m:
            return text, test_mods
        j = m.end()
        while True:  # further attributes on the same item
            a = _ATTR.match(text, j)
            if not a:
                break
            j = match_close(text, a.end() - 1)
        d = _MOD_DECL.match(text, j)
        if d:
            test_mods.add(d.group(1))
        end = item_end(text, j)
        text = text[:m.start()] + _spaces(text[m.start():end]) + text[end:]
        pos = end


# ---------------------------------------------------------------------------------------------
# `use` trees.

_TOKEN = re.compile(r'\s*(::|\$crate|r#' + IDENT + '|' + IDENT + r'|[{},*;])')


def parse_use_tree(text, pos):
    """Leaves of the use tree at `pos`: (segments, alias, offset); and the offset after `;`."""
    toks = []
    while True:
        m = _TOKEN.match(text, pos)
        if not m:
            break
        toks.append((m.group(1), m.start(1)))
        pos = m.end()
        if m.group(1) == ';':
            break
    leaves = []
    k = 0

    def tree(prefix):
        nonlocal k
        segs = list(prefix)
        at = toks[k][1] if k < len(toks) else 0
        if k < len(toks) and toks[k][0] == '::':  # `::std::x`: an outside crate
            segs.append('')
            k += 1
        while k < len(toks):
            t, at = toks[k]
            if t == '{':
                k += 1
                while k < len(toks) and toks[k][0] not in ('}', ';'):
                    if toks[k][0] == ',':
                        k += 1
                        continue
                    tree(segs)
                if k < len(toks) and toks[k][0] == '}':
                    k += 1
                return
            if t == '*':
                leaves.append((segs + ['*'], None, at))
                k += 1
                return
            if t in (',', '}', ';', '::'):
                return
            segs.append(t[2:] if t.startswith('r#') else t)
            k += 1
            if k < len(toks) and toks[k][0] == '::':
                k += 1
                continue
            alias = None
            if k + 1 < len(toks) and toks[k][0] == 'as':
                alias = toks[k + 1][0]
                k += 2
            leaves.append((segs, alias, at))
            return

    tree([])
    return leaves, pos


# ---------------------------------------------------------------------------------------------
# Modules of one crate.

class Unit:
    """One module's text in one file (a file's own module or an inline `mod x { .. }` in it)."""

    def __init__(self, module, path, text):
        self.module, self.path, self.text = module, path, text


_INLINE_MOD = re.compile(r'(?<![\w$])mod\s+(' + IDENT + r')\s*\{')
_DEF = re.compile(r'(?<![\w$])(?:fn|struct|enum|union|trait|type|const|static|mod)\s+(' + IDENT
                  + r')|macro_rules\s*!\s*(' + IDENT + r')')
_USE = re.compile(r'(?<![\w$])use\s')
_PATH = re.compile(r'(?<![\w:$.])(\$crate|' + IDENT + r')((?:\s*::\s*' + IDENT + r')+)')
_VIS_IN = re.compile(r'pub\s*\(\s*in\s+$')
_KEYWORD_HEADS = {'Self', 'std', 'core', 'alloc'}


def split_inline_modules(module, text):
    """[(module, text)] for `text` and each inline `mod x { .. }` in it (recursively), each
    text blanked outside its own module so offsets still index the file."""
    found = []
    pos = 0
    while True:
        m = _INLINE_MOD.search(text, pos)
        if not m:
            break
        open_at = m.end() - 1
        close = match_close(text, open_at)
        inner = _spaces(text[:open_at + 1]) + text[open_at + 1:close - 1] + _spaces(text[close - 1:])
        found.extend(split_inline_modules(module + (m.group(1),), inner))
        text = text[:open_at + 1] + _spaces(text[open_at + 1:close - 1]) + text[close - 1:]
        pos = close
    return [(module, text)] + found


def module_of_file(root, path):
    rel = os.path.relpath(path, root)[:-3].split(os.sep)
    if rel[-1] in ('mod', 'lib', 'main'):
        rel = rel[:-1]
    return tuple(rel)


def name(module):
    return '::'.join(module) or ROOT_NAME


def line_of(text, offset):
    return text.count('\n', 0, offset) + 1


def depth_zero(text):
    """A mask: True where `text` is outside every brace pair."""
    mask = bytearray(len(text))
    depth = 0
    for j, ch in enumerate(text):
        if ch == '{':
            depth += 1
        elif ch == '}':
            depth -= 1
        mask[j] = depth <= 0
    return mask


class Crate:
    def __init__(self, root):
        self.root = root
        self.units = []
        test_only = set()
        files = sorted(glob.glob(os.path.join(root, '**', '*.rs'), recursive=True))
        if os.path.exists(os.path.join(root, 'lib.rs')):
            # The binary beside a library is its own crate, which uses the library by name.
            files = [f for f in files if f != os.path.join(root, 'main.rs')]
        for path in files:
            module = module_of_file(root, path)
            with open(path, encoding='utf-8', errors='replace') as f:
                text = blank_comments_and_literals(f.read())
            text, test_mods = drop_cfg_test(text)
            test_only.update(module + (t,) for t in test_mods)
            for mod, t in split_inline_modules(module, text):
                self.units.append(Unit(mod, path, t))
        # Files of test-only modules (`#[cfg(test)] mod tests;`) and their descendants go.
        self.units = [u for u in self.units
                      if not any(u.module[:len(t)] == t for t in test_only)]
        self.modules = {u.module for u in self.units}
        for m in list(self.modules):  # a/b/c.rs without a/b.rs still makes `a` and `a::b`
            for i in range(len(m)):
                self.modules.add(m[:i])
        self.defs = {m: set() for m in self.modules}
        self.imports = {m: {} for m in self.modules}  # name -> use path (relative)
        self.globs = {m: [] for m in self.modules}
        self.use_leaves = []  # (unit, segments, offset)
        for u in self.units:
            mask = depth_zero(u.text)
            for m in _DEF.finditer(u.text):
                if mask[m.start()]:
                    self.defs[u.module].add(m.group(1) or m.group(2))
            u.use_spans = []
            for m in _USE.finditer(u.text):
                leaves, end = parse_use_tree(u.text, m.end())
                u.use_spans.append((m.start(), end))
                for segs, alias, at in leaves:
                    self.use_leaves.append((u, segs, at))
                    if segs[-1] == '*':
                        self.globs[u.module].append(segs[:-1])
                        continue
                    if segs[-1] == 'self':
                        segs = segs[:-1]
                    if segs:
                        self.imports[u.module].setdefault(alias or segs[-1], segs)
        self.children = {m: set() for m in self.modules}
        for m in self.modules:
            if m:
                self.children[m[:-1]].add(m[-1])

    # Paths -------------------------------------------------------------------------------

    def absolute(self, cur, segs, depth=0):
        """`segs` seen from module `cur` as a path from the crate root, or None (outside)."""
        if not segs or depth > 16:
            return None
        head = segs[0]
        if head in ('crate', '$crate'):
            return list(segs[1:])
        if head == 'super':
            base = list(cur)
            i = 0
            while i < len(segs) and segs[i] == 'super':
                if not base:
                    return None
                base.pop()
                i += 1
            return base + list(segs[i:])
        if head == 'self':
            return list(cur) + list(segs[1:])
        imp = self.imports.get(cur, {}).get(head)
        if imp is not None and imp[0] != head:
            return self.absolute(cur, imp + list(segs[1:]), depth + 1)
        if head in self.children.get(cur, ()):
            return list(cur) + list(segs)
        return None

    def declared(self, path, depth=0):
        """(module, item) declaring the absolute `path`: item None when it names a module."""
        m = ()
        i = 0
        while i < len(path) and m + (path[i],) in self.modules:
            m += (path[i],)
            i += 1
        if i == len(path):
            return m, None
        item = path[i]
        if item == '*' or item in self.defs[m] or depth > 16:
            return m, item
        imp = self.imports[m].get(item)
        if imp is not None:
            target = self.absolute(m, imp + list(path[i + 1:]), depth + 1)
            return self.declared(target, depth + 1) if target is not None else (None, item)
        for g in self.globs[m]:
            base = self.absolute(m, g, depth + 1) if g else None
            if base is None:
                continue
            gm, gi = self.declared(base, depth + 1)
            if gm is None or gi is not None:
                continue
            if item in self.defs[gm] or item in self.imports[gm] or \
                    any(gm + (item,) == x for x in self.modules):
                target = list(gm) + [item] + list(path[i + 1:])
                return self.declared(target, depth + 1)
        return m, item

    # References --------------------------------------------------------------------------

    def references(self):
        """Every intra-crate reference: (unit, offset, segments, declaring module, item)."""
        refs = []
        for u, segs, at in self.use_leaves:
            if segs[-1] == 'self':
                segs = segs[:-1]
            self._add(refs, u, at, segs)
        for u in self.units:
            text = u.text
            for a, b in u.use_spans:
                text = text[:a] + _spaces(text[a:b]) + text[b:]
            for m in _PATH.finditer(text):
                head = m.group(1)
                if head in _KEYWORD_HEADS or _VIS_IN.search(text[max(0, m.start() - 20):m.start()]):
                    continue  # `pub(in crate::a)` restricts visibility, it uses nothing
                segs = [head] + re.findall(IDENT, m.group(2))
                if head not in ('crate', '$crate', 'super', 'self'):
                    # A name in scope: a child module, or an imported module (not an item).
                    imp = self.imports[u.module].get(head)
                    if imp is not None:
                        target = self.absolute(u.module, imp)
                        if target is None or self.declared(target)[1] is not None:
                            continue
                    elif head not in self.children[u.module]:
                        continue
                self._add(refs, u, m.start(), segs)
        return refs

    def _add(self, refs, u, at, segs):
        path = self.absolute(u.module, segs)
        if path is None:
            return
        module, item = self.declared(path)
        if module is None:
            return
        refs.append((u, at, segs, module, item))

    def analyse(self):
        """Edges {module: {module: (path, line, what)}} and the upward imports."""
        edges = {name(m): {} for m in self.modules}
        upward = []
        seen = set()
        for u, at, segs, target, item in self.references():
            cur = u.module
            if target == cur:
                continue
            is_ancestor = len(target) < len(cur) and cur[:len(target)] == target
            if is_ancestor and item is None:
                continue  # the ancestor module itself (`use crate::a::{self}`): its items count
            line = line_of(u.text, at)
            what = '::'.join(segs)
            edges[name(cur)].setdefault(name(target), (u.path, line, what))
            if is_ancestor:
                key = (u.path, line, item)
                if key not in seen:
                    seen.add(key)
                    upward.append((u.path, line, name(cur), name(target), item, what))
        upward.sort(key=lambda r: (r[0], r[1], r[4]))
        return edges, upward


# ---------------------------------------------------------------------------------------------
# Graphs.

def sccs(graph):
    """Strongly connected components of more than one node, each sorted, in sorted order."""
    index, low, stack, on, found = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10000))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def top_of(module_name):
    return module_name.split('::')[0]


def check(root, out=print):
    """Prints the report of one crate root; returns (cycles, upward, top cycles)."""
    crate = Crate(root)
    edges, upward = crate.analyse()
    cycles = sccs(edges)
    out('module cycles: %s' % cycles)
    for comp in cycles:
        members = set(comp)
        for a in comp:
            for b in sorted(edges[a]):
                if b in members:
                    path, line, what = edges[a][b]
                    out('  %s -> %s  (%s:%d %s)' % (a, b, path, line, what))
    if upward:
        out('upward imports: [')
        for path, line, cur, target, item, what in upward:
            out('  %s:%d: %s -> %s: %s' % (path, line, cur, target, item))
        out(']')
    else:
        out('upward imports: []')
    top = {}
    for a, bs in edges.items():
        for b in bs:
            ta, tb = top_of(a), top_of(b)
            if ta != tb:
                top.setdefault(ta, set()).add(tb)
    top_cycles = sccs(top)
    out('top-level cycles: %s' % top_cycles)
    for a in sorted(top):
        out('  %s -> %s' % (a, sorted(top[a])))
    return cycles, upward, top_cycles


def main(argv):
    roots = argv[1:]
    if any(r in ('-h', '--help') for r in roots):
        print(__doc__)
        return 0
    if not roots:
        repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        roots = [os.path.relpath(r) for r in sorted(glob.glob(os.path.join(repo, 'crates', '*', 'src')))]
    failed = []
    for root in roots:
        if not os.path.isdir(root):
            print('%s: not a directory' % root, file=sys.stderr)
            failed.append(root)
            continue
        if len(roots) > 1:
            print('== %s' % root)
        cycles, upward, top_cycles = check(root)
        if cycles or upward or top_cycles:
            failed.append(root)
    if len(roots) > 1:
        print('%d of %d roots with cycles or upward imports%s' % (
            len(failed), len(roots), (': ' + ' '.join(failed)) if failed else ''))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
