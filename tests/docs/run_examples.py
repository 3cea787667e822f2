#!/usr/bin/env python3
"""Runs every shell example of README.md and docs/*.md against the example inputs (examples/).

Usage: run_examples.py --zhc ZHC --example-inputs ZHC_EXAMPLE_INPUTS --maps ENVMAP_DIR REPO_ROOT
       run_examples.py --self-test
       run_examples.py --list REPO_ROOT          (prints the commands it would run, runs nothing)

The rule (also in the README's "Development" section):
  * an example is a line that starts with `zhc ` inside a fenced block whose info string starts with
    `sh` or `bash` (```sh, ```bash); other lines of the block (`bash scripts/...`, `./build/...`) are
    not run;
  * a block opened with ```sh no-test: REASON (or ```bash no-test: REASON) is not run; the reason
    is required;
  * an example exits 0, unless its comment starts with `exit N` (`zhc audit ... # exit 8 ...`);
  * each Markdown file's examples run in order, in one fresh folder per file, with `examples/` there
    holding the checked-in and generated inputs (scripts/make_examples.sh) and `zhc` on PATH, each
    through `bash -o pipefail -c`; a later example may read what an earlier one of the same file wrote;
  * paths in an example are relative and stay in its folder (no `/...`, no `../...`);
  * no example changes a file it names as an input (an argument that exists before it runs and is
    not the value of -o/--output/--html/--markdown/--images/--plots or a `>` redirection), and no
    example changes anything under examples/.
Exits 1 naming each failing example (file:line, the command, what went wrong), else 0.
Standard-library Python only.
"""
import glob
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*(.*)$")
OUTPUT_OPTIONS = {"-o", "--output", "--html", "--markdown", "--images", "--plots"}
TIMEOUT_S = 600


class Example:
    def __init__(self, path, line, command, exit_code):
        self.path, self.line, self.command, self.exit_code = path, line, command, exit_code

    def where(self):
        return "%s:%d" % (self.path, self.line)


def parse(path, text):
    """(examples, problems) of one Markdown file; `path` is used in messages only."""
    examples, problems = [], []
    fence, run = None, False
    for n, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m and fence is None:
            fence = m.group(2)
            info = m.group(3).strip()
            words = info.split(None, 1)
            lang = words[0] if words else ""
            run = lang in ("sh", "bash")
            if run and len(words) > 1:
                rest = words[1].strip()
                if rest.startswith("no-test"):
                    run = False
                    if not re.match(r"no-test:\s*\S", rest):
                        problems.append("%s:%d: `%s no-test` needs a reason: ```%s no-test: WHY" % (path, n, lang, lang))
                else:
                    problems.append("%s:%d: unknown fence attribute '%s' (only 'no-test: REASON')" % (path, n, rest))
            continue
        if m and fence is not None and m.group(2).startswith(fence) and not m.group(3).strip():
            fence, run = None, False
            continue
        if fence is None or not run:
            continue
        stripped = line.strip()
        if not stripped.startswith("zhc "):
            continue
        exit_code = 0
        comment = comment_of(stripped)
        if comment is not None:
            e = re.match(r"exit (\d+)\b", comment)
            if e:
                exit_code = int(e.group(1))
        try:
            outside = [w for w in words_of(stripped) if w.startswith("/") or w.startswith("../")]
        except ValueError as e:
            outside = []
            problems.append("%s:%d: cannot split the command into words: %s" % (path, n, e))
        if outside:
            problems.append("%s:%d: %s: paths must be relative and stay in the folder the example runs in"
                            % (path, n, ", ".join(outside)))
        examples.append(Example(path, n, stripped, exit_code))
    if fence is not None:
        problems.append("%s: a fenced block is not closed" % path)
    return examples, problems


def comment_of(command):
    """The text of the command's trailing shell comment, or None."""
    lexer = shlex.shlex(command, posix=True, punctuation_chars=True)
    lexer.commenters = ""
    lexer.whitespace_split = True
    try:
        tokens = list(lexer)
    except ValueError:
        return None
    for i, t in enumerate(tokens):
        if t.startswith("#"):
            return " ".join(tokens[i:])[1:].strip()
    return None


def words_of(command):
    """The command's words (comment dropped), with shell operators as their own words."""
    lexer = shlex.shlex(command, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    return list(lexer)


def named_inputs(command, cwd):
    """Files the command names as inputs: existing paths that are not an output option's value."""
    words = words_of(command)
    files = set()
    for i, w in enumerate(words):
        prev = words[i - 1] if i > 0 else ""
        if prev in OUTPUT_OPTIONS or prev in (">", ">>"):
            continue
        if w.startswith("-") and "=" in w:
            if w.split("=", 1)[0] in OUTPUT_OPTIONS:
                continue
            w = w.split("=", 1)[1]
        p = os.path.join(cwd, w)
        if os.path.isdir(p):
            for d, _, fs in os.walk(p, followlinks=True):
                files.update(os.path.realpath(os.path.join(d, f)) for f in fs)
        elif os.path.lexists(p):
            files.add(os.path.realpath(p))
    return files


def fingerprint(path):
    st = os.stat(path)
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return (st.st_ino, st.st_mtime_ns, st.st_size, h.hexdigest())


def tree_fingerprints(folder):
    out = {}
    for d, _, fs in os.walk(folder):
        for f in fs:
            p = os.path.join(d, f)
            out[os.path.realpath(p)] = fingerprint(p)
    return out


def markdown_files(root):
    return [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))


def collect(root):
    examples, problems = {}, []
    for md in markdown_files(root):
        rel = os.path.relpath(md, root)
        with open(md, encoding="utf-8") as f:
            ex, pr = parse(rel, f.read())
        problems += pr
        if ex:
            examples[rel] = ex
    return examples, problems


def run_all(root, zhc, example_inputs, maps):
    examples, problems = collect(root)
    failures = list(problems)
    if not examples:
        failures.append("no examples found in README.md and docs/*.md")
    work = tempfile.mkdtemp(prefix="zhc-examples-")
    try:
        inputs = os.path.join(work, "examples")
        # The checked-in example files, then the generated ones beside them.
        shutil.copytree(os.path.join(root, "examples"), inputs,
                        ignore=shutil.ignore_patterns("maps", "*.exr", "*.hdr", "*.zhp"))
        env = dict(os.environ, ZHC=zhc, ZHC_EXAMPLE_INPUTS=example_inputs, ZHC_ENVMAP_DIR=maps)
        gen = subprocess.run(["bash", os.path.join(root, "scripts", "make_examples.sh"), inputs], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if gen.returncode != 0:
            print(gen.stdout)
            print("scripts/make_examples.sh failed (exit %d)" % gen.returncode)
            return 1
        before_all = tree_fingerprints(inputs)
        bindir = os.path.join(work, "bin")
        os.mkdir(bindir)
        os.symlink(os.path.abspath(zhc), os.path.join(bindir, "zhc"))
        env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
        env.pop("ZHC_ENVMAP_DIR", None)
        count = 0
        for md, exs in examples.items():
            cwd = os.path.join(work, "run", md.replace("/", "_"))
            os.makedirs(cwd)
            os.symlink(inputs, os.path.join(cwd, "examples"))
            for ex in exs:
                count += 1
                ins = named_inputs(ex.command, cwd)
                before = {p: fingerprint(p) for p in ins if os.path.isfile(p)}
                t0 = time.monotonic()
                try:
                    r = subprocess.run(["bash", "-o", "pipefail", "-c", ex.command], cwd=cwd, env=env,
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                       errors="replace", timeout=TIMEOUT_S)
                    rc, err = r.returncode, r.stderr
                except subprocess.TimeoutExpired:
                    rc, err = None, "timed out after %d s" % TIMEOUT_S
                dt = time.monotonic() - t0
                status = []
                if rc != ex.exit_code:
                    status.append("exit %s, expected %d: %s" % (rc, ex.exit_code, err.strip()[-600:]))
                for p, fp in sorted(before.items()):
                    if not os.path.isfile(p) or fingerprint(p) != fp:
                        status.append("changed its input %s" % os.path.relpath(p, work))
                print("%-6s %6.1f s  %s  %s" % ("ok" if not status else "FAIL", dt, ex.where(), ex.command))
                for s in status:
                    failures.append("%s: %s: %s" % (ex.where(), ex.command, s))
        after_all = tree_fingerprints(inputs)
        for p in sorted(set(before_all) | set(after_all)):
            if before_all.get(p) != after_all.get(p):
                failures.append("an example changed, added or removed %s" % os.path.relpath(p, work))
        print("%d examples from %d files" % (count, len(examples)))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for f in failures:
        print("FAIL: " + f)
    return 1 if failures else 0


def self_test():
    """The parsing rule on a small Markdown text with known answers."""
    text = "\n".join([
        "```sh",                                  # 1
        "zhc project a.exr            # table",   # 2: exit 0
        "bash scripts/run.sh",                    # 3: not zhc
        "  zhc audit m/ --fail-on-negative   # exit 8 naming the file",  # 4: exit 8
        "```",                                    # 5
        "```sh no-test: needs a GPU",             # 6
        "zhc bench --runtime-cost c.json",        # 7: skipped
        "```",                                    # 8
        "```",                                    # 9
        "zhc --help",                             # 10: plain block, not run
        "```",                                    # 11
        "```bash no-test",                        # 12: reason missing
        "zhc info x",                             # 13
        "```",                                    # 14
        "```json",                                # 15
        "zhc not run",                            # 16
        "```",                                    # 17
        "```bash",                                # 18
        "zhc convert a.zhp -o 'my out.json' > log.txt   # exit 3 hmm",  # 19
        "```",                                    # 20
        "```sh",                                  # 21
        "zhc demo -o /tmp/demo",                  # 22: absolute path: a problem
        "```",                                    # 23
    ])
    ex, pr = parse("t.md", text)
    got = [(e.line, e.exit_code) for e in ex]
    ok = True
    if got != [(2, 0), (4, 8), (19, 3), (22, 0)]:
        print("self-test: examples %s, expected [(2, 0), (4, 8), (19, 3), (22, 0)]" % got)
        ok = False
    if len(pr) != 2 or "t.md:12" not in pr[0] or "t.md:22" not in pr[1]:
        print("self-test: problems %s, expected one at t.md:12 and one at t.md:22" % pr)
        ok = False
    d = tempfile.mkdtemp()
    try:
        for name in ("a.zhp", "my out.json", "log.txt"):
            open(os.path.join(d, name), "w").close()
        ins = {os.path.basename(p) for p in named_inputs(ex[2].command, d)}
        if ins != {"a.zhp"}:
            print("self-test: inputs %s, expected {'a.zhp'}" % ins)
            ok = False
        # A file rewritten with the same bytes (zhc writes a temporary file, then renames it) counts as changed.
        a = os.path.join(d, "a.zhp")
        fp = fingerprint(a)
        with open(a + ".tmp", "w") as f:
            f.write("")
        os.replace(a + ".tmp", a)
        if fingerprint(a) == fp:
            print("self-test: a renamed-over input was not seen as changed")
            ok = False
    finally:
        shutil.rmtree(d)
    print("self-test " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) == 3 and argv[1] == "--list":
        examples, problems = collect(argv[2])
        for exs in examples.values():
            for e in exs:
                print("%s  [exit %d]  %s" % (e.where(), e.exit_code, e.command))
        for p in problems:
            print("PROBLEM: " + p)
        return 1 if problems else 0
    args = dict(zip(argv[1:-1:2], argv[2:-1:2]))
    if len(argv) != 8 or set(args) != {"--zhc", "--example-inputs", "--maps"}:
        print(__doc__)
        return 2
    return run_all(argv[-1], args["--zhc"], args["--example-inputs"], args["--maps"])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
