#!/usr/bin/env python3
"""roar on punctured closed surfaces and on open sheets (inputs of scripts/punctured.py): whether
each output is one piece with the object's genus, how far it is from the unpunctured original,
and whether open sheets come back as plates no farther from the sheet than a baseline binary's.

    python3 scripts/evaluate_punctured.py --roar BIN [--baseline BIN] [--set DIR] [--out DIR]
        [--budgets 1000,5000] [--split report] [--samples 200000]

--set: the folder scripts/punctured.py wrote (made with its defaults when it has no
manifest.tsv; default target/punctured). For every input of the split (seeds 5-9 by default),
every original and every sheet, at every budget: `roar reconstruct --faces N`, then
`roar eval --ref REF --json` with REF the unpunctured original (the sheet itself for sheets),
whose floor-free `chamfer_exact_over_diag` is reported (always measured by --roar's `eval`). The
sheets are also reconstructed with --baseline.
Results go to OUT/results.json and the table to OUT/table.md (default target/punctured-eval);
a rerun skips every run whose result is on disk, so an interrupted run resumes.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
RATIO_LIMIT = 1.25    # the punctured output's Chamfer against the original's own output's
EXCESS_LIMIT = 2      # handles beyond the object's genus never allowed


def read_manifest(folder):
    """The manifest's rows as dicts."""
    with open(os.path.join(folder, 'manifest.tsv')) as f:
        lines = f.read().splitlines()
    header = lines[0].split('\t')
    return [dict(zip(header, line.split('\t'))) for line in lines[1:] if line]


def run_one(roar, evaluator, folder, row, reference, budget, out, samples, tag):
    """Reconstructs one input at one budget with `roar` and measures it against `reference` with
    `evaluator` (the binary under test, whose `eval` has the floor-free Chamfer); the result dict
    (cached in OUT/TAG/ID-N.json)."""
    base = os.path.join(out, tag, '%s-%d' % (row['id'], budget))
    cached = base + '.json'
    if os.path.exists(cached):
        with open(cached) as f:
            return json.load(f)
    os.makedirs(os.path.dirname(base), exist_ok=True)
    mesh = base + '.obj'
    result = {'id': row['id'], 'budget': budget, 'tag': tag}
    rec = subprocess.run([roar, 'reconstruct', os.path.join(folder, row['path']), '-o', mesh,
                          '--faces', str(budget), '--report', base + '.report.json', '-q'],
                         capture_output=True, text=True)
    if rec.returncode != 0:
        result['error'] = (rec.stderr.strip().splitlines() or ['exit %d' % rec.returncode])[-1]
    else:
        ev = subprocess.run([evaluator, 'eval', mesh, '--ref', reference, '--json',
                             '--samples', str(samples)], capture_output=True, text=True)
        if ev.returncode != 0:
            result['error'] = 'eval: ' + (ev.stderr.strip().splitlines() or ['?'])[-1]
        else:
            metrics = json.loads(ev.stdout)
            topo = metrics['topology']
            result.update({
                'genus': topo['genus'], 'components': topo['components'],
                'closed': topo['watertight'] and topo['nonmanifold_edges'] == 0,
                'faces': topo['faces'],
                'self_intersecting': metrics.get('self_intersections', {}).get('faces', None),
                'chamfer': metrics['fidelity']['chamfer_exact_over_diag'],
            })
        with open(base + '.report.json') as f:
            report = json.load(f)
        result['seconds'] = report['seconds_total']
        result['init_genus'] = report['run']['init']['init_genus']
    with open(cached, 'w') as f:
        json.dump(result, f)
    return result


def median(values):
    return statistics.median(values) if values else float('nan')


def table(rows, results, budgets, baseline):
    """The markdown table of the results."""
    by = {(r['tag'], r['id'], r['budget']): r for r in results}
    objects = sorted({r['object'] for r in rows if r['split'] not in ('sheet', 'original')})
    lines = ['| object | genus | faces | inputs | one piece, object genus | most handles over it '
             '| median Chamfer/diag | median ratio to the original\'s output | ratio ≤ %.2f |'
             % RATIO_LIMIT, '|---|---|---|---|---|---|---|---|---|']
    totals = {}
    for budget in budgets:
        for obj in objects:
            items = [r for r in rows if r['object'] == obj and r['split'] not in ('sheet', 'original')]
            original = by.get(('roar', obj + '-original', budget), {})
            genus = int(items[0]['genus'])
            outs = [by.get(('roar', r['id'], budget), {}) for r in items]
            good = [o for o in outs if 'error' not in o and o]
            exact = sum(1 for o in good if o['components'] == 1 and o['genus'] == genus
                        and o['closed'] and o['faces'] == budget
                        and o['self_intersecting'] == 0)
            excess = max([o['genus'] - genus for o in good] or [0])
            ratios = [o['chamfer'] / original['chamfer'] for o in good
                      if original.get('chamfer')]
            within = sum(1 for x in ratios if x <= RATIO_LIMIT)
            t = totals.setdefault(budget, [0, 0, 0, [], 0])
            t[0] += len(items)
            t[1] += exact
            t[2] = max(t[2], excess)
            t[3] += ratios
            t[4] += within
            lines.append('| %s | %d | %d | %d | %d | %d | %.3e | %.2f | %d |' % (
                obj, genus, budget, len(items), exact, excess,
                median([o['chamfer'] for o in good]), median(ratios), within))
    for budget, (n, exact, excess, ratios, within) in sorted(totals.items()):
        lines.append('| **all** | | %d | %d | %d (%.0f %%) | %d | | %.2f | %d (%.0f %%) |' % (
            budget, n, exact, 100.0 * exact / max(n, 1), excess, median(ratios), within,
            100.0 * within / max(n, 1)))
    errors = [r for r in results if 'error' in r]
    lines += ['', 'failures: %d%s' % (len(errors), ''.join(
        '\n- %s @ %d (%s): %s' % (e['id'], e['budget'], e['tag'], e['error']) for e in errors))]
    sheets = [r for r in rows if r['split'] == 'sheet']
    if sheets:
        lines += ['', '| sheet | faces | Chamfer/diag to the sheet | baseline | genus | pieces |',
                  '|---|---|---|---|---|---|']
        for budget in budgets:
            for r in sheets:
                o = by.get(('roar', r['id'], budget), {})
                b = by.get(('baseline', r['id'], budget), {}) if baseline else {}
                lines.append('| %s | %d | %s | %s | %s | %s |' % (
                    r['object'], budget, '%.3e' % o['chamfer'] if 'chamfer' in o else '-',
                    '%.3e' % b['chamfer'] if 'chamfer' in b else '-',
                    o.get('genus', '-'), o.get('components', '-')))
    return '\n'.join(lines) + '\n'


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--roar', required=True)
    p.add_argument('--baseline')
    p.add_argument('--set', default=os.path.join(REPO, 'target', 'punctured'))
    p.add_argument('--out', default=os.path.join(REPO, 'target', 'punctured-eval'))
    p.add_argument('--budgets', default='1000,5000')
    p.add_argument('--split', default='report')
    p.add_argument('--samples', type=int, default=200000)
    args = p.parse_args()
    budgets = [int(b) for b in args.budgets.split(',')]
    if not os.path.exists(os.path.join(args.set, 'manifest.tsv')):
        subprocess.run([sys.executable, os.path.join(HERE, 'punctured.py'), '--out', args.set],
                       check=True)
    rows = read_manifest(args.set)
    chosen = [r for r in rows if r['split'] in (args.split, 'original', 'sheet')]
    results = []
    for budget in budgets:
        for r in chosen:
            ref = os.path.join(args.set, r['path'] if r['split'] == 'sheet'
                               else '%s-original.obj' % r['object'])
            runs = [('roar', args.roar)]
            if args.baseline and r['split'] == 'sheet':
                runs.append(('baseline', args.baseline))
            for tag, binary in runs:
                result = run_one(binary, args.roar, args.set, r, ref, budget, args.out,
                                 args.samples, tag)
                results.append(result)
                print('%s %s @ %d: %s' % (tag, r['id'], budget, result.get('error') or
                      'genus %s, %s pieces, Chamfer/diag %.3e' % (
                          result['genus'], result['components'], result['chamfer'])),
                      file=sys.stderr)
    with open(os.path.join(args.out, 'results.json'), 'w') as f:
        json.dump(results, f, indent=1)
    text = table(chosen, results, budgets, args.baseline)
    with open(os.path.join(args.out, 'table.md'), 'w') as f:
        f.write(text)
    print(text)


if __name__ == '__main__':
    main()
