"""The size bounds of the code (CONTRIBUTING.md): in include/, src/ and python/src no function over
cyclomatic complexity 20 or 80 lines, as lizard measures them (pinned in python/pyproject.toml's test
extra), and no file over 700 lines. A failure names every offender."""

import pathlib

import lizard
import pytest

from conftest import REPO

FOLDERS = ("include", "src", "python/src")
MAX_COMPLEXITY = 20
MAX_FUNCTION_LINES = 80
MAX_FILE_LINES = 700
# lizard picks its reader by the file's ending; these are C++ too
CPP_ALIASES = {".hxx": ".hpp", ".in": ".hpp"}


def source_files():
    files = []
    for folder in FOLDERS:
        files += [p for p in sorted((REPO / folder).rglob("*")) if p.is_file()]
    return files


def measured_functions(path):
    """lizard's functions of one file (none for a file it has no reader for)."""
    code = path.read_text()
    name = str(path) + CPP_ALIASES.get(path.suffix, "")
    return lizard.analyze_file.analyze_source_code(name, code).function_list


def function_offenses(path, functions):
    rel = path.relative_to(REPO)
    return [
        f"{rel}:{f.start_line}: {f.name}: complexity {f.cyclomatic_complexity}, {f.length} lines"
        for f in functions
        if f.cyclomatic_complexity > MAX_COMPLEXITY or f.length > MAX_FUNCTION_LINES
    ]


def test_the_measure_sees_a_long_and_branching_function(tmp_path):
    body = "".join(f"  if (x == {i}) return {i};\n" for i in range(90))
    path = tmp_path / "long.hxx"
    path.write_text("inline int f(int x) {\n" + body + "  return -1;\n}\n")
    (f,) = measured_functions(path)
    assert f.cyclomatic_complexity == 91
    assert f.length == 93  # the signature, 90 branches, the last return and the brace


def test_no_function_over_the_bounds():
    files = source_files()
    offenses, measured = [], 0
    for path in files:
        functions = measured_functions(path)
        measured += len(functions)
        offenses += function_offenses(path, functions)
    assert measured > 500, f"lizard measured only {measured} functions in {FOLDERS}: a reader is missing"
    assert not offenses, (
        f"functions over complexity {MAX_COMPLEXITY} or {MAX_FUNCTION_LINES} lines:\n  " + "\n  ".join(offenses))


def test_no_file_over_the_bound():
    long_files = []
    for path in source_files():
        n = len(path.read_text().splitlines())
        if n > MAX_FILE_LINES:
            long_files.append(f"{path.relative_to(REPO)}: {n} lines")
    assert not long_files, f"files over {MAX_FILE_LINES} lines:\n  " + "\n  ".join(long_files)
