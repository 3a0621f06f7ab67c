"""The function-length rule (ARCHITECTURE.md, "Function length"), run by ``make lint``.

No Python function of the package is longer than :data:`PYTHON_LIMIT` lines and
no Rust function of the two crates longer than :data:`RUST_LIMIT`, counted from
the ``def`` / ``fn`` line to the function's last line (docstring and comments
included, a nested function inside its parent's count too). A Rust hot kernel
may be longer when the line just above its ``fn`` (or above its attributes and
doc comment) says why, as a comment starting ``// hot kernel:``.

The functions that were longer when the rule came are listed in
:data:`TO_SPLIT` with their length then: none may grow, none may be added, and
one split below the limit must leave the list (a stale entry fails too), so
the list only shrinks until it is empty.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON_LIMIT = 80
RUST_LIMIT = 120
HOT_KERNEL = "// hot kernel:"

#: The functions over the limit when the rule came, with their length then
#: (file:qualified name -> lines); to be split, never to grow.
TO_SPLIT: dict[str, int] = {}


def _over_the_limit(found: list[tuple[str, int]], limit: int) -> list[str]:
    """What breaks the rule: a function over ``limit`` that is not in :data:`TO_SPLIT`
    or longer than it was, and an entry of :data:`TO_SPLIT` that is now short enough."""
    lengths = dict(found)
    problems = [
        f"{name}: {lines} lines" + (f" (was {TO_SPLIT[name]}: it may not grow)" if name in TO_SPLIT else "")
        for name, lines in found
        if lines > limit and lines > TO_SPLIT.get(name, limit)
    ]
    prefix = "crates/" if limit == RUST_LIMIT else "python/"
    problems += [
        f"{name}: now {lengths.get(name, 0)} lines or gone: take it off TO_SPLIT"
        for name in TO_SPLIT
        if name.startswith(prefix) and lengths.get(name, 0) <= limit
    ]
    return sorted(problems)


def python_functions(package: Path = ROOT / "python" / "grainlab") -> list[tuple[str, int]]:
    """``(file:qualified name, lines)`` of every function and method of the package."""
    found = []
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        stack: list[tuple[ast.AST, str]] = [(tree, "")]
        while stack:
            node, prefix = stack.pop()
            for child in ast.iter_child_nodes(node):
                if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                    name = f"{prefix}{child.name}"
                    if not isinstance(child, ast.ClassDef):
                        lines = (child.end_lineno or child.lineno) - child.lineno + 1
                        found.append((f"{path.relative_to(ROOT)}:{name}", lines))
                    stack.append((child, name + "."))
                else:
                    stack.append((child, prefix))
    return found


_FN = re.compile(r"^\s*(pub(\([a-z]+\))?\s+)?(const\s+)?(unsafe\s+)?(extern\s+\"C\"\s+)?fn\s+(\w+)")


def _strip(line: str) -> str:
    """A Rust line without its string and char literals and its line comment (enough to count braces)."""
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    return line.split("//", 1)[0]


def rust_functions(crates: Path = ROOT / "crates") -> list[tuple[str, int, bool]]:
    """``(file:fn name, lines, says it is a hot kernel)`` of every Rust function with a body."""
    found = []
    for path in sorted(crates.rglob("*.rs")):
        lines = path.read_text().splitlines()
        for k, line in enumerate(lines):
            match = _FN.match(line)
            if not match:
                continue
            depth, opened, end = 0, False, None
            for m in range(k, len(lines)):
                code = _strip(lines[m])
                if not opened and ";" in code and "{" not in code:
                    break  # a declaration without a body (a trait's)
                depth += code.count("{") - code.count("}")
                opened = opened or "{" in code
                if opened and depth <= 0:
                    end = m
                    break
            if end is None:
                continue
            above = k - 1
            while above >= 0 and lines[above].strip().startswith(("#[", "///")):
                above -= 1
            hot = above >= 0 and lines[above].strip().startswith(HOT_KERNEL)
            found.append((f"{path.relative_to(ROOT)}:{match.group(6)}", end - k + 1, hot))
    return found


def test_the_rule_counts_what_it_says():
    src = "def outer():\n    x = 1\n\n    def inner():\n        return x\n    return inner\n"
    tree = ast.parse(src)
    outer = tree.body[0]
    assert isinstance(outer, ast.FunctionDef) and outer.end_lineno == 6
    assert _FN.match("    pub(crate) fn law_by_four<const R: bool>(") is not None
    assert _FN.match("    fn run(&mut self) -> Result<()>;") is not None
    assert _strip('let s = "{"; // }') == 'let s = ""; '


def test_the_ratchet_refuses_growth_newcomers_and_stale_entries(monkeypatch):
    # a listed function of 100 lines, on a list that holds it alone
    name = "python/grainlab/listed.py:f"
    monkeypatch.setitem(TO_SPLIT, name, 100)
    listed = [(n, lines) for n, lines in TO_SPLIT.items() if n.startswith("python/")]
    others = [(n, lines) for n, lines in listed if n != name]
    assert _over_the_limit(listed, PYTHON_LIMIT) == []
    grown = _over_the_limit([*others, (name, TO_SPLIT[name] + 1)], PYTHON_LIMIT)
    assert len(grown) == 1 and "may not grow" in grown[0]
    new = _over_the_limit([*listed, ("python/grainlab/new.py:f", 81)], PYTHON_LIMIT)
    assert new == ["python/grainlab/new.py:f: 81 lines"]
    stale = _over_the_limit([*others, (name, 40)], PYTHON_LIMIT)
    assert stale == [f"{name}: now 40 lines or gone: take it off TO_SPLIT"]


def test_no_python_function_is_longer_than_the_limit():
    problems = _over_the_limit(python_functions(), PYTHON_LIMIT)
    assert not problems, f"Python functions over {PYTHON_LIMIT} lines (split them):\n" + "\n".join(problems)


def test_no_rust_function_is_longer_than_the_limit_but_a_hot_kernel_that_says_why():
    found = [(name, lines) for name, lines, hot in rust_functions() if not hot]
    problems = _over_the_limit(found, RUST_LIMIT)
    assert not problems, (
        f"Rust functions over {RUST_LIMIT} lines (split them, or for a hot kernel say why "
        f"on the line above: '{HOT_KERNEL} ...'):\n" + "\n".join(problems)
    )
