#!/usr/bin/env python3
"""Every relative Markdown link and every repository path named in README.md and docs/*.md resolves.

Usage: check_paths.py REPO_ROOT

Checked, in each file:
  * links [text](target) that are not URLs: the file or folder exists (relative to the Markdown
    file), and a #anchor into a Markdown file names one of its headings (GitHub's heading ids);
  * paths under the repository's top-level folders (codec/, formats/, cli/, runtime/, tests/,
    bench/, fuzz/, docs/, scripts/, cmake/), in backticks or in prose: the file or folder exists
    (relative to the repository root). `*` is a glob (`codec/lightmap/bc6h.*`), a name without
    its extension names a module or program (`codec/lightmap/bc6h`, `bench/bench_bc6h`), and
    `a.h/.cpp` or `a.{h,cpp}` (any brace expansion) names each file. Paths with a placeholder (<name>, $VAR, ...) and
    paths outside the clone (../) are not checked.
Prints one line per dangling reference (`file:line: what`) and exits 1 if there is any.
"""
import glob
import os
import re
import sys

TOP = ("codec", "formats", "cli", "runtime", "tests", "bench", "fuzz", "docs", "scripts", "cmake")
LINK = re.compile(r"(?<!!)\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)|!\[[^\]]*\]\(([^()\s]+)\)")
PATH = re.compile(r"(?<![\w/.\-])(?:%s)/(?:[\w./*\-]|\{[\w.,]*\})*(?:[\w*/]|\{[\w.,]*\})" % "|".join(TOP))


def slug(heading):
    """GitHub's id for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip()).lower()
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        ids, seen, fenced = set(), {}, False
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.lstrip().startswith("```"):
                    fenced = not fenced
                    continue
                m = None if fenced else re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
                if m:
                    base = slug(m.group(1))
                    n = seen.get(base, 0)
                    seen[base] = n + 1
                    ids.add(base if n == 0 else "%s-%d" % (base, n))
        cache[path] = ids
    return cache[path]


def expand(rel):
    """Bash-style brace expansion: `a{,b}c{d,e}` -> acd, ace, abcd, abce."""
    m = re.search(r"\{([\w.,]*)\}", rel)
    if not m:
        return [rel]
    return [x for alt in m.group(1).split(",") for x in expand(rel[:m.start()] + alt + rel[m.end():])]


def exists(root, rel):
    """rel names a file or folder, a glob, a module (`codec/lightmap/bc6h`: bc6h.h, bc6h.cpp, ...),
    or several files (`probe_file.h/.cpp`, `zh3_channel_q16.{h,cpp}`: each must exist)."""
    rel = rel.rstrip("/")
    if "{" in rel:
        return all(exists(root, r) for r in expand(rel))
    m = re.match(r"(.*)\.(\w+)/\.(\w+)$", rel)
    if m:
        return exists(root, m.group(1) + "." + m.group(2)) and exists(root, m.group(1) + "." + m.group(3))
    full = os.path.join(root, rel)
    if "*" in rel:
        return bool(glob.glob(full))
    return os.path.exists(full) or bool(glob.glob(glob.escape(full) + ".*"))


def check_file(root, md, problems):
    here = os.path.dirname(md)
    name = os.path.relpath(md, root)
    with open(md, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for no, line in enumerate(lines, 1):
        for m in LINK.finditer(line):
            target = m.group(1) or m.group(2)
            if re.match(r"[a-z][a-z0-9+.\-]*:", target, re.I):  # http:, https:, mailto:, ...
                continue
            file_part, _, anchor = target.partition("#")
            dest = os.path.normpath(os.path.join(here, file_part)) if file_part else md
            if not os.path.exists(dest):
                problems.append("%s:%d: link target %s does not exist" % (name, no, target))
            elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                problems.append("%s:%d: link %s: no heading with id '%s' in %s"
                                % (name, no, target, anchor, os.path.relpath(dest, root)))
        prose = LINK.sub(" ", line)
        for m in PATH.finditer(prose):
            rel = m.group(0)
            tail = prose[m.end():m.end() + 1]
            if re.search(r"[<>$]|\.\.\.", rel) or tail in ("<", "{", "$"):
                continue
            if not exists(root, rel):
                problems.append("%s:%d: path %s does not exist" % (name, no, rel))


def main():
    if len(sys.argv) != 2:
        print("usage: check_paths.py REPO_ROOT", file=sys.stderr)
        return 2
    root = os.path.abspath(sys.argv[1])
    files = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    problems = []
    for md in files:
        check_file(root, md, problems)
    for p in problems:
        print(p)
    print("%d Markdown files, %d dangling references" % (len(files), len(problems)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
