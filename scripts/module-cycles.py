#!/usr/bin/env python3
"""Module import cycles of one crate: `scripts/module-cycles.py crates/roar-ops/src`.

Reads every `crate::a::b` and `super::x` path outside `#[cfg(test)] mod tests` (comments
dropped), maps it to the longest module prefix, and prints the cycles between modules and
between top-level modules (strongly connected components), then the top-level edges."""
import re,os,sys,glob
root=sys.argv[1]
def modname(f):
    rel=os.path.relpath(f,root)[:-3].split('/')
    if rel[-1] in ('mod','lib','main'): rel=rel[:-1]
    return rel
graph={}
for f in glob.glob(root+'/**/*.rs',recursive=True):
    m=modname(f); name='::'.join(m) or 'crate'
    src=open(f).read()
    # drop #[cfg(test)] mod tests blocks crudely: cut from "#[cfg(test)]\nmod tests" to end
    k=src.find("#[cfg(test)]\nmod tests")
    if k>=0: src=src[:k]
    src=re.sub(r'//.*','',src)
    deps=set()
    for path in re.findall(r'crate::((?:[a-z_][a-z0-9_]*::)*[a-z_][a-z0-9_]*)',src):
        parts=path.split('::')
        # longest prefix that is a module
        deps.add(tuple(parts))
    for path in re.findall(r'super::([a-z_][a-z0-9_]*)',src):
        deps.add(tuple(m[:-1]+[path]) if m else (path,))
    graph[name]=deps
mods=set(graph)
def resolve(parts):
    for i in range(len(parts),0,-1):
        n='::'.join(parts[:i])
        if n in mods: return n
    return None
edges={a:set() for a in graph}
for a,ds in graph.items():
    for d in ds:
        r=resolve(list(d))
        if r and r!=a and not a.startswith(r+'::') and not r.startswith(a+'::'):
            edges[a].add(r)
# cycles between modules, and between top-level folders
def cycles(E):
    found=[]
    for a in E:
        for b in E[a]:
            if a in E.get(b,()): found.append((a,b))
    # full SCC
    idx={};low={};st=[];on=set();sccs=[];c=[0]
    def sc(v):
        idx[v]=low[v]=c[0];c[0]+=1;st.append(v);on.add(v)
        for w in E.get(v,()):
            if w not in idx: sc(w);low[v]=min(low[v],low[w])
            elif w in on: low[v]=min(low[v],idx[w])
        if low[v]==idx[v]:
            comp=[]
            while True:
                w=st.pop();on.discard(w);comp.append(w)
                if w==v:break
            if len(comp)>1: sccs.append(comp)
    for v in E:
        if v not in idx: sc(v)
    return sccs
print("module cycles:",cycles(edges))
top={}
for a,bs in edges.items():
    ta=a.split('::')[0]
    for b in bs:
        tb=b.split('::')[0]
        if ta!=tb: top.setdefault(ta,set()).add(tb)
print("top-level cycles:",cycles(top))
for a in sorted(top): print(" ",a,"->",sorted(top[a]))
