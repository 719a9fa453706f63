#!/usr/bin/env python3
"""Naive reference rewriter used to cross-check golden module counts.

Deliberately simple and independent of the C++ engine: single-character and
declared multi-character symbols, no parameters, context matched by walking
the string (ABOP semantics: left context skips complete branches and steps
out of enclosing ones; right context skips sibling branches and never leaves
the current one). Usage: naive_lsystem.py FILE.lsys -> prints module count.
"""
import re
import sys


def tokenize(s, modules):
    out, i = [], 0
    s = s.replace(' ', '')
    while i < len(s):
        for m in modules:
            if s.startswith(m, i):
                out.append(m)
                i += len(m)
                break
        else:
            out.append(s[i])
            i += 1
    return out


def parse(path):
    g = {'n': 0, 'axiom': [], 'rules': [], 'ignore': set(), 'modules': []}
    # `//` is a comment at the start of a line or after whitespace; elsewhere
    # it is two roll modules (ABOP writes `S/////F`).
    lines = [re.sub(r'(^|\s)//.*', '', l).strip() for l in open(path)]
    for l in lines:
        if l.startswith('module:'):
            g['modules'] = sorted(l[7:].split(), key=len, reverse=True)
    for l in lines:
        if not l or l.startswith('#'):
            continue
        if l.startswith('interpretation:'):
            break
        key, _, val = l.partition(':')
        if '-->' in l:
            lhs, rhs = [x.strip() for x in l.split('-->')]
            rhs = rhs.split(':')[0].strip()
            left = right = None
            if '<' in lhs:
                left, lhs = [x.strip() for x in lhs.split('<')]
            if '>' in lhs:
                lhs, right = [x.strip() for x in lhs.split('>')]
            left = None if left in (None, '*') else tokenize(left, g['modules'])
            right = None if right in (None, '*') else tokenize(right, g['modules'])
            succ = [] if rhs == '*' else tokenize(rhs, g['modules'])
            g['rules'].append((left, lhs.strip(), right, succ))
        elif key == 'derivation length':
            g['n'] = int(val)
        elif key == 'axiom':
            g['axiom'] = tokenize(val.strip(), g['modules'])
        elif key == 'ignore':
            g['ignore'] = set(tokenize(val.strip(), g['modules']))
    return g


def left_ok(w, i, ctx, ign):
    j = i - 1
    for c in reversed(ctx):
        while True:
            if j < 0:
                return False
            if w[j] == ']':
                depth = 1
                j -= 1
                while depth:
                    depth += {']': 1, '[': -1}.get(w[j], 0)
                    j -= 1
                continue
            if w[j] == '[' or w[j] in ign:
                j -= 1
                continue
            break
        if w[j] != c:
            return False
        j -= 1
    return True


def right_ok(w, i, ctx, ign):
    j = i + 1
    for c in ctx:
        while True:
            if j >= len(w) or w[j] == ']':
                return False
            if w[j] == '[':
                depth = 1
                j += 1
                while depth:
                    depth += {'[': 1, ']': -1}.get(w[j], 0)
                    j += 1
                continue
            if w[j] in ign:
                j += 1
                continue
            break
        if w[j] != c:
            return False
        j += 1
    return True


def derive(g):
    w = list(g['axiom'])
    for _ in range(g['n']):
        out = []
        for i, s in enumerate(w):
            for left, pred, right, succ in g['rules']:
                if pred != s:
                    continue
                if left and not left_ok(w, i, left, g['ignore']):
                    continue
                if right and not right_ok(w, i, right, g['ignore']):
                    continue
                out.extend(succ)
                break
            else:
                out.append(s)
        w = out
    return w


if __name__ == '__main__':
    print(len(derive(parse(sys.argv[1]))))
