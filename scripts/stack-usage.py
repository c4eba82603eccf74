#!/usr/bin/env python3
"""Worst-case stack depth of an entry function along GCC's static call graph.

Reads the call graphs that GCC writes with -fcallgraph-info=su (one .ci file per object, VCG format:
a node per function defined in the translation unit, titled "<source>:<assembler name>", whose label
ends with the -fstack-usage figure "<N> bytes (static|dynamic|dynamic,bounded)"; a node per external
function called, titled with its bare assembler name; an edge per call site). The =su part carries the
same numbers as the .su files of -fstack-usage, which are therefore only cross-checked (same count of
functions with a figure per object).

    scripts/stack-usage.py build-onboard/m7 --entry ffsr_standin_step [--entry ...]
        [--assume sin=64 --assume cos=64 ...] [--strict] [--path]

Directories are searched recursively for .ci files; files may also be named one by one.

The result is exact for what the compiler saw, and a lower bound otherwise. The script says which:
  - external functions with no .ci (libm, libc, libstdc++ compiled without the flag): counted as 0
    bytes unless --assume NAME=BYTES gives a figure; listed;
  - "dynamic" frames (alloca, variable-length arrays): unbounded, the static part counted; listed;
    "dynamic,bounded" frames count their bound;
  - indirect calls (function pointers, virtual calls: GCC's __indirect_call node): not followed; listed;
  - recursion: a cycle in the graph makes the depth unbounded; the cycle is listed.
With --strict the exit status is 1 if any of these makes the figure a lower bound, 0 otherwise (2 on
usage errors, an unknown entry).
"""
import argparse
import collections
import os
import re
import sys

NODE_RE = re.compile(r'node:\s*\{\s*title:\s*"((?:[^"\\]|\\.)*)"(?:\s*label:\s*"((?:[^"\\]|\\.)*)")?')
EDGE_RE = re.compile(r'edge:\s*\{\s*sourcename:\s*"((?:[^"\\]|\\.)*)"\s*targetname:\s*"((?:[^"\\]|\\.)*)"')
SIZE_RE = re.compile(r'(\d+) bytes \(([a-z,]+)\)\s*$')
INDIRECT = "__indirect_call"


class Function:
    """A function defined in some translation unit (a node with a stack figure)."""

    def __init__(self, title, label, source_file):
        self.title = title
        self.asm_name = title.rsplit(":", 1)[-1] if ":" in title else title
        lines = label.split("\\n") if label else [title]
        self.display = lines[0]
        match = SIZE_RE.search(lines[-1]) if label else None
        self.frame = int(match.group(1)) if match else None
        self.qualifier = match.group(2) if match else None
        self.source_file = source_file
        self.callees = []  # target titles or external names, in call order

    @property
    def plain_name(self):
        """The demangled name without parameters or return type, e.g. ffsr::Foo::step."""
        name = self.display.split(" [with ")[0]
        name = name.split("(")[0].strip()
        return name.split(" ")[-1]


def find_files(paths, extension):
    for path in paths:
        if os.path.isdir(path):
            for root, _, names in os.walk(path):
                for name in sorted(names):
                    if name.endswith(extension):
                        yield os.path.join(root, name)
        elif path.endswith(extension):
            yield path


def read_graph(ci_files):
    """Functions by (.ci file, title), and by assembler name across files.

    GCC titles an externally visible function with its bare assembler name and a local or COMDAT one
    (static, inline, template instance, clone) with "<source>:<assembler name>"; a call names its target
    by that title. So a call resolves first within its own file, then by assembler name in any file
    (where COMDAT copies of one inline function may have different frames: the analysis takes the worst).
    Give the .ci files of one program: two programs' main() would both be taken for "main".
    """
    functions = {}  # (ci file, title) -> Function
    by_asm_name = collections.defaultdict(list)  # asm name -> [Function]
    for ci in ci_files:
        with open(ci, encoding="utf-8", errors="replace") as handle:
            text = handle.read()
        for title, label in NODE_RE.findall(text):
            function = Function(title, label, ci)
            if function.frame is None:
                continue  # an external function: resolved by name across the files
            functions[(ci, title)] = function
            by_asm_name[function.asm_name].append(function)
        for source, target in EDGE_RE.findall(text):
            if (ci, source) in functions:
                functions[(ci, source)].callees.append(target)
    return functions, by_asm_name


def su_cross_check(su_files, functions):
    """Counts the figures in the .su files and in the .ci files per object; returns mismatch lines."""
    su_counts = collections.Counter()
    for su in su_files:
        with open(su, encoding="utf-8", errors="replace") as handle:
            su_counts[su[: -len(".su")]] += sum(1 for line in handle if line.strip())
    ci_counts = collections.Counter(f.source_file[: -len(".ci")] for f in functions.values())
    problems = []
    for stem in sorted(set(su_counts) & set(ci_counts)):
        if su_counts[stem] != ci_counts[stem]:
            problems.append(f"{stem}: {su_counts[stem]} functions in .su, {ci_counts[stem]} in .ci")
    return problems


# The Itanium C++ ABI's constructor and destructor variants that GCC emits as aliases of one body:
# a call to the complete-object constructor (C1) reaches the base-object one's node (C2), and so on.
ALIASES = (("C1E", "C2E"), ("D1E", "D2E"), ("C3E", "C2E"))


class Analysis:
    def __init__(self, functions, by_asm_name, assumed):
        self.functions = functions
        self.by_asm_name = by_asm_name
        self.assumed = assumed
        self.memo = {}  # id(Function) -> (depth, path)
        self.unknown = set()
        self.dynamic = set()
        self.indirect = set()
        self.cycles = []

    def resolve(self, caller, target):
        """The definitions a call from `caller` to `target` may reach (empty: unknown)."""
        local = self.functions.get((caller.source_file, target))
        if local is not None:
            return [local]
        name = target.rsplit(":", 1)[-1]
        if name in self.by_asm_name:
            return self.by_asm_name[name]
        for alias, body in ALIASES:
            if alias in name:
                renamed = name.replace(alias, body, 1)
                local = self.functions.get((caller.source_file, target.replace(alias, body, 1)))
                if local is not None:
                    return [local]
                if renamed in self.by_asm_name:
                    return self.by_asm_name[renamed]
        return []

    def depth(self, function, stack):
        """Worst depth (bytes) below and including `function`, with the path that reaches it."""
        key = id(function)
        if key in self.memo:
            return self.memo[key]
        if function in stack:
            cycle = stack[stack.index(function):] + [function]
            self.cycles.append([f.display for f in cycle])
            return 0, []
        if function.qualifier == "dynamic":
            self.dynamic.add(function.display)
        stack.append(function)
        best, best_path = 0, []
        for target in function.callees:
            if target == INDIRECT:
                self.indirect.add(function.display)
                continue
            definitions = self.resolve(function, target)
            if not definitions:
                name = target.rsplit(":", 1)[-1]
                if name in self.assumed:
                    if self.assumed[name] > best:
                        best, best_path = self.assumed[name], [(f"{name} (assumed)", self.assumed[name])]
                else:
                    self.unknown.add(name)
                continue
            for callee in definitions:
                callee_depth, callee_path = self.depth(callee, stack)
                if callee_depth > best:
                    best, best_path = callee_depth, callee_path
        stack.pop()
        result = (function.frame + best, [(function.display, function.frame)] + best_path)
        # Memoised even when a cycle was cut below: the figure is then flagged as unbounded anyway.
        self.memo[key] = result
        return result


def find_entry(name, functions, by_asm_name):
    if name in by_asm_name:
        return by_asm_name[name]
    return [f for f in functions.values() if f.plain_name == name or f.title == name]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="+", help=".ci files or directories holding them")
    parser.add_argument("--entry", action="append", required=True,
                        help="entry function: assembler name (extern \"C\" name) or qualified C++ name")
    parser.add_argument("--assume", action="append", default=[], metavar="NAME=BYTES",
                        help="stack figure of an external function without a .ci (e.g. a libm function)")
    parser.add_argument("--strict", action="store_true",
                        help="exit 1 when the figure is only a lower bound")
    parser.add_argument("--path", action="store_true", help="print the deepest call path")
    args = parser.parse_args()

    assumed = {}
    for item in args.assume:
        name, _, size = item.partition("=")
        if not size.isdigit():
            parser.error(f"--assume {item}: expected NAME=BYTES")
        assumed[name] = int(size)

    ci_files = list(find_files(args.paths, ".ci"))
    if not ci_files:
        print("stack-usage: no .ci files (compile with -fcallgraph-info=su)", file=sys.stderr)
        return 2
    functions, by_asm_name = read_graph(ci_files)
    for problem in su_cross_check(list(find_files(args.paths, ".su")), functions):
        print(f"stack-usage: warning: .su and .ci disagree: {problem}", file=sys.stderr)

    lower_bound = False
    for entry in args.entry:
        definitions = find_entry(entry, functions, by_asm_name)
        if not definitions:
            print(f"stack-usage: no function {entry} in {len(ci_files)} .ci files", file=sys.stderr)
            return 2
        analysis = Analysis(functions, by_asm_name, assumed)
        depth, path = max((analysis.depth(f, []) for f in definitions), key=lambda r: r[0])
        exact = not (analysis.unknown or analysis.dynamic or analysis.indirect or analysis.cycles)
        lower_bound |= not exact
        print(f"{entry}: {depth} bytes worst case{'' if exact else ' (a lower bound: see below)'}")
        if args.path:
            for name, frame in path:
                print(f"  {frame:6d}  {name[:150]}")
        if analysis.unknown:
            print(f"  external functions without a figure (counted as 0; --assume NAME=BYTES): "
                  f"{', '.join(sorted(analysis.unknown))}")
        for name in sorted(analysis.dynamic):
            print(f"  dynamic (unbounded) frame: {name[:150]}")
        for name in sorted(analysis.indirect):
            print(f"  indirect call, not followed, in: {name[:150]}")
        for cycle in analysis.cycles:
            print(f"  recursion (unbounded): {' -> '.join(n[:60] for n in cycle)}")
    return 1 if (args.strict and lower_bound) else 0


if __name__ == "__main__":
    sys.exit(main())
