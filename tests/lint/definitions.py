#!/usr/bin/env python3
"""One definition per type name (ARCHITECTURE.md): a class, struct, union or enum defined at namespace
scope outside an anonymous namespace has external linkage, and two different definitions of one
qualified name in two files break C++'s one-definition rule, silently (the linker keeps either's
inline functions). File-local types belong in an anonymous namespace.

usage: definitions.py SOURCE_DIR [EXTRA_FILE ...]
Scans libvolmorph/, render/ and tools/ under SOURCE_DIR (and any EXTRA_FILE, for the test that plants
a duplicate) and exits 1 listing every qualified name defined in more than one file.

The scan is lexical, not a compiler's: comments, strings and preprocessor lines are dropped, braces
are matched, and a definition is `struct|class|union|enum [class|struct] NAME [final]` followed by
`{` or a base clause, at a depth where every enclosing scope is a named namespace. Explicit
specializations (NAME<...>) and forward declarations are not definitions.
"""
import re
import sys
from collections import defaultdict
from pathlib import Path

TOKEN = re.compile(r"[A-Za-z_]\w*|::|[{}();:<>,=]|\S")
STRIP = re.compile(
    r'//[^\n]*|/\*.*?\*/|R"(?P<d>[^(\s]*)\(.*?\)(?P=d)"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'|^[ \t]*#[^\n]*(?:\\\n[^\n]*)*',
    re.S | re.M)
KEYS = {"struct", "class", "union", "enum"}


def tokens(text):
    return TOKEN.findall(STRIP.sub(" ", text))


def definitions(text):
    """Yields the qualified names of the types `text` defines at named-namespace scope."""
    toks = tokens(text)
    frames = []  # one per open brace: the scopes it opened, [("ns", name), ...] (a::b opens two),
                 # [("anon", None)] or [("other", None)]
    pending = None  # what the next '{' opens
    i = 0
    while i < len(toks):
        t = toks[i]
        if t == "namespace":
            names, j = [], i + 1
            while j < len(toks) and toks[j] not in ("{", ";", "="):
                if toks[j] not in ("::", "inline"): names.append(toks[j])
                j += 1
            if j < len(toks) and toks[j] == "{":
                pending = [("ns", n) for n in names] or [("anon", None)]
                i = j
            else:
                i = j + 1  # a namespace alias
            continue
        if t in KEYS and (i == 0 or toks[i - 1] not in ("<", ",", "friend")):
            j = i + 1
            if t == "enum" and j < len(toks) and toks[j] in ("class", "struct"): j += 1
            if j < len(toks) and re.match(r"[A-Za-z_]\w*$", toks[j]):
                name, j = toks[j], j + 1
                if j < len(toks) and toks[j] == "final": j += 1
                if j < len(toks) and toks[j] in ("{", ":"):
                    scopes = [s for f in frames for s in f]
                    if all(kind == "ns" for kind, _ in scopes):
                        yield "::".join([n for _, n in scopes] + [name])
                    # The body's '{' comes after any base clause.
                    while j < len(toks) and toks[j] not in ("{", ";"): j += 1
                    if j < len(toks) and toks[j] == "{":
                        pending = [("other", None)]
                        i = j
                        continue
            i += 1
            continue
        if t == "{":
            frames.append(pending or [("other", None)])
            pending = None
        elif t == "}" and frames:
            frames.pop()
        i += 1


def scan(files):
    where = defaultdict(set)
    for f in files:
        for name in definitions(Path(f).read_text(errors="replace")):
            where[name].add(str(f))
    return {n: sorted(fs) for n, fs in where.items() if len(fs) > 1}


def main(argv):
    if len(argv) < 2:
        print(__doc__.strip().splitlines()[4], file=sys.stderr)
        return 2
    root = Path(argv[1])
    files = sorted(p for d in ("libvolmorph", "render", "tools") for p in (root / d).rglob("*")
                   if p.suffix in (".h", ".cpp") and "node_modules" not in p.parts)
    files += [Path(f) for f in argv[2:]]
    dupes = scan(files)
    if dupes:
        print("types defined in more than one file (one-definition rule; a file's own type goes in an "
              "anonymous namespace):")
        for name, fs in sorted(dupes.items()):
            print("  %s: %s" % (name, ", ".join(str(Path(f).relative_to(root)) if root in Path(f).parents
                                                 else f for f in fs)))
        return 1
    print("one definition per type name: %d files" % len(files))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
