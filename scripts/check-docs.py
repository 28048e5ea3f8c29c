#!/usr/bin/env python3
"""Checks the documentation's links and citations: `scripts/check-docs.py [--links-only]`.

(a) Links. Every relative link of `README.md` and `docs/*.md` (`[text](path)`,
    `[text](path#anchor)`, images, `[label]: path` definitions; outside code blocks and code
    spans; `http:`, `https:`, `mailto:` and other schemes skipped) must name an existing file,
    and an `#anchor` into a Markdown file must be one of its headings (GitHub's slugs: lower
    case, punctuation but `-` and `_` dropped, each space a `-`, `-1`, `-2`.. on repeats) or an
    HTML `id`/`name`. Every `docs/..` path named in a doc comment (`///`, `//!`) of
    `crates/**/*.rs` must exist too (from the repository root), its anchor likewise.
(b) Citations. No line of `crates/`, `docs/`, `python/`, `benches/`, `scripts/` or `README.md`
    may hold a spec section, the design notes' file, an open question's number, a verification
    note, an INF or SUP tag in brackets or the two commits the measurements were once tied to (see
    CITATION below; this script and scripts/test_module_cycles.py may name the commit whose
    tree that test rebuilds), and every section sign must follow `paper ` or `supplementary `.

Prints each offence as `path:line: reason`, then a count line; exits 1 if there is any.
`--links-only` runs (a) alone; `--root DIR` checks another tree (the tests' fixtures)."""
import os
import re
import sys
import unicodedata
from urllib.parse import unquote

SECTION = '\u00a7'
# The forbidden citations, spelled so that this file does not match them itself.
CITATION = re.compile('|'.join([
    'spec ' + SECTION,
    r'DESIGN\.md',
    r'OQ-[0-9]',
    'Verification' + ' note',
    r'\[(INF|SUP)\]',
    'b9e97f' + 'a',
    'e673cf' + '8',
]))
SECTION_OK = re.compile(r'(paper|supplementary) $')
# The files that may name the commit the module-cycles test rebuilds.
COMMIT_EXEMPT = {'scripts/test_module_cycles.py', 'scripts/check-docs.py'}
EXEMPT_COMMIT = 'e673cf' + '8'
CITATION_TREES = ['crates', 'docs', 'python', 'benches', 'scripts']
CITATION_FILES = ['README.md']
SKIP_DIRS = {'target', '__pycache__', 'node_modules', '.venv', 'venv'}


def rel(root, path):
    return os.path.relpath(path, root).replace(os.sep, '/')


# ---------------------------------------------------------------------------------------------
# Markdown.

_FENCE = re.compile(r'^ {0,3}(`{3,}|~{3,})')


def markdown_lines(text):
    """(line number, line) outside fenced code blocks, inline code spans blanked."""
    fence = None
    for n, line in enumerate(text.split('\n'), 1):
        m = _FENCE.match(line)
        if fence:
            if m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) \
                    and not line.strip()[len(m.group(1)):].strip():
                fence = None
            continue
        if m:
            fence = m.group(1)
            continue
        yield n, re.sub(r'(`+)(.+?)\1', lambda c: ' ' * len(c.group(0)), line)


_ATX = re.compile(r'^ {0,3}(#{1,6})(?:[ \t]+(.*?))?(?:[ \t]+#+)?[ \t]*$')
_SETEXT = re.compile(r'^ {0,3}(=+|-+)[ \t]*$')
_HTML_ID = re.compile(r'<[^>]*\b(?:id|name)\s*=\s*["\']([^"\']+)["\']', re.I)


def slug(heading):
    """GitHub's anchor of a heading's text."""
    text = re.sub(r'!?\[([^\]]*)\]\([^)]*\)', r'\1', heading)  # links and images: their text
    text = re.sub(r'<[^>]+>', '', text)  # HTML tags
    text = text.replace('`', '').replace('*', '')
    out = []
    for ch in text.strip().lower():
        if ch == ' ':
            out.append('-')
        elif ch in '-_' or ch.isalnum() or unicodedata.category(ch)[0] == 'M':
            out.append(ch)
    return ''.join(out)


_anchor_cache = {}


def anchors(path):
    """Every anchor of a Markdown file: its headings' slugs and its HTML ids."""
    if path in _anchor_cache:
        return _anchor_cache[path]
    with open(path, encoding='utf-8', errors='replace') as f:
        text = f.read()
    found, seen = set(), {}
    fence = None
    prev = ''
    for line in text.split('\n'):
        m = _FENCE.match(line)
        if fence or m:
            if fence is None:
                fence = m.group(1)
            elif m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence):
                fence = None
            prev = ''
            continue
        heading = None
        a = _ATX.match(line)
        if a:
            heading = a.group(2) or ''
        elif _SETEXT.match(line) and prev.strip() and not _ATX.match(prev):
            heading = prev.strip()
        if heading is not None:
            s = slug(heading)
            k = seen.get(s, 0)
            seen[s] = k + 1
            found.add(s if k == 0 else '%s-%d' % (s, k))
        for h in _HTML_ID.findall(line):
            found.add(h)
        prev = line
    _anchor_cache[path] = found
    return found


def link_targets(line):
    """The destinations of the links of one Markdown line (code spans already blanked)."""
    out = []
    for m in re.finditer(r'\]\(', line):
        j = m.end()
        while j < len(line) and line[j] in ' \t':
            j += 1
        if j < len(line) and line[j] == '<':
            k = line.find('>', j)
            if k > 0:
                out.append(line[j + 1:k])
            continue
        depth, k = 0, j
        while k < len(line):
            ch = line[k]
            if ch == '(':
                depth += 1
            elif ch == ')':
                if depth == 0:
                    break
                depth -= 1
            elif ch in ' \t':
                break
            k += 1
        if k > j:
            out.append(line[j:k])
    d = re.match(r'^ {0,3}\[[^\]]+\]:\s*<?([^\s>]+)>?', line)  # [label]: destination
    if d:
        out.append(d.group(1))
    return out


_SCHEME = re.compile(r'^[A-Za-z][A-Za-z0-9+.-]*:')


def check_target(root, base_dir, target):
    """The reason a relative link does not resolve, or None (also None for URLs)."""
    if _SCHEME.match(target):
        return None  # http:, https:, mailto:, ...
    path, _, anchor = target.partition('#')
    path = unquote(path)
    if path.startswith('/'):
        full = os.path.join(root, path.lstrip('/'))
    elif path:
        full = os.path.normpath(os.path.join(base_dir, path))
    else:
        full = None  # `#anchor` into the file itself
    if full is not None and not os.path.exists(full):
        return 'broken link %s: no file %s' % (target, rel(root, full))
    if anchor and full is not None and os.path.isdir(full):
        return None
    if anchor:
        md = full if full is not None else None
        if md is None or md.endswith('.md'):
            return ('anchor' if md else 'self-anchor'), unquote(anchor), md
    return None


def check_links(root):
    offences = []
    files = []
    readme = os.path.join(root, 'README.md')
    if os.path.isfile(readme):
        files.append(readme)
    docs = os.path.join(root, 'docs')
    if os.path.isdir(docs):
        files.extend(os.path.join(docs, f) for f in sorted(os.listdir(docs)) if f.endswith('.md'))
    for md in files:
        with open(md, encoding='utf-8', errors='replace') as f:
            text = f.read()
        for n, line in markdown_lines(text):
            for target in link_targets(line):
                offences.extend(_resolve(root, md, n, os.path.dirname(md), target))
    offences.extend(check_rust_doc_links(root))
    return offences


checked = [0]  # relative links and docs/ paths looked at


def _resolve(root, source, n, base_dir, target):
    r = check_target(root, base_dir, target)
    if not _SCHEME.match(target):
        checked[0] += 1
    if r is None:
        return []
    where = '%s:%d' % (rel(root, source), n)
    if isinstance(r, str):
        return [(where, r)]
    _, anchor, md = r
    md = md or source
    if anchor not in anchors(md):
        return [(where, 'broken anchor %s: no heading #%s in %s' % (target, anchor, rel(root, md)))]
    return []


_DOCS_PATH = re.compile(r'(?<![\w/.-])docs/[\w./-]*[\w-](?:#[\w-]+)?')
_DOC_COMMENT = re.compile(r'^\s*//[/!]')


def check_rust_doc_links(root):
    offences = []
    crates = os.path.join(root, 'crates')
    for path in walk(crates):
        if not path.endswith('.rs'):
            continue
        with open(path, encoding='utf-8', errors='replace') as f:
            lines = f.read().split('\n')
        for n, line in enumerate(lines, 1):
            if not _DOC_COMMENT.match(line):
                continue
            for m in _DOCS_PATH.finditer(line):
                offences.extend(_resolve(root, path, n, root, m.group(0)))
    return offences


# ---------------------------------------------------------------------------------------------
# Citations.

def walk(top):
    if not os.path.isdir(top):
        return
    for d, dirs, files in os.walk(top):
        dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS and not x.startswith('.')
                         and not x.endswith('.egg-info'))
        for f in sorted(files):
            yield os.path.join(d, f)


def text_lines(path):
    with open(path, 'rb') as f:
        data = f.read()
    if b'\0' in data[:8192]:
        return None
    try:
        return data.decode('utf-8').split('\n')
    except UnicodeDecodeError:
        return None


def check_citations(root):
    offences = []
    paths = []
    for t in CITATION_TREES:
        paths.extend(walk(os.path.join(root, t)))
    paths.extend(os.path.join(root, f) for f in CITATION_FILES if os.path.isfile(os.path.join(root, f)))
    for path in paths:
        lines = text_lines(path)
        if lines is None:
            continue
        name = rel(root, path)
        for n, line in enumerate(lines, 1):
            covered = set()
            for m in CITATION.finditer(line):
                if m.group(0) == EXEMPT_COMMIT and name in COMMIT_EXEMPT:
                    continue
                offences.append(('%s:%d' % (name, n), 'citation %r' % m.group(0)))
                covered.update(range(m.start(), m.end()))
            for k, ch in enumerate(line):
                if ch == SECTION and k not in covered and not SECTION_OK.search(line[:k]):
                    offences.append(('%s:%d' % (name, n),
                                     "'%s' not after 'paper ' or 'supplementary '" % SECTION))
    return offences


def main(argv):
    args = argv[1:]
    links_only = '--links-only' in args
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if '--root' in args:
        root = args[args.index('--root') + 1]
    if '-h' in args or '--help' in args:
        print(__doc__)
        return 0
    unknown = [a for a in args if a.startswith('-') and a not in ('--links-only', '--root')]
    if unknown:
        print('check-docs: unknown option %s' % ' '.join(unknown), file=sys.stderr)
        return 2
    links = check_links(root)
    citations = [] if links_only else check_citations(root)
    for where, reason in links + citations:
        print('%s: %s' % (where, reason))
    if links_only:
        print('check-docs: %d broken of %d links (citations not checked: --links-only)'
              % (len(links), checked[0]))
    else:
        print('check-docs: %d offences (%d broken of %d links, %d citations)'
              % (len(links) + len(citations), len(links), checked[0], len(citations)))
    return 1 if links or citations else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
