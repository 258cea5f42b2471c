#!/usr/bin/python3
"""Lists C++ functions longer than N lines: scripts/function_lengths.py N FILE... A function starts at a line
that opens a brace after a ')' at depth 0 of a namespace/class, and ends at its matching brace."""
import re, sys
limit = int(sys.argv[1]); files = sys.argv[2:]
res = []
for f in files:
    lines = open(f).read().split("\n")
    depth = 0; start = None; sdepth = 0; name = ""
    for i, ln in enumerate(lines):
        code = re.sub(r'//.*', '', ln)
        code = re.sub(r'"([^"\\]|\\.)*"', '""', code)
        code = re.sub(r"'([^'\\]|\\.)*'", "''", code)
        for ch in code:
            if ch == '{':
                if start is None and re.search(r'\)\s*(const)?\s*(override)?\s*(noexcept)?\s*(->\s*[\w:<>]+)?\s*\{', code) and not re.match(r'\s*(namespace|struct|class|enum)\b', code) and not re.search(r'\b(if|for|while|switch|catch)\s*\(', code):
                    if depth <= 2:
                        start = i; sdepth = depth; name = ln.strip()[:70]
                depth += 1
            elif ch == '}':
                depth -= 1
                if start is not None and depth == sdepth:
                    n = i - start + 1
                    if n > limit: res.append((n, f, start + 1, name))
                    start = None
for n, f, l, name in sorted(res, reverse=True):
    print(f"{n:4d} {f}:{l} {name}")
