"""Writes the API reference of the Python package ffsr as Markdown, from the module's own signatures and
docstrings (nanobind's), for docs/python.md between the lines `<!-- api-reference: begin -->` and
`<!-- api-reference: end -->`.

    build-python/venv/bin/python python/tools/api_reference.py            # print it
    build-python/venv/bin/python python/tools/api_reference.py --write    # replace it in docs/python.md

python/tests/test_docs.py checks that docs/python.md holds what this prints.
"""

import inspect
import pathlib
import re
import sys

import ffsr

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "python.md"
BEGIN, END = "<!-- api-reference: begin -->", "<!-- api-reference: end -->"


def clean(sig):
    """A nanobind signature without the extension's module prefix."""
    sig = re.sub(r"\bffsr\._ffsr\.", "", sig)
    return re.sub(r"<(\w+) object at 0x[0-9a-f]+>", r"\1()", sig)  # a default's repr: no address


def split_doc(obj):
    """(signatures, text) of a nanobind function's __doc__: its signature lines first, then the docstring."""
    doc = inspect.getdoc(obj) or ""
    lines = doc.splitlines()
    sigs, rest = [], []
    for i, line in enumerate(lines):
        if re.match(r"^[A-Za-z_][A-Za-z0-9_]*\(.*\)( -> .*)?$", line) and not rest:
            sigs.append(line)
        else:
            rest = lines[i:]
            break
    return [clean(s) for s in sigs], "\n".join(rest).strip()


def function_entry(name, fn, prefix=""):
    sigs, text = split_doc(fn)
    out = ["```python"] + [prefix + s for s in (sigs or [name + "(...)"])] + ["```"]
    if text:
        out += ["", text]
    return "\n".join(out)


def class_entry(name, cls):
    out = [f"### {name}", "", (inspect.getdoc(cls) or "").strip(), ""]
    members = []
    for attr, value in sorted(vars(cls).items()):
        if attr.startswith("_") and attr != "__init__":
            continue
        if isinstance(value, property):
            doc = (value.__doc__ or "").strip()
            members.append(f"- `{attr}` (property){': ' + doc.splitlines()[-1] if doc else ''}")
        elif callable(value) or isinstance(value, (staticmethod, classmethod)):
            fn = getattr(cls, attr)
            members.append(function_entry(attr, fn, prefix=f"{name}." if attr != "__init__" else ""))
    out += members
    return "\n".join(out) + "\n"


def reference():
    names = sorted(n for n in dir(ffsr) if not n.startswith("_"))
    exceptions = [n for n in names if isinstance(getattr(ffsr, n), type) and issubclass(getattr(ffsr, n), BaseException)]
    classes = [n for n in names if isinstance(getattr(ffsr, n), type) and n not in exceptions]
    functions = [n for n in names if callable(getattr(ffsr, n)) and n not in classes and n not in exceptions]
    out = ["## API reference", "",
           "Generated from the package's signatures and docstrings by `python/tools/api_reference.py`.", "",
           "### Exceptions", ""]
    for n in exceptions:
        cls = getattr(ffsr, n)
        bases = ", ".join(b.__name__ for b in cls.__bases__)
        out.append(f"- `{n}({bases})`: {(cls.__doc__ or '').strip()}")
    out += ["", "### Functions", ""]
    for n in functions:
        out += [function_entry(n, getattr(ffsr, n)), ""]
    for n in classes:
        out.append(class_entry(n, getattr(ffsr, n)))
    return "\n".join(out).rstrip() + "\n"


def main(argv):
    text = reference()
    if "--write" in argv:
        doc = DOC.read_text()
        a, b = doc.index(BEGIN) + len(BEGIN), doc.index(END)
        DOC.write_text(doc[:a] + "\n" + text + doc[b:])
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main(sys.argv[1:])
